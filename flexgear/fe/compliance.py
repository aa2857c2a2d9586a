"""Static compliance of a full FE model or a reduced body under forces at points, one interface held.

For unit forces f_k (k = 1..p) the compliance matrix is C_kl = f_k^T u_l [m/N], u_l the static
displacement under f_l with the interface ``held`` (its RBE3 mean translation and least-squares
rotation zero, flexgear.fe.cms; the interface nodes stay free to deform). A force at a point is spread
over the surface nodes within ``spread_radius_m`` of it, weighted by their lumped surface areas
(default: the nearest surface node); or, with ``kernel``, it is the contact kernel's load
(flexgear.fe.attachment eq. 1) at the point's angle on the circle that holds it, the load a gear
contact puts on a flexible gear, sensed by the same kernel.

- Full FE model: min 1/2 u^T K u - f^T u subject to C u = 0 (C the held interface's six RBE3 rows),
  one sparse factorisation of the free body (flexgear.fe.cms), kept for the next call on the same model.
- Reduced body u = R a + Phi q (rigid modes R, free-free modes Phi, K_r = diag(omega^2)): C u = 0 gives
  a = -(C R)^-1 C Phi q, so u = Phi_h q with Phi_h = Phi - R (C R)^-1 C Phi and
  C = F^T Phi_h diag(omega^-2) Phi_h^T F  (Ritz: exact when the basis holds the static responses).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from flexgear.fe.attachment import LoadCircle, kernel_load
from flexgear.fe.cms import FreeBodySolver, Interface, ReducedBody, interface, rbe3_rows, rbe3_weights
from flexgear.fe.fem import FEModel, rigid_body_modes

__all__ = ["static_compliance", "surface_node_areas", "point_loads", "free_body_solver"]

_SOLVER: list = [None, None]  # (FE model, its free-body solver): the last one, reused by the next call


def surface_node_areas(n_nodes: int, triangles: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Lumped surface area per node [m^2]: a third of each adjacent surface triangle's area (0 inside)."""
    p = nodes[triangles]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    return np.bincount(triangles.ravel(), np.repeat(area / 3.0, 3), minlength=n_nodes)


def point_loads(nodes: np.ndarray, triangles: np.ndarray, points, directions,
                spread_radius_m: float | None = None) -> np.ndarray:
    """Unit forces (3n, p) at ``points`` (p, 3) [m] along ``directions`` (p, 3), spread area-weighted
    over the surface nodes within ``spread_radius_m`` (default: on the nearest surface node)."""
    points, dirs = np.atleast_2d(np.asarray(points, float)), np.atleast_2d(np.asarray(directions, float))
    if points.shape != dirs.shape or points.shape[1] != 3:
        raise ValueError(f"static_compliance: points {points.shape} and directions {dirs.shape} must both be (p, 3)")
    dirs = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    areas = surface_node_areas(len(nodes), triangles, nodes)
    surf = np.flatnonzero(areas > 0.0)
    out = np.zeros((len(nodes), 3, len(points)))
    for k, (x, d) in enumerate(zip(points, dirs, strict=True)):
        dist = np.linalg.norm(nodes[surf] - x, axis=1)
        sel = surf[[np.argmin(dist)]] if spread_radius_m is None else surf[dist <= spread_radius_m]
        if not len(sel):
            raise ValueError(f"static_compliance: no surface node within spread_radius_m = {spread_radius_m} m "
                             f"of point {x}")
        w = areas[sel] / areas[sel].sum()
        out[sel, :, k] = w[:, None] * d
    return out.reshape(3 * len(nodes), -1)


def _kernel_loads(nodes: np.ndarray, circles: Sequence[LoadCircle], points, directions) -> np.ndarray:
    """Kernel load of each point on the circle whose axial range holds it (nearest radius among those)."""
    points, dirs = np.atleast_2d(np.asarray(points, float)), np.atleast_2d(np.asarray(directions, float))
    cols = []
    for x, d in zip(points, dirs, strict=True):
        hold = [c for c in circles if c.z_min_m - 1e-9 <= x[2] <= c.z_max_m + 1e-9]
        if not hold:
            raise ValueError(f"static_compliance: point {x} lies in no kernel circle's axial range")
        circle = min(hold, key=lambda c: abs(c.radius_m - np.hypot(x[0], x[1])))
        cols.append(kernel_load(nodes, circle, float(np.arctan2(x[1], x[0])), d / np.linalg.norm(d)))
    return np.stack(cols, axis=1)


