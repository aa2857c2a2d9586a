"""Components from the user's own geometry: ``[components_geometry]`` of the gearbox file (flexgear.schema_geometry).

A component's entry names a file in the component's frame (the frame ``flexgear export-geometry`` writes: z the
axis, the built-in component's origin), in ``length_unit``:

- **a solid** (STEP, BREP): read by OpenCascade, scaled to metres and stored in the cache as the component's
  solid (``solid-<name>-<key>.brep``, the key hashing the file's content, flexgear.geometry.layout.geometry_hash);
  from there it is meshed exactly as a built-in solid, at the variant's mesh level (flexgear.fe.mesh.source_mesh:
  the level's sizes, tooth size on the faces inside the tooth band, edge nodes on the true surfaces);
- **a volume mesh** (``.vtu``, ``.msh``, ``.inp``, any file meshio reads, of first- or second-order tetrahedra):
  used as it is, whatever the mesh level's sizes (:class:`ImportedMesh`). A second-order file keeps its edge
  nodes; a first-order one is raised to second order with straight edges when the level's element order is 2.

Either way the regions the reduction needs are found by geometry on the mesh, by the built-in parts' rules from
the gear data (flexgear.fe.mesh.region_nodes, flexgear.fe.reduced.component_interfaces), so that a part exported
and imported again gets the same regions; a region the entry's ``regions`` names is found by its selector instead
(a cylinder, a point set, a physical group of the mesh file: flexgear.fe.selectors), under the same name. A part
is refused, in one line naming the component and the file
(:class:`GeometryFileError`), when its file cannot be read, holds no solid or several, is far larger or smaller
than its gear data (a wrong ``length_unit``), when its teeth do not match the gear data (tip or root radius, or
flanks off the involute flanks of the gear data's tooth count, module, helix and profile shift, at any rotation),
or when a region finds no node (or, but the flanks, nodes holding no whole boundary face), or a selector finds no
node or nodes on more than one surface (the message names the selector).
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from flexgear.cache import cache_dir
from flexgear.design import Design, as_design
from flexgear.fe.mesh import (
    GRADING,
    MESH_VERSION,
    ComponentMesh,
    MeshSizes,
    MeshSource,
    region_nodes,
    source_mesh,
)
from flexgear.fe.mesh_io import MeshFileError, boundary_faces, netgen_mesh, read_volume_mesh
from flexgear.fe.parts import cached_brep, quiet_occ, register_file_parts
from flexgear.fe.selectors import SelectorError, group_points, selected_regions, whole_faces
from flexgear.geometry.layout import ComponentLayout, geometry_hash
from flexgear.schema_geometry import CONTACT_BAND, SELECTABLE_REGIONS, ComponentGeometry
from flexgear.spec import GearboxSpec

__all__ = ["GeometryFileError", "ImportedMesh", "imported_brep", "imported_mesh", "check_imported_mesh",
           "read_solid", "check_extent", "volume_arrays", "IMPORT_VERSION"]

IMPORT_VERSION = 1
"""Bump when the import's construction changes without the file or a config value changing (enters the keys)."""
_UNIT_RATIO = 3.0
"""A part whose radial extent differs from its gear data's by more than this factor has the wrong length unit."""
_RADIUS_TOL = 0.02
"""Tip and root radii must match the gear data within this many normal modules."""
_FLANK_TOL = 0.05
"""90 % of the flank nodes must lie within this many normal modules of the gear data's involute flanks."""
_PHASES = 96
"""Rotations tried per pitch to align a part's teeth with the gear data's, before a finer search."""


class GeometryFileError(ValueError):
    """A component's geometry file is refused: one line naming the component, the file and the reason."""

    def __init__(self, component: str, entry: ComponentGeometry, reason: str):
        super().__init__(f"[components_geometry] {component}: {entry.source}: {reason}")


def imported_brep(spec: GearboxSpec | Design, component: str, progress: bool = False) -> Path:
    """Path of the cached solid (``.brep``, metres) of ``component`` read from its ``[components_geometry]`` file;
    read, checked (one solid, its extent against the gear data) and stored on a cache miss."""
    d = as_design(spec)
    entry, layout = d.spec.components_geometry[component], d.layouts[component]
    if entry.kind == "mesh":
        raise GeometryFileError(component, entry, "is a volume mesh; it has no solid (export its mesh instead)")
    path = cache_dir() / f"solid-{layout.name}-{geometry_hash(d.spec, component, IMPORT_VERSION)}.brep"

    def read() -> object:
        return read_solid(component, entry, d.layouts[component].outer_radius)

    return cached_brep(path, read, f"{component}: solid read from {entry.source.name}", progress)


