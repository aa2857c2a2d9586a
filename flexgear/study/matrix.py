"""Variant matrix runner: run variants in parallel, time them, resume, then screen (section 2.2).

``run_matrix`` ships every run to a worker (a local process pool, or a Dask distributed cluster given by
its scheduler address) as a :class:`RunTask` that carries the *content* of the variant file and of its
gearbox file, not their paths: a worker needs no access to the caller's files. The worker loads the
variant from that content, builds (or finds in its own cache, ``FLEXGEAR_CACHE_DIR``, keyed by hash) the
meshes and reduced bodies, runs it and sends the :class:`~flexgear.results.RunResult` back; the caller
writes it with :func:`flexgear.results.save_result` under ``out_dir/<variant name>/`` together with
copies of its input files (``inputs/``), as each run finishes (flexgear.study.pool). The runs with the most
flexible bodies start first (the longest first, so that the last ones overlap); on a local pool with a cold cache
the bodies the runs need are built first, as jobs of the same pool, the longest alone on one worker while the
others build the rest and run the variants that do not need it (those that do go last); the screenings that need no run
(the modal screening of an all-flexible reference, the speed screening) take a worker the runs leave free. One
pool may serve several results folders (``out_dir`` with ``{folder}``: each variant file's folder name), the
longest runs of all of them first. Then it writes, per folder,

- ``matrix_results.csv`` / ``.parquet``: one row per variant: status and reason, components,
  simulated time, the runner's wall and CPU time of the run (model build + simulation), the
  worker's total wall and CPU time (loading, build, simulation), input and configuration hashes,
  whether the run was resumed;
- ``screening.csv`` / ``.parquet``: per variant Bias %, CV %, distance, zone, sigma, time,
  selected (:func:`flexgear.study.screening.screen`); ``screening_indicators.*`` per indicator (with its
  ``purpose``); ``selection.txt``: the selected variant and why;
- with a reference variant, ``verdict.csv`` / ``.parquet``: one row per purpose and one for all purposes
  (flexgear.study.purposes.VERDICT_COLUMNS: the selected variant, empty when none, the deciding indicator with
  its Bias, CV and TEa in its unit, whether the verdict is resolved, the CPU-time ratio to the reference), and
  ``purpose_zones.*``: each variant's zone per purpose and its weakest indicator.

Nothing lost: every file is written atomically and a run folder is complete once its ``run.json`` is
there (written last). A matrix killed at any moment (SIGKILL included) resumes when started again: a
run is skipped when its folder holds an ``ok`` result whose ``input_hash`` equals the hash of the
variant (the gearbox without its ``[screening]`` table, which is post-processing only), the simulated
end time and the cache keys of its bodies (flexgear.study.pool.body_keys); the temporary files of interrupted
writes are deleted. A variant whose file is bad (SpecError), whose runner returns a failed result (divergence,
wall-time budget), raises, or kills its worker process is recorded as failed with its reason while the others go
on. CPU time is the worker process's
``time.process_time`` (all its threads).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from flexgear.cache import atomic_write_bytes, remove_stale_temporaries
from flexgear.results import load_result, save_result
from flexgear.spec import COMPONENTS, ScreeningSettings, SpecError, Variant, load_gearbox, load_variant
from flexgear.study.pool import (
    Runner,
    RunTask,
    execute,
    failed_result,
    make_task,
    run_input_hash,
    run_task,
    save_task_result,
    say_progress,
    write_table,
)
from flexgear.study.purposes import ALL_PURPOSES, verdict_table
from flexgear.study.screening import ReferenceNotUsable, Selection, screen
from flexgear.study.speed_screening import (
    job_files,
    operating_speed_rpm,
    screened_curves,
    speed_curve_job,
    write_speed_screening,
)

__all__ = ["RunTask", "make_task", "run_matrix", "run_input_hash", "run_task", "save_task_result", "write_table",
           "screen_directory"]

# --------------------------------------------------------------------------- tables
# --------------------------------------------------------------------------- matrix
def _row(name: str, meta: dict, resumed: bool) -> dict[str, Any]:
    comps = meta.get("components") or {}
    row = {"variant": name, "file": meta.get("variant_file", ""), "status": meta.get("status", "failed"),
           "reason": meta.get("reason") or "", "resumed": resumed}
    row.update({c: comps.get(c, "") for c in COMPONENTS})
    for key in ("t_end_s", "wall_time_s", "cpu_time_s", "total_wall_time_s", "total_cpu_time_s"):
        row[key] = meta.get(key, float("nan"))
    row.update(input_hash=meta.get("input_hash", ""), config_hash=meta.get("config_hash", ""),
               created=meta.get("created", ""))
    return row


def screen_directory(out_dir: Path, names: Sequence[str], settings: ScreeningSettings,
                     progress: bool = False, reference: str | None = None) -> pd.DataFrame:
    """Screen saved runs ``out_dir/<name>`` and write the screening tables and ``selection.txt``;
    ``reference``: a variant name to screen against (default ``settings.reference``). A reference that has not
    settled is refused: ``selection.txt`` then says so in one line and nothing is selected."""
    results = [load_result(out_dir / n) if (out_dir / n / "run.json").exists()
               else failed_result(n, "no saved run") for n in names]
    ref = settings.reference if reference is None else reference
    purposes = tuple(settings.purposes) if ref else ()
    try:
        s = screen(results, settings, reference)
    except ReferenceNotUsable as exc:
        table = pd.DataFrame({"variant": [r.name for r in results], "status": "not screened", "reason": str(exc),
                              "selected": False})
        indicators = pd.DataFrame(columns=["variant", "indicator", "purpose"])
        selection = Selection(None, settings.selection, str(exc))
        verdict = pd.DataFrame({"purpose": [*purposes, ALL_PURPOSES], "selected": "", "resolved": False,
                                "reasoning": str(exc)}).reindex(columns=list(verdict_table([]).columns))
        zones = None
    else:
        table, indicators, selection = s.table, s.indicators, s.selection
        verdict, zones = verdict_table(list(s.verdicts)), s.purpose_zones
    write_table(table, out_dir / "screening")
    write_table(indicators, out_dir / "screening_indicators")
    if ref:
        write_table(verdict, out_dir / "verdict")
        if zones is not None:
            write_table(zones, out_dir / "purpose_zones")
    atomic_write_bytes(out_dir / "screening.json", json.dumps({"reference": ref}).encode())
    text = (f"selected: {selection.variant}\nrule: {selection.rule}\nreference: {ref or 'theory'}\n"
            f"{selection.reasoning}\n")
    atomic_write_bytes(out_dir / "selection.txt", text.encode())
    say_progress(progress, f"selected {selection.variant}: {selection.reasoning}")
    return table


def modal_job(variant_file: str, variant_text: str, gearbox_text: str,
              candidates: dict[str, tuple[str, ...]] | None = None) -> tuple[pd.DataFrame, pd.DataFrame, str, float]:
    """Worker side: the modal screening of the all-flexible reference (flexgear.modal.screening) from its files'
    content, recommending among ``candidates`` {name: flexible components} (the matrix's variants; None: the
    variant files beside it): (component table, mode table, recommended variant, band [Hz])."""
    from flexgear.modal.screening import modal_screening

    m = modal_screening(load_variant(variant_file, variant_text, gearbox_text),
                        variants_dir=Path(variant_file).parent, candidates=candidates)
    return m.table, m.mode_table(), m.recommended, m.f_band_hz


def write_modal_verdict(out_dir: Path, name: str, screened: Any, progress: bool = False) -> str:
    """Write the modal screening ``screened`` (:func:`modal_job`'s result, or the exception it raised) of reference
    ``name`` beside the Westgard verdict of ``out_dir/selection.txt``: ``modal_screening.csv``,
    ``modal_screening_modes.csv`` (ModalScreening.mode_table) and ``modal_screening.txt`` (one paragraph); returns
    the paragraph. A failure is recorded in the text, not raised: the Westgard verdict stands on its own."""
    if isinstance(screened, BaseException):
        text = f"Modal screening of {name} not done: {type(screened).__name__}: {screened}"
    else:
        table, modes, recommended, f_band = screened
        write_table(table, out_dir / "modal_screening")
        write_table(modes, out_dir / "modal_screening_modes")
        selection = (out_dir / "selection.txt").read_text().splitlines()[0].removeprefix("selected: ")
        must = ", ".join(table.component[table.must_be_flexible]) or "none"
        text = (f"Modal screening of {name}'s modes up to {f_band:.4g} Hz (10x the mesh frequency): "
                f"must be flexible: {must}; recommends {recommended}. Westgard verdict: {selection}"
                + (" (the same)." if selection == recommended else
                   "; they differ: the modal screening asks which components deform in the modes the mesh harmonics "
                   "can excite, the Westgard verdict whether the indicators change beyond their TEa."))
    atomic_write_bytes(out_dir / "modal_screening.txt", (text + "\n").encode())
    say_progress(progress, text)
    return text


def modal_verdict(out_dir: Path, reference: Any, progress: bool = False) -> str:
    """:func:`write_modal_verdict` of the all-flexible ``reference`` (a Variant, or its flexgear.modal.LinearModel
    at the operating point), screened here."""
    from flexgear.modal.screening import modal_screening

    name = reference.variant.name if hasattr(reference, "variant") else getattr(reference, "name", str(reference))
    try:
        m = modal_screening(reference)
        screened: Any = (m.table, m.mode_table(), m.recommended, m.f_band_hz)
    except Exception as exc:  # recorded: the time-domain screening does not depend on it
        screened = exc
    return write_modal_verdict(out_dir, name, screened, progress)


def _check_reference(reference: str, names: Sequence[str]) -> None:
    """A reference variant must be one of the matrix's variants (checked before any run)."""
    if reference and reference not in names:
        raise ValueError(f"screening reference {reference!r} is not one of the variants "
                         f"({', '.join(names)}); allowed: one of them, or '' for the study's mode")


def _flexible_bodies(variant: Variant) -> int:
    """Flexible bodies of a variant (planets count each): the measure of its run time used to order the runs
    when their reduced bodies are not cached yet (:func:`_run_order`)."""
    planets = variant.gearbox.gears.planet_count
    return sum((planets if c == "planets" else 1) for c, form in variant.components.items() if form == "flexible")


def _run_order(variants: dict[Any, Variant]) -> list[Any]:
    """Keys (names, or folder and name) longest run first (the last runs then overlap): by
    flexgear.mbs.gearbox.run_cost (the flexible bodies' dynamic modes, squared and summed) when every variant's
    bodies are cached, else by the count of flexible bodies. Stable for ties."""
    from flexgear.mbs.gearbox import run_cost

    costs = {name: run_cost(v) for name, v in variants.items()}
    if any(c is None for c in costs.values()):
        costs = {name: float(_flexible_bodies(v)) for name, v in variants.items()}
    return sorted(variants, key=lambda name: -costs[name])


def _cold_build(variants: dict[Any, Variant]) -> tuple[list[tuple[Any, Callable, tuple]], set[Any]]:
    """The bodies the ``variants``' runs need that are not in the cache, as pool jobs submitted before the runs, the
    longest first (flexgear.fe.build.COLD_BUILD_ORDER: the tied ring and output shaft of the star's all-flexible
    variants), and the keys of the runs that need the longest, which go last: one worker builds that body while the
    others build the rest and run the variants that do not need it, instead of workers waiting for one body.
    ([], set()) when every body is there."""
    from flexgear.fe.build import COLD_BUILD_ORDER, build_body, build_key, variant_build_items
    from flexgear.fe.reduced import reduced_cache_path

    rank = {item: k for k, item in enumerate(COLD_BUILD_ORDER)}
    cold: dict[str, tuple[str, Variant, set[Any]]] = {}  # body key -> (item, a variant that needs it, run keys)
    for key, v in variants.items():
        try:
            needed = {build_key(v.gearbox, item, v.mesh_level): item
                      for item in variant_build_items(v.gearbox, v.components)}
        except Exception:  # noqa: BLE001  the run itself then fails and is recorded with its reason
            continue
        for body, item in needed.items():
            if not reduced_cache_path(body).exists():
                cold.setdefault(body, (item, v, set()))[2].add(key)
    entries = sorted(cold.values(), key=lambda entry: rank.get(entry[0], len(rank)))
    jobs = [(("build", item, v.mesh_level, k), build_body, (v.gearbox, item, v.mesh_level))
            for k, (item, v, _) in enumerate(entries)]
    return jobs, (entries[0][2] if entries else set())


@dataclasses.dataclass
class _Folder:
    """One results folder of a matrix: its variants, the runs to do and the ones kept."""

    out_dir: Path
    names: list[str] = dataclasses.field(default_factory=list)
    files: dict[str, Path] = dataclasses.field(default_factory=dict)
    metas: dict[str, dict] = dataclasses.field(default_factory=dict)
    resumed: set[str] = dataclasses.field(default_factory=set)
    tasks: list[RunTask] = dataclasses.field(default_factory=list)
    pending: dict[str, Variant] = dataclasses.field(default_factory=dict)
    variants: dict[str, Variant] = dataclasses.field(default_factory=dict)  # every loaded variant file
    settings: ScreeningSettings | None = None
    reference: str = ""


def _folders(variant_paths: Sequence[str | Path], out_dir: str | Path) -> dict[Path, list[Path]]:
    """The results folder of each variant file: ``out_dir``, or, when it holds ``{folder}``, that with the name of
    the variant file's folder (``results/{folder}``: model_variants/quick/model7.toml -> results/quick)."""
    out: dict[Path, list[Path]] = {}
    for path in map(Path, variant_paths):
        folder = Path(str(out_dir).replace("{folder}", path.resolve().parent.name))
        out.setdefault(folder, []).append(path)
    return out


def _prepare(out_dir: Path, paths: list[Path], t_end_s: float | str | None, time_budget_s: float | None,
             reference: str | None, progress: bool) -> _Folder:
    """Load a folder's variant files, record the bad ones, keep the finished runs (resume), make the tasks."""
    f = _Folder(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for stale in remove_stale_temporaries(out_dir):
        say_progress(progress, f"removed {stale.relative_to(out_dir)} (an interrupted write)")
    for path in paths:
        try:
            variant = load_variant(path)
        except SpecError as exc:
            name = path.stem
            result = failed_result(name, f"SpecError: {exc}", variant_file=str(path))
            if name not in f.names:
                f.names.append(name)
                save_result(result, out_dir / name)
                f.metas[name] = dict(result.meta)
            say_progress(progress, f"{name}: bad variant file: {exc}")
            continue
        name = variant.name
        if name in f.names:
            raise SpecError(path, "name", f"variant names in a matrix must be unique; {name!r} is used twice")
        f.names.append(name)
        f.files[name] = path
        f.variants[name] = variant
        f.settings = f.settings or variant.gearbox.screening
        f.reference = reference if reference is not None else f.settings.reference
        task = make_task(variant, t_end_s, time_budget_s,
                         f.settings.error_window_s if f.reference and name == f.reference else 0.0, out_dir)
        run_dir = out_dir / name
        if (run_dir / "run.json").exists():
            old = load_result(run_dir).meta
            if old.get("status") == "ok" and old.get("input_hash") == task.input_hash:
                f.metas[name] = old
                f.resumed.add(name)
                say_progress(progress, f"{name}: unchanged (hash {task.input_hash}), skipped")
                continue
        f.tasks.append(task)
        f.pending[name] = variant
    _check_reference(reference if reference is not None else (f.settings.reference if f.settings else ""), f.names)
    return f


def _jobs(f: _Folder, speeds_rpm: Sequence[float] | None, modal: bool) -> list[tuple[Any, Callable, tuple]]:
    """The folder's screenings that need no run, for the pool: the modal screening of an all-flexible reference,
    and each variant's curves over the speed range (one job per variant, screened together by :func:`_finish`)."""
    jobs: list[tuple[Any, Callable, tuple]] = []
    ref = f.variants.get(f.reference)
    if modal and ref is not None and all(form == "flexible" for form in ref.components.values()):
        from flexgear.modal.screening import flexible_components

        flexible = {name: flexible_components(v) for name, v in f.variants.items()}
        jobs.append((("modal", str(f.out_dir)), modal_job, (*job_files([ref])[0], flexible)))
    if speeds_rpm:
        jobs += [(("speed", str(f.out_dir), name), speed_curve_job, (file, list(speeds_rpm)))
                 for name, file in zip(f.variants, job_files(f.variants.values()), strict=True)]
    return jobs


def _speed_screening(f: _Folder, done: dict) -> Any:
    """The folder's speed screening from its variants' curves among the jobs' results ``done`` (None: not asked);
    a failed curve is the screening's result."""
    curves = {name: done[key] for name in f.variants if (key := ("speed", str(f.out_dir), name)) in done}
    if not curves:
        return None
    failed = next((c for c in curves.values() if isinstance(c, BaseException)), None)
    if failed is not None:
        return failed
    try:
        first = next(iter(f.variants.values()))
        return screened_curves(list(f.variants.values()), curves, f.reference or first.gearbox.screening.reference)
    except ValueError as exc:
        return exc


def _finish(f: _Folder, metas: dict, done: dict, progress: bool, reference: str | None) -> pd.DataFrame:
    """Write the folder's tables and screenings (the runs', then the jobs' results)."""
    f.metas.update({name: meta for (folder, name), meta in metas.items() if folder == str(f.out_dir)})
    table = pd.DataFrame([_row(n, f.metas[n], n in f.resumed) for n in f.names])
    write_table(table, f.out_dir / "matrix_results")
    settings = f.settings or load_gearbox(Path(__file__).resolve().parents[2] / "model_variants"
                                          / "gearbox.toml").screening
    screening = screen_directory(f.out_dir, f.names, settings, progress, reference)
    if ("modal", str(f.out_dir)) in done:
        write_modal_verdict(f.out_dir, f.reference, done["modal", str(f.out_dir)], progress)
    speed = _speed_screening(f, done)
    if speed is not None:
        write_speed_screening(f.out_dir, speed, operating_speed_rpm(f.variants.values()))
    screening = screening.reindex(columns=["variant", "bias_pct", "cv_pct", "distance_pct", "sigma", "zone",
                                           "selected"])
    return table.merge(screening, on="variant", how="left")


def run_matrix(variant_paths: Sequence[str | Path], out_dir: str | Path, t_end_s: float | str | None = None,
               workers: int = 2, scheduler: str | None = None, progress: bool = True,
               runner: Runner | None = None, time_budget_s: float | None = None,
               reference: str | None = None, modal: bool = True,
               speeds_rpm: Sequence[float] | None = None) -> pd.DataFrame:
    """Run the variant files, save each run, screen them; return the results + screening table.

    ``runner(variant, t_end_s=..., progress=...) -> RunResult`` defaults to
    :func:`flexgear.mbs.run.run_variant`; it must be importable by the worker processes.
    ``scheduler`` is a Dask scheduler address (``tcp://host:8786``); None uses ``workers`` local
    processes. ``time_budget_s`` overrides each variant's ``[solver_assumed] wall_time_budget_s``.
    ``reference``: screen against this variant (:func:`flexgear.study.screening.screen`; default the
    gearbox's ``[screening] reference``). ``modal``: with an all-flexible reference and the default runner, also
    the modal screening (:func:`write_modal_verdict`); ``speeds_rpm``: also the speed screening over these input
    speeds (flexgear.study.speed_screening). ``out_dir`` holding ``{folder}`` serves several results folders from
    one pool (:func:`_folders`: each variant file's folder name), the longest runs of all first and the
    screenings that need no run beside them; the table then has a column ``results``. See the module docstring
    for the files written and the resume rule.
    """
    folders = [_prepare(Path(d), paths, t_end_s, time_budget_s, reference, progress)
               for d, paths in _folders(variant_paths, out_dir).items()]
    pending = {(str(f.out_dir), name): v for f in folders for name, v in f.pending.items()}
    first, waits = _cold_build(pending) if runner is None and scheduler is None and workers > 1 else ([], set())
    order = {key: k for k, key in enumerate(_run_order(pending))}
    tasks = sorted((t for f in folders for t in f.tasks), key=lambda t: (t.key in waits, order[t.key]))
    jobs = [j for f in folders for j in _jobs(f, speeds_rpm, modal and runner is None)] if runner is None else []
    # a speed curve whose variant has cold bodies to wait for goes after the runs that wait for none, the rest before
    ahead = [j for j in jobs if j[0][0] == "speed" and (j[0][1], j[0][2]) not in waits]
    jobs = [j for j in jobs if j not in ahead]
    metas, done = execute(tasks, workers, scheduler, runner, progress, jobs, first, ahead, waits)
    tables = [_finish(f, metas, done, progress, reference) for f in folders]
    if len(tables) == 1:
        return tables[0]
    return pd.concat([t.assign(results=str(f.out_dir)) for t, f in zip(tables, folders, strict=True)],
                     ignore_index=True)
