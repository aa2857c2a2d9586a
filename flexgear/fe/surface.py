"""The boundary of a component's FE mesh as a triangle surface (first- or second-order faces, flat-split), and
the mass properties of the meshed solid from it (divergence theorem): for export, drawing and the mesh's mass check
against the exact geometry.
"""

from __future__ import annotations

import numpy as np
import trimesh

from flexgear.fe.mesh import ComponentMesh
from flexgear.geometry.layout import exact_mass_properties
from flexgear.geometry.massprops import MassProperties
from flexgear.spec import GearboxSpec

__all__ = ["surface_mesh", "mesh_mass_properties", "mass_check"]


def _edge_nodes(surface: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Edge nodes of tri6 faces ordered as edges (0,1), (1,2), (2,0), found by position."""
    v, mids = surface[:, :3], surface[:, 3:]
    edge = np.empty((len(surface), 3), np.int64)
    for j, (a, b) in enumerate([(0, 1), (1, 2), (2, 0)]):
        centre = 0.5 * (nodes[v[:, a]] + nodes[v[:, b]])
        d = np.linalg.norm(nodes[mids] - centre[:, None, :], axis=2)
        edge[:, j] = mids[np.arange(len(surface)), d.argmin(axis=1)]
    return edge


def _surface_triangles(surface: np.ndarray, nodes: np.ndarray, subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    """Flat triangles (vertices, faces) of a boundary mesh.

    tri3: the facets themselves. tri6: each curved face sampled through its quadratic map
    x(l) = sum_i l_i (2 l_i - 1) x_i + 4 (l0 l1 x01 + l1 l2 x12 + l2 l0 x20) on a lattice of
    ``subdivisions`` per edge, so the facets follow the second-order geometry the FE model has.
    """
    if surface.shape[1] == 3:
        return nodes, surface
    n = subdivisions
    ij = [(i, j) for i in range(n + 1) for j in range(n + 1 - i)]
    index = {p: k for k, p in enumerate(ij)}
    lat = np.array([(i / n, j / n, 1 - (i + j) / n) for i, j in ij])  # barycentric l0, l1, l2
    l0, l1, l2 = lat.T
    shape = np.column_stack([l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
                             4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0])
    ctrl = np.concatenate([surface[:, :3], _edge_nodes(surface, nodes)], axis=1)
    pts = np.einsum("pk,tkd->tpd", shape, nodes[ctrl]).reshape(-1, 3)
    local = []
    for i in range(n):
        for j in range(n - i):
            local.append((index[(i, j)], index[(i + 1, j)], index[(i, j + 1)]))
            if i + j < n - 1:
                local.append((index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]))
    local = np.array(local)
    faces = (local[None, :, :] + len(ij) * np.arange(len(surface))[:, None, None]).reshape(-1, 3)
    # the lattice runs l0 (i) then l1 (j): orient like the face's vertices 0 -> 1 -> 2
    return pts, faces


def surface_mesh(mesh: ComponentMesh, subdivisions: int = 4) -> trimesh.Trimesh:
    """The boundary as a ``trimesh.Trimesh``: one function for first- and second-order meshes.

    First order: the flat boundary facets. Second order: each curved face sampled through its
    quadratic map with ``subdivisions`` segments per edge (see :func:`_surface_triangles`).
    """
    vertices, faces = _surface_triangles(mesh.surface, mesh.nodes, subdivisions)
    tm = trimesh.Trimesh(vertices, faces, process=True)
    if tm.volume < 0:
        tm.invert()
    return tm


def mesh_mass_properties(mesh: ComponentMesh, density: float, subdivisions: int = 8) -> MassProperties:
    """Mass properties of the meshed solid from its surface (trimesh, divergence theorem).

    For second-order meshes the flat sampling of the curved faces converges as 1/subdivisions^2.
    """
    tm = surface_mesh(mesh, subdivisions)
    tm.density = density
    return MassProperties(float(tm.mass), np.array(tm.center_mass), np.array(tm.moment_inertia))


def mass_check(spec: GearboxSpec, mesh: ComponentMesh) -> dict[str, float]:
    """Relative differences mesh vs exact: mass, Izz, Ixx (and the com offset [m])."""
    exact = exact_mass_properties(spec, mesh.component)
    got = mesh_mass_properties(mesh, spec.material_assumed.density_kg_m3)
    return {"mass": got.mass / exact.mass - 1, "izz": got.inertia[2, 2] / exact.inertia[2, 2] - 1,
            "ixx": got.inertia[0, 0] / exact.inertia[0, 0] - 1,
            "com_m": float(np.linalg.norm(got.com - exact.com))}