def read_solid(component: str, entry: ComponentGeometry, expected_radius: float):
    """The one solid of ``component``'s STEP or BREP file, scaled to metres (netgen.occ); refused
    (:class:`GeometryFileError`) when the file cannot be read, holds no solid or several, has no volume, or reaches
    far from ``expected_radius`` [m] (:func:`check_extent`)."""
    from netgen.occ import OCCGeometry, Pnt

    try:
        with quiet_occ():
            shape = OCCGeometry(str(entry.source)).shape
    except Exception as exc:  # netgen raises NgException or RuntimeError for a damaged file
        raise GeometryFileError(component, entry, f"cannot be read as {entry.kind.upper()} "
                                f"({exc.__class__.__name__}: {' '.join(str(exc).split())[:120]})") from None
    solids = shape.solids
    if len(solids) != 1:
        raise GeometryFileError(component, entry, f"holds {len(solids)} solids ({len(shape.faces)} faces); "
                                "expected one closed solid")
    solid = solids[0]
    if not solid.mass > 0:
        raise GeometryFileError(component, entry, f"its solid has no volume ({solid.mass})")
    if entry.scale != 1.0:
        solid = solid.Scale(Pnt(0, 0, 0), entry.scale)
    lo, hi = solid.bounding_box
    check_extent(component, entry, expected_radius, max(abs(lo[0]), abs(lo[1]), abs(hi[0]), abs(hi[1])))
    return solid


def check_extent(component: str, entry: ComponentGeometry, expected: float, radius: float) -> None:
    """Refuse a part whose largest radius ``radius`` [m] is far from the gear data's ``expected`` [m] (a wrong
    length unit)."""
    if not (expected / _UNIT_RATIO < radius < expected * _UNIT_RATIO):
        raise GeometryFileError(component, entry, f"reaches r = {radius:.6g} m with length_unit = "
                                f"{entry.length_unit!r}, but the gear data give {expected:.6g} m: is the length "
                                f"unit wrong (allowed: 'm', 'mm')?")


class ImportedMesh(ComponentMesh):
    """A component's volume mesh from a file (:func:`imported_mesh`): the arrays of the requested order, and
    :meth:`ngsolve_mesh` the mesh of the level's element order ``fe_order`` as the FE model takes it."""

    fe_arrays: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def ngsolve_mesh(self):
        """The NGSolve mesh of the element order the FE model is made of (second order: the file's edge nodes, or
        mid-edge nodes of a first-order file), whatever order this mesh's arrays have."""
        import ngsolve

        return ngsolve.Mesh(netgen_mesh(*self.fe_arrays))


def volume_arrays(volume, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nodes, elements, boundary triangles) of ``volume`` at element ``order``: its vertices alone for 1; for 2 its
    own edge nodes, or the edges' midpoints of a first-order file (appended after the vertices)."""
    el = volume.elements
    if order == 1:
        n = int(el[:, :4].max()) + 1
        return volume.nodes[:n], el[:, :4], boundary_faces(el[:, :4], volume.nodes[:n])
    nodes = volume.nodes
    if el.shape[1] == 4:
        pairs = np.sort(el[:, [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]].reshape(-1, 2), axis=1)
        edges, inverse = np.unique(pairs, axis=0, return_inverse=True)
        nodes = np.vstack([nodes, 0.5 * (nodes[edges[:, 0]] + nodes[edges[:, 1]])])
        el = np.column_stack([el, len(volume.nodes) + inverse.reshape(-1, 6)])
    return nodes, el, boundary_faces(el, nodes)


