"""When the modified Newton method gets a fresh Jacobian: Exudyn's rule plus a cost balance (ski rental).

Exudyn's modified Newton keeps the factorised Jacobian of an earlier step until a step fails to converge
within ``newton_max_modified_iterations`` iterations: with the default 3, a step that converges in its
fourth iteration keeps the old Jacobian, and so may every following step. That happens where the
Jacobian goes stale slowly: at light load early in the ramps (contacts near separation, where the impact
law's tangent k e delta^(e-1) varies most; model 1 needs about 3 iterations per step over 0-0.1 s and 1
after 0.2 s, ``benchmarks/bench_newton.py``) and in the flexible variants, whose linear joints and seats
turn with the spin (``benchmarks/profile_mbs.py --trace-newton``).

:class:`JacobianEconomy` (the production formulation; the reference keeps Exudyn's rule alone) watches, after every
step, the iterations the step took. Since the last Jacobian the steps have paid ``E = sum(n_k) - count x min(n_k)``
iterations above the fewest any of them needed; when ``E`` reaches ``r``, a Jacobian's cost in iterations
(``[solver_assumed] jacobian_cost_iterations``), it asks Exudyn for a Jacobian at the next step
(``conv.jacobianUpdateRequested``). That is the break-even rule of the ski-rental problem: the extra iterations
paid never exceed about one Jacobian's cost per refresh, and a Jacobian is bought only when the iterations it saves
have already cost as much.

``r`` is a fixed setting, so that a run is deterministic (the same state, the same Jacobians). The run also
measures it, for the report only (:attr:`JacobianEconomy.measured_ratio`, the run's metadata
``jacobian_cost_iterations_measured``): from the steps' wall times, ``t = a + b n`` fitted over the steps
without a Jacobian (least squares in running sums; ``b`` the cost of one iteration) and a Jacobian's cost the
mean excess ``t - (a + b n)`` of the steps with one. The converged solution is the same to the Newton
tolerance (the tolerance and the iteration are unchanged, only the matrix they use is fresher);
``tests/test_newton.py`` checks it against Exudyn's own Jacobian policy.

:class:`MultiplierWarmStart` (production, in models with flexible bodies, :func:`warm_starts`; rigid
models and the reference keep Exudyn's start) gives each step's Newton iteration the last step's Lagrange multipliers
as its start. Exudyn starts every step from zero multipliers, so a step's initial
residual holds every reaction force (about N F_n, the sun's total normal mesh force), and the modified Newton's
Jacobian, which lags the constraint rows that turn with the spin by the angle turned since it was computed, errs
in its first increment by that angle times all of them. From the last step's multipliers the first increment
carries only their change over one step. Converged is then a residual below
:func:`newton_absolute_tolerance`, the level the relative tolerance accepts from a zero start at the nominal load,
or the relative tolerance of the (now smaller) initial residual, whichever comes first.

:class:`MidlifeJacobian` (production, where constraint coefficients turn with the spin: the linear joints and seats,
flexgear.mbs.joints.TurningBlocks, and the flexible gears' contact columns, flexgear.mbs.contact_kinematics.
ContactKinematics) is Exudyn's system Jacobian user function. The modified Newton method keeps a Jacobian for its
life of l steps while the turning coefficients C(t) move on; evaluated with the step's own C(t_j), the Jacobian
lags by up to l steps of spin at the end of its life. The function adds C(t_j + l h / 2) - C(t_j) to the
constraint rows and their transposed columns ([[., C^T], [C, 0]]: Exudyn's constraint Jacobian, unscaled), so that
the Jacobian holds the coefficients of the middle of its expected life, l the mean of the last
:data:`LIFE_SAMPLES` lives: its largest lag is halved. The residual keeps the step's own coefficients, so the
converged solution is the same to the Newton tolerance; only the matrix the iteration uses changes.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np

from flexgear.spec import GearboxSpec
from flexgear.theory import theory

if TYPE_CHECKING:
    from flexgear.mbs.bodies import Body

__all__ = ["MIN_SAMPLES", "LIFE_SAMPLES", "JacobianEconomy", "MidlifeJacobian", "MultiplierWarmStart",
           "newton_absolute_tolerance", "turning_updaters", "warm_starts"]

MIN_SAMPLES = 8
"""Steps without a Jacobian needed (beside one with a Jacobian) before the cost ratio is reported as measured."""
LIFE_SAMPLES = 4
"""Jacobian lifetimes (steps between two Jacobians) whose mean :class:`MidlifeJacobian` takes as the next one's."""


