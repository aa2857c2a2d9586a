"""Page 1 of the screening report: the verdict per purpose, why the cheaper variants fail, the mesh law's static
transmission error, and the other cases' verdicts beside this one.

What it shows, all read from the results folder (no simulation):

- one row per purpose (flexgear.study.purposes): the selected variant, its zone, the deciding indicator with its
  Bias, CV and TEa and its margin, the reference's numerical error of that indicator and whether the verdict is
  resolved, the CPU-time ratio to the reference, the speed band over which it stays acceptable (``speed_bands.csv``
  of flexgear.study.speed_screening, when the matrix screened the speed range), and the other results folders'
  selection for the same purpose;
- why the cheaper variants fail a purpose, from the modes of the all-flexible reference (``modal_screening_modes.csv``
  of flexgear.study.matrix.modal_verdict): the modes near the mesh harmonics whose strain energy sits in a
  component the failing variant keeps rigid (frequency, kind, harmonic, the component's share);
- the modal screening's recommendation beside the Westgard verdict, and the numbers where they disagree;
- each mesh law's effective stiffness at the mean mesh force and its static deflection beside a steel mesh's
  (ISO 6336-1 c_gamma_alpha b, flexgear.laws.iso6336), and the reference's mean loaded transmission error split into
  the meshes' share and the wind-up (flexgear.study.purposes.static_te_split), beside the backlash.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from flexgear.report.data import ReportData
from flexgear.report.figures import draw_table, fmt
from flexgear.study.indicators import ALL_INDICATORS
from flexgear.study.purposes import (
    ALL_PURPOSES,
    PurposeVerdict,
    describe_indicator,
    indicator_ranks,
    static_te_split,
)

__all__ = ["verdict_page", "verdict_lines", "verdict_rows", "why_lines", "mesh_law_lines", "case_verdicts",
           "static_te_lines", "case_difference_lines", "band_difference_lines"]


_SHORT = {"mean_loads": "mean loads", "tooth_loads": "tooth loads", "vibration": "vibration",
          "transmission_error": "transmission error (alternating)", ALL_PURPOSES: "ALL PURPOSES"}


def _read(path: Path) -> pd.DataFrame | None:
    """A CSV table of the results folder, or None when absent or unreadable."""
    try:
        return pd.read_csv(path) if path.is_file() else None
    except (OSError, ValueError, pd.errors.ParserError):
        return None


def _name(key: str) -> str:
    return ALL_INDICATORS.get(key, key)


def _folder_label(d: ReportData) -> str:
    return d.results_dir.name or str(d.results_dir)


def _speed_band(d: ReportData, purpose: str) -> str:
    """The input-speed band [rpm] over which the purpose's selected variant stays within every TEa
    (``speed_bands.csv``); a side at the grid's end reads as "at least"."""
    bands = _read(d.results_dir / "speed_bands.csv")
    if bands is None or "purpose" not in bands:
        return "not screened"
    row = bands[bands["purpose"] == purpose]
    if row.empty:
        return "–"
    r = row.iloc[0]
    if d.reference is not None and str(r.get("selected", "")) == d.reference.reference:
        return "the reference (no comparison)"
    lo, hi = float(r.get("low_rpm", math.nan)), float(r.get("high_rpm", math.nan))
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return textwrap.shorten(str(r.get("text", "–")), 60)
    below = "≤ " if lo <= float(r.get("grid_low_rpm", -math.inf)) else ""
    above = "≥ " if hi >= float(r.get("grid_high_rpm", math.inf)) else ""
    return f"{below}{lo:.0f} to {above}{hi:.0f} rpm"


def case_verdicts(others: list[ReportData]) -> dict[str, dict[str, str]]:
    """Each other results folder's selection per purpose: folder -> {purpose: variant ("none", "refused")}."""
    out = {}
    for o in others:
        if o.refused or o.reference is None:
            out[_folder_label(o)] = {"*": "refused" if o.refused else "no reference"}
            continue
        out[_folder_label(o)] = {v.purpose: (v.selected or "none") + ("" if v.resolved else " (not resolved)")
                                 for v in o.reference.verdicts}
    return out


