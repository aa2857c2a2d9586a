"""Nothing lost: a matrix survives a killed worker, resumes after SIGKILL recomputing only the unfinished
runs, never leaves a half-written file, and writes files readable by others (0644 / 0755)."""

from __future__ import annotations

import os
import shutil
import signal
import stat
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from synthetic import GEARBOX, fake_runner

from flexgear.cache import atomic_write_bytes, remove_stale_temporaries
from flexgear.results import load_result
from flexgear.study.matrix import run_matrix

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
MATRIX_SCRIPT = textwrap.dedent("""
    import sys
    sys.path.insert(0, {tests!r})
    from synthetic import fake_runner
    from flexgear.study.matrix import run_matrix
    run_matrix(sys.argv[2:], sys.argv[1], t_end_s=0.6, workers=2, progress=True, runner=fake_runner)
""")


def _variants(folder: Path, names: list[str]) -> list[Path]:
    shutil.copy(ROOT / GEARBOX, folder / "gearbox.toml")
    comps = "\n".join(f'{c} = "rigid"' for c in ("input_shaft", "sun", "planets", "ring", "output_shaft"))
    paths = []
    for name in names:
        path = folder / f"{name}.toml"
        path.write_text(f'name = "{name}"\ngearbox = "gearbox.toml"\n\n[components]\n{comps}\n')
        paths.append(path)
    return paths


def _start(tmp_path: Path, out: Path, paths: list[Path], slow_s: float) -> subprocess.Popen:
    env = dict(os.environ, FLEXGEAR_TEST_PID_DIR=str(tmp_path), FLEXGEAR_TEST_SLOW_S=str(slow_s))
    script = MATRIX_SCRIPT.format(tests=str(TESTS))
    return subprocess.Popen([sys.executable, "-c", script, str(out), *map(str, paths)], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, process_group=0)


def _wait_for(path: Path, proc: subprocess.Popen, timeout_s: float = 120.0) -> None:
    t0 = time.monotonic()
    while not (path.exists() and path.read_text().strip()):  # written, not only created
        assert proc.poll() is None, proc.stdout.read().decode()
        assert time.monotonic() - t0 < timeout_s, f"{path} never appeared"
        time.sleep(0.1)


def _no_temporaries(folder: Path) -> None:
    assert not [p for p in folder.rglob("*") if p.name.endswith(".tmp")]


def test_a_killed_worker_process_is_rerun_and_the_matrix_completes(tmp_path):
    paths = _variants(tmp_path, ["slow", "fast1", "fast2"])
    out = tmp_path / "out"
    proc = _start(tmp_path, out, paths, slow_s=3.0)
    _wait_for(tmp_path / "slow.pid", proc)
    worker = int((tmp_path / "slow.pid").read_text().split()[0])
    os.kill(worker, signal.SIGKILL)  # the worker process running "slow", mid-run
    log = proc.communicate(timeout=300)[0].decode()
    assert proc.returncode == 0, log
    assert "worker lost" in log
    pids = (tmp_path / "slow.pid").read_text().split()
    assert len(pids) == 2 and pids[0] != pids[1]  # ran again, in a new process
    for name in ("slow", "fast1", "fast2"):
        assert load_result(out / name).ok
    _no_temporaries(out)


def test_sigkill_of_the_matrix_resumes_only_the_unfinished_runs(tmp_path):
    paths = _variants(tmp_path, ["fast1", "fast2", "slow"])
    out = tmp_path / "out"
    proc = _start(tmp_path, out, paths, slow_s=120.0)
    _wait_for(out / "fast1" / "run.json", proc)
    _wait_for(out / "fast2" / "run.json", proc)
    _wait_for(tmp_path / "slow.pid", proc)
    os.killpg(proc.pid, signal.SIGKILL)  # the matrix and its workers, as a kill -9 of the job would
    proc.communicate(timeout=60)
    assert not (out / "slow" / "run.json").exists()
    stamps = {n: (out / n / "run.json").stat().st_mtime_ns for n in ("fast1", "fast2")}
    (out / "fast1" / ".signals.parquet.abc.tmp").write_bytes(b"half")  # what a write killed mid-way leaves
    table = run_matrix(paths, out, t_end_s=0.6, workers=2, progress=False, runner=fake_runner).set_index("variant")
    assert (table["status"] == "ok").all()
    assert table["resumed"].to_dict() == {"fast1": True, "fast2": True, "slow": False}
    assert {n: (out / n / "run.json").stat().st_mtime_ns for n in stamps} == stamps
    _no_temporaries(out)


KILLED_WRITER = textwrap.dedent("""
    import os, sys, time
    from pathlib import Path
    from flexgear.cache import atomic_write_bytes
    os.replace = lambda *a: (Path(sys.argv[2]).touch(), time.sleep(600))  # killed between write and rename
    atomic_write_bytes(Path(sys.argv[1]), b"new" * 100000)
""")


def test_a_writer_killed_mid_write_leaves_the_old_file_whole(tmp_path):
    target = tmp_path / "run.json"
    atomic_write_bytes(target, b"old content")
    flag = tmp_path / "writing"
    proc = subprocess.Popen([sys.executable, "-c", KILLED_WRITER, str(target), str(flag)], cwd=ROOT)
    t0 = time.monotonic()
    while not flag.exists():
        assert proc.poll() is None and time.monotonic() - t0 < 60
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    assert target.read_bytes() == b"old content"
    stale = remove_stale_temporaries(tmp_path)
    assert len(stale) == 1 and stale[0].name.startswith(".run.json.")
    _no_temporaries(tmp_path)


def test_files_and_folders_are_readable_by_others(tmp_path):
    old = os.umask(0o022)
    try:
        paths = _variants(tmp_path, ["fast1"])
        out = tmp_path / "out"
        run_matrix(paths, out, t_end_s=0.6, workers=1, progress=False, runner=fake_runner)
    finally:
        os.umask(old)
    files = [p for p in out.rglob("*") if p.is_file()]
    assert {"run.json", "signals.parquet", "matrix_results.csv", "gearbox.toml"} <= {p.name for p in files}
    for p in files:
        assert stat.S_IMODE(p.stat().st_mode) == 0o644, p
    for p in [out, *[p for p in out.rglob("*") if p.is_dir()]]:
        assert stat.S_IMODE(p.stat().st_mode) == 0o755, p
