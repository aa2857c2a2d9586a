"""Bodies: mass-property algebra and rigid bodies on ``NodeRigidBodyRxyz`` nodes.

Every body, rigid or flexible, has its reference frame on one ``NodeRigidBodyRxyz`` node placed
at the gear centre with the z axis along the rotation axis. Coordinates of that node are
(u_x, u_y, u_z, phi_x, phi_y, phi_z); phi_z is the unwrapped spin angle and, for small tilts,
phi_x and phi_y are the tilt angles in the ground frame (R = R_x(phi_x) R_y(phi_y) R_z(phi_z)).
Bearings on frames, drives and gear contacts act on these frame coordinates, whatever the body's form.

The frame's inertia is, in the production formulation, :func:`add_linear_frame`: the same body to first order
in the tilts about its prescribed spin Omega,

    M q'' + Omega J_p E q' = Q,    E = e_phix e_phiy^T - e_phiy e_phix^T,

M (6 x 6, constant) the mass matrix of the axisymmetric body at the reference, [m I, -m c~; m c~, J_O]
(c = (0, 0, c_z) the centre of mass on the axis, J_O = diag(J_t, J_t, J_p) about the frame origin), and the
gyroscopic term of a body spinning at Omega about its tilted axis (kinetic energy of R = R_x R_y R_z to second
order: 1/2 J_t (phi_x'^2 + phi_y'^2) + 1/2 J_p phi_z'^2 + J_p phi_y phi_x' phi_z'). Every body's mass matrix is then
constant and Exudyn computes it once per run. Left out: the lateral centre-of-mass offset and the inertia's
asymmetry of the meshed body (< ``frame_axisymmetry_tolerance``; a body beyond it, such as a carrier with unequally
spaced planets, takes Exudyn's exact ``ObjectRigidBody``), terms of second order in the tilts.
The reference formulation uses Exudyn's ``ObjectRigidBody`` (exact; its mass matrix depends on the angles, so
Exudyn rebuilds the whole system's mass matrix in every Newton iteration).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexgear.geometry.elements import lever_rows
from flexgear.geometry.massprops import MassProperties, inertia_about_point

__all__ = ["Body", "LinearFrame", "add_frame_inertia", "add_linear_frame", "add_rigid_body", "axisymmetric_frame_mass",
           "frame_asymmetry", "frame_rows", "matrix_container", "zero_user_jacobian"]


@dataclass(frozen=True)
class LinearFrame:
    """A body frame's inertia as constant matrices (:func:`add_linear_frame`)."""

    obj: int  # its ObjectGenericODE2 on the frame node
    polar_inertia: float  # J_p about the spin axis [kg m^2]
    spin_rad_s: float  # nominal spin Omega_n [rad/s]

    def gyroscopic(self, spin_rad_s: float) -> np.ndarray:
        """(6, 6) Omega J_p E at the spin ``spin_rad_s`` [rad/s] (module docstring)."""
        out = np.zeros((6, 6))
        out[3, 4], out[4, 3] = spin_rad_s * self.polar_inertia, -spin_rad_s * self.polar_inertia
        return out


@dataclass(frozen=True)
class Body:
    """Handles of one body in an Exudyn system (rigid or flexible)."""

    name: str
    node: int  # NodeRigidBodyRxyz of the body frame
    obj: int  # the body object
    marker_rigid: int  # MarkerNodeRigid on the frame node
    marker_coordinates: int  # MarkerNodeCoordinates on the frame node
    position: np.ndarray  # reference position of the frame [m]
    props: MassProperties
    flexible: bool = False
    frame: LinearFrame | None = None  # the frame's constant inertia (production), None for ObjectRigidBody


