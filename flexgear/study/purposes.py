"""A verdict per purpose: every reference indicator judged alone, the cheapest acceptable variant per question.

The reference screening (flexgear.study.screening) gives each variant's indicators their own Bias and CV against
the reference variant, each in its own unit with its own TEa (``[screening.reference_indicators]``). A composite
of them lets an indicator of small weight be several times its TEa and still leave the variant "excellent", so
the verdict is taken per indicator, as laboratories judge each analyte alone on the normalised method decision
chart:

- an indicator meets decision line m when |Bias| + m CV <= TEa (flexgear.study.selection.DecisionLines, lines of
  ``[screening] lines``); it is *acceptable* when it meets the first line (m = 2); its zone is the number of lines
  it meets;
- a variant's zone for a purpose (``[screening.purposes]``: purpose -> indicators) is the zone of its weakest
  indicator of that purpose; it is acceptable for the purpose when every indicator of the purpose is;
- per purpose the cheapest acceptable variant (CPU time) is selected; when only the reference is acceptable the
  verdict says so; the *deciding indicator* is the selected variant's indicator with the smallest margin
  (TEa - |Bias| - 2 CV) / TEa, its *numerical error* the change of the reference's mean of that indicator between
  its window solved at h and at h/2 (flexgear.study.screening.numerical_error);
- the verdict is *resolved* when no acceptability that decides it (the selected variant's and every cheaper
  screened variant's, each indicator of the purpose) changes when its Bias moves by -/+ its numerical error;
- the overall verdict ("all purposes") is the cheapest variant acceptable for every purpose.

The mean loaded transmission error is reported beside the transmission-error verdict, not judged: it is a static
offset (:func:`static_te_split`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from flexgear.study.indicators import ALL_INDICATORS
from flexgear.study.selection import DecisionLines, Selection, variant_names

__all__ = ["ALL_PURPOSES", "RULE_PER_PURPOSE", "STUDY_PURPOSE", "PurposeVerdict", "mark_resolved",
           "purpose_selection", "describe_indicator", "indicator_ranks", "purpose_zones", "judge_purposes",
           "verdict_table", "VERDICT_COLUMNS", "static_te_split", "StaticTeSplit"]

ALL_PURPOSES = "all purposes"
"""Name of the overall verdict: the cheapest variant acceptable for every purpose."""

VERDICT_COLUMNS = ["purpose", "selected", "deciding_indicator", "bias", "cv", "tea", "unit", "resolved",
                   "time_ratio"]
"""Columns of ``verdict.csv`` (one row per purpose, then the overall verdict)."""


@dataclass(frozen=True)
class PurposeVerdict:
    """The verdict for one purpose: the selected variant (None when none is acceptable) and why.

    ``bias``, ``cv``, ``tea`` and ``error`` are the deciding indicator's, in ``unit``; ``margin`` = (TEa - Bias -
    2 CV) / TEa (fraction; negative: outside the acceptable line); ``time_ratio`` = the selected variant's CPU time
    over the reference's; ``failing``: each cheaper screened variant -> its weakest indicator of the purpose in
    words; ``zone``: the selected variant's zone for the purpose; ``unresolved_by``: the indicators, in words, whose
    acceptability changes within the numerical error (empty when resolved)."""

    purpose: str
    indicators: tuple[str, ...]
    selected: str | None
    deciding_indicator: str
    bias: float
    cv: float
    tea: float
    unit: str
    margin: float
    zone: str
    error: float
    resolved: bool
    time_ratio: float
    reasoning: str
    failing: tuple[tuple[str, str], ...] = ()
    unresolved_by: tuple[str, ...] = ()

    def row(self) -> dict:
        """The verdict as one row of ``verdict.csv`` (VERDICT_COLUMNS, plus zone, margin, error, reasoning)."""
        return {"purpose": self.purpose, "selected": self.selected or "", "deciding_indicator": self.deciding_indicator,
                "bias": self.bias, "cv": self.cv, "tea": self.tea, "unit": self.unit, "resolved": self.resolved,
                "time_ratio": self.time_ratio, "zone": self.zone, "margin": self.margin, "error": self.error,
                "indicators": " ".join(self.indicators), "reasoning": self.reasoning}


def indicator_ranks(indicators: pd.DataFrame, lines: DecisionLines) -> pd.DataFrame:
    """The indicator table (flexgear.study.screening: variant, indicator, bias, cv, tea, unit) with each row's
    zone rank on its own TEa (``rank``: lines met), ``acceptable`` (the first line met) and ``margin``
    (TEa - Bias - m_1 CV) / TEa."""
    out = indicators.copy()
    m1 = lines.multipliers[0]
    out["rank"] = [DecisionLines(float(r.tea), lines.multipliers).rank(float(r.bias), float(r.cv))
                   for r in out.itertuples()]
    out["acceptable"] = out["rank"] >= 1
    out["margin"] = (out["tea"] - out["bias"] - m1 * out["cv"]) / out["tea"]
    return out


def _purpose_of(purposes: Mapping[str, tuple[str, ...]]) -> dict[str, str]:
    return {k: p for p, keys in purposes.items() for k in keys}


def purpose_zones(indicators: pd.DataFrame, table: pd.DataFrame, purposes: Mapping[str, tuple[str, ...]],
                  lines: DecisionLines) -> pd.DataFrame:
    """One row per screened variant and purpose: ``rank`` and ``zone`` of its weakest indicator of the purpose,
    that ``weakest`` indicator and its ``margin``, ``acceptable``; ``missing``: indicators the reference has and the
    variant lacks (such a variant is not acceptable for the purpose). Purposes none of whose indicators the
    reference has are left out."""
    ranked = indicator_ranks(indicators, lines)
    rows = []
    ok = table[table["status"] == "ok"]
    present = set(ranked["indicator"])
    for purpose, keys in purposes.items():
        judged = [k for k in keys if k in present]
        if not judged:
            continue
        for v in ok.itertuples():
            mine = ranked[(ranked["variant"] == v.variant) & ranked["indicator"].isin(judged)]
            missing = sorted(set(judged) - set(mine["indicator"]))
            if mine.empty:
                rows.append({"variant": v.variant, "purpose": purpose, "rank": 0, "zone": lines.zone_names[0],
                             "weakest": "", "margin": -math.inf, "acceptable": False, "missing": " ".join(missing)})
                continue
            weakest = mine.sort_values(["rank", "margin"], kind="stable").iloc[0]
            rank = 0 if missing else int(mine["rank"].min())
            rows.append({"variant": v.variant, "purpose": purpose, "rank": rank, "zone": lines.zone_names[rank],
                         "weakest": weakest["indicator"], "margin": float(weakest["margin"]),
                         "acceptable": bool(mine["acceptable"].all()) and not missing, "missing": " ".join(missing)})
    return pd.DataFrame(rows, columns=["variant", "purpose", "rank", "zone", "weakest", "margin", "acceptable",
                                       "missing"])


def describe_indicator(ind: pd.Series) -> str:
    """An indicator's standing in words: '<name> 4.2 dB off (+ 2 CV 0.1; TEa 3 dB)'."""
    name = ALL_INDICATORS.get(ind["indicator"], ind["indicator"])
    return (f"{name} {ind['bias']:.3g} {ind['unit']} off, CV {ind['cv']:.2g} (TEa {ind['tea']:g} {ind['unit']})")


