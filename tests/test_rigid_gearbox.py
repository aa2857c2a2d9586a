"""Model 1 (all rigid) on Exudyn against theory, on a shortened load case.

The study's ramps take 0.5 s; the test ramps speed and load over 0.04 s and lets the overdamped
mesh (c/k_lin = 1e5 / 3e6 ~ 33 ms) settle for 5 time constants before it measures.
"""

import dataclasses

import numpy as np
import pytest

from flexgear.mbs.run import run_variant

RAMP, END, WINDOW = 0.04, 0.25, 0.2


def _shortened(variant, **contact_assumed):
    g = variant.gearbox
    g = g.with_changes(load_case=dataclasses.replace(g.load_case, ramp_time_s=RAMP, end_time_s=END))
    if contact_assumed:
        g = g.with_changes(contact_assumed=dataclasses.replace(g.contact_assumed, **contact_assumed))
    return dataclasses.replace(variant, gearbox=g)


@pytest.fixture(scope="module")
def run(model1):
    result = run_variant(_shortened(model1))
    assert result.ok, result.meta.get("reason")
    return result


@pytest.fixture(scope="module")
def steady(run):
    s = run.signals
    return s[s.time_s >= WINDOW]


def test_speeds_equal_theory(run, steady):
    th = run.meta["theory"]
    assert steady.input_speed_rad_per_s.mean() == pytest.approx(np.radians(36000.0), rel=1e-9)  # 6000 rpm
    assert steady.output_speed_rad_per_s.mean() == pytest.approx(th["output_speed_rad_per_s"], rel=1e-5)
    assert steady.transmission_ratio.mean() == pytest.approx(-44 / 136, rel=1e-5)


def test_mesh_forces_and_load_sharing(run, steady):
    f_theory = run.meta["theory"]["mesh_force_n"]  # T_in / (N r_b cos beta_b) = 798.21 N
    forces = [steady[f"{kind}_mesh_force_{i}_n"].mean() for kind in ("outer", "inner") for i in range(1, 6)]
    for f in forces:
        assert f == pytest.approx(f_theory, rel=0.01)
    outer = np.array(forces[:5])
    assert (outer.max() - outer.min()) / outer.mean() < 0.01


def test_power_balance_with_tooth_friction(run, steady, model1):
    """T_in w_in = T_out |w_out| + P_friction, P_friction = sum mu F lambda_mean |w1 - w2| (no solver involved)."""
    from flexgear.mbs.gearbox import mesh_contacts

    th = run.meta["theory"]
    w_in = th["input_speed_rad_per_s"]
    w_out = abs(th["output_speed_rad_per_s"])
    w_planet = w_in * 44 / 45
    loss = 0.0
    for c in mesh_contacts(model1.gearbox)[::2]:  # one helix half per mesh: both halves share lever and speed
        kind, planet = c.name.split("_")[0], c.name.split("_")[2]
        force = steady[f"{kind}_mesh_force_{planet}_n"].mean()
        slip = w_in + w_planet if kind == "outer" else w_planet - w_out
        loss += 0.02 * force * c.lever.mean * slip
    assert 0.002 < loss / (557.025 * w_out) < 0.006  # a few tenths of a percent: plausible mesh losses
    assert steady.input_torque_nm.mean() == pytest.approx((557.025 * w_out + loss) / w_in, rel=2e-4)


def test_mesh_stiffness_variation_excites_mesh_frequency(run, steady):
    x = steady.outer_mesh_force_1_n.to_numpy()
    freqs = np.fft.rfftfreq(len(x), 1e-5)
    amp = np.abs(np.fft.rfft(x - x.mean()))
    harmonics = [freqs[np.argmax(np.where(np.abs(freqs - k * 4400) < 200, amp, 0))] for k in (1, 2)]
    assert harmonics[0] == pytest.approx(4400, abs=25)
    assert harmonics[1] == pytest.approx(8800, abs=25)
    a = steady.input_bearing_accel_x_m_per_s2.to_numpy()
    assert freqs[np.argmax(np.abs(np.fft.rfft(a - a.mean())))] == pytest.approx(4400, abs=25)


def test_constant_stiffness_switch_removes_ripple(model1, steady):
    # friction also varies with the mesh position (contact lines cross the pitch point): switch both off
    short = _shortened(model1, stiffness_variation="constant")
    g = short.gearbox
    short = dataclasses.replace(short, gearbox=g.with_changes(
        load_case=dataclasses.replace(g.load_case, end_time_s=0.1),
        contact=dataclasses.replace(g.contact, friction_coefficient=0.0)))
    s = run_variant(short).signals
    late = s[s.time_s >= 0.09].outer_mesh_force_1_n
    assert late.std() < 0.02 * steady.outer_mesh_force_1_n.std()
