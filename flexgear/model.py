"""Model: a single-stage star gearbox (carrier fixed) assembled from bodies and connectors.

The assembly follows section 2.1 of the study: input shaft fixed to the sun, ring fixed to the
output shaft (for rigid parts the fixed joint merges the two into one body, which is exact),
bushings at the input-shaft, output-shaft and planet bearings (Table 2), a gear contact for every
sun-planet and planet-ring mesh and helix half, the input speed prescribed as a STEP ramp and
the load torque on the output as a STEP ramp (Table 5).

Frames: ground z along the gearbox axis, sun and ring centred at the origin, planet i at
a_w (cos psi_i, sin psi_i, 0) with psi_i = 2 pi i / N. Mesh normals follow from the operating
pressure angles, the base helix angle and the hand of each helix half (see :func:`mesh_contacts`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from flexgear.bodies import Body, add_rigid_body
from flexgear.connectors import (
    Bushing,
    ContactLaw,
    GearContact,
    MeshFriction,
    add_gear_contacts,
    add_linear_elements,
    add_load_torque,
    add_speed_drive,
    contact_gradients,
)
from flexgear.involute import GearSetGeometry, PeriodicSeries, contact_line_series, gear_set_geometry
from flexgear.massprops import MassProperties, combine_mass_properties
from flexgear.spec import GearboxSpec, Variant
from flexgear.theory import Theory, theory

__all__ = ["GearboxModel", "helix_halves", "mesh_contacts", "build_star_gearbox"]


@dataclass
class GearboxModel:
    """Handles of an assembled gearbox in an Exudyn system."""

    spec: GearboxSpec
    theory: Theory
    bodies: dict[str, Body]
    outer_contacts: list[list[int]]  # [planet][half] spring-damper objects, sun-planet
    inner_contacts: list[list[int]]  # [planet][half] spring-damper objects, planet-ring
    drive: int
    load: int
    contacts: list[GearContact] = field(default_factory=list)
    friction: MeshFriction | None = None
    kinematics: object | None = None  # flexgear.contact_kinematics.ContactKinematics for flexible gears
    aux_node: int = -1  # node of the contacts' deflection coordinates


def helix_halves(geo: GearSetGeometry) -> list[tuple[float, int, float]]:
    """(axial position z_h [m], planet hand H, face-width share) of each helix half."""
    if geo.helix_layout == "single":
        return [(0.0, 1, 1.0)]
    z = 0.5 * (geo.helix_face_width + geo.half_gap)
    return [(z, 1, 0.5), (-z, -1, 0.5)]


def _rot(psi: float, v: tuple[float, float]) -> np.ndarray:
    c, s = math.cos(psi), math.sin(psi)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1], 0.0])


def mesh_contacts(spec: GearboxSpec, drive_sign: float = 1.0) -> list[GearContact]:
    """Gear contacts of every planet, mesh and helix half, in the order (planet, outer/inner, half).

    Sun-planet (gear 1 = sun): pitch point at the sun's operating pitch radius, transverse line of
    action t = (sin a_w, sigma cos a_w) rotated by psi_i. Planet-ring (gear 1 = planet): pitch point
    at the ring's operating pitch radius, t = (sin a_w, -sigma cos a_w). Tooth normal
    n = cos(beta_b) t - H sin(beta_b) e_z for a half whose planet helix has hand H (the ring has the
    planet's hand, the sun the opposite), so the planet's axial forces from sun and ring cancel.
    Mesh phase of planet i: phi = z_s theta_drive / (2 pi) - z_s psi_i / (2 pi) (sequential phasing).
    """
    geo = gear_set_geometry(spec)
    g, ca = spec.gears, spec.contact_assumed
    zs, zp, zr, aw = g.sun_teeth, g.planet_teeth, g.ring_teeth, geo.centre_distance
    cos_bb, sin_bb = math.cos(geo.sun.base_helix_angle), math.sin(geo.sun.base_helix_angle)
    sigma = 1.0 if drive_sign >= 0 else -1.0
    n_harm = ca.stiffness_harmonics
    meshes = {
        "outer": (geo.sun_planet, aw * zs / (zs + zp), 1.0, 0.0),
        "inner": (geo.planet_ring, aw * zr / (zr - zp), -1.0, spec.gears_assumed.outer_inner_mesh_phase),
    }
    series = {kind: contact_line_series(m[0], geo.helix_face_width, n_harm) for kind, m in meshes.items()}
    if ca.stiffness_variation == "constant":
        series = {k: (PeriodicSeries(1.0, np.zeros(n_harm), np.zeros(n_harm)), *v[1:]) for k, v in series.items()}
    spin = {"sun": 1.0, "planet": -zs / zp, "ring": -zs / zr}  # nominal spin per drive angle (carrier fixed)
    contacts = []
    for i, psi in enumerate(geo.planet_angles):
        c_planet = aw * np.array([math.cos(psi), math.sin(psi), 0.0])
        for kind, (mesh, r_pitch, t_sign, extra_phase) in meshes.items():
            alpha = mesh.operating_pressure_angle
            t_dir = _rot(psi, (math.sin(alpha), t_sign * sigma * math.cos(alpha)))
            pitch = _rot(psi, (r_pitch, 0.0))
            c1, c2 = (np.zeros(3), c_planet) if kind == "outer" else (c_planet, np.zeros(3))
            b1, b2 = ("sun", f"planet{i + 1}") if kind == "outer" else (f"planet{i + 1}", "ring")
            spins = (spin["sun"], spin["planet"]) if kind == "outer" else (spin["planet"], spin["ring"])
            stiffness, sliding, lever = series[kind]
            for h, (z_h, hand, share) in enumerate(helix_halves(geo)):
                normal = cos_bb * t_dir - hand * sin_bb * np.array([0.0, 0.0, 1.0])
                g1, g2 = contact_gradients(c1, c2, pitch + [0.0, 0.0, z_h], normal, t_dir)
                contacts.append(GearContact(
                    f"{kind}_mesh_{i + 1}_half{h + 1}", b1, b2, g1, g2,
                    ContactLaw.from_contact(spec.contact, share), stiffness, sliding, lever,
                    spec.contact.friction_coefficient, ca.friction_regularisation_m_per_s,
                    zs * psi / (2 * math.pi) + extra_phase, zs / (2 * math.pi),
                    pitch + [0.0, 0.0, z_h], normal, spins, geo.helix_face_width,
                ))
    return contacts


MassSource = Callable[[GearboxSpec, str], MassProperties]
ReducedSource = Callable[[GearboxSpec, str, str], object]


def _default_mass_source(spec: GearboxSpec, component: str) -> MassProperties:
    from flexgear.geometry import component_mass_properties

    return component_mass_properties(spec, component)


def _default_reduced_source(spec: GearboxSpec, component: str, level: str):
    from flexgear.components import component_reduced_body

    return component_reduced_body(spec, component, level, progress=True)


def _add_component(mbs, name: str, form: str, geometry: str, position: np.ndarray, spec: GearboxSpec,
                   level: str, props: MassSource, reduced: ReducedSource) -> Body:
    """One component as a rigid body or a reduced flexible body of the same geometry."""
    if form == "rigid":
        return add_rigid_body(mbs, name, props(spec, geometry), position)
    from flexgear.flexible import add_flexible_body

    return add_flexible_body(mbs, name, reduced(spec, geometry, level), position,
                             stiffness_damping_s=spec.reduction_assumed.modal_stiffness_damping_s,
                             interface_markers=[], show=False)


def _fix_frames(mbs, lead: Body, other: Body) -> int:
    """Fixed joint of two bodies whose frames coincide: equal frame coordinates (linear, exact).

    For a flexible body the frame is its mean-axis frame (Tisserand), so the joint acts on the
    body's mean motion, not on its interface nodes (see the note in the module docstring).
    """
    from exudyn.itemInterface import ObjectConnectorCoordinateVector

    return mbs.AddObject(ObjectConnectorCoordinateVector(
        name=f"fixed_{lead.name}_{other.name}", markerNumbers=[lead.marker_coordinates, other.marker_coordinates],
        scalingMarker0=np.eye(6), scalingMarker1=np.eye(6), offset=np.zeros(6)))


def _modal_columns(contacts: list[GearContact], bodies: dict[str, Body], order: int, radial_band: float) -> list:
    """Contact-deflection coefficients of the flexible gears' modal coordinates (contact_kinematics)."""
    from flexgear.contact_kinematics import ModalColumn, modal_contact_coefficients

    columns = []
    for row, c in enumerate(contacts):
        for name, sign, spin in ((c.body1, 1.0, c.spin_per_drive_angle[0]), (c.body2, -1.0, c.spin_per_drive_angle[1])):
            body = bodies[name]
            if not body.flexible:
                continue
            rel = np.asarray(c.point) - body.position
            values = modal_contact_coefficients(body.reduced.nodes, body.reduced.modes, rel, c.normal,
                                                0.5 * c.half_width, radial_band, order)
            columns.append(ModalColumn(row, name, sign, float(np.arctan2(rel[1], rel[0])), spin, values))
    return columns


def build_star_gearbox(mbs, variant: Variant, mass_source: MassSource | None = None,
                       reduced_source: ReducedSource | None = None) -> GearboxModel:
    """Assemble the star gearbox of ``variant`` into ``mbs`` (call ``mbs.Assemble()`` afterwards).

    Each component is rigid or flexible as the variant says. A shaft and its gear (input shaft-sun,
    ring-output shaft) that are both rigid are one rigid body (the fixed joint of section 2.1 is then
    exact); otherwise they are two bodies whose frames are joined by a fixed joint.
    """
    spec = variant.gearbox
    if spec.gears.arrangement != "star":
        raise ValueError(f"{spec.source}: field 'gears.arrangement': build_star_gearbox needs 'star'")
    props = mass_source or _default_mass_source
    reduced = reduced_source or _default_reduced_source
    form = variant.components
    th = theory(spec)
    geo = gear_set_geometry(spec)
    level = variant.mesh_level
    bodies: list[Body] = []
    joints = []
    for gear, shaft in (("sun", "input_shaft"), ("ring", "output_shaft")):
        if form[gear] == "rigid" and form[shaft] == "rigid":
            merged = combine_mass_properties(props(spec, gear), props(spec, shaft))
            bodies.append(add_rigid_body(mbs, gear, merged, np.zeros(3)))
        else:
            lead = _add_component(mbs, gear, form[gear], gear, np.zeros(3), spec, level, props, reduced)
            other = _add_component(mbs, shaft, form[shaft], shaft, np.zeros(3), spec, level, props, reduced)
            bodies += [lead, other]
            joints.append((lead, other))
    for i, psi in enumerate(geo.planet_angles):
        pos = geo.centre_distance * np.array([math.cos(psi), math.sin(psi), 0.0])
        bodies.append(_add_component(mbs, f"planet{i + 1}", form["planets"], "planet", pos, spec, level,
                                     props, reduced))
    by_body = {bd.name: bd for bd in bodies}
    for lead, other in joints:
        _fix_frames(mbs, lead, other)
    b = spec.bearings
    bushings = [Bushing.from_bearing("sun", b.input_shaft), Bushing.from_bearing("ring", b.output_shaft)]
    bushings += [Bushing.from_bearing(f"planet{i + 1}", b.planet) for i in range(geo.planet_count)]
    flexible = [bd for bd in bodies if bd.flexible]
    offsets, n_modal = {}, 6 * len(bodies)
    for bd in flexible:
        offsets[bd.name] = n_modal
        n_modal += bd.reduced.n_modes
    n_extra = n_modal - 6 * len(bodies)
    frame_elements, coords = add_linear_elements(mbs, bodies, bushings, [bd.modal_node for bd in flexible], n_extra)
    lc = spec.load_case
    contacts = mesh_contacts(spec, math.copysign(1.0, lc.input_speed_rad_s))
    springs, aux, constraint, base = add_gear_contacts(mbs, bodies, coords, contacts, lc.ramp_time_s,
                                                       lc.input_speed_rad_s, n_extra)
    pre_steps = []
    kinematics = None
    # nodes within one normal module of the contact radius (about half the tooth height) enter the fit
    columns = _modal_columns(contacts, by_body, spec.reduction_assumed.contact_fourier_order,
                             spec.gears.normal_module_m)
    if columns:
        from flexgear.contact_kinematics import ContactKinematics

        kinematics = ContactKinematics(constraint, base, columns, offsets, lc.ramp_time_s, lc.input_speed_rad_s,
                                       lc.step_size_s)
        mbs.SetObjectParameter(constraint, "scalingMarker1", kinematics.matrix_at(0.0))
        pre_steps.append(kinematics)
    friction = None
    if spec.contact.friction_coefficient > 0.0:
        friction = MeshFriction(mbs, bodies, frame_elements, aux, contacts, lc.ramp_time_s, lc.input_speed_rad_s)
        pre_steps.append(friction)
    if pre_steps:
        from flexgear.contact_kinematics import PreStepChain

        mbs.SetPreStepUserFunction(PreStepChain(pre_steps) if len(pre_steps) > 1 else pre_steps[0])
    drive = add_speed_drive(mbs, by_body["sun"], lc.ramp_time_s, lc.input_speed_rad_s)
    load = add_load_torque(mbs, by_body["ring"], -math.copysign(lc.load_torque_nm, th.output_speed), lc.ramp_time_s)
    halves = len(helix_halves(geo))
    per_planet = 2 * halves
    outer = [springs[i * per_planet:i * per_planet + halves] for i in range(geo.planet_count)]
    inner = [springs[i * per_planet + halves:(i + 1) * per_planet] for i in range(geo.planet_count)]
    return GearboxModel(spec, th, by_body, outer, inner, drive, load, contacts, friction, kinematics, aux)
