"""The planet carrier from the user's file: ``[components_geometry] carrier`` of a planetary stage.

The file (a STEP or BREP solid, or a volume mesh, flexgear.schema_geometry) holds the carrier in its component frame
(z the gearbox axis, the origin on the planets' axial mid-plane, planet k's pin at the gear data's polar angle psi_k
on the pin circle, the operating centre distance a_w: the frame ``flexgear export-geometry`` writes). A solid is
meshed at the variant's mesh level as the built-in carrier is (the level's body size, its tooth size on the pin
bores), then raised to the level's element order on its true surfaces; a volume mesh is used as it is
(flexgear.fe.imported.volume_arrays). The interfaces the reduction needs (flexgear.fe.carrier) are found by
geometry on the mesh's boundary nodes:

- ``pin_<k>``: the boundary nodes nearest planet k's pin axis (within :data:`REGION_TOL` of the smallest distance
  of any boundary node to it): the pin bores, in every plate that holds the pin;
- ``seat``: the boundary nodes on the output side (z > 0) nearest the gearbox axis: the output-side plate's bore;

each found only if its nodes ring the axis (no angle about it wider than :data:`MAX_BORE_GAP` without a node).

A region the entry's ``regions`` names is found by its selector instead (a cylinder, a point set, a physical group:
flexgear.fe.selectors). Each region becomes a named boundary of the mesh (the boundary triangles whose nodes all lie
in it), so that the FE model weights its nodes by their share of its area, as it does the built-in carrier's named
faces. A part is refused in one line naming the file (flexgear.fe.imported.GeometryFileError) when the file cannot
be read, reaches far from the gear data's carrier (a wrong length unit), or a region holds no whole boundary face.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from flexgear.fe.fem import FEModel, fe_model
from flexgear.fe.imported import GeometryFileError, check_extent, read_solid, volume_arrays
from flexgear.fe.mesh import mesh_arrays
from flexgear.fe.mesh_io import MeshFileError, netgen_mesh, read_volume_mesh
from flexgear.fe.selectors import SelectorError, group_points, picked_nodes, whole_faces
from flexgear.geometry.carrier import CarrierSizes
from flexgear.schema import CARRIER
from flexgear.schema_geometry import ComponentGeometry
from flexgear.spec import GearboxSpec

__all__ = ["imported_carrier_mesh", "carrier_regions", "level_mesh", "pin_bore_faces", "REGION_TOL", "MAX_BORE_GAP"]

REGION_TOL = 1e-6
"""Distance [m] within which a boundary node lies at a region's radius (the file's own rounding is far smaller)."""
MAX_BORE_GAP = np.pi / 2
"""The nodes a rule finds for a bore must ring its axis: no angle about it wider than this [rad] without a node."""
_FACE_TOL = 1e-6
"""Distance [m] within which a face's centre lies on a pin's axis (the faces refined at the level's tooth size)."""


def imported_carrier_mesh(spec: GearboxSpec, level: str, sizes: CarrierSizes, seat: str,
                          pin: Callable[[int], str]) -> tuple[FEModel, np.ndarray]:
    """(the carrier's FE model from its file at mesh ``level``, its tetrahedra in the FE model's node numbering):
    the regions ``seat`` and ``pin(k)`` of the module docstring; ``sizes`` the gear data's carrier (its pins' axes,
    the extent a file in the right unit reaches)."""
    entry = spec.components_geometry[CARRIER]
    settings = spec.meshing_assumed[level]
    order = settings.element_order
    if entry.kind == "mesh":
        try:
            volume = read_volume_mesh(entry.source, entry.scale)
        except MeshFileError as exc:
            raise GeometryFileError(CARRIER, entry, str(exc).split(": ", 1)[1]) from None
        check_extent(CARRIER, entry, sizes.plate_outer_radius, float(np.hypot(*volume.nodes[:, :2].T).max()))
        nodes, elements, surface = volume_arrays(volume, order)
    else:
        solid = read_solid(CARRIER, entry, sizes.plate_outer_radius)
        nodes, elements, surface = _meshed(solid, settings, sizes)
    regions = carrier_regions(entry, sizes, nodes, surface, seat, pin)
    labels = {}
    for name, picked in regions.items():
        held = np.zeros(len(nodes), bool)
        held[picked] = True
        labels[name] = held[surface].all(axis=1)
        if not labels[name].any():
            raise GeometryFileError(CARRIER, entry, f"region {name!r} holds no whole boundary face ({len(picked)} "
                                    "nodes): is the part in the carrier's frame, its pins at the gear data's "
                                    "positions?")
    import ngsolve

    fe = fe_model(ngsolve.Mesh(netgen_mesh(nodes, elements, surface, labels)), spec.material_assumed, order)
    return fe, elements


def carrier_regions(entry: ComponentGeometry, sizes: CarrierSizes, nodes: np.ndarray, surface: np.ndarray,
                    seat: str, pin: Callable[[int], str]) -> dict[str, np.ndarray]:
    """The regions ``seat`` and ``pin(k)`` (node indices, ascending) on a mesh (``nodes`` [m], boundary triangles
    ``surface``): by the entry's selectors where it names them, else by the module docstring's rules."""
    boundary = np.unique(surface)
    p = nodes[boundary]
    groups = None
    out = {}
    names = [seat, *(pin(k) for k in range(sizes.planet_count))]
    chosen = {s.region: s for s in entry.regions}
    for k, name in enumerate(names):
        if name in chosen:
            s = chosen[name]
            try:
                if s.group and groups is None:
                    groups = group_points(entry.source, entry.scale)
                out[name] = picked_nodes(s, nodes, surface, groups)
            except SelectorError as exc:
                raise GeometryFileError(CARRIER, entry, f"selector {exc}") from None
            if not len(whole_faces(out[name], nodes, surface)):
                raise GeometryFileError(CARRIER, entry, f"selector {s.describe()} finds no whole boundary face "
                                        f"({len(out[name])} nodes)")
            continue
        centre = np.zeros(2) if name == seat else sizes.pin_centres()[k - 1, :2]
        d = p[:, :2] - centre
        r = np.hypot(d[:, 0], d[:, 1])
        if name == seat:
            r = np.where(p[:, 2] > 0.0, r, np.inf)
        near = r < r.min() + REGION_TOL
        if _widest_gap(np.arctan2(d[near, 1], d[near, 0])) > MAX_BORE_GAP:
            where = "the gearbox axis on the output side (z > 0)" if name == seat else f"planet {k - 1}'s pin axis"
            raise GeometryFileError(CARRIER, entry, f"region {name!r}: the boundary nodes nearest {where} do not "
                                    "ring it (no bore there): is the part in the carrier's frame, its pins at the "
                                    "gear data's positions?")
        out[name] = boundary[near]
    return out


def _widest_gap(angles: np.ndarray) -> float:
    """The widest angle [rad] between neighbouring ``angles`` [rad] about a circle (2 pi for fewer than two)."""
    if len(angles) < 2:
        return 2 * np.pi
    a = np.sort(np.mod(angles, 2 * np.pi))
    return float(np.diff(np.r_[a, a[0] + 2 * np.pi]).max())


def level_mesh(solid, settings):
    """The first-order Netgen mesh of an OCC ``solid`` at a mesh level's ``settings`` (its body size; faces whose
    ``maxh`` is set keep it), as every carrier is meshed."""
    import netgen.meshing as nm
    from netgen.occ import OCCGeometry

    mp = nm.MeshingParameters(maxh=settings.body_size_mm * 1e-3, curvaturesafety=settings.elements_per_curvature_radius,
                              segmentsperedge=0.0, optsteps2d=settings.optimisation_steps,
                              optsteps3d=settings.optimisation_steps)
    return OCCGeometry(solid).GenerateMesh(mp=mp)


def pin_bore_faces(solid, centres: np.ndarray) -> list[tuple[int, object]]:
    """(k, face) of every face of ``solid`` centred on pin k's axis (``centres`` (N, 2) [m]) at the smallest radius
    about it: the pin bores, in every plate that holds the pin (a window round the planet is centred there too, at a
    larger radius)."""
    on_axis = []
    for face in solid.faces:  # a full cylindrical face's centre lies on its axis
        c = face.center
        off = np.hypot(centres[:, 0] - c.x, centres[:, 1] - c.y)
        k = int(np.argmin(off))
        if off[k] < _FACE_TOL:
            radius = max(float(np.hypot(v.p.x - centres[k, 0], v.p.y - centres[k, 1])) for v in face.vertices)
            on_axis.append((k, radius, face))
    smallest = {k: min(r for j, r, _ in on_axis if j == k) for k, _, _ in on_axis}
    return [(k, face) for k, r, face in on_axis if r < smallest[k] + REGION_TOL]


def _meshed(solid, settings, sizes: CarrierSizes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nodes, tetrahedra, boundary triangles) of ``solid`` meshed at the level ``settings`` as the built-in carrier
    (flexgear.fe.carrier): the level's tooth size on the pin bores (:func:`pin_bore_faces`), raised to the level's
    element order on the solid's surfaces."""
    for _, face in pin_bore_faces(solid, sizes.pin_centres()[:, :2]):
        face.maxh = settings.tooth_size_mm * 1e-3
    mesh = level_mesh(solid, settings)
    if settings.element_order == 2:
        mesh.SecondOrder()
    return mesh_arrays(mesh, settings.element_order)
