"""Connectors: bushings, gear contacts, speed drive and load torque, on body frame coordinates.

Element contract (as ROSS's): every linear element (bushing) gives a 6x6 stiffness and damping
matrix on the frame coordinates (u_x, u_y, u_z, phi_x, phi_y, phi_z) of one body; all of them are
summed into one ``ObjectGenericODE2`` over the frame nodes. A gear contact gives the gradient of
its mesh deflection with respect to the frame coordinates of both gears (the linearised mesh
kinematics) and a scalar contact law.

Gear contact (section 2.1 of the study, ADAMS impact function, per helix half h):

    delta_h  = g1 . q1 + g2 . q2                           (mesh deflection along the tooth normal)
    F_h      = max(0, k_h s(phi) <delta_h>^e + c_max,h STEP(delta_h, 0, 0, d, 1) d(delta_h)/dt)
    friction = mu F_h tanh(Omega lambda_mean / v_reg) (kappa(phi), lambda(phi))  on (sliding, relative spin)

with k_h, c_max,h the study's stiffness and damping scaled by the half's share of the face width,
s(phi) = 1 + sum_n c_n cos(2 pi n (phi - phi_0)) the mesh-stiffness variation of eq. 11-12
(phi: mesh phase in cycles, from the prescribed drive), and F_h = 0 when the teeth separate.
Deflection, pitch-point sliding and relative spin are three auxiliary coordinates per half, tied
to the gear coordinates by one linear ``ObjectConnectorCoordinateVector`` constraint; the law is a
compiled (symbolic) user function of an ``ObjectConnectorCartesianSpringDamper`` on them: no
Python runs per step. Friction (kappa, lambda: see flexgear.involute.contact_line_distribution)
follows from the contact lines' positions relative to the pitch point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from flexgear.bodies import Body
from flexgear.involute import PeriodicSeries
from flexgear.spec import Bearing, Contact

__all__ = [
    "Bushing",
    "ContactLaw",
    "GearContact",
    "impact_force",
    "periodic_value",
    "friction_forces",
    "drive_angle",
    "relative_displacement_gradient",
    "contact_gradients",
    "MeshFriction",
    "StiffnessSchedule",
    "add_linear_elements",
    "MeshConstraint",
    "add_gear_contacts",
    "add_speed_drive",
    "add_load_torque",
    "add_fixed_joint",
    "add_interface_joint",
]


# --------------------------------------------------------------------------- linear elements
@dataclass(frozen=True)
class Bushing:
    """A bearing as a 6-DOF linear spring-damper from a body frame to ground (spin left free).

    Stiffness diag(k_r, k_r, k_a, k_t, k_t, 0) on (u_x, u_y, u_z, phi_x, phi_y, phi_z) [N/m, N·m/rad];
    damping c = k * damping_per_stiffness [s] (stiffness-proportional).
    """

    body: str
    radial_stiffness: float
    axial_stiffness: float
    tilt_stiffness: float
    damping_per_stiffness: float

    @classmethod
    def from_bearing(cls, body: str, bearing: Bearing) -> Bushing:
        """Bushing of a Table 2 bearing."""
        return cls(body, bearing.radial_stiffness_n_per_m, bearing.axial_stiffness_n_per_m,
                   bearing.tilt_stiffness_nm_per_rad, bearing.damping_per_stiffness_s)

    def stiffness_matrix(self) -> np.ndarray:
        k = [self.radial_stiffness, self.radial_stiffness, self.axial_stiffness,
             self.tilt_stiffness, self.tilt_stiffness, 0.0]
        return np.diag(k)

    def damping_matrix(self) -> np.ndarray:
        return self.damping_per_stiffness * self.stiffness_matrix()


def add_linear_elements(mbs, bodies: list[Body], elements: list[Bushing], extra_nodes: list[int] | None = None,
                        extra_size: int = 0) -> tuple[int, int]:
    """Sum the elements' matrices into one ``ObjectGenericODE2`` over the bodies' frame nodes.

    ``extra_nodes`` (e.g. the modal nodes of flexible bodies, ``extra_size`` coordinates in all) are
    appended to the object with zero matrices so that its marker spans them too.
    Returns ``(object, marker)``: the marker (``MarkerObjectODE2Coordinates``) spans all frame
    coordinates in the order of ``bodies``, then the extra ones, and is reused by the gear contacts.
    """
    from exudyn.itemInterface import MarkerObjectODE2Coordinates, ObjectGenericODE2

    index = {b.name: i for i, b in enumerate(bodies)}
    n = 6 * len(bodies) + extra_size
    stiffness, damping = np.zeros((n, n)), np.zeros((n, n))
    for e in elements:
        if e.body not in index:
            raise KeyError(f"bushing on unknown body {e.body!r}; bodies: {sorted(index)}")
        s = slice(6 * index[e.body], 6 * index[e.body] + 6)
        stiffness[s, s] += e.stiffness_matrix()
        damping[s, s] += e.damping_matrix()
    obj = mbs.AddObject(ObjectGenericODE2(
        name="frame_elements", nodeNumbers=[b.node for b in bodies] + list(extra_nodes or []),
        massMatrix=np.zeros((n, n)), stiffnessMatrix=stiffness, dampingMatrix=damping, forceVector=np.zeros(n),
    ))
    marker = mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=obj))
    return obj, marker


# --------------------------------------------------------------------------- contact laws
@dataclass(frozen=True)
class ContactLaw:
    """Impact-function parameters of one contact half (section 2.1)."""

    stiffness: float  # N/m^exponent
    exponent: float
    damping_max: float  # N s/m, reached at the penetration depth
    penetration_depth: float  # m

    @classmethod
    def from_contact(cls, contact: Contact, share: float = 1.0) -> ContactLaw:
        """The study's law scaled to a ``share`` of the face width (one helix half: 0.5)."""
        k = contact.stiffness * share
        return cls(k, contact.exponent, contact.damping_fraction_of_stiffness * k, contact.penetration_depth_m)


