"""Where does a multibody run spend its time: Exudyn's CPU-time statistics per solver part, Newton iterations and
Jacobians per step, and the Python functions (cProfile)?

Run: nice -n 5 python benchmarks/profile_mbs.py model1 [floor] [model7] [--t-end 0.02] [--cprofile]
     [--trace-newton 6] [--blas-threads 2] [--frozen contacts joints] [--held BODY ...]
     [--midlife on|off|both] [--rounds 3]

Each case is built as flexgear.mbs.run.run_variant builds it (``floor``: model 1 with a constant mesh
stiffness and no friction, bench_speed.floor_variant), warmed with a 1e-4 s run, then solved as a run solves it
(the production formulation's Jacobian economy and, with flexible bodies, warm-started multipliers; the collector's
generations frozen) with Exudyn's timers on (``timeIntegration.verboseMode``/``displayComputationTime``). Printed
per case: every non-zero timer's share applied to the solve's CPU time, in seconds and microseconds per step (the
``Python`` timer is the pre-step and pre-Newton user functions), Newton iterations and Jacobians per step; with
``--cprofile`` the top Python functions. ``--blas-threads 2`` shows what BLAS threads cost the build.
``--frozen contacts joints``: the flexible gears' contact columns (flexgear.mbs.contact_kinematics.ContactKinematics)
and the turning joints' coefficients (flexgear.mbs.joints.TurningBlocks) written at the first step only (wrong physics:
a bound on what the Newton iterations and Jacobians that their change from step to step costs).
``--held BODY ...``: the same bound for the named bodies only (shell patterns: ``'planet*'``): their contact columns
and the turning joints' and seats' blocks on them keep their first-step values (a joint is held when either of its
bodies is).
``--midlife off``: without the production's mid-life Jacobian (flexgear.mbs.newton.MidlifeJacobian); ``both``: each
case with and without it, side by side in every round; ``--rounds``: rounds, the medians of CPU per step printed last.
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import gc
import io
import pstats
import re
import sys
import time
import warnings
from collections.abc import Sequence
from fnmatch import fnmatch
from pathlib import Path

from bench_speed import floor_variant, load_average, shortened

from flexgear.mbs.gearbox import build_star_gearbox
from flexgear.mbs.newton import JacobianEconomy, MidlifeJacobian, MultiplierWarmStart, turning_updaters, warm_starts
from flexgear.mbs.recording import add_gearbox_sensors, simulation_settings
from flexgear.spec import load_variant

ROOT = Path(__file__).resolve().parents[1]


def solve(variant, t_end: float, timers: bool, profile: bool, trace: bool = False, midlife: bool = True,
          held: Sequence[str] = ()) -> tuple[str, float, float]:
    """Build and solve; returns Exudyn's printed statistics, wall and CPU time of the solve."""
    import exudyn as exu

    mbs = exu.SystemContainer().AddSystem()
    b0, bc0 = time.perf_counter(), time.process_time()
    model = build_star_gearbox(mbs, variant)
    add_gearbox_sensors(mbs, model)
    mbs.Assemble()
    if timers:
        print(f"  build: wall {time.perf_counter() - b0:.2f} s, cpu {time.process_time() - bc0:.2f} s")
    sv = variant.gearbox.solver_assumed
    warm = warm_starts(model.bodies.values(), sv.reference)
    settings = simulation_settings(variant, t_end, False, warm)
    if timers:
        settings.timeIntegration.verboseMode = 2 if trace else 1  # 2: every Newton iteration's residual
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            settings.displayComputationTime = True
            settings.displayStatistics = True
    if held:
        hold_bodies(mbs, held)
    if not sv.reference:  # as flexgear.mbs.run's post-step guard drives it
        economy = JacobianEconomy(sv.jacobian_cost_iterations)
        mbs.SetPostStepUserFunction(lambda mbs, t: economy(mbs) or True)
        updaters = turning_updaters(mbs)
        if midlife and updaters:
            mbs.SetSystemJacobianUserFunction(MidlifeJacobian(updaters, variant.gearbox.load_case.step_size_s))
    if warm:
        mbs.SetPreNewtonResidualUserFunction(MultiplierWarmStart())
    prof = cProfile.Profile() if profile else None
    gc.collect()
    gc.freeze()  # as flexgear.mbs.run solves: the collector does not walk the built model every few steps
    w0, c0 = time.perf_counter(), time.process_time()
    with _captured_stdout() as out:
        if prof:
            prof.enable()
        mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.GeneralizedAlpha, storeSolver=True)
        if prof:
            prof.disable()
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    gc.unfreeze()
    text = out.getvalue()
    if prof:
        s = io.StringIO()
        pstats.Stats(prof, stream=s).sort_stats("tottime").print_stats(12)
        text += s.getvalue()
    return text, wall, cpu


