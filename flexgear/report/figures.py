"""Table drawing and the run-time chart of the screening report (matplotlib, into given axes).

The figures of results, spectra, screenings and sweeps are drawn by their objects' ``plot(ax)``
(flexgear.results.RunResult, flexgear.study.compare.BearingSpectrum, flexgear.study.screening.Screening,
flexgear.study.sweep.SweepResult); the pages (flexgear.report.pages) only lay them out.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.axes import Axes

__all__ = ["fmt", "draw_table", "run_time_chart", "EMPTY_TABLE_TEXT"]


def fmt(value: object, digits: int = 4) -> str:
    """Table text: numbers with ``digits`` significant digits (no exponent between 1e-3 and 1e6,
    integers kept whole there), NaN/None as an en dash."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "–"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(value)
    if isinstance(value, (float, np.floating)):
        a = abs(float(value))
        if math.isinf(a):
            return "∞" if value > 0 else "−∞"
        if 1e-3 <= a < 1e6 and a >= 10 ** (digits - 1):
            return f"{value:.0f}"
        return f"{value:.{digits}g}"
    return str(value)


_CHAR_WIDTH_EM = 0.56   # mean character width of DejaVu Sans, in font sizes

EMPTY_TABLE_TEXT = "no rows"
"""What :func:`draw_table` writes in place of a table without rows, unless told why."""

_LINE_HEIGHT_EM = 1.45  # height of one table text line, in font sizes
_SENTENCE_WRAP = 160    # characters per line of the sentence that stands for an empty table
_POINTS_PER_INCH = 72.0


def _line_fraction(ax: Axes, fontsize: float) -> float:
    """Height of one text line of ``fontsize`` points, as a fraction of the height of ``ax``."""
    height_in = ax.get_position().height * ax.figure.get_figheight()
    return fontsize * _LINE_HEIGHT_EM / _POINTS_PER_INCH / height_in


def draw_table(ax: Axes, table: pd.DataFrame, col_widths: Sequence[float] | None = None, fontsize: float = 8.0,
               wrap: int | dict[str, int] = 30, top: float = 1.0, max_height: float | None = None,
               empty: str = EMPTY_TABLE_TEXT) -> float:
    """Draw ``table`` at the top of ``ax``; return its bottom (axes fraction).

    Long cells are wrapped (``wrap`` characters, per column if a dict), each row is as high as its
    longest cell, columns are as wide as their text (unless ``col_widths`` is given) and the font
    shrinks if the text would not fit the width. Height: as the text needs, at most ``max_height``.
    A table without rows or columns is one italic sentence instead, ``empty`` (why it is empty; ``fontsize`` in
    points as for the table).
    """
    ax.axis("off")
    if table.empty:
        text = textwrap.fill(empty, _SENTENCE_WRAP) or EMPTY_TABLE_TEXT
        ax.text(0.0, top, text, va="top", ha="left", fontsize=fontsize, style="italic", transform=ax.transAxes)
        return top - (text.count("\n") + 1.5) * _line_fraction(ax, fontsize)
    cols = [str(c) for c in table.columns]
    widths = {c: (wrap.get(c, 30) if isinstance(wrap, dict) else wrap) for c in cols}
    body = [[textwrap.fill(fmt(v), widths[c]) or " " for c, v in zip(cols, row, strict=True)]
            for row in table.itertuples(index=False)]

    def longest(texts: Sequence[str]) -> int:
        return max((len(line) for t in texts for line in t.split("\n")), default=1)

    data_len = [longest([r[j] for r in body]) for j in range(len(cols))]
    header = [textwrap.fill(c, max(min(widths[c], 16), data_len[j], 6)) for j, c in enumerate(cols)]
    chars = [max(data_len[j], longest([header[j]])) + 2 for j in range(len(cols))]
    box = ax.get_position()
    width_in = box.width * ax.figure.get_figwidth()
    needed_in = sum(chars) * _CHAR_WIDTH_EM * fontsize / 72.0 if col_widths is None else 0.0
    if needed_in > width_in:
        fontsize *= width_in / needed_in
    if col_widths is None:
        col_widths = [c / sum(chars) for c in chars]
    lines = [max(h.count("\n") + 1 for h in header)] + [max(c.count("\n") + 1 for c in r) for r in body]
    line = _line_fraction(ax, fontsize)   # one text line, axes fraction
    total = min(sum(n + 0.5 for n in lines) * line, max_height if max_height is not None else top)
    tab = ax.table(cellText=body, colLabels=header, colWidths=col_widths, cellLoc="left", loc="upper center",
                   bbox=[0.0, top - total, 1.0, total])
    tab.auto_set_font_size(False)
    tab.set_fontsize(fontsize)
    for (r, _c), cell in tab.get_celld().items():
        cell.set_height(lines[r] + 0.5)
        cell.PAD = 0.02
        if r == 0:
            cell.set_facecolor("#e8e8e8")
            cell.get_text().set_fontweight("bold")
    return top - total


