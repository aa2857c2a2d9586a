"""Modal screening (flexgear.modal.screening) on model 4 (coarse; sun and ring flexible): the mechanics.

- The weighted elastic strain shares are energy shares averaged with weights that sum to 1: each lies in [0, 1],
  and so does their sum; a component that is rigid in the variant has no elastic coordinates, share 0.
- The decision and the recommendation follow the threshold: at 0 every component with elastic strain must be
  flexible (model 4's sun and ring: model 4 itself, Table 3's smallest variant with both), at 1 none (model 1).
- The weight is the single-degree-of-freedom amplification: 1/(2 zeta) at resonance, 1 in the static limit.
"""

import numpy as np
import pytest
from conftest import VARIANTS

from flexgear.modal import linearize, modal_screening
from flexgear.modal.screening import TABLE3_COMPONENTS, amplification, folder_variants, recommend
from flexgear.spec import load_variant


@pytest.fixture(scope="module")
def model4_linear():
    return linearize(load_variant(VARIANTS / "model4.toml"))


@pytest.fixture(scope="module")
def screened(model4_linear):
    return modal_screening(model4_linear)


@pytest.mark.slow
def test_shares_in_unit_interval_rigid_components_zero(screened):
    t = screened.table.set_index("component")
    assert tuple(t.index) == TABLE3_COMPONENTS
    s = t.weighted_elastic_strain_share
    assert np.all((s >= 0.0) & (s <= 1.0)) and s.sum() <= 1.0 + 1e-12
    for c in ("input_shaft", "planets", "output_shaft"):
        assert s[c] == 0.0
    assert s["sun"] > 0.0 and s["ring"] > 0.0
    np.testing.assert_array_equal(t.judged, [c in ("sun", "ring") for c in t.index])  # model 4's flexible ones
    np.testing.assert_array_equal(t.must_be_flexible, s > screened.threshold)
    assert screened.reason.endswith("; not judged, rigid in model4: input_shaft, planets, output_shaft")
    assert screened.weights.sum() == pytest.approx(1.0) and np.all(screened.weights > 0.0)
    assert screened.f_band_hz == pytest.approx(10 * screened.f_mesh_hz)
    assert np.all(screened.modes.frequencies_hz <= screened.f_band_hz)


@pytest.mark.slow
def test_recommendation_holds_every_must_be_flexible_component(screened):
    must = set(screened.table.component[screened.table.must_be_flexible])
    candidates = screened.candidates
    assert list(candidates) == [f"model{i}" for i in range(1, 8)]
    assert must <= set(candidates[screened.recommended])
    fewest = min(len(f) for f in candidates.values() if must <= set(f))
    assert len(candidates[screened.recommended]) == fewest
    assert "\n" not in screened.reason and screened.recommended in screened.reason


@pytest.mark.slow
def test_threshold_bounds(model4_linear):
    everything = modal_screening(model4_linear, threshold=0.0)
    assert set(everything.table.component[everything.table.must_be_flexible]) == {"sun", "ring"}
    assert everything.recommended == "model4"
    nothing = modal_screening(model4_linear, threshold=1.0)
    assert not nothing.table.must_be_flexible.any() and nothing.recommended == "model1"


def test_a_variant_without_flexible_components_is_refused_before_its_linearisation(monkeypatch):
    """Every component rigid (model 1): nothing to judge; refused in one line naming the file and the field, before
    the linearisation (which would fail the test here)."""
    import flexgear.modal

    monkeypatch.setattr(flexgear.modal, "linearize", None)
    with pytest.raises(ValueError, match=r"model1\.toml: field 'components': .* model1 makes none flexible") as e:
        modal_screening(load_variant(VARIANTS / "model1.toml"))
    assert "\n" not in str(e.value)


def test_recommend_all_flexible_when_none_fits():
    candidates = folder_variants(VARIANTS)
    assert list(candidates) == [f"model{k}" for k in range(1, 8)]  # Table 3's order; gearbox.toml is no variant
    assert candidates["model7"] == TABLE3_COMPONENTS and candidates["model1"] == ()
    name, reason = recommend(("input_shaft", "sun"), candidates)  # only model 7 has both
    assert name == "model7" and "model7" in reason


def test_amplification_limits():
    zeta = np.array([0.02, 0.05])
    f_mesh = 1000.0
    np.testing.assert_allclose(amplification(np.array([3000.0, 5000.0]), zeta, f_mesh), 1 / (2 * zeta))
    assert amplification(np.array([1e9]), np.array([0.02]), f_mesh)[0] == pytest.approx(1.0, rel=1e-9)


@pytest.mark.slow
def test_matrix_sets_the_modal_screening_beside_the_westgard_verdict(model4_linear, screened, tmp_path):
    """flexgear.study.matrix.modal_verdict: the modal recommendation written beside the Westgard verdict of a
    results folder, 'the same' exactly when they agree; a reference that cannot be linearised is recorded."""
    from flexgear.study.matrix import modal_verdict

    for westgard in (screened.recommended, "model1" if screened.recommended != "model1" else "model2"):
        (tmp_path / "selection.txt").write_text(f"selected: {westgard}\n")
        text = modal_verdict(tmp_path, model4_linear)
        assert f"recommends {screened.recommended}" in text and f"Westgard verdict: {westgard}" in text
        assert ("(the same)" in text) == (westgard == screened.recommended)
        assert (tmp_path / "modal_screening.csv").exists()
        assert (tmp_path / "modal_screening.txt").read_text().strip() == text
    not_a_variant = type("NotAVariant", (), {"name": "x"})()   # cannot be linearised: recorded, not raised
    assert "Modal screening of x not done" in modal_verdict(tmp_path, not_a_variant)


def test_any_gearbox_folder_recommends_among_its_own_variants():
    """The spur planetary example's folder (rigid.toml, flexible.toml beside gearbox.toml: no Table 3 names): its
    variants are the candidates, and a screening that asks for a flexible ring and carrier recommends the one
    variant that has them."""
    folder = VARIANTS.parent / "examples" / "spur_planetary"
    candidates = folder_variants(folder)
    assert candidates == {"flexible": (*TABLE3_COMPONENTS, "carrier"), "rigid": ()}
    name, reason = recommend(("ring", "carrier"), candidates)
    assert name == "flexible" and "fewest flexible components" in reason
    assert recommend((), candidates)[0] == "rigid"
