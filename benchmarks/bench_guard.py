"""Cost of the divergence guard (flexgear.mbs.run.RunGuard, a Python post-step function called every step).

Run: nice -n 5 python benchmarks/bench_guard.py [--case model1] [--t-end 0.1] [--repeat 3]

The variant is built as run_variant builds it and solved with and without the guard as post-step function,
rounds interleaved; printed: CPU time of each solve, the medians, and the guard's cost per step.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from speed_common import figure_line, load_average, median

from flexgear.mbs.gearbox import build_star_gearbox
from flexgear.mbs.recording import add_gearbox_sensors, simulation_settings
from flexgear.mbs.run import RunGuard
from flexgear.spec import load_variant

ROOT = Path(__file__).resolve().parents[1]


def solve(variant, t_end: float, guarded: bool) -> float:
    """CPU time [s] of one solve of ``variant`` (build excluded)."""
    import math

    import exudyn as exu
    import exudyn.solver as exu_solver

    exu_solver.solverCheckMemoryAllocationsThreshold = math.inf  # as run_variant: the sensors allocate by design
    mbs = exu.SystemContainer().AddSystem()
    model = build_star_gearbox(mbs, variant)
    add_gearbox_sensors(mbs, model)
    mbs.Assemble()
    if guarded:
        mbs.SetPostStepUserFunction(RunGuard(model, variant, t_end, budget_s=1e9))
    c0 = time.process_time()
    mbs.SolveDynamic(simulation_settings(variant, t_end, False), solverType=exu.DynamicSolverType.GeneralizedAlpha)
    return time.process_time() - c0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default="model1")
    ap.add_argument("--t-end", type=float, default=0.1)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    from threadpoolctl import threadpool_limits

    variant = load_variant(ROOT / "model_variants" / f"{a.case}.toml")
    steps = round(a.t_end / variant.gearbox.load_case.step_size_s)
    print(f"bench_guard: {a.case}, {a.t_end} s simulated ({steps} steps); {load_average()}", flush=True)
    times: dict[bool, list[float]] = {False: [], True: []}
    with threadpool_limits(1):
        solve(variant, 1e-4, False)  # warm caches and compiled kernels
        for _ in range(a.repeat):
            for guarded in (False, True):
                times[guarded].append(solve(variant, a.t_end, guarded))
    print(figure_line("solve without the guard, CPU", times[False]))
    print(figure_line("solve with the guard, CPU", times[True]))
    extra = median(times[True]) - median(times[False])
    print(f"guard cost: {1e6 * extra / steps:.2f} us per step ({100 * extra / median(times[False]):+.1f} %); "
          f"{load_average()}")


if __name__ == "__main__":
    main()
