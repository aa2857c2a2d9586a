"""Harmonic response to the transmission-error excitation (flexgear.harmonic) against the models' own physics.

(1) The lumped model's frequency-domain mesh-force and bearing-acceleration amplitudes at 1x and 2x mesh against its
    own time integration (flexgear.lumped.run, ISO 6336 law, contact-line stiffness variation, no friction), settled,
    at speeds whose 1x and 2x mesh frequencies lie away from the natural frequencies: the first-order excitation
    F_0 (s - 1) leaves out terms of order c_h^2 (c_1, c_2 ~ 0.05-0.1), so within 10 %.
(2) Resonance: the mesh-force response of a harmonic peaks where a natural frequency of the linearised model
    (flexgear.lumped.modal) equals h f_mesh, within the speed grid's step (lightly damped).
(3) Mesh phasing of equally spaced planets (Parker 2004, sequential phasing z_s psi_i / 2 pi): harmonic h excites the
    rotational modes only if h z_s / N is an integer, the translational ones only if (h z_s +- 1) / N is; with
    z_s = 44, N = 5 the transmission error (output spin) vanishes at h = 1..4 and the central members' bearing
    accelerations at h = 2, 3, 5.
(4) The multibody model 1 (rigid) against its own time integration (flexgear.mbs.run.run_variant), as (1); and
    against the lumped model at 2x mesh, which excites planet modes only (3): for them the lumped model is the
    multibody model's in-plane part (tests/test_modal.py). Its gears are bodies of revolution, so the gearbox is
    cyclically symmetric and the phasing of (3) holds in the time domain too, with the parametric and nonlinear
    terms the frequency domain leaves out: the central members' 2x mesh acceleration vanishes in both domains.
(5) The diagnostics of the checks (flexgear.study.harmonic_check): a line at exactly one frequency told from a
    sideband; K_v of a signal's mesh-periodic part, without a slow tone added to it.
(6) Tooth friction's excitation (flexgear.harmonic.friction) is the multibody model's own friction force (the
    compiled per-step kernel flexgear.laws.compiled.mesh_friction_forces) at a fixed deflection over one mesh
    cycle, Fourier-analysed: both are trigonometric polynomials of degree 2 H sampled more than 3 H times per cycle,
    so the coefficients h <= H agree to round-off, for either mesh and either drive sense.
"""

import dataclasses
import math

import numpy as np
import pytest

from flexgear.harmonic import harmonic_response, lumped_harmonic_response, mesh_frequency_hz
from flexgear.modal.cli import speeds_rpm as parse_speeds
from flexgear.study.harmonic_check import line_amplitude, periodic_peak_factor

RAMP_S, END_S = 0.05, 0.25  # short load case: the ramps, then 0.2 s (the slowest decay time is about 33 ms)
WINDOW_S = 0.1  # analysed: the last 0.1 s, a whole number of mesh cycles
COLUMNS = ("outer_mesh_force_1_n", "inner_mesh_force_1_n", "input_bearing_accel_x_m_per_s2")


@pytest.fixture(scope="module")
def iso_spec(gearbox):
    """The ISO 6336 law with the contact-line stiffness variation and no friction (the linearisation's scope)."""
    spec = gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    return spec.with_fields("contact_assumed", stiffness_variation="contact_lines")


def _time_amplitudes(spec, speed_rpm: float) -> dict[str, np.ndarray]:
    """1x, 2x amplitudes of the settled time signals of the lumped model at ``speed_rpm``."""
    from flexgear.lumped.run import run_lumped
    from flexgear.study.compare import harmonic_amplitudes

    spec = spec.with_fields("load_case", input_speed_rpm=speed_rpm, ramp_time_s=RAMP_S, end_time_s=END_S)
    signals = run_lumped(spec).signals
    dt = spec.load_case.step_size_s
    f_mesh = mesh_frequency_hz(spec, speed_rpm)
    n = int(math.floor(WINDOW_S * f_mesh) / f_mesh / dt)  # whole mesh cycles
    return {c: harmonic_amplitudes(signals[c].to_numpy()[-n:], dt, f_mesh, (1, 2)) for c in COLUMNS}


