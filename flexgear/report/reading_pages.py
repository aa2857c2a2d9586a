"""A source study's contact stiffness under both readings of its length unit: a report page.

A source may print its impact law's stiffness number without a usable unit (the GTF study's section 2.1: "1.0×10^8
N·m"; ``[published.contact]`` of the gearbox file gives the number, the exponent e, the damping fraction and how it
is printed). Multibody codes such as ADAMS are commonly run in millimetres, and the IMPACT law F = k delta^e depends
on the length unit: the number read in N/mm^e is 1000^e times stiffer in SI than read in N/m^e, with the damping
"fraction of the stiffness" fraction x number N s/mm (for the GTF study 1e5 N s/mm = 1e8 N s/m,
``model_variants/quick_mm_reading/``). :func:`contact_reading_pages` sets the results folders of the two readings
side by side:

- the reference variant's static loaded transmission error (mean of ``transmission_error_m`` over its settled window,
  flexgear.study.screening.run_window) and the static mesh deflection the law predicts at the mean mesh forces
  (flexgear.laws.contact.static_deflection, effective_stiffness), with the meshes' share of the TE
  (flexgear.study.purposes.static_te_split);
- Tables 6 and 7 as the report computes them (flexgear.report.result_pages.tables_6_7_pages: compare_results over
  each run's settled window) for the study's multibody model (``[published] multibody_variant`` of the gearbox
  file) and the lumped run, beside the study's published ADAMS and lumped columns (``[published]``: without it, no
  page);
- each reading's verdict per purpose (``verdict.csv`` of the results folder);
- one sentence naming the reading whose Tables 6-7 lie closer to the source's, by the mean absolute decimal
  log-ratio of the values to the source's (:func:`log_distance`).
Without ``[published.contact]`` (or without ``[published]``) there is no page.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from flexgear.design import as_design
from flexgear.laws.contact import ContactLaw, effective_stiffness, static_deflection
from flexgear.report.data import ReportData
from flexgear.report.figures import fmt
from flexgear.report.layout import Page, table_pages
from flexgear.results import RunResult
from flexgear.schema_published import PublishedContact
from flexgear.spec import Contact
from flexgear.study.compare import TABLE7_HARMONICS, compare_results
from flexgear.study.purposes import static_te_split

__all__ = ["contact_reading_pages", "reading_of", "stiffness_n_per_m_exp", "damping_n_s_per_m", "log_distance",
           "ReadingValues", "reading_values", "READINGS", "READING_M", "READING_MM"]

READING_M, READING_MM = "N/m^e", "N/mm^e"
READINGS: dict[str, float] = {READING_M: 1.0, READING_MM: 1.0e-3}
"""Each reading of a source's stiffness unit -> the model's length unit [m] (metre, millimetre)."""


_REL_TOL = 1e-6   # a run's saved stiffness matches a reading within this relative tolerance
_TE_UM, _F_N = "µm", "N"


def stiffness_n_per_m_exp(number: float, length_unit_m: float, exponent: float) -> float:
    """The impact law's stiffness in SI [N/m^exponent] of ``number`` given in N per (model length unit)^exponent,
    ``length_unit_m`` the model's length unit [m]: F = number (delta / unit)^e, so k = number / unit^e (a millimetre
    model: number 1000^e)."""
    return number / length_unit_m**exponent


def damping_n_s_per_m(number: float, length_unit_m: float, fraction: float) -> float:
    """The impact law's maximum damping in SI [N s/m] when it is ``fraction`` of the stiffness ``number`` in the
    model's units (N s per model length unit): c = fraction number / unit (a millimetre model: 0.1 % of 1e8 is
    1e5 N s/mm = 1e8 N s/m)."""
    return fraction * number / length_unit_m


def _stiffnesses(case: ReportData) -> set[float]:
    """The impact-law stiffnesses [N/m^e] saved with the case's runs (and its lumped run)."""
    out = set()
    for r in [*case.runs.values(), *([case.lumped] if case.lumped is not None else [])]:
        contact = (r.meta.get("spec") or {}).get("contact") or {}
        if contact.get("law", "impact") == "impact" and contact.get("stiffness") is not None:
            out.add(float(contact["stiffness"]))
    return out