class JacobianEconomy:
    """Post-step bookkeeping of one run (call it after every step with the run's Exudyn system).

    ``ratio``: a Jacobian's cost in iterations that the rule uses (``[solver_assumed] jacobian_cost_iterations``);
    ``clock`` [s]: the wall clock of the cost measurement (a scripted one in the tests).
    """

    __slots__ = ("_it", "_conv", "_jacobians", "_clock", "_count", "_sum", "_min", "_free", "_jac", "_now",
                 "ratio", "requests")

    def __init__(self, ratio: float, clock: Callable[[], float] = time.perf_counter) -> None:
        if not ratio >= 1.0:
            raise ValueError(f"a Jacobian's cost in iterations must be >= 1, got {ratio!r}")
        self.ratio = float(ratio)
        self.requests = 0  # Jacobians this rule asked for
        self._now = clock
        self._it = None  # the stored solver's iteration data (flexgear.mbs.run stores the solver)
        self._conv = None
        self._jacobians = 0
        self._clock = 0.0
        self._count, self._sum, self._min = 0, 0, 1 << 30  # steps, iterations and the fewest since the last Jacobian
        self._free = [0.0, 0.0, 0.0, 0.0, 0.0]  # steps without a Jacobian: count, sum n, sum n^2, sum t, sum n t [s]
        self._jac = [0.0, 0.0, 0.0]  # steps with one: count, sum n, sum t [s]

    def new_solve(self) -> None:
        """A run continued by a new ``SolveDynamic`` (a new solver object): read its data at the next step."""
        self._it = None

    def __call__(self, mbs) -> None:
        now = self._now()
        it = self._it
        if it is None:  # first step: the solver's data, no timing (the step includes the solver's set-up)
            solver = mbs.sys["dynamicSolver"]
            self._it, self._conv = solver.it, solver.conv
            self._jacobians, self._clock = solver.it.newtonJacobiCount, now
            return
        n, jacobians = it.newtonSteps, it.newtonJacobiCount
        dt, self._clock = now - self._clock, now
        if jacobians != self._jacobians:  # a Jacobian in this step (Exudyn's rule or ours)
            self._jacobians = jacobians
            s = self._jac
            s[0] += 1.0
            s[1] += n
            s[2] += dt
            self._count, self._sum, self._min = 0, 0, 1 << 30
            return
        f = self._free
        f[0] += 1.0
        f[1] += n
        f[2] += n * n
        f[3] += dt
        f[4] += n * dt
        self._count += 1
        self._sum += n
        if n < self._min:
            self._min = n
        if self._sum - self._count * self._min >= self.ratio and not self._conv.jacobianUpdateRequested:
            self._conv.jacobianUpdateRequested = True
            self.requests += 1

    @property
    def measured_ratio(self) -> float | None:
        """A Jacobian's cost in iterations as this run measured it, or None before enough steps (report only)."""
        f, s = self._free, self._jac
        if f[0] < MIN_SAMPLES or s[0] < 1.0:
            return None
        det = f[0] * f[2] - f[1] * f[1]
        b = (f[0] * f[4] - f[1] * f[3]) / det if det > 1e-9 * f[0] * f[0] else f[3] / f[1]
        if not b > 0.0:  # iteration counts that do not vary enough to fit: the mean time per iteration
            b = f[3] / f[1]
        a = (f[3] - b * f[1]) / f[0]
        return max((s[2] - s[0] * a - b * s[1]) / s[0] / b, 0.0)


def warm_starts(bodies: Iterable[Body], reference: bool) -> bool:
    """Whether a run warm-starts its multipliers (:class:`MultiplierWarmStart`): the production formulation with a
    flexible body, whose constraint rows turn with the spin (a rigid model converges in about one iteration from
    either start)."""
    return not reference and any(b.flexible for b in bodies)


def newton_absolute_tolerance(spec: GearboxSpec) -> float:
    """Newton's absolute residual tolerance [N] with warm-started multipliers: ``newton_warm_start_tolerance_factor``
    x ``newton_relative_tolerance`` x N F_n, N F_n the sun's total normal mesh force at the nominal load
    (flexgear.theory: F_n = T_sun / (N r_b cos(beta_b))).

    A step started from zero multipliers has an initial residual of about N F_n (the reactions it starts without),
    so its relative criterion accepts about ``newton_relative_tolerance`` x N F_n; a warm-started step is held to a
    multiple of that level (the factor's evidence: docs/configuration.md).
    """
    th = theory(spec)
    sa = spec.solver_assumed
    zero_start_level = sa.newton_relative_tolerance * spec.gears.planet_count * th.mesh_force
    return sa.newton_warm_start_tolerance_factor * zero_start_level


