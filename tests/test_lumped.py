"""Lumped-parameter model: closed-form eigenvalues, mode structure, static and dynamic mesh forces, speeds."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from flexgear.geometry.contact_lines import mesh_stiffness_harmonics
from flexgear.geometry.involute import gear_set_geometry
from flexgear.lumped.modal import modal_analysis
from flexgear.lumped.model import LumpedParameters, MemberParameters, friction_tables, mesh_friction_tables
from flexgear.lumped.run import run_lumped, static_mesh_forces
from flexgear.results import signal_columns
from flexgear.spec import load_gearbox
from flexgear.theory import theory

GEARBOX = Path(__file__).resolve().parents[1] / "model_variants" / "gearbox.toml"


@pytest.fixture(scope="module")
def spec():
    return load_gearbox(GEARBOX)


def plain_set(n: int = 4, fixed=("carrier",), helix: float = 0.0) -> LumpedParameters:
    """A literature-style planetary set (plain numbers, SI)."""
    return LumpedParameters(
        sun=MemberParameters(0.4, 0.39, 0.024, 1e8),
        ring=MemberParameters(2.35, 3.0, 0.1085, 1e8, torsional_stiffness_n_per_m=0.0),
        carrier=MemberParameters(5.43, 6.29, 0.0663, 1e8),
        planet=MemberParameters(0.66, 0.61, 0.0212, 1e8),
        planet_count=n, sun_mesh_stiffness_n_per_m=5e8, ring_mesh_stiffness_n_per_m=4e8,
        sun_pressure_angle_rad=math.radians(24.6), ring_pressure_angle_rad=math.radians(24.6),
        fixed=fixed, base_helix_angle_rad=helix,
    )


@pytest.mark.parametrize("n", [3, 4, 5])
def test_torsional_planet_modes_closed_form(n):
    """Purely torsional model: planet modes at (k_sp + k_rp)/(I_p/r_p^2), multiplicity N-1, one rigid-body mode."""
    helix = math.radians(20.0)
    p = plain_set(n, helix=helix)
    res = modal_analysis(p, translations=False)
    k_eff = (p.sun_mesh_stiffness_n_per_m + p.ring_mesh_stiffness_n_per_m) * math.cos(helix) ** 2
    f_planet = math.sqrt(k_eff / p.planet.inertia_per_radius2_kg) / (2 * math.pi)
    planet = res.frequencies_hz[np.array(res.kinds) == "planet"]
    assert planet.size == n - 1
    np.testing.assert_allclose(planet, f_planet, rtol=1e-9)
    assert np.sum(res.frequencies_hz < 1e-6) == 1  # carrier held: sun, ring, planets turn together
    # the rotational modes (all planets alike) are those of the 3-DOF chain sun - "N planets" - ring
    rs, rp, rr = p.sun.radius_m, p.planet.radius_m, p.ring.radius_m
    ks, kr = p.sun_mesh_stiffness_n_per_m * math.cos(helix) ** 2, p.ring_mesh_stiffness_n_per_m * math.cos(helix) ** 2
    K = n * np.array([[ks * rs**2, 0, ks * rs * rp], [0, kr * rr**2, -kr * rr * rp],
                      [ks * rs * rp, -kr * rr * rp, (ks + kr) * rp**2]])
    M = np.diag([p.sun.inertia_kg_m2, p.ring.inertia_kg_m2, n * p.planet.inertia_kg_m2])
    lam = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    f_chain = np.sqrt(np.clip(lam, 0, None)) / (2 * math.pi)
    rot = res.frequencies_hz[np.array(res.kinds) == "rotational"]
    np.testing.assert_allclose(rot[1:], f_chain[1:], rtol=1e-8)


def test_free_carrier_has_two_rigid_body_modes():
    """Sun, ring and carrier all free: a differential with two rigid-body modes (torsional model)."""
    res = modal_analysis(plain_set(4, fixed=()), translations=False)
    assert np.sum(res.frequencies_hz < 1e-6) == 2


@pytest.mark.parametrize("fixed", [("carrier",), ("ring",)])
def test_mode_structure_equally_spaced(fixed):
    """x-y-theta model, equally spaced planets: translational modes in pairs, rotational single, planet N-3."""
    n = 5
    res = modal_analysis(plain_set(n, fixed=fixed))
    kinds = np.array(res.kinds)
    assert set(kinds) <= {"rotational", "translational", "planet"}
    assert np.all(res.multiplicity[kinds == "translational"] == 2)
    assert np.all(res.multiplicity[(kinds == "rotational") & (res.frequencies_hz > 1e-6)] == 1)
    assert np.all(res.multiplicity[kinds == "planet"] == n - 3)
    # counts (Lin & Parker 1999): 3 rotational... per free DOF set, each planet-mode family has N-3 members
    assert np.sum(kinds == "planet") == 3 * (n - 3)


def test_unequal_spacing_mixes_modes():
    p = dataclasses.replace(plain_set(4), planet_angles_rad=(0.0, 1.4, 3.3, 4.6))
    assert "mixed" in modal_analysis(p).kinds


def test_study_gearbox_modes(spec):
    """The study's star gearbox: rigid-body spin mode, then the expected mode families."""
    res = modal_analysis(spec)
    assert res.frequencies_hz[0] < 1e-6 and res.kinds[0] == "rotational"
    held = modal_analysis(spec, hold_input=True)
    assert held.frequencies_hz[0] > 1.0  # the prescribed drive removes the rigid-body mode
    assert {"rotational", "translational", "planet"} == set(held.kinds)
    # bearings at their seats (flexgear.geometry.supports): the ring + output shaft floats on its single
    # bearing 0.17 m away (1/k = 1/k_r + L^2/k_t at the gear centre), following through the free planet
    # spins: the lowest pair is its translation on that condensed support, sqrt(k/m_app)/(2 pi) = 36.6 Hz
    p = LumpedParameters.from_spec(spec)
    floating = math.sqrt(p.ring.bearing_stiffness_n_per_m / p.ring.mass_kg) / (2 * math.pi)
    assert held.kinds[0] == held.kinds[1] == "translational"
    assert held.frequencies_hz[0] == pytest.approx(floating, rel=0.05)


