"""The regions of an imported part found by the named selectors of its ``[components_geometry]`` entry.

A selector (flexgear.schema_geometry.RegionSelector: ``cylinder``, ``points``, ``physical_group``) picks boundary
nodes of the part's mesh (:func:`picked_nodes`); :func:`selected_regions` puts them in place of the built-in rule's
node set of the same name, so that the named regions reach everything the built-in ones reach under the same
names. ``bolt_holes`` is split into ``bolt_hole_<k>`` (its connected patches, numbered by polar angle as the
built-in holes are: hole k nearest 2 pi k / n); ``bolt_hole_<k>`` named alone replace those holes, and
``bolt_holes`` is then the union of all of them.

**One surface.** A selection must lie on the surface it names, and is refused (:class:`SelectorError`) when:

- it finds no boundary node;
- it holds no whole boundary face (a triangle whose three vertices it holds): nodes along an edge or a few
  scattered nodes are no surface (``flanks`` excepted: between form and tip radius a coarse mesh's flank may
  hold nodes but no whole face);
- its faces form another number of connected patches (faces sharing a node are connected) than the region is
  made of: one for ``bore``, ``bearing_seat``, ``gear_seat`` and each ``bolt_hole_<k>``, the layout's number of
  holes for ``bolt_holes`` and for ``bolt_discs`` (one clamped disc per bolt), any number for ``flanks`` (two per
  tooth);
- two of its faces sharing an edge turn by more than :data:`FEATURE_ANGLE_DEG` (the selection goes round an edge
  of the part onto another surface, such as a bore and the end face it meets at a right angle).

Nodes of the selection outside its faces (on the edges where other surfaces meet the selected one) are kept, as
the built-in rules keep them. The test is topological; its angle lies between the facets of a coarse mesh of a
curved surface (a bolt hole of the study's coarse output shaft has six faces round: 60 degrees) and a part's right
angles, so a chamfer or a rounded edge (turning by less) is not found by it.
"""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import numpy as np

from flexgear.schema_geometry import CONTACT_BAND, RegionSelector

__all__ = ["SelectorError", "FEATURE_ANGLE_DEG", "group_points", "picked_nodes", "whole_faces", "check_surface",
           "named_selector", "patches_by_angle", "selected_discs", "selected_regions"]

FEATURE_ANGLE_DEG = 75.0
"""Two faces of one selection that share an edge may turn by at most this angle [deg] (module docstring)."""
_SINGLE = ("bore", "bearing_seat", "gear_seat")
"""Regions made of one connected surface (so is each ``bolt_hole_<k>``)."""
_MATCH_TOL = 1e-9
"""Distance [m] within which a group's node of the file is a node of the part's mesh (the same coordinates)."""


class SelectorError(ValueError):
    """A selector finds no node, or nodes on more than one surface, or names a group the file lacks: the message is
    one line naming the selector (the caller names the component and the file)."""


def group_points(source: str | Path, scale: float) -> dict[str, np.ndarray]:
    """Name -> coordinates (k, 3) [m] of the nodes of each named group of the mesh file ``source`` (coordinates
    times ``scale``): Gmsh physical groups (``$PhysicalNames``), Abaqus element sets (``*ELSET``, the nodes of their
    elements) and node sets (``*NSET``), as meshio reads them."""
    import meshio

    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        mesh = meshio.read(Path(source))
    points = np.asarray(mesh.points, float)[:, :3] * scale
    ids: dict[str, list[np.ndarray]] = {}
    tags = mesh.cell_data.get("gmsh:physical")
    for name, (tag, dim) in ((n, v[:2]) for n, v in mesh.field_data.items() if len(v) >= 2):
        if tags is not None:  # a physical group: its tag among the cells of its dimension
            ids.setdefault(name, []).extend(
                np.ravel(block.data[np.asarray(t) == tag]) for block, t in zip(mesh.cells, tags, strict=True)
                if getattr(block, "dim", dim) == dim)
    for name, blocks in mesh.cell_sets.items():
        ids.setdefault(name, []).extend(np.ravel(block.data[np.asarray(s, np.int64)])
                                        for block, s in zip(mesh.cells, blocks, strict=False) if len(s))
    for name, nodes in mesh.point_sets.items():
        ids.setdefault(name, []).append(np.asarray(nodes, np.int64))
    return {name: points[np.unique(np.concatenate(a).astype(np.int64))] for name, a in ids.items()
            if sum(len(x) for x in a)}