def run_time_chart(ax: Axes, runs: pd.DataFrame, empty: str = "no runs: no run time to chart",
                   published: str | None = None) -> None:
    """Log-scale bars: our wall time per simulated second, beside a published one (column ``published_per_s``
    [s/s], labelled ``published``) where ``runs`` has it; columns variant, wall_time_s [s], t_end_s [s]. Without
    runs, a sentence ``empty`` says why instead; a run without a positive simulated time has no bar."""
    if runs.empty or "variant" not in runs.columns:
        ax.axis("off")
        ax.text(0.5, 0.5, empty, ha="center", va="center", fontsize=10, style="italic", transform=ax.transAxes)
        return
    names = list(runs["variant"])
    x = np.arange(len(names))
    t_end = pd.to_numeric(runs["t_end_s"], errors="coerce").to_numpy(dtype=float)
    wall = pd.to_numeric(runs["wall_time_s"], errors="coerce").to_numpy(dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        ours = np.where(t_end > 0, wall / t_end, np.nan)
    theirs = (pd.to_numeric(runs["published_per_s"], errors="coerce").to_numpy(dtype=float) if "published_per_s" in runs
              else np.full(len(names), np.nan))
    w = 0.38
    ax.bar(x - w / 2, np.where(np.isfinite(ours), ours, 0), w, color="#1f4e99",
           label="flexgear (Exudyn), wall time per simulated second")
    if np.isfinite(theirs).any():
        ax.bar(x + w / 2, np.where(np.isfinite(theirs), theirs, 0), w, color="#bbbbbb", label=published or "published")
    for xi, v, a in zip(x, ours, theirs, strict=True):
        if np.isfinite(v) and v > 0:
            ax.annotate(fmt(v, 3), (xi - w / 2, v), ha="center", va="bottom", fontsize=7, xytext=(0, 2),
                        textcoords="offset points")
        else:
            ax.text(xi - w / 2, 0.02, "failed", ha="center", va="bottom", fontsize=7, color="#b22222",
                    rotation=90, transform=ax.get_xaxis_transform())
        if np.isfinite(a):
            ax.annotate(fmt(a, 3), (xi + w / 2, a), ha="center", va="bottom", fontsize=7, xytext=(0, 2),
                        textcoords="offset points", color="#555555")
    if np.any(np.isfinite(ours) & (ours > 0)) or np.any(np.isfinite(theirs)):
        ax.set_yscale("log")
    ax.set_xticks(x, names, rotation=30 if len(names) > 9 else 0, fontsize=8)
    ax.set_ylabel("wall time per simulated second [s/s] (log scale)")
    finite = np.concatenate([ours[np.isfinite(ours) & (ours > 0)], theirs[np.isfinite(theirs)]])
    if finite.size:
        ax.set_ylim(finite.min() / 5, finite.max() * 20)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    ax.grid(axis="y", which="major", alpha=0.3)
