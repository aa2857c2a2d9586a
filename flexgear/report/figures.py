"""Figures and tables of the screening report (matplotlib): each function draws into given axes.

Kept apart from :mod:`flexgear.report.pages` (which gathers the saved results and lays out pages) so
that every figure can be drawn and tested alone.
"""

from __future__ import annotations

import math
import re
import textwrap
from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.patches import Polygon
from matplotlib.ticker import MaxNLocator

from flexgear.study.compare import amplitude_spectrum
from flexgear.study.reference import ADAMS_TIME_S
from flexgear.study.screening import DecisionLines, Window

__all__ = [
    "HARMONICS",
    "fmt",
    "draw_table",
    "decision_diagram",
    "run_time_chart",
    "spectrum_panel",
    "history_panel",
    "envelope",
]

"""Table 4 of the study: ADAMS (GSTIFF) simulation time of models 1-7 for 0.6 s, in s."""

HARMONICS = (1, 2, 4, 6, 9)
"""Multiples of the mesh frequency the study reports (section 3.2, Table 7)."""

_ZONE_COLOURS = ("#f4b6b6", "#fbd9a6", "#fff3b0", "#d4efc4", "#a9dcb0", "#7fc8a9")


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


def draw_table(ax: Axes, table: pd.DataFrame, col_widths: Sequence[float] | None = None, fontsize: float = 8.0,
               wrap: int | dict[str, int] = 30, top: float = 1.0, max_height: float | None = None) -> float:
    """Draw ``table`` at the top of ``ax``; return its bottom (axes fraction).

    Long cells are wrapped (``wrap`` characters, per column if a dict), each row is as high as its
    longest cell, columns are as wide as their text (unless ``col_widths`` is given) and the font
    shrinks if the text would not fit the width. Height: as the text needs, at most ``max_height``.
    """
    ax.axis("off")
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
    line = fontsize * 1.45 / 72.0 / (box.height * ax.figure.get_figheight())   # one text line, axes fraction
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


def _zone_label_points(lines: DecisionLines) -> list[tuple[float, float]]:
    """A point inside each zone (worst first) to write its name, in (Bias, CV)."""
    tea, ms = lines.tea_pct, list(lines.multipliers)
    pts = [(0.08 * tea, tea / ms[0] * 1.12 + 0.02 * tea)]
    bounds = ms + [None]
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        x = 0.04 * tea
        y = (tea - x) / lo if hi is None else 0.5 * ((tea - x) / lo + (tea - x) / hi)
        pts.append((x, y if hi is not None else 0.45 * (tea - x) / lo))
    return pts


