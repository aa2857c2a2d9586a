"""Contact law, stiffness variation and drive angle: pure functions, numpy and compiled forms agree."""

import math

import numpy as np
import pytest

from flexgear.geometry.contact_lines import PeriodicSeries
from flexgear.laws.contact import ContactLaw, backlash_linear_force, friction_forces, impact_force
from flexgear.laws.ramps import drive_angle, step, step_integral

LAW = ContactLaw(stiffness=1e8, exponent=1.5, damping_max=1e5, penetration_depth=1e-4)


def test_impact_law_values():
    # separated teeth carry nothing, also when approaching
    assert impact_force(-1e-5, 1.0, LAW) == 0.0
    # static penetration: k delta^e (study's mesh force needs ~0.4 mm at k = 1e8)
    delta = (798.21 / 1e8) ** (1 / 1.5)
    assert impact_force(delta, 0.0, LAW) == pytest.approx(798.21)
    # damping ramps with STEP(delta, 0, 0, d, c_max): half way -> half of c_max
    assert impact_force(0.5e-4, 1e-3, LAW) - impact_force(0.5e-4, 0.0, LAW) == pytest.approx(0.5 * 1e5 * 1e-3)
    # full damping beyond the penetration depth, no adhesion when separating fast
    assert impact_force(2e-4, 1e-3, LAW) - impact_force(2e-4, 0.0, LAW) == pytest.approx(100.0)
    assert impact_force(1e-6, -1.0, LAW) == 0.0


def test_compiled_series_value_equals_direct_fourier_sum():
    """The one compiled series evaluator (angle-addition recurrence) against the direct sum of cosines and sines."""
    from flexgear.laws.compiled import periodic_values, series_value

    series = PeriodicSeries(1.0, np.array([-0.0158, 0.0087, -0.0012, 0.004]), np.array([0.01, -0.002, 0.003, 0.0]))
    phi = np.linspace(-1, 3, 401)
    row = series.packed()
    compiled = np.array([series_value(row, math.cos(2 * math.pi * p), math.sin(2 * math.pi * p)) for p in phi])
    assert np.max(np.abs(compiled - series(phi))) < 1e-13
    assert np.max(np.abs(periodic_values(phi, np.tile(row, (phi.size, 1))) - series(phi))) < 1e-13
    assert series_value(PeriodicSeries(1.0, np.zeros(3), np.zeros(3)).packed(), 0.3, 0.9) == 1.0
    assert series_value(np.array([0.7]), 0.3, 0.9) == 0.7  # no harmonics: the mean


def test_friction_law():
    # full sliding: mu F kappa on the sliding coordinate, mu F lambda on the relative spin; odd in Omega
    f_slide, f_spin = friction_forces(800.0, 1000.0, 0.25, 3e-3, 0.02, 0.01, 3e-3)
    assert f_slide == pytest.approx(0.02 * 800 * 0.25) and f_spin == pytest.approx(0.02 * 800 * 3e-3)
    assert friction_forces(800.0, -1000.0, 0.25, 3e-3, 0.02, 0.01, 3e-3)[1] == pytest.approx(-f_spin)
    assert friction_forces(800.0, 0.0, 0.25, 3e-3, 0.02, 0.01, 3e-3) == (0.0, 0.0)


def test_compiled_tooth_friction_is_the_regularised_coulomb_law():
    """mu F tanh(v / v_reg), odd in v; where it skips tanh (saturation) it returns the very number tanh gives."""
    from flexgear.laws.compiled import TANH_SATURATION, tooth_friction

    for slip in (-40.0, -19.2, -3.0, -0.4, 0.0, 1e-3, 0.7, 19.0, 19.2, 25.0, 1e6):
        assert tooth_friction(0.02, 800.0, slip) == 0.02 * 800.0 * math.tanh(slip)
        f_slide, _ = friction_forces(800.0, slip, 1.0, 1.0, 0.02, 1.0, 1.0)
        assert tooth_friction(0.02, 800.0, slip) == pytest.approx(f_slide, rel=1e-15)
    beyond = np.linspace(TANH_SATURATION, 60.0, 20001)
    assert all(math.tanh(x) == 1.0 for x in beyond)  # where tanh rounds to 1 in double precision