def impact_force(delta: Any, delta_t: Any, law: ContactLaw, factor: Any = 1.0, m: Any = np) -> Any:
    """Normal force of the impact law [N]; ``m`` is numpy or ``exudyn.symbolic``.

    F = max(0, k s <delta>^e + c_max STEP(delta, 0, 0, d, 1) delta_t), zero for delta <= 0.
    """
    mx = m.maximum if m is np else m.max
    mn = m.minimum if m is np else m.min
    pen = mx(delta, 0.0)
    ramp = mn(pen / law.penetration_depth, 1.0)
    damp = law.damping_max * ramp * ramp * (3.0 - 2.0 * ramp)
    if m is np:
        power = pen**law.exponent
    elif law.exponent == 1.5:
        power = pen * m.sqrt(pen)
    else:
        power = m.pow(pen, law.exponent)
    force = law.stiffness * factor * power
    return mx(force + damp * delta_t, 0.0)


def drive_angle(t: Any, ramp_time: float, speed: float, m: Any = np) -> Any:
    """Angle [rad] of a STEP speed ramp to ``speed`` over ``ramp_time`` (t >= 0; see theory.step_integral).

    speed T d^3 (1 - d/2) with d = t/T during the ramp, speed (t - T/2) after it.
    """
    d = t * (1.0 / ramp_time)
    during = (speed * ramp_time) * d * d * d * (1.0 - 0.5 * d)
    after = speed * (t - 0.5 * ramp_time)
    if m is np:
        return np.where(np.asarray(t) < ramp_time, during, after)
    return m.IfThenElse(t < ramp_time, during, after)


