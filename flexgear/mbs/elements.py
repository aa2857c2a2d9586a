"""Linear elements and supports on bodies: bearings, fixed joints, speed drive, load torque.

Element contract (flexgear.geometry.elements): a bearing is a 6x6 stiffness and damping matrix about a point on
a body's axis with its DOF map (:class:`BearingElement`). Bearings on body frames are moved to the frame origin
(:meth:`BearingElement.at`) and summed into one ``ObjectGenericODE2`` over the frame nodes
(:func:`add_linear_elements`); a fixed joint (:class:`FixedJointElement`) holds two interfaces together
(:func:`add_interface_joint`). Bearings where they are (:func:`add_support`), the drive and
the load at an interface (:func:`interface_spin_marker`) act through the interface's exact virtual-node
motion for a flexible body (flexgear.mbs.flexible) and at the same point of a rigid body.
"""

from __future__ import annotations

import numpy as np

from flexgear.deprecation import moved
from flexgear.geometry.elements import BearingElement, FixedJointElement
from flexgear.laws.ramps import drive_angle, ramp_fraction
from flexgear.mbs.bodies import Body, matrix_container, resting_node, zero_user_jacobian

_DEPRECATED = {"Bushing": ("BearingElement.axisymmetric", "0.3")}
"""This module's moved names: old name -> (new name in flexgear, removal version), as ``flexgear._DEPRECATED``."""


def __getattr__(name: str):
    """A moved name (``_DEPRECATED``, PEP 562) gives its new object with a DeprecationWarning."""
    if name in _DEPRECATED:
        return moved(__name__, name, *_DEPRECATED[name])
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def add_linear_elements(mbs, bodies: list[Body], elements: list[BearingElement], extra_nodes: list[int] | None = None,
                        extra_size: int = 0) -> tuple[int, int]:
    """Sum the bearings' matrices, each moved to its body's frame origin (:meth:`BearingElement.at`), into one
    ``ObjectGenericODE2`` over the bodies' frame nodes (each bearing to ground, on the body frame: no interface).

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
            raise KeyError(f"bearing on unknown body {e.body!r}; bodies: {sorted(index)}")
        if e.other is not None or e.interface is not None:
            raise ValueError(f"bearing on {e.body!r}: frame elements act between a body frame and ground "
                             f"(other={e.other!r}, interface={e.interface!r}); use add_support or add_planet_bearing")
        s = slice(6 * index[e.body], 6 * index[e.body] + 6)
        at_frame = e.at(np.zeros(3))
        stiffness[s, s] += at_frame.stiffness
        damping[s, s] += at_frame.damping
    obj = mbs.AddObject(ObjectGenericODE2(
        name="frame_elements", nodeNumbers=[b.node for b in bodies] + list(extra_nodes or []),
        stiffnessMatrix=matrix_container(stiffness), dampingMatrix=matrix_container(damping), forceVector=np.zeros(n),
        jacobianUserFunction=zero_user_jacobian(n),
    ))
    marker = mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=obj))
    return obj, marker


def add_support(mbs, body: Body, bearing: BearingElement, other: Body | None = None,
                other_interface: str | None = None) -> list[int]:
    """The bearing ``bearing`` (acting on ``body``, ground on the other side) where it is.

    Rigid body on a linear frame (flexgear.mbs.bodies.add_linear_frame): the 6 x 6 bearing on its frame
    coordinates (flexgear.mbs.joints.add_frame_bearing). Otherwise the bearing realised as its three spring-dampers
    on the axis (:meth:`BearingElement.axis_springs`): ``ObjectConnectorCartesianSpringDamper`` from ground to a
    ``MarkerSuperElementPosition`` on a virtual node moving rigidly with the interface ``bearing.interface`` of a
    flexible body (``FlexibleBody.point_markers``, placed at the same points, :func:`support_points`) or a
    body-fixed marker of a rigid body. Points on the axis: the spin does not move them, so the bearing leaves the
    spin free and damps only translation and tilt. ``other``: the rigid body on the bearing's other side
    (``bearing.other``; a planet's pin on a turning carrier), whose points at the same places replace ground (the
    springs are isotropic about the axis: the carrier's turning does not change them); a flexible ``other`` (a
    flexible carrier) gives its point markers on ``other_interface`` (its pin), placed at the same points. Returns
    the connectors.
    """
    from exudyn.itemInterface import (
        MarkerBodyPosition,
        MarkerNodePosition,
        NodePointGround,
        ObjectConnectorCartesianSpringDamper,
        VObjectConnectorCartesianSpringDamper,
    )

    if other is None:
        bearing.check_to_ground(body.name)
    elif (bearing.body, bearing.other) != (body.name, other.name) or (other.flexible and other_interface is None):
        raise ValueError(f"bearing of {bearing.body!r} on {bearing.other!r} placed on {body.name!r} and "
                         f"{other.name!r}{' (flexible: name its interface)' if other.flexible else ''}")
    if body.frame is not None and not body.flexible and other is None:  # a linear frame: one linear bearing
        from flexgear.mbs.joints import add_frame_bearing

        return [add_frame_bearing(mbs, body, bearing)]
    springs = bearing.axis_springs()
    if body.flexible:
        markers = body.point_markers.get(bearing.interface, [])
        if len(markers) != len(springs):
            raise KeyError(f"flexible body {body.name!r} needs {len(springs)} point markers on interface "
                           f"{bearing.interface!r} (add_flexible_body point_markers); has {len(markers)}")
    else:
        markers = [mbs.AddMarker(MarkerBodyPosition(bodyNumber=body.obj, localPosition=[float(v) for v in sp.point]))
                   for sp in springs]
    bases = []
    if other is not None and other.flexible:
        bases = other.point_markers.get(other_interface, [])
        if len(bases) != len(springs):
            raise KeyError(f"flexible body {other.name!r} needs {len(springs)} point markers on interface "
                           f"{other_interface!r} (add_flexible_body point_markers); has {len(bases)}")
    out = []
    for k, (spring, marker) in enumerate(zip(springs, markers, strict=True)):
        place = body.position + spring.point
        if other is None:
            base = mbs.AddMarker(MarkerNodePosition(nodeNumber=mbs.AddNode(NodePointGround(
                referenceCoordinates=list(map(float, place))))))
        elif bases:
            base = bases[k]
        else:
            base = mbs.AddMarker(MarkerBodyPosition(bodyNumber=other.obj,
                                                    localPosition=[float(v) for v in place - other.position]))
        out.append(mbs.AddObject(ObjectConnectorCartesianSpringDamper(
            name=f"bearing_{body.name}{bearing.tag}_{k}", markerNumbers=[base, marker],
            stiffness=[float(v) for v in spring.stiffness], damping=[float(v) for v in spring.damping],
            visualization=VObjectConnectorCartesianSpringDamper(show=False))))
    return out


def support_points(bearing: BearingElement) -> list[np.ndarray]:
    """Points [m, body frame] of the bearing's axis springs: the ``point_markers`` a flexible body needs."""
    return [np.array(sp.point) for sp in bearing.axis_springs()]


