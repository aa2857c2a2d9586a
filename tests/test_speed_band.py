"""The acceptable speed band of a purpose's selected variant (flexgear.study.speed_screening.acceptable_band,
speed_bands).

Synthetic speed-screening tables (no simulation) whose differences are known functions of the speed:

- piecewise linear with knots at grid speeds: the linear interpolation between grid speeds is exact, so the band's
  limits are the analytic crossings |d| = TEa (d = 0.0024 dB/rpm (n - 6000 rpm) crosses 3 dB at 4750 and 7250 rpm);
- convex (d = 3 dB ((n - 6000 rpm) / 1300 rpm)^2, crossing 3 dB at 4700 and 7300 rpm): the chord between two grid
  speeds lies above the curve, so the interpolated crossing is the chord's, between the last grid speed within and
  the analytic crossing (on the safe side);
- within TEa everywhere, beyond TEa at the operating speed, a single resonance beyond TEa (the band stops at it).

Through the real screening (flexgear.study.speed_screening.speed_screening, rigid model 1 under the ISO 6336 law):
the same model with all its damping scaled by 0.1 answers up to 1 / 0.1 = 20 dB louder at a resonance and hardly
differs away from one; from an operating speed below the resonance the band of the dynamic factor ends between the
operating speed and the reference's K_v peak, where the light variant is beyond TEa; a variant against itself is
within TEa over the whole grid.
"""

import dataclasses
import json
import math

import numpy as np
import pandas as pd
import pytest

from flexgear.study.speed_screening import BAND_COLUMNS, SPEED_INDICATORS, acceptable_band, speed_bands, speed_screening

GRID = np.arange(3000.0, 9001.0, 500.0)
TEA = {"dynamic_factor": 2.0, "input_bearing_rms": 3.0, "output_bearing_rms": 3.0, "input_bearing_mesh1x": 3.0,
       "output_bearing_mesh1x": 3.0}
UNIT = {key: ("% of load" if scale == "load" else "dB") for key, scale in SPEED_INDICATORS.items()}
VIBRATION = ["input_bearing_rms", "output_bearing_rms", "input_bearing_mesh1x", "output_bearing_mesh1x"]


def _table(curves: dict[str, dict[str, object]], grid: np.ndarray = GRID) -> pd.DataFrame:
    """A speed-screening table: per variant, the difference of each indicator (a function of the speed [rpm] or an
    array over ``grid``; 0 when not given), with the reference model7 (all zero)."""
    rows = []
    for variant, given in {"model7": {}, **curves}.items():
        for key in SPEED_INDICATORS:
            f = given.get(key, 0.0)
            d = np.asarray(f(grid) if callable(f) else np.broadcast_to(f, grid.shape), float)
            rows.append(pd.DataFrame({"variant": variant, "speed_rpm": grid, "indicator": key, "value": 1.0,
                                      "reference_value": 1.0, "difference": d, "unit": UNIT[key], "tea": TEA[key],
                                      "exceeds": np.abs(d) > TEA[key]}))
    return pd.concat(rows, ignore_index=True)


def _rms_slope(n):
    return 0.0024 * (n - 6000.0)  # dB: +-3 dB at 6000 +- 1250 rpm


def _kv_below(n):
    return 0.0025 * np.maximum(6000.0 - n, 0.0)  # % of load: 2 % at 5200 rpm, a knot at the grid speed 6000


def test_linear_crossings_are_the_analytic_ones():
    table = _table({"model6": {"input_bearing_rms": _rms_slope, "dynamic_factor": _kv_below}})
    band = acceptable_band(table, "model6", ["dynamic_factor", *VIBRATION], 6000.0)
    assert band.status == "band"
    assert band.low_rpm == pytest.approx(5200.0, abs=1e-9)  # the dynamic factor's crossing comes first below
    assert band.high_rpm == pytest.approx(7250.0, abs=1e-9)
    assert (band.low_indicator, band.high_indicator) == ("dynamic_factor", "input_bearing_rms")
    assert band.low_bracket_rpm == (5000.0, 5500.0) and band.high_bracket_rpm == (7000.0, 7500.0)
    assert not band.low_is_grid_end and not band.high_is_grid_end
    assert (band.grid_low_rpm, band.grid_high_rpm, band.operating_rpm) == (3000.0, 9000.0, 6000.0)
    assert "5200 rpm (dynamic_factor crosses TEa between 5000 and 5500 rpm)" in band.text
    assert "7250 rpm (input_bearing_rms crosses TEa between 7000 and 7500 rpm)" in band.text
    vibration = acceptable_band(table, "model6", VIBRATION, 6000.0)  # the dynamic factor not judged
    assert (vibration.low_rpm, vibration.high_rpm) == (pytest.approx(4750.0), pytest.approx(7250.0))