def periodic_value(phase_cycles: Any, series: PeriodicSeries, m: Any = np) -> Any:
    """Value of a Fourier series in the mesh phase (cycles); ``m`` is numpy or ``exudyn.symbolic``.

    Uses one cosine and one sine and the recurrences cos(n x) = 2 cos(x) cos((n-1) x) - cos((n-2) x),
    sin(n x) = sin(x) U_(n-1)(cos x) with U_n = 2 cos(x) U_(n-1) - U_(n-2): short compiled expressions.
    """
    out = series.mean
    if len(series.cos_coeffs) == 0 or not (np.any(series.cos_coeffs) or np.any(series.sin_coeffs)):
        return out
    x = 2.0 * math.pi * phase_cycles
    c1, s1 = m.cos(x), m.sin(x)
    t_prev, t_cur = 1.0, c1  # Chebyshev T_(n-1), T_n
    u_prev, u_cur = 0.0, 1.0  # U_(n-2), U_(n-1)
    for a, b in zip(series.cos_coeffs, series.sin_coeffs, strict=True):
        if np.ndim(a) == 0:  # plain numbers (symbolic expressions need Python floats)
            a, b = float(a), float(b)
        out = out + a * t_cur + b * s1 * u_cur
        t_prev, t_cur = t_cur, 2.0 * c1 * t_cur - t_prev
        u_prev, u_cur = u_cur, 2.0 * c1 * u_cur - u_prev
    return out


def friction_forces(normal_force: Any, relative_spin: Any, sliding: Any, lever: Any, mu: float,
                    regularisation: float, mean_lever: float, m: Any = np) -> tuple[Any, Any]:
    """Lumped Coulomb friction of a mesh: forces on the sliding and relative-spin coordinates.

    Each contact line at distance s from the pitch point slides with s * Omega (Omega = relative spin
    rate omega_1 - omega_2); summed over the lines with the load uniform along them, friction gives
    mu F sigma kappa(phi) on the sliding coordinate (pitch-point sliding along w = e_z x t) and
    mu F sigma lambda(phi) on the relative spin (a moment), sigma = tanh(Omega lambda_mean / v_reg)
    the regularised sign of sliding.
    """
    sigma = m.tanh(relative_spin * (mean_lever / regularisation))
    f = mu * normal_force * sigma
    return f * sliding, f * lever


# --------------------------------------------------------------------------- gear contact
@dataclass(frozen=True)
class GearContact:
    """One contact (helix half) between two gears: linear mesh kinematics plus its contact law.

    ``gradient1``/``gradient2`` (3, 6) are the derivatives, with respect to the frame coordinates of
    ``body1``/``body2``, of the contact's three kinematic coordinates: the mesh deflection along the
    tooth normal, the sliding displacement at the pitch point along w = e_z x t, and the relative spin
    angle. The local mesh phase in cycles is ``phase_per_drive_angle * drive_angle(t) - phase_offset``.
    """

    name: str
    body1: str
    body2: str
    gradient1: np.ndarray
    gradient2: np.ndarray
    law: ContactLaw
    stiffness: PeriodicSeries  # normalised mesh stiffness s(phi), eq. 11-12
    sliding: PeriodicSeries  # kappa(phi): net sliding direction of the load
    lever: PeriodicSeries  # lambda(phi) [m]: mean distance of the load from the pitch point
    friction_coefficient: float
    friction_regularisation: float  # m/s
    phase_offset: float
    phase_per_drive_angle: float
    point: np.ndarray | None = None  # contact point (pitch point of the half) in the ground frame [m]
    normal: np.ndarray | None = None  # tooth normal, force direction on gear 2
    spin_per_drive_angle: tuple[float, float] = (0.0, 0.0)  # nominal spin of gear 1, 2 per drive angle
    half_width: float = 0.0  # face width of the contact half [m]


