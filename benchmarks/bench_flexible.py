"""Benchmark: reduced flexible bodies of the study's components (build time, DOF, frequencies, memory).

    python benchmarks/bench_flexible.py [--level coarse] [--order 2] [--modes 20] [component ...]

Each component runs in its own process (peak memory per build = that process's max RSS).
Solid: flexgear.geometry.solids.component_solid (the geometry engineer's OCC solids); mesh: Netgen with
``maxh`` = the level's body size (global modes do not need tooth-resolved meshes); interfaces
picked geometrically until the meshing module names its regions:
sun/planet: bore; ring: the 12 bolt holes; shafts: the two end faces.
Prints one table row per component: FE DOF, times, reduced vs full free-free frequencies and the
mass-property difference to the exact (section-integral) values.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
COMPONENTS = ("sun", "planet", "ring", "input_shaft", "output_shaft")


def _interfaces(fe, spec, component):
    from flexgear.fe.cms import interface

    c = spec.components_assumed
    r = np.hypot(fe.nodes[:, 0], fe.nodes[:, 1])
    z = fe.nodes[:, 2]
    tol = 1e-6
    if component in ("sun", "planet"):
        bore = getattr(c, f"{component}_bore_diameter_mm") * 1e-3 / 2
        return [interface(fe, np.flatnonzero(np.abs(r - bore) < tol), "bore")]
    if component == "ring":
        from flexgear.geometry.layout import component_layout

        flange = [p for p in component_layout(spec, "ring").prisms if p.section.holes][0].section
        itfs = []
        for k in range(flange.holes):
            centre = flange.hole_circle_radius * np.array([np.cos(2 * np.pi * k / flange.holes),
                                                           np.sin(2 * np.pi * k / flange.holes)])
            d = np.hypot(fe.nodes[:, 0] - centre[0], fe.nodes[:, 1] - centre[1])
            sel = np.flatnonzero(np.abs(d - flange.hole_radius) < tol)
            itfs.append(interface(fe, sel, f"bolt{k}"))
        return itfs
    return [interface(fe, np.flatnonzero(np.abs(z - z.min()) < tol), "end_min"),
            interface(fe, np.flatnonzero(np.abs(z - z.max()) < tol), "end_max")]


def run_one(component: str, level: str, order: int, modes: int) -> dict:
    import ngsolve as ngs
    from netgen.meshing import meshsize
    from netgen.occ import OCCGeometry

    from flexgear.fe.cms import reduce
    from flexgear.fe.fem import fe_model
    from flexgear.geometry.layout import exact_mass_properties
    from flexgear.geometry.solids import component_solid
    from flexgear.spec import load_gearbox

    spec = load_gearbox(ROOT / "model_variants" / "gearbox.toml")
    size = spec.meshing_assumed[level].body_size_mm * 1e-3
    t0 = time.perf_counter()
    solid = component_solid(spec, "planet" if component == "planet" else component)
    t_geo = time.perf_counter() - t0
    # very_coarse: default curvature refinement gave the sun 993 k tetrahedra at maxh = 8 mm
    mesh = ngs.Mesh(OCCGeometry(solid).GenerateMesh(meshsize.very_coarse, maxh=size))
    t_mesh = time.perf_counter() - t0 - t_geo
    t1 = time.perf_counter()
    fe = fe_model(mesh, spec.material_assumed, order)
    t_fe = time.perf_counter() - t1
    itfs = _interfaces(fe, spec, component)
    body = reduce(fe, itfs, modes, kind=spec.reduction_assumed.interface, n_compare=12)
    exact = exact_mass_properties(spec, component)
    k = min(6, len(body.full_frequencies_hz))
    return {
        "component": component, "tets": mesh.ne, "nodes": fe.n_nodes, "dof": fe.n_dof,
        "interfaces": len(itfs), "itf_nodes": int(sum(len(i.nodes) for i in itfs)), "modes": body.n_modes,
        "geometry_s": round(t_geo, 2), "mesh_s": round(t_mesh, 2), "fe_s": round(t_fe, 2),
        "reduce_s": round(body.info["total_time_s"], 2),
        "full_hz": np.round(body.full_frequencies_hz[:k], 1).tolist(),
        "reduced_hz": np.round(body.frequencies_hz[:k], 1).tolist(),
        "max_rel_err_first6": float(np.max(np.abs(body.frequencies_hz[:k] / body.full_frequencies_hz[:k] - 1))),
        "mass_rel_err": body.props.mass / exact.mass - 1,
        "izz_rel_err": body.props.inertia[2, 2] / exact.inertia[2, 2] - 1,
        "ixx_rel_err": body.props.inertia[0, 0] / exact.inertia[0, 0] - 1,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "npz_mb": len(body.save()) / 1e6,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("components", nargs="*", default=list(COMPONENTS))
    ap.add_argument("--level", default="coarse")
    ap.add_argument("--order", type=int, default=2)
    ap.add_argument("--modes", type=int, default=20)
    ap.add_argument("--one", action="store_true", help="internal: run one component in this process")
    a = ap.parse_args()
    if a.one:
        print(json.dumps(run_one(a.components[0], a.level, a.order, a.modes)))
        return 0
    rows = []
    for comp in a.components:
        print(f"[bench_flexible] {comp} ...", file=sys.stderr, flush=True)
        out = subprocess.run([sys.executable, __file__, comp, "--one", "--level", a.level, "--order",
                              str(a.order), "--modes", str(a.modes)], capture_output=True, text=True)
        if out.returncode:
            print(f"{comp}: failed\n{out.stderr[-2000:]}", file=sys.stderr)
            continue
        row = json.loads(out.stdout.strip().splitlines()[-1])
        rows.append(row)
        print(json.dumps(row), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
