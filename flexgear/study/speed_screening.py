"""Screening over the speed range: each variant's frequency-domain indicator curves against the reference's.

Every variant's steady harmonic response over the speed grid (flexgear.harmonic.harmonic_response: mesh harmonics
1..H, the linearised model at each speed) gives, at each speed n, the indicators of flexgear.study.indicators that
the frequency domain determines:

- ``dynamic_factor`` K_v [-]: the steady waveform's peak mesh force over its static value (flexgear.harmonic);
- ``input_bearing_rms``, ``output_bearing_rms`` [m/s^2]: RMS of the radial bearing acceleration about its mean,
  sqrt(mean(a_x^2 + a_y^2)) = sqrt(sum_h (|A_x,h|^2 + |A_y,h|^2) / 2) (Parseval over the harmonics);
- ``input_bearing_mesh1x``, ``output_bearing_mesh1x`` [m/s^2]: |A_x,1|, the x acceleration at 1x mesh.

Each curve is compared with the reference variant's at the same speed on the scale where the indicator matters,
the scale and TEa of ``[screening.reference_indicators]``: vibration levels in dB, d(n) = 20 log10(y(n) /
y_ref(n)); K_v in % of the mean load, d(n) = 100 (K_v(n) - K_v,ref(n)). A variant's verdict over the range: the
largest |d| / TEa over the indicators and speeds (where and which), and the share of the speed range (speeds of the
grid, each standing for its neighbourhood: the trapezoid weights of the grid) where some indicator exceeds its TEa.
``within`` means no indicator exceeds its TEa anywhere in the range.

The reference is the matrix's screening reference when that is a variant, else the variant with the most flexible
bodies (the all-flexible model 7 of the study's matrix): the frequency domain has no theory values to compare with.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

__all__ = ["SpeedScreening", "speed_indicators", "compare_curves", "speed_screening", "screen_speed_range",
           "SPEED_INDICATORS"]

SPEED_INDICATORS = {"dynamic_factor": "load", "input_bearing_rms": "db", "output_bearing_rms": "db",
                    "input_bearing_mesh1x": "db", "output_bearing_mesh1x": "db"}
"""The frequency-domain indicators screened over the speed range and their scale (module docstring)."""

_UNIT = {"load": "% of load", "db": "dB"}


def speed_indicators(response: Any) -> pd.DataFrame:
    """The indicators of :data:`SPEED_INDICATORS` over the speed grid of ``response`` (a flexgear.harmonic.Response):
    one row per speed [rpm] (index ``speed_rpm``), one column per indicator (SI units, K_v [-])."""
    out = {"dynamic_factor": response.dynamic_factor()}
    for side in ("input", "output"):
        ax = response.amplitudes(f"{side}_bearing_accel_x_m_per_s2")
        ay = response.amplitudes(f"{side}_bearing_accel_y_m_per_s2")
        out[f"{side}_bearing_rms"] = np.sqrt(((ax**2 + ay**2) / 2.0).sum(axis=1))
        out[f"{side}_bearing_mesh1x"] = ax[1]
    frame = pd.DataFrame(out)
    frame.index.name = "speed_rpm"
    return frame


def _difference(value: np.ndarray, reference: np.ndarray, scale: str) -> np.ndarray:
    if scale == "db":
        with np.errstate(divide="ignore", invalid="ignore"):
            return 20.0 * np.log10(value / reference)
    return 100.0 * (value - reference)


def _range_weights(speeds: np.ndarray) -> np.ndarray:
    """Share of the speed range each grid speed stands for (trapezoid weights; equal ones for a single speed)."""
    if speeds.size == 1:
        return np.ones(1)
    w = np.zeros(speeds.size)
    step = np.diff(speeds)
    w[:-1] += 0.5 * step
    w[1:] += 0.5 * step
    return w / w.sum()


@dataclass
class SpeedScreening:
    """The screening over the speed range (module docstring).

    ``table``: one row per variant, speed and indicator: variant, speed_rpm, indicator, value, reference_value,
    difference (in ``unit``), unit, tea, exceeds. ``summary``: one row per variant: variant, worst_indicator,
    worst_difference, unit, worst_speed_rpm, tea, worst_over_tea (|d| / TEa), exceed_share_pct (of the speed
    range), within. ``reference``: the reference variant's name.
    """

    table: pd.DataFrame
    summary: pd.DataFrame
    reference: str

    def lines(self) -> list[str]:
        """One line per variant (the text of speed_screening.txt)."""
        speeds = self.table.speed_rpm
        span = f"{speeds.min():g}-{speeds.max():g} rpm"
        out = []
        for r in self.summary.itertuples():
            if r.variant == self.reference:
                out.append(f"{r.variant}: the reference over {span}")
                continue
            verdict = ("within TEa over the whole range" if r.within else
                       f"exceeds TEa over {r.exceed_share_pct:.0f} % of the range")
            out.append(f"{r.variant}: {verdict} ({span}); largest {r.worst_indicator} {r.worst_difference:+.2f} "
                       f"{r.unit} at {r.worst_speed_rpm:g} rpm (TEa {r.tea:g} {r.unit})")
        return out


def compare_curves(curves: dict[str, pd.DataFrame], reference: str, tea: dict[str, float]) -> SpeedScreening:
    """Each variant's curves (``curves``: name -> :func:`speed_indicators`' frame on the same speed grid) against
    those of ``reference``; ``tea``: indicator -> TEa on its scale (dB, % of load)."""
    if reference not in curves:
        raise ValueError(f"reference {reference!r} is not among the variants ({', '.join(curves)})")
    ref = curves[reference]
    speeds = ref.index.to_numpy(float)
    weights = _range_weights(speeds)
    rows, summary = [], []
    for name, frame in curves.items():
        if not np.array_equal(frame.index.to_numpy(float), speeds):
            raise ValueError(f"{name}: a speed grid other than the reference's")
        worst = (0.0, "", 0.0, speeds[0])  # (|d| / TEa, indicator, d, speed)
        exceed = np.zeros(speeds.size, bool)
        for key, scale in SPEED_INDICATORS.items():
            d = _difference(frame[key].to_numpy(float), ref[key].to_numpy(float), scale)
            d = np.where(np.isfinite(d), d, 0.0)  # both zero (a harmonic the phasing cancels): no difference
            over = np.abs(d) > tea[key]
            exceed |= over
            k = int(np.argmax(np.abs(d)))
            if abs(d[k]) / tea[key] > worst[0] or not worst[1]:
                worst = (abs(d[k]) / tea[key], key, float(d[k]), float(speeds[k]))
            rows.append(pd.DataFrame({"variant": name, "speed_rpm": speeds, "indicator": key,
                                      "value": frame[key].to_numpy(float), "reference_value": ref[key].to_numpy(float),
                                      "difference": d, "unit": _UNIT[scale], "tea": tea[key], "exceeds": over}))
        key = worst[1]
        summary.append({"variant": name, "worst_indicator": key, "worst_difference": worst[2],
                        "unit": _UNIT[SPEED_INDICATORS[key]], "worst_speed_rpm": worst[3], "tea": tea[key],
                        "worst_over_tea": worst[0], "exceed_share_pct": 100.0 * float(weights[exceed].sum()),
                        "within": not exceed.any()})
    return SpeedScreening(pd.concat(rows, ignore_index=True), pd.DataFrame(summary), reference)


def _tea(settings: Any) -> dict[str, float]:
    """TEa of each speed indicator from ``[screening.reference_indicators]``."""
    ri = settings.reference_indicators
    return {key: float(getattr(ri, key).tea) for key in SPEED_INDICATORS}


def _flexible_count(variant: Any) -> int:
    planets = variant.gearbox.gears.planet_count
    return sum((planets if c == "planets" else 1) for c, f in variant.components.items() if f == "flexible")


def speed_screening(variants: Sequence[Any], speeds_rpm: Sequence[float], reference: str = "",
                    harmonics: int | None = None,
                    response: Callable[..., Any] | None = None) -> SpeedScreening:
    """Screen ``variants`` (flexgear.spec.Variant, unique names) over ``speeds_rpm`` [rpm] against ``reference``
    (a name; "" = the one with the most flexible bodies, the first on a tie) with the TEa of the reference's
    ``[screening.reference_indicators]``. ``harmonics``: mesh harmonics (default flexgear.harmonic's);
    ``response(variant, speeds_rpm, harmonics)``: the harmonic response (default flexgear.harmonic.harmonic_response).
    """
    from flexgear.harmonic import harmonic_response
    from flexgear.harmonic.base import DEFAULT_HARMONICS

    names = [v.name for v in variants]
    if len(set(names)) != len(names):
        raise ValueError(f"variant names must be unique: {', '.join(names)}")
    if not reference:
        reference = max(variants, key=_flexible_count).name
    if reference not in names:
        raise ValueError(f"reference {reference!r} is not among the variants ({', '.join(names)})")
    run = response or harmonic_response
    h = DEFAULT_HARMONICS if harmonics is None else int(harmonics)
    curves = {v.name: speed_indicators(run(v, list(speeds_rpm), h)) for v in variants}
    ref = variants[names.index(reference)]
    return compare_curves(curves, reference, _tea(ref.gearbox.screening))


def screen_speed_range(variant_paths: Sequence[str | Path], out_dir: str | Path, speeds_rpm: Sequence[float],
                       reference: str | None = None, harmonics: int | None = None) -> str:
    """:func:`speed_screening` of the variant files into the results folder ``out_dir``: writes
    speed_screening.csv (the table), speed_screening_summary.csv and speed_screening.txt (one line per variant);
    returns the text. ``reference``: None = the gearbox's ``[screening] reference`` (then, if empty, the most
    flexible variant)."""
    from flexgear.cache import atomic_write_bytes
    from flexgear.spec import load_variant
    from flexgear.study.matrix import write_table

    variants = [load_variant(p) for p in variant_paths]
    if not variants:
        raise ValueError("no variants to screen over the speed range")
    ref = reference if reference is not None else variants[0].gearbox.screening.reference
    result = speed_screening(variants, speeds_rpm, ref or "", harmonics)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_table(result.table, out / "speed_screening")
    write_table(result.summary, out / "speed_screening_summary")
    text = "\n".join(result.lines()) + "\n"
    atomic_write_bytes(out / "speed_screening.txt", text.encode())
    return text
