"""What does meshing the built-in solids in their STEP exchange form cost, and what does the round trip give?

Run: nice -n 5 python benchmarks/bench_step_round_trip.py [GEARBOX] [--components sun planet ring ...]
                                                          [--round-trip ring] [--level coarse] [--reduce]

- cost: per component of GEARBOX (default the study's), the solid built in memory
  (flexgear.geometry.solids.component_solid) and its exchange form (flexgear.fe.parts.exchange_form: written as
  STEP in mm and read back), wall time of each; whether a second round trip changes the form (its BREP bytes).
- round trip: each ``--round-trip`` component exported by ``flexgear export-geometry`` as STEP and imported again
  (``[components_geometry]``, in a private cache) against the built-in one at ``--level``: first-order mesh nodes
  and elements, the largest node distance; with ``--reduce`` also the reduced bodies: mass, the free-free modes and
  the modes clamped on ``bolt_patches`` (a ring) below 3x the mesh frequency (largest relative difference), the
  compliance at the contact bands under the contact kernel's loads (largest difference / largest term).
"""

from __future__ import annotations

import argparse
import hashlib
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _brep_digest(shape, folder: Path) -> str:
    path = folder / "shape.brep"
    shape.WriteBrep(str(path))
    return hashlib.sha256(path.read_bytes()).hexdigest()


def cost(gearbox: Path, components: list[str]) -> None:
    from flexgear.design import as_design
    from flexgear.fe.parts import exchange_form
    from flexgear.geometry.solids import component_solid
    from flexgear.spec import load_gearbox

    d = as_design(load_gearbox(gearbox))
    print("component: solid built [s]; exchange form [s]; a second round trip changes it", flush=True)
    with tempfile.TemporaryDirectory() as folder:
        for name in components:
            t0 = time.perf_counter()
            solid = component_solid(d.layouts[name])
            t1 = time.perf_counter()
            form = exchange_form(solid)
            t2 = time.perf_counter()
            again = _brep_digest(exchange_form(form), Path(folder)) != _brep_digest(form, Path(folder))
            print(f"  {name}: {t1 - t0:.1f}; {t2 - t1:.1f}; {'yes' if again else 'no'}", flush=True)


def round_trip(gearbox: Path, component: str, level: str, reduce: bool) -> None:
    from flexgear.cli import main
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.spec import load_gearbox

    spec = load_gearbox(gearbox)
    built = component_mesh(spec, component, level, order=1)
    built_body = component_reduced_body(spec, component, level) if reduce else None
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        assert main(["export-geometry", str(gearbox), "--component", component, "--level", level, "--out",
                     str(out)]) == 0
        copy = out / "gearbox.toml"
        copy.write_text(gearbox.read_text() + f'\n[components_geometry]\n{component} = '
                        f'{{ file = "{out / (component + ".step")}", length_unit = "mm" }}\n')
        os.environ["FLEXGEAR_CACHE_DIR"] = str(out / "cache")
        imported_spec = load_gearbox(copy)
        mesh = component_mesh(imported_spec, component, level, order=1)
        same = len(mesh.nodes) == len(built.nodes)
        far = float(np.abs(mesh.nodes - built.nodes).max()) if same else float("nan")
        equal = same and np.array_equal(mesh.elements, built.elements)
        print(f"{component} ({level}) round trip: nodes {len(mesh.nodes)} / {len(built.nodes)}; elements "
              f"{len(mesh.elements)} / {len(built.elements)}; largest node distance {far:.3g} m; elements "
              f"{'identical' if equal else 'differ'}", flush=True)
        if reduce:
            _bodies(spec, built_body, component_reduced_body(imported_spec, component, level), component)


def _bodies(spec, built, imported, component: str) -> None:
    import scipy.linalg as la

    import flexgear as fg
    from flexgear.fe.joined import body_matrices, joint_rows
    from flexgear.fe.reduced import component_contacts, component_load_circles
    from flexgear.theory import mesh_frequency_hz

    band = 3 * mesh_frequency_hz(spec, spec.load_case.input_speed_rpm)

    def held(body) -> np.ndarray:
        mass, stiffness = body_matrices(body)
        basis = la.null_space(joint_rows(body, "bolt_patches", body.interface("bolt_patches").point))
        return np.sqrt(la.eigh(basis.T @ stiffness @ basis, basis.T @ mass @ basis, eigvals_only=True)) / (2 * np.pi)

    def free(body) -> np.ndarray:
        f = np.sort(np.asarray(body.frequencies_hz, float))
        return f[f > 1.0]

    print(f"  mass: {imported.props.mass / built.props.mass - 1:.3g}")
    kinds = [("free-free", free)] + ([("clamped on bolt_patches", held)] if component == "ring" else [])
    for label, fn in kinds:
        ref, got = fn(built), fn(imported)
        ref = ref[ref < band]
        print(f"  {label} modes below {band:.0f} Hz ({len(ref)}): largest difference "
              f"{np.abs(got[:len(ref)] / ref - 1).max():.3g}")
    if component == "ring":
        points, normals = component_contacts(spec, component)
        kernel = component_load_circles(spec, component, spec.reduction_assumed.contact_fourier_order)
        c_imp, c_ref = (fg.static_compliance(b, points, normals, "bolt_patches", kernel=kernel)
                        for b in (imported, built))
        print(f"  compliance at the contact bands: largest difference / largest term "
              f"{np.max(np.abs(c_imp - c_ref)) / np.max(np.abs(c_ref)):.3g}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gearbox", nargs="?", type=Path, default=ROOT / "model_variants" / "gearbox.toml")
    parser.add_argument("--components", nargs="*", default=["sun", "planet", "ring", "input_shaft", "output_shaft"])
    parser.add_argument("--round-trip", nargs="*", default=["ring"])
    parser.add_argument("--level", default="coarse")
    parser.add_argument("--reduce", action="store_true")
    args = parser.parse_args(argv)
    if args.components:
        cost(args.gearbox, args.components)
    for component in args.round_trip:
        round_trip(args.gearbox, component, args.level, args.reduce)
    return 0


if __name__ == "__main__":
    sys.exit(main())
