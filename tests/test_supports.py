"""Supports where they are and the ISO 6336 law: multibody and lumped models on the same assumptions.

Bearings at the shafts' bearing seats (flexgear.geometry.supports), condensed to the gear centres in the
lumped model; with law = "iso6336" both models carry the same linear mesh stiffness and eq. 13 damping.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from flexgear.geometry.supports import gearbox_supports
from flexgear.lumped.model import LumpedParameters
from flexgear.lumped.run import run_lumped
from flexgear.mbs.run import run_variant
from flexgear.study.compare import harmonic_amplitudes
from flexgear.theory import theory


def _skew(r: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def test_bearing_springs_make_the_table2_bearing(gearbox):
    """The three axis springs of each bearing sum to diag(k_r, k_r, k_a, k_t, k_t, 0) about its centre."""
    for name, support in gearbox_supports(gearbox).items():
        k6 = np.zeros((6, 6))
        for spring in support.axis_springs():
            g = np.hstack([np.eye(3), -_skew(spring.point - support.centre)])  # u = t + phi x r
            k6 += g.T @ np.diag(spring.stiffness) @ g
        b = getattr(gearbox.bearings, name)
        expect = np.diag([b.radial_stiffness_n_per_m, b.radial_stiffness_n_per_m, b.axial_stiffness_n_per_m,
                          b.tilt_stiffness_nm_per_rad, b.tilt_stiffness_nm_per_rad, 0.0])
        np.testing.assert_allclose(k6, expect, rtol=1e-12, atol=1e-6)


def test_bearing_positions_and_the_floating_sun(gearbox):
    """Input bearing seat by hand: tube from the sun's +z face (15 + 4 mm) 150 mm along -z, seat 20 mm at its end.

    z_c = 0.019 - 0.150 + 0.010 = -0.121 m; at the sun 1/k = 1/2e7 + 0.121^2/4e3 -> k = 2.695e5 N/m: the sun
    floats (1.3 % of the bearing's own radial stiffness); the lumped model's sun support is that value.
    """
    s = gearbox_supports(gearbox)
    assert s["input_shaft"].centre[2] == pytest.approx(-0.121, abs=1e-9)
    assert s["planet"].centre[2] == 0.0
    k = s["input_shaft"].condensed_radial_stiffness()
    assert k == pytest.approx(1.0 / (1.0 / 2e7 + 0.121**2 / 4e3), rel=1e-12)
    assert k == pytest.approx(2.695e5, rel=1e-3)
    p = LumpedParameters.from_spec(gearbox)
    assert p.sun.bearing_stiffness_n_per_m == pytest.approx(k, rel=1e-12)
    assert p.planet.bearing_stiffness_n_per_m == pytest.approx(2e8, rel=1e-12)  # bore centre = gear centre


@pytest.fixture(scope="module")
def iso_runs(model1):
    """Rigid model 1 (exact mass properties) and the lumped model, law = "iso6336", ramps over 0.02 s, 0.1 s."""
    gb = model1.gearbox
    gb = gb.with_changes(contact=dataclasses.replace(gb.contact, law="iso6336"),
                         load_case=dataclasses.replace(gb.load_case, ramp_time_s=0.02, end_time_s=0.1))
    mbs = run_variant(dataclasses.replace(model1, gearbox=gb))
    assert mbs.ok, mbs.meta.get("reason")
    return gb, mbs, run_lumped(gb)


def _window(result):
    s = result.signals
    return s[s.time_s >= 0.05]


def test_iso6336_rigid_model1_and_lumped_agree_at_mesh_frequency(iso_runs):
    """Same supports, law and damping: bearing acceleration amplitude at 1x mesh frequency within 10 %."""
    gb, mbs, lumped = iso_runs
    f_mesh = theory(gb).mesh_frequency
    for side in ("input", "output"):
        a = [harmonic_amplitudes(_window(r)[f"{side}_bearing_accel_x_m_per_s2"].to_numpy(), 1e-5, f_mesh, (1,))[0]
             for r in (mbs, lumped)]
        assert a[0] == pytest.approx(a[1], rel=0.10), (side, a)
    for r in (mbs, lumped):  # and both at theory
        w = _window(r)
        assert w.output_speed_rad_per_s.mean() == pytest.approx(theory(gb).output_speed, rel=1e-4)


def test_loaded_transmission_error_equals_lumped_static_solution(iso_runs):
    """Mean loaded TE of the rigid multibody model = the lumped model's linear static solution (mean stiffness).

    Static lumped problem (flexgear.lumped.run.static_mesh_forces' system): the ring lags by theta_r; TE =
    r_b,ring |theta_r| (planet bearings about 7 um, mesh deflections about 1.7 and 1.3 um along the normals).
    """
    from flexgear.lumped.kernel_layout import LOAD_SIGN, OUT_SPIN, T_LOAD
    from flexgear.lumped.run import build_lumped_model

    gb, mbs, _ = iso_runs
    model = build_lumped_model(gb)
    s = model.system
    load = np.zeros(s.n)
    load[model.ip[OUT_SPIN]] = model.fp[LOAD_SIGN] * model.fp[T_LOAD]
    q = np.zeros(s.n)
    k = s.stiffness()
    q[model.free] = np.linalg.solve(k[np.ix_(model.free, model.free)], load[model.free])
    from flexgear.geometry.involute import gear_set_geometry

    te_static = gear_set_geometry(gb).ring.base_radius * abs(q[model.ip[OUT_SPIN]])
    te = _window(mbs).transmission_error_m.mean()
    assert 5e-6 < te_static < 5e-5
    assert te == pytest.approx(te_static, rel=0.02)
    assert math.isfinite(te)
