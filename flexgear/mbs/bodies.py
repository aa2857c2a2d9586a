"""Bodies: mass-property algebra and rigid bodies on ``NodeRigidBodyRxyz`` nodes.

Every body, rigid or flexible, has its reference frame on one ``NodeRigidBodyRxyz`` node placed
at the gear centre with the z axis along the rotation axis. Coordinates of that node are
(u_x, u_y, u_z, phi_x, phi_y, phi_z); phi_z is the unwrapped spin angle and, for small tilts,
phi_x and phi_y are the tilt angles in the ground frame (R = R_x(phi_x) R_y(phi_y) R_z(phi_z)).
Bushings, drives and gear contacts act on these frame coordinates, whatever the body's form.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexgear.geometry.massprops import MassProperties, inertia_about_point

__all__ = ["Body", "add_rigid_body", "frame_rows", "matrix_container", "zero_user_jacobian"]


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


def add_rigid_body(mbs, name: str, props: MassProperties, position: np.ndarray) -> Body:
    """Add a rigid body whose frame sits at ``position`` (ground frame axes) [m].

    ``props`` is given in the body frame; Exudyn's ``ObjectRigidBody`` takes the inertia about
    the frame origin and the centre-of-mass offset, so no approximation is involved.
    """
    import exudyn as exu  # noqa: F401  (imported for side effects of the item interface)
    from exudyn.itemInterface import MarkerNodeCoordinates, MarkerNodeRigid, NodeRigidBodyRxyz, ObjectRigidBody
    from exudyn.rigidBodyUtilities import InertiaTensor2Inertia6D

    node = mbs.AddNode(NodeRigidBodyRxyz(name=f"{name}_node", referenceCoordinates=[*position, 0.0, 0.0, 0.0]))
    j_ref = inertia_about_point(props)
    obj = mbs.AddObject(ObjectRigidBody(
        name=name, mass=props.mass, inertia=InertiaTensor2Inertia6D(j_ref),
        centerOfMass=list(np.asarray(props.com, float)), nodeNumber=node,
    ))
    m_rigid = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node))
    m_coords = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=node))
    return Body(name, node, obj, m_rigid, m_coords, np.asarray(position, float), props)


def frame_rows(point: np.ndarray) -> np.ndarray:
    """(6, 6): translation at ``point`` [m] and rotation of a body per frame translation and small rotation
    (u, phi), [I, -p~; 0, I] (u + phi x p, phi)."""
    x, y, z = (float(v) for v in point)
    out = np.eye(6)
    out[:3, 3:] = -np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return out


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