def decision_diagram(ax: Axes, screening: pd.DataFrame, lines: DecisionLines,
                     xlim: float | None = None, ylim: float | None = None, title: str = "",
                     labels: bool = True) -> None:
    """Westgard method decision diagram in the study's axes: Bias % on x, CV % on y.

    Lines Bias + m·CV = TEa for each m; zones filled; the variants' composite points labelled.
    """
    tea, ms = lines.tea_pct, list(lines.multipliers)
    ok = screening[screening["status"] == "ok"]
    xmax = xlim or max(1.3 * tea, 1.15 * float(ok["bias_pct"].max()) if len(ok) else 0.0)
    ymax = ylim or max(0.65 * tea, 1.15 * float(ok["cv_pct"].max()) if len(ok) else 0.0)
    names = lines.zone_names
    # zones: non-conforming above line m0, then bands between consecutive lines, best under the last
    ax.add_patch(Polygon([(0, tea / ms[0]), (tea, 0), (xmax, 0), (xmax, ymax), (0, ymax)],
                         color=_ZONE_COLOURS[0], lw=0))
    # every line passes through (TEa, 0): each band between two lines is a triangle
    for k, m in enumerate(ms):
        below = tea / ms[k + 1] if k + 1 < len(ms) else 0.0
        ax.add_patch(Polygon([(0, tea / m), (tea, 0), (0, below)],
                             color=_ZONE_COLOURS[min(k + 1, len(_ZONE_COLOURS) - 1)], lw=0))
    # far wider than TEa (points far outside): the zones shrink into a corner; only the far points get labels
    compact = xmax > 4 * tea or ymax > 2 * tea
    b = np.linspace(0.0, tea, 50)
    for m in ms:
        ax.plot(b, lines.cv_on_line(m, b), color="k", lw=0.9)
        if not compact:
            x_lab = 0.55 * tea
            ax.annotate(f"Bias + {m}·CV = TEa", (x_lab, (tea - x_lab) / m), fontsize=7, xytext=(3, 2),
                        textcoords="offset points", clip_on=True)
    if not compact:
        for name, (x, y) in zip(names, _zone_label_points(lines), strict=True):
            if y < ymax:
                ax.text(x, y, name, fontsize=8, style="italic", va="center", color="#333333", clip_on=True)
        ax.annotate(f"TEa = {tea:g} %", (tea, 0), xytext=(4, 8), textcoords="offset points", fontsize=8)
    ax.axvline(tea, color="#444444", lw=0.8, ls=":")
    for i, row in enumerate(ok.itertuples()):
        if row.bias_pct > xmax or row.cv_pct > ymax:
            continue
        ax.plot(row.bias_pct, row.cv_pct, "o", ms=6, mfc="#1f4e99" if not row.selected else "#d62728", mec="k",
                clip_on=False, zorder=5)
        near = row.bias_pct <= 1.3 * tea and row.cv_pct <= 0.65 * tea
        if not labels or (compact and near):
            continue
        dy = 6 + 9 * (i % 3)
        ax.annotate(row.variant + (" (selected)" if row.selected else ""), (row.bias_pct, row.cv_pct),
                    xytext=(6, dy), textcoords="offset points", fontsize=8,
                    arrowprops={"arrowstyle": "-", "lw": 0.5, "color": "#555555"})
    hidden = ok[(ok["bias_pct"] > xmax) | (ok["cv_pct"] > ymax)]
    if len(hidden):
        ax.text(0.98, 0.97, "outside this view: " + ", ".join(hidden["variant"]), transform=ax.transAxes,
                ha="right", va="top", fontsize=8, bbox={"fc": "white", "ec": "#999999"})
    ax.set_xlim(0, xmax)
    ax.set_ylim(0, ymax)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.yaxis.set_major_locator(MaxNLocator(6))
    ax.set_xlabel("inaccuracy Bias [%]  (x, as in the study)")
    ax.set_ylabel("imprecision CV [%]  (y, as in the study)")
    if title:
        ax.set_title(title, fontsize=10)


def _model_number(name: str) -> int | None:
    m = re.fullmatch(r"model(\d+)", name)
    return int(m.group(1)) if m else None


def run_time_chart(ax: Axes, runs: pd.DataFrame) -> None:
    """Log-scale bars: our wall time per variant beside the study's ADAMS time (Table 4)."""
    names = list(runs["variant"])
    x = np.arange(len(names))
    ours = runs["wall_time_s"].to_numpy(dtype=float)
    adams = np.array([ADAMS_TIME_S.get(_model_number(n) or 0, np.nan) for n in names])
    t_end = runs["t_end_s"].to_numpy(dtype=float)
    w = 0.38
    ax.bar(x - w / 2, np.where(np.isfinite(ours), ours, 0), w, color="#1f4e99", label="flexgear (Exudyn), wall")
    ax.bar(x + w / 2, np.where(np.isfinite(adams), adams, 0), w, color="#bbbbbb",
           label="study, ADAMS GSTIFF, 0.6 s (Table 4)")
    for xi, v, te in zip(x, ours, t_end, strict=True):
        if np.isfinite(v) and v > 0:
            ax.annotate(f"{v:.3g} s\n({te:g} s sim.)", (xi - w / 2, v), ha="center", va="bottom", fontsize=6.5,
                        xytext=(0, 2), textcoords="offset points")
        else:
            ax.text(xi - w / 2, 0.02, "failed", ha="center", va="bottom", fontsize=7, color="#b22222",
                    rotation=90, transform=ax.get_xaxis_transform())
    ax.set_yscale("log")
    ax.set_xticks(x, names, rotation=0, fontsize=8)
    ax.set_ylabel("wall time [s] (log scale)")
    finite = np.concatenate([ours[np.isfinite(ours) & (ours > 0)], adams[np.isfinite(adams)]])
    if finite.size:
        ax.set_ylim(finite.min() / 5, finite.max() * 20)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    ax.grid(axis="y", which="major", alpha=0.3)


