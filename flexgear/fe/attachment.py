"""Attachment (static-correction) modes: Fourier load patterns on a circle of a body and the smooth contact kernel.

A gear contact senses the elastic deflection of a flexible gear through a smooth kernel: the tooth-normal
displacement of the mesh nodes in a band around the contact circle (radius r, axial range [z_min, z_max],
radial band |rho - r| <= b) is fitted by a Fourier series of order N in the material angle alpha,

    s(alpha) = sum_i w_i(alpha) d(alpha_i) . u_i,   w(alpha) = B (B^T B)^-1 b(alpha),          (1)

with B (k, 2N+1) the basis [1, cos h alpha_i, sin h alpha_i] at the k band nodes, b(alpha) the same row at
alpha, and d(alpha) = d_r e_r(alpha) + d_t e_t(alpha) + d_z e_z a direction constant in the local radial,
tangential and axial frame (the tooth normal carried round with the material). By virtue of work the
force F of the contact loads the body with the kernel load f(alpha) = F w_i(alpha) d(alpha_i) at the band
nodes: every kernel load at every angle is a combination of the 2N + 1 load patterns

    P_j = B[:, j] d(alpha_i)  at the band nodes,  j = 0..2N.                                  (2)

Their static responses with the body's interfaces held (RBE3, flexgear.fe.cms) are the attachment modes: a
reduction basis that holds them reproduces the full FE model's compliance under every kernel load of
order <= N exactly (Ritz). :func:`modal_basis` mass-orthonormalises the whole basis (dropping numerically
dependent directions) and solves the reduced eigenproblem, so the flexible coordinates stay free-free
modes (M-orthonormal, K diagonal) however large the basis is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla

__all__ = ["LoadCircle", "fourier_basis", "circle_band", "local_directions", "load_patterns", "kernel_load",
           "modal_basis"]

_ON_CYLINDER_M = 1e-6  # default radial band: nodes on the circle's own cylinder (exact OCC geometry)
_Z_TOL_M = 1e-9  # nodes on the faces that bound the axial range belong to it
_GROW, _GROW_STEPS = 1.5, 8  # band widening when too few nodes for the fit


@dataclass(frozen=True)
class LoadCircle:
    """A circle of contact loads on a body (body frame, z the axis): the Fourier load patterns of eq. (2).

    ``radius_m`` and the axial range [``z_min_m``, ``z_max_m``] [m] place the band of mesh nodes; ``order``
    N the highest harmonic (2N + 1 patterns); ``direction`` (radial, tangential, axial) the load
    direction, constant in the local frame round the circle (radial by default, the tooth normal for a
    gear); ``radial_band_m`` the band's radial half-width (default: nodes on the cylinder r = radius_m;
    the gear contact uses about one normal module). The band widens by factors of 1.5 until it holds
    4 (2N + 1) nodes, as the contact kernel's does.
    """

    radius_m: float
    z_min_m: float
    z_max_m: float
    order: int
    direction: tuple[float, float, float] = (1.0, 0.0, 0.0)
    radial_band_m: float | None = None

    def __post_init__(self):
        if not self.radius_m > 0.0:
            raise ValueError(f"LoadCircle: radius_m must be > 0, got {self.radius_m!r}")
        if not self.z_max_m >= self.z_min_m:
            raise ValueError(f"LoadCircle: z_max_m must be >= z_min_m, got [{self.z_min_m}, {self.z_max_m}]")
        if int(self.order) != self.order or self.order < 0:
            raise ValueError(f"LoadCircle: order must be an integer >= 0, got {self.order!r}")
        d = np.asarray(self.direction, float)
        if d.shape != (3,) or not np.linalg.norm(d) > 0.0:
            raise ValueError(f"LoadCircle: direction must be 3 numbers (radial, tangential, axial), not all "
                             f"zero; got {self.direction!r}")
        object.__setattr__(self, "direction", tuple(float(v) for v in d / np.linalg.norm(d)))
        if self.radial_band_m is not None and not self.radial_band_m > 0.0:
            raise ValueError(f"LoadCircle: radial_band_m must be > 0 or None, got {self.radial_band_m!r}")

    @property
    def n_patterns(self) -> int:
        return 2 * self.order + 1

    def key(self) -> tuple:
        """Plain tuple of the fields (for cache hashes)."""
        return (self.radius_m, self.z_min_m, self.z_max_m, self.order, self.direction, self.radial_band_m)


def fourier_basis(alpha: np.ndarray, order: int) -> np.ndarray:
    """Rows [1, cos alpha, sin alpha, ..., cos N alpha, sin N alpha] (k, 2N + 1) at angles ``alpha`` [rad]."""
    alpha = np.asarray(alpha, float)
    cols = [np.ones_like(alpha)]
    for h in range(1, order + 1):
        cols += [np.cos(h * alpha), np.sin(h * alpha)]
    return np.stack(cols, axis=-1)


def circle_band(nodes: np.ndarray, circle: LoadCircle, fit_order: int | None = None) -> np.ndarray:
    """Indices of the nodes in the circle's band: |rho - r| <= band, z in [z_min, z_max].

    The band starts at ``circle.radial_band_m`` and widens until it holds 4 (2 N + 1) nodes for a fit of
    order N = ``fit_order`` (default the circle's order); ValueError if it never does.
    """
    order = circle.order if fit_order is None else fit_order
    rho = np.hypot(nodes[:, 0], nodes[:, 1])
    in_z = (nodes[:, 2] >= circle.z_min_m - _Z_TOL_M) & (nodes[:, 2] <= circle.z_max_m + _Z_TOL_M)
    band = _ON_CYLINDER_M if circle.radial_band_m is None else circle.radial_band_m
    need = 4 * (2 * order + 1)
    for _ in range(_GROW_STEPS):
        sel = np.flatnonzero((np.abs(rho - circle.radius_m) <= band) & in_z)
        if len(sel) >= need:
            return sel
        band *= _GROW
    raise ValueError(f"only {len(sel)} mesh nodes near the circle r = {circle.radius_m:.4f} m, "
                     f"z = [{circle.z_min_m:.4f}, {circle.z_max_m:.4f}] m: too few for a Fourier fit of order {order}")


def local_directions(alpha: np.ndarray, direction) -> np.ndarray:
    """d(alpha) = d_r e_r + d_t e_t + d_z e_z (k, 3) for (radial, tangential, axial) ``direction``."""
    dr, dt, dz = (float(v) for v in direction)
    c, s = np.cos(alpha), np.sin(alpha)
    return np.stack([dr * c - dt * s, dr * s + dt * c, np.full_like(alpha, dz)], axis=1)


def _spread(n_nodes: int, sel: np.ndarray, weights: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Load vectors (3n, p): weights (k, p) times directions (k, 3) at nodes ``sel``."""
    out = np.zeros((n_nodes, 3, weights.shape[1]))
    out[sel] = dirs[:, :, None] * weights[:, None, :]
    return out.reshape(3 * n_nodes, -1)


def load_patterns(nodes: np.ndarray, circle: LoadCircle) -> np.ndarray:
    """The 2N + 1 load patterns P_j of eq. (2), (3n, 2N + 1) [N per unit coefficient]."""
    sel = circle_band(nodes, circle)
    alpha = np.arctan2(nodes[sel, 1], nodes[sel, 0])
    return _spread(len(nodes), sel, fourier_basis(alpha, circle.order), local_directions(alpha, circle.direction))


def kernel_load(nodes: np.ndarray, circle: LoadCircle, angle: float, direction=None) -> np.ndarray:
    """Kernel load (3n,) of a unit contact force at material angle ``angle`` [rad], eq. (1).

    ``direction`` (global, at ``angle``; default the circle's local direction there) is carried round
    the circle with the material. The force's work on a displacement u is the kernel's reading of u.
    """
    sel = circle_band(nodes, circle)
    alpha = np.arctan2(nodes[sel, 1], nodes[sel, 0])
    b = fourier_basis(alpha, circle.order)
    w = b @ np.linalg.lstsq(b.T @ b, fourier_basis(np.array([angle]), circle.order)[0], rcond=None)[0]
    if direction is None:
        local = np.asarray(circle.direction)
    else:
        d = np.asarray(direction, float)
        c, s = math.cos(angle), math.sin(angle)
        local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]])
    return _spread(len(nodes), sel, w[:, None], local_directions(alpha, local))[:, 0]


