"""Gear-shaft joints and seat bearings of flexible bodies as linear equations about the prescribed spin.

``[joints_assumed] joint_equations`` and ``[supports_assumed] seat_equations`` choose them.

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
The joint point must lie on the axis (x = y = 0: the sun's bore, the ring's bolt-circle RBE3); a joint
off the axis (the ring on bolt patches) keeps ``ObjectJointGeneric``.

A bearing at a flexible body's seat (flexgear.geometry.supports: three springs on the axis) acts on the seat
interface's motion s = (translation at the bearing centre, rotation) in ground, the same first-order
expression: an auxiliary coordinate vector s tied by s = J_f (frame - reference) + R_n Psi q (one linear
constraint, its modal block rewritten each step) carries the bearing's constant 6 x 6 stiffness and damping
(:class:`LinearSeat`): the three springs' sum, exact to first order, in place of three spring-dampers on the
body's virtual nodes, which Exudyn evaluates and differentiates numerically through the whole mode basis.
"""

from __future__ import annotations

import numpy as np

from flexgear.laws.compiled import ramp_state, turn_columns
from flexgear.mbs.bodies import Body, matrix_container, zero_user_jacobian

__all__ = ["LinearInterfaceJoint", "LinearSeat", "TurningBlocks", "interface_rows", "seat_matrices"]


def interface_rows(body: Body, interface: str, local_point: np.ndarray) -> np.ndarray:
    """(6, m): translation [m] at ``local_point`` (body frame) and rotation [rad] of ``interface`` per modal
    coordinate of the flexible ``body`` (the RBE3 motion, flexgear.fe.cms.ReducedBody.interface_motion)."""
    red = body.reduced
    motion = red.interface_motion(interface)
    arm = np.asarray(local_point, float) - red.interface(interface).point
    return np.vstack([motion[:3] + np.cross(motion[3:].T, arm).T, motion[3:]])


def _frame_rows(local_point: np.ndarray) -> np.ndarray:
    """(6, 6): ground translation at a point on the axis and rotation per frame coordinate (u, phi): [I, -p~; 0, I]."""
    z = float(local_point[2])
    out = np.eye(6)
    out[0, 4], out[1, 3] = z, -z
    return out


def _turned(rows: np.ndarray, c: float, s: float) -> np.ndarray:
    """blockdiag(R_z, R_z) @ ``rows`` (6, m) for cos, sin of the angle."""
    out = rows.copy()
    for k in (0, 3):
        out[k], out[k + 1] = c * rows[k] - s * rows[k + 1], s * rows[k] + c * rows[k + 1]
    return out


def seat_matrices(support) -> tuple[np.ndarray, np.ndarray]:
    """The bearing's (flexgear.geometry.supports.Support) stiffness and damping on its centre's ground translation
    and rotation (6, 6): sum over its springs at z_k of B_k^T diag(k) B_k, B_k = [I, d_k (e_y, -e_x, 0) columns],
    d_k = z_k - centre_z; damping = damping_per_stiffness x stiffness."""
    k6 = np.zeros((6, 6))
    for z, stiffness in support.spring_points():
        b = _frame_rows(np.array([0.0, 0.0, z - support.centre_z]))[:3]
        k6 += b.T @ np.diag(stiffness) @ b
    return k6, support.damping_per_stiffness * k6


