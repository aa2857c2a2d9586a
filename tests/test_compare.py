"""Tables 6 and 7 and the spectrum helpers on synthetic signals with known values."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from flexgear.results import RunResult, signal_columns
from flexgear.study.compare import amplitude_spectrum, compare_results, harmonic_amplitudes

F_MESH = 4400.0
DT = 1e-5


def synthetic(name: str, backend: str, amps_in: dict[int, float], amps_out: dict[int, float], force: float,
              t_end: float = 0.6, ramp: float = 0.5, n: int = 5) -> RunResult:
    t = np.arange(int(round(t_end / DT)) + 1) * DT
    df = pd.DataFrame(0.0, index=np.arange(t.size), columns=signal_columns(n))
    df["time_s"] = t
    df["input_speed_rad_per_s"] = np.radians(36000.0)
    df["output_speed_rad_per_s"] = np.radians(-11647.0588)
    df["transmission_ratio"] = -11647.0588 / 36000.0
    for i in range(1, n + 1):
        df[f"outer_mesh_force_{i}_n"] = force + 5.0 * np.sin(2 * np.pi * F_MESH * t + i)
        df[f"inner_mesh_force_{i}_n"] = force - 1.0
    for side, amps in (("input", amps_in), ("output", amps_out)):
        ax = sum(a * np.cos(2 * np.pi * k * F_MESH * t + 0.3 * k) for k, a in amps.items())
        ay = sum(a * np.sin(2 * np.pi * k * F_MESH * t + 0.3 * k) for k, a in amps.items())
        df[f"{side}_bearing_accel_x_m_per_s2"] = ax
        df[f"{side}_bearing_accel_y_m_per_s2"] = ay
    meta = {"variant": name, "backend": backend, "status": "ok", "ramp_time_s": ramp, "t_end_s": t_end,
            "theory": {"input_speed_rad_per_s": np.radians(36000.0), "output_speed_rad_per_s": np.radians(-11647.0588),
                       "mesh_force_n": 798.21, "mesh_frequency_hz": F_MESH}}
    return RunResult(meta, df)


def test_amplitude_spectrum_recovers_sine():
    t = np.arange(10000) * DT
    x = 0.7 * np.sin(2 * np.pi * 1000 * t) + 0.05 * np.cos(2 * np.pi * 8000 * t)
    f, a = amplitude_spectrum(x, DT)
    assert a[np.argmin(abs(f - 1000))] == pytest.approx(0.7, rel=1e-6)
    assert a[np.argmin(abs(f - 8000))] == pytest.approx(0.05, rel=1e-6)


def test_harmonic_amplitudes_off_bin():
    """A harmonic between bins keeps its amplitude (no scalloping loss)."""
    t = np.arange(10001) * DT  # 10001 samples: 9 x f_mesh falls 0.4 bin off the grid
    x = 0.02 * np.sin(2 * np.pi * 9 * F_MESH * t) + 0.1 * np.sin(2 * np.pi * F_MESH * t)
    np.testing.assert_allclose(harmonic_amplitudes(x, DT, F_MESH, (1, 9)), [0.1, 0.02], rtol=2e-3)


def test_tables_6_and_7_from_known_signals():
    amps_a = {1: 0.055, 2: 0.002, 4: 0.0126, 6: 0.0094, 9: 0.0017}
    amps_a_out = {1: 0.059, 4: 0.0014, 6: 0.0015, 9: 0.0013}
    amps_b = {1: 0.0621, 2: 0.0033, 4: 0.004, 6: 0.0007, 9: 0.0013}
    amps_b_out = {1: 0.086, 2: 0.0105, 4: 0.0135, 6: 0.0047, 9: 0.001}
    a = synthetic("model4", "exudyn", amps_a, amps_a_out, 800.7533)
    b = synthetic("lumped", "lumped", amps_b, amps_b_out, 798.1762)
    t6, t7 = compare_results(a, b)
    assert list(t6.columns) == ["theory", "model4", "lumped"]
    assert t6.loc["input_speed_deg_per_s", "model4"] == pytest.approx(36000.0)
    assert t6.loc["outer_mesh_force_n", "model4"] == pytest.approx(800.7533, abs=1e-3)
    assert t6.loc["inner_mesh_force_n", "lumped"] == pytest.approx(797.1762, abs=1e-9)
    assert t6.loc["outer_mesh_force_n", "theory"] == pytest.approx(798.21)
    # each harmonic is a circular whirl (x, y in quadrature): radial magnitude peaks at <= sum of amplitudes
    assert t6.loc["input_bearing_peak_accel_m_per_s2", "model4"] <= sum(amps_a.values()) + 1e-12
    assert t6.loc["input_bearing_peak_accel_m_per_s2", "model4"] > 0.9 * sum(amps_a.values())
    assert np.isnan(t6.loc["input_bearing_peak_accel_m_per_s2", "theory"])
    for (run, side), amps in {("model4", "input"): amps_a, ("model4", "output"): amps_a_out,
                              ("lumped", "input"): amps_b, ("lumped", "output"): amps_b_out}.items():
        expected = [amps.get(k, 0.0) for k in (1, 2, 4, 6, 9)]
        np.testing.assert_allclose(t7[(run, side)].to_numpy(), expected, atol=2e-5)
    assert t7.attrs["window_s"] == pytest.approx((0.5, 0.6))


def test_same_names_are_told_apart_and_window_is_checked():
    a = synthetic("x", "exudyn", {1: 0.1}, {1: 0.1}, 800.0, t_end=0.02, ramp=0.5)
    b = synthetic("x", "lumped", {1: 0.2}, {1: 0.2}, 800.0, t_end=0.02, ramp=0.5)
    t6, t7 = compare_results(a, b)
    assert list(t6.columns) == ["theory", "x (exudyn)", "x (lumped)"]
    assert t6.attrs["window_s"] == pytest.approx((0.01, 0.02))  # ramp not reached: last half
    assert t7[("x (lumped)", "input")].loc[1] == pytest.approx(0.2, rel=1e-2)
    with pytest.raises(ValueError, match="axis"):
        compare_results(a, b, axis="z")
    failed = RunResult({"variant": "bad", "status": "failed"}, None)
    with pytest.raises(ValueError, match="no signals"):
        compare_results(a, failed)
