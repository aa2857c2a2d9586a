"""What the report reads: the saved runs of a results folder, the gearbox file and its documented assumptions."""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from flexgear.report.figures import fmt
from flexgear.results import RunResult, load_result
from flexgear.spec import GearboxSpec, ScreeningSettings, SpecError, load_gearbox
from flexgear.study.screening import (
    DecisionLines,
    ReferenceNotUsable,
    Screening,
    Selection,
    Window,
    run_window,
    screen,
)
from flexgear.study.sweep import SweepResult

DEFAULT_GEARBOX = Path(__file__).resolve().parents[2] / "model_variants" / "gearbox.toml"


@dataclass
class ReportData:
    """Everything the report shows, gathered from a results directory."""

    results_dir: Path
    runs: dict[str, RunResult]          # Exudyn variants, in natural order
    lumped: RunResult | None
    gearbox: GearboxSpec
    gearbox_file: Path
    gearbox_note: str
    settings: ScreeningSettings
    study: Screening                    # the study's mode: Bias against theory
    reference: Screening | None         # against a reference variant, if one was used or configured
    sweep: SweepResult | None = None
    refused: str = ""                   # why the reference screening was refused (its reference has not settled)
    modal_note: str = ""                # the modal screening beside the Westgard verdict (modal_screening.txt)

    @property
    def primary(self) -> Screening:
        """The screening the selection is taken from: the reference screening if there is one."""
        return self.reference if self.reference is not None else self.study

    @property
    def screening(self) -> pd.DataFrame:
        return self.primary.table

    @property
    def indicators(self) -> pd.DataFrame:
        return self.primary.indicators

    @property
    def selection(self) -> Selection:
        return self.primary.selection

    @property
    def lines(self) -> DecisionLines:
        return self.primary.lines

    def window(self, result: RunResult) -> Window:
        return run_window(result, self.settings)


def _natural(name: str) -> tuple:
    digits = "".join(ch for ch in name if ch.isdigit())
    return (name.rstrip("0123456789"), int(digits) if digits else -1, name)


def _find_gearbox(results_dir: Path, runs: list[RunResult]) -> tuple[Path, str]:
    for r in runs:
        rel = (r.meta.get("inputs") or {}).get("gearbox")
        if rel and (results_dir / r.name / rel).exists():
            return results_dir / r.name / rel, f"copy saved with run {r.name}"
    return DEFAULT_GEARBOX, "no gearbox file saved with the runs: the package's model_variants/gearbox.toml"


def gather(results_dir: str | Path) -> ReportData:
    """Load every saved run under ``results_dir`` and screen the Exudyn variants."""
    results_dir = Path(results_dir)
    loaded = [load_result(p.parent) for p in sorted(results_dir.glob("*/run.json"))]
    if not loaded:
        raise FileNotFoundError(f"{results_dir}: no saved runs (expected <run>/run.json); run `flexgear matrix` first")
    lumped = next((r for r in loaded if r.meta.get("backend") == "lumped"), None)
    runs = {r.name: r for r in sorted((r for r in loaded if r.meta.get("backend") != "lumped"),
                                      key=lambda r: _natural(r.name))}
    gearbox_file, note = _find_gearbox(results_dir, list(runs.values()))
    try:
        gearbox = load_gearbox(gearbox_file)
    except SpecError as exc:  # an old copy that no longer validates: say so, use the package's file
        gearbox_file, note = DEFAULT_GEARBOX, f"saved gearbox file is not valid now ({exc}); package default used"
        gearbox = load_gearbox(gearbox_file)
    settings = gearbox.screening
    recorded = results_dir / "screening.json"
    ref_name = json.loads(recorded.read_text()).get("reference", "") if recorded.exists() else settings.reference
    study = screen(runs.values(), settings, reference="")
    reference, refused = None, ""
    if ref_name and ref_name in runs:
        try:
            reference = screen(runs.values(), settings, reference=ref_name)
        except ReferenceNotUsable as exc:
            refused = str(exc)
    sweeps = sorted([results_dir / "sweep.json", *results_dir.glob("*/sweep.json")])
    sweep = next((SweepResult.load(f.parent) for f in sweeps if f.exists()), None)
    modal = results_dir / "modal_screening.txt"
    return ReportData(results_dir, runs, lumped, gearbox, gearbox_file, note, settings, study, reference, sweep,
                      refused, modal.read_text().strip() if modal.exists() else "")


def _split_comment(line: str) -> tuple[str, str]:
    """Split a TOML line into code and comment (a '#' inside a string is not a comment)."""
    quote = None
    for i, ch in enumerate(line):
        if ch in "\"'" and quote in (None, ch):
            quote = None if quote == ch else ch
        elif ch == "#" and quote is None:
            return line[:i].strip(), line[i + 1:].strip()
    return line.strip(), ""


def documented_assumptions(path: Path) -> pd.DataFrame:
    """Every value of a gearbox file that the study does not give, with its documenting comment.

    That is every key of the ``*_assumed`` and ``screening`` tables, plus any key of a study table
    whose comment says "assumed"; comment lines just above a key (or a table header) are its note.
    """
    text = Path(path).read_text()
    data = tomllib.loads(text)
    rows, pending, table, table_note = [], [], "", ""
    for raw in text.splitlines():
        code, comment = _split_comment(raw)
        if not code:
            if comment:
                pending.append(comment)
            continue
        if code.startswith("["):
            table = code.strip("[]").strip()
            table_note = " ".join([*pending, comment]).strip()
            pending = []
            continue
        key = code.split("=", 1)[0].strip()
        note = " ".join([*pending, comment]).strip()
        pending = []
        top = table.split(".")[0]
        if top.endswith("_assumed") or top == "screening" or "assumed" in comment.lower():
            value = data
            for part in [*table.split("."), key] if table else [key]:
                value = value[part]
            rows.append({"table": table, "key": key, "value": fmt(value, 6),
                         "note": note or (table_note if table_note else "")})
            table_note = ""
    return pd.DataFrame(rows, columns=["table", "key", "value", "note"])
