"""PDF screening report from saved results (no simulation is run): ``flexgear report RESULTS_DIR``.

The report reads every run directory under ``results_dir`` (``run.json`` + ``signals.parquet``,
see :mod:`flexgear.results`): Exudyn variants are screened (:mod:`flexgear.study.screening`) with the
``[screening]`` settings of the gearbox file saved beside the runs (``<run>/inputs/``); a run of
the lumped-parameter backend (e.g. ``results/lumped``) joins the time histories, spectra and
Tables 6 and 7. Pages, in order: title and selection, gearbox data (study), assumptions,
variant matrix (Table 3 as run), run times against the study's ADAMS times (Table 4), Westgard
decision diagram, screening tables, per run time histories and bearing spectra, Tables 6 and 7,
provenance (versions, configuration hashes, dates).
"""

from __future__ import annotations

import datetime as _dt
import textwrap
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.backends.backend_pdf import PdfPages  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from flexgear.report.data import ReportData, documented_assumptions, gather  # noqa: E402
from flexgear.report.figures import decision_diagram, draw_table, fmt, history_panel, run_time_chart, spectrum_panel  # noqa: E402
from flexgear.results import RunResult  # noqa: E402
from flexgear.spec import COMPONENTS  # noqa: E402
from flexgear.study.reference import ADAMS_TIME_S, STUDY_TABLE6, STUDY_TABLE7  # noqa: E402
from flexgear.study.screening import INDICATORS  # noqa: E402

__all__ = ["ReportData", "gather", "documented_assumptions", "build_report"]

A4_LANDSCAPE_IN = (11.69, 8.27)
_TABLE_LINES_PER_PAGE = 34










# --------------------------------------------------------------------------- assumptions




# --------------------------------------------------------------------------- pages
Page = tuple[str, Callable[[Figure], None]]


def _paginate(df: pd.DataFrame, wrap: dict[str, int], lines_per_page: int = _TABLE_LINES_PER_PAGE
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


def _text_block(ax, text: str, width: int = 120, fontsize: float = 9, top: float = 1.0) -> None:
    ax.axis("off")
    wrapped = "\n".join(textwrap.fill(p, width) if p else "" for p in text.split("\n"))
    ax.text(0.0, top, wrapped, va="top", ha="left", fontsize=fontsize, family="DejaVu Sans", transform=ax.transAxes)


def _components_text(meta: dict) -> str:
    comps = meta.get("components") or {}
    flex = [c for c in COMPONENTS if comps.get(c) == "flexible"]
    return "all rigid" if comps and not flex else ("flexible: " + ", ".join(flex) if flex else "–")


def _title_page(d: ReportData, contents: list[tuple[int, str]], created: str) -> Callable[[Figure], None]:
    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.06, 0.08, 0.88, 0.8])
        ok = sum(r.ok for r in d.runs.values())
        steady = d.screening.get("steady_window")
        unsteady = [] if steady is None else list(d.screening.loc[steady == False, "variant"])  # noqa: E712
        lines = [f"Gearbox: {d.gearbox.title}",
                 f"Results: {d.results_dir.resolve()}  ({ok} of {len(d.runs)} variants finished"
                 + (", lumped-parameter run present)" if d.lumped is not None else ", no lumped-parameter run)"),
                 f"Created: {created}",
                 "",
                 f"Selected model: {d.selection.variant or 'none'}",
                 d.selection.reasoning,
                 f"Screening: TEa = {d.settings.allowable_total_error_pct:g} %, lines "
                 f"m = {', '.join(map(str, d.lines.multipliers))}, {d.settings.sample_count} samples per window, "
                 f"weights 20 % per indicator unless configured otherwise, rule '{d.settings.selection}'."]
        if unsteady:
            lines += ["", "CAUTION: these runs end before the load ramps do (quick runs): " + ", ".join(unsteady)
                      + ". Their windows are not steady, so their Bias and CV measure the ramp, not the model's "
                      "accuracy."]
        lines += ["", "Contents"] + [f"  page {p:>2}   {t}" for p, t in contents]
        _text_block(ax, "\n".join(lines), width=125, fontsize=9.5)
    return draw


