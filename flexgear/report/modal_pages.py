"""Report pages of the modal analysis: modal tables, Campbell diagram, run-up order maps, speed response.

Computed once per report from the saved runs' variant files (no time-domain run): the selected variant and the
reference (the all-flexible model 7 when the matrix used it) linearised at their operating point
(flexgear.modal.linear) and their modes within the excitation band (10 mesh harmonics at the load case's speed,
flexgear.modal.eigenmodes); the selected variant's Campbell diagram over :data:`CAMPBELL_POINTS` speeds from rest to the
nominal speed (flexgear.modal.campbell_diagram); the run-up order map of the selected and the reference run
(flexgear.study.runup: the load case's STEP ramp of the input speed read as a run-up; also the selected variant's
run of another results folder whose ramp is slower, where the orders are resolved further down); the steady
harmonic response over the speed range (flexgear.harmonic) of the selected variant, the reference and the lumped model.

Cost. The reference's Campbell diagram is not drawn: it needs one linearisation and eigen solution per speed (for
the flexible model 7 about ten times the rigid model's). Its modes at the nominal speed are marked on the selected
variant's diagram instead. The reference's harmonic response uses its one linearisation at the nominal speed for
every speed of a coarser grid (:data:`REFERENCE_STEPS`): its gyroscopic and spin-softening terms are frozen at the
nominal speed, which the page says. Every part that fails (a variant file that no longer loads, a run without
signals) is reported on its page instead of stopping the report.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from flexgear.report.data import ReportData, saved_gearbox
from flexgear.report.figures import draw_table, fmt
from flexgear.report.layout import Page, text_block
from flexgear.results import RunResult

__all__ = ["ModalStudy", "modal_study", "modal_pages", "variant_of", "CAMPBELL_POINTS", "TABLE_MODES",
           "RESPONSE_STEPS", "REFERENCE_STEPS", "BAND_ORDERS"]

ROOT = Path(__file__).resolve().parents[2]

CAMPBELL_POINTS = 13
"""Speeds of the Campbell diagram, evenly from rest to the load case's input speed (the CLI's 0:6000:500)."""

BAND_ORDERS = 10
"""Excitation band of the modal tables: up to this mesh harmonic at the load case's speed."""

TABLE_MODES = 24
"""Modes shown per modal table (the lowest resonant ones within the band)."""

RESPONSE_SPAN = (1.0 / 12.0, 7.0 / 6.0)
"""Speed range of the harmonic response, as fractions of the load case's input speed (500-7000 rpm at 6000)."""

RESPONSE_STEPS = 66
"""Speeds of the selected variant's and the lumped model's response over :data:`RESPONSE_SPAN` (100 rpm apart at
6000 rpm)."""

REFERENCE_STEPS = 27
"""Speeds of the reference's response (coarse: 250 rpm apart at 6000 rpm, every solve is of its full size)."""

_COMPONENTS = ("input_shaft", "sun", "planets", "ring", "output_shaft", "carrier")  # carrier: a planetary stage's
_COLOURS = {"input_shaft": "#1f77b4", "sun": "#ff7f0e", "planets": "#2ca02c", "ring": "#d62728",
            "output_shaft": "#9467bd", "carrier": "#bcbd22", "outer_mesh": "#8c564b", "inner_mesh": "#e377c2",
            "residual": "#7f7f7f"}


def variant_of(run: RunResult, results_dir: Path) -> Any:
    """The variant a saved run was made from: its saved input copies, else the file its metadata names (relative
    to the package's checkout) when the copies no longer validate."""
    from flexgear.spec import load_variant

    gearbox = saved_gearbox(results_dir, run)
    own = next((results_dir / run.name / rel for rel in (run.meta.get("inputs") or {}).values()
                if str(rel).endswith(".toml") and results_dir / run.name / rel != gearbox), None)
    if own is not None and gearbox is not None:
        try:
            return load_variant(own, own.read_text(), gearbox.read_text())
        except Exception:  # an older copy (schema changed): the package's file below
            pass
    rel = run.meta.get("variant_file") or run.meta.get("source")
    if rel is None:
        raise FileNotFoundError(f"run {run.name}: no variant file recorded")
    path = Path(rel) if Path(rel).is_absolute() else ROOT / rel
    return load_variant(path)


