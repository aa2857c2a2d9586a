"""Run-up order map (flexgear.study.runup): ridges of a synthetic run-up lie at the crossings it was built with."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy.signal import lsim

from flexgear.laws.ramps import step
from flexgear.study.runup import match_crossings, order_tracks, ridges, spectrogram, swept_peak

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


def test_spectrogram_amplitude_of_a_tone():
    """A steady tone of amplitude A shows as A in the Hann-windowed amplitude spectrum (on a bin)."""
    t = np.arange(0.0, 0.1, DT)
    f0 = 4000.0  # Hz: a whole number of cycles per 10 ms window (on a bin)
    mp = spectrogram(t, 0.3 * np.cos(2 * math.pi * f0 * t), np.full(t.size, 1000.0), PER_RPM)
    j = int(np.argmin(np.abs(mp.frequency_hz - f0)))
    assert np.allclose(mp.amplitude[j], 0.3, rtol=1e-6)
