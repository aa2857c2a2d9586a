"""Run-up order map of a saved run against its variant's Campbell diagram: the strongest ridges and their crossings.

    python benchmarks/bench_runup.py [RUN_DIR] [VARIANT_FILE]   (default: results/full/model1, model1.toml)

Prints, per bearing, the ridges (speed, order, prominence) with the nearest crossing of the same order and the
relative error, the single-mode swept prediction of each (flexgear.study.runup.swept_peak), and the CPU times.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from flexgear.modal import campbell
from flexgear.results import load_result
from flexgear.spec import load_variant
from flexgear.study.runup import runup, swept_peak

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    run_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "results" / "full" / "model1"
    variant = load_variant(sys.argv[2] if len(sys.argv) > 2 else ROOT / "model_variants" / "model1.toml")
    result = load_result(run_dir)
    t0 = time.process_time()
    c = campbell(variant, np.linspace(0.0, variant.gearbox.load_case.input_speed_rpm, 13))
    print(f"Campbell of {variant.name}, 13 speeds: {time.process_time() - t0:.1f} s CPU")
    s = result.signals
    t, n = s["time_s"].to_numpy(), s["input_speed_deg_per_s"].to_numpy() / 6.0
    for side in ("output", "input"):
        t0 = time.process_time()
        ru = runup(result, side, campbell=c)
        print(f"{run_dir.name} {side} bearing: {time.process_time() - t0:.2f} s CPU, {len(ru.ridges)} ridges")
        for _, r in ru.ridges.head(3).iterrows():
            line = c.table[c.table["mode"] == r["mode"]] if r["mode"] == r["mode"] else c.table.iloc[:0]
            swept = (swept_peak(t, n, ru.map.mesh_hz_per_rpm, int(r["order"]), r["mode_hz"],
                                float(line["damping_ratio"].iloc[0])) if len(line) else float("nan"))
            print(f"  {r['order']:.0f}x at {r['speed_rpm']:7.1f} rpm ({r['prominence_db']:.1f} dB): crossing "
                  f"{r['crossing_rpm']:7.1f} rpm ({r['kind']}, {r['mode_hz']:.1f} Hz), error {r['error_pct']:+.2f} %; "
                  f"single-mode swept peak {swept:7.1f} rpm")


if __name__ == "__main__":
    main()
