"""Gear contacts in the multibody model: contact points of a gear pair, mesh kinematics, per-step updates.

A gear contact gives the gradient of its mesh deflection with respect to the frame coordinates of both
gears (the linearised mesh kinematics) and a scalar contact law (flexgear.laws.contact).

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
Python runs per step. Friction (kappa, lambda: see flexgear.geometry.contact_lines.contact_line_distribution)
follows from the contact lines' positions relative to the pitch point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from flexgear.geometry.contact_lines import MeshContactGeometry, PeriodicSeries, mesh_contact_geometry
from flexgear.geometry.involute import GearMesh
from flexgear.laws.contact import ContactLaw, friction_forces, half_laws, normal_force
from flexgear.laws.ramps import drive_angle
from flexgear.mbs.bodies import Body, normal_lever, resting_node
from flexgear.mbs.elements import keep_alive
from flexgear.mbs.mesh_constraint import MeshConstraint, contact_pairs
from flexgear.spec import Contact, ContactAssumed

__all__ = [
    "GearContact",
    "relative_displacement_gradient",
    "contact_gradients",
    "MeshFriction",
    "StiffnessSchedule",
    "add_gear_contacts",
    "pair_contacts",
    "mesh_pair_contacts",
]

_EZ = np.array([0.0, 0.0, 1.0])  # the gear axis (unit z)

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
    return normal_lever(point, direction, centre1), -normal_lever(point, direction, centre2)


def contact_gradients(centre1: np.ndarray, centre2: np.ndarray, point: np.ndarray, normal: np.ndarray,
                      line_of_action: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(3, 6) gradients of (deflection, pitch-point sliding, relative spin) for both gears."""
    ez = np.array([0.0, 0.0, 1.0])
    w = np.cross(ez, line_of_action)
    n1, n2 = relative_displacement_gradient(centre1, centre2, point, normal)
    a1, a2 = relative_displacement_gradient(centre1, centre2, point, w)
    spin = np.concatenate([np.zeros(3), ez])
    return np.vstack([n1, a1, spin]), np.vstack([n2, a2, -spin])


def add_gear_contacts(mbs, bodies: list[Body], contacts: list[GearContact], ramp_time: float, drive_speed: float,
                      modal_offsets: dict[str, int] | None = None, n_coordinates: int | None = None,
                      residual_markers: dict[int, int] | None = None
                      ) -> tuple[list[int], int, MeshConstraint, np.ndarray, StiffnessSchedule | None]:
    """Add the contacts: one auxiliary deflection coordinate each, their linear kinematics
    (:class:`MeshConstraint`), one compiled normal-force law each.

    ``modal_offsets``, ``n_coordinates``: first global column of each flexible body's modal
    coordinates and the total number of columns (frame coordinates first; the modal columns start
    at zero and are filled by flexgear.mbs.contact_kinematics). ``residual_markers``: {contact row: marker of its
    residual deflection coordinate} (flexgear.mbs.residual): the law then acts on delta - e, not on delta.
    Returns the spring-damper of every contact (its ``Force`` output is the normal force), the
    auxiliary nodes holding the deflections (one per gear pair, consecutive), the constraint, its (frame)
    gradient matrix and the :class:`StiffnessSchedule` (a pre-step function; None for constant stiffness).
    """
    from exudyn import symbolic as esym
    from exudyn.itemInterface import (
        MarkerNodeCoordinate,
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
    # one deflection node per gear pair, added one after the other: their coordinates are one vector
    pairs = contact_pairs(contacts)
    aux = [resting_node(mbs, f"mesh_deflections_{a}_{b}", len(rows)) for (a, b), rows in pairs]
    slot = {int(i): (node, k) for node, (_, rows) in zip(aux, pairs, strict=True) for k, i in enumerate(rows)}
    constraint = MeshConstraint(mbs, bodies, contacts, aux, gradient, q_ref, modal_offsets or {})
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    springs, laws = [], []
    shared: dict[tuple, tuple[Any, GearContact]] = {}  # one factor per distinct s(phi(t)): helix halves share it
    varying = any(np.any(c.stiffness.cos_coeffs) or np.any(c.stiffness.sin_coeffs) for c in contacts)
    for i, c in enumerate(contacts):
        spring = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
            name=c.name, markerNumbers=[(residual_markers or {}).get(i, m_ground),
                                        mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=slot[i][0],
                                                                           coordinate=slot[i][1]))]))
        key = _schedule_key(c)
        if varying and key not in shared:
            shared[key] = (esym.Real(f"mesh_stiffness_factor_{id(mbs)}_{spring}", 1.0), c)
        law = _normal_law_function(c, shared[key][0] if varying else 1.0, esym)
        laws.append(CreateSymbolicUserFunction(mbs, law, "springForceUserFunction", spring))
        mbs.SetObjectParameter(spring, "springForceUserFunction", laws[-1])
        springs.append(spring)
    factors = [v for v, _ in shared.values()]
    keep_alive(mbs, laws + factors)
    schedule = (StiffnessSchedule([c for _, c in shared.values()], ramp_time, drive_speed, factors)
                if varying else None)
    return springs, aux, constraint, gradient, schedule


