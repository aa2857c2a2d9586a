"""The report's sweep pages: a sweep's table (its indicators from the runs again, with the report's screening
settings) and its sensitivity figures (the bearing accelerations against the swept number, the face width's as the
overlap ratio of one helix half)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from flexgear.report.data import ReportData
from flexgear.report.figures import draw_table
from flexgear.report.layout import Page, text_block

__all__ = ["sweep_pages"]


def _peak(d: ReportData, folder, name: str, side: str) -> float:
    """Largest radial bearing acceleration of a sweep run in its settled window (as Table 6)."""
    from flexgear.results import load_result

    r = d.runs.get(name)
    if r is None and folder is not None and (folder / name / "run.json").exists():
        r = load_result(folder / name)
    if r is None or not r.ok:
        return np.nan
    w = d.window(r)
    t = r.signals["time_s"].to_numpy()
    y = r.signal(f"{side}_bearing_accel")
    return float(y[(t >= w.start_s) & (t <= w.end_s)].max())


def sweep_pages(d: ReportData) -> list[Page]:
    """The sweep's table page and, where a number was swept, its sensitivity figures ([] without a sweep)."""
    if d.sweep is None:
        return []
    sw = d.sweep
    table = sw.table.copy()
    if sw.folder is not None:   # indicator means again from the runs, with the report's screening settings
        from flexgear.study.sweep import indicator_means

        def means(name: str) -> dict[str, float]:
            try:
                return indicator_means(sw.folder / name, d.settings)
            except (ValueError, KeyError):   # a run too short for its samples: no means, its status says why
                return {}

        fresh = pd.DataFrame([means(n) for n in table["variant"]], index=table.index)
        table[list(fresh.columns)] = fresh
    table["input_bearing_peak"] = [_peak(d, sw.folder, n, "input") for n in table["variant"]]
    table["output_bearing_peak"] = [_peak(d, sw.folder, n, "output") for n in table["variant"]]
    params = sw.parameters
    keep = ["variant", *params, "eps_beta", "status", "wall_time_s", "input_bearing_peak", "output_bearing_peak",
            "input_bearing_rms", "outer_mesh_ripple", "dynamic_factor", "transmission_error"]
    names = {"wall_time_s": "wall [s]", "input_bearing_peak": "input bearing peak [m/s²]",
             "output_bearing_peak": "output bearing peak [m/s²]", "input_bearing_rms": "input bearing RMS [m/s²]",
             "outer_mesh_ripple": "outer ripple [%]", "dynamic_factor": "K_v",
             "transmission_error": "loaded TE [m]"}
    shown = table[[c for c in keep if c in table.columns]].rename(columns=lambda c: names.get(c, c.split(".")[-1]))
    from flexgear.study.sweep import SweepResult

    plotted = SweepResult(sw.meta, table, sw.folder)

    def draw_table_page(fig: Figure) -> None:
        ax = fig.add_axes([0.03, 0.07, 0.94, 0.83])
        text_block(ax, f"Sweep '{sw.meta['name']}' ({sw.meta['grid']} grid): " + "; ".join(
            f"{k} = {', '.join(map(str, v))}" for k, v in sw.meta["parameters"].items()), width=180, fontsize=8.5)
        draw_table(ax, shown, top=0.92, fontsize=7, wrap=26)

    def draw_figures(fig: Figure) -> None:
        x = "eps_beta" if width else numeric[0]
        panels = (("input_bearing_peak", "input bearing, peak radial accel. [m/s²]"),
                  ("output_bearing_peak", "output bearing, peak radial accel. [m/s²]"),
                  ("input_bearing_rms", "input bearing accel. RMS [m/s²]"),
                  ("outer_mesh_ripple", "outer mesh-force ripple [%]"))
        for i, (y, label) in enumerate(panels):
            ax = fig.add_axes([0.07 + 0.48 * (i % 2), 0.55 - 0.42 * (i // 2), 0.4, 0.32])
            plotted.plot(ax, y, x)
            if x == "eps_beta":
                ax.axvline(1.0, color="#d62728", ls="--", lw=0.8, label="ε_β = 1")
                pub = d.gearbox.published
                row = f"{y.split('_')[0]}_bearing_peak_accel_m_per_s2"
                if "peak" in y and pub is not None and np.isfinite(pub.table6.get(row, (np.nan,) * 3)[1]):
                    published = pub.table6[row][1]
                    ax.axhline(published, color="#555555", ls=":", lw=0.9, label=f"published multibody "
                               f"{published:g}")
            ax.set_yscale("log" if "peak" in y or "rms" in y else "linear")
            ax.set_xlabel("overlap ratio ε_β of one helix half" if x == "eps_beta" else x)
            ax.set_ylabel(label, fontsize=8)
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=6.5, loc="best")
        text_block(fig.add_axes([0.07, 0.02, 0.9, 0.05]), "ε_β = (b/2) sin β / (π m_n) of one helix half (b: total "
                   "face width, double-helical). Near integer ε_β the contact-line length, and so the mesh stiffness, "
                   "hardly varies with mesh position: the mesh excitation and the bearing accelerations drop by orders "
                   "of magnitude. The study does not give b, so its bearing accelerations cannot be a target by "
                   "themselves. Peak: largest radial acceleration in the settled window (as Table 6).", width=190,
                   fontsize=7.5)
    width = any(p.endswith("face_width_mm") for p in params)
    numeric = [p for p in params if len(sw.meta["parameters"][p]) > 1
               and all(isinstance(v, (int, float)) for v in sw.meta["parameters"][p])]
    pages = [(f"Sweep table: {sw.meta['name']}", draw_table_page)]
    if numeric:     # a sensitivity figure needs a swept number
        what = "the face width (ε_β)" if width else ", ".join(numeric)
        pages.append((f"Sweep: sensitivity to {what}", draw_figures))
    return pages
