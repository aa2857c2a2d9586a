"""Decision lines of the Westgard diagram and the selection of a model from a screening table (section 2.2):
the zones, the rules and their reasoning in words."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from flexgear.schema import ScreeningSettings

__all__ = ["DecisionLines", "Selection", "select_variant", "variant_names"]

_ZONE_NAMES = {
    (2, 3, 4): ("non-conforming", "critical", "good", "excellent"),
    (2, 3, 4, 5, 6): ("non-conforming", "poor", "marginal", "good", "excellent", "world-class"),
}
_LINE_SETS = {"westgard": (2, 3, 4), "six_sigma": (2, 3, 4, 5, 6)}
_ON_LINE_RTOL = 1e-12


# --------------------------------------------------------------------------- decision lines
@dataclass(frozen=True)
class DecisionLines:
    """Lines Bias + m·CV = TEa (all in %) and the zones between them, worst zone first."""

    tea_pct: float
    multipliers: tuple[int, ...] = (2, 3, 4)
    normalised: bool = False   # reference mode: Bias and CV in % of each indicator's own TEa, TEa = 100

    @classmethod
    def from_settings(cls, settings: ScreeningSettings, reference: str | None = None) -> DecisionLines:
        if reference if reference is not None else settings.reference:
            return cls(100.0, _LINE_SETS[settings.lines], True)
        return cls(settings.allowable_total_error_pct, _LINE_SETS[settings.lines])

    @property
    def unit(self) -> str:
        return "% of TEa" if self.normalised else "%"

    @property
    def zone_names(self) -> tuple[str, ...]:
        names = _ZONE_NAMES.get(tuple(self.multipliers))
        if names is None:
            names = ("non-conforming", *(f"sigma >= {m}" for m in self.multipliers))
        return names

    def rank(self, bias: float, cv: float) -> int:
        """Zone index: the number of lines whose criterion Bias + m·CV <= TEa is met (0 = worst)."""
        limit = self.tea_pct * (1.0 + _ON_LINE_RTOL)
        return sum(1 for m in self.multipliers if bias + m * cv <= limit)

    def zone(self, bias: float, cv: float) -> str:
        return self.zone_names[self.rank(bias, cv)]

    def cv_on_line(self, m: float, bias: np.ndarray | float) -> np.ndarray | float:
        """CV of line m at a given Bias (the study's axes: Bias on x, CV on y): (TEa - Bias)/m."""
        return (self.tea_pct - np.asarray(bias, dtype=float)) / m


@dataclass(frozen=True)
class Selection:
    """The selected variant (None if the rule selects none) and the reasoning, in words."""

    variant: str | None
    rule: str
    reasoning: str
    resolved: bool = True   # False: a zone that decides the verdict lies within the numerical error


def variant_names(df: pd.DataFrame) -> str:
    return ", ".join(df["variant"].astype(str)) or "none"


def _pick(candidates: pd.DataFrame, keys: Sequence[str]) -> pd.Series:
    return candidates.sort_values(list(keys), kind="stable").iloc[0]


def select_variant(table: pd.DataFrame, rule: str, lines: DecisionLines, reference: str = "") -> Selection:
    """Apply a selection rule to a screening table (columns: variant, status, zone_rank, time_s,
    distance_pct) and explain the choice.

    Only acceptable variants are candidates: those meeting at least the first decision line (zone above
    non-conforming). When none is acceptable, nothing is selected; when only the ``reference`` variant is, the
    verdict is "only the reference is acceptable" (it is selected, never the fastest non-conforming variant).

    - ``fastest_in_best_zone``: among the acceptable variants in the best zone reached, the fastest; ties
      (equal time) by distance from the origin. This is the study's reasoning (section 2.2: of
      models 4, 6, 7 in the excellent zone, model 4 is the cheapest).
    - ``closest_to_origin``: the acceptable variant with the smallest relative error distance; ties by time.
    - ``fastest_acceptable``: the fastest acceptable variant; ties by distance.
    """
    if rule not in ("fastest_in_best_zone", "closest_to_origin", "fastest_acceptable"):
        raise ValueError(f"unknown selection rule {rule!r}; allowed: fastest_in_best_zone, closest_to_origin, "
                         "fastest_acceptable")
    ok = table[table["status"] == "ok"]
    notes = "".join(f" Not screened ({status}): {variant_names(table[table['status'] == status])}."
                    for status in ("unsettled", "failed") if (table["status"] == status).any())
    tea = (f"TEa = {lines.tea_pct:g} %" if not lines.normalised
           else "each indicator scaled by its own TEa, composite TEa = 100 %")
    if ok.empty:
        return Selection(None, rule, "No variant was screened, nothing to select." + notes)
    acceptable = ok[ok["zone_rank"] >= 1]
    first = f"Bias + {lines.multipliers[0]} CV <= {tea}"
    if acceptable.empty:
        return Selection(None, rule, f"No variant is acceptable: none meets {first}; nothing is selected." + notes)
    others = acceptable[acceptable["variant"] != reference]
    if reference and others.empty:
        return Selection(reference, rule, f"Only the reference {reference} is acceptable: no other variant meets "
                                          f"{first}." + notes)
    if rule == "closest_to_origin":
        best = _pick(acceptable, ("distance_pct", "time_s"))
        why = (f"Rule closest_to_origin: {best['variant']} has the smallest relative error distance "
               f"({best['distance_pct']:.4g} %, zone {best['zone']}, {tea}).")
    elif rule == "fastest_acceptable":
        best = _pick(acceptable, ("time_s", "distance_pct"))
        why = (f"Rule fastest_acceptable: variants meeting {first}: {variant_names(acceptable)}; "
               f"the fastest is {best['variant']} ({best['time_s']:.4g} s, zone {best['zone']}).")
    else:
        top = int(acceptable["zone_rank"].max())
        zone = lines.zone_names[top]
        in_zone = acceptable[acceptable["zone_rank"] == top]
        best = _pick(in_zone, ("time_s", "distance_pct"))
        why = (f"Rule fastest_in_best_zone: best zone reached ({tea}) is '{zone}', holding {variant_names(in_zone)}; "
               f"the fastest of them is {best['variant']} ({best['time_s']:.4g} s, distance "
               f"{best['distance_pct']:.4g} %).")
        if len(in_zone) > 1:
            slower = in_zone[in_zone["variant"] != best["variant"]]
            why += " It is as accurate as zone '" + zone + "' asks while " + ", ".join(
                f"{r.variant} takes {r.time_s / best['time_s']:.3g}x as long" for r in slower.itertuples()) + "."
    return Selection(str(best["variant"]), rule, why + notes)