def verdict_rows(d: ReportData, others: list[ReportData]) -> pd.DataFrame:
    """The verdict table of page 1: one row per purpose, then all purposes (module docstring)."""
    s = d.reference
    if s is None or not s.verdicts:
        return _study_rows(d)
    cases = case_verdicts(others)
    rows = []
    for v in s.verdicts:
        row = {"purpose": _SHORT.get(v.purpose, v.purpose), "selected": v.selected or "none", "zone": v.zone,
               "deciding indicator": _name(v.deciding_indicator) if v.selected else "–",
               "Bias / CV / TEa": (f"{fmt(v.bias, 3)} / {fmt(v.cv, 2)} / {fmt(v.tea, 3)} {v.unit}"
                                   if v.selected else "–"),
               "margin": f"{100 * v.margin:.0f} % of TEa" if math.isfinite(v.margin) else "–",
               "numerical error": fmt(v.error, 2) + (f" {v.unit}" if v.selected else ""),
               "resolved": "yes" if v.resolved else "NO",
               "CPU time / ref.": fmt(v.time_ratio, 3),
               "speed band": _speed_band(d, v.purpose) if v.purpose in ("vibration", "tooth_loads", ALL_PURPOSES)
               else "–"}
        for folder, sel in cases.items():
            row[folder] = sel.get(v.purpose, sel.get("*", "–"))
        rows.append(row)
    return pd.DataFrame(rows)


def _study_rows(d: ReportData) -> pd.DataFrame:
    """The study's mode (no reference): one row per variant, its composite zone, distance and CPU time."""
    t = d.primary.table
    if t.empty:
        return pd.DataFrame()
    cols = {"variant": "variant", "status": "status", "zone": "zone", "distance_pct": f"distance [{d.lines.unit}]",
            "time_s": "CPU time [s]", "selected": "selected"}
    return t.reindex(columns=list(cols)).rename(columns=cols)


def _rigid(d: ReportData, variant: str) -> list[str]:
    run = d.runs.get(variant)
    comps = (run.meta.get("components") or {}) if run is not None else {}
    return [c for c, kind in comps.items() if kind == "rigid"]


def _component_modes(modes: pd.DataFrame, components: list[str]) -> list[str]:
    """Per component, the reference's mode near the mesh harmonics with the largest weighted share of its strain
    energy in that component, in words."""
    parts = []
    for c in components:
        col = f"share_{c}"
        if col not in modes or not (modes[col] > 0).any():
            continue
        m = modes.loc[(modes[col] * modes["weight"]).idxmax()]
        parts.append(f"{c.replace('_', ' ')}: {m['frequency_hz']:.0f} Hz ({str(m['kind']).replace('_', ' ')}, "
                     f"near {int(m['harmonic'])}x mesh, {100 * m[col]:.0f} % of its strain energy there)")
    return parts


def why_lines(d: ReportData) -> list[str]:
    """Why the cheaper variants fail each purpose, with the modes behind it (module docstring)."""
    s = d.reference
    if s is None:
        return []
    modes = _read(d.results_dir / "modal_screening_modes.csv")
    lines = []
    for v in s.verdicts:
        if v.purpose == ALL_PURPOSES or not v.failing:
            continue
        head = "cheaper variants fail" if v.selected else "no variant is acceptable, the reference included"
        text = (f"{_SHORT.get(v.purpose, v.purpose)}: {head}: "
                + "; ".join(f"{variant} {reason}" for variant, reason in v.failing) + ".")
        rigid = list(dict.fromkeys(c for variant, _ in v.failing for c in _rigid(d, variant)))
        found = _component_modes(modes, rigid) if modes is not None else []
        if found:
            text += (" Modes of the reference that those variants lose where they keep a component rigid: "
                     + "; ".join(found) + ".")
        lines.append(text)
    return lines


