"""Simulation (Exudyn backend): build a variant, integrate the load case, return a RunResult.

Solver: generalized-alpha (spectral radius from ``[solver_assumed]``), modified Newton with a
Jacobian update after at most ``newton_max_modified_iterations`` iterations, Eigen's sparse LU,
one thread, no solution file; sensors store every ``record_every_steps``-th step in memory.

Divergence guard (:class:`RunGuard`, a post-step user function; it also drives the Jacobian economy of the
production formulation, flexgear.mbs.newton): the run stops and is recorded as
failed, with its reason, when the state is not finite (NaN), when a shaft spins faster than
``runaway_speed_factor`` times its nominal speed (a runaway), when the wall time exceeds
``wall_time_budget_s`` (all three in ``[solver_assumed]``), or when Newton's method fails (Exudyn's
own error). Exudyn's console output (its per-run banner and step lines) is switched off; the guard
drives a :class:`flexgear.progress.Progress` display instead.
"""

from __future__ import annotations

import gc
import math
import time
import traceback

import numpy as np
import pandas as pd

from flexgear.design import design
from flexgear.mbs.assemble import build_gearbox
from flexgear.mbs.deflection import mesh_deflection_signals, transmission_error
from flexgear.mbs.gearbox import GearboxModel, MassSource, ReducedSource
from flexgear.mbs.newton import JacobianEconomy, MidlifeJacobian, MultiplierWarmStart, turning_updaters, warm_starts
from flexgear.mbs.recording import add_gearbox_sensors, joint_axis_torque, simulation_settings
from flexgear.mbs.states import add_state_sensors, state_bodies, state_table
from flexgear.progress import Progress
from flexgear.results import RunResult, run_metadata, signal_columns
from flexgear.spec import Variant, as_dict, spec_hash

__all__ = ["GUARD_EVERY_STEPS", "RunGuard", "SensorLog", "numerical_error_windows", "ramp_warning", "run_variant"]

GUARD_EVERY_STEPS = 50
"""Steps between two checks of the divergence guard (each reads two node velocities and the clock)."""


class SensorLog:
    """Stored sensor data of a run solved in one or more chunks (Exudyn clears it at each ``SolveDynamic``):
    :meth:`collect` after each chunk appends its rows, :meth:`GetSensorStoredData` reads them all (the name of
    Exudyn's own reader, so that the signal functions read either)."""

    def __init__(self, mbs, sensors: dict[str, int]) -> None:
        self.mbs = mbs
        self.parts: dict[int, list[np.ndarray]] = {i: [] for i in set(sensors.values())}

    def collect(self) -> None:
        for i, parts in self.parts.items():
            data = np.asarray(self.mbs.GetSensorStoredData(i))
            if parts:  # a continued chunk starts with the previous chunk's last recorded time
                data = data[data[:, 0] > parts[-1][-1, 0] + 1e-12]
            parts.append(data)

    def GetSensorStoredData(self, i: int) -> np.ndarray:  # noqa: N802 (Exudyn's name)
        parts = self.parts[i]
        return parts[0] if len(parts) == 1 else np.vstack(parts)


