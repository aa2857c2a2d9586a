"""Benchmark (issue 16): the lumped model's own RK4 kernel against scipy.integrate.solve_ivp on the same RHS.

Run: nice -n 5 python benchmarks/bench_lumped_scipy.py [--t-end 0.6] [--repeat 3] [--methods RK45 LSODA]
     [--plain-t-end 0.01]

1. Truth: flexgear.lumped.run.run_lumped with 8 RK4 substeps per recorded step (4x ours).
2. Ours: run_lumped as configured ([lumped_assumed] integration_substeps). Its error on the Table 6-7
   values is e_ours = max over Table 6 rows of |x - truth| / |truth| and over Table 7 amplitudes of
   |x - truth| / (the truth's largest amplitude of that bearing) (flexgear.study.compare.compare_results).
3. Matching tolerance: for each solve_ivp method, the loosest tol in 1e-5, 1e-6, ... 1e-10 whose run
   (rtol = tol, atol = tol x state scale: 1e-6 for coordinates [m, rad], 1e-2 for rates) has an error
   against the truth no larger than e_ours. solve_ivp drives the SAME compiled right-hand side
   (flexgear.lumped.run.lumped_rhs) with t_eval on the recorded grid; its signals are recorded
   afterwards with the kernel's own recording (not timed: in scipy's favour).
4. Timing: ours and every method at its matching tolerance, ``--repeat`` rounds, medians, ratios.
5. A plain-Python/numpy right-hand side (the same kernel interpreted, numba's py_func) driving RK45 at
   the matching tolerance over ``--plain-t-end`` (it is far too slow for the full run), against the
   compiled RHS and ours over the same span.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp
from speed_common import figure_line, load_average, median, ratio_line

from flexgear.lumped.run import build_lumped_model, lumped_rhs, run_lumped
from flexgear.results import RunResult, signal_columns
from flexgear.spec import load_gearbox
from flexgear.study.compare import compare_results

ROOT = Path(__file__).resolve().parents[1]
TOLERANCES = [10.0 ** -k for k in range(5, 11)]  # at 1e-3, 1e-4 RK45 and LSODA erred >100x more than ours


def table_error(run: RunResult, truth: RunResult) -> float:
    """Largest relative difference of the Table 6-7 values of ``run`` against ``truth`` (see module doc)."""
    t6, t7 = compare_results(truth, run)
    a, b = t6.columns[1], t6.columns[2]
    rows = t6[a].abs() > 0
    e6 = float(((t6.loc[rows, b] - t6.loc[rows, a]).abs() / t6.loc[rows, a].abs()).max())
    ra, rb = t7.columns.get_level_values(0).unique()[:2]
    e7 = max(float((t7[(rb, side)] - t7[(ra, side)]).abs().max() / t7[(ra, side)].max())
             for side in ("input", "output"))
    return max(e6, e7)


def solve(spec, method: str, tol: float, t_end: float, compiled: bool = True) -> tuple[RunResult, float]:
    """solve_ivp on the lumped RHS; the run as a RunResult (signals recorded afterwards) and its wall time."""
    model = build_lumped_model(spec)
    rhs = lumped_rhs(model, compiled=compiled)
    h = spec.load_case.step_size_s
    n = int(round(t_end / h))
    t_eval = np.arange(n + 1) * h
    nf = model.free.size
    atol = np.r_[np.full(nf, 1e-6), np.full(nf, 1e-2)] * tol
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, t_eval[-1]), np.zeros(2 * nf), method=method, t_eval=t_eval, rtol=tol, atol=atol)
    wall = time.perf_counter() - t0
    if not sol.success:
        raise RuntimeError(f"solve_ivp {method} tol {tol}: {sol.message}")
    rec = np.array([rhs.record(t, y) for t, y in zip(sol.t, sol.y.T, strict=True)])
    return _result(spec, sol.t, rec, method, tol, sol.nfev), wall


def _result(spec, t: np.ndarray, rec: np.ndarray, method: str, tol: float, nfev: int) -> RunResult:
    """Recorded kernel rows -> the signal table of flexgear.lumped.run.run_lumped."""
    base = run_lumped(spec, t_end_s=2 * spec.load_case.step_size_s)  # metadata (theory, load case)
    n = spec.gears.planet_count
    nm = 2 * n
    w_in, w_out = np.degrees(rec[:, 0]), np.degrees(rec[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(w_in != 0.0, w_out / w_in, np.nan)
    data = np.column_stack([t, w_in, w_out, ratio, rec[:, 2], rec[:, 3:3 + nm], rec[:, 3 + nm:7 + nm]])
    meta = dict(base.meta, name=f"solve_ivp_{method}", end_time_s=float(t[-1]),
                integration={"method": method, "tol": tol, "nfev": int(nfev)})
    return RunResult(meta, pd.DataFrame(data, columns=signal_columns(n)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("gearbox", nargs="?", default=str(ROOT / "model_variants" / "gearbox.toml"))
    ap.add_argument("--t-end", type=float, default=None)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--methods", nargs="+", default=["RK45", "LSODA"],
                    help="solve_ivp methods (BDF, Radau also work; not in the default, not timed on the full run)")
    ap.add_argument("--plain-t-end", type=float, default=0.01)
    a = ap.parse_args()
    spec = load_gearbox(a.gearbox)
    if a.t_end is not None:
        spec = spec.with_changes(load_case=dataclasses.replace(spec.load_case, end_time_s=a.t_end))
    t_end = spec.load_case.end_time_s
    print(f"bench_lumped_scipy: t_end {t_end} s; {load_average()}", flush=True)
    run_lumped(spec, t_end_s=1e-3)  # compile / load the kernel
    substeps = spec.lumped_assumed.integration_substeps
    truth = run_lumped(spec.with_changes(lumped_assumed=dataclasses.replace(spec.lumped_assumed,
                                                                            integration_substeps=4 * substeps)))
    ours = run_lumped(spec)
    e_ours = table_error(ours, truth)
    print(f"ours (RK4, {substeps} substeps per step): Table 6-7 error against {4 * substeps} substeps "
          f"{e_ours:.2e}", flush=True)
    matched: dict[str, float] = {}
    for method in a.methods:
        for tol in TOLERANCES:
            try:
                res, wall = solve(spec, method, tol, t_end)
            except RuntimeError as exc:
                print(f"  {method} tol {tol:.0e}: {exc}", flush=True)
                continue
            err = table_error(res, truth)
            print(f"  {method} tol {tol:.0e}: error {err:.2e}, {res.meta['integration']['nfev']} RHS calls, "
                  f"{wall:.2f} s", flush=True)
            if err <= e_ours:
                matched[method] = tol
                break
        else:
            print(f"  {method}: no tolerance down to {TOLERANCES[-1]:.0e} matched ours", flush=True)
    times: dict[str, list[float]] = {"ours": [], **{m: [] for m in matched}}
    for _ in range(a.repeat):
        times["ours"].append(run_lumped(spec).meta["wall_time_s"])
        for method, tol in matched.items():
            times[method].append(solve(spec, method, tol, t_end)[1])
    print()
    for name, values in times.items():
        label = name if name == "ours" else f"solve_ivp {name} (tol {matched[name]:.0e})"
        print(figure_line(f"{label} wall [s]", values))
    for method in matched:
        print(ratio_line(f"solve_ivp {method} / ours", times[method], times["ours"], ">= 10"))
    if "RK45" in matched and a.plain_t_end > 0:
        short = spec.with_changes(load_case=dataclasses.replace(spec.load_case, end_time_s=a.plain_t_end))
        plain = [solve(short, "RK45", matched["RK45"], a.plain_t_end, compiled=False)[1]]
        comp = [solve(short, "RK45", matched["RK45"], a.plain_t_end)[1]]
        own = [run_lumped(short).meta["wall_time_s"]]
        print(f"\nplain-Python/numpy RHS, RK45 tol {matched['RK45']:.0e}, {a.plain_t_end} s simulated (one run):")
        print(figure_line("  plain RHS solve_ivp RK45 wall [s]", plain))
        print(figure_line("  compiled RHS solve_ivp RK45 wall [s]", comp))
        print(figure_line("  ours wall [s]", own))
        print(ratio_line("  plain RHS RK45 / ours", plain, own))
        print(ratio_line("  plain RHS RK45 / compiled RHS RK45", plain, comp))
    print(f"after: {load_average()}; medians: " + ", ".join(f"{k} {median(v):.3f} s" for k, v in times.items()))


if __name__ == "__main__":
    main()
