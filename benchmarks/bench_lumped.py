"""How long does the lumped-parameter model take for the full Table 5 load case, and is its integration step
converged (Table 7 with twice the RK4 substeps)?

Run: python benchmarks/bench_lumped.py [model_variants/gearbox.toml] [--out DIR]

Prints the wall time of the full run (numba kernel already compiled: a warm-up run of 1 ms comes
first and its time, which includes compiling or loading the cache, is printed separately), Tables 6
and 7 of the run, the first natural frequencies, and Table 7 with twice the RK4 substeps as a
convergence check of the step size. ``--out`` saves the run (flexgear.results format).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time
from pathlib import Path

import pandas as pd

from flexgear.lumped.modal import modal_analysis
from flexgear.lumped.run import run_lumped
from flexgear.results import save_result
from flexgear.spec import load_gearbox
from flexgear.study.compare import compare_results

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("gearbox", nargs="?", default=str(ROOT / "model_variants" / "gearbox.toml"))
    ap.add_argument("--out", default=None)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    pd.set_option("display.width", 160)
    spec = load_gearbox(a.gearbox)

    t0 = time.perf_counter()
    run_lumped(spec, t_end_s=1e-3)
    print(f"warm-up (compile or load numba cache): {time.perf_counter() - t0:.2f} s")
    times, cpu = [], []
    for _ in range(a.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = run_lumped(spec)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    n_steps = len(res.signals) - 1
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"full run {spec.load_case.end_time_s} s, {n_steps} recorded steps x "
          f"{spec.lumped_assumed.integration_substeps} RK4 substeps: wall time best {min(times):.3f} s "
          f"(all {', '.join(f'{t:.3f}' for t in times)} s), CPU time best {min(cpu):.3f} s, "
          f"load average {load:.1f} on {os.cpu_count()} cores")
    if a.out:
        print("saved ->", save_result(res, a.out))

    for hold in (False, True):
        modes = modal_analysis(spec, hold_input=hold).table()
        title = "drive held (as in the run)" if hold else "free sun spin"
        print(f"\nfirst 12 natural frequencies, {title}:")
        print(modes.head(12)[["frequency_hz", "kind", "multiplicity"]].to_string())

    la = spec.lumped_assumed
    fine = spec.with_changes(lumped_assumed=dataclasses.replace(la, integration_substeps=2 * la.integration_substeps))
    res_fine = run_lumped(fine)
    res_fine.meta["variant"] = f"lumped, {2 * la.integration_substeps} substeps"
    t6, t7 = compare_results(res, res_fine)
    print("\nTable 6 (lumped run; and with twice the substeps):")
    print(t6.to_string())
    print("\nTable 7 [m/s^2] (x component):")
    print(t7.to_string())


if __name__ == "__main__":
    main()
