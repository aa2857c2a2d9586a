"""Component geometry as axial stacks of (helically twisted) prisms, and their exact mass properties.

Every component is a union of non-overlapping prisms: a transverse section (annulus, external
gear with bore, internal gear in a rim, annulus with bolt holes) extruded from z0 to z1 and, for
helical teeth, rotated about the axis at the rate dtheta/dz = hand * tan(beta) / r (lead
2 pi r / tan beta). The same layout drives the solid modeller (flexgear.geometry.solids) and the exact
integrals here.

Component frames (z = rotation axis, SI units):

- sun, planet, ring: origin at the gear's axial mid-plane centre. Double-helical (default): the
  two halves of opposite hand, each half the face width, occupy |z| in [g/2, g/2 + b/2] with the
  relief groove (gap g, ``relief_groove_depth_mm`` beyond the root circle) between them.
  Single-helical: one helix over |z| <= b/2. Hands: sun +, planet -, ring - (external pairs have
  opposite hands, an internal pair the same hand).
- ring: rim of ``ring_rim_thickness_mm`` below the tooth root; the bolt flange is a collar axially
  beyond the teeth at the +z end (so the output shaft's web clears the planets), from the groove
  radius to the flange diameter, with the bolt holes on the circle midway between rim and flange
  outer radius.
- input_shaft: origin at the sun's centre; a tube through the sun bore from the sun's +z face
  along -z for its length; bearing seat at the far (-z) end.
- output_shaft: origin at the ring's centre; a web of the flange thickness bolted to the ring
  flange (same bolt holes), then the tube along +z for its length measured from the ring flange
  face; bearing seat at the far (+z) end.

Mass properties: a section with n >= 3-fold symmetry has its centroid on the axis and equal
in-plane second moments J/2, and rotating it does not change either, so for a prism

    m = rho A L,  I_zz = rho J L,  I_xx = I_yy = rho (J L / 2 + A (z1^3 - z0^3) / 3)  (about the origin)

exactly, with A and J of the section from Green's theorem on the exact tooth curves
(flexgear.geometry.profile). Results are cached as JSON under ``meshes/`` keyed by a hash of every input.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from flexgear.cache import atomic_write_bytes, cache_dir
from flexgear.geometry.involute import Gear, GearSetGeometry, gear_set_geometry
from flexgear.geometry.massprops import MassProperties
from flexgear.geometry.profile import ToothProfile, tooth_profile
from flexgear.spec import GEOMETRY_COMPONENTS, GearboxSpec, spec_hash

__all__ = [
    "Section",
    "Prism",
    "ComponentLayout",
    "tooth_profiles",
    "gear_profiles",
    "component_layout",
    "gear_set_layout",
    "toothed_prisms",
    "section_integrals",
    "exact_mass_properties",
    "layout_mass_properties",
    "component_mass_properties",
    "stacked_prism_mass_properties",
    "cached_mass_properties",
    "geometry_hash",
    "HelixSweep",
    "helix_sweep",
    "GEOMETRY_VERSION",
]

_HANDS = {"sun": 1.0, "planet": -1.0, "ring": -1.0}
GEOMETRY_VERSION = 3
"""Version of the geometry construction, part of every geometry cache key (:func:`geometry_hash`, the toothed
bodies' solids): bump when the construction changes, which invalidates every cache entry. 3: the solids are
meshed in their STEP exchange form (flexgear.fe.parts.exchange_form)."""




_SWEEP_TOLERANCE = 1e-7
"""Largest deviation [m] of a helical sweep's faces from the exact twisted outline (:func:`helix_sweep`)."""
_SWEEP_ERROR = 2.6e-3
"""Measured e / (r theta^4) of netgen's sweep in metres (OCC's pipe shell, approximation tolerance 1e-4 in model
units), e the largest distance of the second-order mesh's lateral surface nodes from the exact twisted outline,
r the outer radius of the toothed band and theta the twist angle of the sweep: 2.6e-3 for the study's sun and
planet (theta = 0.136 and 0.133 rad, e = 0.049 and 0.044 um) and for a 13-tooth sun of m_n = 10 mm,
beta = 30 deg (theta = 0.46 rad, e = 9.4 um)."""
_PLAIN_MIN_CURVE = 0.2e-3
"""Shortest outline curve [m] a sweep in metres takes: it failed with a tip land or radial flank of 0.1 mm and a
fillet arc of 0.05 mm (m_n 1, 3 and 10 mm; OCC's approximation tolerance is 0.1 mm there) and built them from
0.12-0.15 mm on."""
_PRECISE_SCALE = 1000.0
"""Scale of a precise sweep: built in millimetres (OCC's approximation tolerance 1e-4 mm), then scaled back."""
_PRECISE_ANGLE = 0.5
"""Largest twist angle [rad] of one precise sweep. Measured: the 13-tooth sun above in one precise sweep of
0.46 rad 0.024 um (9.4 um in metres); a 12-tooth sun of m_n 1 mm, beta 45 deg 0.06 um at 1.18 rad and 0.24 um at
3.54 rad in one sweep."""


@dataclass(frozen=True)
class HelixSweep:
    """How flexgear.geometry.solids sweeps one helical toothed prism: ``pieces`` consecutive sweeps, each built at
    ``scale`` (1: in metres, the study's construction; :data:`_PRECISE_SCALE`: in millimetres, scaled back)."""

    pieces: int = 1
    scale: float = 1.0

    @property
    def plain(self) -> bool:
        return self.pieces == 1 and self.scale == 1.0


def helix_sweep(twist: float, length: float, profile: ToothProfile) -> HelixSweep:
    """The sweep of a toothed prism of ``profile`` turning at ``twist`` [rad/m] over ``length`` [m].

    One sweep in metres deviates from the exact surfaces by about e = :data:`_SWEEP_ERROR` r theta^4
    (theta = |twist| L, r the outer radius of the toothed band) and needs every outline curve at least
    :data:`_PLAIN_MIN_CURVE` long; when both hold it is taken (the study's gears: e <= 0.05 um, curves >= 1.2 mm),
    otherwise ceil(theta / :data:`_PRECISE_ANGLE`) precise sweeps (in millimetres).
    """
    gear = profile.gear
    theta = abs(twist) * length
    error = _SWEEP_ERROR * max(gear.tip_radius, gear.root_radius) * theta**4
    if error <= _SWEEP_TOLERANCE and min(c for _, c in profile.outline_curves()) >= _PLAIN_MIN_CURVE:
        return HelixSweep()
    return HelixSweep(max(1, math.ceil(theta / _PRECISE_ANGLE - 1e-9)), _PRECISE_SCALE)


def _helix_sweeps(spec: GearboxSpec) -> tuple[HelixSweep, ...]:
    """:func:`helix_sweep` of the toothed prisms of sun, planet and ring if any (as :func:`_gear_prisms` lays them);
    plain for spur gears (extruded) and for a gear set whose profiles cannot be built (nothing is swept)."""
    gs, a = gear_set_geometry(spec), spec.gears_assumed
    if gs.sun.helix_angle == 0.0:
        return (HelixSweep(),) * 3
    length = a.face_width_m / 2 if a.helix_layout == "double" else a.face_width_m
    try:
        profiles = tooth_profiles(gs, a.root_fillet_coefficient)
    except ValueError:
        return (HelixSweep(),) * 3
    return tuple(helix_sweep(math.tan(g.helix_angle) / g.reference_radius, length, profiles[name])
                 for name, g in gs.named_gears)


def geometry_hash(spec: GearboxSpec, *extra: object) -> str:
    """Hash of every spec table the geometry depends on, the construction version and ``extra``.

    A gear set with a helix that is not swept in one piece in metres (:func:`helix_sweep`) also hashes its
    sweeps: such solids were swept in one piece before (or could not be built), so earlier cache entries are not
    reused; a parallel-axis pair hashes its shafts' straddle rule (:data:`NEAR_SEAT_GAP_PER_WIDTH`); every other key,
    the study's among them, is unchanged.
    """
    sweeps = _helix_sweeps(spec)
    construction = () if all(w.plain for w in sweeps) else (
        ("precise_sweeps", *((w.pieces, w.scale) for w in sweeps)),)
    if not spec.gears.has_ring:  # the parallel-axis pair's shafts reach to their near bearing seats
        construction = (*construction, ("straddle", NEAR_SEAT_GAP_PER_WIDTH))
    return spec_hash(spec.gears, spec.gears_assumed, spec.components_assumed, spec.material_assumed,
                     GEOMETRY_VERSION, *construction, *extra, *_imported_files(spec, extra))


def _imported_files(spec: GearboxSpec, extra: tuple) -> tuple:
    """The ``[components_geometry]`` entries (hashed as their files' SHA-256 and unit) of the components that the
    first two of ``extra`` name (a component, or a tuple of them as in the tied ring and output shaft's key): () for
    the built-in components, whose keys are then unchanged."""
    imported = getattr(spec, "components_geometry", None) or {}
    named = {n for e in extra[:2] for n in (e if isinstance(e, tuple) else (e,)) if isinstance(n, str)}
    return tuple(imported[c] for c in sorted(named & set(imported)))


@dataclass(frozen=True)
class Section:
    """Transverse section with n-fold symmetry about the axis (radii in m).

    ``gear`` None: annulus inner..outer; "ring": rim of radius ``outer`` with the internal toothed outline
    inside; any other name ("sun", "planet", a single gear's name, flexgear.geometry.gear_body): external
    toothed outline with a bore of radius ``inner``. The name is the key of the outline's tooth profile.
    ``holes`` circular holes of radius ``hole_radius`` equally spaced on ``hole_circle_radius``.
    """

    inner: float
    outer: float
    gear: str | None = None
    holes: int = 0
    hole_radius: float = 0.0
    hole_circle_radius: float = 0.0

    def hole_centres(self) -> np.ndarray:
        """(holes, 2) centres of the bolt holes [m]: hole k at polar angle 2 pi k / holes."""
        a = 2 * np.pi * np.arange(self.holes) / max(self.holes, 1)
        return self.hole_circle_radius * np.column_stack([np.cos(a), np.sin(a)])


@dataclass(frozen=True)
class Prism:
    """Section extruded from z0 to z1 [m], rotated by ``twist`` [rad/m] * z (helical teeth)."""

    name: str
    z0: float
    z1: float
    section: Section
    twist: float = 0.0

    @property
    def length(self) -> float:
        return self.z1 - self.z0


@dataclass(frozen=True)
class ComponentLayout:
    """A component as a union of non-overlapping prisms, plus the radii its regions refer to."""

    name: str
    prisms: tuple[Prism, ...]
    gear: Gear | None = None
    profile: ToothProfile | None = None

    @property
    def z_range(self) -> tuple[float, float]:
        return min(p.z0 for p in self.prisms), max(p.z1 for p in self.prisms)

    @property
    def outer_radius(self) -> float:
        return max(p.section.outer if p.section.gear is None or p.section.gear == "ring"
                   else self.gear.tip_radius for p in self.prisms)


@lru_cache(maxsize=16)
def tooth_profiles(gs: GearSetGeometry, fillet_coefficient: float) -> dict[str, ToothProfile]:
    """Tooth profiles of the gear set's sun, planet and ring (root fillet radius = ``fillet_coefficient`` * m_n)."""
    return {name: tooth_profile(gear, fillet_coefficient * gear.normal_module) for name, gear in gs.named_gears}


def gear_profiles(spec: GearboxSpec) -> dict[str, ToothProfile]:
    """Tooth profiles of sun, planet and ring (root fillet radius = root_fillet_coefficient * m_n)."""
    return tooth_profiles(gear_set_geometry(spec), spec.gears_assumed.root_fillet_coefficient)


NEAR_SEAT_GAP_PER_WIDTH = 0.5
"""The parallel-axis pair's near bearing seat lies this many seat widths beyond the gear's face (its nodes apart from
the gear seat's)."""


def _gear_half_length(spec: GearboxSpec) -> float:
    a = spec.gears_assumed
    return a.face_width_m / 2 + (a.half_gap_m / 2 if a.helix_layout == "double" else 0.0)


def _gear_prisms(spec: GearboxSpec, name: str, gear: Gear, inner: float, outer: float) -> list[Prism]:
    """Toothed prisms (one or two helices) and, for a double helix, the grooved gap between them."""
    a = spec.gears_assumed
    return toothed_prisms(name, gear, inner, outer, _HANDS[name], a.helix_layout, a.face_width_m, a.half_gap_m,
                          spec.components_assumed.relief_groove_depth_mm * 1e-3)


def toothed_prisms(name: str, gear: Gear, inner: float, outer: float, hand: float, helix_layout: str,
                   face_width: float, half_gap: float, groove_depth: float) -> list[Prism]:
    """The toothed prisms of ``gear`` about its axial mid-plane: one helix over the ``face_width`` [m] ("single"),
    or two halves of opposite hand, each half the face width, with a relief groove ``groove_depth`` [m] beyond
    the root circle over the ``half_gap`` [m] between them ("double"); ``hand`` (+1 / -1) of the helix at +z.

    The sections are named ``name`` (the key of the gear's tooth profile; "ring" marks an internal outline, see
    :class:`Section`); ``inner``, ``outer`` [m]: the bore radius of an external gear (``outer`` unused), the
    outer rim radius of an internal one (``inner`` 0).
    """
    twist = hand * math.tan(gear.helix_angle) / gear.reference_radius
    section = Section(inner, outer, name)
    if helix_layout == "single":
        return [Prism("teeth", -face_width / 2, face_width / 2, section, twist)]
    g, b = half_gap, face_width / 2
    depth = groove_depth
    groove = Section(inner, gear.root_radius - depth) if not gear.internal else Section(gear.root_radius + depth, outer)
    prisms = [Prism("teeth_lower", -g / 2 - b, -g / 2, section, -twist)]
    if g > 0:
        prisms.append(Prism("groove", -g / 2, g / 2, groove))
    prisms.append(Prism("teeth_upper", g / 2, g / 2 + b, section, twist))
    return prisms


def component_layout(spec: GearboxSpec, component: str) -> ComponentLayout:
    """The prisms of ``component`` (one of GEOMETRY_COMPONENTS) in its component frame."""
    return gear_set_layout(spec, gear_set_geometry(spec), component)


def gear_set_layout(spec: GearboxSpec, gs: GearSetGeometry, component: str) -> ComponentLayout:
    """:func:`component_layout` of ``spec`` with its gear set ``gs`` (flexgear.geometry.involute.gear_set_geometry)
    given."""
    if component not in GEOMETRY_COMPONENTS:
        raise ValueError(f"unknown component {component!r}; allowed: {', '.join(GEOMETRY_COMPONENTS)}")
    c = spec.components_assumed
    profiles = tooth_profiles(gs, spec.gears_assumed.root_fillet_coefficient)
    mm = 1e-3
    h = _gear_half_length(spec)
    if component in ("sun", "planet"):
        gear = getattr(gs, component)
        bore = getattr(c, f"{component}_bore_diameter_mm") * mm / 2
        if bore >= gear.root_radius - c.relief_groove_depth_mm * mm:
            raise ValueError(f"{component} bore diameter {2 * bore} m does not fit inside the root/groove circle")
        return ComponentLayout(component, tuple(_gear_prisms(spec, component, gear, bore, 0.0)), gear,
                               profiles[component])
    # the parallel-axis pair's shafts reach past the gear's other face to their near bearing seat (straddle mount)
    near = 0.0 if gs.ring is not None else (1.0 + NEAR_SEAT_GAP_PER_WIDTH) * c.bearing_seat_width_mm * mm
    if component == "input_shaft":
        ri, ro = c.input_shaft_inner_diameter_mm * mm / 2, c.input_shaft_outer_diameter_mm * mm / 2
        if ri >= ro:
            raise ValueError("input_shaft_inner_diameter_mm must be smaller than the outer diameter")
        return ComponentLayout(component, (Prism("tube", h - c.input_shaft_length_mm * mm, h + near,
                                                 Section(ri, ro)),))
    ring = gs.ring
    if ring is None:  # the parallel-axis pair: the output shaft in the wheel's bore, as the input shaft in the pinion's
        if component != "output_shaft":
            raise ValueError(f"a parallel-axis pair has no {component}")
        ri, ro = c.output_shaft_inner_diameter_mm * mm / 2, c.output_shaft_outer_diameter_mm * mm / 2
        if ri >= ro:
            raise ValueError("output_shaft_inner_diameter_mm must be smaller than the outer diameter")
        return ComponentLayout(component, (Prism("tube", -h - near, c.output_shaft_length_mm * mm - h,
                                                 Section(ri, ro)),))
    rim = ring.root_radius + c.ring_rim_thickness_mm * mm
    flange_out = c.ring_flange_outer_diameter_mm * mm / 2
    flange_in = ring.root_radius + c.relief_groove_depth_mm * mm
    tf = c.ring_flange_thickness_mm * mm
    holes = dict(holes=c.ring_bolt_count, hole_radius=c.ring_bolt_hole_diameter_mm * mm / 2,
                 hole_circle_radius=(rim + flange_out) / 2)
    if flange_out - rim < 2 * holes["hole_radius"]:
        raise ValueError("ring_flange_outer_diameter_mm leaves no room for the bolt holes outside the rim")
    if component == "ring":
        prisms = _gear_prisms(spec, "ring", ring, 0.0, rim)
        prisms.append(Prism("flange", h, h + tf, Section(flange_in, flange_out, **holes)))
        return ComponentLayout("ring", tuple(prisms), ring, profiles["ring"])
    ri, ro = c.output_shaft_inner_diameter_mm * mm / 2, c.output_shaft_outer_diameter_mm * mm / 2
    length = c.output_shaft_length_mm * mm
    if ri >= ro or length <= tf:
        raise ValueError("output shaft: need inner < outer diameter and length > ring_flange_thickness_mm")
    return ComponentLayout(component, (
        Prism("web", h + tf, h + 2 * tf, Section(ri, flange_out, **holes)),
        Prism("tube", h + 2 * tf, h + tf + length, Section(ri, ro)),
    ))


def section_integrals(section: Section, profiles: dict[str, ToothProfile] | None = None) -> tuple[float, float]:
    """Area A [m^2] and polar second moment J = int r^2 dA [m^4] of a section about the axis."""
    def disc(r: float) -> tuple[float, float]:
        return math.pi * r**2, math.pi * r**4 / 2

    if section.gear is None:
        a_out, j_out = disc(section.outer)
        a_in, j_in = disc(section.inner)
    elif section.gear == "ring":
        a_out, j_out = disc(section.outer)
        a_in, j_in = profiles["ring"].outline_integrals
    else:
        a_out, j_out = profiles[section.gear].outline_integrals
        a_in, j_in = disc(section.inner)
    area, polar = a_out - a_in, j_out - j_in
    if section.holes:
        a_h, j_h = disc(section.hole_radius)
        area -= section.holes * a_h
        polar -= section.holes * (j_h + a_h * section.hole_circle_radius**2)
    return area, polar


def exact_mass_properties(spec: GearboxSpec, component: str) -> MassProperties:
    """Mass properties of ``component`` from the exact section integrals (no cache)."""
    return layout_mass_properties(component_layout(spec, component), gear_profiles(spec),
                                  spec.material_assumed.density_kg_m3)


def layout_mass_properties(layout: ComponentLayout, profiles: dict[str, ToothProfile],
                           rho: float) -> MassProperties:
    """Mass properties of a component ``layout`` of density ``rho`` [kg/m^3] from the exact section integrals
    (module docstring), the gear sections' outlines from ``profiles``."""
    return stacked_prism_mass_properties(
        [(*section_integrals(p.section, profiles), p.z0, p.z1) for p in layout.prisms], rho)


def stacked_prism_mass_properties(prisms: list[tuple[float, float, float, float]], rho: float) -> MassProperties:
    """Mass properties of prisms along the z axis, each (area A [m^2], polar moment J = int r^2 dA [m^4], z0, z1 [m])
    of a section with n-fold symmetry (n >= 3: the transverse inertia is axisymmetric), density ``rho`` [kg/m^3]:
    m = rho sum A L, I_zz = rho sum J L, I_xx = rho sum (J L / 2 + A (z1^3 - z0^3) / 3) - m z_c^2."""
    mass = first = i_zz = i_xx = 0.0
    for area, polar, z0, z1 in prisms:
        mass += rho * area * (z1 - z0)
        first += rho * area * (z1**2 - z0**2) / 2
        i_zz += rho * polar * (z1 - z0)
        i_xx += rho * (polar * (z1 - z0) / 2 + area * (z1**3 - z0**3) / 3)
    zc = first / mass
    inertia = np.diag([i_xx - mass * zc**2, i_xx - mass * zc**2, i_zz])
    return MassProperties(mass, np.array([0.0, 0.0, zc]), inertia)


def component_mass_properties(spec: GearboxSpec, component: str) -> MassProperties:
    """Mass [kg], centre of mass [m] and inertia about it [kg m^2] of ``component`` (cached).

    ``component``: "sun", "planet", "ring", "input_shaft" or "output_shaft"; frames as in the
    module docstring. The JSON cache ``meshes/massprops-<hash>.json`` is keyed by every input.
    """
    return cached_mass_properties(spec, component, lambda: exact_mass_properties(spec, component))


def cached_mass_properties(spec: GearboxSpec, component: str, compute: Callable[[], MassProperties],
                           method: str = "exact section integrals") -> MassProperties:
    """:func:`component_mass_properties` from its JSON cache, else computed by ``compute()`` (the exact section
    integrals of ``component``'s layout, or ``method``) and stored."""
    key = geometry_hash(spec, component) if method == "exact section integrals" else geometry_hash(spec, component,
                                                                                                   method)
    path = cache_dir() / f"massprops-{component}-{key}.json"
    if path.exists():
        try:
            d = json.loads(path.read_text())
            return MassProperties(float(d["mass_kg"]), np.array(d["com_m"], float),
                                  np.array(d["inertia_kg_m2"], float))
        except (ValueError, KeyError):
            pass  # unreadable entry: recompute and overwrite
    props = compute()
    payload = {"component": component, "mass_kg": props.mass, "com_m": props.com.tolist(),
               "inertia_kg_m2": props.inertia.tolist(), "method": method}
    atomic_write_bytes(path, json.dumps(payload, indent=1).encode())
    return props
