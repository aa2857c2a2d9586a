"""Shared helpers of the speed benchmarks (issue 16): load average, medians, the floor variant.

Every figure is measured ``repeat`` times within one run of a script and reported as its median; ratios
are ratios of medians measured side by side (rounds interleave the cases, so the machine's load hits
them alike). The machine is shared: the load average is printed before and after.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import statistics
import time
from collections.abc import Sequence

from flexgear.spec import Variant


def load_average() -> str:
    """The 1/5/15-minute load averages and the CPU count, as one line."""
    if not hasattr(os, "getloadavg"):
        return "load average: n/a"
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} on {os.cpu_count()} CPUs"


def median(values: Sequence[float]) -> float:
    return float(statistics.median(values))


def figure_line(name: str, values: Sequence[float], unit: str = "s") -> str:
    """``name``: each run's value and the median."""
    runs = " ".join(f"{v:9.3f}" for v in values)
    return f"{name:<44s} {runs}   median {median(values):9.3f} {unit}"


def ratio_line(name: str, numerator: Sequence[float], denominator: Sequence[float], goal: str = "") -> str:
    """Ratio of the medians, the median of the per-round ratios (same round = same machine load) and the ratio of
    the minima (each case's least disturbed run: a shared machine's load only ever adds time)."""
    per_round = [a / b for a, b in zip(numerator, denominator, strict=True)]
    text = (f"{name:<44s} {median(numerator) / median(denominator):9.3f} (ratio of medians), "
            f"{median(per_round):.3f} (median of per-round ratios), {min(numerator) / min(denominator):.3f} "
            "(ratio of minima)")
    return f"{text}   goal {goal}" if goal else text


def floor_variant(variant: Variant) -> Variant:
    """The formulation's floor (issue 16): ``variant`` with a constant mesh stiffness and no friction.

    Same bodies, contacts, solver and load case; only ``contact_assumed.stiffness_variation =
    "constant"`` and ``contact.friction_coefficient = 0``.
    """
    gb = variant.gearbox
    for table, fld in (("contact_assumed", "stiffness_variation"), ("contact", "friction_coefficient")):
        if not hasattr(getattr(gb, table, None), fld):
            raise SystemExit(f"floor variant: the gearbox spec has no field '{table}.{fld}' any more; "
                             "update benchmarks/speed_common.floor_variant")
    gb = gb.with_changes(
        contact_assumed=dataclasses.replace(gb.contact_assumed, stiffness_variation="constant"),
        contact=dataclasses.replace(gb.contact, friction_coefficient=0.0))
    return dataclasses.replace(variant, gearbox=gb, name=f"{variant.name}_floor")


def with_jacobian_updates(variant: Variant, updates: str) -> Variant:
    """``variant`` with ``[solver_assumed] jacobian_updates = updates`` (flexgear.mbs.newton)."""
    return dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("solver_assumed", jacobian_updates=updates))


def shortened(variant: Variant, ramp: float, t_end: float) -> Variant:
    """``variant`` with its STEP ramps shortened to ``ramp`` [s] and its load case ending at ``t_end`` [s]."""
    gb = variant.gearbox
    lc = dataclasses.replace(gb.load_case, ramp_time_s=ramp, end_time_s=t_end)
    return dataclasses.replace(variant, gearbox=gb.with_changes(load_case=lc))


@contextlib.contextmanager
def solver_marks(times: Sequence[float], step: float):
    """While active, every run's post-step function (flexgear.mbs.run.RunGuard, wrapped) records the CPU clock and
    the solver's running (iterations, Jacobians) counts at the first step at or after each of ``times`` [s] (in
    increasing order): yields the list of those marks, (cpu [s], iterations, Jacobians, t [s])."""
    import flexgear.mbs.run as run_module

    ends = sorted(times)
    marks: list[tuple[float, int, int, float]] = []
    guard_call = run_module.RunGuard.__call__

    def call(guard, mbs, t):
        if len(marks) < len(ends) and t >= ends[len(marks)] - 0.5 * step:
            it = mbs.sys["dynamicSolver"].it
            marks.append((time.process_time(), it.newtonStepsCount, it.newtonJacobiCount, t))
        return guard_call(guard, mbs, t)

    run_module.RunGuard.__call__ = call
    try:
        yield marks
    finally:
        run_module.RunGuard.__call__ = guard_call


def measure_window(variant: Variant, window: tuple[float, float]) -> tuple[float, float, float]:
    """Run ``variant`` (flexgear.mbs.run.run_variant) to ``window[1]``: CPU [us] per step, Newton iterations per step
    and Jacobians per 1000 steps over ``window`` [s]."""
    from flexgear.mbs.run import run_variant

    h = variant.gearbox.load_case.step_size_s
    with solver_marks(window, h) as marks:
        r = run_variant(variant, t_end_s=window[1])
    if not r.ok or len(marks) < 2:
        raise SystemExit(f"{variant.name}: {r.meta.get('reason') or 'window not reached'}")
    (c0, n0, j0, t0), (c1, n1, j1, t1) = marks
    steps = round((t1 - t0) / h)
    return 1e6 * (c1 - c0) / steps, (n1 - n0) / steps, 1e3 * (j1 - j0) / steps
