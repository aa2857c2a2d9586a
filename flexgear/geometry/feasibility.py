"""Geometric and physical feasibility of a gearbox, checked when the file is loaded (before any meshing).

:func:`check_feasibility` raises a one-line :class:`flexgear.spec.SpecError` that names the file, the
field that causes the problem and what is allowed:

- gear set: neighbouring planets' tip circles must not overlap, 2 a_w sin(pi/N) > d_a,planet
  (the equal-spacing assembly condition is checked in :mod:`flexgear.spec`);
- centre distance: reachable by profile shifts, cos(alpha_wt) = a_0 cos(alpha_t) / a_w < 1 for both meshes
  (ISO 21771 centre-distance equation), also the mean standard centre distance that 0 selects;
- no involute interference: along each mesh's line of action no tip passes the mate's base-circle tangent point;
- no undercut of sun and planet by the generating basic rack (:func:`undercut_limit`; the field named sets the
  gear's profile shift: the planet's own, the sun's through the centre distance);
- tooth thickness at the tip > 0 for sun, planet and ring (no pointed tooth), psi(r_a) of
  :meth:`flexgear.geometry.involute.Gear.tooth_half_angle`; the field named is the one that makes it pointed
  (backlash, addendum or the profile shift, which the centre distance sets for sun and ring);
- a gear whose tip circle lies inside its base circle has no involute flank (external gears: a negative
  profile shift or a small addendum; the ring: a large addendum);
- the root fillets of every gear fit in its tooth space (the tooth profile of
  :func:`flexgear.geometry.profile.tooth_profile` can be built): the field named is
  ``root_fillet_coefficient`` with the largest value that fits, or ``dedendum_coefficient`` when even a
  fillet-less space closes above the root circle;
- every curve of each outline (tip and root lands, involute, radial flank below the base circle, fillet) at
  least 1/500 of the largest tooth mesh size long (Netgen cannot mesh shorter ones);
- backlash below the normal module (a larger one is a unit slip);
- a relief groove depth > 0 (it sets the ring flange's inner edge beyond the tooth roots in either helix
  layout, and the double helix's groove);
- bores inside the root circle less the relief groove, shaft inner < outer diameter, the input shaft
  inside the sun's bore, the output shaft inside the ring flange, the flange beyond the rim with room for
  the bolt holes, the bolts side by side on their circle, bearing seats shorter than the shafts, the bolts'
  clamped discs wider than their holes and narrower than the bolt spacing;
- every mesh level's tooth size at most 2 normal modules (Netgen's surface mesher fails in the tooth spaces
  above about 2.5 m_n).

The checks register themselves with :func:`flexgear.spec.register_feasibility_check` when
:mod:`flexgear` is imported, so every :func:`flexgear.spec.load_gearbox` and
:func:`flexgear.spec.load_variant` runs them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

from flexgear.geometry.involute import Gear, gear_set_geometry, min_planet_gap, transverse_pressure_angle
from flexgear.geometry.profile import ToothProfile, tooth_profile
from flexgear.spec import GearboxSpec, SpecError, register_feasibility_check

__all__ = ["check_feasibility", "undercut_limit"]

_MM = 1e-3
_ELEMENTS_PER_CURVE = 500.0
"""Largest ratio of the tooth mesh size to the shortest outline curve (tip or root land, radial flank, fillet):
Netgen failed to mesh a 1 um tip land at 5.7 mm elements (ratio 5700), a 20 um tip land at 38 mm (1900) and a
2.4 um radial flank at 5.7 mm (2400), and meshed a 5 um tip land at 1.9 mm (380), a 50 um one at 38 mm (760) and
an 11 um radial flank at 5.7 mm (520)."""
_MIN_CURVE = 1e-6
"""Shortest outline curve [m] in any case: ten times the approximation tolerance of a precise sweep (0.1 um)."""
_TOOTH_SIZE_PER_MODULE = 2.0
"""Largest tooth mesh size ([meshing_assumed.<level>] tooth_size_mm) per normal module m_n. Netgen's surface
mesher failed on ring tooth spaces at 2.5 m_n (1 of 12 gears), 3 m_n (3 of 12) and 4 m_n, and meshed every
ring at 2.2 and 2.35 m_n, on the sets 12/18/48 (m_n 20 mm, spur), 21/30/81 (4 mm, beta 15 deg), 24/30/84
(3 mm, beta 20 deg, double) and 30/60/150 (1 mm, spur, double); at 2.0 m_n it meshed all 24 gears of these and
of the sets of tests/test_gear_sets.py. The study's coarse level is 4 mm = 1.89 m_n."""


