"""The Westgard method decision diagram (section 2.2, Fig. 2 of the study), drawn by ``Screening.plot``.

Bias on x and CV on y as in the study. Each finished variant is a numbered marker; variants whose
markers fall within a few points of each other share one label ("1, 4"), and labels are placed
greedily so that no two overlap (the numbers are explained by the legend lines returned).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.lines import Line2D
from matplotlib.patches import Ellipse, Patch, Polygon
from matplotlib.ticker import MaxNLocator

__all__ = ["ZONE_COLOURS", "decision_diagram", "indicator_diagram", "place_labels", "PURPOSE_MARKERS"]

ZONE_COLOURS = ("#f4b6b6", "#fbd9a6", "#fff3b0", "#d4efc4", "#a9dcb0", "#7fc8a9")
_CLUSTER_PT = 7.0          # markers closer than this (points) share one label
_OFFSETS_PT = [(7, 5), (7, -12), (-7, 5), (-7, -12), (7, 16), (-7, 16), (7, -23), (-7, -23), (18, 27), (-18, 27),
               (18, -34), (-18, -34)]


def _clusters(xy: np.ndarray, tol: float) -> list[list[int]]:
    """Groups of indices whose display positions chain within ``tol`` (single linkage)."""
    groups: list[list[int]] = []
    for i, p in enumerate(xy):
        near = [g for g in groups if any(np.hypot(*(p - xy[j])) <= tol for j in g)]
        merged = [i] + [j for g in near for j in g]
        groups = [g for g in groups if g not in near] + [sorted(merged)]
    return sorted(groups, key=lambda g: g[0])


def place_labels(anchors: list[tuple[float, float]], texts: list[str], fontsize: float,
                 dpi: float = 72.0) -> list[tuple[float, float]]:
    """Offsets (points) for labels at display ``anchors`` (pixels) so that no two label boxes overlap.

    Greedy: each label takes the first candidate offset whose box is free (box width 0.62 em per
    character, height 1.2 em). Returns one (dx, dy) per label.
    """
    px = dpi / 72.0
    boxes: list[tuple[float, float, float, float]] = []
    out = []
    for (ax_, ay_), text in zip(anchors, texts, strict=True):
        w, h = 0.62 * fontsize * len(text) * px, 1.2 * fontsize * px
        chosen = _OFFSETS_PT[-1]
        for dx, dy in _OFFSETS_PT:
            x0 = ax_ + dx * px - (w if dx < 0 else 0.0)
            y0 = ay_ + dy * px
            box = (x0, y0, x0 + w, y0 + h)
            if all(box[2] <= b[0] or box[0] >= b[2] or box[3] <= b[1] or box[1] >= b[3] for b in boxes):
                chosen = (dx, dy)
                break
        x0 = ax_ + chosen[0] * px - (w if chosen[0] < 0 else 0.0)
        boxes.append((x0, ay_ + chosen[1] * px, x0 + w, ay_ + chosen[1] * px + h))
        out.append(chosen)
    return out


def _zones(ax: Axes, tea: float, ms: list[int], xmax: float, ymax: float, names: tuple[str, ...]) -> list[Patch]:
    ax.add_patch(Polygon([(0, tea / ms[0]), (tea, 0), (xmax, 0), (xmax, ymax), (0, ymax)],
                         color=ZONE_COLOURS[0], lw=0))
    handles = [Patch(color=ZONE_COLOURS[0], label=f"{names[0]} (Bias + {ms[0]}·CV > TEa)")]
    for k, m in enumerate(ms):        # every line passes through (TEa, 0): each band is a triangle
        below = tea / ms[k + 1] if k + 1 < len(ms) else 0.0
        colour = ZONE_COLOURS[min(k + 1, len(ZONE_COLOURS) - 1)]
        ax.add_patch(Polygon([(0, tea / m), (tea, 0), (0, below)], color=colour, lw=0))
        handles.append(Patch(color=colour, label=f"{names[k + 1]} (Bias + {m}·CV ≤ TEa)"))
    return handles[::-1]


def decision_diagram(ax: Axes, screening: pd.DataFrame, lines, xlim: float | None = None,
                     ylim: float | None = None, title: str = "") -> list[str]:
    """Draw the diagram of a screening table (columns variant, status, bias_pct, cv_pct, selected,
    zone, distance_pct); returns "n  variant: Bias, CV, zone" per numbered marker (in ``lines.unit``)."""
    tea, ms = lines.tea_pct, list(lines.multipliers)
    ok = screening[screening["status"] == "ok"].reset_index(drop=True)
    xmax = xlim or max(1.3 * tea, 1.15 * float(ok["bias_pct"].max()) if len(ok) else 0.0)
    ymax = ylim or max(0.65 * tea, 1.15 * float(ok["cv_pct"].max()) if len(ok) else 0.0)
    handles = _zones(ax, tea, ms, xmax, ymax, lines.zone_names)
    b = np.linspace(0.0, tea, 50)
    for m in ms:
        ax.plot(b, lines.cv_on_line(m, b), color="k", lw=0.9)
    ax.axvline(tea, color="#444444", lw=0.8, ls=":")
    ax.set_xlim(0, xmax)
    ax.set_ylim(0, ymax)
    legend = []
    inside = ok[(ok["bias_pct"] <= xmax) & (ok["cv_pct"] <= ymax)]
    for i, row in enumerate(ok.itertuples(), start=1):
        legend.append(f"{i}  {row.variant}: {row.bias_pct:.3g}, {row.cv_pct:.3g}, {row.zone}"
                      + (" (selected)" if row.selected else ""))
    if len(inside):
        pts = inside[["bias_pct", "cv_pct"]].to_numpy(dtype=float)
        disp = ax.transData.transform(pts)
        px = ax.figure.dpi / 72.0
        for _, row in inside.iterrows():
            error = float(row.get("error_pct", math.nan))
            if math.isfinite(error) and error > 0:   # the numerical error as the point's size (Bias -/+ error)
                ax.add_patch(Ellipse((row.bias_pct, row.cv_pct), 2 * error, 2 * error, fc="none", ec="#555555",
                                     ls="--", lw=0.8, zorder=4))
            ax.plot(row.bias_pct, row.cv_pct, "o", ms=6, mfc="#d62728" if row.selected else "#1f4e99", mec="k",
                    clip_on=False, zorder=5)
        groups = _clusters(disp, _CLUSTER_PT * px)
        numbers = [", ".join(str(int(inside.index[j]) + 1) for j in g) for g in groups]
        anchors = [tuple(disp[g].mean(axis=0)) for g in groups]
        for g, text, (dx, dy) in zip(groups, numbers, place_labels(anchors, numbers, 9, ax.figure.dpi), strict=True):
            x, y = pts[g].mean(axis=0)
            ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points", fontsize=9, weight="bold",
                        ha="right" if dx < 0 else "left", va="bottom", zorder=6,
                        bbox={"fc": "white", "ec": "none", "alpha": 0.7, "pad": 0.5})
    hidden = ok[(ok["bias_pct"] > xmax) | (ok["cv_pct"] > ymax)]
    if len(hidden):
        nums = [str(i + 1) for i in hidden.index]
        ax.text(0.98, 0.02, "outside this view: " + ", ".join(nums), transform=ax.transAxes, ha="right",
                va="bottom", fontsize=8, bbox={"fc": "white", "ec": "#999999"})
    ax.legend(handles=handles, loc="upper right", fontsize=7.5, title=f"zones, TEa = {tea:g} {lines.unit}",
              title_fontsize=7.5, framealpha=0.9)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.yaxis.set_major_locator(MaxNLocator(6))
    ax.set_xlabel(f"inaccuracy Bias [{lines.unit}]")
    ax.set_ylabel(f"imprecision CV [{lines.unit}]")
    if title:
        ax.set_title(title, fontsize=10)
    return legend


PURPOSE_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
"""Marker of each purpose, in the order of ``[screening.purposes]`` (indicators of no purpose: "x")."""


def indicator_diagram(ax: Axes, indicators: pd.DataFrame, lines, purposes: list[str], xmax: float = 200.0,
                      ymax: float = 60.0, title: str = "") -> list[str]:
    """The normalised method decision chart of a reference screening: one point per variant and indicator at
    (Bias / TEa 100, CV / TEa 100) [% of its own TEa], the decision lines at TEa = 100 %; marker shape per purpose,
    colour per variant; points beyond the view sit on its edge as open markers. ``indicators``: the screening's
    indicator table (variant, indicator, bias, cv, tea, purpose). Returns one legend line per variant: its
    indicators outside the first line."""
    lines = type(lines)(100.0, lines.multipliers, True)
    handles = _zones(ax, 100.0, list(lines.multipliers), xmax, ymax, lines.zone_names)
    b = np.linspace(0.0, 100.0, 50)
    for m in lines.multipliers:
        ax.plot(b, lines.cv_on_line(m, b), color="k", lw=0.9)
    ax.set_xlim(0, xmax)
    ax.set_ylim(0, ymax)
    variants = list(dict.fromkeys(indicators["variant"]))
    colours = [f"C{i % 10}" for i in range(len(variants))]
    legend = []
    for v, colour in zip(variants, colours, strict=True):
        mine = indicators[indicators["variant"] == v]
        x = (mine["bias"] / mine["tea"] * 100.0).to_numpy(float)
        y = (mine["cv"] / mine["tea"] * 100.0).to_numpy(float)
        outside = []
        for xi, yi, p, name in zip(x, y, mine["purpose"], mine["indicator"], strict=True):
            marker = PURPOSE_MARKERS[purposes.index(p) % len(PURPOSE_MARKERS)] if p in purposes else "x"
            clipped = xi > xmax or yi > ymax
            ax.plot(min(xi, xmax), min(yi, ymax), marker, ms=5.5, mfc="none" if clipped else colour, mec=colour,
                    mew=1.2, clip_on=False, zorder=5, alpha=0.9)
            if xi + lines.multipliers[0] * yi > 100.0 * (1 + 1e-12):
                outside.append(f"{name} {xi:.0f} %")
        legend.append(f"{v}: " + (", ".join(outside) if outside else "every indicator acceptable"))
    handles += [Line2D([], [], color=c, marker="o", ls="", label=v) for v, c in zip(variants, colours, strict=True)]
    handles += [Line2D([], [], color="k", marker=PURPOSE_MARKERS[i % len(PURPOSE_MARKERS)], mfc="none", ls="",
                       label=p.replace("_", " ")) for i, p in enumerate(purposes)]
    ax.legend(handles=handles, loc="upper right", fontsize=6.5, ncol=2, framealpha=0.9,
              title="zones (TEa = 100 % of each indicator's own); variants; purposes", title_fontsize=6.5)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.yaxis.set_major_locator(MaxNLocator(6))
    ax.set_xlabel("inaccuracy |Bias| [% of the indicator's TEa]")
    ax.set_ylabel("imprecision CV [% of the indicator's TEa]")
    if title:
        ax.set_title(title, fontsize=10)
    return legend
