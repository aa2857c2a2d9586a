"""Model: a single-stage planetary gearbox (ring fixed, carrier output), rigid or flexible gears.

The same gear set, contacts, bearings and load case as the star (flexgear.mbs.gearbox), arranged as a planetary
stage (``[gears] arrangement = "planetary"``): the input shaft drives the sun, the ring is held by the housing,
the carrier turns at z_s / (z_s + z_r) of the input and carries the planets' bearings on its pins and the output
shaft, which takes the output bearing and the load torque. Each contact's geometry turns with the carrier
(flexgear.mbs.carrier.CarrierKinematics); the planets' frames are absolute, so their orbit's Coriolis and
centripetal terms come from the rigid-body equations themselves.

Components. The carrier is a component (``[components] carrier``, optional, rigid by default). Rigid, it is a body
whose mass and polar inertia are ``[lumped_assumed] carrier_mass_kg`` and ``carrier_inertia_kg_m2`` (the lumped
model's, eq. 1-13; derived from the gear set when the file leaves them out, flexgear.sizing), its transverse inertia
half the polar (a disc); flexible, its reduced body (flexgear.fe.carrier), its seat bolted to the output shaft's
flange. Every component of the file is rigid or a reduced flexible body, as in the star
(flexgear.mbs.gearbox.add_component):

- the output shaft: rigid, one rigid body with a rigid carrier; flexible (or beside a flexible carrier), bolted to
  the carrier at its bolts' clamped discs (a fixed joint where the star bolts the ring's flange to it), the output
  bearing at its seat and the load torque there;
- the sun and the input shaft: one rigid body when both are rigid, else two bodies and the linear fixed joint of
  the star (flexgear.mbs.joints.LinearInterfaceJoint); the input bearing at the shaft's seat;
- each planet's bearing: the one linear bearing element of the production formulation
  (flexgear.mbs.joints.linear_bearing) between the planet's frame, or a flexible planet's seat node (its bore's
  motion, flexgear.mbs.joints.LinearSeat with ``carrier``), and its pin's node (flexgear.mbs.carrier.CarrierPins:
  the pin's motion on the rigid or flexible carrier). A flexible planet's modal equations spin at its absolute speed
  (flexgear.mbs.spin). Its frame orbits, but its modes are mass-orthogonal to the rigid translations (mean axes), so
  the orbit's uniform acceleration does not load them;
- the ring: rigid, held on all six frame coordinates; flexible, held at its bolts' clamped discs by a fixed joint
  to the housing (a rigid body held to ground);
- the gears' contact columns follow each gear's spin relative to the carrier (flexgear.mbs.train.modal_columns).

Every mode of a flexible gear stays dynamic here (no residual compliance, flexgear.mbs.residual): the planets'
dropped modes would answer their bearing's reaction in axes that turn with the carrier, which that model does not
hold. The reference formulation (``[solver_assumed] formulation = "reference"``) builds the same stage from Exudyn's
nonlinear objects (``ObjectFFRFreducedOrder`` with its floating-frame terms, generic joints on interface markers,
every planet's bearing as spring-dampers between its bore's (or the rigid planet's) points and the carrier's pin
points, flexgear.mbs.elements.add_support): the check of the production formulation on the turning carrier.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from flexgear.design import Design, as_design
from flexgear.geometry.elements import FixedJointElement
from flexgear.geometry.massprops import MassProperties, combine_mass_properties
from flexgear.mbs.bodies import Body, add_rigid_body
from flexgear.mbs.carrier import Carrier, CarrierPins
from flexgear.mbs.elements import (
    add_fixed_joint,
    add_interface_joint,
    add_load_torque,
    add_speed_drive,
    add_support,
    interface_spin_marker,
)
from flexgear.mbs.gearbox import (
    GearboxModel,
    add_component,
    component_sources,
    helix_halves,
    joint_axes,
    mesh_contacts,
)
from flexgear.mbs.joints import LinearInterfaceJoint, LinearSeat, TurningBlocks, linear_bearing
from flexgear.mbs.spin import SpinSchedule
from flexgear.mbs.train import add_gear_train
from flexgear.spec import CARRIER, GearboxSpec, Variant

__all__ = ["build_planetary_gearbox", "carrier_mass_properties"]

PIN_STEPS = 10
"""The carrier's pins predict its angle over a time step up to this many load-case steps long
(flexgear.mbs.carrier.CarrierPins: a longer "step" is a static solve)."""


def carrier_mass_properties(spec: GearboxSpec | Design) -> MassProperties:
    """The carrier as a disc: mass m and polar inertia J of ``[lumped_assumed]`` (or of the carrier's part from a
    file, flexgear.design.Design.carrier_disc), transverse J / 2, centred."""
    m, j = as_design(spec).carrier_disc()
    return MassProperties(m, np.zeros(3), np.diag([0.5 * j, 0.5 * j, j]))


def build_planetary_gearbox(mbs, variant: Variant, mass_source=None, design: Design | None = None,
                            reduced_source=None, superelements: bool = False) -> GearboxModel:
    """Assemble the planetary gearbox of ``variant`` into ``mbs`` (module docstring); returns its
    flexgear.mbs.gearbox.GearboxModel (output body: the carrier, or a flexible output shaft). ``mass_source``
    (spec, component) -> MassProperties overrides the variant's rigid mass properties, ``reduced_source`` (spec,
    component, level) its reduced bodies, ``superelements`` whether every flexible body keeps its
    ``ObjectFFRFreducedOrder`` (for recorded states), as in flexgear.mbs.assemble.build_gearbox."""
    from flexgear.fe.carrier import SEAT, pin_interface
    from flexgear.fe.reduced import BOLT_PATCHES, gear_shaft_joints, joint_point

    d = as_design(variant.gearbox if design is None else design)
    spec, th, geo = d.spec, d.theory, d.gears
    form = variant.components
    reference = spec.solver_assumed.reference
    props, reduced = component_sources(variant, d, mass_source, reduced_source)
    lc, level = spec.load_case, variant.mesh_level
    ratio = th.output_speed / th.input_speed  # carrier spin per drive angle
    contacts = mesh_contacts(d, math.copysign(1.0, lc.input_speed_rad_s))
    supports = d.supports

    def component(name: str, geometry: str, position, spin: float, **kw) -> Body:
        """A rigid body (Exudyn's ``ObjectRigidBody``) or a flexible one (flexgear.mbs.gearbox.add_component)."""
        if form["planets" if geometry == "planet" else geometry] == "rigid":
            return add_rigid_body(mbs, name, props(spec, geometry), position)
        return add_component(mbs, name, "flexible", geometry, position, spec, level, props, reduced, spin_rad_s=spin,
                             contacts=contacts, superelement=superelements, **kw)

    turning, joints, linear_gears, body_axes = [], {}, [], []

    def join(lead: Body, other: Body, found: list[FixedJointElement], spin: float, label: str) -> None:
        """The fixed joints ``found`` of ``lead`` and ``other`` (their common spin per drive angle ``spin``):
        Exudyn's generic joints in the reference formulation, else linear joints (flexgear.mbs.joints, in body
        axes where ``other`` is flexible) whose turning blocks join the others; recorded under ``lead``."""
        labels = [label + (f"_{k}" if k else "") for k in range(len(found))]
        if reference:
            joints[lead.name] = [(add_interface_joint(mbs, lead, other, j, name), np.array(j.point))
                                 for j, name in zip(found, labels, strict=True)]
            return
        axes = joint_axes(other)
        made = [LinearInterfaceJoint(mbs, lead, other, j, spin, name, axes=axes)
                for j, name in zip(found, labels, strict=True)]
        turning.extend(e for j in made for e in j.turning())
        joints[lead.name] = [(j.obj, np.array(e.point)) for j, e in zip(made, found, strict=True)]
        linear_gears.append(lead.name)
        if axes == "body":
            body_axes.append(lead.name)
    if form["sun"] == "rigid" and form["input_shaft"] == "rigid":
        sun = add_rigid_body(mbs, "sun", combine_mass_properties(props(spec, "sun"), props(spec, "input_shaft")),
                             np.zeros(3))
        shafts, input_end = [], sun
    else:
        found = [FixedJointElement.gear_shaft("sun", "input_shaft", j) for j in gear_shaft_joints(d, "sun")]
        sun = component("sun", "sun", np.zeros(3), th.input_speed, joints={j.interface: j.point for j in found})
        input_end = component("input_shaft", "input_shaft", np.zeros(3), th.input_speed,
                              joints={j.other_interface: j.point for j in found}, support=supports["input_shaft"])
        shafts = [input_end]
        join(sun, input_end, found, 1.0, "joint_sun_input_shaft")
    ring_joints = [FixedJointElement("ring", gi, "housing", si, p) for gi, si, p in gear_shaft_joints(d, "ring")]
    ring = component("ring", "ring", np.zeros(3), 0.0, joints={j.interface: j.point for j in ring_joints})
    places = [geo.centre_distance * np.array([math.cos(psi), math.sin(psi), 0.0]) for psi in geo.planet_angles]
    names = [f"planet{i + 1}" for i in range(len(places))]
    bearings = [replace(supports["planet"].on(name), other="carrier") for name in names]
    pins = [pin_interface(i) for i in range(len(places))]
    point = joint_point(d, "ring")  # the output shaft's flange: where the star bolts the ring to it
    flexible_carrier = form.get(CARRIER, "rigid") == "flexible"
    if flexible_carrier:  # its seat on the output shaft, the planets' bearings on its pins
        carrier = component("carrier", CARRIER, np.zeros(3), th.output_speed, joints={SEAT: point},
                            bearing_points={pin: [place + sp.point for sp in b.axis_springs()]
                                            for pin, place, b in zip(pins, places, bearings, strict=True)})
    if not flexible_carrier and form["output_shaft"] == "rigid":  # one rigid body with the carrier
        carrier = add_rigid_body(mbs, "carrier", combine_mass_properties(carrier_mass_properties(d),
                                                                         props(spec, "output_shaft")), np.zeros(3))
        output_end = carrier
    else:  # bolted to the carrier at its bolts' clamped discs (where the star bolts the ring's flange to it)
        if not flexible_carrier:
            carrier = add_rigid_body(mbs, "carrier", carrier_mass_properties(d), np.zeros(3))
        joint = FixedJointElement("output_shaft", BOLT_PATCHES, "carrier", SEAT if flexible_carrier else "carrier",
                                  point)
        output_end = component("output_shaft", "output_shaft", np.zeros(3), th.output_speed,
                               joints={BOLT_PATCHES: point}, support=supports["output_shaft"])
        shafts.append(output_end)
        join(output_end, carrier, [joint], ratio, "joint_output_shaft_carrier")
    planets = [component(name, "planet", place, th.planet_speed, support=supports["planet"])
               for name, place in zip(names, places, strict=True)]
    bodies: list[Body] = [sun, ring, carrier, *planets]
    if ring.flexible:  # held at its bolts' clamped discs by the housing
        housing = add_rigid_body(mbs, "housing", props(spec, "ring"), np.zeros(3))
        add_fixed_joint(mbs, housing, name="housing_ground")
        join(ring, housing, ring_joints, 0.0, "joint_ring_housing")
    else:
        add_fixed_joint(mbs, ring, name="ring_housing")
    seat_nodes, pin_nodes = {}, {}
    extra = []
    if not reference:  # each pin's motion on a node of its own, the planet's bearing between it and the planet
        carrier_pins = CarrierPins(mbs, carrier, pins, PIN_STEPS * lc.step_size_s,
                                   None if carrier.flexible else places)
        pin_nodes = dict(zip(pins, carrier_pins.nodes, strict=True))
        extra.append(carrier_pins)
    for planet, bearing, pin in zip(planets, bearings, pins, strict=True):
        if reference:  # springs on the bore's (or the rigid planet's) points and the pin's points
            add_support(mbs, planet, bearing, other=carrier, other_interface=pin if carrier.flexible else None)
        elif planet.flexible:
            seat = LinearSeat(mbs, planet, bearing, th.planet_speed / th.input_speed, carrier=carrier,
                              pin_node=pin_nodes[pin])
            turning += seat.turning()
            seat_nodes[planet.name] = seat.node
        else:  # the bearing about the planet's centre, its frame's origin
            linear_bearing(mbs, f"bearing_{planet.name}", planet.node, bearing.stiffness, bearing.damping,
                           other_node=pin_nodes[pin])
    for end, key, spin in ((input_end, "input_shaft", 1.0), (output_end, "output_shaft", ratio)):  # shafts' seats
        if end.flexible and not reference:
            turning += LinearSeat(mbs, end, supports[key].on(end.name), spin).turning()
        else:
            add_support(mbs, end, supports[key].on(end.name))
    if turning:
        extra.append(TurningBlocks(turning, lc.ramp_time_s, lc.input_speed_rad_s))
    linear = [b for b in [*bodies, *shafts] if getattr(b, "spin", None) is not None]
    frames = [b.frame for b in [*bodies, *shafts] if b.frame is not None]
    if linear or frames:
        extra.append(SpinSchedule(mbs, linear, lc.ramp_time_s, spec.solver_assumed.spin_update_interval_s, frames))
    train = add_gear_train(mbs, [*bodies, *shafts], [], contacts, lc.ramp_time_s, lc.input_speed_rad_s,
                           friction=spec.contact.friction_coefficient > 0.0, carrier=Carrier("carrier", ratio),
                           extra_pre_steps=extra, contact_fourier_order=spec.reduction_assumed.contact_fourier_order,
                           radial_band=spec.gears.normal_module_m)
    spin_in = interface_spin_marker(mbs, input_end, "bearing_seat" if input_end.flexible else None)
    spin_out = interface_spin_marker(mbs, output_end, "bearing_seat" if output_end.flexible else None)
    drive = add_speed_drive(mbs, input_end, lc.ramp_time_s, lc.input_speed_rad_s, spin_in[0])
    load = add_load_torque(mbs, output_end, -math.copysign(lc.load_torque_nm, th.output_speed), lc.ramp_time_s,
                           spin_out[0])
    springs = train.springs
    halves = len(helix_halves(geo))
    per_planet = 2 * halves
    outer = [springs[i * per_planet:i * per_planet + halves] for i in range(geo.planet_count)]
    inner = [springs[i * per_planet + halves:(i + 1) * per_planet] for i in range(geo.planet_count)]
    return GearboxModel(d, {b.name: b for b in [*bodies, *shafts]}, outer, inner, drive, load, contacts,
                        train.friction, train.kinematics, tuple(train.aux_nodes), input_end.name, output_end.name,
                        joints, spin_out[1:], linear_joints=tuple(linear_gears), body_axes_joints=tuple(body_axes),
                        carrier_seat_nodes=seat_nodes, carrier_pin_nodes=pin_nodes)
