"""Linear floating-frame formulation of a spinning flexible body (``[reduction_assumed] floating_frame = "linear"``).

Exudyn's ``ObjectFFRFreducedOrder`` with its floating-frame terms evaluates the full nonlinear coupling of
frame and modes (mass matrix (6 + m)^2 and quadratic velocity vector every step; its Jacobian by numerical
differentiation, ~ (6 + m)^3). A gear or shaft of the star gearbox spins about its own z axis at a
prescribed speed with small tilts and small elastic coordinates q, and its modes are mean-axis modes
(M-orthogonal to the rigid modes: the invariants ``mPhitTPsi`` and ``mXRefTildePsi`` vanish, < 1e-11 of
the others). Kept to first order in q and in the frame's deviation from the nominal spin, the modal
equations of the floating frame (Shabana, *Dynamics of Multibody Systems*, ch. 5; the same invariants
Exudyn uses) are

    q'' + (D + 2 Omega G) q' + (Lambda - Omega^2 S) q = Psi^T f + Omega^2 c        (M = I)

    G_jl = psi_j^T M e_z~ psi_l        (skew: Coriolis, gyroscopic)     = mPsiTildePsi[3j + 2, l]
    S_jl = (e_z x psi_j)^T M (e_z x psi_l)  (spin softening)           = mPsiTildePsiTilde[3j + 2, 3l + 2]
    c_j  = (e_z x psi_j)^T M (e_z x x_ref)  (centrifugal load)         = mXRefTildePsiTilde[2, 3j + 2]

with Omega(t) the body's prescribed spin (the drive's STEP ramp times the body's nominal speed,
flexgear.theory). The frame itself is an ``ObjectRigidBody`` with the body's exact mass properties on the
same node; the superelement markers still place every interface and contact by frame motion plus
modes. Left out (second order): the inertia tensor's change with q, the terms in the tilt rates and in
the angular acceleration. At the nominal spin the matrices above are constant: one ``ObjectGenericODE2``
per body carries them (analytic Jacobian); during the ramp one shared force vector adds the difference
to the scheduled spin (:class:`SpinSchedule`), written once when the ramp ends.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexgear.laws.ramps import ramp_fraction
from flexgear.mbs.bodies import matrix_container, zero_user_jacobian
from flexgear.mbs.deflection import centrifugal_modal_load

__all__ = ["SpinMatrices", "spin_matrices", "add_linear_modal_equations", "SpinSchedule"]


@dataclass(frozen=True)
class SpinMatrices:
    """Per-(rad/s) and per-(rad/s)^2 terms of a body spinning about its z axis (module docstring)."""

    gyroscopic: np.ndarray  # G (m, m), skew [-]
    softening: np.ndarray  # S (m, m), symmetric [-]
    centrifugal: np.ndarray  # c (m,) [modal force per (rad/s)^2]


def spin_matrices(reduced) -> SpinMatrices:
    """G, S and c of the module docstring from a reduced body's (flexgear.fe.cms.ReducedBody) invariants."""
    inv = reduced.invariants
    m = inv["mPsiTildePsi"].shape[1]
    z = 3 * np.arange(m) + 2
    g = inv["mPsiTildePsi"][z, :]
    s = inv["mPsiTildePsiTilde"][np.ix_(z, z)]
    return SpinMatrices(0.5 * (g - g.T), 0.5 * (s + s.T), centrifugal_modal_load(reduced))


def add_linear_modal_equations(mbs, name: str, modal_node: int, stiffness: np.ndarray, damping: np.ndarray,
                               spin: SpinMatrices, nominal_spin_rad_s: float) -> int:
    """The modal equations at the nominal spin as one ``ObjectGenericODE2`` on ``modal_node``.

    M = I, K = diag(``stiffness``) - Omega_n^2 S, D = ``damping`` (diagonal) + 2 Omega_n G, with Omega_n =
    ``nominal_spin_rad_s`` [rad/s]; the centrifugal load and the ramp's difference come from
    :class:`SpinSchedule`. Returns the object.
    """
    from exudyn.itemInterface import ObjectGenericODE2

    w = float(nominal_spin_rad_s)
    m = len(stiffness)
    k = np.diag(stiffness) - w * w * spin.softening
    d = np.diag(np.broadcast_to(damping, (m,))) + 2.0 * w * spin.gyroscopic
    return mbs.AddObject(ObjectGenericODE2(name=f"{name}_modal_equations", nodeNumbers=[modal_node],
                                           massMatrix=matrix_container(np.eye(m)),
                                           stiffnessMatrix=matrix_container(k), dampingMatrix=matrix_container(d),
                                           jacobianUserFunction=zero_user_jacobian(m)))


class SpinSchedule:
    """Pre-step function: the centrifugal load and the spin terms' difference to the nominal spin.

    One massless ``ObjectGenericODE2`` over the linear bodies' modal nodes carries the force vector

        f = Omega(t)^2 c - 2 (Omega(t) - Omega_n) G q' + (Omega(t)^2 - Omega_n^2) S q

    (Omega(t) = Omega_n STEP(t, 0, 0, T, 1), the prescribed speed ramp; q, q' at the step's start: explicit,
    and zero once the ramp is over, when f = Omega_n^2 c is written once).
    """

    def __init__(self, mbs, bodies: list[tuple[int, SpinMatrices, float]], ramp_time: float):
        """``bodies``: (modal node, its :class:`SpinMatrices`, nominal spin [rad/s]) per linear body."""
        from exudyn.itemInterface import ObjectGenericODE2

        self.ramp_time = float(ramp_time)
        nodes = [b[0] for b in bodies]
        sizes = [len(b[1].centrifugal) for b in bodies]
        self.obj = mbs.AddObject(ObjectGenericODE2(name="spin_schedule", nodeNumbers=nodes,
                                                   forceVector=np.zeros(sum(sizes)),
                                                   jacobianUserFunction=zero_user_jacobian(sum(sizes))))
        self._nodes = nodes
        self._index: np.ndarray | None = None  # global ODE2 indices of the modal coordinates (after Assemble)
        n = sum(sizes)
        self.gyro, self.soft = np.zeros((n, n)), np.zeros((n, n))
        self.cent, self.nominal = np.zeros(n), np.zeros(n)
        start = 0
        for (_, s, w), size in zip(bodies, sizes, strict=True):
            sl = slice(start, start + size)
            self.gyro[sl, sl], self.soft[sl, sl] = s.gyroscopic, s.softening
            self.cent[sl], self.nominal[sl] = s.centrifugal, w
            start += size
        self._steady = False

    def force(self, t: float, q: np.ndarray, q_t: np.ndarray) -> np.ndarray:
        """f(t) of the class docstring for modal coordinates ``q`` and velocities ``q_t``."""
        r = float(ramp_fraction(float(t), self.ramp_time))
        w = r * self.nominal
        f = w * w * self.cent
        if r < 1.0:
            f -= 2.0 * self.gyro @ ((w - self.nominal) * q_t)
            f += self.soft @ ((w * w - self.nominal ** 2) * q)
        return f

    def __call__(self, mbs, t: float) -> bool:
        if self._steady:
            return True
        if self._index is None:
            self._index = np.concatenate([
                mbs.GetNodeODE2Index(n) + np.arange(mbs.GetNode(n)["numberOfODE2Coordinates"]) for n in self._nodes])
        data = mbs.systemData
        q = np.asarray(data.GetODE2Coordinates())[self._index]
        q_t = np.asarray(data.GetODE2Coordinates_t())[self._index]
        mbs.SetObjectParameter(self.obj, "forceVector", self.force(t, q, q_t))
        self._steady = t > self.ramp_time
        return True
