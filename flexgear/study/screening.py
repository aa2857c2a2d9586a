"""Westgard screening of model variants (section 2.2 of the study): inaccuracy, imprecision, zones.

The study screens its seven multibody variants with the Westgard method decision chart and the
"relative error distance method of speed, transmission ratio and meshing force". This module is
that arithmetic as small pure functions; everything configurable comes from
:class:`flexgear.spec.ScreeningSettings` (``[screening]`` in gearbox.toml).

Samples
    The analysis window [t0, t1] (default: the steady part after the STEP ramps) is cut into
    ``sample_count`` equal, contiguous time segments. One *sample* of an indicator is the
    arithmetic mean of its recorded values inside one segment (recording is at a constant step,
    so this is the segment's time average); the ripple at mesh frequency averages out inside a
    segment, what remains between samples is drift and slow oscillation: the signal's
    unsteadiness, which the study says a single window mean hides.

Per indicator (input speed, output speed, transmission ratio, outer and inner mesh force; the
mesh forces are first averaged over the planets at every step), with the sample means x_k,
their mean x̄ and the theoretical value x_th:

- inaccuracy  Bias % = |x̄ - x_th| / |x_th| · 100
- imprecision CV %   = s / |x̄| · 100, s the sample standard deviation (ddof = 1) of the x_k

Composite point of a variant: Bias_c = Σ w_i Bias_i and CV_c = Σ w_i CV_i (w_i = 0.2 each,
"taking 20 % of each of the five simulation indicators"); its relative error distance is
d = sqrt(Bias_c² + CV_c²), the distance from the diagram's origin.

Decision lines Bias + m·CV = TEa (m = 2, 3, 4 by default; 2…6 for the Six-Sigma chart) split the
plane into zones. A point satisfies line m when Bias + m·CV <= TEa; a point exactly on a line
belongs to the better zone (the line's criterion is met; a relative tolerance of 1e-12 absorbs
round-off). The zone is the number of lines met: 0 = non-conforming ... The sigma metric is
(TEa - Bias) / CV. The study draws Bias on x and CV on y; Westgard's charts swap the axes.

Reference mode (``[screening] reference = "model7"`` or ``flexgear matrix --reference model7``): the
five study indicators are fixed by kinematics and torque balance and cannot tell flexible from
rigid variants apart, so the dynamic indicators of :mod:`flexgear.study.indicators` join them and
every Bias is taken against the reference variant's mean (the reference has Bias 0 and sits on
the CV axis). Each indicator i has its own TEa_i (``[screening.reference_indicators]``) and is judged
alone: the verdict is per purpose (:mod:`flexgear.study.purposes`), a variant's zone the zone of its
weakest indicator. The weighted composite Bias_c = Σ w_i Bias_i / TEa_i · 100 (CV_c likewise, in % of
TEa) is kept as a summary distance only; it decides nothing.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from flexgear.results import RunResult
from flexgear.settling import SettleRule, Settling, settled_start
from flexgear.spec import ScreeningSettings
from flexgear.study.indicators import STUDY_INDICATORS, indicator_segments, on_scale, segment_slices
from flexgear.study.purposes import (
    ALL_PURPOSES,
    STUDY_PURPOSE,
    PurposeVerdict,
    judge_purposes,
    mark_resolved,
    purpose_selection,
)
from flexgear.study.selection import DecisionLines, Selection, select_variant

__all__ = ["INDICATORS", "DecisionLines", "Window", "IndicatorResult", "VariantScreening", "Selection",
           "analysis_window", "sample_means", "bias_pct", "cv_pct", "sigma_metric", "indicator_samples", "Screening",
           "screen", "screen_result", "screening_tables", "select_variant", "scaled_bias_cv", "scaled_bias",
           "run_window", "reference_means", "UnsettledReference", "ReferenceNotUsable", "numerical_error"]

INDICATORS: dict[str, str] = STUDY_INDICATORS
"""The study's five indicators (section 2.2): key -> readable name."""

