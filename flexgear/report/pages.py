"""PDF screening report from saved results (no simulation is run): ``flexgear report RESULTS_DIR``.

The report reads every run directory under ``results_dir`` (``run.json`` + ``signals.parquet``,
see :mod:`flexgear.results`): Exudyn variants are screened (:mod:`flexgear.study.screening`) with the
``[screening]`` settings of the gearbox file saved beside the runs (``<run>/inputs/``), in the study's
mode and, when the matrix used one (``screening.json``) or the gearbox names one, against a reference
variant; a run of the lumped-parameter backend (e.g. ``results/lumped``) joins the overlays, spectra
and Tables 6 and 7; a sweep (``sweep.json``) adds its table and sensitivity figures. Pages, in order:
title (selection, load case), gearbox data, assumptions, variant matrix (Table 3 as run), run time per
simulated second, Westgard decision diagrams, screening tables, one page per signal type with all variants
overlaid, bearing spectra, Tables 6 and 7, sweep pages, provenance. Where the gearbox file gives a source study's
results (``[published]``, flexgear.schema_published), the run times, Tables 6 and 7 and the spectra set them
beside the runs'. This module lays pages out; the figures are drawn by the objects'
``plot(ax)`` (:mod:`flexgear.report.result_pages`).
"""

from __future__ import annotations

import datetime as _dt
import math
import textwrap
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.backends.backend_pdf import PdfPages  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from flexgear.report import result_pages as rp  # noqa: E402
from flexgear.report.data import ReportData, documented_assumptions, gather, results_folder_problem  # noqa: E402
from flexgear.report.figures import draw_table, fmt  # noqa: E402
from flexgear.report.layout import Page, table_pages, text_block  # noqa: E402
from flexgear.report.reading_pages import contact_reading_pages  # noqa: E402
from flexgear.report.sweep_pages import sweep_pages  # noqa: E402
from flexgear.report.verdict_page import verdict_page  # noqa: E402
from flexgear.spec import COMPONENTS, OPTIONAL_COMPONENTS  # noqa: E402

__all__ = ["ReportData", "gather", "documented_assumptions", "build_report"]

A4_LANDSCAPE_IN = (11.69, 8.27)


def _load_case_text(d: ReportData) -> list[str]:
    """The load case as run (per distinct case), beside the gearbox file's (and the published values', where the
    file gives them: ``[published]``)."""
    lc = d.gearbox.load_case
    cases: dict[tuple, list[str]] = {}
    for n, r in d.runs.items():
        spec_lc = (r.meta.get("spec") or {}).get("load_case") or {}
        key = (spec_lc.get("input_speed_rpm", lc.input_speed_rpm), spec_lc.get("load_torque_nm", lc.load_torque_nm),
               r.meta.get("ramp_time_s"), r.meta.get("t_end_s"), r.meta.get("step_size_s"))
        cases.setdefault(key, []).append(n)
    lines = [f"Load case as run: input {fmt(k[0])} rpm, load torque {fmt(k[1], 6)} N·m, STEP ramps over {fmt(k[2])} s, "
             f"{fmt(k[3])} s simulated, step {fmt(k[4])} s ({', '.join(v)})" for k, v in cases.items()]
    lines.append(f"Gearbox file [load_case]: input {fmt(lc.input_speed_rpm)} rpm, {fmt(lc.load_torque_nm, 6)} N·m, "
                 f"ramps over {fmt(lc.ramp_time_s)} s, {fmt(lc.end_time_s)} s simulated, step {fmt(lc.step_size_s)} s.")
    pub = d.gearbox.published
    if pub is not None:
        lines.append(f"Published values ({pub.source}): ramps over {fmt(pub.ramp_time_s)} s, "
                     f"{fmt(pub.simulated_time_s)} s simulated.")
    return lines


_REASONING_CHARS = 500
"""Characters of a selection's reasoning on the contents page (page 1 gives it whole)."""