def spectrum_panel(ax: Axes, t: np.ndarray, series: dict[str, np.ndarray], mesh_frequency_hz: float,
                   title: str) -> None:
    """Amplitude spectra with markers at 1, 2, 4, 6, 9 x mesh frequency."""
    fmax = 10.5 * mesh_frequency_hz
    peak, floor = 0.0, np.inf
    for label, y in series.items():
        f, a = amplitude_spectrum(np.asarray(y), float(np.median(np.diff(t))))
        keep = (f > 0) & (f <= fmax)
        ax.semilogy(f[keep] / 1e3, a[keep], lw=0.7, label=label)
        if keep.any():
            peak, floor = max(peak, float(a[keep].max())), min(floor, float(np.percentile(a[keep], 5)))
    if peak > 0:   # down to the noise floor, at most 9 decades below the peak
        ax.set_ylim(max(floor, peak * 1e-9), peak * 3)
    top = ax.get_ylim()[1]
    for k in HARMONICS:
        ax.axvline(k * mesh_frequency_hz / 1e3, color="#d62728", lw=0.7, ls="--", alpha=0.7)
        ax.text(k * mesh_frequency_hz / 1e3, top, f"{k}×", color="#d62728", fontsize=7, ha="center", va="bottom")
    ax.set_xlim(0, fmax / 1e3)
    ax.set_xlabel(f"frequency [kHz]  (mesh frequency {mesh_frequency_hz:g} Hz)")
    ax.set_ylabel("amplitude [m/s²] (log scale)")
    ax.set_title(title, fontsize=9, pad=12)
    ax.legend(loc="upper right", fontsize=7)


def envelope(t: np.ndarray, y: np.ndarray, bins: int = 1500) -> tuple[np.ndarray, np.ndarray]:
    """Min/max envelope of a long signal for plotting (keeps ripple amplitude visible, drops points)."""
    n = len(t)
    if n <= 2 * bins:
        return t, y
    size = n // bins
    m = size * bins
    tb = t[:m].reshape(bins, size)
    yb = y[:m].reshape(bins, size)
    lo, hi = yb.argmin(axis=1), yb.argmax(axis=1)
    first = np.minimum(lo, hi)
    second = np.maximum(lo, hi)
    rows = np.arange(bins)
    tt = np.column_stack([tb[rows, first], tb[rows, second]]).ravel()
    yy = np.column_stack([yb[rows, first], yb[rows, second]]).ravel()
    return np.append(tt, t[m:]), np.append(yy, y[m:])


def history_panel(ax: Axes, t: np.ndarray, series: dict[str, np.ndarray], ylabel: str, title: str,
                  window: Window | None = None, zoom: tuple[float, float] | None = None,
                  reference: tuple[str, float] | None = None, legend: str = "best",
                  emphasise: Sequence[str] = ("planet mean",)) -> None:
    """Time histories (label -> values over ``t``), optionally zoomed to ``zoom``, with a dashed red
    reference line (label, value) and the screening window shaded on full-length views; series
    named in ``emphasise`` are drawn thick and black."""
    sel = slice(None) if zoom is None else (t >= zoom[0]) & (t <= zoom[1])
    lo, hi = np.inf, -np.inf
    for label, y in series.items():
        style = {"color": "k", "lw": 1.4} if label in emphasise else {"lw": 0.7}
        tt, yy = envelope(t[sel], np.asarray(y)[sel])
        ax.plot(tt, yy, label=label, **style)
        if yy.size:
            lo, hi = min(lo, float(yy.min())), max(hi, float(yy.max()))
    if reference is not None:
        ref = reference[1]
        span = max(hi - lo, 1e-12 * max(abs(ref), 1.0))
        if zoom is None or lo - 3 * span <= ref <= hi + 3 * span:
            ax.axhline(ref, color="#d62728", ls="--", lw=1.0, label=reference[0])
        else:  # a zoom on data far from the reference: keep the data's scale and say where the reference is
            above = ref > hi
            ax.text(0.02, 0.95 if above else 0.05, f"{reference[0]}: {ref:.6g} ({'above' if above else 'below'})",
                    transform=ax.transAxes, fontsize=7, color="#d62728", va="top" if above else "bottom")
    if window is not None and zoom is None:
        ax.axvspan(window.start_s, window.end_s, color="#2ca02c", alpha=0.12, label="screening window")
    if zoom is not None:
        ax.set_xlim(*zoom)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.ticklabel_format(axis="y", useOffset=False)
    if legend and len(ax.get_legend_handles_labels()[0]) > 1:
        ax.legend(fontsize=6.5, loc=legend, ncol=2 if len(series) > 3 else 1, framealpha=0.8)