_THEORY_KEYS = {
    "input_speed": "input_speed_rad_per_s",
    "output_speed": "output_speed_rad_per_s",
    "transmission_ratio": "ratio",
    "outer_mesh_force": "mesh_force_n",
    "inner_mesh_force": "mesh_force_n",
}



def sigma_metric(bias: float, cv: float, tea: float) -> float:
    """Sigma metric (TEa - Bias) / CV; +inf for a point with CV = 0 inside TEa."""
    if cv > 0.0:
        return (tea - bias) / cv
    return math.inf if bias < tea else (0.0 if bias == tea else -math.inf)


# --------------------------------------------------------------------------- samples
@dataclass(frozen=True)
class Window:
    """Analysis window [start_s, end_s]; ``steady`` is False when the run ended before the ramps or (window
    "settled") has not settled, ``settling`` the settling test's outcome then."""

    start_s: float
    end_s: float
    steady: bool
    rule: str
    settling: Settling | None = None


def analysis_window(meta: dict, t_first: float, t_last: float, settings: ScreeningSettings,
                    signals: pd.DataFrame | None = None) -> Window:
    """The window of a run per ``settings.window`` (see gearbox.toml ``[screening]``).

    ``"settled"`` needs the run's ``signals`` (flexgear.settling.settled_start); a run that
    does not settle is screened after its ramps and marked not steady.
    """
    if settings.window == "settled" and signals is not None:
        ramp = float(meta.get("ramp_time_s", 0.0)) + settings.after_ramp_delay_s
        f_mesh = float((meta.get("theory") or {}).get("mesh_frequency_hz", 0.0))
        if ramp < t_last and f_mesh > 0:
            test = settled_start(signals, max(ramp, t_first), f_mesh, SettleRule.from_settings(settings))
            if test.settled:
                return Window(test.start_s, t_last, True, test.reason, test)
            return Window(max(ramp, t_first), t_last, False, f"after the ramps, {ramp:g}-{t_last:g} s, NOT steady: "
                          + test.reason, test)
    if settings.window == "fixed":
        start, end = max(settings.window_start_s, t_first), min(settings.window_end_s, t_last)
        if end <= start:
            raise ValueError(f"screening window [{settings.window_start_s}, {settings.window_end_s}] s lies "
                             f"outside the run [{t_first}, {t_last}] s")
        return Window(start, end, True, f"fixed window {start:g}-{end:g} s")
    ramp = float(meta.get("ramp_time_s", 0.0)) + settings.after_ramp_delay_s
    if ramp < t_last:
        start = max(ramp, t_first)
        return Window(start, t_last, True, f"steady part after the ramps, {start:g}-{t_last:g} s")
    start = t_last - settings.short_run_fraction * (t_last - t_first)
    return Window(start, t_last, False,
                  f"run ends ({t_last:g} s) before the ramps ({ramp:g} s): last "
                  f"{settings.short_run_fraction:.0%} of the run, {start:g}-{t_last:g} s, NOT steady")