def _title_page(d: ReportData, contents: list[tuple[int, str]], created: str) -> Callable[[Figure], None]:
    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.06, 0.45, 0.88, 0.45])
        ok = sum(r.ok for r in d.runs.values())
        steady = d.study.table.get("steady_window")
        unsteady = [] if steady is None else list(d.study.table.loc[steady == False, "variant"])  # noqa: E712
        ref = d.reference
        lines = [f"Gearbox: {d.gearbox.title}",
                 f"Results: {d.results_dir.resolve()}  ({ok} of {len(d.runs)} variants finished"
                 + (", lumped-parameter run present)" if d.lumped is not None else ", no lumped-parameter run)"),
                 f"Created: {created}", "", *_load_case_text(d), "",
                 f"Selected model: {d.selection.variant or 'none'}"
                 + (f" (screened against the reference {ref.reference})" if ref is not None else
                    " (the study's mode: against theory)"),
                 textwrap.shorten(d.selection.reasoning, _REASONING_CHARS, placeholder=" … (page 1)")]
        if ref is not None:
            lines += [f"In the study's mode (against theory, TEa = {d.settings.allowable_total_error_pct:g} %): "
                      f"{d.study.selection.variant or 'none'}. "
                      + textwrap.shorten(d.study.selection.reasoning, _REASONING_CHARS, placeholder=" …")]
        lines += [f"Screening: lines m = {', '.join(map(str, d.lines.multipliers))}, {d.settings.sample_count} "
                  f"samples per window, window '{d.settings.window}', rule '{d.settings.selection}'."]
        if d.refused:
            lines += ["", f"Reference screening refused, nothing selected: {d.refused}."]
        if unsteady:
            lines += ["", "CAUTION: these runs have no settled window (they end before their transients decay): "
                      + ", ".join(unsteady) + ". Their Bias and CV measure the start-up, not the model's accuracy."]
        text_block(ax, "\n".join(lines), width=150, fontsize=8.5)
        half = (len(contents) + 1) // 2       # the contents in two columns below
        for k, part in enumerate((contents[:half], contents[half:])):
            col = fig.add_axes([0.06 + 0.45 * k, 0.05, 0.43, 0.38])
            text_block(col, "\n".join((["Contents"] if k == 0 else [""]) + [f"page {p:>2}   {t}" for p, t in part]),
                       width=95, fontsize=7.5)
    return draw


def case_summary(d: ReportData) -> str:
    """The load case and law of a results folder's runs, in words (to tell two verdicts' cases apart)."""
    if not d.runs:
        return f"no runs in {d.results_dir}"
    laws = {((r.meta.get("spec") or {}).get("contact") or {}).get("law", "?") for r in d.runs.values()}
    ramps = {r.meta.get("ramp_time_s") for r in d.runs.values()}
    ends = [float(r.meta["t_end_s"]) for r in d.runs.values() if r.meta.get("t_end_s") is not None]
    span = f"runs to {fmt(min(ends))}-{fmt(max(ends))} s" if ends else "no finished runs"
    ref = d.runs.get(d.primary.reference) if d.primary.reference else None
    te = ""
    if ref is not None and ref.ok and "transmission_error_m" in ref.signals:  # the law's static penetration shows here
        w = d.window(ref)
        t = ref.signals["time_s"]
        mean_te = float(ref.signals["transmission_error_m"][(t >= w.start_s) & (t <= w.end_s)].mean())
        te = f", {ref.name}'s loaded transmission error {1e6 * mean_te:.4g} um"
    return (f"{'/'.join(sorted(map(str, laws)))} law, ramps {'/'.join(fmt(x) for x in sorted(ramps, key=str))} s, "
            f"{span}{te}")


def other_verdicts(d: ReportData, others: list[ReportData]) -> list[str]:
    """One line per other results folder (another load case or law): its verdict, and whether it agrees."""
    lines = []
    for o in others:
        verdict = "none" if o.refused else (o.selection.variant or "none")
        same = verdict == ("none" if d.refused else (d.selection.variant or "none"))
        lines.append(f"{o.results_dir.name} ({case_summary(o)}): verdict {verdict}"
                     + ("" if o.selection.resolved else " (NOT RESOLVED)")
                     + (" - the same." if same else " - DIFFERENT: the verdict depends on the load case or law."))
    return lines


