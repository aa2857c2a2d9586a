"""Transverse tooth profiles: involute flanks, root fillets, tip and root arcs as exact curves.

One pitch of a gear's transverse section is built from parametric curve segments (SI units,
gear centre at the origin, tooth 0 centred on the +x axis):

- tip arc at the tip radius, across half the tooth (polar angle 0 .. psi(r_a)),
- involute flank, polar angle theta = psi(r) (``Gear.tooth_half_angle``), parametrised by the
  roll angle t: r = r_b sqrt(1 + t^2), inv(alpha_r) = t - atan(t),
- a radial line below the base circle when an external gear's fillet (or, without a fillet, its root
  circle) lies below it,
- root fillet: circular arc of radius rho tangent to the flank and to the root circle,
- root arc at the root radius up to the middle of the tooth space (polar angle pi/z).

The other half pitch is the mirror image (theta -> -theta). The same curves give the points
for the solid modeller (flexgear.geometry.solids) and the exact section integrals

    A = 1/2 closed-integral (x dy - y dx),     J = integral r^2 dA = 1/4 closed-integral r^2 (x dy - y dx)

(Green's theorem), evaluated with Gauss-Legendre quadrature per segment: the integrand is a
polynomial in t on involutes (r^2 dtheta = r_b^2 t^2 dt) and trigonometric on arcs, so the
quadrature is exact to rounding.

The fillet is a simplification of the generated trochoid (no hob simulation): its radius is the
documented ``root_fillet_coefficient * m_n`` of gearbox.toml.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.optimize import brentq

from flexgear.geometry.involute import Gear

__all__ = [
    "ArcSegment",
    "InvoluteSegment",
    "LineSegment",
    "ToothProfile",
    "tooth_profile",
    "sector_integrals",
    "mirror_segment",
]

_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(48)


@dataclass(frozen=True)
class ArcSegment:
    """Circular arc: centre (cx, cy) [m], radius [m], from angle phi0 to phi1 [rad]."""

    cx: float
    cy: float
    radius: float
    phi0: float
    phi1: float

    def points(self, s: np.ndarray) -> np.ndarray:
        phi = self.phi0 + (self.phi1 - self.phi0) * np.asarray(s, float)
        return np.column_stack([self.cx + self.radius * np.cos(phi), self.cy + self.radius * np.sin(phi)])

    def velocity(self, s: np.ndarray) -> np.ndarray:
        dphi = self.phi1 - self.phi0
        phi = self.phi0 + dphi * np.asarray(s, float)
        return dphi * self.radius * np.column_stack([-np.sin(phi), np.cos(phi)])


@dataclass(frozen=True)
class InvoluteSegment:
    """Involute of the base circle r_b [m]: polar angle theta0 + sign * (t - atan t), t from t0 to t1."""

    base_radius: float
    theta0: float
    sign: float
    t0: float
    t1: float

    def _t(self, s: np.ndarray) -> np.ndarray:
        return self.t0 + (self.t1 - self.t0) * np.asarray(s, float)

    def points(self, s: np.ndarray) -> np.ndarray:
        t = self._t(s)
        r = self.base_radius * np.sqrt(1 + t * t)
        theta = self.theta0 + self.sign * (t - np.arctan(t))
        return np.column_stack([r * np.cos(theta), r * np.sin(theta)])

    def velocity(self, s: np.ndarray) -> np.ndarray:
        t = self._t(s)
        r = self.base_radius * np.sqrt(1 + t * t)
        theta = self.theta0 + self.sign * (t - np.arctan(t))
        dr = self.base_radius * t / np.sqrt(1 + t * t)
        dtheta = self.sign * t * t / (1 + t * t)
        c, si = np.cos(theta), np.sin(theta)
        return (self.t1 - self.t0) * np.column_stack([dr * c - r * si * dtheta, dr * si + r * c * dtheta])


@dataclass(frozen=True)
class LineSegment:
    """Straight line from p0 to p1 [m]."""

    x0: float
    y0: float
    x1: float
    y1: float

    def points(self, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, float)[:, None]
        return (1 - s) * np.array([self.x0, self.y0]) + s * np.array([self.x1, self.y1])

    def velocity(self, s: np.ndarray) -> np.ndarray:
        d = np.array([self.x1 - self.x0, self.y1 - self.y0])
        return np.tile(d, (len(np.atleast_1d(s)), 1))


Segment = ArcSegment | InvoluteSegment | LineSegment


def sector_integrals(segments: list[Segment] | tuple[Segment, ...]) -> tuple[float, float]:
    """(1/2 int (x dy - y dx), 1/4 int r^2 (x dy - y dx)) along the segments [m^2, m^4].

    For a closed curve traversed counter-clockwise these are the enclosed area and polar second
    moment about the origin (Green's theorem); over an open part of a curve, the sector values.
    """
    s = 0.5 * (_GAUSS_NODES + 1)
    w = 0.5 * _GAUSS_WEIGHTS
    area = polar = 0.0
    for seg in segments:
        p, v = seg.points(s), seg.velocity(s)
        cross = p[:, 0] * v[:, 1] - p[:, 1] * v[:, 0]
        area += 0.5 * float(w @ cross)
        polar += 0.25 * float(w @ (cross * (p[:, 0] ** 2 + p[:, 1] ** 2)))
    return area, polar


def _roll(base_radius: float, radius: float) -> float:
    """Roll angle t = tan(alpha_r) of the involute point at ``radius``."""
    return math.sqrt(max(radius * radius / (base_radius * base_radius) - 1.0, 0.0))


@dataclass(frozen=True)
class ToothProfile:
    """Half a pitch of a gear's transverse section (tooth centre to space centre), exact curves.

    ``half_pitch`` runs with increasing polar angle from the tooth centre line (angle 0) to the
    space centre line (angle pi/z). For an external gear the curves bound the gear from outside;
    for an internal gear they bound the hole (tips inside, root circle outside).
    """

    gear: Gear
    fillet_radius: float
    half_pitch: tuple[Segment, ...]
    fillet_center: tuple[float, float]
    form_radius: float  # where the fillet meets the flank [m]

    @property
    def teeth(self) -> int:
        return self.gear.teeth

    @cached_property
    def outline_integrals(self) -> tuple[float, float]:
        """(area, polar moment about the axis) of the region inside the full outline [m^2, m^4]."""
        a, j = sector_integrals(self.half_pitch)
        return 2 * self.teeth * a, 2 * self.teeth * j

    def pitch_segments(self) -> list[Segment]:
        """One full pitch from the space centre at -pi/z to the space centre at +pi/z."""
        mirrored = [mirror_segment(seg) for seg in reversed(self.half_pitch)]
        return mirrored + list(self.half_pitch)

    def sample(self, points_per_segment: int = 25) -> np.ndarray:
        """Closed outline of the whole gear as an (n, 2) array [m], counter-clockwise, not repeated."""
        pitch = np.vstack([seg.points(np.linspace(0, 1, points_per_segment))[:-1] for seg in self.pitch_segments()])
        out = []
        for k in range(self.teeth):
            a = 2 * math.pi * k / self.teeth
            rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
            out.append(pitch @ rot.T)
        return np.vstack(out)

    def outline_curves(self) -> list[tuple[str, float]]:
        """(name, length [m]) of each curve of one pitch of the outline as the solid modeller builds it, one
        edge each: the full tip land (twice its half-pitch part), an involute flank, the radial flank below the
        base circle (if any), the root fillet (if any) and the full root land. Lengths by Gauss-Legendre
        quadrature of |dp/ds| (exact to rounding on arcs and lines)."""
        s = 0.5 * (_GAUSS_NODES + 1)
        w = 0.5 * _GAUSS_WEIGHTS
        half = self.half_pitch
        names = ["tip land", "involute flank"] + [
            "radial flank" if isinstance(seg, LineSegment) else "root fillet" for seg in half[2:-1]] + ["root land"]
        lengths = [float(w @ np.linalg.norm(seg.velocity(s), axis=1)) for seg in half]
        return [(n, length * (2 if n in ("tip land", "root land") else 1))
                for n, length in zip(names, lengths, strict=True)]

    def flank_segment(self) -> InvoluteSegment:
        """The involute part of the upper flank of tooth 0."""
        return next(seg for seg in self.half_pitch if isinstance(seg, InvoluteSegment))


def mirror_segment(seg: Segment) -> Segment:
    """Mirror image in the x axis, traversed in the opposite direction (keeps orientation)."""
    if isinstance(seg, ArcSegment):
        return ArcSegment(seg.cx, -seg.cy, seg.radius, -seg.phi1, -seg.phi0)
    if isinstance(seg, InvoluteSegment):
        return InvoluteSegment(seg.base_radius, -seg.theta0, -seg.sign, seg.t1, seg.t0)
    return LineSegment(seg.x1, -seg.y1, seg.x0, -seg.y0)


def _flank_point(gear: Gear, r: float) -> tuple[np.ndarray, np.ndarray]:
    """Point of the upper flank of tooth 0 at radius r and unit normal into the tooth space.

    Below the base circle (external gears only) the flank continues radially.
    """
    rb = gear.base_radius
    theta = gear.tooth_half_angle(max(r, rb))
    radial = np.array([math.cos(theta), math.sin(theta)])
    tangential = np.array([-math.sin(theta), math.cos(theta)])
    # d theta / d r = -/+ tan(alpha_r)/r (external/internal), tangent = e_r + r theta' e_theta
    slope = math.sqrt(max(r * r - rb * rb, 0.0)) / rb if r > rb else 0.0
    tangent = radial + (slope if gear.internal else -slope) * tangential
    tangent /= np.linalg.norm(tangent)
    normal = np.array([-tangent[1], tangent[0]])  # counter-clockwise: towards the space
    return r * radial, normal


def tooth_profile(gear: Gear, fillet_radius: float) -> ToothProfile:
    """Half-pitch profile of ``gear`` with a root fillet of radius ``fillet_radius`` [m].

    The fillet centre lies on the circle r_f + rho (external) or r_f - rho (internal) and at
    distance rho from the flank; it is found by root bracketing along the flank. Raises
    ValueError if the tooth is pointed or the fillets of one space overlap.
    """
    z, rb, ra, rf, rho = gear.teeth, gear.base_radius, gear.tip_radius, gear.root_radius, fillet_radius
    half_space = math.pi / z
    if gear.internal and ra <= rb:
        raise ValueError(f"internal gear tip radius {ra} m is inside the base circle {rb} m")
    if gear.tooth_half_angle(ra) <= 0:
        raise ValueError(f"pointed tooth: tooth thickness at the tip radius {ra} m is not positive")
    target = rf - rho if gear.internal else rf + rho

    def miss(r: float) -> float:
        p, n = _flank_point(gear, r)
        return float(np.linalg.norm(p + rho * n)) - target

    lo, hi = (ra, rf) if gear.internal else (rf, ra)
    if rho > 0:
        if miss(lo) * miss(hi) > 0:
            raise ValueError(f"root fillet of radius {rho} m does not fit between flank and root circle")
        r_form = brentq(miss, lo, hi, xtol=1e-13)
    else:  # no fillet: the flank (radial below an external gear's base circle) runs down to the root circle
        r_form = rf
    p_form, n_form = _flank_point(gear, r_form)
    centre = p_form + rho * n_form
    root_point = centre * (rf / np.linalg.norm(centre))
    root_angle = math.atan2(root_point[1], root_point[0])
    if root_angle >= half_space:
        raise ValueError(f"root fillets of radius {rho} m overlap in the tooth space (z = {z})")

    psi_tip = gear.tooth_half_angle(ra)
    segments: list[Segment] = [ArcSegment(0.0, 0.0, ra, 0.0, psi_tip)]
    theta_b = gear.tooth_half_angle(rb)
    # polar angle of the flank: theta_b -/+ inv(alpha_r); inv = t - atan t
    sign = 1.0 if gear.internal else -1.0
    t_tip, t_form = _roll(rb, ra), _roll(rb, max(r_form, rb))
    segments.append(InvoluteSegment(rb, theta_b, sign, t_tip, t_form))
    if not gear.internal and r_form < rb:
        segments.append(LineSegment(*(rb * p_form / r_form), *p_form))
    if rho > 0:
        phi0 = math.atan2(p_form[1] - centre[1], p_form[0] - centre[0])
        phi1 = math.atan2(root_point[1] - centre[1], root_point[0] - centre[0])
        phi1 = phi0 + math.remainder(phi1 - phi0, 2 * math.pi)  # the short way round
        segments.append(ArcSegment(float(centre[0]), float(centre[1]), rho, phi0, phi1))
    segments.append(ArcSegment(0.0, 0.0, rf, root_angle, half_space))
    return ToothProfile(gear, rho, tuple(segments), (float(centre[0]), float(centre[1])), float(r_form))