def sample_means(t: np.ndarray, y: np.ndarray, window: Window, count: int) -> np.ndarray:
    """Mean of ``y`` in each of ``count`` equal contiguous segments of the window (the samples)."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    edges = np.linspace(window.start_s, window.end_s, count + 1)
    seg = np.searchsorted(edges, t, side="right") - 1
    seg[t == window.end_s] = count - 1  # the window's end point belongs to the last segment
    inside = (seg >= 0) & (seg < count)
    counts = np.bincount(seg[inside], minlength=count)
    if np.any(counts == 0):
        raise ValueError(f"window {window.start_s:g}-{window.end_s:g} s is too short for {count} samples "
                         f"({int(inside.sum())} recorded points)")
    return np.bincount(seg[inside], weights=y[inside], minlength=count) / counts


def bias_pct(mean: float, theory: float) -> float:
    """Inaccuracy |mean - theory| / |theory| · 100 (%)."""
    return abs(mean - theory) / abs(theory) * 100.0


def cv_pct(samples: np.ndarray) -> float:
    """Imprecision: sample standard deviation (ddof = 1) / |mean| · 100 (%)."""
    samples = np.asarray(samples, dtype=float)
    return float(np.std(samples, ddof=1) / abs(np.mean(samples)) * 100.0)


# --------------------------------------------------------------------------- one variant
@dataclass(frozen=True)
class IndicatorResult:
    """One indicator of one run on its judging scale: target (theory or the reference), mean of the samples,
    Bias, CV and TEa in ``unit`` ("%" relative to the target, "% of load", "dB"), and the samples."""

    name: str
    theory: float
    mean: float
    bias: float
    cv: float
    samples: tuple[float, ...]
    tea: float = math.nan
    weight: float = math.nan
    unit: str = "%"


@dataclass(frozen=True)
class VariantScreening:
    """Composite Westgard point of one run."""

    variant: str
    window: Window
    indicators: dict[str, IndicatorResult]
    bias_pct: float
    cv_pct: float
    distance_pct: float
    sigma: float
    zone: str
    zone_rank: int


def run_window(result: RunResult, settings: ScreeningSettings) -> Window:
    """The analysis window of a finished run (:func:`analysis_window` over its own signals)."""
    if not result.ok or result.signals is None:
        raise ValueError(f"{result.name}: run did not finish ({result.meta.get('reason')})")
    t = result.signals["time_s"].to_numpy()
    return analysis_window(result.meta, float(t[0]), float(t[-1]), settings, result.signals)


def indicator_samples(result: RunResult, settings: ScreeningSettings, keys: tuple[str, ...] | None = None,
                      window: Window | None = None) -> tuple[Window, dict[str, np.ndarray]]:
    """The run's window (``window`` when already known) and each indicator's samples in it (``sample_count``
    segments)."""
    window = run_window(result, settings) if window is None else window
    t = result.signals["time_s"].to_numpy()
    slices = segment_slices(t, window.start_s, window.end_s, settings.sample_count)
    f_mesh = float(result.meta["theory"]["mesh_frequency_hz"])
    return window, indicator_segments(result.signals, slices, f_mesh, keys)


_UNITS = {"relative": "%", "load": "% of load", "db": "dB"}


def scaled_bias_cv(samples: np.ndarray, target: float, scale: str) -> tuple[float, float]:
    """Bias and CV of samples already on their judging scale (indicators.on_scale): relative to the target in %
    for the "relative" scale (Bias = |mean - target| / |target| 100, CV = s / |mean| 100), otherwise absolute in
    the scale's unit (Bias = |mean - target|, CV = s), s the sample standard deviation (ddof = 1)."""
    cv = cv_pct(samples) if scale == "relative" else float(np.std(samples, ddof=1))
    return scaled_bias(float(np.mean(samples)), target, scale), cv


def scaled_bias(mean: float, target: float, scale: str) -> float:
    """Bias of a mean on its judging scale: |mean - target| / |target| 100 (%) on the "relative" scale, otherwise
    |mean - target| in the scale's unit."""
    return bias_pct(mean, target) if scale == "relative" else abs(mean - target)