def _gearbox_page(d: ReportData) -> Callable[[Figure], None]:
    g, lc, c = d.gearbox.gears, d.gearbox.load_case, d.gearbox.contact
    th = next((r.meta["theory"] for r in d.runs.values() if "theory" in r.meta), None)

    def draw(fig: Figure) -> None:
        left = fig.add_axes([0.05, 0.08, 0.42, 0.8])
        right = fig.add_axes([0.53, 0.08, 0.42, 0.8])
        t1 = pd.DataFrame({"gear": ["sun", f"planet (x{g.planet_count})", "ring"],
                           "teeth": [g.sun_teeth, g.planet_teeth, g.ring_teeth],
                           "normal module [mm]": [g.normal_module_mm] * 3,
                           "helix angle [°]": [g.helix_angle_deg] * 3,
                           "normal pressure angle [°]": [g.normal_pressure_angle_deg] * 3})
        left.text(0, 1.0, "Table 1: gear parameters (study)", fontsize=9, weight="bold", transform=left.transAxes)
        y = draw_table(left, t1, top=0.97, wrap=14)
        b = d.gearbox.bearings
        t2 = pd.DataFrame([{"bearing": n, "radial [N/m]": x.radial_stiffness_n_per_m,
                            "axial [N/m]": x.axial_stiffness_n_per_m, "tilt [N·m/rad]": x.tilt_stiffness_nm_per_rad}
                           for n, x in (("input shaft", b.input_shaft), ("output shaft", b.output_shaft),
                                        ("planet", b.planet))])
        left.text(0, y - 0.04, "Table 2: bearing stiffness (study)", fontsize=9, weight="bold",
                  transform=left.transAxes)
        y = draw_table(left, t2, top=y - 0.07, wrap=16)
        t5 = pd.DataFrame({"quantity": ["input speed [rpm]", "load torque [N·m]", "STEP ramp time [s]",
                                        "simulated time [s]", "step size [s]"],
                           "value": [lc.input_speed_rpm, lc.load_torque_nm, lc.ramp_time_s, lc.end_time_s,
                                     lc.step_size_s]})
        left.text(0, y - 0.04, "Table 5: load case (study)", fontsize=9, weight="bold", transform=left.transAxes)
        draw_table(left, t5.assign(value=[fmt(v, 8) for v in t5["value"]]), top=y - 0.07, wrap=30)
        contact = pd.DataFrame({"quantity": ["contact stiffness [N/m^e]", "exponent e", "damping / stiffness",
                                             "penetration depth [m]", "friction coefficient"],
                                "value": [c.stiffness, c.exponent, c.damping_fraction_of_stiffness,
                                          c.penetration_depth_m, c.friction_coefficient]})
        right.text(0, 1.0, "Gear contact, section 2.1 (study)", fontsize=9, weight="bold", transform=right.transAxes)
        y = draw_table(right, contact, top=0.97, wrap=30)
        if th is not None:
            tv = pd.DataFrame({"theoretical value": ["input speed [°/s]", "output speed [°/s]", "ratio",
                                                     "input torque [N·m]", "output torque [N·m]",
                                                     "normal mesh force per planet [N]", "mesh frequency [Hz]"],
                               "value": [th["input_speed_deg_per_s"], th["output_speed_deg_per_s"], th["ratio"],
                                         th["input_torque_nm"], th["output_torque_nm"], th["mesh_force_n"],
                                         th["mesh_frequency_hz"]]})
            right.text(0, y - 0.04, "Theory (flexgear.theory; study: 798.1894 N, -11647.0554 °/s)", fontsize=9,
                       weight="bold", transform=right.transAxes)
            draw_table(right, tv.assign(value=[fmt(v, 8) for v in tv["value"]]), top=y - 0.07, wrap=34)
    return draw


def _table_pages(title: str, df: pd.DataFrame, wrap: dict[str, int], widths: list[float] | None,
                 intro: str = "", fontsize: float = 8) -> list[Page]:
    parts = _paginate(df, wrap, _TABLE_LINES_PER_PAGE - (4 if intro else 0))
    pages = []
    for k, part in enumerate(parts):
        label = title if len(parts) == 1 else f"{title} ({k + 1}/{len(parts)})"

        def draw(fig: Figure, part: pd.DataFrame = part, first: bool = k == 0) -> None:
            ax = fig.add_axes([0.04, 0.07, 0.92, 0.83])
            top = 1.0
            if intro and first:
                _text_block(ax, intro, width=160, fontsize=8.5)
                top = 0.9
            draw_table(ax, part, col_widths=widths, wrap=wrap, top=top, fontsize=fontsize)
        pages.append((label, draw))
    return pages


