"""Comparison of two runs (multibody, lumped or any two): the study's Tables 6 and 7, and spectra.

- Table 6 (section 4.1): input and output speed, mean outer and inner mesh force (over time and
  planets), peak radial bearing acceleration sqrt(a_x^2 + a_y^2) at the input and output shaft,
  as theory vs run A vs run B, over a steady window (default: from the end of the ramps to the end).
- Table 7 (section 4.2): amplitudes of the bearing acceleration spectra at 1, 2, 4, 6 and 9 times
  the mesh frequency, per run and bearing.

Spectra are single-sided amplitude spectra of a Hann-windowed signal, scaled by the window's
coherent gain so that a sinusoid of amplitude A shows as A (:func:`amplitude_spectrum`).
A harmonic's amplitude is the windowed discrete-time Fourier transform evaluated at the harmonic's
frequency (best within +-half a bin), so it does not suffer the bin-grid scalloping loss
(:func:`harmonic_amplitudes`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from flexgear.results import RunResult

__all__ = [
    "TABLE7_HARMONICS",
    "amplitude_spectrum",
    "harmonic_amplitudes",
    "steady_window",
    "compare_results",
    "load_case_differences",
    "BearingSpectrum",
    "mark_harmonics",
]

TABLE7_HARMONICS = (1, 2, 4, 6, 9)
"""Multiples of the mesh frequency in Table 7."""

_AXES = ("x", "y", "max")


def amplitude_spectrum(signal: np.ndarray, dt: float, window: str = "hann",
                       detrend: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Single-sided amplitude spectrum: frequencies [Hz] and amplitudes (units of ``signal``).

    A_k = 2 |sum_n w_n x_n exp(-2 pi i k n / N)| / sum_n w_n (DC not doubled); ``window`` "hann" or
    "rect"; ``detrend`` removes the mean first.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise ValueError("amplitude_spectrum: expected a 1-D signal with at least 2 samples")
    if detrend:
        x = x - x.mean()
    w = _window(window, x.size)
    amp = 2.0 * np.abs(np.fft.rfft(w * x)) / w.sum()
    amp[0] *= 0.5
    return np.fft.rfftfreq(x.size, dt), amp


def _window(name: str, n: int) -> np.ndarray:
    if name == "hann":
        return np.hanning(n)
    if name == "rect":
        return np.ones(n)
    raise ValueError(f"window: expected 'hann' or 'rect', got {name!r}")


def harmonic_amplitudes(signal: np.ndarray, dt: float, base_frequency_hz: float,
                        harmonics: Sequence[int] = TABLE7_HARMONICS, window: str = "hann") -> np.ndarray:
    """Amplitude of ``signal`` at each k * base frequency (windowed DTFT, best within +-half a bin)."""
    x = np.asarray(signal, dtype=float)
    x = x - x.mean()
    w = _window(window, x.size)
    t = np.arange(x.size) * dt
    half_bin = 0.5 / (x.size * dt)
    out = np.zeros(len(harmonics))
    for i, k in enumerate(harmonics):
        f = k * base_frequency_hz + np.linspace(-half_bin, half_bin, 11)
        dtft = np.exp(-2j * math.pi * np.outer(f, t)) @ (w * x)
        out[i] = 2.0 * np.abs(dtft).max() / w.sum()
    return out


def steady_window(result: RunResult) -> tuple[float, float]:
    """Default analysis window: from the end of the ramps to the end of the run.

    A run that ends before its ramps do is analysed over its last half instead.
    """
    _check(result)
    t = result.signals["time_s"].to_numpy()
    t0, t1 = float(t[0]), float(t[-1])
    ramp = float(result.meta.get("ramp_time_s", t0))
    return (ramp, t1) if ramp < t1 else (0.5 * (t0 + t1), t1)


def _check(result: RunResult) -> None:
    if result.signals is None or not result.ok:
        raise ValueError(f"run {result.name!r} has no signals (status {result.meta.get('status')!r})")


def _select(result: RunResult, window: tuple[float, float]) -> pd.DataFrame:
    _check(result)
    s = result.signals
    sel = s[(s["time_s"] >= window[0] - 1e-12) & (s["time_s"] <= window[1] + 1e-12)]
    if len(sel) < 4:
        raise ValueError(f"run {result.name!r}: window {window} holds fewer than 4 samples")
    return sel


def _labels(a: RunResult, b: RunResult) -> tuple[str, str]:
    """Column names of the two runs: variant names, made distinct by backend, then by A/B."""
    la, lb = a.name, b.name
    if la == lb:
        la, lb = f"{la} ({a.meta.get('backend', '?')})", f"{lb} ({b.meta.get('backend', '?')})"
    if la == lb:
        la, lb = f"{la} A", f"{lb} B"
    return la, lb


def _accel(sel: pd.DataFrame, side: str, axis: str) -> np.ndarray:
    return sel[f"{side}_bearing_accel_{axis}_m_per_s2"].to_numpy()


def compare_results(a: RunResult, b: RunResult, window: tuple[float, float] | None = None,
                    axis: str = "x", harmonics: Sequence[int] = TABLE7_HARMONICS) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Tables 6 and 7 of the study from two runs.

    ``window``: (t0, t1) [s]; default the later ramp end of the two runs to the earlier run end.
    ``axis``: bearing acceleration component whose spectrum Table 7 reports ("x", "y", or "max",
    the larger of the two amplitudes). Theory values come from the runs' metadata (run A first).
    Returns (table6, table7); table6 columns "theory", A, B; table7 rows k (multiple of the mesh
    frequency), columns (run, "input"/"output") in m/s^2.
    """
    if axis not in _AXES:
        raise ValueError(f"axis: expected one of {_AXES}, got {axis!r}")
    if window is None:
        wa, wb = steady_window(a), steady_window(b)
        window = (max(wa[0], wb[0]), min(wa[1], wb[1]))
        if window[1] <= window[0]:
            window = wa
    th = a.meta.get("theory") or b.meta.get("theory") or {}
    f_mesh = th.get("mesh_frequency_hz")
    if not f_mesh:
        raise ValueError("compare_results: neither run's metadata holds theory.mesh_frequency_hz")
    rows = ["input_speed_deg_per_s", "output_speed_deg_per_s", "outer_mesh_force_n", "inner_mesh_force_n",
            "input_bearing_peak_accel_m_per_s2", "output_bearing_peak_accel_m_per_s2"]
    table6 = pd.DataFrame(index=pd.Index(rows, name="indicator"))
    # Table 6 of the study, in its units: speeds in deg/s
    table6["theory"] = [np.degrees(th.get("input_speed_rad_per_s", np.nan)),
                        np.degrees(th.get("output_speed_rad_per_s", np.nan)),
                        th.get("mesh_force_n", np.nan), th.get("mesh_force_n", np.nan), np.nan, np.nan]
    t7 = {}
    for run, label in zip((a, b), _labels(a, b), strict=True):
        sel = _select(run, window)
        outer = sel.filter(regex=r"^outer_mesh_force_\d+_n$").to_numpy()
        inner = sel.filter(regex=r"^inner_mesh_force_\d+_n$").to_numpy()
        peaks = [float(np.hypot(_accel(sel, side, "x"), _accel(sel, side, "y")).max()) for side in ("input", "output")]
        table6[label] = [np.degrees(sel["input_speed_rad_per_s"].mean()),
                         np.degrees(sel["output_speed_rad_per_s"].mean()),
                         outer.mean(), inner.mean() if inner.size else np.nan, *peaks]  # no inner: a pair
        dt = float(np.median(np.diff(sel["time_s"].to_numpy())))
        for side in ("input", "output"):
            axes = ("x", "y") if axis == "max" else (axis,)
            amps = np.max([harmonic_amplitudes(_accel(sel, side, ax), dt, f_mesh, harmonics) for ax in axes], axis=0)
            t7[(label, side)] = amps
    table7 = pd.DataFrame(t7, index=pd.Index(list(harmonics), name="mesh_harmonic"))
    table7.columns = pd.MultiIndex.from_tuples(table7.columns, names=["run", "bearing"])
    table6.attrs["window_s"] = window
    table7.attrs["window_s"] = window
    table7.attrs["mesh_frequency_hz"] = f_mesh
    table7.attrs["axis"] = axis
    return table6, table7