def _signals(mbs, model: GearboxModel, sensors: dict[str, int]) -> pd.DataFrame:
    """Signal table (flexgear.results.signal_columns) from the stored sensor data."""
    def data(key: str) -> np.ndarray:
        return np.asarray(mbs.GetSensorStoredData(sensors[key]))

    speed_in, speed_out = data("input_speed"), data("output_speed")
    n = model.spec.gears.planet_count
    cols: dict[str, np.ndarray] = {"time_s": speed_in[:, 0]}
    cols["input_speed_rad_per_s"] = speed_in[:, 3]
    cols["output_speed_rad_per_s"] = speed_out[:, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        cols["transmission_ratio"] = np.where(speed_in[:, 3] != 0, speed_out[:, 3] / speed_in[:, 3], np.nan)
    cols["input_torque_nm"] = -data("input_torque")[:, 1]  # constraint reaction -> torque applied by the drive
    inner = model.spec.gears.has_ring
    for kind in ("outer", "inner") if inner else ("outer",):
        for i in range(1, n + 1):
            halves = [k for k in sensors if k.startswith(f"{kind}_{i}_")]
            cols[f"{kind}_mesh_force_{i}_n"] = sum(data(k)[:, 1] for k in halves)
    for side, key in (("input", "input_accel"), ("output", "output_accel")):
        acc = data(key)
        cols[f"{side}_bearing_accel_x_m_per_s2"] = acc[:, 1]
        cols[f"{side}_bearing_accel_y_m_per_s2"] = acc[:, 2]
    frame = pd.DataFrame({c: cols[c] for c in signal_columns(n, inner)})
    # optional columns (flexgear.mbs.deflection): loaded transmission error, flexible gears' mesh deflections
    time = cols["time_s"]
    extra = {"transmission_error_m": transmission_error(model, time, data("output_spin")[:, 1 + model.output_spin[1]])}
    if model.kinematics is not None:
        modal = {name: np.hstack([data(k)[:, 1:] for k in sensors if k.startswith(f"modes_{name}/")])
                 for name, body in model.bodies.items() if body.flexible}  # each body's q~ (recording.py)
        residual = data("residual")[:, 1:] if "residual" in sensors else None
        seats = [data(f"seat_residual/{k}")[:, 1:] for k in range(len(model.seat_residual_nodes))]
        extra.update(mesh_deflection_signals(model, time, modal, residual, np.hstack(seats) if seats else None))
    return pd.concat([frame, pd.DataFrame(extra)], axis=1)


def elastic_share(mbs, model: GearboxModel, sensors: dict[str, int], signals: pd.DataFrame,
                  window_start: float) -> dict[str, float]:
    """Share of the mesh penetration that the flexible gears' deformation takes up, per mesh kind.

    ``elastic_share_{kind}``: load-induced deflection (flexgear.mbs.deflection, relative to the gears' seats)
    over the mean penetration delta of the contacts; ``centrifugal_share_{kind}``: the centrifugal part
    likewise (negative: spin growth deepens the penetration).
    """
    parts = [np.asarray(mbs.GetSensorStoredData(sensors[k])) for k in sensors if k.startswith("deflections/")]
    defl = np.hstack([parts[0][:, :1], *(d[:, 1:] for d in parts)])  # time, then every contact's deflection
    total = defl[defl[:, 0] >= window_start, 1:]
    w = signals[signals.time_s >= window_start]
    out = {}
    for kind in ("outer", "inner") if model.spec.gears.has_ring else ("outer",):
        rows = [i for i, c in enumerate(model.contacts) if c.name.startswith(kind)]
        for part, key in (("load", "elastic_share"), ("centrifugal", "centrifugal_share")):
            cols = [c for c in w.columns if c.startswith(f"{kind}_deflection_{part}_")]
            out[f"{key}_{kind}"] = float(w[cols].to_numpy().mean() / total[:, rows].mean())
    return out


class RunGuard:
    """Post-step user function of one run: divergence guard, wall-time budget and progress display.

    Every ``GUARD_EVERY_STEPS`` steps it reads the spin speed of the input and output body; it stops
    the solver (returns False) with :attr:`reason` set when a speed is not finite, when
    |omega| > runaway_speed_factor * |omega_nominal| (omega_nominal: the load case's speed and its theory
    ratio), or when the wall time since construction exceeds ``budget_s``.
    """

    def __init__(self, model: GearboxModel, variant: Variant, t_end: float, budget_s: float,
                 progress: bool = False) -> None:
        th = model.theory
        factor = variant.gearbox.solver_assumed.runaway_speed_factor
        self.nodes = {"input": model.bodies[model.input_body].node, "output": model.bodies[model.output_body].node}
        self.limits = {"input": factor * abs(th.input_speed), "output": factor * abs(th.output_speed)}
        self.budget_s, self.t_end = budget_s, t_end
        self.reason = ""
        self.steps = 0
        self.t0 = time.perf_counter()
        self.bar = Progress(t_end, f"run {variant.name}", "s", enabled=progress, fmt="{:.4g}")
        sv = variant.gearbox.solver_assumed
        self.economy = None if sv.reference else JacobianEconomy(sv.jacobian_cost_iterations)
        self._warm_start = warm_starts(model.bodies.values(), sv.reference)

    @property
    def warm_start(self) -> bool:
        """Whether the run warm-starts its multipliers (flexgear.mbs.newton.warm_starts)."""
        return self._warm_start

    def __call__(self, mbs, t: float) -> bool:
        if self.economy is not None:
            self.economy(mbs)
        self.steps += 1
        if self.steps % GUARD_EVERY_STEPS:
            return True
        import exudyn as exu

        for side, node in self.nodes.items():
            w = float(mbs.GetNodeOutput(node, exu.OutputVariableType.AngularVelocity)[2])
            if not math.isfinite(w):
                self.reason = f"diverged: non-finite {side} speed at t = {t:.6g} s"
            elif abs(w) > self.limits[side]:
                self.reason = (f"diverged: {side} speed {abs(w):.4g} rad/s above the runaway limit "
                               f"{self.limits[side]:.4g} rad/s (runaway_speed_factor) at t = {t:.6g} s")
            if self.reason:
                return False
        elapsed = time.perf_counter() - self.t0
        if elapsed > self.budget_s:
            self.reason = (f"wall-time budget of {self.budget_s:g} s exceeded at t = {t:.6g} s "
                           f"of {self.t_end:g} s (wall_time_budget_s)")
            return False
        self.bar.update_to(t)
        return True


def ramp_warning(variant: Variant, t_end: float) -> str:
    """A warning when the run ends before the STEP ramps of speed and load do (no steady part), else ''."""
    ramp = variant.gearbox.load_case.ramp_time_s
    if t_end <= ramp:
        return (f"the run ends at t = {t_end:g} s, inside the load ramps (ramp_time_s = {ramp:g} s): "
                "no steady part; screening and Tables 6/7 use its last part only")
    return ""


def _solve(mbs, variant: Variant, t_start: float, t_end: float, guard: RunGuard, step_s: float | None = None) -> None:
    """SolveDynamic from ``t_start`` to ``t_end`` [s] at the load case's step (or ``step_s``) with Exudyn's console
    output off, leaving the final state as the initial state of a continuation; raises with the guard's or the
    solver's reason."""
    import exudyn as exu
    import exudyn.solver as exu_solver

    # Exudyn warns when a run allocates memory in every step. Ours do by design: the sensors store
    # every recorded step in memory (storeInternal) and the contact user functions return new
    # vectors. The warning says nothing about a particular run, so it is switched off.
    exu_solver.solverCheckMemoryAllocationsThreshold = math.inf
    # a post-step function: the pre-step one belongs to the model (contact kinematics, friction, drive schedule)
    if t_start == 0.0 and mbs.GetPostStepUserFunction() not in (0, None):
        raise RuntimeError("the model has a post-step user function already; the divergence guard needs it")
    mbs.SetPostStepUserFunction(guard)
    step = variant.gearbox.load_case.step_size_s if step_s is None else step_s
    if guard.economy is not None:  # the production formulation
        guard.economy.new_solve()
        updaters = turning_updaters(mbs)
        if updaters:
            mbs.SetSystemJacobianUserFunction(MidlifeJacobian(updaters, step))
    if guard.warm_start:
        mbs.SetPreNewtonResidualUserFunction(MultiplierWarmStart())
    settings = simulation_settings(variant, t_end, False, guard.warm_start)
    settings.timeIntegration.startTime = t_start
    settings.timeIntegration.numberOfSteps = max(1, round((t_end - t_start) / step))
    was_printing = exu.config.printToConsole
    exu.config.printToConsole = False
    # the per-step Python allocates small objects: without this, each garbage collection of the older generations
    # walks every object of the built model (gc_collect_main was 2-3 % of model 7's run in perf)
    gc.collect()
    gc.freeze()
    try:
        mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.GeneralizedAlpha, storeSolver=True,
                         showHints=False, updateInitialValues=True)
    except Exception as exc:
        guard.bar.close()
        if guard.reason:
            raise FloatingPointError(guard.reason) from None
        _ok, message = exu.SolverSuccess(mbs.sys["dynamicSolver"]) if "dynamicSolver" in mbs.sys else (False, "")
        first = " ".join(message.split())[:600] if message else str(exc)
        raise RuntimeError(f"solver failed: {first}") from None
    finally:
        exu.config.printToConsole = was_printing
        gc.unfreeze()
    if guard.reason:
        guard.bar.close()
        raise FloatingPointError(guard.reason)
    guard.bar.update_to(t_end)


