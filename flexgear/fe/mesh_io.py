"""Volume meshes to and from files (meshio), and Netgen meshes made from node and element arrays.

Node order of a tetrahedron. flexgear (Netgen) stores a tetrahedron as its 4 vertices, then for second order the
nodes on its edges (0,1), (0,2), (0,3), (1,2), (1,3), (2,3), with the vertices ordered so that
(x1 - x0) . ((x2 - x0) x (x3 - x0)) < 0. VTK (and meshio, whose readers convert Gmsh's and Abaqus' orders to it)
orders the edges (0,1), (1,2), (0,2), (0,3), (1,3), (2,3) and the vertices so that that volume is positive. The two
orders map into each other by swapping vertices 1 and 2 (:data:`NETGEN_TO_VTK`); a file's elements are brought
into Netgen's orientation one by one by their signed volumes, and each edge node is checked to lie near its
edge's midpoint, so that a file in another order is refused, not read into a wrong FE model.
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["NETGEN_TO_VTK", "VTK_TO_NETGEN", "VolumeMesh", "write_vtu", "read_volume_mesh", "netgen_mesh",
           "boundary_faces", "MeshFileError"]

NETGEN_TO_VTK = {4: np.array([0, 2, 1, 3]), 10: np.array([0, 2, 1, 3, 5, 7, 4, 6, 9, 8])}
"""``vtk = netgen[:, NETGEN_TO_VTK[n]]``: a Netgen tetrahedron (4 or 10 nodes) in VTK's order and orientation."""
VTK_TO_NETGEN = {n: np.argsort(p) for n, p in NETGEN_TO_VTK.items()}
"""``netgen = vtk[:, VTK_TO_NETGEN[n]]``: the inverse of :data:`NETGEN_TO_VTK`."""
_EDGES = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))
"""The edges of a tetrahedron in Netgen's order of its edge nodes 4..9."""
_FACES = ((1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1))
"""Face k of a tetrahedron (the face opposite vertex k)."""
_MIRROR = {4: np.array([0, 2, 1, 3]), 10: np.array([0, 2, 1, 3, 5, 4, 6, 7, 9, 8])}
"""A tetrahedron in Netgen's order with vertices 1 and 2 swapped (and their edge nodes): its orientation reversed."""
_MID_TOLERANCE = 0.25
"""An edge node may lie at most this fraction of its edge's length from the edge's midpoint."""


class MeshFileError(ValueError):
    """A mesh file cannot serve as a component's volume mesh (the message is one line naming the file)."""


@dataclass
class VolumeMesh:
    """A tetrahedral mesh read from a file (SI units): ``nodes`` (n, 3) [m], the vertices first; ``elements``
    (m, 4 | 10) 0-based in Netgen's order and orientation (module docstring); ``order`` 1 or 2."""

    nodes: np.ndarray
    elements: np.ndarray
    order: int


def write_vtu(path: str | Path, nodes: np.ndarray, elements: np.ndarray,
              point_sets: dict[str, np.ndarray] | None = None) -> Path:
    """Write a VTU file of the tetrahedra ``elements`` (Netgen order, 4 or 10 nodes; written as VTK ``tetra`` /
    ``tetra10``) on ``nodes`` [m, written as they are]; every node set of ``point_sets`` becomes a point-data array
    of that name (1 on its nodes, else 0)."""
    import meshio

    n = elements.shape[1]
    cells = [("tetra" if n == 4 else "tetra10", np.ascontiguousarray(elements[:, NETGEN_TO_VTK[n]]))]
    data = {}
    for name, ids in (point_sets or {}).items():
        flag = np.zeros(len(nodes), np.uint8)
        flag[np.asarray(ids, np.int64)] = 1
        data[name] = flag
    path = Path(path)
    meshio.write(path, meshio.Mesh(np.asarray(nodes, float), cells, point_data=data), file_format="vtu")
    return path


def read_volume_mesh(path: str | Path, scale: float) -> VolumeMesh:
    """The tetrahedra of a mesh file that meshio reads (``.vtu``, ``.msh``, ``.inp``, ...), coordinates times
    ``scale`` [m per file unit], in Netgen's order (module docstring); nodes no tetrahedron uses are dropped.
    Raises :class:`MeshFileError` (one line) for a file that cannot be read, holds no tetrahedra, mixes first- and
    second-order ones, or whose edge nodes are not at their edges."""
    import meshio

    path = Path(path)
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            mesh = meshio.read(path)
    except (Exception, SystemExit) as exc:  # meshio raises many kinds for a damaged file, or exits
        text = " ".join(str(exc).split())[:160] or "no tetrahedra found"
        raise MeshFileError(f"{path}: cannot be read as a mesh ({exc.__class__.__name__}: {text})") from None
    kinds = {c.type: c.data for c in mesh.cells if c.type in ("tetra", "tetra10") and len(c.data)}
    if not kinds:
        found = sorted({c.type for c in mesh.cells}) or ["no cells"]
        raise MeshFileError(f"{path}: holds no tetrahedra ({', '.join(found)}); expected a volume mesh of "
                            "first- or second-order tetrahedra")
    if len(kinds) > 1:
        raise MeshFileError(f"{path}: mixes first- and second-order tetrahedra; expected one kind")
    ((kind, cells),) = kinds.items()
    n = 4 if kind == "tetra" else 10
    cells = np.vstack([c.data for c in mesh.cells if c.type == kind]).astype(np.int64)
    points = np.asarray(mesh.points, float)[:, :3] * scale
    if not np.isfinite(points).all():
        raise MeshFileError(f"{path}: has coordinates that are not finite numbers")
    return _renumbered(path, points, _netgen_orientation(path, points, cells[:, VTK_TO_NETGEN[n]]))