@dataclass
class ModalStudy:
    """What the modal pages show (module docstring). ``modes``: variant name -> flexgear.modal.Modes;
    ``campbell``: the selected variant's flexgear.modal.Campbell; ``runups``: (run, side) -> flexgear.study.runup.
    RunUp; ``responses``: label -> flexgear.harmonic.Response; ``notes``: failures and approximations, by page;
    ``cpu_s``: CPU time of each part [s]."""

    selected: str | None
    reference: str | None
    nominal_rpm: float
    mesh_hz_per_rpm: float
    modes: dict[str, Any] = field(default_factory=dict)
    campbell: Any = None
    runups: dict[tuple[str, str], Any] = field(default_factory=dict)
    responses: dict[str, Any] = field(default_factory=dict)
    notes: dict[str, list[str]] = field(default_factory=dict)
    cpu_s: dict[str, float] = field(default_factory=dict)

    def note(self, page: str, text: str) -> None:
        self.notes.setdefault(page, []).append(text)


def _timed(study: ModalStudy, key: str, page: str, fn, *args, **kwargs):
    t0 = time.process_time()
    try:
        return fn(*args, **kwargs)
    except Exception as exc:  # reported on the page: the rest of the report stands
        study.note(page, f"{key}: not computed ({type(exc).__name__}: {str(exc)[:160]})")
        return None
    finally:
        study.cpu_s[key] = study.cpu_s.get(key, 0.0) + time.process_time() - t0


def modal_study(d: ReportData, others: Sequence[ReportData] = ()) -> ModalStudy:
    """Compute everything the modal pages show (module docstring) for the selected variant and the reference of
    the report's primary screening; ``others``: results folders of other load cases whose run of the selected
    variant ramps more slowly than the primary's (a run-up resolves the orders better) add its run-up map, as
    ``<folder>/<run>``."""
    from flexgear.harmonic.lumped import lumped_harmonic_response
    from flexgear.harmonic.response import harmonic_response
    from flexgear.modal import campbell, linearize, mesh_frequency_hz, period_modes
    from flexgear.study.runup import runup

    lc = d.gearbox.load_case
    nominal = float(lc.input_speed_rpm)
    selected = d.selection.variant
    reference = d.primary.reference or None
    study = ModalStudy(selected, reference if reference != selected else None, nominal,
                       mesh_frequency_hz(d.gearbox, 1.0))
    names = [n for n in (selected, study.reference) if n is not None and n in d.runs]
    variants = {}
    for name in names:
        v = _timed(study, f"{name}: variant file", "modes", variant_of, d.runs[name], d.results_dir)
        if v is not None:
            variants[name] = v
    linear = {}
    for name, v in variants.items():
        band = BAND_ORDERS * mesh_frequency_hz(v.gearbox, v.gearbox.load_case.input_speed_rpm)
        lm = _timed(study, f"{name}: linearisation", "modes", linearize, v)
        if lm is not None:
            linear[name] = lm
            m = _timed(study, f"{name}: modes", "modes", period_modes, v, None, band, first=lm)
            if m is not None:
                study.modes[name] = m
    if selected in variants:
        v = variants[selected]
        n_top = float(v.gearbox.load_case.input_speed_rpm)
        study.campbell = _timed(study, f"{selected}: Campbell", "campbell", campbell, v,
                                np.linspace(0.0, n_top, CAMPBELL_POINTS))
    runs = {name: d.runs[name] for name in names}
    ramp = float(d.runs[selected].meta.get("ramp_time_s") or 0.0) if selected in d.runs else 0.0
    for o in others:
        r = o.runs.get(selected) if selected else None
        if r is not None and r.ok and float(r.meta.get("ramp_time_s") or 0.0) > ramp:
            runs[f"{o.results_dir.name}/{selected}"] = r
    for name, run in runs.items():
        for side in ("output", "input"):
            ru = _timed(study, f"{name}: run-up map ({side})", "runup", runup, run, side,
                        campbell=study.campbell if run.name == selected else None)
            if ru is not None:
                study.runups[(name, side)] = ru
    lo, hi = RESPONSE_SPAN
    fine = np.linspace(lo * nominal, hi * nominal, RESPONSE_STEPS)
    coarse = np.linspace(lo * nominal, hi * nominal, REFERENCE_STEPS)
    if selected in variants:
        r = _timed(study, f"{selected}: harmonic response", "response", harmonic_response, variants[selected], fine)
        if r is not None:
            study.responses[selected] = r
    if study.reference in linear:
        r = _timed(study, f"{study.reference}: harmonic response", "response", harmonic_response,
                   linear[study.reference], coarse)
        if r is not None:
            study.responses[study.reference] = r
            study.note("response", f"{study.reference}: {len(coarse)} speeds only, its matrices linearised once at "
                       f"{fmt(linear[study.reference].speed_rpm)} rpm (gyroscopic and spin terms frozen there): "
                       "the full sweep costs one linearisation per speed node.")
    r = _timed(study, "lumped: harmonic response", "response", lumped_harmonic_response, d.gearbox, fine)
    if r is not None:
        study.responses["lumped"] = r
    return study


