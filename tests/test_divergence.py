"""Divergence guard with the Exudyn solver: a run that Newton cannot carry, or that exceeds its wall-time
budget, is stopped and recorded as failed with its reason, and a matrix goes on with the other variants."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

from flexgear.results import load_result
from flexgear.spec import load_variant
from flexgear.study.matrix import run_matrix

pytest.importorskip("exudyn")
from flexgear.mbs.run import run_variant  # noqa: E402

VARIANTS = Path(__file__).resolve().parents[1] / "model_variants"
T_END = 0.005  # s: 500 steps of the study's 1e-5 s
# Section 2.1's contact stiffness is 1e8 N/m^1.5. At 1e20 the contact force of a 1 um penetration is
# 1e11 N: the Jacobian of the impact law spans 20 orders of magnitude and Newton's method fails in the
# first steps even after Exudyn has cut the step to its minimum (measured).
DIVERGING_STIFFNESS = 1.0e20


def _model1(**contact) -> object:
    v = dataclasses.replace(load_variant(VARIANTS / "model1.toml"), rigid_mass_properties="exact")
    g = v.gearbox
    return dataclasses.replace(v, gearbox=g.with_changes(contact=dataclasses.replace(g.contact, **contact)))


def test_newton_failure_is_a_failed_run_with_its_reason():
    result = run_variant(_model1(stiffness=DIVERGING_STIFFNESS), t_end_s=T_END)
    assert result.meta["status"] == "failed" and result.signals is None
    assert "solver failed" in result.meta["reason"] and "minimum step size" in result.meta["reason"]


def test_the_study_stiffness_runs_through_the_same_steps():
    result = run_variant(_model1(), t_end_s=T_END)
    assert result.ok, result.meta["reason"]
    assert result.signals["time_s"].iloc[-1] == pytest.approx(T_END)
    assert "inside the load ramps" in result.meta["warning"]


def test_a_runaway_output_is_stopped():
    """With a contact stiffness of 1 N/m^1.5 the gears hardly touch (1 N at 1 m penetration): the load torque
    T (STEP-ramped over 0.02 s) spins the free output (ring + output shaft, J_z from the exact geometry) up at
    alpha = T / J, omega(t) = alpha (t - ramp/2) after the ramp. The guard must stop the run when omega passes
    runaway_speed_factor (here 1.2) times the nominal output speed, at its first check (every
    GUARD_EVERY_STEPS steps) after t = ramp/2 + 1.2 omega_nom J / T."""
    from flexgear.geometry.layout import exact_mass_properties
    from flexgear.mbs.run import GUARD_EVERY_STEPS
    from flexgear.theory import theory

    v = _model1(stiffness=1.0)
    g = v.gearbox
    ramp = 0.02
    g = g.with_changes(load_case=dataclasses.replace(g.load_case, ramp_time_s=ramp),
                       solver_assumed=dataclasses.replace(g.solver_assumed, runaway_speed_factor=1.2))
    result = run_variant(dataclasses.replace(v, gearbox=g), t_end_s=0.15)
    assert result.meta["status"] == "failed"
    reason = result.meta["reason"]
    assert "output speed" in reason and "runaway limit" in reason
    t_trip = float(reason.rsplit("t = ", 1)[1].split()[0])
    j_out = sum(exact_mass_properties(g, c).inertia[2, 2] for c in ("ring", "output_shaft"))
    w_nom = abs(np.radians(theory(g).output_speed_deg_per_s))
    predicted = ramp / 2 + 1.2 * w_nom * j_out / g.load_case.load_torque_nm
    check = GUARD_EVERY_STEPS * g.load_case.step_size_s
    assert predicted - 1e-9 <= t_trip <= predicted + check + 2e-5, (t_trip, predicted)


def test_the_wall_time_budget_stops_a_run():
    result = run_variant(_model1(), t_end_s=T_END, time_budget_s=1e-6)
    assert result.meta["status"] == "failed"
    assert "wall-time budget" in result.meta["reason"] and "wall_time_budget_s" in result.meta["reason"]


def test_a_diverging_variant_fails_in_the_matrix_and_the_others_go_on(tmp_path):
    shutil.copy(VARIANTS / "gearbox.toml", tmp_path / "gearbox.toml")
    base = 'rigid_mass_properties = "exact"\n' + (VARIANTS / "model1.toml").read_text()
    good, bad = tmp_path / "good.toml", tmp_path / "stiff.toml"
    good.write_text(base.replace('name = "model1"', 'name = "good"'))
    bad.write_text(base.replace('name = "model1"', 'name = "stiff"')
                   + f"\n[overrides.contact]\nstiffness = {DIVERGING_STIFFNESS:.1e}\n")
    table = run_matrix([bad, good], tmp_path / "out", t_end_s=T_END, workers=2, progress=False).set_index("variant")
    assert table.loc["stiff", "status"] == "failed" and "solver failed" in table.loc["stiff", "reason"]
    assert table.loc["good", "status"] == "ok"
    assert load_result(tmp_path / "out" / "good").ok
    assert load_result(tmp_path / "out" / "stiff").meta["reason"] == table.loc["stiff", "reason"]