def interface_spin_marker(mbs, body: Body, interface: str | None) -> tuple[int, int, int]:
    """A coordinate marker on the spin angle of ``body`` at ``interface`` [rad]: drive and load act on it.

    Rigid body (or ``interface`` None): the frame's spin coordinate. Flexible body: an auxiliary coordinate s
    tied by one linear constraint to s = phi_z + r . q, r the interface's elastic rotation about the axis per
    modal coordinate (``ReducedBody.interface_motion`` row 5, the rotation its RBE3 virtual-node marker
    carries; first order in the elastic rotation and tilt). A torque on s reaches the body there.
    Returns (marker, node, coordinate index in the node) of that spin angle.
    """
    from exudyn.itemInterface import (
        MarkerNodeCoordinate,
        MarkerNodeCoordinates,
        MarkerObjectODE2Coordinates,
        ObjectConnectorCoordinateVector,
        ObjectGenericODE2,
    )

    if interface is None or not body.flexible:
        return mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=body.node, coordinate=5)), body.node, 5
    modal_nodes, r = body.span(body.reduced.interface_motion(interface)[5][None, :])
    spin = resting_node(mbs, f"{body.name}_{interface}_spin", 1)
    span = mbs.AddObject(ObjectGenericODE2(name=f"{body.name}_{interface}_span",
                                           nodeNumbers=[body.node, *modal_nodes],
                                           jacobianUserFunction=zero_user_jacobian(6 + r.shape[1])))
    row = np.concatenate([np.eye(6)[5], r[0]])[None, :]
    mbs.AddObject(ObjectConnectorCoordinateVector(
        name=f"{body.name}_{interface}_spin_tie",
        markerNumbers=[mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=spin)),
                       mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=span))],
        scalingMarker0=np.ones((1, 1)), scalingMarker1=row, offset=np.zeros(1)))
    return mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=spin, coordinate=0)), spin, 0


