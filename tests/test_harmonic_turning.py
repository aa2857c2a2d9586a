"""The harmonic response over a turning asymmetric body (flexgear.harmonic.turning) against time integration.

(1) A mass on two springs in parallel, one of them turning with a B-fold pattern, k_1(theta) = k_a (1 + e_1 cos
    B theta + e_2 cos 2 B theta), theta = 2 pi f_rot t, under a static load P and a two-harmonic force at f and 2 f
    (f the stand-in for the mesh frequency), integrated in time: the spring force f_1 = k_1 x and the acceleration
    hold lines at h f + p B f_rot. With B f_rot far below the natural frequency and far from h f's distance to it,
    the frozen system's response X_h(theta) = F_h / (k_1(theta) + k_b - m w_h^2 + i c w_h) at J angles gives
    (eq. 1 of the module) the root-sum-square of those lines, each sideband |X_{h,p}|, and (eq. 2) the time
    signal's peak over its mean, which holds the load sharing F_s(theta) = k_1 P / (k_1 + k_b). The tolerances
    are the quasi-static approximation's: the FRF's change over B f_rot at h f (2.7 % at 2 f, each sideband
    answering at its own frequency; second order, below 1e-3, in the root-sum-square), and the peak's sampling by
    the mesh cycles (pi B f_rot / f in phase: below 5e-3 of K_v - 1).
(2) Without a turning asymmetric flexible body (model 1, rigid) the response over the angle is
    flexgear.harmonic.harmonic_response's, exactly; a flexible ring or output shaft carries the bolt pattern.
"""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from flexgear.harmonic.base import waveform_peak
from flexgear.harmonic.turning import angle_rms, quasi_static_peak, sideband_amplitudes, turning_pattern
from flexgear.study.harmonic_check import line_amplitude, sideband_rss

M_KG, F_N_HZ, ZETA = 1.0, 200.0, 0.05  # mass, undamped natural frequency, damping ratio
SHARE = 0.5  # the turning spring's share of the mean stiffness
E1, E2 = 0.3, 0.1  # the pattern's first and second order in the turning spring
B, F_ROT_HZ = 4, 0.5  # pattern folds and rotation: B f_rot = 2 Hz
F_HZ = 50.0  # the excitation's fundamental
P_N, F1_N, F2_N = 1000.0, 40.0, 15.0  # static load, amplitudes at f and 2 f
SETTLE_S, WINDOW_S = 0.3, 2.0  # 0.3 s is 19 decay times 1 / (zeta w_n); the window: four pattern periods


def _stiffness(theta: np.ndarray) -> tuple[np.ndarray, float]:
    k = M_KG * (2.0 * math.pi * F_N_HZ) ** 2
    k_a, k_b = SHARE * k, (1.0 - SHARE) * k
    return k_a * (1.0 + E1 * np.cos(B * theta) + E2 * np.cos(2 * B * theta)), k_b


