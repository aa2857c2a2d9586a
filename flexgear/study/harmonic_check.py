"""The lumped model's harmonic response (flexgear.harmonic.lumped) against its own settled time integration
(flexgear.lumped.run), at check speeds taken from its Campbell diagram.

Check speeds (:func:`check_speeds`). The response over a speed grid locates the peaks of K_v - 1; the first whose
height is at least :data:`STRONG` of the highest is the first strong peak n_p (the rule of the multibody model's
check, benchmarks/bench_harmonic.py). At n_p the mesh that sets K_v, that mesh's harmonic h* with the largest
dynamic force, and the mode multiplet that carries that harmonic (flexgear.harmonic.peaks.mode_contributions) name
the crossing: the Campbell crossing n_c of that mode with mesh order h* (flexgear.harmonic.peaks.lumped_campbell,
the same grid). The check speeds are n_c x :data:`BESIDE` (below, on, above the crossing).

Time runs (:func:`settled_lumped_run`). The load case's STEP ramps shortened to ``ramp_s``, then on to
``[load_case] settle_max_time_s``; the settled part is flexgear.settling.settled_start's with the spec's
``[screening]`` rule. Amplitudes (:func:`window_amplitudes`): the last :data:`WINDOW_S` rounded down to whole mesh
cycles at the recorded step, 1x and 2x by flexgear.study.compare.harmonic_amplitudes (Hann-windowed DTFT); K_v the
largest over planets and both meshes of a planet's peak mesh force over its mean in the window
(flexgear.study.indicators). The same over the window before the last shows how much the run still moves.

Diagnostics of a settled run: :func:`line_amplitude`, the amplitude at exactly one frequency over a long window,
which tells a mesh harmonic from the sidebands h f_mesh +- p f_rot that a rotating asymmetric member (flexible
gears' meshes, the ring's bolt pattern) adds and that the analysed window's resolution 1 / WINDOW_S merges with
it; :func:`periodic_peak_factor`, K_v of the window's mesh-periodic part alone (what the frequency domain
computes); :func:`sideband_rss`, the amplitude of a mesh harmonic with its sidebands, the root-sum-square of the
lines at h f_mesh + p B f_ring, p = -P..P, which the frequency domain over the turning angle gives as the RMS over
the angles (flexgear.harmonic.turning, eq. 1).

Comparison (:func:`compare_lumped`): frequency domain over time domain minus 1 for each amplitude, and
(K_v,f - 1) / (K_v,t - 1) - 1. An amplitude the planets' phasing cancels (below :data:`CANCELLED` of its family's
largest at that speed in the frequency domain: mesh forces, bearing accelerations) is listed but not judged.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from flexgear.settling import SettleRule, Settling, settled_start
from flexgear.study.compare import harmonic_amplitudes
from flexgear.study.indicators import dynamic_factor

__all__ = ["CheckSpeeds", "LumpedCheck", "check_speeds", "settled_lumped_run", "window_amplitudes",
           "compare_lumped", "line_amplitude", "sideband_rss", "periodic_peak_factor",
           "STRONG", "BESIDE", "WINDOW_S", "RAMP_S", "CANCELLED", "COLUMNS", "SWEEP_RPM"]

STRONG = 0.5
"""A peak of K_v - 1 at least this fraction of the highest counts as a strong crossing."""
BESIDE = (0.75, 1.0, 1.25)
"""The three check speeds as multiples of the first strong crossing's speed."""
SWEEP_RPM = (500.0, 7000.0, 25.0)
"""The grid [rpm] (first, last, step) of the response and the Campbell diagram that locate the crossing."""
RAMP_S = 0.05
"""STEP ramps of speed and load of the time runs [s] (the slowest decay time after them is about 33 ms)."""
WINDOW_S = 0.05
"""Analysed window at the end of a run [s], rounded down to whole mesh cycles."""
CANCELLED = 0.01
"""Amplitudes below this fraction of their family's largest (frequency domain, same speed) are not judged."""
COLUMNS = ("outer_mesh_force_1_n", "inner_mesh_force_1_n", "input_bearing_accel_x_m_per_s2",
           "input_bearing_accel_y_m_per_s2", "output_bearing_accel_x_m_per_s2", "output_bearing_accel_y_m_per_s2")