def _reachable_centre_distance(spec: GearboxSpec) -> None:
    g, a = spec.gears, spec.gears_assumed
    alpha_t = transverse_pressure_angle(g.normal_pressure_angle_rad, g.helix_angle_rad)
    mt_mm = g.normal_module_mm / math.cos(g.helix_angle_rad)
    others = (g.sun_teeth, -g.ring_teeth) if g.has_ring else (g.sun_teeth,)
    lower = max(abs(mt_mm * (g.planet_teeth + z) / 2) * math.cos(alpha_t) for z in others)
    if a.operating_centre_distance_mm == 0.0:  # 0: the mean of the two standard centre distances (a pair's own)
        mean = mt_mm * ((g.sun_teeth + g.ring_teeth) / 4 if g.has_ring else (g.sun_teeth + g.planet_teeth) / 2)
        if mean <= lower:
            raise SpecError(spec.source, "gears_assumed.operating_centre_distance_mm",
                            f"0 selects the mean standard centre distance {mean:.3f} mm, which profile shifts "
                            f"cannot reach (base-circle limit a_0 cos(alpha_t) of the larger mesh {lower:.3f} mm): "
                            f"expected a centre distance > {lower:.3f} mm", a.operating_centre_distance_mm)
        return
    if a.operating_centre_distance_mm <= lower:
        raise SpecError(spec.source, "gears_assumed.operating_centre_distance_mm",
                        f"cannot be reached by profile shifts: expected > {lower:.3f} mm (base-circle limit "
                        "a_0 cos(alpha_t) of the larger mesh) or 0 (the mean standard centre distance)",
                        a.operating_centre_distance_mm)


def _backlash(spec: GearboxSpec) -> None:
    a, g = spec.gears_assumed, spec.gears
    if a.normal_backlash_mm >= g.normal_module_mm:
        raise SpecError(spec.source, "gears_assumed.normal_backlash_mm",
                        f"expected < the normal module ({g.normal_module_mm} mm): millimetres, not micrometres?",
                        a.normal_backlash_mm)


def _tip_thickness(gear: Gear) -> float:
    """Transverse tooth thickness (arc) at the tip circle, 2 r_a psi(r_a) [m]."""
    return 2 * gear.tip_radius * gear.tooth_half_angle(gear.tip_radius)


def _pointed_field(spec: GearboxSpec, name: str, gear: Gear) -> str:
    """The field that takes most tip thickness away: backlash (thinning), an addendum above the standard 1,
    or a positive profile shift (the planet's own; sun's and ring's follow from the centre distance)."""
    s = _tip_thickness(gear)
    losses = {"gears_assumed.normal_backlash_mm": _tip_thickness(dataclasses.replace(gear, thinning=0.0)) - s,
              "gears_assumed.addendum_coefficient": _tip_thickness(dataclasses.replace(
                  gear, addendum_coefficient=min(gear.addendum_coefficient, 1.0))) - s}
    shift_field = ("gears_assumed.planet_shift_coefficient" if name == "planet"
                   else "gears_assumed.operating_centre_distance_mm")
    losses[shift_field] = _tip_thickness(dataclasses.replace(gear, shift=min(gear.shift, 0.0))) - s
    return max(losses, key=losses.__getitem__)


def undercut_limit(gear: Gear, fillet_coefficient: float) -> float:
    """Smallest profile shift of an external gear that the generating basic rack does not undercut:
    x_min = h_s - z sin^2(alpha_t) / (2 cos beta), h_s = h_f - rho_f (1 - sin alpha_n) the rack's straight flank
    beyond its reference line per m_n (the rack's addendum, the gear's dedendum h_f, ends in the root fillet rho_f):
    its flank must not reach past the interference point, r sin^2(alpha_t) from the reference line."""
    h = gear.dedendum_coefficient - fillet_coefficient * (1.0 - math.sin(gear.normal_pressure_angle))
    return h - gear.teeth * math.sin(gear.transverse_pressure_angle) ** 2 / (2.0 * math.cos(gear.helix_angle))