# --------------------------------------------------------------------------- modal tables
def _grouped(energy: pd.DataFrame, prefix: str) -> pd.DataFrame:
    """Energy shares per Table 3 component (planets summed, each component's elastic part added to it), plus the
    meshes and residual compliances for strain."""
    out = {}
    for c in (*_COMPONENTS, "outer_mesh", "inner_mesh", "residual"):
        cols = [k for k in energy.columns if k.startswith(f"{prefix}_")
                and (k[len(prefix) + 1:] == c or k[len(prefix) + 1:] == f"{c}_elastic"
                     or (c == "planets" and k[len(prefix) + 1:].startswith("planet_")))]
        if cols:
            out[c] = energy[cols].sum(axis=1).to_numpy()
    return pd.DataFrame(out)


def _elastic(energy: pd.DataFrame) -> np.ndarray:
    cols = [k for k in energy.columns if k.startswith("strain_") and k.endswith("_elastic")]
    return energy[cols].sum(axis=1).to_numpy() if cols else np.zeros(len(energy))


def _modal_table_page(name: str, m: Any, study: ModalStudy, role: str) -> Page:
    from flexgear.modal import resonant

    keep = resonant(m)[:TABLE_MODES]
    energy = m.energy.iloc[keep].reset_index(drop=True)
    kin, strain = _grouped(energy, "kinetic"), _grouped(energy, "strain")
    elastic = _elastic(energy)
    ticks = [f"{i + 1:>2}  {fmt(float(m.frequencies_hz[j]), 5):>7} Hz {fmt(float(m.spread_pct[j]), 2):>6} %"
              f"  {fmt(100 * float(m.damping_ratios[j]), 3):>5} %  {m.kinds[j]:<22.22} "
              f"{fmt(100 * float(elastic[i]), 2):>5} %" for i, j in enumerate(keep)]
    speed = m.model.speed_rpm
    band = BAND_ORDERS * study.mesh_hz_per_rpm * speed

    def draw(fig: Figure) -> None:
        fig.text(0.04, 0.91, f"{name} ({role}) linearised at {fmt(speed)} rpm under the load torque (flexgear.modal):"
                 f" {len(m)} modes up to {fmt(band, 4)} Hz ({BAND_ORDERS}x mesh), {len(resonant(m))} with a "
                 f"resonance peak; the lowest {len(keep)} shown, each frequency the mean over one revolution of the "
                 "slowest flexible gear and its spread over it (flexgear.modal.period). Bars: each component's "
                 "share of the mode's kinetic (K, upper) and strain (S, lower) energy, planets summed, elastic "
                 "parts included; elastic strain: the share in the flexible bodies' elastic coordinates.", fontsize=7.5,
                 wrap=True)
        bars = fig.add_axes([0.4, 0.07, 0.58, 0.8])
        fig.text(0.02, 0.875, " #        f     spread    zeta   kind                   elastic strain",
                 family="monospace", fontsize=7, weight="bold")
        y = np.arange(len(keep))
        for shares, dy, label in ((kin, -0.2, "K"), (strain, 0.2, "S")):
            left = np.zeros(len(keep))
            for c in shares.columns:
                bars.barh(y + dy, shares[c], 0.36, left=left, color=_COLOURS.get(c, "k"),
                          label=c.replace("_", " ") if label == "S" or c not in strain.columns else None)
                left = left + shares[c].to_numpy()
        bars.set_yticks(y, ticks, fontsize=7, family="monospace")
        for i in y:
            bars.text(1.005, i - 0.2, "K", fontsize=5.5, va="center", transform=bars.get_yaxis_transform())
            bars.text(1.005, i + 0.2, "S", fontsize=5.5, va="center", transform=bars.get_yaxis_transform())
        bars.set_ylim(len(keep) - 0.5, -0.5)
        bars.set_xlim(0, 1)
        bars.set_xlabel("energy share [-]")
        handles, names = bars.get_legend_handles_labels()
        seen = dict(zip(names, handles, strict=True))
        bars.legend(seen.values(), seen.keys(), fontsize=6.5, ncol=4, loc="lower center",
                    bbox_to_anchor=(0.5, 1.0), frameon=False)
    return (f"Modes of {name} ({role}): frequency, kind, energy per component", draw)