class LinearInterfaceJoint:
    """A fixed joint of ``body`` (interface ``interfaces[0]``) and ``other`` (``interfaces[1]``) at ``point``.

    ``point`` [m, ground frame at the reference] on the z axis; ``spin_per_drive_angle`` the bodies' nominal
    spin per prescribed drive angle. ``obj`` is the constraint; :meth:`turning` gives its blocks that a
    :class:`TurningBlocks` pre-step function turns with the spin.
    """

    def __init__(self, mbs, body: Body, other: Body, interfaces: tuple[str, str], point, spin_per_drive_angle: float,
                 name: str = ""):
        from exudyn.itemInterface import (
            MarkerObjectODE2Coordinates,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        point = np.asarray(point, float)
        if np.hypot(point[0], point[1]) > 1e-9:
            raise ValueError(f"LinearInterfaceJoint {name!r}: the joint point must lie on the z axis, got {point}")
        self.spin = float(spin_per_drive_angle)
        parts, q_ref, markers = [], [], []
        for b, itf, sign in ((body, interfaces[0], -1.0), (other, interfaces[1], 1.0)):
            nodes = [b.node]
            local = point - b.position
            q_ref.append(np.concatenate([b.position, np.zeros(3)]))
            modal = np.zeros((6, 0))
            if b.flexible:  # on the interface's own coordinates when the body has them (FlexibleBody.span)
                modal_nodes, modal = b.span(interface_rows(b, itf, local))
                nodes += modal_nodes
                q_ref.append(np.zeros(modal.shape[1]))
            parts.append((sign, local, modal))
            # one marker per body: Exudyn's constraint costs rows x columns^2 per marker (its dense Jacobian)
            span = mbs.AddObject(ObjectGenericODE2(name=f"{name}_{b.name}_span", nodeNumbers=nodes,
                                                   jacobianUserFunction=zero_user_jacobian(6 + modal.shape[1])))
            markers.append(mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span)))
        self.parts = parts
        self.q_ref = np.concatenate(q_ref)
        self._split = 6 + parts[0][2].shape[1]  # columns of the first body
        c = self.matrix_at(0.0)
        # Exudyn's equation: scalingMarker1 q_1 - scalingMarker0 q_0 - offset = 0
        self.obj = mbs.AddObject(ObjectConnectorCoordinateVector(
            name=name, markerNumbers=markers, scalingMarker0=-c[:, :self._split], scalingMarker1=c[:, self._split:],
            offset=c @ self.q_ref))
        self._moving = [k for k, (_, _, modal) in enumerate(parts) if modal.shape[1]]  # blocks that turn

    def matrix_at(self, phi: float) -> np.ndarray:
        """C (6, columns) at the spin angle ``phi`` [rad]: rows ground translation x, y, z and rotation x, y, z of
        body 2 minus body 1."""
        return self._matrix(np.cos(phi), np.sin(phi))

    def _matrix(self, c: float, s: float) -> np.ndarray:
        blocks = []
        for sign, local, modal in self.parts:
            blocks.append(sign * _frame_rows(local))
            if modal.shape[1]:
                blocks.append(sign * _turned(modal, c, s))
        return np.hstack(blocks)

    def turning(self) -> list[tuple]:
        """The marker blocks whose modal columns turn with the spin (:class:`TurningBlocks` entries): the point
        on the axis, a rigid body's block and the offset C q_ref are constant, written at construction."""
        out = []
        for k, param in ((0, "scalingMarker0"), (1, "scalingMarker1")):
            if k not in self._moving:
                continue
            sign, local, modal = self.parts[k]
            template = np.hstack([_frame_rows(local), np.zeros_like(modal)])  # marker 0 carries -C_a = +rows
            out.append((self.obj, param, template, np.arange(6, 6 + modal.shape[1]), modal, self.spin))
        return out