def _shift_field(name: str) -> str:
    """The field that sets an external gear's profile shift: the planet's own, the sun's through the centre
    distance."""
    return ("gears_assumed.planet_shift_coefficient" if name == "planet"
            else "gears_assumed.operating_centre_distance_mm")


def _tip_inside_field(spec: GearboxSpec, name: str, gear: Gear) -> str:
    """The field that puts a gear's tip circle inside its base circle: its profile shift where that is negative
    (an external gear's own, the sun's through the centre distance; the ring's follows a negative planet shift
    with the opposite sign), else the addendum."""
    if not gear.internal and gear.shift < 0:
        return _shift_field(name)
    if gear.internal and gear.shift > 0 and spec.gears_assumed.planet_shift_coefficient < 0:
        return "gears_assumed.planet_shift_coefficient"
    return "gears_assumed.addendum_coefficient"


def _teeth(spec: GearboxSpec) -> None:
    gs = gear_set_geometry(spec)
    g = spec.gears
    for name, gear in gs.named_gears:
        if gear.tip_radius <= gear.base_radius:  # external r_a = r + m_n (h_a + x) <= r_b; the ring's tips inwards
            field = _tip_inside_field(spec, name, gear)
            raise SpecError(spec.source, field,
                            f"the {name}'s tip circle (d = {2e3 * gear.tip_radius:.2f} mm, profile shift x = "
                            f"{gear.shift:.3f}) lies inside its base circle (d = {2e3 * gear.base_radius:.2f} mm): "
                            "no involute at the tip; expected a value that puts the tip circle outside it",
                            _value(spec, field))
        if _tip_thickness(gear) <= 0:
            field = _pointed_field(spec, name, gear)
            raise SpecError(spec.source, field,
                            f"makes the {name} tooth pointed (no tooth thickness left at the tip circle, profile "
                            f"shift x = {gear.shift:.3f}); expected a value that leaves a tip thickness > 0",
                            _value(spec, field))
    for name, gear in (("sun", gs.sun), ("planet", gs.planet)):  # after the tips: a pointed tooth is named first
        limit = undercut_limit(gear, spec.gears_assumed.root_fillet_coefficient)
        if gear.shift < limit - 1e-9:
            field = _shift_field(name)
            raise SpecError(spec.source, field,
                            f"the {name} ({gear.teeth} teeth) is undercut by the generating rack: profile shift "
                            f"x = {gear.shift:.3f} < {limit:.3f} (x_min = h_s - z sin^2(alpha_t) / (2 cos beta)); "
                            "expected a value that gives it a larger profile shift, or more teeth",
                            _value(spec, field))
    tip_d = 2 * gs.planet.tip_radius
    spacing = 2 * gs.centre_distance * math.sin(min_planet_gap(gs.planet_angles) / 2)
    if spacing <= tip_d and g.planet_positions_deg:
        raise SpecError(spec.source, "gears.planet_positions_deg",
                        f"neighbouring planets' tip circles overlap (closest centres {spacing / _MM:.2f} mm apart <= "
                        f"tip diameter {tip_d / _MM:.2f} mm); expected planets farther apart", g.planet_positions_deg)
    if spacing <= tip_d:
        fit = max(n for n in range(1, g.planet_count)
                  if n == 1 or 2 * gs.centre_distance * math.sin(math.pi / n) > tip_d)
        raise SpecError(spec.source, "gears.planet_count",
                        f"neighbouring planets' tip circles overlap (centre spacing {spacing / _MM:.2f} mm <= "
                        f"tip diameter {tip_d / _MM:.2f} mm); expected at most {fit} planets", g.planet_count)


