"""Reduced flexible bodies joined by fixed joints: the assembly's free-free modes as one linear modal problem.

Each reduced body (flexgear.fe.cms.ReducedBody, frame at the gearbox origin) has the coordinates
z = (a, q): a rigid motion a = (translation at the frame origin, rotation) and its flexible free-free modal
coordinates q. Its node displacements are u_i = a_t + a_theta x x_i + Psi_i q, so that

    M_b = [[m I, -m [c]x, C_t], [m [c]x, J_o, C_r], [C_t^T, C_r^T, I]],   K_b = diag(0, 0, omega^2),     (1)

with mass m, centre of mass c, inertia J_o about the origin and the couplings C_t = sum_ik M_ik Psi_k
(``mPhitTPsi``), C_r = sum_ik M_ik x_i x Psi_k (= -``mXRefTildePsi``), both zero for mean axes. A fixed joint
at point p between interfaces i (body b) and j (body e) equates the rigid motions the two RBE3 interfaces
carry to p (flexgear.mbs.flexible.interface_point_modes, the motion of the multibody model's markers):

    u_p = a_t + a_theta x p + t_i q + theta_i q x (p - p_i),   theta = a_theta + theta_i q,             (2)

(t_i, theta_i) = ``interface_motion``. With the joint rows G z = 0 and a basis N of their null space, the
assembly's modes solve (N^T K N) y = omega^2 (N^T M N) y; the six rigid-body modes (omega = 0) are dropped.
This is the same joint the multibody model (flexgear.mbs.elements.add_interface_joint) imposes, without
time integration.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as la

from flexgear.fe.cms import ReducedBody

__all__ = ["body_matrices", "joint_rows", "joined_free_modes"]


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def body_matrices(body: ReducedBody) -> tuple[np.ndarray, np.ndarray]:
    """Mass and stiffness (6 + m, 6 + m) of eq. (1) [kg, kg m, kg m^2; N/m ...] from the body's invariants."""
    inv = body.invariants
    m, n = float(inv["mass"]), body.n_modes
    c = np.asarray(inv["centerOfMass"], float)
    mass = np.zeros((6 + n, 6 + n))
    mass[:3, :3] = m * np.eye(3)
    mass[:3, 3:6] = -m * _skew(c)
    mass[3:6, :3] = m * _skew(c)
    mass[3:6, 3:6] = inv["inertia"]
    mass[:3, 6:] = inv["mPhitTPsi"]
    mass[3:6, 6:] = -np.asarray(inv["mXRefTildePsi"])
    mass[6:, :6] = mass[:6, 6:].T
    mass[6:, 6:] = np.eye(n)
    stiffness = np.zeros_like(mass)
    stiffness[6:, 6:] = np.diag(body.stiffness)
    return mass, stiffness


def joint_rows(body: ReducedBody, interface: str, point) -> np.ndarray:
    """Rows (6, 6 + m) of eq. (2): translation [m] at ``point`` [m] and rotation [rad] of ``interface``."""
    p = np.asarray(point, float)
    itf = body.interface(interface)
    motion = body.interface_motion(interface)
    rows = np.zeros((6, 6 + body.n_modes))
    rows[:3, :3] = np.eye(3)
    rows[:3, 3:6] = -_skew(p)
    rows[3:6, 3:6] = np.eye(3)
    rows[:3, 6:] = motion[:3] - _skew(p - itf.point) @ motion[3:]
    rows[3:6, 6:] = motion[3:]
    return rows


def joined_free_modes(bodies: list[ReducedBody], joints: list[tuple[int, str, int, str, np.ndarray]],
                      k: int = 10) -> np.ndarray:
    """Lowest ``k`` elastic free-free frequencies [Hz] of ``bodies`` joined by ``joints``.

    ``joints``: (body index, interface, other body index, its interface, joint point [m]) each, a fixed joint
    of eq. (2). RuntimeError if the joined assembly has not exactly six rigid-body modes.
    """
    mats = [body_matrices(b) for b in bodies]
    sizes = [len(m) for m, _ in mats]
    start = np.concatenate([[0], np.cumsum(sizes)])
    mass = la.block_diag(*[m for m, _ in mats])
    stiffness = la.block_diag(*[s for _, s in mats])
    g = np.zeros((6 * len(joints), start[-1]))
    for j, (b0, i0, b1, i1, point) in enumerate(joints):
        g[6 * j:6 * j + 6, start[b0]:start[b0 + 1]] += joint_rows(bodies[b0], i0, point)
        g[6 * j:6 * j + 6, start[b1]:start[b1 + 1]] -= joint_rows(bodies[b1], i1, point)
    basis = la.null_space(g)
    lam = la.eigh(basis.T @ stiffness @ basis, basis.T @ mass @ basis, eigvals_only=True)
    if lam[6] < 1e-8 * lam[-1] or np.any(np.abs(lam[:6]) > 1e-6 * lam[6]):
        raise RuntimeError(f"joined assembly: expected six rigid-body modes, eigenvalues start {lam[:8]}")
    return np.sqrt(np.maximum(lam[6:6 + k], 0.0)) / (2 * math.pi)
