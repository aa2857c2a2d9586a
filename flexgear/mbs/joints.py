"""Gear-shaft joints and seat bearings of flexible bodies as linear equations about the prescribed spin.

They are the production formulation; the reference formulation uses Exudyn's ``ObjectJointGeneric`` and
spring-dampers on marker points instead.

Exudyn's ``ObjectJointGeneric`` on two ``MarkerSuperElementRigid`` markers evaluates the markers' full
kinematics, and their derivatives by automatic differentiation, in every Newton iteration: with 35-mode
shafts it cost about half of model 7's step (``perf``: ``ConstraintReactionForcesRigidMarkers``). A gear and
its shaft turn together about the common z axis at the prescribed spin phi_n(t) with small frame
translations u, tilts (phi_x, phi_y), spin deviation and elastic coordinates q. To first order in those, a
point p (body frame, at the reference position x_0) of a body sits at

    X = x_0 + u + R_n (p + Psi_t q) + (phi_x e_x + phi_y e_y + (phi_z - phi_n) e_z) x R_n p

and the interface turns by (phi_x, phi_y, phi_z) + R_n Psi_r q (ground axes; R = R_x R_y R_z of the
frame node, R_n = R_z(phi_n); Psi_t, Psi_r the interface's RBE3 translation at p and rotation per modal
coordinate, flexgear.fe.cms.ReducedBody.interface_motion). A fixed joint makes both equal for the two bodies
(the same point p in ground at the reference): six linear equations C(t) q = 0 whose coefficients turn
with R_n. They are one ``ObjectConnectorCoordinateVector`` over the two bodies' coordinates, rewritten
before each step (:meth:`LinearInterfaceJoint.__call__`), one marker per body; its multipliers lambda
(``Force`` output) are the joint's force [N] (ground x, y, z) and moment [N m] (ground x, y, z) on the second body.
Every joint lies on the axis (the sun's bore, the ring's bolt patches at their centroid), where the frame
columns are constant (:func:`frame_form`).

The six equations are written in ground or in body axes. "ground": as above, the
modal columns turn (R_n Psi) and, off the axis, the frame rotations' lever. "body": the same equations
premultiplied by Q_n^T = blockdiag(R_n^T, R_n^T) (:func:`body_axes_form`), an exact row transformation, so
the solution is the same; the modal columns are then constant and the frame columns (R_n^T u, R_n^T phi) turn.
The modified Newton method keeps a Jacobian over many steps while the coefficients turn; with a flexible
shaft, turning frame columns cost it fewer Newton iterations than turning modal ones (benchmarks/bench_newton.py
counts them per step), with a rigid
shaft more Jacobians; so a joint takes body axes where its shaft is flexible, ground axes where it is rigid.
The multipliers are then the force and moment in the gear's body axes.

A bearing at a flexible body's seat (flexgear.geometry.elements.BearingElement, at its place by
flexgear.geometry.supports) acts on the seat interface's motion s = (translation at the bearing centre, rotation)
in ground, the same first-order expression: an auxiliary coordinate vector s tied by
s = J_f (frame - reference) + R_n Psi q (one linear constraint, its modal block rewritten each step) carries the
bearing's constant 6 x 6 stiffness and damping (:class:`LinearSeat`), in place of the reference formulation's
three spring-dampers on the body's virtual nodes (the same element realised on the axis,
flexgear.mbs.elements.add_support), which Exudyn evaluates and differentiates numerically through the whole mode
basis.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from flexgear.geometry.elements import BearingElement, FixedJointElement
from flexgear.laws.compiled import bound_entry, ramp_state, turn_columns
from flexgear.mbs.bodies import Body, frame_rows, matrix_container, motion_at_point, resting_node, zero_user_jacobian

_ON_AXIS_M = 1e-9
"""A joint point within this distance [m] of the spin axis lies on it (the exact geometry places it there)."""

__all__ = ["LinearInterfaceJoint", "LinearSeat", "TurningBlocks",
           "add_frame_bearing", "body_axes_form", "frame_form",
           "interface_rows", "linear_bearing", "turning_form"]


def interface_rows(body: Body, interface: str, local_point: np.ndarray) -> np.ndarray:
    """(6, m): translation [m] at ``local_point`` (body frame) and rotation [rad] of ``interface`` per modal
    coordinate of the flexible ``body`` (the RBE3 motion, flexgear.fe.cms.ReducedBody.interface_motion)."""
    red = body.reduced
    return motion_at_point(red.interface_motion(interface), red.interface(interface).point, local_point)


def turning_form(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(C, A, B) with blockdiag(R_z(a), R_z(a)) ``rows`` = C + cos(a) A + sin(a) B: rows (6, w) of ground
    translation and rotation in the body frame, turned with the spin a; rows (6 k, w) of k points, six by six."""
    blocks = rows.reshape(rows.shape[0] // 6, 6, rows.shape[1])
    const, cos_part, sin_part = np.zeros_like(blocks), blocks.copy(), np.zeros_like(blocks)
    const[:, [2, 5]], cos_part[:, [2, 5]] = blocks[:, [2, 5]], 0.0
    for k in (0, 3):
        sin_part[:, k], sin_part[:, k + 1] = -blocks[:, k + 1], blocks[:, k]
    return tuple(a.reshape(rows.shape) for a in (const, cos_part, sin_part))


def frame_form(point: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(C, A, B) (6, 6) of the frame coordinates (u, phi) of a body turned by the spin: ground translation of
    its ``point`` p [m] (from the frame origin, on the spin axis) and rotation, [I, -p~; 0, I], constant (C; A = B
    = 0: a point on the axis does not move with the spin). A point off the axis raises ValueError."""
    p = np.asarray(point, float)
    if np.hypot(p[0], p[1]) > _ON_AXIS_M:
        raise ValueError(f"frame_form: point {p.tolist()} m is off the spin axis (linear joints lie on the axis)")
    return frame_rows(p), np.zeros((6, 6)), np.zeros((6, 6))


def body_axes_form(form: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(C', A', B') with Q(a)^T (C + cos(a) A + sin(a) B) = C' + cos(a) A' + sin(a) B': six rows of ground
    translation and rotation, rewritten in the axes turned by the spin a, Q(a) = blockdiag(R_z(a), R_z(a)).

    With Q^T = Z + cos(a) P + sin(a) S (Z keeps the z rows, P the x and y rows, S maps (x, y) to (y, -x)), the
    product has the terms Z C + (P A + S B)/2, cos(a) (P C + Z A), sin(a) (S C + Z B) and the second harmonics
    cos(2a) (P A - S B)/2, sin(2a) (P B + S A)/2. Those vanish for rows that turn as R_z(a) does: the modal
    columns of :func:`turning_form` become constant, :func:`frame_form`'s rows become [R^T, -p~ R^T] (the lever
    the point p itself, the ground frame coordinates turned). A form with a second harmonic raises ValueError."""
    const, cos_part, sin_part = form
    keep_z = np.diag([0.0, 0.0, 1.0, 0.0, 0.0, 1.0])
    plane = np.diag([1.0, 1.0, 0.0, 1.0, 1.0, 0.0])
    swap = np.kron(np.eye(2), np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    second = (plane @ cos_part - swap @ sin_part, plane @ sin_part + swap @ cos_part)
    scale = max(np.abs(const).max(initial=0.0), np.abs(cos_part).max(initial=0.0), np.abs(sin_part).max(initial=0.0))
    if max(np.abs(h).max(initial=0.0) for h in second) > 1e-12 * scale:
        raise ValueError("body_axes_form: the rows do not turn with the spin (a second harmonic in body axes)")
    return (keep_z @ const + 0.5 * (plane @ cos_part + swap @ sin_part), plane @ const + keep_z @ cos_part,
            swap @ const + keep_z @ sin_part)


def linear_bearing(mbs, name: str, node: int, stiffness: np.ndarray, damping: np.ndarray,
                   series_node: int | None = None, other_node: int | None = None) -> int:
    """A constant 6 x 6 ``stiffness`` and ``damping`` on the six coordinates of ``node`` to ground (one
    ``ObjectGenericODE2``, its Jacobian exact): a seat's bearing (:class:`LinearSeat`) or a rigid body's on its
    linear frame (:func:`add_frame_bearing`). ``series_node``: six more coordinates added to the bearing's
    deflection, s + e (the seat's residual motion, flexgear.mbs.residual): [[K, K], [K, K]] on (s, e).
    ``other_node``: the bearing's other side instead of ground (a planet's pin, flexgear.mbs.carrier.CarrierPins),
    a rigid-body node at the same reference place: the deflection s - p, [[K, -K], [-K, K]] on (s, p). A bearing
    isotropic about the axis (diag(k_r, k_r, k_a, k_t, k_t, 0)) acts so in ground axes whatever the turning of
    either side."""
    from exudyn.itemInterface import ObjectGenericODE2

    if series_node is not None and other_node is not None:
        raise ValueError(f"{name}: a bearing in series with a residual acts to ground, not on another node")
    nodes = [node] + [n for n in (series_node, other_node) if n is not None]
    pattern = np.array([[1.0, -1.0], [-1.0, 1.0]]) if other_node is not None else np.ones((len(nodes), len(nodes)))
    k, d = (np.kron(pattern, a) for a in (stiffness, damping))
    return mbs.AddObject(ObjectGenericODE2(name=name, nodeNumbers=nodes, stiffnessMatrix=matrix_container(k),
                                           dampingMatrix=matrix_container(d),
                                           jacobianUserFunction=zero_user_jacobian(6 * len(nodes))))


def add_frame_bearing(mbs, body: Body, bearing: BearingElement) -> int:
    """The ``bearing`` of a rigid ``body`` on its frame coordinates: its matrices moved from the bearing centre to
    the frame origin (:meth:`BearingElement.at`, T^T K T with T = [I, -p~; 0, I], exact to first order in the
    tilts)."""
    at_frame = bearing.at(np.zeros(3))
    return linear_bearing(mbs, f"bearing_{body.name}{bearing.tag}", body.node, at_frame.stiffness,
                          at_frame.damping)


class LinearInterfaceJoint:
    """The fixed joint ``joint`` of ``body`` (its interface ``joint.interface``) and ``other``
    (``joint.other_interface``) at ``joint.point``.

    ``joint.point`` [m, ground frame at the reference]: on the bodies' common axis, where their frame columns are
    constant (:func:`frame_form`). ``spin_per_drive_angle`` the bodies'
    nominal spin per prescribed drive angle (both turn together). ``obj`` is the constraint; :meth:`turning`
    gives its blocks that a :class:`TurningBlocks` pre-step function turns with the spin. ``residual``: the
    gear's (``body``) interface moves by six more coordinates, ``residual_node``, its dropped modes' motion e_s
    of the interface at ``point`` in ground axes (flexgear.mbs.residual: the joint's reaction loads them).
    ``axes``: "ground" or "body", the axes of its six equations and multipliers (module docstring).
    """

    def __init__(self, mbs, body: Body, other: Body, joint: FixedJointElement, spin_per_drive_angle: float,
                 name: str = "", residual: bool = False, axes: str = "ground"):
        from exudyn.itemInterface import (
            MarkerObjectODE2Coordinates,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        joint.check_bodies(body.name, other.name)
        point = np.array(joint.point)
        self.spin = float(spin_per_drive_angle)
        self.centre = point - body.position  # the gear's interface point, its body frame at the reference
        self.residual_node = -1
        forms, q_ref, markers = [], [], []
        for b, itf, sign in ((body, joint.interface, -1.0), (other, joint.other_interface, 1.0)):
            nodes = [b.node]
            local = point - b.position
            q_ref.append(np.concatenate([b.position, np.zeros(3)]))
            parts = [frame_form(local)]
            if b.flexible:  # on the interface's own coordinates when the body has them (FlexibleBody.span)
                modal_nodes, modal = b.span(interface_rows(b, itf, local))
                nodes += modal_nodes
                q_ref.append(np.zeros(modal.shape[1]))
                parts.append(turning_form(modal))
            if residual and b is body:
                self.residual_node = resting_node(mbs, f"{name}_{b.name}_seat_residual", 6)
                nodes.append(self.residual_node)
                q_ref.append(np.zeros(6))
                parts.append((np.eye(6), np.zeros((6, 6)), np.zeros((6, 6))))  # ground axes: does not turn
            form = tuple(sign * np.hstack([f[k] for f in parts]) for k in range(3))
            forms.append(body_axes_form(form) if axes == "body" else form)
            # one marker per body: Exudyn's constraint costs rows x columns^2 per marker (its dense Jacobian)
            width = forms[-1][0].shape[1]
            span = mbs.AddObject(ObjectGenericODE2(name=f"{name}_{b.name}_span", nodeNumbers=nodes,
                                                   jacobianUserFunction=zero_user_jacobian(width)))
            markers.append(mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span)))
        self.forms = forms  # per body (C, A, B), signed: body 2 minus body 1
        self.q_ref = np.concatenate(q_ref)
        split = forms[0][0].shape[1]  # columns of the first body
        c = self.matrix_at(0.0)
        offset = c @ self.q_ref
        if axes == "body" and np.abs(offset[[0, 1, 3, 4]]).max() > 1e-12 * max(1.0, np.abs(offset).max()):
            # the offset would turn: Q^T C q_ref is constant only while the frames' reference offsets lie on the axis
            raise ValueError(f"{name}: body axes need the bodies' frames on the common axis")
        # Exudyn's equation: scalingMarker1 q_1 - scalingMarker0 q_0 - offset = 0
        self.obj = mbs.AddObject(ObjectConnectorCoordinateVector(
            name=name, markerNumbers=markers, scalingMarker0=-c[:, :split], scalingMarker1=c[:, split:],
            offset=offset))

    def matrix_at(self, phi: float) -> np.ndarray:
        """C (6, columns) at the spin angle ``phi`` [rad]: rows translation x, y, z and rotation x, y, z of body 2
        minus body 1, in ground axes or in the axes turned by ``phi`` (the joint's ``axes``)."""
        c, s = np.cos(phi), np.sin(phi)
        return np.hstack([f[0] + c * f[1] + s * f[2] for f in self.forms])

    def turning(self) -> list[tuple]:
        """The markers whose coefficients turn with the spin (:class:`TurningBlocks` entries); the offset C q_ref
        stays constant (the frames' rotation coordinates are zero at the reference)."""
        out = []
        for k, param, sign in ((0, "scalingMarker0", -1.0), (1, "scalingMarker1", 1.0)):
            const, cos_part, sin_part = (sign * f for f in self.forms[k])
            if np.any(cos_part) or np.any(sin_part):
                out.append((self.obj, param, const, cos_part, sin_part, self.spin))
        return out


class LinearSeat:
    """The ``bearing`` (flexgear.geometry.elements.BearingElement, ground on its other side) at its interface, the
    seat of the flexible ``body`` (module docstring): its 6 x 6 stiffness and damping about its centre on the seat
    coordinates. ``spin_per_drive_angle``: the body's nominal spin per prescribed drive angle; ``node``: the six
    seat coordinates; :meth:`turning` gives the block that a :class:`TurningBlocks` pre-step function turns.
    ``residual``: the seat coordinates are the kept motion plus six more, ``residual_node``, the dropped modes'
    seat motion e_s (flexgear.mbs.residual: the bearing acts on the seat in series with it).
    ``carrier``: the carrier, rigid or flexible, on the bearing's other side (``bearing.other``; a planet on its pin
    of a turning carrier) instead of ground: the seat coordinates are then those of a rigid-body node at the
    bearing centre (displacement from its reference place and rotation, the same six numbers) and the bearing acts
    between it and the node of its pin's motion ``pin_node`` (flexgear.mbs.carrier.CarrierPins,
    :func:`linear_bearing` with ``other_node``); no residual then.
    """

    def __init__(self, mbs, body: Body, bearing: BearingElement, spin_per_drive_angle: float, residual: bool = False,
                 carrier: Body | None = None, pin_node: int | None = None):
        from exudyn.itemInterface import (
            MarkerNodeCoordinates,
            MarkerObjectODE2Coordinates,
            NodeRigidBodyRxyz,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        if carrier is None:
            bearing.check_to_ground(body.name)
        elif (bearing.body, bearing.other) != (body.name, carrier.name) or residual or pin_node is None:
            raise ValueError(f"bearing of {bearing.body!r} on {bearing.other!r} placed on {body.name!r} at "
                             f"{carrier.name!r}{' with a residual' if residual else ''}"
                             f"{' without its pin node' if pin_node is None else ''}")
        self.spin = float(spin_per_drive_angle)
        label = body.name + bearing.tag
        centre = np.array(bearing.centre)
        modal_nodes, self.rows = body.span(interface_rows(body, bearing.interface, centre))
        frame = frame_rows(centre)
        self.centre = centre
        self.residual_node = -1
        seat_ref = np.zeros(6)  # the seat node's reference coordinates (the markers measure reference + coordinates)
        if carrier is not None:
            seat_ref[:3] = body.position + centre
            self.node = mbs.AddNode(NodeRigidBodyRxyz(name=f"{label}_seat", referenceCoordinates=seat_ref))
            linear_bearing(mbs, f"bearing_{label}", self.node, bearing.stiffness, bearing.damping,
                           other_node=pin_node)
        else:
            self.node = resting_node(mbs, f"{label}_seat", 6)
            if residual:  # the bearing acts on s + e_s: its force loads the dropped modes' seat coordinates as well
                self.residual_node = resting_node(mbs, f"{label}_seat_residual", 6)
            linear_bearing(mbs, f"bearing_{label}", self.node, bearing.stiffness, bearing.damping,
                           series_node=self.residual_node if residual else None)
        span = mbs.AddObject(ObjectGenericODE2(name=f"{label}_seat_span", nodeNumbers=[self.node, body.node],
                                               jacobianUserFunction=zero_user_jacobian(12)))
        # Exudyn's equation: scalingMarker1 q - scalingMarker0 (s, frame) - offset = 0, i.e.
        # R_n Psi q + J_f (frame - reference) - s = 0
        q_ref = np.concatenate([body.position, np.zeros(3)])
        modal = (MarkerNodeCoordinates(nodeNumber=modal_nodes[0]) if len(modal_nodes) == 1 else
                 MarkerObjectODE2Coordinates(objectNumber=mbs.AddObject(ObjectGenericODE2(
                     name=f"{label}_seat_modes", nodeNumbers=modal_nodes,
                     jacobianUserFunction=zero_user_jacobian(self.rows.shape[1])))))
        self.obj = mbs.AddObject(ObjectConnectorCoordinateVector(
            name=f"{label}_seat_tie",
            markerNumbers=[mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span)), mbs.AddMarker(modal)],
            scalingMarker0=np.hstack([np.eye(6), -frame]), scalingMarker1=self.rows, offset=frame @ q_ref - seat_ref))

    def turning(self) -> list[tuple]:
        """The seat tie's modal block, which turns with the spin (:class:`TurningBlocks` entry)."""
        return [(self.obj, "scalingMarker1", *turning_form(self.rows), self.spin)]


@njit(cache=True)
def turned_blocks(buffer, t, ramp_time, drive_speed, const, cos_part, sin_part, spin_index, spins,
                  target):  # pragma: no cover - compiled
    """flexgear.laws.compiled.turn_columns at the drive angle of time ``t`` [s] (``drive_speed`` x integral of the
    STEP ramp ``ramp_time`` [s]), in one compiled call."""
    turn_columns(buffer, const, cos_part, sin_part, spin_index, spins, target,
                 drive_speed * ramp_state(t, ramp_time)[0])


class TurningBlocks:
    """Pre-step function: the constraint coefficients of the linear joints and seats that turn with the spin
    (``entries``: their :meth:`turning` lists, (constraint, parameter, C, A, B, spin per drive angle)), each matrix
    C + cos(phi_n) A + sin(phi_n) B with phi_n = spin x the prescribed drive angle (STEP ramp ``ramp_time`` [s] to
    ``drive_speed`` [rad/s]). Every entry's matrix is a contiguous block of one buffer, written by one compiled
    call (flexgear.laws.compiled.turn_columns: one cosine and sine per distinct spin), then handed to its
    constraint."""

    def __init__(self, entries: list[tuple], ramp_time: float, drive_speed: float):
        self.ramp_time, self.drive_speed = float(ramp_time), float(drive_speed)
        self.const, self.cos_part, self.sin_part = (np.ascontiguousarray(np.hstack([e[k] for e in entries]))
                                                    for k in (2, 3, 4))
        self.spin = np.concatenate([np.full(e[2].shape[1], e[5]) for e in entries])
        self.spins, self.spin_index = np.unique(self.spin, return_inverse=True)
        rows, starts = self.const.shape[0], np.cumsum([0, *(e[2].shape[1] for e in entries)])
        self.buffer = np.zeros(self.const.size)
        # column j of entry e (its columns a..b) goes to row r of e's block: rows * a + r (b - a) + (j - a)
        self.target = np.zeros(self.const.shape, dtype=np.int64)
        self.items = []
        for e, a, b in zip(entries, starts[:-1], starts[1:], strict=True):
            cols = np.arange(a, b)
            self.target[:, a:b] = rows * a + np.arange(rows)[:, None] * (b - a) + (cols - a)[None, :]
            self.items.append((e[0], e[1], self.buffer[rows * a:rows * b].reshape(rows, b - a)))
        self._args = (self.ramp_time, self.drive_speed, self.const, self.cos_part, self.sin_part, self.spin_index,
                      self.spins, self.target)
        self._kernel = None  # turned_blocks' compiled entry for these arguments (first call)
        self.time = 0.0  # the time [s] whose coefficients the buffer holds

    @property
    def views(self) -> list[tuple[int, str, np.ndarray]]:
        """(constraint, parameter, its matrix: a view of :attr:`buffer`) of every entry."""
        return self.items

    def buffer_at(self, t: float, out: np.ndarray) -> np.ndarray:
        """The buffer's values at time ``t`` [s] written into ``out`` (an array of its size): the coefficients a
        Jacobian evaluated then would hold (flexgear.mbs.newton.MidlifeJacobian)."""
        self._bound(out, t)(out, float(t), *self._args)
        return out

    def _bound(self, buffer: np.ndarray, t: float):
        """turned_blocks' compiled entry for these arguments (bound at the first call)."""
        if self._kernel is None:
            self._kernel = bound_entry(turned_blocks, (buffer, float(t), *self._args))
        return self._kernel

    def turned(self, t: float) -> np.ndarray:
        """All blocks at time t, column by column (6, W): the numpy reference of the compiled kernel."""
        phi = self.spin * (self.drive_speed * ramp_state(float(t), self.ramp_time)[0])
        return self.const + np.cos(phi) * self.cos_part + np.sin(phi) * self.sin_part

    def __call__(self, mbs, t: float) -> bool:
        kernel = self._kernel
        if kernel is None:
            kernel = self._bound(self.buffer, t)
        kernel(self.buffer, t, *self._args)
        self.time = t
        set_parameter = mbs.SetObjectParameter
        for obj, param, matrix in self.items:
            set_parameter(obj, param, matrix)
        return True