def _variant_table(d: ReportData) -> pd.DataFrame:
    rows = []
    for name, r in d.runs.items():
        comps = r.meta.get("components") or {}
        rows.append({"variant": name, **{c.replace("_", " "): comps.get(c, "–") for c in COMPONENTS},
                     "status": r.meta.get("status"), "simulated time [s]": r.meta.get("t_end_s"),
                     "reason": r.meta.get("reason") or ""})
    return pd.DataFrame(rows)


def _run_time_page(d: ReportData) -> Callable[[Figure], None]:
    rows = []
    for name, r in d.runs.items():
        num = name[5:] if name.startswith("model") and name[5:].isdigit() else None
        rows.append({"variant": name, "components": _components_text(r.meta), "status": r.meta.get("status"),
                     "t_end_s": r.meta.get("t_end_s", np.nan), "wall_time_s": r.meta.get("wall_time_s", np.nan)
                     if r.ok else np.nan, "cpu_time_s": r.meta.get("cpu_time_s", np.nan) if r.ok else np.nan,
                     "total_wall_time_s": r.meta.get("total_wall_time_s", np.nan),
                     "adams_s": ADAMS_TIME_S.get(int(num), np.nan) if num else np.nan})
    runs = pd.DataFrame(rows)

    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.07, 0.43, 0.88, 0.46])
        run_time_chart(ax, runs)
        tab = fig.add_axes([0.04, 0.07, 0.92, 0.27])
        shown = runs.rename(columns={"t_end_s": "simulated [s]", "wall_time_s": "wall [s]",
                                     "cpu_time_s": "CPU [s]", "total_wall_time_s": "worker total wall [s]",
                                     "adams_s": "study ADAMS, 0.6 s [s]"})
        draw_table(tab, shown, wrap={"components": 34}, fontsize=7.5)
        fig.text(0.04, 0.355, "wall/CPU: the runner's model build + simulation; worker total: + file loading and "
                 "saving. The study's times (Table 4) are for 0.6 s simulated on its own computer.", fontsize=7.5)
    return draw


def _diagram_page(d: ReportData) -> Callable[[Figure], None]:
    """Zones at the TEa scale; a second panel when the points lie far outside it or crowd the origin."""
    ok = d.screening[d.screening["status"] == "ok"]
    tea = d.lines.tea_pct
    zones = (1.3 * tea, 0.65 * tea)
    pts = (1.25 * float(ok["bias_pct"].max()), 1.25 * float(ok["cv_pct"].max())) if len(ok) else zones
    beyond = pts[0] > zones[0] or pts[1] > zones[1]
    crowded = len(ok) > 0 and pts[0] < 0.15 * zones[0] and pts[1] < 0.15 * zones[1]

    def draw(fig: Figure) -> None:
        listing = "Composite points (weighted indicators):\n" + "\n".join(
            f"  {r.variant}: Bias {fmt(r.bias_pct, 3)} %, CV {fmt(r.cv_pct, 3)} %, sigma {fmt(r.sigma, 3)}, {r.zone}"
            for r in ok.itertuples())
        if beyond or crowded:
            a1 = fig.add_axes([0.07, 0.2, 0.4, 0.68])
            a2 = fig.add_axes([0.56, 0.2, 0.4, 0.68])
            if beyond:
                decision_diagram(a1, d.screening, d.lines, max(pts[0], zones[0]), max(pts[1], zones[1]),
                                 title="all variants (those near the origin: see the zones on the right)")
                decision_diagram(a2, d.screening, d.lines, *zones, title="zones at the scale of TEa")
            else:
                decision_diagram(a1, d.screening, d.lines, *zones, title="zones at the scale of TEa", labels=False)
                decision_diagram(a2, d.screening, d.lines, max(pts[0], 1e-9), max(pts[1], 1e-9),
                                 title="zoom on the variants' points (all in the best zone)")
            txt = fig.add_axes([0.07, 0.04, 0.88, 0.08])
        else:
            decision_diagram(fig.add_axes([0.08, 0.2, 0.6, 0.68]), d.screening, d.lines, *zones)
            txt = fig.add_axes([0.71, 0.2, 0.26, 0.68])
        _text_block(txt, listing, width=150 if beyond or crowded else 44, fontsize=8)
        fig.text(0.07, 0.125, "Axes as in the study (Bias on x, CV on y); Westgard's own charts put Bias on y and "
                 "CV on x. Lines: Bias + m·CV = TEa; a point on a line belongs to the better zone.", fontsize=8)
    return draw