_LOAD_CASE_KEYS = (("t_end_s", "end time [s]"), ("step_size_s", "step [s]"), ("ramp_time_s", "ramp time [s]"),
                   ("theory.input_speed_rad_per_s", "input speed [rad/s]"), ("theory.input_torque_nm",
                                                                             "input torque [N m]"))


def load_case_differences(a: RunResult, b: RunResult, rel: float = 1e-9) -> list[str]:
    """The load-case values in which two runs differ (end time, step, ramps, theory speed and torque):
    compared runs must share their load case, or Tables 6 and 7 compare different things. Two runs continued until
    they settled (``meta["settled"]``) end where each settles: their end times are not compared."""
    def value(meta: dict, dotted: str) -> float | None:
        for key in dotted.split("."):
            meta = meta.get(key) if isinstance(meta, dict) else None
        return None if meta is None else float(meta)

    settled = bool(a.meta.get("settled")) and bool(b.meta.get("settled"))
    out = []
    for key, label in _LOAD_CASE_KEYS:
        if settled and key == "t_end_s":
            continue
        va, vb = value(a.meta, key), value(b.meta, key)
        if va is not None and vb is not None and not math.isclose(va, vb, rel_tol=rel):
            out.append(f"{label} {va:g} vs {vb:g}")
    return out


