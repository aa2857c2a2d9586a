"""The ring-output shaft bolted joint in full FE: the two component meshes tied over the bolts' clamped areas.

Section 2.1 of the study: "12 bolt holes between the gear rings and the output shaft". The ring's flange
(+z face at z_j) lies on the output shaft's web (-z face at the same z_j, flexgear.geometry.layout); the bolts
pass through the holes of both. A preloaded bolt holds the two plates together over its clamped area: the
disc around the bolt axis that the pressure cone under the bolt head reaches at the interface (VDI 2230;
diameter ``[joints_assumed] bolt_clamp_diameter_mm``, clipped by the flange's edges). Outside those discs
the faces may open, so they are not tied; the bolt shank sits in a clearance hole and carries nothing.

The tie is a multipoint constraint (no penalty stiffness): every node of the output shaft's web face inside a
clamped disc (slave) moves with the point of the ring's flange face where it lies (master), interpolated by
the ring face's quadratic (or linear) triangle shape functions,

    u_s = sum_a N_a(xi_s) u_a,                                                                 (1)

and the slave coordinates are eliminated, u = T v, K_t = T^T K T, M_t = T^T M T. The lowest free-free modes
of (K_t, M_t) (shift-invert at a negative shift, the six rigid-body modes dropped) are the reference for the
reduced joints (flexgear.fe.joined).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from threadpoolctl import threadpool_limits

from flexgear.design import Design, as_design
from flexgear.fe.fem import FEModel, rigid_body_modes, surface_faces
from flexgear.spec import GearboxSpec

__all__ = ["bolt_axes", "clamped_patches", "tie_matrix", "tied_free_modes", "ring_output_shaft_fe_modes",
           "shape_functions", "locate_in_triangles", "isoparametric_coordinates"]

_TOL = 1e-6  # m: nodes on an exact plane or cylinder of the OCC geometry


def bolt_axes(spec: GearboxSpec | Design) -> tuple[np.ndarray, float, float]:
    """Bolt axes of the ring-output shaft joint: centres (n, 2) [m], hole radius [m], interface plane z_j [m].

    Hole k at polar angle 2 pi k / n on the ring flange's hole circle (flexgear.geometry.layout); z_j is the
    flange's +z face, where the output shaft's web lies on it. ``spec``: a spec or its design (flexgear.design).
    """
    flange = next(p for p in as_design(spec).layouts["ring"].prisms if p.section.holes)
    return flange.section.hole_centres(), flange.section.hole_radius, flange.z1


def clamped_patches(fe: FEModel, spec: GearboxSpec | Design, clamp_radius: float | None = None,
                    component: str | None = None) -> list[np.ndarray]:
    """Per bolt, the nodes of ``fe`` on the interface plane z_j within the clamped disc around its axis.

    ``clamp_radius`` [m] defaults to half of ``[joints_assumed] bolt_clamp_diameter_mm``; the hole's edge
    (at the hole radius) is included. Works for the ring (flange face) and the output shaft (web face).
    ``component`` (the ring or the output shaft that ``fe`` models): when its part comes from a file whose
    ``regions`` name ``bolt_discs`` (flexgear.schema_geometry), the discs that selector picks on ``fe`` instead
    (one per bolt, bolt k nearest the polar angle 2 pi k / n; flexgear.fe.selectors.selected_discs), unless a
    ``clamp_radius`` is given.
    """
    d = as_design(spec)
    centres, hole_radius, z_j = bolt_axes(d)
    selected = _selected_discs(fe, d, component, len(centres)) if clamp_radius is None else None
    if selected is not None:
        return selected
    radius = d.spec.joints_assumed.bolt_clamp_diameter_mm * 1e-3 / 2 if clamp_radius is None else clamp_radius
    on_plane = np.abs(fe.nodes[:, 2] - z_j) < _TOL
    out = []
    for cx, cy in centres:
        d = np.hypot(fe.nodes[:, 0] - cx, fe.nodes[:, 1] - cy)
        nodes = np.flatnonzero(on_plane & (d > hole_radius - _TOL) & (d < radius + _TOL))
        if len(nodes) < 3:
            raise ValueError(f"bolt at ({cx:.4f}, {cy:.4f}) m: only {len(nodes)} mesh nodes in its clamped disc "
                             f"of radius {radius:.4f} m; refine the mesh or widen bolt_clamp_diameter_mm")
        out.append(nodes)
    return out


def _selected_discs(fe: FEModel, d: Design, component: str | None, n_bolts: int) -> list[np.ndarray] | None:
    """The clamped discs of ``component``'s imported part by its ``bolt_discs`` selector (None: no such selector)."""
    from flexgear.fe.selectors import named_selector, selected_discs

    found = named_selector(d.spec.components_geometry.get(component) if component is not None else None, "bolt_discs")
    return None if found is None else selected_discs(found[0], fe.nodes, fe.surface_triangles, n_bolts, found[1])