def _netgen_orientation(path: Path, points: np.ndarray, el: np.ndarray) -> np.ndarray:
    """``el`` (Netgen order) with every element of positive signed volume mirrored (vertices 1 and 2 swapped, and
    their edge nodes); refuses degenerate elements and, for second order, edge nodes away from their edges."""
    v = points[el[:, :4]]
    vol = np.einsum("ij,ij->i", v[:, 1] - v[:, 0], np.cross(v[:, 2] - v[:, 0], v[:, 3] - v[:, 0]))
    scale = np.linalg.norm(v[:, 1] - v[:, 0], axis=1) ** 3
    if np.any(np.abs(vol) <= 1e-12 * scale):
        raise MeshFileError(f"{path}: has {int(np.sum(np.abs(vol) <= 1e-12 * scale))} degenerate (flat) tetrahedra")
    out = el.copy()
    flip = vol > 0
    swap = _MIRROR[el.shape[1]]
    out[flip] = el[flip][:, swap]
    if el.shape[1] == 10:
        for k, (a, b) in enumerate(_EDGES):
            edge = points[out[:, b]] - points[out[:, a]]
            off = np.linalg.norm(points[out[:, 4 + k]] - 0.5 * (points[out[:, a]] + points[out[:, b]]), axis=1)
            bad = off > _MID_TOLERANCE * np.linalg.norm(edge, axis=1)
            if bad.any():
                raise MeshFileError(f"{path}: {int(bad.sum())} second-order tetrahedra have edge nodes away from their "
                                    "edges; expected VTK's node order (as meshio writes and reads it)")
    return out


def _renumbered(path: Path, points: np.ndarray, el: np.ndarray) -> VolumeMesh:
    """The used nodes only, the vertices first (Netgen's numbering), each group in the file's order."""
    vertices = np.unique(el[:, :4])
    edges = np.setdiff1d(np.unique(el[:, 4:]), vertices) if el.shape[1] == 10 else np.zeros(0, np.int64)
    if el.shape[1] == 10 and len(np.intersect1d(np.unique(el[:, 4:]), vertices)):
        raise MeshFileError(f"{path}: a node is both a vertex and an edge node of its tetrahedra")
    keep = np.concatenate([vertices, edges])
    new = np.full(len(points), -1, np.int64)
    new[keep] = np.arange(len(keep))
    return VolumeMesh(points[keep], new[el], 1 if el.shape[1] == 4 else 2)


def boundary_faces(elements: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The boundary triangles (faces of one element only) of tetrahedra in Netgen's order, normals outward: (k, 3)
    vertices, or (k, 6) with the edge nodes of edges (1,2), (0,2), (0,1) as Netgen orders a second-order triangle."""
    faces = np.concatenate([elements[:, list(f)] for f in _FACES])
    opposite = np.concatenate([elements[:, k] for k in range(4)])
    key = np.sort(faces, axis=1)
    _, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
    once = first[count == 1]
    tri, far = faces[once], opposite[once]
    p = nodes[tri]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    inward = np.einsum("ij,ij->i", normal, nodes[far] - p[:, 0]) > 0
    tri[inward] = tri[inward][:, [0, 2, 1]]
    if elements.shape[1] == 4:
        return tri
    edge_node = {}
    for k, (a, b) in enumerate(_EDGES):
        for u, v, m in zip(elements[:, a], elements[:, b], elements[:, 4 + k], strict=True):
            edge_node[(min(u, v), max(u, v))] = m
    mids = [[edge_node[(min(t[i], t[j]), max(t[i], t[j]))] for i, j in ((1, 2), (0, 2), (0, 1))] for t in tri]
    return np.column_stack([tri, np.array(mids, np.int64).reshape(-1, 3)])


def netgen_mesh(nodes: np.ndarray, elements: np.ndarray, surface: np.ndarray,
                labels: dict[str, np.ndarray] | None = None):
    """A Netgen mesh of the tetrahedra ``elements`` (Netgen order, 4 or 10 nodes) on ``nodes`` [m] with the boundary
    triangles ``surface`` (3 or 6 nodes) as one boundary ("default", as the components' own meshes), but the rows of
    ``surface`` that ``labels`` {name: boolean mask over the rows} names: each such set a boundary of that name
    (flexgear.fe.fem.fe_model makes each a region, its nodes weighted by their share of its area). A second-order
    mesh keeps its edge nodes where they are (flexgear.fe.fem.fe_model uses it as it is)."""
    import netgen.meshing as nm
    from netgen.csg import Pnt

    mesh = nm.Mesh(dim=3)
    for p in np.asarray(nodes, float):
        mesh.Add(nm.MeshPoint(Pnt(float(p[0]), float(p[1]), float(p[2]))))
    surface = np.asarray(surface, np.int64)
    label = np.zeros(len(surface), np.int64)  # 0: "default"
    names = ["default", *(labels or {})]
    for k, mask in enumerate((labels or {}).values(), start=1):
        label[np.asarray(mask, bool) & (label == 0)] = k
    faces = []
    for k, name in enumerate(names):
        faces.append(mesh.Add(nm.FaceDescriptor(bc=k + 1, domin=1, surfnr=k + 1)))
        mesh.SetBCName(k, name)
    for el in np.asarray(elements, np.int64) + 1:
        mesh.Add(nm.Element3D(1, [nm.PointId(int(i)) for i in el]))
    for tri, k in zip(surface + 1, label, strict=True):
        mesh.Add(nm.Element2D(faces[k], [nm.PointId(int(i)) for i in tri]))
    return mesh
