"""The bolted ring and output shaft as one tied body, or with one rigid bolt-patch interface, beside today's two
bodies with a rigid patch per bolt: coordinates, cold build time and peak memory, and the checks against full FE.

Run: nice -n 5 python benchmarks/bench_tied.py [--level coarse] [--sections build checks] [--bolted] [--out FILE]

- build: each body built cold in its own process from the cached meshes (the reduction without its cache; the
  meshes are the same for every form): today's "ring" and "output_shaft" (flexgear.fe.reduced, a rigid patch per
  bolt), the tied pair (flexgear.fe.ring_shaft.tied_pair_body) and the one-rigid-interface forms
  (flexgear.fe.ring_shaft.rigid_partner_body). Per body: flexible coordinates, wall and CPU time, the process's
  peak resident set (getrusage ru_maxrss).
- checks: the tied body (cached) against the full FE model of the tied pair: the first ten elastic free-free
  frequencies (flexgear.fe.cms.full_free_modes on the tied model, which equals flexgear.fe.bolted's tie) and with
  ``--bolted`` also flexgear.fe.bolted.ring_output_shaft_fe_modes itself (its own solver: minutes, 4 GB); the
  largest compliance error at the ring's contacts (kernel loads, bearing seat held) relative to the largest
  entry, and of the bearing seat's six RBE3 compliances (ring side held); and today's ring and shaft with their 12
  patches all held against the one-rigid-interface bodies held at "bolt_patches" (the same physics: lowest ten
  frequencies).
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
CASES = ("ring", "output_shaft", "tied", "ring_rigid_partner", "output_shaft_rigid_partner")


def _builder(spec, case: str, level: str):
    """The uncached build function of ``case``."""
    if case in ("ring", "output_shaft"):
        from flexgear.fe.reduced import _component_reduction

        return _component_reduction(spec, case, level, False)[1]
    if case == "tied":
        from flexgear.fe.ring_shaft import _tied_build

        return _tied_build(spec, level, False)
    from flexgear.fe.reduced import component_load_circles
    from flexgear.fe.ring_shaft import BOLT_PATCHES, part_fe_model, rigid_partner_interfaces
    from flexgear.fe.tied import reduce

    component = case.removesuffix("_rigid_partner")

    def build():
        fe = part_fe_model(spec, component, level)
        red = spec.reduction_assumed
        return reduce(fe, rigid_partner_interfaces(fe, spec, component), red.fixed_interface_modes, n_compare=0,
                      load_circles=component_load_circles(spec, component, red.attachment_order), rigid=(BOLT_PATCHES,))

    return build


def child(case: str, level: str) -> None:
    """Build ``case`` in this process; print one JSON line."""
    from flexgear.spec import load_gearbox

    spec = load_gearbox(ROOT / "model_variants" / "gearbox.toml")
    build = _builder(spec, case, level)
    t0, c0 = time.perf_counter(), time.process_time()
    body = build()
    usage = resource.getrusage(resource.RUSAGE_SELF)
    print(json.dumps({"case": case, "modes": body.n_modes, "interfaces": [i.name for i in body.interfaces],
                      "wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0,
                      "peak_rss_gb": usage.ru_maxrss * 1024 / 1e9}))


def build_section(level: str) -> list[dict]:
    rows = []
    for case in CASES:
        out = subprocess.run([sys.executable, __file__, "--child", case, "--level", level], capture_output=True,
                             text=True, check=True, env=os.environ.copy())
        row = json.loads(out.stdout.strip().splitlines()[-1])
        rows.append(row)
        print(f"{case:28s} {row['modes']:4d} modes  {row['wall_s']:6.1f} s wall  {row['cpu_s']:6.1f} s CPU  "
              f"peak {row['peak_rss_gb']:.2f} GB", flush=True)
    return rows


def checks_section(level: str, bolted: bool) -> dict:
    import numpy as np
    import scipy.linalg as la

    import flexgear as fg
    from flexgear.fe.cms import _rbe3_rows, full_free_modes, rbe3_weights
    from flexgear.fe.compliance import free_body_solver
    from flexgear.fe.fem import rigid_body_modes
    from flexgear.fe.joined import body_matrices, joint_rows
    from flexgear.fe.reduced import component_contacts, component_load_circles, component_reduced_body
    from flexgear.fe.ring_shaft import pair_fe_models, rigid_partner_body, ring_seat, tied_pair, tied_pair_body
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
    rows_load, rows_held = _rbe3_rows(fe, seat), _rbe3_rows(fe, ring_side)
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

    def held_hz(b, names):
        mass, stiffness = body_matrices(b)
        g = np.vstack([joint_rows(b, n, b.interface(n).point) for n in names])
        basis = la.null_space(g)
        lam = la.eigh(basis.T @ stiffness @ basis, basis.T @ mass @ basis, eigvals_only=True)
        return np.sqrt(lam[:10]) / (2 * np.pi)

    for component in ("ring", "output_shaft"):
        today = component_reduced_body(spec, component, level)
        patches = [i.name for i in today.interfaces if i.name.startswith("bolt_")]
        one = rigid_partner_body(spec, component, level)
        f_today, f_one = held_hz(today, patches), held_hz(one, ["bolt_patches"])
        out[f"{component}_held_today_hz"], out[f"{component}_held_one_interface_hz"] = f_today.tolist(), f_one.tolist()
        print(f"{component} held at its bolts: {len(patches)} patches ({today.n_modes} modes) vs one rigid interface "
              f"({one.n_modes} modes): largest difference {np.abs(f_one / f_today - 1).max():.2e}")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", default="coarse")
    parser.add_argument("--sections", nargs="+", default=["build", "checks"], choices=["build", "checks"])
    parser.add_argument("--bolted", action="store_true", help="also run flexgear.fe.bolted's own full-FE modes")
    parser.add_argument("--out", type=Path, help="write the results here as JSON")
    parser.add_argument("--child", choices=CASES, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child, args.level)
        return
    results: dict = {"level": args.level}
    if "build" in args.sections:
        results["build"] = build_section(args.level)
    if "checks" in args.sections:
        results["checks"] = checks_section(args.level, args.bolted)
    if args.out:
        from flexgear.cache import atomic_write_bytes

        atomic_write_bytes(args.out, json.dumps(results, indent=1).encode())


if __name__ == "__main__":
    main()
