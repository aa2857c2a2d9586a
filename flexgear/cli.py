"""Command line: flexgear run | matrix | sweep | lpm | compare | report | animate | meshes | export-geometry | modes |
campbell | modal-screening | sweep-speed.

Each subcommand is a pair of functions, ``_args_<name>(parser)`` (its arguments, each with help text) and
``cmd_<name>(args) -> exit code`` (a thin wrapper over one library function), listed in ``SUBCOMMANDS``;
adding a subcommand is adding one pair and one line there. Heavy modules are imported only by the
subcommand that needs them. Errors in input files end in one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from flexgear.harmonic.cli import SWEEP_SPEED
from flexgear.modal.cli import CAMPBELL, SCREENING, speeds_rpm
from flexgear.modal.cli import SUBCOMMAND as MODES
from flexgear.progress import Progress, say

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["main", "SUBCOMMANDS"]

OUT_HELP = "results folder; each run goes to OUT/<variant name>/ (default: %(default)s)"
T_END_HELP = ("simulated time in s, or 'settled': continue past the load case's end_time_s until the run has "
              "settled ([load_case] settle_max_time_s at most) (default: the load case's end)")


def _t_end(text: str) -> float | str:
    """``--t-end``: a time in s or the word 'settled'."""
    if text == "settled":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a time in s or 'settled', got {text!r}") from None


# --------------------------------------------------------------------------- run
def _args_run(p: argparse.ArgumentParser) -> None:
    p.add_argument("variant", help="variant file (model_variants/model1.toml ...)")
    p.add_argument("--t-end", type=_t_end, default=None, metavar="S", help=T_END_HELP)
    p.add_argument("--out", default="results", metavar="DIR", help=OUT_HELP)
    p.add_argument("--time-budget", type=float, default=None, metavar="S",
                   help="wall-time budget in s (default: [solver_assumed] wall_time_budget_s)")
    p.add_argument("--states", type=int, default=0, metavar="N",
                   help="also record the bodies' states (frames, modal coordinates) every N steps, for "
                        "`flexgear animate` (default: 0, none)")


def cmd_run(a: argparse.Namespace) -> int:
    from flexgear.mbs.run import ramp_warning, run_variant
    from flexgear.spec import load_variant
    from flexgear.study.matrix import make_task, save_task_result

    variant = load_variant(a.variant)
    task = make_task(variant, a.t_end, a.time_budget)
    warning = ramp_warning(variant, a.t_end if isinstance(a.t_end, float) else variant.gearbox.load_case.end_time_s)
    if warning:
        say(f"warning: {variant.name}: {warning}")
    result = run_variant(variant, t_end_s=a.t_end, progress=True, time_budget_s=a.time_budget,
                         record_states_every=a.states)
    result.meta.update(input_hash=task.input_hash, variant_file=task.variant_file)
    out = Path(a.out) / variant.name
    save_task_result(task, result, out)
    print(f"{variant.name}: {result.meta['status']} in {result.meta.get('wall_time_s', 0):.1f} s -> {out}")
    if not result.ok:
        print(f"reason: {result.meta.get('reason')}", file=sys.stderr)
        return 1
    return 0


# --------------------------------------------------------------------------- matrix
def _args_matrix(p: argparse.ArgumentParser) -> None:
    p.add_argument("variants", nargs="+", metavar="VARIANT", help="variant files, one run each")
    p.add_argument("--t-end", type=_t_end, default=None, metavar="S", help=T_END_HELP)
    p.add_argument("--out", default="results", metavar="DIR",
                   help=OUT_HELP + "; finished runs are kept (resume); a DIR with {folder} (e.g. 'results/{folder}') "
                        "puts each variant file in the folder named after its own, all run in one pool")
    p.add_argument("--workers", type=int, default=2, metavar="N",
                   help="local worker processes (default: %(default)s; ignored with --scheduler)")
    p.add_argument("--scheduler", default=None, metavar="ADDR",
                   help="Dask scheduler address, e.g. tcp://host:8786 (default: local processes); workers get the "
                        "files' content and send the results back")
    p.add_argument("--time-budget", type=float, default=None, metavar="S",
                   help="wall-time budget per run in s (default: [solver_assumed] wall_time_budget_s)")
    p.add_argument("--reference", default=None, metavar="NAME",
                   help="screen against this variant (dynamic indicators, Bias against its values) instead of "
                        "theory (default: [screening] reference of the gearbox file)")
    p.add_argument("--speeds-rpm", type=speeds_rpm, default=None, metavar="A:B:S",
                   help="also screen the variants' frequency-domain indicators over these input speeds in rpm, "
                        "START:STOP:STEP or a list a,b,c, against the reference (flexgear.study.speed_screening; "
                        "default: none)")


def cmd_matrix(a: argparse.Namespace) -> int:
    from flexgear.study.matrix import run_matrix

    table = run_matrix([Path(p) for p in a.variants], out_dir=a.out, t_end_s=a.t_end, workers=a.workers,
                       scheduler=a.scheduler, progress=True, time_budget_s=a.time_budget, reference=a.reference,
                       speeds_rpm=a.speeds_rpm)
    folders = list(dict.fromkeys(table["results"])) if "results" in table.columns else [a.out]
    wanted = ["variant", "status", "wall_time_s", "bias_pct", "cv_pct", "distance_pct", "zone", "selected", "reason"]
    for folder in map(Path, folders):
        rows = table[table["results"] == str(folder)] if "results" in table.columns else table
        rows = _with_screening_reason(rows, folder)
        if len(folders) > 1:
            print(f"{folder}:")
        print(rows[[c for c in wanted if c in rows.columns]].to_string(index=False))
        _print_verdict(folder)
        speed = folder / "speed_screening.txt"
        if a.speeds_rpm and speed.is_file():
            selection = folder / "selection.txt"
            if selection.is_file():
                print(f"Westgard: {selection.read_text().splitlines()[0]}")
            print(f"Over the speed range (-> {speed}):\n{speed.read_text()}", end="")
    return 0


def _print_verdict(out: Path) -> None:
    """The verdict per purpose of ``out/verdict.csv`` (reference screening), one line each."""
    import pandas as pd

    path = out / "verdict.csv"
    if not path.is_file():
        return
    print("Verdict per purpose (each indicator alone, |Bias| + 2 CV <= TEa; cheapest acceptable):")
    for r in pd.read_csv(path, keep_default_na=False).itertuples():
        deciding = (f"{r.deciding_indicator} {float(r.bias):.3g} {r.unit} (TEa {float(r.tea):g})"
                    if r.selected else r.reasoning[:160])
        flag = "" if str(r.resolved) == "True" else " NOT RESOLVED"
        print(f"  {r.purpose}: {r.selected or 'none'}{flag}; {deciding}")


def _with_screening_reason(table: pd.DataFrame, out: Path) -> pd.DataFrame:
    """The matrix table whose rows without a Westgard point say why: a finished run that was not screened gets
    the screening's status (unsettled, failed, not screened) and reason from ``out/screening.parquet``."""
    import pandas as pd

    saved = out / "screening.parquet"
    if not saved.is_file() or not {"variant", "status", "reason"} <= set(table.columns):
        return table
    screened = pd.read_parquet(saved).reindex(columns=["variant", "status", "reason"]).set_index("variant")
    table = table.astype({"status": object, "reason": object})
    status = table["variant"].map(screened["status"])
    unscreened = (table["status"] == "ok") & status.notna() & (status != "ok")
    table.loc[unscreened, "status"] = status[unscreened]
    table.loc[unscreened, "reason"] = table.loc[unscreened, "variant"].map(screened["reason"]).fillna("")
    return table


