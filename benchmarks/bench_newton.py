"""How many Newton iterations and Jacobians per step does each Jacobian policy need over the load case, and where
(which part of the ramps) does a policy pay?

Run: nice -n 5 python benchmarks/bench_newton.py [--cases model1 floor] [--updates exudyn economy]
     [--ends 0.01 0.02 0.05 0.1 0.2 0.3 0.6]

Each case runs once to the last of ``--ends`` (the full Table 5 load case, cut there) with each policy of
``[solver_assumed] formulation`` (the production formulation's Jacobian economy, flexgear.mbs.newton, against
the reference's Exudyn policy); the solver's running counts, read by the run's
post-step function (bench_speed.solver_marks) when it passes each end time, give the iterations and Jacobians
per step in each window (one run: the economy's choices depend on measured times, so runs to different end times
are not prefixes of each other). ``floor``: model 1 with a constant mesh stiffness and no friction
(bench_speed.floor_variant).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from bench_speed import floor_variant, load_average, solver_marks, with_formulation

from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["model1", "floor"])
    ap.add_argument("--updates", nargs="+", default=["reference", "production"],
                    choices=["reference", "production"])
    ap.add_argument("--ends", type=float, nargs="+", default=[0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.6])
    ap.add_argument("--variants-dir", default=str(ROOT / "model_variants"))
    a = ap.parse_args()
    print(f"bench_newton: windows ending at {a.ends} s; {load_average()}", flush=True)
    for case in a.cases:
        v = load_variant(Path(a.variants_dir) / f"{'model1' if case == 'floor' else case}.toml")
        if case == "floor":
            v = floor_variant(v)
        h = v.gearbox.load_case.step_size_s
        for updates in a.updates:
            with solver_marks(a.ends, h) as marks:
                r = run_variant(with_formulation(v, updates), t_end_s=max(a.ends))
            if not r.ok:
                raise SystemExit(f"{case} {updates}: {r.meta['reason']}")
            before, start, cells = (0, 0), 0.0, []
            for end, (_, *now, _) in zip(sorted(a.ends), marks, strict=False):
                steps = (end - start) / h
                cells.append(f"{start:g}-{end:g} s: {(now[0] - before[0]) / steps:.2f} it, "
                             f"{1e3 * (now[1] - before[1]) / steps:.1f} Jac/1000")
                before, start = now, end
            print(f"{case} [{updates}]: " + "; ".join(cells), flush=True)
    print(f"after: {load_average()}")


if __name__ == "__main__":
    main()