"""The compared signals (flexgear.results.signal_columns)."""


@dataclass(frozen=True)
class CheckSpeeds:
    """The first strong peak of K_v - 1 and its crossing (module docstring): ``peak_rpm`` [rpm] and ``kv`` there,
    ``mesh`` (the indicator that sets K_v) and its harmonic ``order``, the carrying multiplet's ``frequency_hz``,
    ``damping_ratio`` and ``share`` (|contribution| over the mesh force's response part), ``crossing_rpm`` [rpm]
    and the check ``speeds_rpm``."""

    peak_rpm: float
    kv: float
    mesh: str
    order: int
    frequency_hz: float
    damping_ratio: float
    share: float
    crossing_rpm: float
    speeds_rpm: tuple[float, ...]


def check_speeds(spec: Any, grid_rpm: Sequence[float] = SWEEP_RPM, strong: float = STRONG,
                 beside: Sequence[float] = BESIDE) -> CheckSpeeds:
    """The check speeds of the lumped model of ``spec`` (module docstring); ``grid_rpm``: (first, last, step)."""
    from flexgear.harmonic.lumped import lumped_harmonic_response, lumped_linear
    from flexgear.harmonic.peaks import lumped_campbell, mode_contributions

    a, b, step = grid_rpm
    speeds = np.arange(a, b + 0.5 * step, step)
    harmonics = spec.contact_assumed.stiffness_harmonics
    response = lumped_harmonic_response(spec, speeds, harmonics)
    kv = response.dynamic_factor()
    n, y = kv.index.to_numpy(float), kv.to_numpy() - 1.0
    inner = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
    if not inner.size:
        raise RuntimeError("no peak of K_v in the range")
    peak = int(inner[y[inner] >= strong * y[inner].max()][0])
    n_p = float(n[peak])
    meshes = [m for m in response.static_forces_n]
    waves = {m: response.complex(m).loc[n_p].to_numpy() for m in meshes}
    mesh = max(meshes, key=lambda m: float(np.abs(waves[m]).sum()) / response.static_forces_n[m])
    order = int(np.argmax(np.abs(waves[mesh]))) + 1
    top = mode_contributions(lumped_linear(spec, harmonics), n_p, mesh, order).iloc[0]
    band = order * response.mesh_frequency_hz_per_rpm * speeds[-1] * (1.0 + 1e-9)
    crossings = lumped_campbell(spec, speeds, band, orders=(order,)).crossings
    at = crossings[np.isclose(crossings.frequency_hz, top.frequency_hz, rtol=1e-3)]
    if at.empty:
        raise RuntimeError(f"the mode at {top.frequency_hz:.1f} Hz does not cross order {order} in the range")
    n_c = float(at.speed_rpm.iloc[int(np.argmin(np.abs(at.speed_rpm.to_numpy() - n_p)))])
    return CheckSpeeds(n_p, float(kv.loc[n_p]), mesh, order, float(top.frequency_hz), float(top.damping_ratio),
                       float(top.share), n_c, tuple(round(n_c * f, 1) for f in beside))


def settled_lumped_run(spec: Any, speed_rpm: float, ramp_s: float = RAMP_S) -> tuple[Any, Settling]:
    """The lumped model of ``spec`` at ``speed_rpm`` [rpm], ramps over ``ramp_s`` [s], run to ``[load_case]
    settle_max_time_s``; returns (flexgear.results.RunResult, flexgear.settling.Settling of its signals)."""
    from flexgear.harmonic import mesh_frequency_hz
    from flexgear.lumped.run import run_lumped

    spec = spec.with_fields("load_case", input_speed_rpm=float(speed_rpm), ramp_time_s=ramp_s)
    result = run_lumped(spec, t_end_s="settled")
    after = ramp_s + spec.screening.after_ramp_delay_s
    test = settled_start(result.signals, after, mesh_frequency_hz(spec, speed_rpm),
                         SettleRule.from_settings(spec.screening))
    return result, test


