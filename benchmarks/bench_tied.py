"""The bolted ring and output shaft: what do the joined forms (one tied body when both are flexible, one rigid
bolt-patch interface and one joint when one of them is rigid) cost and change against two bodies joined per bolt?

Run: nice -n 5 python benchmarks/bench_tied.py [--level coarse] [--sections build checks mbs] [--bolted]
                                               [--baseline DIR] [--variants 1 3 4 5 6 7] [--t-end S] [--out FILE]

- build: each body built cold in its own process from the cached meshes (the reduction without its cache): the
  ring's and the output shaft's bodies (flexgear.fe.reduced) and the tied pair (flexgear.fe.ring_shaft); with
  ``--baseline DIR`` (a checkout of the code to compare with, e.g. ``git worktree add --detach DIR <commit>``)
  also that code's ring and output shaft, side by side. Per body: modes, wall and CPU time, the process's peak
  resident set (getrusage ru_maxrss).
- checks: the tied body (cached) against the full FE model of the tied pair: the first ten elastic free-free
  frequencies (flexgear.fe.cms.full_free_modes on the tied model, which equals flexgear.fe.bolted's tie) and with
  ``--bolted`` also flexgear.fe.bolted.ring_output_shaft_fe_modes itself (its own solver: minutes, 4 GB); the
  largest compliance error at the ring's contacts (kernel loads, bearing seat held) relative to the largest
  entry, and of the bearing seat's six RBE3 compliances (ring side held).
- mbs (needs ``--baseline``): each variant of ``model_variants/`` run for ``--t-end`` (default the study's load
  case, 0.6 s) by this code and by the baseline's, alternately, each in its own process on warm caches: the
  system's second-order coordinates and constraint rows, wall and CPU time of the run, and the agreement of every
  signal over the last ``--window`` seconds (flexgear.study.agreement: means within 0.1 %, 1x mesh amplitudes
  within 2 %); then model 7's time against the baseline's and against model 1's.
The tied body's spectrum against full FE in the band the meshes excite: benchmarks/bench_convergence.py --band.
Results are printed and, with ``--out``, written as JSON (atomically).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = ("ring", "output_shaft", "tied")
BASELINE_CASES = ("ring", "output_shaft")
"""A baseline's bodies (the per-bolt code has no tied pair; a baseline with flexgear/fe/ring_shaft.py builds it too)."""


def _builder(spec, case: str, level: str):
    """The uncached build function of ``case``."""
    if case == "tied":
        from flexgear.fe.ring_shaft import _tied_build

        return _tied_build(spec, level, False)
    from flexgear.fe.reduced import _component_reduction

    return _component_reduction(spec, case, level, False)[1]


def child(case: str, level: str) -> None:
    """Build ``case`` in this process (on the code and gearbox file of the working directory); print one JSON
    line."""
    from flexgear.spec import load_gearbox

    spec = load_gearbox(Path.cwd() / "model_variants" / "gearbox.toml")
    build = _builder(spec, case, level)
    t0, c0 = time.perf_counter(), time.process_time()
    body = build()
    usage = resource.getrusage(resource.RUSAGE_SELF)
    print(json.dumps({"case": case, "modes": body.n_modes, "interfaces": [i.name for i in body.interfaces],
                      "wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0,
                      "peak_rss_gb": usage.ru_maxrss * 1024 / 1e9}))


