"""Component-mode synthesis: Hurty-Craig-Bampton reduction of an FE model to a floating-frame body.

Basis. For interfaces j = 1..J (node sets where the body is joined to others) the reduction basis
is T = [Psi_s, Phi_f]:

- ``kind="rbe3"`` (default, distributing interface): the 6 motions of interface j are the weighted
  average translation and rotation of its nodes (weights w_i = surface areas, r_i = x_i - p_j),

      t_j = sum w_i u_i / sum w_i,   theta_j = A_j^-1 sum w_i r_i x u_i,  A_j = sum w_i (|r_i|^2 I - r_i r_i^T),

  written C u = q. Static (constraint) modes Psi_s minimise u^T K u subject to C u = e_k; the
  fixed-interface modes Phi_f solve K phi = omega^2 M phi subject to C phi = 0. The interface
  nodes stay free to deform, so a bore or a bolt patch does not stiffen the body.
- ``kind="rbe2"`` (rigid interface): the interface nodes move as a rigid patch, u_b = R_b q; static
  modes [R_b; -K_ii^-1 K_ib R_b], fixed-interface modes from (K_ii, M_ii): classical Craig-Bampton.
  Mixed (``rigid=`` names): those interfaces rigid, the others RBE3 rows on the interior (bolt patches).

Both are solved with one sparse Cholesky factorisation (flexgear.fe.cholesky). The free body's K is
singular, so the rigid-body motion is split off exactly: u = R a + u_f with u_f zero on six determinate
support coordinates (chosen by pivoted QR of the rigid modes R); u^T K u = u_f^T K_ff u_f with K_ff positive definite,
and each constrained solve is one K_ff solve plus a small dense saddle-point system.

Free-free modes. T contains the rigid-body modes exactly (a rigid motion is the zero-energy solution
of its own interface values). The reduced eigenproblem (T^T K T) y = omega^2 (T^T M T) y has six
zero eigenvalues (dropped); the remaining eigenvectors Psi = T y, mass-normalised, are the flexible
coordinates of the floating-frame body. They are M-orthogonal to the rigid modes (Tisserand mean
axes), so the reduced mass matrix is I and the stiffness diag(omega^2). The full FE model's lowest
free-free frequencies (same solver, constraint R^T M u = 0) are stored beside them for checking.

Floating-frame invariants (Zwoelfer and Gerstmayr, Acta Mechanica 2021; the terms Exudyn's
ObjectFFRFreducedOrder takes) follow from the scalar mass matrix M_s (M = M_s (x) I_3):
with G = X^T M_s X for the node-wise mode array X (n, 3m) and H = X_ref^T M_s X,
sum_ik M_ik skew(a_i)^T skew(b_k) = tr(P) I - P^T  (P = sum_ik M_ik a_i b_k^T).
"""

from __future__ import annotations

import io
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from threadpoolctl import threadpool_limits

from flexgear.fe.attachment import LoadCircle, load_patterns, modal_basis
from flexgear.fe.cholesky import SparseCholesky
from flexgear.fe.fem import FEModel, rigid_body_modes
from flexgear.fe.invariants import EPS as _EPS
from flexgear.fe.invariants import ffrf_invariants
from flexgear.fe.spectrum import lowest_eigenpairs, shift_invert_pairs
from flexgear.geometry.massprops import MassProperties

__all__ = ["Interface", "ReducedBody", "BasisParts", "interface", "rbe3_weights", "reduce", "reduction_basis",
           "full_free_modes", "ffrf_invariants", "FreeBodySolver", "rbe3_rows"]

_SOLVE_BLOCK = 8  # columns per block of constrained static solves (memory: 6 work arrays of 3n x 8)


@dataclass(frozen=True)
class Interface:
    """A node set where the body is connected: node indices, weights (sum 1), reference point [m]."""

    name: str
    nodes: np.ndarray
    weights: np.ndarray
    point: np.ndarray


