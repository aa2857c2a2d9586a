"""Variant matrix runner: run variants in parallel, time them, resume, then screen (section 2.2).

``run_matrix`` runs every variant file in a worker process (a local process pool, or a Dask
distributed cluster given by its scheduler address), the runs with the most flexible bodies first
(the longest start first, so that the last ones overlap), writes each run with
:func:`flexgear.results.save_result` under ``out_dir/<variant name>/`` together with copies of
its input files (``inputs/``), and then writes

- ``matrix_results.csv`` / ``.parquet``: one row per variant: status and reason, components,
  simulated time, the runner's wall and CPU time of the run (model build + simulation), the
  worker's total wall and CPU time (file loading, build, simulation, saving), input and
  configuration hashes, whether the run was resumed;
- ``screening.csv`` / ``.parquet``: per variant Bias %, CV %, distance, zone, sigma, time,
  selected (:func:`flexgear.study.screening.screening_tables`); ``screening_indicators.*`` per
  indicator; ``selection.txt``: the selected variant and why.

Resume: a run is skipped when its directory holds an ``ok`` result whose ``input_hash`` equals
the hash of the variant (the gearbox without its ``[screening]`` table, which is
post-processing only) and the simulated end time. A variant whose file is bad (SpecError), whose
runner returns a failed result, raises, or kills its worker process is recorded as failed with
its reason while the others go on. CPU time is the worker process's ``time.process_time``
(all its threads). With a remote Dask cluster, ``out_dir`` must be on a file system the workers
share with the caller.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import pandas as pd

from flexgear.cache import atomic_write_bytes
from flexgear.results import RunResult, load_result, save_result
from flexgear.spec import COMPONENTS, ScreeningSettings, SpecError, Variant, load_gearbox, load_variant, spec_hash
from flexgear.study.screening import screening_tables

__all__ = ["run_matrix", "run_input_hash", "run_one", "write_table", "screen_directory"]

Runner = Callable[..., RunResult]

_HEARTBEAT_S = 30.0
_POLL_S = 0.2


def run_input_hash(variant: Variant, t_end_s: float) -> str:
    """Hash of everything a run depends on: the variant, its gearbox (without ``[screening]``), t_end."""
    gearbox = dataclasses.replace(variant.gearbox, screening=None)
    return spec_hash(dataclasses.replace(variant, gearbox=gearbox), float(t_end_s), "exudyn")


def _default_runner() -> Runner:
    from flexgear.mbs.run import run_variant

    return run_variant


def _failed(name: str, reason: str, **meta: Any) -> RunResult:
    return RunResult({"variant": name, "backend": "exudyn", "status": "failed", "reason": reason,
                      "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"), **meta})


def _copy_inputs(variant: Variant, run_dir: Path) -> dict[str, str]:
    inputs = run_dir / "inputs"
    inputs.mkdir(parents=True, exist_ok=True)
    copied = {}
    for key, src in (("variant", variant.source), ("gearbox", variant.gearbox.source)):
        dst = inputs / Path(src).name
        atomic_write_bytes(dst, Path(src).read_bytes())
        copied[key] = str(dst.relative_to(run_dir))
    return copied


def run_one(variant_path: str, run_dir: str, t_end_s: float | None, input_hash: str,
            runner: Runner | None = None) -> dict[str, Any]:
    """Worker task: load, run and save one variant; never raises for a model failure.

    Returns the saved metadata (small, cheap to send back from a worker process).
    """
    wall0, cpu0 = time.perf_counter(), time.process_time()
    name = Path(variant_path).stem
    try:
        variant = load_variant(variant_path)
        name = variant.name
        result = (runner or _default_runner())(variant, t_end_s=t_end_s, progress=False)
        inputs = _copy_inputs(variant, Path(run_dir))
    except Exception as exc:  # recorded, not raised: the other variants go on
        result, inputs = _failed(name, f"{type(exc).__name__}: {exc}"), {}
    result.meta.update(input_hash=input_hash, variant_file=str(variant_path), inputs=inputs,
                       total_wall_time_s=time.perf_counter() - wall0, total_cpu_time_s=time.process_time() - cpu0)
    save_result(result, run_dir)
    return dict(result.meta)


def write_table(table: pd.DataFrame, stem: Path) -> None:
    """Write ``stem.csv`` and ``stem.parquet`` atomically."""
    atomic_write_bytes(stem.with_suffix(".csv"), table.to_csv(index=False).encode())
    atomic_write_bytes(stem.with_suffix(".parquet"), table.to_parquet(index=False))


# --------------------------------------------------------------------------- execution
@dataclasses.dataclass(frozen=True)
class _Task:
    name: str
    path: str
    run_dir: str
    input_hash: str


def _say(progress: bool, text: str) -> None:
    if progress:
        print(f"[matrix {time.strftime('%H:%M:%S')}] {text}", file=sys.stderr, flush=True)


def _run_pool(tasks: list[_Task], submit: Callable, t_end_s: float | None, runner: Runner | None,
              progress: bool, done_count: list[int], total: int) -> tuple[dict[str, dict], list[_Task]]:
    """Submit tasks, poll until all finish; return metas and the tasks whose worker died."""
    futures = {submit(run_one, t.path, t.run_dir, t_end_s, t.input_hash, runner): t for t in tasks}
    started = time.perf_counter()
    last_beat = started
    metas: dict[str, dict] = {}
    died: list[_Task] = []
    while futures:
        finished = [f for f in futures if f.done()]
        for fut in finished:
            task = futures.pop(fut)
            try:
                meta = fut.result()
            except Exception as exc:  # the worker process died (segfault, out of memory) or was killed
                died.append(task)
                _say(progress, f"{task.name}: worker lost ({type(exc).__name__}: {exc})")
                continue
            metas[task.name] = meta
            done_count[0] += 1
            _say(progress, f"{done_count[0]}/{total} {task.name}: {meta['status']}, "
                           f"{meta.get('wall_time_s', float('nan')):.1f} s wall, "
                           f"{meta.get('cpu_time_s', float('nan')):.1f} s CPU"
                           + (f" ({meta.get('reason')})" if meta["status"] != "ok" else ""))
        now = time.perf_counter()
        if futures and now - last_beat >= _HEARTBEAT_S:
            last_beat = now
            _say(progress, f"running {len(futures)}: {', '.join(t.name for t in futures.values())} "
                           f"({now - started:.0f} s elapsed)")
        if futures and not finished:
            time.sleep(_POLL_S)
    return metas, died


def _execute(tasks: list[_Task], t_end_s: float | None, workers: int, scheduler: str | None,
             runner: Runner | None, progress: bool) -> dict[str, dict]:
    done_count = [0]
    if not tasks:
        return {}
    if scheduler is not None:
        from distributed import Client

        with Client(scheduler) as client:
            _say(progress, f"{len(tasks)} runs on Dask cluster {scheduler}")

            def submit(fn: Callable, *args: Any) -> Any:
                return client.submit(fn, *args, pure=False, key=f"flexgear-run-{args[0]}-{args[3]}")

            metas, died = _run_pool(tasks, submit, t_end_s, runner, progress, done_count, len(tasks))
    else:
        _say(progress, f"{len(tasks)} runs on {workers} local worker process(es)")
        ctx = get_context("spawn")
        with ProcessPoolExecutor(max_workers=max(1, workers), mp_context=ctx) as pool:
            metas, died = _run_pool(tasks, pool.submit, t_end_s, runner, progress, done_count, len(tasks))
        # A dead worker breaks the whole pool: rerun each affected task alone to find the culprit.
        retry, died = died, []
        for task in retry:
            with ProcessPoolExecutor(max_workers=1, mp_context=ctx) as solo:
                again, lost = _run_pool([task], solo.submit, t_end_s, runner, progress, done_count, len(tasks))
            metas.update(again)
            died += lost
    for task in died:  # died again alone (or on the cluster): record it
        result = _failed(task.name, "worker process died (crash or out of memory in the solver)",
                         input_hash=task.input_hash, variant_file=task.path)
        save_result(result, task.run_dir)
        metas[task.name] = dict(result.meta)
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
                     progress: bool = False) -> pd.DataFrame:
    """Screen saved runs ``out_dir/<name>`` and write the screening tables and ``selection.txt``."""
    results = [load_result(out_dir / n) if (out_dir / n / "run.json").exists()
               else _failed(n, "no saved run") for n in names]
    table, indicators, selection = screening_tables(results, settings)
    write_table(table, out_dir / "screening")
    write_table(indicators, out_dir / "screening_indicators")
    text = f"selected: {selection.variant}\nrule: {selection.rule}\n{selection.reasoning}\n"
    atomic_write_bytes(out_dir / "selection.txt", text.encode())
    _say(progress, f"selected {selection.variant}: {selection.reasoning}")
    return table


def _flexible_bodies(variant: Variant) -> int:
    """Flexible bodies of a variant (planets count each): the measure of its run time used to order the runs."""
    planets = variant.gearbox.gears.planet_count
    return sum((planets if c == "planets" else 1) for c, form in variant.components.items() if form == "flexible")


def run_matrix(variant_paths: Sequence[str | Path], out_dir: str | Path, t_end_s: float | None = None,
               workers: int = 2, scheduler: str | None = None, progress: bool = True,
               runner: Runner | None = None) -> pd.DataFrame:
    """Run the variant files, save each run, screen them; return the results + screening table.

    ``runner(variant, t_end_s=..., progress=...) -> RunResult`` defaults to
    :func:`flexgear.mbs.run.run_variant`; it must be importable by the worker processes.
    ``scheduler`` is a Dask scheduler address (``tcp://host:8786``); None uses ``workers`` local
    processes. See the module docstring for the files written and the resume rule.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    names: list[str] = []
    metas: dict[str, dict] = {}
    resumed: set[str] = set()
    tasks: list[_Task] = []
    cost: dict[str, int] = {}
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
        settings = settings or variant.gearbox.screening
        t_end = variant.gearbox.load_case.end_time_s if t_end_s is None else float(t_end_s)
        h = run_input_hash(variant, t_end)
        run_dir = out_dir / name
        if (run_dir / "run.json").exists():
            old = load_result(run_dir).meta
            if old.get("status") == "ok" and old.get("input_hash") == h:
                metas[name] = old
                resumed.add(name)
                _say(progress, f"{name}: unchanged (hash {h}), skipped")
                continue
        tasks.append(_Task(name, str(path), str(run_dir), h))
        cost[name] = _flexible_bodies(variant)
    tasks.sort(key=lambda t: -cost[t.name])  # longest first: the last runs overlap (stable for ties)
    metas.update(_execute(tasks, t_end_s, workers, scheduler, runner, progress))
    table = pd.DataFrame([_row(n, metas[n], n in resumed) for n in names])
    write_table(table, out_dir / "matrix_results")
    if settings is None:
        settings = load_gearbox(Path(__file__).resolve().parents[2] / "model_variants" / "gearbox.toml").screening
    screening = screen_directory(out_dir, names, settings, progress)
    cols = ["variant", "bias_pct", "cv_pct", "distance_pct", "sigma", "zone", "selected"]
    return table.merge(screening[cols], on="variant", how="left")
