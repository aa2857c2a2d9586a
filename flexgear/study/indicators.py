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
  its peak-to-peak: near integer overlap ratios the steady TE ripple vanishes (the iso6336 law at
  eps_beta near 1) and a relative error of it is meaningless.
- ``transmission_error_mesh1x`` / ``transmission_error_mesh2x`` [m]: amplitude of the transmission error at 1x
  and 2x the mesh frequency (windowed DTFT as for the bearings): the TE's alternating part, the excitation of the
  vibration; judged in dB above a floor (``[screening.reference_indicators]``, ErrorLevelTolerance).

The settled window is :mod:`flexgear.settling`'s test.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from flexgear.settling import mesh_forces, mesh_kinds, radial_rms, ripple_pct, segment_slices
from flexgear.study.compare import harmonic_amplitudes

__all__ = ["STUDY_INDICATORS", "DYNAMIC_INDICATORS", "ALL_INDICATORS", "LEVEL_FLOOR_M_PER_S2", "segment_slices",
           "indicator_segments", "on_scale", "dynamic_factor"]

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
    "transmission_error_mesh1x": "transmission error at 1x mesh",
    "transmission_error_mesh2x": "transmission error at 2x mesh",
}
"""Dynamic indicators of the reference screening: key -> readable name."""

ALL_INDICATORS = {**STUDY_INDICATORS, **DYNAMIC_INDICATORS}

def _sharing(*meshes: np.ndarray) -> float:
    """K_gamma: the largest planet's mean mesh force over the mean of all planets, the largest over the meshes
    (each an array, one column per planet)."""
    return float(max((f.mean(axis=0).max() / f.mean()) for f in meshes))


def dynamic_factor(*meshes: np.ndarray) -> float:
    """K_v: a planet's peak mesh force over its own mean, the largest over planets and the meshes (the sun-planet
    and planet-ring forces; the parallel-axis pair's one mesh)."""
    return float(max((f.max(axis=0) / f.mean(axis=0)).max() for f in meshes))


def indicator_segments(signals: pd.DataFrame, slices: list[slice], mesh_frequency_hz: float,
                       keys: tuple[str, ...] | None = None) -> dict[str, np.ndarray]:
    """Each indicator's value in each segment (module docstring): key -> array over ``slices``.

    ``keys`` restricts the indicators (default: all available; ``transmission_error`` only when the
    ``transmission_error_m`` column exists).
    """
    wanted = tuple(ALL_INDICATORS) if keys is None else keys
    has_te = "transmission_error_m" in signals.columns
    cols = {k: signals[c].to_numpy() for k, c in (("input_speed", "input_speed_rad_per_s"),
                                                   ("output_speed", "output_speed_rad_per_s"),
                                                   ("transmission_ratio", "transmission_ratio"))}
    meshes = {m: mesh_forces(signals, m) for m in mesh_kinds(signals)}  # no inner mesh in the parallel-axis pair
    fo, fi = meshes["outer"], meshes.get("inner")
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
        "outer_mesh_ripple": lambda s: ripple_pct(fo[s]),
        "load_sharing": lambda s: _sharing(*(f[s] for f in meshes.values())),
        "dynamic_factor": lambda s: dynamic_factor(*(f[s] for f in meshes.values())),
        "input_bearing_rms": lambda s: radial_rms(acc["input"][0][s], acc["input"][1][s]),
        "output_bearing_rms": lambda s: radial_rms(acc["output"][0][s], acc["output"][1][s]),
        "input_bearing_mesh1x": one_x("input"),
        "output_bearing_mesh1x": one_x("output"),
    }
    if fi is not None:
        funcs["inner_mesh_force"] = lambda s: float(fi[s].mean())
        funcs["inner_mesh_ripple"] = lambda s: ripple_pct(fi[s])
    if te is not None:
        funcs["transmission_error"] = lambda s: float(te[s].mean())
        for order in (1, 2):
            funcs[f"transmission_error_mesh{order}x"] = lambda s, n=order: float(harmonic_amplitudes(
                te[s], float(np.median(np.diff(t[s]))), mesh_frequency_hz, (n,))[0])
    for s in slices:
        if s.stop - s.start < 4:
            raise ValueError(f"a segment holds {s.stop - s.start} recorded points (at least 4 needed): "
                             "window too short for the sample count")
    return {k: np.array([funcs[k](s) for s in slices]) for k in wanted if k in funcs}


LEVEL_FLOOR_M_PER_S2 = 1e-9
"""Smallest acceleration amplitude [m/s^2] taken to dB (-180 dB re 1 m/s^2): a variant that predicts no
vibration where the reference has some is then far off in dB, not undefined."""


def on_scale(key: str, scale: str, samples: np.ndarray, floor: float | None = None) -> np.ndarray:
    """An indicator's samples on the scale where it is judged (``[screening.reference_indicators]``):

    - "relative": unchanged (the bias is then relative to the reference's value);
    - "load": % of the mean tooth load: the ripples are that already (RMS alternating load / mean load), a load
      factor K (K_gamma, K_v) becomes 100 K, so that a difference is the extra load in % of the mean load;
    - "db": 20 log10(x / 1 SI unit), a level in dB (amplitudes below ``floor``, default LEVEL_FLOOR_M_PER_S2, at
      the floor).
    """
    x = np.asarray(samples, dtype=float)
    if scale == "relative":
        return x
    if scale == "load":
        return x if key.endswith("_ripple") else 100.0 * x
    if scale == "db":
        return 20.0 * np.log10(np.maximum(np.abs(x), LEVEL_FLOOR_M_PER_S2 if floor is None else floor))
    raise ValueError(f"unknown indicator scale {scale!r}; allowed: relative, load, db")
