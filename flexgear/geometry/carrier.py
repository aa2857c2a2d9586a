"""A planet carrier: two side plates joined by posts between the planets, its solid and exact mass properties.

The carrier of a planetary stage holds each planet's pin in its two side plates and turns with them. Component
frame: z the gearbox axis, the origin on the planets' axial mid-plane, planet k's pin on the pin circle (the
operating centre distance a_w) at the gear set's polar angle psi_k (flexgear.geometry.involute.GearSetGeometry).

- **Plates**: two annuli between the bore radius r_b and the outer radius R_p, thickness t, their inner faces a gap
  g apart (the gears' length and an axial clearance on each side), each with N pin bores of radius r_pin on the pin
  circle. The output-side plate (+z) sits on the output shaft by its bore (the carrier's seat).
- **Posts**: between the plates, the annulus between R_1 (clear of the sun's tip circle) and R_p, with a window of
  radius r_w (the planet's tip circle and a clearance) round each planet, which cuts it into N posts.

Sizes follow the gear set (:class:`CarrierSizes`, each a named default relative to the module, the pin or the face
width, and each may be given). Exact mass properties (:func:`carrier_mass_properties`) integrate the sections, for
any planet positions, by their area A, first moments Q = int (x, y) dA and second moments S = int (x, y) (x, y)^T dA:
a plate is the annulus between r_b and R_p less N pin bores (discs: A = pi r_pin^2, Q = A c, S = A (r_pin^2 / 4 I +
c c^T) at centre c); the posts' annulus less the part of each window inside it, in the window's own axes (x'
towards its centre)

    A_w = int phi r dr,   Q_x' = int 2 sin(phi / 2) r^2 dr,   S_x'x', S_y'y' = int (phi +- sin phi) r^3 / 2 dr,
    phi(r) = 2 acos((r^2 + a_w^2 - r_w^2) / (2 a_w r))   (R_1 <= r <= R_p)

(phi the window's angular width at radius r, 0 or 2 pi beyond its reach), by Gauss-Legendre quadrature on the
pieces between the points where phi has a square-root end (r = a_w -+ r_w), then turned to the planet's angle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from flexgear.geometry.involute import gear_set_geometry_of, min_planet_gap
from flexgear.geometry.massprops import MassProperties
from flexgear.schema import ComponentsAssumed, GearSet, GearSetAssumed
from flexgear.spec import GearboxSpec

__all__ = ["CarrierSizes", "carrier_sizes", "carrier_sizes_of", "carrier_solid", "carrier_mass_properties",
           "PIN_PER_PLANET_BORE", "PLATE_THICKNESS_PER_FACE_WIDTH", "CLEARANCE_PER_MODULE", "PLATE_LIGAMENT_PER_PIN"]

PIN_PER_PLANET_BORE = 0.6
"""Pin diameter over the planet's bore diameter (the planet bearing's rings and rolling elements in between)."""
PLATE_THICKNESS_PER_FACE_WIDTH = 0.5
"""Side plate thickness over the gears' face width (the toothed width, both helices of a double-helical gear
together, as flexgear.geometry.layout lays the teeth out)."""
CLEARANCE_PER_MODULE = 1.0
"""Radial clearance of the posts to the sun's and the planets' tip circles, and axial clearance of the plates to
the gears' faces, in normal modules."""
PLATE_LIGAMENT_PER_PIN = 1.0
"""Plate material outside the pin bores, radially, in pin radii: R_p = a_w + (1 + this) r_pin."""
_QUADRATURE_POINTS = 64
"""Gauss-Legendre points per piece of the window integrals (a square-root end: the error falls as n^-3; 64 points
give about 1e-7 of the window's area)."""


@dataclass(frozen=True)
class CarrierSizes:
    """A carrier's dimensions [m] (module docstring): pin circle ``pin_circle_radius`` a_w, planets' polar angles
    ``planet_angles`` [rad]."""

    pin_circle_radius: float
    planet_angles: tuple[float, ...]
    pin_radius: float
    bore_radius: float
    plate_outer_radius: float
    plate_thickness: float
    gap: float
    post_inner_radius: float
    window_radius: float

    @property
    def planet_count(self) -> int:
        return len(self.planet_angles)

    def pin_centres(self) -> np.ndarray:
        """(N, 3) pin centres on the axial mid-plane [m]."""
        psi = np.asarray(self.planet_angles)
        return np.column_stack([self.pin_circle_radius * np.cos(psi), self.pin_circle_radius * np.sin(psi),
                                np.zeros(len(psi))])

    def check(self) -> None:
        """ValueError naming the dimension when the carrier cannot be built (module docstring's order of radii)."""
        a, n = self.pin_circle_radius, self.planet_count
        if not 0.0 < self.bore_radius < self.post_inner_radius < self.plate_outer_radius:
            raise ValueError(f"carrier: need 0 < bore radius ({self.bore_radius:.6g} m) < posts' inner radius "
                             f"({self.post_inner_radius:.6g} m) < plate outer radius ({self.plate_outer_radius:.6g} m)")
        if not self.pin_radius > 0.0 or a + self.pin_radius >= self.plate_outer_radius:
            raise ValueError(f"carrier: the pin bores (radius {self.pin_radius:.6g} m on {a:.6g} m) must lie inside "
                             f"the plates (outer radius {self.plate_outer_radius:.6g} m)")
        if a - self.pin_radius <= self.bore_radius:
            raise ValueError("carrier: the pin bores reach the plates' central bore")
        if n >= 2 and 2.0 * self.window_radius >= 2.0 * a * math.sin(min_planet_gap(self.planet_angles) / 2):
            raise ValueError(f"carrier: the planets' windows (radius {self.window_radius:.6g} m) overlap: no room for "
                             f"posts between {n} planets on a {a:.6g} m pin circle")
        if not (self.plate_thickness > 0.0 and self.gap > 0.0):
            raise ValueError("carrier: plate thickness and gap must be positive")