# --------------------------------------------------------------------------- sweep
def _args_sweep(p: argparse.ArgumentParser) -> None:
    p.add_argument("sweep", help="sweep file (TOML; see flexgear.study.sweep)")
    p.add_argument("--out", default=None, metavar="DIR", help="results folder (default: results/sweep_<name>)")
    p.add_argument("--t-end", type=_t_end, default=None, metavar="S", help=T_END_HELP)
    p.add_argument("--workers", type=int, default=2, metavar="N", help="local worker processes (default: %(default)s)")
    p.add_argument("--scheduler", default=None, metavar="ADDR", help="Dask scheduler address (default: local)")
    p.add_argument("--all-combinations", action="store_true",
                   help="run every base variant in all 2^5 rigid/flexible forms")
    p.add_argument("--reference", default=None, metavar="NAME", help="screen against this variant")


def cmd_sweep(a: argparse.Namespace) -> int:
    from flexgear.study.sweep import load_sweep, run_sweep

    plan = load_sweep(a.sweep, all_combinations=True if a.all_combinations else None)
    out = Path(a.out) if a.out else Path("results") / f"sweep_{plan.name}"
    table = run_sweep(plan, out, t_end_s=a.t_end, workers=a.workers, scheduler=a.scheduler, reference=a.reference)
    wanted = ["variant", *plan.parameters, "eps_beta", "status", "wall_time_s", "distance_pct", "zone"]
    print(table[[c for c in wanted if c in table.columns]].to_string(index=False))
    print(f"sweep table -> {out / 'sweep.csv'}; report: flexgear report {out}")
    return 0


