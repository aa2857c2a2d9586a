"""Sizes that follow the gear set: the default of every component dimension, joint size, mesh size and
gear-dependent setting a gearbox file leaves out.

A gearbox file needs only its gear data, bearings and load case (:data:`flexgear.spec.REQUIRED_TABLES`); every
other value has a documented default. Fixed defaults sit on the schema's fields (:mod:`flexgear.schema`); the
ones below scale with the gears, so that one file serves a 1 mm or a 20 mm module alike. Each rule states its
proportion and what it gives for the study's gear set (44/45/136, m_n 2.12 mm, helix 25 deg, 30 mm per helix half;
the study's file gives its own values, docs/configuration.md). A value given in the file is checked like any other
field and wins.

With m = m_n the normal module, d_f the root diameters (profile-shifted, :mod:`flexgear.geometry.involute`):

- gears (the parallel-axis pair): no ring (``ring_teeth`` 0) and one planet, the wheel;
- gears_assumed: face width 0.6 d_sun (reference diameter) in all, split over the halves of a double helix (study
  61.8 vs 60 mm); half gap between the halves 4 m (8.5 vs 8); normal backlash 0.05 m (0.106 vs 0.10);
- bores: sun and planet 0.5 d_f (48.6 and 49.9 vs 50); relief groove 0.5 m (1.06 vs 1.0);
- ring: rim 4 m below the root (8.5 vs 8); bolt holes 4 m (8.5 vs 8); flange outer diameter the rim's diameter
  plus four bolt holes (376 vs 370); flange 4 m thick (8.5 vs 8); the bolt count is a fixed default (12);
- joint: each bolt's clamped disc 2.5 bolt holes (21.2 vs 21);
- shafts: input shaft outer diameter the sun's bore, inner 0.6 of it, length 3 sun bores (48.6/29.2/146 vs
  50/30/150); output shaft outer diameter a quarter of the ring flange's, inner 0.78 of it, length as the input
  shaft's (94/73/146 vs 90/70/150); bearing seats 0.4 sun bores wide (19.5 vs 20);
- the parallel-axis pair: the output shaft in the wheel's bore as the input shaft in the pinion's (outer diameter
  the wheel's bore, inner 0.6 of it, length as the input shaft's); the ring's sizes (no ring: unused) as if the
  wheel's tip circle plus two modules were the ring's root circle;
- mesh levels: ``coarse`` teeth 1.9 m, body 3.8 m but no coarser than the teeth allow 6 elements across the
  input shaft (4.03/8.06 vs 4/8); ``default`` teeth 0.95 m, body 2.8 m, 8 across the shaft (2.0/5.9 vs 2/6);
  the ring's own: teeth 1.2 m (``coarse``) or 0.95 m (``default``), never coarser than the level's teeth, and
  at least two elements through its rim (2.54/4.25 vs 2.5/4; 2.0/4.25 vs 2/4);
  Netgen's curvature refinement and optimisation passes as the study's levels;
- reduction: fixed-interface cutoff 3.5 mesh orders at the load case's input speed (15.4 kHz, as the study's);
- load case: step 1/24 of the mesh period (9.5 vs 10 us);
- screening: settled-window blocks of z_ring / settle_final_blocks mesh cycles, rounded (17, as the study's; the
  parallel-axis pair's wheel z_p instead of z_ring);
  a fixed window from the ramps' end to the load case's end;
- the carrier's mass and polar inertia (``[lumped_assumed]``: the lumped and the multibody model's rigid carrier,
  turning in the planetary arrangement only): in the planetary arrangement those of the carrier's solid with its
  default sizes (flexgear.geometry.carrier: two plates and the posts between the planets, exact section
  integrals); where no posts fit between the planets, and in the star arrangement (the carrier held), as heavy as
  its planets together (solid discs over the root circle, the whole face width), the inertia that of a disc of
  radius a_w.
"""

from __future__ import annotations

import math
from typing import Any