def _screening_pages(d: ReportData) -> list[Page]:
    s = d.screening.astype({"time_s": object, "steady_window": object, "selected": object})
    s.loc[s["status"] != "ok", ["time_s", "steady_window", "selected"]] = None
    comp = s[["variant", "status", "bias_pct", "cv_pct", "distance_pct", "sigma", "zone", "time_s",
              "steady_window", "selected"]].rename(columns={
                  "bias_pct": "Bias [%]", "cv_pct": "CV [%]", "distance_pct": "distance [%]", "time_s": "wall [s]",
                  "steady_window": "steady window"})
    ind = d.indicators
    wide = pd.DataFrame({"variant": list(dict.fromkeys(ind["variant"]))})
    for key, label in INDICATORS.items():
        part = ind[ind["indicator"] == key].set_index("variant")
        wide[f"{label}: Bias [%]"] = wide["variant"].map(part["bias_pct"])
        wide[f"{label}: CV [%]"] = wide["variant"].map(part["cv_pct"])

    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.04, 0.07, 0.92, 0.83])
        ax.text(0, 1.0, "Composite point per variant", fontsize=9, weight="bold", transform=ax.transAxes)
        y = draw_table(ax, comp, top=0.97, fontsize=7.5, max_height=0.4)
        ax.text(0, y - 0.04, "Per indicator (samples: segment means of the window, see flexgear.study.screening)",
                fontsize=9, weight="bold", transform=ax.transAxes)
        y = draw_table(ax, wide, top=y - 0.07, fontsize=7, wrap=13, max_height=0.4)
        _text_block(ax, f"Selected model: {d.selection.variant or 'none'}.  {d.selection.reasoning}", width=170,
                    fontsize=8.5, top=y - 0.04)
    return [("Screening results and selection", draw)]


def _history_pages(d: ReportData, label: str, r: RunResult) -> list[Page]:
    s, th = r.signals, r.meta["theory"]
    t = s["time_s"].to_numpy()
    w = d.window(r)
    detail = (max(w.end_s - 0.001, w.start_s), w.end_s)
    n = int(r.meta.get("planet_count") or sum(c.startswith("outer_mesh_force_") for c in s.columns))

    def forces(kind: str) -> dict[str, np.ndarray]:
        cols = {f"planet {i}": s[f"{kind}_mesh_force_{i}_n"].to_numpy() for i in range(1, n + 1)}
        return {**cols, "planet mean": np.mean(list(cols.values()), axis=0)}

    def draw_kin(fig: Figure) -> None:
        gs = fig.add_gridspec(3, 3, left=0.07, right=0.98, top=0.9, bottom=0.16, hspace=0.6, wspace=0.38)
        history_panel(fig.add_subplot(gs[0, 0]), t, {"input": s["input_speed_deg_per_s"].to_numpy()},
                      "speed [°/s]", "input speed", w, reference=("theory", th["input_speed_deg_per_s"]),
                      legend="lower right")
        history_panel(fig.add_subplot(gs[0, 1]), t, {"output": s["output_speed_deg_per_s"].to_numpy()},
                      "speed [°/s]", "output speed", w, reference=("theory", th["output_speed_deg_per_s"]),
                      legend="upper right")
        history_panel(fig.add_subplot(gs[0, 2]), t, {"output": s["output_speed_deg_per_s"].to_numpy()},
                      "speed [°/s]", "output speed, screening window", zoom=(w.start_s, w.end_s),
                      reference=("theory", th["output_speed_deg_per_s"]), legend="")
        for row, kind, name in ((1, "outer", "outer (sun-planet)"), (2, "inner", "inner (planet-ring)")):
            f = forces(kind)
            history_panel(fig.add_subplot(gs[row, 0]), t, f, "normal force [N]", f"{name} mesh force", w,
                          reference=("theory", th["mesh_force_n"]), legend="")
            history_panel(fig.add_subplot(gs[row, 1]), t, {"planet mean": f["planet mean"]}, "normal force [N]",
                          f"{name}, planet mean, window", zoom=(w.start_s, w.end_s),
                          reference=("theory", th["mesh_force_n"]), legend="")
            ax = fig.add_subplot(gs[row, 2])
            history_panel(ax, t, f, "normal force [N]", f"{name}, last {1e3 * (detail[1] - detail[0]):.3g} ms",
                          zoom=detail, reference=("theory", th["mesh_force_n"]), legend="")
        handles, names = ax.get_legend_handles_labels()
        green = Patch(color="#2ca02c", alpha=0.12, label="screening window")
        fig.legend([*handles, green], [*names, green.get_label()], loc="lower center", ncol=len(names) + 1,
                   fontsize=8, frameon=False, bbox_to_anchor=(0.5, 0.06))
        fig.text(0.07, 0.04, f"Screening window: {w.rule}. Mesh forces: normal force per planet (both helix "
                 "halves); planet mean: their average at each step.", fontsize=7.5)

    def draw_acc(fig: Figure) -> None:
        gs = fig.add_gridspec(2, 2, left=0.07, right=0.98, top=0.9, bottom=0.12, hspace=0.45, wspace=0.2)
        sel = (t >= w.start_s) & (t <= w.end_s)
        for col, side in enumerate(("input", "output")):
            acc = {a: s[f"{side}_bearing_accel_{a}_m_per_s2"].to_numpy() for a in ("x", "y")}
            history_panel(fig.add_subplot(gs[0, col]), t,
                          {"x component": acc["x"], "radial magnitude √(x²+y²)": np.hypot(acc["x"], acc["y"])},
                          "acceleration [m/s²]", f"{side}-shaft bearing, radial acceleration", w,
                          legend="upper left")
            spectrum_panel(fig.add_subplot(gs[1, col]), t[sel], {k: v[sel] for k, v in acc.items()},
                           th["mesh_frequency_hz"], f"{side}-shaft bearing spectrum (x, y), window "
                           f"{w.start_s:.3g}–{w.end_s:.3g} s")
        fig.text(0.07, 0.04, "Spectra: Hann window, amplitude-corrected one-sided spectrum of the mean-removed "
                 "signal over the screening window (flexgear.study.compare); dashed red: 1, 2, 4, 6, 9 × mesh "
                 "frequency.",
                 fontsize=7.5)

    return [(f"Time histories: {label}", draw_kin), (f"Bearing accelerations and spectra: {label}", draw_acc)]


