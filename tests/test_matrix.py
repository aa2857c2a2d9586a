"""Matrix runner: parallel runs, failures recorded, resume by input hash, Dask, end to end."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
from pathlib import Path

import pandas as pd
import pytest
from synthetic import GEARBOX, fake_runner

from flexgear.results import load_result
from flexgear.study.matrix import run_matrix

VARIANTS = Path("model_variants")


def _variant(folder: Path, name: str, flexible: tuple[str, ...] = (), sun: str | None = None) -> Path:
    comps = {c: ("flexible" if c in flexible else "rigid")
             for c in ("input_shaft", "sun", "planets", "ring", "output_shaft")}
    if sun is not None:
        comps["sun"] = sun
    body = "\n".join(f'{k} = "{v}"' for k, v in comps.items())
    path = folder / f"{name}.toml"
    path.write_text(f'name = "{name}"\ngearbox = "gearbox.toml"\n\n[components]\n{body}\n')
    return path


def _gearbox_after_ramps(folder: Path) -> None:
    """The study's gearbox with the screening window from the end of the ramps: the synthetic runs' sample noise
    is not a settled run's, and these tests are about the runner, not the settling test (test_reference_screening)."""
    text = Path(GEARBOX).read_text().replace('window = "settled"', 'window = "after_ramps"')
    (folder / "gearbox.toml").write_text(text)


@pytest.fixture()
def variants(tmp_path: Path) -> dict[str, Path]:
    _gearbox_after_ramps(tmp_path)
    return {"rigid": _variant(tmp_path, "rigid"),
            "flex": _variant(tmp_path, "flex", ("sun", "ring")),
            "bad": _variant(tmp_path, "bad", sun="elastic"),
            "boom": _variant(tmp_path, "boom"),
            "diverge": _variant(tmp_path, "diverge"),
            "crash": _variant(tmp_path, "crash")}


def test_matrix_of_three_with_a_bad_file(variants, tmp_path):
    out = tmp_path / "results"
    table = run_matrix([variants["rigid"], variants["flex"], variants["bad"]], out, t_end_s=0.6,
                       workers=2, progress=False, runner=fake_runner)
    assert list(table["variant"]) == ["rigid", "flex", "bad"]
    bad = table.set_index("variant").loc["bad"]
    assert bad["status"] == "failed"
    assert "bad.toml" in bad["reason"] and "components.sun" in bad["reason"] and "rigid" in bad["reason"]
    ok = table[table["status"] == "ok"].set_index("variant")
    assert (ok["total_wall_time_s"] > 0).all() and (ok["total_cpu_time_s"] >= 0).all()
    # fake runner: Bias 1 % / (1 + flexible count) and CV 0.2 % on 3 of 5 indicators, 20 % weights:
    # rigid (0.6 %, 0.12 %) meets Bias + 3 CV <= 1 % but not 4 CV (good); flex (0.2 %, 0.12 %) excellent
    assert ok.loc["rigid", "bias_pct"] == pytest.approx(0.6, rel=1e-6)
    assert ok.loc["flex", "bias_pct"] == pytest.approx(0.2, rel=1e-6)
    assert ok.loc["flex", "zone"] == "excellent" and ok.loc["rigid", "zone"] == "good"
    assert bool(ok.loc["flex", "selected"]) and not bool(ok.loc["rigid", "selected"])
    for stem in ("matrix_results", "screening", "screening_indicators"):
        assert pd.read_csv(out / f"{stem}.csv").shape[0] > 0
        assert pd.read_parquet(out / f"{stem}.parquet").shape[0] > 0
    assert "selected: flex" in (out / "selection.txt").read_text()
    saved = load_result(out / "flex")
    assert saved.ok and len(saved.signals) > 1000 and saved.meta["input_hash"]
    assert (out / "flex" / "inputs" / "gearbox.toml").exists()
    assert json.loads((out / "bad" / "run.json").read_text())["status"] == "failed"


def test_runner_failures_are_recorded_and_the_others_go_on(variants, tmp_path):
    table = run_matrix([variants["boom"], variants["diverge"], variants["rigid"]], tmp_path / "r", t_end_s=0.6,
                       workers=2, progress=False, runner=fake_runner).set_index("variant")
    assert table.loc["boom", "status"] == "failed" and "RuntimeError: solver blew up" in table.loc["boom", "reason"]
    assert table.loc["diverge", "status"] == "failed" and "diverged" in table.loc["diverge", "reason"]
    assert table.loc["rigid", "status"] == "ok" and bool(table.loc["rigid", "selected"])


