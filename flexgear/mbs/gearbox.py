"""Model: a single-stage gearbox assembled from bodies and connectors; here the star (carrier fixed), the
planetary stage in flexgear.mbs.planetary, either through flexgear.mbs.assemble.build_gearbox.

The assembly follows section 2.1 of the study: input shaft fixed to the sun, ring fixed to the
output shaft (for rigid parts the fixed joint merges the two into one body, which is exact),
bearings at the input-shaft and output-shaft seats and the planet bores (Table 2), a gear contact for every
sun-planet and planet-ring mesh and helix half, the input speed prescribed as a STEP ramp and
the load torque on the output as a STEP ramp (Table 5).

Frames: ground z along the gearbox axis, sun and ring centred at the origin, planet i at
a_w (cos psi_i, sin psi_i, 0) with psi_i = 2 pi i / N. Mesh normals follow from the operating
pressure angles, the base helix angle and the hand of each helix half (see :func:`mesh_contacts`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from flexgear.design import Design, as_design
from flexgear.fe.reduced import component_mass_properties, contact_band_selector
from flexgear.fe.ring_shaft import TIED_PAIR
from flexgear.geometry.elements import BearingElement, FixedJointElement
from flexgear.geometry.involute import GearSetGeometry
from flexgear.geometry.massprops import MassProperties, combine_mass_properties
from flexgear.geometry.pair import helix_halves as pair_helix_halves
from flexgear.laws.contact import half_laws, mesh_laws
from flexgear.mbs.bodies import Body, add_rigid_body
from flexgear.mbs.connections import GearboxModel, connect_stage, joint_axes
from flexgear.mbs.contacts import GearContact, mesh_pair_contacts
from flexgear.mbs.elements import (
    support_points,
)
from flexgear.spec import COMPONENT_GEOMETRY, GearboxSpec, Variant

__all__ = ["GearboxModel", "helix_halves", "mesh_contacts", "build_star_gearbox", "mass_source_of", "dynamic_modes",
           "run_cost", "add_component", "component_sources", "joint_axes", "linear_frame_tolerance",
           "add_gear_and_shaft", "dynamic_cutoff_hz"]


def helix_halves(geo: GearSetGeometry) -> list[tuple[float, int, float]]:
    """(axial position z_h [m], planet hand H, face-width share) of each helix half."""
    return [(h.z, h.hand, h.share) for h in pair_helix_halves(geo.helix_layout, geo.helix_face_width, geo.half_gap)]


def mesh_contacts(spec: GearboxSpec | Design, drive_sign: float = 1.0) -> list[GearContact]:
    """Gear contacts of every planet, mesh and helix half, in the order (planet, outer/inner, half).

    Built with :func:`flexgear.mbs.contacts.mesh_pair_contacts` from the design's mesh contact geometry
    (flexgear.design ``meshes``). Sun-planet: gear 1 = sun, pushing
    in the drive sense; planet-ring: gear 1 = planet, pushing against the drive sense. The halves'
    hands (flexgear.geometry.pair convention, gear 1 in the +z half): sun +1, planet -1, so that the
    planet's axial forces from sun and ring cancel. Mesh phase of planet i:
    phi = z_s theta_drive / (2 pi) - z_s psi_i / (2 pi) (sequential phasing), plus the configured
    outer-inner phase on the planet-ring mesh. ``spec``: a spec or its design (flexgear.design).
    """
    d = as_design(spec)
    geo, spec, th = d.gears, d.spec, d.theory
    g = spec.gears
    zs, aw = g.sun_teeth, geo.centre_distance
    sigma = 1.0 if drive_sign >= 0 else -1.0
    # nominal spins per drive angle: the star's carrier fixed, the planetary's ring fixed (flexgear.theory)
    carrier = th.ratio if g.arrangement == "planetary" else 0.0
    spin = {"sun": 1.0, "planet": carrier - g.sun_teeth / g.planet_teeth * (1.0 - carrier),
            "ring": th.ratio if carrier == 0.0 else 0.0}
    common = dict(contact=spec.contact, contact_assumed=spec.contact_assumed, carrier_spin=carrier,
                  phase_per_drive_angle=zs * (1.0 - carrier) / (2 * math.pi))
    outer, inner = d.meshes["outer"], d.meshes.get("inner")  # no inner mesh in the parallel-axis pair
    laws = mesh_laws(d)  # whole face width, then each helix half's share
    outer_laws = half_laws(outer, spec.contact, laws["outer"])
    inner_laws = half_laws(inner, spec.contact, laws["inner"]) if inner is not None else None
    contacts = []
    for i, psi in enumerate(geo.planet_angles):
        c_planet = aw * np.array([math.cos(psi), math.sin(psi), 0.0])
        phase = zs * psi / (2 * math.pi)
        contacts += mesh_pair_contacts(f"outer_mesh_{i + 1}", "sun", f"planet{i + 1}", outer, np.zeros(3), c_planet,
                                       laws=outer_laws, drive_sign=sigma, spins=(spin["sun"], spin["planet"]),
                                       phase_offset=phase, **common)
        if inner is None:
            continue
        contacts += mesh_pair_contacts(f"inner_mesh_{i + 1}", f"planet{i + 1}", "ring", inner, c_planet, np.zeros(3),
                                       laws=inner_laws, drive_sign=-sigma, spins=(spin["planet"], spin["ring"]),
                                       phase_offset=phase + spec.gears_assumed.outer_inner_mesh_phase, **common)
    return contacts


MassSource = Callable[[GearboxSpec, str], MassProperties]
ReducedSource = Callable[[GearboxSpec, str, str], object]


def _default_reduced_source(spec: GearboxSpec, component: str, level: str):
    from flexgear.fe.ring_shaft import reduced_body

    return reduced_body(spec, component, level, progress=True)


def mass_source_of(variant: Variant, d: Design) -> MassSource:
    """The rigid components' mass properties of ``variant`` (its ``rigid_mass_properties``: the coarse reduced
    bodies' "mesh" or the "exact" geometry's) for its design ``d``."""
    return _mass_source(variant, d, _default_reduced_source, True)


def _mass_source(variant: Variant, d: Design, reduced: ReducedSource, default_bodies: bool) -> MassSource:
    """Mass properties of rigid components: the reduced body's (twins identical) or the exact geometry's (of the
    variant's design ``d``). With the default reduced bodies (``default_bodies``) a rigid twin reads only its body's
    mass properties."""
    level = variant.mesh_level
    if variant.rigid_mass_properties == "mesh":
        if default_bodies:
            return lambda spec, component: component_mass_properties(d, component, level, progress=True)
        return lambda spec, component: reduced(spec, component, level).props
    return lambda spec, component: d.masses[component]  # "exact"


def component_sources(variant: Variant, d: Design, mass_source: MassSource | None = None,
                      reduced_source: ReducedSource | None = None) -> tuple[MassSource, ReducedSource]:
    """The mass properties of ``variant``'s rigid components and its reduced bodies, for one build: each reduced body
    loaded once (``reduced_source`` (spec, component, level), default the cached bodies), the rigid mass properties
    those of :func:`mass_source_of` unless ``mass_source`` is given."""
    source = reduced_source or _default_reduced_source
    loaded: dict[tuple[str, str], object] = {}

    def reduced(spec: GearboxSpec, component: str, level: str):  # each component loaded once per build
        if (component, level) not in loaded:
            loaded[component, level] = source(spec, component, level)
        return loaded[component, level]

    return mass_source or _mass_source(variant, d, reduced, reduced_source is None), reduced


GEARS = ("sun", "planet", "ring")
"""Geometries that carry gear contacts: their modes above the dynamic cut-off become residual compliance."""


def dynamic_modes(geometry: str, frequencies_hz: np.ndarray, cutoff_hz: float) -> int:
    """How many of a component's modes (free-free ``frequencies_hz``, ascending) the time integration keeps: a gear
    its modes below ``cutoff_hz`` (> 0; the rest return as residual compliance, flexgear.mbs.residual), at least
    one (the floating-frame object needs one); a shaft, and the ring, every mode (the ring carries no residual:
    tied to the output shaft its deflections are measured from a seat that is not its support)."""
    n = len(frequencies_hz)
    if cutoff_hz <= 0 or geometry not in GEARS or geometry == "ring":
        return n
    return max(1, int(np.count_nonzero(np.asarray(frequencies_hz) < cutoff_hz)))


def run_cost(variant: Variant) -> float | None:
    """An estimate of a variant's run time in arbitrary units, to order the runs of a matrix longest first: the sum
    over its flexible bodies of (dynamic modes)^2 (each body's dense modal matrices and the constraint columns it
    feeds grow with it), from the cached reduced bodies' frequencies; None if one of them is not cached yet."""
    from flexgear.fe.build import build_key
    from flexgear.fe.reduced import cached_frequencies

    d = as_design(variant.gearbox)
    spec = d.spec
    cutoff = dynamic_cutoff_hz(d)
    cost = 0.0
    for component, form in variant.components.items():
        if form != "flexible":
            continue
        geometry = COMPONENT_GEOMETRY[component]
        frequencies = cached_frequencies(build_key(spec, geometry, variant.mesh_level))
        if frequencies is None:
            return None
        count = spec.gears.planet_count if component == "planets" else 1
        cost += count * float(dynamic_modes(geometry, frequencies, cutoff)) ** 2
    return cost


def linear_frame_tolerance(spec: GearboxSpec) -> float | None:
    """The axisymmetry tolerance of the production formulation's linear body frames, None for the reference's
    ``ObjectRigidBody`` (flexgear.mbs.bodies.add_linear_frame)."""
    sv = spec.solver_assumed
    return None if sv.reference else sv.frame_axisymmetry_tolerance


def add_component(mbs, name: str, form: str, geometry: str, position: np.ndarray, spec: GearboxSpec,
                   level: str, props: MassSource, reduced: ReducedSource,
                   joints: dict[str, np.ndarray] | None = None, support: BearingElement | None = None,
                   cutoff_hz: float = 0.0, dropped: dict | None = None, spin_rad_s: float = 0.0,
                   superelement: bool = True, contacts: list[GearContact] = (), source: str | None = None,
                   bearing_points: dict[str, list[np.ndarray]] | None = None) -> Body:
    """One component as a rigid body or a reduced flexible body of the same geometry.

    ``joints`` {interface name: point [m]}: a flexible body gets those interfaces' markers at those points;
    ``support``: the point markers of that bearing's springs on its interface (flexgear.mbs.elements.add_support);
    ``cutoff_hz`` > 0: a gear keeps its modes below it as coordinates, the others as ``dropped`` modes whose
    static compliance the contacts carry (flexgear.mbs.residual); ``dropped``: those per geometry, shared by
    the bodies of one build (the five planets compute them once); ``spin_rad_s``: the nominal spin about the
    body's z axis [rad/s] (the linear floating frame's spin terms, flexgear.mbs.spin); ``superelement``: whether a
    flexible body gets its ``ObjectFFRFreducedOrder`` (markers, mesh-node sensors; flexgear.mbs.flexible);
    ``contacts``: the gear contacts, whose sensed coordinates a gear on interface coordinates gets as a node;
    ``source``: the reduced body to load when it is not ``geometry``'s own (the tied ring and output shaft).
    ``bearing_points`` {interface: points [m, body frame]}: further interfaces where bearings of other bodies act (a
    flexible carrier's pins): in the production formulation each interface's own coordinates, in the reference
    formulation point markers at those points (flexgear.mbs.elements.add_support with ``other``).
    """
    frame_tol = linear_frame_tolerance(spec)
    reference = spec.solver_assumed.reference
    if form == "rigid":
        return add_rigid_body(mbs, name, props(spec, geometry), position, spin_rad_s, frame_tol)
    from dataclasses import replace

    from flexgear.mbs.flexible import add_flexible_body

    # production: linear joints and seats (flexgear.mbs.joints) on their interfaces' own coordinates, no markers;
    # reference: Exudyn's generic joints on interface markers, seat springs on point markers
    points = {support.interface: support_points(support)} if support is not None and reference else None
    if reference and bearing_points:
        points = {**(points or {}), **bearing_points}
    coordinates = []
    if not reference:
        coordinates = (list(joints or {}) + ([support.interface] if support is not None else [])
                       + list(bearing_points or {}))
        joints = {}
    full = reduced(spec, source or geometry, level)
    keep = dynamic_modes(geometry, full.frequencies_hz, cutoff_hz)
    kept = full.truncated(keep) if keep < full.n_modes else full
    sensing = None
    band = contact_band_selector(spec, geometry) if geometry in GEARS else None  # an imported gear's own band
    if coordinates and geometry in GEARS and kept.n_modes > 6 * len(coordinates):  # room beside the interfaces
        from flexgear.mbs.train import contact_sensing_rows

        sensing = contact_sensing_rows(kept, name, position, list(contacts),
                                       spec.reduction_assumed.contact_fourier_order, spec.gears.normal_module_m, band)
    body = add_flexible_body(mbs, name, kept, position,
                             stiffness_damping_s=spec.reduction_assumed.modal_stiffness_damping_s,
                             interface_markers=joints or [], point_markers=points,
                             show=False, reference=reference,
                             nominal_spin_rad_s=spin_rad_s, superelement=superelement or reference,
                             interface_coordinates=tuple(dict.fromkeys(coordinates)), sensing_rows=sensing,
                             linear_frame_tolerance=frame_tol)
    if band is not None:
        body = replace(body, contact_band=band)
    if keep == full.n_modes:
        return body
    from flexgear.mbs.residual import dropped_modes

    cache = {} if dropped is None else dropped
    if geometry not in cache:
        cache[geometry] = dropped_modes(spec, full, keep, geometry)
    return replace(body, dropped=cache[geometry])


def dynamic_cutoff_hz(d: Design) -> float:
    """The frequency [Hz] below which a gear's modes stay coordinates (``[reduction_assumed]
    dynamic_cutoff_mesh_orders`` times the load case's mesh frequency; 0: every mode dynamic)."""
    return d.spec.reduction_assumed.dynamic_cutoff_mesh_orders * d.theory.mesh_frequency


def add_gear_and_shaft(mbs, d: Design, name: str, gear: str, gear_form: str, shaft: str, shaft_form: str,
                       spin_rad_s: float, centre: np.ndarray, props: MassSource, reduced: ReducedSource, level: str,
                       dropped: dict, superelements: bool, contacts: list[GearContact],
                       bearing_points: dict[str, list[np.ndarray]] | None = None,
                       ) -> tuple[Body, Body, list[FixedJointElement]]:
    """A gear and its shaft as two bodies at ``centre`` [m] (:func:`add_component`, the gear named ``name``) and
    their fixed joints (flexgear.fe.reduced.gear_shaft_joints, points in the gear's frame, the joints' at ``centre``
    plus them): (gear body, shaft body, joints). The shaft carries its ``d.supports[shaft]`` bearing and any
    ``bearing_points``; the gear keeps its modes below :func:`dynamic_cutoff_hz`."""
    from flexgear.fe.reduced import gear_shaft_joints

    found = gear_shaft_joints(d, gear)
    joints = [FixedJointElement.gear_shaft(name, shaft, (a, b, centre + p)) for a, b, p in found]
    spec = d.spec
    lead = add_component(mbs, name, gear_form, gear, centre, spec, level, props, reduced,
                         {a: p for a, _, p in found}, cutoff_hz=dynamic_cutoff_hz(d), dropped=dropped,
                         spin_rad_s=spin_rad_s, superelement=superelements, contacts=contacts)
    other = add_component(mbs, shaft, shaft_form, shaft, centre, spec, level, props, reduced,
                          {b: p for _, b, p in found}, d.supports[shaft], spin_rad_s=spin_rad_s,
                          superelement=superelements, bearing_points=bearing_points)
    return lead, other, joints


def build_star_gearbox(mbs, variant: Variant, mass_source: MassSource | None = None,
                       reduced_source: ReducedSource | None = None, superelements: bool = False,
                       design: Design | None = None) -> GearboxModel:
    """Assemble the star gearbox of ``variant`` into ``mbs`` (call ``mbs.Assemble()`` afterwards).

    Each component is rigid or flexible as the variant says. A shaft and its gear (input shaft-sun,
    ring-output shaft) that are both rigid are one rigid body (the fixed joint of section 2.1 is then
    exact); a flexible ring and output shaft are one flexible body, reduced together (flexgear.fe.ring_shaft, no
    joint between them); otherwise they are two bodies joined by a fixed joint at their interfaces
    (flexgear.fe.reduced.gear_shaft_joints: the sun at its bore, the ring at its bolt patches, rigid in the
    rigid partner's motion): a flexible body through its interface's RBE3 (or rigid patch) motion, a rigid one at
    the joint's point. The input bearing and the drive act on the input shaft, the output bearing and the load on
    the output shaft (on the merged or tied body when shaft and gear are one), at the shafts' bearing seats and
    the planets' bores
    (flexgear.geometry.supports, flexgear.mbs.elements.add_support, interface_spin_marker), through the seat
    interfaces' motion of a flexible body. Production formulation: linear joints and seats
    (flexgear.mbs.joints), linear frames (flexgear.mbs.bodies, flexgear.mbs.spin); ``[solver_assumed] formulation
    = "reference"``: Exudyn's generic joints, marker seats, ``ObjectRigidBody`` and ``ObjectFFRFreducedOrder``.
    Rigid components carry the mass properties of the variant's ``rigid_mass_properties``: "mesh",
    those of the reduced body at the variant's mesh level (rigid and flexible twins identical), or
    "exact", the exact geometry's; ``mass_source`` overrides both. ``superelements``: every flexible body keeps
    its ``ObjectFFRFreducedOrder`` even when the linear forms need none (for mesh-node sensors: recorded states).
    ``design``: the design of the variant's gearbox (flexgear.design; made from it when None).
    """

    d = as_design(variant.gearbox if design is None else design)
    spec = d.spec
    if spec.gears.arrangement != "star":
        raise ValueError(f"{spec.source}: field 'gears.arrangement': expected 'star' here: build_star_gearbox builds "
                         "the star; flexgear.mbs.assemble.build_gearbox builds any arrangement")
    props, reduced = component_sources(variant, d, mass_source, reduced_source)
    form = variant.components
    th, geo = d.theory, d.gears
    level = variant.mesh_level
    lc = spec.load_case
    cutoff = dynamic_cutoff_hz(d)
    dropped: dict = {}  # geometry -> its dropped modes (flexgear.mbs.residual.DroppedModes), once per build
    supports = d.supports
    contacts = mesh_contacts(d, math.copysign(1.0, lc.input_speed_rad_s))
    bodies: list[Body] = []
    pairs = []
    ends = {}
    for gear, shaft, spin in (("sun", "input_shaft", th.input_speed), ("ring", "output_shaft", th.output_speed)):
        if form[gear] == "rigid" and form[shaft] == "rigid":
            merged = combine_mass_properties(props(spec, gear), props(spec, shaft))
            bodies.append(add_rigid_body(mbs, gear, merged, np.zeros(3), spin, linear_frame_tolerance(spec)))
            ends[gear] = gear
        elif gear == "ring" and form[gear] == form[shaft]:  # both flexible: one body, reduced together
            bodies.append(add_component(mbs, gear, "flexible", gear, np.zeros(3), spec, level, props, reduced,
                                         support=supports[shaft], spin_rad_s=spin, superelement=superelements,
                                         contacts=contacts, source=TIED_PAIR))
            ends[gear] = gear
        else:
            lead, other, joints = add_gear_and_shaft(mbs, d, gear, gear, form[gear], shaft, form[shaft], spin,
                                                     np.zeros(3), props, reduced, level, dropped, superelements,
                                                     contacts)
            bodies += [lead, other]
            pairs.append((lead, other, joints, spin / th.input_speed))  # spin per drive angle
            ends[gear] = shaft
    for i, psi in enumerate(geo.planet_angles):
        pos = geo.centre_distance * np.array([math.cos(psi), math.sin(psi), 0.0])
        bodies.append(add_component(mbs, f"planet{i + 1}", form["planets"], "planet", pos, spec, level,
                                     props, reduced, support=supports["planet"],
                                     cutoff_hz=cutoff, dropped=dropped, spin_rad_s=th.planet_speed,
                                     superelement=superelements, contacts=contacts))
    planets = [f"planet{i + 1}" for i in range(geo.planet_count)]
    placed = [(ends["sun"], "input_shaft"), (ends["ring"], "output_shaft"), *((p, "planet") for p in planets)]
    return connect_stage(mbs, d, bodies, pairs, placed, contacts, ends["sun"], ends["ring"], meshes_per_planet=2)