def write_westgard_png(d: ReportData, path: str | Path) -> Path:
    """The Westgard diagram of the verdict's screening as a PNG (the README's picture)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(7.0, 5.0))
    ax = fig.add_axes([0.1, 0.1, 0.86, 0.8])
    s = d.primary
    s.plot(ax, title=f"{d.results_dir.name}: verdict {d.selection.variant or 'none'}"
           + (f" (against {s.reference})" if s.reference else " (against theory)"))
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)
    return path


def _gearbox_page(d: ReportData) -> Callable[[Figure], None]:
    g, lc, c = d.gearbox.gears, d.gearbox.load_case, d.gearbox.contact
    th = next((r.meta["theory"] for r in d.runs.values() if "theory" in r.meta), None)

    def draw(fig: Figure) -> None:
        left = fig.add_axes([0.05, 0.08, 0.42, 0.8])
        right = fig.add_axes([0.53, 0.08, 0.42, 0.8])
        where = ("" if g.equally_spaced else
                 " at " + ", ".join(f"{math.degrees(a):.4g}" for a in g.planet_positions_rad) + "°")
        gears = ([("sun", g.sun_teeth), (f"planet (x{g.planet_count}{where})", g.planet_teeth), ("ring", g.ring_teeth)]
                 if g.has_ring else [("pinion (sun)", g.sun_teeth), ("wheel (planet)", g.planet_teeth)])
        t1 = pd.DataFrame({"gear": [n for n, _ in gears], "teeth": [z for _, z in gears],
                           "normal module [mm]": [g.normal_module_mm] * len(gears),
                           "helix angle [°]": [g.helix_angle_deg] * len(gears),
                           "normal pressure angle [°]": [g.normal_pressure_angle_deg] * len(gears)})
        left.text(0, 1.0, "Gear parameters ([gears])", fontsize=9, weight="bold", transform=left.transAxes)
        y = draw_table(left, t1, top=0.97, wrap=14)
        b = d.gearbox.bearings
        t2 = pd.DataFrame([{"bearing": n, "radial [N/m]": x.radial_stiffness_n_per_m,
                            "axial [N/m]": x.axial_stiffness_n_per_m, "tilt [N·m/rad]": x.tilt_stiffness_nm_per_rad}
                           for n, x in (("input shaft" + (" (each of 2)" if not g.has_ring else ""), b.input_shaft),
                                        ("output shaft" + (" (each of 2)" if not g.has_ring else ""), b.output_shaft),
                                        ("planet", b.planet)) if x is not None])
        left.text(0, y - 0.04, "Bearing stiffness ([bearings])", fontsize=9, weight="bold",
                  transform=left.transAxes)
        y = draw_table(left, t2, top=y - 0.07, wrap=16)
        t5 = pd.DataFrame({"quantity": ["input speed [rpm]", "load torque [N·m]", "STEP ramp time [s]",
                                        "simulated time [s]", "step size [s]"],
                           "value": [lc.input_speed_rpm, lc.load_torque_nm, lc.ramp_time_s, lc.end_time_s,
                                     lc.step_size_s]})
        left.text(0, y - 0.04, "Load case ([load_case])", fontsize=9, weight="bold", transform=left.transAxes)
        draw_table(left, t5.assign(value=[fmt(v, 8) for v in t5["value"]]), top=y - 0.07, wrap=30)
        contact = pd.DataFrame({"quantity": ["contact stiffness [N/m^e]", "exponent e", "damping / stiffness",
                                             "penetration depth [m]", "friction coefficient"],
                                "value": [c.stiffness, c.exponent, c.damping_fraction_of_stiffness,
                                          c.penetration_depth_m, c.friction_coefficient]})
        right.text(0, 1.0, "Gear contact ([contact])", fontsize=9, weight="bold", transform=right.transAxes)
        y = draw_table(right, contact, top=0.97, wrap=30)
        if th is not None:
            tv = pd.DataFrame({"theoretical value": ["input speed [°/s]", "output speed [°/s]", "ratio",
                                                     "input torque [N·m]", "output torque [N·m]",
                                                     "normal mesh force per planet [N]", "mesh frequency [Hz]"],
                               "value": [math.degrees(th["input_speed_rad_per_s"]),
                                         math.degrees(th["output_speed_rad_per_s"]), th["ratio"],
                                         th["input_torque_nm"], th["output_torque_nm"], th["mesh_force_n"],
                                         th["mesh_frequency_hz"]]})
            pub = d.gearbox.published.table6 if d.gearbox.published is not None else {}
            given = [f"{fmt(pub[k][0], 9)} {unit}" for k, unit in (("outer_mesh_force_n", "N"),
                                                                    ("output_speed_deg_per_s", "°/s"))
                     if k in pub and math.isfinite(pub[k][0])]
            right.text(0, y - 0.04, "Theory (flexgear.theory" + (f"; published: {', '.join(given)})" if given else ")"),
                       fontsize=9, weight="bold", transform=right.transAxes)
            draw_table(right, tv.assign(value=[fmt(v, 8) for v in tv["value"]]), top=y - 0.07, wrap=34)
    return draw


_RUN_COLUMNS = ["status", "simulated time [s]", "reason"]
_PROVENANCE_COLUMNS = ["run", "backend", "status", "created", "t_end [s]", "step [s]", "config hash", "input hash"]


def _variant_table(d: ReportData) -> pd.DataFrame:
    """Each run's components (Table 3's columns, and a column for an optional component such as the planetary
    stage's carrier where any run names it: rigid where another leaves it out), status and reason."""
    rows, optional = [], [c for c in OPTIONAL_COMPONENTS
                          if any(c in (r.meta.get("components") or {}) for r in d.runs.values())]
    for name, r in d.runs.items():
        comps = r.meta.get("components") or {}
        rows.append({"variant": name, **{c.replace("_", " "): comps.get(c, "–") for c in COMPONENTS},
                     **{c.replace("_", " "): comps.get(c, "rigid" if comps else "–") for c in optional},
                     "status": r.meta.get("status"), "simulated time [s]": r.meta.get("t_end_s"),
                     "reason": r.meta.get("reason") or ""})
    return pd.DataFrame(rows, columns=["variant", *(c.replace("_", " ") for c in (*COMPONENTS, *optional)),
                                       *_RUN_COLUMNS])