def _modal_line(d: ReportData, verdicts: dict[str, PurposeVerdict]) -> str:
    """The modal screening's recommendation beside the Westgard verdict; where they disagree, the numbers."""
    table = _read(d.results_dir / "modal_screening.csv")
    if table is None or "component" not in table:
        return d.modal_note.split(". Westgard")[0] if d.modal_note else ""
    must = table[table["must_be_flexible"].astype(bool)]
    shares = ", ".join(f"{r.component} {100 * r.weighted_elastic_strain_share:.1f} %" for r in must.itertuples())
    rec = d.modal_note.split("recommends ")[1].split(".")[0] if "recommends " in d.modal_note else "?"
    overall = verdicts.get(ALL_PURPOSES)
    text = (f"Modal screening of {d.primary.reference}: components that must be flexible (weighted strain share "
            f"> 5 %): {shares or 'none'}; recommends {rec}.")
    if overall is None or overall.selected is None:
        return text
    if overall.selected == rec:
        return text + f" The Westgard verdict for all purposes agrees ({rec})."
    rigid = set(_rigid(d, overall.selected))
    kept = [r for r in must.itertuples() if r.component in rigid]
    return text + (f" The Westgard verdict for all purposes is {overall.selected}, which keeps "
                   + (", ".join(f"{r.component} ({100 * r.weighted_elastic_strain_share:.1f} % share)" for r in kept)
                      or "none of them") + " rigid, yet every indicator stays within its TEa: weakest "
                   f"{_name(overall.deciding_indicator)} {fmt(overall.bias, 3)} {overall.unit} (TEa "
                   f"{fmt(overall.tea, 3)} {overall.unit}). The modes shift, the judged levels do not move past TEa.")


def mesh_law_lines(d: ReportData) -> list[str]:
    """Each law's effective mesh stiffness and static deflection at the load, beside a steel mesh's, and the
    reference's loaded TE split (module docstring)."""
    from flexgear.design import design
    from flexgear.laws.contact import effective_stiffness, mesh_laws, static_deflection

    s = d.reference
    ref = d.runs.get(s.reference) if s is not None else None
    if ref is None or not ref.ok:
        return []
    contact = (ref.meta.get("spec") or {}).get("contact") or {}
    try:
        spec = d.gearbox.with_fields("contact", **contact) if contact else d.gearbox
        des = design(spec)
        laws = mesh_laws(des)
        steel = mesh_laws(des if spec.contact.law == "iso6336" else design(spec.with_fields("contact",
                                                                                               law="iso6336")))
    except Exception as exc:  # page 1 still stands without these lines
        return [f"Mesh law at the load not evaluated: {type(exc).__name__}: {exc}"]
    ind = s.indicators[s.indicators["variant"] == ref.name].set_index("indicator")
    force = {m: float(ind.loc[f"{m}_mesh_force", "mean"]) if f"{m}_mesh_force" in ind.index
             else des.theory.mesh_force for m in laws if m in des.meshes}  # the parallel-axis pair: outer only
    delta = {m: static_deflection(force[m], laws[m]) for m in force}
    law = spec.contact.law
    head = ("impact law F = k delta^e, k = " + fmt(spec.contact.stiffness, 3) + f" N/m^{fmt(spec.contact.exponent)}"
            if law == "impact" else "linear ISO 6336-1 law")
    lines = [f"Mesh law ({head}) at the mean normal mesh force {fmt(force['outer'], 4)} N: effective stiffness "
             + ", ".join(f"{m} {fmt(effective_stiffness(force[m], laws[m]), 3)} N/m" for m in force)
             + "; static normal deflection " + ", ".join(f"{m} {1e6 * delta[m]:.4g} um" for m in delta)
             + ". A steel mesh (ISO 6336-1 c_gamma_alpha b / cos^2 beta_b): "
             + ", ".join(f"{m} {fmt(steel[m].stiffness, 3)} N/m, {1e6 * static_deflection(force[m], steel[m]):.3g} um"
                         for m in force) + "."]
    if "transmission_error" in ind.index:   # the reference's mean loaded TE over its screening window [m]
        total = float(ind.loc["transmission_error", "mean"])
        split = static_te_split(total, delta["outer"], delta.get("inner", 0.0),
                                des.gears.sun_planet.gear1.base_helix_angle)
        backlash = des.gears.sun_planet.normal_backlash
        lines.append(f"{ref.name}'s mean loaded transmission error {1e6 * total:.4g} um = the meshes' static "
                     f"deflection {1e6 * split.meshes_m:.4g} um + wind-up of shafts, bearings and supports "
                     f"{1e6 * split.windup_m:.4g} um; normal backlash {1e6 * backlash:.3g} um "
                     f"(TE / backlash = {total / backlash:.3g}). The mean TE is reported, not judged: a static "
                     "offset; its alternating part at the mesh harmonics is judged.")
    return lines


def _contact(d: ReportData) -> str:
    """The mesh law and contact stiffness of a folder's runs (two folders of the same contact differ only in
    their load case)."""
    keys = {(str(c.get("law", "?")), str(c.get("stiffness", "?")))
            for c in (((r.meta.get("spec") or {}).get("contact") or {}) for r in d.runs.values())}
    return "/".join(sorted(f"{law} {k}" for law, k in keys))