def modal_basis(basis: np.ndarray, stiffness: sp.spmatrix, mass: sp.spmatrix | sla.LinearOperator,
                rel_tol: float = 1e-10, n_rigid: int = 6) -> tuple[np.ndarray, np.ndarray, int]:
    """Free-free modes spanned by ``basis`` (3n, p): mass-orthonormalise, then the reduced eigenproblem.

    ``mass``: M [kg], a matrix or an operator (flexgear.fe.fem.FEModel.mass_operator).

    Columns are scaled to unit mass norm; the eigenvectors of T^T M T with eigenvalue below
    ``rel_tol`` times the largest are numerically dependent directions and dropped (one Cholesky pass
    restores Q^T M Q = I to round-off); in the M-orthonormal basis Q the eigenproblem
    (Q^T K Q) y = omega^2 y gives modes Q y. The ``n_rigid`` lowest (the rigid-body modes the basis
    holds exactly) are checked to be zero and dropped. Returns (modes (3n, m), omega^2 (m,) [1/s^2],
    number of dropped directions).
    """
    scale = 1.0 / np.sqrt(np.einsum("ij,ij->j", basis, mass @ basis))
    t = basis * scale
    m_red = t.T @ (mass @ t)
    w, v = la.eigh((m_red + m_red.T) / 2)
    keep = w > rel_tol * w.max()
    q = t @ (v[:, keep] / np.sqrt(w[keep]))
    q = q @ la.inv(la.cholesky(q.T @ (mass @ q)))  # one more pass: M-orthonormal to round-off
    k_red = q.T @ (stiffness @ q)
    lam, y = la.eigh((k_red + k_red.T) / 2)
    if lam[n_rigid] < 1e-8 * abs(lam[-1]) or np.any(np.abs(lam[:n_rigid]) > 1e-6 * lam[n_rigid]):
        raise RuntimeError(f"expected exactly {n_rigid} rigid-body modes, eigenvalues start {lam[:n_rigid + 2]}")
    return q @ y[:, n_rigid:], lam[n_rigid:], int((~keep).sum())
