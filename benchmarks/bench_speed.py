"""Benchmark (issue 16): model 1, the floor, model 7 and their ratios, medians of three runs in one run.

Run: nice -n 5 python benchmarks/bench_speed.py [--t-end 0.6] [--repeat 3] [--variants-dir model_variants]
     [--updates exudyn economy]

- model 1: the all-rigid variant, full Table 5 load case (0.6 s at h = 1e-5 s), warm caches;
- floor: model 1 with ``stiffness_variation = "constant"`` and a zero friction coefficient
  (benchmarks/speed_common.floor_variant): the cost of this formulation without the per-step updates;
- model 7: all components flexible.

Each case is warmed first (a 1e-4 s run: meshes, reduced bodies and compiled kernels cached), then the
rounds interleave model 1, floor and model 7 so that the machine's load hits them alike. Printed per
case: each run's wall time (build + solve, as flexgear.mbs.run.run_variant reports it), solve-only wall
time (wall - build) and CPU time, with medians; then the ratios model7/model1 (goal <= 6) and
model1/floor (goal <= 1.2), and the load average before and after. ``--t-end`` shortens the runs.
``--updates`` runs every case with each Jacobian policy (``[solver_assumed] jacobian_updates``,
flexgear.mbs.newton) side by side, the ratios per policy; without it, the variants' own.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from speed_common import figure_line, floor_variant, load_average, ratio_line, with_jacobian_updates

from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=None, help="simulated time [s] (default: the load case's)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    ap.add_argument("--cases", nargs="+", default=["model1", "floor", "model7"],
                    choices=["model1", "floor", "model7"])
    ap.add_argument("--updates", nargs="+", default=None, choices=["exudyn", "economy"],
                    help="Jacobian policies to compare (default: the variants' own)")
    a = ap.parse_args()
    folder = Path(a.variants_dir)
    model1 = load_variant(folder / "model1.toml")
    chosen = {"model1": model1, "floor": floor_variant(model1), "model7": load_variant(folder / "model7.toml")}
    chosen = {k: chosen[k] for k in a.cases}
    suffixes = [f"[{u}]" for u in a.updates] if a.updates else [""]
    variants = {}
    for suffix, updates in zip(suffixes, a.updates or [None], strict=True):
        for k, v in chosen.items():
            variants[k + suffix] = v if updates is None else with_jacobian_updates(v, updates)
    t_end = a.t_end if a.t_end is not None else model1.gearbox.load_case.end_time_s
    print(f"bench_speed: t_end {t_end} s, step {model1.gearbox.load_case.step_size_s} s, {a.repeat} rounds; "
          f"{load_average()}", flush=True)
    for name, v in variants.items():
        r = run_variant(v, t_end_s=1e-4)
        if not r.ok:
            sys.exit(f"{name}: warm-up failed: {r.meta['reason']}")
    wall: dict[str, list[float]] = {k: [] for k in variants}
    solve = {k: [] for k in variants}
    cpu = {k: [] for k in variants}
    for i in range(a.repeat):
        for name, v in variants.items():
            r = run_variant(v, t_end_s=t_end)
            if not r.ok:
                sys.exit(f"{name}: run failed: {r.meta['reason']}")
            m = r.meta
            wall[name].append(m["wall_time_s"])
            solve[name].append(m["wall_time_s"] - m["build_time_s"])
            cpu[name].append(m["cpu_time_s"])
            print(f"round {i + 1} {name}: wall {m['wall_time_s']:.2f} s (build {m['build_time_s']:.2f} s), "
                  f"cpu {m['cpu_time_s']:.2f} s; {load_average()}", flush=True)
    print()
    for name in variants:
        print(figure_line(f"{name} wall [s]", wall[name]))
        print(figure_line(f"{name} solve-only wall [s]", solve[name]))
        print(figure_line(f"{name} cpu [s]", cpu[name]))
    for suffix in suffixes:
        for num, den, goal in (("model7", "model1", "<= 6"), ("model1", "floor", "<= 1.2")):
            num, den = num + suffix, den + suffix
            if num in variants and den in variants:
                print(ratio_line(f"{num}/{den} wall", wall[num], wall[den], goal))
                print(ratio_line(f"{num}/{den} solve-only wall", solve[num], solve[den], goal))
                print(ratio_line(f"{num}/{den} cpu", cpu[num], cpu[den], goal))
    for name in variants:
        if any(s and name.endswith(s) for s in suffixes[1:]):  # each policy's run against the first policy's
            base = name[:name.index("[")] + suffixes[0]
            print(ratio_line(f"{name}/{base} cpu", cpu[name], cpu[base]))
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