def add_speed_drive(mbs, body: Body, ramp_time: float, speed: float, marker: int | None = None) -> int:
    """Prescribe the spin angle of ``body`` (or the coordinate of ``marker``, :func:`interface_spin_marker`)
    to the STEP speed ramp's integral (position level).

    Returns the constraint; its ``Force`` output is the drive torque [N·m].
    """
    from exudyn import symbolic as esym
    from exudyn.itemInterface import MarkerNodeCoordinate, NodePointGround, ObjectConnectorCoordinate
    from exudyn.utilities import CreateSymbolicUserFunction

    ground = mbs.AddNode(NodePointGround())
    m0 = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    m1 = marker if marker is not None else mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=body.node, coordinate=5))
    drive = mbs.AddObject(ObjectConnectorCoordinate(name="drive", markerNumbers=[m0, m1]))

    def offset(mbs, t, itemNumber, lOffset):  # noqa: N803
        return drive_angle(t, ramp_time, speed, esym)

    fn = CreateSymbolicUserFunction(mbs, offset, "offsetUserFunction", drive)
    mbs.SetObjectParameter(drive, "offsetUserFunction", fn)
    keep_alive(mbs, [fn])
    return drive


def add_load_torque(mbs, body: Body, torque: float, ramp_time: float, marker: int | None = None) -> int:
    """Torque ``torque`` [N·m] about the body's spin axis (or on the coordinate of ``marker``,
    :func:`interface_spin_marker`), ramped by STEP(t, 0, 0, T, 1)."""
    from exudyn import symbolic as esym
    from exudyn.itemInterface import LoadCoordinate, MarkerNodeCoordinate
    from exudyn.utilities import CreateSymbolicUserFunction

    if marker is None:
        marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=body.node, coordinate=5))
    load = mbs.AddLoad(LoadCoordinate(name="load_torque", markerNumber=marker, load=torque))

    def ramped(mbs, t, load):
        return load * ramp_fraction(t, ramp_time, esym)

    fn = CreateSymbolicUserFunction(mbs, ramped, "loadUserFunction", load)
    mbs.SetLoadParameter(load, "loadUserFunction", fn)
    keep_alive(mbs, [fn])
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


def add_interface_joint(mbs, body: Body, other: Body, joint: FixedJointElement, name: str = "") -> int:
    """The fixed joint ``joint`` of ``body`` and ``other`` at their interfaces, at ``joint.point`` [m, ground frame,
    reference configuration].

    A flexible body joins through the ``MarkerSuperElementRigid`` of its interface (the RBE3 motion
    of the interface node set, see flexgear.mbs.flexible.add_flexible_body, which must have placed that
    marker at the point); a rigid body through a body-fixed marker at the point. All six relative
    motions are constrained (``ObjectJointGeneric``); its ``Force``/``Torque`` outputs are the
    forces [N] and moments [N·m] the joint transmits. Returns the joint.
    """
    from exudyn.itemInterface import MarkerBodyRigid, ObjectJointGeneric, VObjectJointGeneric

    joint.check_bodies(body.name, other.name)
    markers = []
    for b, itf in zip((body, other), joint.interfaces, strict=True):
        if b.flexible:
            if itf not in b.interface_markers:
                raise KeyError(f"flexible body {b.name!r} has no marker on interface {itf!r}; "
                               f"have {sorted(b.interface_markers)}")
            markers.append(b.interface_markers[itf])
        else:
            local = joint.point - b.position
            markers.append(mbs.AddMarker(MarkerBodyRigid(bodyNumber=b.obj, localPosition=list(map(float, local)))))
    return mbs.AddObject(ObjectJointGeneric(name=name or f"joint_{body.name}_{other.name}", markerNumbers=markers,
                                            constrainedAxes=[1] * 6, visualization=VObjectJointGeneric(show=False)))


def keep_alive(mbs, functions: list) -> None:
    """Symbolic user functions must outlive the simulation: keep them with the system."""
    store = mbs.variables.setdefault("flexgear_symbolic_functions", [])
    store.extend(functions)
