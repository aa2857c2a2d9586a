"""Run-up order map: the load case's STEP ramp of the input speed read as a run-up.

During the ramp the input speed n(t) [rpm] rises from 0 to its nominal value (flexgear.laws.ramps, STEP), so the
mesh harmonics k f_m(n) sweep through the natural frequencies: where the order k line of a Campbell diagram
crosses a mode (flexgear.modal.campbell_diagram), the bearing acceleration's k-th mesh order swells to a ridge. This
module computes, from a saved run's signals (flexgear.results):

Spectrogram (for the picture). Short-time Fourier transform of a bearing acceleration y(t) with a Hann window of
length L [s], hop h [s]; each column is drawn at the instantaneous input speed of its window's centre. Amplitude
spectrum |Y(f)| = 2 |sum_j w_j y_j e^{-i 2 pi f t_j}| / sum_j w_j [signal unit].

Order tracks (for the ridges). The k-th mesh order is demodulated along the mesh phase
phi(t) = int_0^t f_m(n(tau)) dtau [cycles] (the mesh frequency is proportional to the input speed:
f_m = c n, c [Hz/rpm]), and averaged over a window w of length L centred at t:

    A_k(t) = 2 |sum_j w(t_j - t) y(t_j) e^{-i 2 pi k phi(t_j)}| / sum_j w(t_j - t).

Demodulating along the phase follows the order through its frequency change within the window, so that the
order does not smear across bins as it does in a spectrogram. The window is the four-term Blackman-Harris window
(side lobes below -92 dB): the neighbouring orders, f_m apart, are rejected where the window holds at least
:data:`MIN_MESH_CYCLES` mesh cycles (f_m L >= 8: they fall beyond the main lobe, +-4/L); the tracks are kept only
there and during the ramp (n rising).

Ridges. A ridge is a local maximum of an order track over the speed that stands :data:`MIN_PROMINENCE_DB` above
its neighbourhood (the peak prominence of the track in dB) and :data:`MIN_SNR_DB` above the floor at its time: the
larger of the noise floor (the median amplitude of the spectrogram's bins between the first and the highest order:
most bins hold no order) and the leakage floor (the strongest order's track times the window's side-lobe level,
:data:`SIDE_LOBE_DB`: what a strong order leaks into the others' tracks). Ridges are ranked by prominence. Each
is compared with a predicted crossing of the same order (flexgear.modal.campbell_diagram.Campbell.crossings; below):
error = (n_ridge - n_crossing) / n_crossing.

The ridge of a crossing need not lie exactly at it. A damped mode's steady response peak is shifted by the trend
of the excitation (the mesh force grows with the load, which ramps with the speed) and of the measured quantity (an
acceleration, omega^2 times the displacement): for a response ~ r^3 / |1 - r^2 + 2 i zeta r|, r = n / n_cross, the
peak lies at r ~ 1 + 2 zeta^2. A fast sweep delays it further: the mode's response builds up over its time
constant 1 / (zeta omega_n), during which the speed rises by n' / (zeta omega_n). :func:`swept_peak` predicts the
ridge of one mode with both effects: the single mode

    q'' + 2 zeta omega_n q' + omega_n^2 q = s(t) cos(2 pi k phi(t))

(phi the run's mesh phase) integrated along the run's own speed history, its acceleration q'' tracked like the
run's signal, the track's maximum near the crossing. The excitation's amplitude s(t) is the run's own mesh load:
the mesh stiffness variation acts on the mean mesh force, Delta k delta^p = (Delta k / k) F for a contact law
F = k delta^p, so s(t) ~ F(t) = sum_c F_c(t), the sum of the recorded mesh forces averaged over the track window
(:func:`mesh_excitation`). During the ramp F is not the load fraction n / n_nominal of the load torque: the drive
also accelerates the driven members, whose inertia torque J alpha(t) the meshes carry on top of it.

Ridges against predictions. :func:`runup` compares each ridge with the crossings of its order that the order
excites (flexgear.modal.campbell_diagram: mesh phasing), each with its swept prediction n_swept
(:func:`swept_crossings`, the line's damping ratio at the crossing): the ridge is matched with the nearest n_swept,
swept_error =
(n_ridge - n_swept) / n_swept, next to the error against the crossing itself. The Campbell diagram's operating point
is the full load torque; the modes along the ramp differ where the mesh stiffness matters (the impact law's tangent
1.5 k delta^0.5 follows the load), which flexgear.modal.linearize at the ridge's speed and time t* shows. The
reference with all modes together is the linearised model's own run-up (flexgear.study.runup_linear).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from flexgear.results import RunResult
from flexgear.study.hold import single_mode_acceleration

__all__ = ["OrderMap", "RunUp", "order_tracks", "ridges", "match_crossings", "runup", "spectrogram",
           "mesh_phase", "mesh_excitation", "swept_peak", "swept_crossings", "DEFAULT_WINDOW_S", "DEFAULT_HOP_S",
           "MIN_MESH_CYCLES", "MIN_PROMINENCE_DB", "MIN_SNR_DB", "SIDE_LOBE_DB", "ORDERS"]

DEFAULT_WINDOW_S = 0.01
"""Window length L [s] of the spectrogram and the order tracks: 1000 samples at the runs' 1e-5 s step; the
tracks then resolve the orders from f_m = 800 Hz (:data:`MIN_MESH_CYCLES` / L)."""

DEFAULT_HOP_S = 5e-4
"""Hop h [s] between the evaluated windows."""

MIN_MESH_CYCLES = 8.0
"""Mesh cycles a track window must hold: the Blackman-Harris main lobe spans +-4/L, so at f_m L >= 8 the
neighbouring orders lie outside it, under the -92 dB side lobes."""

MIN_PROMINENCE_DB = 1.0
"""Prominence [dB] of a track maximum that counts as a ridge (a resonance raises its order above both sides)."""

SIDE_LOBE_DB = -92.0
"""Highest side lobe of the four-term Blackman-Harris window [dB]."""

MIN_SNR_DB = 20.0
"""Level [dB] above the spectrogram's noise floor that a ridge must reach (an order at the floor wanders at
random: its maxima are noise)."""

ORDERS = tuple(range(1, 11))
"""Mesh orders k tracked: 1x to 10x (the Campbell diagram's)."""

RPM_PER_RAD_PER_S = 30.0 / math.pi  # 1 rad/s = 1/(2 pi) rev/s = 60/(2 pi) rpm


def mesh_phase(time_s: np.ndarray, speed_rpm: np.ndarray, mesh_hz_per_rpm: float) -> np.ndarray:
    """Mesh phase phi(t) [cycles] = int_0^t c n dt (trapezoidal rule), c = ``mesh_hz_per_rpm`` [Hz/rpm]."""
    f = mesh_hz_per_rpm * np.asarray(speed_rpm, float)
    t = np.asarray(time_s, float)
    return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))])


