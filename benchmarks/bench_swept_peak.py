"""The single-mode integration of the run-up's swept predictions (flexgear.study.runup.swept_peak): the exact
first-order-hold filter (flexgear.study.hold.single_mode_acceleration) against scipy's state-space integration
(scipy.signal.lsim, the same hold), side by side on the same forcing: wall time per call and their largest
difference relative to the response's peak.

    python benchmarks/bench_swept_peak.py [--t-end 0.6] [--dt 5e-6] [--repeat 3]

The forcing is a mesh order swept through the mode, as along a run's ramp (the study's runs: 0.6 s at 5 us).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.signal import lsim

from flexgear.study.hold import single_mode_acceleration

MODES = ((1500.0, 0.03), (4400.0, 0.05), (9000.0, 0.005))
"""(frequency [Hz], damping ratio) of the modes timed."""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=0.6, help="run length [s]")
    parser.add_argument("--dt", type=float, default=5e-6, help="sample step [s]")
    parser.add_argument("--repeat", type=int, default=3, help="rounds (the median is reported)")
    a = parser.parse_args(argv)
    t = np.arange(0.0, a.t_end, a.dt)
    sweep = 0.5 * 12000.0 / a.t_end  # the order's frequency rises from 0 to 12 kHz over the run
    force = (t / a.t_end) * np.cos(2 * math.pi * sweep * t**2)
    print(f"{t.size} samples; median of {a.repeat} rounds")
    for f_n, zeta in MODES:
        w = 2 * math.pi * f_n
        system = ([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [1.0]], [[-w * w, -2 * zeta * w]], [[1.0]])
        times = {"lsim": [], "filter": []}
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            ref = lsim(system, force, t)[1]
            t1 = time.perf_counter()
            got = single_mode_acceleration(t, force, f_n, zeta)
            t2 = time.perf_counter()
            times["lsim"].append(t1 - t0)
            times["filter"].append(t2 - t1)
        lsim_s, filter_s = (float(np.median(v)) for v in times.values())
        diff = float(np.abs(got - ref).max() / np.abs(ref).max())
        print(f"{f_n:7.0f} Hz, zeta {zeta}: lsim {1e3 * lsim_s:8.1f} ms, filter {1e3 * filter_s:6.2f} ms "
              f"({lsim_s / filter_s:5.0f}x); largest difference {diff:.1e} of the peak")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
