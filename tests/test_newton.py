"""The Jacobian economy (flexgear.mbs.newton): its rule on a scripted solver, and a run that keeps every signal.

No timings (benchmarks/bench_speed.py measures the runs); the cost ratio is fitted from a scripted clock.
"""

import dataclasses

import numpy as np
import pytest
from conftest import VARIANTS

from flexgear.mbs.newton import MIN_SAMPLES, JacobianEconomy
from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant
from flexgear.study.agreement import signal_agreement


class _Solver:
    """Stand-in for Exudyn's stored solver: ``it.newtonSteps``, ``it.newtonJacobiCount``, ``conv`` flag."""

    def __init__(self):
        self.it = type("It", (), {"newtonSteps": 0, "newtonJacobiCount": 1})()
        self.conv = type("Conv", (), {"jacobianUpdateRequested": False})()


class _System:
    def __init__(self):
        self.sys = {"dynamicSolver": _Solver()}


class _Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def _step(economy, system, clock, n, jacobian, a=10e-6, b=5e-6, cost=40e-6):
    """One scripted step: n iterations, with a Jacobian or not; its wall time a + b n (+ cost)."""
    solver = system.sys["dynamicSolver"]
    solver.it.newtonSteps = n
    if jacobian:
        solver.it.newtonJacobiCount += 1
        solver.conv.jacobianUpdateRequested = False  # Exudyn consumes the request with the Jacobian
    clock.now += a + b * n + (cost if jacobian else 0.0)
    economy(system)
    return solver.conv.jacobianUpdateRequested


def test_a_jacobian_is_requested_when_the_extra_iterations_reach_its_cost():
    clock, system = _Clock(), _System()
    economy = JacobianEconomy(ratio=4.0, clock=clock)
    _step(economy, system, clock, 1, False)  # first call: binds the solver, no timing
    assert not _step(economy, system, clock, 1, False)  # the fewest since the last Jacobian: 1
    assert not _step(economy, system, clock, 3, False)  # paid 2 above it
    assert _step(economy, system, clock, 3, False)  # paid 4 = the cost: the next step gets a Jacobian
    assert not _step(economy, system, clock, 1, True)  # the Jacobian step resets the account
    assert economy.requests == 1


def test_the_cost_ratio_is_measured_from_the_steps_times_and_only_reported():
    """Steps take a + b n, a Jacobian adds c: the measured ratio is c / b (40 us / 5 us = 8 iterations); the rule
    keeps its configured ratio (deterministic runs)."""
    clock, system = _Clock(), _System()
    economy = JacobianEconomy(ratio=100.0, clock=clock)
    _step(economy, system, clock, 1, False)
    for k in range(2 * MIN_SAMPLES):
        _step(economy, system, clock, 1 + k % 3, False)  # iteration counts that vary: a and b identifiable
    assert economy.measured_ratio is None  # no Jacobian step measured yet
    _step(economy, system, clock, 2, True)
    assert economy.measured_ratio == pytest.approx(8.0, rel=1e-9)
    assert economy.ratio == pytest.approx(100.0)


def test_a_cost_below_one_iteration_is_refused():
    with pytest.raises(ValueError, match="cost in iterations"):
        JacobianEconomy(ratio=0.5)


@pytest.fixture(scope="module")
def short_model1():
    """Model 1 on ramps of 0.02 s to 0.03 s: light load early in the ramps, where Exudyn keeps a stale Jacobian."""
    v = load_variant(VARIANTS / "model1.toml")
    g = v.gearbox
    g = g.with_changes(load_case=dataclasses.replace(g.load_case, ramp_time_s=0.02, end_time_s=0.03))
    return dataclasses.replace(v, gearbox=g, rigid_mass_properties="exact")


def _in(variant, formulation: str):
    return dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("solver_assumed", formulation=formulation))


def test_the_economy_keeps_every_signal_and_saves_iterations(short_model1):
    """The production formulation (the economy) against the reference (Exudyn's own Jacobian policy): the agreement
    rule (means 0.1 %, 1x amplitudes 2 %); fewer iterations."""
    ref = run_variant(_in(short_model1, "reference"))
    new = run_variant(_in(short_model1, "production"))
    assert ref.ok and new.ok, (ref.meta.get("reason"), new.meta.get("reason"))
    lc = short_model1.gearbox.load_case
    agreement = signal_agreement(ref, new, (lc.ramp_time_s, lc.end_time_s), ref.meta["theory"]["mesh_frequency_hz"])
    assert agreement.ok(), agreement.table
    assert new.meta["newton_iterations"] < ref.meta["newton_iterations"]
    assert new.meta["jacobian_requests"] > 0