def _interference(spec: GearboxSpec) -> None:
    """No involute interference: along each mesh's line of action a tip must not pass the mate's base-circle
    tangent point T (beyond it the mate has no involute): external pair sqrt(r_a^2 - r_b^2) <= a_w sin(alpha_wt)
    for each gear; internal pair the ring's tip sqrt(r_a2^2 - r_b2^2) >= a_w sin(alpha_wt)."""
    gs = gear_set_geometry(spec)
    for names, mesh in gs.named_meshes:
        gw = mesh.centre_distance * math.sin(mesh.operating_pressure_angle)
        label = "-".join(names)
        for (name, other), gear in ((names, mesh.gear1), (names[::-1], mesh.gear2)):
            reach = math.sqrt(max(gear.tip_radius ** 2 - gear.base_radius ** 2, 0.0))
            bad = reach < gw - 1e-12 if gear.internal else (not mesh.internal and reach > gw + 1e-12)
            if bad:
                raise SpecError(spec.source, "gears_assumed.addendum_coefficient",
                                f"the {name}'s tips interfere with the {other} in the {label} mesh: they reach "
                                f"{reach / _MM:.3f} mm along the line of action against {gw / _MM:.3f} mm to the "
                                f"{other}'s base-circle tangent point, below which it has no involute; expected a "
                                "smaller addendum (or other profile shifts)", spec.gears_assumed.addendum_coefficient)


def _profile_fits(gear: Gear, fillet_radius: float) -> bool:
    """Whether the tooth profile of ``gear`` with a root fillet of ``fillet_radius`` [m] can be built."""
    try:
        tooth_profile(gear, fillet_radius)
    except ValueError:
        return False
    return True


def _largest(fits: Callable[[float], bool], lo: float, hi: float) -> float:
    """The largest x in [lo, hi] with ``fits(x)``, by bisection (``fits(lo)`` true, ``fits(hi)`` false)."""
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if fits(mid) else (lo, mid)
    return lo


def _short_curves(spec: GearboxSpec, name: str, gear: Gear, profile: ToothProfile) -> None:
    """Every curve of the gear's outline (:meth:`ToothProfile.outline_curves`) at least the largest tooth mesh size
    / :data:`_ELEMENTS_PER_CURVE` and :data:`_MIN_CURVE` long."""
    tooth = max(level.sizes_mm(name)[0] for level in spec.meshing_assumed.values()) * _MM
    limit = max(_MIN_CURVE, tooth / _ELEMENTS_PER_CURVE)
    curve, shortest = min(profile.outline_curves(), key=lambda c: c[1])
    if shortest >= limit:
        return
    c = spec.gears_assumed.root_fillet_coefficient
    hi = next(f.metadata["hi"] for f in dataclasses.fields(spec.gears_assumed) if f.name == "root_fillet_coefficient")

    def curves(coefficient: float) -> dict[str, float]:
        return dict(tooth_profile(gear, coefficient * gear.normal_module).outline_curves())

    field, hint = "gears_assumed.root_fillet_coefficient", "another value"
    if curve == "tip land":
        field, hint = _pointed_field(spec, name, gear), "a value that leaves a longer tip land"
    elif curve == "root fillet":
        hint = "0 (no fillet) or a larger value"
    elif curve == "involute flank":
        field, hint = "gears_assumed.addendum_coefficient", "a larger value"
    elif curve == "radial flank":  # a smaller fillet lengthens it, a larger one meets the flank above r_b
        def fits(x: float) -> bool:
            return _profile_fits(gear, x * gear.normal_module)

        top = hi if fits(hi) else _largest(fits, c, hi)
        shorter = _largest(lambda x: curves(x).get(curve, 0.0) >= limit, 0.0, c)
        hint = f"< {shorter:.4f}"
        if curve not in curves(top):
            hint += f" or > {_largest(lambda x: curve in curves(x), c, top):.4f} (no radial flank)"
    elif curve == "root land":
        hint = f"< {_largest(lambda x: curves(x)['root land'] >= limit, 0.0, c):.4f}"
    raise SpecError(spec.source, field,
                    f"the {name}'s {curve} is {shortest * 1e6:.1f} um long, shorter than {limit * 1e6:.1f} um "
                    f"(1/{_ELEMENTS_PER_CURVE:g} of the largest tooth mesh size {tooth / _MM:g} mm): Netgen cannot "
                    f"mesh it; expected {hint}", _value(spec, field))