def _uniform_step(time_s: np.ndarray) -> float:
    dt = np.diff(time_s)
    step = float(np.median(dt))
    if not np.allclose(dt, step, rtol=1e-6, atol=1e-12):
        raise ValueError("the order map needs uniformly sampled signals")
    return step


@dataclass(frozen=True)
class OrderMap:
    """Spectrogram of one signal during a run-up (module docstring).

    ``time_s``, ``speed_rpm`` (n_t,): each window's centre and the input speed there; ``frequency_hz`` (n_f,);
    ``amplitude`` (n_f, n_t) [signal unit]; ``floor`` (n_t,): the noise floor [signal unit];
    ``mesh_hz_per_rpm`` [Hz/rpm]; ``window_s`` [s]; ``signal``: the column.
    """

    time_s: np.ndarray
    speed_rpm: np.ndarray
    frequency_hz: np.ndarray
    amplitude: np.ndarray
    floor: np.ndarray
    mesh_hz_per_rpm: float
    window_s: float
    signal: str


def spectrogram(time_s: np.ndarray, y: np.ndarray, speed_rpm: np.ndarray, mesh_hz_per_rpm: float,
                window_s: float = DEFAULT_WINDOW_S, hop_s: float = DEFAULT_HOP_S, signal: str = "",
                orders: Sequence[int] = ORDERS) -> OrderMap:
    """Hann-windowed short-time amplitude spectrum of ``y`` (module docstring), windows of ``window_s`` [s] every
    ``hop_s`` [s]; the noise floor is the median over the bins from f_m to max(orders) f_m at each time (all
    bins where f_m is 0)."""
    t = np.asarray(time_s, float)
    dt = _uniform_step(t)
    m = max(int(round(window_s / dt)), 8)
    hop = max(int(round(hop_s / dt)), 1)
    if t.size < m:
        raise ValueError(f"signal of {t.size} samples is shorter than the window ({m} samples)")
    starts = np.arange(0, t.size - m + 1, hop)
    w = np.hanning(m)
    frames = np.lib.stride_tricks.sliding_window_view(np.asarray(y, float), m)[starts]
    amp = 2.0 * np.abs(np.fft.rfft(frames * w, axis=1)).T / w.sum()
    freq = np.fft.rfftfreq(m, dt)
    centre = starts + m // 2
    speed = np.asarray(speed_rpm, float)[centre]
    floor = np.empty(centre.size)
    for j, n in enumerate(speed):
        f_m = mesh_hz_per_rpm * n
        band = (freq >= f_m) & (freq <= max(orders) * f_m) if f_m > 0 else np.ones(freq.size, bool)
        floor[j] = float(np.median(amp[band, j])) if band.sum() >= 3 else float(np.median(amp[:, j]))
    return OrderMap(t[centre], speed, freq, amp, floor, float(mesh_hz_per_rpm), m * dt, signal)