# --------------------------------------------------------------------------- lpm
def _args_lpm(p: argparse.ArgumentParser) -> None:
    p.add_argument("gearbox", help="gearbox file, or a variant file (its gearbox with its overrides)")
    p.add_argument("--t-end", type=_t_end, default=None, metavar="S", help=T_END_HELP)
    p.add_argument("--out", default="results", metavar="DIR",
                   help="results folder; the run goes to OUT/lumped/ (default: %(default)s)")


def _gearbox_or_variant(path: str):
    """The gearbox of a gearbox file, or of a variant file (its gearbox with its overrides)."""
    import tomllib

    from flexgear.spec import SpecError, load_gearbox, load_variant

    try:
        with open(path, "rb") as fh:
            is_variant = "components" in tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise SpecError(path, "<file>", f"cannot be read as TOML ({exc.__class__.__name__})") from None
    return load_variant(path).gearbox if is_variant else load_gearbox(path)


def cmd_lpm(a: argparse.Namespace) -> int:
    from flexgear.lumped.run import run_lumped
    from flexgear.results import save_result

    spec = _gearbox_or_variant(a.gearbox)
    result = run_lumped(spec, t_end_s=a.t_end, progress=True)
    out = save_result(result, Path(a.out) / "lumped", inputs={Path(spec.source).name: Path(spec.source).read_bytes()})
    print(f"lumped: {result.meta['status']} in {result.meta.get('wall_time_s', 0):.2f} s -> {out}")
    return 0 if result.ok else 1


# --------------------------------------------------------------------------- compare
def _args_compare(p: argparse.ArgumentParser) -> None:
    p.add_argument("a", metavar="A", help="a run folder (holds run.json) or a results folder (holds NAME/run.json)")
    p.add_argument("b", metavar="B", help="the same kind as A; two results folders compare their common runs")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write table6 and table7 as CSV to DIR (default: print only)")
    p.add_argument("--allow-unequal", action="store_true",
                   help="compare runs with different load cases (end time, step, ramps) with a warning, "
                        "instead of refusing")


def cmd_compare(a: argparse.Namespace) -> int:
    from flexgear.results import load_result
    from flexgear.study.compare import compare_results, load_case_differences
    from flexgear.study.matrix import write_table

    pairs = _run_pairs(Path(a.a), Path(a.b))
    for label, run_a, run_b in pairs:
        ra, rb = load_result(run_a), load_result(run_b)
        diffs = load_case_differences(ra, rb)
        if diffs and not a.allow_unequal:
            raise ValueError(f"{run_a} and {run_b} have different load cases ({'; '.join(diffs)}); "
                             "expected equal ones (or --allow-unequal)")
        if diffs:
            say(f"warning: {label}: different load cases ({'; '.join(diffs)})")
        table6, table7 = compare_results(ra, rb)
        print(f"{label}\n{table6.to_string()}\n\n{table7.to_string()}\n")
        if a.out:
            out = Path(a.out)
            write_table(table6.reset_index(), out / f"{label}_table6")
            t7 = table7.copy()
            t7.columns = [" ".join(map(str, c)) if isinstance(c, tuple) else str(c) for c in t7.columns]
            write_table(t7.reset_index(), out / f"{label}_table7")
            print(f"tables -> {out}/{label}_table6.csv, {label}_table7.csv")
    return 0


