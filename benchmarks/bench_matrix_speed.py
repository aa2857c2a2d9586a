"""Benchmark (issue 16): the seven-variant matrix with two workers against the sum of its single runs.

Run: nice -n 5 python benchmarks/bench_matrix_speed.py [--t-end 0.6] [--repeat 3] [--workers 2]
     [model_variants/model*.toml]

Per round: every variant run alone, one after the other, in this process
(flexgear.mbs.run.run_variant, wall time as it reports it: build + solve), summed; then the whole
matrix (flexgear.study.matrix.run_matrix: worker processes, saving, screening) into a fresh temporary
folder, its wall time from call to return. Caches are warmed first (a 1e-4 s run of each variant).
Prints each round, the medians and the ratio matrix / sum (goal <= 0.55), with the load average:
on a shared 2-core machine the parallel gain depends on the cores the other users leave free.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from speed_common import figure_line, load_average, ratio_line

from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant
from flexgear.study.matrix import run_matrix

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("variants", nargs="*",
                    default=sorted(str(p) for p in (ROOT / "model_variants").glob("model*.toml")))
    ap.add_argument("--t-end", type=float, default=None)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    variants = [load_variant(p) for p in a.variants]
    print(f"bench_matrix_speed: {len(variants)} variants, t_end {a.t_end or 'load case'}, {a.workers} workers, "
          f"{a.repeat} rounds; {load_average()}", flush=True)
    for v in variants:
        r = run_variant(v, t_end_s=1e-4)
        if not r.ok:
            sys.exit(f"{v.name}: warm-up failed: {r.meta['reason']}")
    sums, matrix = [], []
    for i in range(a.repeat):
        walls = []
        for v in variants:
            r = run_variant(v, t_end_s=a.t_end)
            if not r.ok:
                sys.exit(f"{v.name}: run failed: {r.meta['reason']}")
            walls.append(r.meta["wall_time_s"])
        sums.append(sum(walls))
        print(f"round {i + 1} singles: " + ", ".join(f"{v.name} {w:.1f}" for v, w in zip(variants, walls, strict=True))
              + f" -> sum {sums[-1]:.1f} s; {load_average()}", flush=True)
        with tempfile.TemporaryDirectory(prefix="flexgear-bench-matrix-") as out:
            t0 = time.perf_counter()
            table = run_matrix(a.variants, out, t_end_s=a.t_end, workers=a.workers, progress=False)
            matrix.append(time.perf_counter() - t0)
        failed = table.loc[table.status != "ok", "variant"].tolist()
        if failed:
            sys.exit(f"matrix: failed variants {failed}")
        print(f"round {i + 1} matrix ({a.workers} workers): {matrix[-1]:.1f} s; {load_average()}", flush=True)
    print()
    print(figure_line("sum of single runs [s]", sums))
    print(figure_line(f"matrix, {a.workers} workers [s]", matrix))
    print(ratio_line("matrix / sum of single runs", matrix, sums, "<= 0.55"))
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