def _solve_chunk(mbs, variant: Variant, t_start: float, t_end: float, guard: RunGuard, log: SensorLog,
                 counts: dict[str, int]) -> dict[str, int]:
    """Solve one chunk, keep its sensor data, add its solver counts to ``counts`` (returned)."""
    _solve(mbs, variant, t_start, t_end, guard)
    log.collect()
    return {k: counts.get(k, 0) + v for k, v in solver_counts(mbs).items()}


def numerical_error_windows(mbs, model: GearboxModel, variant: Variant, sensors: dict[str, int], guard: RunGuard,
                            t_end: float, window_s: float) -> dict[str, pd.DataFrame]:
    """The numerical error of a run at its final state: the window [t_end, t_end + window_s] solved twice from
    that same state, at the load case's step h and at h/2 (generalized-alpha is second-order accurate, so the
    difference of the two estimates the error of the h solution within a factor 4/3). Returns their signal
    tables as ``error_step`` and ``error_half_step``; the run's own signals are not changed."""
    import exudyn as exu

    state = mbs.systemData.GetSystemState()
    h = variant.gearbox.load_case.step_size_s
    out = {}
    guard.bar.extend(t_end + 2 * window_s)
    for name, step in (("error_step", h), ("error_half_step", h / 2)):
        mbs.systemData.SetSystemState(systemStateList=state, configuration=exu.ConfigurationType.Initial)
        log = SensorLog(mbs, sensors)
        _solve(mbs, variant, t_end, t_end + window_s, guard, step)
        log.collect()
        out[name] = _signals(log, model, sensors)
    return out