def _run_pairs(a: Path, b: Path) -> list[tuple[str, Path, Path]]:
    """(label, run A, run B) from two run folders or two results folders (their common run names)."""
    def kind(p: Path) -> str:
        if (p / "run.json").is_file():
            return "run"
        if p.is_dir() and any((c / "run.json").is_file() for c in p.iterdir()):
            return "results"
        raise FileNotFoundError(f"{p}: expected a run folder (with run.json) or a results folder "
                                "(with <name>/run.json inside)")

    ka, kb = kind(a), kind(b)
    if ka != kb:
        raise ValueError(f"{a} is a {ka} folder, {b} a {kb} folder: expected two of the same kind")
    if ka == "run":
        return [(f"{a.name}_vs_{b.name}", a, b)]
    names = sorted(c.name for c in a.iterdir() if (c / "run.json").is_file() and (b / c.name / "run.json").is_file())
    if not names:
        raise ValueError(f"{a} and {b} have no run name in common")
    return [(n, a / n, b / n) for n in names]


# --------------------------------------------------------------------------- report
def _args_report(p: argparse.ArgumentParser) -> None:
    p.add_argument("results", help="results folder of a matrix or sweep: a directory holding <run>/run.json, "
                   "screening.json or matrix_results.csv. Every such folder gives a PDF, whatever its runs (failed, "
                   "unsettled, too short, none screened: each said with its reason); an empty directory gives a PDF "
                   "that says 'no runs in DIR'. Any other path (missing, a file, a directory without runs) prints one "
                   "line naming it and exits with code 2")
    p.add_argument("--output", default="reports/screening_report.pdf", metavar="FILE",
                   help="PDF to write (default: %(default)s)")
    p.add_argument("--westgard-png", default=None, metavar="FILE",
                   help="also write the verdict's Westgard diagram as a PNG (default: none)")
    p.add_argument("--also", nargs="*", default=[], metavar="DIR",
                   help="results folders of other load cases or contact laws: their verdicts beside this one on "
                        "page 1 (a path that is not a results folder, or holds no run, is skipped)")


def cmd_report(a: argparse.Namespace) -> int:
    from flexgear.report.data import check_results_folder
    from flexgear.report.pages import build_report

    results = check_results_folder(a.results)   # one line and exit code 2 (main) for any other path
    path = build_report(results, Path(a.output), a.westgard_png, tuple(a.also))
    print(f"report -> {path}")
    return 0


# --------------------------------------------------------------------------- animate
def _args_animate(p: argparse.ArgumentParser) -> None:
    p.add_argument("run_dir", help="a run folder whose run recorded states (flexgear run ... --states N)")
    p.add_argument("--out", default=None, metavar="DIR", help="output folder (default: RUN_DIR/animation)")
    p.add_argument("--scale", type=float, default=1.0, help="factor on the elastic deformation (default: 1)")


def cmd_animate(a: argparse.Namespace) -> int:
    from flexgear.report.animate import write_animation

    path = write_animation(Path(a.run_dir), a.out, scale=a.scale)
    print(f"animation -> {path} (open in ParaView)")
    return 0


# --------------------------------------------------------------------------- meshes
def _args_meshes(p: argparse.ArgumentParser) -> None:
    p.add_argument("gearbox", nargs="?", default="model_variants/gearbox.toml",
                   help="gearbox file, or a variant file (its gearbox with its overrides) (default: %(default)s)")
    p.add_argument("--level", default="coarse", help="mesh level of gearbox.toml [meshing_assumed] (default: coarse)")
    p.add_argument("--no-reduce", action="store_true", help="meshes only, no reduced flexible bodies")
    p.add_argument("--workers", type=int, default=2, metavar="N",
                   help="worker processes, one component each (default: %(default)s; 1: in this process)")