@pytest.mark.parametrize("speed_rpm", [1500.0, 3500.0, 4000.0])
def test_lumped_frequency_domain_matches_time_integration(iso_spec, speed_rpm):
    from flexgear.lumped.modal import modal_analysis

    f_mesh = mesh_frequency_hz(iso_spec, speed_rpm)
    modes = modal_analysis(iso_spec, hold_input=True).frequencies_hz
    for h in (1, 2):  # the speed is away from resonance: no natural frequency within 2 % of h f_mesh
        assert np.min(np.abs(modes / (h * f_mesh) - 1.0)) > 0.02
    response = lumped_harmonic_response(iso_spec, [speed_rpm], harmonics=iso_spec.contact_assumed.stiffness_harmonics)
    timed = _time_amplitudes(iso_spec, speed_rpm)
    for column, amp in timed.items():
        freq = response.amplitudes(column).iloc[0].to_numpy()[:2]
        if column.startswith("input_bearing"):  # 2x excites no central-member translation (test 3)
            freq, amp = freq[:1], amp[:1]
        np.testing.assert_allclose(freq, amp, rtol=0.10, err_msg=f"{column} at {speed_rpm} rpm")


def _lightly_damped(spec, factor: float = 0.1):
    """``spec`` with the mesh damping ratio and the bearings' damping per stiffness scaled by ``factor``."""
    spec = spec.with_fields("contact_assumed", mesh_damping_ratio=factor * spec.contact_assumed.mesh_damping_ratio)
    b = spec.bearings
    return spec.with_fields("bearings", **{
        f.name: dataclasses.replace(getattr(b, f.name), damping_per_stiffness_s=factor * getattr(
            b, f.name).damping_per_stiffness_s) for f in dataclasses.fields(b)})


def test_lumped_response_peaks_at_natural_frequencies(iso_spec):
    """Lightly damped (damping ratios about 1 %), the largest resonance peak of each harmonic lies at a natural
    frequency up to the peak's shift of order zeta^2: within one step of a 10 rpm grid (0.07 Hz per rpm at 1x)."""
    from flexgear.lumped.modal import modal_analysis

    spec = _lightly_damped(iso_spec)
    modes = modal_analysis(spec, hold_input=True).frequencies_hz
    step = 10.0
    speeds = np.arange(500.0, 7000.0 + step, step)
    response = lumped_harmonic_response(spec, speeds, harmonics=4)
    per_rpm = response.mesh_frequency_hz_per_rpm
    for h in (1, 2, 3, 4):
        amp = response.amplitudes("outer_mesh_force_1_n")[h].to_numpy()
        inner = np.flatnonzero((amp[1:-1] > amp[:-2]) & (amp[1:-1] > amp[2:])) + 1
        assert inner.size, f"{h}x: no resonance peak in {speeds[0]:g}-{speeds[-1]:g} rpm"
        peak = inner[np.argmax(amp[inner])]  # the largest local maximum
        resonant_rpm = modes / (h * per_rpm)  # speed at which h f_mesh = f_n
        assert np.min(np.abs(resonant_rpm - speeds[peak])) <= step, (h, speeds[peak])


def test_planet_phasing_selects_the_excited_modes(iso_spec):
    response = lumped_harmonic_response(iso_spec, [1500.0, 4000.0], harmonics=5)
    force = response.amplitudes("outer_mesh_force_1_n").to_numpy()
    te = response.amplitudes("transmission_error_m").to_numpy()
    accel = np.maximum(response.amplitudes("input_bearing_accel_x_m_per_s2").to_numpy(),
                       response.amplitudes("output_bearing_accel_y_m_per_s2").to_numpy())
    assert np.all(force > 0.0)
    te_scale = te.max()
    accel_scale = accel.max()
    assert np.all(te[:, :4] < 1e-9 * te_scale) and np.all(te[:, 4] > 1e-3 * te_scale)  # h = 1..4 off, 5 on
    assert np.all(accel[:, [1, 2, 4]] < 1e-9 * accel_scale)  # h = 2, 3, 5 off
    assert np.all(accel[:, [0, 3]] > 1e-3 * accel_scale)  # h = 1, 4 on


def test_dynamic_factor_and_table(iso_spec):
    response = lumped_harmonic_response(iso_spec, [2000.0, 4000.0], harmonics=3)
    assert list(response.table.columns) == ["speed_rpm", "harmonic", "frequency_hz", "indicator", "amplitude", "phase"]
    kv = response.dynamic_factor()
    for speed, value in kv.items():  # K_v: the peak of F_0 + Re sum_h F_h e^{i h phi}, a mesh cycle on a fine grid
        phi = np.linspace(0.0, 2.0 * np.pi, 20000, endpoint=False)
        peaks = []
        for m, f0 in response.static_forces_n.items():
            c = response.complex(m).loc[speed].to_numpy()
            wave = f0 + sum((c[h - 1] * np.exp(1j * h * phi)).real for h in range(1, c.size + 1))
            peaks.append(wave.max() / f0)
            assert wave.max() / f0 <= 1.0 + np.abs(c).sum() / f0  # below the bound of all harmonics in phase
        assert value == pytest.approx(max(peaks), rel=1e-5)
    from flexgear.theory import theory

    th = theory(iso_spec)  # the static mesh force balances the input torque: F_0 = T_in / (N r_bs cos beta_b)
    assert np.mean(list(response.static_forces_n.values())) == pytest.approx(th.mesh_force, rel=1e-6)


