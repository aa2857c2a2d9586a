"""Report pages of the results: run times, Westgard diagrams, screening tables, overlaid signals,
spectra, Tables 6-7, sweeps. Each page lays out objects that draw themselves (``plot(ax)``).

Every page builder takes any :class:`flexgear.report.data.ReportData`: no runs, no finished run, no screened
variant, a reference refused. What cannot be drawn is one sentence saying why, and every table row that has
no values gives its status and reason."""

from __future__ import annotations

import dataclasses
import textwrap

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from flexgear.report.data import ReportData, nothing_screened_reason, short_reason
from flexgear.report.figures import draw_table, fmt, run_time_chart
from flexgear.report.layout import Page, colours, components_text, text_block
from flexgear.results import SIGNAL_TYPES, RunResult
from flexgear.schema_published import TABLE6_ROWS
from flexgear.study.compare import TABLE7_HARMONICS, BearingSpectrum, compare_results, mark_harmonics
from flexgear.study.indicators import ALL_INDICATORS
from flexgear.study.screening import Screening

__all__ = ["run_time_page", "diagram_pages", "screening_pages", "overlay_pages", "spectrum_pages",
           "tables_6_7_pages", "shown_runs"]

_NOTE_WRAP = 110                        # characters per line of a note inside a figure
NOT_RECORDED = "not recorded"           # an indicator a screened run has no signal for
_RUN_TIME_REASON_CHARS = 100           # a failed run's reason in the run-time table (the variant matrix has it all)
_RUN_TIME_COLUMNS = ["variant", "components", "status", "reason", "t_end_s", "wall_time_s", "cpu_time_s", "per_s",
                     "cpu_per_s", "published_per_s"]


def shown_runs(d: ReportData) -> dict[str, RunResult]:
    """Finished runs to draw: the variants, then the lumped model."""
    out = {n: r for n, r in d.runs.items() if r.ok}
    if d.lumped is not None and d.lumped.ok:
        out["lumped"] = d.lumped
    return out


def _number(meta: dict, key: str) -> float:
    """A number of a run's metadata (NaN when it is missing or not a number)."""
    try:
        return float(meta.get(key))
    except (TypeError, ValueError):
        return np.nan


def run_time_page(d: ReportData) -> Page:
    """Run time per simulated second [s/s] of every run, beside the published wall times where the gearbox file
    gives them (``[published] wall_time_s``); a run without a time says its status and reason."""
    pub = d.gearbox.published
    rows = []
    for name, r in d.runs.items():
        published = pub.wall_time_per_simulated_s(name) if pub is not None else np.nan
        t_end = _number(r.meta, "t_end_s")
        wall = _number(r.meta, "wall_time_s") if r.ok else np.nan
        cpu = _number(r.meta, "cpu_time_s") if r.ok else np.nan
        per = t_end if t_end > 0 else np.nan
        rows.append({"variant": name, "components": components_text(r.meta), "status": r.meta.get("status"),
                     "reason": "" if r.ok else short_reason(r.meta.get("reason"), chars=_RUN_TIME_REASON_CHARS),
                     "t_end_s": t_end, "wall_time_s": wall, "cpu_time_s": cpu, "per_s": wall / per,
                     "cpu_per_s": cpu / per, "published_per_s": published})
    runs = pd.DataFrame(rows, columns=_RUN_TIME_COLUMNS)
    empty = f"no runs in {d.results_dir}: no run time to show"

    if pub is None or not runs["published_per_s"].notna().any():
        runs = runs.drop(columns="published_per_s")

    def draw(fig: Figure) -> None:
        run_time_chart(fig.add_axes([0.07, 0.45, 0.88, 0.44]), runs, empty,
                       None if pub is None else f"{pub.source}, published ({fmt(pub.simulated_time_s)} s simulated)")
        shown = runs.rename(columns={
            "t_end_s": "simulated [s]", "wall_time_s": "wall [s]", "cpu_time_s": "CPU [s]",
            "per_s": "wall per simulated s", "cpu_per_s": "CPU per simulated s",
            "published_per_s": "published per simulated s"})
        if "published_per_s" in runs:
            shown["published / flexgear"] = runs["published_per_s"] / runs["per_s"]
        draw_table(fig.add_axes([0.04, 0.07, 0.92, 0.28]), shown, wrap={"components": 34, "reason": 34},
                   fontsize=7.5, empty=empty)
        fig.text(0.04, 0.37, "Per simulated second: ours for the simulated time shown (model build + simulation); "
                 + ("" if "published_per_s" not in runs else f"the published times ({pub.source}) for "
                    f"{fmt(pub.simulated_time_s)} s simulated on its own computer; ")
                 + "wall time includes waiting for a shared CPU, CPU time does not.", fontsize=7.5, wrap=True)
    title = "Run time per simulated second"
    return (title + (f" against the published times ({pub.source})" if "published_per_s" in runs else ""), draw)


