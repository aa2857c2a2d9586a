"""Model: the connections of a single-stage gearbox's bodies, whatever its arrangement, and the handles of the
assembled model.

:func:`connect_stage` joins bodies already added (flexgear.mbs.gearbox.add_component): each gear to its shaft by its
fixed joints (the production formulation's linear joints, flexgear.mbs.joints.LinearInterfaceJoint, or Exudyn's
generic joints in the reference formulation), each bearing at its seat (flexgear.geometry.supports: a linear seat on a
flexible body, spring-dampers on a rigid one), the gear contacts (flexgear.mbs.train), the spin schedule of the
linear frames (flexgear.mbs.spin), the speed drive on the input and the load torque on the output (Table 5). The
star (flexgear.mbs.gearbox) and the parallel-axis pair (flexgear.mbs.parallel) use it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from flexgear.design import Design
from flexgear.geometry.elements import FixedJointElement
from flexgear.geometry.pair import helix_halves as pair_helix_halves
from flexgear.mbs.bodies import Body
from flexgear.mbs.contacts import GearContact, MeshFriction
from flexgear.mbs.elements import (
    add_interface_joint,
    add_load_torque,
    add_speed_drive,
    add_support,
    interface_spin_marker,
)
from flexgear.mbs.train import add_gear_train
from flexgear.spec import GearboxSpec
from flexgear.theory import Theory

__all__ = ["GearboxModel", "connect_stage", "joint_axes"]


@dataclass
class GearboxModel:
    """Handles of an assembled gearbox in an Exudyn system."""

    design: Design  # the gearbox's spec, gear set and theory (flexgear.design)
    bodies: dict[str, Body]
    outer_contacts: list[list[int]]  # [planet][half] spring-damper objects, sun-planet
    inner_contacts: list[list[int]]  # [planet][half] spring-damper objects, planet-ring
    drive: int
    load: int
    contacts: list[GearContact] = field(default_factory=list)
    friction: MeshFriction | None = None
    kinematics: object | None = None  # flexgear.mbs.contact_kinematics.ContactKinematics for flexible gears
    aux_nodes: tuple[int, ...] = ()  # nodes of the contacts' deflection coordinates (one per gear pair, in order)
    input_body: str = "sun"  # body carrying the input bearing and the drive (the input shaft if separate)
    output_body: str = "ring"  # body carrying the output bearing and the load (the output shaft if separate)
    # gear -> its fixed joints to its shaft (separate bodies): (joint, joint point [m] in the gear's frame)
    joints: dict[str, list[tuple[int, np.ndarray]]] = field(default_factory=dict)
    output_spin: tuple[int, int] = (-1, 5)  # (node, coordinate) of the output's spin angle where the load acts
    residual_node: int = -1  # node of the contacts' residual deflections (flexgear.mbs.residual), -1: none
    residual: object | None = None  # flexgear.mbs.residual.ResidualCompliance of the node's contacts (rows)
    # gears whose joints are flexgear.mbs.joints constraints (Force output: force, moment in ground axes, or in the
    # gear's body axes for the gears in body_axes_joints: those on a flexible shaft)
    linear_joints: tuple[str, ...] = ()
    body_axes_joints: tuple[str, ...] = ()
    seat_residual_nodes: tuple[int, ...] = ()  # e_s node of each of residual.seat_bodies (flexgear.mbs.residual)
    # planet -> the rigid-body node of its seat on a turning carrier (flexgear.mbs.joints.LinearSeat): it orbits
    carrier_seat_nodes: dict[str, int] = field(default_factory=dict)
    # pin interface -> the rigid-body node of the carrier's pin (flexgear.mbs.carrier.CarrierPins): it orbits
    carrier_pin_nodes: dict[str, int] = field(default_factory=dict)

    @property
    def spec(self) -> GearboxSpec:
        return self.design.spec

    @property
    def theory(self) -> Theory:
        return self.design.theory


def joint_axes(shaft: Body) -> str:
    """The axes of a linear gear-shaft joint's equations (flexgear.mbs.joints): body axes where the ``shaft`` is
    flexible, ground axes where it is rigid."""
    return "body" if shaft.flexible else "ground"


def _seat_loads_carried(body: Body) -> bool:
    """Whether ``body`` has dropped modes, which then answer its seat's own reaction (a linear joint's or
    bearing's; flexgear.mbs.residual)."""
    return getattr(body, "dropped", None) is not None


def _is_gear_seat(body: Body, interface: str) -> bool:
    """Whether ``interface`` of ``body`` is the seat its residual is measured from (flexgear.fe.reduced.gear_seat:
    the bore; the ring's bolt patches)."""
    from flexgear.fe.reduced import gear_seat

    return gear_seat(body.reduced, body.name).name == interface