def _blackman_harris(m: int) -> np.ndarray:
    """Four-term Blackman-Harris window (side lobes -92 dB)."""
    x = 2.0 * math.pi * np.arange(m) / (m - 1)
    return 0.35875 - 0.48829 * np.cos(x) + 0.14128 * np.cos(2 * x) - 0.01168 * np.cos(3 * x)


def order_tracks(time_s: np.ndarray, y: np.ndarray, speed_rpm: np.ndarray, mesh_hz_per_rpm: float,
                 orders: Sequence[int] = ORDERS, window_s: float = DEFAULT_WINDOW_S, hop_s: float = DEFAULT_HOP_S,
                 ramp_end_s: float | None = None, min_cycles: float = MIN_MESH_CYCLES) -> pd.DataFrame:
    """Order tracks A_k (module docstring): columns time_s, speed_rpm, order, frequency_hz (k f_m),
    amplitude [signal unit]; kept where the window holds ``min_cycles`` mesh cycles, lies inside the signal and
    ends by ``ramp_end_s`` [s] (None: anywhere)."""
    from scipy.signal import fftconvolve

    t = np.asarray(time_s, float)
    n = np.asarray(speed_rpm, float)
    dt = _uniform_step(t)
    m = max(int(round(window_s / dt)) | 1, 9)  # odd: centred
    w = _blackman_harris(m)
    w /= w.sum()
    hop = max(int(round(hop_s / dt)), 1)
    phi = mesh_phase(t, n, mesh_hz_per_rpm)
    half = m // 2
    at = np.arange(half, t.size - half, hop)
    f_m = mesh_hz_per_rpm * n[at]
    keep = f_m * window_s >= min_cycles
    if ramp_end_s is not None:
        keep &= t[at] + half * dt <= ramp_end_s
    at = at[keep]
    rows = []
    for k in orders:
        z = fftconvolve(np.asarray(y, float) * np.exp(-2j * math.pi * k * phi), w, mode="same")
        rows.append(pd.DataFrame({"time_s": t[at], "speed_rpm": n[at], "order": int(k),
                                  "frequency_hz": k * mesh_hz_per_rpm * n[at], "amplitude": 2.0 * np.abs(z[at])}))
    cols = ["time_s", "speed_rpm", "order", "frequency_hz", "amplitude"]
    return pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(columns=cols)