def _diagram_page(s: Screening, title: str, note: str, why: str = "") -> Page:
    """A Westgard diagram page; ``why``: the sentence shown when no variant has a point (the zones alone)."""
    ok = s.table[s.table["status"] == "ok"]
    tea = s.lines.tea_pct
    far = len(ok) and (float(ok["bias_pct"].max()) > 4 * tea or float(ok["cv_pct"].max()) > 2 * tea)

    def draw(fig: Figure) -> None:
        if far:
            s.plot(fig.add_axes([0.06, 0.2, 0.3, 0.68]), title="all variants")
            legend = s.plot(fig.add_axes([0.41, 0.2, 0.3, 0.68]), 1.3 * tea, 0.65 * tea, title="zones at TEa scale")
        else:
            xmax = max(1.3 * tea, 1.1 * float(ok["bias_pct"].max()) if len(ok) else 0.0)
            ymax = max(0.65 * tea, 1.15 * float(ok["cv_pct"].max()) if len(ok) else 0.0)
            ax = fig.add_axes([0.07, 0.2, 0.6, 0.68])
            legend = s.plot(ax, xmax, ymax)
            if not len(ok):
                ax.text(0.5, 0.5, "no screened variant: no marker\n(the reasons beside)", ha="center",
                        va="center", fontsize=11, style="italic", transform=ax.transAxes,
                        bbox={"fc": "white", "ec": "#999999"})
        if legend:
            markers = "\n".join(legend)
        elif why and why.lower() in s.selection.reasoning.lower():   # the selection's reasoning says why
            markers = "No marker: no screened variant (why: below)."
        else:
            markers = "No marker: " + (why or "no screened variant") + "."
        head, labels = (("Outside the acceptable line [% of each indicator's TEa]", "One marker per variant and "
                         "indicator, shape per purpose.") if s.reference else (f"Markers: variant: Bias, CV "
                         f"[{s.lines.unit}], zone", "Markers closer than a few points share one label."))
        text_block(fig.add_axes([0.72, 0.2, 0.27, 0.68]), f"{head}\n{markers}\n\nSelected: "
                   f"{s.selection.variant or 'none'}. {s.selection.reasoning}", width=56, fontsize=7.2)
        text_block(fig.add_axes([0.07, 0.04, 0.9, 0.1]), f"{note} Axes as in the study (Bias on x, CV on y). Lines "
                   f"Bias + m·CV = TEa; a point on a line belongs to the better zone. {labels}", width=175, fontsize=8)
    return (title, draw)


def _refused_page(d: ReportData) -> Page:
    """The page of a reference screening that was refused: its reason instead of the diagram."""
    def draw(fig: Figure) -> None:
        text_block(fig.add_axes([0.07, 0.2, 0.86, 0.68]), f"No diagram: {d.refused}.\n\nThe verdict is none; the "
                   "study's mode (against theory) is on the page before.", width=150, fontsize=10)
    return ("Westgard decision diagram against the reference: not drawn", draw)


