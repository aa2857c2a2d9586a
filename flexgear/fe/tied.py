"""Tied FE assemblies: several FE models joined by multipoint ties over mating faces, reduced as one body.

Parts are FE models (flexgear.fe.fem.FEModel) given in one frame. A :class:`Tie` joins a set of nodes of one
part (the slave nodes, on a mating plane) to the face of another part (the master) on that plane: each slave
node moves with the master face's point where it lies, interpolated by the face's triangle shape functions
(linear or quadratic, isoparametric: the same interpolation as flexgear.fe.bolted),

    u_s = sum_a N_a(xi_s) u_a.                                                                          (1)

The same weights act on each of the three directions, so the tie of all coordinates is T = T_s (x) I_3 with the
scalar tie T_s (N, N_t): identity on the kept nodes, eq. (1) on the eliminated slave nodes (N all nodes of the
parts, N_t the kept ones). With the parts' block-diagonal matrices the tied model is

    K_t = T^T K T,   M_t = T^T M T = (T_s^T M_s T_s) (x) I_3,                                          (2)

again an FE model of the form flexgear.fe.cms reduces (scalar mass matrix, interleaved coordinates). The
isoparametric weights reproduce the slave nodes' positions (sum_a N_a x_a = x_s) and sum to 1, so T_s carries
every linear field, rigid motions and the node coordinates among them: the tied model's rigid-body modes have
zero energy and its mass, centre of mass and inertia (m = 1^T M_s 1, X^T M_s 1, X^T M_s X) are exactly the sums
of the parts'.

:func:`reduce` is flexgear.fe.cms.reduce for an FE model, a :class:`TiedFE`, or a list of FE models with their
ties (the tied model (2) built first): the public entry ``flexgear.reduce``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from flexgear.fe.attachment import LoadCircle
from flexgear.fe.bolted import isoparametric_coordinates, locate_in_triangles, shape_functions
from flexgear.fe.cms import Interface, ReducedBody
from flexgear.fe.cms import reduce as _reduce_fe
from flexgear.fe.fem import FEModel, surface_faces

__all__ = ["Tie", "TiedFE", "tie_parts", "tie_weights", "reduce"]

PLANE_TOL_M = 1e-6
"""Distance [m] within which a node lies on a mating plane (nodes sit on the exact OCC surfaces to ~1e-9 m)."""
MAX_OUTSIDE = 0.05
"""Default largest barycentric distance outside the master face (of its triangle) at which a slave node is still
tied to the nearest triangle: a node on a curved edge beyond the chord; farther means not on the mating face."""


@dataclass(frozen=True)
class Tie:
    """Slave nodes of part ``slave`` tied to the face of part ``master`` on a mating plane, eq. (1).

    ``master``, ``slave``: part indices (positions in the parts list); ``slave_nodes``: node indices of the slave
    part (on the plane); ``plane_point`` [m] and ``plane_normal`` (3,): the plane; the master face is the master's
    boundary triangles on it. ``max_outside``: see :data:`MAX_OUTSIDE`.
    """

    master: int
    slave: int
    slave_nodes: np.ndarray
    plane_point: tuple[float, float, float]
    plane_normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    max_outside: float = MAX_OUTSIDE


def _plane_frame(point, normal) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), in-plane axes (3, 2)) of the plane through ``point`` with ``normal``."""
    n = np.asarray(normal, float)
    if n.shape != (3,) or not np.linalg.norm(n) > 0:
        raise ValueError(f"Tie: plane_normal must be 3 numbers, not all zero; got {normal!r}")
    n = n / np.linalg.norm(n)
    helper = np.eye(3)[np.argmin(np.abs(n))]
    e1 = np.cross(n, helper)
    e1 /= np.linalg.norm(e1)
    return np.asarray(point, float), np.column_stack([e1, np.cross(n, e1)])


def tie_weights(master: FEModel, points: np.ndarray, plane_point, plane_normal=(0.0, 0.0, 1.0),
                max_outside: float = MAX_OUTSIDE) -> tuple[np.ndarray, np.ndarray]:
    """Master nodes (k, 3 | 6) and weights N_a (k, 3 | 6) of eq. (1) for ``points`` (k, 3) [m] on the plane.

    The master face is ``master``'s boundary faces whose corners lie on the plane; each point is located in the
    face (in-plane coordinates) and its isoparametric coordinates solved (flexgear.fe.bolted). ValueError if a
    point is off the plane, the master has no face there, or a point lies outside the face by more than
    ``max_outside`` (barycentric).
    """
    origin, axes = _plane_frame(plane_point, plane_normal)
    normal = np.cross(axes[:, 0], axes[:, 1])
    points = np.atleast_2d(np.asarray(points, float))
    off = np.abs((points - origin) @ normal)
    if off.max(initial=0.0) > PLANE_TOL_M:
        raise ValueError(f"tie: a slave node lies {off.max():.2e} m off the mating plane")
    faces = surface_faces(master)
    on_plane = np.all(np.abs((master.nodes[faces[:, :3]] - origin) @ normal) < PLANE_TOL_M, axis=1)
    faces = faces[on_plane]
    if not len(faces):
        raise ValueError(f"tie: the master has no boundary face on the plane through {origin} normal {normal}")
    local = (points - origin) @ axes
    corners = (master.nodes[faces[:, :3]] - origin) @ axes
    face, bary = locate_in_triangles(local, corners)
    bary = isoparametric_coordinates(local, (master.nodes[faces[face]] - origin) @ axes, bary)
    if bary.min() < -max_outside:
        raise ValueError(f"tie: a slave node lies outside the master face (barycentric {bary.min():.3f})")
    return faces[face], shape_functions(bary, faces.shape[1])


