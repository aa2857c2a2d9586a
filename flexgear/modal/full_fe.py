"""Reference modes of a flexible variant with every flexible body as its full FE model (exact substructuring).

The linearised gearbox (flexgear.modal.linear, at zero speed: no spin terms) couples each flexible body to the
rest only through attachment motions a = W^T u, linear functionals of the body's nodal displacements u (body
frame): the RBE3 motion of each interface (flexgear.fe.cms.rbe3_weights: seats, joints, the bearing points that
move rigidly with a seat) and the least-squares Fourier coefficients of every contact band's normal displacement
(flexgear.mbs.contact_kinematics.modal_contact_fourier: the contact columns c(alpha) are combinations of them
whatever the angle alpha). In the reduced model u = Phi T y (Phi the mass-normalised modes, T the body's
coordinate basis) and a = A y with A = W^T Phi T. The linearised equations over q = [r; y_1; ...] (r every
other coordinate) with constraint Jacobian C then read, per body b,

    (K_e - s M_e) y + A^T g = 0,   g = K_aa a + K_ar r + C_a^T lambda       (s = omega^2)

with K_yy = K_e + A^T K_aa A, K_yr = A^T K_ar, C_y = C_a A. Where A has full row rank the attachment-space
couplings are recovered exactly, K_ar = (A A^T)^-1 A K_yr (likewise K_aa, C_a); :func:`recover` checks that
every coupling lies in A's row space. Eliminating y, a = -H(s) g with the body's dynamic flexibility at its
attachments; the assembled problem over x = [r; lambda; a; g] is the eigenproblem T(s) x = 0,

    T(s) = [[K_rr - s M_rr, C_r^T, K_ra, 0], [C_r, 0, C_a, 0], [K_ar, C_a^T, K_aa, -I], [0, 0, -I, -H(s)]].

Each body's H(s) is written as w diag(1 / (lambda_j - s)) w^T + sum_k s^k R_k: modes with coordinates eta_j
(-kappa w_j^T g + (lambda_j - s) eta_j = 0, g scaled by kappa) and a power series. Up to the series' terms of
order s^2 and higher, T(s) = T_0 - s T_1 is a linear pencil (dense, shift-inverted eigen solve); each of its
eigenpairs (s, x) then moves to the root of its Rayleigh functional x^T T(s) x = 0 with the whole series (T is
symmetric: the error is of second order in the series' effect on the mode shape).

- Reduced body: its modes K_e v = lambda M_e v, w = A v, no series. T(s) x = 0 has exactly the linear model's
  eigenvalues (the check of the recovery).
- Full FE model (K, M of flexgear.fe.fem; the tied ring and output shaft's of flexgear.fe.ring_shaft; the
  carrier's of flexgear.fe.carrier): H(s) = W^T F(s) W, F(s) = sum_j phi_j phi_j^T / (lambda_j - s) over its
  flexible free-free modes (the frame carries the rigid motion; mean axes R^T M u = 0, as the reduced modes).
  The modes with lambda_j < lambda_c are computed (sparse shift-invert, flexgear.fe.cms), the others summed
  exactly as the Neumann series
  R_k = W^T (S M)^k X_0, X_0 = S W - sum_{j<c} phi_j phi_j^T W / lambda_j, with S the free body's static
  flexibility on the mean-axis subspace (one sparse Cholesky factorisation); its terms fall as (s / lambda_c)^k.
  An interface the reduction holds as a rigid patch (RBE2, e.g. the carrier's seat; found by
  flexgear.fe.patches.rigid_interfaces) is held so in the full model too: u = T u_t with u_b = R_b r on each
  patch's nodes (six coordinates r each, flexgear.fe.patches.held_rigid_basis), K_t = T^T K T, M_t = T^T M T,
  W_t = T^T W (a patch's RBE3 motion is its rigid one).

The linearisation used for the couplings keeps every mode of the gears' bases (no residual compliance,
``dynamic_cutoff_mesh_orders = 0``): the full FE carries that compliance itself.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from flexgear.modal.linear import LinearModel

__all__ = ["Attachments", "Coupled", "Flexibility", "attachments",
           "carries_attachments", "recover", "reduced_flexibility", "body_fe_model", "full_flexibility", "assembled",
           "eigenvalues"]

_RANK_TOL = 1e-10  # relative singular value below which constraint rows are redundant


@dataclass
class Attachments:
    """One flexible body's coupling: its elastic coordinates ``index`` in q, W (3n, n_a) sparse nodal weights of
    its attachment motions, A = W^T Phi T (n_a, m), and its modal K_e, M_e (m, m)."""

    component: str
    index: np.ndarray
    weights: sp.csr_matrix
    motion: np.ndarray
    modal_stiffness: np.ndarray
    modal_mass: np.ndarray


def _contact_weights(nodes: np.ndarray, point: np.ndarray, normal: np.ndarray, half_width: float,
                     radial_band: float, order: int) -> sp.csr_matrix:
    """(3n, 2 order + 1): the least-squares Fourier coefficients of a contact band's normal displacement as nodal
    weights, coef = (B^T B)^-1 B^T d(alpha)^T u over the band's nodes (flexgear.mbs.contact_kinematics.
    modal_contact_fourier applied to nodal displacements instead of mode shapes)."""
    import math

    from flexgear.fe.attachment import LoadCircle, circle_band, fourier_basis, local_directions

    r, z, psi = math.hypot(point[0], point[1]), point[2], math.atan2(point[1], point[0])
    sel = circle_band(nodes, LoadCircle(r, z - half_width, z + half_width, order, radial_band_m=radial_band))
    alpha = np.arctan2(nodes[sel, 1], nodes[sel, 0])
    c, s = math.cos(psi), math.sin(psi)
    local = (c * normal[0] + s * normal[1], -s * normal[0] + c * normal[1], normal[2])
    b = fourier_basis(alpha, order)
    fit = np.linalg.solve(b.T @ b, b.T)  # (2N+1, k)
    dirs = local_directions(alpha, local)  # (k, 3)
    rows = (3 * sel[:, None] + np.arange(3)[None, :]).ravel()
    vals = (fit.T[:, None, :] * dirs[:, :, None]).reshape(-1, fit.shape[0])
    return sp.csr_matrix(sp.coo_matrix((vals.ravel(), (np.repeat(rows, fit.shape[0]),
                                                       np.tile(np.arange(fit.shape[0]), len(rows)))),
                                       shape=(3 * len(nodes), fit.shape[0])))


def _interface_weights(nodes: np.ndarray, itf) -> sp.csr_matrix:
    """(3n, 6): the RBE3 translation and rotation of interface ``itf`` (flexgear.fe.cms.rbe3_weights)."""
    from flexgear.fe.cms import rbe3_weights

    rows = rbe3_weights(nodes, itf)  # (k, 6, 3)
    r = (3 * itf.nodes[:, None, None] + np.arange(3)[None, None, :]).repeat(6, axis=1)
    col = np.broadcast_to(np.arange(6)[None, :, None], rows.shape)
    return sp.csr_matrix((rows.ravel(), (r.ravel(), col.ravel())), shape=(3 * len(nodes), 6))


def attachments(system: LinearModel) -> list[Attachments]:
    """Every flexible body's :class:`Attachments` in the linear model ``system`` (flexgear.modal.linear.linearize,
    every mode of the gears' bases kept): all its interfaces' RBE3 motions and the Fourier coefficients of each
    distinct contact band (bands and local normals that coincide, the planets' turned copies, once)."""
    from flexgear.modal.linear import component_name

    spec = system.variant.gearbox
    order, radial_band = spec.reduction_assumed.contact_fourier_order, spec.gears.normal_module_m
    out = []
    for name, body in system.bodies.items():
        if not body.flexible:
            continue
        comp = component_name(name)
        red = body.reduced
        index = np.array([i for i, c in enumerate(system.full_coordinates)
                          if c.kind == "elastic" and c.component == comp])
        blocks = [_interface_weights(red.nodes, itf) for itf in red.interfaces]
        seen = set()
        for c in system.contacts:
            if name not in (c.body1, c.body2):
                continue
            w = _contact_weights(red.nodes, np.asarray(c.point) - body.position, np.asarray(c.normal, float),
                                 0.5 * c.half_width, radial_band, order)
            key = (w.indices.tobytes(), np.round(w.data, 12).tobytes())
            if key not in seen:
                seen.add(key)
                blocks.append(w)
        weights = sp.hstack(blocks, format="csr")
        shapes = red.modes if body.basis is None else red.modes @ body.basis
        motion = np.asarray(weights.T @ shapes)
        k_e = body.modal_matrices[1] if body.modal_matrices is not None else np.diag(red.stiffness)
        out.append(Attachments(comp, index, weights, motion, np.asarray(k_e, float),
                               system.full_mass[np.ix_(index, index)]))
    return out


@dataclass
class Coupled:
    """The rest of the system and its couplings in attachment space (module docstring): K_rr, M_rr over the
    coordinates ``rest`` of q; C = [C_r, C_a] with independent rows; K_ra, K_aa over the stacked attachments
    (``slices``: each body's); ``leak``: the largest part of a coupling outside A's row space, relative."""

    rest: np.ndarray
    k_rr: np.ndarray
    m_rr: np.ndarray
    k_ra: np.ndarray
    k_aa: np.ndarray
    c_r: np.ndarray
    c_a: np.ndarray
    slices: list[slice]
    leak: float

    @property
    def n_attachments(self) -> int:
        return self.k_aa.shape[0]


def _relative_leak(x: np.ndarray, q: np.ndarray, side: str) -> float:
    scale = np.abs(x).max()
    if scale == 0.0:
        return 0.0
    return float(np.abs(q @ x if side == "left" else x @ q).max() / scale)


def carries_attachments(body: Attachments) -> bool:
    """Whether the body's attachment motions A have full row rank (its modes can move every attachment motion on
    its own): the condition under which :func:`recover` finds its couplings exactly."""
    a = body.motion
    if a.shape[0] > a.shape[1]:
        return False
    sv = np.linalg.svd(a / np.linalg.norm(a, axis=1)[:, None], compute_uv=False)
    return bool(sv[-1] >= 1e-8 * sv[0])


def recover(system: LinearModel, bodies: list[Attachments]) -> Coupled:
    """The couplings of every flexible body in attachment space (module docstring), exact where each A has full
    row rank; raises ValueError where it has not. Requires the bodies' elastic coordinates to carry no mass
    coupling to the rest."""
    m, k, c = system.full_mass, system.full_stiffness, system.full_constraint
    n = m.shape[0]
    elastic = np.concatenate([b.index for b in bodies])
    rest = np.setdiff1d(np.arange(n), elastic)
    pinv, leak, slices, start = [], 0.0, [], 0
    for b in bodies:
        a = b.motion
        if not carries_attachments(b):
            raise ValueError(f"{b.component}: attachment motions A {a.shape} lack full row rank")
        p = a.T @ np.linalg.inv(a @ a.T)  # A^+ (m, n_a)
        q = np.eye(a.shape[1]) - p @ a
        leak = max(leak, _relative_leak(k[np.ix_(b.index, rest)], q, "left"),
                   _relative_leak(c[:, b.index], q, "right"),
                   _relative_leak(k[np.ix_(b.index, b.index)] - b.modal_stiffness, q, "left"),
                   _relative_leak(m[np.ix_(b.index, np.setdiff1d(np.arange(n), b.index))], np.eye(a.shape[1]), "left"))
        pinv.append(p)
        slices.append(slice(start, start + a.shape[0]))
        start += a.shape[0]
    big = np.zeros((n, start))  # q = J [r; a]: the elastic part of J
    for b, p, sl in zip(bodies, pinv, slices, strict=True):
        big[b.index, sl] = p
    k_el = k.copy()
    for b in bodies:
        k_el[np.ix_(b.index, b.index)] -= b.modal_stiffness
    k_ra = k[np.ix_(rest, elastic)] @ big[elastic]
    k_aa = big[elastic].T @ k_el[np.ix_(elastic, elastic)] @ big[elastic]
    c_r, c_a = c[:, rest], c[:, elastic] @ big[elastic]
    full = np.hstack([c_r, c_a])
    if full.size:
        from scipy.linalg import qr

        scale = np.linalg.norm(full, axis=1)
        scale[scale == 0.0] = 1.0
        _, r, piv = qr((full / scale[:, None]).T, pivoting=True, mode="economic")
        d = np.abs(np.diag(r))
        keep = np.sort(piv[:int(np.count_nonzero(d > _RANK_TOL * d[0]))])
        c_r, c_a = (c_r / scale[:, None])[keep], (c_a / scale[:, None])[keep]
    return Coupled(rest, k[np.ix_(rest, rest)], m[np.ix_(rest, rest)], k_ra, 0.5 * (k_aa + k_aa.T), c_r, c_a,
                   slices, leak)


@dataclass
class Flexibility:
    """A body's dynamic flexibility at its attachments, H(s) = w diag(1 / (lambda_j - s)) w^T + sum_k s^k R_k:
    ``participation`` w (n_a, p) of its modes with ``eigenvalues`` lambda_j [1/s^2] taken as coordinates, and the
    rest of its modes as the series ``moments`` R_k (n_a, n_a) [m/N s^2k] (empty for a reduced body)."""

    participation: np.ndarray
    eigenvalues: np.ndarray
    moments: list[np.ndarray] = dataclasses.field(default_factory=list)

    def remainder(self, s: float, first: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """sum_{k >= first} s^k R_k and its derivative in s."""
        n = self.participation.shape[0]
        h, dh = np.zeros((n, n)), np.zeros((n, n))
        for k, r in enumerate(self.moments):
            if k >= first:
                h += s ** k * r
                if k:
                    dh += k * s ** (k - 1) * r
        return h, dh


def reduced_flexibility(body: Attachments) -> Flexibility:
    """The reduced body's: its modes K_e v = lambda M_e v (v^T M_e v = 1), w = A v; no remainder."""
    from scipy.linalg import eigh

    lam, v = eigh(body.modal_stiffness, body.modal_mass)
    return Flexibility(body.motion @ v, lam)


def assembled(coupled: Coupled, flexibilities: list[Flexibility], scale: float | None = None):
    """The linear part T(s) = T_0 - s T_1 of the problem over x = [r; lambda; a; g; eta] (module docstring) with
    each body's modes eta_j as coordinates, -kappa w_j^T g + (lambda_j - s) eta_j = 0, and its R_0 + s R_1 on the
    g block; the forces g scaled by ``scale`` kappa [N/m] (default the largest stiffness entry). Returns (T_0,
    T_1, remainder), remainder(s) -> (the g-block terms of order s^2 and higher of T(s), their derivative), as
    full matrices."""
    nr, nc, na = len(coupled.rest), coupled.c_r.shape[0], coupled.n_attachments
    kap = float(scale or max(np.abs(coupled.k_aa).max(), np.abs(coupled.k_rr).max()))
    n_eta = [f.participation.shape[1] for f in flexibilities]
    n = nr + nc + 2 * na + sum(n_eta)
    t0, t1 = np.zeros((n, n)), np.zeros((n, n))
    r, lam, a = slice(0, nr), slice(nr, nr + nc), slice(nr + nc, nr + nc + na)
    g0 = nr + nc + na
    t0[r, r], t1[r, r] = coupled.k_rr, coupled.m_rr
    t0[r, lam], t0[lam, r] = coupled.c_r.T, coupled.c_r
    t0[r, a], t0[a, r] = coupled.k_ra, coupled.k_ra.T
    t0[lam, a], t0[a, lam] = coupled.c_a, coupled.c_a.T
    t0[a, a] = coupled.k_aa
    t0[a, g0:g0 + na], t0[g0:g0 + na, a] = -kap * np.eye(na), -kap * np.eye(na)
    e0 = g0 + na
    blocks = []
    for sl, f, ne in zip(coupled.slices, flexibilities, n_eta, strict=True):
        g = slice(g0 + sl.start, g0 + sl.stop)
        e = slice(e0, e0 + ne)
        t0[g, e], t0[e, g] = -kap * f.participation, -kap * f.participation.T
        t0[e, e], t1[e, e] = np.diag(f.eigenvalues), np.eye(ne)
        h0, _ = f.remainder(0.0)
        t0[g, g] -= kap ** 2 * h0
        if len(f.moments) > 1:
            t1[g, g] += kap ** 2 * f.moments[1]
        blocks.append((g, f))
        e0 += ne

    def remainder(s: float) -> tuple[np.ndarray, np.ndarray]:
        out, dout = np.zeros((n, n)), np.zeros((n, n))
        for g, f in blocks:
            h, dh = f.remainder(s, first=2)
            out[g, g], dout[g, g] = -kap ** 2 * h, -kap ** 2 * dh
        return out, dout

    return t0, t1, remainder


CLUSTER_RTOL = 1e-3
"""Roots of the linear pencil closer than this (relative, in s = omega^2) are refined together as one cluster: near-
equal roots (the five planets' local modes) share their subspace, and refining each alone can carry two of them to
the same root."""


def eigenvalues(t0: np.ndarray, t1: np.ndarray, remainder=None, s_max: float = np.inf, newton: int = 4,
                refine: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Roots s <= ``s_max`` of T(s) = T_0 - s T_1 + remainder(s) (ascending, s = omega^2 [1/s^2]): the linear
    pencil's real positive eigenvalues, then refined for the remainder cluster by cluster (roots within
    :data:`CLUSTER_RTOL`; a single root is a cluster of one). On the cluster's vectors X the remainder is linearised
    at the cluster's mean root s_c, h(s) ~ h(s_c) + (s - s_c) h'(s_c), and the projected pencil

        X^T (T_0 + h(s_c) - s_c h'(s_c)) X y = s X^T (T_1 - h'(s_c)) X y

    gives the cluster's roots (for one vector: Newton's step on its Rayleigh functional x^T T(s) x = 0; T symmetric,
    so the error is of second order in the vectors'), ``newton`` times; then ``refine`` times more after an
    inverse-iteration step X <- T(s_c)^-1 T'(s_c) X. Returns (s, x (n, modes) unit vectors)."""
    from scipy.linalg import eig

    sigma = 0.0 if not np.isfinite(s_max) else 0.5 * s_max
    # shift-inverted pencil: (T_0 - sigma T_1)^-1 T_1 x = mu x, s = sigma + 1 / mu
    mu, x = eig(np.linalg.solve(t0 - sigma * t1, t1))
    ok = np.abs(mu) > 1e-14 * np.abs(mu).max()
    s, x = sigma + 1.0 / mu[ok], x[:, ok]
    real = (np.abs(s.imag) <= 1e-8 * np.abs(s)) & (s.real > 0) & (s.real <= 1.05 * s_max)
    s, x = s[real].real, x[:, real].real
    order = np.argsort(s)
    s, x = s[order], x[:, order]
    if remainder is None:
        return s[s <= s_max], x[:, s <= s_max]
    starts = np.flatnonzero(np.concatenate([[True], s[1:] > s[:-1] * (1.0 + CLUSTER_RTOL)]))
    for cluster in np.split(np.arange(len(s)), starts[1:]):
        basis = np.linalg.qr(x[:, cluster])[0]  # orthonormal, spans the cluster's vectors
        for step in range(refine + 1):
            for _ in range(newton):
                s_c = float(np.mean(s[cluster]))
                h, dh = remainder(s_c)
                a, b = basis.T @ (t0 + h - s_c * dh) @ basis, basis.T @ (t1 - dh) @ basis
                roots, y = eig(0.5 * (a + a.T), 0.5 * (b + b.T))
                order = np.argsort(roots.real)
                s[cluster], y = roots.real[order], y[:, order].real
            ritz = basis @ y
            if step < refine:  # h, dh: the remainder at s_c, from the last Newton step
                try:
                    basis = np.linalg.qr(np.linalg.solve(t0 - s_c * t1 + h, (dh - t1) @ ritz))[0]
                except np.linalg.LinAlgError:  # T(s_c) singular in working precision: s_c is a root, keep them
                    pass
        x[:, cluster] = ritz / np.linalg.norm(ritz, axis=0)
    order = np.argsort(s)
    s, x = s[order], x[:, order]
    return s[s <= s_max], x[:, s <= s_max]


def body_fe_model(spec, name: str, reduced, level: str):
    """The full FE model (flexgear.fe.fem.FEModel) of flexible body ``name`` (flexgear.mbs: ``planet3``, ``ring``
    for the tied ring and output shaft, ``carrier``, ...), with the reduced body's node numbering (checked)."""
    from flexgear.fe.carrier import carrier_fe_model
    from flexgear.fe.reduced import is_tied
    from flexgear.fe.ring_shaft import pair_fe_models, part_fe_model, tied_pair
    from flexgear.spec import CARRIER, COMPONENT_GEOMETRY

    if is_tied(reduced):
        fe = tied_pair(*pair_fe_models(spec, level), spec).fe
    elif name == CARRIER:
        fe = carrier_fe_model(spec, level)
    else:
        geometry = "planet" if name.startswith("planet") else COMPONENT_GEOMETRY.get(name, name)
        fe = part_fe_model(spec, geometry, level)
    if fe.nodes.shape != reduced.nodes.shape or not np.allclose(fe.nodes, reduced.nodes, rtol=0, atol=1e-9):
        raise ValueError(f"{name}: the FE model's nodes are not the reduced body's")
    return fe


def full_flexibility(fe, weights: sp.spmatrix, s_max: float, frequencies_hz: np.ndarray, cut: float = 2.25,
                     tol: float = 1e-10, max_terms: int = 80, rigid: tuple[np.ndarray, ...] = ()) -> Flexibility:
    """The full FE model's H(s) at the attachments ``weights`` W (3n, n_a) for s <= ``s_max`` (module docstring):
    its lowest flexible free-free modes as coordinates (sparse shift-invert, flexgear.fe.cms), as many as reach
    lambda >= ``cut`` s_max, the others as the series R_k = W^T X_k, X_k = S M X_{k-1}, until s_max^k |R_k| <= ``tol``
    |R_0| (its ratio s_max / lambda_c <= 1 / ``cut``). ``frequencies_hz``: the reduced body's free-free
    frequencies (each above the full model's of the same order), to size the eigen solve. ``rigid``: node sets held
    as rigid patches as the reduction holds them (module docstring, flexgear.fe.patches.held_rigid_basis)."""
    from threadpoolctl import threadpool_limits

    from flexgear.fe.cms import FreeBodySolver

    with threadpool_limits(limits=1, user_api="blas"):
        if rigid:  # the patches held rigid: the problem on u = T u_t (module docstring)
            from types import SimpleNamespace

            from flexgear.fe.fem import rigid_body_modes
            from flexgear.fe.patches import held_rigid_basis

            t = held_rigid_basis(fe.nodes, rigid)
            kept = t[:, :t.shape[1] - 6 * len(rigid)].tocsc().indices  # the coordinates outside, in order
            r_t = np.vstack([rigid_body_modes(fe.nodes)[kept], *([np.eye(6)] * len(rigid))])
            m = (t.T @ fe.M @ t).tocsr()
            fe = SimpleNamespace(n_dof=t.shape[1], K=(t.T @ fe.K @ t).tocsr())
            weights = (t.T @ weights).tocsr()
            solver = FreeBodySolver(fe, rigid_modes=r_t)
        else:
            solver = FreeBodySolver(fe)
            m = fe.mass_operator()
        cons = solver.constrained((m @ solver.R).T)
        k = int(np.count_nonzero((2 * np.pi * np.asarray(frequencies_hz)) ** 2 < cut * s_max)) + 4
        while True:
            lam, phi = cons.eigen(fe, k, m)
            if lam[-1] >= cut * s_max or k >= fe.n_dof // 4:
                break
            k += max(4, k // 2)
        phi = phi / np.sqrt(np.einsum("ij,ij->j", phi, m @ phi))  # mass-normalised
        w = np.asarray(weights.todense())
        part = phi.T @ w  # (p, n_a)
        x = cons.solve(w) - phi @ (part / lam[:, None])
        moments = []
        for _ in range(max_terms):
            r = w.T @ x
            moments.append(0.5 * (r + r.T))
            if s_max ** (len(moments) - 1) * np.abs(moments[-1]).max() <= tol * np.abs(moments[0]).max():
                break
            x = cons.solve(np.asarray(m @ x))
            x -= phi @ (phi.T @ (m @ x))  # the computed modes' part is round-off: removed
    return Flexibility(part.T, lam, moments)