def _weakest(d: ReportData, variant: str, keys: tuple[str, ...]) -> str:
    """A variant's weakest indicator of ``keys`` in a folder's reference screening, in words ('' if absent)."""
    s = d.reference
    if s is None:
        return ""
    ind = s.indicators[(s.indicators["variant"] == variant) & s.indicators["indicator"].isin(keys)]
    if ind.empty:
        return ""
    return describe_indicator(indicator_ranks(ind, s.lines).sort_values("margin").iloc[0])


def case_difference_lines(d: ReportData, others: list[ReportData]) -> list[str]:
    """Where another folder under the same mesh law and contact stiffness (another load case) selects another
    variant for a purpose: which indicator
    differs, and how much, in each case (the cheaper of the two variants' weakest indicator of the purpose)."""
    if d.reference is None:
        return []
    here = {v.purpose: v for v in d.reference.verdicts}
    lines = []
    for o in others:
        if o.reference is None or _contact(o) != _contact(d):
            continue
        for v in o.reference.verdicts:
            mine = here.get(v.purpose)
            if mine is None or mine.selected == v.selected:
                continue
            times = d.reference.table.set_index("variant")["time_s"]
            pair = [x for x in (mine.selected, v.selected) if x]
            cheap = min(pair, key=lambda x: float(times.get(x, math.inf))) if pair else None
            if cheap is None:
                continue
            lines.append(f"{_SHORT.get(v.purpose, v.purpose)}: {_folder_label(d)} selects {mine.selected or 'none'}, "
                         f"{_folder_label(o)} {v.selected or 'none'}; {cheap}'s weakest indicator here: "
                         f"{_weakest(d, cheap, mine.indicators) or '–'}; in {_folder_label(o)}: "
                         f"{_weakest(o, cheap, v.indicators) or '–'}.")
    return lines


def band_difference_lines(d: ReportData, others: list[ReportData]) -> list[str]:
    """Where another folder of the same contact selects the same variant for a purpose but its speed band differs:
    both bands, and why they can (the frequency-domain models are linearised at the gears' angle at the end of
    each case's ramp; a flexible gear's contact columns turn with that angle)."""
    if d.reference is None:
        return []
    lines = []
    for o in others:
        if o.reference is None or _contact(o) != _contact(d):
            continue
        theirs = {v.purpose: v.selected for v in o.reference.verdicts}
        for v in d.reference.verdicts:
            if v.purpose == ALL_PURPOSES or v.selected is None or theirs.get(v.purpose) != v.selected:
                continue
            here, there = _speed_band(d, v.purpose), _speed_band(o, v.purpose)
            if "–" in (here, there) or "not screened" in (here, there) or here == there:
                continue
            lines.append(f"{_SHORT.get(v.purpose, v.purpose)} speed band of {v.selected}: {here} here, {there} in "
                         f"{_folder_label(o)}. NOT RESOLVED over speed: the two cases' variant files differ only in "
                         "their load case, whose ramp time sets the gears' angle at which the frequency-domain models "
                         "are linearised (flexgear.modal.linearize, t* = the ramp time).")
    return lines


def static_te_lines(d: ReportData) -> list[str]:
    """The transmission error beside its verdict: the reference's amplitudes at the judged mesh harmonics, and each
    variant's mean loaded TE against the reference's (a static offset, reported, not judged)."""
    s = d.reference
    if s is None or "transmission_error" not in set(s.indicators["indicator"]):
        return []
    ind = s.indicators
    ref = ind[ind["variant"] == s.reference].set_index("indicator")
    harm = [k for k in ("transmission_error_mesh1x", "transmission_error_mesh2x") if k in ref.index]
    tol = d.settings.reference_indicators
    lines = []
    if harm:
        amps = ", ".join(f"{k[-2:]} {1e6 * 10 ** (float(ref.loc[k, 'mean']) / 20.0):.3g} um" for k in harm)
        floor = getattr(tol, harm[0]).floor_um
        lines.append(f"Transmission error at the mesh harmonics, {s.reference}: {amps} (levels below {floor:g} um "
                     "count as the floor: a TE ripple no measurement resolves).")
    te = ind[ind["indicator"] == "transmission_error"]
    lines.append("Mean loaded TE against " + s.reference + f" ({1e6 * float(ref.loc['transmission_error', 'mean']):.4g}"
                 " um): " + ", ".join(f"{r.variant} {r.bias:.2g} % off" for r in te.itertuples()
                                      if r.variant != s.reference)
                 + ". Reported, not judged: a static offset that the shafts' torsional wind-up sets (rigid shafts"
                 " have none), not the dynamic fidelity the purposes ask about.")
    return lines