def ridges(tracks: pd.DataFrame, floor: tuple[np.ndarray, np.ndarray] | None = None,
           min_prominence_db: float = MIN_PROMINENCE_DB, min_snr_db: float = MIN_SNR_DB) -> pd.DataFrame:
    """Ridges of the order tracks (module docstring), strongest first: speed_rpm, order, frequency_hz, time_s,
    amplitude, prominence_db, snr_db (above the larger floor). ``floor``: (time_s, noise floor) of the spectrogram
(None: the leakage floor alone)."""
    from scipy.signal import find_peaks

    rows = []
    leak = tracks.groupby("time_s")["amplitude"].max() * 10.0 ** (SIDE_LOBE_DB / 20.0)
    for k, tr in tracks.groupby("order", sort=True):
        a = tr["amplitude"].to_numpy()
        if a.size < 3:
            continue
        level = 20.0 * np.log10(np.maximum(a, 1e-300))
        peaks, props = find_peaks(level, prominence=min_prominence_db)
        tt = tr["time_s"].to_numpy()
        noise = np.maximum(np.interp(tt, *floor) if floor is not None else 0.0, leak.reindex(tt).to_numpy())
        snr = level - 20.0 * np.log10(np.maximum(noise, 1e-300))
        for p, prom in zip(peaks, props["prominences"], strict=True):
            if snr[p] < min_snr_db:
                continue
            rows.append({"speed_rpm": float(tr["speed_rpm"].iloc[p]), "order": int(k),
                         "frequency_hz": float(tr["frequency_hz"].iloc[p]), "time_s": float(tt[p]),
                         "amplitude": float(a[p]), "prominence_db": float(prom), "snr_db": float(snr[p])})
    cols = ["speed_rpm", "order", "frequency_hz", "time_s", "amplitude", "prominence_db", "snr_db"]
    out = pd.DataFrame(rows, columns=cols)
    return out.sort_values("prominence_db", ascending=False, ignore_index=True)


def match_crossings(found: pd.DataFrame, crossings: pd.DataFrame, on: str = "speed_rpm") -> pd.DataFrame:
    """Each ridge with the predicted crossing of its order (Campbell crossings: speed_rpm, order, mode, kind,
    frequency_hz; only those with ``excited`` true where that column is given) whose column ``on`` (speed_rpm: the
    crossing; swept_rpm: its swept prediction, :func:`swept_crossings`) lies nearest the ridge: adds crossing_rpm,
    mode, kind, mode_hz and error_pct = 100 (n_ridge - n_cross) / n_cross, and where the crossings carry swept_rpm,
    swept_rpm and swept_error_pct = 100 (n_ridge - n_swept) / n_swept (NaN where the order has no crossing)."""
    out = found.copy()
    swept = "swept_rpm" in crossings.columns
    keys = ["crossing_rpm", "mode", "kind", "mode_hz", "error_pct"]
    keys += ["swept_rpm", "swept_error_pct"] if swept else []
    extra: dict[str, list] = {key: [] for key in keys}
    usable = crossings[crossings["excited"].astype(bool)] if "excited" in crossings.columns else crossings
    for _, r in found.iterrows():
        same = usable[(usable["order"] == r["order"]) & (usable["speed_rpm"] > 0) & usable[on].notna()]
        if same.empty:
            for key in extra:
                extra[key].append(np.nan if key != "kind" else "")
            continue
        c = same.iloc[int(np.argmin(np.abs(same[on].to_numpy() - r["speed_rpm"])))]
        extra["crossing_rpm"].append(float(c["speed_rpm"]))
        extra["mode"].append(int(c["mode"]))
        extra["kind"].append(str(c["kind"]))
        extra["mode_hz"].append(float(c["frequency_hz"]))
        extra["error_pct"].append(100.0 * (r["speed_rpm"] - c["speed_rpm"]) / c["speed_rpm"])
        if swept:
            extra["swept_rpm"].append(float(c["swept_rpm"]))
            extra["swept_error_pct"].append(100.0 * (r["speed_rpm"] - c["swept_rpm"]) / c["swept_rpm"])
    for key, values in extra.items():
        out[key] = values
    return out


