"""Screening indicators per time segment, and the settled analysis window.

An indicator is a number computed from the signals inside one time segment (flexgear.results
signal columns). The study's five (section 2.2) are segment means; the dynamic ones are what a
gear engineer reads off a run, each computed per segment so that its scatter over the segments
gives its CV like the study's:

- ``outer_mesh_ripple`` / ``inner_mesh_ripple`` [%]: RMS of each planet's mesh force about its
  segment mean, over that mean, averaged over the planets: 100 · mean_i( std_t F_i / mean_t F_i ).
- ``load_sharing`` [-]: load-sharing factor K_gamma (ISO 6336-1 sec. 6.3 for planetary sets): the
  largest planet's mean mesh force over the mean of all planets, the larger of the two meshes.
- ``dynamic_factor`` [-]: dynamic factor K_v (ISO 6336-1 sec. 6): the peak mesh force of a planet
  over its own mean (peak dynamic over static load), the largest over planets and both meshes.
- ``input_bearing_rms`` / ``output_bearing_rms`` [m/s^2]: RMS of the radial bearing acceleration
  about its mean, sqrt(mean((a_x - ā_x)^2 + (a_y - ā_y)^2)).
- ``input_bearing_mesh1x`` / ``output_bearing_mesh1x`` [m/s^2]: amplitude of a_x at the mesh
  frequency (windowed DTFT, flexgear.study.compare.harmonic_amplitudes; Table 7's 1x row).
- ``transmission_error`` [m]: the loaded transmission error, segment mean of ``transmission_error_m``
  (the static TE under load, which the compliance of gears, shafts and supports sets directly;
  present only when the backend records it, otherwise left out and its weight shared out). Not
  its peak-to-peak: near integer overlap ratios the steady TE ripple vanishes (below 0.1 nm with
  the iso6336 law at eps_beta = 0.95, model 1) and a relative error of it is meaningless.

Settled window (``[screening] window = "settled"``, :func:`settled_start`): after the STEP ramps
the run is cut into blocks of ``settle_block_mesh_cycles`` mesh cycles. Each settling signal gets
one value per block: the planet-mean mesh forces and the two speeds their block means (a drift),
the mesh-force ripples and bearing accelerations RMS their block values (a decaying vibration).
Its final value is the mean of the last ``settle_final_blocks`` blocks, and must differ from
the mean of the blocks just before by at most the tolerance (else the run has not settled). The
run has settled at the start of the first block after which every later block of every settling
signal lies within the tolerance of its final value, if at least ``sample_count`` blocks remain:
``settle_mean_tolerance_pct`` for the drifts, ``settle_amplitude_tolerance_pct`` for the
vibrations. For y = A + B e^(-t/tau) this is the first block start t with |B| e^(-t/tau) <= tol |A|
(to a block), tau·ln(|B| / (tol |A|)).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from flexgear.study.compare import harmonic_amplitudes

__all__ = ["STUDY_INDICATORS", "DYNAMIC_INDICATORS", "ALL_INDICATORS", "segment_slices", "indicator_segments",
           "settled_start", "SETTLING_SIGNALS"]

STUDY_INDICATORS: dict[str, str] = {
    "input_speed": "input speed",
    "output_speed": "output speed",
    "transmission_ratio": "transmission ratio",
    "outer_mesh_force": "outer (sun-planet) mesh force",
    "inner_mesh_force": "inner (planet-ring) mesh force",
}
"""The study's five indicators (section 2.2): key -> readable name."""

DYNAMIC_INDICATORS: dict[str, str] = {
    "outer_mesh_ripple": "outer mesh-force ripple",
    "inner_mesh_ripple": "inner mesh-force ripple",
    "load_sharing": "load-sharing factor K_gamma",
    "dynamic_factor": "dynamic factor K_v",
    "input_bearing_rms": "input bearing accel. RMS",
    "output_bearing_rms": "output bearing accel. RMS",
    "input_bearing_mesh1x": "input bearing accel. at 1x mesh",
    "output_bearing_mesh1x": "output bearing accel. at 1x mesh",
    "transmission_error": "loaded transmission error (mean)",
}
"""Dynamic indicators of the reference screening: key -> readable name."""