def _provenance_pages(d: ReportData) -> list[Page]:
    runs = list(d.runs.values()) + ([d.lumped] if d.lumped is not None else [])
    prov = pd.DataFrame([{"run": r.name, "backend": r.meta.get("backend"), "status": r.meta.get("status"),
                          "created": r.meta.get("created", ""), "t_end [s]": r.meta.get("t_end_s"),
                          "step [s]": r.meta.get("step_size_s"), "config hash": r.meta.get("config_hash", ""),
                          "input hash": r.meta.get("input_hash", "")} for r in runs])
    versions: dict[str, set[str]] = {}
    for r in runs:
        for k, v in (r.meta.get("versions") or {}).items():
            versions.setdefault(k, set()).add(str(v))
    ver = pd.DataFrame({"package": list(versions), "version(s) used by the runs": [", ".join(sorted(v))
                                                                                  for v in versions.values()]})
    intro = f"Gearbox file used for the screening settings and assumptions: {d.gearbox_file} ({d.gearbox_note})."

    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.04, 0.07, 0.92, 0.83])
        _text_block(ax, intro, width=170, fontsize=8.5)
        ax.text(0, 0.93, "Runs", fontsize=9, weight="bold", transform=ax.transAxes)
        y = draw_table(ax, prov, top=0.9, fontsize=7.5, max_height=0.5)
        ax.text(0, y - 0.05, "Software versions recorded by the runs", fontsize=9, weight="bold",
                transform=ax.transAxes)
        draw_table(ax, ver, top=y - 0.08, fontsize=7.5, wrap=60, max_height=y - 0.1)
    return [("Provenance: runs, configuration hashes, software versions", draw)]