DB_RANGE = 120.0
"""Colour range of the drawn map below its top level [dB] (the numerical noise of the runs lies lower)."""

F_MIN_HZ = 50.0
"""Lowest frequency of the drawn map [Hz] (its frequency axis is logarithmic)."""

SWEPT_SEARCH = 0.25
"""Relative speed range around a crossing in which :func:`swept_peak` takes its track's maximum [-]."""


def mesh_excitation(signals: pd.DataFrame, window_s: float = DEFAULT_WINDOW_S,
                    reference_n: float | None = None) -> np.ndarray | None:
    """Amplitude s(t) of the mesh excitation along a run (module docstring): the sum of its recorded mesh forces
    (the columns named ``*mesh_force*`` [N]) averaged over a window of ``window_s`` [s], divided by its largest
    value (or by ``reference_n`` [N] where given) [-]; None where the run recorded no mesh force."""
    from scipy.ndimage import uniform_filter1d

    cols = [c for c in signals.columns if "mesh_force" in c]
    if not cols:
        return None
    t = signals["time_s"].to_numpy()
    m = max(int(round(window_s / _uniform_step(t))), 1) | 1  # odd: centred
    f = uniform_filter1d(np.abs(signals[cols].to_numpy(float)).sum(axis=1), m, mode="nearest")
    top = float(f.max()) if reference_n is None else float(reference_n)
    return f / top if top > 0.0 else None


def swept_peak(time_s: np.ndarray, speed_rpm: np.ndarray, mesh_hz_per_rpm: float, order: int, mode_hz: float,
               damping_ratio: float, nominal_rpm: float | None = None, window_s: float = DEFAULT_WINDOW_S,
               hop_s: float = DEFAULT_HOP_S, min_cycles: float = MIN_MESH_CYCLES,
               excitation: np.ndarray | None = None) -> float:
    """Speed [rpm] of the ridge that a single mode (``mode_hz`` [Hz], ``damping_ratio`` [-]) makes on order
    ``order`` along the speed history ``speed_rpm`` (module docstring), tracked with the same window; force
    amplitude ``excitation`` s(t) (one value per sample, e.g. :func:`mesh_excitation`; None: the load fraction
    n / ``nominal_rpm``, default the highest speed). NaN if the order never reaches the mode or the track has no
    maximum within :data:`SWEPT_SEARCH` of the crossing."""
    t = np.asarray(time_s, float)
    n = np.asarray(speed_rpm, float)
    crossing = mode_hz / (order * mesh_hz_per_rpm)
    if not n.max() >= crossing:
        return math.nan
    nominal = float(n.max()) if nominal_rpm is None else float(nominal_rpm)
    amplitude = n / nominal if excitation is None else np.asarray(excitation, float)
    force = amplitude * np.cos(2.0 * math.pi * order * mesh_phase(t, n, mesh_hz_per_rpm))
    accel = single_mode_acceleration(t, force, mode_hz, damping_ratio)
    tr = order_tracks(t, accel, n, mesh_hz_per_rpm, (order,), window_s, hop_s, min_cycles=min_cycles)
    rising = np.concatenate([[True], np.diff(tr["speed_rpm"].to_numpy()) > 0])
    near = rising & (np.abs(tr["speed_rpm"].to_numpy() / crossing - 1.0) <= SWEPT_SEARCH)
    if not near.any():
        return math.nan
    sel = tr[near]
    return float(sel["speed_rpm"].iloc[int(np.argmax(sel["amplitude"].to_numpy()))])