def test_friction_table_length_matches_stiffness_harmonics(spec):
    """Total contact-line length over a mesh cycle has the Fourier coefficients of eq. 11-12 (two routes)."""
    geo = gear_set_geometry(spec)
    eps_b = geo.sun_planet.overlap_ratio(geo.helix_face_width)
    for mesh, table in zip((geo.sun_planet, geo.planet_ring), mesh_friction_tables(geo, 1024), strict=True):
        eps_a = mesh.transverse_contact_ratio
        c = mesh_stiffness_harmonics(eps_a, eps_b, 3)
        spec_n = np.fft.rfft(table.length)[1:4] * 2 / table.length.size
        centre = 0.5 * (eps_a + eps_b)
        shifted = (spec_n * np.exp(2j * np.pi * np.arange(1, 4) * centre)).real
        np.testing.assert_allclose(shifted, c, atol=2e-5)


@pytest.mark.parametrize("sign_slope", [1.0, -1.0])
def test_friction_table_arms_match_sampled_contact_lines(sign_slope):
    """Friction force and arms per unit mu F_n, (1/L) int sg dl and (1/L) int sg d_j dl over the contact lines, against
    dense sampling of the lines (load uniform along them, sg = sign_slope sign(s - s_p), d1 = d1_A + p_bt s)."""
    d1_start, d1_end, d1_pitch, d2_offset, p_bt, eps_b = 0.004, 0.0155, 0.0112, -0.1, 0.0062, 0.95
    table = friction_tables(d1_start, d1_end, d1_pitch, d2_offset, p_bt, eps_b, sign_slope, 64)
    eps_a, s_p = (d1_end - d1_start) / p_bt, (d1_pitch - d1_start) / p_bt
    n_y = 4000
    y = (np.arange(n_y) + 0.5) / n_y
    u = table.phase[:, None, None] + np.arange(-2, 6)[None, :, None] - eps_b * y[None, None, :]
    inside = (u >= 0.0) & (u <= eps_a)
    sg = sign_slope * np.sign(u - s_p) * inside
    lines = inside.sum(axis=(1, 2)) / n_y  # total length in lines across the face
    force = sg.sum(axis=(1, 2)) / n_y / lines
    arm1 = (sg * (d1_start + p_bt * u)).sum(axis=(1, 2)) / n_y / lines
    # sampling error: the midpoint rule is wrong only in the cells at a line's <= 3 jumps (field ends, pitch point),
    # by 1/n_y of a line each; at most ceil(eps_a + eps_b) + 1 = 4 lines: |dS| <= 12 / n_y, |dL| <= 8 / n_y
    tol = (12 + 8) / (n_y * lines.min())
    np.testing.assert_allclose(table.force, force, atol=tol)
    np.testing.assert_allclose(table.arm1, arm1, atol=tol * max(abs(d1_start), abs(d1_end)))
    np.testing.assert_allclose(table.arm2, arm1 + d2_offset * force, atol=tol * (max(abs(d1_start), abs(d1_end))
                                                                                  + abs(d2_offset)))