def picked_nodes(selector: RegionSelector, nodes: np.ndarray, surface: np.ndarray,
                 groups: dict[str, np.ndarray] | None = None, strict: bool = True) -> np.ndarray:
    """The boundary nodes (indices into ``nodes`` [m], ascending) that ``selector`` picks on a mesh whose boundary
    triangles are ``surface`` (3 or 6 nodes). ``groups``: :func:`group_points` of the file, for a physical group.
    ``strict``: a point that finds no node or a group the file lacks raises :class:`SelectorError`."""
    boundary = np.unique(surface)
    p = nodes[boundary]
    tol = selector.tolerance
    if selector.kind == "cylinder":
        r = np.hypot(p[:, 0] - selector.axis[0], p[:, 1] - selector.axis[1])
        hit = np.abs(r - selector.radius) < tol
        if selector.z_range is not None:
            hit &= (p[:, 2] > selector.z_range[0] - tol) & (p[:, 2] < selector.z_range[1] + tol)
        return boundary[hit]
    from scipy.spatial import cKDTree

    if selector.kind == "points":
        near = cKDTree(p).query_ball_point(np.asarray(selector.points, float), tol)
        for k, found in enumerate(near):
            if strict and not found:
                x = np.asarray(selector.points[k]) * 1e3
                raise SelectorError(f"{selector.describe()}: point {k} ({x[0]:g}, {x[1]:g}, {x[2]:g}) mm finds no "
                                    "boundary node within the tolerance")
        return boundary[np.unique(np.concatenate([np.asarray(f, np.int64) for f in near]))]
    if selector.group not in (groups or {}):
        if not strict:
            return np.zeros(0, np.int64)
        raise SelectorError(f"{selector.describe()}: no group of that name in the file (its groups: "
                            f"{', '.join(sorted(groups or {})) or 'none'})")
    dist, index = cKDTree(nodes).query(groups[selector.group], distance_upper_bound=_MATCH_TOL)
    inside = np.zeros(len(nodes), bool)
    inside[index[np.isfinite(dist)]] = True
    whole = inside[surface[:, :3]].all(axis=1)  # faces of the group's vertices: their edge nodes too
    return np.union1d(boundary[inside[boundary]], np.unique(surface[whole]))


def whole_faces(picked: np.ndarray, nodes: np.ndarray, surface: np.ndarray) -> np.ndarray:
    """The boundary triangles (rows of ``surface``) whose three vertices are all in ``picked`` (node indices)."""
    held = np.zeros(len(nodes), bool)
    held[picked] = True
    return surface[held[surface[:, :3]].all(axis=1)]