@dataclass
class TiedFE:
    """A tied assembly as one FE model: ``fe`` (eq. 2) and the maps between the parts and it.

    ``names``: part names (the tied model's regions are ``"<name>.<region>"``); ``offsets`` (parts + 1,): first
    node of each part in the stacked numbering of all parts' nodes; ``column`` (N,): each stacked node's index in
    ``fe`` (-1: eliminated slave node); ``scalar_tie`` (N, N_t): T_s of eq. (2).
    """

    fe: FEModel
    names: tuple[str, ...]
    offsets: np.ndarray
    column: np.ndarray
    scalar_tie: sp.csr_matrix

    def part_index(self, part: int | str) -> int:
        """Index of ``part`` (its index or name)."""
        if isinstance(part, str):
            if part not in self.names:
                raise KeyError(f"no part {part!r}; the assembly has {list(self.names)}")
            return self.names.index(part)
        return int(part)

    def nodes_of(self, part: int | str, nodes: np.ndarray) -> np.ndarray:
        """Indices in ``fe`` of the nodes ``nodes`` of ``part``; ValueError if one of them was eliminated."""
        p = self.part_index(part)
        out = self.column[self.offsets[p] + np.asarray(nodes, np.int64)]
        if np.any(out < 0):
            raise ValueError(f"part {self.names[p]!r}: {int(np.sum(out < 0))} of the nodes are tied slave nodes "
                             "(eliminated); choose nodes off the tied faces or on the master side")
        return out

    def interface(self, part: int | str, itf: Interface, name: str | None = None) -> Interface:
        """``itf`` of ``part`` (its node indices) as an interface of ``fe`` (same weights and point)."""
        return Interface(name or itf.name, self.nodes_of(part, itf.nodes), itf.weights, itf.point)

    def expand(self, u: np.ndarray) -> np.ndarray:
        """Displacements (3N, ...) of all parts' nodes (stacked) from those of ``fe`` (3N_t, ...): T u."""
        u = np.asarray(u, float)
        n_t = self.scalar_tie.shape[1]
        flat = u.reshape(n_t, -1)
        return (self.scalar_tie @ flat).reshape((3 * self.scalar_tie.shape[0],) + u.shape[1:])


def _scalar_tie(parts: Sequence[FEModel], ties: Sequence[Tie], offsets: np.ndarray) -> tuple[sp.csr_matrix, np.ndarray]:
    """T_s (N, N_t) of eq. (2) and the column map (N,) (-1 for eliminated nodes)."""
    n_all = int(offsets[-1])
    slave = np.zeros(n_all, bool)
    rows, cols, vals = [], [], []
    for k, tie in enumerate(ties):
        for p in (tie.master, tie.slave):
            if not 0 <= p < len(parts):
                raise ValueError(f"tie {k}: part index {p} out of range 0..{len(parts) - 1}")
        if tie.master == tie.slave:
            raise ValueError(f"tie {k}: master and slave are the same part {tie.master}")
        local = np.unique(np.asarray(tie.slave_nodes, np.int64))
        stacked = offsets[tie.slave] + local
        if np.any(slave[stacked]):
            raise ValueError(f"tie {k}: a slave node is already tied by another tie")
        slave[stacked] = True
        master_nodes, weights = tie_weights(parts[tie.master], parts[tie.slave].nodes[local], tie.plane_point,
                                            tie.plane_normal, tie.max_outside)
        rows.append(np.repeat(stacked, master_nodes.shape[1]))
        cols.append((offsets[tie.master] + master_nodes).ravel())
        vals.append(weights.ravel())
    column = np.full(n_all, -1, np.int64)
    kept = np.flatnonzero(~slave)
    column[kept] = np.arange(len(kept))
    tied_cols = np.concatenate(cols) if cols else np.zeros(0, np.int64)
    if np.any(slave[tied_cols]):
        raise ValueError("tie: a master face node is itself a slave node of another tie (chained ties)")
    rows = np.concatenate([kept, *rows])
    cols = np.concatenate([column[kept], column[tied_cols]])
    vals = np.concatenate([np.ones(len(kept)), *vals])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_all, len(kept))), column


