"""Involute helical gear relations (ISO 21771 conventions), in SI units.

Internal gears follow the signed convention of ISO 21771: an internal gear has a negative
tooth count in the mesh equations, and a positive profile-shift coefficient thickens its
teeth on the reference circle, exactly as for an external gear. Functions take and return
positive radii and tooth counts; the sign appears only inside the mesh relations.

Equations (ISO 21771:2007 / Niemann-Winter):
- transverse pressure angle  tan(alpha_t) = tan(alpha_n) / cos(beta)
- base helix angle           sin(beta_b) = sin(beta) cos(alpha_n)
- base radius                r_b = m_n z cos(alpha_t) / (2 cos beta)
- no-backlash mesh           inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2)
- centre distance            a_w = a_0 cos(alpha_t) / cos(alpha_wt),  a_0 = m_n (z1 + z2) / (2 cos beta)
- tooth thickness (normal)   s_n = m_n (pi/2 + 2 x tan(alpha_n)) - thinning
- transverse contact ratio   eps_alpha = (g_a1 + g_a2 -/+ a_w sin(alpha_wt)) / p_bt
- overlap ratio              eps_beta = b sin(beta) / (pi m_n)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from flexgear.spec import GearboxSpec, GearSet, GearSetAssumed

__all__ = [
    "inv",
    "inv_inverse",
    "pair_profile_shifts",
    "transverse_pressure_angle",
    "base_helix_angle",
    "Gear",
    "GearMesh",
    "min_planet_gap",
    "gear_set_geometry_of",
    "Mesh",
    "HelixHalf",
    "helix_halves",
    "tooth_normal_local",
    "GearSetGeometry",
    "solve_profile_shifts",
    "gear_set_geometry",
]


def inv(alpha: float) -> float:
    """Involute function inv(alpha) = tan(alpha) - alpha (alpha in rad)."""
    return math.tan(alpha) - alpha


def inv_inverse(value: float) -> float:
    """The angle alpha in (0, pi/2) with inv(alpha) = value (value >= 0)."""
    if value < 0.0:
        raise ValueError(f"inv_inverse needs a value >= 0, got {value}")
    if value == 0.0:
        return 0.0
    return brentq(lambda a: inv(a) - value, 1e-9, math.pi / 2 - 1e-9, xtol=1e-15, rtol=1e-15)


def transverse_pressure_angle(normal_pressure_angle: float, helix_angle: float) -> float:
    """alpha_t = atan(tan(alpha_n) / cos(beta)) [rad]."""
    return math.atan(math.tan(normal_pressure_angle) / math.cos(helix_angle))


def base_helix_angle(normal_pressure_angle: float, helix_angle: float) -> float:
    """beta_b = asin(sin(beta) cos(alpha_n)) [rad]."""
    return math.asin(math.sin(helix_angle) * math.cos(normal_pressure_angle))


@dataclass(frozen=True)
class Gear:
    """One involute helical gear (radii in m, angles in rad)."""

    teeth: int
    internal: bool
    normal_module: float
    helix_angle: float
    normal_pressure_angle: float
    shift: float
    thinning: float  # normal tooth-thickness reduction on the reference circle [m]
    addendum_coefficient: float
    dedendum_coefficient: float
    face_width: float

    @property
    def signed_teeth(self) -> int:
        return -self.teeth if self.internal else self.teeth

    @property
    def transverse_module(self) -> float:
        return self.normal_module / math.cos(self.helix_angle)

    @property
    def transverse_pressure_angle(self) -> float:
        return transverse_pressure_angle(self.normal_pressure_angle, self.helix_angle)

    @property
    def base_helix_angle(self) -> float:
        return base_helix_angle(self.normal_pressure_angle, self.helix_angle)

    @property
    def reference_radius(self) -> float:
        return 0.5 * self.teeth * self.transverse_module

    @property
    def base_radius(self) -> float:
        return self.reference_radius * math.cos(self.transverse_pressure_angle)

    @property
    def tip_radius(self) -> float:
        """Tip radius; for the internal gear the (inner) radius of its tooth tips."""
        h = self.normal_module * (self.addendum_coefficient + self.shift)
        return self.reference_radius - h if self.internal else self.reference_radius + h

    @property
    def root_radius(self) -> float:
        """Root radius; for the internal gear the (outer) radius of its tooth spaces."""
        h = self.normal_module * (self.dedendum_coefficient - self.shift)
        return self.reference_radius + h if self.internal else self.reference_radius - h

    @property
    def normal_tooth_thickness(self) -> float:
        """Normal tooth thickness (arc) on the reference circle [m]."""
        mn, an = self.normal_module, self.normal_pressure_angle
        return mn * (math.pi / 2 + 2 * self.shift * math.tan(an)) - self.thinning

    @property
    def transverse_tooth_thickness(self) -> float:
        """Transverse tooth thickness (arc) on the reference circle [m]."""
        return self.normal_tooth_thickness / math.cos(self.helix_angle)

    @property
    def base_pitch(self) -> float:
        """Transverse base pitch p_bt = pi m_t cos(alpha_t) [m]."""
        return math.pi * self.transverse_module * math.cos(self.transverse_pressure_angle)

    @property
    def lead(self) -> float:
        """Axial length of one helix turn, 2 pi r / tan(beta) [m] (inf for spur gears)."""
        t = math.tan(self.helix_angle)
        return math.inf if t == 0 else 2 * math.pi * self.reference_radius / t

    def tooth_half_angle(self, radius: float) -> float:
        """Half the angular tooth thickness at ``radius`` in the transverse plane [rad].

        psi(r) = s_t / (2 r_ref) + inv(alpha_t) - inv(alpha_r), cos(alpha_r) = r_b / r.
        For the internal gear the angle is that of its tooth (material), which grows outward.
        """
        alpha_r = math.acos(min(1.0, self.base_radius / radius))
        half_ref = self.transverse_tooth_thickness / (2 * self.reference_radius)
        sign = -1.0 if self.internal else 1.0
        return half_ref + sign * (inv(self.transverse_pressure_angle) - inv(alpha_r))


@dataclass(frozen=True)
class GearMesh:
    """A gear pair at its operating centre distance (gear1 external, gear2 external or internal)."""

    gear1: Gear
    gear2: Gear
    centre_distance: float
    operating_pressure_angle: float  # transverse, rad

    @property
    def internal(self) -> bool:
        return self.gear2.internal

    @property
    def base_pitch(self) -> float:
        return self.gear1.base_pitch

    @property
    def operating_pitch_radii(self) -> tuple[float, float]:
        """r_w1 = a z1 / (z2 +/- z1), r_w2 = a z2 / (z2 +/- z1) [m] (- for an internal gear 2)."""
        z1, z2, a = self.gear1.teeth, self.gear2.teeth, self.centre_distance
        den = z2 - z1 if self.internal else z1 + z2
        return a * z1 / den, a * z2 / den

    @property
    def transverse_contact_ratio(self) -> float:
        """eps_alpha from the tip radii, base radii and operating centre distance."""
        g1, g2 = self.gear1, self.gear2
        ga1 = math.sqrt(g1.tip_radius**2 - g1.base_radius**2)
        ga2 = math.sqrt(g2.tip_radius**2 - g2.base_radius**2)
        gw = self.centre_distance * math.sin(self.operating_pressure_angle)
        length = ga1 - ga2 + gw if self.internal else ga1 + ga2 - gw
        return length / self.base_pitch

    def overlap_ratio(self, face_width: float) -> float:
        """eps_beta = b sin(beta) / (pi m_n) for the face width b [m] of one helix."""
        return face_width * math.sin(self.gear1.helix_angle) / (math.pi * self.gear1.normal_module)

    @property
    def approach_length(self) -> float:
        """Distance [m] along the line of action from the start of contact A to the pitch point C.

        Gear 1 drives, so contact starts on the driven gear's tip circle:
        external: g_f = sqrt(r_a2^2 - r_b2^2) - r_w2 sin(a_w); internal: g_f = r_w2 sin(a_w) - sqrt(r_a2^2 - r_b2^2).
        """
        g2, aw = self.gear2, self.operating_pressure_angle
        tip = math.sqrt(g2.tip_radius**2 - g2.base_radius**2)
        pitch = g2.base_radius * math.tan(aw)  # r_w2 sin(a_w) = r_b2 tan(a_w)
        return pitch - tip if self.internal else tip - pitch

    @property
    def normal_backlash(self) -> float:
        """Normal backlash from the tooth thinning of both gears, j_n = (ds1 + ds2) cos(alpha_n) [m].

        The no-backlash centre distance equation places the unthinned flanks in contact, so the
        thinning alone opens the backlash.
        """
        return (self.gear1.thinning + self.gear2.thinning) * math.cos(self.gear1.normal_pressure_angle)


Mesh = GearMesh
"""Deprecated alias of :class:`GearMesh` (kept for one release; 'mesh' alone also means an FE mesh)."""


def tooth_normal_local(mesh: GearMesh, drive_sign: float, hand: int) -> tuple[float, float, float]:
    """Tooth normal (force on gear 2) at the pitch point in gear 1's local (radial, tangential, axial) frame.

    n = cos(beta_b) t - h s sin(beta_b) e_z with t = sin(alpha_wt) e_r + s cos(alpha_wt) e_t: the normal
    of flexgear.mbs.contacts.pair_contacts (s: ``drive_sign``, h: ``hand`` of gear 1 in the helix half). An
    internal gear 2 has the same local components; an external gear 2 (e_r, e_t reversed)
    (-n_r, -n_t, n_z).
    """
    s = 1.0 if drive_sign >= 0 else -1.0
    alpha, beta_b = mesh.operating_pressure_angle, mesh.gear1.base_helix_angle
    return (math.cos(beta_b) * math.sin(alpha), s * math.cos(beta_b) * math.cos(alpha),
            -hand * s * math.sin(beta_b))


@dataclass(frozen=True)
class HelixHalf:
    """One helix of a single- or double-helical gear: axial mid-plane z [m], hand of gear 1, face-width share."""

    z: float
    hand: int
    share: float


def helix_halves(layout: str, helix_face_width: float, half_gap: float, hand: int = 1) -> list[HelixHalf]:
    """Helix halves of a ``"single"`` or ``"double"`` (herringbone) layout; ``hand``: gear 1 in the half at +z."""
    if hand not in (1, -1):
        raise ValueError(f"hand must be +1 (right) or -1 (left), got {hand!r}")
    if layout == "single":
        return [HelixHalf(0.0, hand, 1.0)]
    if layout == "double":
        z = 0.5 * (helix_face_width + half_gap)
        return [HelixHalf(z, hand, 0.5), HelixHalf(-z, -hand, 0.5)]
    raise ValueError(f"helix_layout must be 'single' or 'double', got {layout!r}")


@dataclass(frozen=True)
class GearSetGeometry:
    """Sun, planet, ring and the two meshes of a single-stage planetary/star set; of a parallel-axis pair the sun
    (pinion), the one planet (wheel) and their mesh, ``ring`` and ``planet_ring`` None."""

    sun: Gear
    planet: Gear
    ring: Gear | None
    sun_planet: GearMesh
    planet_ring: GearMesh | None
    centre_distance: float
    planet_count: int
    helix_layout: str
    half_gap: float
    planet_positions: tuple[float, ...] = ()  # each planet's polar angle [rad]; () = equally spaced from 0

    @property
    def named_gears(self) -> tuple[tuple[str, Gear], ...]:
        """(name, gear) of each gear of the set: sun, planet and, where there is one, ring."""
        return tuple((n, g) for n, g in (("sun", self.sun), ("planet", self.planet), ("ring", self.ring))
                     if g is not None)

    @property
    def named_meshes(self) -> tuple[tuple[tuple[str, str], GearMesh], ...]:
        """((gear 1, gear 2), mesh) of each mesh of the set: sun-planet and, where there is a ring, planet-ring."""
        return tuple((n, m) for n, m in ((("sun", "planet"), self.sun_planet), (("planet", "ring"), self.planet_ring))
                     if m is not None)

    @property
    def helix_face_width(self) -> float:
        """Face width of one helix: half the total for a double-helical set [m]."""
        total = self.sun.face_width
        return total / 2 if self.helix_layout == "double" else total

    @property
    def planet_angles(self) -> np.ndarray:
        """Angular positions of the planets [rad]: ``planet_positions``, else equally spaced from 0."""
        if self.planet_positions:
            return np.asarray(self.planet_positions, float)
        return 2 * math.pi * np.arange(self.planet_count) / self.planet_count


def min_planet_gap(angles: np.ndarray | tuple[float, ...]) -> float:
    """Smallest polar angle between neighbouring planets [rad] (pi for one planet: no neighbour closer than the
    far side)."""
    psi = np.sort(np.mod(np.asarray(angles, float), 2 * math.pi))
    if psi.size < 2:
        return math.pi
    return float(np.diff(np.r_[psi, psi[0] + 2 * math.pi]).min())


def _mesh_angle(z1: int, z2: int, x1: float, x2: float, alpha_n: float, alpha_t: float) -> float:
    """Operating transverse pressure angle of the no-backlash mesh (signed tooth counts)."""
    return inv_inverse(inv(alpha_t) + 2 * math.tan(alpha_n) * (x1 + x2) / (z1 + z2))


def solve_profile_shifts(
    z_sun: int, z_planet: int, z_ring: int, normal_module: float, helix_angle: float,
    normal_pressure_angle: float, centre_distance: float, planet_shift: float,
) -> tuple[float, float, float, float, float]:
    """Profile shifts giving one operating centre distance for both meshes.

    With the planet shift chosen, the no-backlash mesh equation fixes the sun shift from the
    sun-planet operating pressure angle and the ring shift from the planet-ring one.

    Returns ``(x_sun, x_planet, x_ring, alpha_wt_sun_planet, alpha_wt_planet_ring)``.
    """
    alpha_t = transverse_pressure_angle(normal_pressure_angle, helix_angle)
    mt = normal_module / math.cos(helix_angle)
    tan_an = math.tan(normal_pressure_angle)
    shifts = []
    angles = []
    for z_other in (z_sun, -z_ring):
        a0 = abs(mt * (z_planet + z_other) / 2)
        cos_w = a0 * math.cos(alpha_t) / centre_distance
        if not 0.0 < cos_w < 1.0:
            raise ValueError(f"centre distance {centre_distance} m cannot be reached (a0 = {a0} m)")
        alpha_w = math.acos(cos_w)
        x_sum = (inv(alpha_w) - inv(alpha_t)) * (z_planet + z_other) / (2 * tan_an)
        shifts.append(x_sum - planet_shift)
        angles.append(alpha_w)
    return shifts[0], planet_shift, shifts[1], angles[0], angles[1]


def pair_profile_shifts(z_pinion: int, z_wheel: int, normal_module: float, helix_angle: float,
                        normal_pressure_angle: float, centre_distance: float, wheel_shift: float,
                        ) -> tuple[float, float, float]:
    """Profile shifts of an external pair at ``centre_distance`` [m] with no backlash: the wheel's chosen, the
    pinion's from the no-backlash mesh equation; returns ``(x_pinion, x_wheel, alpha_wt)``."""
    alpha_t = transverse_pressure_angle(normal_pressure_angle, helix_angle)
    a0 = normal_module / math.cos(helix_angle) * (z_pinion + z_wheel) / 2
    cos_w = a0 * math.cos(alpha_t) / centre_distance
    if not 0.0 < cos_w < 1.0:
        raise ValueError(f"centre distance {centre_distance} m cannot be reached (a0 = {a0} m)")
    alpha_w = math.acos(cos_w)
    x_sum = (inv(alpha_w) - inv(alpha_t)) * (z_pinion + z_wheel) / (2 * math.tan(normal_pressure_angle))
    return x_sum - wheel_shift, wheel_shift, alpha_w