def _frozen(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Static spring force (J,), dynamic spring force and acceleration amplitudes (J, 2) at the angles."""
    k1, kb = _stiffness(theta)
    c = 2.0 * ZETA * M_KG * 2.0 * math.pi * F_N_HZ
    w = 2.0 * math.pi * F_HZ * np.array([1.0, 2.0])
    x = np.array([F1_N, F2_N])[None] / (k1[:, None] + kb - M_KG * w**2 + 1j * c * w)
    return k1 * P_N / (k1 + kb), k1[:, None] * x, -(w**2) * x


@pytest.fixture(scope="module")
def integrated() -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """(spring force f_1, acceleration, time) over the window, sampled at dt; and dt [s]."""
    c = 2.0 * ZETA * M_KG * 2.0 * math.pi * F_N_HZ

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        k1, kb = _stiffness(np.array(2.0 * math.pi * F_ROT_HZ * t))
        force = P_N + F1_N * math.cos(2.0 * math.pi * F_HZ * t) + F2_N * math.cos(4.0 * math.pi * F_HZ * t)
        return np.array([y[1], (force - c * y[1] - (k1 + kb) * y[0]) / M_KG])

    dt = 2.5e-4
    t = SETTLE_S + np.arange(int(round(WINDOW_S / dt))) * dt
    k1, kb = _stiffness(np.zeros(1))
    sol = solve_ivp(rhs, (0.0, t[-1]), [P_N / float(k1[0] + kb), 0.0], method="DOP853", t_eval=t, rtol=1e-10,
                    atol=1e-14)
    assert sol.success, sol.message
    x = sol.y[0]
    k1, kb = _stiffness(2.0 * math.pi * F_ROT_HZ * t)
    accel = np.array([rhs(ti, yi)[1] for ti, yi in zip(t, sol.y.T, strict=True)])
    return k1 * x, accel, t, dt


def test_angle_rms_and_sidebands_match_the_time_lines(integrated):
    force, accel, _, dt = integrated
    spacing = B * F_ROT_HZ
    count = 9  # J = 2 P + 1, P = 4: the pattern's orders 1 and 2 and their products in 1 / k_1 above order 4 are
    theta = 2.0 * math.pi * F_ROT_HZ * np.arange(count) / (count * spacing)  # ~1e-4 of the amplitude
    _, dyn, acc = _frozen(theta)
    for signal, freq in ((force, dyn), (accel, acc)):
        rms = angle_rms(freq)
        for h in (1, 2):
            timed = sideband_rss(signal, dt, h * F_HZ, spacing, (count - 1) // 2)
            assert rms[h - 1] == pytest.approx(timed, rel=2e-3)
            sidebands = sideband_amplitudes(freq[:, h - 1])
            assert sidebands.index.tolist() == list(range(-4, 5))
            assert math.sqrt((sidebands**2).sum()) == pytest.approx(rms[h - 1], rel=1e-12)  # Parseval
            lines = np.array([line_amplitude(signal, dt, h * F_HZ + p * spacing) for p in sidebands.index])
            # each line answers at its own frequency: |H(h f + p B f_rot) / H(h f) - 1| ~ 2 p B f_rot h f /
            # (f_n^2 - (h f)^2), 2.7 % at h = 2, p = 1, of the dynamic part that makes the sideband
            np.testing.assert_allclose(sidebands.to_numpy(), lines, rtol=0.0, atol=0.02 * rms[h - 1])
            assert min(sidebands.loc[-1], sidebands.loc[1]) > 0.03 * sidebands.loc[0]  # the case has sidebands


def test_quasi_static_peak_matches_the_time_peak_factor(integrated):
    force, _, t, _ = integrated
    count = 64  # dense in the angle: eq. 2's maximum over theta
    theta = 2.0 * math.pi * np.arange(count) / (count * B)
    static, dyn, _ = _frozen(theta)
    kv = quasi_static_peak(static[:, None], dyn[:, None, :])
    kv_t = force.max() / force.mean()
    assert kv - 1.0 == pytest.approx(kv_t - 1.0, rel=5e-3)
    # the static load sharing is a visible part of it: the frozen peak at the mean stiffness alone is lower
    assert kv - 1.0 > 1.1 * (waveform_peak(dyn.mean(axis=0), static.mean()) / static.mean() - 1.0)
    # one angle: flexgear.harmonic.base's peak factor
    assert quasi_static_peak(static[:1, None], dyn[:1, None, :]) == pytest.approx(
        waveform_peak(dyn[0], static[0]) / static[0], rel=1e-15)


@pytest.fixture(scope="module")
def iso_spec(gearbox):
    """The ISO 6336 law with the contact-line stiffness variation and no friction (the linearisation's scope)."""
    spec = gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    return spec.with_fields("contact_assumed", stiffness_variation="contact_lines")


def test_without_a_turning_asymmetric_body_the_response_is_harmonic_response(model1, iso_spec):
    from flexgear.harmonic import harmonic_response, turning_response

    variant = dataclasses.replace(model1, gearbox=iso_spec)
    assert turning_pattern(variant) is None
    turning = turning_response(variant, [2000.0], harmonics=3, angles=7)
    plain = harmonic_response(variant, [2000.0], harmonics=3)
    assert turning.count == 1 and turning.sideband_order == 0
    for column in ("outer_mesh_force_1_n", "input_bearing_accel_x_m_per_s2"):
        np.testing.assert_allclose(turning.amplitudes(column).to_numpy(), plain.amplitudes(column).to_numpy(),
                                   rtol=1e-15)  # sqrt(|X|^2) of one angle
        np.testing.assert_allclose(np.abs(turning.complex_mean(column).to_numpy()),
                                   plain.amplitudes(column).to_numpy(), rtol=1e-15)
    assert turning.dynamic_factor().iloc[0] == pytest.approx(plain.dynamic_factor().iloc[0], rel=1e-14)
    ring = dataclasses.replace(variant, components={**variant.components, "ring": "flexible"})
    pattern = turning_pattern(ring)
    assert pattern is not None and pattern.order == iso_spec.components_assumed.ring_bolt_count
    f_ring = iso_spec.gears.sun_teeth / iso_spec.gears.ring_teeth * 2000.0 / 60.0
    assert pattern.period_s(2000.0) == pytest.approx(1.0 / (pattern.order * f_ring), rel=1e-14)


def test_pattern_times_hold_the_mesh_phase_and_spread_the_pattern_phase(iso_spec, model1):
    from flexgear.harmonic.turning import pattern_times_s

    variant = dataclasses.replace(model1, gearbox=iso_spec, components={**model1.components, "ring": "flexible"})
    pattern = turning_pattern(variant)
    g = iso_spec.gears
    count = pattern.admissible(13)
    assert pattern.phases % count == 0 and count >= 13
    speed = 2000.0
    f_mesh = g.sun_teeth * speed / 60.0  # star: the carrier stands still
    t = pattern_times_s(pattern, speed, count, 0.5)
    cycles = (t - 0.5) * f_mesh
    np.testing.assert_allclose(cycles, np.round(cycles), atol=1e-9)  # whole mesh cycles: the same mesh phase
    phase = np.mod((t - 0.5) / pattern.period_s(speed), 1.0)
    np.testing.assert_allclose(phase, np.arange(count) / count, atol=1e-9)  # the pattern phases j / J
    with pytest.raises(ValueError):
        pattern_times_s(pattern, speed, count + 1, 0.5)