HARMONIC_PROMINENCE = 10.0
"""A harmonic k of the mesh frequency is "present" when its amplitude is this many times the median
amplitude of the spectrum between (k - 1/2) and (k + 1/2) times the mesh frequency (20 dB)."""


@dataclass(frozen=True)
class BearingSpectrum:
    """Amplitude spectrum of a bearing's x acceleration over a window (:func:`amplitude_spectrum`)."""

    name: str
    side: str
    frequency_hz: np.ndarray
    amplitude: np.ndarray
    mesh_frequency_hz: float

    @classmethod
    def of(cls, result: RunResult, side: str, window: tuple[float, float], label: str | None = None
           ) -> BearingSpectrum:
        sel = _select(result, window)
        dt = float(np.median(np.diff(sel["time_s"].to_numpy())))
        f, a = amplitude_spectrum(_accel(sel, side, "x"), dt)
        return cls(label or result.name, side, f, a, float(result.meta["theory"]["mesh_frequency_hz"]))

    def present(self, max_harmonic: int = 10) -> list[int]:
        """Harmonics k = 1..max_harmonic of the mesh frequency that stand out (HARMONIC_PROMINENCE)."""
        out = []
        for k in range(1, max_harmonic + 1):
            band = np.abs(self.frequency_hz / self.mesh_frequency_hz - k) <= 0.5
            near = np.abs(self.frequency_hz / self.mesh_frequency_hz - k) <= 0.02
            if band.any() and near.any() and self.amplitude[near].max() > HARMONIC_PROMINENCE * np.median(
                    self.amplitude[band]):
                out.append(k)
        return out

    def plot(self, ax, max_harmonic: int = 10, **style) -> None:
        """Log-amplitude spectrum up to max_harmonic + 1/2 times the mesh frequency, in kHz."""
        keep = (self.frequency_hz > 0) & (self.frequency_hz <= (max_harmonic + 0.5) * self.mesh_frequency_hz)
        ax.semilogy(self.frequency_hz[keep] / 1e3, self.amplitude[keep], label=self.name, **{"lw": 0.7, **style})


def mark_harmonics(ax, mesh_frequency_hz: float, present: Sequence[int], highlight: Sequence[int] = ()) -> None:
    """Dashed markers at every harmonic in ``present`` and in ``highlight`` (e.g. a published table's), those in
    red."""
    top = ax.get_ylim()[1]
    for k in sorted(set(present) | set(highlight)):
        red = k in highlight
        ax.axvline(k * mesh_frequency_hz / 1e3, color="#d62728" if red else "#555555", lw=0.8 if red else 0.6,
                   ls="--", alpha=0.8)
        ax.text(k * mesh_frequency_hz / 1e3, top, f"{k}×", color="#d62728" if red else "#555555", fontsize=7.5,
                ha="center", va="bottom", weight="bold" if red else "normal")