def free_body_solver(fe: FEModel) -> FreeBodySolver:
    """The free-body factorisation of ``fe`` (flexgear.fe.cms), kept for the next call on the same model."""
    if _SOLVER[0] is not fe:
        _SOLVER[:] = [fe, FreeBodySolver(fe)]
    return _SOLVER[1]


def _held(model: FEModel | ReducedBody, held: Interface | str) -> Interface:
    if isinstance(held, Interface):
        return held
    if isinstance(model, ReducedBody):
        return model.interface(held)
    return interface(model, held)


def static_compliance(model: FEModel | ReducedBody, points, directions,
                      held: Interface | str | Sequence[Interface | str],
                      spread_radius_m: float | None = None, *,
                      kernel: LoadCircle | Sequence[LoadCircle] | None = None) -> np.ndarray:
    """Compliance matrix (p, p) [m/N] of ``model`` for unit forces at ``points`` along ``directions``.

    ``model``: a full FE model (flexgear.fe.fem.FEModel) or a reduced body (flexgear.fe.cms.ReducedBody) of
    the same mesh; ``held``: the interface (or its name: a reduced body's interface, a full model's
    named boundary region) whose RBE3 motion is held, or several (a ring's bolt patches, each held);
    ``spread_radius_m`` [m]: each force is spread area-weighted over the surface nodes within it (default: the
    nearest surface node); ``kernel``: load circles whose contact-kernel loads replace the spread forces (see the
    module docstring).
    """
    nodes = model.nodes
    if kernel is not None:
        circles = [kernel] if isinstance(kernel, LoadCircle) else list(kernel)
        f = _kernel_loads(nodes, circles, points, directions)
    else:
        f = point_loads(nodes, model.surface_triangles, points, directions, spread_radius_m)
    parts = [held] if isinstance(held, (Interface, str)) else list(held)
    itfs = [_held(model, h) for h in parts]
    if isinstance(model, ReducedBody):
        # u = Phi q + R r; each held interface i: C_i (Phi q + R r) = 0. The first eliminates the rigid motion r,
        # the others constrain q (D q = 0): C = G (L - L D^T (D L D^T)^-1 D L) G^T with L = Lambda^-1
        c_phi, c_r = [], []
        rig_all = rigid_body_modes(nodes)
        for itf in itfs:
            rows = rbe3_weights(nodes, itf)  # (k, 6, 3)
            phi = model.modes.reshape(len(nodes), 3, -1)[itf.nodes]
            rig = rig_all.reshape(len(nodes), 3, 6)[itf.nodes]
            c_phi.append(np.einsum("idc,icm->dm", rows, phi))
            c_r.append(np.einsum("idc,icm->dm", rows, rig))
        elim = np.linalg.solve(c_r[0], c_phi[0])  # r = -elim q
        g = f.T @ model.modes - (f.T @ rig_all) @ elim
        flex = 1.0 / model.stiffness
        out = (g * flex) @ g.T
        if len(itfs) > 1:
            d = np.vstack([cp - cr @ elim for cp, cr in zip(c_phi[1:], c_r[1:], strict=True)])
            gd = (g * flex) @ d.T
            out -= gd @ np.linalg.solve((d * flex) @ d.T, gd.T)
        return 0.5 * (out + out.T)
    if not isinstance(model, FEModel):
        raise TypeError(f"static_compliance: model must be an FEModel or a ReducedBody, got {type(model).__name__}")
    rows = sp.vstack([sp.csr_matrix(rbe3_rows(model, itf)) for itf in itfs]).tocsr()
    con = free_body_solver(model).constrained(rows)
    u = con.solve(f, np.zeros((rows.shape[0], f.shape[1])))
    c = f.T @ u
    return 0.5 * (c + c.T)