from flexgear.geometry.carrier import carrier_mass_properties, carrier_sizes_of
from flexgear.geometry.involute import gear_set_geometry_of
from flexgear.schema import ComponentsAssumed, GearSet, GearSetAssumed, LoadCase, Material
from flexgear.spec import register_derived_defaults
from flexgear.theory import mesh_frequency_hz

__all__ = ["derived_defaults", "FACE_WIDTH_PER_SUN_DIAMETER", "CUTOFF_MESH_ORDERS", "STEPS_PER_MESH_PERIOD",
           "MESH_SIZES_PER_MODULE", "MESH_REFINEMENT", "ELEMENTS_PER_SHAFT_DIAMETER", "RING_TOOTH_SIZE_PER_MODULE",
           "ELEMENTS_THROUGH_RING_RIM"]

FACE_WIDTH_PER_SUN_DIAMETER = 0.6
"""Face width (all helix halves) over the sun's reference diameter: b/d_1 of a planetary sun, 0.5-0.8 in practice."""
CUTOFF_MESH_ORDERS = 3.5
"""Fixed-interface cutoff of the reduction in mesh orders: every body's modes to 3 mesh orders converge within 0.5 %
(benchmarks/RESULTS.md, the band check)."""
STEPS_PER_MESH_PERIOD = 24.0
"""Time steps per mesh period: 24 resolves the third mesh harmonic with 8 steps."""
MESH_SIZES_PER_MODULE = {"coarse": (1.9, 3.8), "default": (0.95, 2.8)}
"""(tooth, body) element size per normal module of the mesh levels every gearbox has."""
ELEMENTS_PER_SHAFT_DIAMETER = {"coarse": 6.0, "default": 8.0}
"""Least elements across the input shaft's diameter (body size <= d / this): a coarser shaft is meshed too
unevenly for its axisymmetric frame (``frame_axisymmetry_tolerance``; 2.8 elements gave 3e-4 against 1e-4). The
study's 50 mm shaft has 6.25 at its coarse level."""
RING_TOOTH_SIZE_PER_MODULE = {"coarse": 1.2, "default": 0.95}
"""Element size on the ring's teeth per normal module, at most the level's tooth size: the ring's in-band modes
bend its thin rim, and its teeth (their mass and root compliance) need finer elements than the solid gears' to
converge (benchmarks/RESULTS.md, mesh convergence)."""
ELEMENTS_THROUGH_RING_RIM = 2.0
"""Least second-order elements through the ring's rim below the tooth root (ring body size <= rim / this): one
element through it makes the rim's bending about 1.4 % too stiff (benchmarks/RESULTS.md, mesh convergence)."""
MESH_REFINEMENT = {"coarse": (0.1, 1), "default": (0.3, 3)}
"""(elements per curvature radius, optimisation passes) of the two levels, as the study's coarse and default."""

_MM = 1e-3


def _gear_sizes(g: GearSet, halves: int) -> dict[str, float]:
    """[gears_assumed]: face width per helix half (``halves`` 1 or 2), half gap, backlash [mm]."""
    m = g.normal_module_mm
    d_sun = g.sun_teeth * m / math.cos(g.helix_angle_rad)
    return {"face_width_mm": FACE_WIDTH_PER_SUN_DIAMETER * d_sun / halves, "half_gap_mm": 4.0 * m,
            "normal_backlash_mm": 0.05 * m}


def _given(given: dict[str, Any], name: str, default: float) -> float:
    """The file's value of ``name`` when it is a positive number (the field's check judges any other), else
    ``default``: derived sizes follow the sizes the file gives."""
    value = given.get(name)
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and value > 0
    return float(value) if ok else default


