"""Toothed bodies of any gear set (flexgear.geometry.gear_body, flexgear.fe.toothed) against the exact geometry and
their full FE models.

- The study's sun and planet described as GearBody give the study's own layouts and contact bands (no meshing).
- The pinion and wheel of examples/helical_pair_flexible.py (20/50 teeth, m_n 3 mm, helix 15 deg, alpha_n 20 deg,
  25 mm face, single helix, 40 mm bores) on their coarse second-order meshes: mass and inertia within 0.1 % of the
  exact section integrals, flank nodes on the involute helicoid within 1 um on both flanks of every tooth.
- The wheel's reduced body (the example's, shared through the mesh cache): its free-free modes below 3 x a 3 kHz
  mesh frequency (the pinion at 9000 rpm; the example's 1 kHz has no wheel mode below 3 kHz) within 1 % of its
  full FE model's; its compliance at the contact band under the contact kernel's load (the load a mesh puts on a
  flexible gear, flexgear.fe.compliance) within 2 % of full FE, also with its high modes as residual compliance.
- An internal spur gear in its rim builds: mesh mass, flanks, its rim seat, a reduced body against full FE.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import flexgear as fg
from flexgear.fe.cms import full_free_modes
from flexgear.fe.compliance import free_body_solver, static_compliance
from flexgear.fe.toothed import toothed_interfaces, toothed_mesh
from flexgear.geometry.check import flank_deviation

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
MESH_FREQUENCY_HZ = 3000.0
"""The test's mesh frequency: the example's pinion (20 teeth) at 9000 rpm."""


def _example():
    spec = importlib.util.spec_from_file_location("helical_pair_flexible", EXAMPLES / "helical_pair_flexible.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def example():
    return _example()


@pytest.fixture(scope="module")
def pair(example, gearbox):
    """(mesh, pinion, wheel, the wheel's engagement) of the example."""
    return example.gear_bodies(gearbox)


@pytest.fixture(scope="module")
def wheel_fe(pair):
    """The wheel's FE model (the one its reduced body is built on) and its free-body factorisation."""
    fe = fg.toothed_fe_model(pair[2])
    return fe, free_body_solver(fe)


def _flank_check(body: fg.GearBody) -> float:
    """Largest distance [m] of the coarse second-order mesh's flank nodes from the involute helicoid; asserts that
    both flanks of every tooth carry nodes (one flank per half pitch, as tests/test_gear_sets.py)."""
    layout = body.layout()
    mesh = toothed_mesh(body, 2)
    points = mesh.nodes[mesh.regions["flanks"]]
    dist, _, _ = flank_deviation(layout, points)
    twist = np.array([next(q.twist for q in layout.prisms if q.section.gear and q.z0 - 1e-9 <= z <= q.z1 + 1e-9)
                      for z in points[:, 2]])
    phase = np.arctan2(points[:, 1], points[:, 0]) - twist * points[:, 2]
    half_pitch = np.floor(phase / (math.pi / body.teeth))
    assert len(np.unique(half_pitch % (2 * body.teeth))) == 2 * body.teeth
    return float(np.abs(dist).max())


def _mass_check(body: fg.GearBody, mesh_props: fg.MassProperties) -> float:
    """Relative mass error of the mesh against the exact section integrals; asserts inertia and centre of mass."""
    exact = fg.toothed_mass_properties(body)
    np.testing.assert_allclose(np.diag(mesh_props.inertia), np.diag(exact.inertia), rtol=1e-3)
    assert np.linalg.norm(mesh_props.com - exact.com) < 1e-3 * body.normal_module
    return mesh_props.mass / exact.mass - 1


def test_study_gears_as_gear_bodies_keep_the_study_layouts_and_bands(gearbox):
    """GearBody.from_gear_set: the sun's and planet's layouts are the study's (same prisms, gear and profile), their
    exact mass properties the study's, and their engagements' load circles the study's contact bands; the ring is
    its toothed rim without the flange (lighter than the study's ring)."""
    from flexgear.design import design
    from flexgear.fe.reduced import component_load_circles

    d = design(gearbox)
    geo, sigma = d.gears, int(math.copysign(1.0, gearbox.load_case.input_speed_rad_s))
    engagements = {"sun": [fg.Engagement(geo.sun_planet, 1, sigma)],
                   "planet": [fg.Engagement(geo.sun_planet, 2, sigma), fg.Engagement(geo.planet_ring, 1, -sigma)],
                   "ring": [fg.Engagement(geo.planet_ring, 2, -sigma)]}
    order = gearbox.reduction_assumed.attachment_order
    for name in ("sun", "planet", "ring"):
        body = fg.GearBody.from_gear_set(gearbox, name)
        assert fg.toothed_load_circles(body, engagements[name], order) == component_load_circles(gearbox, name, order)
        if name == "ring":
            assert body.layout().prisms == d.layouts[name].prisms[:len(body.layout().prisms)]
            assert body.mass_properties().mass < d.masses[name].mass
            continue
        assert body.layout() == d.layouts[name]
        assert body.mass_properties().mass == d.masses[name].mass
        np.testing.assert_array_equal(body.mass_properties().inertia, d.masses[name].inertia)


@pytest.mark.parametrize("which", ["pinion", "wheel"])
def test_example_gears_mesh_their_exact_mass_and_involute_flanks(pair, wheel_fe, which):
    """Coarse second-order meshes of the example's pinion and wheel: mass within 0.1 % of the exact section
    integrals (measured 2.7e-5 for the wheel), flank nodes within 1 um of the involute helicoid (measured 5 nm)."""
    body = pair[1] if which == "pinion" else pair[2]
    props = wheel_fe[0].mass_properties() if which == "wheel" else fg.toothed_mass_properties(body, "mesh")
    error = _mass_check(body, props)
    deviation = _flank_check(body)
    print(f"{which}: mass error {error:.2e}, largest flank deviation {deviation * 1e9:.1f} nm")
    assert abs(error) < 1e-3
    assert deviation < 1e-6


def test_wheel_reduced_body_against_full_fe(example, gearbox, pair, wheel_fe):
    """The example's wheel: free-free modes below 3 x the 3 kHz mesh frequency within 1 % of full FE (measured
    0.17 % for the third mode at 7.5 kHz, 4e-8 for the 4.5 kHz pair), the reduced compliance at the contact band under
    the contact kernel's load within 2 % of full FE (measured 1e-13: the attachment modes span the kernel), and so
    is the kept modes' static compliance plus the residual of the modes dropped above the example's cut-off."""
    _, _, wheel, engagement = pair
    fe, solver = wheel_fe
    body = example.wheel_body(gearbox, wheel, engagement)
    np.testing.assert_array_equal(body.nodes, fe.nodes)  # built on this FE model (the cached mesh)
    full = full_free_modes(fe, 6, solver)[0]
    band = 3 * MESH_FREQUENCY_HZ
    n = int(np.count_nonzero(full < band))
    assert n >= 3 and full[n] > band  # the six computed reach beyond the band
    errors = body.frequencies_hz[:n] / full[:n] - 1
    print(f"modes below {band:.0f} Hz: full FE {np.round(full[:n])} Hz, reduced errors {errors}")
    assert np.all(np.abs(errors) < 0.01)

    points, normals = fg.toothed_contacts(wheel, [engagement])
    kernel = fg.toothed_load_circles(wheel, [engagement], gearbox.reduction_assumed.contact_fourier_order)
    seat = body.interface("bore")
    c_full = static_compliance(fe, points, normals, toothed_interfaces(fe, wheel)[0], kernel=kernel)[0, 0]
    c_red = static_compliance(body, points, normals, seat, kernel=kernel)[0, 0]
    # the modes above the example's cut-off leave the integration and return as a static residual (the mode-
    # acceleration method, flexgear.mbs.residual): the kept modes alone are stiffer, kept + residual is the whole
    keep = body.modes_below(example.KEEP_BELOW_HZ)
    kept = static_compliance(body.truncated(keep), points, normals, seat, kernel=kernel)[0, 0]
    high = dataclasses.replace(body, modes=body.modes[:, keep:], stiffness=body.stiffness[keep:])
    residual = static_compliance(high, points, normals, seat, kernel=kernel)[0, 0]
    dropped = fg.dropped_modes(gearbox, body, keep, "wheel")
    print(f"kernel compliance: full FE {c_full:.4e} m/N, reduced {c_red / c_full - 1:+.1e}; {keep} of {body.n_modes} "
          f"modes kept, the residual of the others {residual / c_full:.1%} of it")
    assert c_full > 0 and abs(c_red / c_full - 1) < 0.02
    assert 0 < keep < body.n_modes and dropped.keep == keep
    assert residual > 0.5 * c_full  # the contact band's compliance lives in the high modes
    assert kept + residual == pytest.approx(c_red, rel=1e-9)


def test_internal_spur_gear_builds(tmp_path, monkeypatch):
    """A 40-tooth internal spur gear (m 2 mm, 12 mm face, 5 mm rim) meshing with a 16-tooth pinion: its mesh's mass
    within 0.1 % of exact, flank nodes within 1 um, its seat on the rim's outer surface, and its reduced body's
    lowest free-free modes (the rim's ovalling pair) within 1 % of full FE, its kernel compliance within 2 %."""
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(tmp_path / "cache"))
    mesh = fg.gear_pair_geometry(16, 40, 2e-3, 0.0, math.radians(20.0), 0.012, internal=True, normal_backlash=1e-4)
    ring = fg.GearBody.from_gear(mesh.gear2, name="annulus", rim_thickness=0.005)
    engagement = fg.Engagement(mesh, gear=2, drive_sign=1, angles=(0.0,))
    fe = fg.toothed_fe_model(ring)
    error, deviation = _mass_check(ring, fe.mass_properties()), _flank_check(ring)
    seat = toothed_interfaces(fe, ring)[0]
    assert seat.name == "rim"
    np.testing.assert_allclose(np.hypot(*fe.nodes[seat.nodes, :2].T), ring.gear.root_radius + 0.005, atol=1e-6)
    body = fg.toothed_body(ring, [engagement], cutoff_hz=6000.0, attachment_order=4)
    full = full_free_modes(fe, 2, free_body_solver(fe))[0]
    points, normals = fg.toothed_contacts(ring, [engagement])
    kernel = fg.toothed_load_circles(ring, [engagement], 4)
    c_full = static_compliance(fe, points, normals, seat, kernel=kernel)[0, 0]
    c_red = static_compliance(body, points, normals, "rim", kernel=kernel)[0, 0]
    print(f"internal: mass error {error:.2e}, flank deviation {deviation * 1e9:.1f} nm, modes {full} Hz "
          f"({body.frequencies_hz[:2] / full - 1}), compliance {c_red / c_full - 1:+.1e}")
    assert abs(error) < 1e-3 and deviation < 1e-6
    assert np.all(np.abs(body.frequencies_hz[:2] / full - 1) < 0.01)
    assert abs(c_red / c_full - 1) < 0.02