def _continue_until_settled(mbs, model: GearboxModel, variant: Variant, sensors: dict[str, int], guard: RunGuard,
                            log: SensorLog, counts: dict[str, int], meta: dict) -> tuple[float, dict[str, int]]:
    """Continue a run at its steady operating point in chunks until it settles (:mod:`flexgear.settling`) or
    reaches ``settle_max_time_s``; records the outcome in ``meta``. Returns the end time [s] and solver counts."""
    from flexgear.settling import SettleRule, settled_start

    lc, screening = variant.gearbox.load_case, variant.gearbox.screening
    rule = SettleRule.from_settings(screening)
    after = lc.ramp_time_s + screening.after_ramp_delay_s
    f_mesh = float(meta["theory"]["mesh_frequency_hz"])
    t_end = lc.end_time_s
    while True:
        test = settled_start(_signals(log, model, sensors), after, f_mesh, rule)
        if test.settled or t_end >= lc.settle_max_time_s - 1e-12:
            break
        # one chunk, or up to four at once when the test's estimate says that many are needed
        jump = min(test.needed_end_s, t_end + 4 * lc.settle_chunk_s) if math.isfinite(test.needed_end_s) else 0.0
        t_next = min(lc.settle_max_time_s, max(t_end + lc.settle_chunk_s, jump))
        t_next = round(t_next / lc.step_size_s) * lc.step_size_s  # whole steps: the time grid of a single run
        guard.bar.extend(t_next)
        guard.t_end = t_next
        counts = _solve_chunk(mbs, variant, t_end, t_next, guard, log, counts)
        t_end = t_next
    meta.update(settled=test.settled, settled_at_s=test.start_s, settle_reason=test.reason,
                settle_max_time_s=lc.settle_max_time_s)
    return t_end, counts


def solver_counts(mbs) -> dict[str, int]:
    """Newton iterations and Jacobian computations of the last ``SolveDynamic`` (stored solver), for the metadata."""
    solver = mbs.sys.get("dynamicSolver")
    if solver is None:
        return {}
    return {"newton_iterations": int(solver.it.newtonStepsCount), "jacobians": int(solver.it.newtonJacobiCount)}


