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

__all__ = ["FlexibleNotAvailableError", "GearboxModel", "helix_halves", "mesh_contacts", "build_star_gearbox"]


class FlexibleNotAvailableError(NotImplementedError):
    """A variant asks for a flexible component that this version cannot build yet."""


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
    contacts = []
    for i, psi in enumerate(geo.planet_angles):
        c_planet = aw * np.array([math.cos(psi), math.sin(psi), 0.0])
        for kind, (mesh, r_pitch, t_sign, extra_phase) in meshes.items():
            alpha = mesh.operating_pressure_angle
            t_dir = _rot(psi, (math.sin(alpha), t_sign * sigma * math.cos(alpha)))
            pitch = _rot(psi, (r_pitch, 0.0))
            c1, c2 = (np.zeros(3), c_planet) if kind == "outer" else (c_planet, np.zeros(3))
            b1, b2 = ("sun", f"planet{i + 1}") if kind == "outer" else (f"planet{i + 1}", "ring")
            stiffness, sliding, lever = series[kind]
            for h, (z_h, hand, share) in enumerate(helix_halves(geo)):
                normal = cos_bb * t_dir - hand * sin_bb * np.array([0.0, 0.0, 1.0])
                g1, g2 = contact_gradients(c1, c2, pitch + [0.0, 0.0, z_h], normal, t_dir)
                contacts.append(GearContact(
                    f"{kind}_mesh_{i + 1}_half{h + 1}", b1, b2, g1, g2,
                    ContactLaw.from_contact(spec.contact, share), stiffness, sliding, lever,
                    spec.contact.friction_coefficient, ca.friction_regularisation_m_per_s,
                    zs * psi / (2 * math.pi) + extra_phase, zs / (2 * math.pi),
                ))
    return contacts


MassSource = Callable[[GearboxSpec, str], MassProperties]


def _default_mass_source(spec: GearboxSpec, component: str) -> MassProperties:
    from flexgear.geometry import component_mass_properties

    return component_mass_properties(spec, component)


def build_star_gearbox(mbs, variant: Variant, mass_source: MassSource | None = None) -> GearboxModel:
    """Assemble the star gearbox of ``variant`` into ``mbs`` (call ``mbs.Assemble()`` afterwards)."""
    flexible = [c for c, form in variant.components.items() if form == "flexible"]
    if flexible:
        raise FlexibleNotAvailableError(
            f"{variant.source}: field 'components.{flexible[0]}': flexible bodies are not yet available "
            f"in this version; allowed now: 'rigid' (flexible requested for: {', '.join(flexible)})"
        )
    spec = variant.gearbox
    if spec.gears.arrangement != "star":
        raise ValueError(f"{spec.source}: field 'gears.arrangement': build_star_gearbox needs 'star'")
    props = mass_source or _default_mass_source
    th = theory(spec)
    geo = gear_set_geometry(spec)
    sun = combine_mass_properties(props(spec, "sun"), props(spec, "input_shaft"))
    ring = combine_mass_properties(props(spec, "ring"), props(spec, "output_shaft"))
    planet = props(spec, "planet")
    bodies = [add_rigid_body(mbs, "sun", sun, np.zeros(3))]
    for i, psi in enumerate(geo.planet_angles):
        pos = geo.centre_distance * np.array([math.cos(psi), math.sin(psi), 0.0])
        bodies.append(add_rigid_body(mbs, f"planet{i + 1}", planet, pos))
    bodies.append(add_rigid_body(mbs, "ring", ring, np.zeros(3)))
    b = spec.bearings
    bushings = [Bushing.from_bearing("sun", b.input_shaft), Bushing.from_bearing("ring", b.output_shaft)]
    bushings += [Bushing.from_bearing(f"planet{i + 1}", b.planet) for i in range(geo.planet_count)]
    frame_elements, coords = add_linear_elements(mbs, bodies, bushings)
    lc = spec.load_case
    contacts = mesh_contacts(spec, math.copysign(1.0, lc.input_speed_rad_s))
    springs, aux = add_gear_contacts(mbs, bodies, coords, contacts, lc.ramp_time_s, lc.input_speed_rad_s)
    friction = None
    if spec.contact.friction_coefficient > 0.0:
        friction = MeshFriction(mbs, bodies, frame_elements, aux, contacts, lc.ramp_time_s, lc.input_speed_rad_s)
        mbs.SetPreStepUserFunction(friction)
    by_body = {bd.name: bd for bd in bodies}
    drive = add_speed_drive(mbs, by_body["sun"], lc.ramp_time_s, lc.input_speed_rad_s)
    load = add_load_torque(mbs, by_body["ring"], -math.copysign(lc.load_torque_nm, th.output_speed), lc.ramp_time_s)
    halves = len(helix_halves(geo))
    per_planet = 2 * halves
    outer = [springs[i * per_planet:i * per_planet + halves] for i in range(geo.planet_count)]
    inner = [springs[i * per_planet + halves:(i + 1) * per_planet] for i in range(geo.planet_count)]
    return GearboxModel(spec, th, by_body, outer, inner, drive, load, contacts, friction)