def carrier_sizes(spec: GearboxSpec, **given: float) -> CarrierSizes:
    """The carrier of ``spec``'s gear set with the default sizes (module constants), any of them ``given`` [m] by
    its :class:`CarrierSizes` name; checked (ValueError naming the dimension)."""
    return carrier_sizes_of(spec.gears, spec.gears_assumed, spec.components_assumed, **given)


def carrier_sizes_of(gears: GearSet, a: GearSetAssumed, c: ComponentsAssumed, **given: float) -> CarrierSizes:
    """:func:`carrier_sizes` from the tables ``[gears]``, ``[gears_assumed]`` and ``[components_assumed]`` alone
    (e.g. while the rest of a gearbox file is loaded, flexgear.sizing)."""
    gs = gear_set_geometry_of(gears, a)
    module = gears.normal_module_mm * 1e-3
    clearance = CLEARANCE_PER_MODULE * module
    length = a.face_width_m + (a.half_gap_m if a.helix_layout == "double" else 0.0)
    pin = PIN_PER_PLANET_BORE * c.planet_bore_diameter_mm * 1e-3 / 2
    sizes = CarrierSizes(
        pin_circle_radius=gs.centre_distance, planet_angles=tuple(float(p) for p in gs.planet_angles),
        pin_radius=pin, bore_radius=c.input_shaft_outer_diameter_mm * 1e-3 / 2 + clearance,
        plate_outer_radius=min(gs.centre_distance + (1.0 + PLATE_LIGAMENT_PER_PIN) * pin,
                               gs.ring.tip_radius - clearance),
        plate_thickness=PLATE_THICKNESS_PER_FACE_WIDTH * a.face_width_m, gap=length + 2.0 * clearance,
        post_inner_radius=gs.sun.tip_radius + clearance, window_radius=gs.planet.tip_radius + clearance)
    unknown = set(given) - set(CarrierSizes.__dataclass_fields__)
    if unknown:
        raise ValueError(f"carrier_sizes: unknown sizes {sorted(unknown)}; allowed: "
                         f"{', '.join(CarrierSizes.__dataclass_fields__)}")
    sizes = replace(sizes, **given)
    sizes.check()
    return sizes


def carrier_solid(sizes: CarrierSizes):
    """One OCC solid (netgen.occ) of the carrier in its component frame (module docstring)."""
    from netgen import occ

    s = sizes
    half = s.gap / 2

    def cylinder(x: float, y: float, z0: float, length: float, radius: float):
        return occ.Cylinder(occ.Pnt(x, y, z0), occ.Z, radius, length)

    pins = [(float(x), float(y)) for x, y, _ in s.pin_centres()]
    plates = []
    for z0 in (-half - s.plate_thickness, half):
        plate = cylinder(0, 0, z0, s.plate_thickness, s.plate_outer_radius) - cylinder(
            0, 0, z0 - s.plate_thickness, 3 * s.plate_thickness, s.bore_radius)
        for x, y in pins:
            plate = plate - cylinder(x, y, z0 - s.plate_thickness, 3 * s.plate_thickness, s.pin_radius)
        plates.append(plate)
    cage = cylinder(0, 0, -half, s.gap, s.plate_outer_radius) - cylinder(0, 0, -half - s.gap, 3 * s.gap,
                                                                          s.post_inner_radius)
    for x, y in pins:
        cage = cage - cylinder(x, y, -half - s.gap, 3 * s.gap, s.window_radius)
    return plates[0] + cage + plates[1]


@dataclass(frozen=True)
class _Section:
    """A plane section's area A [m^2], first moments Q = int (x, y) dA [m^3] and second moments S = int (x, y)
    (x, y)^T dA [m^4] about the axis."""

    area: float
    first: np.ndarray
    second: np.ndarray

    def __sub__(self, other: _Section) -> _Section:
        return _Section(self.area - other.area, self.first - other.first, self.second - other.second)

    def __add__(self, other: _Section) -> _Section:
        return _Section(self.area + other.area, self.first + other.first, self.second + other.second)