def test_a_dying_worker_process_is_recorded_and_the_others_rerun(variants, tmp_path):
    table = run_matrix([variants["crash"], variants["rigid"], variants["flex"]], tmp_path / "c", t_end_s=0.6,
                       workers=2, progress=False, runner=fake_runner).set_index("variant")
    assert table.loc["crash", "status"] == "failed" and "worker process died" in table.loc["crash", "reason"]
    assert (table.loc[["rigid", "flex"], "status"] == "ok").all()


def test_resume_skips_unchanged_runs(variants, tmp_path):
    out = tmp_path / "results"
    paths = [variants["rigid"], variants["flex"]]
    first = run_matrix(paths, out, t_end_s=0.6, workers=1, progress=False, runner=fake_runner)
    stamp = (out / "rigid" / "run.json").stat().st_mtime_ns
    again = run_matrix(paths, out, t_end_s=0.6, workers=1, progress=False, runner=fake_runner)
    assert again["resumed"].all() and not first["resumed"].any()
    assert (out / "rigid" / "run.json").stat().st_mtime_ns == stamp
    pd.testing.assert_series_equal(first["bias_pct"], again["bias_pct"])
    # a changed input (here: the simulated time) runs again
    changed = run_matrix(paths[:1], out, t_end_s=0.5, workers=1, progress=False, runner=fake_runner)
    assert not changed["resumed"].any()


def test_a_run_made_with_replaced_bodies_runs_again(variants, tmp_path, monkeypatch):
    """The input hash holds the cache keys of the bodies a run is built from (flexgear.study.pool.body_keys): a new
    geometry construction (its version, part of every body's key) replaces the bodies, so the runs made with the
    old ones are not kept. The tied ring and output shaft is among an all-flexible variant's bodies only."""
    import flexgear.geometry.layout as layout
    from flexgear.spec import load_variant
    from flexgear.study.pool import body_keys

    flex = load_variant(VARIANTS / "model7.toml")
    assert any("tied" in k for k in body_keys(flex))
    assert not any("tied" in k for k in body_keys(load_variant(VARIANTS / "model1.toml")))
    out = tmp_path / "results"
    run_matrix([variants["rigid"]], out, t_end_s=0.6, workers=1, progress=False, runner=fake_runner)
    assert run_matrix([variants["rigid"]], out, t_end_s=0.6, workers=1, progress=False,
                      runner=fake_runner)["resumed"].all()
    monkeypatch.setattr(layout, "GEOMETRY_VERSION", layout.GEOMETRY_VERSION + 1)
    assert not run_matrix([variants["rigid"]], out, t_end_s=0.6, workers=1, progress=False,
                          runner=fake_runner)["resumed"].any()


def _confine(workdir: str, forbidden: list[str]) -> str:
    """On a Dask worker: run in ``workdir`` and refuse any file access under ``forbidden`` (the caller's
    variant files and output folder), as on a cluster node that does not share the caller's disk."""
    import os
    import sys

    roots = [os.path.realpath(f) for f in forbidden]

    def hook(event: str, args: tuple) -> None:
        if event in ("open", "os.rename", "os.replace", "os.mkdir", "os.remove", "os.listdir", "os.scandir"):
            for arg in args[:2]:
                if isinstance(arg, (str, bytes, os.PathLike)):
                    path = os.path.realpath(os.fsdecode(arg))
                    if any(path == r or path.startswith(r + os.sep) for r in roots):
                        raise PermissionError(f"worker may not touch {path}")

    os.chdir(workdir)
    sys.addaudithook(hook)
    return os.getcwd()


def test_dask_workers_get_content_not_paths_and_the_caller_writes(variants, tmp_path, tmp_path_factory):
    """Workers in another working directory and cache folder, unable to read the variant files or to write
    the output folder: the runs still succeed and every result lands in the caller's folder."""
    distributed = pytest.importorskip("distributed")
    remote = tmp_path_factory.mktemp("worker_node")
    cache = remote / "cache"
    out = tmp_path / "d"
    forbidden = [str(variants["rigid"]), str(variants["flex"]), str(variants["boom"]), str(tmp_path / "gearbox.toml"),
                 str(out)]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  local_directory=str(remote), env={"FLEXGEAR_CACHE_DIR": str(cache)}) as cluster:
        with distributed.Client(cluster) as client:
            cwds = client.run(_confine, str(remote), forbidden)
            assert set(cwds.values()) == {str(remote)}
            blocked = client.submit(lambda p: open(p).read(), str(variants["rigid"]), pure=False)
            with pytest.raises(PermissionError):
                blocked.result()
        table = run_matrix([variants["rigid"], variants["flex"], variants["boom"]], out, t_end_s=0.6,
                           scheduler=cluster.scheduler_address, progress=False, runner=fake_runner)
    status = dict(zip(table["variant"], table["status"], strict=True))
    assert status == {"rigid": "ok", "flex": "ok", "boom": "failed"}
    assert table.loc[table["variant"] == "flex", "selected"].item()
    for name in ("rigid", "flex"):
        saved = load_result(out / name)
        assert saved.ok and len(saved.signals) > 1000
        assert saved.meta["worker_cwd"] == str(remote) and saved.meta["worker_cache"] == str(cache)
        assert (out / name / "inputs" / "gearbox.toml").read_text() == (tmp_path / "gearbox.toml").read_text()


