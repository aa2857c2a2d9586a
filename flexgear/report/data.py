"""What the report reads: the saved runs of a results folder, the gearbox file and its documented assumptions.

A results folder is an existing directory that holds saved runs (``<run>/run.json``) or what a matrix or sweep
writes beside them (:data:`RESULTS_MARKERS`), or that is empty (a matrix that has not saved a run yet). Any other
path raises :class:`NotResultsFolder` with one line naming the path and what was expected. Every results folder
gives a :class:`ReportData`, whatever its runs: none, all failed, none settled, a reference that is missing or not
usable; :attr:`ReportData.nothing_screened` then says in one sentence why no variant has a Westgard point.
"""

from __future__ import annotations

import dataclasses
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

RESULTS_MARKERS = ("screening.json", "matrix_results.csv", "matrix_results.parquet", "sweep.json")
"""Files a matrix or sweep writes into its results folder (besides the runs' ``<run>/run.json``)."""

REASON_CHARS = 160
"""Longest run reason quoted in :attr:`ReportData.nothing_screened` (a failed run's reason can be a traceback)."""

_FILES = ("<run>/run.json", *RESULTS_MARKERS)
EXPECTED = (f"expected a results folder: a directory holding {', '.join(_FILES[:-1])} or {_FILES[-1]} (as `flexgear "
            "matrix --out DIR` writes), or an empty directory")


class NotResultsFolder(ValueError):
    """A path that is not a results folder (module docstring); the message is one line naming it."""


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
    refused: str = ""                   # why the reference screening was refused (reference missing, failed, unsettled)
    modal_note: str = ""                # the modal screening beside the Westgard verdict (modal_screening.txt)
    nothing_screened: str = ""          # why no variant has a Westgard point in the verdict's screening ("" if one has)

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
        """The run's analysis window [s]; a finished run whose window cannot be taken (e.g. a fixed window outside
        the run) gets its whole span, marked not steady, with the reason as its rule."""
        try:
            return run_window(result, self.settings)
        except (ValueError, KeyError) as exc:
            if result.signals is None or result.signals.empty:
                raise
            t = result.signals["time_s"]
            return Window(float(t.iloc[0]), float(t.iloc[-1]), False, f"whole run, NOT steady: {exc}")


def _natural(name: str) -> tuple:
    digits = "".join(ch for ch in name if ch.isdigit())
    return (name.rstrip("0123456789"), int(digits) if digits else -1, name)


def saved_gearbox(results_dir: Path, run: RunResult) -> Path | None:
    """The gearbox file saved with ``run`` in its ``inputs/`` (flexgear.results.save_result: the run's input files
    under their names): the saved TOML file with a ``[gears]`` table; None if there is none."""
    import tomllib

    for rel in (run.meta.get("inputs") or {}).values():
        path = results_dir / run.name / rel
        if path.suffix != ".toml" or not path.is_file():
            continue
        try:
            if "gears" in tomllib.loads(path.read_text()):
                return path
        except (tomllib.TOMLDecodeError, UnicodeDecodeError):
            continue
    return None


def _find_gearbox(results_dir: Path, runs: list[RunResult]) -> tuple[Path, str]:
    for r in runs:
        path = saved_gearbox(results_dir, r)
        if path is not None:
            return path, f"copy saved with run {r.name}"
    return DEFAULT_GEARBOX, "no gearbox file saved with the runs: the package's model_variants/gearbox.toml"


def results_folder_problem(path: str | Path) -> str:
    """Why ``path`` is not a results folder (module docstring), in one line; "" when it is one."""
    path = Path(path)
    if not path.exists():
        return f"{path}: does not exist; {EXPECTED}"
    if not path.is_dir():
        return f"{path}: is a file, not a directory; {EXPECTED}"
    if any(path.glob("*/run.json")) or any((path / m).is_file() for m in RESULTS_MARKERS):
        return ""
    if not any(not p.name.startswith(".") for p in path.iterdir()):
        return ""
    return f"{path}: holds no saved run and no matrix file; {EXPECTED}"


def check_results_folder(path: str | Path) -> Path:
    """``path`` as a Path if it is a results folder, else :class:`NotResultsFolder` (one line)."""
    problem = results_folder_problem(path)
    if problem:
        raise NotResultsFolder(problem)
    return Path(path)


def short_reason(text: object, empty: str = "no reason recorded", chars: int = REASON_CHARS) -> str:
    """A reason on one line, at most ``chars`` characters (``empty`` when there is none)."""
    line = " ".join(str(text or "").split())
    if not line:
        return empty
    return line if len(line) <= chars else line[:chars - 1] + "…"


def nothing_screened_reason(results_dir: Path, runs: dict[str, RunResult], screening: Screening,
                            refused: str = "") -> str:
    """Why no variant has a Westgard point in ``screening`` (one sentence), "" when one has: no runs, the
    reference refused, or each run's status and reason (failed, unsettled, too short)."""
    if not runs:
        return f"no runs in {results_dir} (expected <run>/run.json, written by `flexgear matrix`)"
    if refused:
        return refused
    tab = screening.table
    if (tab["status"] == "ok").any():
        return ""
    groups: dict[tuple[str, str], list[str]] = {}   # runs of the same status and reason named together
    for r in tab.itertuples():
        groups.setdefault((str(r.status), short_reason(r.reason)), []).append(str(r.variant))
    return "no screened variant: " + "; ".join(f"{', '.join(names)} {status} ({reason})"
                                               for (status, reason), names in groups.items())


