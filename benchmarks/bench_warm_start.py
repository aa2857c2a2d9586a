"""What do warm-started multipliers save, and do they change any signal? Each variant with the production Newton
(flexgear.mbs.newton.MultiplierWarmStart and its absolute tolerance, where the model has flexible bodies) beside
the same run started from zero multipliers at Exudyn's tolerances, and every variant against model 1.

Run: nice -n 5 python benchmarks/bench_warm_start.py [--cases model1 model4 model7] [--t-end 0.6] [--ramp 0.005]
     [--repeat 1]

Each case is warmed first (a 1e-4 s run: meshes, reduced bodies and compiled kernels cached); then per round every
case runs warm-started and zero-started, one after the other, so that the machine's load hits both alike. Printed
per case: CPU time of each run (flexgear.mbs.run.run_variant's ``cpu_time_s``, build and solve), Newton iterations
and Jacobians per step, the ratio warm / zero (bench_speed.ratio_line), the agreement of the two runs over the part
after the ramps (flexgear.study.agreement: worst mean and 1x amplitude differences), and each case's CPU time over
model 1's (when ``model1`` is among the cases). ``--ramp`` shortens the ramps (full speed sooner).
"""

from __future__ import annotations

import argparse
import contextlib
from pathlib import Path

from bench_speed import load_average, median, ratio_line, shortened

import flexgear.mbs.run as run_module
from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant
from flexgear.study.agreement import signal_agreement

ROOT = Path(__file__).resolve().parents[1]


@contextlib.contextmanager
def zero_started():
    """While active, runs start each step from zero multipliers at Exudyn's tolerances (the start before)."""
    saved = run_module.RunGuard.warm_start
    run_module.RunGuard.warm_start = property(lambda self: False)
    try:
        yield
    finally:
        run_module.RunGuard.warm_start = saved


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=[f"model{k}" for k in range(1, 8)])
    ap.add_argument("--t-end", type=float, default=None, help="simulated time [s] (default: the load case's)")
    ap.add_argument("--ramp", type=float, default=None, help="shorten the ramps to this [s]")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    a = ap.parse_args()
    print(f"bench_warm_start: {load_average()}", flush=True)
    variants = {}
    for case in a.cases:
        v = load_variant(Path(a.variants_dir) / f"{case}.toml")
        t_end = a.t_end or v.gearbox.load_case.end_time_s
        v = shortened(v, a.ramp if a.ramp is not None else v.gearbox.load_case.ramp_time_s, t_end)
        run_variant(shortened(v, v.gearbox.load_case.ramp_time_s, 1e-4))  # warm the caches
        variants[case] = v
    cpu = {(c, m): [] for c in variants for m in ("warm", "zero")}
    last = {}
    for r in range(a.repeat):
        for case, v in variants.items():
            for mode in ("warm", "zero"):
                with zero_started() if mode == "zero" else contextlib.nullcontext():
                    run = run_variant(v)
                if not run.ok:
                    raise SystemExit(f"{case} ({mode}) failed: {run.meta.get('reason')}")
                steps = round(v.gearbox.load_case.end_time_s / v.gearbox.load_case.step_size_s)
                cpu[case, mode].append(run.meta["cpu_time_s"])
                last[case, mode] = run
                print(f"round {r + 1} {case:8s} {mode}: cpu {run.meta['cpu_time_s']:8.2f} s, "
                      f"{run.meta['newton_iterations'] / steps:.3f} iterations, {run.meta['jacobians'] / steps:.4f} "
                      "Jacobians per step", flush=True)
    print(f"bench_warm_start: {load_average()}")
    for case, v in variants.items():
        lc = v.gearbox.load_case
        warm, zero = last[case, "warm"], last[case, "zero"]
        agreement = signal_agreement(zero, warm, (lc.ramp_time_s, lc.end_time_s),
                                     zero.meta["theory"]["mesh_frequency_hz"])
        print(ratio_line(f"{case} warm / zero-started, CPU", cpu[case, "warm"], cpu[case, "zero"]))
        print(f"{case:8s} agreement warm against zero-started: worst mean {agreement.worst_mean:.2e}, worst 1x "
              f"amplitude {agreement.worst_amplitude:.2e} ({'within' if agreement.ok() else 'OUTSIDE'} the rule)")
    if "model1" in variants:
        for case in variants:
            for mode in ("warm", "zero"):
                print(ratio_line(f"{case} / model1 ({mode})", cpu[case, mode], cpu["model1", mode]))
        print(f"model1 median CPU: warm {median(cpu['model1', 'warm']):.2f} s, "
              f"zero {median(cpu['model1', 'zero']):.2f} s")


if __name__ == "__main__":
    main()