def screen_result(result: RunResult, settings: ScreeningSettings,
                  reference: dict[str, float] | None = None, window: Window | None = None) -> VariantScreening:
    """Screen one finished run.

    ``reference`` None: the study's mode, the five indicators against ``result.meta["theory"]``,
    composite Bias and CV the weighted sums in % (the weights of the indicators present rescaled to sum 1 where the
    stage lacks one: the parallel-axis pair's inner mesh). Otherwise the reference variant's indicator means on their
    judging scales (:func:`reference_means`): every indicator both runs have, each Bias and CV on its scale and
    divided by its own TEa (``[screening.reference_indicators]``), composite = weighted sum in % of TEa (weights
    of the indicators present, rescaled to sum 1).
    """
    lines = DecisionLines.from_settings(settings, "ref" if reference is not None else "")
    if reference is None:
        window, samples = indicator_samples(result, settings, tuple(INDICATORS), window)
        theory = result.meta["theory"]
        targets = {k: float(theory[_THEORY_KEYS[k]]) for k in samples}
        weights = dataclasses.asdict(settings.weights)
        if set(samples) < set(weights):  # an indicator the stage has not (the parallel-axis pair's inner mesh)
            present = sum(weights[k] for k in samples)
            weights = {k: weights[k] / present for k in samples}
        tols = dict.fromkeys(samples, (settings.allowable_total_error_pct, "relative"))
    else:
        window, samples = indicator_samples(result, settings, window=window)
        tol = {k: getattr(settings.reference_indicators, k) for k in samples if k in reference}
        samples = {k: on_scale(k, tol[k].scale, v, tol[k].floor) for k, v in samples.items() if k in tol}
        targets = {k: float(reference[k]) for k in samples}
        total = sum(t.weight for t in tol.values())
        weights = {k: t.weight / total for k, t in tol.items()}
        tols = {k: (t.tea, t.scale) for k, t in tol.items()}
    indicators = {}
    for key, x in samples.items():
        tea, scale = tols[key]
        bias, cv = scaled_bias_cv(x, targets[key], scale)
        indicators[key] = IndicatorResult(key, targets[key], float(np.mean(x)), bias, cv, tuple(map(float, x)), tea,
                                          weights[key], _UNITS[scale])
    norm = {k: (100.0 / r.tea if lines.normalised else 1.0) for k, r in indicators.items()}
    bias = sum(weights[k] * r.bias * norm[k] for k, r in indicators.items())
    cv = sum(weights[k] * r.cv * norm[k] for k, r in indicators.items())
    return VariantScreening(result.name, window, indicators, bias, cv, math.hypot(bias, cv),
                            sigma_metric(bias, cv, lines.tea_pct), lines.zone(bias, cv), lines.rank(bias, cv))


# --------------------------------------------------------------------------- many variants
def _run_time(meta: dict) -> float:
    """Time a variant is judged by [s]: the runner's CPU time of the run (model build and simulation), its wall
    time when no CPU time is recorded. CPU time, because the matrix runs variants side by side on shared cores:
    their wall times include waiting for a core, which depends on what else ran, not on the model."""
    value = meta.get("cpu_time_s", meta.get("wall_time_s"))
    return float(value) if value is not None else math.nan


@dataclass(frozen=True)
class Screening:
    """A screened set of runs: one row per run (``table``), one per run and indicator
    (``indicators``), the selection, the decision lines and the reference variant ("" = theory)."""

    table: pd.DataFrame
    indicators: pd.DataFrame
    selection: Selection
    lines: DecisionLines
    reference: str = ""
    verdicts: tuple[PurposeVerdict, ...] = ()   # reference mode: one per purpose, then ALL_PURPOSES
    purpose_zones: pd.DataFrame | None = None    # reference mode: flexgear.study.purposes.purpose_zones

    def plot(self, ax, xlim: float | None = None, ylim: float | None = None, title: str = "") -> list[str]:
        """Westgard decision diagram: in the study's mode the composite points (numbered markers,
        flexgear.study.diagram.decision_diagram; legend lines "n: variant ..."), against a reference every
        indicator's own normalised point (flexgear.study.diagram.indicator_diagram; legend lines per variant)."""
        from flexgear.study.diagram import decision_diagram, indicator_diagram

        if self.reference and len(self.indicators):
            purposes = [v.purpose for v in self.verdicts if v.purpose != ALL_PURPOSES]
            return indicator_diagram(ax, self.indicators, self.lines, purposes, xlim or 200.0, ylim or 60.0, title)
        return decision_diagram(ax, self.table, self.lines, xlim, ylim, title)