def test_quick_matrix_end_to_end_with_the_exudyn_backend(tmp_path):
    """model1 (rigid) and model2 (flexible planets, coarse mesh) for 0.02 s, through the real runner."""
    pytest.importorskip("flexgear.mbs.run")
    from flexgear.laws.ramps import step
    from flexgear.spec import load_gearbox
    from flexgear.study.screening import screen_result

    shutil.copy(GEARBOX, tmp_path / "gearbox.toml")
    m1 = tmp_path / "model1.toml"
    # exact mass properties for the rigid parts: only the planets' coarse reduced body is built
    exact = 'rigid_mass_properties = "exact"\n'
    m1.write_text(exact + (VARIANTS / "model1.toml").read_text())
    m2 = tmp_path / "model2.toml"
    m2.write_text(exact + (VARIANTS / "model2.toml").read_text())  # flexible planets, coarse mesh level
    table = run_matrix([m1, m2], tmp_path / "quick", t_end_s=0.02, workers=2, progress=False).set_index("variant")
    assert table.loc["model1", "status"] == "ok"
    assert table.loc["model2", "status"] == "ok", table.loc["model2", "reason"]
    assert table.loc["model1", "wall_time_s"] > 0 and table.loc["model1", "cpu_time_s"] > 0
    screening = pd.read_csv(tmp_path / "quick" / "screening.csv").set_index("variant")
    # a run that ends inside its ramps has not settled: marked, not scored
    assert screening.loc["model1", "status"] == "unsettled" and "ramps" in screening.loc["model1", "reason"]
    # The input speed is prescribed (STEP ramp, Table 5): its screened mean over the window must be
    # the ramp's own mean there, an independent check of signals -> samples -> Bias.
    result = load_result(tmp_path / "quick" / "model1")
    s = screen_result(result, load_gearbox(GEARBOX).screening)
    t = result.signals["time_s"].to_numpy()
    inside = (t >= s.window.start_s) & (t <= s.window.end_s)
    nominal = 6000.0 * math.pi / 30.0  # rad/s, Table 5
    prescribed = step(t[inside], 0.0, 0.0, result.meta["ramp_time_s"], nominal).mean()
    assert s.indicators["input_speed"].mean == pytest.approx(prescribed, rel=1e-3)
    assert s.indicators["input_speed"].bias == pytest.approx(100 * (1 - prescribed / nominal), rel=1e-3)


def test_one_pool_serves_several_results_folders(tmp_path):
    """``--out results/{folder}``: the variant files of two folders, with the same names in both, run in one pool;
    each folder gets its runs, tables and screening, as a matrix of its own would."""
    paths = []
    for folder in ("impact", "iso"):
        (tmp_path / folder).mkdir()
        _gearbox_after_ramps(tmp_path / folder)
        paths += [_variant(tmp_path / folder, "rigid"), _variant(tmp_path / folder, "flex", ("sun",))]
    table = run_matrix(paths, tmp_path / "results" / "{folder}", t_end_s=0.6, workers=2, progress=False,
                       runner=fake_runner)
    assert sorted(set(table["results"])) == [str(tmp_path / "results" / f) for f in ("impact", "iso")]
    for folder in ("impact", "iso"):
        out = tmp_path / "results" / folder
        assert (out / "matrix_results.csv").is_file() and (out / "selection.txt").is_file()
        rows = table[table["results"] == str(out)].set_index("variant")
        assert set(rows.index) == {"rigid", "flex"} and (rows["status"] == "ok").all()
        assert load_result(out / "rigid").meta["variant_file"] == str(tmp_path / folder / "rigid.toml")


