"""Assembled gear set: nominal placement, interference and backlash check, export and picture.

Nominal position (carrier fixed, angles in rad): sun tooth 0 on the +x axis; planet i at polar
angle theta_i = 2 pi i / N, centre distance a, turned so that a tooth space faces the sun
(planet 0: rotation pi - pi/z_p) and, for the other planets, by the kinematic relation of a star
gear (theta_i (1 + z_s/z_p)); ring turned so that a tooth space faces planet 0's tooth (-pi/z_r).

Every gear is a stack of twisted prisms, so the assembly is checked exactly in transverse
sections: at height z each gear's section is its profile turned by twist * z. In a section,
overlap area > 0 means interference; turning the planet until its flanks touch the sun's (or
ring's) on either side gives the free play, i.e. the backlash

    j_t = (phi_plus - phi_minus) r_b,planet  (along the line of action),  j_n = j_t cos(beta_b)

(ISO 21771), to compare with the design value from the tooth thinning (Mesh.normal_backlash).
Booleans of the sampled exact outlines use manifold3d cross sections (in mm).

:func:`flank_deviation` checks points of a meshed gear (its flank nodes) against the involute helicoid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import manifold3d
import numpy as np

from flexgear.geometry.involute import gear_set_geometry
from flexgear.geometry.layout import ComponentLayout, component_layout, gear_profiles
from flexgear.spec import GearboxSpec

__all__ = [
    "Placement",
    "nominal_placements",
    "section_overlap",
    "measure_backlash",
    "assembly_check",
    "flank_deviation",
    "transverse_section",
    "MM_PER_M",
]

MM_PER_M = 1e3
"""Millimetres per metre: :func:`transverse_section` builds its cross sections in mm (manifold3d works on a
fixed-point grid), so lengths in metres are scaled by this to meet them."""


@dataclass(frozen=True)
class Placement:
    """Rigid placement of a component: rotation about its own z axis [rad], then the centre [m]."""

    component: str
    rotation: float
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def matrix(self) -> np.ndarray:
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        m = np.eye(4)
        m[:2, :2] = [[c, -s], [s, c]]
        m[:3, 3] = self.centre
        return m


def nominal_placements(spec: GearboxSpec) -> list[Placement]:
    """Placements of sun, planets, ring and shafts at the nominal (assembly) position."""
    gs = gear_set_geometry(spec)
    zs, zp, zr = gs.sun.teeth, gs.planet.teeth, gs.ring.teeth
    out = [Placement("input_shaft", 0.0), Placement("sun", 0.0)]
    for theta in gs.planet_angles:
        rot = math.pi - math.pi / zp + theta * (1 + zs / zp)
        out.append(Placement("planet", rot, (gs.centre_distance * math.cos(theta),
                                             gs.centre_distance * math.sin(theta), 0.0)))
    out += [Placement("ring", -math.pi / zr), Placement("output_shaft", 0.0)]
    return out


def transverse_section(spec: GearboxSpec, component: str, placement: Placement, z: float,
                       points_per_segment: int = 60) -> manifold3d.CrossSection:
    """Transverse section of a placed gear at height z (teeth region), in mm."""
    layout = component_layout(spec, component)
    prism = next((p for p in layout.prisms if p.section.gear is not None and p.z0 <= z <= p.z1), None)
    if prism is None:
        raise ValueError(f"{component}: z = {z} m is not in a toothed part of the gear")
    outline = gear_profiles(spec)[component].sample(points_per_segment)
    angle = placement.rotation + prism.twist * z
    c, s = math.cos(angle), math.sin(angle)
    pts = outline @ np.array([[c, -s], [s, c]]).T + np.array(placement.centre[:2])
    shape = manifold3d.CrossSection([pts * MM_PER_M])
    if layout.gear.internal:
        rim = manifold3d.CrossSection.circle(prism.section.outer * MM_PER_M, 720)
        return rim - shape
    return shape


def section_overlap(spec: GearboxSpec, a: Placement, b: Placement, z: float) -> float:
    """Overlap area [m^2] of two placed gears' sections at height z (0: no interference)."""
    overlap = transverse_section(spec, a.component, a, z) ^ transverse_section(spec, b.component, b, z)
    return overlap.area() / MM_PER_M**2


