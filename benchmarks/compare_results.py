"""Do two results folders hold the same signals? Every common run compared by the agreement rule's measures
(flexgear.study.agreement: each signal's mean and its 1x mesh amplitude, relative) over the last 0.05 s of the
shorter run: e.g. the matrix before and after a change that must not move the study's signals.

Run: python benchmarks/compare_results.py RESULTS_A RESULTS_B [--window S]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from flexgear.results import load_result  # noqa: E402
from flexgear.study.agreement import signal_agreement  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("a", type=Path)
    p.add_argument("b", type=Path)
    p.add_argument("--window", type=float, default=0.05, help="analysis window at the end [s] (default 0.05)")
    a = p.parse_args(argv)
    names = sorted(d.name for d in a.a.iterdir()
                   if (d / "run.json").is_file() and (a.b / d.name / "run.json").is_file())
    print(f"{'run':<12} {'worst mean':>11} {'worst 1x':>10}")
    for name in names:
        ra, rb = load_result(a.a / name), load_result(a.b / name)
        if ra.signals is None or rb.signals is None:
            print(f"{name:<12} (a run without signals)")
            continue
        end = min(ra.signals.time_s.iloc[-1], rb.signals.time_s.iloc[-1])
        half_step = 0.5 * float(ra.signals.time_s.diff().median())  # window edges between samples, not on them
        ag = signal_agreement(ra, rb, (end - a.window + half_step, end + half_step),
                              ra.meta["theory"]["mesh_frequency_hz"])
        print(f"{name:<12} {ag.worst_mean:>11.2e} {ag.worst_amplitude:>10.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
