"""Variant matrix runner: run variants in parallel, time them, resume, then screen (section 2.2).

``run_matrix`` ships every run to a worker (a local process pool, or a Dask distributed cluster given by
its scheduler address) as a :class:`RunTask` that carries the *content* of the variant file and of its
gearbox file, not their paths: a worker needs no access to the caller's files. The worker loads the
variant from that content, builds (or finds in its own cache, ``FLEXGEAR_CACHE_DIR``, keyed by hash) the
meshes and reduced bodies, runs it and sends the :class:`~flexgear.results.RunResult` back; the caller
writes it with :func:`flexgear.results.save_result` under ``out_dir/<variant name>/`` together with
copies of its input files (``inputs/``), as each run finishes. The runs with the most flexible bodies
start first (the longest first, so that the last ones overlap). Then it writes

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
variant (the gearbox without its ``[screening]`` table, which is post-processing only) and the simulated
end time; the temporary files of interrupted writes are deleted. A variant whose file is bad (SpecError),
whose runner returns a failed result (divergence, wall-time budget), raises, or kills its worker process
is recorded as failed with its reason while the others go on. CPU time is the worker process's
``time.process_time`` (all its threads).
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import json
import socket
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import pandas as pd

from flexgear.cache import atomic_write_bytes, remove_stale_temporaries
from flexgear.progress import Progress, say
from flexgear.results import RunResult, load_result, save_result
from flexgear.spec import COMPONENTS, ScreeningSettings, SpecError, Variant, load_gearbox, load_variant, spec_hash
from flexgear.study.purposes import ALL_PURPOSES, verdict_table
from flexgear.study.screening import ReferenceNotUsable, Selection, screen

__all__ = ["RunTask", "make_task", "run_matrix", "run_input_hash", "run_task", "save_task_result", "write_table",
           "screen_directory"]

Runner = Callable[..., RunResult]

_HEARTBEAT_S = 60.0
_POLL_S = 0.2


def run_input_hash(variant: Variant, t_end_s: float | str, error_window_s: float = 0.0) -> str:
    """Hash of everything a run depends on: the variant, its gearbox (without ``[screening]``, except the settling
    test's fields for a run continued until it settles), t_end (s, or "settled"), the error windows' length."""
    gearbox = dataclasses.replace(variant.gearbox, screening=None)
    if t_end_s != "settled":
        extra: tuple = (float(t_end_s),)
    else:
        sc = variant.gearbox.screening
        extra = ("settled", sc.settle_block_mesh_cycles, sc.settle_final_blocks, sc.settle_mean_tolerance_pct,
                 sc.settle_amplitude_tolerance_pct, sc.sample_count, sc.after_ramp_delay_s)
    if error_window_s > 0:
        extra = (*extra, "error_window", float(error_window_s))
    return spec_hash(dataclasses.replace(variant, gearbox=gearbox), *extra, "exudyn")


def _default_runner() -> Runner:
    from flexgear.mbs.run import run_variant

    return run_variant


def _failed(name: str, reason: str, **meta: Any) -> RunResult:
    return RunResult({"variant": name, "backend": "exudyn", "status": "failed", "reason": reason,
                      "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"), **meta})


@dataclasses.dataclass(frozen=True)
class RunTask:
    """One run as shipped to a worker: the input files' names and contents (no paths to open)."""

    name: str
    variant_file: str  # the caller's path: names the file in messages only
    variant_text: str
    gearbox_file: str
    gearbox_text: str
    t_end_s: float | str | None
    input_hash: str
    time_budget_s: float | None = None
    error_window_s: float = 0.0   # > 0: the run also solves its numerical error windows (the screening reference)

    def inputs(self) -> dict[str, bytes]:
        """The input files for ``inputs/`` of the run folder."""
        return {Path(self.variant_file).name: self.variant_text.encode(),
                Path(self.gearbox_file).name: self.gearbox_text.encode()}


def make_task(variant: Variant, t_end_s: float | str | None, time_budget_s: float | None = None,
              error_window_s: float = 0.0) -> RunTask:
    """The task of a loaded variant: reads its two files once, on the caller's side; ``t_end_s`` in s, "settled"
    or None (the load case's end: ``end_time_s``, or "settled" with ``[load_case] end = "settled"``)."""
    lc = variant.gearbox.load_case
    t_end = t_end_s if t_end_s is not None else ("settled" if lc.end == "settled" else lc.end_time_s)
    return RunTask(variant.name, str(variant.source), Path(variant.source).read_text(),
                   str(variant.gearbox.source), Path(variant.gearbox.source).read_text(), t_end_s,
                   run_input_hash(variant, t_end, error_window_s), time_budget_s, error_window_s)


def run_task(task: RunTask, runner: Runner | None = None) -> RunResult:
    """Worker side: load the variant from the shipped content, run it, return the result (writes nothing
    but cache entries). Never raises for a model failure."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    try:
        variant = load_variant(task.variant_file, task.variant_text, task.gearbox_text)
        extra: dict[str, Any] = {} if task.time_budget_s is None else {"time_budget_s": task.time_budget_s}
        if task.error_window_s > 0:
            extra["error_window_s"] = task.error_window_s
        result = (runner or _default_runner())(variant, t_end_s=task.t_end_s, progress=False, **extra)
    except Exception as exc:  # recorded, not raised: the other variants go on
        result = _failed(task.name, f"{type(exc).__name__}: {exc}")
    result.meta.update(input_hash=task.input_hash, variant_file=task.variant_file, worker_host=socket.gethostname(),
                       total_wall_time_s=time.perf_counter() - wall0, total_cpu_time_s=time.process_time() - cpu0)
    return result


def save_task_result(task: RunTask, result: RunResult, run_dir: Path) -> dict[str, Any]:
    """Caller side: write the result and copies of its input files; return its metadata."""
    save_result(result, run_dir, inputs=task.inputs())
    return dict(result.meta)


def write_table(table: pd.DataFrame, stem: Path) -> None:
    """Write ``stem.csv`` and ``stem.parquet`` atomically."""
    atomic_write_bytes(stem.with_suffix(".csv"), table.to_csv(index=False).encode())
    atomic_write_bytes(stem.with_suffix(".parquet"), table.to_parquet(index=False))


# --------------------------------------------------------------------------- execution
def _say(progress: bool, text: str) -> None:
    if progress:
        say(f"[matrix {time.strftime('%H:%M:%S')}] {text}")


def _run_pool(tasks: list[RunTask], submit: Callable, runner: Runner | None, out_dir: Path,
              progress: bool, bar: Progress) -> tuple[dict[str, dict], list[RunTask]]:
    """Submit tasks, save each result as it arrives; return the metas and the tasks whose worker died."""
    futures = {submit(run_task, t, runner): t for t in tasks}
    started = last_beat = time.perf_counter()
    metas: dict[str, dict] = {}
    died: list[RunTask] = []
    while futures:
        finished = [f for f in futures if f.done()]
        for fut in finished:
            task = futures.pop(fut)
            try:
                result = fut.result()
            except Exception as exc:  # the worker process died (segfault, out of memory) or was killed
                died.append(task)
                _say(progress, f"{task.name}: worker lost ({type(exc).__name__}: {exc})")
                continue
            meta = metas[task.name] = save_task_result(task, result, out_dir / task.name)
            bar.update_to(bar.value + 1, postfix=f"{task.name} {meta['status']}")
            _say(progress, f"{task.name}: {meta['status']}, {meta.get('wall_time_s', float('nan')):.1f} s wall, "
                           f"{meta.get('cpu_time_s', float('nan')):.1f} s CPU"
                           + (f" ({meta.get('reason')})" if meta["status"] != "ok" else ""))
        now = time.perf_counter()
        if futures and now - last_beat >= _HEARTBEAT_S:
            last_beat = now
            _say(progress, f"running or queued {len(futures)}: {', '.join(t.name for t in futures.values())} "
                           f"({now - started:.0f} s elapsed)")
        if futures and not finished:
            time.sleep(_POLL_S)
    return metas, died


def _execute(tasks: list[RunTask], workers: int, scheduler: str | None, runner: Runner | None,
             out_dir: Path, progress: bool) -> dict[str, dict]:
    if not tasks:
        return {}
    # on a terminal a bar; in a log the per-run lines of _say are the progress
    bar = Progress(len(tasks), "matrix", "runs", enabled=progress and sys.stderr.isatty(), fmt="{:.0f}")
    if scheduler is not None:
        from distributed import Client

        with Client(scheduler) as client:
            _say(progress, f"{len(tasks)} runs on Dask cluster {scheduler}")

            def submit(fn: Callable, task: RunTask, run: Runner | None) -> Any:
                return client.submit(fn, task, run, pure=False, key=f"flexgear-run-{task.name}-{task.input_hash}")

            metas, died = _run_pool(tasks, submit, runner, out_dir, progress, bar)
    else:
        _say(progress, f"{len(tasks)} runs on {workers} local worker process(es)")
        ctx = get_context("spawn")
        with ProcessPoolExecutor(max_workers=max(1, workers), mp_context=ctx) as pool:
            metas, died = _run_pool(tasks, pool.submit, runner, out_dir, progress, bar)
        # A dead worker breaks the whole pool: rerun each affected task alone to find the culprit.
        retry, died = died, []
        for task in retry:
            with ProcessPoolExecutor(max_workers=1, mp_context=ctx) as solo:
                again, lost = _run_pool([task], solo.submit, runner, out_dir, progress, bar)
            metas.update(again)
            died += lost
    for task in died:  # died again alone (or on the cluster): record it
        result = _failed(task.name, "worker process died (crash or out of memory in the solver)",
                         input_hash=task.input_hash, variant_file=task.variant_file)
        metas[task.name] = save_task_result(task, result, out_dir / task.name)
        bar.update_to(bar.value + 1, postfix=f"{task.name} failed")
    bar.close()
    return metas


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
               else _failed(n, "no saved run") for n in names]
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
    _say(progress, f"selected {selection.variant}: {selection.reasoning}")
    return table


def modal_verdict(out_dir: Path, reference: Any, progress: bool = False) -> str:
    """The modal screening of the all-flexible reference (flexgear.modal.screening: which components deform in the
    modes that the mesh harmonics can excite) beside the Westgard verdict of ``out_dir/selection.txt``; writes
    ``modal_screening.csv``, ``modal_screening_modes.csv`` (ModalScreening.mode_table) and ``modal_screening.txt``
    (one paragraph) and returns the paragraph. ``reference``: a Variant or its flexgear.modal.LinearModel. A
    failure is recorded in the text, not raised: the Westgard verdict stands on its own."""
    from flexgear.modal.screening import modal_screening

    name = reference.variant.name if hasattr(reference, "variant") else reference.name

    try:
        m = modal_screening(reference)
    except Exception as exc:  # recorded: the time-domain screening does not depend on it
        text = f"Modal screening of {name} not done: {type(exc).__name__}: {exc}"
    else:
        write_table(m.table, out_dir / "modal_screening")
        write_table(m.mode_table(), out_dir / "modal_screening_modes")
        selection = (out_dir / "selection.txt").read_text().splitlines()[0].removeprefix("selected: ")
        must = ", ".join(m.table.component[m.table.must_be_flexible]) or "none"
        text = (f"Modal screening of {name}'s modes up to {m.f_band_hz:.4g} Hz (10x the mesh frequency): "
                f"must be flexible: {must}; recommends {m.recommended}. Westgard verdict: {selection}"
                + (" (the same)." if selection == m.recommended else
                   "; they differ: the modal screening asks which components deform in the modes the mesh harmonics "
                   "can excite, the Westgard verdict whether the indicators change beyond their TEa."))
    atomic_write_bytes(out_dir / "modal_screening.txt", (text + "\n").encode())
    _say(progress, text)
    return text


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


def _run_order(variants: dict[str, Variant]) -> list[str]:
    """Names longest run first (the last runs then overlap): by flexgear.mbs.gearbox.run_cost (the flexible
    bodies' dynamic modes, squared and summed) when every variant's bodies are cached, else by the count of
    flexible bodies. Stable for ties."""
    from flexgear.mbs.gearbox import run_cost

    costs = {name: run_cost(v) for name, v in variants.items()}
    if any(c is None for c in costs.values()):
        costs = {name: float(_flexible_bodies(v)) for name, v in variants.items()}
    return sorted(variants, key=lambda name: -costs[name])


def run_matrix(variant_paths: Sequence[str | Path], out_dir: str | Path, t_end_s: float | str | None = None,
               workers: int = 2, scheduler: str | None = None, progress: bool = True,
               runner: Runner | None = None, time_budget_s: float | None = None,
               reference: str | None = None, modal: bool = True) -> pd.DataFrame:
    """Run the variant files, save each run, screen them; return the results + screening table.

    ``runner(variant, t_end_s=..., progress=...) -> RunResult`` defaults to
    :func:`flexgear.mbs.run.run_variant`; it must be importable by the worker processes.
    ``scheduler`` is a Dask scheduler address (``tcp://host:8786``); None uses ``workers`` local
    processes. ``time_budget_s`` overrides each variant's ``[solver_assumed] wall_time_budget_s``.
    ``reference``: screen against this variant (:func:`flexgear.study.screening.screen`; default the
    gearbox's ``[screening] reference``). ``modal``: with an all-flexible reference and the default runner, also
    :func:`modal_verdict`. See the module docstring for the files written and the resume rule.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    for stale in remove_stale_temporaries(out_dir):
        _say(progress, f"removed {stale.relative_to(out_dir)} (an interrupted write)")
    names: list[str] = []
    variant_files: dict[str, Path] = {}
    metas: dict[str, dict] = {}
    resumed: set[str] = set()
    tasks: list[RunTask] = []
    pending: dict[str, Variant] = {}
    settings: ScreeningSettings | None = None
    for path in map(Path, variant_paths):
        try:
            variant = load_variant(path)
        except SpecError as exc:
            name = path.stem
            result = _failed(name, f"SpecError: {exc}", variant_file=str(path))
            if name not in names:
                names.append(name)
                save_result(result, out_dir / name)
                metas[name] = dict(result.meta)
            _say(progress, f"{name}: bad variant file: {exc}")
            continue
        name = variant.name
        if name in names:
            raise SpecError(path, "name", f"variant names in a matrix must be unique; {name!r} is used twice")
        names.append(name)
        variant_files[name] = path
        settings = settings or variant.gearbox.screening
        ref = reference if reference is not None else settings.reference
        task = make_task(variant, t_end_s, time_budget_s,
                         settings.error_window_s if ref and name == ref else 0.0)
        run_dir = out_dir / name
        if (run_dir / "run.json").exists():
            old = load_result(run_dir).meta
            if old.get("status") == "ok" and old.get("input_hash") == task.input_hash:
                metas[name] = old
                resumed.add(name)
                _say(progress, f"{name}: unchanged (hash {task.input_hash}), skipped")
                continue
        tasks.append(task)
        pending[name] = variant
    order = {name: k for k, name in enumerate(_run_order(pending))}
    tasks.sort(key=lambda t: order[t.name])
    _check_reference(reference if reference is not None else (settings.reference if settings else ""), names)
    metas.update(_execute(tasks, workers, scheduler, runner, out_dir, progress))
    table = pd.DataFrame([_row(n, metas[n], n in resumed) for n in names])
    write_table(table, out_dir / "matrix_results")
    if settings is None:
        settings = load_gearbox(Path(__file__).resolve().parents[2] / "model_variants" / "gearbox.toml").screening
    screening = screen_directory(out_dir, names, settings, progress, reference)
    ref_name = reference if reference is not None else settings.reference
    ref_file = variant_files.get(ref_name)
    if ref_file is not None and modal and runner is None:
        ref_variant = load_variant(ref_file)
        if all(form == "flexible" for form in ref_variant.components.values()):
            modal_verdict(out_dir, ref_variant, progress)
    screening = screening.reindex(columns=["variant", "bias_pct", "cv_pct", "distance_pct", "sigma", "zone",
                                           "selected"])
    return table.merge(screening, on="variant", how="left")