def _frozen_classes() -> dict:
    from flexgear.mbs.contact_kinematics import ContactKinematics
    from flexgear.mbs.joints import TurningBlocks

    return {"contacts": ContactKinematics, "joints": TurningBlocks}


def hold_bodies(mbs, patterns: Sequence[str]) -> None:
    """The turning coefficients of the bodies matching ``patterns`` at their first-step values (``--held``): their
    spin per drive angle set to zero in the contact columns (flexgear.mbs.contact_kinematics.ContactKinematics) and in
    the blocks of the joints and seats whose constraint names them (flexgear.mbs.joints.TurningBlocks)."""
    import numpy as np

    from flexgear.mbs.contact_kinematics import ContactKinematics
    from flexgear.mbs.joints import TurningBlocks

    def named(name: str) -> bool:
        return any(fnmatch(name, f) for p in patterns for f in (p, f"{p}_*", f"*_{p}_*", f"*_{p}"))

    for u in turning_updaters(mbs):
        if isinstance(u, ContactKinematics):
            u.spin[[named(b) for b in u.bodies]] = 0.0  # the compiled kernel reads this array
        elif isinstance(u, TurningBlocks):
            start = 0
            for obj, _, view in u.views:
                if named(mbs.GetObject(obj)["name"]):
                    u.spin[start:start + view.shape[1]] = 0.0
                start += view.shape[1]
            u.spins, u.spin_index = np.unique(u.spin, return_inverse=True)
            u._args = (u.ramp_time, u.drive_speed, u.const, u.cos_part, u.sin_part, u.spin_index, u.spins, u.target)


def freeze_after_first_step(cls) -> None:
    """Make the pre-step ``cls.__call__`` act at each object's first step only (``--frozen``)."""
    update = cls.__call__

    def first_only(self, mbs, t):
        if getattr(self, "_written", False):
            return True
        self._written = True
        return update(self, mbs, t)

    cls.__call__ = first_only


@contextlib.contextmanager
def _captured_stdout():
    """Exudyn prints from C++ through Python's sys.stdout: collect it."""
    buf, old = io.StringIO(), sys.stdout
    sys.stdout = buf
    try:
        yield buf
    finally:
        sys.stdout = old


