"""Reference screening (dynamic indicators, Bias against a reference variant) and the settled window,
on synthetic signals whose differences and decay are known by construction."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from synthetic import GEARBOX, synthetic_result

from flexgear.settling import SettleRule, settled_start
from flexgear.spec import load_gearbox
from flexgear.study.screening import UnsettledReference, analysis_window, screen


@pytest.fixture(scope="module")
def settings():
    return dataclasses.replace(load_gearbox(GEARBOX).screening, window="after_ramps")


def _with_te(res, loaded: float):
    """A loaded transmission error of mean ``loaded`` [m] with a ripple at the mesh frequency."""
    t = res.signals["time_s"].to_numpy()
    f = res.meta["theory"]["mesh_frequency_hz"]
    res.signals["transmission_error_m"] = loaded + 0.05 * loaded * np.sin(2 * np.pi * f * t + 0.3)
    return res


def test_reference_has_zero_bias_and_known_differences_are_recovered(settings):
    ref = _with_te(synthetic_result("ref"), 2e-6)
    louder = synthetic_result("louder")               # input bearing 10 % louder, no TE signal
    for axis in ("x", "y"):
        louder.signals[f"input_bearing_accel_{axis}_m_per_s2"] *= 1.10
    heavier = synthetic_result("heavier")             # every outer mesh force 2 % higher, no TE signal
    cols = [c for c in heavier.signals.columns if c.startswith("outer_mesh_force_")]
    heavier.signals[cols] *= 1.02
    noisier = _with_te(synthetic_result("noisier"), 2.2e-6)   # loaded TE 10 % larger, all else equal
    s = screen([ref, louder, heavier, noisier], settings, reference="ref")
    tab = s.table.set_index("variant")
    ind = s.indicators.set_index(["variant", "indicator"])
    tol = settings.reference_indicators
    # the reference sits on the CV axis
    assert tab.loc["ref", "bias_pct"] == pytest.approx(0.0, abs=1e-9)
    # louder: RMS and 1x amplitude 10 % up, 20 log10(1.1) = 0.828 dB; composite = weights (rescaled without TE)
    # x Bias / TEa, each TEa in dB
    db = 20.0 * math.log10(1.10)
    for key in ("input_bearing_rms", "input_bearing_mesh1x"):
        assert ind.loc[("louder", key), "bias"] == pytest.approx(db, rel=1e-6)
        assert ind.loc[("louder", key), "unit"] == "dB"
    no_te = 1.0 - tol.transmission_error.weight
    expect = (tol.input_bearing_rms.weight * db / tol.input_bearing_rms.tea_db
              + tol.input_bearing_mesh1x.weight * db / tol.input_bearing_mesh1x.tea_db) / no_te * 100.0
    assert tab.loc["louder", "bias_pct"] == pytest.approx(expect, rel=1e-6)
    # heavier: only the mean outer mesh force moves (ripple, K_gamma, K_v are ratios and do not)
    assert ind.loc[("heavier", "outer_mesh_force"), "bias"] == pytest.approx(2.0, rel=1e-9)
    for key in ("outer_mesh_ripple", "load_sharing", "dynamic_factor"):
        assert ind.loc[("heavier", key), "bias"] == pytest.approx(0.0, abs=1e-9)
    expect = tol.outer_mesh_force.weight * 2.0 / tol.outer_mesh_force.tea_pct / no_te * 100.0
    assert tab.loc["heavier", "bias_pct"] == pytest.approx(expect, rel=1e-6)
    # noisier: TE present in both, loaded TE 2.2 um against 2.0 um: 10 % of the static TE off
    assert ind.loc[("noisier", "transmission_error"), "bias"] == pytest.approx(10.0, rel=1e-3)
    expect = tol.transmission_error.weight * 10.0 / tol.transmission_error.tea_pct * 100.0
    assert tab.loc["noisier", "bias_pct"] == pytest.approx(expect, rel=1e-3)
    assert ("louder", "transmission_error") not in ind.index
    # per purpose, each indicator alone (equal CPU times: the first by name among the acceptable): heavier fails
    # the mean loads by its 2 % outer force (TEa 1 %); louder and heavier have no TE signal, which the reference
    # has, so only noisier can be judged acceptable for the transmission error and for every purpose
    assert {v.purpose: v.selected for v in s.verdicts} == {
        "mean_loads": "louder", "tooth_loads": "heavier", "vibration": "heavier", "transmission_error": "noisier",
        "all purposes": "noisier"}
    assert s.selection.variant == "noisier"
    assert "heavier: outer (sun-planet) mesh force 2 % off" in s.selection.reasoning
    assert s.lines.tea_pct == pytest.approx(100.0) and s.lines.normalised


def test_missing_reference_is_a_one_line_error(settings):
    with pytest.raises(ValueError, match="reference 'model9' is not among the runs"):
        screen([synthetic_result("a")], settings, reference="model9")


def _decaying(tau: float, rel: float):
    """Clean stationary run (mesh-frequency ripple, whole cycles per block) whose output speed decays
    as A (1 + rel e^(-(t - t_ramp)/tau)) after the ramp."""
    res = synthetic_result("decay")
    s, th = res.signals, res.meta["theory"]
    t, f = s["time_s"].to_numpy(), th["mesh_frequency_hz"]
    for kind in ("outer", "inner"):
        for i, off in enumerate(np.linspace(-4.0, 4.0, 5)):
            s[f"{kind}_mesh_force_{i + 1}_n"] = th["mesh_force_n"] + off + 5.0 * np.sin(2 * np.pi * f * t)
    for key, col in (("input_speed_rad_per_s", "input_speed_rad_per_s"), ("ratio", "transmission_ratio")):
        s[col] = th[key]
    a = th["output_speed_rad_per_s"]
    s["output_speed_rad_per_s"] = a * (1.0 + rel * np.exp(-np.clip(t - 0.5, 0.0, None) / tau))
    return res


def test_settling_time_of_an_exponential_decay(settings):
    tau, rel = 0.01, 0.01
    res = _decaying(tau, rel)
    f = res.meta["theory"]["mesh_frequency_hz"]
    block = settings.settle_block_mesh_cycles / f
    tol = settings.settle_mean_tolerance_pct / 100.0
    test = settled_start(res.signals, 0.5, f, dataclasses.replace(SettleRule.from_settings(settings), min_blocks=1))
    start, why = test.start_s, test.reason
    # a group's mean deviation is rel e^(-t_k/tau) (tau/W)(1 - e^(-W/tau)), W = final_blocks blocks; final ~ A
    group = settings.settle_final_blocks * block
    t_star = 0.5 + tau * math.log(rel * (tau / group) * (1 - math.exp(-group / tau)) / tol)
    assert start is not None and "output_speed" in why
    assert t_star - 1e-9 <= start <= t_star + block + 1e-9
    # the same through the screening settings: a settled (steady) window from there to the end
    w = analysis_window(res.meta, 0.4, float(res.signals["time_s"].iloc[-1]),
                        dataclasses.replace(settings, window="settled"), res.signals)
    assert w.steady and w.start_s == pytest.approx(start)


def test_a_run_still_drifting_at_its_end_is_not_steady(settings):
    res = _decaying(0.2, 0.05)          # tau = 0.2 s in a 0.1 s window: far from settled
    w = analysis_window(res.meta, 0.4, float(res.signals["time_s"].iloc[-1]),
                        dataclasses.replace(settings, window="settled"), res.signals)
    assert not w.steady and "not settled" in w.rule and "output_speed" in w.rule


def test_an_unsettled_reference_is_refused_with_its_signal_and_the_time_needed(settings):
    """The reference still drifts (tau = 0.2 s in a 0.1 s window): the screening refuses it in one line naming the
    reference, the signal that still moves and the time the settling test estimates it needs."""
    ref = _decaying(0.2, 0.05)
    ref.meta["variant"] = "decay"
    settled = dataclasses.replace(settings, window="settled")
    with pytest.raises(UnsettledReference) as err:
        screen([ref, synthetic_result("other")], settled, reference="decay")
    text = str(err.value)
    assert "\n" not in text and "reference decay" in text and "output_speed" in text and "s needed" in text
    # the estimate: the group mean's change decays by e^(-group/tau) a group; needed when it falls below the tolerance
    needed = float(text.split("about ")[1].split(" s needed")[0])
    assert needed > float(ref.signals["time_s"].iloc[-1])


def test_unsettled_variants_are_marked_not_scored(settings):
    """A variant that has not settled is 'unsettled', gets no Westgard point and is not a candidate."""
    ref = _decaying(0.01, 0.0)          # clean and stationary
    ref.meta["variant"] = "ref"
    late = _decaying(0.2, 0.05)
    late.meta["variant"] = "late"
    s = screen([ref, late], dataclasses.replace(settings, window="settled"), reference="ref")
    row = s.table.set_index("variant").loc["late"]
    assert row["status"] == "unsettled" and "not settled" in row["reason"] and math.isnan(row["distance_pct"])
    assert s.selection.variant == "ref"


def test_a_near_zero_quantity_does_not_make_a_variant_non_conforming(settings):
    """Ripple 0.3 % of the mean load in the reference, 0.7 % in the variant: a relative error of 133 %, but 0.4 %
    of the tooth load, a fifth of its TEa (2 % of load): the variant stays acceptable on that indicator."""
    ref, other = synthetic_result("ref"), synthetic_result("other")
    for res, ripple in ((ref, 0.003), (other, 0.007)):
        s, th = res.signals, res.meta["theory"]
        t, f = s["time_s"].to_numpy(), th["mesh_frequency_hz"]
        for kind in ("outer", "inner"):
            for i in range(1, 6):
                wave = ripple * math.sqrt(2) * np.sin(2 * np.pi * f * t)
                s[f"{kind}_mesh_force_{i}_n"] = th["mesh_force_n"] * (1 + wave)
    scr = screen([ref, other], settings, reference="ref")
    ind = scr.indicators.set_index(["variant", "indicator"])
    assert ind.loc[("other", "outer_mesh_ripple"), "bias"] == pytest.approx(0.4, rel=0.02)
    assert ind.loc[("other", "outer_mesh_ripple"), "zone"] != "non-conforming"


def _scaled_forces(res, factor: float, kinds=("outer",)):
    for kind in kinds:
        cols = [c for c in res.signals.columns if c.startswith(f"{kind}_mesh_force_")]
        res.signals[cols] *= factor
    return res


def test_a_verdict_within_the_numerical_error_is_not_resolved(settings):
    """The reference's window at h/2 has its mean outer mesh force x higher than at h: the outer force's numerical
    error is 100 x % of the force. A faster variant whose outer force sits y = 0.99 TEa above the reference's meets
    the acceptable line on its own (Bias 0.99 % against TEa 1 %), so it is selected, but its acceptability changes
    within Bias -/+ error: the verdict is "not resolved". Without the error it is resolved."""
    tol = settings.reference_indicators
    y = 0.99 * tol.outer_mesh_force.tea_pct / 100.0
    x = 0.05 * tol.outer_mesh_force.tea_pct / 100.0

    def runs(error: float):
        ref = _decaying(0.01, 0.0)
        ref.meta.update(variant="ref", wall_time_s=100.0, cpu_time_s=100.0)
        window = ref.signals[ref.signals["time_s"] >= 0.55].reset_index(drop=True)
        ref.extra.update(error_step=window.copy(), error_half_step=_scaled_forces(
            type(ref)(ref.meta, window.copy()), 1.0 + error).signals)
        near = _scaled_forces(_decaying(0.01, 0.0), 1.0 + y)
        near.meta.update(variant="near", wall_time_s=10.0, cpu_time_s=10.0)
        return [ref, near]

    s = screen(runs(x), settings, reference="ref")
    tab = s.table.set_index("variant")
    ind = s.indicators.set_index(["variant", "indicator"])
    assert ind.loc[("near", "outer_mesh_force"), "bias"] == pytest.approx(100.0 * y, rel=1e-6)
    assert s.selection.variant == "near" and not s.selection.resolved and not tab.loc["near", "resolved"]
    mean_loads = next(v for v in s.verdicts if v.purpose == "mean_loads")
    assert mean_loads.deciding_indicator == "outer_mesh_force" and not mean_loads.resolved
    assert mean_loads.error == pytest.approx(100.0 * x, rel=1e-6)
    assert mean_loads.reasoning.startswith("NOT RESOLVED")
    clean = screen(runs(0.0), settings, reference="ref")
    assert clean.selection.variant == "near" and clean.selection.resolved


def test_a_failed_reference_is_refused_and_the_matrix_writes_why(settings, tmp_path):
    """A reference that did not finish: screen() refuses in one line naming it and its reason; the matrix's
    screening writes that line to selection.txt and selects nothing, instead of stopping."""
    from flexgear.results import RunResult, save_result
    from flexgear.study.matrix import screen_directory
    from flexgear.study.screening import ReferenceNotUsable

    failed = RunResult({"variant": "model7", "backend": "exudyn", "status": "failed", "reason": "solver failed"})
    other = synthetic_result("model1")
    with pytest.raises(ReferenceNotUsable, match="reference model7 did not finish \\(solver failed\\)"):
        screen([other, failed], settings, reference="model7")
    for r in (other, failed):
        save_result(r, tmp_path / r.name)
    table = screen_directory(tmp_path, ["model1", "model7"], settings, reference="model7")
    text = (tmp_path / "selection.txt").read_text()
    assert text.startswith("selected: None") and "did not finish" in text
    assert set(table["status"]) == {"not screened"}


def test_a_bearing_level_at_the_noise_floor_settles(settings):
    """A bearing whose acceleration is round-off (the rigid stage with in-phase planets: 1e-8 to 1e-6 m/s^2, its
    RMS changing by tens of percent from block to block) settles: it may move by the configured floor, 1e-3 m/s^2;
    with no floor the relative tolerance never holds and names it."""
    res = synthetic_result("m")
    rng = np.random.default_rng(7)
    f = res.meta["theory"]["mesh_frequency_hz"]
    t = res.signals["time_s"].to_numpy()
    level = 1e-7 * np.exp(rng.standard_normal(len(t) // 50 + 1))[np.arange(len(t)) // 50]  # wanders, factor ~e
    for axis in ("x", "y"):
        res.signals[f"output_bearing_accel_{axis}_m_per_s2"] = level * rng.standard_normal(len(t))
    rule = dataclasses.replace(SettleRule.from_settings(settings), min_blocks=1)
    assert rule.acceleration_floor == pytest.approx(1e-3)
    assert settled_start(res.signals, 0.5, f, rule).start_s is not None
    bare = settled_start(res.signals, 0.5, f, dataclasses.replace(rule, acceleration_floor=0.0))
    assert bare.start_s is None and "output_bearing_rms" in bare.reason