def diagram_pages(d: ReportData) -> list[Page]:
    """The study mode's diagram, then the reference screening's (or why it was refused): the last is the verdict's."""
    weights = dataclasses.asdict(d.settings.weights)
    table = d.study.indicators
    if len(table) and "weight" in table:  # the weights the screening used (rescaled where an indicator is missing)
        weights = dict(zip(table["indicator"], table["weight"], strict=True))
    used = ", ".join(f"{name.replace('_', ' ')} {100 * w:.4g} %" for name, w in weights.items() if w > 0)
    pages = [_diagram_page(d.study, "Westgard decision diagram, the study's mode: Bias against theory (section "
                           "2.2, Fig. 2)", f"Indicators weighted by [screening.weights] ({used}), TEa = "
                           f"{d.study.lines.tea_pct:g} %. They are fixed by kinematics and torque balance and barely "
                           "depend on flexibility.", nothing_screened_reason(d.results_dir, d.runs, d.study))]
    if d.reference is not None:
        name = d.reference.reference
        pages.append(_diagram_page(d.reference, f"Westgard decision diagram against the reference {name}: "
                                   "dynamic indicators", "Each indicator's Bias and CV in % of its own TEa "
                                   "([screening.reference_indicators]), judged alone; the reference sits on the CV "
                                   "axis.",
                                   nothing_screened_reason(d.results_dir, d.runs, d.reference)))
    elif d.refused:
        pages.append(_refused_page(d))
    return pages


def screening_pages(d: ReportData) -> list[Page]:
    pages = []
    for s, mode in ((d.study, "against theory"), (d.reference, "against the reference")):
        if s is None:
            continue
        t = s.table
        why = nothing_screened_reason(d.results_dir, d.runs, s) or "no indicator values"
        names = {"bias_pct": f"Bias [{s.lines.unit}]", "cv_pct": f"CV [{s.lines.unit}]",
                 "distance_pct": f"distance [{s.lines.unit}]", "time_s": "wall [s]",
                 "window_start_s": "window from [s]", "window_end_s": "to [s]", "steady_window": "settled"}
        comp = t.reindex(columns=["variant", "status", "reason", "bias_pct", "cv_pct", "distance_pct", "zone",
                                  "time_s", "window_start_s", "window_end_s", "steady_window", "selected"]
                         ).rename(columns=names)
        ind = s.indicators
        order = [k for k in ALL_INDICATORS if k in set(ind["indicator"])]
        means = ind.pivot(index="indicator", columns="variant", values="mean").reindex(order)
        bias = ind.pivot(index="indicator", columns="variant", values="bias").reindex(order)
        first = ind.drop_duplicates("indicator").set_index("indicator").reindex(order)
        head = pd.DataFrame({"indicator": order, "unit": first["unit"].to_numpy(), "TEa": first["tea"].to_numpy(),
                             "weight": first["weight"].to_numpy()})
        mean_tab = _explained(pd.concat([head, means.reset_index(drop=True)], axis=1), head.columns)
        bias_tab = _explained(pd.concat([head, bias.reset_index(drop=True)], axis=1), head.columns)

        def draw(fig: Figure, s: Screening = s, comp=comp, mean_tab=mean_tab, bias_tab=bias_tab, why=why) -> None:
            ax = fig.add_axes([0.04, 0.06, 0.92, 0.85])
            ax.text(0, 1.0, "Composite point per variant (no values: see status and reason)", fontsize=9,
                    weight="bold", transform=ax.transAxes)
            y = draw_table(ax, comp, top=0.975, fontsize=6.5, max_height=0.22, wrap={"reason": 40},
                           empty=f"no runs in {d.results_dir}")
            ax.text(0, y - 0.02, "Indicator means over each run's window (definitions and units: "
                    "flexgear.study.indicators)", fontsize=8.5, weight="bold", transform=ax.transAxes)
            y = draw_table(ax, mean_tab, top=y - 0.035, fontsize=6.5, wrap=30, empty=why)
            ax.text(0, y - 0.02, f"Bias of each indicator against {'theory' if not s.reference else s.reference} "
                    "in its unit (not yet scaled by its TEa)", fontsize=8.5, weight="bold", transform=ax.transAxes)
            draw_table(ax, bias_tab, top=y - 0.035, fontsize=6.5, wrap=30, empty=why)
        pages.append((f"Screening {mode}: composite points, indicators and selection", draw))
    return pages