class LinearSeat:
    """The bearing ``support`` (flexgear.geometry.supports.Support) at the seat of the flexible ``body`` (module
    docstring). ``spin_per_drive_angle``: the body's nominal spin per prescribed drive angle; ``node``: the six
    seat coordinates; :meth:`turning` gives the block that a :class:`TurningBlocks` pre-step function turns.
    """

    def __init__(self, mbs, body: Body, support, spin_per_drive_angle: float):
        from exudyn.itemInterface import (
            MarkerNodeCoordinates,
            MarkerObjectODE2Coordinates,
            NodeGenericODE2,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        self.spin = float(spin_per_drive_angle)
        centre = np.array([0.0, 0.0, support.centre_z])
        modal_nodes, self.rows = body.span(interface_rows(body, support.interface, centre))
        frame = _frame_rows(centre)
        self.node = mbs.AddNode(NodeGenericODE2(name=f"{body.name}_seat", numberOfODE2Coordinates=6,
                                                referenceCoordinates=[0.0] * 6, initialCoordinates=[0.0] * 6,
                                                initialCoordinates_t=[0.0] * 6))
        k6, d6 = seat_matrices(support)
        mbs.AddObject(ObjectGenericODE2(name=f"bearing_{body.name}", nodeNumbers=[self.node],
                                        stiffnessMatrix=matrix_container(k6), dampingMatrix=matrix_container(d6),
                                        jacobianUserFunction=zero_user_jacobian(6)))
        span = mbs.AddObject(ObjectGenericODE2(name=f"{body.name}_seat_span", nodeNumbers=[self.node, body.node],
                                               jacobianUserFunction=zero_user_jacobian(12)))
        # Exudyn's equation: scalingMarker1 q - scalingMarker0 (s, frame) - offset = 0, i.e.
        # R_n Psi q + J_f (frame - reference) - s = 0
        q_ref = np.concatenate([body.position, np.zeros(3)])
        modal = (MarkerNodeCoordinates(nodeNumber=modal_nodes[0]) if len(modal_nodes) == 1 else
                 MarkerObjectODE2Coordinates(objectNumber=mbs.AddObject(ObjectGenericODE2(
                     name=f"{body.name}_seat_modes", nodeNumbers=modal_nodes,
                     jacobianUserFunction=zero_user_jacobian(self.rows.shape[1])))))
        self.obj = mbs.AddObject(ObjectConnectorCoordinateVector(
            name=f"{body.name}_seat_tie",
            markerNumbers=[mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span)), mbs.AddMarker(modal)],
            scalingMarker0=np.hstack([np.eye(6), -frame]), scalingMarker1=self.rows, offset=frame @ q_ref))

    def turning(self) -> list[tuple]:
        """The seat tie's modal block, which turns with the spin (:class:`TurningBlocks` entry)."""
        return [(self.obj, "scalingMarker1", np.zeros_like(self.rows), np.arange(self.rows.shape[1]), self.rows,
                 self.spin)]


class TurningBlocks:
    """Pre-step function: the modal blocks R_n(t) Psi of the linear joints' and seats' constraints (``entries``:
    their :meth:`turning` lists), phi_n = spin x the prescribed drive angle (STEP ramp ``ramp_time`` [s] to
    ``drive_speed`` [rad/s]). Every entry's matrix is a slice of one buffer, its turning columns written by one
    compiled call (flexgear.laws.compiled.turn_columns), then each matrix handed to its constraint."""

    def __init__(self, entries: list[tuple], ramp_time: float, drive_speed: float):
        self.ramp_time, self.drive_speed = float(ramp_time), float(drive_speed)
        self.rows = np.ascontiguousarray(np.hstack([e[4] for e in entries]))  # (6, W)
        self.spin = np.concatenate([np.full(e[4].shape[1], e[5]) for e in entries])
        widths = [e[2].shape[1] for e in entries]
        starts = np.cumsum([0, *widths])
        self.buffer = np.hstack([e[2] for e in entries]).astype(float)  # the templates side by side
        self.dest = np.concatenate([a + e[3] for e, a in zip(entries, starts[:-1], strict=True)]).astype(np.int64)
        # views of the buffer, which the kernel rewrites in place
        self.items = [(e[0], e[1], self.buffer[:, a:b])
                      for e, a, b in zip(entries, starts[:-1], starts[1:], strict=True)]

    def turned(self, t: float) -> np.ndarray:
        """All blocks at time t, column by column (6, W): the numpy reference of the compiled kernel."""
        phi = self.spin * (self.drive_speed * ramp_state(float(t), self.ramp_time)[0])
        c, s = np.cos(phi), np.sin(phi)
        r = self.rows
        out = r.copy()
        for k in (0, 3):
            out[k], out[k + 1] = c * r[k] - s * r[k + 1], s * r[k] + c * r[k + 1]
        return out

    def __call__(self, mbs, t: float) -> bool:
        turn_columns(self.buffer, self.rows, self.spin, self.dest, self.drive_speed * ramp_state(t, self.ramp_time)[0])
        set_parameter = mbs.SetObjectParameter
        for obj, param, matrix in self.items:
            set_parameter(obj, param, matrix)
        return True