def test_operating_speed_between_grid_speeds():
    table = _table({"model6": {"input_bearing_rms": _rms_slope}})
    band = acceptable_band(table, "model6", VIBRATION, 6100.0)
    assert band.operating_rpm == 6100.0
    assert (band.low_rpm, band.high_rpm) == (pytest.approx(4750.0), pytest.approx(7250.0))


def test_convex_difference_gives_the_chord_crossing():
    def d(n):
        return 3.0 * ((n - 6000.0) / 1300.0) ** 2

    band = acceptable_band(_table({"model6": {"output_bearing_rms": d}}), "model6", VIBRATION, 6000.0)
    d_in, d_out = d(7000.0), d(7500.0)
    chord = 7000.0 + 500.0 * (3.0 - d_in) / (d_out - d_in)
    assert band.high_rpm == pytest.approx(chord, rel=1e-12)
    assert band.low_rpm == pytest.approx(12000.0 - chord, rel=1e-12)  # the curve is symmetric about 6000 rpm
    assert 7000.0 < band.high_rpm < 7300.0  # between the last grid speed within and the analytic crossing


def test_within_tea_on_the_whole_grid():
    table = _table({"model6": {key: lambda n: 0.9 * TEA["input_bearing_rms"] * np.sin(n / 700.0)
                               for key in VIBRATION}})
    band = acceptable_band(table, "model6", VIBRATION, 6000.0)
    assert band.status == "whole grid"
    assert (band.low_rpm, band.high_rpm) == (3000.0, 9000.0)
    assert band.low_is_grid_end and band.high_is_grid_end
    assert "within TEa over the whole grid, at least 3000-9000 rpm" in band.text


def test_one_side_reaches_the_grid_end():
    table = _table({"model6": {"input_bearing_mesh1x": lambda n: _rms_slope(np.maximum(n, 6000.0))}})
    band = acceptable_band(table, "model6", VIBRATION, 6000.0)
    assert band.low_is_grid_end and not band.high_is_grid_end
    assert (band.low_rpm, band.high_rpm) == (3000.0, pytest.approx(7250.0))
    assert "from 3000 rpm or lower (grid end) to 7250 rpm" in band.text


def test_beyond_tea_at_the_operating_speed_gives_no_band():
    table = _table({"model1": {"output_bearing_mesh1x": lambda n: -4.5 + 0.0 * n}})
    band = acceptable_band(table, "model1", VIBRATION, 6000.0)
    assert band.status == "fails"
    assert math.isnan(band.low_rpm) and math.isnan(band.high_rpm)
    assert "beyond TEa at the operating speed 6000 rpm (output_bearing_mesh1x -4.50 dB, TEa 3 dB)" in band.text


def test_the_band_stops_at_a_resonance_and_tea_itself_is_within():
    resonance = np.where(GRID == 7500.0, 6.0, 0.0)  # 6 dB at 7500 rpm only, within on both sides of it
    band = acceptable_band(_table({"model6": {"input_bearing_rms": resonance}}), "model6", VIBRATION, 6000.0)
    assert band.high_rpm == pytest.approx(7000.0 + 500.0 * 3.0 / 6.0)
    assert band.low_is_grid_end and not band.high_is_grid_end
    at_tea = np.where(GRID >= 7000.0, 3.0 + 6.0 * (GRID - 7000.0) / 500.0, 0.0)  # exactly 3 dB at 7000 rpm
    band = acceptable_band(_table({"model6": {"input_bearing_rms": at_tea}}), "model6", VIBRATION, 6000.0)
    assert band.high_rpm == 7000.0


def test_operating_speed_outside_the_grid():
    band = acceptable_band(_table({"model6": {}}), "model6", VIBRATION, 10000.0)
    assert band.status == "off grid" and math.isnan(band.low_rpm)