def interface(fe: FEModel, where: str | np.ndarray, name: str | None = None) -> Interface:
    """Interface from a named boundary region (surface-area weights) or from node indices.

    Node indices given directly are weighted by their share of the surface area where they lie
    on named regions, else equally.
    """
    if isinstance(where, str):
        nodes, weights = fe.region(where), fe.region_weights[where]
        name = name or where
    else:
        nodes = np.unique(np.asarray(where, dtype=np.int64))
        weights = np.ones(len(nodes))
        for reg, reg_nodes in fe.regions.items():
            hit = np.isin(reg_nodes, nodes)
            if hit.any():
                pos = np.searchsorted(nodes, reg_nodes[hit])
                weights[pos] = fe.region_weights[reg][hit] / fe.region_weights[reg][hit].mean()
        if name is None:
            raise ValueError("interface: give a name for an interface defined by node indices")
    if len(nodes) < 3:
        raise ValueError(f"interface {name!r}: needs at least 3 nodes, got {len(nodes)}")
    w = np.asarray(weights, float) / np.sum(weights)
    return Interface(name, np.asarray(nodes, np.int64), w, w @ fe.nodes[nodes])


def rbe3_weights(nodes: np.ndarray, itf: Interface) -> np.ndarray:
    """Local RBE3 rows (k, 6, 3) of ``itf``: (t, theta) = sum_i rows[i] @ u_i over its k nodes.

    t = sum w_i u_i (weighted mean translation), theta = A^-1 sum w_i r_i x u_i with
    A = sum w_i (|r_i|^2 I - r_i r_i^T), r_i = x_i - p (least-squares rotation); ``nodes`` (n, 3) [m].
    """
    r = nodes[itf.nodes] - itf.point
    w = itf.weights
    a = np.einsum("i,ij,ik->jk", w, r, r)
    a = np.trace(a) * np.eye(3) - a
    if np.linalg.cond(a) > 1e12:
        raise ValueError(f"interface {itf.name!r}: nodes are collinear, rotation undefined")
    a_inv = np.linalg.inv(a)
    skew = np.einsum("ejk,ij->iek", _EPS, r)  # skew(r_i)[e, k] = eps_ejk r_j  (skew(r) u = r x u)
    rows = np.zeros((len(itf.nodes), 6, 3))
    rows[:, 0:3, :] = w[:, None, None] * np.eye(3)[None]
    rows[:, 3:6, :] = np.einsum("de,i,iek->idk", a_inv, w, skew)
    return rows


def rbe3_rows(fe: FEModel, itf: Interface) -> sp.csr_matrix:
    """Rows (6, 3n) of C: weighted mean translation and least-squares rotation of the interface."""
    rows = rbe3_weights(fe.nodes, itf)
    cols = (3 * itf.nodes[:, None, None] + np.arange(3)[None, None, :]).repeat(6, axis=1)
    rr = np.broadcast_to(np.arange(6)[None, :, None], rows.shape)
    return sp.csr_matrix((rows.ravel(), (rr.ravel(), cols.ravel())), shape=(6, fe.n_dof))