def swept_crossings(crossings: pd.DataFrame, time_s: np.ndarray, speed_rpm: np.ndarray, mesh_hz_per_rpm: float,
                    speed_range_rpm: tuple[float, float], orders: Sequence[int],
                    excitation: np.ndarray | None = None, window_s: float = DEFAULT_WINDOW_S,
                    hop_s: float = DEFAULT_HOP_S) -> pd.DataFrame:
    """The ``crossings`` (flexgear.modal.campbell_diagram: speed_rpm, order, frequency_hz, damping_ratio, excited) of
    the ``orders`` whose crossing speed lies within ``speed_range_rpm`` [rpm], each with swept_rpm, its ridge under the
    run's own sweep (:func:`swept_peak` with the line's damping ratio and ``excitation``); only the excited ones
    where the column is given."""
    lo, hi = speed_range_rpm
    sel = crossings[crossings["order"].isin(list(orders)) & crossings["speed_rpm"].between(lo, hi)]
    if "excited" in sel.columns:
        sel = sel[sel["excited"].astype(bool)]
    sel = sel.copy()
    sel["swept_rpm"] = [swept_peak(time_s, speed_rpm, mesh_hz_per_rpm, int(c["order"]), float(c["frequency_hz"]),
                                   float(c["damping_ratio"]), window_s=window_s, hop_s=hop_s, excitation=excitation)
                        for _, c in sel.iterrows()]
    return sel


@dataclass(frozen=True)
class RunUp:
    """A run's run-up (module docstring): ``map`` the spectrogram, ``tracks`` the order tracks, ``ridges`` (matched
    to ``crossings`` when given), ``ramp_end_s`` [s] the end of the speed ramp, ``name`` the run."""

    name: str
    map: OrderMap
    tracks: pd.DataFrame
    ridges: pd.DataFrame
    ramp_end_s: float
    orders: tuple[int, ...]

    def plot(self, ax: Any, campbell: Any = None, ridges: int = 3, db_range: float = DB_RANGE,
             f_min_hz: float = F_MIN_HZ) -> Any:
        """The map over the input speed [rpm] during the ramp, frequency [Hz] on a log axis from ``f_min_hz``,
        amplitude in dB (``db_range`` below the map's top level); the mesh orders (white dashed), the Campbell
        lines of ``campbell`` (flexgear.modal.campbell_diagram.Campbell, black), the region where the tracks do not
        resolve the orders (hatched) and the ``ridges`` strongest ridges (red circles). Returns ``ax``."""
        mp = self.map
        rising = (mp.time_s <= self.ramp_end_s) & np.concatenate([[True], np.diff(mp.speed_rpm) > 0])
        n, a = mp.speed_rpm[rising], mp.amplitude[:, rising]
        n_top = float(n.max()) if n.size else 1.0
        f_top = max(self.orders) * mp.mesh_hz_per_rpm * n_top * 1.05
        band = (mp.frequency_hz >= f_min_hz) & (mp.frequency_hz <= f_top)
        level = 20.0 * np.log10(np.maximum(a[band], 1e-300))
        top = float(np.percentile(level, 99.9)) if level.size else 0.0
        if n.size >= 2 and band.any():
            ax.pcolormesh(n, mp.frequency_hz[band], level, shading="nearest", vmin=top - db_range, vmax=top,
                          cmap="viridis", rasterized=True)
        span = np.array([max(n_top * 1e-3, f_min_hz / (max(self.orders) * mp.mesh_hz_per_rpm)), n_top])
        if campbell is not None:
            for _, line in campbell.table.groupby("mode", sort=True):
                ax.plot(line.speed_rpm, line.frequency_hz, "-", color="k", lw=0.7, alpha=0.9)
            ax.plot([], [], "-", color="k", lw=0.7, label=f"Campbell lines ({campbell.variant_name})")
        for k in self.orders:
            ax.plot(span, k * mp.mesh_hz_per_rpm * span, "--", color="w", lw=0.5)
            ax.annotate(f"{k}x", (span[1], k * mp.mesh_hz_per_rpm * span[1]), color="0.2", fontsize=6,
                        xytext=(2, -2), textcoords="offset points", annotation_clip=False)
        resolved = self.tracks["speed_rpm"].min() if len(self.tracks) else n_top
        ax.axvspan(0.0, resolved, facecolor="none", edgecolor="w", hatch="//", lw=0.0, alpha=0.5,
                   label=f"orders not resolved (< {MIN_MESH_CYCLES:g} mesh cycles per {1e3 * mp.window_s:g} ms)")
        shown = self.ridges.head(ridges)
        if len(shown):
            ax.plot(shown.speed_rpm, shown.frequency_hz, "o", mfc="none", mec="r", ms=10, mew=1.5,
                    label=f"{len(shown)} strongest ridges")
        ax.set_yscale("log")
        ax.set_xlim(0.0, n_top)
        ax.set_ylim(f_min_hz, f_top)
        ax.set_xlabel("instantaneous input speed [rpm] (during the STEP ramp)")
        ax.set_ylabel("frequency [Hz]")
        ax.legend(fontsize=6.5, loc="lower right", framealpha=0.8)
        return ax