def relative_displacement_gradient(centre1: np.ndarray, centre2: np.ndarray, point: np.ndarray,
                                   direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradients of (v1 - v2) . d at ``point``, v_k = u_k + phi_k x (X - c_k) (small rotations).

    d/d(u1, phi1) = (d, (X - c1) x d);  d/d(u2, phi2) = -(d, (X - c2) x d). For the tooth normal this is
    the mesh deflection: exact in the spin (lever arm r_b cos(beta_b) on the line of action),
    linearised in translation and tilt.
    """
    d = np.asarray(direction, float)
    x = np.asarray(point, float)
    return np.concatenate([d, np.cross(x - centre1, d)]), -np.concatenate([d, np.cross(x - centre2, d)])


def contact_gradients(centre1: np.ndarray, centre2: np.ndarray, point: np.ndarray, normal: np.ndarray,
                      line_of_action: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(3, 6) gradients of (deflection, pitch-point sliding, relative spin) for both gears."""
    ez = np.array([0.0, 0.0, 1.0])
    w = np.cross(ez, line_of_action)
    n1, n2 = relative_displacement_gradient(centre1, centre2, point, normal)
    a1, a2 = relative_displacement_gradient(centre1, centre2, point, w)
    spin = np.concatenate([np.zeros(3), ez])
    return np.vstack([n1, a1, spin]), np.vstack([n2, a2, -spin])


class MeshConstraint:
    """The contacts' linear kinematics, delta = G (q - q_ref), as one Exudyn constraint per gear pair.

    ``matrix`` G (n_contacts, n_coordinates) acts on the global coordinate vector (frame coordinates
    of every body in order, then the modal coordinates of the flexible ones at ``modal_offsets``).
    Exudyn's ``ObjectConnectorCoordinateVector`` multiplies its scaling matrix by the marker's dense
    identity Jacobian in every Newton iteration, O(rows cols^2): one constraint over all coordinates
    of model 7 (20 x 162) took half of the run time. Each gear pair's rows therefore get their own
    constraint whose marker spans only the two gears' coordinates (an empty ``ObjectGenericODE2``
    over their nodes). :meth:`set` writes a new G (and offset) into the blocks.
    """

    def __init__(self, mbs, bodies: list[Body], contacts: list[GearContact], aux_node: int, matrix: np.ndarray,
                 q_ref: np.ndarray, modal_offsets: dict[str, int]):
        from exudyn.itemInterface import (
            MarkerNodeCoordinates,
            MarkerObjectODE2Coordinates,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        index = {b.name: i for i, b in enumerate(bodies)}
        by_name = {b.name: b for b in bodies}
        aux_marker = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=aux_node))
        self.q_ref = q_ref
        self.blocks: list[tuple[int, np.ndarray, tuple]] = []  # (constraint, rows, np.ix_(rows, columns))
        pairs = list(dict.fromkeys((c.body1, c.body2) for c in contacts))
        for pair in pairs:
            rows = np.array([i for i, c in enumerate(contacts) if (c.body1, c.body2) == pair])
            nodes = [by_name[n].node for n in pair]
            cols = [np.arange(6 * index[n], 6 * index[n] + 6) for n in pair]
            for n in pair:
                if by_name[n].flexible:
                    nodes.append(by_name[n].modal_node)
                    cols.append(np.arange(modal_offsets[n], modal_offsets[n] + by_name[n].reduced.n_modes))
            cols = np.concatenate(cols)
            span = mbs.AddObject(ObjectGenericODE2(name=f"mesh_span_{pair[0]}_{pair[1]}", nodeNumbers=nodes))
            block = mbs.AddObject(ObjectConnectorCoordinateVector(
                name=f"mesh_kinematics_{pair[0]}_{pair[1]}",
                markerNumbers=[aux_marker, mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span))],
                scalingMarker0=np.eye(len(contacts))[rows], scalingMarker1=matrix[np.ix_(rows, cols)],
                offset=matrix[rows] @ q_ref))
            self.blocks.append((block, rows, np.ix_(rows, cols)))

    def set(self, mbs, matrix: np.ndarray, offset: np.ndarray | None = None) -> None:
        """Write G (and the offset, if given) into the constraints (a pre-step hot path)."""
        for block, rows, sub in self.blocks:
            mbs.SetObjectParameter(block, "scalingMarker1", matrix[sub])
            if offset is not None:
                mbs.SetObjectParameter(block, "offset", offset[rows])