def test_static_mesh_force_equals_theory(spec):
    outer, inner = static_mesh_forces(spec)
    np.testing.assert_allclose(outer, 798.21, atol=0.01)
    np.testing.assert_allclose(inner, 798.21, atol=0.01)
    np.testing.assert_allclose(outer, theory(spec).mesh_force, rtol=1e-9)


def short_case(spec, arrangement: str = "star", friction: float = 0.0, variation: str = "constant",
               law: str = "iso6336"):
    """Ramps 0.02 s, 0.15 s; the linear mesh law of eq. 10-13 unless ``law`` says otherwise."""
    lc = dataclasses.replace(spec.load_case, ramp_time_s=0.02, end_time_s=0.15)
    return spec.with_changes(
        load_case=lc, gears=dataclasses.replace(spec.gears, arrangement=arrangement),
        contact=dataclasses.replace(spec.contact, friction_coefficient=friction, law=law),
        contact_assumed=dataclasses.replace(spec.contact_assumed, stiffness_variation=variation),
    )


@pytest.mark.parametrize("arrangement", ["star", "planetary"])
def test_dynamic_run_settles_to_theory(spec, arrangement):
    """Constant mesh stiffness, no friction: after the ramp, speeds and mesh forces reach theory."""
    s = short_case(spec, arrangement)
    th = theory(s)
    res = run_lumped(s)
    assert res.meta["backend"] == "lumped" and res.ok
    assert list(res.signals.columns) == signal_columns(s.gears.planet_count)
    assert np.allclose(np.diff(res.signals["time_s"]), s.load_case.step_size_s)
    w = res.signals[res.signals["time_s"] >= 0.13]
    assert w["input_speed_rad_per_s"].mean() == pytest.approx(th.input_speed, rel=1e-12)
    assert w["output_speed_rad_per_s"].mean() == pytest.approx(th.output_speed, rel=1e-7)
    forces = w.filter(regex="mesh_force").to_numpy()
    # planetary: centrifugal stiffening of the whirling planets shifts the force by ~1e-4
    np.testing.assert_allclose(forces.mean(0), th.mesh_force, rtol=1e-5 if arrangement == "star" else 3e-4)
    assert w["input_torque_nm"].mean() == pytest.approx(th.input_torque, rel=3e-4)