def reading_of(case: ReportData) -> str | None:
    """The reading (:data:`READINGS`) of the source's stiffness number (``[published.contact]`` of the case's gearbox
    file) whose SI value every impact-law run of ``case`` carries (``run.meta["spec"]["contact"]["stiffness"]``);
    None when the runs carry another value, several, or none, or the gearbox file gives no published law."""
    pub = case.gearbox.published
    if pub is None or pub.contact is None:
        return None
    ks = _stiffnesses(case)
    for name, unit in READINGS.items():
        target = stiffness_n_per_m_exp(pub.contact.stiffness_number, unit, pub.contact.exponent)
        if ks and all(math.isclose(k, target, rel_tol=_REL_TOL) for k in ks):
            return name
    return None


def log_distance(values: Mapping[str, float], study: Mapping[str, float], keys: list[str] | None = None) -> float:
    """Mean |log10(|value| / |study|)| [decades] over ``keys`` (default: every key of ``study``) where both are
    finite and non-zero; NaN when there is none."""
    terms = []
    for k in keys if keys is not None else list(study):
        a, b = abs(float(values.get(k, np.nan))), abs(float(study.get(k, np.nan)))
        if np.isfinite(a) and np.isfinite(b) and a > 0.0 and b > 0.0:
            terms.append(abs(math.log10(a / b)))
    return float(np.mean(terms)) if terms else math.nan


@dataclass
class ReadingValues:
    """What one results folder gives for the comparison.

    ``law``: its rows of the contact law and the reference's static state (label -> value, SI units in the labels);
    ``tables``: Table 6-7 values (label -> value) whose study value is ``study[label]``; ``verdicts``: purpose ->
    the selected variant in words; ``notes``: what could not be computed and why."""

    case: ReportData
    reading: str
    law: dict[str, object] = field(default_factory=dict)
    tables: dict[str, float] = field(default_factory=dict)
    study: dict[str, float] = field(default_factory=dict)
    verdicts: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    @property
    def multibody(self) -> str:
        """The variant the published multibody column belongs to (``[published] multibody_variant``)."""
        return self.case.gearbox.published.multibody_variant


def _window_mean(case: ReportData, r: RunResult, pattern: str) -> float:
    """Mean [signal unit] of the columns matching ``pattern`` over the run's settled window."""
    w = case.window(r)
    t = r.signals["time_s"]
    sel = r.signals.loc[(t >= w.start_s) & (t <= w.end_s)].filter(regex=pattern)
    return float(sel.to_numpy().mean()) if sel.size else math.nan


def _law_rows(case: ReportData, out: ReadingValues) -> None:
    """The law's parameters, the reference's static TE and the law's static deflection at its mean mesh forces."""
    ref_name = case.reference.reference if case.reference is not None else case.gearbox.screening.reference
    ref = case.runs.get(ref_name)
    spec_contact = next(((r.meta.get("spec") or {}).get("contact") for r in case.runs.values()
                         if (r.meta.get("spec") or {}).get("contact")), None)
    names = {f.name for f in dataclasses.fields(Contact)}
    law = ContactLaw.from_contact(Contact(**{k: v for k, v in spec_contact.items() if k in names})) \
        if spec_contact else None
    e = case.gearbox.published.contact.exponent
    out.law["results folder"] = case.results_dir.name
    out.law[f"contact stiffness k [N/m^{e:g}]"] = law.stiffness if law else math.nan
    out.law["maximum damping c_max [N s/m]"] = law.damping_max if law else math.nan
    out.law["penetration (cutting) depth [m]"] = law.penetration_depth if law else math.nan
    steps = sorted({float(r.meta["step_size_s"]) for r in case.runs.values() if r.meta.get("step_size_s")})
    out.law["step size [s]"] = "/".join(fmt(s) for s in steps) if steps else math.nan
    label_te = f"{ref_name}: static loaded TE (window mean) [{_TE_UM}]"
    forces = {"outer": math.nan, "inner": math.nan}
    te_m = math.nan
    if ref is None or not ref.ok or ref.signals is None:
        out.notes.append(f"{case.results_dir.name}: reference {ref_name} has no finished run")
    else:
        try:
            forces = {m: _window_mean(case, ref, rf"^{m}_mesh_force_\d+_n$") for m in forces}
            if "transmission_error_m" in ref.signals:
                te_m = _window_mean(case, ref, r"^transmission_error_m$")
        except (ValueError, KeyError) as exc:
            out.notes.append(f"{case.results_dir.name}: {ref_name}'s window ({exc})")
    out.law[label_te] = 1e6 * te_m
    known = {m: law is not None and np.isfinite(f) for m, f in forces.items()}
    deflection = {m: static_deflection(f, law) if known[m] else math.nan for m, f in forces.items()}
    for m, f in forces.items():
        out.law[f"{ref_name}: mean {m} mesh force [{_F_N}]"] = f
    for m in forces:
        out.law[f"law: static {m} mesh deflection (F/k)^(1/{e:g}) [{_TE_UM}]"] = 1e6 * deflection[m]
    for m, f in forces.items():
        out.law[f"law: {m} mesh tangent stiffness {e:g} F/delta [N/m]"] = (
            effective_stiffness(f, law) if known[m] else math.nan)
    beta_b = as_design(case.gearbox).gears.sun_planet.gear1.base_helix_angle
    split = static_te_split(te_m, deflection["outer"], deflection["inner"], beta_b)
    out.law[f"meshes' share of the TE (delta_o + delta_i) / cos(beta_b) [{_TE_UM}]"] = 1e6 * split.meshes_m
    out.law[f"rest of the TE: wind-up of shafts, bearings, bodies [{_TE_UM}]"] = 1e6 * split.windup_m