def window_amplitudes(signals: pd.DataFrame, mesh_frequency_hz: float, window_s: float = WINDOW_S, back: int = 0,
                      columns: Sequence[str] = COLUMNS) -> tuple[dict[str, np.ndarray], float, tuple[float, float]]:
    """1x, 2x amplitudes of ``columns`` and K_v over a window of whole mesh cycles (module docstring): the last one
    (``back`` = 0) or the ``back``-th before it. Returns ({column: (2,) amplitudes}, K_v, (start, end) [s])."""
    t = signals["time_s"].to_numpy()
    dt = float(t[-1] - t[-2])
    k = int(round(math.floor(window_s * mesh_frequency_hz) / mesh_frequency_hz / dt))
    end = t.size - back * k
    sel = slice(end - k, end)
    if sel.start < 0 or not np.allclose(np.diff(t[sel]), dt, rtol=1e-6):
        raise RuntimeError("the analysed window is not uniformly sampled inside the run")
    amps = {c: harmonic_amplitudes(signals[c].to_numpy()[sel], dt, mesh_frequency_hz, (1, 2)) for c in columns}
    forces = [np.stack([signals[c].to_numpy()[sel] for c in signals.columns
                        if c.startswith(f"{kind}_mesh_force_") and c.endswith("_n")], axis=1)
              for kind in ("outer", "inner")]
    return amps, dynamic_factor(*forces), (float(t[sel.start]), float(t[sel.stop - 1]))


@dataclass(frozen=True)
class LumpedCheck:
    """One check speed: ``table`` (quantity, harmonic (0 for K_v - 1), frequency, time, difference (frequency /
    time - 1), judged, moved (time value's relative change from the window before the last)), the settling test,
    the analysed window (start, end) [s] and the run's wall time [s]."""

    speed_rpm: float
    table: pd.DataFrame
    settling: Settling
    window_s: tuple[float, float]
    wall_time_s: float

    @property
    def worst(self) -> float:
        """The largest judged |difference|."""
        judged = self.table[self.table.judged]
        return float(judged.difference.abs().max()) if len(judged) else 0.0


def compare_lumped(spec: Any, speed_rpm: float, ramp_s: float = RAMP_S, window_s: float = WINDOW_S) -> LumpedCheck:
    """The frequency-domain 1x, 2x amplitudes and K_v - 1 of the lumped model at ``speed_rpm`` [rpm] against its
    settled time run (module docstring). Raises if the run has not settled before the two analysed windows."""
    from flexgear.harmonic import lumped_harmonic_response, mesh_frequency_hz

    freq = lumped_harmonic_response(spec, [speed_rpm], spec.contact_assumed.stiffness_harmonics)
    result, test = settled_lumped_run(spec, speed_rpm, ramp_s)
    f_mesh = mesh_frequency_hz(spec, speed_rpm)
    last, kv_t, window = window_amplitudes(result.signals, f_mesh, window_s)
    before, kv_b, _ = window_amplitudes(result.signals, f_mesh, window_s, back=1)
    if not test.settled or test.start_s > window[0] - (window[1] - window[0]):
        raise RuntimeError(f"{speed_rpm:g} rpm: {test.reason}; the two analysed windows start at "
                           f"{2 * window[0] - window[1]:.4g} s")
    rows = []
    for column in COLUMNS:
        fd = freq.amplitudes(column).iloc[0].to_numpy()[:2]
        family = [c for c in COLUMNS if ("accel" in c) == ("accel" in column)]
        scale = max(freq.amplitudes(c).iloc[0].to_numpy()[:2].max() for c in family)
        for h in (0, 1):
            rows.append({"quantity": column, "harmonic": h + 1, "frequency": fd[h], "time": last[column][h],
                         "difference": fd[h] / last[column][h] - 1.0, "judged": bool(fd[h] >= CANCELLED * scale),
                         "moved": last[column][h] / before[column][h] - 1.0})
    kv_f = float(freq.dynamic_factor().iloc[0])
    rows.append({"quantity": "dynamic_factor - 1", "harmonic": 0, "frequency": kv_f - 1.0, "time": kv_t - 1.0,
                 "difference": (kv_f - 1.0) / (kv_t - 1.0) - 1.0, "judged": True,
                 "moved": (kv_t - 1.0) / (kv_b - 1.0) - 1.0})
    return LumpedCheck(float(speed_rpm), pd.DataFrame(rows), test, window, float(result.meta.get("wall_time_s", 0.0)))


