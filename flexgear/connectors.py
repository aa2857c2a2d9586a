"""Connectors: bushings, gear contacts, speed drive and load torque, on body frame coordinates.

Element contract (as ROSS's): every linear element (bushing) gives a 6x6 stiffness and damping
matrix on the frame coordinates (u_x, u_y, u_z, phi_x, phi_y, phi_z) of one body; all of them are
summed into one ``ObjectGenericODE2`` over the frame nodes. A gear contact gives the gradient of
its mesh deflection with respect to the frame coordinates of both gears (the linearised mesh
kinematics) and a scalar contact law.

Gear contact (section 2.1 of the study, ADAMS impact function, per helix half h):

    delta_h  = g1 . q1 + g2 . q2                           (mesh deflection along the tooth normal)
    F_h      = max(0, k_h s(phi) <delta_h>^e + c_max,h STEP(delta_h, 0, 0, d, 1) d(delta_h)/dt)

with k_h, c_max,h the study's stiffness and damping scaled by the half's share of the face width,
s(phi) = 1 + sum_n c_n cos(2 pi n (phi - phi_0)) the mesh-stiffness variation of eq. 11-12
(phi: mesh phase in cycles, from the prescribed drive), and F_h = 0 when the teeth separate.
The deflection is carried by an auxiliary coordinate per half, tied to the gear coordinates by
one linear ``ObjectConnectorCoordinateVector`` constraint; the law is a compiled (symbolic)
user function of a ``ObjectConnectorCoordinateSpringDamper``: no Python runs per step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from flexgear.bodies import Body
from flexgear.spec import Bearing, Contact

__all__ = [
    "Bushing",
    "ContactLaw",
    "GearContact",
    "impact_force",
    "stiffness_factor",
    "drive_angle",
    "mesh_deflection_gradients",
    "add_linear_elements",
    "add_gear_contacts",
    "add_speed_drive",
    "add_load_torque",
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


def add_linear_elements(mbs, bodies: list[Body], elements: list[Bushing]) -> tuple[int, int]:
    """Sum the elements' matrices into one ``ObjectGenericODE2`` over the bodies' frame nodes.

    Returns ``(object, marker)``: the marker (``MarkerObjectODE2Coordinates``) spans all frame
    coordinates in the order of ``bodies`` and is reused by the gear-contact constraint.
    """
    from exudyn.itemInterface import MarkerObjectODE2Coordinates, ObjectGenericODE2

    index = {b.name: i for i, b in enumerate(bodies)}
    n = 6 * len(bodies)
    stiffness, damping = np.zeros((n, n)), np.zeros((n, n))
    for e in elements:
        if e.body not in index:
            raise KeyError(f"bushing on unknown body {e.body!r}; bodies: {sorted(index)}")
        s = slice(6 * index[e.body], 6 * index[e.body] + 6)
        stiffness[s, s] += e.stiffness_matrix()
        damping[s, s] += e.damping_matrix()
    obj = mbs.AddObject(ObjectGenericODE2(
        name="bushings", nodeNumbers=[b.node for b in bodies], massMatrix=np.zeros((n, n)),
        stiffnessMatrix=stiffness, dampingMatrix=damping,
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
    if law.exponent == 1.5:
        power = pen * m.sqrt(pen)
    else:
        power = pen**law.exponent if m is np else m.pow(pen, law.exponent)
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


def stiffness_factor(phase_cycles: Any, coefficients: np.ndarray, phase0: float, m: Any = np) -> Any:
    """s(phi) = 1 + sum_n c_n cos(2 pi n (phi - phi_0)) (eq. 11-12 with contact-line coefficients).

    Evaluated with one cosine and the Chebyshev recurrence cos(n x) = 2 cos(x) cos((n-1) x) - cos((n-2) x),
    which keeps the compiled expression short.
    """
    if len(coefficients) == 0 or not np.any(coefficients):
        return 1.0
    c1 = m.cos(2.0 * math.pi * (phase_cycles - phase0))
    out = 1.0 + float(coefficients[0]) * c1
    prev, cur = 1.0, c1
    for c in coefficients[1:]:
        prev, cur = cur, 2.0 * c1 * cur - prev
        out = out + float(c) * cur
    return out


# --------------------------------------------------------------------------- gear contact
@dataclass(frozen=True)
class GearContact:
    """One contact (helix half) between two gears: linear mesh kinematics plus its contact law.

    ``gradient1``/``gradient2`` are d(delta)/dq of the frame coordinates (6,) of ``body1``/``body2``.
    The mesh phase in cycles is ``phase_per_drive_angle * drive_angle(t) + phase0``.
    """

    name: str
    body1: str
    body2: str
    gradient1: np.ndarray
    gradient2: np.ndarray
    law: ContactLaw
    harmonics: np.ndarray
    phase0: float
    phase_per_drive_angle: float


def mesh_deflection_gradients(
    centre1: np.ndarray, centre2: np.ndarray, contact_point: np.ndarray, normal: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Gradients of delta = (v1 - v2) . n with v_k = u_k + phi_k x (X - c_k) (small rotations).

    d(delta)/d(u1, phi1) = (n, (X - c1) x n);  d(delta)/d(u2, phi2) = -(n, (X - c2) x n).
    Exact for the spin angle (lever arm = base radius cos(beta_b) for X on the line of action),
    linearised for translations and tilts.
    """
    n = np.asarray(normal, float)
    x = np.asarray(contact_point, float)
    g1 = np.concatenate([n, np.cross(x - centre1, n)])
    g2 = -np.concatenate([n, np.cross(x - centre2, n)])
    return g1, g2