def _provenance_pages(d: ReportData) -> list[Page]:
    runs = list(d.runs.values()) + ([d.lumped] if d.lumped is not None else [])
    prov = pd.DataFrame([{"run": r.name, "backend": r.meta.get("backend"), "status": r.meta.get("status"),
                          "created": r.meta.get("created", ""), "t_end [s]": r.meta.get("t_end_s"),
                          "step [s]": r.meta.get("step_size_s"), "config hash": r.meta.get("config_hash", ""),
                          "input hash": r.meta.get("input_hash", "")} for r in runs], columns=_PROVENANCE_COLUMNS)
    versions: dict[str, set[str]] = {}
    for r in runs:
        for k, v in (r.meta.get("versions") or {}).items():
            versions.setdefault(k, set()).add(str(v))
    ver = pd.DataFrame({"package": list(versions), "version(s) used by the runs": [", ".join(sorted(v))
                                                                                  for v in versions.values()]})
    intro = f"Gearbox file used for the screening settings and assumptions: {d.gearbox_file} ({d.gearbox_note})."

    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.04, 0.07, 0.92, 0.83])
        text_block(ax, intro, width=170, fontsize=8.5)
        ax.text(0, 0.93, "Runs", fontsize=9, weight="bold", transform=ax.transAxes)
        y = draw_table(ax, prov, top=0.9, fontsize=7.5, max_height=0.5, empty=f"no runs in {d.results_dir}")
        ax.text(0, y - 0.05, "Software versions recorded by the runs", fontsize=9, weight="bold",
                transform=ax.transAxes)
        draw_table(ax, ver, top=y - 0.08, fontsize=7.5, wrap=60, max_height=y - 0.1, empty="no run recorded any")
    return [("Provenance: runs, configuration hashes, software versions", draw)]