def shape_functions(bary: np.ndarray, n_nodes: int) -> np.ndarray:
    """Triangle shape functions at barycentric ``bary`` (k, 3): linear (3) or quadratic (6, mid-nodes 01, 12, 20)."""
    if n_nodes == 3:
        return bary
    l0, l1, l2 = bary.T
    return np.column_stack([l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
                            4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0])


def locate_in_triangles(points: np.ndarray, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Face index and barycentric coordinates (k, 3) of each in-plane point (k, 2) in triangles (t, 3, 2).

    The triangle whose smallest barycentric coordinate is largest: the one holding the point, or for a point
    just outside the polygon (a node on a curved hole edge beyond the chord) the nearest one.
    """
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    dx = points[:, None, 0] - a[None, :, 0]
    dy = points[:, None, 1] - a[None, :, 1]
    l1 = (dx * (c[None, :, 1] - a[None, :, 1]) - dy * (c[None, :, 0] - a[None, :, 0])) / det
    l2 = (dy * (b[None, :, 0] - a[None, :, 0]) - dx * (b[None, :, 1] - a[None, :, 1])) / det
    l0 = 1.0 - l1 - l2
    worst = np.minimum(np.minimum(l0, l1), l2)
    face = worst.argmax(axis=1)
    rows = np.arange(len(points))
    return face, np.column_stack([l0[rows, face], l1[rows, face], l2[rows, face]])


def isoparametric_coordinates(points: np.ndarray, nodes: np.ndarray, bary: np.ndarray, steps: int = 8) -> np.ndarray:
    """Barycentric coordinates (k, 3) with sum_a N_a(l) x_a = x for each point x (k, 2) in its face's nodes
    (k, 3 | 6, 2): Newton's method on (l1, l2) from the corners' affine guess ``bary``. On a curved (quadratic)
    face the affine guess misses by the edge's sagitta, and the tie would not carry a rigid rotation exactly.
    """
    lam = bary[:, 1:].copy()
    for _ in range(steps):
        full = np.column_stack([1.0 - lam.sum(axis=1), lam])
        resid = np.einsum("ka,kad->kd", shape_functions(full, nodes.shape[1]), nodes) - points
        jac = np.stack([_shape_derivative(full, nodes, j) for j in (1, 2)], axis=2)  # (k, 2 coords, 2 params)
        lam -= np.linalg.solve(jac, resid[:, :, None])[:, :, 0]
    return np.column_stack([1.0 - lam.sum(axis=1), lam])


def _shape_derivative(bary: np.ndarray, nodes: np.ndarray, j: int) -> np.ndarray:
    """d x / d l_j (k, 2) of the face map sum_a N_a(l) x_a, with l_0 = 1 - l_1 - l_2 (j = 1 or 2)."""
    n = nodes.shape[1]
    d = np.zeros((len(bary), n))
    if n == 3:
        d[:, j], d[:, 0] = 1.0, -1.0
    else:
        l0, l1, l2 = bary.T
        d[:, 0] = -(4 * l0 - 1)
        d[:, j] = 4 * bary[:, j] - 1
        if j == 1:
            d[:, 3], d[:, 4], d[:, 5] = 4 * (l0 - l1), 4 * l2, -4 * l2
        else:
            d[:, 3], d[:, 4], d[:, 5] = -4 * l1, 4 * l1, 4 * (l0 - l2)
    return np.einsum("ka,kad->kd", d, nodes)


def tie_matrix(master: FEModel, slave: FEModel, slave_nodes: np.ndarray, z_plane: float,
               max_outside: float = 0.05) -> sp.csr_matrix:
    """T (3 (n_m + n_s), 3 (n_m + n_s) - 3 k): eq. (1) for ``slave_nodes`` (k) of ``slave`` on ``master``'s face.

    Coordinates: master's then slave's (interleaved); columns: all but the slave nodes' (in order). The master
    face is ``master``'s boundary triangles on the plane z = ``z_plane``. ValueError if a slave node lies
    outside that face by more than ``max_outside`` of its triangle (barycentric), i.e. not on the mating face.
    """
    faces = surface_faces(master)
    on_plane = np.all(np.abs(master.nodes[faces[:, :3], 2] - z_plane) < _TOL, axis=1)
    faces = faces[on_plane]
    if not len(faces):
        raise ValueError(f"tie_matrix: the master has no boundary face on the plane z = {z_plane:.4f} m")
    points = slave.nodes[slave_nodes, :2]
    face, bary = locate_in_triangles(points, master.nodes[faces[:, :3], :2])
    bary = isoparametric_coordinates(points, master.nodes[faces[face], :2], bary)
    if bary.min() < -max_outside:
        raise ValueError(f"tie_matrix: a slave node lies outside the master face (barycentric {bary.min():.3f})")
    weights = shape_functions(bary, faces.shape[1])
    n_m, n_all = master.n_nodes, master.n_nodes + slave.n_nodes
    tied = np.zeros(n_all, bool)
    tied[n_m + np.asarray(slave_nodes)] = True
    column = np.full(n_all, -1)
    column[~tied] = np.arange(int((~tied).sum()))
    kept = np.flatnonzero(~tied)
    rows = [3 * kept[:, None] + np.arange(3)]
    cols = [3 * column[kept][:, None] + np.arange(3)]
    vals = [np.ones((len(kept), 3))]
    for a in range(faces.shape[1]):  # u_s,d = sum_a N_a u_a,d for each direction d
        m_nodes = faces[face, a]
        rows.append(3 * (n_m + np.asarray(slave_nodes))[:, None] + np.arange(3))
        cols.append(3 * column[m_nodes][:, None] + np.arange(3))
        vals.append(np.repeat(weights[:, a:a + 1], 3, axis=1))
    return sp.csr_matrix((np.concatenate([v.ravel() for v in vals]),
                          (np.concatenate([r.ravel() for r in rows]), np.concatenate([c.ravel() for c in cols]))),
                         shape=(3 * n_all, 3 * int((~tied).sum())))


@threadpool_limits.wrap(limits=1, user_api="blas")
def tied_free_modes(ring: FEModel, shaft: FEModel, spec: GearboxSpec, k: int = 10,
                    clamp_radius: float | None = None) -> np.ndarray:
    """Lowest ``k`` elastic free-free frequencies [Hz] of ring + output shaft tied over the clamped discs.

    Both models in the gearbox frame (component frames coincide, flexgear.geometry.layout). Eq. (1) with the
    ring's flange face as master (it carries rigid motions exactly); K_t phi = omega^2 M_t phi solved by
    shift-invert about a small negative shift (K_t - sigma M_t is positive definite although K_t is singular)
    on the M_t-orthogonal complement of the six rigid-body modes R_t (the operator projects them out:
    Lanczos would find a six-fold eigenvalue only by round-off). RuntimeError if a zero mode is left.
    """
    _, _, z_j = bolt_axes(spec)
    slaves = np.concatenate(clamped_patches(shaft, spec, clamp_radius))
    t = tie_matrix(ring, shaft, slaves, z_j)
    k_t = (t.T @ sp.block_diag([ring.K, shaft.K], format="csr") @ t).tocsc()
    m_t = (t.T @ sp.block_diag([ring.M, shaft.M], format="csr") @ t).tocsc()
    k_t = ((k_t + k_t.T) * 0.5).tocsc()
    tied = np.zeros(ring.n_nodes + shaft.n_nodes, bool)
    tied[ring.n_nodes + slaves] = True
    rigid = rigid_body_modes(np.vstack([ring.nodes, shaft.nodes])[~tied])
    m_rigid = m_t @ rigid
    gram = np.linalg.inv(rigid.T @ m_rigid)

    def project(x: np.ndarray) -> np.ndarray:  # M_t-orthogonal to the rigid modes
        return x - rigid @ (gram @ (m_rigid.T @ x))

    # a shift far below the first elastic mode: 1e-6 of the mean diagonal ratio (about omega_max^2)
    sigma = -float(k_t.diagonal().mean() / m_t.diagonal().mean()) * 1e-6
    lu = sla.splu(k_t - sigma * m_t, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
    op = sla.LinearOperator(k_t.shape, matvec=lambda f: project(lu.solve(f)), dtype=float)
    v0 = project(np.random.default_rng(0).standard_normal(k_t.shape[0]))
    lam = np.sort(sla.eigsh(k_t, k=k, M=m_t, sigma=sigma, OPinv=op, which="LM", v0=v0, tol=1e-10,
                            return_eigenvectors=False))
    if lam[0] < 1e-6 * lam[-1]:
        raise RuntimeError(f"tied ring + output shaft: a rigid-body mode is left, eigenvalues start {lam[:3]}")
    return np.sqrt(lam) / (2 * math.pi)


def ring_output_shaft_fe_modes(spec: GearboxSpec, level: str = "coarse", k: int = 10,
                               progress: bool = False) -> np.ndarray:
    """:func:`tied_free_modes` of the ring and output shaft FE models at mesh ``level`` (element order of the
    level on the first-order mesh topology, as flexgear.fe.reduced builds them)."""
    from flexgear.fe.fem import fe_model
    from flexgear.fe.mesh import component_mesh

    order = spec.meshing_assumed[level].element_order
    ring, shaft = (fe_model(component_mesh(spec, name, level, order=1, progress=progress).ngsolve_mesh(),
                            spec.material_assumed, order) for name in ("ring", "output_shaft"))
    return tied_free_modes(ring, shaft, spec, k)