def _report_window(case: ReportData, name: str, r: RunResult) -> tuple[float, float]:
    """The window Tables 6-7 of the report use (flexgear.report.result_pages.tables_6_7_pages): a variant's own
    settled window; the lumped run: the variants' common window if it lies inside the lumped run, else its own."""
    if name != "lumped":
        w = case.window(r)
        return (w.start_s, w.end_s)
    windows = [case.window(v) for v in case.runs.values() if v.ok]
    span = (max(w.start_s for w in windows), min(w.end_s for w in windows)) if windows else (0.0, 0.0)
    if span[1] > span[0] and span[1] <= float(r.signals["time_s"].iloc[-1]) + 1e-9:
        return span
    w = case.window(r)
    return (w.start_s, w.end_s)


_T6_LABELS = {"input_speed_deg_per_s": "input speed [°/s]", "output_speed_deg_per_s": "output speed [°/s]",
              "outer_mesh_force_n": "outer mesh force [N]", "inner_mesh_force_n": "inner mesh force [N]",
              "input_bearing_peak_accel_m_per_s2": "input bearing peak accel. [m/s²]",
              "output_bearing_peak_accel_m_per_s2": "output bearing peak accel. [m/s²]"}


def _table_rows(case: ReportData, out: ReadingValues) -> None:
    """Tables 6-7 of the published multibody variant (``[published] multibody_variant``) against the published
    multibody column and of the lumped run against the lumped column (Table 6: column 1 and 2; Table 7: columns 0-1
    and 2-3)."""
    pub = case.gearbox.published
    runs = {pub.multibody_variant: (case.runs.get(pub.multibody_variant), 1, 0, "multibody"),
            "lumped": (case.lumped, 2, 2, "lumped")}
    for name, (r, col6, col7, who) in runs.items():
        t6: dict[str, float] = {}
        t7: dict[tuple[int, str], float] = {}
        if r is None or not r.ok or r.signals is None:
            out.notes.append(f"{case.results_dir.name}: no finished {name} run")
        else:
            try:
                a, b = compare_results(r, r, window=_report_window(case, name, r))
                t6 = dict(a.iloc[:, 1])
                t7 = {(k, side): float(b.iloc[i, j]) for i, k in enumerate(TABLE7_HARMONICS)
                      for j, side in enumerate(("input", "output"))}
            except (ValueError, KeyError) as exc:
                out.notes.append(f"{case.results_dir.name}: {name} not in Tables 6-7 ({exc})")
        for key, label in _T6_LABELS.items():
            row = f"T6 {name} vs source {who}: {label}"
            out.tables[row] = float(t6.get(key, math.nan))
            out.study[row] = pub.table6[key][col6] if key in pub.table6 else math.nan
        for k in TABLE7_HARMONICS:
            for j, side in enumerate(("input", "output")):
                row = f"T7 {name} vs source {who}: {side} bearing {k}× mesh [m/s²]"
                out.tables[row] = t7.get((k, side), math.nan)
                out.study[row] = pub.table7[k][col7 + j] if k in pub.table7 else math.nan


