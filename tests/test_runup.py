"""Run-up order map (flexgear.study.runup): ridges of a synthetic run-up lie at the crossings it was built with
(slow ramp), or at their swept predictions under the run's own mesh load (the study's fast ramp)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest
from scipy.signal import lsim

from flexgear.laws.ramps import step
from flexgear.study.hold import single_mode_acceleration
from flexgear.study.runup import (
    match_crossings,
    mesh_excitation,
    mesh_phase,
    order_tracks,
    ridges,
    spectrogram,
    swept_crossings,
    swept_peak,
)

DT = 1e-5            # s, the runs' recording step
RAMP = 4.0           # s: a slow run-up, so that the sweep delay stays below 1 % of the crossing speed
NOMINAL = 6000.0     # rpm
PER_RPM = 44.0 / 60.0  # Hz/rpm: 44 sun teeth, star arrangement
MODES = ((900.0, 0.05, 1), (2500.0, 0.05, 2))  # (f_n [Hz], zeta, the order that crosses it)


def _mode_response(t: np.ndarray, n: np.ndarray, f_n: float, zeta: float, order: int) -> np.ndarray:
    """Acceleration of a single mode driven by order ``order`` of the mesh, force amplitude n / NOMINAL."""
    phase = np.concatenate([[0.0], np.cumsum(0.5 * PER_RPM * (n[1:] + n[:-1]) * DT)])
    w = 2 * math.pi * f_n
    sys = ([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [1.0]], [[-w * w, -2 * zeta * w]], [[1.0]])
    return lsim(sys, n / NOMINAL * np.cos(2 * math.pi * order * phase), t)[1]


@pytest.fixture(scope="module")
def runup_signal():
    t = np.arange(0.0, RAMP, DT)
    n = step(t, 0.0, 0.0, RAMP, NOMINAL)
    y = sum(_mode_response(t, n, f, z, k) for f, z, k in MODES)
    return t, n, y


def test_ridges_at_the_crossings(runup_signal):
    t, n, y = runup_signal
    tracks = order_tracks(t, y, n, PER_RPM, ramp_end_s=RAMP)
    mp = spectrogram(t, y, n, PER_RPM)
    found = ridges(tracks, (mp.time_s, mp.floor))
    crossings = pd.DataFrame({"speed_rpm": [f / (k * PER_RPM) for f, _, k in MODES], "order": [k for *_, k in MODES],
                              "mode": [1, 2], "kind": ["test", "test"], "frequency_hz": [f for f, *_ in MODES]})
    top = match_crossings(found.head(2), crossings)
    assert sorted(top["order"]) == [1, 2]
    # a damped mode's ridge lies above its crossing: r ~ 1 + 2 zeta^2 (0.5 %) plus the sweep delay (< 1 % here)
    assert (top["error_pct"] > 0.0).all(), top
    assert (top["error_pct"] < 3.0).all(), top
    # orders that carry nothing make no ridges (their maxima are noise or leakage)
    assert set(found["order"]) <= {1, 2}, found


def test_swept_peak_follows_the_signal(runup_signal):
    """The single-mode prediction of a ridge is the ridge of that mode's own response."""
    t, n, _ = runup_signal
    f, z, k = MODES[0]
    y = _mode_response(t, n, f, z, k)
    found = ridges(order_tracks(t, y, n, PER_RPM, orders=(k,), ramp_end_s=RAMP))
    predicted = swept_peak(t, n, PER_RPM, k, f, z, NOMINAL)
    assert found["speed_rpm"].iloc[0] == pytest.approx(predicted, rel=2e-3)
    assert predicted > f / (k * PER_RPM)


def test_single_mode_acceleration_is_the_state_space_solution_and_its_steady_amplitude():
    """The exact first-order-hold filter against scipy's state-space integration (lsim, the same hold) on a chirp,
    and at constant frequency against the steady amplitude Omega^2 / |omega^2 - Omega^2 + 2 i zeta omega Omega|
    (the hold's sinc^2(f dt) factor is 3e-4 at 1 kHz)."""
    t = np.arange(0.0, 0.2, DT)
    f_n, zeta = 1500.0, 0.03
    w = 2 * math.pi * f_n
    chirp = np.cos(2 * math.pi * (500.0 * t + 5000.0 * t**2))
    ref = lsim(([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [1.0]], [[-w * w, -2 * zeta * w]], [[1.0]]), chirp, t)[1]
    got = single_mode_acceleration(t, chirp, f_n, zeta)
    assert np.abs(got - ref).max() < 1e-10 * np.abs(ref).max()
    big = 2 * math.pi * 1000.0
    steady = single_mode_acceleration(t, np.cos(big * t), f_n, zeta)[t > 0.15]  # transient decayed: e^-42
    expected = big**2 / abs(w * w - big**2 + 2j * zeta * w * big)
    assert abs(np.abs(steady).max() / expected - 1.0) < 1e-3


