"""The linear joints' equations in ground or body axes (``[joints_assumed] joint_axes``): Newton iterations and cost.

Run: nice -n 5 python benchmarks/bench_joint_axes.py [--cases model7] [--repeat 3]               (full Table 5 case)
     nice -n 5 python benchmarks/bench_joint_axes.py --ramp 0.002 --window 0.01 0.03           (quick, full speed)

The two settings give the same solution (flexgear.mbs.joints.body_axes_form is an exact row transformation;
tests/test_joint_axes.py); they differ in which columns of each joint turn with the spin, which the modified
Newton method's kept Jacobian sees. Per case and setting, rounds interleaved: CPU per step, Newton iterations
and Jacobians per step over the window (speed_common.measure_window), medians, and the ratio body / ground.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from speed_common import figure_line, load_average, measure_window, median, ratio_line, shortened

from flexgear.spec import Variant, load_variant

ROOT = Path(__file__).resolve().parents[1]
AXES = ("ground", "body")


def with_axes(variant: Variant, axes: str) -> Variant:
    """``variant`` with ``[joints_assumed] joint_axes = axes``."""
    return dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("joints_assumed", joint_axes=axes))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["model7"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ramp", type=float, default=None, help="shorten the ramps to this [s] (default: Table 5's)")
    ap.add_argument("--window", type=float, nargs=2, default=None, metavar=("START", "END"),
                    help="measured window [s] (default: the whole run)")
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    a = ap.parse_args()
    variants = {c: load_variant(Path(a.variants_dir) / f"{c}.toml") for c in a.cases}
    lc = next(iter(variants.values())).gearbox.load_case
    window = (float(a.window[0]), float(a.window[1])) if a.window else (lc.step_size_s, lc.end_time_s)
    if a.ramp is not None:
        variants = {c: shortened(v, a.ramp, window[1]) for c, v in variants.items()}
    print(f"bench_joint_axes: window {window[0]:g}-{window[1]:g} s; {load_average()}", flush=True)
    results = {(c, x): [] for c in variants for x in AXES}
    for r in range(a.repeat):
        for c, v in variants.items():
            for x in AXES if r % 2 == 0 else AXES[::-1]:
                results[c, x].append(measure_window(with_axes(v, x), window))
                us, it, jac = results[c, x][-1]
                print(f"  round {r + 1} {c} {x:<7s} {us:8.1f} us/step  {it:5.2f} it/step  {jac:5.1f} Jac/1000 steps",
                      flush=True)
    for c in variants:
        for x in AXES:
            vals = results[c, x]
            print(figure_line(f"{c} {x} [us/step]", [v[0] for v in vals], "us"))
            print(f"{'':<44s} Newton iterations per step, median {median([v[1] for v in vals]):.2f}; "
                  f"Jacobians per 1000 steps, median {median([v[2] for v in vals]):.1f}")
        print(ratio_line(f"{c} body / ground", [v[0] for v in results[c, "body"]],
                         [v[0] for v in results[c, "ground"]]))
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