def test_model1_matches_lumped_model_at_2x(model1, iso_spec):
    variant = dataclasses.replace(model1, gearbox=iso_spec)
    speeds = [1500.0, 4000.0]
    mbs = harmonic_response(variant, speeds, harmonics=2)
    lumped = lumped_harmonic_response(iso_spec, speeds, harmonics=2)
    for column in ("outer_mesh_force_1_n", "inner_mesh_force_3_n"):
        np.testing.assert_allclose(mbs.amplitudes(column)[2], lumped.amplitudes(column)[2], rtol=0.02)
    assert mbs.static_forces_n["outer_mesh_force_1_n"] == pytest.approx(
        lumped.static_forces_n["outer_mesh_force_1_n"], rel=1e-4)


def test_parse_speeds():
    assert parse_speeds("500:7000:200")[:2] == [500.0, 700.0]
    assert parse_speeds("500:7000:200")[-1] == 6900.0
    assert parse_speeds("1000:2000:500") == [1000.0, 1500.0, 2000.0]
    assert parse_speeds("1000,3000") == [1000.0, 3000.0]


@pytest.mark.parametrize("speed_rpm", [1500.0, 4000.0])
def test_model1_frequency_domain_matches_time_integration(model1, iso_spec, speed_rpm):
    from flexgear.mbs.run import run_variant
    from flexgear.study.compare import harmonic_amplitudes

    spec = iso_spec.with_fields("load_case", input_speed_rpm=speed_rpm, ramp_time_s=0.03, end_time_s=0.15)
    variant = dataclasses.replace(model1, gearbox=spec)
    response = harmonic_response(variant, [speed_rpm], harmonics=spec.contact_assumed.stiffness_harmonics)
    result = run_variant(variant)
    assert result.ok, result.meta.get("reason")
    t = result.signals["time_s"].to_numpy()
    dt = float(t[-1] - t[-2])  # the recorded step (a run may start with shorter ones)
    f_mesh = mesh_frequency_hz(spec, speed_rpm)
    n = int(math.floor(0.05 * f_mesh) / f_mesh / dt)  # the last 0.05 s, whole mesh cycles
    for column in COLUMNS:
        timed = harmonic_amplitudes(result.signals[column].to_numpy()[-n:], dt, f_mesh, (1, 2))
        freq = response.amplitudes(column).iloc[0].to_numpy()[:2]
        if column.startswith("input_bearing"):
            freq, timed = freq[:1], timed[:1]
        np.testing.assert_allclose(freq, timed, rtol=0.10, err_msg=f"{column} at {speed_rpm} rpm")
    for column in ("input_bearing_accel_x_m_per_s2", "output_bearing_accel_y_m_per_s2"):  # (4): 2x cancelled
        x = result.signals[column].to_numpy()[-n:]
        first, second = line_amplitude(x, dt, f_mesh), line_amplitude(x, dt, 2.0 * f_mesh)
        freq = response.amplitudes(column).iloc[0].to_numpy()
        assert freq[1] < 1e-6 * freq[0], column
        assert second < 1e-3 * first, (column, second / first)  # zero, but for what the ramps leave 0.12 s on


def test_line_amplitude_tells_a_mesh_harmonic_from_a_sideband():
    dt, f_mesh, f_side = 1e-5, 1595.0, 12 * 11.73  # a sideband 2 f_mesh + 12 f_ring, no line at 2 f_mesh
    t = np.arange(int(round(0.2 * f_mesh)) * int(round(1.0 / (f_mesh * dt)))) * dt
    x = 0.7 * np.sin(2 * np.pi * f_mesh * t) + 0.035 * np.cos(2 * np.pi * (2 * f_mesh + f_side) * t + 0.3)
    assert line_amplitude(x, dt, f_mesh) == pytest.approx(0.7, rel=1e-3)
    assert line_amplitude(x, dt, 2 * f_mesh + f_side) == pytest.approx(0.035, rel=1e-3)
    assert line_amplitude(x, dt, 2 * f_mesh) < 1e-4 * 0.035  # 28 resolution widths away: Hann leakage only