def numerical_error(reference: RunResult, settings: ScreeningSettings) -> tuple[float, dict[str, float]]:
    """The reference's numerical error: its final state's window solved at h and at h/2 (extra tables
    ``error_step``, ``error_half_step`` of flexgear.mbs.run.numerical_error_windows). Per indicator, the change
    of its window mean on its judging scale (absolute, or in % for the relative scale); composite e = sum_i w_i
    e_i / TEa_i 100 in % of TEa, with the reference screening's weights. (nan, {}) without the two windows."""
    coarse, fine = reference.extra.get("error_step"), reference.extra.get("error_half_step")
    if coarse is None or fine is None:
        return math.nan, {}
    f_mesh = float(reference.meta["theory"]["mesh_frequency_hz"])
    tol = settings.reference_indicators
    means = []
    for table in (coarse, fine):
        t = table["time_s"].to_numpy()
        samples = indicator_segments(table, segment_slices(t, float(t[0]), float(t[-1]), settings.sample_count),
                                     f_mesh)
        means.append({k: float(np.mean(on_scale(k, getattr(tol, k).scale, v, getattr(tol, k).floor)))
                      for k, v in samples.items()})
    errors = {k: scaled_bias(means[1][k], means[0][k], getattr(tol, k).scale) for k in means[0] if k in means[1]}
    total = sum(getattr(tol, k).weight for k in errors)
    return sum(getattr(tol, k).weight / total * e / getattr(tol, k).tea * 100.0 for k, e in errors.items()), errors


class ReferenceNotUsable(ValueError):
    """The screening's reference did not finish or has not settled: nothing can be screened against it."""


class UnsettledReference(ReferenceNotUsable):
    """The screening's reference has not settled."""


def _unsettled_reason(result: RunResult, settings: ScreeningSettings, window: Window) -> str:
    """Why a finished run cannot be screened as settled ('' when it can): the runner's own settling test
    (``[load_case] end = "settled"``) or, with ``window = "settled"``, its ``window``'s."""
    if result.meta.get("settled") is False:
        return str(result.meta.get("settle_reason") or "not settled")
    if settings.window != "settled" or window.steady:
        return ""
    return window.settling.reason if window.settling else window.rule


def reference_means(results: list[RunResult], name: str, settings: ScreeningSettings) -> dict[str, float]:
    """The reference variant's indicator means on their judging scales (indicators.on_scale). Raises when it is
    missing or failed, and :class:`UnsettledReference` with a one-line reason when it has not settled."""
    ref = next((r for r in results if r.name == name), None)
    if ref is None:
        raise ValueError(f"screening reference {name!r} is not among the runs "
                         f"({', '.join(r.name for r in results) or 'none'})")
    if not ref.ok:
        raise ReferenceNotUsable(f"not screened: reference {name} did not finish ({ref.meta.get('reason')})")
    window = run_window(ref, settings)
    why = _unsettled_reason(ref, settings, window)
    if why:
        raise UnsettledReference(f"not screened: reference {name} has not settled by "
                                 f"{float(ref.meta.get('t_end_s', math.nan)):.4g} s ({why}); run it longer "
                                 "(--t-end settled)")
    _, samples = indicator_samples(ref, settings, window=window)
    tol = settings.reference_indicators
    return {k: float(np.mean(on_scale(k, getattr(tol, k).scale, v, getattr(tol, k).floor))) for k, v in samples.items()}


