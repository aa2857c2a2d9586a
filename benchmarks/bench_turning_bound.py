"""What model 7 would cost with no coefficient turning with the spin: the ceiling of a stationary-frame formulation.

Run: nice -n 5 python benchmarks/bench_turning_bound.py [--repeat 3] [--groups]                (full Table 5 case)
     nice -n 5 python benchmarks/bench_turning_bound.py --ramp 0.002 --window 0.01 0.03 --groups  (quick, full speed)

Issue 16 asks for model 7 at most 6x model 1. Model 7's linear joints and seats (flexgear.mbs.joints.TurningBlocks)
and its modal contact columns (flexgear.mbs.contact_kinematics.ContactKinematics) are rewritten before every step:
their coefficients turn with the spin, so the modified Newton method's Jacobian goes stale and each step needs
more iterations than model 1's. A formulation whose coordinates do not turn (a stationary frame for the
axisymmetric parts, the lever sessions 6-12 named) could at best remove that. This script measures that best
case on the same coordinates, constraints, bodies and contact laws: the pre-step functions are frozen at their
first call (t = 0), so every coefficient keeps its initial value. **That is wrong physics** (a frozen joint ties
the turning body's interface to a fixed direction), used only as a bound on the cost: the same sparse system,
the same contact laws, no turning.

Cases per round (rounds interleave them), each a run of ``flexgear.mbs.run.run_variant``: by default the full
Table 5 load case measured over the whole run (bench_speed.py's figure); with ``--ramp`` [s] the ramps shortened and
the run measured over ``--window`` [s] at full speed. Per case: CPU per step, Newton iterations and Jacobians per
step in the window (the run's post-step function, RunGuard, wrapped to read the clock and the solver's counts):

- ``model1``: the reference of the ratio;
- ``model7``: as it runs;
- ``model7_joints_frozen``: the joints' and seats' coefficients frozen;
- ``model7_contacts_frozen``: the modal contact columns frozen;
- ``model7_all_frozen``: the contact columns frozen as well (nothing turns);
- with ``--groups``: model 7 with only one spin's joints and seats turning (sun and input shaft, planets, ring and
  output shaft), to show whether one group alone costs the iterations.

Printed: each figure per round and its median, ratios to model 1 (``speed_common.ratio_line``).
"""

from __future__ import annotations

import argparse
import contextlib
from pathlib import Path

from speed_common import figure_line, load_average, measure_window, median, ratio_line, shortened

from flexgear.mbs.contact_kinematics import ContactKinematics
from flexgear.mbs.joints import TurningBlocks
from flexgear.spec import Variant, load_variant

ROOT = Path(__file__).resolve().parents[1]

GROUPS = {  # spin per drive angle of each co-rotating group: sun +1, planets -44/45, ring -44/136 (star gearbox)
    "sun": lambda spin: spin > 0.0,
    "planets": lambda spin: spin < -0.5,
    "ring": lambda spin: -0.5 < spin < 0.0,
}


def _once_at_zero(call):
    """A pre-step function that does its work once, at t = 0, and nothing after (a cost bound, wrong physics)."""
    def frozen(self, mbs, t):
        if getattr(self, "_bound_done", False):
            return True
        self._bound_done = True
        return call(self, mbs, 0.0)
    return frozen


@contextlib.contextmanager
def _frozen(classes: tuple[type, ...] = (), keep_turning=None):
    """The pre-step functions of ``classes`` frozen at t = 0; ``keep_turning(spin)``: TurningBlocks keep only the
    entries of those spins (the others stay at their initial coefficients)."""
    saved = {cls: (cls.__init__, cls.__call__) for cls in (TurningBlocks, ContactKinematics)}
    try:
        for cls in classes:
            cls.__call__ = _once_at_zero(saved[cls][1])
        if keep_turning is not None:
            init = saved[TurningBlocks][0]
            TurningBlocks.__init__ = lambda self, entries, *rest: init(
                self, [e for e in entries if keep_turning(e[5])], *rest)
        yield
    finally:
        for cls, (init, call) in saved.items():
            cls.__init__, cls.__call__ = init, call


def measure(variant: Variant, window: tuple[float, float], classes=(), keep_turning=None) -> tuple[float, float, float]:
    """speed_common.measure_window with ``classes`` frozen and only ``keep_turning`` spins turning (:func:`_frozen`)."""
    with _frozen(classes, keep_turning):
        return measure_window(variant, window)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ramp", type=float, default=None, help="shorten the ramps to this [s] (default: Table 5's)")
    ap.add_argument("--window", type=float, nargs=2, default=None, metavar=("START", "END"),
                    help="measured window [s] (default: the whole run)")
    ap.add_argument("--groups", action="store_true", help="also model 7 with one group's joints and seats turning")
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    a = ap.parse_args()
    folder = Path(a.variants_dir)
    m1, m7 = (load_variant(folder / f"{n}.toml") for n in ("model1", "model7"))
    lc = m1.gearbox.load_case
    window = (float(a.window[0]), float(a.window[1])) if a.window else (lc.step_size_s, lc.end_time_s)
    if a.ramp is not None:
        m1, m7 = (shortened(v, a.ramp, window[1]) for v in (m1, m7))
    cases = {"model1": (m1, (), None), "model7": (m7, (), None),
             "model7_joints_frozen": (m7, (TurningBlocks,), None),
             "model7_contacts_frozen": (m7, (ContactKinematics,), None),
             "model7_all_frozen": (m7, (TurningBlocks, ContactKinematics), None)}
    if a.groups:
        for g, sel in GROUPS.items():
            cases[f"model7_only_{g}_turning"] = (m7, (), sel)
    ramp = m1.gearbox.load_case.ramp_time_s
    print(f"bench_turning_bound: ramp {ramp} s, window {window[0]:g}-{window[1]:g} s; {load_average()}",
          flush=True)
    results: dict[str, list[tuple[float, float, float]]] = {k: [] for k in cases}
    for r in range(a.repeat):
        for name, (variant, classes, keep) in cases.items():
            results[name].append(measure(variant, window, classes, keep))
            us, it, jac = results[name][-1]
            print(f"  round {r + 1} {name:<28s} {us:8.1f} us/step  {it:5.2f} it/step  {jac:5.1f} Jac/1000 steps",
                  flush=True)
    print("CPU per step over the window [us]:")
    for name, vals in results.items():
        print(figure_line(name, [v[0] for v in vals], "us"))
        print(f"{'':<44s} Newton iterations per step, median {median([v[1] for v in vals]):.2f}; "
              f"Jacobians per 1000 steps, median {median([v[2] for v in vals]):.1f}")
    ref = [v[0] for v in results["model1"]]
    for name in cases:
        if name != "model1":
            goal = "6 (issue 16)" if name != "model7" else "6 (issue 16; as it runs)"
            print(ratio_line(f"{name} / model1", [v[0] for v in results[name]], ref, goal))
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