def _schedule_key(c: GearContact) -> tuple:
    """What the stiffness factor s(phi(t)) of a contact depends on (equal keys: equal factors at all t)."""
    return (float(c.stiffness.mean), tuple(np.ravel(c.stiffness.cos_coeffs)), tuple(np.ravel(c.stiffness.sin_coeffs)),
            float(c.phase_offset), float(c.phase_per_drive_angle))


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
        return normal_force(displacement, velocity, c.law, factor, esym)

    return law


class StiffnessSchedule:
    """Mesh-stiffness factors s(phi(t)) of all contacts (eq. 11-12), set once per step into the laws.

    The factor is a function of time only (the mesh phase follows the prescribed drive angle), so
    setting it for the step's end time before the step is exact; evaluating it once per step in numpy
    instead of inside every compiled law call halves the cost of a run. ``contacts[i]`` gives the
    factor of ``variables[i]``; contacts with equal series and phase (the helix halves of one mesh)
    share one variable (:func:`add_gear_contacts`).
    """

    def __init__(self, contacts: list[GearContact], ramp_time: float, drive_speed: float, variables: list):
        self.series = _stack([c.stiffness for c in contacts])
        self.offsets = np.array([c.phase_offset for c in contacts])
        self.rate = np.array([c.phase_per_drive_angle for c in contacts])
        self.ramp_time, self.drive_speed, self.variables = ramp_time, drive_speed, variables
        self._cos = np.ascontiguousarray(np.atleast_2d(self.series.cos_coeffs).T)
        self._sin = np.ascontiguousarray(np.atleast_2d(self.series.sin_coeffs).T)
        self._means = np.asarray(self.series.mean, float) * np.ones(len(variables))
        self._packed = self.series.packed()
        self(None, 0.0)

    def values(self, t: float) -> np.ndarray:
        """Factors at time t (reference implementation, numpy: the series' direct Fourier sum)."""
        phase = self.rate * float(drive_angle(t, self.ramp_time, self.drive_speed)) - self.offsets
        return np.asarray(self.series(phase), float) * np.ones(len(self.variables))

    def fast_values(self, t: float) -> np.ndarray:
        """Same as :meth:`values`, compiled (flexgear.laws.compiled.periodic_values)."""
        from flexgear.laws.compiled import periodic_values, ramp_state

        phase = self.rate * (self.drive_speed * ramp_state(float(t), self.ramp_time)[0]) - self.offsets
        return periodic_values(phase, self._packed)

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

    def __init__(self, mbs, bodies: list[Body], container: int, aux_nodes: list[int], contacts: list[GearContact],
                 ramp_time: float, drive_speed: float, residual: tuple[int, np.ndarray] | None = None):
        self.mbs, self.container, self.contacts = mbs, container, contacts
        self.residual = residual  # (node, contact rows) of the residual deflections e: the law acts on delta - e
        self.ramp_time, self.drive_speed = ramp_time, drive_speed
        self.sliding_rows = _assemble_rows(bodies, contacts, row=1)
        self.spin_rows = _assemble_rows(bodies, contacts, row=2)
        self.bodies = bodies
        self.aux_nodes = list(aux_nodes)  # the contacts' deflection nodes, one per gear pair, consecutive
        self.mu = np.array([c.friction_coefficient for c in contacts])
        self.reg = np.array([c.friction_regularisation for c in contacts])
        self.offsets = np.array([c.phase_offset for c in contacts])
        self.phase_rate = np.array([c.phase_per_drive_angle for c in contacts])
        # every contact's law and series stacked into arrays: one vectorised evaluation per step
        kinds = {c.law.kind for c in contacts}
        if len(kinds) != 1:
            raise ValueError(f"tooth friction needs one contact law for all contacts, got {sorted(kinds)}")
        self.law = ContactLaw(*(np.array([getattr(c.law, f) for c in contacts])
                                for f in ("stiffness", "exponent", "damping_max", "penetration_depth")), kinds.pop())
        self.series = {name: _stack([getattr(c, name) for c in contacts]) for name in ("stiffness", "sliding", "lever")}
        self._cos = np.ascontiguousarray([np.atleast_2d(self.series[k].cos_coeffs).T
                                          for k in ("stiffness", "sliding", "lever")])
        self._sin = np.ascontiguousarray([np.atleast_2d(self.series[k].sin_coeffs).T
                                          for k in ("stiffness", "sliding", "lever")])
        self._means = np.array([self.series[k].mean for k in ("stiffness", "sliding", "lever")])
        self._packed = np.ascontiguousarray([self.series[k].packed() for k in ("stiffness", "sliding", "lever")])
        self._index: tuple[np.ndarray, np.ndarray] | None = None
        self._force: np.ndarray | None = None

    def forces(self, t: float, delta: np.ndarray, delta_t: np.ndarray, q_t: np.ndarray) -> np.ndarray:
        """Generalized friction forces on the frame coordinates (reference implementation, numpy)."""
        phase = self.phase_rate * drive_angle(t, self.ramp_time, self.drive_speed) - self.offsets
        value = {name: series(phase) for name, series in self.series.items()}
        normal = normal_force(delta, delta_t, self.law, value["stiffness"])
        f_slide, f_spin = friction_forces(normal, self.spin_rows @ q_t, value["sliding"], value["lever"],
                                          self.mu, self.reg, self.series["lever"].mean)
        return -(self.sliding_rows.T @ f_slide + self.spin_rows.T @ f_spin)

    def fast_forces(self, t: float, delta: np.ndarray, delta_t: np.ndarray, q_t: np.ndarray) -> np.ndarray:
        """Same as :meth:`forces`, compiled (flexgear.laws.compiled.mesh_friction_forces)."""
        from flexgear.laws.compiled import mesh_friction_forces, ramp_state

        phase = self.phase_rate * (self.drive_speed * ramp_state(float(t), self.ramp_time)[0]) - self.offsets
        law = self.law
        return mesh_friction_forces(
            phase, delta, delta_t, q_t, law.stiffness, law.exponent, law.damping_max, law.penetration_depth,
            self._packed, self.mu, self.reg, self.sliding_rows, self.spin_rows,
            law.kind == "iso6336")

    def deflection_indices(self, mbs) -> np.ndarray:
        """System indices of the contacts' deflection coordinates (after ``mbs.Assemble()``): one run over the
        pairs' consecutive nodes (checked)."""
        first = mbs.GetNodeODE2Index(self.aux_nodes[0])
        sizes = [len(mbs.GetNode(n)["referenceCoordinates"]) for n in self.aux_nodes]
        starts = first + np.cumsum([0, *sizes[:-1]])
        if [mbs.GetNodeODE2Index(n) for n in self.aux_nodes] != starts.tolist():
            raise RuntimeError("the contacts' deflection nodes do not hold consecutive system coordinates")
        return np.arange(first, first + sum(sizes), dtype=np.int64)

    def tooth_index(self, mbs) -> np.ndarray:
        """(2, n_contacts) system indices (after ``mbs.Assemble()``): each contact's deflection coordinate and its
        residual deflection coordinate e (flexgear.mbs.residual; -1: none)."""
        index = np.full((2, len(self.contacts)), -1, dtype=np.int64)
        index[0] = self.deflection_indices(mbs)
        if self.residual is not None:
            node, rows = self.residual
            index[1, rows] = mbs.GetNodeODE2Index(node) + np.arange(len(rows))
        return index

    def frame_indices(self, mbs) -> np.ndarray:
        """System indices of the bodies' frame coordinates, six per body in order (after ``mbs.Assemble()``)."""
        return np.concatenate([np.arange(mbs.GetNodeODE2Index(b.node), mbs.GetNodeODE2Index(b.node) + 6)
                               for b in self.bodies]).astype(np.int64)

    @staticmethod
    def tooth_deflections(q: np.ndarray, q_t: np.ndarray, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The tooth deflections the law sees and their rates (new arrays): each contact's deflection coordinate
        less its residual deflection, at the system state ``q``, ``q_t`` (``index``: :meth:`tooth_index`)."""
        delta, delta_t = q[index[0]], q_t[index[0]]
        has = index[1] >= 0
        delta[has] -= q[index[1, has]]
        delta_t[has] -= q_t[index[1, has]]
        return delta, delta_t

    def __call__(self, mbs, t: float) -> bool:
        """Pre-step user function: friction from the state at the start of the step."""
        if self._index is None:
            self._index = (self.tooth_index(mbs), self.frame_indices(mbs))
            self._force = np.zeros(len(mbs.GetObjectParameter(self.container, "forceVector")))
        tooth, frames = self._index
        q, q_t = mbs.systemData.GetODE2Coordinates(), mbs.systemData.GetODE2Coordinates_t()
        self._force[:len(frames)] = self.fast_forces(t, *self.tooth_deflections(q, q_t, tooth), q_t[frames])
        mbs.SetObjectParameter(self.container, "forceVector", self._force)
        return True


# --------------------------------------------------------------------------- drive and load


def pair_contacts(name: str, body1: str, body2: str, mesh: GearMesh, centre1, centre2, contact: Contact,
                  contact_assumed: ContactAssumed, *, helix_layout: str = "single", half_gap: float = 0.0,
                  hand: int = 1, drive_sign: float = 1.0, spins: tuple[float, float] | None = None,
                  carrier_spin: float = 0.0, phase_offset: float = 0.0,
                  phase_per_drive_angle: float | None = None, law: ContactLaw | None = None) -> list[GearContact]:
    """Gear contacts (one per helix half) of ``mesh`` between bodies ``body1`` and ``body2``.

    ``centre1``/``centre2``: gear centres in the ground frame [m] at the reference configuration; their
    distance must be the mesh's operating centre distance. ``contact`` and ``contact_assumed``: the
    impact law, friction and stiffness variation (flexgear.spec). ``hand``: helix hand of gear 1 in
    the (first, +z) half, +1 right / -1 left. ``drive_sign``: +1 when gear 1 pushes gear 2
    counter-clockwise about +z (gear 1 driving in its positive sense), -1 clockwise.
    ``spins``: nominal spin of gear 1 and gear 2 per drive angle (default for fixed centres:
    (1, -z1/z2) external, (1, z1/z2) internal); ``carrier_spin``: that of the carrier holding the
    centres (0 when fixed). The mesh phase in cycles is phase_per_drive_angle * theta - phase_offset,
    by default z1 (spin1 - carrier_spin) drive_sign / (2 pi) mesh cycles per drive angle theta.
    ``law``: the whole-face-width normal law (flexgear.laws.contact.mesh_laws; default the study's impact law
    from ``contact``), shared by the halves in proportion to their face width. Names: ``f"{name}_half{k}"``.
    The mesh's contact geometry is made here (flexgear.geometry.contact_lines.mesh_contact_geometry); a gearbox's
    design holds it made already (:func:`mesh_pair_contacts`).
    """
    helix_width = mesh.gear1.face_width / (2 if helix_layout == "double" else 1)
    geometry = mesh_contact_geometry(mesh, helix_layout, helix_width, half_gap, hand,
                                     contact_assumed.stiffness_harmonics)
    return mesh_pair_contacts(name, body1, body2, geometry, centre1, centre2, contact, contact_assumed,
                              half_laws(geometry, contact, law), drive_sign=drive_sign, spins=spins,
                              carrier_spin=carrier_spin, phase_offset=phase_offset,
                              phase_per_drive_angle=phase_per_drive_angle)


def mesh_pair_contacts(name: str, body1: str, body2: str, geometry: MeshContactGeometry, centre1, centre2,
                       contact: Contact, contact_assumed: ContactAssumed, laws: list[ContactLaw], *,
                       drive_sign: float = 1.0, spins: tuple[float, float] | None = None, carrier_spin: float = 0.0,
                       phase_offset: float = 0.0, phase_per_drive_angle: float | None = None) -> list[GearContact]:
    """:func:`pair_contacts` of a mesh whose contact geometry (helix halves, tooth normals, contact-line series with
    ``[contact_assumed] stiffness_harmonics`` harmonics) is given as ``geometry`` and whose halves' normal laws are
    ``laws`` (:func:`half_laws`); the other arguments as there."""
    mesh = geometry.mesh
    g1, g2 = mesh.gear1, mesh.gear2
    c1, c2 = np.asarray(centre1, float), np.asarray(centre2, float)
    d = (c2 - c1) * [1.0, 1.0, 0.0]
    a = float(np.linalg.norm(d))
    if not math.isclose(a, mesh.centre_distance, rel_tol=1e-9, abs_tol=1e-12):
        raise ValueError(f"{name}: gear centres are {a} m apart, the mesh needs its operating centre distance "
                         f"{mesh.centre_distance} m")
    s = 1.0 if drive_sign >= 0 else -1.0
    e = -d / a if mesh.internal else d / a
    r_w1 = mesh.operating_pitch_radii[0]
    alpha = mesh.operating_pressure_angle
    t_dir = math.sin(alpha) * e + s * math.cos(alpha) * np.cross(_EZ, e)
    helix_width = geometry.helix_width
    stiffness, sliding, lever = geometry.stiffness, geometry.sliding, geometry.lever
    if contact_assumed.stiffness_variation == "constant":
        n_harm = contact_assumed.stiffness_harmonics
        stiffness = PeriodicSeries(1.0, np.zeros(n_harm), np.zeros(n_harm))
    if spins is None:
        spins = (1.0, g1.teeth / g2.teeth if mesh.internal else -g1.teeth / g2.teeth)
    if phase_per_drive_angle is None:
        phase_per_drive_angle = g1.teeth * (spins[0] - carrier_spin) * s / (2 * math.pi)
    out = []
    halves = zip(geometry.halves, geometry.normals[int(s)], laws, strict=True)
    for k, (half, (n_r, n_t, n_z), law) in enumerate(halves, start=1):
        normal = n_r * e + n_t * np.cross(_EZ, e) + n_z * _EZ
        point = c1 + r_w1 * e + [0.0, 0.0, half.z]
        grad1, grad2 = contact_gradients(c1, c2, point, normal, t_dir)
        out.append(GearContact(
            f"{name}_half{k}", body1, body2, grad1, grad2, law, stiffness, sliding, lever, contact.friction_coefficient,
            contact_assumed.friction_regularisation_m_per_s, phase_offset, phase_per_drive_angle,
            point, normal, (float(spins[0]), float(spins[1])), helix_width))
    return out