class FreeBodySolver:
    """Constrained static solves and shift-invert operators for a free body with one factorisation.

    Solves min 1/2 u^T K u - g^T u subject to C u = e for a free (singular) K, see module docstring.
    """

    def __init__(self, fe: FEModel, rigid_modes: np.ndarray | None = None):
        """``rigid_modes`` (n, 6): the body's rigid motions where its coordinates are not its nodes' (default
        flexgear.fe.fem.rigid_body_modes of ``fe.nodes``)."""
        self.n = fe.n_dof
        self.R = rigid_body_modes(fe.nodes) if rigid_modes is None else np.array(rigid_modes, float)
        scale = np.linalg.norm(self.R[:, :3], axis=0).mean() / np.linalg.norm(self.R[:, 3:], axis=0).mean()
        self.R[:, 3:] *= scale
        _, _, piv = la.qr(self.R.T, mode="economic", pivoting=True)
        self.support = np.sort(piv[:6])
        mask = np.ones(self.n, bool)
        mask[self.support] = False
        self.free = np.flatnonzero(mask)
        self.Rs_inv = np.linalg.inv(self.R[self.support])
        self.R = self.R @ self.Rs_inv  # now R[support] = I: u = R u_s + E_f u_f
        # K_ff (positive definite): its lower triangle, which is the lower triangle of K restricted to the
        # (ascending) free coordinates, all the factorisation reads
        self.chol = SparseCholesky(sp.tril(fe.K, format="csr")[self.free][:, self.free])

    def solve_ff(self, rhs: np.ndarray) -> np.ndarray:
        return self.chol.solve(rhs)

    def constrained(self, c: sp.spmatrix | np.ndarray) -> _Constrained:
        return _Constrained(self, c)


class _Constrained:
    """Saddle-point data for one constraint matrix C (p, 3n) of full row rank."""

    def __init__(self, s: FreeBodySolver, c):
        self.s = s
        c = sp.csr_matrix(c) if sp.issparse(c) else np.asarray(c)
        self.c_f = c[:, s.free]
        self.g = np.asarray(c @ s.R)  # (p, 6)
        ct = self.c_f.T.toarray() if sp.issparse(self.c_f) else self.c_f.T
        self.z = s.solve_ff(ct)  # K_ff^-1 C_f^T  (nf, p)
        sc = np.asarray(self.c_f @ self.z)
        p = sc.shape[0]
        big = np.zeros((p + 6, p + 6))
        big[:p, :p], big[:p, p:], big[p:, :p] = sc, -self.g, self.g.T
        self.lu_small = la.lu_factor(big)
        self.p = p

    def solve(self, g: np.ndarray | None, e: np.ndarray | None = None) -> np.ndarray:
        """u minimising 1/2 u^T K u - g^T u with C u = e; g (3n, k) (None: no load, e (p, k) given), e (p, k).

        Columns are solved in blocks of ``_SOLVE_BLOCK``: each is independent, and the work arrays stay small.
        Without a load no K_ff solve is needed: u is the constraint part alone.
        """
        g = None if g is None else np.atleast_2d(g.T).T
        k = e.shape[1] if g is None else g.shape[1]
        if k <= _SOLVE_BLOCK:
            return self._solve(g, e)
        u = np.empty((self.s.n, k))
        for j in range(0, k, _SOLVE_BLOCK):
            cols = slice(j, j + _SOLVE_BLOCK)
            u[:, cols] = self._solve(None if g is None else g[:, cols], None if e is None else e[:, cols])
        return u

    def _solve(self, g: np.ndarray | None, e: np.ndarray | None) -> np.ndarray:
        s, p = self.s, self.p
        if g is None:  # K_ff^-1 0 = 0: the same numbers as the solve, without it
            y, rg = np.zeros((len(s.free), e.shape[1])), np.zeros((6, e.shape[1]))
        else:
            y, rg = s.solve_ff(g[s.free]), s.R.T @ g
        rhs = np.vstack([np.asarray(self.c_f @ y) - (0.0 if e is None else e), rg])
        sol = la.lu_solve(self.lu_small, rhs)
        lam, a = sol[:p], sol[p:]
        u = s.R @ a
        u[s.free] += y - self.z @ lam
        return u

    def eigen(self, fe: FEModel, k: int, m: sp.spmatrix | sla.LinearOperator, found: np.ndarray | None = None,
              below: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Lowest k eigenpairs of K phi = omega^2 M phi on {C phi = 0} beyond the eigenvectors ``found``, or every
        pair with omega^2 below ``below`` [1/s^2] and the next (flexgear.fe.spectrum.shift_invert_pairs)."""
        v0 = self.solve(m @ np.random.default_rng(0).standard_normal(self.s.n))[:, 0]
        k = min(k, self.s.n - self.p - 2)
        return shift_invert_pairs(self.solve, m, k, v0, found, below=below)


@threadpool_limits.wrap(limits=1, user_api="blas")
def full_free_modes(fe: FEModel, k: int, solver: FreeBodySolver | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lowest k flexible free-free modes of the full FE model: frequencies [Hz] and shapes (3n, k)."""
    solver = solver or FreeBodySolver(fe)
    m = fe.mass_operator()
    lam, vec = solver.constrained((m @ solver.R).T).eigen(fe, k, m)
    return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi), vec