def runup(result: RunResult, side: str = "output", axis: str = "x", campbell: Any = None,
          window_s: float = DEFAULT_WINDOW_S, hop_s: float = DEFAULT_HOP_S,
          orders: Sequence[int] = ORDERS) -> RunUp:
    """The run-up of a saved run (module docstring) from the ``side`` ("input"/"output") bearing acceleration
    along ``axis`` ("x"/"y"); the instantaneous speed is the recorded input speed, the ramp's end the run's
    ``ramp_time_s``, the mesh frequency per rpm the run's theory values (mesh frequency / nominal input speed).
    ``campbell``: a flexgear.modal.campbell_diagram.Campbell whose crossings the ridges are matched with (module
    docstring: by their swept predictions under the run's mesh excitation); the ridges against the linearised
    model's own run-up: flexgear.study.runup_linear.match_linear."""
    if not result.ok or result.signals is None:
        raise ValueError(f"run {result.name!r} has no signals")
    s = result.signals
    column = f"{side}_bearing_accel_{axis}_m_per_s2"
    t = s["time_s"].to_numpy()
    n = s["input_speed_rad_per_s"].to_numpy() * RPM_PER_RAD_PER_S
    meta = result.meta
    nominal = float(((meta.get("spec") or {}).get("load_case") or {}).get("input_speed_rpm", 0.0))
    f_mesh = float((meta.get("theory") or {}).get("mesh_frequency_hz", 0.0))
    if not (nominal > 0.0 and f_mesh > 0.0):
        raise ValueError(f"run {result.name!r}: no nominal input speed or mesh frequency in its metadata")
    per_rpm = f_mesh / nominal
    ramp = float(meta.get("ramp_time_s") or t[-1])
    y = s[column].to_numpy()
    mp = spectrogram(t, y, n, per_rpm, window_s, hop_s, column, orders)
    tracks = order_tracks(t, y, n, per_rpm, orders, window_s, hop_s, ramp_end_s=ramp)
    found = ridges(tracks, (mp.time_s, mp.floor))
    if campbell is not None:
        crossings = campbell.crossings
        if "damping_ratio" in crossings.columns and len(found) and len(tracks):
            span = (float(tracks["speed_rpm"].min()), float(tracks["speed_rpm"].max()))
            crossings = swept_crossings(crossings, t, n, per_rpm, span, sorted(set(found["order"])),
                                        mesh_excitation(s, window_s), window_s, hop_s)
            found = match_crossings(found, crossings, on="swept_rpm")
        else:
            found = match_crossings(found, crossings)
    return RunUp(result.name, mp, tracks, found, ramp, tuple(orders))