def _patches(faces: np.ndarray, n_nodes: int) -> np.ndarray:
    """Patch label of each of ``faces`` (3 or 6 nodes): faces sharing a node are in one patch."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    a, b = faces[:, 0].repeat(faces.shape[1]), faces.ravel()
    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(n_nodes, n_nodes))
    labels = connected_components(graph, directed=False)[1]
    return np.unique(labels[faces[:, 0]], return_inverse=True)[1]


def _sharpest_turn(faces: np.ndarray, nodes: np.ndarray) -> tuple[float, np.ndarray]:
    """The largest angle [deg] between the normals of two of ``faces`` sharing an edge, and a point [m] on that
    edge ((0.0, nan) when no two faces share an edge)."""
    tri = faces[:, :3]
    x = nodes[tri]
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    pairs = np.sort(tri[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1)
    inverse = np.unique(pairs, axis=0, return_inverse=True)[1].ravel()
    order = np.argsort(inverse, kind="stable")
    same = inverse[order][1:] == inverse[order][:-1]
    if not same.any():
        return 0.0, np.full(3, np.nan)
    a, b = order[:-1][same] // 3, order[1:][same] // 3
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", normal[a], normal[b]), -1.0, 1.0)))
    worst = int(np.argmax(angle))
    return float(angle[worst]), nodes[pairs[order[:-1][same][worst]]].mean(axis=0)


def check_surface(selector: RegionSelector, picked: np.ndarray, nodes: np.ndarray, surface: np.ndarray,
                  patches: int | None) -> np.ndarray:
    """Refuse (:class:`SelectorError`) a selection ``picked`` that finds no node or does not lie on one surface
    (module docstring); ``patches`` the number of connected patches the region is made of (None: any). Returns the
    patch label of each node of ``picked`` (-1 off its faces)."""
    what = selector.describe()
    if not len(picked):
        raise SelectorError(f"{what}: finds no boundary node")
    faces = whole_faces(picked, nodes, surface)
    if not len(faces) and selector.region == "flanks":
        return np.full(len(picked), -1, np.int64)
    if not len(faces):
        raise SelectorError(f"{what}: finds {len(picked)} boundary nodes but no whole boundary face (nodes along "
                            "edges or scattered, not a surface)")
    label = _patches(faces, len(nodes))
    found = int(label.max()) + 1
    if patches is not None and found != patches:
        raise SelectorError(f"{what}: finds nodes on {found} separate surfaces; expected {patches}")
    turn, at = _sharpest_turn(faces, nodes)
    if turn > FEATURE_ANGLE_DEG:
        raise SelectorError(f"{what}: finds nodes on more than one surface: its faces turn by {turn:.0f} deg "
                            f"(allowed: {FEATURE_ANGLE_DEG:g}) round the edge at ({at[0] * 1e3:.3f}, "
                            f"{at[1] * 1e3:.3f}, {at[2] * 1e3:.3f}) mm")
    of_node = np.full(len(nodes), -1, np.int64)
    for k in range(faces.shape[1]):
        of_node[faces[:, k]] = label
    return of_node[picked]


def patches_by_angle(picked: np.ndarray, label: np.ndarray, nodes: np.ndarray) -> list[np.ndarray]:
    """The nodes of each patch of a selection (``label`` from :func:`check_surface`), patch k the one whose centroid
    lies nearest the polar angle 2 pi k / n (as the built-in bolt holes are numbered). A node off the selection's
    whole faces (label -1: an edge node) joins the patch whose centroid is nearest."""
    n = int(label.max()) + 1
    centres = np.array([nodes[picked[label == j]].mean(axis=0) for j in range(n)])
    label = label.copy()
    off = label < 0
    if off.any():
        label[off] = np.argmin(np.linalg.norm(nodes[picked[off]][:, None, :] - centres[None], axis=2), axis=1)
    angle = np.arctan2(centres[:, 1], centres[:, 0])
    order = np.argsort((angle + math.pi / n) % (2 * math.pi))
    return [np.sort(picked[label == j]) for j in order]


def _holes(picked: np.ndarray, label: np.ndarray, nodes: np.ndarray) -> dict[str, np.ndarray]:
    """``bolt_hole_<k>`` of a ``bolt_holes`` selection (:func:`patches_by_angle`)."""
    return {f"bolt_hole_{k}": s for k, s in enumerate(patches_by_angle(picked, label, nodes))}


def named_selector(entry, region: str) -> tuple[RegionSelector, dict[str, np.ndarray] | None] | None:
    """The selector of ``region`` in an imported part's entry (flexgear.schema_geometry.ComponentGeometry, or None)
    and its file's named groups (:func:`group_points`, read only for a ``physical_group``); None when the entry
    names no such region."""
    chosen = next((s for s in entry.regions if s.region == region), None) if entry is not None else None
    if chosen is None:
        return None
    return chosen, (group_points(entry.source, entry.scale) if chosen.group else None)


def selected_discs(selector: RegionSelector, nodes: np.ndarray, surface: np.ndarray, n_bolts: int,
                   groups: dict[str, np.ndarray] | None = None) -> list[np.ndarray]:
    """The bolts' clamped discs that a ``bolt_discs`` selector picks on a mesh (``nodes`` [m], boundary triangles
    ``surface``): one patch per bolt, ``n_bolts`` of them on one plane surface each (:func:`check_surface`), bolt k
    the patch nearest the polar angle 2 pi k / n (:func:`patches_by_angle`)."""
    picked = picked_nodes(selector, nodes, surface, groups)
    return patches_by_angle(picked, check_surface(selector, picked, nodes, surface, n_bolts), nodes)


def selected_regions(selectors: tuple[RegionSelector, ...], builtin: dict[str, np.ndarray], n_holes: int,
                     nodes: np.ndarray, surface: np.ndarray, groups: dict[str, np.ndarray] | None = None,
                     strict: bool = True) -> dict[str, np.ndarray]:
    """The regions of a part's mesh (``nodes`` [m], boundary triangles ``surface``): the built-in rules' ``builtin``
    with each region a selector names found by it instead (module docstring). ``n_holes``: the layout's number
    of bolt holes. ``strict``: every selection checked (:func:`check_surface`), else taken as found (a mesh of
    another element order than the FE model's, whose nodes are not checked)."""
    out = dict(builtin)
    for s in selectors:
        if s.region == CONTACT_BAND:  # not boundary nodes: the reduction's and the contacts' band (fe.reduced)
            continue
        picked = picked_nodes(s, nodes, surface, groups, strict)
        expected = (n_holes if s.region in ("bolt_holes", "bolt_discs")
                    else 1 if s.region in _SINGLE or "_hole_" in s.region else None)
        if s.region.startswith("bolt_hole_") and strict and int(s.region.removeprefix("bolt_hole_")) >= n_holes:
            raise SelectorError(f"{s.describe()}: the part has {n_holes} bolt holes (bolt_hole_0 .. "
                                f"bolt_hole_{n_holes - 1})")
        try:
            label = check_surface(s, picked, nodes, surface, expected)
        except SelectorError:
            if strict:
                raise
            label = None
        if s.region == "bolt_holes" and label is not None:
            out.update(_holes(picked, label, nodes))
        out[s.region] = picked
    if any(s.region.startswith("bolt_hole_") for s in selectors):
        out["bolt_holes"] = np.unique(np.concatenate([v for k, v in out.items() if k.startswith("bolt_hole_")]))
    return {k: np.unique(v) for k, v in out.items()}