def add_rigid_body(mbs, name: str, props: MassProperties, position: np.ndarray, spin_rad_s: float = 0.0,
                   linear_frame_tolerance: float | None = None) -> Body:
    """Add a rigid body whose frame sits at ``position`` (ground frame axes) [m].

    ``props`` is given in the body frame; its inertia about the frame origin and centre-of-mass offset go to
    :func:`add_frame_inertia` (``spin_rad_s`` the nominal spin [rad/s], ``linear_frame_tolerance`` its choice).
    """
    import exudyn as exu  # noqa: F401  (imported for side effects of the item interface)
    from exudyn.itemInterface import MarkerNodeCoordinates, MarkerNodeRigid, NodeRigidBodyRxyz

    node = mbs.AddNode(NodeRigidBodyRxyz(name=f"{name}_node", referenceCoordinates=[*position, 0.0, 0.0, 0.0]))
    obj, frame = add_frame_inertia(mbs, name, node, props.mass, props.com, inertia_about_point(props), spin_rad_s,
                                   linear_frame_tolerance)
    m_rigid = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node))
    m_coords = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=node))
    return Body(name, node, obj, m_rigid, m_coords, np.asarray(position, float), props, frame=frame)


def add_frame_inertia(mbs, label: str, node: int, mass: float, com, inertia, spin_rad_s: float,
                      linear_frame_tolerance: float | None) -> tuple[int, LinearFrame | None]:
    """The inertia of a body frame on ``node``: ``mass`` [kg], ``com`` [m] and ``inertia`` [kg m^2] about the frame
    origin (body axes). ``linear_frame_tolerance`` None, or a body less axisymmetric than it
    (:func:`frame_asymmetry`, e.g. a carrier with unequally spaced planets): Exudyn's ``ObjectRigidBody`` named
    ``label`` (exact); else :func:`add_linear_frame` at the nominal spin ``spin_rad_s`` [rad/s].
    Returns (object, its LinearFrame or None)."""
    from exudyn.itemInterface import ObjectRigidBody
    from exudyn.rigidBodyUtilities import InertiaTensor2Inertia6D

    if linear_frame_tolerance is None or frame_asymmetry(mass, com, inertia) > linear_frame_tolerance:
        return mbs.AddObject(ObjectRigidBody(name=label, nodeNumber=node, mass=float(mass),
                                             inertia=InertiaTensor2Inertia6D(np.asarray(inertia, float)),
                                             centerOfMass=[float(v) for v in com])), None
    frame = add_linear_frame(mbs, label, node, mass, com, inertia, spin_rad_s, linear_frame_tolerance)
    return frame.obj, frame


def frame_asymmetry(mass: float, com, inertia) -> float:
    """What the linear frame leaves out, relative: the largest of the lateral centre-of-mass offset over the radius
    of gyration sqrt(J_p / m), and an off-diagonal of the inertia ``inertia`` [kg m^2] about the frame origin or
    J_xx - J_yy over J_p (``mass`` [kg], ``com`` [m])."""
    c, j = np.asarray(com, float), np.asarray(inertia, float)
    polar = float(j[2, 2])
    return max(float(np.hypot(c[0], c[1])) / np.sqrt(polar / mass), abs(j[0, 0] - j[1, 1]) / polar,
               *(abs(j[a, b]) / polar for a, b in ((0, 1), (0, 2), (1, 2))))


def axisymmetric_frame_mass(mass: float, com, inertia, tolerance: float, name: str = "body"
                            ) -> tuple[np.ndarray, float]:
    """(M (6, 6), J_p) of the module docstring from ``mass`` [kg], ``com`` [m] and ``inertia`` [kg m^2] about the
    frame origin (body axes): the axisymmetric part. Raises ValueError when the dropped part exceeds ``tolerance``:
    the lateral centre-of-mass offset relative to the radius of gyration sqrt(J_p/m), or an off-diagonal or
    J_xx - J_yy relative to J_p."""
    c, j = np.asarray(com, float), np.asarray(inertia, float)
    polar = float(j[2, 2])
    defect = frame_asymmetry(mass, com, inertia)
    if defect > tolerance:
        raise ValueError(f"{name}: a linear frame needs an axisymmetric body; its asymmetry {defect:.2e} exceeds "
                         f"[solver_assumed] frame_axisymmetry_tolerance = {tolerance:g}")
    b = frame_rows(np.array([0.0, 0.0, c[2]]))[:3]
    out = mass * b.T @ b
    out[3:, 3:] = np.diag([0.5 * (j[0, 0] + j[1, 1])] * 2 + [polar])
    return out, polar