def _profiles(spec: GearboxSpec) -> None:
    """Each gear's tooth space must hold its root fillets (flexgear.geometry.profile.tooth_profile): the fillet of
    radius rho = c m_n, tangent to the flank and the root circle, must lie inside the tooth space at the root,
    i.e. the root point's polar angle < pi / z; without a fillet the flanks must not meet above the root circle."""
    gs, a = gear_set_geometry(spec), spec.gears_assumed
    coefficient = a.root_fillet_coefficient
    for name, gear in gs.named_gears:
        if _profile_fits(gear, coefficient * gear.normal_module):
            _short_curves(spec, name, gear, tooth_profile(gear, coefficient * gear.normal_module))
            continue
        shift = f"{round(gear.shift, 3) + 0.0:.3f}"  # + 0.0: no "-0.000"
        if coefficient > 0 and _profile_fits(gear, 0.0):
            c_max = _largest(lambda c, g=gear: _profile_fits(g, c * g.normal_module), 0.0, coefficient)
            raise SpecError(spec.source, "gears_assumed.root_fillet_coefficient",
                            f"the {name}'s root fillets (radius {coefficient * gear.normal_module / _MM:.3f} mm) "
                            f"do not fit in its tooth space (profile shift x = {shift}); expected < {c_max:.4f}",
                            coefficient)
        # the flanks meet above the root circle: a smaller dedendum raises an external gear's root circle and
        # lowers the ring's, into the wider part of the space
        def fits(dedendum: float, g: Gear = gear) -> bool:
            return _profile_fits(dataclasses.replace(g, dedendum_coefficient=dedendum), coefficient * g.normal_module)

        lowest = next(f.metadata["lo"] for f in dataclasses.fields(a) if f.name == "dedendum_coefficient")
        hint = f"< {_largest(fits, lowest, a.dedendum_coefficient):.4f}" if fits(lowest) else "a smaller value"
        raise SpecError(spec.source, "gears_assumed.dedendum_coefficient",
                        f"the {name}'s tooth spaces close above its root circle (profile shift x = {shift}, no room "
                        f"for the root fillets); expected {hint}", a.dedendum_coefficient)


def _value(spec: GearboxSpec, dotted: str) -> object:
    table, name = dotted.split(".")
    return getattr(getattr(spec, table), name)