def _explained(table: pd.DataFrame, head: pd.Index) -> pd.DataFrame:
    """An indicator table whose empty cells in a screened variant's column say why (:data:`NOT_RECORDED`: the run
    has no signal for that indicator) instead of a bare dash."""
    out = table.astype(object)
    variants = [c for c in out.columns if c not in set(head)]
    out[variants] = out[variants].where(out[variants].notna(), NOT_RECORDED)
    return out


def _unsettled(d: ReportData, runs: dict[str, RunResult]) -> list[str]:
    """The variants among ``runs`` whose analysis window is not settled (their values are of the start-up)."""
    return [n for n, r in runs.items() if n != "lumped" and (r.meta.get("settled") is False or not d.window(r).steady)]


def _settled_words(unsettled: list[str]) -> str:
    """"settled window", or what it is when some runs have none."""
    return "settled window" if not unsettled else f"window (NOT settled: {', '.join(unsettled)})"


def _window_span(d: ReportData, runs: dict[str, RunResult]) -> tuple[float, float]:
    windows = [d.window(r) for n, r in runs.items() if n != "lumped"]
    return (max(w.start_s for w in windows), min(w.end_s for w in windows)) if windows else (0.0, 0.0)


def _run_window(d: ReportData, name: str, r: RunResult, runs: dict[str, RunResult]) -> tuple[float, float]:
    """A variant's own settled window; the lumped run: the variants' common window if it lies inside
    the lumped run, else its own."""
    if name != "lumped":
        w = d.window(r)
        return (w.start_s, w.end_s)
    span = _window_span(d, runs)
    t_end = float(r.signals["time_s"].iloc[-1])
    if span[1] > span[0] and span[1] <= t_end + 1e-9:
        return span
    w = d.window(r)
    return (w.start_s, w.end_s)


def overlay_pages(d: ReportData) -> list[Page]:
    """One page per signal type: every run overlaid on common axes, full length and the last mesh cycles."""
    runs = shown_runs(d)
    col = colours(list(runs))
    th = next((r.meta["theory"] for r in runs.values() if "theory" in r.meta), {})
    span = _window_span(d, runs)
    window = _settled_words(_unsettled(d, runs))
    cycles = 5.0 / th.get("mesh_frequency_hz", 5000.0)
    pages = []
    targets = dict.fromkeys(("outer_mesh_force", "inner_mesh_force"), th.get("mesh_force_n"))
    targets |= {k: np.degrees(th[f"{k}_rad_per_s"]) for k in ("input_speed", "output_speed") if f"{k}_rad_per_s" in th}
    pair = not d.gearbox.gears.has_ring
    for kind, (title, ylabel) in SIGNAL_TYPES.items():
        having = {n: r for n, r in runs.items() if r.has(kind)}
        if not having or kind == "input_speed":
            continue
        if pair and kind == "outer_mesh_force":  # the parallel-axis pair's one mesh: pinion and wheel
            title = "mesh force (pinion-wheel)"

        def draw(fig: Figure, kind=kind, having=having, ylabel=ylabel) -> None:
            top = fig.add_axes([0.1, 0.53, 0.87, 0.36])
            zoom = fig.add_axes([0.1, 0.1, 0.38, 0.34])
            last = fig.add_axes([0.59, 0.1, 0.38, 0.34])
            for n, r in having.items():
                style = {"color": "k", "ls": "--", "lw": 1.0} if n == "lumped" else {"color": col[n]}
                r.plot(top, kind, **style)
                r.plot(zoom, kind, zoom=span, **style)
                t_end = float(r.signals["time_s"].iloc[-1])
                r.plot(last, kind, zoom=(t_end - cycles, t_end), **style)
            for ax, name in ((top, "whole run"), (zoom, f"common {window} {span[0]:.3g}–{span[1]:.3g} s"),
                             (last, "last 5 mesh cycles of each run")):
                if targets.get(kind) is not None:
                    ax.axhline(targets[kind], color="#d62728", lw=0.9, ls=":", label="theory")
                ax.set_title(name, fontsize=9)
                ax.set_xlabel("time [s]")
                ax.set_ylabel(ylabel)
                ax.grid(alpha=0.3)
                if "accel" in kind:      # the lumped model's level can be ten times the variants': log scale
                    ax.set_yscale("log")
                else:
                    ax.ticklabel_format(axis="y", useOffset=False)
            if span[1] > span[0]:
                top.axvspan(*span, color="#2ca02c", alpha=0.1, label=f"common {window}")
            top.legend(fontsize=7, ncol=min(6, len(having) + 2), loc="best", framealpha=0.85)
        pages.append((f"All variants overlaid: {title}", draw))
    return pages