@dataclass
class ReducedBody:
    """A Craig-Bampton-reduced flexible body in its component frame (SI units).

    ``modes`` (3n, m) mass-normalised flexible free-free modes of the reduced model (M-orthogonal
    to the rigid modes); ``stiffness`` (m,) = omega^2 [1/s^2] (reduced M = I); ``frequencies_hz``
    the reduced model's and ``full_frequencies_hz`` the full FE model's lowest free-free
    frequencies; ``invariants`` the floating-frame terms of Exudyn's ObjectFFRFreducedOrder;
    ``props`` mass properties of the FE model (exactly those of the reduced body).
    """

    nodes: np.ndarray
    modes: np.ndarray
    stiffness: np.ndarray
    frequencies_hz: np.ndarray
    full_frequencies_hz: np.ndarray
    interfaces: list[Interface]
    kind: str
    n_fixed_interface_modes: int
    props: MassProperties
    invariants: dict[str, np.ndarray]
    surface_triangles: np.ndarray
    info: dict[str, float] = field(default_factory=dict)

    @property
    def n_modes(self) -> int:
        return self.modes.shape[1]

    def interface(self, name: str) -> Interface:
        for itf in self.interfaces:
            if itf.name == name:
                return itf
        raise KeyError(f"no interface {name!r}; have {[i.name for i in self.interfaces]}")

    def interface_motion(self, name: str | Interface) -> np.ndarray:
        """(6, m): RBE3 translation [m] and rotation [rad] of interface ``name`` (or of an Interface of the
        body's nodes) per modal coordinate.

        The interface's six motions in the body frame are ``interface_motion(name) @ q`` (eq. of
        :func:`rbe3_weights` applied to the mode shapes); exact for the RBE3 Craig-Bampton basis.
        """
        itf = name if isinstance(name, Interface) else self.interface(name)
        rows = rbe3_weights(self.nodes, itf)
        shapes = self.modes.reshape(len(self.nodes), 3, -1)[itf.nodes]  # (k, 3, m)
        return np.einsum("idc,icm->dm", rows, shapes)

    def truncated(self, n: int) -> ReducedBody:
        """The same body on its ``n`` lowest modes (exact: each floating-frame invariant is a per-mode block,
        so the kept blocks equal :func:`ffrf_invariants` of the kept modes)."""
        if not 0 <= n <= self.n_modes:
            raise ValueError(f"truncated: n must be in 0..{self.n_modes}, got {n}")
        inv = dict(self.invariants)
        k3 = 3 * n
        inv["mPsiTildePsi"] = self.invariants["mPsiTildePsi"][:k3, :n]
        inv["mPsiTildePsiTilde"] = self.invariants["mPsiTildePsiTilde"][:k3, :k3]
        for key in ("mPhitTPsi", "mXRefTildePsi"):
            inv[key] = self.invariants[key][:, :n]
        for key in ("mPhitTPsiTilde", "mXRefTildePsiTilde"):
            inv[key] = self.invariants[key][:, :k3]
        return replace(self, modes=self.modes[:, :n], stiffness=self.stiffness[:n],
                       frequencies_hz=self.frequencies_hz[:n], invariants=inv)

    def modes_below(self, cutoff_hz: float) -> int:
        """Number of modes whose frequency is below ``cutoff_hz`` [Hz] (modes are sorted by frequency)."""
        return int(np.count_nonzero(self.frequencies_hz < cutoff_hz))

    def save(self) -> bytes:
        """The body as ``.npz`` bytes (write them with flexgear.results.atomic_write_bytes)."""
        arrays = {"nodes": self.nodes, "modes": self.modes, "stiffness": self.stiffness,
                  "frequencies_hz": self.frequencies_hz, "full_frequencies_hz": self.full_frequencies_hz,
                  "kind": np.array(self.kind), "n_fixed": np.array(self.n_fixed_interface_modes),
                  "mass": np.array(self.props.mass), "com": self.props.com, "inertia": self.props.inertia,
                  "surface_triangles": self.surface_triangles,
                  "itf_names": np.array([i.name for i in self.interfaces]),
                  "info_keys": np.array(list(self.info)), "info_values": np.array(list(self.info.values()), float)}
        for k, i in enumerate(self.interfaces):
            arrays[f"itf{k}_nodes"], arrays[f"itf{k}_weights"], arrays[f"itf{k}_point"] = i.nodes, i.weights, i.point
        for key, val in self.invariants.items():
            arrays[f"inv_{key}"] = val
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        return buf.getvalue()

    @classmethod
    def load(cls, data: bytes | str | Path) -> ReducedBody:
        """Inverse of :meth:`save` (bytes or a file path)."""
        with np.load(io.BytesIO(data) if isinstance(data, bytes) else data, allow_pickle=False) as z:
            itfs = [Interface(str(nm), z[f"itf{k}_nodes"], z[f"itf{k}_weights"], z[f"itf{k}_point"])
                    for k, nm in enumerate(z["itf_names"])]
            inv = {k[4:]: z[k] for k in z.files if k.startswith("inv_")}
            info = dict(zip([str(k) for k in z["info_keys"]], [float(v) for v in z["info_values"]], strict=True))
            return cls(z["nodes"], z["modes"], z["stiffness"], z["frequencies_hz"], z["full_frequencies_hz"], itfs,
                       str(z["kind"]), int(z["n_fixed"]), MassProperties(float(z["mass"]), z["com"], z["inertia"]),
                       inv, z["surface_triangles"], info)


