"""Gear geometry against involute theory, exact mass properties, assembly and backlash.

Coarse meshes (at second order, nodes on the exact surfaces) of sun, planet and ring; the OCC solids
of every component against the exact section integrals.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from flexgear import gear_set_geometry, load_gearbox
from flexgear.fe.mesh import component_mesh
from flexgear.geometry.check import assembly_check, flank_deviation, measure_backlash
from flexgear.geometry.layout import component_layout, component_mass_properties, exact_mass_properties, gear_profiles

SPEC = load_gearbox(Path(__file__).resolve().parents[1] / "model_variants" / "gearbox.toml")
GS = gear_set_geometry(SPEC)


def _flank_deviation(component: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normal distance of each flank node of the coarse mesh from the involute helicoid, and the nodes' z and
    phase (flexgear.geometry.check.flank_deviation)."""
    mesh = component_mesh(SPEC, component, "coarse", order=2)
    return flank_deviation(component_layout(SPEC, component), mesh.nodes[mesh.regions["flanks"]])


@pytest.mark.parametrize("component", ["sun", "planet", "ring"])
def test_flank_nodes_lie_on_the_involute_helicoid(component):
    dist, _, _ = _flank_deviation(component)
    assert len(dist) > 200
    assert np.abs(dist).max() < 1e-6  # 1 um


@pytest.mark.parametrize("component", ["sun", "planet", "ring"])
def test_helix_lead_fitted_from_flank_nodes(component):
    """Fit the twist rate: phase residual = c + d z per helix half; lead = 2 pi / tau."""
    layout = component_layout(SPEC, component)
    gear = layout.gear
    _, z, d_theta = _flank_deviation(component)
    upper = z > 0
    slope = np.polyfit(z[upper], d_theta[upper], 1)[0]
    tau = abs(next(q.twist for q in layout.prisms if q.name == "teeth_upper") + slope)
    lead = 2 * math.pi / tau
    assert lead == pytest.approx(gear.lead, rel=1e-5)
    assert math.degrees(math.atan(2 * math.pi * gear.reference_radius / lead)) == pytest.approx(25.0, abs=1e-3)


@pytest.mark.parametrize("name", ["sun", "planet", "ring"])
def test_profile_tooth_thickness_and_radii(name):
    """Crossings of the sampled outline with the reference circle give the tooth thickness."""
    prof = gear_profiles(SPEC)[name]
    gear = prof.gear
    pts = prof.sample(200)
    r = np.hypot(pts[:, 0], pts[:, 1])
    assert r.max() == pytest.approx(gear.root_radius if gear.internal else gear.tip_radius, abs=1e-9)
    assert r.min() == pytest.approx(gear.tip_radius if gear.internal else gear.root_radius, abs=1e-9)
    rr = gear.reference_radius
    s = np.sign(r - rr)
    idx = np.flatnonzero(s[:-1] != s[1:])
    f = (rr - r[idx]) / (r[idx + 1] - r[idx])
    cross = pts[idx] + f[:, None] * (pts[idx + 1] - pts[idx])
    ang = np.arctan2(cross[:, 1], cross[:, 0])
    near = np.sort(ang[np.abs(ang) < math.pi / gear.teeth])  # the two flanks of tooth 0 (material for the ring)
    assert len(near) == 2
    s_t = rr * (near[1] - near[0])
    s_n = s_t * math.cos(gear.helix_angle)
    assert s_n == pytest.approx(gear.normal_tooth_thickness, abs=2e-8)
    expected = 2.12e-3 * (math.pi / 2 + 2 * gear.shift * math.tan(math.radians(14.5))) - 0.1e-3 / (
        2 * math.cos(math.radians(14.5)))
    assert s_n == pytest.approx(expected, abs=2e-8)


@pytest.mark.parametrize("component", ["sun", "planet"])
def test_mesh_tip_and_root_radii(component):
    mesh = component_mesh(SPEC, component, "coarse", order=2)
    gear = component_layout(SPEC, component).gear
    p = mesh.nodes
    r, z = np.hypot(p[:, 0], p[:, 1]), np.abs(p[:, 2])
    z_end = component_layout(SPEC, component).z_range[1]
    teeth = (z > SPEC.gears_assumed.half_gap_m / 2 + 1e-6) & (z < z_end - 1e-6)  # lateral surface only
    assert r.max() == pytest.approx(gear.tip_radius, abs=1e-6)
    boundary = np.unique(mesh.surface)
    outer = boundary[teeth[boundary] & (r[boundary] > gear.root_radius - 1e-4)]
    assert r[outer].min() == pytest.approx(gear.root_radius, abs=1e-6)


