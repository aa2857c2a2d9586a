"""How fast do the variants run: model 7 against model 1 (goal <= 6), model 1 against its floor (goal <= 1.2), the
matrix's workers against its single runs (goal <= 0.55), and each variant's full load case against theory?

Run: nice -n 5 python benchmarks/bench_speed.py [ratios] [--t-end 0.6] [--repeat 3] [--updates reference production]
     nice -n 5 python benchmarks/bench_speed.py matrix [--t-end 0.6] [--repeat 3] [--workers 2] [model*.toml ...]
     nice -n 5 python benchmarks/bench_speed.py variants [--t-end 0.6] [--out results/bench] [model*.toml ...]

- ``ratios``: model 1 (all rigid, the full Table 5 load case), its floor (:func:`floor_variant`: a constant mesh
  stiffness and no friction, the formulation without its per-step updates) and model 7 (all flexible). Each case
  is warmed first (a 1e-4 s run: meshes, reduced bodies and compiled kernels cached), then the rounds interleave
  the cases so that the machine's load hits them alike. Printed per case: each run's wall time (build + solve, as
  flexgear.mbs.run.run_variant reports it), solve-only wall time and CPU time with medians, then the ratios
  (:func:`ratio_line`). ``--updates`` runs every case in each formulation (``[solver_assumed]
  formulation``: production or reference) side by side.
- ``matrix``: per round every variant run alone, one after the other, in this process, their wall times summed;
  then the whole matrix (flexgear.study.matrix.run_matrix: worker processes, saving, screening) into a fresh
  temporary folder, its wall time from call to return; the ratio matrix / sum. On a shared 2-core machine the
  parallel gain depends on the cores the other users leave free.
- ``variants``: every variant once over its load case, caches warmed first: wall and CPU time beside the study's
  ADAMS times (its Table 4), and the steady values against theory (output speed, mean mesh forces, transmission
  error over the last tenth of the run); printed and written as CSV to ``--out``.

Every figure of ``ratios`` and ``matrix`` is measured ``--repeat`` times within one run and reported as its median;
the load average is printed before and after. The other scripts of this folder import the helpers below.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from flexgear.spec import Variant, load_variant

ROOT = Path(__file__).resolve().parents[1]
ADAMS_S = {"model1": 371, "model2": 17948, "model3": 507, "model4": 34903, "model5": 11745, "model6": 35662,
           "model7": 42955}  # the study's Table 4: ADAMS run times [s]


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
    """The formulation's floor: ``variant`` with a constant mesh stiffness and no friction.

    Same bodies, contacts, solver and load case; only ``contact_assumed.stiffness_variation = "constant"`` and
    ``contact.friction_coefficient = 0``.
    """
    gb = variant.gearbox
    for table, fld in (("contact_assumed", "stiffness_variation"), ("contact", "friction_coefficient")):
        if not hasattr(getattr(gb, table, None), fld):
            raise SystemExit(f"floor variant: the gearbox spec has no field '{table}.{fld}' any more; "
                             "update benchmarks/bench_speed.floor_variant")
    gb = gb.with_changes(
        contact_assumed=dataclasses.replace(gb.contact_assumed, stiffness_variation="constant"),
        contact=dataclasses.replace(gb.contact, friction_coefficient=0.0))
    return dataclasses.replace(variant, gearbox=gb, name=f"{variant.name}_floor")


def with_formulation(variant: Variant, formulation: str) -> Variant:
    """``variant`` with ``[solver_assumed] formulation`` ("production" or "reference")."""
    return dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("solver_assumed", formulation=formulation))


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


def _run(variant: Variant, t_end: float | None, what: str):
    from flexgear.mbs.run import run_variant

    r = run_variant(variant, t_end_s=t_end)
    if not r.ok:
        sys.exit(f"{variant.name}: {what} failed: {r.meta['reason']}")
    return r


def ratios(a: argparse.Namespace) -> None:
    folder = Path(a.variants_dir)
    model1 = load_variant(folder / "model1.toml")
    chosen = {"model1": model1, "floor": floor_variant(model1), "model7": load_variant(folder / "model7.toml")}
    chosen = {k: chosen[k] for k in a.cases}
    suffixes = [f"[{u}]" for u in a.updates] if a.updates else [""]
    variants = {}
    for suffix, updates in zip(suffixes, a.updates or [None], strict=True):
        for k, v in chosen.items():
            variants[k + suffix] = v if updates is None else with_formulation(v, updates)
    t_end = a.t_end if a.t_end is not None else model1.gearbox.load_case.end_time_s
    print(f"bench_speed ratios: t_end {t_end} s, step {model1.gearbox.load_case.step_size_s} s, {a.repeat} rounds; "
          f"{load_average()}", flush=True)
    for v in variants.values():
        _run(v, 1e-4, "warm-up")
    wall: dict[str, list[float]] = {k: [] for k in variants}
    solve = {k: [] for k in variants}
    cpu = {k: [] for k in variants}
    for i in range(a.repeat):
        for name, v in variants.items():
            m = _run(v, t_end, "run").meta
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


def matrix(a: argparse.Namespace) -> None:
    from flexgear.study.matrix import run_matrix

    variants = [load_variant(p) for p in a.variants]
    print(f"bench_speed matrix: {len(variants)} variants, t_end {a.t_end or 'load case'}, {a.workers} workers, "
          f"{a.repeat} rounds; {load_average()}", flush=True)
    for v in variants:
        _run(v, 1e-4, "warm-up")
    sums, matrix_walls = [], []
    for i in range(a.repeat):
        walls = [_run(v, a.t_end, "run").meta["wall_time_s"] for v in variants]
        sums.append(sum(walls))
        print(f"round {i + 1} singles: " + ", ".join(f"{v.name} {w:.1f}" for v, w in zip(variants, walls, strict=True))
              + f" -> sum {sums[-1]:.1f} s; {load_average()}", flush=True)
        with tempfile.TemporaryDirectory(prefix="flexgear-bench-matrix-") as out:
            t0 = time.perf_counter()
            table = run_matrix(a.variants, out, t_end_s=a.t_end, workers=a.workers, progress=False)
            matrix_walls.append(time.perf_counter() - t0)
        failed = table.loc[table.status != "ok", "variant"].tolist()
        if failed:
            sys.exit(f"matrix: failed variants {failed}")
        print(f"round {i + 1} matrix ({a.workers} workers): {matrix_walls[-1]:.1f} s; {load_average()}", flush=True)
    print()
    print(figure_line("sum of single runs [s]", sums))
    print(figure_line(f"matrix, {a.workers} workers [s]", matrix_walls))
    print(ratio_line("matrix / sum of single runs", matrix_walls, sums, "<= 0.55"))


def variants_table(a: argparse.Namespace) -> None:
    import pandas as pd

    from flexgear.cache import atomic_write_bytes
    from flexgear.mbs.run import run_variant
    from flexgear.results import save_result

    rows = []
    for path in a.variants:
        v = load_variant(path)
        run_variant(v, t_end_s=1e-4)  # warm the caches (meshes, reduced bodies, compiled kernels)
        r = run_variant(v, t_end_s=a.t_end)
        save_result(r, Path(a.out) / v.name)
        row = {"variant": v.name, "status": r.meta["status"], "wall_s": r.meta["wall_time_s"],
               "cpu_s": r.meta["cpu_time_s"], "adams_s": ADAMS_S.get(v.name)}
        if r.ok:
            s, th = r.signals, r.meta["theory"]
            w = s[s.time_s >= 0.9 * s.time_s.iloc[-1]]
            row["output_speed_err_pct"] = 100 * (w.output_speed_rad_per_s.mean() / th["output_speed_rad_per_s"] - 1)
            for kind in ("outer", "inner"):
                forces = [c for c in w.columns if c.startswith(f"{kind}_mesh_force")]
                row[f"{kind}_force_n"] = w[forces].to_numpy().mean()
            row["mesh_force_theory_n"] = th["mesh_force_n"]
            if "transmission_error_m" in w:
                row["te_um"] = 1e6 * w.transmission_error_m.mean()
        else:
            row["reason"] = r.meta["reason"][:200]
        rows.append(row)
        print(pd.DataFrame([row]).to_string(index=False, header=len(rows) == 1), flush=True)
    table = pd.DataFrame(rows)
    atomic_write_bytes(Path(a.out) / "bench_variants.csv", table.to_csv(index=False).encode())
    print(table.to_string(index=False))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("section", nargs="?", default="ratios", choices=["ratios", "matrix", "variants"])
    ap.add_argument("variants", nargs="*", help="matrix, variants: variant files (default: model_variants/model*.toml)")
    ap.add_argument("--t-end", type=float, default=None, help="simulated time [s] (default: the load case's)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"), help="ratios: folder of model1/7.toml")
    ap.add_argument("--cases", nargs="+", default=["model1", "floor", "model7"], choices=["model1", "floor", "model7"])
    ap.add_argument("--updates", nargs="+", default=None, choices=["reference", "production"],
                    help="ratios: Jacobian policies to compare (default: the variants' own)")
    ap.add_argument("--workers", type=int, default=2, help="matrix: worker processes")
    ap.add_argument("--out", default="results/bench", help="variants: folder of the runs and the CSV")
    a = ap.parse_args()
    a.variants = a.variants or sorted(str(p) for p in (ROOT / "model_variants").glob("model*.toml"))
    {"ratios": ratios, "matrix": matrix, "variants": variants_table}[a.section](a)
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