def test_drive_angle_is_step_integral():
    t = np.linspace(0, 0.6, 1201)
    w = 6000 * 2 * math.pi / 60
    assert np.allclose(drive_angle(t, 0.5, w), step_integral(t, 0.5, w), rtol=0, atol=1e-9)
    h = 1e-7
    assert (drive_angle(0.3 + h, 0.5, w) - drive_angle(0.3 - h, 0.5, w)) / (2 * h) == pytest.approx(
        step(0.3, 0, 0, 0.5, w), rel=1e-6)


def test_numba_twins_equal_the_laws():
    """Each law's compiled (numba) twin gives the numpy law's force over penetration, separation and play."""
    from flexgear.laws.compiled import backlash_linear_force as linear_nb
    from flexgear.laws.compiled import impact_normal_force

    for delta in (-2e-4, -1e-5, 0.0, 3e-5, 1e-4, 4e-4):
        for rate in (-1e-2, 0.0, 2e-3):
            assert impact_normal_force(delta, rate, 1e8 * 1.03, 1.5, 1e5, 1e-4) == pytest.approx(
                float(impact_force(delta, rate, LAW, 1.03)), rel=1e-13, abs=1e-12)
            assert linear_nb(delta, rate, 5e8, 2e3, 5e-5) == pytest.approx(
                float(backlash_linear_force(delta, rate, 5e8, 2e3, 5e-5)), rel=1e-13, abs=1e-12)
    # the linear law is two-sided with zero force inside the play (eq. 11-13)
    assert backlash_linear_force(-2e-5, 1.0, 5e8, 2e3, 5e-5) == 0.0
    assert backlash_linear_force(-6e-5, 0.0, 5e8, 2e3, 5e-5) == pytest.approx(-5e8 * 1e-5)


def test_compiled_forms_match_numpy():
    """The symbolic (Exudyn) normal law with a stiffness-factor variable, as the runs use it, equals the numpy law."""
    from exudyn import symbolic as esym

    d, v = esym.Real(2.5e-4), esym.Real(3e-3)
    c = PeriodicSeries(1.0, np.array([-0.0158, 0.0087, -0.0012]), np.array([0.003, 0.001, -0.002]))
    factor = float(c(drive_angle(0.31, 0.5, 628.3) * 7.0 - 0.2))
    f_sym = impact_force(d, v, LAW, esym.Real("test_stiffness_factor", factor), esym)
    f_np = impact_force(2.5e-4, 3e-3, LAW, factor)
    assert f_sym.Evaluate() == pytest.approx(float(f_np), rel=1e-12)
    t = esym.Real(0.31)
    assert drive_angle(t, 0.5, 628.3, esym).Evaluate() == pytest.approx(drive_angle(0.31, 0.5, 628.3), rel=1e-12)


@pytest.mark.parametrize("law", ["impact", "iso6336"])
def test_compiled_friction_kernel_equals_reference(model1, law):
    import dataclasses

    import exudyn as exu

    from flexgear.mbs.gearbox import build_star_gearbox

    gb = model1.gearbox
    variant = dataclasses.replace(model1, gearbox=gb.with_changes(contact=dataclasses.replace(gb.contact, law=law)))
    mbs = exu.SystemContainer().AddSystem()
    friction = build_star_gearbox(mbs, variant).friction
    assert friction.law.kind == law
    rng = np.random.default_rng(7)
    scale = 1e-4 if law == "impact" else 1e-5  # deflections of the law's order
    for t in (0.01, 0.3, 0.55):
        d, dt, qt = rng.uniform(-scale, 5 * scale, 20), rng.normal(0, 1e-3, 20), rng.normal(0, 300, 42)
        ref = friction.forces(t, d, dt, qt)
        assert np.max(np.abs(friction.fast_forces(t, d, dt, qt) - ref)) < 1e-9 * np.max(np.abs(ref))


def test_compiled_stiffness_schedule_equals_reference(model1):
    from exudyn import symbolic as esym

    from flexgear.mbs.contacts import StiffnessSchedule
    from flexgear.mbs.gearbox import mesh_contacts

    contacts = mesh_contacts(model1.gearbox)
    variables = [esym.Real(f"test_factor_{i}", 1.0) for i in range(len(contacts))]
    schedule = StiffnessSchedule(contacts, 0.5, 628.3, variables)
    for t in (0.0, 0.013, 0.31, 0.55):
        assert np.max(np.abs(schedule.fast_values(t) - schedule.values(t))) < 1e-12
        assert 0.9 < schedule.values(t).min() <= schedule.values(t).max() < 1.1