def _lead_with(s: Screening, why: str) -> Screening:
    """``s`` whose selection reasoning starts with ``why`` (a first sentence the verdict quotes)."""
    sel = s.selection
    first = why[:1].upper() + why[1:]
    reasoning = first + ("" if first.endswith(".") else ".") + " " + sel.reasoning
    return dataclasses.replace(s, selection=Selection(sel.variant, sel.rule, reasoning, sel.resolved))


def _recorded_reference(results_dir: Path, settings: ScreeningSettings) -> str:
    """The reference the matrix screened against (``screening.json``), else the gearbox's ``[screening]``."""
    recorded = results_dir / "screening.json"
    try:
        return str(json.loads(recorded.read_text()).get("reference", "") or "")
    except (OSError, ValueError, AttributeError):
        return settings.reference


def gather(results_dir: str | Path) -> ReportData:
    """Load every saved run under ``results_dir`` and screen the Exudyn variants.

    Raises :class:`NotResultsFolder` for a path that is not a results folder (module docstring); otherwise
    returns the data of every case, with :attr:`ReportData.nothing_screened` and :attr:`ReportData.refused` saying
    what could not be screened and why."""
    results_dir = check_results_folder(results_dir)
    loaded = [load_result(p.parent) for p in sorted(results_dir.glob("*/run.json"))]
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
    ref_name = _recorded_reference(results_dir, settings)
    study = screen(runs.values(), settings, reference="")
    reference, refused = None, ""
    if ref_name and runs and ref_name not in runs:
        refused = f"not screened: reference {ref_name} is not among the runs ({', '.join(runs)})"
    elif ref_name and ref_name in runs:
        try:
            reference = screen(runs.values(), settings, reference=ref_name)
        except ReferenceNotUsable as exc:
            refused = str(exc)
        except (ValueError, KeyError) as exc:  # e.g. a fixed window outside the reference run
            refused = f"not screened: reference {ref_name} cannot be screened ({short_reason(exc)})"
    why = nothing_screened_reason(results_dir, runs, reference if reference is not None else study, refused)
    if why and not refused:
        if reference is not None:
            reference = _lead_with(reference, why)
        else:
            study = _lead_with(study, why)
    sweeps = sorted([results_dir / "sweep.json", *results_dir.glob("*/sweep.json")])
    sweep = next((SweepResult.load(f.parent) for f in sweeps if f.exists()), None)
    modal = results_dir / "modal_screening.txt"
    return ReportData(results_dir, runs, lumped, gearbox, gearbox_file, note, settings, study, reference, sweep,
                      refused, modal.read_text().strip() if modal.exists() else "", why)


def _split_comment(line: str) -> tuple[str, str]:
    """Split a TOML line into code and comment (a '#' inside a string is not a comment)."""
    quote = None
    for i, ch in enumerate(line):
        if ch in "\"'" and quote in (None, ch):
            quote = None if quote == ch else ch
        elif ch == "#" and quote is None:
            return line[:i].strip(), line[i + 1:].strip()
    return line.strip(), ""


DERIVED_NOTE = "derived from the gear set: not in the file (flexgear.sizing, docs/configuration.md)"
"""The note of an assumption the gearbox file leaves to its derived default."""


def documented_assumptions(path: Path, spec: GearboxSpec | None = None) -> pd.DataFrame:
    """Every value of a gearbox file that the study does not give, with its documenting comment.

    That is every key of the ``*_assumed`` and ``screening`` tables, plus any key of a study table
    whose comment says "assumed"; comment lines just above a key (or a table header) are its note. Then every
    value the file leaves to a default derived from its gear set (:data:`DERIVED_NOTE`), as the loaded gearbox
    holds it (``spec``: the gearbox of ``path`` when the caller has loaded it already).
    """
    rows = _file_assumptions(path)
    try:
        spec = spec or load_gearbox(path)
    except SpecError:  # a file the report cannot load: what it says itself
        return rows
    given = set(zip(rows.table, rows.key, strict=True))
    derived = []
    for name in spec.derived:
        table, key = name.rsplit(".", 1)
        if (table, key) in given:
            continue
        top, _, level = table.partition(".")
        holder = spec.meshing_assumed[level] if top == "meshing_assumed" and level else getattr(spec, top)
        derived.append({"table": table, "key": key, "value": fmt(getattr(holder, key), 6), "note": DERIVED_NOTE})
    return pd.concat([rows, pd.DataFrame(derived, columns=rows.columns)], ignore_index=True) if derived else rows


def _file_assumptions(path: Path) -> pd.DataFrame:
    """The file's own assumptions of :func:`documented_assumptions`, with their comments."""
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
