"""Westgard screening arithmetic against synthetic signals of known bias and CV (section 2.2)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest
from synthetic import GEARBOX, failed_result, synthetic_result

from flexgear.spec import SpecError, load_gearbox
from flexgear.study.screening import (
    DecisionLines,
    Window,
    analysis_window,
    sample_means,
    screen_result,
    screening_tables,
    select_variant,
    sigma_metric,
)


@pytest.fixture(scope="module")
def settings():
    # the synthetic signals step between segments by construction (that is their CV): they never
    # "settle", so the arithmetic tests use the study's window, from the end of the ramps
    return dataclasses.replace(load_gearbox(GEARBOX).screening, window="after_ramps")


def test_known_bias_and_cv_per_indicator_and_composite(settings):
    bias = {"input_speed": 0.0, "output_speed": -0.002, "transmission_ratio": 0.001,
            "outer_mesh_force": 0.004, "inner_mesh_force": -0.003}
    cv = {"input_speed": 0.0, "output_speed": 0.001, "transmission_ratio": 0.0005,
          "outer_mesh_force": 0.002, "inner_mesh_force": 0.003}
    s = screen_result(synthetic_result("synth", bias, cv), settings)
    assert s.window.steady and s.window.start_s == pytest.approx(0.5)
    for key, r in s.indicators.items():
        assert r.bias == pytest.approx(100 * abs(bias[key]), abs=1e-9)
        assert r.cv == pytest.approx(100 * cv[key] / abs(1 + bias[key]), rel=1e-9, abs=1e-12)
        assert len(r.samples) == settings.sample_count
    # composite point: 20 % of each indicator (section 2.2), distance from the origin
    exp_bias = 0.2 * sum(100 * abs(b) for b in bias.values())
    exp_cv = 0.2 * sum(100 * cv[k] / abs(1 + bias[k]) for k in cv)
    assert s.bias_pct == pytest.approx(exp_bias, rel=1e-9)
    assert s.cv_pct == pytest.approx(exp_cv, rel=1e-9)
    assert s.distance_pct == pytest.approx(math.hypot(exp_bias, exp_cv), rel=1e-9)
    assert s.sigma == pytest.approx((settings.allowable_total_error_pct - exp_bias) / exp_cv, rel=1e-9)


def test_mesh_force_is_the_mean_over_planets(settings):
    # each planet is offset by -4..+4 N (zero mean): the indicator sees the planet mean only
    s = screen_result(synthetic_result("synth"), settings)
    for key in ("outer_mesh_force", "inner_mesh_force"):
        r = s.indicators[key]
        assert r.bias == pytest.approx(0.0, abs=1e-9)
        assert r.mean == pytest.approx(r.theory, rel=1e-12)


def test_points_exactly_on_each_line_get_the_better_zone():
    tea, cv = 10.0, 1.5
    lines = DecisionLines(tea, (2, 3, 4))
    assert lines.zone_names == ("non-conforming", "critical", "good", "excellent")
    for m, zone in ((2, "critical"), (3, "good"), (4, "excellent")):
        bias = tea - m * cv
        assert lines.zone(bias, cv) == zone
        assert sigma_metric(bias, cv, tea) == pytest.approx(m)
        assert lines.zone(bias + 1e-6, cv) == lines.zone_names[m - 2]   # just above the line: worse zone
    assert lines.zone(tea + 0.1, 0.0) == "non-conforming"
    assert lines.zone(0.0, 0.0) == "excellent"
    six = DecisionLines(tea, (2, 3, 4, 5, 6))
    assert len(six.zone_names) == 6
    assert six.zone(tea - 6 * cv, cv) == "world-class"
    assert six.zone(tea - 5 * cv, cv) == "excellent"
    # the line in the study's axes: CV on y at Bias on x
    assert lines.cv_on_line(3, tea - 3 * cv) == pytest.approx(cv)


def test_sigma_metric_edge_cases():
    assert sigma_metric(0.5, 0.0, 1.0) == math.inf
    assert sigma_metric(2.0, 0.0, 1.0) == -math.inf
    assert sigma_metric(0.4, 0.2, 1.0) == pytest.approx(3.0)


def _study_table() -> pd.DataFrame:
    """Fig. 2 / Table 4 of the study: zones as the study reports them, ADAMS times."""
    zones = {1: 1, 2: 1, 3: 1, 4: 3, 5: 1, 6: 3, 7: 3}
    times = {1: 371, 2: 17948, 3: 507, 4: 34903, 5: 11745, 6: 35662, 7: 42955}
    dist = {1: 0.5, 2: 0.45, 3: 0.48, 4: 0.12, 5: 0.44, 6: 0.11, 7: 0.05}
    return pd.DataFrame({"variant": [f"model{i}" for i in zones], "status": "ok",
                         "zone_rank": list(zones.values()), "zone": ["x"] * 7,
                         "time_s": [float(v) for v in times.values()], "distance_pct": list(dist.values())})


def test_selection_rules_on_the_studys_table():
    lines = DecisionLines(1.0)
    table = _study_table()
    sel = select_variant(table, "fastest_in_best_zone", lines)
    assert sel.variant == "model4"                      # the study's choice (section 2.2)
    assert "excellent" in sel.reasoning and "model6" in sel.reasoning and "model7" in sel.reasoning
    assert select_variant(table, "closest_to_origin", lines).variant == "model7"
    assert select_variant(table, "fastest_acceptable", lines).variant == "model1"
    # ties in time are broken by distance
    tied = table.copy()
    tied.loc[tied["variant"] == "model6", "time_s"] = 34903.0
    assert select_variant(tied, "fastest_in_best_zone", lines).variant == "model6"
    # a failed variant is never selected, and the reasoning names it
    failed = table.copy()
    failed.loc[failed["variant"] == "model4", "status"] = "failed"
    sel = select_variant(failed, "fastest_in_best_zone", lines)
    assert sel.variant == "model6" and "model4" in sel.reasoning
    nothing = table.assign(zone_rank=0)
    assert select_variant(nothing, "fastest_acceptable", lines).variant is None
    honest = select_variant(nothing, "fastest_in_best_zone", lines)   # never the fastest non-conforming variant
    assert honest.variant is None and "No variant is acceptable" in honest.reasoning
    only_ref = nothing.copy()
    only_ref.loc[only_ref["variant"] == "model7", "zone_rank"] = 3
    sel = select_variant(only_ref, "fastest_in_best_zone", lines, reference="model7")
    assert sel.variant == "model7" and sel.reasoning.startswith("Only the reference model7 is acceptable")
    with pytest.raises(ValueError, match="unknown selection rule"):
        select_variant(table, "cheapest", lines)


def test_screening_tables_rank_synthetic_variants(settings):
    tea = settings.allowable_total_error_pct
    # composite Bias 0.2 * 5 * b, CV 0.2 * 5 * c (all indicators alike): place one point per zone
    specs = {"excellent": (0.001, 0.001), "good": (0.002, 0.0022), "critical": (0.002, 0.0035),
             "non-conforming": (0.004, 0.004)}
    results = []
    for i, (zone, (b, c)) in enumerate(specs.items()):
        keys = ("input_speed", "output_speed", "transmission_ratio", "outer_mesh_force", "inner_mesh_force")
        results.append(synthetic_result(zone, dict.fromkeys(keys, b), dict.fromkeys(keys, c), wall_time_s=10 - i))
    results.append(failed_result("broken", "diverged at t = 0.01 s"))
    table, indicators, selection = screening_tables(results, settings)
    assert list(table["zone"].iloc[:4]) == list(specs)
    assert table.loc[4, "status"] == "failed" and "diverged" in table.loc[4, "reason"]
    assert len(indicators) == 4 * 5
    assert selection.variant == "excellent" and table["selected"].sum() == 1
    row = table.iloc[0]
    assert row["bias_pct"] + 4 * row["cv_pct"] <= tea


def test_sample_means_are_segment_averages():
    t = np.arange(0, 1000) / 1000.0
    y = np.where(t < 0.5, 1.0, 3.0)
    w = Window(0.0, t[-1], True, "test")
    assert np.allclose(sample_means(t, y, w, 2), [1.0, 3.0])
    with pytest.raises(ValueError, match="too short"):
        sample_means(t[:3], y[:3], Window(0.0, 0.002, True, "test"), 10)


def test_short_run_window_is_marked_not_steady(settings):
    w = analysis_window({"ramp_time_s": 0.5}, 0.0, 0.02, settings)
    assert not w.steady and w.start_s == pytest.approx(0.01) and "NOT steady" in w.rule
    fixed = dataclasses.replace(settings, window="fixed", window_start_s=0.55, window_end_s=0.6)
    w = analysis_window({"ramp_time_s": 0.5}, 0.0, 0.6, fixed)
    assert (w.start_s, w.end_s, w.steady) == (0.55, 0.6, True)
    with pytest.raises(ValueError, match="outside the run"):
        analysis_window({}, 0.0, 0.02, fixed)


def test_weights_must_sum_to_one(tmp_path):
    text = open(GEARBOX).read().replace("inner_mesh_force = 0.2", "inner_mesh_force = 0.3")
    bad = tmp_path / "gearbox.toml"
    bad.write_text(text)
    with pytest.raises(SpecError, match=r"screening\.weights.*sum to 1"):
        load_gearbox(bad)
