"""The components' solids as STEP and their volume meshes as VTU (``flexgear export-geometry``).

- ``<component>.step``: the component's OCC solid (flexgear.fe.mesh.component_brep) in **millimetres**, the CAD
  convention (the file declares its unit, mm), in the component's frame: z the axis, the origin where the
  multibody model places the component's frame (the sun's and planets' centres on their axial mid-plane, the
  ring and the shafts in the gearbox frame). Read back with ``length_unit = "mm"`` in ``[components_geometry]``.
- ``<component>.vtu``: its volume mesh at the mesh level (flexgear.fe.mesh.component_mesh, the level's element
  order: VTK ``tetra10`` in VTK's node order, flexgear.fe.mesh_io) in **metres**, the FE model's unit, with one
  point-data array per mesh region (``flanks``, ``bore``, ``bolt_hole_<k>``, ``bearing_seat`` ...), per interface
  of the component's reduction (``interface_<name>``: ``bore``, ``bolt_patches`` the clamped discs, ``sun_seat``,
  ``bearing_seat``) and per contact band of a gear (``contact_band_<k>``: the nodes the contact kernel reads),
  1 on the set's nodes, else 0. Read back with ``length_unit = "m"``.

A component whose geometry is a volume mesh file (``[components_geometry]``) has no solid: only its VTU is written.
The planetary stage's carrier (flexgear.fe.carrier) is written the same way, in the gearbox frame (its origin on the
axis at the planets' mid-plane), its point sets its faces ``seat`` and ``pin_<k>`` and the same sets as its reduction's
interfaces (``interface_seat``, ``interface_pin_<k>``).
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np

from flexgear.design import as_design
from flexgear.fe.mesh import component_brep, component_mesh
from flexgear.fe.mesh_io import write_vtu
from flexgear.fe.parts import STEP_UNIT_MM, write_step_mm
from flexgear.spec import CARRIER, GearboxSpec, stage_geometries

__all__ = ["export_geometry", "exported_components", "write_step", "STEP_UNIT_MM"]

def write_step(brep: Path | object, path: Path) -> Path:
    """The solid of ``brep`` (a ``.brep`` file or an OCC shape, metres) as a STEP file in millimetres at ``path``."""
    from netgen.occ import OCCGeometry

    return write_step_mm(OCCGeometry(str(brep)).shape if isinstance(brep, Path) else brep, path)


def _point_sets(spec: GearboxSpec, component: str, nodes: np.ndarray, regions: dict) -> dict[str, np.ndarray]:
    """The mesh's regions, its reduction's interfaces and a gear's contact bands as node sets (module docstring)."""
    from flexgear.fe.attachment import circle_band
    from flexgear.fe.reduced import component_interfaces, component_load_circles

    d = as_design(spec)
    sets = dict(regions)
    shell = SimpleNamespace(nodes=nodes, regions={}, region_weights={})  # node positions are all they read
    for itf in component_interfaces(shell, d, component):
        sets[f"interface_{itf.name}"] = itf.nodes
    for k, circle in enumerate(component_load_circles(d, component, spec.reduction_assumed.contact_fourier_order)):
        sets[f"contact_band_{k}"] = circle_band(nodes, circle)
    return sets


def exported_components(spec: GearboxSpec) -> tuple[str, ...]:
    """The components ``flexgear export-geometry`` writes for ``spec``: every geometry component, and in the
    planetary arrangement the carrier."""
    return (*stage_geometries(spec.gears), *((CARRIER,) if spec.gears.arrangement == "planetary" else ()))


def _carrier_files(spec: GearboxSpec, level: str, folder: Path) -> list[Path]:
    """The carrier's STEP and VTU (module docstring)."""
    from flexgear.fe.carrier import carrier_exchange_solid, carrier_interfaces, carrier_volume_mesh
    from flexgear.geometry.carrier import carrier_sizes

    sizes = carrier_sizes(spec)
    fe, elements = carrier_volume_mesh(spec, level, sizes)
    sets = {**fe.regions, **{f"interface_{itf.name}": itf.nodes for itf in carrier_interfaces(fe, sizes)}}
    return [write_step(carrier_exchange_solid(sizes), folder / f"{CARRIER}.step"),
            write_vtu(folder / f"{CARRIER}.vtu", fe.nodes, elements, sets)]


def export_geometry(spec: GearboxSpec, components: tuple[str, ...] | None = None, level: str = "coarse",
                    out: str | Path = "geometry", progress: bool = False) -> list[Path]:
    """Write ``<component>.step`` and ``<component>.vtu`` of each of ``components`` (default
    :func:`exported_components`) at mesh ``level`` into ``out`` (module docstring); the paths written."""
    allowed = exported_components(spec)
    components = allowed if components is None else components
    if level not in spec.meshing_assumed:
        raise ValueError(f"unknown mesh level {level!r}; the gearbox has {', '.join(sorted(spec.meshing_assumed))}")
    for c in components:
        if c == CARRIER and c not in allowed:
            raise ValueError(f"component 'carrier': the {spec.gears.arrangement} arrangement holds its carrier, "
                             "which has no solid (a carrier needs [gears] arrangement = 'planetary')")
        if c not in allowed:
            raise ValueError(f"unknown component {c!r}; allowed: {', '.join(allowed)}")
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for c in components:
        if c == CARRIER:
            written += _carrier_files(spec, level, folder)
            continue
        entry = spec.components_geometry.get(c)
        if entry is None or entry.kind != "mesh":
            written.append(write_step(component_brep(spec, c, progress), folder / f"{c}.step"))
        mesh = component_mesh(spec, c, level, progress=progress)
        sets = _point_sets(spec, c, mesh.nodes, mesh.regions)
        written.append(write_vtu(folder / f"{c}.vtu", mesh.nodes, mesh.elements, sets))
    return written
