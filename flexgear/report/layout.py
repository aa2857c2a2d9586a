"""Page layout helpers of the report: a page is (title, draw(fig)); text blocks and paginated tables."""

from __future__ import annotations

import textwrap
from collections.abc import Callable

import pandas as pd
from matplotlib.figure import Figure

from flexgear.report.figures import draw_table, fmt
from flexgear.spec import COMPONENTS, OPTIONAL_COMPONENTS

__all__ = ["Page", "TABLE_LINES_PER_PAGE", "paginate", "text_block", "table_pages", "components_text", "colours"]

Page = tuple[str, Callable[[Figure], None]]
TABLE_LINES_PER_PAGE = 34


def paginate(df: pd.DataFrame, wrap: dict[str, int], lines_per_page: int = TABLE_LINES_PER_PAGE
             ) -> list[pd.DataFrame]:
    """Split a table into page-sized parts by the wrapped text lines of its rows."""
    parts, start, used = [], 0, 0
    for i, row in enumerate(df.itertuples(index=False)):
        n = max(len(textwrap.wrap(fmt(v), wrap.get(c, 30))) or 1 for c, v in zip(df.columns, row, strict=True))
        if used + n > lines_per_page and i > start:
            parts.append(df.iloc[start:i])
            start, used = i, 0
        used += n
    parts.append(df.iloc[start:])
    return parts


def text_block(ax, text: str, width: int = 120, fontsize: float = 9, top: float = 1.0) -> None:
    """Wrapped text at the top of ``ax`` (axes hidden)."""
    ax.axis("off")
    wrapped = "\n".join(textwrap.fill(p, width) if p else "" for p in text.split("\n"))
    ax.text(0.0, top, wrapped, va="top", ha="left", fontsize=fontsize, family="DejaVu Sans", transform=ax.transAxes)


def table_pages(title: str, df: pd.DataFrame, wrap: dict[str, int], widths: list[float] | None,
                intro: str = "", fontsize: float = 8) -> list[Page]:
    """One or more pages holding ``df`` (numbered "(k/n)" when it needs several)."""
    parts = paginate(df, wrap, TABLE_LINES_PER_PAGE - (4 if intro else 0))
    pages = []
    for k, part in enumerate(parts):
        label = title if len(parts) == 1 else f"{title} ({k + 1}/{len(parts)})"

        def draw(fig: Figure, part: pd.DataFrame = part, first: bool = k == 0) -> None:
            ax = fig.add_axes([0.04, 0.07, 0.92, 0.83])
            top = 1.0
            if intro and first:
                text_block(ax, intro, width=160, fontsize=8.5)
                top = 0.9
            draw_table(ax, part, col_widths=widths, wrap=wrap, top=top, fontsize=fontsize)
        pages.append((label, draw))
    return pages


def components_text(meta: dict) -> str:
    comps = meta.get("components") or {}
    flex = [c for c in (*COMPONENTS, *OPTIONAL_COMPONENTS) if comps.get(c) == "flexible"]
    return "all rigid" if comps and not flex else ("flexible: " + ", ".join(flex) if flex else "–")


def colours(names: list[str]) -> dict[str, str]:
    """One colour per run, the same on every page (tab10, then tab20 for more than ten runs)."""
    import matplotlib

    cmap = matplotlib.colormaps["tab10" if len(names) <= 10 else "tab20"]
    return {n: matplotlib.colors.to_hex(cmap(i % cmap.N)) for i, n in enumerate(names)}
