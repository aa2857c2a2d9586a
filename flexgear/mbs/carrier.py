"""A rotating carrier: planet bearings on the carrier and the contacts' geometry turning with it.

Planet bearing: the planet's bearing element (flexgear.geometry.elements.BearingElement, the carrier on its
other side) at the planet's frame origin, realised as an ``ObjectConnectorCartesianSpringDamper`` from a
``MarkerBodyPosition`` at the pin on the carrier to the planet's frame node (radial stiffness in x, y, axial in
z: the bearing is isotropic about the axis, so the carrier's spin does not matter), plus tilt springs between
the planet's and the carrier's tilt coordinates (both ground-frame tilts for small tilts); the planet's spin
relative to the carrier stays free (:func:`add_planet_bearing`, :func:`add_pin_bearing`: a rigid carrier, no
per-step update). The planetary stage's builder (flexgear.mbs.planetary) realises the same element as every other
bearing of its production formulation, flexgear.mbs.joints.linear_bearing, between the planet's frame (or a
flexible planet's seat node, flexgear.mbs.joints.LinearSeat) and its pin's node (flexgear.mbs.carrier.CarrierPins,
for a rigid or a flexible carrier).

Contacts (flexgear.mbs.contacts.GearContact) are linearised at the reference configuration, carrier
angle 0. With the carrier at angle theta every contact's pitch point, normal and planet centre are
turned about the carrier axis by R(theta); the deflection of contact i is

    delta_i = G_i(theta) . (q - q_ref(theta)) + sum_k S_ik phi_k - S_i theta,    S_i = sum_k S_ik

with G_i(theta) the gradient rows with every body's translation and rotation 3-blocks turned by
R(theta), q_ref(theta) the reference frame positions with the orbiting bodies (planets) moved round
the axis, S_ik the spin coefficients (turning-invariant) and the last term the carrier's rotation
taken out of the absolute spins (the mesh sees spins relative to the carrier). Planets' translations
are absolute coordinates, so the carrier's actual angle enters through the planets' positions, not
as a column of its own: a column -S_i on the carrier's spin would count the carrier's rotation twice
(a rigid rotation of the whole stage would then load the mesh). ``theta`` is the nominal carrier
angle (spin ratio x prescribed drive angle), set once per step by a pre-step function: delta is
stationary in theta at the nominal state (d delta / d theta = (c x n)_z - S_i = 0), so an error of
theta (one step, elastic wind-up) enters only at second order, a eps^2 / 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from flexgear.geometry.elements import BearingElement
from flexgear.laws.ramps import drive_angle
from flexgear.mbs.bodies import Body, zero_user_jacobian
from flexgear.mbs.joints import interface_rows, turning_form

__all__ = ["Carrier", "CarrierKinematics", "CarrierPins", "add_pin_bearing", "add_planet_bearing", "pin_coefficients"]


@dataclass(frozen=True)
class Carrier:
    """The carrier: its body name and nominal spin per prescribed drive angle (e.g. z_s / (z_s + z_r))."""

    body: str
    spin_per_drive_angle: float


def _rotation(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class CarrierKinematics:
    """Pre-step update of the contact constraint's gradient rows and offset for a rotating carrier.

    ``rows`` (n_contacts, 6 n_bodies + n_modal): the contacts' gradient rows at carrier angle 0 (one kinematic
    row of every contact, over the frame coordinates in the order of ``bodies``, then the flexible gears' modal
    coordinates, zero here). Bodies off the carrier axis (other than the carrier) orbit with it. The carrier's frame
    (rigid, or a flexible carrier's mean axes) carries no contact: only its position, the axis, enters. ``extra_rows``
    are further row sets over the frame coordinates to turn in place (the friction's sliding rows), given as
    arrays to overwrite. With flexible gears (modal columns) the update writes only the frame columns and the
    offset: flexgear.mbs.contact_kinematics.ContactKinematics writes the modal ones, at the material angle of
    each contact relative to the turning carrier.
    """

    def __init__(self, constraint, rows: np.ndarray, bodies: list[Body], carrier: Carrier, ramp_time: float,
                 drive_speed: float, extra_rows: list[np.ndarray] | None = None):
        self.constraint, self.carrier = constraint, carrier
        self.ramp_time, self.drive_speed = ramp_time, drive_speed
        self.n_frames = 6 * len(bodies)
        self.rows0 = np.asarray(rows, float)[:, :self.n_frames].copy()
        self.modal = np.shape(rows)[1] > self.n_frames  # flexible gears: their modal columns are not written here
        names = [b.name for b in bodies]
        if carrier.body not in names:
            raise KeyError(f"carrier body {carrier.body!r} is not among the bodies {names}")
        axis = next(b.position for b in bodies if b.name == carrier.body)
        self.axis = np.asarray(axis, float)
        self.positions = np.array([b.position for b in bodies], float)
        radial = np.hypot(*(self.positions[:, :2] - self.axis[:2]).T)
        self.orbiting = (radial > 1e-12) & (np.array(names) != carrier.body)
        spin_cols = 6 * np.arange(len(bodies)) + 5
        self.spin_sum = self.rows0[:, spin_cols].sum(axis=1)
        self.extra = [(r, np.asarray(r, float).copy()) for r in (extra_rows or [])]

    def theta(self, t: float) -> float:
        """Nominal carrier angle [rad] at time t."""
        return self.carrier.spin_per_drive_angle * float(drive_angle(t, self.ramp_time, self.drive_speed))

    @staticmethod
    def turned(rows: np.ndarray, theta: float) -> np.ndarray:
        """Rows with every body's translation and rotation 3-blocks turned about z: g -> R(theta) g."""
        n, m = rows.shape
        blocks = rows.reshape(n, m // 3, 3)
        return (blocks @ _rotation(theta).T).reshape(n, m)

    def reference(self, theta: float) -> np.ndarray:
        """Frame coordinates of the reference configuration with the carrier at ``theta`` (all rotations 0)."""
        pos = self.positions.copy()
        pos[self.orbiting] = self.axis + (pos[self.orbiting] - self.axis) @ _rotation(theta).T
        return np.hstack([pos, np.zeros_like(pos)]).ravel()

    def matrix_and_offset(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Constraint scaling matrix over the frame coordinates and offset at time t (aux = G q - offset; the modal
        columns, where there are any, are flexgear.mbs.contact_kinematics.ContactKinematics')."""
        theta = self.theta(t)
        g = self.turned(self.rows0, theta)
        return g, g @ self.reference(theta) + self.spin_sum * theta

    def __call__(self, mbs, t: float) -> bool:
        g, offset = self.matrix_and_offset(t)
        self.constraint.set(mbs, g, offset, modal=not self.modal)
        theta = self.theta(t)
        for target, rows0 in self.extra:
            target[:] = self.turned(rows0, theta)
        return True


def add_planet_bearing(mbs, carrier: Body, planet: Body, bearing: BearingElement, name: str | None = None
                       ) -> list[int]:
    """The ``bearing`` of the rigid ``planet`` on its pin of ``carrier`` (its DOF map: body ``planet.name``, other
    ``carrier.name``), the spin free: :func:`add_pin_bearing` at the planet's frame node, the bearing moved to the
    frame origin (:meth:`BearingElement.at`). Returns the connectors."""
    if (bearing.body, bearing.other) != (planet.name, carrier.name):
        raise ValueError(f"bearing of {bearing.body!r} on {bearing.other!r} placed as {planet.name!r} on "
                         f"{carrier.name!r}")
    return add_pin_bearing(mbs, carrier, planet.node, planet.position, bearing.at(np.zeros(3)),
                           name or f"bearing_{planet.name}")


def add_pin_bearing(mbs, carrier: Body, node: int, point: np.ndarray, bearing: BearingElement, name: str
                    ) -> list[int]:
    """A bearing between the rigid node ``node`` (e.g. a planet's frame) whose reference position is ``point`` [m,
    ground] and the pin of the rigid ``carrier`` there, the spin free: Exudyn's nonlinear connectors, no per-step
    update (flexgear.mbs.planetary realises its planets' bearings as flexgear.mbs.joints.linear_bearing on the
    pins' nodes of flexgear.mbs.carrier.CarrierPins instead).

    ``bearing`` about ``point`` must be diag(k_r, k_r, k_a, k_t, k_t, 0) (ValueError otherwise). Translation: an
    ``ObjectConnectorCartesianSpringDamper`` with stiffness (k_r, k_r, k_a) and the matching damping entries
    between the pin (``point`` fixed in the carrier) and the node (isotropic about the axis: the carrier's spin does
    not matter); tilt: a coordinate spring-damper k_t between the node's and the carrier's tilt coordinates about
    x and y (both ground-frame tilts for small tilts). Returns the connectors.
    """
    from exudyn.itemInterface import (
        MarkerBodyPosition,
        MarkerNodeCoordinate,
        MarkerNodePosition,
        ObjectConnectorCartesianSpringDamper,
        ObjectConnectorCoordinateSpringDamper,
    )

    k_r, k_a, k_t = bearing.axisymmetric_entries()
    d_r, d_a, d_t = bearing.axisymmetric_entries(bearing.damping)
    pin = mbs.AddMarker(MarkerBodyPosition(bodyNumber=carrier.obj,
                                           localPosition=list(np.asarray(point, float) - carrier.position)))
    out = [mbs.AddObject(ObjectConnectorCartesianSpringDamper(
        name=name, markerNumbers=[pin, mbs.AddMarker(MarkerNodePosition(nodeNumber=node))],
        stiffness=[k_r, k_r, k_a], damping=[d_r, d_r, d_a]))]
    for axis in (3, 4):
        out.append(mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
            name=f"{name}_tilt{axis - 2}",
            markerNumbers=[mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=carrier.node, coordinate=axis)),
                           mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=axis))],
            stiffness=k_t, damping=d_t)))
    return out


