"""The linear joints' equations in body axes (flexgear.mbs.joints.body_axes_form).

Premultiplying a joint's six equations by Q(a)^T = blockdiag(R_z(a)^T, R_z(a)^T) is an exact row transformation:
the forms must equal Q^T times the ground-axes rows at every angle. A joint is written in body axes where its shaft
is flexible (model 7 in body axes against the reference formulation: tests/test_spin.py).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import VARIANTS

import flexgear as fg
from flexgear.mbs.joints import body_axes_form, frame_form, turning_form


def _q_transposed(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.kron(np.eye(2), np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]))


def _at(form, a: float) -> np.ndarray:
    return form[0] + np.cos(a) * form[1] + np.sin(a) * form[2]


def test_body_axes_form_is_the_rotated_rows():
    """Modal rows (turning as R_z) become constant; a frame lever on the axis gives rows equal to Q^T times the
    ground rows at every angle; rows that do not turn as R_z (a second harmonic in body axes) are refused, and so
    is a joint off the axis."""
    rng = np.random.default_rng(3)
    rows = rng.normal(size=(6, 7))
    const, cos_part, sin_part = body_axes_form(turning_form(rows))
    assert np.allclose(const, rows, rtol=0, atol=1e-14) and not cos_part.any() and not sin_part.any()
    ground = frame_form(np.array([0.0, 0.0, 0.03]))  # a joint on the axis: constant in ground axes
    body = body_axes_form(ground)
    for a in rng.uniform(-np.pi, np.pi, 5):
        assert np.allclose(_at(body, a), _q_transposed(a) @ _at(ground, a), rtol=0, atol=1e-14)
    # in body axes the rows are [R^T, -p~ R^T] on the ground frame coordinates
    a = 1.1
    r_t = _q_transposed(a)[:3, :3]
    p_tilde = np.array([[0.0, -0.03, 0.0], [0.03, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert np.allclose(_at(body, a)[:3], np.hstack([r_t, -p_tilde @ r_t]), rtol=0, atol=1e-14)
    with pytest.raises(ValueError, match="second harmonic"):
        body_axes_form((np.zeros((6, 6)), np.eye(6), np.zeros((6, 6))))
    with pytest.raises(ValueError, match="off the spin axis"):
        frame_form(np.array([0.12, -0.05, 0.03]))


@pytest.mark.parametrize("case, body_axes", [("model3", ("sun", "ring")), ("model4", ())])
def test_joints_are_in_body_axes_where_the_shaft_is_flexible(case, body_axes):
    """Model 3's flexible shafts take both gears' joints to body axes, model 4's rigid shafts keep them in ground
    axes (where body axes cost more Jacobians)."""
    import exudyn as exu

    from flexgear.mbs.gearbox import build_star_gearbox

    v = fg.load_variant(VARIANTS / f"{case}.toml")
    model = build_star_gearbox(exu.SystemContainer().AddSystem(), v)
    assert set(model.linear_joints) == {"sun", "ring"}
    assert model.body_axes_joints == body_axes