def gear_set_geometry(spec: GearboxSpec) -> GearSetGeometry:
    """Gears and meshes of the spec, profile-shifted to one operating centre distance.

    Computed once per distinct (gears, gears_assumed) content and shared by every stage that asks
    (geometry, FE, contacts, theory, lumped model): both are frozen dataclasses, so the cache key is
    their content.
    """
    return _gear_set_geometry(spec.gears, spec.gears_assumed)


def gear_set_geometry_of(gears: GearSet, assumed: GearSetAssumed) -> GearSetGeometry:
    """:func:`gear_set_geometry` from the two gear tables alone (``[gears]``, ``[gears_assumed]``), e.g. while the
    rest of a gearbox file is still being loaded (flexgear.sizing)."""
    return _gear_set_geometry(gears, assumed)


@functools.lru_cache(maxsize=64)
def _gear_set_geometry(g, a) -> GearSetGeometry:
    mn, beta, an = g.normal_module_m, g.helix_angle_rad, g.normal_pressure_angle_rad
    aw = a.operating_centre_distance_m
    mt = mn / math.cos(beta)
    if aw == 0.0:  # 0 selects the mean of the two standard centre distances (the pair's own standard one)
        aw = 0.25 * mt * (g.sun_teeth + g.ring_teeth) if g.has_ring else 0.5 * mt * (g.sun_teeth + g.planet_teeth)
    thinning = a.normal_backlash_m / (2 * math.cos(an))

    def gear(z: int, x: float, internal: bool) -> Gear:
        return Gear(z, internal, mn, beta, an, x, thinning, a.addendum_coefficient,
                    a.dedendum_coefficient, a.face_width_m)

    if not g.has_ring:  # the parallel-axis pair: the wheel's shift chosen, the pinion's from the centre distance
        xs, xp, aw_sp = pair_profile_shifts(g.sun_teeth, g.planet_teeth, mn, beta, an, aw, a.planet_shift_coefficient)
        sun, planet = gear(g.sun_teeth, xs, False), gear(g.planet_teeth, xp, False)
        return GearSetGeometry(sun, planet, None, GearMesh(sun, planet, aw, aw_sp), None, aw, 1, a.helix_layout,
                               a.half_gap_m)
    xs, xp, xr, aw_sp, aw_pr = solve_profile_shifts(
        g.sun_teeth, g.planet_teeth, g.ring_teeth, mn, beta, an, aw, a.planet_shift_coefficient
    )
    sun, planet, ring = gear(g.sun_teeth, xs, False), gear(g.planet_teeth, xp, False), gear(g.ring_teeth, xr, True)
    return GearSetGeometry(
        sun, planet, ring, GearMesh(sun, planet, aw, aw_sp), GearMesh(planet, ring, aw, aw_pr),
        aw, g.planet_count, a.helix_layout, a.half_gap_m, g.planet_positions_rad if g.planet_positions_deg else (),
    )