def _verdict_rows(case: ReportData, out: ReadingValues) -> None:
    """The selected variant per purpose: ``verdict.csv`` of the folder, else the reference screening's verdicts."""
    path = case.results_dir / "verdict.csv"
    if path.exists():
        table = pd.read_csv(path, keep_default_na=False)
    elif case.reference is not None and case.reference.verdicts:
        table = pd.DataFrame([v.row() for v in case.reference.verdicts])
    else:
        out.notes.append(f"{case.results_dir.name}: no verdict per purpose (no verdict.csv, no reference screening)")
        return
    for row in table.itertuples():
        resolved = str(row.resolved).strip().lower() in ("true", "1", "yes")
        zone = f" ({row.zone})" if getattr(row, "zone", "") else ""
        out.verdicts[str(row.purpose)] = (f"{row.selected or 'none'}{zone}"
                                          + ("" if resolved else ", NOT RESOLVED"))


def reading_values(case: ReportData, reading: str) -> ReadingValues:
    """Everything :func:`contact_reading_pages` shows of one results folder (``reading``: its :data:`READINGS`)."""
    out = ReadingValues(case, reading)
    _law_rows(case, out)
    _table_rows(case, out)
    _verdict_rows(case, out)
    return out


def _ramps(case: ReportData) -> set[float | None]:
    """The ramp times [s] of the case's runs (its load case; None for a run that has none)."""
    return {r.meta.get("ramp_time_s") for r in case.runs.values()}


def _pick(cases: list[ReportData], reading: str, like: ReportData | None) -> ReportData | None:
    """The first folder of ``reading``, preferring one whose ramps are those of ``like`` (the same load case)."""
    found = [c for c in cases if reading_of(c) == reading]
    same = [c for c in found if like is not None and _ramps(c) == _ramps(like)]
    return (same or found or [None])[0]


def _case_words(case: ReportData | None) -> str:
    """A results folder's name and ramp times [s] (its load case), or a dash."""
    if case is None:
        return "–"
    ramps = "/".join(fmt(x) for x in sorted(_ramps(case) - {None}))
    return f"{case.results_dir.name}, ramps {ramps} s" if ramps else case.results_dir.name


def _sentence(m: ReadingValues | None, mm: ReadingValues, keys: list[str], names: dict[str, str]) -> str:
    """Which reading reproduces the source's Tables 6-7 better, by :func:`log_distance` over ``keys`` (``names``: each
    reading's label with the source's exponent)."""
    e_mm = log_distance(mm.tables, mm.study, keys)
    r_m, r_mm = names[READING_M], names[READING_MM]
    if m is None:
        return (f"Only the {r_mm} reading was run: its Tables 6-7 lie a mean |log10(ours/source)| of "
                f"{e_mm:.3g} decades from the source's; no {r_m} folder to set beside it.")
    e_m = log_distance(m.tables, m.study, keys)
    if not (np.isfinite(e_m) and np.isfinite(e_mm)):
        return "No Table 6-7 value is there for both readings: no comparison."
    better = r_mm if e_mm < e_m else r_m
    lo, hi = min(e_m, e_mm), max(e_m, e_mm)
    by_table = ", ".join(
        f"Table {n} alone {log_distance(m.tables, m.study, part):.3g} / {log_distance(mm.tables, mm.study, part):.3g}"
        for n in (6, 7) if (part := [k for k in keys if k.startswith(f"T{n} ")]))
    source = mm.case.gearbox.published.source
    return (f"Over the {len(keys)} Table 6-7 values both readings give ({mm.multibody} against the multibody column "
            f"of {source}, the lumped run against its lumped column) the mean |log10(ours/source)| is {e_m:.3g} "
            f"decades under the {r_m} reading and {e_mm:.3g} under the {r_mm} reading: the {better} "
            f"reading reproduces the source better (its values a geometric-mean factor {10 ** lo:.3g} off the "
            f"source's, against {10 ** hi:.3g}). By table ({r_m} / {r_mm}): {by_table}.")


def _source_law(contact: PublishedContact) -> dict[str, str]:
    """The source's value of each law row, in its own words (``[published.contact]``)."""
    e = contact.exponent
    out = {f"contact stiffness k [N/m^{e:g}]": contact.printed or fmt(contact.stiffness_number),
           "maximum damping c_max [N s/m]": f"{100 * contact.damping_fraction:g} % of k"}
    if math.isfinite(contact.penetration_depth_m):
        out["penetration (cutting) depth [m]"] = f"{contact.penetration_depth_m:g} m"
    if math.isfinite(contact.step_size_s):
        out["step size [s]"] = f"{contact.step_size_s:g}"
    return out


