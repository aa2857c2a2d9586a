"""Model: a parallel-axis gear pair (``[gears] arrangement = "parallel"``), rigid or flexible gears and shafts.

The sun is the pinion and the one planet the wheel: the input shaft drives the pinion at the origin; the wheel, at
the operating centre distance on the x axis, is fixed to the output shaft, which takes the load torque. Each gear
and its shaft are one rigid body when both are rigid, else two bodies and the linear fixed joint of the star
(flexgear.mbs.joints.LinearInterfaceJoint) between the gear's bore and the shaft's seat in it. Each shaft runs on
two bearings straddling its gear, at their seats (flexgear.geometry.supports). The pair's one mesh is the star's
sun-planet mesh of its first planet (flexgear.mbs.gearbox.mesh_contacts): its helix halves, contact law, friction
and phasing the same; so are the bodies (flexgear.mbs.gearbox.add_component), their spin terms and the connections
(flexgear.mbs.connections.connect_stage). A flexible gear keeps its modes below the dynamic cut-off as coordinates
and the rest as residual compliance at its contacts, as in the star.
"""

from __future__ import annotations

import math

import numpy as np

from flexgear.design import Design, as_design
from flexgear.geometry.massprops import combine_mass_properties
from flexgear.geometry.supports import NEAR
from flexgear.mbs.bodies import Body, add_rigid_body
from flexgear.mbs.connections import GearboxModel, connect_stage
from flexgear.mbs.elements import support_points
from flexgear.mbs.gearbox import (
    MassSource,
    ReducedSource,
    add_gear_and_shaft,
    component_sources,
    linear_frame_tolerance,
    mesh_contacts,
)
from flexgear.spec import Variant

__all__ = ["build_parallel_gearbox", "WHEEL"]

WHEEL = "planet1"
"""The wheel's body name: the first (and only) planet, whose contacts flexgear.mbs.gearbox.mesh_contacts names."""


def build_parallel_gearbox(mbs, variant: Variant, mass_source: MassSource | None = None,
                           reduced_source: ReducedSource | None = None, superelements: bool = False,
                           design: Design | None = None) -> GearboxModel:
    """Assemble the parallel-axis pair of ``variant`` into ``mbs`` (call ``mbs.Assemble()`` afterwards); the
    arguments as flexgear.mbs.gearbox.build_star_gearbox's. The wheel's body is :data:`WHEEL`; its mesh forces are
    the model's ``outer_contacts`` (``inner_contacts`` empty)."""
    d = as_design(variant.gearbox if design is None else design)
    spec = d.spec
    if spec.gears.arrangement != "parallel":
        raise ValueError(f"{spec.source}: field 'gears.arrangement': expected 'parallel' here: build_parallel_gearbox "
                         "builds the parallel-axis pair; flexgear.mbs.assemble.build_gearbox builds any arrangement")
    props, reduced = component_sources(variant, d, mass_source, reduced_source)
    form, th = variant.components, d.theory
    level, lc = variant.mesh_level, spec.load_case
    dropped: dict = {}  # geometry -> its dropped modes (flexgear.mbs.residual.DroppedModes), once per build
    contacts = mesh_contacts(d, math.copysign(1.0, lc.input_speed_rad_s))
    wheel_centre = np.array([d.gears.centre_distance, 0.0, 0.0])
    bodies: list[Body] = []
    pairs, ends = [], {}
    for gear, name, shaft, spin, centre in (("sun", "sun", "input_shaft", th.input_speed, np.zeros(3)),
                                            ("planet", WHEEL, "output_shaft", th.output_speed, wheel_centre)):
        gear_form = form["planets" if gear == "planet" else gear]
        if gear_form == "rigid" and form[shaft] == "rigid":
            merged = combine_mass_properties(props(spec, gear), props(spec, shaft))
            bodies.append(add_rigid_body(mbs, name, merged, centre, spin, linear_frame_tolerance(spec)))
            ends[gear] = name
            continue
        near = d.supports[shaft + NEAR]  # the shaft's second bearing, beyond the gear
        lead, other, joints = add_gear_and_shaft(mbs, d, name, gear, gear_form, shaft, form[shaft], spin, centre,
                                                 props, reduced, level, dropped, superelements, contacts,
                                                 {near.interface: support_points(near)})
        bodies += [lead, other]
        pairs.append((lead, other, joints, spin / th.input_speed))  # spin per drive angle
        ends[gear] = shaft
    placed = [(ends[gear], key) for gear, shaft in (("sun", "input_shaft"), ("planet", "output_shaft"))
              for key in (shaft, shaft + NEAR)]
    return connect_stage(mbs, d, bodies, pairs, placed, contacts, ends["sun"], ends["planet"], meshes_per_planet=1)