def imported_mesh(spec: GearboxSpec | Design, component: str, level: str, order: int,
                  progress: bool = False) -> ComponentMesh:
    """The mesh of ``component`` from its ``[components_geometry]`` file at mesh ``level`` and element ``order``
    (module docstring). The mesh of the level's element order (the FE model's nodes) is checked
    (:func:`check_imported_mesh`), whatever ``order``. A solid is meshed and cached like a built-in one."""
    d = as_design(spec)
    spec = d.spec
    entry, settings = spec.components_geometry[component], spec.meshing_assumed[level]

    def regions(nodes: np.ndarray, boundary: np.ndarray) -> dict[str, np.ndarray]:
        return region_nodes(d, component, nodes, boundary)

    if entry.kind == "mesh":
        try:
            volume = read_volume_mesh(entry.source, entry.scale)
        except MeshFileError as exc:
            raise GeometryFileError(component, entry, str(exc).split(": ", 1)[1]) from None
        check_extent(component, entry, d.layouts[component].outer_radius,
                     float(np.hypot(*volume.nodes[:, :2].T).max()))
        meshes = {}
        for k in {order, settings.element_order}:
            nodes, elements, surface = volume_arrays(volume, k)
            meshes[k] = ImportedMesh(component, level, k, nodes, elements, surface, regions(nodes, np.unique(surface)))
            meshes[k].fe_arrays = volume_arrays(volume, settings.element_order)
        mesh, checked = meshes[order], meshes[settings.element_order]
    else:
        solid_key = geometry_hash(spec, component, IMPORT_VERSION)
        imported_brep(d, component, progress)  # the cache entry source_mesh reads as the component's solid
        source = MeshSource(d.layouts[component], level, MeshSizes.of(settings, component), settings.element_order,
                            solid_key,
                            lambda o: geometry_hash(spec, component, settings.for_component(component), o, GRADING,
                                                    MESH_VERSION, IMPORT_VERSION), regions)
        try:
            mesh = source_mesh(source, order, progress)
            checked = mesh if order == settings.element_order else source_mesh(source, settings.element_order, progress)
        except GeometryFileError:
            raise
        except Exception as exc:  # Netgen fails on a solid it cannot mesh
            raise GeometryFileError(component, entry, f"cannot be meshed at level {level!r} "
                                    f"({exc.__class__.__name__}: {' '.join(str(exc).split())[:120]})") from None
    if entry.regions:  # the named regions, checked on the FE model's nodes (of the level's order)
        _select(d, component, entry, checked, True)
        if mesh is not checked:
            _select(d, component, entry, mesh, False)
    check_imported_mesh(d, component, checked, entry)  # the regions the FE model's nodes (of the level's order) get
    return mesh


def _select(d: Design, component: str, entry: ComponentGeometry, mesh: ComponentMesh, strict: bool) -> None:
    """``mesh``'s regions with those the entry's selectors name found by them (flexgear.fe.selectors); ``strict``:
    a selection that finds no node or more than one surface is refused (:class:`GeometryFileError`)."""
    holes = sum(q.section.holes for q in d.layouts[component].prisms)
    try:
        groups = group_points(entry.source, entry.scale) if any(s.group for s in entry.regions) else None
        mesh.regions = selected_regions(entry.regions, mesh.regions, holes, mesh.nodes, mesh.surface, groups, strict)
    except SelectorError as exc:
        raise GeometryFileError(component, entry, f"selector {exc}") from None


_REGIONS = {c: tuple(n for n in names if "<" not in n and n != CONTACT_BAND) for c, names in SELECTABLE_REGIONS.items()}
"""The mesh regions of each component that its reduction's interfaces and contact bands stand on."""


def _check_contact_band(d: Design, component: str, entry: ComponentGeometry, band, nodes: np.ndarray) -> None:
    """Refuse a ``contact_band`` selector whose band (its radius +- its radial half-width, the gear data's one normal
    module when it gives none, over its axial range) holds no node of the part's mesh."""
    if band.axis != (0.0, 0.0):
        raise GeometryFileError(component, entry, f"selector {band.describe()}: a contact band lies about the gear's "
                                "axis (axis_<unit> = [0, 0])")
    half = band.tolerance or d.spec.gears.normal_module_m
    r, z = np.hypot(nodes[:, 0] - band.axis[0], nodes[:, 1] - band.axis[1]), nodes[:, 2]
    inside = np.abs(r - band.radius) <= half
    if band.z_range is not None:
        inside &= (z >= band.z_range[0]) & (z <= band.z_range[1])
    if not inside.any():
        raise GeometryFileError(component, entry, f"selector {band.describe()} finds no node of its mesh within "
                                f"{half * 1e3:g} mm of that circle")


def check_imported_mesh(d: Design, component: str, mesh: ComponentMesh, entry: ComponentGeometry) -> None:
    """Refuse (:class:`GeometryFileError`) an imported mesh whose regions find no node (or, but the flanks, nodes
    that hold no whole boundary face: no surface), or whose teeth do not match the gear data
    (:func:`_check_teeth`); the bolts' clamped discs must each hold nodes (flexgear.fe.bolted)."""
    selected = {s.region for s in entry.regions}
    band = next((s for s in entry.regions if s.region == CONTACT_BAND), None)
    if band is not None:
        _check_contact_band(d, component, entry, band, mesh.nodes)
    for name in _REGIONS[component]:
        if name == "bolt_discs" and name not in selected:
            continue  # the built-in discs: checked below
        nodes = mesh.regions.get(name, np.zeros(0, np.int64))
        if not len(nodes) or (name != "flanks" and not len(whole_faces(nodes, mesh.nodes, mesh.surface))):
            plural = "s" if len(nodes) > 1 else ""
            found = f" on a surface ({len(nodes)} node{plural}, no whole boundary face)" if len(nodes) else ""
            raise GeometryFileError(component, entry, f"region {name!r} finds no node{found} on its mesh (by the "
                                    "gear data's rule, flexgear.fe.mesh.region_nodes): is the part in the "
                                    "component's frame and of the gear data's dimensions?")
    if component in ("ring", "output_shaft") and "bolt_discs" not in selected:
        from flexgear.fe.bolted import clamped_patches

        try:
            clamped_patches(SimpleNamespace(nodes=mesh.nodes), d)
        except ValueError as exc:
            raise GeometryFileError(component, entry, f"bolt clamped disc: {exc}") from None
    layout = d.layouts[component]
    if layout.gear is not None:
        _check_teeth(component, entry, layout, mesh, d.spec.gears.normal_module_m)