def _child_json(args: list[str], root: Path) -> dict:
    """Run this script with ``args`` in a process on the code at ``root``; its last printed line as JSON."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    out = subprocess.run([sys.executable, __file__, *args], capture_output=True, text=True, env=env, cwd=root)
    if out.returncode != 0:
        return {"status": "failed", "reason": out.stderr.strip().splitlines()[-1] if out.stderr.strip() else "?"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def build_section(level: str, baseline: Path | None) -> list[dict]:
    rows = []
    old = CASES if baseline and (baseline / "flexgear" / "fe" / "ring_shaft.py").exists() else BASELINE_CASES
    runs = [(ROOT, "current", CASES)] + ([(baseline, "baseline", old)] if baseline else [])
    for root, label, cases in runs:
        for case in cases:
            row = {"code": label, **_child_json(["--child", case, "--level", level], root)}
            rows.append(row)
            print(f"{label:8s} {case:14s} {row['modes']:4d} modes  {row['wall_s']:6.1f} s wall  "
                  f"{row['cpu_s']:6.1f} s CPU  peak {row['peak_rss_gb']:.2f} GB", flush=True)
    return rows


def child_run(variant_file: str, t_end: float | None, save: str) -> None:
    """Run ``variant_file`` in this process; save its result to ``save``; print one JSON line."""
    import exudyn as exu

    from flexgear.mbs.gearbox import build_star_gearbox
    from flexgear.mbs.run import run_variant
    from flexgear.results import save_result
    from flexgear.spec import load_variant

    variant = load_variant(variant_file)
    mbs = exu.SystemContainer().AddSystem()
    build_star_gearbox(mbs, variant)
    mbs.Assemble()
    size = {"ode2_coordinates": len(mbs.systemData.GetODE2Coordinates()),
            "constraint_rows": len(mbs.systemData.GetAECoordinates())}
    result = run_variant(variant, t_end)
    save_result(result, save)
    print(json.dumps({**size, **{k: result.meta.get(k) for k in ("status", "reason", "wall_time_s", "cpu_time_s",
                                                                  "t_end_s", "newton_iterations", "jacobians")}}))


def mbs_section(baseline: Path, variants: list[int], t_end: float | None, window: float) -> list[dict]:
    import tempfile

    from flexgear.results import load_result
    from flexgear.study.agreement import signal_agreement

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for m in variants:
            runs = {}
            for root, label in ((ROOT, "current"), (baseline, "baseline")):
                save = Path(tmp) / f"{label}-model{m}"
                args = ["--child-run", f"model_variants/model{m}.toml", "--save", str(save)]
                runs[label] = {"save": save, **_child_json(args + (["--t-end", str(t_end)] if t_end else []), root)}
            row = {"variant": f"model{m}", **{f"{k}_{lb}": r.get(k) for lb, r in runs.items()
                                              for k in ("ode2_coordinates", "constraint_rows", "wall_time_s",
                                                        "cpu_time_s", "status")}}
            if all(r.get("status") == "ok" for r in runs.values()):
                ref, new = load_result(runs["baseline"]["save"]), load_result(runs["current"]["save"])
                end = float(runs["current"]["t_end_s"])
                agreement = signal_agreement(ref, new, (end - window, end), ref.meta["theory"]["mesh_frequency_hz"])
                table = agreement.table
                mesh = table[table.index.str.contains("mesh_force")]
                accel = table[table.index.str.contains("accel")]
                row.update(worst_mean=agreement.worst_mean, worst_mean_signal=str(table["mean_diff"].abs().idxmax()),
                           worst_amp_1x=agreement.worst_amplitude,
                           worst_amp_signal=str(table["amp_diff"].abs().idxmax()),
                           mesh_force_mean=float(mesh["mean_diff"].abs().max()),
                           mesh_force_amp_1x=float(mesh["amp_diff"].abs().max()),
                           bearing_accel_amp_1x=float(accel["amp_diff"].abs().max()))
            rows.append(row)
            print(json.dumps(row), flush=True)
    by = {r["variant"]: r for r in rows}
    if "model7" in by and by["model7"].get("wall_time_s_baseline"):
        seven = by["model7"]
        new, old = seven["wall_time_s_current"], seven["wall_time_s_baseline"]
        print(f"model 7: {new:.1f} s against the baseline's {old:.1f} s ({new / old:.2f}x)")
        if "model1" in by:
            print(f"model 7 / model 1: {seven['wall_time_s_current'] / by['model1']['wall_time_s_current']:.1f}x "
                  f"(baseline {seven['wall_time_s_baseline'] / by['model1']['wall_time_s_baseline']:.1f}x)")
    return rows


def checks_section(level: str, bolted: bool) -> dict:
    import numpy as np

    import flexgear as fg
    from flexgear.fe.cms import full_free_modes, rbe3_rows, rbe3_weights
    from flexgear.fe.compliance import free_body_solver
    from flexgear.fe.fem import rigid_body_modes
    from flexgear.fe.reduced import component_contacts, component_load_circles
    from flexgear.fe.ring_shaft import pair_fe_models, ring_seat, tied_pair, tied_pair_body
    from flexgear.spec import load_gearbox

    spec = load_gearbox(ROOT / "model_variants" / "gearbox.toml")
    out: dict = {}
    body = tied_pair_body(spec, level)
    ring, shaft = pair_fe_models(spec, level)
    tied = tied_pair(ring, shaft, spec)
    fe = tied.fe
    solver = free_body_solver(fe)
    full = full_free_modes(fe, 10, solver)[0]
    out["tied_full_hz"], out["tied_reduced_hz"] = full.tolist(), body.frequencies_hz[:10].tolist()
    err = body.frequencies_hz[:10] / full - 1
    out["tied_mode_error_max"] = float(np.abs(err).max())
    print("tied pair, first ten elastic free-free modes [Hz]:")
    print("  full FE ", np.round(full, 1))
    print("  reduced ", np.round(body.frequencies_hz[:10], 1))
    print(f"  error max {100 * np.abs(err).max():.3f} %")
    if bolted:
        from flexgear.fe.bolted import ring_output_shaft_fe_modes

        ref = ring_output_shaft_fe_modes(spec, level, 10)
        out["bolted_full_hz"] = ref.tolist()
        worst = np.abs(body.frequencies_hz[:10] / ref - 1).max()
        print(f"  flexgear.fe.bolted reference: error max {100 * worst:.3f} %, its frequencies vs "
              f"full_free_modes: {np.abs(ref / full - 1).max():.1e}")
    points, normals = component_contacts(spec, "ring")
    kernel = component_load_circles(spec, "ring", spec.reduction_assumed.contact_fourier_order)
    seat = body.interface("bearing_seat")
    c_full = fg.static_compliance(fe, points, normals, seat, kernel=kernel)
    c_red = fg.static_compliance(body, points, normals, "bearing_seat", kernel=kernel)
    out["contact_compliance_error"] = float(np.abs(c_red - c_full).max() / np.abs(c_full).max())
    ring_side = tied.interface("ring", ring_seat(ring, spec))
    rows_load, rows_held = rbe3_rows(fe, seat), rbe3_rows(fe, ring_side)
    u = solver.constrained(rows_held).solve(rows_load.T.toarray(), np.zeros((6, 6)))
    s_full = np.diag(rows_load @ u)
    rig = rigid_body_modes(body.nodes).reshape(len(body.nodes), 3, 6)

    def c_r(itf):  # (6, 6): the interface's RBE3 motion per rigid-body mode
        return np.einsum("idc,icm->dm", rbe3_weights(body.nodes, itf), rig[itf.nodes])

    held = body.interface("ring_seat")
    phi = body.interface_motion(seat) - c_r(seat) @ np.linalg.solve(c_r(held), body.interface_motion(held))
    s_red = np.diag((phi / body.stiffness) @ phi.T)
    out["seat_compliance_error_max"] = float(np.abs(s_red / s_full - 1).max())
    print(f"  compliance at the ring's contacts: largest error {100 * out['contact_compliance_error']:.4f} % of the "
          f"largest entry; bearing seat (6 RBE3 diagonals): {100 * out['seat_compliance_error_max']:.4f} %")

    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", default="coarse")
    parser.add_argument("--sections", nargs="+", default=["build", "checks"],
                        choices=["build", "checks", "mbs"])
    parser.add_argument("--bolted", action="store_true", help="also run flexgear.fe.bolted's own full-FE modes")
    parser.add_argument("--baseline", type=Path, help="a checkout of the code to compare with (build, mbs)")
    parser.add_argument("--variants", type=int, nargs="+", default=[1, 3, 4, 5, 6, 7])
    parser.add_argument("--t-end", type=float, default=None, help="mbs: simulated time [s] (default: load case's)")
    parser.add_argument("--window", type=float, default=0.1, help="mbs: agreement over the last WINDOW s")
    parser.add_argument("--out", type=Path, help="write the results here as JSON")
    parser.add_argument("--child", choices=CASES, help=argparse.SUPPRESS)
    parser.add_argument("--child-run", help=argparse.SUPPRESS)
    parser.add_argument("--save", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child, args.level)
        return
    if args.child_run:
        child_run(args.child_run, args.t_end, args.save)
        return
    results: dict = {"level": args.level}
    if "build" in args.sections:
        results["build"] = build_section(args.level, args.baseline)
    if "checks" in args.sections:
        results["checks"] = checks_section(args.level, args.bolted)
    if "mbs" in args.sections:
        if args.baseline is None:
            parser.error("--sections mbs needs --baseline DIR")
        results["mbs"] = mbs_section(args.baseline.resolve(), args.variants, args.t_end, args.window)
    if args.out:
        from flexgear.cache import atomic_write_bytes

        atomic_write_bytes(args.out, json.dumps(results, indent=1).encode())


if __name__ == "__main__":
    main()