def spectrum_pages(d: ReportData) -> list[Page]:
    """Both bearings' acceleration spectra of every run overlaid, the published Table 7's harmonics marked."""
    runs = shown_runs(d)
    pub = d.gearbox.published
    col = colours(list(runs))
    window = _settled_words(_unsettled(d, runs))

    def draw(fig: Figure) -> None:
        for i, side in enumerate(("input", "output")):
            ax = fig.add_axes([0.07, 0.58 - 0.44 * i, 0.9, 0.31])
            spectra, skipped = [], []
            for n, r in runs.items():
                try:
                    spectra.append(BearingSpectrum.of(r, side, _run_window(d, n, r, runs), n))
                except (ValueError, KeyError) as exc:   # e.g. a window too short for a spectrum
                    skipped.append(f"{n} ({short_reason(exc)})")
            if skipped:
                ax.text(0.99, 0.96, textwrap.fill("no spectrum: " + "; ".join(skipped), _NOTE_WRAP),
                        transform=ax.transAxes, fontsize=7, ha="right", va="top", style="italic", zorder=7,
                        bbox={"fc": "white", "ec": "#999999", "alpha": 0.9})
            if not spectra:
                ax.axis("off")
                continue
            present: set[int] = set()
            for sp in spectra:
                sp.plot(ax, color="k" if sp.name == "lumped" else col[sp.name],
                        **({"ls": "--"} if sp.name == "lumped" else {}))
                present |= set(sp.present())
            f = spectra[0].mesh_frequency_hz
            ax.set_xlim(0, 10.5 * f / 1e3)
            mark_harmonics(ax, f, sorted(present), () if pub is None else tuple(pub.table7))
            ax.set_xlabel(f"frequency [kHz] (mesh frequency {f:g} Hz)")
            ax.set_ylabel("amplitude of a_x [m/s²]")
            ax.set_title(f"{side}-shaft bearing, x acceleration, each run's {window}", fontsize=9, pad=14)
            ax.legend(fontsize=7, ncol=min(8, len(spectra)), loc="lower left", framealpha=0.85)
            ax.grid(alpha=0.3, which="major")
        published = "" if pub is None or not pub.table7 else (
            f", the published Table 7's {', '.join(map(str, pub.table7))}× ({pub.source}) in red")
        text_block(fig.add_axes([0.07, 0.01, 0.9, 0.04]), "Hann-windowed amplitude spectrum "
                   "(flexgear.study.compare). Markers at every harmonic of the mesh frequency that stands 20 dB above "
                   f"its neighbourhood in any run (grey){published}.", width=190, fontsize=7.5)
    return [("Bearing acceleration spectra, all variants overlaid", draw)]


def _load_case_note(d: ReportData) -> str:
    """A caution where runs used another load case than the published values' (``[published]``)."""
    pub = d.gearbox.published
    if pub is None:
        return ""
    cases = {(r.meta.get("ramp_time_s"), r.meta.get("t_end_s")) for r in shown_runs(d).values()}
    differ = [c for c in cases if c != (pub.ramp_time_s, pub.simulated_time_s)]
    if not differ:
        return ""
    text = ", ".join(f"ramps {fmt(a)} s / {fmt(b)} s simulated" for a, b in sorted(differ, key=str))
    return (f"CAUTION: these runs used a load case other than the published values' (ramps over "
            f"{fmt(pub.ramp_time_s)} s, {fmt(pub.simulated_time_s)} s simulated): {text}. The published values are "
            f"{pub.source}'s own model's under its load case: compare trends, not digits.")


