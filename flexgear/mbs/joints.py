"""Fixed gear-shaft joints as linear constraints about the prescribed spin (``[joints_assumed] joint_equations``).

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
"""

from __future__ import annotations

import numpy as np

from flexgear.laws.ramps import drive_angle
from flexgear.mbs.bodies import Body, zero_user_jacobian

__all__ = ["LinearInterfaceJoint"]

_EZ = np.array([0.0, 0.0, 1.0])


class LinearInterfaceJoint:
    """A fixed joint of ``body`` (interface ``interfaces[0]``) and ``other`` (``interfaces[1]``) at ``point``.

    ``point`` [m, ground frame at the reference] on the z axis; ``spin_per_drive_angle`` the bodies' nominal
    spin per prescribed drive angle (STEP ramp ``ramp_time`` [s] to ``drive_speed`` [rad/s]). ``obj`` is the
    constraint. Call the instance as a pre-step function (mbs, t) -> True.
    """

    def __init__(self, mbs, body: Body, other: Body, interfaces: tuple[str, str], point, spin_per_drive_angle: float,
                 ramp_time: float, drive_speed: float, name: str = ""):
        from exudyn.itemInterface import (
            MarkerObjectODE2Coordinates,
            ObjectConnectorCoordinateVector,
            ObjectGenericODE2,
        )

        point = np.asarray(point, float)
        if np.hypot(point[0], point[1]) > 1e-9:
            raise ValueError(f"LinearInterfaceJoint {name!r}: the joint point must lie on the z axis, got {point}")
        self.spin, self.ramp_time, self.drive_speed = float(spin_per_drive_angle), float(ramp_time), float(drive_speed)
        parts, q_ref, markers = [], [], []
        for b, itf, sign in ((body, interfaces[0], -1.0), (other, interfaces[1], 1.0)):
            nodes = [b.node]
            local = point - b.position
            q_ref.append(np.concatenate([b.position, np.zeros(3)]))
            modal = np.zeros((6, 0))
            if b.flexible:
                red = b.reduced
                motion = red.interface_motion(itf)  # (6, m) RBE3 translation and rotation at the interface point
                arm = local - red.interface(itf).point
                trans = motion[:3] + np.cross(motion[3:].T, arm).T  # translation at the joint point
                modal = np.vstack([trans, motion[3:]])
                nodes.append(b.modal_node)
                q_ref.append(np.zeros(red.n_modes))
            parts.append((sign, local, modal))
            # one marker per body: Exudyn's constraint costs rows x columns^2 per marker (its dense Jacobian)
            span = mbs.AddObject(ObjectGenericODE2(name=f"{name}_{b.name}_span", nodeNumbers=nodes,
                                                   jacobianUserFunction=zero_user_jacobian(6 + modal.shape[1])))
            markers.append(mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span)))
        self.parts = parts
        self._parts: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.q_ref = np.concatenate(q_ref)
        self._split = 6 + parts[0][2].shape[1]  # columns of the first body
        c = self.matrix_at(0.0)
        # Exudyn's equation: scalingMarker1 q_1 - scalingMarker0 q_0 - offset = 0
        self.obj = mbs.AddObject(ObjectConnectorCoordinateVector(
            name=name, markerNumbers=markers, scalingMarker0=-c[:, :self._split], scalingMarker1=c[:, self._split:],
            offset=c @ self.q_ref))
        self._moving = [k for k, (_, _, modal) in enumerate(parts) if modal.shape[1]]  # blocks that turn

    def matrix_at(self, t: float) -> np.ndarray:
        """C(t) (6, columns): rows ground translation x, y, z and rotation x, y, z of body 2 minus body 1."""
        phi = self.spin * float(drive_angle(t, self.ramp_time, self.drive_speed))
        return self._matrix(np.cos(phi), np.sin(phi))

    def _matrix(self, c: float, s: float) -> np.ndarray:
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        blocks = []
        for sign, local, modal in self.parts:
            frame = np.zeros((6, 6))
            frame[:3, :3] = np.eye(3)
            lever = rot @ local
            frame[:3, 3:] = -np.array([[0.0, -lever[2], lever[1]], [lever[2], 0.0, -lever[0]],
                                       [-lever[1], lever[0], 0.0]])  # d(phi x lever)/d phi = -lever~
            frame[3:, 3:] = np.eye(3)
            blocks.append(sign * frame)
            if modal.shape[1]:
                blocks.append(sign * np.vstack([rot @ modal[:3], rot @ modal[3:]]))
        return np.hstack(blocks)

    def __call__(self, mbs, t: float) -> bool:
        """Pre-step: C(t) = C_0 + cos(phi_n) C_c + sin(phi_n) C_s into the flexible bodies' markers (the point
        on the axis: a rigid body's block and the offset C q_ref are constant, written at construction)."""
        if self._parts is None:
            c0 = self._matrix(0.0, 0.0)
            self._parts = (c0, self._matrix(1.0, 0.0) - c0, self._matrix(0.0, 1.0) - c0)
        phi = self.spin * float(drive_angle(t, self.ramp_time, self.drive_speed))
        c0, cc, cs = self._parts
        c = c0 + np.cos(phi) * cc + np.sin(phi) * cs
        if 0 in self._moving:
            mbs.SetObjectParameter(self.obj, "scalingMarker0", -c[:, :self._split])
        if 1 in self._moving:
            mbs.SetObjectParameter(self.obj, "scalingMarker1", c[:, self._split:])
        return True