class MultiplierWarmStart:
    """Pre-Newton-residual user function (Exudyn's ``SetPreNewtonResidualUserFunction``): at a step's first
    residual (Newton iteration 0) the Lagrange multipliers are set to their start-of-step values, the last step's
    converged ones, in place of the zeros Exudyn starts from (module docstring)."""

    __slots__ = ("_start",)

    def __init__(self) -> None:
        import exudyn as exu

        self._start = exu.ConfigurationType.StartOfStep

    def __call__(self, mbs, t: float, newton_iteration: int, discontinuous_iteration: int) -> None:
        if newton_iteration == 0:
            data = mbs.systemData
            data.SetAECoordinates(data.GetAECoordinates(self._start))


def turning_updaters(mbs) -> list:
    """The pre-step functions of ``mbs`` whose constraint coefficients turn with the spin (those with
    ``buffer_at``: flexgear.mbs.joints.TurningBlocks, flexgear.mbs.contact_kinematics.ContactKinematics)."""
    function = mbs.GetPreStepUserFunction()
    function = function.get("function") if isinstance(function, dict) else function
    return [f for f in getattr(function, "functions", [function]) if hasattr(f, "buffer_at")]


class MidlifeJacobian:
    """System Jacobian user function (Exudyn's ``SetSystemJacobianUserFunction``) of one run: the turning
    coefficients of ``updaters`` (:func:`turning_updaters`) at the middle of the Jacobian's expected life (module
    docstring); ``step_s`` [s] the time step."""

    def __init__(self, updaters: list, step_s: float) -> None:
        self.updaters, self.step = list(updaters), float(step_s)
        self.lives: deque[float] = deque(maxlen=LIFE_SAMPLES)
        self._last: float | None = None
        self._layout: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] | None = None
        self._scratch = [np.empty_like(u.buffer) for u in self.updaters]
        self._size = 0

    def _place(self, mbs) -> None:
        """Per updater: (its buffer's entries, their Jacobian rows and columns, signs), both the constraint rows
        and the transposed columns; the system's size."""
        data = mbs.systemData
        first_ae = data.ODE2Size() + data.ODE1Size()
        self._size = first_ae + data.AEsize()
        self._layout = []
        for u in self.updaters:
            start = u.buffer.__array_interface__["data"][0]
            entries, rows, cols, signs = [], [], [], []
            for obj, param, view in u.views:
                offset = (view.__array_interface__["data"][0] - start) // view.itemsize
                ae = first_ae + np.asarray(data.GetObjectLTGAE(obj), np.int64)
                coordinates = np.asarray(data.GetObjectLTGODE2(obj), np.int64)
                # Exudyn's equation: scalingMarker1 q1 - scalingMarker0 q0 - offset = 0, marker 0's coordinates first
                width0 = np.asarray(mbs.GetObjectParameter(obj, "scalingMarker0")).shape[1]
                columns = coordinates[width0:width0 + view.shape[1]] if param == "scalingMarker1" else (
                    coordinates[:view.shape[1]])
                r, c = np.meshgrid(ae, columns, indexing="ij")
                k = offset + np.arange(view.size)
                sign = 1.0 if param == "scalingMarker1" else -1.0
                entries += [k, k]
                rows += [r.ravel(), c.ravel()]
                cols += [c.ravel(), r.ravel()]
                signs += [np.full(k.size, sign)] * 2
            self._layout.append(tuple(np.concatenate(a) if a else np.zeros(0) for a in (entries, rows, cols, signs)))

    @property
    def life(self) -> float:
        """The expected life [steps] of the next Jacobian: the mean of the last ones (0 before the second)."""
        return float(np.mean(self.lives)) if self.lives else 0.0

    def __call__(self, mbs, t: float, factor_ode2: float, factor_ode2_t: float, factor_ode1: float):
        import exudyn as exu

        if self._last is not None and t > self._last:
            self.lives.append((t - self._last) / self.step)
        self._last = t
        if self._layout is None:
            self._place(mbs)
        triplets = [np.zeros((0, 3))]
        shift = 0.5 * self.life * self.step
        if shift > 0.0:
            for u, scratch, (entries, rows, cols, signs) in zip(self.updaters, self._scratch, self._layout,
                                                                strict=True):
                moved = u.buffer_at(u.time + shift, scratch)
                delta = signs * (moved[entries] - u.buffer[entries])
                triplets.append(np.column_stack([rows, cols, delta]))
        out = exu.MatrixContainer()
        out.SetWithSparseMatrixCSR(self._size, self._size, np.vstack(triplets), useDenseMatrix=False)
        return out