class CarrierPins:
    """The pins of a planet carrier, rigid or flexible, each on a rigid-body node whose coordinates are the pin's
    motion: the planets' bearings act on them (flexgear.mbs.joints.linear_bearing with ``other_node``).

    The carrier (its frame on the axis at c_0) turns; theta is its angle at the end of each step, predicted from its
    spin coordinate and rate at the step's start (:meth:`angle`; ``max_step_s`` [s] the longest step the integrator
    takes). Pin k (a flexible carrier's RBE3 interface ``names[k]``) has its point p_k [m, carrier frame] off the
    axis, so, to first order in the frame's translation u, its small rotation
    (phi - theta e_z) and the modal coordinates q (module docstring), with r = R_z(theta) p_k,

        s_t = c_0 + u + r + (phi - theta e_z) x r + R_theta Psi_t q,     s_r = phi + R_theta Psi_r q

    (s_t the pin's position [m], s_r its rotation coordinates: ground tilts, the carrier's spin angle; Psi the
    interface's RBE3 motion per modal coordinate; none for a rigid carrier, whose pins are ``points`` [m, ground]).
    One ``ObjectConnectorCoordinateVector`` ties the pins' nodes, six rows each, to the carrier: s = F(r) (c_0 + u,
    phi) + R_theta Psi q - o with F(r) = [I, -r~; 0, I] (the lever to the turned pin) and o = -(r + theta r x e_z,
    0). Its frame columns, its modal columns and its offset all turn with theta; the pre-step call rewrites them
    each step (two parameters for all pins; the offset grows with theta: its theta r x e_z cancels the carrier's
    spin coordinate's own lever, phi_z r x e_z, to round-off). The multipliers are the pins' reactions on the
    carrier, force [N] and moment [N m] in ground axes.

    Why the actual angle, not the nominal one: the tie's lever r is frozen over a step, so its moment about the
    axis, (r x F)_z, is off by (phi_z - theta) a F_r for a pin force F with a radial part F_r (the planets'
    centripetal force) at the pin radius a: the nominal angle would leave the carrier's wind-up behind it (its pins'
    own deflection, the shafts' torsion) as a first-order error of the torque the pins pass on; the predicted angle
    leaves the change of that wind-up within one step.
    """

    def __init__(self, mbs, carrier: Body, names: list[str], max_step_s: float, points: list | None = None):
        from exudyn.itemInterface import (
            MarkerObjectODE2Coordinates,
            NodeRigidBodyRxyz,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        if carrier.flexible == (points is not None):
            raise ValueError(f"CarrierPins: carrier {carrier.name!r}: a flexible carrier's pins are its interfaces "
                             "``names``, a rigid carrier's are ``points``")
        self.carrier_node, self.max_step_s = carrier.node, float(max_step_s)
        n = len(names)
        if carrier.flexible:
            self.points = np.array([carrier.reduced.interface(name).point for name in names], float)
            rows = [interface_rows(carrier, name, p) for name, p in zip(names, self.points, strict=True)]
            modal_nodes = list(dict.fromkeys(node for r in rows for node in carrier.span(r)[0]))
            columns = carrier.node_columns(modal_nodes)
            modal = np.vstack([carrier.to_coordinates(r)[:, columns] for r in rows])
        else:
            self.points = np.asarray(points, float).reshape(n, 3) - carrier.position
            modal_nodes, modal = [], np.zeros((6 * n, 0))
        self.forms = tuple(np.ascontiguousarray(f) for f in turning_form(modal))
        self.nodes = [mbs.AddNode(NodeRigidBodyRxyz(name=f"{carrier.name}_{name}_node",
                                                    referenceCoordinates=[*(carrier.position + p), 0.0, 0.0, 0.0]))
                      for name, p in zip(names, self.points, strict=True)]
        # marker 0 the pins' nodes, marker 1 the carrier's frame and the modal coordinates the pins move with
        own = mbs.AddObject(ObjectGenericODE2(name=f"{carrier.name}_pins_own", nodeNumbers=self.nodes,
                                              jacobianUserFunction=zero_user_jacobian(6 * n)))
        span = mbs.AddObject(ObjectGenericODE2(name=f"{carrier.name}_pins_span",
                                               nodeNumbers=[carrier.node, *modal_nodes],
                                               jacobianUserFunction=zero_user_jacobian(6 + modal.shape[1])))
        self.scaling = np.zeros((6 * n, 6 + modal.shape[1]))
        for k in range(n):
            self.scaling[6 * k:6 * k + 6, :6] = np.eye(6)
        self.offset = np.zeros(6 * n)
        scaling1, offset = self.coefficients(0.0)
        self.obj = mbs.AddObject(ObjectConnectorCoordinateVector(
            name=f"{carrier.name}_pins_tie",
            markerNumbers=[mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=own)),
                           mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span))],
            scalingMarker0=np.eye(6 * n), scalingMarker1=scaling1, offset=offset))

    def angle(self, mbs, t: float) -> float:
        """The carrier's angle [rad] at the end of the step to time ``t`` [s], predicted from its state at the step's
        start: its spin coordinate plus its rate times the step h = t - the start's time. Outside a time step (a
        static solve at ``t``, or no step 0 < h <= ``max_step_s``) the spin coordinate as it is."""
        import exudyn as exu

        ovt = exu.OutputVariableType
        angle = float(mbs.GetNodeOutput(self.carrier_node, ovt.Coordinates)[5])
        h = t - mbs.systemData.GetTime(exu.ConfigurationType.StartOfStep)
        if 0.0 < h <= self.max_step_s:
            angle += float(mbs.GetNodeOutput(self.carrier_node, ovt.Coordinates_t)[5]) * h
        return angle

    def coefficients(self, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """(scaling of (carrier frame, modal coordinates), offset) of the pins' ties at the carrier angle ``theta``
        [rad], six rows per pin (class docstring; Exudyn's equation: scaling1 (frame, q) - s - offset = 0, both
        markers measuring reference plus displacement): buffers rewritten in place by one compiled call
        (:func:`pin_coefficients`)."""
        const, cos_part, sin_part = self.forms
        pin_coefficients(float(theta), self.points, const, cos_part, sin_part, self.scaling, self.offset)
        return self.scaling, self.offset

    def __call__(self, mbs, t: float) -> bool:
        scaling, offset = self.coefficients(self.angle(mbs, t))
        mbs.SetObjectParameter(self.obj, "scalingMarker1", scaling)
        mbs.SetObjectParameter(self.obj, "offset", offset)
        return True


@njit(cache=True)
def pin_coefficients(theta, points, const, cos_part, sin_part, scaling, offset):  # pragma: no cover - compiled
    """:meth:`CarrierPins.coefficients` in place: per pin k (rows 6 k ...), r = R_z(theta) p_k, the lever block -r~
    of F(r) in ``scaling[:, 3:6]``, the modal block C + cos(theta) A + sin(theta) B in ``scaling[:, 6:]``, and
    ``offset`` -(r + theta r x e_z, 0)."""
    c, s = np.cos(theta), np.sin(theta)
    for k in range(points.shape[0]):
        x = c * points[k, 0] - s * points[k, 1]
        y = s * points[k, 0] + c * points[k, 1]
        z = points[k, 2]
        i = 6 * k
        scaling[i, 4], scaling[i, 5] = z, -y
        scaling[i + 1, 3], scaling[i + 1, 5] = -z, x
        scaling[i + 2, 3], scaling[i + 2, 4] = y, -x
        offset[i], offset[i + 1], offset[i + 2] = -(x + theta * y), -(y - theta * x), -z
    for i in range(const.shape[0]):
        for j in range(const.shape[1]):
            scaling[i, 6 + j] = const[i, j] + c * cos_part[i, j] + s * sin_part[i, j]