def tables_6_7_pages(d: ReportData) -> list[Page]:
    """Tables 6 and 7 for every finished run and the lumped model, beside the published values where the gearbox
    file gives them (``[published] table6`` and ``table7``, marked "published:")."""
    runs = shown_runs(d)
    pub = d.gearbox.published
    t6 = {}
    t7 = []
    skipped = []
    for n, r in runs.items():
        try:
            a, b = compare_results(r, r, window=_run_window(d, n, r, runs))
        except (ValueError, KeyError) as exc:   # e.g. a window too short: named below the tables
            skipped.append(f"{n} ({short_reason(exc)})")
            continue
        t6.setdefault("theory", a["theory"])
        t6[n] = a.iloc[:, 1]
        row = {"run": n}
        for side in ("input", "output"):
            for k, v in zip(TABLE7_HARMONICS, b.iloc[:, 0 if side == "input" else 1], strict=True):
                row[f"{side} {k}×"] = v
        t7.append(row)
    table6 = pd.DataFrame(t6).reindex(list(TABLE6_ROWS))
    if pub is not None and pub.table6:
        multibody = f"published: multibody ({pub.multibody_variant})" if pub.multibody_variant else \
            "published: multibody"
        for j, col in enumerate(("published: theory", multibody, "published: lumped")):
            table6[col] = [pub.table6[k][j] if k in pub.table6 else np.nan for k in table6.index]
    labels = {"input_speed_deg_per_s": "input speed [°/s]", "output_speed_deg_per_s": "output speed [°/s]",
              "outer_mesh_force_n": "outer mesh force, mean [N]", "inner_mesh_force_n": "inner mesh force, mean [N]",
              "input_bearing_peak_accel_m_per_s2": "input bearing peak accel. [m/s²]",
              "output_bearing_peak_accel_m_per_s2": "output bearing peak accel. [m/s²]"}
    table6 = table6.rename(index=labels).reset_index(names="Table 6")
    for j, name in ((0, "published: multibody"), (2, "published: lumped")):
        if pub is None or not pub.table7:
            break
        row = {"run": name}
        for side, off in (("input", 0), ("output", 1)):
            row.update({f"{side} {k}×": pub.table7[k][j + off] if k in pub.table7 else np.nan
                        for k in TABLE7_HARMONICS})
        t7.append(row)
    table7 = pd.DataFrame(t7)
    unsettled = _unsettled(d, runs)
    note = " ".join(filter(None, [
        _load_case_note(d),
        f"CAUTION: {', '.join(unsettled)} have not settled: their values are of the start-up, not of the steady "
        "state." if unsettled else "",
        f"Not in the tables: {'; '.join(skipped)}." if skipped else ""]))

    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.03, 0.06, 0.94, 0.85])
        ax.text(0, 1.0, "Table 6: time-domain indicators over each run's settled window" + (
            "" if pub is None else f"; 'published:' columns: {pub.source}"), fontsize=9, weight="bold",
            transform=ax.transAxes)
        shown = table6.astype(object)
        for i, name in enumerate(shown.iloc[:, 0]):
            shown.iloc[i, 1:] = [fmt(v, 4 if "accel" in name else 9) for v in shown.iloc[i, 1:]]
        y = draw_table(ax, shown, top=0.97, fontsize=7, wrap=14)
        ax.text(0, y - 0.04, "Table 7: bearing x acceleration at multiples of the mesh frequency [m/s²] (windowed "
                "DTFT)" + ("" if pub is None else f"; 'published:' rows: {pub.source}"), fontsize=9, weight="bold",
                transform=ax.transAxes)
        y = draw_table(ax, table7.astype(object).map(lambda v: fmt(v, 3)), top=y - 0.07, fontsize=7, wrap=14)
        text_block(ax, note, width=190, fontsize=8, top=y - 0.03)
    return [("Tables 6 and 7: every variant and the lumped model" + ("" if pub is None else ", beside the published "
             "values"), draw)]