def _cost_text(study: ModalStudy, keys: tuple[str, ...]) -> str:
    parts = [f"{k} {v:.1f} s" for k, v in study.cpu_s.items() if any(s in k for s in keys)]
    return ("CPU: " + ", ".join(parts) + ".") if parts else ""


def _notes_text(study: ModalStudy, page: str) -> str:
    return " ".join(study.notes.get(page, []))


# --------------------------------------------------------------------------- Campbell
def _campbell_page(study: ModalStudy) -> Page:
    c = study.campbell

    def draw(fig: Figure) -> None:
        ax = fig.add_axes([0.07, 0.1, 0.58, 0.8])
        c.plot(ax)
        low = float(c.table.frequency_hz[c.table.frequency_hz > 0].min()) if len(c.table) else 1.0
        ax.set_yscale("log")
        ax.set_ylim(0.5 * low, c.f_max_hz)
        n = np.geomspace(max(1.0, 1e-3 * study.nominal_rpm), float(c.table.speed_rpm.max()), 100)
        for k in c.orders:  # on a log axis the orders' lines from (0, 0) need their points drawn
            ax.plot(n, k * c.mesh_hz_per_rpm * n, "--", lw=0.7, color="0.5")
        ref = study.modes.get(study.reference) if study.reference else None
        if ref is not None:
            from flexgear.modal import resonant

            f = ref.frequencies_hz[resonant(ref)]
            f = f[f <= c.f_max_hz]
            x = np.full(f.size, ref.model.speed_rpm)
            ax.plot(x, f, "_", color="#d62728", ms=9, mew=1.0, clip_on=False,
                    label=f"{study.reference} at {fmt(ref.model.speed_rpm)} rpm")
            ax.legend(fontsize=7, loc="upper left")
        side = fig.add_axes([0.68, 0.1, 0.3, 0.8])
        cross = c.crossings.copy()
        cross = cross[cross.speed_rpm >= RESPONSE_SPAN[0] * study.nominal_rpm]
        shown = cross.assign(speed_rpm=[fmt(v, 4) for v in cross.speed_rpm],
                             frequency_hz=[fmt(v, 4) for v in cross.frequency_hz]).rename(
            columns={"speed_rpm": "n [rpm]", "frequency_hz": "f [Hz]"})
        text = (f"{len(c.crossings)} crossings of {c.table['mode'].nunique()} lines with the mesh orders 1x-"
                f"{max(c.orders)}x ({CAMPBELL_POINTS} speeds, tracked by MAC >= {fmt(c.mac_min, 2)}); listed: the "
                f"{len(cross)} from {fmt(RESPONSE_SPAN[0] * study.nominal_rpm)} rpm (below it the load, ramped with "
                "the speed, hardly excites them). Frequency axis logarithmic. "
                + (f"{study.reference}'s Campbell diagram is not drawn (cost: one flexible linearisation per "
                   "speed); its modes at the nominal speed are the red marks. " if study.reference else "")
                + _cost_text(study, ("Campbell",)) + " " + _notes_text(study, "campbell"))
        text_block(side, text, width=62, fontsize=7)
        draw_table(side, shown.head(40), top=0.86, fontsize=6.2, wrap=14, max_height=0.86)
    return (f"Campbell diagram of {study.selected}: natural frequencies against input speed, mesh orders", draw)


