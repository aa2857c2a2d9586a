"""Benchmark: the full Table 5 load case (0.6 s, h = 1e-5 s) of every variant, one at a time.

Run: python benchmarks/bench_variants.py [model_variants/model*.toml] [--out results/bench]
Caches (meshes, reduced bodies) are warmed first; the table lists wall/CPU time beside the times before the
flexible-physics issue (``before_s``: 12 free-free modes, supports on the frames) and the study's ADAMS times
(Table 4), and the steady values against theory; it is also written as CSV.
"""

import argparse
import sys
from pathlib import Path

import pandas as pd

from flexgear.cache import atomic_write_bytes
from flexgear.mbs.run import run_variant
from flexgear.results import save_result
from flexgear.spec import load_variant

ADAMS_S = {"model1": 371, "model2": 17948, "model3": 507, "model4": 34903, "model5": 11745, "model6": 35662,
           "model7": 42955}  # Table 4 of the study
BEFORE_S = {"model1": 8.3, "model2": 48, "model3": 26, "model4": 46, "model5": 58, "model6": 68,
            "model7": 85}  # README before the flexible-physics issue: 12 free-free modes, supports on the frames


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("variants", nargs="*", default=sorted(str(p) for p in Path("model_variants").glob("model*.toml")))
    ap.add_argument("--out", default="results/bench")
    ap.add_argument("--t-end", type=float, default=None)
    a = ap.parse_args()
    rows = []
    for path in a.variants:
        v = load_variant(path)
        run_variant(v, t_end_s=1e-4)  # warm the caches (meshes, reduced bodies, compiled kernels)
        r = run_variant(v, t_end_s=a.t_end)
        save_result(r, Path(a.out) / v.name)
        row = {"variant": v.name, "status": r.meta["status"], "wall_s": r.meta["wall_time_s"],
               "cpu_s": r.meta["cpu_time_s"], "before_s": BEFORE_S.get(v.name), "adams_s": ADAMS_S.get(v.name)}
        if r.ok:
            s, th = r.signals, r.meta["theory"]
            w = s[s.time_s >= 0.9 * s.time_s.iloc[-1]]
            row["output_speed_err_pct"] = 100 * (w.output_speed_deg_per_s.mean() / th["output_speed_deg_per_s"] - 1)
            for kind in ("outer", "inner"):
                f = w[[c for c in w.columns if c.startswith(f"{kind}_mesh_force")]].to_numpy().mean()
                row[f"{kind}_force_n"] = f
            row["elastic_share_inner"] = r.meta.get("elastic_share_inner")
            if "transmission_error_m" in w:
                row["te_um"] = 1e6 * w.transmission_error_m.mean()
        else:
            row["reason"] = r.meta["reason"][:200]
        rows.append(row)
        print(pd.DataFrame([row]).to_string(index=False, header=len(rows) == 1), flush=True)
    table = pd.DataFrame(rows)
    atomic_write_bytes(Path(a.out) / "bench_variants.csv", table.to_csv(index=False).encode())
    print(table.to_string(index=False))


if __name__ == "__main__":
    sys.exit(main())
