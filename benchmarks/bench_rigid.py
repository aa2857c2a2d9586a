"""How long does model 1 (all rigid) take for the full Table 5 load case (0.6 s at h = 1e-5 s), and do its steady
values match theory? (``make bench`` runs it.)

Run: python benchmarks/bench_rigid.py [--repeat N] [--variant model_variants/model1.toml]

Prints wall and CPU time of each run, the best and the median, and over the last 0.05 s the output speed, the
mean outer and inner mesh forces (and their spread over the planets) and the drive torque against theory.
"""

import argparse
import statistics

from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="model_variants/model1.toml")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    variant = load_variant(a.variant)
    walls = []
    for i in range(a.repeat):
        r = run_variant(variant)
        if not r.ok:
            raise SystemExit(f"{variant.name} failed: {r.meta['reason']}")
        walls.append(r.meta["wall_time_s"])
        print(f"run {i + 1}: wall {r.meta['wall_time_s']:.2f} s, cpu {r.meta['cpu_time_s']:.2f} s", flush=True)
    s, th = r.signals, r.meta["theory"]
    w = s[s.time_s >= 0.55]
    print(f"{variant.name}: best {min(walls):.2f} s, median {statistics.median(walls):.2f} s over {a.repeat} runs")
    print(f"output speed {w.output_speed_rad_per_s.mean():.6f} rad/s (theory {th['output_speed_rad_per_s']:.6f})")
    for kind in ("outer", "inner"):
        f = w[[f"{kind}_mesh_force_{i}_n" for i in range(1, 6)]].mean()
        print(f"{kind} mesh force {f.mean():.4f} N (theory {th['mesh_force_n']:.4f}), spread {f.max() - f.min():.4f} N")
    print(f"drive torque {w.input_torque_nm.mean():.4f} N m (theory {th['input_torque_nm']:.4f})")


if __name__ == "__main__":
    main()
