"""Flexible bodies in Exudyn: a reduced body (flexgear.fe.cms) as ``ObjectFFRFreducedOrder``, and its cache.

The body's reference frame is a ``NodeRigidBodyRxyz`` node exactly like a rigid body's
(flexgear.mbs.bodies): bushings, drives and gear contacts attach to the frame coordinates whatever the
body's form. The flexible coordinates are the reduced free-free modes, M-orthogonal to the rigid
modes (Tisserand mean axes), on a ``NodeGenericODE2``. Interfaces get ``MarkerSuperElementRigid``
markers for fixed joints. A marker over an interface's real node set (~1 400 nodes) cost 230x a
frame bushing per step in the prototype, so the marker acts on six virtual nodes that carry the
interface's RBE3 motion exactly (:func:`interface_virtual_nodes`).

Cache: ``cached_reduced_body(key, build)`` stores the reduced body as ``meshes/reduced-<key>.npz``
(atomic write); the key must hash every input (geometry, mesh, reduction settings, versions).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from flexgear.fe.cms import ReducedBody
from flexgear.mbs.bodies import Body, matrix_container

__all__ = ["FlexibleBody", "add_flexible_body", "interface_virtual_nodes", "interface_point_modes"]



@dataclass(frozen=True)
class FlexibleBody(Body):
    """Handles of a flexible body: a :class:`flexgear.mbs.bodies.Body` plus modal node and interface markers."""

    modal_node: int = -1
    interface_markers: dict[str, int] = field(default_factory=dict)
    reduced: ReducedBody | None = None
    point_markers: dict[str, list[int]] = field(default_factory=dict)  # interface -> position markers
    # modes of the converged basis left out of the time integration (flexgear.mbs.residual.DroppedModes);
    # their static compliance returns at the contacts
    dropped: object | None = None
    # floating_frame = "linear": the body's spin terms (flexgear.mbs.spin.SpinMatrices) and nominal spin [rad/s]
    spin: object | None = None
    nominal_spin_rad_s: float = 0.0
    modal_equations: int = -1  # their ObjectGenericODE2 ("linear")
    superelement: bool = True  # an ObjectFFRFreducedOrder places markers and mesh nodes (else ``obj`` is the frame)
    modal_damping: np.ndarray | None = None  # diagonal of D [1/s] ("linear")


def interface_virtual_nodes(reduced: ReducedBody, name: str, point=None, arm: float = 0.01):
    """Six virtual mesh nodes that carry the RBE3 motion of interface ``name`` as a rigid pattern.

    Nodes at ``point`` +- ``arm`` e_k (body frame [m]; default the interface's RBE3 point) whose
    displacements are the interface's rigid motion u = t + theta x (x - p) with (t, theta) =
    ``reduced.interface_motion(name) @ q``. A ``MarkerSuperElementRigid`` with equal weights on them
    moves exactly as the RBE3 marker over the interface's real node set (same weighted least-squares
    rotation), at the cost of six nodes instead of hundreds. Returns (positions (6, 3), modes (18, m)).
    """
    p = reduced.interface(name).point if point is None else np.asarray(point, float)
    positions = np.array([p + sign * arm * np.eye(3)[k] for k in range(3) for sign in (1.0, -1.0)])
    return positions, interface_point_modes(reduced, name, positions)


def interface_point_modes(reduced: ReducedBody, name: str, points) -> np.ndarray:
    """(3 n_points, m) displacements of ``points`` [m, body frame] moving rigidly with interface ``name``.

    u = t + theta x (x - p) per mode, (t, theta) = ``reduced.interface_motion(name)``, p its RBE3 point.
    """
    itf = reduced.interface(name)
    motion = reduced.interface_motion(name)
    t, th = motion[:3], motion[3:]
    return np.vstack([t + np.cross(th, np.asarray(x, float) - itf.point, axis=0) for x in points])


def add_flexible_body(mbs, name: str, reduced: ReducedBody, position, rotation_matrix=None,
                      velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
                      stiffness_damping_s: float = 0.0, mass_damping_per_s: float = 0.0,
                      interface_markers: list[str] | dict[str, np.ndarray] | None = None,
                      point_markers: dict[str, list] | None = None, show: bool = True,
                      floating_frame: str = "ffrf", nominal_spin_rad_s: float = 0.0,
                      superelement: bool = True) -> FlexibleBody:
    """Add ``reduced`` as an ``ObjectFFRFreducedOrder`` whose frame node sits at ``position`` [m].

    ``rotation_matrix`` (3, 3) body-to-ground (default identity); ``velocity`` [m/s] and
    ``angular_velocity`` [rad/s, ground frame] are initial values of the frame. Damping of the
    flexible coordinates D = mass_damping_per_s * M_r + stiffness_damping_s * K_r (Rayleigh).
    ``interface_markers``: interfaces that get a ``MarkerSuperElementRigid`` (default all), as names
    (marker at the interface's RBE3 point) or as {name: marker point in the body frame [m]}. The
    markers act on six virtual nodes per interface (:func:`interface_virtual_nodes`) appended to the
    mode basis; the floating-frame inertia terms come from the real mesh only. ``point_markers``:
    {interface: points [m, body frame]}: one virtual node per point moving rigidly with the interface
    (:func:`interface_point_modes`) and a ``MarkerSuperElementPosition`` on it (bearing springs at a seat).
    ``floating_frame``: "ffrf" (Exudyn's nonlinear floating-frame terms) or "linear" (flexgear.mbs.spin: the
    frame an ``ObjectRigidBody``, the modes linear equations at ``nominal_spin_rad_s`` about the body's z
    axis; the object then only places the markers; add a flexgear.mbs.spin.SpinSchedule for the ramp).
    ``superelement`` False ("linear" only): no ``ObjectFFRFreducedOrder`` at all (no interface or point markers,
    no mesh-node sensors; its zero mass matrix cost ~7 % of model 7's step); ``obj`` is then the frame's rigid body.
    """
    import exudyn as exu
    from exudyn.itemInterface import (
        MarkerNodeCoordinates,
        MarkerNodeRigid,
        MarkerSuperElementPosition,
        MarkerSuperElementRigid,
        NodeGenericODE2,
        ObjectFFRFreducedOrder,
        VObjectFFRFreducedOrder,
    )
    from exudyn.rigidBodyUtilities import GetRigidBodyNode

    rot = np.eye(3) if rotation_matrix is None else np.asarray(rotation_matrix, float)
    node_item = GetRigidBodyNode(nodeType=exu.NodeType.RotationRxyz, position=list(map(float, position)),
                                 velocity=list(map(float, velocity)), rotationMatrix=rot,
                                 angularVelocity=list(map(float, angular_velocity)))
    node_item.name = f"{name}_node"
    node = mbs.AddNode(node_item)
    m = reduced.n_modes
    modal = mbs.AddNode(NodeGenericODE2(name=f"{name}_modes", numberOfODE2Coordinates=m,
                                        referenceCoordinates=[0.0] * m, initialCoordinates=[0.0] * m,
                                        initialCoordinates_t=[0.0] * m))

    if floating_frame not in ("ffrf", "linear"):
        raise ValueError(f"floating_frame must be 'ffrf' or 'linear', got {floating_frame!r}")
    if not superelement and (floating_frame == "ffrf" or interface_markers or point_markers):
        raise ValueError(f"{name}: a body without superelement needs floating_frame 'linear' and no markers")
    if not superelement:
        interface_markers = []
    if interface_markers is None:
        interface_markers = [i.name for i in reduced.interfaces]
    points = (dict(interface_markers) if isinstance(interface_markers, dict)
              else {n: None for n in interface_markers})
    positions, modes, first = [reduced.nodes], [reduced.modes], {}
    count = len(reduced.nodes)
    for itf_name, point in points.items():
        x, rows = interface_virtual_nodes(reduced, itf_name, point)
        first[itf_name] = count
        positions.append(x)
        modes.append(rows)
        count += len(x)
    point_first = {}
    for itf_name, pts in (point_markers or {}).items():
        point_first[itf_name] = (count, len(pts))
        positions.append(np.asarray(pts, float).reshape(-1, 3))
        modes.append(interface_point_modes(reduced, itf_name, pts))
        count += len(pts)
    damping = mass_damping_per_s + stiffness_damping_s * reduced.stiffness
    inv = reduced.invariants
    obj = -1 if not superelement else mbs.AddObject(ObjectFFRFreducedOrder(
        name=name, nodeNumbers=[node, modal],
        massMatrixReduced=matrix_container(np.eye(m)),
        stiffnessMatrixReduced=matrix_container(np.diag(reduced.stiffness)),
        dampingMatrixReduced=matrix_container(np.diag(damping)) if np.any(damping) else [],
        modeBasis=np.vstack(modes), referencePositions=np.vstack(positions).ravel(),
        mass=float(inv["mass"]), inertia=inv["inertia"], centerOfMass=inv["centerOfMass"],
        mPsiTildePsi=inv["mPsiTildePsi"], mPsiTildePsiTilde=inv["mPsiTildePsiTilde"],
        mPhitTPsi=inv["mPhitTPsi"], mPhitTPsiTilde=inv["mPhitTPsiTilde"],
        mXRefTildePsi=inv["mXRefTildePsi"], mXRefTildePsiTilde=inv["mXRefTildePsiTilde"],
        computeFFRFterms=floating_frame == "ffrf",
        visualization=VObjectFFRFreducedOrder(show=show, triangleMesh=reduced.surface_triangles if show else []),
    ))
    spin, equations = None, -1
    if floating_frame == "linear":
        from exudyn.itemInterface import ObjectRigidBody
        from exudyn.rigidBodyUtilities import InertiaTensor2Inertia6D

        from flexgear.mbs.spin import add_linear_modal_equations, spin_matrices

        # the inertia about the frame origin, as flexgear.mbs.bodies.add_rigid_body (exact mass properties)
        frame = mbs.AddObject(ObjectRigidBody(name=f"{name}_frame", nodeNumber=node, mass=float(inv["mass"]),
                                      inertia=InertiaTensor2Inertia6D(inv["inertia"]),
                                      centerOfMass=list(map(float, inv["centerOfMass"]))))
        spin = spin_matrices(reduced)
        # at rest: flexgear.mbs.spin.SpinSchedule moves the spin terms with the ramp
        equations = add_linear_modal_equations(mbs, name, modal, reduced.stiffness, damping, spin, 0.0)
        obj = obj if superelement else frame
    markers = {}
    for itf_name, start in first.items():
        markers[itf_name] = mbs.AddMarker(MarkerSuperElementRigid(
            name=f"{name}_{itf_name}", bodyNumber=obj, offset=[0.0, 0.0, 0.0],
            meshNodeNumbers=np.arange(start, start + 6, dtype=np.int64), weightingFactors=np.full(6, 1.0 / 6.0),
            useAlternativeApproach=True, visualization={"show": False, "showMarkerNodes": False}))
    points = {itf_name: [mbs.AddMarker(MarkerSuperElementPosition(
        name=f"{name}_{itf_name}_point{k}", bodyNumber=obj, meshNodeNumbers=[start + k], weightingFactors=[1.0],
        visualization={"show": False, "showMarkerNodes": False})) for k in range(n)]
        for itf_name, (start, n) in point_first.items()}
    m_rigid = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node))
    m_coords = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=node))
    return FlexibleBody(name, node, obj, m_rigid, m_coords, np.asarray(position, float), reduced.props, True,
                        modal, markers, reduced, points, spin=spin, nominal_spin_rad_s=float(nominal_spin_rad_s),
                        modal_equations=equations, modal_damping=np.broadcast_to(damping, (m,)).copy(),
                        superelement=superelement)