def screen(results: Iterable[RunResult], settings: ScreeningSettings, reference: str | None = None) -> Screening:
    """Screen runs in the study's mode (``reference`` "") or against a reference variant (its name);
    default ``settings.reference``.

    Failed runs, and runs whose signals cannot be screened, get a row with status "failed" and their reason;
    runs that have not settled (:func:`_unsettled_reason`) get status "unsettled" and are not scored. None of
    them is a candidate for selection. A missing or failed reference raises ValueError, an unsettled one
    :class:`UnsettledReference`.
    """
    results = list(results)
    ref_name = settings.reference if reference is None else reference
    lines = DecisionLines.from_settings(settings, ref_name)
    ref = reference_means(results, ref_name, settings) if ref_name else None
    rows, ind_rows = [], []
    for res in results:
        row = {"variant": res.name, "status": res.meta.get("status", "failed"),
               "reason": res.meta.get("reason") or "", "time_s": _run_time(res.meta),
               "t_end_s": res.meta.get("t_end_s", math.nan)}
        try:
            window = run_window(res, settings) if res.ok else None
        except (ValueError, KeyError) as exc:
            row.update(status="failed", reason=f"screening: {exc}")
            window = None
        why = _unsettled_reason(res, settings, window) if window is not None else ""
        if why:
            row.update(status="unsettled", reason=why)
        elif window is not None:
            try:
                s = screen_result(res, settings, ref, window)
            except (ValueError, KeyError) as exc:
                row.update(status="failed", reason=f"screening: {exc}")
            else:
                row.update(bias_pct=s.bias_pct, cv_pct=s.cv_pct, distance_pct=s.distance_pct, sigma=s.sigma,
                           zone=s.zone, zone_rank=s.zone_rank, steady_window=s.window.steady,
                           window_start_s=s.window.start_s, window_end_s=s.window.end_s, window_rule=s.window.rule)
                for r in s.indicators.values():
                    ind_rows.append({"variant": res.name, "indicator": r.name, "target": r.theory, "mean": r.mean,
                                     "bias": r.bias, "cv": r.cv, "tea": r.tea, "unit": r.unit,
                                     "weight": r.weight, "sigma": sigma_metric(r.bias, r.cv, r.tea),
                                     "zone": DecisionLines(r.tea, lines.multipliers).zone(r.bias, r.cv)})
        rows.append(row)
    columns = ["variant", "status", "reason", "bias_pct", "cv_pct", "distance_pct", "sigma", "zone", "zone_rank",
               "time_s", "t_end_s", "steady_window", "window_start_s", "window_end_s", "window_rule"]
    table = pd.DataFrame(rows).reindex(columns=columns)
    indicators = pd.DataFrame(ind_rows, columns=["variant", "indicator", "target", "mean", "bias", "cv", "tea", "unit",
                                                 "weight", "sigma", "zone"])
    over = indicators[indicators["bias"] > indicators["tea"]]
    table["outside_tea"] = [", ".join(f"{r.indicator} {r.bias:.3g} {r.unit} (TEa {r.tea:g})"
                                      for r in over[over["variant"] == v].itertuples()) for v in table["variant"]]
    if not ref_name:
        indicators["purpose"] = STUDY_PURPOSE
        selection = select_variant(table, settings.selection, lines, ref_name)
        table["selected"] = table["variant"] == selection.variant
        return Screening(table, indicators, selection, lines, ref_name)
    error, errors = numerical_error(next(r for r in results if r.name == ref_name), settings)
    purpose_of = {k: p for p, keys in settings.purposes.items() for k in keys}
    indicators["purpose"] = indicators["indicator"].map(purpose_of).fillna("reported")
    zones, verdicts = judge_purposes(indicators, table, settings.purposes, lines, ref_name, errors)
    ok = table["status"] == "ok"
    weakest = zones.groupby("variant")["rank"].min()
    table["zone_rank"] = np.where(ok, table["variant"].map(weakest).fillna(0), np.nan)
    table["zone"] = [lines.zone_names[int(r)] if o else z for r, o, z in zip(table["zone_rank"], ok, table["zone"],
                                                                             strict=True)]
    table["error_pct"] = np.where(ok, error, math.nan)
    mark_resolved(table, indicators, errors, lines.multipliers[0])
    selection = purpose_selection(table, verdicts, ref_name)
    table["selected"] = table["variant"] == selection.variant
    return Screening(table, indicators, selection, lines, ref_name, tuple(verdicts), zones)


def screening_tables(results: Iterable[RunResult], settings: ScreeningSettings, reference: str | None = None
                     ) -> tuple[pd.DataFrame, pd.DataFrame, Selection]:
    """(table, indicators, selection) of :func:`screen`."""
    s = screen(results, settings, reference)
    return s.table, s.indicators, s.selection
