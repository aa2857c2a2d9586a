"""Reference screening (dynamic indicators, Bias against a reference variant) and the settled window,
on synthetic signals whose differences and decay are known by construction."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from synthetic import GEARBOX, synthetic_result

from flexgear.spec import load_gearbox
from flexgear.study.indicators import settled_start
from flexgear.study.screening import analysis_window, screen


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
    # louder: RMS and 1x amplitude 10 % off; composite = weights (rescaled without TE) x Bias / TEa
    for key in ("input_bearing_rms", "input_bearing_mesh1x"):
        assert ind.loc[("louder", key), "bias_pct"] == pytest.approx(10.0, rel=1e-6)
    no_te = 1.0 - tol.transmission_error.weight
    expect = (tol.input_bearing_rms.weight * 10.0 / tol.input_bearing_rms.tea_pct
              + tol.input_bearing_mesh1x.weight * 10.0 / tol.input_bearing_mesh1x.tea_pct) / no_te * 100.0
    assert tab.loc["louder", "bias_pct"] == pytest.approx(expect, rel=1e-6)
    # heavier: only the mean outer mesh force moves (ripple, K_gamma, K_v are ratios and do not)
    assert ind.loc[("heavier", "outer_mesh_force"), "bias_pct"] == pytest.approx(2.0, rel=1e-9)
    for key in ("outer_mesh_ripple", "load_sharing", "dynamic_factor"):
        assert ind.loc[("heavier", key), "bias_pct"] == pytest.approx(0.0, abs=1e-9)
    expect = tol.outer_mesh_force.weight * 2.0 / tol.outer_mesh_force.tea_pct / no_te * 100.0
    assert tab.loc["heavier", "bias_pct"] == pytest.approx(expect, rel=1e-6)
    # noisier: TE present in both, 10 % larger loaded TE, full weights
    assert ind.loc[("noisier", "transmission_error"), "bias_pct"] == pytest.approx(10.0, rel=1e-3)
    expect = tol.transmission_error.weight * 10.0 / tol.transmission_error.tea_pct * 100.0
    assert tab.loc["noisier", "bias_pct"] == pytest.approx(expect, rel=1e-3)
    assert ("louder", "transmission_error") not in ind.index
    # the distances order the variants; the reasoning names the reference and each one's largest term
    assert "Against reference ref" in s.selection.reasoning
    assert "louder at distance" in s.selection.reasoning
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
    for key, col in (("input_speed_deg_per_s", "input_speed_deg_per_s"), ("ratio", "transmission_ratio")):
        s[col] = th[key]
    a = th["output_speed_deg_per_s"]
    s["output_speed_deg_per_s"] = a * (1.0 + rel * np.exp(-np.clip(t - 0.5, 0.0, None) / tau))
    return res


def test_settling_time_of_an_exponential_decay(settings):
    tau, rel = 0.01, 0.01
    res = _decaying(tau, rel)
    f = res.meta["theory"]["mesh_frequency_hz"]
    block = settings.settle_block_mesh_cycles / f
    tol = settings.settle_mean_tolerance_pct / 100.0
    start, why = settled_start(res.signals, 0.5, f, settings.settle_block_mesh_cycles, settings.settle_final_blocks,
                               settings.settle_mean_tolerance_pct, settings.settle_amplitude_tolerance_pct)
    # a block's mean deviation is rel e^(-t_k/tau) (tau/h)(1 - e^(-h/tau)); final value ~ A (e^-10 left)
    t_star = 0.5 + tau * math.log(rel * (tau / block) * (1 - math.exp(-block / tau)) / tol)
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