def add_linear_frame(mbs, name: str, node: int, mass: float, com, inertia, spin_rad_s: float,
                     tolerance: float) -> LinearFrame:
    """The frame's inertia on ``node`` as one ``ObjectGenericODE2`` named ``name`` (module docstring): constant mass
    (:func:`axisymmetric_frame_mass`), the gyroscopic term at rest (flexgear.mbs.spin.SpinSchedule moves it
    with the ramp); ``spin_rad_s`` the nominal spin [rad/s]."""
    from exudyn.itemInterface import ObjectGenericODE2

    m6, polar = axisymmetric_frame_mass(mass, com, inertia, tolerance, name)
    obj = mbs.AddObject(ObjectGenericODE2(name=name, nodeNumbers=[node], massMatrix=matrix_container(m6),
                                          dampingMatrix=matrix_container(np.zeros((6, 6))),
                                          jacobianUserFunction=zero_user_jacobian(6)))
    return LinearFrame(obj, polar, float(spin_rad_s))


def frame_rows(point: np.ndarray) -> np.ndarray:
    """(6, 6): translation at ``point`` [m] and rotation of a body per frame translation and small rotation
    (u, phi), [I, -p~; 0, I] (u + phi x p, phi): the rigid lever from the frame origin to ``point``
    (flexgear.geometry.elements.lever_rows)."""
    return lever_rows(point)


def normal_lever(point: np.ndarray, normal: np.ndarray, about: np.ndarray) -> np.ndarray:
    """(n, (x - p) x n) [-, m]: the motion along ``normal`` n at ``point`` x per rigid translation and small
    rotation about ``about`` p (the transpose of :func:`frame_rows`' translation rows on n); equally the force and
    moment about p of a unit force along n at x. Broadcasts over leading axes (..., 3) -> (..., 6)."""
    normal = np.asarray(normal, float)
    arm = np.asarray(point, float) - np.asarray(about, float)
    return np.concatenate(np.broadcast_arrays(normal, np.cross(arm, normal)), axis=-1)


def motion_at_point(motion: np.ndarray, origin: np.ndarray, point: np.ndarray) -> np.ndarray:
    """(6, m) rigid motions, translation [m] at ``origin`` and rotation [rad], moved to translation at ``point``
    (t + theta x (point - origin), theta)."""
    arm = np.asarray(point, float) - np.asarray(origin, float)
    return np.vstack([motion[:3] + np.cross(motion[3:].T, arm).T, motion[3:]])


def resting_node(mbs, name: str, n: int) -> int:
    """A ``NodeGenericODE2`` of ``n`` coordinates, reference, initial value and rate zero."""
    from exudyn.itemInterface import NodeGenericODE2

    zeros = [0.0] * n
    return mbs.AddNode(NodeGenericODE2(name=name, numberOfODE2Coordinates=n, referenceCoordinates=zeros,
                                       initialCoordinates=zeros, initialCoordinates_t=zeros))


def matrix_container(a: np.ndarray, dense: bool = False):
    """An (n, n) array as Exudyn's ``MatrixContainer``: sparse triplets (its zeros dropped) or, ``dense``, a dense
    matrix (for a filled block: Exudyn's triplet product then costs several times the dense one)."""
    import exudyn as exu

    mc = exu.MatrixContainer()
    mc.SetWithDenseMatrix(np.asarray(a, float), useDenseMatrix=bool(dense))
    return mc


def zero_user_jacobian(n: int, dense: bool = False):
    """A ``jacobianUserFunction`` for an ``ObjectGenericODE2`` of ``n`` coordinates without user forces.

    Exudyn differentiates an ``ObjectGenericODE2`` numerically (n evaluations of its equations per
    Jacobian) unless it has this function; its constant stiffness and damping matrices (sparse) are then
    added to the Jacobian exactly. Returns the function (it returns an all-zero matrix, ``dense`` as the
    object's matrices: Exudyn requires the same format).
    """
    import exudyn as exu

    zero = exu.MatrixContainer()
    if dense:
        zero.SetWithDenseMatrix(np.zeros((n, n)), useDenseMatrix=True)
    else:
        zero.SetWithSparseMatrixCSR(n, n, np.zeros((0, 3)), useDenseMatrix=False)

    def jacobian(mbs, t, item, q, q_t, f_ode2, f_ode2_t):  # noqa: ARG001 (Exudyn's signature)
        return zero

    return jacobian