def cmd_meshes(a: argparse.Namespace) -> int:
    from flexgear.fe.build import build_components, build_items
    from flexgear.spec import SpecError

    spec = _gearbox_or_variant(a.gearbox)
    if a.level not in spec.meshing_assumed:
        raise SpecError(a.gearbox, "meshing_assumed", f"has no level {a.level!r}; levels: "
                        f"{', '.join(sorted(spec.meshing_assumed))}")
    if a.workers < 1:
        raise SystemExit(f"flexgear meshes: --workers must be >= 1, got {a.workers}")
    what = "meshes" if a.no_reduce else "meshes and reduced bodies"
    items = build_items(not a.no_reduce, spec.gears.arrangement)
    with Progress(len(items), f"{what} ({a.level})", "parts", fmt="{:.0f}", plain_step=1 / len(items)) as bar:
        def done(c) -> None:
            modes = "" if c.n_modes is None else f", {c.n_modes} modes, first {c.first_frequency_hz:.0f} Hz"
            bar.update_to(bar.value + 1, postfix=f"{c.component}: {c.n_elements} tetrahedra, order "
                          f"{c.element_order}{modes}")

        build_components(spec, a.level, reduce=not a.no_reduce, workers=a.workers, on_done=done)
    return 0


# --------------------------------------------------------------------------- export-geometry
def _args_export_geometry(p: argparse.ArgumentParser) -> None:
    p.add_argument("gearbox", help="gearbox file, or a variant file (its gearbox with its overrides)")
    p.add_argument("--component", action="append", default=None, metavar="NAME",
                   help="sun, planet, ring, input_shaft, output_shaft or (planetary stage) carrier; repeat for "
                   "several (default: all of them)")
    p.add_argument("--level", default="coarse", help="mesh level of [meshing_assumed] (default: %(default)s)")
    p.add_argument("--out", default="geometry", metavar="DIR", help="output folder (default: %(default)s)")


def cmd_export_geometry(a: argparse.Namespace) -> int:
    from flexgear.fe.geometry_export import export_geometry

    spec = _gearbox_or_variant(a.gearbox)
    for path in export_geometry(spec, tuple(a.component) if a.component else None, a.level, a.out, progress=True):
        unit = "mm, solid" if path.suffix == ".step" else "m, volume mesh with its regions as point data"
        print(f"{path} ({unit})")
    return 0


# --------------------------------------------------------------------------- parser
SUBCOMMANDS: list[tuple[str, str, Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], int]]] = [
    ("run", "run one variant file with the Exudyn backend", _args_run, cmd_run),
    ("matrix", "run a matrix of variant files (resumable) and screen them", _args_matrix, cmd_matrix),
    ("sweep", "run a parameter sweep file (grid over gearbox fields x variants)", _args_sweep, cmd_sweep),
    ("lpm", "run the lumped-parameter model of a gearbox (or variant) file", _args_lpm, cmd_lpm),
    ("compare", "Tables 6 and 7 of two runs, or of the common runs of two results folders", _args_compare,
     cmd_compare),
    ("report", "PDF screening report from saved results", _args_report, cmd_report),
    ("animate", "VTK time series (.pvd + .vtu) of the deformed bodies of a run", _args_animate, cmd_animate),
    ("meshes", "build (or load from the cache) the component meshes and reduced bodies", _args_meshes, cmd_meshes),
    ("export-geometry", "write the components' solids as STEP (mm) and meshes as VTU (m)", _args_export_geometry,
     cmd_export_geometry),
    MODES,
    CAMPBELL,
    SCREENING,
    SWEEP_SPEED,
]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="flexgear", description="Dynamics of geared transmissions on Exudyn: "
                                "rigid or flexible components, variant matrix, screening report.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, help_text, add_args, func in SUBCOMMANDS:
        sp = sub.add_parser(name, help=help_text, description=help_text)
        add_args(sp)
        sp.set_defaults(func=func)
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, OSError) as exc:  # SpecError is a ValueError; missing/unreadable paths are OSErrors
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except RuntimeError as exc:  # a computation that failed (Exudyn's solver errors are RuntimeErrors)
        kind = "" if type(exc) is RuntimeError else f"{type(exc).__name__}: "
        print(f"error: {kind}{' '.join(str(exc).split())}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    raise SystemExit(main())