def _flips(ind: pd.DataFrame, errors: Mapping[str, float], m1: float) -> list[str]:
    """The indicators whose acceptability changes when their Bias moves by -/+ their numerical error, in words."""
    out = []
    for r in ind.itertuples():
        e = float(errors.get(r.indicator, 0.0))
        if not math.isfinite(e):
            continue
        hi = r.bias + e + m1 * r.cv <= r.tea
        lo = max(r.bias - e, 0.0) + m1 * r.cv <= r.tea
        if hi != lo:
            out.append(f"{r.variant}'s {ALL_INDICATORS.get(r.indicator, r.indicator)} {r.bias:.3g} -/+ {e:.2g} "
                       f"{r.unit} (TEa {r.tea:g})")
    return out


def _judge(purpose: str, keys: tuple[str, ...], ranked: pd.DataFrame, zones: pd.DataFrame, table: pd.DataFrame,
           reference: str, errors: Mapping[str, float], lines: DecisionLines) -> PurposeVerdict:
    m1 = lines.multipliers[0]
    ok = table[table["status"] == "ok"].sort_values(["time_s", "variant"], kind="stable")
    mine = zones[zones["purpose"] == purpose] if purpose != ALL_PURPOSES else (
        zones.groupby("variant", sort=False).agg(rank=("rank", "min"), acceptable=("acceptable", "all"))
        .reset_index())
    acceptable = set(mine.loc[mine["acceptable"], "variant"])
    order = [v for v in ok["variant"] if v in set(mine["variant"])]
    selected = next((v for v in order if v in acceptable), None)
    ref_time = float(table.loc[table["variant"] == reference, "time_s"].iloc[0]) if (
        table["variant"] == reference).any() else math.nan
    failing = []
    for v in order:
        if v == selected:
            break
        ind = ranked[(ranked["variant"] == v) & ranked["indicator"].isin(keys)].sort_values("margin")
        if len(ind):
            failing.append((v, describe_indicator(ind.iloc[0])))
    if selected is None:
        why = (f"{purpose}: no variant is acceptable (every indicator within |Bias| + {m1} CV <= TEa)"
               + (f"; closest: {failing[0][0]}, {failing[0][1]}" if failing else "") + ".")
        return PurposeVerdict(purpose, keys, None, "", math.nan, math.nan, math.nan, "", math.nan,
                              lines.zone_names[0], math.nan, True, math.nan, why, tuple(failing))
    ind = ranked[(ranked["variant"] == selected) & ranked["indicator"].isin(keys)].sort_values(
        ["margin", "indicator"], kind="stable")
    deciding = ind.iloc[0]
    rank = int(ind["rank"].min())
    cheaper = order[:order.index(selected) + 1]
    flips = [f for v in cheaper for f in _flips(ranked[(ranked["variant"] == v) & ranked["indicator"].isin(keys)],
                                                 errors, m1)]
    resolved = not flips
    t_sel = float(ok.loc[ok["variant"] == selected, "time_s"].iloc[0])
    ratio = t_sel / ref_time if ref_time > 0 else math.nan
    if selected == reference:
        why = (f"{purpose}: only the reference {reference} is acceptable; "
               + ("; ".join(f"{v}: {w}" for v, w in failing) or "no other variant was screened") + ".")
    else:
        why = (f"{purpose}: {selected} is the cheapest variant whose every indicator meets |Bias| + {m1} CV <= TEa "
               f"(zone '{lines.zone_names[rank]}', deciding: {describe_indicator(deciding)}; {ratio:.3g}x the "
               "reference's time)"
               + ("; cheaper and failing: " + "; ".join(f"{v}: {w}" for v, w in failing) if failing else "") + ".")
    if not resolved:
        why = ("NOT RESOLVED: an acceptability that decides this verdict changes within the reference's numerical "
               "error (h against h/2): " + "; ".join(flips) + ". " + why)
    return PurposeVerdict(purpose, keys, selected, str(deciding["indicator"]), float(deciding["bias"]),
                          float(deciding["cv"]), float(deciding["tea"]), str(deciding["unit"]),
                          float(deciding["margin"]), lines.zone_names[rank],
                          float(errors.get(deciding["indicator"], math.nan)), resolved, ratio, why, tuple(failing),
                          tuple(flips))