def _check_teeth(component: str, entry: ComponentGeometry, layout: ComponentLayout, mesh: ComponentMesh,
                 module: float) -> None:
    """Tip and root radius within ``_RADIUS_TOL`` normal modules of the gear data's; 90 % of the flank nodes within
    ``_FLANK_TOL`` normal modules of the involute flanks of the gear data (tooth count, module, pressure and helix
    angles, profile shift), at the rotation that fits best; every flank of every tooth carries nodes."""
    g = layout.gear
    boundary = np.unique(mesh.surface)
    p = mesh.nodes[boundary]
    r, z = np.hypot(p[:, 0], p[:, 1]), p[:, 2]
    tol_z = 0.01 * module
    inside = np.zeros(len(p), bool)
    for q in layout.prisms:
        if q.section.gear is not None:
            inside |= (z > q.z0 + tol_z) & (z < q.z1 - tol_z)
    r_in = r[inside]
    sign = -1.0 if g.internal else 1.0  # tips at the largest radius of an external gear, the smallest of internal
    tip = float(sign * np.max(sign * r_in))
    window = r_in[sign * (r_in - g.root_radius) > -0.5 * module]
    root = float(-sign * np.max(-sign * window)) if len(window) else math.nan
    for what, got, want in (("tip", tip, g.tip_radius), ("root", root, g.root_radius)):
        if not abs(got - want) <= _RADIUS_TOL * module:
            raise GeometryFileError(component, entry, f"{what} radius {got * 1e3:.4f} mm, the gear data's "
                                    f"{want * 1e3:.4f} mm (allowed: within {_RADIUS_TOL} m_n)")
    _check_flanks(component, entry, layout, mesh.nodes[mesh.regions["flanks"]], module)


def _check_flanks(component: str, entry: ComponentGeometry, layout: ComponentLayout, points: np.ndarray,
                  module: float) -> None:
    g = layout.gear
    pitch = 2 * math.pi / g.teeth
    r, theta, z = np.hypot(points[:, 0], points[:, 1]), np.arctan2(points[:, 1], points[:, 0]), points[:, 2]
    psi = np.array([g.tooth_half_angle(x) for x in r])
    toothed = [q for q in layout.prisms if q.section.gear is not None]
    twist = np.zeros(len(points))
    for q in toothed:
        twist[(z >= q.z0 - 1e-9) & (z <= q.z1 + 1e-9)] = q.twist
    base = theta - twist * z

    def residual(phase: float) -> np.ndarray:
        both = np.stack([(base - phase - s * psi + pitch / 2) % pitch - pitch / 2 for s in (1.0, -1.0)])
        return both[np.abs(both).argmin(axis=0), np.arange(len(points))]

    def spread(phase: float) -> float:
        return float(np.percentile(np.abs(residual(phase)), 90))

    step = pitch / _PHASES
    phase = min((k * step for k in range(_PHASES)), key=spread)
    for _ in range(3):  # finer grids around the best rotation
        step /= 8
        phase = min((phase + k * step for k in range(-8, 9)), key=spread)
    worst = spread(phase) * g.base_radius
    if not worst <= _FLANK_TOL * module:
        raise GeometryFileError(component, entry, f"its flanks do not match the involute flanks of the gear data's "
                                f"{g.teeth} teeth (module, pressure and helix angles, profile shift): 90 % "
                                f"of the flank nodes within {worst * 1e3:.3f} mm of the involute flanks at the best "
                                f"rotation (allowed: {_FLANK_TOL} m_n = {_FLANK_TOL * module * 1e3:.3f} mm)")
    half = np.floor((base - phase) / (pitch / 2)).astype(np.int64) % (2 * g.teeth)
    if len(np.unique(half)) != 2 * g.teeth:
        raise GeometryFileError(component, entry, f"flank nodes on {len(np.unique(half))} of the "
                                f"{2 * g.teeth} flanks of the gear data's {g.teeth} teeth")


register_file_parts(imported_brep, imported_mesh)
