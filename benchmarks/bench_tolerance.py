"""Newton tolerance against accuracy and cost (issue 16: "Jacobian reuse and fewer Newton iterations").

Run: nice -n 5 python benchmarks/bench_tolerance.py [--cases model1 model4 model7] [--tolerances 1e-6 1e-5 1e-4]
     [--reference 1e-8] [--ramp 0.006] [--t-end 0.024] [--window 0.012]

Each case runs on a shortened load case (ramps ``--ramp``, ``--t-end`` simulated) once with the reference
tolerance (``[solver_assumed] newton_relative_tolerance = --reference``) and once per tolerance. Printed per
run: CPU time of the run, Newton iterations and Jacobians per step (Exudyn's solver statistics), and against the
reference run the worst relative difference of every signal's mean and 1x mesh amplitude over the window
(flexgear.study.agreement, issue 16's rule: 0.1 % and 2 %), the worst signals named.

Exudyn's tolerance is relative to the step's first residual (forces [N] and constraint residuals stacked, L2):
the modified Newton's first iteration reduces it by the Jacobian's age (about 0.006 per step since the last
Jacobian in the flexible variants, whose constraint coefficients turn with the spin), the second by about 1e-3.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

from speed_common import load_average

from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant
from flexgear.study.agreement import signal_agreement
from flexgear.theory import theory

ROOT = Path(__file__).resolve().parents[1]


def shortened(variant, ramp: float, t_end: float, tolerance: float):
    """``variant`` on ramps of ``ramp`` [s] to ``t_end`` [s] with the Newton relative tolerance ``tolerance``."""
    g = variant.gearbox
    g = g.with_fields("load_case", ramp_time_s=ramp, end_time_s=t_end).with_fields(
        "solver_assumed", newton_relative_tolerance=tolerance)
    return dataclasses.replace(variant, gearbox=g)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["model1", "model4", "model7"])
    ap.add_argument("--tolerances", type=float, nargs="+", default=[1e-6, 1e-5, 1e-4])
    ap.add_argument("--reference", type=float, default=1e-8)
    ap.add_argument("--ramp", type=float, default=0.006, help="ramp time [s] of the shortened load case")
    ap.add_argument("--t-end", type=float, default=0.024, help="simulated time [s]")
    ap.add_argument("--window", type=float, default=0.012, help="start [s] of the compared window")
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    a = ap.parse_args()
    print(f"bench_tolerance: ramps {a.ramp} s, {a.t_end} s simulated, window from {a.window} s, reference "
          f"tolerance {a.reference:g}; {load_average()}", flush=True)
    for case in a.cases:  # the runs' CPU includes the build; "solve" = CPU - the build's wall time
        v = load_variant(Path(a.variants_dir) / f"{case}.toml")
        f_mesh = theory(v.gearbox).mesh_frequency
        steps = round(a.t_end / v.gearbox.load_case.step_size_s)
        runs = {}
        for tol in [a.reference, *a.tolerances]:
            c0 = time.process_time()
            run = run_variant(shortened(v, a.ramp, a.t_end, tol))
            cpu = time.process_time() - c0
            if not run.ok:
                print(f"{case} tol {tol:g}: FAILED {run.meta.get('reason')}", flush=True)
                continue
            runs[tol] = run
            m = run.meta
            solve = m["cpu_time_s"] - m["build_time_s"]
            line = (f"{case} tol {tol:8.1e}: cpu {cpu:6.2f} s, solve {solve:.2f} s, Newton "
                    f"{m['newton_iterations'] / steps:.2f} and Jacobians {m['jacobians'] / steps:.3f} per step")
            if tol != a.reference and a.reference in runs:
                agr = signal_agreement(runs[a.reference], run, (a.window, a.t_end), f_mesh)
                t = agr.table
                wm = t["mean_diff"].abs().sort_values(ascending=False).head(2)
                wa = t["amp_diff"].abs().sort_values(ascending=False).head(2)
                line += (f"; worst mean {agr.worst_mean:.1e} ({', '.join(f'{k} {x:.1e}' for k, x in wm.items())}), "
                         f"worst 1x {agr.worst_amplitude:.1e} ({', '.join(f'{k} {x:.1e}' for k, x in wa.items())}); "
                         f"rule {'met' if agr.ok() else 'NOT met'}")
            print(line, flush=True)
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