def judge_purposes(indicators: pd.DataFrame, table: pd.DataFrame, purposes: Mapping[str, tuple[str, ...]],
                   lines: DecisionLines, reference: str, errors: Mapping[str, float] | None = None
                   ) -> tuple[pd.DataFrame, list[PurposeVerdict]]:
    """Per purpose (and overall, :data:`ALL_PURPOSES`) the verdict of the module docstring, from a reference
    screening's indicator table and run table (columns variant, status, time_s). ``errors``: indicator -> the
    reference's numerical error in the indicator's unit. Returns (:func:`purpose_zones`, verdicts)."""
    errors = errors or {}
    ranked = indicator_ranks(indicators, lines)
    zones = purpose_zones(indicators, table, purposes, lines)
    judged = [p for p in purposes if (zones["purpose"] == p).any()]
    verdicts = [_judge(p, purposes[p], ranked, zones, table, reference, errors, lines) for p in judged]
    if judged:
        keys = tuple(k for p in judged for k in purposes[p])
        verdicts.append(_judge(ALL_PURPOSES, keys, ranked, zones, table, reference, errors, lines))
    return zones, verdicts


def verdict_table(verdicts: list[PurposeVerdict]) -> pd.DataFrame:
    """``verdict.csv``: one row per purpose (VERDICT_COLUMNS first)."""
    rows = [v.row() for v in verdicts]
    extra = ["zone", "margin", "error", "indicators", "reasoning"]
    return pd.DataFrame(rows, columns=VERDICT_COLUMNS + extra)


