"""Benchmark: cold build of every component's OCC solid and Netgen meshes at the configured levels.

Run: python benchmarks/bench_meshes.py [--runs level[:order] ...] [--components sun ring ...] [--keep DIR]

Everything is built in a fresh, temporary cache folder (``FLEXGEAR_CACHE_DIR``), so nothing is
reused from ``meshes/``. Per component the solid is built once (flexgear.fe.mesh.component_brep)
and meshed at each run (default: ``coarse`` at its order, ``coarse:2`` as the geometry tests use
it, ``default``). Prints one row per component and run: tetrahedra, nodes, solid time, mesh time
(Netgen, from reading the ``.brep`` to the last node), the smallest element shape quality of the
vertex tetrahedra (mean ratio 12 (3V)^(2/3) / sum of squared edge lengths: 1 regular, 0 flat) and
the mesh-vs-exact differences of mass and Izz (flexgear.fe.mesh.mass_check: trimesh on the
boundary, second-order faces sampled through their quadratic map). The solid's own OCC volume
against the exact section integrals is printed once per component.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
COMPONENTS = ("sun", "planet", "ring", "input_shaft", "output_shaft")


def shape_quality(nodes: np.ndarray, elements: np.ndarray) -> float:
    """Smallest mean-ratio quality of the tetrahedra spanned by the first four nodes of each element."""
    p = nodes[elements[:, :4]]
    a, b, c = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    volume = np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6
    edges2 = sum(np.sum((p[:, i] - p[:, j]) ** 2, axis=1) for i in range(4) for j in range(i + 1, 4))
    return float((12 * (3 * volume) ** (2 / 3) / edges2).min())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", nargs="+", default=["coarse", "coarse:2", "default"],
                    help="mesh level, optionally :order (default: coarse coarse:2 default)")
    ap.add_argument("--components", nargs="+", default=list(COMPONENTS), choices=COMPONENTS)
    ap.add_argument("--gearbox", default=str(ROOT / "model_variants" / "gearbox.toml"))
    ap.add_argument("--keep", help="build in this folder and keep it (default: a temporary folder, removed)")
    a = ap.parse_args()
    folder = Path(a.keep) if a.keep else Path(tempfile.mkdtemp(prefix="flexgear-bench-meshes-"))
    os.environ["FLEXGEAR_CACHE_DIR"] = str(folder)

    import netgen.occ as occ

    from flexgear.fe.mesh import component_brep, component_mesh, mass_check
    from flexgear.geometry.layout import exact_mass_properties
    from flexgear.spec import load_gearbox

    spec = load_gearbox(a.gearbox)
    rho = spec.material_assumed.density_kg_m3
    print(f"cache folder {folder} (cold)", flush=True)
    header = (f"{'component':<13}{'level':<8}{'order':>5}{'tets':>9}{'nodes':>9}{'solid s':>9}{'mesh s':>8}"
              f"{'q_min':>7}{'mass err %':>12}{'Izz err %':>11}")
    rows = []
    try:
        for name in a.components:
            t0 = time.perf_counter()
            brep = component_brep(spec, name)
            t_solid = time.perf_counter() - t0
            shape = occ.OCCGeometry(str(brep)).shape
            exact = exact_mass_properties(spec, name)
            print(f"{name}: solid {t_solid:.1f} s, {len(shape.faces)} faces, OCC mass vs exact "
                  f"{100 * (rho * shape.mass / exact.mass - 1):+.5f} %", flush=True)
            for run in a.runs:
                level, _, order = run.partition(":")
                mesh = component_mesh(spec, name, level, order=int(order) if order else None)
                err = mass_check(spec, mesh)
                row = (f"{name:<13}{level:<8}{mesh.order:>5}{mesh.n_elements:>9}{mesh.n_nodes:>9}{t_solid:>9.1f}"
                       f"{mesh.build_time_s:>8.1f}{shape_quality(mesh.nodes, mesh.elements):>7.3f}"
                       f"{100 * err['mass']:>+12.4f}{100 * err['izz']:>+11.4f}")
                rows.append(row)
                print(row, flush=True)
    finally:
        if not a.keep:
            shutil.rmtree(folder, ignore_errors=True)
    print()
    print(header)
    print("\n".join(rows))


if __name__ == "__main__":
    main()