def _annulus(r_in: float, r_out: float) -> _Section:
    """Annulus between radii ``r_in`` and ``r_out``: A = pi (R^2 - r^2), S = pi (R^4 - r^4) / 4 I."""
    return _Section(math.pi * (r_out**2 - r_in**2), np.zeros(2), math.pi * (r_out**4 - r_in**4) / 4 * np.eye(2))


def _disc(radius: float, centre: np.ndarray) -> _Section:
    """Disc of ``radius`` at ``centre`` (2,): A = pi r^2, Q = A c, S = A (r^2 / 4 I + c c^T)."""
    area = math.pi * radius**2
    return _Section(area, area * centre, area * (radius**2 / 4 * np.eye(2) + np.outer(centre, centre)))


def _window(a: float, rw: float, r1: float, r2: float, psi: float) -> _Section:
    """The part between radii ``r1`` and ``r2`` of a window of radius ``rw`` centred at distance ``a`` from the
    axis at polar angle ``psi`` (module docstring), in its own axes (x' towards the window) first:
    A = int phi r dr, Q_x' = int 2 sin(phi / 2) r^2 dr, S_x'x' = int (phi + sin phi) r^3 / 2 dr,
    S_y'y' = int (phi - sin phi) r^3 / 2 dr; then turned by ``psi``."""
    cuts = sorted({r1, r2, *(r for r in (a - rw, a + rw) if r1 < r < r2)})
    x, w = np.polynomial.legendre.leggauss(_QUADRATURE_POINTS)
    area = first = s_xx = s_yy = 0.0
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        r = 0.5 * (hi - lo) * x + 0.5 * (hi + lo)
        cos_half = (r**2 + a**2 - rw**2) / (2.0 * a * r)
        phi = 2.0 * np.arccos(np.clip(cos_half, -1.0, 1.0))
        half = 0.5 * (hi - lo)
        area += half * float(np.sum(w * phi * r))
        first += half * float(np.sum(w * 2.0 * np.sin(phi / 2) * r**2))
        s_xx += half * float(np.sum(w * (phi + np.sin(phi)) * r**3 / 2))
        s_yy += half * float(np.sum(w * (phi - np.sin(phi)) * r**3 / 2))
    turn = np.array([[math.cos(psi), -math.sin(psi)], [math.sin(psi), math.cos(psi)]])
    return _Section(area, first * turn[:, 0], turn @ np.diag([s_xx, s_yy]) @ turn.T)


def _prisms_mass_properties(prisms: list[tuple[_Section, float, float]], rho: float) -> MassProperties:
    """Mass properties of prisms along z, each (section, z0, z1 [m]), at density ``rho`` [kg/m^3]: about the
    origin I_xx = rho (S_yy L + A (z1^3 - z0^3) / 3), I_yy likewise, I_zz = rho (S_xx + S_yy) L,
    I_xy = -rho S_xy L, I_xz = -rho Q_x (z1^2 - z0^2) / 2, I_yz likewise; then moved to the centre of mass."""
    mass, moment, inertia = 0.0, np.zeros(3), np.zeros((3, 3))
    for sec, z0, z1 in prisms:
        length, z2, z3 = z1 - z0, (z1**2 - z0**2) / 2, (z1**3 - z0**3) / 3
        mass += rho * sec.area * length
        moment += rho * np.array([sec.first[0] * length, sec.first[1] * length, sec.area * z2])
        sxx, syy, sxy = sec.second[0, 0], sec.second[1, 1], sec.second[0, 1]
        inertia += rho * np.array([[syy * length + sec.area * z3, -sxy * length, -sec.first[0] * z2],
                                   [-sxy * length, sxx * length + sec.area * z3, -sec.first[1] * z2],
                                   [-sec.first[0] * z2, -sec.first[1] * z2, (sxx + syy) * length]])
    com = moment / mass
    return MassProperties(mass, com, inertia - mass * (com @ com * np.eye(3) - np.outer(com, com)))


def carrier_mass_properties(sizes: CarrierSizes, density: float) -> MassProperties:
    """Mass [kg], centre of mass [m] and inertia about it [kg m^2] of the carrier of ``sizes`` at ``density``
    [kg/m^3], from the exact section integrals (module docstring), for any planet positions: unequally spaced
    pins and windows move the centre of mass off the axis and make the transverse inertia unequal."""
    s = sizes
    centres = s.pin_centres()[:, :2]
    plate = _annulus(s.bore_radius, s.plate_outer_radius)
    posts = _annulus(s.post_inner_radius, s.plate_outer_radius)
    for c, psi in zip(centres, s.planet_angles, strict=True):
        plate = plate - _disc(s.pin_radius, c)
        posts = posts - _window(s.pin_circle_radius, s.window_radius, s.post_inner_radius, s.plate_outer_radius,
                                psi)
    half = s.gap / 2
    return _prisms_mass_properties([(plate, -half - s.plate_thickness, -half), (posts, -half, half),
                                    (plate, half, half + s.plate_thickness)], density)