def build_report(results_dir: str | Path, output: str | Path = Path("reports/screening_report.pdf"),
                 westgard_png: str | Path | None = None, also: tuple[str | Path, ...] = (), modal: bool = True) -> Path:
    """Write the screening report of the saved results in ``results_dir`` to ``output`` (PDF): page 1 the verdict,
    then the details, the assumptions in an appendix. ``westgard_png``: also the verdict's diagram as a PNG.
    ``also``: results folders of other load cases or laws whose verdicts page 1 sets beside this one (a path that is
    not a results folder, or holds no run, is skipped). ``modal``: add the modal pages (flexgear.report.modal_pages:
    modal tables, Campbell diagram, run-up maps, speed response) when a run finished. Any results folder gives a
    report (flexgear.report.data: none, failed or unsettled runs, a refused reference say so); a path that is not
    one raises flexgear.report.data.NotResultsFolder."""
    d = gather(results_dir)
    others = [o for o in (gather(x) for x in also if not results_folder_problem(x)) if o.runs]
    output = Path(output)
    created = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    assumptions = documented_assumptions(d.gearbox_file, d.gearbox)
    body: list[Page] = [rp.run_time_page(d), *rp.diagram_pages(d), *rp.screening_pages(d)]
    if rp.shown_runs(d):
        body += [*rp.overlay_pages(d), *rp.spectrum_pages(d), *rp.tables_6_7_pages(d),
                 *contact_reading_pages(d, others)]
    if modal and rp.shown_runs(d):   # no finished run: no model to analyse
        from flexgear.report.modal_pages import modal_pages

        body += modal_pages(d, others=others)
    body += sweep_pages(d)
    body += table_pages("Variant matrix (Table 3 as run)", _variant_table(d), {"reason": 60}, None)
    body += [("Gearbox data (the gearbox file) and theoretical values", _gearbox_page(d))]
    body += table_pages("Appendix: assumptions, every value the study does not give", assumptions,
                        {"table": 18, "key": 30, "value": 14, "note": 100}, [0.13, 0.2, 0.1, 0.57],
                        f"From {d.gearbox_file.name} ({d.gearbox_note}).", fontsize=7)
    body += _provenance_pages(d)
    # the other results folders' verdict diagrams first, each titled with its folder
    body = [(f"{o.results_dir.name}: {title}", draw) for o in others for title, draw in rp.diagram_pages(o)[-1:]] + body
    contents = [(i + 3, title) for i, (title, _) in enumerate(body)]
    first = verdict_page(d, others, case_summary(d), other_verdicts(d, others))
    pages: list[Page] = [("flexgear screening report: verdict", first),
                         ("Runs, screening rule and contents", _title_page(d, contents, created)), *body]
    if westgard_png is not None:
        write_westgard_png(d, westgard_png)
    output.parent.mkdir(parents=True, exist_ok=True)
    tmp = output.with_name(f".{output.name}.tmp")
    with PdfPages(tmp, metadata={"Title": "flexgear screening report", "Creator": "flexgear"}) as pdf:
        for number, (title, draw) in enumerate(pages, start=1):
            fig = plt.figure(figsize=A4_LANDSCAPE_IN)
            fig.text(0.04, 0.955, title, fontsize=13, weight="bold")
            draw(fig)
            fig.text(0.96, 0.012, f"page {number} / {len(pages)}", ha="right", fontsize=8, color="#555555")
            fig.text(0.5, 0.012, f"flexgear screening report · {created}", ha="center", fontsize=7, color="#777777")
            pdf.savefig(fig)
            plt.close(fig)
    tmp.replace(output)
    return output
