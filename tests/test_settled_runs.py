"""Runs continued until they settle: a run solved in chunks is the run solved at once, and the settling test
decides when to stop (flexgear.mbs.run, flexgear.settling)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from flexgear.mbs.run import run_variant
from flexgear.settling import SettleRule, radial_rms, settled_start


def _short(model1, **load_case):
    gb = model1.gearbox.with_fields("load_case", ramp_time_s=0.01, **load_case)
    return dataclasses.replace(model1, gearbox=gb)


@pytest.mark.slow
def test_a_run_continued_in_chunks_is_the_run_solved_at_once(model1):
    """Model 1, ramps 10 ms; the settled mode cannot pass by 40 ms (too few blocks after the ramps), so the run is
    solved as 0-20, 20-30, 30-40 ms. Against one solve to 40 ms on the same time grid: every signal equal before
    the first restart, mean mesh forces within 1e-5 and the bearing RMS of the last 10 ms within 1 % after it
    (generalized-alpha restarts from consistent accelerations: a one-step transient in the accelerations)."""
    chunked = run_variant(_short(model1, end_time_s=0.02, end="settled", settle_chunk_s=0.01, settle_max_time_s=0.04))
    once = run_variant(_short(model1, end_time_s=0.04))
    assert chunked.ok and once.ok, (chunked.meta.get("reason"), once.meta.get("reason"))
    assert chunked.meta["t_end_s"] == pytest.approx(0.04) and chunked.meta["settled"] is False
    assert "not settled" in chunked.meta["settle_reason"]
    a, b = chunked.signals, once.signals
    assert len(a) == len(b)
    np.testing.assert_allclose(a["time_s"], b["time_s"], rtol=0, atol=1e-12)
    before = a["time_s"].to_numpy() <= 0.02
    for col in ("outer_mesh_force_1_n", "input_bearing_accel_x_m_per_s2", "output_speed_rad_per_s"):
        np.testing.assert_array_equal(a[col].to_numpy()[before], b[col].to_numpy()[before])
    after = a["time_s"].to_numpy() > 0.03
    for col in ("outer_mesh_force_1_n", "inner_mesh_force_3_n"):
        assert a[col][after].mean() == pytest.approx(b[col][after].mean(), rel=1e-5)
    rms = [radial_rms(r["input_bearing_accel_x_m_per_s2"].to_numpy()[after],
                      r["input_bearing_accel_y_m_per_s2"].to_numpy()[after]) for r in (a, b)]
    assert rms[0] == pytest.approx(rms[1], rel=0.01)


@pytest.mark.slow
def test_a_settled_run_stops_where_the_settling_test_passes(model1):
    """Model 1, ramps 10 ms, first chunk to 40 ms, then 20 ms chunks: the run stops settled, and the settling test
    on its own signals agrees (settled, before the end, with one block per screening sample after it)."""
    v = _short(model1, end_time_s=0.04, end="settled", settle_chunk_s=0.02, settle_max_time_s=0.5)
    res = run_variant(v)
    assert res.ok and res.meta["settled"] is True, res.meta.get("settle_reason")
    screening = v.gearbox.screening
    rule = SettleRule.from_settings(screening)
    test = settled_start(res.signals, 0.01, res.meta["theory"]["mesh_frequency_hz"], rule)
    assert test.settled and test.start_s == pytest.approx(res.meta["settled_at_s"])
    block = rule.block_mesh_cycles / res.meta["theory"]["mesh_frequency_hz"]
    assert res.meta["t_end_s"] - test.start_s >= rule.min_blocks * block - 1e-9
    assert res.meta["t_end_s"] < 0.5


@pytest.mark.slow
def test_verdicts_against_the_reference_at_half_the_step_are_unchanged_or_not_resolved(model1):
    """Model 1 (ramps 10 ms) as the reference, run to 0.12 s and its window 0.12-0.15 s solved from there at h and
    at h/2; two candidates run to 0.15 s: a numerical variant (spectral radius 0.6 instead of 0.8) and a physical
    one (no tooth friction). Screened over 0.12-0.15 s against the reference's h window and against its h/2
    window, each candidate's zone is the same, or the screening marks it not resolved (its zone changes within
    the numerical error)."""
    import dataclasses as dc

    from flexgear.results import RunResult
    from flexgear.study.screening import screen

    base = _short(model1, end_time_s=0.15)
    gb = base.gearbox
    ref = run_variant(dc.replace(base, name="ref"), t_end_s=0.12, error_window_s=0.03)
    radius = gb.with_fields("solver_assumed", spectral_radius=0.6)
    frictionless = gb.with_fields("contact", friction_coefficient=0.0)
    cands = [run_variant(dc.replace(base, name="radius", gearbox=radius)),
             run_variant(dc.replace(base, name="frictionless", gearbox=frictionless))]
    assert all(r.ok for r in (ref, *cands))
    settings = dc.replace(gb.screening, window="fixed", window_start_s=0.12, window_end_s=0.15)
    assert len(ref.extra["error_half_step"]) > 1.9 * len(ref.extra["error_step"])   # h/2: twice the points
    zones = []
    for window in ("error_step", "error_half_step"):
        at = RunResult(ref.meta, ref.extra[window], {})
        zones.append(screen([at, *cands], settings, reference="ref").table.set_index("variant")["zone"])
    with_error = screen([RunResult(ref.meta, ref.extra["error_step"], ref.extra), *cands], settings,
                        reference="ref").table.set_index("variant")
    assert (with_error["error_pct"].dropna() > 0).all()
    for name in ("radius", "frictionless"):
        assert zones[0][name] == zones[1][name] or not with_error.loc[name, "resolved"], name


def test_the_error_windows_are_timed_apart_from_the_run(model1):
    """A run with its numerical error windows records their cost apart: its own CPU time stays the run's."""
    v = _short(model1, end_time_s=0.02)
    res = run_variant(v, error_window_s=0.01)
    assert res.ok and res.meta["error_windows_cpu_time_s"] > 0.0
    assert 0.0 < res.meta["cpu_time_s"] and set(res.extra) == {"error_step", "error_half_step"}
    assert float(res.signals["time_s"].iloc[-1]) == pytest.approx(0.02)   # the run's own signals end at its end