def connect_stage(mbs, d: Design, bodies: list[Body],
                  pairs: list[tuple[Body, Body, list[FixedJointElement], float]],
                  placed: list[tuple[str, str]], contacts: list[GearContact], input_end: str, output_end: str,
                  meshes_per_planet: int) -> GearboxModel:
    """Connect the ``bodies`` of design ``d`` (module docstring) and return the model's handles.

    ``pairs``: (gear, shaft, their fixed joints, the pair's spin per drive angle); ``placed``: (body, key of
    ``d.supports``) of each bearing; ``contacts`` in the order (planet, mesh, helix half) with
    ``meshes_per_planet`` meshes per planet (2: sun-planet and planet-ring; 1: the parallel-axis pair's one mesh);
    ``input_end`` / ``output_end``: the bodies carrying the drive and the load at their "bearing_seat".
    """
    spec, th, geo, lc = d.spec, d.theory, d.gears, d.spec.load_case
    reference = spec.solver_assumed.reference
    supports = d.supports
    by_body = {bd.name: bd for bd in bodies}
    joints, extra, turning = {}, [], []  # turning: blocks of linear joints and seats (flexgear.mbs.joints)
    seat_residuals = {}  # gears whose seat's joint or bearing carries their dropped modes' seat motion (residual)
    linear_gears, body_axes = [], []  # gears whose joints are linear constraints; those written in body axes
    for lead, other, found, ratio in pairs:  # one joint per interface pair (the ring: per bolt with bolt patches)
        label = f"joint_{lead.name}_{other.name}"
        if not reference:
            from flexgear.mbs.joints import LinearInterfaceJoint

            # the gear's dropped modes answer the joint's reaction (flexgear.mbs.residual): one joint at its seat
            carried = (_seat_loads_carried(lead) and len(found) == 1
                       and _is_gear_seat(lead, found[0].interface))
            axes = joint_axes(other)
            made = [LinearInterfaceJoint(mbs, lead, other, j, ratio, label + (f"_{k}" if k else ""),
                                         residual=carried, axes=axes) for k, j in enumerate(found)]
            if axes == "body":
                body_axes.append(lead.name)
            if carried:
                seat_residuals[lead.name] = (made[0].residual_node, made[0].centre)
            linear_gears.append(lead.name)
            turning += [e for j in made for e in j.turning()]
            joints[lead.name] = [(j.obj, np.array(e.point)) for j, e in zip(made, found, strict=True)]
            continue
        joints[lead.name] = [(add_interface_joint(mbs, lead, other, j, label + (f"_{k}" if k else "")),
                              np.array(j.point)) for k, j in enumerate(found)]
    for body, key in placed:  # bearings at their seats (flexgear.geometry.supports)
        if by_body[body].flexible and not reference:
            from flexgear.mbs.joints import LinearSeat

            spin = by_body[body].nominal_spin_rad_s / th.input_speed  # per drive angle
            carried = _seat_loads_carried(by_body[body])
            seat = LinearSeat(mbs, by_body[body], supports[key].on(body), spin, residual=carried)
            turning += seat.turning()
            if carried:
                seat_residuals[body] = (seat.residual_node, seat.centre)
            continue
        add_support(mbs, by_body[body], supports[key].on(body))
    if turning:
        from flexgear.mbs.joints import TurningBlocks

        extra.append(TurningBlocks(turning, lc.ramp_time_s, lc.input_speed_rad_s))
    linear = [bd for bd in bodies if getattr(bd, "spin", None) is not None]
    frames = [bd.frame for bd in bodies if bd.frame is not None]
    if linear or frames:
        from flexgear.mbs.spin import SpinSchedule

        extra.append(SpinSchedule(mbs, linear, lc.ramp_time_s, spec.solver_assumed.spin_update_interval_s, frames))
    # nodes within one normal module of the contact radius (about half the tooth height) enter the fit
    train = add_gear_train(mbs, bodies, [], contacts, lc.ramp_time_s, lc.input_speed_rad_s, extra_pre_steps=extra,
                           friction=spec.contact.friction_coefficient > 0.0,
                           contact_fourier_order=spec.reduction_assumed.contact_fourier_order,
                           radial_band=spec.gears.normal_module_m, seat_residuals=seat_residuals)
    springs = train.springs
    seat = "bearing_seat"  # drive and load at the shafts' seats (spline, flange)
    spin_in = interface_spin_marker(mbs, by_body[input_end], seat)
    spin_out = interface_spin_marker(mbs, by_body[output_end], seat)
    drive = add_speed_drive(mbs, by_body[input_end], lc.ramp_time_s, lc.input_speed_rad_s, spin_in[0])
    load = add_load_torque(mbs, by_body[output_end], -math.copysign(lc.load_torque_nm, th.output_speed),
                           lc.ramp_time_s, spin_out[0])
    halves = len(pair_helix_halves(geo.helix_layout, geo.helix_face_width, geo.half_gap))
    per_planet = meshes_per_planet * halves
    outer = [springs[i * per_planet:i * per_planet + halves] for i in range(geo.planet_count)]
    inner = [springs[i * per_planet + halves:(i + 1) * per_planet] for i in range(geo.planet_count)
             if meshes_per_planet == 2]
    return GearboxModel(d, by_body, outer, inner, drive, load, contacts, train.friction, train.kinematics,
                        tuple(train.aux_nodes), input_end, output_end, joints, spin_out[1:], train.residual_node,
                        train.residual, linear_joints=tuple(linear_gears), body_axes_joints=tuple(body_axes),
                        seat_residual_nodes=train.seat_residual_nodes)