def summary(text: str, steps: int, cpu: float) -> list[str]:
    """The timer lines as CPU seconds and microseconds per step, Newton counts per step.

    Exudyn's timers measure wall time; on a shared machine that includes waiting for a core, so
    each timer's share of the measured time is applied to the process's CPU time of the solve.
    """
    total = re.search(r"total time\s*=\s*([\d.eE+-]+)", text)
    lines = []
    if total:
        t = cpu
        for name, pct in re.findall(r"^\s*(\w+)\s*=\s*([\d.eE+-]+)%", text, flags=re.M):
            sec = t * float(pct) / 100
            if sec > 1e-3 * t:
                lines.append(f"  {name:<20s} {sec:8.3f} s  {1e6 * sec / steps:8.1f} us/step  {float(pct):5.1f} %")
    for label, key in (("Newton iterations", "Newton iterations"), ("Jacobians", "Newton Jacobians")):
        m = re.search(rf"{key}:\s*(\d+)", text)
        if m:
            lines.append(f"  {label:<20s} {int(m.group(1)):8d}    {int(m.group(1)) / steps:8.3f} per step")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases", nargs="+", help="variant names in model_variants/ (model1, model7, ...) or 'floor'")
    ap.add_argument("--t-end", type=float, default=0.02)
    ap.add_argument("--cprofile", action="store_true")
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    ap.add_argument("--ramp", type=float, default=None,
                    help="shorten the ramps to this [s] (profile at full speed: 0.005 with --t-end 0.02)")
    ap.add_argument("--trace-newton", type=int, default=0, metavar="STEPS",
                    help="print Exudyn's Newton residuals and contractions of the last STEPS steps (verboseMode 2; "
                         "the timers then include the printing)")
    ap.add_argument("--blas-threads", type=int, default=1,
                    help="BLAS threads during build and solve (flexgear.mbs.run.run_variant uses 1)")
    ap.add_argument("--frozen", nargs="+", choices=("contacts", "joints"), default=(),
                    help="write these constraint coefficients at the first step only (a cost bound, wrong physics)")
    ap.add_argument("--held", nargs="+", default=(), metavar="BODY",
                    help="hold the turning coefficients of these bodies only (shell patterns; a bound, wrong physics)")
    ap.add_argument("--midlife", choices=("on", "off", "both"), default="on",
                    help="the mid-life Jacobian (production: on); both: each case with and without it")
    ap.add_argument("--rounds", type=int, default=1, help="rounds over the cases (medians printed last)")
    a = ap.parse_args()
    from threadpoolctl import threadpool_limits

    for name in a.frozen:
        freeze_after_first_step(_frozen_classes()[name])

    threadpool_limits(limits=a.blas_threads, user_api="blas")
    folder = Path(a.variants_dir)
    print(f"profile_mbs: t_end {a.t_end} s; {load_average()}", flush=True)
    modes = {"on": (True,), "off": (False,), "both": (True, False)}[a.midlife]
    per_step: dict[str, list[float]] = {}
    for _, case, midlife in ((r, c, m) for r in range(a.rounds) for c in a.cases for m in modes):
        variant = floor_variant(load_variant(folder / "model1.toml")) if case == "floor" else \
            load_variant(folder / f"{case}.toml")
        if a.ramp is not None:
            variant = shortened(variant, a.ramp, max(a.t_end, a.ramp))
        solve(variant, 1e-4, False, False, midlife=midlife, held=a.held)
        text, wall, cpu = solve(variant, a.t_end, True, a.cprofile, a.trace_newton > 0, midlife, a.held)
        if len(modes) > 1:
            case = f"{case} (mid-life Jacobian {'on' if midlife else 'off'})"
        if a.trace_newton:
            lines = [ln for ln in text.splitlines() if "initial residual" in ln or "NEWTON STEP" in ln]
            starts = [k for k, ln in enumerate(lines) if "initial residual" in ln]
            print("\n".join(lines[starts[-a.trace_newton]:] if len(starts) >= a.trace_newton else lines))
        steps = round(a.t_end / variant.gearbox.load_case.step_size_s)
        print(f"{case}: solve wall {wall:.2f} s, cpu {cpu:.2f} s ({1e6 * cpu / steps:.1f} us/step cpu); "
              f"{load_average()}")
        print("\n".join(summary(text, steps, cpu)))
        per_step.setdefault(case, []).append(1e6 * cpu / steps)
        if a.cprofile:
            print(text[text.find("Ordered by"):])
    if a.rounds > 1:
        for case, values in per_step.items():
            print(f"median of {len(values)} rounds: {case} {sorted(values)[len(values) // 2]:.1f} us/step cpu "
                  f"({', '.join(f'{v:.1f}' for v in values)})")


if __name__ == "__main__":
    main()
