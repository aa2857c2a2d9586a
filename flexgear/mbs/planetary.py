"""Model: a single-stage planetary gearbox (ring fixed, carrier output) assembled from rigid bodies.

The same gear set, contacts, bearings and load case as the star (flexgear.mbs.gearbox), arranged as a planetary
stage (``[gears] arrangement = "planetary"``): the input shaft drives the sun, the ring is held by the housing
(a fixed joint on all six frame coordinates), the carrier turns at z_s / (z_s + z_r) of the input and carries
the planets' bearings on its pins (flexgear.mbs.carrier.add_planet_bearing) and the output shaft, which takes
the output bearing and the load torque. Each contact's geometry turns with the carrier
(flexgear.mbs.carrier.CarrierKinematics); the planets' frames are absolute, so their orbit's Coriolis and
centripetal terms come from the rigid-body equations themselves.

Components: the input shaft and the sun are one rigid body (their fixed joint is then exact), the output shaft and
the carrier one rigid body. The carrier is not a component of the gearbox file: its mass and polar inertia are
``[lumped_assumed] carrier_mass_kg`` and ``carrier_inertia_kg_m2`` (the lumped model's, eq. 1-13; derived from
the gear set when the file leaves them out, flexgear.sizing), its transverse inertia half the polar (a disc).
Every component is rigid: the multibody model's rotating carrier takes rigid gears only (flexgear.mbs.train), and a
variant with a flexible component is refused when it is loaded (flexgear.spec).
"""

from __future__ import annotations

import math

import numpy as np

from flexgear.design import Design, as_design
from flexgear.geometry.elements import BearingElement
from flexgear.geometry.massprops import MassProperties, combine_mass_properties
from flexgear.mbs.bodies import Body, add_rigid_body
from flexgear.mbs.carrier import Carrier, add_planet_bearing
from flexgear.mbs.elements import add_fixed_joint, add_load_torque, add_speed_drive, add_support, interface_spin_marker
from flexgear.mbs.gearbox import GearboxModel, helix_halves, mass_source_of, mesh_contacts
from flexgear.mbs.train import add_gear_train
from flexgear.spec import GearboxSpec, Variant

__all__ = ["build_planetary_gearbox", "carrier_mass_properties"]


def carrier_mass_properties(spec: GearboxSpec) -> MassProperties:
    """The carrier as a disc: mass m and polar inertia J of ``[lumped_assumed]``, transverse J / 2, centred."""
    la = spec.lumped_assumed
    j = la.carrier_inertia_kg_m2
    return MassProperties(la.carrier_mass_kg, np.zeros(3), np.diag([0.5 * j, 0.5 * j, j]))


def build_planetary_gearbox(mbs, variant: Variant, mass_source=None, design: Design | None = None):
    """Assemble the planetary gearbox of ``variant`` (every component rigid) into ``mbs``; returns its
    flexgear.mbs.gearbox.GearboxModel (output body: the carrier). ``mass_source`` (spec, geometry) ->
    MassProperties overrides the variant's rigid mass properties, as in flexgear.mbs.assemble.build_gearbox."""
    d = as_design(variant.gearbox if design is None else design)
    spec, th, geo = d.spec, d.theory, d.gears
    flexible = [c for c, f in variant.components.items() if f != "rigid"]
    if flexible:
        raise ValueError(f"{variant.source}: field 'components.{flexible[0]}': the planetary arrangement takes rigid "
                         "components only")
    props = mass_source or mass_source_of(variant, d)
    lc = spec.load_case
    ratio = th.output_speed / th.input_speed  # carrier spin per drive angle
    sun = add_rigid_body(mbs, "sun", combine_mass_properties(props(spec, "sun"), props(spec, "input_shaft")),
                         np.zeros(3))
    ring = add_rigid_body(mbs, "ring", props(spec, "ring"), np.zeros(3))
    carrier = add_rigid_body(mbs, "carrier", combine_mass_properties(carrier_mass_properties(spec),
                                                                     props(spec, "output_shaft")), np.zeros(3))
    bodies: list[Body] = [sun, ring, carrier]
    planets = []
    for i, psi in enumerate(geo.planet_angles):
        pos = geo.centre_distance * np.array([math.cos(psi), math.sin(psi), 0.0])
        planets.append(add_rigid_body(mbs, f"planet{i + 1}", props(spec, "planet"), pos))
    bodies += planets
    contacts = mesh_contacts(d, math.copysign(1.0, lc.input_speed_rad_s))
    supports = d.supports
    train = add_gear_train(mbs, bodies, [], contacts, lc.ramp_time_s, lc.input_speed_rad_s,
                           friction=spec.contact.friction_coefficient > 0.0, carrier=Carrier("carrier", ratio))
    add_support(mbs, sun, supports["input_shaft"].on("sun"))
    add_support(mbs, carrier, supports["output_shaft"].on("carrier"))
    add_fixed_joint(mbs, ring, name="ring_housing")
    for planet in planets:
        add_planet_bearing(mbs, carrier, planet, BearingElement.from_bearing(spec.bearings.planet, planet.name,
                                                                             other="carrier"))
    spin_in = interface_spin_marker(mbs, sun, None)
    spin_out = interface_spin_marker(mbs, carrier, None)
    drive = add_speed_drive(mbs, sun, lc.ramp_time_s, lc.input_speed_rad_s, spin_in[0])
    load = add_load_torque(mbs, carrier, -math.copysign(lc.load_torque_nm, th.output_speed), lc.ramp_time_s,
                           spin_out[0])
    springs = train.springs
    halves = len(helix_halves(geo))
    per_planet = 2 * halves
    outer = [springs[i * per_planet:i * per_planet + halves] for i in range(geo.planet_count)]
    inner = [springs[i * per_planet + halves:(i + 1) * per_planet] for i in range(geo.planet_count)]
    return GearboxModel(d, {b.name: b for b in bodies}, outer, inner, drive, load, contacts, train.friction,
                        train.kinematics, tuple(train.aux_nodes), "sun", "carrier", {}, spin_out[1:])
