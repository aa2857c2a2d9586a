"""Benchmark (issue 16): the per-step Python of a run's pre-step user function, timed alone.

Run: nice -n 5 python benchmarks/bench_prestep.py [--cases model1 floor model7] [--number 20000] [--repeat 7]

Whole runs on a shared machine spread by ±20 % between rounds, more than the per-step Python that
separates model 1 from its floor (benchmarks/bench_speed.py). This script builds each case as
flexgear.mbs.run.run_variant does, solves it for a few steps past its ramps (so that the pre-step
function is bound and in its steady state), then calls that function alone ``number`` times at one
steady time and prints the fastest of ``repeat`` such loops in µs per call (the least disturbed
loop; load only adds time), with the load average. ``floor``: model 1 with a constant mesh stiffness and
no friction (benchmarks/speed_common.floor_variant). The difference model 1 - floor is the per-step price
of the mesh-stiffness variation and tooth friction.
"""

from __future__ import annotations

import argparse
import dataclasses
import timeit
from pathlib import Path

from speed_common import floor_variant, load_average

from flexgear.mbs.gearbox import build_star_gearbox
from flexgear.mbs.recording import simulation_settings
from flexgear.spec import load_variant

ROOT = Path(__file__).resolve().parents[1]


def pre_step_cost(variant, number: int, repeat: int) -> tuple[float, str]:
    """Fastest loop's µs per call of the steady pre-step function, and its composition."""
    import exudyn as exu

    lc = variant.gearbox.load_case
    ramp = 2e-4  # short ramps: the steady state after a few steps
    short = dataclasses.replace(variant, gearbox=variant.gearbox.with_changes(
        load_case=dataclasses.replace(lc, ramp_time_s=ramp, end_time_s=ramp + 20 * lc.step_size_s)))
    mbs = exu.SystemContainer().AddSystem()
    build_star_gearbox(mbs, short)
    mbs.Assemble()
    was = exu.config.printToConsole
    exu.config.printToConsole = False
    try:
        mbs.SolveDynamic(simulation_settings(short, short.gearbox.load_case.end_time_s, False),
                         solverType=exu.DynamicSolverType.GeneralizedAlpha)
    finally:
        exu.config.printToConsole = was
    entry = mbs.GetPreStepUserFunction()
    function = entry["function"] if isinstance(entry, dict) else entry
    parts = [type(f).__name__ for f in getattr(function, "functions", [function])]
    t = short.gearbox.load_case.end_time_s
    best = min(timeit.repeat(lambda: function(mbs, t), number=number, repeat=repeat)) / number
    return best * 1e6, f"{type(function).__name__}: {', '.join(parts)}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["model1", "floor"], choices=["model1", "floor", "model7"])
    ap.add_argument("--number", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    a = ap.parse_args()
    folder = Path(a.variants_dir)
    model1 = load_variant(folder / "model1.toml")
    variants = {"model1": model1, "floor": floor_variant(model1)}
    if "model7" in a.cases:
        variants["model7"] = load_variant(folder / "model7.toml")
    print(f"bench_prestep: fastest of {a.repeat} loops of {a.number} calls; {load_average()}", flush=True)
    cost = {}
    for name in a.cases:
        cost[name], parts = pre_step_cost(variants[name], a.number, a.repeat)
        print(f"{name:<8s} pre-step {cost[name]:8.3f} µs per step   ({parts})", flush=True)
    if {"model1", "floor"} <= cost.keys():
        print(f"model1 - floor: {cost['model1'] - cost['floor']:.3f} µs per step", flush=True)
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