def _surface(parts: Sequence[FEModel], offsets: np.ndarray, column: np.ndarray, order: int) -> np.ndarray:
    """Boundary triangles of the tied model in flexgear.fe.fem's flat layout (for order 2 the four sub-triangle
    blocks of the six-node faces), without the faces that touch an eliminated node (the tied faces)."""
    faces = [offsets[p] + surface_faces(fe) for p, fe in enumerate(parts)]
    faces = np.concatenate(faces) if faces else np.zeros((0, 3), np.int64)
    faces = column[faces]
    faces = faces[np.all(faces >= 0, axis=1)]
    if order != 2:
        return faces
    c0, c1, c2, m01, m12, m02 = (faces[:, k] for k in range(6))
    return np.concatenate([np.c_[c0, m01, m02], np.c_[m01, c1, m12], np.c_[m01, m12, m02], np.c_[m02, m12, c2]])


def tie_parts(parts: Sequence[FEModel], ties: Sequence[Tie], names: Sequence[str] | None = None) -> TiedFE:
    """The tied model (2) of ``parts`` joined by ``ties``; ``names`` the parts' names (default "part<k>").

    The parts must share their element order. The tied model's ``material`` is the first part's (K and M carry
    each part's own); its regions are the parts' named regions as ``"<name>.<region>"`` (eliminated nodes left
    out, the others' surface weights kept).
    """
    parts = list(parts)
    if not parts:
        raise ValueError("tie_parts: no parts")
    names = tuple(names) if names is not None else tuple(f"part{k}" for k in range(len(parts)))
    if len(names) != len(parts) or len(set(names)) != len(names):
        raise ValueError(f"tie_parts: need {len(parts)} distinct part names, got {list(names)}")
    orders = {fe.order for fe in parts}
    if len(orders) != 1:
        raise ValueError(f"tie_parts: parts of different element orders {sorted(orders)}")
    offsets = np.concatenate([[0], np.cumsum([fe.n_nodes for fe in parts])]).astype(np.int64)
    t_s, column = _scalar_tie(parts, ties, offsets)
    t_3 = sp.kron(t_s, sp.identity(3), format="csr")
    k_t = (t_3.T @ sp.block_diag([fe.K for fe in parts], format="csr") @ t_3).tocsr()
    k_t = ((k_t + k_t.T) * 0.5).tocsr()
    k_t.sort_indices()
    m_t = (t_s.T @ sp.block_diag([fe.mass_scalar for fe in parts], format="csr") @ t_s).tocsr()
    m_t = ((m_t + m_t.T) * 0.5).tocsr()
    m_t.sort_indices()
    nodes = np.vstack([fe.nodes for fe in parts])[column >= 0]
    regions, weights = {}, {}
    for p, (name, fe) in enumerate(zip(names, parts, strict=True)):
        for region, local in fe.regions.items():
            cols = column[offsets[p] + local]
            keep = cols >= 0
            if keep.sum() >= 1:
                regions[f"{name}.{region}"] = cols[keep]
                weights[f"{name}.{region}"] = np.asarray(fe.region_weights[region])[keep]
    order = parts[0].order
    fe = FEModel(nodes, k_t, m_t, order, parts[0].material, regions, weights, _surface(parts, offsets, column, order))
    return TiedFE(fe, names, offsets, column, t_s)


def reduce(model: FEModel | TiedFE | Sequence[FEModel], interfaces: list[Interface | str],
           n_modes: int | None = None, kind: str = "rbe3", n_compare: int = 12,
           load_circles: list[LoadCircle] | None = None, rigid: tuple[str, ...] = (),
           ties: Sequence[Tie] = (), names: Sequence[str] | None = None, max_hz: float | None = None) -> ReducedBody:
    """Craig-Bampton reduction (flexgear.fe.cms.reduce, same arguments) of an FE model or a tied assembly.

    ``model``: an FE model; a :class:`TiedFE`; or a list of FE models, tied by ``ties`` (and named ``names``)
    through :func:`tie_parts` first. For an assembly, ``interfaces`` are interfaces of the tied model: node
    indices of ``TiedFE.fe`` (map a part's with :meth:`TiedFE.interface`) or its region names
    ``"<part>.<region>"``. The body's nodes are the tied model's (every part's nodes but the eliminated ones).
    """
    if isinstance(model, FEModel):
        if ties:
            raise ValueError("reduce: ties need a list of FE models (the parts), not one FE model")
        fe = model
    elif isinstance(model, TiedFE):
        if ties:
            raise ValueError("reduce: a TiedFE is tied already; pass its parts as a list to tie them anew")
        fe = model.fe
    else:
        fe = tie_parts(list(model), ties, names).fe
    return _reduce_fe(fe, interfaces, n_modes, kind=kind, n_compare=n_compare, load_circles=load_circles,
                      rigid=rigid, max_hz=max_hz)