@pytest.mark.parametrize("component", ["sun", "planet", "ring", "input_shaft", "output_shaft"])
def test_solid_volume_integrals_match_exact_section_integrals(component):
    """The sewn OCC solid (geometry.solids) against Green's-theorem section integrals (geometry.layout)."""
    from netgen.occ import OCCGeometry

    from flexgear.fe.mesh import component_brep
    from flexgear.geometry.solids import occ_mass_properties

    exact = exact_mass_properties(SPEC, component)
    shape = OCCGeometry(str(component_brep(SPEC, component))).shape
    mass, com, inertia = occ_mass_properties(shape, SPEC.material_assumed.density_kg_m3)
    assert len(shape.solids) == 1
    assert mass == pytest.approx(exact.mass, rel=1e-5)
    np.testing.assert_allclose(np.diag(inertia), np.diag(exact.inertia), rtol=1e-5)
    assert np.linalg.norm(com - exact.com) < 1e-7


@pytest.mark.parametrize("component", ["sun", "planet", "ring", "input_shaft", "output_shaft"])
def test_mesh_mass_properties_match_exact_integrals(component):
    exact = exact_mass_properties(SPEC, component)
    from flexgear.fe.surface import mesh_mass_properties

    got = mesh_mass_properties(component_mesh(SPEC, component, "coarse", order=2), SPEC.material_assumed.density_kg_m3)
    assert got.mass == pytest.approx(exact.mass, rel=1e-3)
    np.testing.assert_allclose(np.diag(got.inertia), np.diag(exact.inertia), rtol=1e-3)
    assert np.linalg.norm(got.com - exact.com) < 1e-5


def test_exact_mass_properties_are_plausible_steel():
    """Steel gears lie between the solid annuli out to the root and to the tip circle (rigorous
    bounds); the tube shaft matches its closed form."""
    rho = SPEC.material_assumed.density_kg_m3
    a = SPEC.gears_assumed
    for name in ("sun", "planet"):
        gear = getattr(GS, name)
        props = component_mass_properties(SPEC, name)
        r_bore = getattr(SPEC.components_assumed, f"{name}_bore_diameter_mm") * 5e-4
        groove = rho * math.pi * ((gear.root_radius - 1e-3) ** 2 - r_bore**2) * a.half_gap_m
        lower = rho * math.pi * (gear.root_radius**2 - r_bore**2) * a.face_width_m + groove
        upper = rho * math.pi * (gear.tip_radius**2 - r_bore**2) * a.face_width_m + groove
        assert lower < props.mass < upper
    shaft = component_mass_properties(SPEC, "input_shaft")
    c = SPEC.components_assumed
    ro, ri, length = c.input_shaft_outer_diameter_mm * 5e-4, c.input_shaft_inner_diameter_mm * 5e-4, 0.15
    assert shaft.mass == pytest.approx(rho * math.pi * (ro**2 - ri**2) * length, rel=1e-12)
    assert shaft.inertia[2, 2] == pytest.approx(0.5 * shaft.mass * (ro**2 + ri**2), rel=1e-12)
    for name in ("sun", "planet", "ring", "input_shaft", "output_shaft"):
        props = component_mass_properties(SPEC, name)
        assert 0.5 < props.mass < 20.0
        assert props.inertia[2, 2] > 0 and np.allclose(props.inertia, np.diag(np.diag(props.inertia)))


def test_no_interference_and_design_backlash_at_nominal_position():
    check = assembly_check(SPEC, z_levels=3)
    assert check["max_overlap_m2"] == 0.0
    design = GS.sun_planet.normal_backlash
    assert check["sun_planet_normal_backlash_m"] == pytest.approx(design, abs=2e-6)
    assert check["planet_ring_normal_backlash_m"] == pytest.approx(design, abs=2e-6)


def test_every_planet_fits_the_ring_spaces():
    for i in range(GS.planet_count):
        play = measure_backlash(SPEC, "planet_ring", planet=i, z=0.012)
        assert play["normal_m"] == pytest.approx(GS.planet_ring.normal_backlash, abs=2e-6)