# --------------------------------------------------------------------------- run-up
def _runup_page(study: ModalStudy, name: str) -> Page | None:
    maps = [(side, study.runups[(name, side)]) for side in ("output", "input") if (name, side) in study.runups]
    if not maps:
        return None
    campbell = study.campbell if name.split("/")[-1] == study.selected else None

    def draw(fig: Figure) -> None:
        for i, (side, ru) in enumerate(maps):
            ax = fig.add_axes([0.07, 0.58 - 0.44 * i, 0.6, 0.32])
            ru.plot(ax, campbell)
            ax.set_title(f"{name}: {side}-shaft bearing, x acceleration (ramp over {fmt(ru.ramp_end_s)} s)",
                         fontsize=8.5)
            cols = ["speed_rpm", "order", "frequency_hz", "prominence_db"]
            if "crossing_rpm" in ru.ridges.columns:
                cols += ["crossing_rpm", "kind", "error_pct"]
            if "swept_rpm" in ru.ridges.columns:
                cols += ["swept_rpm", "swept_error_pct"]
            tab = ru.ridges.head(5)[cols].rename(columns={"speed_rpm": "n [rpm]", "frequency_hz": "f [Hz]",
                                                          "prominence_db": "prom. [dB]", "crossing_rpm": "crossing",
                                                          "error_pct": "error [%]", "swept_rpm": "swept",
                                                          "swept_error_pct": "vs swept [%]"})
            right = fig.add_axes([0.7, 0.58 - 0.44 * i, 0.28, 0.32])
            right.axis("off")
            right.text(0, 1.0, f"Strongest ridges ({side})" + ("" if len(tab) else ": none found"), fontsize=8,
                       weight="bold", transform=right.transAxes)
            if len(tab):
                draw_table(right, tab.astype(object).map(lambda v: fmt(v, 4)), top=0.95, fontsize=6.3, wrap=13)
        resolved = min((float(ru.tracks["speed_rpm"].min()) for _, ru in maps if len(ru.tracks)), default=np.nan)
        text_block(fig.add_axes([0.07, 0.02, 0.9, 0.05]),
                   "Spectrogram (Hann, 10 ms) against the instantaneous input speed of the load case's STEP ramp; "
                   "ridges: maxima of the order tracks (the order demodulated along the mesh phase, Blackman-Harris "
                   f"window), ranked by prominence, at least 20 dB above the floor; orders resolved from "
                   f"{fmt(resolved, 4)} rpm (flexgear.study.runup). "
                   + ("Campbell lines and crossings: the diagram's. " if campbell is not None else
                      "No Campbell lines (the diagram is computed for the selected variant only). ")
                   + "Error: ridge speed against the crossing of the same order that the order excites (mesh "
                   "phasing) and against that crossing's swept prediction (one mode under the run's own speed "
                   "history and mesh load, tracked alike): a damped mode's ridge lies above its crossing (excitation "
                   "growing with the ramp, sweep delay). "
                   + _notes_text(study, "runup"), width=200, fontsize=7)
    return (f"Run-up order map of {name}: bearing acceleration against input speed during the ramp", draw)