def test_runs_with_the_economy_are_deterministic(short_model1):
    """The rule counts iterations, not seconds: two runs take the same steps (bit-identical signals)."""
    first = run_variant(_in(short_model1, "production"))
    second = run_variant(_in(short_model1, "production"))
    assert first.meta["jacobians"] == second.meta["jacobians"]
    np.testing.assert_array_equal(first.signals.to_numpy(), second.signals.to_numpy())  # reproducibility itself


@pytest.fixture(scope="module")
def full_speed_model4():
    """Model 4 (flexible sun and ring: contact columns and seats that turn with the spin) at full speed after
    ramps of 5 ms, to 20 ms."""
    v = load_variant(VARIANTS / "model4.toml")
    g = v.gearbox
    return dataclasses.replace(v, gearbox=g.with_changes(load_case=dataclasses.replace(
        g.load_case, ramp_time_s=0.005, end_time_s=0.02)))


def test_warm_started_multipliers_keep_every_signal_and_save_iterations(full_speed_model4, monkeypatch):
    """The production run (multipliers warm-started, flexgear.mbs.newton.MultiplierWarmStart, with the absolute
    tolerance that goes with it) against the same run started from zero multipliers at Exudyn's tolerances: the
    agreement rule (means 0.1 %, 1x amplitudes 2 %); fewer iterations and Jacobians."""
    import flexgear.mbs.run as run_module

    warm = run_variant(full_speed_model4)
    monkeypatch.setattr(run_module.RunGuard, "warm_start", property(lambda self: False))
    cold = run_variant(full_speed_model4)
    assert warm.ok and cold.ok, (warm.meta.get("reason"), cold.meta.get("reason"))
    lc = full_speed_model4.gearbox.load_case
    agreement = signal_agreement(cold, warm, (lc.ramp_time_s, lc.end_time_s), cold.meta["theory"]["mesh_frequency_hz"])
    assert agreement.ok(), agreement.table
    assert warm.meta["newton_iterations"] < cold.meta["newton_iterations"]
    assert warm.meta["jacobians"] < cold.meta["jacobians"]


def test_the_midlife_jacobian_holds_the_turning_coefficients_of_the_middle_of_its_life(full_speed_model4):
    """Exudyn's Newton Jacobian with flexgear.mbs.newton.MidlifeJacobian (an expected life of 10 steps) equals the
    Jacobian computed with every turning coefficient written at 5 steps later (the joints' and seats', the contact
    columns'), entry by entry."""
    import exudyn as exu

    from flexgear.mbs.gearbox import build_star_gearbox
    from flexgear.mbs.newton import MidlifeJacobian, turning_updaters
    from flexgear.mbs.recording import simulation_settings

    v = full_speed_model4
    h = v.gearbox.load_case.step_size_s
    mbs = exu.SystemContainer().AddSystem()
    build_star_gearbox(mbs, v)
    mbs.Assemble()
    settings = simulation_settings(v, 0.006, False, True)  # beyond the ramps: full speed
    mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.GeneralizedAlpha, storeSolver=True)
    solver = mbs.sys["dynamicSolver"]
    updaters = turning_updaters(mbs)
    assert len(updaters) == 2  # the linear joints and seats; the contact columns

    def jacobian() -> np.ndarray:
        solver.ComputeNewtonJacobian(mbs, settings)
        return np.array(solver.GetSystemJacobian())

    now = {id(u): u.time for u in updaters}
    at_rest = jacobian()
    for u in updaters:
        u(mbs, now[id(u)] + 5 * h)
    shifted = jacobian()
    for u in updaters:
        u(mbs, now[id(u)])
    midlife = MidlifeJacobian(updaters, h)
    midlife.lives.append(10.0)
    mbs.SetSystemJacobianUserFunction(midlife)
    got = jacobian()
    scale = np.abs(shifted).max()
    assert np.abs(shifted - at_rest).max() > 1e-9 * scale  # the coefficients did turn
    assert np.abs(got - shifted).max() <= 1e-13 * scale


def test_the_midlife_jacobian_keeps_every_signal(full_speed_model4, monkeypatch):
    """The production run with the mid-life Jacobian against the same run with the Jacobian of its own step: the
    agreement rule (means 0.1 %, 1x amplitudes 2 %; the converged solution is the same to the Newton tolerance)."""
    import flexgear.mbs.run as run_module

    midlife = run_variant(full_speed_model4)
    monkeypatch.setattr(run_module, "turning_updaters", lambda mbs: [])
    own = run_variant(full_speed_model4)
    assert midlife.ok and own.ok, (midlife.meta.get("reason"), own.meta.get("reason"))
    lc = full_speed_model4.gearbox.load_case
    agreement = signal_agreement(own, midlife, (lc.ramp_time_s, lc.end_time_s), own.meta["theory"]["mesh_frequency_hz"])
    assert agreement.ok(), agreement.table