def test_phasing_cancels_bearing_harmonics(spec):
    """Sequentially phased planets (z_s = 44, N = 5): the sun's bearing sees only harmonics k with
    k z_s mod N = +-1 (1, 4, 6, 9 ...); 2, 3 and 5 cancel (Parker & Lin).

    Stated for a steady cyclically symmetric response. With the bearings at their seats the sun and ring float
    (36-50 Hz, lightly damped) and their free whirl, modulated by the mesh stiffness, puts sidebands next to the
    cancelled harmonics, of second order: the cancelled harmonics stay below 1e-4 of the 1x, two orders of
    magnitude below the weakest present one.
    """
    from flexgear.study.compare import harmonic_amplitudes

    s = short_case(spec, friction=0.02, variation="contact_lines")
    res = run_lumped(s, t_end_s=0.08)
    w = res.signals[res.signals["time_s"] >= 0.06]
    amps = harmonic_amplitudes(w["input_bearing_accel_x_m_per_s2"].to_numpy(), 1e-5, theory(s).mesh_frequency,
                               (1, 2, 3, 4, 5, 6))
    present, absent = amps[[0, 3, 5]], amps[[1, 2, 4]]
    assert absent.max() < 1e-4 * amps[0]
    assert present.min() > 1e2 * absent.max()


def test_friction_costs_input_torque(spec):
    """Tooth friction dissipates: at the same output the drive needs more torque than theory."""
    s = short_case(spec, friction=0.02)
    w = run_lumped(s, t_end_s=0.06).signals
    w = w[w["time_s"] >= 0.05]
    loss = w["input_torque_nm"].mean() / theory(s).input_torque - 1.0
    assert 0.0 < loss < 0.02


def test_reversed_load_crosses_backlash_to_back_flanks(spec):
    """A driving (negative) load torque pushes the teeth through the backlash j_n onto the back flanks:
    the mesh force becomes -798.21 N after the gap is crossed (contact loss allowed)."""
    s = short_case(spec)
    s = s.with_changes(load_case=dataclasses.replace(s.load_case, load_torque_nm=-s.load_case.load_torque_nm))
    w = run_lumped(s).signals
    forces = w.filter(regex="mesh_force").to_numpy()
    assert (np.abs(forces[1:]) < 1e-9).any()  # free flight inside the backlash at some point
    np.testing.assert_allclose(forces[w["time_s"].to_numpy() >= 0.13].mean(0), -theory(spec).mesh_force, rtol=1e-5)


def test_impact_law_mesh_carries_the_torque_at_the_laws_own_deflection(spec):
    """The study's impact law in the lumped model (the multibody model's law): after the ramps the mean mesh force
    is theory's (torque balance, any law); and the kernel's mesh force at a deflection delta, constant stiffness,
    no rate, is the law's k delta^e with the whole-face k (at 798 N, delta = (F/k)^(1/e): a few tenths of a mm)."""
    from flexgear.laws.contact import mesh_laws
    from flexgear.lumped.run import build_lumped_model, lumped_rhs

    s = short_case(spec, law="impact").with_fields("load_case", end_time_s=0.4)
    th = theory(s)
    w = run_lumped(s).signals
    forces = w[w["time_s"] >= 0.3].filter(regex="mesh_force").to_numpy()
    assert forces.mean() == pytest.approx(th.mesh_force, rel=2e-3)
    law = mesh_laws(s)["outer"]
    delta = (th.mesh_force / law.stiffness) ** (1.0 / law.exponent)
    assert 1e-4 < delta < 1e-3
    model = build_lumped_model(s)
    g = model.system.mesh_G[0]   # the first sun-planet mesh: delta = G_0 . q, put on one free coordinate of it
    j = next(k for k, i in enumerate(model.free) if abs(g[i]) > 0)
    y = np.zeros(2 * model.free.size)
    y[j] = delta / g[model.free[j]]
    row = lumped_rhs(model).record(0.0, y)   # t = 0: the prescribed input spin at rest; signals row: speeds,
    # torque, then the mesh forces
    assert row[3] == pytest.approx(th.mesh_force, rel=1e-9)