def test_spectrogram_amplitude_of_a_tone():
    """A steady tone of amplitude A shows as A in the Hann-windowed amplitude spectrum (on a bin)."""
    t = np.arange(0.0, 0.1, DT)
    f0 = 4000.0  # Hz: a whole number of cycles per 10 ms window (on a bin)
    mp = spectrogram(t, 0.3 * np.cos(2 * math.pi * f0 * t), np.full(t.size, 1000.0), PER_RPM)
    j = int(np.argmin(np.abs(mp.frequency_hz - f0)))
    assert np.allclose(mp.amplitude[j], 0.3, rtol=1e-6)


STUDY_RAMP = 0.5  # s: the study's STEP ramp to NOMINAL
INERTIA = 0.3     # inertia torque of the driven members at the ramp's fastest acceleration, in units of the load [-]


def _fast_runup() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The study's ramp and a mesh load that carries the load torque s(t) plus an inertia torque ~ s'(t)."""
    t = np.arange(0.0, STUDY_RAMP, DT)
    n = step(t, 0.0, 0.0, STUDY_RAMP, NOMINAL)
    load = n / NOMINAL + INERTIA * np.gradient(n / NOMINAL, t) * STUDY_RAMP / 1.5  # s' peaks at 1.5 / T
    return t, n, load / load.max()


def _driven(t: np.ndarray, n: np.ndarray, amplitude: np.ndarray, f_n: float, zeta: float, order: int) -> np.ndarray:
    """Acceleration of a single mode under order ``order`` of the mesh with the force amplitude ``amplitude``."""
    phase = np.concatenate([[0.0], np.cumsum(0.5 * PER_RPM * (n[1:] + n[:-1]) * DT)])
    w = 2 * math.pi * f_n
    sys = ([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [1.0]], [[-w * w, -2 * zeta * w]], [[1.0]])
    return lsim(sys, amplitude * np.cos(2 * math.pi * order * phase), t)[1]


def test_fast_sweep_ridges_lie_at_their_swept_predictions():
    """On the study's 0.5 s ramp a damped mode's ridge lies above its crossing by more than the steady peak shift
    (~2 zeta^2) plus the sweep delay (the speed gained over the build-up time 1 / (zeta omega_n)). The swept
    prediction under the run's own mesh load places each ridge of a signal that holds two modes on two orders
    within the tracks' speed resolution (one hop)."""
    t, n, load = _fast_runup()
    modes = ((955.0, 0.073, 1), (2500.0, 0.05, 2))
    y = sum(_driven(t, n, load, f, z, k) for f, z, k in modes)
    found = ridges(order_tracks(t, y, n, PER_RPM, orders=(1, 2), ramp_end_s=STUDY_RAMP))
    for f, z, k in modes:
        ridge = found[found["order"] == k]["speed_rpm"].iloc[0]
        crossing = f / (k * PER_RPM)
        i = int(np.searchsorted(n, crossing))
        rate = (n[i + 1] - n[i - 1]) / (2 * DT)  # rpm/s
        sweep_delay = rate / (z * 2 * math.pi * f)  # rpm: n' / (zeta omega_n)
        assert ridge / crossing - 1.0 > 2 * z * z + sweep_delay / crossing  # both shifts add up
        swept = swept_peak(t, n, PER_RPM, k, f, z, excitation=load)
        assert abs(ridge - swept) <= rate * 5e-4  # one hop of the tracks


def test_mesh_excitation_is_the_normalised_mesh_load():
    t, n, load = _fast_runup()
    signals = pd.DataFrame({"time_s": t, "outer_mesh_force_1_n": 300.0 * load, "inner_mesh_force_1_n": 500.0 * load,
                            "input_speed_rad_per_s": np.pi / 30.0 * n})
    e = mesh_excitation(signals, window_s=1e-4)
    assert np.allclose(e[100:-100], load[100:-100], atol=1e-6)
    assert mesh_excitation(signals.drop(columns=["outer_mesh_force_1_n", "inner_mesh_force_1_n"])) is None


def test_ridges_match_excited_crossings_by_their_swept_prediction():
    """A ridge is matched with the crossing whose swept prediction lies nearest, among those its order excites."""
    t, n, load = _fast_runup()
    crossings = pd.DataFrame({"speed_rpm": [1302.3, 1330.0, 1400.0], "order": [1, 1, 1], "mode": [1, 2, 3],
                              "kind": ["translational", "planet", "translational"],
                              "frequency_hz": [955.0, 975.3, 1026.7], "damping_ratio": [0.073, 0.05, 0.073],
                              "excited": [True, False, True]})
    swept = swept_crossings(crossings, t, n, PER_RPM, (1000.0, 2000.0), (1,), load)
    assert list(swept["mode"]) == [1, 3]
    assert (swept["swept_rpm"] > swept["speed_rpm"]).all()
    ridge = pd.DataFrame({"speed_rpm": [float(swept["swept_rpm"].iloc[0])], "order": [1]})
    matched = match_crossings(ridge, swept, on="swept_rpm")
    assert matched["mode"].iloc[0] == 1 and matched["swept_error_pct"].iloc[0] == pytest.approx(0.0)


