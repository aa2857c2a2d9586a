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

The acceptable speed band of a purpose (:func:`acceptable_band`, :func:`speed_bands`): the contiguous input-speed
band around the operating speed (the load case's input speed) over which the purpose's selected variant keeps every
frequency-domain indicator of the purpose within its TEa (|d| <= TEa). Between grid speeds each d(n) is taken as
linear (on its own scale, dB or % of load); a limit of the band is the interpolated crossing |d| = TEa, which lies
between the last grid speed within and the first one beyond (named in the band's text): both responses are
continuous in the speed, so the crossing is in that bracket, and its position inside it is uncertain by up to one
grid step. A resonance narrower than the grid step can fall between two grid speeds unseen: the grid's step bounds
what the band can claim.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

__all__ = ["SpeedScreening", "speed_indicators", "compare_curves", "speed_screening", "screened_curves",
           "speed_curve_job", "screen_speed_range",
           "SPEED_INDICATORS", "SpeedBand", "acceptable_band", "speed_bands", "BAND_COLUMNS"]

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


def _reference(variants: Sequence[Any], reference: str) -> str:
    """The reference's name among ``variants`` (unique names): ``reference``, or "" = the one with the most flexible
    bodies, the first on a tie."""
    names = [v.name for v in variants]
    if len(set(names)) != len(names):
        raise ValueError(f"variant names must be unique: {', '.join(names)}")
    if not reference:
        reference = max(variants, key=_flexible_count).name
    if reference not in names:
        raise ValueError(f"reference {reference!r} is not among the variants ({', '.join(names)})")
    return reference


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

    reference = _reference(variants, reference)
    run = response or harmonic_response
    h = DEFAULT_HARMONICS if harmonics is None else int(harmonics)
    return screened_curves(variants, {v.name: speed_indicators(run(v, list(speeds_rpm), h)) for v in variants},
                           reference)


def screened_curves(variants: Sequence[Any], curves: dict[str, pd.DataFrame], reference: str = "") -> SpeedScreening:
    """:func:`compare_curves` of the variants' indicator curves ``curves`` (by name, :func:`speed_indicators`)
    against ``reference`` ("" as in :func:`speed_screening`), with its TEa."""
    reference = _reference(variants, reference)
    ref = next(v for v in variants if v.name == reference)
    return compare_curves(dict(curves), reference, _tea(ref.gearbox.screening))


def speed_curve_job(variant_file: tuple[str, str, str], speeds_rpm: Sequence[float]) -> pd.DataFrame:
    """Worker side: one variant's indicator curves over ``speeds_rpm`` [rpm] (:func:`speed_indicators` of its
    harmonic response, flexgear.harmonic's default harmonics), the variant given as (variant file, its text, its
    gearbox's text); a matrix screens them together (:func:`screened_curves`), each variant a job of its own so that
    a pool's workers share them."""
    from flexgear.harmonic import harmonic_response
    from flexgear.harmonic.base import DEFAULT_HARMONICS
    from flexgear.spec import load_variant

    variant = load_variant(*variant_file)
    return speed_indicators(harmonic_response(variant, list(speeds_rpm), DEFAULT_HARMONICS))


def write_speed_screening(out_dir: str | Path, result: SpeedScreening | BaseException,
                          operating_rpm: float | None) -> str:
    """Write a speed screening ``result`` (:func:`screened_curves`) into the results folder ``out_dir``:
    speed_screening.csv (the table), speed_screening_summary.csv and speed_screening.txt (one line per variant);
    when the folder holds a verdict
    against a reference variant (verdict.csv), also speed_bands.csv (:func:`speed_bands` about ``operating_rpm``,
    the variants' load-case input speed) and one line per band in the text; returns the text. A failed screening
    (the exception as ``result``) is one line in the text."""
    from flexgear.cache import atomic_write_bytes
    from flexgear.study.pool import write_table

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if isinstance(result, BaseException):
        lines = [f"speed screening not done: {type(result).__name__}: {result}"]
    else:
        write_table(result.table, out / "speed_screening")
        write_table(result.summary, out / "speed_screening_summary")
        lines = result.lines()
        bands = speed_bands(out, operating_rpm)
        if bands is not None:
            lines += [f"acceptable speed band, {r.purpose}: {r.text}" for r in bands.itertuples()]
    text = "\n".join(lines) + "\n"
    atomic_write_bytes(out / "speed_screening.txt", text.encode())
    return text


def job_files(variants: Sequence[Any]) -> list[tuple[str, str, str]]:
    """(variant file, its text, its gearbox file's text) of each loaded variant (flexgear.spec.Variant), for the
    pool's jobs (:func:`speed_curve_job`, flexgear.study.matrix.modal_job)."""
    return [(str(v.source), Path(v.source).read_text(), Path(v.gearbox.source).read_text()) for v in variants]


def operating_speed_rpm(variants: Sequence[Any]) -> float | None:
    """The variants' common load-case input speed [rpm], None when they differ."""
    speeds = {float(v.gearbox.load_case.input_speed_rpm) for v in variants}
    return speeds.pop() if len(speeds) == 1 else None


def screen_speed_range(variant_paths: Sequence[str | Path], out_dir: str | Path, speeds_rpm: Sequence[float],
                       reference: str | None = None, harmonics: int | None = None) -> str:
    """:func:`speed_screening` of the variant files into the results folder ``out_dir``
    (:func:`write_speed_screening`); returns the text. ``reference``: None = the gearbox's ``[screening]
    reference`` (then, if empty, the most flexible variant); ``harmonics``: mesh harmonics (default
    flexgear.harmonic's)."""
    from flexgear.spec import load_variant

    variants = [load_variant(p) for p in variant_paths]
    if not variants:
        raise ValueError("no variants to screen over the speed range")
    ref = reference if reference is not None else variants[0].gearbox.screening.reference
    result = speed_screening(variants, speeds_rpm, ref or "", harmonics)
    return write_speed_screening(out_dir, result, operating_speed_rpm(variants))


# --------------------------------------------------------------------------- acceptable speed band
@dataclass(frozen=True)
class SpeedBand:
    """The contiguous speed band around ``operating_rpm`` over which ``variant`` keeps every one of ``indicators``
    within its TEa (module docstring). Speeds in rpm.

    ``low_rpm``, ``high_rpm``: the band's limits (NaN when there is no band: the variant exceeds TEa at the operating
    speed, or the operating speed lies outside the grid); ``grid_low_rpm``, ``grid_high_rpm``: the grid's range;
    ``low_is_grid_end`` / ``high_is_grid_end``: that side of the band reaches the grid's end, so the band extends
    at least that far (the grid does not tell how much further); otherwise the limit is the interpolated crossing of
    ``low_indicator`` / ``high_indicator``, between the grid speeds ``low_bracket_rpm`` / ``high_bracket_rpm``
    (the inner one is the operating speed when no grid speed lies between). ``status``: "band" (bounded on at least
    one side), "whole grid" (within TEa at every grid speed), "fails" (beyond TEa at the operating speed), "off
    grid" (operating speed outside the grid). ``text``: one line.
    """

    variant: str
    indicators: tuple[str, ...]
    operating_rpm: float
    grid_low_rpm: float
    grid_high_rpm: float
    low_rpm: float
    high_rpm: float
    low_is_grid_end: bool
    high_is_grid_end: bool
    status: str
    text: str
    low_indicator: str = ""
    high_indicator: str = ""
    low_bracket_rpm: tuple[float, float] | None = None
    high_bracket_rpm: tuple[float, float] | None = None


def _band_limit(speeds: np.ndarray, diff: np.ndarray, tea: np.ndarray, start_rpm: float, start: np.ndarray,
                ahead: np.ndarray) -> tuple[float, int, tuple[float, float] | None]:
    """Walk from ``start_rpm`` (differences ``start``, all within TEa) over the grid speeds ``ahead`` (indices into
    ``speeds`` / ``diff`` rows, in walking order) until an indicator leaves its TEa. Returns (limit [rpm], the
    indicator's column, -1 at the grid's end; the bracketing speeds [rpm], None at the grid's end)."""
    n_a, d_a = start_rpm, start
    for j in ahead:
        n_b, d_b = float(speeds[j]), diff[j]
        out = ~(np.abs(d_b) <= tea)  # NaN counts as beyond
        if out.any():
            frac = np.full(tea.size, np.inf)
            for i in np.flatnonzero(out):
                if np.isfinite(d_b[i]):
                    bound = np.copysign(tea[i], d_b[i])
                    frac[i] = (bound - d_a[i]) / (d_b[i] - d_a[i])
                else:
                    frac[i] = 0.0  # no value to interpolate to: the last speed known within
            i = int(np.argmin(frac))
            return n_a + float(frac[i]) * (n_b - n_a), i, (min(n_a, n_b), max(n_a, n_b))
        n_a, d_a = n_b, d_b
    return n_a, -1, None


def acceptable_band(table: pd.DataFrame, variant: str, indicators: Sequence[str], operating_rpm: float) -> SpeedBand:
    """The contiguous input-speed band around ``operating_rpm`` [rpm] over which ``variant`` keeps each of
    ``indicators`` within its TEa against the reference (|difference| <= tea), from ``table``: the speed
    screening's table (:attr:`SpeedScreening.table` or speed_screening.csv; columns variant, speed_rpm [rpm],
    indicator, difference and tea on the indicator's scale, unit). Between grid speeds each difference is taken
    as linear in the speed, so the limits are the interpolated crossings |difference| = TEa (module docstring);
    an operating speed between grid speeds is judged on the interpolated differences too."""
    keys = tuple(dict.fromkeys(indicators))
    if not keys:
        raise ValueError(f"{variant}: no indicators to judge over the speed range")
    rows = table[(table.variant == variant) & table.indicator.isin(keys)]
    missing = [k for k in keys if k not in set(rows.indicator)]
    if missing:
        raise ValueError(f"{variant}: not in the speed screening for {', '.join(missing)}")
    diff_frame = rows.pivot(index="speed_rpm", columns="indicator", values="difference").reindex(
        columns=list(keys)).sort_index()
    tea_of = rows.groupby("indicator").tea.first()
    unit_of = rows.groupby("indicator").unit.first()
    speeds = diff_frame.index.to_numpy(float)
    diff = diff_frame.to_numpy(float)
    tea = np.array([float(tea_of[k]) for k in keys])
    lo, hi = float(speeds[0]), float(speeds[-1])
    n0 = float(operating_rpm)
    base = dict(variant=variant, indicators=keys, operating_rpm=n0, grid_low_rpm=lo, grid_high_rpm=hi)
    grid = f"{lo:g}-{hi:g} rpm"
    near = np.isclose(speeds, n0, rtol=1e-9, atol=1e-6)
    if near.any():
        n0 = float(speeds[np.flatnonzero(near)[0]])
        start = diff[np.flatnonzero(near)[0]]
    elif lo < n0 < hi:
        start = np.array([np.interp(n0, speeds, diff[:, i]) for i in range(len(keys))])
    else:
        return SpeedBand(**base, low_rpm=np.nan, high_rpm=np.nan, low_is_grid_end=False, high_is_grid_end=False,
                         status="off grid", text=f"{variant}: operating speed {n0:g} rpm outside the speed grid "
                                                 f"{grid}: no band")
    if not np.all(np.abs(start) <= tea):
        with np.errstate(invalid="ignore"):
            ratio = np.where(np.isfinite(start), np.abs(start) / tea, np.inf)
        i = int(np.argmax(ratio))
        return SpeedBand(**base, low_rpm=np.nan, high_rpm=np.nan, low_is_grid_end=False, high_is_grid_end=False,
                         status="fails", text=f"{variant}: beyond TEa at the operating speed {n0:g} rpm ({keys[i]} "
                                              f"{start[i]:+.2f} {unit_of[keys[i]]}, TEa {tea[i]:g} "
                                              f"{unit_of[keys[i]]}): no band in {grid}")
    low, i_low, br_low = _band_limit(speeds, diff, tea, n0, start, np.flatnonzero(speeds < n0)[::-1])
    high, i_high, br_high = _band_limit(speeds, diff, tea, n0, start, np.flatnonzero(speeds > n0))
    whole = i_low < 0 and i_high < 0
    if whole:
        text = (f"{variant}: within TEa over the whole grid, at least {lo:g}-{hi:g} rpm (operating speed {n0:g} "
                f"rpm; {', '.join(keys)})")
    else:
        def side(limit: float, i: int, bracket: tuple[float, float] | None, end: str) -> str:
            if i < 0:
                return f"{limit:g} rpm or {end} (grid end)"
            return f"{limit:.0f} rpm ({keys[i]} crosses TEa between {bracket[0]:g} and {bracket[1]:g} rpm)"

        text = (f"{variant}: within TEa from {side(low, i_low, br_low, 'lower')} to "
                f"{side(high, i_high, br_high, 'higher')}; operating speed {n0:g} rpm")
    return SpeedBand(**base, low_rpm=low, high_rpm=high, low_is_grid_end=i_low < 0, high_is_grid_end=i_high < 0,
                     status="whole grid" if whole else "band", text=text,
                     low_indicator=keys[i_low] if i_low >= 0 else "",
                     high_indicator=keys[i_high] if i_high >= 0 else "",
                     low_bracket_rpm=br_low, high_bracket_rpm=br_high)


BAND_COLUMNS = ("purpose", "selected", "indicators", "low_rpm", "high_rpm", "operating_rpm", "grid_low_rpm",
                "grid_high_rpm", "text")
"""The columns of speed_bands.csv (:func:`speed_bands`)."""


def _operating_rpm(out: Path, variant: str) -> float:
    """The input speed [rpm] of the load case of the saved run ``out/variant``."""
    import json

    meta = out / variant / "run.json"
    try:
        return float(json.loads(meta.read_text())["spec"]["load_case"]["input_speed_rpm"])
    except (OSError, KeyError, TypeError, ValueError):
        raise ValueError(f"{meta}: no load case input speed to take as the operating speed") from None


def speed_bands(out_dir: str | Path, operating_rpm: float | None = None) -> pd.DataFrame | None:
    """The acceptable speed band (:func:`acceptable_band`) of each purpose of ``out_dir/verdict.csv`` that has
    indicators of :data:`SPEED_INDICATORS`, from ``out_dir/speed_screening.csv``; writes ``speed_bands.csv`` /
    ``.parquet`` (columns :data:`BAND_COLUMNS`: purpose, selected, indicators judged over speed (space-separated),
    low_rpm, high_rpm (empty when there is no band), operating_rpm, grid_low_rpm, grid_high_rpm, text) and returns
    the table. ``operating_rpm`` [rpm]: None = the load case input speed of the selected variant's saved run
    (``out_dir/<selected>/run.json``). Returns None, writing nothing, when the folder has no verdict (screened
    without a reference variant). Raises ValueError when the speed screening was made against another reference
    than the verdict's (the verdict's reference differs from itself in speed_screening.csv)."""
    import json

    from flexgear.study.pool import write_table

    out = Path(out_dir)
    saved = out / "screening.json"
    reference = json.loads(saved.read_text()).get("reference", "") if saved.is_file() else ""
    if not (out / "verdict.csv").is_file() or not reference:
        return None
    table = pd.read_csv(out / "speed_screening.csv")
    ref_rows = table[table.variant == reference]
    if len(ref_rows) and not np.all(ref_rows.difference.fillna(0.0) == 0.0):
        raise ValueError(f"{out}: speed_screening.csv was screened against another reference than verdict.csv "
                         f"({reference})")
    verdict = pd.read_csv(out / "verdict.csv", usecols=["purpose", "selected", "indicators"], dtype=str,
                          keep_default_na=False)
    rows = []
    for purpose, selected, indicators in verdict.itertuples(index=False):
        keys = [k for k in indicators.split() if k in SPEED_INDICATORS]
        if not keys:
            continue
        row = dict(purpose=purpose, selected=selected, indicators=" ".join(keys), low_rpm=np.nan, high_rpm=np.nan,
                   operating_rpm=np.nan, grid_low_rpm=float(table.speed_rpm.min()),
                   grid_high_rpm=float(table.speed_rpm.max()))
        if not selected:
            row["text"] = "no variant selected: no band"
        elif selected not in set(table.variant):
            row["text"] = f"{selected}: not in the speed screening: no band"
        else:
            n0 = operating_rpm if operating_rpm is not None else _operating_rpm(out, selected)
            band = acceptable_band(table, selected, keys, n0)
            row.update(low_rpm=band.low_rpm, high_rpm=band.high_rpm, operating_rpm=band.operating_rpm,
                       grid_low_rpm=band.grid_low_rpm, grid_high_rpm=band.grid_high_rpm, text=band.text)
        rows.append(row)
    bands = pd.DataFrame(rows, columns=list(BAND_COLUMNS))
    write_table(bands, out / "speed_bands")
    return bands