def _root_diameters_mm(g: GearSet, a: GearSetAssumed) -> tuple[float, float, float]:
    """Root diameters [mm] of sun, planet and ring, profile-shifted to the operating centre distance; unshifted
    sun and ring where that distance cannot be reached (the feasibility check then refuses the set by name)."""
    try:
        gs = gear_set_geometry_of(g, a)
    except ValueError:
        mt, m = g.normal_module_mm / math.cos(g.helix_angle_rad), g.normal_module_mm
        shifts = (0.0, a.planet_shift_coefficient, 0.0)
        sun, planet, ring = (mt * z + (1 if internal else -1) * 2 * m * (a.dedendum_coefficient - x)
                             for z, x, internal in zip((g.sun_teeth, g.planet_teeth, g.ring_teeth), shifts,
                                                       (False, False, True), strict=True))
        if not g.has_ring:  # the wheel's tip circle plus two modules (module docstring)
            ring = planet + 2 * m * (a.dedendum_coefficient + a.addendum_coefficient + 2.0)
        return sun, planet, ring
    if not g.has_ring:  # the parallel-axis pair: the ring's sizes (unused) follow the wheel as if it were a ring
        return (2 * gs.sun.root_radius / _MM, 2 * gs.planet.root_radius / _MM,
                2 * (gs.planet.tip_radius + 2 * g.normal_module_m) / _MM)
    return tuple(2 * getattr(gs, n).root_radius / _MM for n in ("sun", "planet", "ring"))


def _component_sizes(g: GearSet, a: GearSetAssumed, given: dict[str, Any]) -> dict[str, float]:
    """[components_assumed] [mm] from the profile-shifted root diameters and the sizes the file ``given`` (module
    docstring): the shafts follow the sun's bore, the flange the rim and bolt holes, whether given or derived."""
    m = g.normal_module_mm
    df_sun, df_planet, df_ring = _root_diameters_mm(g, a)
    rim = _given(given, "ring_rim_thickness_mm", 4.0 * m)
    hole = _given(given, "ring_bolt_hole_diameter_mm", 4.0 * m)
    flange = _given(given, "ring_flange_outer_diameter_mm", df_ring + 2 * rim + 4 * hole)
    sun_bore = _given(given, "sun_bore_diameter_mm", 0.5 * df_sun)
    shaft_in = _given(given, "input_shaft_outer_diameter_mm", sun_bore)
    planet_bore = _given(given, "planet_bore_diameter_mm", 0.5 * df_planet)
    shaft_out = _given(given, "output_shaft_outer_diameter_mm", 0.25 * flange if g.has_ring else planet_bore)
    length = _given(given, "input_shaft_length_mm", 3.0 * sun_bore)
    return {
        "sun_bore_diameter_mm": sun_bore, "planet_bore_diameter_mm": planet_bore,
        "ring_rim_thickness_mm": rim, "ring_flange_outer_diameter_mm": flange, "ring_flange_thickness_mm": 4.0 * m,
        "ring_bolt_hole_diameter_mm": hole,
        "input_shaft_outer_diameter_mm": shaft_in, "input_shaft_inner_diameter_mm": 0.6 * shaft_in,
        "input_shaft_length_mm": length,
        "output_shaft_outer_diameter_mm": shaft_out,
        "output_shaft_inner_diameter_mm": (0.78 if g.has_ring else 0.6) * shaft_out,
        "output_shaft_length_mm": _given(given, "output_shaft_length_mm", length),
        "relief_groove_depth_mm": 0.5 * m, "bearing_seat_width_mm": 0.4 * sun_bore,
    }


def _carrier(g: GearSet, a: GearSetAssumed, material: Material, c: ComponentsAssumed) -> dict[str, float]:
    """[lumped_assumed] carrier mass [kg] and polar inertia [kg m^2] (module docstring)."""
    if g.arrangement == "planetary":
        try:
            props = carrier_mass_properties(carrier_sizes_of(g, a, c), material.density_kg_m3)
        except ValueError:  # no room for posts between the planets: the estimate below
            pass
        else:
            return {"carrier_mass_kg": props.mass, "carrier_inertia_kg_m2": float(props.inertia[2, 2])}
    df_planet = _root_diameters_mm(g, a)[1] * _MM
    width = a.face_width_m * (2 if a.helix_layout == "double" else 1)
    mass = g.planet_count * material.density_kg_m3 * math.pi * (df_planet / 2) ** 2 * width
    centre = a.operating_centre_distance_m or 0.25 * g.normal_module_m / math.cos(g.helix_angle_rad) * (
        g.sun_teeth + g.ring_teeth)
    return {"carrier_mass_kg": mass, "carrier_inertia_kg_m2": 0.5 * mass * centre ** 2}