# --------------------------------------------------------------------------- the static transmission error
@dataclass(frozen=True)
class StaticTeSplit:
    """The mean loaded transmission error of a run [m] at the output's base circle, split into the meshes' share
    (both meshes' static contact deflection under the law at their mean normal force) and the rest: the wind-up
    of shafts, bearings and supports (and the gears' bodies where flexible)."""

    total_m: float
    meshes_m: float

    @property
    def windup_m(self) -> float:
        return self.total_m - self.meshes_m


def static_te_split(total_m: float, outer_deflection_m: float, inner_deflection_m: float,
                    base_helix_angle_rad: float) -> StaticTeSplit:
    """Split a mean loaded TE [m]: the meshes' share is (delta_n,outer + delta_n,inner) / cos(beta_b), each mesh's
    normal static deflection taken to the transverse line of action (the sun's and the ring's base-circle arcs
    differ by the transverse approach of both meshes in series, the carrier held; the parallel-axis pair's one mesh:
    ``inner_deflection_m`` 0); the rest is wind-up."""
    meshes = (outer_deflection_m + inner_deflection_m) / math.cos(base_helix_angle_rad)
    return StaticTeSplit(float(total_m), float(meshes))


STUDY_PURPOSE = "study composite"
"""The ``purpose`` of the study mode's five indicators: judged together, as the study's composite point."""

RULE_PER_PURPOSE = "cheapest_acceptable_per_purpose"
"""The reference mode's rule (flexgear.study.purposes): each indicator alone, the cheapest acceptable variant per
purpose, overall the cheapest acceptable for every purpose."""


def mark_resolved(table: pd.DataFrame, indicators: pd.DataFrame, errors: dict[str, float], m1: float) -> None:
    """Mark each screened variant ``resolved`` when no indicator's acceptability (|Bias| + m1 CV <= TEa) changes as
    its Bias moves by -/+ the reference's numerical error of that indicator (``errors``, the indicator's unit)."""
    ok = table["status"] == "ok"
    resolved = [not _flips(indicators[indicators["variant"] == v], errors, m1) for v in table["variant"]]
    table["resolved"] = np.where(ok, resolved, True)


def purpose_selection(table: pd.DataFrame, verdicts: list[PurposeVerdict], reference: str) -> Selection:
    """The reference mode's overall selection: the :data:`ALL_PURPOSES` verdict, its reasoning followed by each
    purpose's."""
    notes = "".join(f" Not screened ({status}): {variant_names(table[table['status'] == status])}."
                    for status in ("unsettled", "failed") if (table["status"] == status).any())
    if not verdicts:
        return Selection(None, RULE_PER_PURPOSE, "No variant was screened, nothing to select." + notes)
    overall = verdicts[-1]
    head = overall.reasoning.replace(f"{ALL_PURPOSES}:", "For every purpose:", 1)
    per = " ".join(v.reasoning for v in verdicts[:-1])
    return Selection(overall.selected, RULE_PER_PURPOSE, f"{head} Per purpose: {per}{notes}",
                     all(v.resolved for v in verdicts))