def add_gear_contacts(mbs, bodies: list[Body], contacts: list[GearContact], ramp_time: float, drive_speed: float,
                      modal_offsets: dict[str, int] | None = None, n_coordinates: int | None = None
                      ) -> tuple[list[int], int, MeshConstraint, np.ndarray, StiffnessSchedule | None]:
    """Add the contacts: one auxiliary deflection coordinate each, their linear kinematics
    (:class:`MeshConstraint`), one compiled normal-force law each.

    ``modal_offsets``, ``n_coordinates``: first global column of each flexible body's modal
    coordinates and the total number of columns (frame coordinates first; the modal columns start
    at zero and are filled by flexgear.contact_kinematics).
    Returns the spring-damper of every contact (its ``Force`` output is the normal force), the
    auxiliary node holding the deflections, the constraint, its (frame) gradient matrix and the
    :class:`StiffnessSchedule` (a pre-step function; None for constant stiffness).
    """
    from exudyn import symbolic as esym
    from exudyn.itemInterface import (
        MarkerNodeCoordinate,
        NodeGenericODE2,
        NodePointGround,
        ObjectConnectorCoordinateSpringDamper,
    )
    from exudyn.utilities import CreateSymbolicUserFunction

    n_c = len(contacts)
    n_frames = 6 * len(bodies)
    extra = (n_coordinates or n_frames) - n_frames
    gradient = np.hstack([_assemble_rows(bodies, contacts, row=0), np.zeros((n_c, extra))])
    # the markers measure reference + displacement coordinates: subtract the reference
    q_ref = np.concatenate([[*b.position, 0.0, 0.0, 0.0] for b in bodies] + [np.zeros(extra)])
    aux = mbs.AddNode(NodeGenericODE2(name="mesh_deflections", numberOfODE2Coordinates=n_c,
                                      referenceCoordinates=[0.0] * n_c, initialCoordinates=[0.0] * n_c,
                                      initialCoordinates_t=[0.0] * n_c))
    constraint = MeshConstraint(mbs, bodies, contacts, aux, gradient, q_ref, modal_offsets or {})
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    springs, laws, factors = [], [], []
    varying = any(np.any(c.stiffness.cos_coeffs) or np.any(c.stiffness.sin_coeffs) for c in contacts)
    for i, c in enumerate(contacts):
        spring = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
            name=c.name, markerNumbers=[m_ground, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=aux, coordinate=i))]))
        if varying:
            factors.append(esym.Real(f"mesh_stiffness_factor_{id(mbs)}_{spring}", 1.0))
        law = _normal_law_function(c, factors[-1] if varying else 1.0, esym)
        laws.append(CreateSymbolicUserFunction(mbs, law, "springForceUserFunction", spring))
        mbs.SetObjectParameter(spring, "springForceUserFunction", laws[-1])
        springs.append(spring)
    _keep_alive(mbs, laws + factors)
    schedule = StiffnessSchedule(contacts, ramp_time, drive_speed, factors) if varying else None
    return springs, aux, constraint, gradient, schedule


def _assemble_rows(bodies: list[Body], contacts: list[GearContact], row: int) -> np.ndarray:
    """(n_contacts, 6 n_bodies) matrix of one kinematic row of every contact."""
    index = {b.name: i for i, b in enumerate(bodies)}
    out = np.zeros((len(contacts), 6 * len(bodies)))
    for i, c in enumerate(contacts):
        out[i, 6 * index[c.body1]:6 * index[c.body1] + 6] += c.gradient1[row]
        out[i, 6 * index[c.body2]:6 * index[c.body2] + 6] += c.gradient2[row]
    return out


def _normal_law_function(c: GearContact, factor: Any, esym: Any):
    """The normal-force law of ``c`` as a spring-force user function (traced once into a symbolic one).

    ``factor`` is the contact's mesh-stiffness factor: a named symbolic variable that
    :class:`StiffnessSchedule` sets once per step (or a plain 1.0 for constant stiffness).
    """

    def law(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):  # noqa: N803
        return impact_force(displacement, velocity, c.law, factor, esym)

    return law