def run_variant(variant: Variant, t_end_s: float | str | None = None, progress: bool = False,
                mass_source: MassSource | None = None, reduced_source: ReducedSource | None = None,
                time_budget_s: float | None = None, record_states_every: int = 0,
                error_window_s: float = 0.0) -> RunResult:
    """Run ``variant`` for ``t_end_s`` [s] (default: the load case's end), or until it has settled.

    ``t_end_s = "settled"`` (or ``[load_case] end = "settled"`` with ``t_end_s`` None): the run goes to the load
    case's ``end_time_s``, then continues in chunks of ``settle_chunk_s`` at the steady operating point until the
    settling test of :mod:`flexgear.settling` (``[screening]`` settle_* fields) passes or ``settle_max_time_s`` is
    reached; the metadata records ``settled``, ``settled_at_s`` and the test's reason either way.
    ``error_window_s`` > 0: then also :func:`numerical_error_windows` from the final state (extra tables
    ``error_step`` and ``error_half_step``, for the screening's numerical error bars), timed apart from the run
    (``error_windows_wall_time_s``, ``error_windows_cpu_time_s``; ``wall_time_s`` and ``cpu_time_s`` exclude them).
    ``time_budget_s`` overrides ``[solver_assumed] wall_time_budget_s``. ``record_states_every`` > 0 also
    records the bodies' states every that many steps (extra table ``states``, flexgear.mbs.states; for
    ``flexgear animate``). Never raises for a model or solver failure: the result then has status
    "failed" and the reason (see :class:`RunGuard`).
    """
    import exudyn as exu
    from threadpoolctl import threadpool_limits

    lc = variant.gearbox.load_case
    until_settled = t_end_s == "settled" or (t_end_s is None and lc.end == "settled")
    t_end = lc.end_time_s if (t_end_s is None or until_settled) else float(t_end_s)
    budget = variant.gearbox.solver_assumed.wall_time_budget_s if time_budget_s is None else float(time_budget_s)
    # the design and the run's metadata, made once at the start; the model below is built from this design
    gb = variant.gearbox
    d = design(gb)
    run_key, spec_data = spec_hash(variant, t_end), as_dict(gb)
    meta = run_metadata(variant.name, "exudyn", run_key, t_end, gb.load_case, gb.gears.planet_count,
                        variant.components, d.theory, source=str(variant.source), spec=spec_data)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    extra: dict[str, pd.DataFrame] = {}
    # small BLAS calls only (mode-shape fits, post-processing): threads contend on a shared machine
    # (model 7's build: 6-7 s CPU with 2 OpenBLAS threads, 0.5-1.4 s with one; benchmarks/profile_mbs.py)
    blas = threadpool_limits(limits=1, user_api="blas")
    sc = None
    try:
        if not (t_end > 0 and math.isfinite(t_end)):
            raise ValueError(f"t_end_s must be a positive number, got {t_end_s!r}")
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        model = build_gearbox(mbs, variant, mass_source, reduced_source, superelements=record_states_every > 0,
                              design=d)
        sensors = add_gearbox_sensors(mbs, model)
        states = add_state_sensors(mbs, model) if record_states_every > 0 else {}
        mbs.Assemble()
        build_s = time.perf_counter() - wall0
        # the system's size: second-order coordinates and algebraic ones (a constraint row's multiplier each)
        meta.update(ode2_coordinates=len(mbs.systemData.GetODE2Coordinates()),
                    constraint_rows=len(mbs.systemData.GetAECoordinates()))
        guard = RunGuard(model, variant, t_end, budget - build_s, progress)
        log = SensorLog(mbs, {**sensors, **{f"state/{k}": v for k, v in states.items()}})
        counts = _solve_chunk(mbs, variant, 0.0, t_end, guard, log, {})
        if until_settled:
            t_end, counts = _continue_until_settled(mbs, model, variant, sensors, guard, log, counts, meta)
        if error_window_s > 0:  # not part of the run's cost: timed apart
            err_wall, err_cpu = time.perf_counter(), time.process_time()
            extra.update(numerical_error_windows(mbs, model, variant, sensors, guard, t_end, error_window_s))
            err_wall, err_cpu = time.perf_counter() - err_wall, time.process_time() - err_cpu
            meta.update(error_window_s=error_window_s, error_windows_wall_time_s=err_wall,
                        error_windows_cpu_time_s=err_cpu)
        guard.bar.close()
        meta.update(counts, t_end_s=t_end)
        mbs = log  # the signals below read every chunk's sensor data
        if guard.economy is not None:  # the Jacobians it asked for, a Jacobian's cost as measured (flexgear.mbs.newton)
            meta.update(jacobian_requests=guard.economy.requests,
                        jacobian_cost_iterations_measured=guard.economy.measured_ratio)
        signals = _signals(mbs, model, sensors)
        window_start = min(variant.gearbox.load_case.ramp_time_s, 0.8 * t_end)
        if model.kinematics is not None:
            meta.update(elastic_share(mbs, model, sensors, signals, window_start))
        for gear in model.joints:  # torque about the axis that each gear-shaft joint (set) transmits
            t, torque = joint_axis_torque(mbs, model, sensors, gear)
            meta[f"joint_torque_{gear}_nm"] = float(torque[t >= window_start].mean())
        if not np.all(np.isfinite(signals.drop(columns="transmission_ratio").to_numpy())):
            raise FloatingPointError("diverged: non-finite signals")
        if states:
            extra["states"] = state_table(mbs, states, record_states_every)
            meta.update(state_bodies=state_bodies(model), record_states_every=record_states_every)
        meta.update(status="ok", reason="", build_time_s=build_s, warning=ramp_warning(variant, t_end))
    except Exception as exc:  # recorded, not raised: a failed variant must not stop a matrix
        signals = None
        meta.update(status="failed", reason=f"{type(exc).__name__}: {exc}",
                    traceback=traceback.format_exc(limit=5))
    finally:
        blas.restore_original_limits()
        if sc is not None:
            # The user functions (contact laws, drive, pre-step kinematics) hold the system and the system
            # holds them: a cycle through C++ that Python's collector cannot free. Without the reset every
            # run left its model in the process (model 7 coarse: ~0.4 GB a run in a matrix worker).
            sc.Reset()
    # the run's cost, without the numerical error windows (they serve the screening, not the run)
    meta.update(wall_time_s=time.perf_counter() - wall0 - meta.get("error_windows_wall_time_s", 0.0),
                cpu_time_s=time.process_time() - cpu0 - meta.get("error_windows_cpu_time_s", 0.0))
    return RunResult(meta, signals, extra)