def contact_reading_pages(d: ReportData, others: list[ReportData]) -> list[Page]:
    """The two readings of the source's contact stiffness side by side (module docstring); [] unless ``d`` or one of
    ``others`` is a millimetre-reading run (its runs' saved stiffness is the published number times 1000^e N/m^e)
    whose gearbox file gives ``[published.contact]``."""
    cases = [d, *others]
    mm_case = _pick(cases, READING_MM, d if reading_of(d) != READING_MM else None)
    if mm_case is None or mm_case.gearbox.published is None or mm_case.gearbox.published.contact is None:
        return []
    contact = mm_case.gearbox.published.contact
    e = contact.exponent
    names = {r: r.replace("^e", f"^{e:g}") for r in READINGS}
    m_case = _pick(cases, READING_M, mm_case)
    mm = reading_values(mm_case, READING_MM)
    m = reading_values(m_case, READING_M) if m_case is not None else None
    blank = ReadingValues(mm_case, READING_M)
    mv = m if m is not None else blank
    law = _source_law(contact)
    rows = [{"quantity": f"unit of the source's stiffness number {fmt(contact.stiffness_number)}",
             "study": contact.printed or "–", READING_M: names[READING_M], READING_MM: names[READING_MM]}]
    for label in mm.law:
        rows.append({"quantity": label, "study": law.get(label, "–"), READING_M: mv.law.get(label, math.nan),
                     READING_MM: mm.law[label]})
    for label in mm.tables:
        rows.append({"quantity": label, "study": mm.study[label], READING_M: mv.tables.get(label, math.nan),
                     READING_MM: mm.tables[label]})
    for purpose in dict.fromkeys([*mv.verdicts, *mm.verdicts]):
        chosen = f"{mm.multibody} ({contact.selection})" if contact.selection else mm.multibody
        rows.append({"quantity": f"verdict: {purpose}", "study": chosen if purpose == "all purposes" else "–",
                     READING_M: mv.verdicts.get(purpose, "–"), READING_MM: mm.verdicts.get(purpose, "–")})
    keys = [k for k in mm.tables if np.isfinite(mm.tables[k]) and np.isfinite(mv.tables.get(k, math.nan))]
    if m is None:
        keys = [k for k in mm.tables if np.isfinite(mm.tables[k])]
    measure = {"quantity": "mean |log10(ours / source)| over Tables 6-7 [decades]", "study": 0.0,
               READING_M: log_distance(mv.tables, mv.study, keys) if m is not None else math.nan,
               READING_MM: log_distance(mm.tables, mm.study, keys)}
    rows.append(measure)
    table = pd.DataFrame(rows, columns=["quantity", "study", READING_M, READING_MM])
    table = table.assign(**{c: [fmt(v, 4) for v in table[c]] for c in ("study", READING_M, READING_MM)})
    table = table.rename(columns={"study": "source", READING_M: f"reading {names[READING_M]}",
                                  READING_MM: f"reading {names[READING_MM]}"})
    k_mm = stiffness_n_per_m_exp(contact.stiffness_number, READINGS[READING_MM], e)
    c_mm = damping_n_s_per_m(contact.stiffness_number, READINGS[READING_MM], contact.damping_fraction)
    printed = contact.printed or fmt(contact.stiffness_number)
    intro = " ".join([
        f"The contact stiffness of {mm_case.gearbox.published.source}, {printed}, "
        f"read as {names[READING_M]} ({_case_words(m_case)}) and as {names[READING_MM]} = {k_mm:.4g} "
        f"{names[READING_M]} with c_max {c_mm:.3g} N s/m ({_case_words(mm_case)}).",
        _sentence(m, mm, keys, names),
        *(["Not shown: " + "; ".join([*mv.notes, *mm.notes]) + "."] if mv.notes or mm.notes else [])])
    return table_pages("The source's contact stiffness under both readings of its unit", table,
                       {"quantity": 70, "source": 20, f"reading {names[READING_M]}": 26,
                        f"reading {names[READING_MM]}": 26},
                       [0.46, 0.12, 0.21, 0.21], intro, fontsize=7)