# --------------------------------------------------------------------------- speed response
_PANELS = (("dynamic_factor", "K_v [-]", False), ("outer_mesh_force_max_n", "outer mesh force [N], RMS of harmonics",
                                                    True),
           ("input_bearing_accel_x_m_per_s2", "input bearing a_x [m/s²], RMS of harmonics", True),
           ("output_bearing_accel_x_m_per_s2", "output bearing a_x [m/s²], RMS of harmonics", True))


def _response_curve(r: Any, indicator: str) -> pd.Series:
    amp = r.amplitudes(indicator)
    if indicator == "dynamic_factor":
        return amp[0]
    return np.sqrt(0.5 * (amp ** 2).sum(axis=1))


def _response_page(study: ModalStudy) -> Page:
    styles = {study.selected: {"color": "#1f4e99", "lw": 1.3}, study.reference: {"color": "#d62728", "lw": 1.0,
                                                                                   "marker": ".", "ms": 4},
              "lumped": {"color": "k", "lw": 1.0, "ls": "--"}}

    def draw(fig: Figure) -> None:
        for i, (ind, label, log) in enumerate(_PANELS):
            ax = fig.add_axes([0.07 + 0.48 * (i % 2), 0.53 - 0.4 * (i // 2), 0.4, 0.32])
            for name, r in study.responses.items():
                if ind not in r.indicators:
                    continue
                curve = _response_curve(r, ind)
                ax.plot(curve.index, curve.to_numpy(), label=name, **styles.get(name, {}))
            if study.campbell is not None:
                cross = study.campbell.crossings
                cross = cross[(cross.speed_rpm > 0) & (cross.order <= 3)]
                for n in cross.speed_rpm:
                    ax.axvline(n, color="0.6", lw=0.5, ls=":")
                ax.plot([], [], color="0.6", lw=0.5, ls=":", label=f"{study.selected} crossings, orders 1-3")
            if log:
                ax.set_yscale("log")
            ax.set_xlabel("input speed [rpm]")
            ax.set_ylabel(label, fontsize=8)
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=6.5, loc="best")
        times = ", ".join(f"{k} {r.wall_time_s:.1f} s" for k, r in study.responses.items())
        text_block(fig.add_axes([0.07, 0.02, 0.9, 0.06]),
                   "Steady response to the transmission-error and tooth-friction excitation at the static loads, "
                   "mesh harmonics 1-10, with the stiffness variation's parametric coupling of the harmonics "
                   "(flexgear.harmonic, Hill's method; fails near parametric instabilities and contact loss). "
                   "RMS of harmonics: sqrt(sum_h |X_h|²/2). K_v: 1 + the largest mesh's sum of harmonic amplitudes "
                   f"over its static load. Wall time of the sweeps: {times}. " + _notes_text(study, "response"),
                   width=200, fontsize=7)
    names = ", ".join(study.responses)
    return (f"Speed response (frequency domain): {names}", draw)


def modal_pages(d: ReportData, study: ModalStudy | None = None, others: Sequence[ReportData] = ()) -> list[Page]:
    """The modal pages of the report (module docstring): the modal tables of the selected variant and of the
    reference, the Campbell diagram, the run-up maps, the speed response. ``study``: precomputed
    (:func:`modal_study`), else computed here (with ``others``)."""
    if study is None:
        study = modal_study(d, others)
    pages: list[Page] = []
    for name, role in ((study.selected, "selected"), (study.reference, "reference")):
        if name is not None and name in study.modes:
            pages.append(_modal_table_page(name, study.modes[name], study, role))
    if study.campbell is not None:
        pages.append(_campbell_page(study))
    for name in dict.fromkeys(name for name, _ in study.runups):
        page = _runup_page(study, name)
        if page is not None:
            pages.append(page)
    if study.responses:
        pages.append(_response_page(study))
    missing = [t for k in ("modes", "campbell", "runup", "response") for t in study.notes.get(k, [])
               if "not computed" in t]
    if missing:
        def draw(fig: Figure, text: str = "\n".join(missing)) -> None:
            text_block(fig.add_axes([0.05, 0.1, 0.9, 0.8]), text, width=170, fontsize=8.5)
        pages.append(("Modal analysis: parts not computed", draw))
    return pages
