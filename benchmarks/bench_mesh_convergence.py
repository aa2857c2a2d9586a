"""Mesh convergence of a mesh level: each body's full FE free-free spectrum at the level the variants use against
the same body meshed finer (by default with half the element sizes), in the band the meshes excite.

Run: FLEXGEAR_CACHE_DIR=/tmp/conv_cache python benchmarks/bench_mesh_convergence.py [--level coarse]
         [--half | --tooth MM --body MM] [--base-tooth MM] [--base-body MM] [--band-orders 3] [--criterion-pct 1]
         [--reduction] [--spectra DIR] [--out FILE] [body ...]

Bodies: sun, planet, ring, input_shaft, output_shaft (each alone) and "tied" (the ring and the output shaft tied
over the bolts' clamped discs, flexgear.fe.ring_shaft.tied_pair: the body of the variants where both are flexible).

- Levels. The base is ``[meshing_assumed.<level>]`` of the gearbox file (the variants' ``mesh_level``, coarse),
  its tooth and body sizes replaced by ``--base-tooth`` / ``--base-body`` when given (to measure a candidate size).
  The reference has the base's settings with the tooth and body sizes halved (``--half``, the default) or set to
  ``--tooth`` / ``--body``; element order, curvature safety and optimisation steps stay the base's. The levels are
  added to the spec in memory (``spec.with_changes(meshing_assumed=...)``): neither gearbox.toml nor the meshing
  code changes. New meshes go to the cache folder, so point ``FLEXGEAR_CACHE_DIR`` at a private folder.
- Spectrum. Both levels as the production reduction builds the FE model (flexgear.fe.ring_shaft.part_fe_model: the
  level's element order raised on the first-order mesh), every free-free mode below 1.05 x the band (``--band-orders``
  x the mesh frequency of the load case, flexgear.theory.mesh_frequency_hz: 3 x 4400 Hz), by the project's
  shift-invert block Lanczos on the Cholesky factor of the free body (flexgear.fe.cms.FreeBodySolver). The six
  rigid-body modes are removed exactly: the eigenproblem is solved on the constraint (M R)^T phi = 0 (R the rigid
  modes), as flexgear.fe.cms.full_free_modes does, so every mode found is elastic.
- Pairing. By order: the k-th elastic mode of the base with the k-th of the reference, for every k up to the larger
  of the two counts in the band (modes computed to 1.05 x the band so that a mode just across the band edge on one
  level still has its partner). Sorted lists paired by order never show a larger frequency difference than the
  same modes paired by shape (for sorted sequences, order pairing minimises the largest difference), so the pairs
  are checked by shape too: each base node takes the displacement of the nearest reference node (nodes at most a
  fraction of an element apart), and for every group of modes that lie within 0.5 % of each other on either level
  (the degenerate pairs of the cyclic gears, whose shapes are any rotation within the pair) the subspace MAC of each
  reference mode onto the base modes of the group is taken: near 1 for all, order pairing is pairing by shape.
- Reported per body: DOFs, mode counts in the band, the largest relative frequency difference (base / reference - 1)
  and the mode where it occurs, the lowest shape agreement, pass / fail against ``--criterion-pct`` (1 %), wall time
  of mesh, FE assembly and eigen solve per level, and the peak resident set of the body's process. Each body runs in
  its own process (its peak memory its own). With ``--reduction`` also the production reduction of the body at the
  base level (flexgear.fe.reduced / flexgear.fe.ring_shaft, built without its cache): modes and wall time, the cost
  of the base level in the variants. ``--spectra DIR`` keeps each level's spectrum (frequencies, shapes, node
  coordinates and the times it took, keyed by a hash of the spec, the level and the limit) and reuses it: a finer
  reference computed once serves every candidate base (its times are then those of the first run).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BODIES = ("sun", "planet", "ring", "input_shaft", "output_shaft", "tied")
EDGE = 1.05
"""Modes are computed to this multiple of the band (partners of modes near the band edge)."""
CLUSTER = 0.005
"""Modes within this relative spacing on either level form one group for the shape check (degenerate pairs)."""


def _sized(settings, tooth: float, body: float):
    """``settings`` with every component's tooth and body sizes (the ring's too) set to ``tooth`` / ``body`` mm."""
    return dataclasses.replace(settings, tooth_size_mm=tooth, body_size_mm=body, ring_tooth_size_mm=tooth,
                               ring_body_size_mm=body)


def levels(spec, body_name: str, level: str, base_tooth: float | None, base_body: float | None, half: bool,
           tooth: float | None, body: float | None):
    """The spec with the base and reference levels added; (spec, base name, reference name). The sizes are those
    ``body_name`` takes at the level (the ring has its own, MeshingSettings.sizes_mm); both levels give them to
    every component."""
    from flexgear.schema import MeshingSettings

    base: MeshingSettings = spec.meshing_assumed[level]
    t0, b0 = base.sizes_mm("ring" if body_name in ("ring", "tied") else body_name)
    base_name = level
    if base_tooth is not None or base_body is not None:
        t0, b0 = base_tooth or t0, base_body or b0
        base_name = f"{level}_t{t0:g}_b{b0:g}"
    base = _sized(base, t0, b0)
    if half or (tooth is None and body is None):
        ref = _sized(base, t0 / 2, b0 / 2)
    else:
        ref = _sized(base, tooth or t0, body or b0)
    ref_name = f"ref_t{ref.tooth_size_mm:g}_b{ref.body_size_mm:g}"
    spec = spec.with_changes(meshing_assumed={**spec.meshing_assumed, base_name: base, ref_name: ref})
    return spec, base_name, ref_name


def fe_of(spec, body: str, level: str):
    """(FE model of ``body`` at ``level`` as the production reduction builds it, mesh seconds, FE seconds)."""
    from flexgear.fe.fem import fe_model
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.ring_shaft import PAIR, tied_pair

    settings = spec.meshing_assumed[level]
    t0 = time.perf_counter()
    meshes = [component_mesh(spec, p, level, order=1) for p in (PAIR if body == "tied" else (body,))]
    t1 = time.perf_counter()
    parts = [fe_model(m.ngsolve_mesh(), spec.material_assumed, settings.element_order) for m in meshes]
    fe = tied_pair(*parts, spec).fe if body == "tied" else parts[0]
    return fe, t1 - t0, time.perf_counter() - t1


def free_modes(fe, f_max_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """Every elastic free-free mode below ``f_max_hz``: frequencies [Hz], M-orthonormal shapes (3n, k)."""
    from flexgear.fe.cms import FreeBodySolver
    from flexgear.fe.spectrum import lowest_eigenpairs

    solver = FreeBodySolver(fe)
    m = fe.mass_operator()
    free = solver.constrained((m @ solver.R).T)  # rigid-body modes removed: (M R)^T phi = 0
    lam, vec = lowest_eigenpairs(lambda k, found, below=None: free.eigen(fe, k, m, found, below), max_hz=f_max_hz)
    return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi), vec


def groups(f_a: np.ndarray, f_b: np.ndarray) -> list[np.ndarray]:
    """Index groups 0..n-1: k and k+1 together when they lie within :data:`CLUSTER` on either level."""
    n = len(f_a)
    close = (f_a[1:] / f_a[:-1] - 1 < CLUSTER) | (f_b[1:] / f_b[:-1] - 1 < CLUSTER)
    starts = np.r_[0, np.flatnonzero(~close) + 1]
    return [np.arange(s, e) for s, e in zip(starts, np.r_[starts[1:], n], strict=True)]


def shape_agreement(nodes_b: np.ndarray, vec_b: np.ndarray, nodes_r: np.ndarray, vec_r: np.ndarray,
                    grp: list[np.ndarray]) -> tuple[np.ndarray, float]:
    """Per order pair: the subspace MAC of the reference mode (sampled at the nearest reference node of every base
    node) onto the base modes of its group; and the largest base-to-reference node distance [m]."""
    from scipy.spatial import cKDTree

    dist, near = cKDTree(nodes_r).query(nodes_b)
    n = sum(len(g) for g in grp)
    a = vec_b[:, :n].reshape(len(nodes_b), 3, n).reshape(-1, n)
    b = vec_r[:, :n].reshape(len(nodes_r), 3, n)[near].reshape(-1, n)
    out = np.empty(n)
    for g in grp:
        q, _ = np.linalg.qr(a[:, g])
        proj = q.T @ b[:, g]
        out[g] = np.sum(proj**2, axis=0) / np.sum(b[:, g] ** 2, axis=0)
    return out, float(dist.max())


def reduction_cost(spec, body: str, level: str) -> dict:
    """The production reduced body of ``body`` at ``level``, built without its cache: modes, wall time [s]."""
    t0 = time.perf_counter()
    if body == "tied":
        from flexgear.fe.ring_shaft import _tied_build

        red = _tied_build(spec, level, False)()
    else:
        from flexgear.fe.reduced import _component_reduction

        red = _component_reduction(spec, body, level, False)[1]()
    return {"reduced_modes": int(red.n_modes), "reduction_wall_s": time.perf_counter() - t0}


def _spectrum_key(spec, body: str, level: str, f_max_hz: float) -> str:
    """Hash of what a stored spectrum depends on: the gearbox (geometry, material), the settings the body is
    meshed with at the level (MeshingSettings.for_component), the limit."""
    from flexgear.spec import spec_hash

    settings = spec.meshing_assumed[level].for_component("ring" if body == "tied" else body)
    return spec_hash(spec.with_changes(meshing_assumed={}), body, settings, round(f_max_hz, 3))


def run_body(spec, body: str, base: str, ref: str, band_orders: float, criterion_pct: float,
             reduction: bool, spectra: Path | None = None) -> dict:
    """The comparison of one body (module docstring) as a dict."""
    from flexgear.theory import mesh_frequency_hz

    f_band = band_orders * mesh_frequency_hz(spec, spec.load_case.input_speed_rpm)
    row: dict = {"body": body, "base": base, "reference": ref, "band_hz": f_band,
                 **{f"{tag}_sizes_mm": list(spec.meshing_assumed[lv].sizes_mm(body))
                    for tag, lv in (("base", base), ("reference", ref))}}
    res = {}
    for tag, lv in (("base", base), ("reference", ref)):
        stored = spectra / f"{body}-{_spectrum_key(spec, body, lv, EDGE * f_band)}.npz" if spectra else None
        if stored is not None and stored.exists():
            with np.load(stored) as data:
                nodes, f, vec, n_dof = data["nodes"], data["f"], data["vec"], int(data["n_dof"])
                t_mesh, t_fe, t_eig = (float(x) for x in data["seconds"])
        else:
            fe, t_mesh, t_fe = fe_of(spec, body, lv)
            t0 = time.perf_counter()
            f, vec = free_modes(fe, EDGE * f_band)
            t_eig = time.perf_counter() - t0
            nodes, n_dof = fe.nodes, int(fe.n_dof)
            del fe
            if stored is not None:
                tmp = stored.with_suffix(f".{os.getpid()}.tmp.npz")
                np.savez(tmp, nodes=nodes, f=f, vec=vec, n_dof=n_dof, seconds=[t_mesh, t_fe, t_eig])
                tmp.replace(stored)
        res[tag] = (nodes, f, vec)
        row.update({f"{tag}_dof": n_dof, f"{tag}_in_band": int(np.count_nonzero(f < f_band)),
                    f"{tag}_mesh_s": t_mesh, f"{tag}_fe_s": t_fe, f"{tag}_eigen_s": t_eig,
                    f"{tag}_wall_s": t_mesh + t_fe + t_eig})
        print(f"  {body} {lv}: {row[f'{tag}_dof']} dof, {row[f'{tag}_in_band']} modes below {f_band:.0f} Hz; "
              f"mesh {t_mesh:.1f} s, FE {t_fe:.1f} s, eigen {t_eig:.1f} s", file=sys.stderr, flush=True)
    (nb, fb, vb), (nr, fr, vr) = res["base"], res["reference"]
    n = max(row["base_in_band"], row["reference_in_band"])
    if len(fb) < n or len(fr) < n:
        raise RuntimeError(f"{body}: {n} modes in the band, {len(fb)} / {len(fr)} computed to {EDGE} x the band")
    diff = fb[:n] / fr[:n] - 1.0
    grp = groups(fb[:n], fr[:n])
    mac, dmax = shape_agreement(nb, vb, nr, vr, grp)
    k = int(np.argmax(np.abs(diff))) if n else 0
    row.update({"pairs": n, "largest_diff_pct": float(100 * diff[k]) if n else 0.0,
                "largest_at_hz": float(fr[k]) if n else None, "largest_mode": k + 1,
                "median_abs_diff_pct": float(100 * np.median(np.abs(diff))) if n else 0.0,
                "over_criterion": int(np.count_nonzero(np.abs(diff) > criterion_pct / 100)),
                "first_over_hz": float(fr[np.flatnonzero(np.abs(diff) > criterion_pct / 100)[0]])
                if np.any(np.abs(diff) > criterion_pct / 100) else None,
                "lowest_shape_mac": float(mac.min()) if n else 1.0, "node_distance_mm": 1e3 * dmax,
                "passes": bool(np.all(np.abs(diff) <= criterion_pct / 100)),
                "frequencies_base_hz": fb[:n].round(2).tolist(), "frequencies_reference_hz": fr[:n].round(2).tolist(),
                "differences_pct": (100 * diff).round(4).tolist(), "shape_mac": mac.round(4).tolist()})
    del res, vb, vr
    if reduction:
        row.update(reduction_cost(spec, body, base))
    row["peak_rss_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e9
    return row


def print_row(r: dict) -> None:
    verdict = "PASS" if r["passes"] else "FAIL"
    sizes = (f"{r['base']} ({r['base_sizes_mm'][0]:g}/{r['base_sizes_mm'][1]:g} mm) vs "
             f"{r['reference_sizes_mm'][0]:g}/{r['reference_sizes_mm'][1]:g} mm")
    print(f"{r['body']:13s} {sizes}: band {r['band_hz']:.0f} Hz, modes {r['base_in_band']}/{r['reference_in_band']}, "
          f"largest {r['largest_diff_pct']:+.3f} % (mode {r['largest_mode']}, {r['largest_at_hz']:.0f} Hz), "
          f"median {r['median_abs_diff_pct']:.3f} %, {r['over_criterion']} over, shape MAC >= "
          f"{r['lowest_shape_mac']:.3f}; dof {r['base_dof']}/{r['reference_dof']}; wall {r['base_wall_s']:.0f}/"
          f"{r['reference_wall_s']:.0f} s; peak {r['peak_rss_gb']:.2f} GB  {verdict}", flush=True)
    if "reduction_wall_s" in r:
        print(f"{'':13s} production reduction at {r['base']}: {r['reduced_modes']} modes, "
              f"{r['reduction_wall_s']:.1f} s wall", flush=True)


def child_options(args: argparse.Namespace) -> list[str]:
    """The options of this run for a body's process."""
    out = ["--level", args.level, "--band-orders", str(args.band_orders), "--criterion-pct", str(args.criterion_pct),
           "--gearbox", args.gearbox]
    for flag, value in (("--tooth", args.tooth), ("--body", args.body), ("--base-tooth", args.base_tooth),
                        ("--base-body", args.base_body)):
        out += [flag, str(value)] if value is not None else []
    out += ["--spectra", args.spectra] if args.spectra else []
    return out + (["--half"] if args.half else []) + (["--reduction"] if args.reduction else [])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bodies", nargs="*", help=f"among {', '.join(BODIES)} (default all)")
    ap.add_argument("--level", default="coarse", help="the base level of [meshing_assumed] (the variants')")
    ap.add_argument("--half", action="store_true", help="reference: the base's tooth and body sizes halved (default)")
    ap.add_argument("--tooth", type=float, help="reference tooth size [mm]")
    ap.add_argument("--body", type=float, help="reference body size [mm]")
    ap.add_argument("--base-tooth", type=float, help="base tooth size [mm] (default the level's)")
    ap.add_argument("--base-body", type=float, help="base body size [mm] (default the level's)")
    ap.add_argument("--band-orders", type=float, default=3.0, help="band: this multiple of the mesh frequency")
    ap.add_argument("--criterion-pct", type=float, default=1.0)
    ap.add_argument("--reduction", action="store_true", help="also time the production reduction at the base level")
    ap.add_argument("--gearbox", default=str(ROOT / "model_variants" / "gearbox.toml"))
    ap.add_argument("--out", help="write the rows as JSON")
    ap.add_argument("--spectra", help="folder that keeps each level's spectrum (frequencies, shapes) for reuse")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.half and (args.tooth or args.body):
        ap.error("--half and --tooth/--body exclude each other")
    if set(args.bodies) - set(BODIES):
        ap.error(f"bodies must be among {list(BODIES)}, got {args.bodies}")

    from flexgear.spec import load_gearbox

    if args.child:  # one body in this process: its row as the last line of stdout
        spec, base, ref = levels(load_gearbox(args.gearbox), args.bodies[0], args.level, args.base_tooth,
                                 args.base_body, args.half, args.tooth, args.body)
        row = run_body(spec, args.bodies[0], base, ref, args.band_orders, args.criterion_pct, args.reduction,
                       Path(args.spectra) if args.spectra else None)
        print(json.dumps(row))
        return
    if "FLEXGEAR_CACHE_DIR" not in os.environ:
        print("note: FLEXGEAR_CACHE_DIR is not set; new meshes go to the project's meshes/", file=sys.stderr)
    rows = []
    for body in args.bodies or BODIES:
        cmd = [sys.executable, __file__, "--child", body, *child_options(args)]
        out = subprocess.run(cmd, stdout=subprocess.PIPE, text=True, cwd=ROOT)
        if out.returncode != 0:
            print(f"{body}: failed (exit {out.returncode})", flush=True)
            continue
        row = json.loads(out.stdout.strip().splitlines()[-1])
        rows.append(row)
        print_row(row)
    if args.out:
        from flexgear.cache import atomic_write_bytes

        atomic_write_bytes(Path(args.out), json.dumps(rows, indent=1).encode())
    if rows:
        print(f"{sum(r['passes'] for r in rows)} of {len(rows)} bodies within {args.criterion_pct:g} %")


if __name__ == "__main__":
    main()