class StiffnessSchedule:
    """Mesh-stiffness factors s(phi(t)) of all contacts (eq. 11-12), set once per step into the laws.

    The factor is a function of time only (the mesh phase follows the prescribed drive angle), so
    setting it for the step's end time before the step is exact; evaluating it once per step in numpy
    instead of inside every compiled law call halves the cost of a run.
    """

    def __init__(self, contacts: list[GearContact], ramp_time: float, drive_speed: float, variables: list):
        self.series = _stack([c.stiffness for c in contacts])
        self.offsets = np.array([c.phase_offset for c in contacts])
        self.rate = np.array([c.phase_per_drive_angle for c in contacts])
        self.ramp_time, self.drive_speed, self.variables = ramp_time, drive_speed, variables
        self._cos = np.ascontiguousarray(np.atleast_2d(self.series.cos_coeffs).T)
        self._sin = np.ascontiguousarray(np.atleast_2d(self.series.sin_coeffs).T)
        self._means = np.asarray(self.series.mean, float) * np.ones(len(variables))
        self(None, 0.0)

    def values(self, t: float) -> np.ndarray:
        """Factors at time t (reference implementation, numpy)."""
        phase = self.rate * float(drive_angle(t, self.ramp_time, self.drive_speed)) - self.offsets
        return np.asarray(periodic_value(phase, self.series), float) * np.ones(len(self.variables))

    def fast_values(self, t: float) -> np.ndarray:
        """Same as :meth:`values`, compiled (flexgear.kernels.periodic_values)."""
        from flexgear.kernels import periodic_values

        phase = self.rate * float(drive_angle(t, self.ramp_time, self.drive_speed)) - self.offsets
        return periodic_values(phase, self._means, self._cos, self._sin)

    def __call__(self, mbs, t: float) -> bool:
        for var, value in zip(self.variables, self.fast_values(t).tolist(), strict=True):
            var.SetValue(value)
        return True


def _stack(series: list[PeriodicSeries]) -> PeriodicSeries:
    """Several series as one with array coefficients (harmonic-major), evaluated element-wise."""
    width = max(len(x.cos_coeffs) for x in series)

    def pad(v: np.ndarray) -> np.ndarray:
        return np.pad(np.asarray(v, float), (0, width - len(v)))

    return PeriodicSeries(np.array([x.mean for x in series]), np.array([pad(x.cos_coeffs) for x in series]).T,
                          np.array([pad(x.sin_coeffs) for x in series]).T)