def _part_runner(variant, t_end_s, progress=False, **_):
    """A runner that reports the sun's part file as the worker loaded it (its SHA-256, whether it is there)."""
    from flexgear.results import RunResult

    entry = variant.gearbox.components_geometry["sun"]
    return RunResult({"variant": variant.name, "status": "ok", "sha256": entry.sha256,
                      "loaded_sha256": __import__("hashlib").sha256(entry.source.read_bytes()).hexdigest()})


def test_part_files_travel_with_the_task_and_land_in_the_run_folders_inputs(gearbox, tmp_path, monkeypatch):
    """A variant (in ``variants/``) of a gearbox (one folder up) whose sun comes from ``parts/sun.vtu``: its task
    carries the part, so it runs after the caller's folder is gone, as on a Dask worker that sees none of the
    caller's files: the worker loads the very same part (its SHA-256) from the task's own copy, laid out as the
    files lie relative to each other. The run folder's ``inputs/`` holds the part beside the two files."""
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.mesh_io import write_vtu
    from flexgear.spec import load_variant
    from flexgear.study import pool
    from flexgear.study.pool import make_task, run_task, save_task_result

    home = tmp_path / "study"
    (home / "parts").mkdir(parents=True)
    (home / "variants").mkdir()
    mesh = component_mesh(gearbox, "sun", "coarse")
    write_vtu(home / "parts" / "sun.vtu", mesh.nodes, mesh.elements)
    (home / "gearbox.toml").write_text(Path(GEARBOX).read_text() + '\n[components_geometry]\nsun = { file = '
                                       '"parts/sun.vtu", length_unit = "m" }\n')
    path = _variant(home / "variants", "rigid")
    path.write_text(path.read_text().replace('gearbox = "gearbox.toml"', 'gearbox = "../gearbox.toml"'))
    task = make_task(load_variant(path), 0.01)
    expected = load_variant(path).gearbox.components_geometry["sun"].sha256
    assert make_task(load_variant(path), 0.01).parts[0][1] is task.parts[0][1]  # read once for every variant
    changed = dataclasses.replace(load_variant(path), name="changed")
    (home / "parts" / "sun.vtu").write_bytes((home / "parts" / "sun.vtu").read_bytes() + b" ")
    assert make_task(changed, 0.01).parts == task.parts  # the content its cache keys name, read before
    with monkeypatch.context() as m:  # not read before in this process: the changed file is refused
        m.setattr(pool, "_PARTS", {})
        with pytest.raises(ValueError, match="sun.vtu: the part file changed since its gearbox file was loaded"):
            make_task(changed, 0.01)
    (home / "parts" / "sun.vtu").write_bytes((home / "parts" / "sun.vtu").read_bytes()[:-1])
    shutil.move(home, tmp_path / "elsewhere")
    result = run_task(task, _part_runner)
    assert result.ok, result.meta.get("reason")
    assert result.meta["sha256"] == result.meta["loaded_sha256"] == expected
    save_task_result(task, result, tmp_path / "out" / "rigid")
    inputs = tmp_path / "out" / "rigid" / "inputs"
    assert sorted(p.relative_to(inputs).as_posix() for p in inputs.rglob("*") if p.is_file()) == [
        "gearbox.toml", "parts/sun.vtu", "rigid.toml"]
    assert (inputs / "parts" / "sun.vtu").read_bytes() == (tmp_path / "elsewhere" / "parts" / "sun.vtu").read_bytes()
    # without the part in the task the worker would look for the caller's file, which is gone
    bare = run_task(dataclasses.replace(task, parts=()), _part_runner)
    assert not bare.ok and "sun.vtu" in bare.meta["reason"]


def _body(n_modes: int) -> int:
    if n_modes < 0:
        raise RuntimeError("no mesh")
    return n_modes


def test_cold_bodies_are_reported_as_they_are_built(capsys):
    """A newcomer's first matrix builds its bodies before any run ends: each body's line says when it is built (or
    why not)."""
    from concurrent.futures import ThreadPoolExecutor

    from flexgear.progress import Progress
    from flexgear.study.pool import _run_pool

    first = [(("build", "ring+output_shaft", "coarse", 0), _body, (63,)),
             (("build", "sun", "coarse", 1), _body, (-1,))]
    with ThreadPoolExecutor(1) as pool:
        _, _, done = _run_pool([], pool.submit, None, True, Progress(0, "matrix", enabled=False), first=first)
    assert done[first[0][0]] == 63 and isinstance(done[first[1][0]], RuntimeError)
    err = capsys.readouterr().err
    assert "ring+output_shaft (coarse) body built (" in err
    assert "sun (coarse) body not built (RuntimeError: no mesh) (" in err