ALL_INDICATORS = {**STUDY_INDICATORS, **DYNAMIC_INDICATORS}

SETTLING_SIGNALS = {"mean": ("input_speed", "output_speed", "outer_mesh_force", "inner_mesh_force"),
                    "amplitude": ("outer_mesh_ripple", "inner_mesh_ripple", "input_bearing_rms",
                                  "output_bearing_rms")}
"""Signals of the settling test: drifts (mean tolerance) and vibrations (amplitude tolerance). Not the
loaded transmission error: it integrates the output-speed error, so the last 0.01 % of the speed's
creep moves it by more than 0.05 % long after the speeds and forces have settled (impact law, quick
runs: about 1 % over 0.1 s); it is screened over the window the other signals set."""


def segment_slices(t: np.ndarray, start: float, end: float, count: int) -> list[slice]:
    """Index ranges of ``count`` equal contiguous segments of [start, end] in the sorted times ``t``
    (the end point joins the last segment)."""
    edges = np.linspace(start, end, count + 1)
    idx = np.searchsorted(t, edges, side="left")
    idx[-1] = np.searchsorted(t, end, side="right")
    return [slice(int(a), int(b)) for a, b in zip(idx[:-1], idx[1:], strict=True)]


def _forces(signals: pd.DataFrame, mesh: str) -> np.ndarray:
    cols = [c for c in signals.columns if c.startswith(f"{mesh}_mesh_force_") and c.endswith("_n")]
    if not cols:
        raise ValueError(f"signal table has no {mesh}_mesh_force_<i>_n columns")
    return signals[cols].to_numpy()


def _ripple(f: np.ndarray) -> float:
    return float(np.mean(f.std(axis=0) / f.mean(axis=0)) * 100.0)


def _sharing(fo: np.ndarray, fi: np.ndarray) -> float:
    return float(max((f.mean(axis=0).max() / f.mean()) for f in (fo, fi)))


def _kv(fo: np.ndarray, fi: np.ndarray) -> float:
    return float(max((f.max(axis=0) / f.mean(axis=0)).max() for f in (fo, fi)))


def _rms(ax: np.ndarray, ay: np.ndarray) -> float:
    return float(np.sqrt(np.mean((ax - ax.mean()) ** 2 + (ay - ay.mean()) ** 2)))


def indicator_segments(signals: pd.DataFrame, slices: list[slice], mesh_frequency_hz: float,
                       keys: tuple[str, ...] | None = None) -> dict[str, np.ndarray]:
    """Each indicator's value in each segment (module docstring): key -> array over ``slices``.

    ``keys`` restricts the indicators (default: all available; ``transmission_error`` only when the
    ``transmission_error_m`` column exists).
    """
    wanted = tuple(ALL_INDICATORS) if keys is None else keys
    has_te = "transmission_error_m" in signals.columns
    cols = {k: signals[c].to_numpy() for k, c in (("input_speed", "input_speed_deg_per_s"),
                                                   ("output_speed", "output_speed_deg_per_s"),
                                                   ("transmission_ratio", "transmission_ratio"))}
    fo, fi = _forces(signals, "outer"), _forces(signals, "inner")
    acc = {side: (signals[f"{side}_bearing_accel_x_m_per_s2"].to_numpy(),
                  signals[f"{side}_bearing_accel_y_m_per_s2"].to_numpy()) for side in ("input", "output")}
    t = signals["time_s"].to_numpy()
    te = signals["transmission_error_m"].to_numpy() if has_te else None

    def one_x(side: str) -> Callable[[slice], float]:
        def f(s: slice) -> float:
            dt = float(np.median(np.diff(t[s])))
            return float(harmonic_amplitudes(acc[side][0][s], dt, mesh_frequency_hz, (1,))[0])
        return f

    funcs: dict[str, Callable[[slice], float]] = {
        **{k: (lambda s, y=y: float(y[s].mean())) for k, y in cols.items()},
        "outer_mesh_force": lambda s: float(fo[s].mean()),
        "inner_mesh_force": lambda s: float(fi[s].mean()),
        "outer_mesh_ripple": lambda s: _ripple(fo[s]),
        "inner_mesh_ripple": lambda s: _ripple(fi[s]),
        "load_sharing": lambda s: _sharing(fo[s], fi[s]),
        "dynamic_factor": lambda s: _kv(fo[s], fi[s]),
        "input_bearing_rms": lambda s: _rms(acc["input"][0][s], acc["input"][1][s]),
        "output_bearing_rms": lambda s: _rms(acc["output"][0][s], acc["output"][1][s]),
        "input_bearing_mesh1x": one_x("input"),
        "output_bearing_mesh1x": one_x("output"),
    }
    if te is not None:
        funcs["transmission_error"] = lambda s: float(te[s].mean())
    for s in slices:
        if s.stop - s.start < 4:
            raise ValueError(f"a segment holds {s.stop - s.start} recorded points (at least 4 needed): "
                             "window too short for the sample count")
    return {k: np.array([funcs[k](s) for s in slices]) for k in wanted if k in funcs}