def derived_defaults(table: str, built: dict[str, Any], given: dict[str, Any]) -> dict[str, Any]:
    """The derived defaults of ``table`` from the tables already ``built`` (flexgear.spec's loading order: gears,
    gears_assumed, load_case, material_assumed, then the rest) and the values ``given`` in the table itself (raw:
    a value of the wrong type is left to the field's check); {} for a table without any."""
    if table == "gears":  # the parallel-axis pair: no ring, one wheel; the other stages give both
        return {"ring_teeth": 0, "planet_count": 1} if given.get("arrangement") == "parallel" else {}
    g: GearSet = built["gears"]
    if table == "gears_assumed":
        return _gear_sizes(g, 2 if given.get("helix_layout") == "double" else 1)
    a: GearSetAssumed = built["gears_assumed"]
    if table == "components_assumed":
        return _component_sizes(g, a, given)
    if table == "joints_assumed":
        hole = built["components_assumed"].ring_bolt_hole_diameter_mm
        return {"bolt_clamp_diameter_mm": 2.5 * hole}
    if table.startswith("meshing_assumed."):
        level = table.split(".", 1)[1]
        if level not in MESH_SIZES_PER_MODULE:
            return {}
        tooth, body = MESH_SIZES_PER_MODULE[level]
        curvature, passes = MESH_REFINEMENT[level]
        shaft = built["components_assumed"].input_shaft_outer_diameter_mm
        tooth_mm = _given(given, "tooth_size_mm", tooth * g.normal_module_mm)
        body_mm = _given(given, "body_size_mm", max(
            tooth_mm, min(body * g.normal_module_mm, shaft / ELEMENTS_PER_SHAFT_DIAMETER[level])))
        ring_tooth_mm = min(tooth_mm, RING_TOOTH_SIZE_PER_MODULE[level] * g.normal_module_mm)
        rim = built["components_assumed"].ring_rim_thickness_mm / ELEMENTS_THROUGH_RING_RIM
        ring_tooth_mm = _given(given, "ring_tooth_size_mm", ring_tooth_mm)
        return {"tooth_size_mm": tooth_mm, "body_size_mm": body_mm, "ring_tooth_size_mm": ring_tooth_mm,
                "ring_body_size_mm": max(ring_tooth_mm, min(body_mm, rim)),
                "elements_per_curvature_radius": curvature, "optimisation_steps": passes}
    if table == "lumped_assumed":
        return _carrier(g, a, built["material_assumed"], built["components_assumed"])
    if table == "load_case":
        speed = given.get("input_speed_rpm")
        if not isinstance(speed, (int, float)) or isinstance(speed, bool) or not speed:
            return {}
        return {"step_size_s": 1.0 / (STEPS_PER_MESH_PERIOD * mesh_frequency_hz(g, speed))}
    lc: LoadCase = built["load_case"]
    f_mesh = mesh_frequency_hz(g, lc.input_speed_rpm)
    if table == "reduction_assumed":
        return {"fixed_interface_cutoff_hz": CUTOFF_MESH_ORDERS * f_mesh}
    if table == "screening":
        blocks = given.get("settle_final_blocks", 8)
        blocks = blocks if isinstance(blocks, int) and blocks > 0 else 8
        output_teeth = g.ring_teeth if g.has_ring else g.planet_teeth  # mesh cycles per output revolution
        return {"settle_block_mesh_cycles": max(1, round(output_teeth / blocks)),
                "window_start_s": lc.ramp_time_s, "window_end_s": lc.end_time_s}
    return {}


register_derived_defaults(derived_defaults)