def _results_folder(path, reference: str = "model7"):
    """A results folder with a verdict against model7 and a synthetic speed screening."""
    table = _table({"model6": {"input_bearing_rms": _rms_slope}, "model1": {"dynamic_factor": _kv_below}})
    table.to_csv(path / "speed_screening.csv", index=False)
    (path / "screening.json").write_text(json.dumps({"reference": reference}))
    verdict = pd.DataFrame({
        "purpose": ["mean_loads", "tooth_loads", "vibration", "all purposes"],
        "selected": ["model1", "model1", "model6", ""],
        "indicators": ["input_speed output_speed", "dynamic_factor load_sharing outer_mesh_ripple",
                       " ".join(VIBRATION), "input_speed dynamic_factor " + " ".join(VIBRATION)]})
    verdict.to_csv(path / "verdict.csv", index=False)
    for name in ("model1", "model6"):
        (path / name).mkdir()
        (path / name / "run.json").write_text(json.dumps({"spec": {"load_case": {"input_speed_rpm": 6000.0}}}))


def test_speed_bands_of_a_results_folder(tmp_path):
    _results_folder(tmp_path)
    bands = speed_bands(tmp_path)
    written = pd.read_csv(tmp_path / "speed_bands.csv", keep_default_na=False)
    assert list(written.columns) == ["purpose", "selected", "indicators", "low_rpm", "high_rpm", "operating_rpm",
                                     "grid_low_rpm", "grid_high_rpm", "text"] == list(BAND_COLUMNS)
    assert list(bands.purpose) == ["tooth_loads", "vibration", "all purposes"]  # mean_loads: no such indicator
    rows = bands.set_index("purpose")
    assert rows.loc["tooth_loads", "indicators"] == "dynamic_factor"
    assert (rows.loc["tooth_loads", "low_rpm"], rows.loc["tooth_loads", "high_rpm"]) == (pytest.approx(5200.0), 9000.0)
    assert rows.loc["vibration", "indicators"] == " ".join(VIBRATION)
    assert (rows.loc["vibration", "low_rpm"], rows.loc["vibration", "high_rpm"]) == (pytest.approx(4750.0),
                                                                                   pytest.approx(7250.0))
    assert (rows.loc["vibration", "operating_rpm"], rows.loc["vibration", "grid_low_rpm"],
            rows.loc["vibration", "grid_high_rpm"]) == (6000.0, 3000.0, 9000.0)
    assert math.isnan(rows.loc["all purposes", "low_rpm"])
    assert rows.loc["all purposes", "text"] == "no variant selected: no band"


def test_speed_bands_need_a_verdict_against_the_same_reference(tmp_path):
    _results_folder(tmp_path, reference="")
    assert speed_bands(tmp_path) is None and not (tmp_path / "speed_bands.csv").exists()
    other = tmp_path / "other"
    other.mkdir()
    _results_folder(other, reference="model6")  # model6 differs from model7 in the speed screening
    with pytest.raises(ValueError, match="another reference"):
        speed_bands(other)


def test_real_screening_band_ends_before_the_resonance(model1):
    from test_harmonic_speed import _lightly_damped

    spec = model1.gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    spec = spec.with_fields("contact_assumed", stiffness_variation="contact_lines")
    base = dataclasses.replace(model1, gearbox=spec, name="base")
    same = dataclasses.replace(base, name="same")
    light = dataclasses.replace(_lightly_damped(base, 0.1), name="light")
    grid = np.arange(4000.0, 7001.0, 100.0)
    screening = speed_screening([base, same, light], grid, reference="base", harmonics=3)
    table = screening.table
    kv = table[(table.variant == "light") & (table.indicator == "dynamic_factor")].set_index("speed_rpm")
    operating = 4500.0
    light_kv = kv.value[kv.index >= operating].to_numpy()
    first = int(np.flatnonzero((light_kv[1:-1] > light_kv[:-2]) & (light_kv[1:-1] >= light_kv[2:]))[0]) + 1
    peak = float(kv.index[kv.index >= operating][first])  # the first resonance of the light variant above it
    assert kv.exceeds[peak]  # less damping: beyond TEa at the resonance
    band = acceptable_band(table, "light", ["dynamic_factor"], operating)
    assert band.status == "band" and operating < band.high_rpm < peak
    inside = kv.loc[(kv.index >= operating) & (kv.index <= band.high_rpm)]
    assert not inside.exceeds.any() and kv.exceeds[band.high_bracket_rpm[1]]
    assert acceptable_band(table, "same", ["dynamic_factor", *VIBRATION], operating).status == "whole grid"