def settled_start(signals: pd.DataFrame, after_s: float, mesh_frequency_hz: float, block_cycles: int,
                  final_blocks: int, mean_tol_pct: float, amplitude_tol_pct: float,
                  min_blocks: int = 1) -> tuple[float | None, str]:
    """Start [s] of the settled part of a run (module docstring), or None if it does not settle.

    Returns (start, explanation); ``after_s`` is the end of the ramps. Besides the band test, the
    final value itself must have stopped moving: the mean of the last ``final_blocks`` blocks may
    differ from the mean of the ``final_blocks`` before them by at most the tolerance (for a decay
    with a time constant near the two groups' length this bounds the residual to about 1.4
    tolerances), and the settled part must hold at least ``min_blocks`` blocks (the screening
    asks for one block per sample).
    """
    t = signals["time_s"].to_numpy()
    block = block_cycles / mesh_frequency_hz
    count = int((t[-1] - after_s) // block)
    if count < max(2 * final_blocks, min_blocks):
        return None, (f"not settled: only {max(count, 0)} blocks of {block_cycles} mesh cycles ({1e3 * block:.3g} "
                      f"ms) after the ramps at {after_s:g} s; the settling test needs "
                      f"{max(2 * final_blocks, min_blocks)}")
    starts = t[-1] - block * np.arange(count, 0, -1)
    slices = [slice(int(a), int(b)) for a, b in zip(np.searchsorted(t, starts), np.searchsorted(t, starts + block),
                                                    strict=True)]
    keys = SETTLING_SIGNALS["mean"] + SETTLING_SIGNALS["amplitude"]
    values = indicator_segments(signals, slices, mesh_frequency_hz, keys)   # TE only if recorded
    first_ok = 0
    slowest = ""
    for kind, tol in (("mean", mean_tol_pct), ("amplitude", amplitude_tol_pct)):
        for key in (k for k in SETTLING_SIGNALS[kind] if k in values):
            v = values[key]
            final = v[-final_blocks:].mean()
            if abs(final - v[-2 * final_blocks:-final_blocks].mean()) > tol / 100.0 * abs(final):
                return None, (f"not settled: the final value of {key} still moves by more than {tol:g} % between "
                              f"the last two groups of {final_blocks} blocks of {block_cycles} mesh cycles")
            bad = np.flatnonzero(np.abs(v - final) > tol / 100.0 * abs(final))
            k = int(bad[-1]) + 1 if bad.size else 0
            if k > first_ok:
                first_ok, slowest = k, key
    if count - first_ok < min_blocks:
        return None, (f"not settled: {slowest} settles {count - first_ok} blocks of {block_cycles} mesh cycles "
                      f"before the end; the window needs {min_blocks}")
    start = float(starts[first_ok])
    why = (f"settled at {start:.4g} s: every later block of {block_cycles} mesh cycles within "
           f"{mean_tol_pct:g} % (speeds, mean forces) and {amplitude_tol_pct:g} % (ripple, bearing RMS) of its "
           f"final value" + (f"; slowest: {slowest}" if slowest else ""))
    return start, why