class MeshFriction:
    """Tooth friction of all contacts as one generalized load, updated once per time step.

    The friction forces (:func:`friction_forces`) need each contact's normal force, which lives in
    another connector; they are therefore evaluated at the start of every step from the converged
    state of the previous one (explicit in time, one step h behind; friction is mu = 0.02 of the
    normal force, whose mesh-frequency content has 22 steps per period at 4400 Hz) and applied as the
    ``forceVector`` of the frame-element container: Q = -(A f_slide + B f_spin).
    """

    def __init__(self, mbs, bodies: list[Body], container: int, aux_node: int, contacts: list[GearContact],
                 ramp_time: float, drive_speed: float):
        self.mbs, self.container, self.contacts = mbs, container, contacts
        self.ramp_time, self.drive_speed = ramp_time, drive_speed
        self.sliding_rows = _assemble_rows(bodies, contacts, row=1)
        self.spin_rows = _assemble_rows(bodies, contacts, row=2)
        self.bodies = bodies
        self.aux_node = aux_node
        self.mu = np.array([c.friction_coefficient for c in contacts])
        self.reg = np.array([c.friction_regularisation for c in contacts])
        self.offsets = np.array([c.phase_offset for c in contacts])
        self.phase_rate = np.array([c.phase_per_drive_angle for c in contacts])
        # every contact's law and series stacked into arrays: one vectorised evaluation per step
        self.law = ContactLaw(*(np.array([getattr(c.law, f) for c in contacts])
                                for f in ("stiffness", "exponent", "damping_max", "penetration_depth")))
        self.series = {name: _stack([getattr(c, name) for c in contacts]) for name in ("stiffness", "sliding", "lever")}
        self._cos = np.ascontiguousarray([np.atleast_2d(self.series[k].cos_coeffs).T
                                          for k in ("stiffness", "sliding", "lever")])
        self._sin = np.ascontiguousarray([np.atleast_2d(self.series[k].sin_coeffs).T
                                          for k in ("stiffness", "sliding", "lever")])
        self._means = np.array([self.series[k].mean for k in ("stiffness", "sliding", "lever")])
        self._index: tuple[np.ndarray, np.ndarray] | None = None
        self._force: np.ndarray | None = None

    def forces(self, t: float, delta: np.ndarray, delta_t: np.ndarray, q_t: np.ndarray) -> np.ndarray:
        """Generalized friction forces on the frame coordinates (reference implementation, numpy)."""
        phase = self.phase_rate * drive_angle(t, self.ramp_time, self.drive_speed) - self.offsets
        value = {name: periodic_value(phase, series) for name, series in self.series.items()}
        normal = impact_force(delta, delta_t, self.law, value["stiffness"])
        f_slide, f_spin = friction_forces(normal, self.spin_rows @ q_t, value["sliding"], value["lever"],
                                          self.mu, self.reg, self.series["lever"].mean)
        return -(self.sliding_rows.T @ f_slide + self.spin_rows.T @ f_spin)

    def fast_forces(self, t: float, delta: np.ndarray, delta_t: np.ndarray, q_t: np.ndarray) -> np.ndarray:
        """Same as :meth:`forces`, compiled (flexgear.kernels.mesh_friction_forces)."""
        from flexgear.kernels import mesh_friction_forces

        phase = self.phase_rate * float(drive_angle(t, self.ramp_time, self.drive_speed)) - self.offsets
        law = self.law
        return mesh_friction_forces(
            phase, delta, delta_t, q_t, law.stiffness, law.exponent, law.damping_max, law.penetration_depth,
            self._means, self._cos, self._sin, self.mu, self.reg, self.sliding_rows, self.spin_rows)

    def __call__(self, mbs, t: float) -> bool:
        """Pre-step user function: friction from the state at the start of the step."""
        if self._index is None:
            self._index = (
                np.arange(mbs.GetNodeODE2Index(self.aux_node), mbs.GetNodeODE2Index(self.aux_node) + len(self.mu)),
                np.concatenate([np.arange(mbs.GetNodeODE2Index(b.node), mbs.GetNodeODE2Index(b.node) + 6)
                                for b in self.bodies]),
            )
        aux, frames = self._index
        if self._force is None:
            self._force = np.zeros(len(mbs.GetObjectParameter(self.container, "forceVector")))
        q, q_t = mbs.systemData.GetODE2Coordinates(), mbs.systemData.GetODE2Coordinates_t()
        self._force[:len(frames)] = self.fast_forces(t, q[aux], q_t[aux], q_t[frames])
        mbs.SetObjectParameter(self.container, "forceVector", self._force)
        return True


# --------------------------------------------------------------------------- drive and load
def add_speed_drive(mbs, body: Body, ramp_time: float, speed: float) -> int:
    """Prescribe the spin angle of ``body`` to the STEP speed ramp's integral (position level).

    Returns the constraint; its ``Force`` output is the drive torque [N·m].
    """
    from exudyn import symbolic as esym
    from exudyn.itemInterface import MarkerNodeCoordinate, NodePointGround, ObjectConnectorCoordinate
    from exudyn.utilities import CreateSymbolicUserFunction

    ground = mbs.AddNode(NodePointGround())
    m0 = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    m1 = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=body.node, coordinate=5))
    drive = mbs.AddObject(ObjectConnectorCoordinate(name="drive", markerNumbers=[m0, m1]))

    def offset(mbs, t, itemNumber, lOffset):  # noqa: N803
        return drive_angle(t, ramp_time, speed, esym)

    fn = CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", drive)
    mbs.SetObjectParameter(drive, "offsetUserFunction", fn)
    _keep_alive(mbs, [fn])
    return drive