def verdict_lines(d: ReportData) -> list[str]:
    """The verdict in at most three lines (page 1's head and ``flexgear report``'s output)."""
    if d.refused:
        return ["Verdict: none. " + d.refused[:200]]
    s = d.primary
    if s.table.empty or not (s.table["status"] == "ok").any():
        why = d.nothing_screened or "no variant could be screened."
        return ["Verdict: none. " + (why[:1].upper() + why[1:])[:300]]
    if s.reference and s.verdicts:
        by = {v.purpose: v for v in s.verdicts}
        overall = by.get(ALL_PURPOSES)
        per = ", ".join(f"{_SHORT.get(p, p)} {v.selected or 'none'}" + ("" if v.resolved else " (NOT RESOLVED)")
                        for p, v in by.items() if p != ALL_PURPOSES)
        return [f"Verdict per purpose against {s.reference}, each indicator alone (|Bias| + 2 CV <= TEa): {per}.",
                f"For all purposes: {(overall.selected if overall else None) or 'none'}"
                + ("" if overall is None or overall.resolved else " (NOT RESOLVED)") + "."]
    sel = s.selection
    return [f"Verdict: {sel.variant or 'none'}" + ("" if sel.resolved else " (NOT RESOLVED)")
            + ", screened against theory (the study's mode).", textwrap.shorten(sel.reasoning, 220)]


def verdict_page(d: ReportData, others: list[ReportData], case_text: str, other_lines: list[str] = ()
                 ) -> Callable[[Figure], None]:
    """Page 1 (module docstring); ``case_text``: this folder's load case and law in words; ``other_lines``: the
    other folders' overall verdicts in words."""
    table = verdict_rows(d, others)
    notes = [f"This case: {case_text}.", *other_lines]
    if d.reference is not None and d.reference.verdicts:
        notes += [f"{_SHORT.get(v.purpose, v.purpose)} NOT RESOLVED: within the reference's numerical error (h against "
                  "h/2) the acceptability of " + "; ".join(v.unresolved_by) + " changes."
                  for v in d.reference.verdicts if v.unresolved_by and v.purpose != ALL_PURPOSES]
        notes += case_difference_lines(d, others)
        notes += band_difference_lines(d, others)
        notes += why_lines(d)
        modal = _modal_line(d, {v.purpose: v for v in d.reference.verdicts})
        if modal:
            notes.append(modal)
        notes += mesh_law_lines(d)
        notes += static_te_lines(d)
    elif d.refused:
        notes.append(f"Reference screening refused: {d.refused}")
    unscreened = d.primary.table[d.primary.table["status"] != "ok"] if len(d.primary.table) else d.primary.table
    if len(unscreened):
        notes.append("Not screened: " + "; ".join(f"{r.variant} ({r.status}): {r.reason}"
                                                  for r in unscreened.itertuples()) + ".")

    def draw(fig: Figure) -> None:
        fig.text(0.04, 0.925, "\n".join(textwrap.fill(t, 160) for t in verdict_lines(d)), fontsize=9, va="top")
        top = fig.add_axes([0.04, 0.59, 0.92, 0.27])
        draw_table(top, table, top=1.0, fontsize=7.0, wrap=16,
                   empty="No verdict: " + (d.refused or d.nothing_screened or "nothing was screened."))
        text = fig.add_axes([0.47, 0.04, 0.50, 0.53])
        text.axis("off")
        wrapped = "\n".join(textwrap.fill(n, 128) for n in notes)
        text.text(0.0, 1.0, wrapped, va="top", ha="left", fontsize=6.2, transform=text.transAxes)
        ax = fig.add_axes([0.06, 0.07, 0.38, 0.46])
        if len(d.primary.indicators) or (len(d.primary.table) and (d.primary.table["status"] == "ok").any()):
            d.primary.plot(ax, title="")
        else:
            ax.axis("off")
            ax.text(0.0, 1.0, "No Westgard chart: nothing was screened.", va="top", fontsize=9,
                    transform=ax.transAxes)
    return draw

