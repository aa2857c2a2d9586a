"""Linear floating-frame formulation of a spinning flexible body (the production formulation).

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
same node, or its linear form (flexgear.mbs.bodies.add_linear_frame, production).
Left out (second order): the inertia tensor's change with q, the terms in the tilt rates and in
the angular acceleration. One ``ObjectGenericODE2`` per body carries M, K(Omega), D(Omega) (constant
Jacobian); :class:`SpinSchedule` moves K and D with the ramp and writes the centrifugal load.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexgear.laws.compiled import bound_entry, ramp_state
from flexgear.mbs.bodies import matrix_container, zero_user_jacobian
from flexgear.mbs.deflection import centrifugal_modal_load

__all__ = ["SpinMatrices", "spin_matrices", "transformed", "add_linear_modal_equations", "SpinSchedule"]


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


def transformed(spin: SpinMatrices, basis: np.ndarray) -> SpinMatrices:
    """The spin terms in coordinates q~ with q = ``basis`` q~ (T^T G T, T^T S T, T^T c)."""
    t = basis
    return SpinMatrices(t.T @ spin.gyroscopic @ t, t.T @ spin.softening @ t, t.T @ spin.centrifugal)


def spin_terms(stiffness: np.ndarray, damping: np.ndarray, spin: SpinMatrices, spin_rad_s: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """K = ``stiffness`` - Omega^2 S and D = ``damping`` + 2 Omega G (m, m) at the spin Omega [rad/s]."""
    w = float(spin_rad_s)
    return stiffness - w * w * spin.softening, damping + 2.0 * w * spin.gyroscopic


def dense_modal_matrices(matrices: tuple, spin: SpinMatrices) -> bool:
    """Whether a body's K(Omega) and D(Omega) (:func:`spin_terms`) fill more than half of their entries: Exudyn then
    gets them as dense matrices (the same format for the whole run, :class:`SpinSchedule`)."""
    k, d = spin_terms(*matrices[1:], spin, 1.0)
    return bool(np.count_nonzero(k) + np.count_nonzero(d) > k.size)


def add_linear_modal_equations(mbs, name: str, modal_nodes: tuple[int, ...], matrices: tuple, spin: SpinMatrices,
                               spin_rad_s: float) -> int:
    """The modal equations as one ``ObjectGenericODE2`` on ``modal_nodes``: ``matrices`` (M, K, D) at rest (M = I,
    K = Lambda, D diagonal in modal coordinates) with :func:`spin_terms` at ``spin_rad_s`` [rad/s]
    (:class:`SpinSchedule` moves them with the ramp and adds the centrifugal load). Returns the object."""
    from exudyn.itemInterface import ObjectGenericODE2

    mass, stiffness, damping = matrices
    k, d = spin_terms(stiffness, damping, spin, spin_rad_s)
    dense = dense_modal_matrices(matrices, spin)
    return mbs.AddObject(ObjectGenericODE2(name=f"{name}_modal_equations", nodeNumbers=list(modal_nodes),
                                           massMatrix=matrix_container(mass),
                                           stiffnessMatrix=matrix_container(k, dense),
                                           dampingMatrix=matrix_container(d, dense),
                                           jacobianUserFunction=zero_user_jacobian(len(mass), dense)))


class SpinSchedule:
    """Pre-step function: the linear bodies' spin terms at the prescribed speed Omega(t) = Omega_n STEP(t, 0, 0,
    T, 1) (T = ``ramp_time`` [s]).

    The centrifugal load Omega(t)^2 c, on one massless ``ObjectGenericODE2`` over the modal nodes, every step;
    the matrices K(Omega), D(Omega) (:func:`spin_terms`) of each body's modal equations every
    ``update_interval`` [s] of the ramp, at the step's speed, and once at its end (exact from then on). During
    the ramp the speed in the matrices lags by at most Omega_n max|STEP'| ``update_interval`` = 1.5 Omega_n
    ``update_interval`` / T.
    """

    def __init__(self, mbs, bodies: list, ramp_time: float, update_interval: float, frames: list = ()):
        """``bodies``: flexible bodies of the production formulation (flexgear.mbs.flexible.FlexibleBody:
        ``modal_nodes``, ``modal_equations``, ``spin``, ``nominal_spin_rad_s``, ``reduced``, ``modal_matrices``);
        ``frames``: linear body frames (flexgear.mbs.bodies.LinearFrame), whose gyroscopic term moves likewise."""
        from exudyn.itemInterface import ObjectGenericODE2

        self.ramp_time, self.interval = float(ramp_time), float(update_interval)
        self.bodies, self.frames = bodies, list(frames)
        n = sum(b.reduced.n_modes for b in bodies)
        nodes = [node for b in bodies for node in b.modal_nodes]
        self.obj = -1 if not bodies else mbs.AddObject(ObjectGenericODE2(
            name="spin_schedule", nodeNumbers=nodes, forceVector=np.zeros(n),
            jacobianUserFunction=zero_user_jacobian(n)))
        self.cent = np.array([b.nominal_spin_rad_s ** 2 * c for b in bodies for c in b.spin.centrifugal])  # Omega_n^2 c
        self._dense = [dense_modal_matrices(b.modal_matrices, b.spin) for b in bodies]  # each body's format
        self._next = 0.0  # time of the next matrix update
        self._steady = False
        self._force = np.empty_like(self.cent)  # the step's load, written in place (Exudyn copies it)
        self._ramp = None  # ramp_state's compiled entry (first call)
        self._work = [(np.empty(b.spin.softening.shape), np.empty(b.spin.gyroscopic.shape)) for b in bodies]

    @property
    def finished(self) -> bool:
        """True once the ramp is over: nothing is left to do (flexgear.mbs.contact_kinematics.PreStepChain drops it)."""
        return self._steady

    def force(self, t: float) -> np.ndarray:
        """Omega(t)^2 c, stacked over the bodies."""
        return ramp_state(float(t), self.ramp_time)[1] ** 2 * self.cent

    def matrices(self, t: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """(K, D) of every body at the speed of time t."""
        r = ramp_state(float(t), self.ramp_time)[1]
        return [spin_terms(*b.modal_matrices[1:], b.spin, r * b.nominal_spin_rad_s) for b in self.bodies]

    def __call__(self, mbs, t: float) -> bool:
        if self._steady:
            return True
        if self.bodies:  # the numbers of :meth:`force`, without temporaries
            ramp = self._ramp
            if ramp is None:
                ramp = self._ramp = bound_entry(ramp_state, (float(t), self.ramp_time))
            np.multiply(ramp(t, self.ramp_time)[1] ** 2, self.cent, out=self._force)
            mbs.SetObjectParameter(self.obj, "forceVector", self._force)
        last = t >= self.ramp_time
        if t >= self._next or last:
            r = ramp_state(float(t), self.ramp_time)[1]
            for b, (k, d), dense in zip(self.bodies, self._work, self._dense, strict=True):
                # :func:`spin_terms` at r Omega_n into the work arrays; a dense body's arrays go to Exudyn as they are
                # (it stores an array as a dense matrix), a sparse body's as triplets
                w = float(r * b.nominal_spin_rad_s)
                np.subtract(b.modal_matrices[1], np.multiply(w * w, b.spin.softening, out=k), out=k)
                np.add(b.modal_matrices[2], np.multiply(2.0 * w, b.spin.gyroscopic, out=d), out=d)
                mbs.SetObjectParameter(b.modal_equations, "stiffnessMatrix", k if dense else matrix_container(k))
                mbs.SetObjectParameter(b.modal_equations, "dampingMatrix", d if dense else matrix_container(d))
            for f in self.frames:
                mbs.SetObjectParameter(f.obj, "dampingMatrix", matrix_container(f.gyroscopic(r * f.spin_rad_s)))
            self._next = t + self.interval
        self._steady = last
        return True