def add_load_torque(mbs, body: Body, torque: float, ramp_time: float) -> int:
    """Torque ``torque`` [N·m] about the body's spin axis, ramped by STEP(t, 0, 0, T, 1)."""
    from exudyn import symbolic as esym
    from exudyn.itemInterface import LoadCoordinate, MarkerNodeCoordinate
    from exudyn.utilities import CreateSymbolicUserFunction

    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=body.node, coordinate=5))
    load = mbs.AddLoad(LoadCoordinate(name="load_torque", markerNumber=marker, load=torque))

    def ramped(mbs, t, load):
        d = esym.min(esym.max(t, 0.0) / ramp_time, 1.0)
        return load * d * d * (3.0 - 2.0 * d)

    fn = CreateSymbolicUserFunction(mbs, ramped, "loadUserFunction", load)
    mbs.SetLoadParameter(load, "loadUserFunction", fn)
    _keep_alive(mbs, [fn])
    return load


def add_fixed_joint(mbs, body: Body, other: Body | None = None, coordinates: tuple[int, ...] = (0, 1, 2, 3, 4, 5),
                    name: str | None = None) -> list[int]:
    """Fixed joint on frame coordinates (linear, exact): ``body`` to ``other``, or to ground if ``other`` is None.

    Joins the selected frame coordinates (0-2 translation, 3-5 rotation, 5 = spin) of two bodies whose
    frames coincide in the reference configuration: q_body = q_other (one constraint). For a flexible
    body the frame is its mean-axis frame (Tisserand), so the joint acts on the body's mean motion, not
    on its interface nodes. To ground: each selected displacement coordinate is held at zero (one
    constraint each; e.g. ``coordinates=(5,)`` holds a ring's spin and leaves its bearing compliance to
    a bushing). Returns the constraints.
    """
    from exudyn.itemInterface import (
        MarkerNodeCoordinate,
        NodePointGround,
        ObjectConnectorCoordinate,
        ObjectConnectorCoordinateVector,
    )

    label = name or f"fixed_{body.name}_{other.name if other is not None else 'ground'}"
    if other is not None:
        rows = np.eye(6)[list(coordinates)]
        return [mbs.AddObject(ObjectConnectorCoordinateVector(
            name=label, markerNumbers=[body.marker_coordinates, other.marker_coordinates],
            scalingMarker0=rows, scalingMarker1=rows, offset=np.zeros(len(rows))))]
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    return [mbs.AddObject(ObjectConnectorCoordinate(
        name=f"{label}_{k}", markerNumbers=[ground, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=body.node,
                                                                                       coordinate=k))]))
        for k in coordinates]


def add_interface_joint(mbs, body: Body, other: Body, interfaces: tuple[str, str], point, name: str = "") -> int:
    """Fixed joint of two bodies at their interfaces, at ``point`` [m, ground frame, reference configuration].

    A flexible body joins through the ``MarkerSuperElementRigid`` of its interface (the RBE3 motion
    of the interface node set, see flexgear.flexible.add_flexible_body, which must have placed that
    marker at ``point``); a rigid body through a body-fixed marker at ``point``. All six relative
    motions are constrained (``ObjectJointGeneric``); its ``Force``/``Torque`` outputs are the
    forces [N] and moments [N·m] the joint transmits. Returns the joint.
    """
    from exudyn.itemInterface import MarkerBodyRigid, ObjectJointGeneric, VObjectJointGeneric

    markers = []
    for b, itf in zip((body, other), interfaces, strict=True):
        if b.flexible:
            if itf not in b.interface_markers:
                raise KeyError(f"flexible body {b.name!r} has no marker on interface {itf!r}; "
                               f"have {sorted(b.interface_markers)}")
            markers.append(b.interface_markers[itf])
        else:
            local = np.asarray(point, float) - b.position
            markers.append(mbs.AddMarker(MarkerBodyRigid(bodyNumber=b.obj, localPosition=list(map(float, local)))))
    return mbs.AddObject(ObjectJointGeneric(name=name or f"joint_{body.name}_{other.name}", markerNumbers=markers,
                                            constrainedAxes=[1] * 6, visualization=VObjectJointGeneric(show=False)))


def _keep_alive(mbs, functions: list) -> None:
    """Symbolic user functions must outlive the simulation: keep them with the system."""
    store = mbs.variables.setdefault("flexgear_symbolic_functions", [])
    store.extend(functions)
