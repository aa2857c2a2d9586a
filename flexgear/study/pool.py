"""The runs of a variant matrix in a pool: local worker processes or a Dask cluster (flexgear.study.matrix).

A run goes to a worker as a :class:`RunTask` carrying the *content* of its variant and gearbox files and of the part
files its ``[components_geometry]`` names (no paths to open: the worker lays the files out in a folder of its own,
as they lie relative to each other); the worker runs it (:func:`run_task`) and sends the
:class:`~flexgear.results.RunResult` back, which the caller saves in the run's results folder as it arrives
(:func:`save_task_result`), with copies of those files. Beside the runs, jobs that need no run (the modal and speed
screenings) take a worker the runs leave free. A worker that dies is retried alone
once, then its run is recorded as failed.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import os
import socket
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import pandas as pd

from flexgear.cache import atomic_write_bytes
from flexgear.progress import Progress, say
from flexgear.results import RunResult, save_result
from flexgear.spec import Variant, load_variant, spec_hash

__all__ = ["Runner", "RunTask", "make_task", "run_input_hash", "body_keys", "run_task", "save_task_result",
           "failed_result", "execute", "say_progress", "write_table"]

Runner = Callable[..., RunResult]

_HEARTBEAT_S = 60.0
_POLL_S = 0.2


def run_input_hash(variant: Variant, t_end_s: float | str, error_window_s: float = 0.0) -> str:
    """Hash of everything a run depends on: the variant, its gearbox (without ``[screening]``, except the settling
    test's fields for a run continued until it settles), t_end (s, or "settled"), the error windows' length, and
    the cache keys of the bodies it is built from (:func:`body_keys`): a run made with bodies that a new
    geometry, mesh or reduction has replaced is not kept."""
    gearbox = dataclasses.replace(variant.gearbox, screening=None)
    if t_end_s != "settled":
        extra: tuple = (float(t_end_s),)
    else:
        sc = variant.gearbox.screening
        extra = ("settled", sc.settle_block_mesh_cycles, sc.settle_final_blocks, sc.settle_mean_tolerance_pct,
                 sc.settle_amplitude_tolerance_pct, sc.sample_count, sc.after_ramp_delay_s,
                 sc.settle_acceleration_floor_m_per_s2)
    if error_window_s > 0:
        extra = (*extra, "error_window", float(error_window_s))
    return spec_hash(dataclasses.replace(variant, gearbox=gearbox), *extra, "exudyn", *body_keys(variant))


def body_keys(variant: Variant) -> tuple[str, ...]:
    """The cache keys (flexgear.fe.build.build_key) of the bodies ``variant`` is built from at its mesh level: every
    component's reduced body (a rigid one takes its mass properties from the same mesh) and the tied ring and output
    shaft where the variant joins them (flexgear.fe.build.variant_build_items). () when they cannot be named (a bad
    variant: its run fails with the reason)."""
    from flexgear.fe.build import build_key, variant_build_items
    from flexgear.spec import COMPONENT_GEOMETRY

    try:
        items = {COMPONENT_GEOMETRY[c] for c in variant.components}
        items |= set(variant_build_items(variant.gearbox, variant.components))
        return tuple(sorted(build_key(variant.gearbox, item, variant.mesh_level) for item in items))
    except Exception:  # noqa: BLE001  (a bad variant is refused with its reason when it runs)
        return ()


def _default_runner() -> Runner:
    from flexgear.mbs.run import run_variant

    return run_variant


def failed_result(name: str, reason: str, **meta: Any) -> RunResult:
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
    out_dir: str = ""  # the caller's results folder of the run (not read by the worker)
    parts: tuple[tuple[str, bytes], ...] = ()  # the part files of [components_geometry]: (caller's path, content)

    @property
    def key(self) -> tuple[str, str]:
        """(results folder, variant name): unique over the folders of one pool."""
        return (self.out_dir, self.name)

    def inputs(self) -> dict[str, bytes]:
        """The input files for ``inputs/`` of the run folder: the variant and gearbox files, and each part file
        under its path from the gearbox file's folder (its name alone where that path leaves the folder)."""
        out = {Path(self.variant_file).name: self.variant_text.encode(),
               Path(self.gearbox_file).name: self.gearbox_text.encode()}
        for path, data in self.parts:
            rel = Path(os.path.relpath(path, Path(self.gearbox_file).parent))
            out[(rel if ".." not in rel.parts else Path(rel.name)).as_posix()] = data
        return out

    def laid_out(self, folder: Path) -> Path:
        """Write the variant, gearbox and part files into ``folder`` as they lie relative to the variant file's
        folder (as deep in ``folder`` as their ``..`` need); returns the variant file's path there."""
        home = Path(self.variant_file).parent
        files = [(Path(os.path.relpath(p, home)), data) for p, data in
                 ((self.gearbox_file, self.gearbox_text.encode()), *self.parts)]
        depth = max((sum(part == ".." for part in rel.parts) for rel, _ in files), default=0)
        base = folder.joinpath(*["up"] * depth)
        for rel, data in files:
            target = Path(os.path.normpath(base / rel))
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        variant = base / Path(self.variant_file).name
        base.mkdir(parents=True, exist_ok=True)
        variant.write_text(self.variant_text)
        return variant


_PARTS: dict[tuple[str, str], bytes] = {}
"""Part files read for tasks, by (resolved path, SHA-256 at load): the variants of a matrix share one read."""


def part_bytes(path: str | Path, sha256: str) -> bytes:
    """The content of the part file ``path`` whose content had the SHA-256 ``sha256`` when its gearbox was loaded
    (flexgear.schema_geometry.ComponentGeometry), read once per process; a file changed since then raises ValueError
    in one line (the run would not be the one its cache keys name)."""
    import hashlib

    key = (str(Path(path).resolve()), sha256)
    if key not in _PARTS:
        data = Path(path).read_bytes()
        if hashlib.sha256(data).hexdigest() != sha256:
            raise ValueError(f"{path}: the part file changed since its gearbox file was loaded; load it again")
        _PARTS[key] = data
    return _PARTS[key]


def make_task(variant: Variant, t_end_s: float | str | None, time_budget_s: float | None = None,
              error_window_s: float = 0.0, out_dir: str | Path = "") -> RunTask:
    """The task of a loaded variant: reads its two files once, on the caller's side; ``t_end_s`` in s, "settled"
    or None (the load case's end: ``end_time_s``, or "settled" with ``[load_case] end = "settled"``)."""
    lc = variant.gearbox.load_case
    t_end = t_end_s if t_end_s is not None else ("settled" if lc.end == "settled" else lc.end_time_s)
    parts = {str(Path(e.source).resolve()): part_bytes(e.source, e.sha256)
             for e in variant.gearbox.components_geometry.values()}
    return RunTask(variant.name, str(Path(variant.source).resolve()), Path(variant.source).read_text(),
                   str(Path(variant.gearbox.source).resolve()), Path(variant.gearbox.source).read_text(), t_end_s,
                   run_input_hash(variant, t_end, error_window_s), time_budget_s, error_window_s, str(out_dir),
                   tuple(sorted(parts.items())))


def run_task(task: RunTask, runner: Runner | None = None) -> RunResult:
    """Worker side: load the variant from the shipped content, run it, return the result (writes nothing
    but cache entries and, for a variant with part files, a temporary folder that holds them during the run,
    :meth:`RunTask.laid_out`: the worker needs none of the caller's files). Never raises for a model failure."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    try:
        with tempfile.TemporaryDirectory(prefix="flexgear-task-") as folder:
            path = task.laid_out(Path(folder)) if task.parts else Path(task.variant_file)
            variant = load_variant(path, task.variant_text, task.gearbox_text)
            extra: dict[str, Any] = {} if task.time_budget_s is None else {"time_budget_s": task.time_budget_s}
            if task.error_window_s > 0:
                extra["error_window_s"] = task.error_window_s
            result = (runner or _default_runner())(variant, t_end_s=task.t_end_s, progress=False, **extra)
    except Exception as exc:  # recorded, not raised: the other variants go on
        result = failed_result(task.name, f"{type(exc).__name__}: {exc}")
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


def say_progress(progress: bool, text: str) -> None:
    if progress:
        say(f"[matrix {time.strftime('%H:%M:%S')}] {text}")


def _run_pool(tasks: list[RunTask], submit: Callable, runner: Runner | None, progress: bool, bar: Progress,
              jobs: Sequence[tuple[Any, Callable, tuple]] = (),
              first: Sequence[tuple[Any, Callable, tuple]] = (), ahead: Sequence[tuple[Any, Callable, tuple]] = (),
              waiting: set | frozenset = frozenset()) -> tuple[dict, list[RunTask], dict]:
    """Submit the ``first`` jobs (key, function, arguments: a cold body that runs wait for), the runs that wait for
    none, the ``ahead`` jobs, the runs whose key is in ``waiting``, then the ``jobs``: work that needs no run (the
    modal and speed screenings), taken by a worker when the runs leave one free. Each run's result is saved in its
    folder as it arrives. Returns the runs' metas by :attr:`RunTask.key`, the runs whose worker died, the jobs'
    results by key (an exception raised by a job is its result)."""
    several = len({t.out_dir for t in tasks}) > 1
    side = {submit(fn, *args): key for key, fn, args in first}
    futures = {submit(run_task, t, runner): t for t in tasks if t.key not in waiting}
    side.update({submit(fn, *args): key for key, fn, args in ahead})
    futures.update({submit(run_task, t, runner): t for t in tasks if t.key in waiting})
    side.update({submit(fn, *args): key for key, fn, args in jobs})
    started = last_beat = time.perf_counter()
    metas: dict[tuple[str, str], dict] = {}
    done: dict[Any, Any] = {}
    died: list[RunTask] = []
    while futures or side:
        for fut in [f for f in side if f.done()]:
            key = side.pop(fut)
            try:
                done[key] = fut.result()
            except Exception as exc:  # recorded by the caller: the screenings of the runs do not depend on it
                done[key] = exc
            if key[0] == "build":  # a cold body (flexgear.study.matrix): the runs that need it start now
                outcome = "built" if not isinstance(done[key], BaseException) else (
                    f"not built ({type(done[key]).__name__}: {done[key]})")
                say_progress(progress, f"{key[1]} ({key[2]}) body {outcome} "
                                       f"({time.perf_counter() - started:.0f} s elapsed)")
        finished = [f for f in futures if f.done()]
        for fut in finished:
            task = futures.pop(fut)
            try:
                result = fut.result()
            except Exception as exc:  # the worker process died (segfault, out of memory) or was killed
                died.append(task)
                say_progress(progress, f"{task.name}: worker lost ({type(exc).__name__}: {exc})")
                continue
            meta = metas[task.key] = save_task_result(task, result, Path(task.out_dir) / task.name)
            bar.update_to(bar.value + 1, postfix=f"{task.name} {meta['status']}")
            say_progress(progress, f"{_label(task, several)}: {meta['status']}, "
                           f"{meta.get('wall_time_s', float('nan')):.1f} s wall, "
                           f"{meta.get('cpu_time_s', float('nan')):.1f} s CPU"
                           + (f" ({meta.get('reason')})" if meta["status"] != "ok" else ""))
        now = time.perf_counter()
        if (futures or side) and now - last_beat >= _HEARTBEAT_S:
            last_beat = now
            pending = [_label(t, several) for t in futures.values()] + [
                f"speed:{k[2]}" if k[0] == "speed" else str(k[0]) for k in side.values()]  # a speed curve's variant
            say_progress(progress, f"running or queued {len(pending)}: {', '.join(pending)} "
                                   f"({now - started:.0f} s elapsed)")
        if (futures or side) and not finished:
            time.sleep(_POLL_S)
    return metas, died, done


def _label(task: RunTask, several: bool) -> str:
    """A run's name in progress lines: with its folder's name when a pool serves ``several`` folders."""
    return f"{Path(task.out_dir).name}/{task.name}" if several else task.name


def execute(tasks: list[RunTask], workers: int, scheduler: str | None, runner: Runner | None,
            progress: bool, jobs: Sequence[tuple[Any, Callable, tuple]] = (),
            first: Sequence[tuple[Any, Callable, tuple]] = (), ahead: Sequence[tuple[Any, Callable, tuple]] = (),
            waiting: set | frozenset = frozenset()) -> tuple[dict, dict]:
    """Run ``first`` (local pools only), ``tasks``, ``ahead`` and ``jobs`` in one pool (module docstring,
    :func:`_run_pool`); ``ahead``: jobs queued before the tasks whose key is in ``waiting`` (runs that wait for a
    cold body of ``first``). Returns the runs' metas by key and the jobs' results by key."""
    if not tasks and not jobs and not ahead:
        return {}, {}
    # on a terminal a bar; in a log the per-run lines of _say are the progress
    bar = Progress(len(tasks), "matrix", "runs", enabled=progress and sys.stderr.isatty(), fmt="{:.0f}")
    if scheduler is not None:
        from distributed import Client

        with Client(scheduler) as client:
            say_progress(progress, f"{len(tasks)} runs on Dask cluster {scheduler}")

            def submit(fn: Callable, *args: Any) -> Any:
                key = f"flexgear-run-{args[0].name}-{args[0].input_hash}" if fn is run_task else None
                return client.submit(fn, *args, pure=False, key=key)

            metas, died, done = _run_pool(tasks, submit, runner, progress, bar, [*ahead, *jobs])
    else:
        n_jobs = len(jobs) + len(ahead)
        say_progress(progress, f"{len(tasks)} runs" + (f" and {n_jobs} screening jobs" if n_jobs else "")
                     + f" on {workers} local worker process(es)")
        ctx = get_context("spawn")
        with ProcessPoolExecutor(max_workers=max(1, workers), mp_context=ctx) as pool:
            metas, died, done = _run_pool(tasks, pool.submit, runner, progress, bar, jobs, first, ahead, waiting)
        # A dead worker breaks the whole pool: rerun each affected task alone to find the culprit.
        retry, died = died, []
        for task in retry:
            with ProcessPoolExecutor(max_workers=1, mp_context=ctx) as solo:
                again, lost, _ = _run_pool([task], solo.submit, runner, progress, bar)
            metas.update(again)
            died += lost
    for task in died:  # died again alone (or on the cluster): record it
        result = failed_result(task.name, "worker process died (crash or out of memory in the solver)",
                         input_hash=task.input_hash, variant_file=task.variant_file)
        metas[task.key] = save_task_result(task, result, Path(task.out_dir) / task.name)
        bar.update_to(bar.value + 1, postfix=f"{task.name} failed")
    bar.close()
    return metas, done