def _rigid_patch_basis(fe: FEModel, interfaces: list[Interface], rigid: set[str], n_modes: int | None,
                       patterns: np.ndarray, max_hz: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Craig-Bampton basis with the interfaces named in ``rigid`` as rigid patches (RBE2: their nodes move as
    one, u_b = R_b q) and the others distributing (RBE3 rows C u = q, nodes free to deform).

    With the rigid patches' nodes b clamped, K_ii is regular; a constrained solve of the interior
    min 1/2 u^T K_ii u - g^T u subject to C u = e is u = K_ii^-1 (g - C^T lam), (C K_ii^-1 C^T) lam =
    C K_ii^-1 g - e. Static modes: each rigid patch's six rigid motions (g = -K_ib R_b e_k, e = 0) and each
    distributing interface's six motions (g = 0, e = e_k); fixed-interface modes of (K_ii, M_ii) on C u = 0;
    attachment modes the responses to the load ``patterns`` (3n, p) with all interfaces held.
    """
    bnodes = np.unique(np.concatenate([i.nodes for i in interfaces if i.name in rigid]))
    bdofs = (3 * bnodes[:, None] + np.arange(3)).ravel()
    mask = np.ones(fe.n_dof, bool)
    mask[bdofs] = False
    idofs = np.flatnonzero(mask)
    # K_ii's lower triangle, all the factorisation reads (the rows and columns kept are ascending)
    chol = SparseCholesky(sp.tril(fe.K, format="csr")[idofs][:, idofs])
    soft = [i for i in interfaces if i.name not in rigid]
    c = sp.vstack([rbe3_rows(fe, i) for i in soft]).tocsc()[:, idofs] if soft else sp.csc_matrix((0, len(idofs)))
    z = chol.solve(c.T.toarray()) if soft else np.zeros((len(idofs), 0))
    schur = la.lu_factor(c @ z) if soft else None

    def solve(g: np.ndarray | None, e: np.ndarray | None = None) -> np.ndarray:
        """Interior response to loads ``g`` (None: no load, e given) with the soft interfaces at ``e``."""
        y = chol.solve(g) if g is not None else np.zeros((len(idofs), e.shape[1]))
        if soft:
            lam = la.lu_solve(schur, c @ y - (0.0 if e is None else e))
            y = y - z @ lam
        return y

    ub = np.zeros((len(bdofs), 6 * (len(interfaces) - len(soft))))
    for j, itf in enumerate(i for i in interfaces if i.name in rigid):
        pos = np.searchsorted(bnodes, itf.nodes)
        ub[(3 * pos[:, None] + np.arange(3)).ravel(), 6 * j:6 * j + 6] = rigid_body_modes(fe.nodes[itf.nodes],
                                                                                          centre=itf.point)
    static = np.zeros((fe.n_dof, ub.shape[1] + 6 * len(soft)))
    static[bdofs, :ub.shape[1]] = ub
    # K_ib = K_bi^T (K symmetric): a few rows sliced instead of nearly all
    static[idofs, :ub.shape[1]] = solve(-np.asarray(fe.K[bdofs][:, idofs].T @ ub))
    if soft:
        static[idofs, ub.shape[1]:] = solve(None, np.eye(c.shape[0]))
    m_ii = fe.mass_operator(np.setdiff1d(np.arange(fe.n_nodes), bnodes))  # rows and columns idofs
    v0 = solve(m_ii @ np.random.default_rng(0).standard_normal((len(idofs), 1)))[:, 0]

    def eigen(k: int, found: np.ndarray | None, below: float | None = None
              ) -> tuple[np.ndarray, np.ndarray]:  # reads K_ii only through solve
        return shift_invert_pairs(solve, m_ii, k, v0, found, below=below)

    vec = lowest_eigenpairs(eigen, n_modes, max_hz, limit=len(idofs) - c.shape[0] - 2)[1]
    fixed = np.zeros((fe.n_dof, vec.shape[1]))
    fixed[idofs] = vec
    attached = np.zeros_like(patterns)
    if patterns.shape[1]:
        attached[idofs] = solve(patterns[idofs])
    return static, fixed, attached


@dataclass
class BasisParts:
    """The reduction basis before compression: interface static modes (3n, 6 J), fixed-interface modes
    (3n, n_modes, lowest first), attachment modes (3n, sum 2 N + 1, per circle in the order of
    flexgear.fe.attachment.fourier_basis); the free-body solver (RBE3)."""

    static: np.ndarray
    fixed: np.ndarray
    attached: np.ndarray
    solver: FreeBodySolver | None = None


@threadpool_limits.wrap(limits=1, user_api="blas")
def reduction_basis(fe: FEModel, itfs: list[Interface], n_modes: int | None, kind: str = "rbe3",
                    load_circles: list[LoadCircle] | None = None,
                    solver: FreeBodySolver | None = None, rigid: tuple[str, ...] = (),
                    max_hz: float | None = None) -> BasisParts:
    """Static, fixed-interface and attachment modes of ``fe`` (see :func:`reduce`), one factorisation
    (``solver``: the free body's, if already made)."""
    circles = list(load_circles or [])
    patterns = (np.hstack([load_patterns(fe.nodes, c) for c in circles]) if circles
                else np.zeros((fe.n_dof, 0)))
    rigid_set = {i.name for i in itfs} if kind == "rbe2" else set(rigid)
    if rigid_set:
        return BasisParts(*_rigid_patch_basis(fe, itfs, rigid_set, n_modes, patterns, max_hz))
    solver = solver or FreeBodySolver(fe)
    con = solver.constrained(sp.vstack([rbe3_rows(fe, i) for i in itfs]))
    static = con.solve(None, np.eye(con.p))
    m = fe.mass_operator()
    vec = lowest_eigenpairs(lambda k, found, below=None: con.eigen(fe, k, m, found, below), n_modes, max_hz,
                            limit=con.s.n - con.p - 2)[1]
    fixed = vec if vec.shape[1] else np.zeros((fe.n_dof, 0))
    attached = con.solve(patterns, np.zeros((con.p, patterns.shape[1]))) if circles else patterns
    return BasisParts(static, fixed, attached, solver)


@threadpool_limits.wrap(limits=1, user_api="blas")  # small BLAS calls in solver loops: threads only contend
def reduce(fe: FEModel, interfaces: list[Interface | str], n_modes: int | None = None, kind: str = "rbe3",
           n_compare: int = 12, load_circles: list[LoadCircle] | None = None, rigid: tuple[str, ...] = (),
           max_hz: float | None = None) -> ReducedBody:
    """Craig-Bampton reduction of ``fe`` with ``interfaces`` and ``n_modes`` fixed-interface modes, or with every
    fixed-interface mode below ``max_hz`` [Hz] (exactly one of the two; flexgear.fe.spectrum).

    ``kind``: "rbe3" (distributing interfaces, default; those named in ``rigid`` are rigid patches all the
    same) or "rbe2" (all rigid patches). ``load_circles``
    (flexgear.fe.attachment.LoadCircle): their Fourier load patterns' static responses with the
    interfaces held join the basis as attachment modes (exact compliance under the contact kernel's
    loads). The basis is mass-orthonormalised (dependent directions dropped) and its free-free modes
    are the flexible coordinates: 6 J + n_modes + sum(2 N + 1) - 6 of them, less dropped ones (the lowest
    alone: ReducedBody.truncated, which loses the static correction). ``n_compare`` lowest free-free
    modes of the full FE model are computed for the comparison stored in the result (0 skips it).
    """
    if kind not in ("rbe3", "rbe2"):
        raise ValueError(f"reduce: kind must be 'rbe3' or 'rbe2', got {kind!r}")
    names = [i if isinstance(i, str) else i.name for i in interfaces]
    if set(rigid) - set(names):
        raise ValueError(f"reduce: rigid interfaces {sorted(set(rigid) - set(names))} are not among {names}")
    if not interfaces:
        raise ValueError("reduce: at least one interface is needed (it fixes the static modes' rigid part)")
    itfs = [interface(fe, i) if isinstance(i, str) else i for i in interfaces]
    t0 = time.perf_counter()
    parts = reduction_basis(fe, itfs, n_modes, kind, load_circles, rigid=tuple(rigid), max_hz=max_hz)
    t_full, full = time.perf_counter(), np.zeros(0)
    if n_compare:  # here, while the factor exists: it is freed before the dense work on the basis
        full = full_free_modes(fe, n_compare, parts.solver or FreeBodySolver(fe))[0]
    t_full = time.perf_counter() - t_full
    n_attached, n_fixed = parts.attached.shape[1], parts.fixed.shape[1]
    basis = np.hstack([parts.static, parts.fixed, parts.attached])
    del parts  # the factor and the blocks: the peak memory is the factor's or the basis's, not both
    modes, lam, dropped = modal_basis(basis, fe.K, fe.mass_operator())
    del basis
    t_reduce = time.perf_counter() - t0 - t_full
    invariants = ffrf_invariants(fe.mass_scalar, fe.nodes, modes)
    info = {"n_dof_full": float(fe.n_dof), "n_nodes": float(fe.n_nodes),
            "attachment_vectors": float(n_attached), "dropped_directions": float(dropped),
            "reduce_time_s": t_reduce, "total_time_s": time.perf_counter() - t0}
    return ReducedBody(fe.nodes, modes, lam, np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi), full, itfs, kind,
                       n_fixed, fe.mass_properties(), invariants, fe.surface_triangles, info)