def test_linear_runup_of_one_mode_is_the_swept_prediction():
    """The linear run-up of a one-mode system (unit mass, forced by s(t) Re(e^{i 2 pi phi})) is swept_peak's own
    signal: both integrate the same ODE exactly for the piecewise-linear forcing, so they coincide to round-off;
    split into segments of the same system, with the state carried across, it is unchanged."""
    from flexgear.harmonic.base import Operating
    from flexgear.study.runup_linear import linear_response, match_linear

    t, n, load = _fast_runup()
    f, z = 955.0, 0.073
    w = 2 * math.pi * f
    # one mode, its acceleration the output; no contact (the force is given): an operating point without meshes
    one = Operating(np.eye(1), np.array([[2 * z * w]]), np.array([[w * w]]), np.zeros((0, 1)), np.zeros(0),
                    np.zeros(0), np.zeros(0), np.zeros((0, 1), complex), np.zeros(0, int), (), np.eye(1), np.zeros(1),
                    2 * math.pi * f)
    unit = np.ones((1, 1), complex)
    phase = mesh_phase(t, n, PER_RPM)
    y = linear_response(t, phase, load, [one], unit)[0]
    reference = _driven(t, n, load, f, z, 1)
    assert np.abs(y - reference).max() <= 1e-9 * np.abs(reference).max()
    split = linear_response(t, phase, load, [one] * 3, unit, [0, t.size // 3, 2 * t.size // 3])[0]
    assert np.abs(split - y).max() <= 1e-9 * np.abs(y).max()
    found = ridges(order_tracks(t, y, n, PER_RPM, orders=(1,), ramp_end_s=STUDY_RAMP))
    assert found["speed_rpm"].iloc[0] == pytest.approx(swept_peak(t, n, PER_RPM, 1, f, z, excitation=load), rel=1e-12)
    assert match_linear(found, found)["linear_error_pct"].iloc[0] == 0.0


def test_linear_runup_at_constant_speed_is_the_harmonic_solve():
    """At a constant speed the linear run-up of a gyroscopic, non-proportionally damped system with two contacts settles
    to the harmonic-response stage's own steady solution (flexgear.harmonic.base._solve) at each mesh harmonic,
    first order in the stiffness variation as the run-up is (the parametric force left out: k_t = 0 in it, which
    here enters nothing else the bearing accelerations read): its order track equals the bearing acceleration's
    |Y_h| to within the first-order hold's attenuation of the forcing the modes see, (2 pi h f_m dt)^2 / 12 of
    the modes' part Y_h - a^T M^-1 f_h of the output (the direct part a^T M^-1 u is exact at the samples), plus
    the track window's side lobes (-92 dB) of the other harmonics."""
    from flexgear.harmonic.base import ACCEL_INDICATORS, Operating, _solve, excitation
    from flexgear.study.runup import SIDE_LOBE_DB
    from flexgear.study.runup_linear import linear_response

    mass = np.diag([1.0, 2.0, 1.5])
    k = np.array([[6.0, -2.0, 0.0], [-2.0, 9.0, -3.0], [0.0, -3.0, 7.0]]) * 4e7  # modes of 700-1700 Hz
    damping = 3e-5 * k + 40.0 * np.diag([1.0, 0.0, 2.0])  # not proportional
    gyro = 300.0 * np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.5], [0.0, -0.5, 0.0]])
    rows = np.array([[1.0, -0.5, 0.0], [0.0, 0.3, -1.0]])
    coef = np.array([[0.05 - 0.02j, 0.01 + 0.004j], [0.03 + 0.04j, -0.006 + 0.002j]])  # C_h, h = 1, 2
    accel = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.0, 0.5]])
    f_m, harmonics = 1000.0, 2
    op = Operating(mass, damping + gyro, k, rows, np.full(2, 1e8), np.zeros(2), np.array([900.0, 1100.0]), coef,
                   np.arange(2), ("outer_mesh_force_1_n", "inner_mesh_force_1_n"), accel, np.zeros(3),
                   2 * math.pi * f_m)
    steady = _solve(dataclasses.replace(op, k_t=np.zeros(2)), harmonics)
    forces = excitation(op, harmonics)[1]
    t = np.arange(0.0, 0.2, DT)  # > 30 time constants 1 / (zeta omega) of the slowest decaying mode
    n = np.full(t.size, f_m / PER_RPM)
    y = linear_response(t, mesh_phase(t, n, PER_RPM), np.ones(t.size), [op], forces)
    direct = accel @ np.linalg.solve(mass, forces.T)  # (4, H): a^T M^-1 f_h
    for i, name in enumerate(ACCEL_INDICATORS):
        amp = np.abs(steady[name])
        tracks = order_tracks(t, y[i], n, PER_RPM, orders=(1, 2))
        for h in (1, 2):
            a = tracks[(tracks["order"] == h) & (tracks["time_s"] > 0.15)]["amplitude"].to_numpy()
            modal = abs(steady[name][h - 1] - direct[i, h - 1]) / amp[h - 1]
            tol = (2 * math.pi * h * f_m * DT) ** 2 / 12 * modal + 10 ** (SIDE_LOBE_DB / 20) * amp.sum() / amp[h - 1]
            assert np.abs(a / amp[h - 1] - 1.0).max() <= tol, (name, h)