def test_periodic_peak_factor_leaves_out_a_slow_tone():
    dt, f_mesh, mean = 1e-5, 1196.2, 800.0
    t = np.arange(int(round(60 / (f_mesh * dt)))) * dt  # 60 mesh cycles, to the nearest step
    wave = 0.76 * np.cos(2 * np.pi * f_mesh * t + 0.4) + 4.0 * np.cos(4 * np.pi * f_mesh * t - 1.1)
    slow = 0.46 * np.cos(2 * np.pi * 106.9 * t)
    phi = np.linspace(0.0, 2 * np.pi, 200001)  # the periodic part's peak on a fine grid of one mesh cycle
    peak = (mean + 0.76 * np.cos(phi + 0.4) + 4.0 * np.cos(2 * phi - 1.1)).max() / mean
    forces = np.stack([mean + wave, mean + wave + slow], axis=1)
    kv = periodic_peak_factor(forces, dt, f_mesh, harmonics=3)
    assert kv - 1.0 == pytest.approx(peak - 1.0, rel=2e-3)
    assert forces[:, 1].max() / forces[:, 1].mean() - 1.0 > kv - 1.0 + 0.5 * 0.46 / mean  # the raw peak has the tone


FRICTION_CYCLE_SAMPLES = 64
"""Samples of the time-domain friction force over one mesh cycle in (6): > 3 H for the model's H = 3 (exact DFT)."""


@pytest.mark.parametrize("drive_sign", [1.0, -1.0])
def test_friction_excitation_is_the_time_models_friction_over_a_mesh_cycle(gearbox, drive_sign):
    from flexgear.harmonic.base import excited_spec
    from flexgear.harmonic.friction import friction_harmonics
    from flexgear.laws.compiled import mesh_friction_forces
    from flexgear.mbs.gearbox import mesh_contacts

    harmonics = gearbox.contact_assumed.stiffness_harmonics
    spec = excited_spec(gearbox, harmonics)
    speed = drive_sign * spec.load_case.input_speed_rad_s
    contacts = mesh_contacts(spec, drive_sign)
    delta0 = 1e-5  # a fixed deflection [m]: any loaded one
    k = np.arange(FRICTION_CYCLE_SAMPLES)
    chosen = [next(c for c in contacts if c.name.startswith(kind) and c.phase_offset % 1.0 != 0.0)
              for kind in ("outer", "inner")]  # off the reference phase: the planet's own phase shift enters
    for c in chosen:
        law = c.law
        rows = [np.concatenate([c.gradient1[r], c.gradient2[r]])[None] for r in (1, 2)]  # sliding, spin
        q_t = np.zeros(12)
        q_t[5], q_t[11] = (s * speed for s in c.spin_per_drive_angle)
        series = np.ascontiguousarray([[x.packed()] for x in (c.stiffness, c.sliding, c.lever)])
        theta = np.sign(speed) * k / (FRICTION_CYCLE_SAMPLES * c.phase_per_drive_angle)  # mesh phase k / N
        forces = np.array([mesh_friction_forces(
            np.array([c.phase_per_drive_angle * th - c.phase_offset]), np.array([delta0]), np.zeros(1), q_t,
            np.array([law.stiffness]), np.array([law.exponent]), np.array([law.damping_max]),
            np.array([law.penetration_depth]), series, np.array([c.friction_coefficient]),
            np.array([c.friction_regularisation]), *rows, law.kind == "iso6336") for th in theta])
        h = np.arange(1, harmonics + 1)
        timed = 2.0 / k.size * np.exp(-2j * np.pi * np.outer(h, k) / k.size) @ forces  # (H, 12) at +h f_mesh
        s_h, l_h = friction_harmonics([c], np.array([delta0]), speed, harmonics)[:, 0]
        series_force = -(np.outer(s_h, rows[0][0]) + np.outer(l_h, rows[1][0]))
        scale = np.abs(forces).max()
        assert scale > 0.0 and np.abs(timed[0]).max() > 1e-3 * scale  # a first harmonic to compare
        # round-off: sums of N = 64 terms of size <= scale, N eps ~ 1.4e-14 of it; 1e-12 leaves a margin
        np.testing.assert_allclose(series_force, timed, rtol=0.0, atol=1e-12 * scale)
