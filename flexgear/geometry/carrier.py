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
width, and each may be given). Exact mass properties (:func:`carrier_mass_properties`) integrate the sections: a
plate's area A = pi (R_p^2 - r_b^2) - N pi r_pin^2, polar moment J = pi (R_p^4 - r_b^4) / 2 - N pi r_pin^2 (r_pin^2
/ 2 + a_w^2); the posts' annulus less the part of each window inside it, whose area and polar moment are

    A_w = int_R1^R2 phi(r) r dr,   J_w = int_R1^R2 phi(r) r^3 dr,   phi(r) = 2 acos((r^2 + a_w^2 - r_w^2) / (2 a_w r))

(phi the window's angular width at radius r, 0 or 2 pi beyond its reach), by Gauss-Legendre quadrature on the
pieces between the points where phi has a square-root end (r = a_w -+ r_w).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from flexgear.geometry.involute import gear_set_geometry_of
from flexgear.geometry.layout import stacked_prism_mass_properties
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
        if n >= 2 and 2.0 * self.window_radius >= 2.0 * a * math.sin(math.pi / n):
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


def _window_integrals(a: float, rw: float, r1: float, r2: float) -> tuple[float, float]:
    """(A_w, J_w) of the module docstring: area [m^2] and polar moment [m^4] of the part of a window of radius
    ``rw`` centred at distance ``a`` from the axis that lies between radii ``r1`` and ``r2``."""
    cuts = sorted({r1, r2, *(r for r in (a - rw, a + rw) if r1 < r < r2)})
    x, w = np.polynomial.legendre.leggauss(_QUADRATURE_POINTS)
    area = polar = 0.0
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        r = 0.5 * (hi - lo) * x + 0.5 * (hi + lo)
        cos_half = (r**2 + a**2 - rw**2) / (2.0 * a * r)
        phi = 2.0 * np.arccos(np.clip(cos_half, -1.0, 1.0))
        area += 0.5 * (hi - lo) * float(np.sum(w * phi * r))
        polar += 0.5 * (hi - lo) * float(np.sum(w * phi * r**3))
    return area, polar


def carrier_mass_properties(sizes: CarrierSizes, density: float) -> MassProperties:
    """Mass [kg], centre of mass [m] and inertia about it [kg m^2] of the carrier of ``sizes`` at ``density``
    [kg/m^3], from the exact section integrals (module docstring); the pins' N-fold pattern (N >= 3) makes the
    transverse inertia axisymmetric."""
    s = sizes
    n, a = s.planet_count, s.pin_circle_radius
    plate_area = math.pi * (s.plate_outer_radius**2 - s.bore_radius**2) - n * math.pi * s.pin_radius**2
    plate_polar = (math.pi * (s.plate_outer_radius**4 - s.bore_radius**4) / 2
                   - n * math.pi * s.pin_radius**2 * (s.pin_radius**2 / 2 + a**2))
    win_area, win_polar = _window_integrals(a, s.window_radius, s.post_inner_radius, s.plate_outer_radius)
    post_area = math.pi * (s.plate_outer_radius**2 - s.post_inner_radius**2) - n * win_area
    post_polar = math.pi * (s.plate_outer_radius**4 - s.post_inner_radius**4) / 2 - n * win_polar
    half = s.gap / 2
    return stacked_prism_mass_properties([(plate_area, plate_polar, -half - s.plate_thickness, -half),
                                          (post_area, post_polar, -half, half),
                                          (plate_area, plate_polar, half, half + s.plate_thickness)], density)