def _tables_6_7_pages(d: ReportData) -> list[Page]:
    """Tables 6 and 7: theory, our multibody (selected) and lumped runs (flexgear.study.compare), the study's."""
    from flexgear.study.compare import compare_results

    mbd = d.runs.get(d.selection.variant) if d.selection.variant else None
    ours = [r for r in (mbd, d.lumped) if r is not None and r.ok]
    notes = []
    if not ours:
        t6 = pd.DataFrame(index=pd.Index(list(STUDY_TABLE6), name="indicator"))
        t7 = pd.DataFrame(index=pd.Index(list(STUDY_TABLE7), name="mesh_harmonic"))
        notes.append("No finished run to compare: only the study's values are shown.")
    else:
        t6 = None
        if len(ours) == 2:
            try:
                t6, t7 = compare_results(*ours)
            except ValueError as exc:          # e.g. runs of different lengths share no window
                notes.append(f"The lumped run is not compared ({exc}).")
                ours = ours[:1]
        if t6 is None:
            t6, t7 = compare_results(ours[0], ours[0])
        w = t6.attrs["window_s"]
        keep = 1 + len(ours)                   # one run only: drop its duplicate column
        t6 = t6.iloc[:, :keep]
        t7 = t7.iloc[:, :2 * len(ours)]
        t6.columns = ["theory"] + [r.name if r.name == r.meta.get("backend") else f"{r.name} ({r.meta.get('backend')})"
                                   for r in ours]
        t7.columns = [f"{r.name}: {side}" for r in ours for side in ("input", "output")]
        notes.append(f"flexgear values over the window {w[0]:.4g}–{w[1]:.4g} s (flexgear.study.compare); Table 7: "
                     "x component of the bearing acceleration, windowed DTFT at each harmonic.")
        if d.lumped is None:
            notes.append(f"No lumped-parameter run in {d.results_dir} (run `flexgear lpm ... --out "
                         f"{d.results_dir}`), so the lumped column is the study's only.")
    study6 = pd.DataFrame(STUDY_TABLE6, index=["study theory", "study ADAMS", "study lumped"]).T
    t6 = t6.join(study6, how="outer").reindex(list(STUDY_TABLE6))
    study7 = pd.DataFrame(STUDY_TABLE7, index=["study ADAMS: input", "study ADAMS: output", "study lumped: input",
                                            "study lumped: output"]).T
    t7 = t7.join(study7, how="outer")
    labels = {"input_speed_deg_per_s": "input speed [°/s]", "output_speed_deg_per_s": "output speed [°/s]",
              "outer_mesh_force_n": "outer mesh force, mean [N]", "inner_mesh_force_n": "inner mesh force, mean [N]",
              "input_bearing_peak_accel_m_per_s2": "input bearing peak radial accel. [m/s²]",
              "output_bearing_peak_accel_m_per_s2": "output bearing peak radial accel. [m/s²]"}
    t6 = t6.rename(index=labels).reset_index(names="Table 6 (time domain)")
    t7 = t7.reset_index(names="× mesh frequency")

    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.04, 0.07, 0.92, 0.83])
        ax.text(0, 1.0, "Table 6: time-domain indicators", fontsize=9, weight="bold", transform=ax.transAxes)
        shown = t6.astype(object)
        for i, name in enumerate(shown.iloc[:, 0]):
            digits = 4 if "accel" in name else 9
            shown.iloc[i, 1:] = [fmt(v, digits) for v in shown.iloc[i, 1:]]
        y = draw_table(ax, shown, top=0.97, fontsize=7.5, wrap=22)
        ax.text(0, y - 0.05, "Table 7: bearing acceleration amplitude at multiples of the mesh frequency [m/s²]",
                fontsize=9, weight="bold", transform=ax.transAxes)
        y = draw_table(ax, t7, top=y - 0.08, fontsize=7.5, wrap=16)
        _text_block(ax, " ".join(notes), width=170, fontsize=8, top=y - 0.04)
    return [("Tables 6 and 7: theory, multibody, lumped-parameter model", draw)]


def build_report(results_dir: str | Path, output: str | Path = Path("reports/screening_report.pdf")) -> Path:
    """Write the screening report of the saved results in ``results_dir`` to ``output`` (PDF)."""
    d = gather(results_dir)
    output = Path(output)
    created = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    assumptions = documented_assumptions(d.gearbox_file)
    body: list[Page] = [("Gearbox data from the study and theoretical values", _gearbox_page(d))]
    body += _table_pages("Assumptions: every value the study does not give", assumptions,
                         {"table": 18, "key": 30, "value": 14, "note": 100}, [0.13, 0.2, 0.1, 0.57],
                         f"From {d.gearbox_file.name} ({d.gearbox_note}).", fontsize=7)
    body += _table_pages("Variant matrix (Table 3 as run)", _variant_table(d), {"reason": 60}, None)
    body += [("Run times against the study's ADAMS times (Table 4)", _run_time_page(d)),
             ("Westgard decision diagram (section 2.2, Fig. 2)", _diagram_page(d))]
    body += _screening_pages(d)
    shown = [(n, r) for n, r in d.runs.items() if r.ok]
    if d.lumped is not None and d.lumped.ok:
        shown.append(("lumped-parameter model", d.lumped))
    for name, r in shown:
        body += _history_pages(d, name + (" (selected)" if name == d.selection.variant else ""), r)
    body += _tables_6_7_pages(d)
    body += _provenance_pages(d)
    contents = [(i + 2, title) for i, (title, _) in enumerate(body)]
    pages: list[Page] = [("flexgear screening report", _title_page(d, contents, created)), *body]
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