def line_amplitude(signal: np.ndarray, dt: float, frequency_hz: float) -> float:
    """Amplitude of the sinusoid at exactly ``frequency_hz`` [Hz] in ``signal`` sampled at ``dt`` [s]: the
    Hann-windowed DTFT A = 2 |sum_n w_n (x_n - mean x) e^{-i 2 pi f n dt}| / sum_n w_n. A line at another frequency
    f' leaks into it by the window's transform at f' - f: about 3e-4 of its amplitude at |f' - f| = 10 / (n dt),
    4e-5 at 20 / (n dt)."""
    x = np.asarray(signal, float)
    x = x - x.mean()
    w = np.hanning(x.size)
    t = np.arange(x.size) * dt
    return float(2.0 * abs(np.exp(-2j * math.pi * frequency_hz * t) @ (w * x)) / w.sum())


def sideband_rss(signal: np.ndarray, dt: float, frequency_hz: float, spacing_hz: float, order: int) -> float:
    """sqrt(sum_{p=-P..P} A(f + p f_s)^2), A = :func:`line_amplitude` of ``signal`` sampled at ``dt`` [s], f =
    ``frequency_hz`` [Hz], f_s = ``spacing_hz`` [Hz] (a turning pattern's passing frequency B f_ring), P =
    ``order``; P = 0 is the line at exactly f. Lines at 0 Hz or below are left out. The lines need to lie some
    resolutions 1 / (n dt) apart (line_amplitude's leakage)."""
    if order < 0:
        raise ValueError(f"order: expected >= 0, got {order}")
    lines = [frequency_hz + p * spacing_hz for p in range(-order, order + 1)]
    return float(math.sqrt(sum(line_amplitude(signal, dt, f) ** 2 for f in lines if f > 0.0)))


def periodic_peak_factor(forces: np.ndarray, dt: float, mesh_frequency_hz: float, harmonics: int) -> float:
    """K_v of the mesh-periodic part of ``forces`` (n, m): m mesh-force signals sampled at ``dt`` [s] over a whole
    number of mesh cycles. Each column x has the mean F and the Fourier coefficients X_h = (2 / n) sum_k x_k
    e^{-i 2 pi h f_mesh k dt} (exact for whole cycles), h = 1..``harmonics``; its peak factor is
    max_phi (F + Re sum_h X_h e^{i h phi}) / F (flexgear.harmonic.base.waveform_peak), K_v the largest over the
    columns. Content at other frequencies (sidebands, slow load-sharing changes) does not enter it."""
    from flexgear.harmonic.base import waveform_peak

    f = np.atleast_2d(np.asarray(forces, float).T).T
    t = np.arange(f.shape[0]) * dt
    h = np.arange(1, harmonics + 1)
    mean = f.mean(axis=0)
    coef = 2.0 * (np.exp(-2j * math.pi * mesh_frequency_hz * np.outer(h, t)) @ (f - mean)) / f.shape[0]  # (H, m)
    return max(waveform_peak(coef[:, j], mean[j]) / mean[j] for j in range(f.shape[1]))