def _components(spec: GearboxSpec) -> None:
    gs, c, p = gear_set_geometry(spec), spec.components_assumed, spec.source
    # the groove depth sets the ring flange's inner edge in either helix layout, and the bore limit with it
    groove = c.relief_groove_depth_mm
    if groove <= 0:
        raise SpecError(p, "components_assumed.relief_groove_depth_mm",
                        "expected > 0: the ring flange's inner edge (and a double helix's relief groove) lies this "
                        "far beyond the root circle; at 0 its circle touches the tooth roots", groove)
    for name in ("sun", "planet"):
        limit = 2 * getattr(gs, name).root_radius / _MM - 2 * groove
        bore = getattr(c, f"{name}_bore_diameter_mm")
        if bore >= limit:
            raise SpecError(p, f"components_assumed.{name}_bore_diameter_mm",
                            f"expected < {limit:.2f} mm (the {name}'s root diameter less twice the relief groove "
                            "depth)", bore)
    if c.input_shaft_outer_diameter_mm > c.sun_bore_diameter_mm:
        raise SpecError(p, "components_assumed.input_shaft_outer_diameter_mm",
                        f"expected <= sun_bore_diameter_mm ({c.sun_bore_diameter_mm} mm): the shaft sits in the "
                        "sun's bore", c.input_shaft_outer_diameter_mm)
    if not gs.ring and c.output_shaft_outer_diameter_mm > c.planet_bore_diameter_mm:
        raise SpecError(p, "components_assumed.output_shaft_outer_diameter_mm",
                        f"expected <= planet_bore_diameter_mm ({c.planet_bore_diameter_mm} mm): in the parallel-axis "
                        "pair the shaft sits in the wheel's bore", c.output_shaft_outer_diameter_mm)
    if gs.ring and c.output_shaft_length_mm <= c.ring_flange_thickness_mm:
        raise SpecError(p, "components_assumed.output_shaft_length_mm",
                        f"expected > ring_flange_thickness_mm ({c.ring_flange_thickness_mm} mm)",
                        c.output_shaft_length_mm)
    for shaft in ("input_shaft", "output_shaft"):
        inner, outer = (getattr(c, f"{shaft}_{k}_diameter_mm") for k in ("inner", "outer"))
        if inner >= outer:
            raise SpecError(p, f"components_assumed.{shaft}_inner_diameter_mm",
                            f"expected < {shaft}_outer_diameter_mm ({outer} mm)", inner)
        if c.bearing_seat_width_mm >= getattr(c, f"{shaft}_length_mm"):
            raise SpecError(p, "components_assumed.bearing_seat_width_mm",
                            f"expected < {shaft}_length_mm ({getattr(c, f'{shaft}_length_mm')} mm)",
                            c.bearing_seat_width_mm)
    if not gs.ring:  # the parallel-axis pair: no ring, no flange, no bolts
        return
    if groove >= c.ring_rim_thickness_mm:
        raise SpecError(p, "components_assumed.relief_groove_depth_mm",
                        f"expected < ring_rim_thickness_mm ({c.ring_rim_thickness_mm} mm): the groove is cut into "
                        "the ring's rim", c.relief_groove_depth_mm)
    rim_d = 2 * gs.ring.root_radius / _MM + 2 * c.ring_rim_thickness_mm
    need = rim_d + 2 * c.ring_bolt_hole_diameter_mm
    if c.ring_flange_outer_diameter_mm <= need:
        raise SpecError(p, "components_assumed.ring_flange_outer_diameter_mm",
                        f"expected > {need:.2f} mm (the ring's rim diameter {rim_d:.2f} mm plus room for the bolt "
                        "holes)", c.ring_flange_outer_diameter_mm)
    if c.output_shaft_outer_diameter_mm >= c.ring_flange_outer_diameter_mm:
        raise SpecError(p, "components_assumed.output_shaft_outer_diameter_mm",
                        f"expected < ring_flange_outer_diameter_mm ({c.ring_flange_outer_diameter_mm} mm)",
                        c.output_shaft_outer_diameter_mm)
    bolt_circle = math.pi * (rim_d + c.ring_flange_outer_diameter_mm) / 2
    if c.ring_bolt_count * c.ring_bolt_hole_diameter_mm >= bolt_circle:
        raise SpecError(p, "components_assumed.ring_bolt_count",
                        f"expected < {bolt_circle / c.ring_bolt_hole_diameter_mm:.0f} bolt holes of "
                        f"{c.ring_bolt_hole_diameter_mm} mm side by side on the {bolt_circle:.1f} mm bolt circle",
                        c.ring_bolt_count)
    clamp = spec.joints_assumed.bolt_clamp_diameter_mm
    spacing = 2 * (bolt_circle / math.pi / 2) * math.sin(math.pi / c.ring_bolt_count)  # chord between bolt axes
    if not c.ring_bolt_hole_diameter_mm < clamp < spacing:
        raise SpecError(p, "joints_assumed.bolt_clamp_diameter_mm",
                        f"expected between the bolt hole diameter {c.ring_bolt_hole_diameter_mm} mm and the bolt "
                        f"spacing {spacing:.1f} mm (clamped discs of neighbouring bolts must not overlap)", clamp)


def _mesh_sizes(spec: GearboxSpec) -> None:
    """Every mesh level's tooth size at most :data:`_TOOTH_SIZE_PER_MODULE` normal modules (Netgen fails above)."""
    limit = _TOOTH_SIZE_PER_MODULE * spec.gears.normal_module_mm
    for level, settings in spec.meshing_assumed.items():
        for name in ("tooth_size_mm", "ring_tooth_size_mm"):
            if getattr(settings, name) > limit:
                raise SpecError(spec.source, f"meshing_assumed.{level}.{name}",
                                f"expected <= {limit:.3f} mm ({_TOOTH_SIZE_PER_MODULE:g} normal modules): coarser "
                                "tooth elements make Netgen's surface mesher fail in the tooth spaces",
                                getattr(settings, name))


def check_feasibility(spec: GearboxSpec) -> None:
    """Raise a :class:`SpecError` for the first infeasible value of ``spec`` (see the module docstring)."""
    _backlash(spec)
    _reachable_centre_distance(spec)
    _teeth(spec)
    _interference(spec)
    _profiles(spec)
    _components(spec)
    _mesh_sizes(spec)


register_feasibility_check(check_feasibility)