def add_gear_contacts(mbs, bodies: list[Body], coordinates_marker: int, contacts: list[GearContact],
                      ramp_time: float, drive_speed: float) -> list[int]:
    """Add the contacts: auxiliary deflection coordinates, one constraint, one compiled law each.

    Returns the spring-damper object of every contact (their ``Force`` output is the normal force).
    """
    from exudyn import symbolic as esym
    from exudyn.itemInterface import (
        MarkerNodeCoordinate,
        MarkerNodeCoordinates,
        NodeGenericODE2,
        NodePointGround,
        ObjectConnectorCoordinateSpringDamper,
        ObjectConnectorCoordinateVector,
    )
    from exudyn.utilities import CreateSymbolicUserFunction

    index = {b.name: i for i, b in enumerate(bodies)}
    n_c, n_q = len(contacts), 6 * len(bodies)
    gradient = np.zeros((n_c, n_q))
    for i, c in enumerate(contacts):
        gradient[i, 6 * index[c.body1]:6 * index[c.body1] + 6] += c.gradient1
        gradient[i, 6 * index[c.body2]:6 * index[c.body2] + 6] += c.gradient2
    # MarkerObjectODE2Coordinates measures reference + displacement coordinates: subtract the reference
    q_ref = np.concatenate([[*b.position, 0.0, 0.0, 0.0] for b in bodies])
    aux = mbs.AddNode(NodeGenericODE2(name="mesh_deflections", numberOfODE2Coordinates=n_c,
                                      referenceCoordinates=[0.0] * n_c, initialCoordinates=[0.0] * n_c,
                                      initialCoordinates_t=[0.0] * n_c))
    m_aux = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=aux))
    mbs.AddObject(ObjectConnectorCoordinateVector(
        name="mesh_kinematics", markerNumbers=[m_aux, coordinates_marker],
        scalingMarker0=np.eye(n_c), scalingMarker1=gradient, offset=gradient @ q_ref,
    ))
    ground = mbs.AddNode(NodePointGround())
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    springs, laws = [], []
    for i, c in enumerate(contacts):
        m_i = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=aux, coordinate=i))
        spring = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
            name=c.name, markerNumbers=[m_ground, m_i], stiffness=0.0, damping=0.0))

        law = _contact_law_function(c, ramp_time, drive_speed, esym)
        laws.append(CreateSymbolicUserFunction(mbs, law, "springForceUserFunction", spring))
        mbs.SetObjectParameter(spring, "springForceUserFunction", laws[-1])
        springs.append(spring)
    _keep_alive(mbs, laws)
    return springs


def _contact_law_function(c: GearContact, ramp_time: float, drive_speed: float, esym: Any):
    """The contact law of ``c`` as a spring-force user function (traced once into a symbolic one)."""

    def law(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):  # noqa: N803
        phase = c.phase_per_drive_angle * drive_angle(t, ramp_time, drive_speed, esym) + c.phase0
        factor = stiffness_factor(phase, c.harmonics, 0.0, esym)
        return impact_force(displacement, velocity, c.law, factor, esym)

    return law


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


def _keep_alive(mbs, functions: list) -> None:
    """Symbolic user functions must outlive the simulation: keep them with the system."""
    store = mbs.variables.setdefault("flexgear_symbolic_functions", [])
    store.extend(functions)