def measure_backlash(spec: GearboxSpec, pair: str, planet: int = 0, z: float | None = None,
                     tol: float = 1e-9) -> dict[str, float]:
    """Free play of ``planet`` against the sun (pair "sun_planet") or ring ("planet_ring") at height z.

    Bisection on the planet's extra rotation until the sections overlap, on both sides.
    Returns the transverse (along the line of action) and normal backlash [m] and the design value.
    """
    gs = gear_set_geometry(spec)
    places = nominal_placements(spec)
    planets = [p for p in places if p.component == "planet"]
    other = next(p for p in places if p.component == ("sun" if pair == "sun_planet" else "ring"))
    pl = planets[planet]
    if z is None:
        z = next(p for p in component_layout(spec, "planet").prisms if p.section.gear is not None).z1 - 1e-4
    fixed = transverse_section(spec, other.component, other, z)
    pitch = 2 * math.pi / gs.planet.teeth

    def overlaps(delta: float) -> bool:
        moved = Placement("planet", pl.rotation + delta, pl.centre)
        return (fixed ^ transverse_section(spec, "planet", moved, z)).area() > 0.0

    if overlaps(0.0):
        raise RuntimeError(f"interference at the nominal position ({pair}, planet {planet}, z = {z} m)")
    limits = []
    for sign in (1.0, -1.0):
        lo, hi = 0.0, sign * pitch / 4
        while abs(hi - lo) * gs.planet.base_radius > tol:
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if overlaps(mid) else (mid, hi)
        limits.append(lo)
    play = limits[0] - limits[1]
    jt = play * gs.planet.base_radius
    mesh = gs.sun_planet if pair == "sun_planet" else gs.planet_ring
    return {"transverse_m": jt, "normal_m": jt * math.cos(gs.planet.base_helix_angle),
            "design_normal_m": mesh.normal_backlash, "z_m": z}


def assembly_check(spec: GearboxSpec, z_levels: int = 5) -> dict[str, float]:
    """Largest overlap area of any planet with sun or ring over ``z_levels`` heights per helix,
    and the backlash of both meshes (planet 0)."""
    places = nominal_placements(spec)
    sun = next(p for p in places if p.component == "sun")
    ring = next(p for p in places if p.component == "ring")
    worst = 0.0
    for prism in (p for p in component_layout(spec, "planet").prisms if p.section.gear is not None):
        for z in np.linspace(prism.z0, prism.z1, z_levels):
            for pl in (p for p in places if p.component == "planet"):
                worst = max(worst, section_overlap(spec, sun, pl, z), section_overlap(spec, pl, ring, z))
    sp, pr = measure_backlash(spec, "sun_planet"), measure_backlash(spec, "planet_ring")
    return {"max_overlap_m2": worst, "sun_planet_normal_backlash_m": sp["normal_m"],
            "planet_ring_normal_backlash_m": pr["normal_m"], "design_normal_backlash_m": sp["design_normal_m"]}


def flank_deviation(layout: ComponentLayout, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Signed normal distance [m] of flank ``points`` (n, 3) [m] from the involute helicoid of ``layout``'s gear,
    their axial position z [m] and their phase residual d_theta [rad].

    A point at (r, theta, z) of a toothed prism with twist tau [rad/m] lies on a flank if
    theta - tau z = +/- psi(r) (mod 2 pi / z_teeth), psi(r) = Gear.tooth_half_angle(r) (radial below the
    base circle); d_theta is the residual of the nearer flank. The distance along the flank normal is
    r d_theta cos(alpha_r) = r_b d_theta, cos(alpha_r) = r_b / r. Points outside every toothed prism raise
    ValueError.
    """
    gear = layout.gear
    pitch = 2 * math.pi / gear.teeth
    p = np.asarray(points, float)
    r, theta, z = np.hypot(p[:, 0], p[:, 1]), np.arctan2(p[:, 1], p[:, 0]), p[:, 2]
    psi = np.array([gear.tooth_half_angle(x) for x in r])
    toothed = [q for q in layout.prisms if q.section.gear]
    twist = np.array([next(q.twist for q in toothed if q.z0 - 1e-9 <= zz <= q.z1 + 1e-9) for zz in z])
    base = theta - twist * z
    resid = np.stack([(base - s * psi + pitch / 2) % pitch - pitch / 2 for s in (1.0, -1.0)])
    best = np.abs(resid).argmin(axis=0)
    d_theta = resid[best, np.arange(len(p))]
    return d_theta * gear.base_radius, z, d_theta
