"""Damaged cache entries are rebuilt with a warning naming the file, and a missing entry is built once among
processes (flexgear.cache.load_or_build, used by flexgear.fe.mesh and flexgear.fe.reduced).

The component is the input shaft at the coarse level (the smallest, a few seconds to mesh and reduce), in a
cache folder of its own (``FLEXGEAR_CACHE_DIR``). A rebuilt entry must give the body the intact entry gave:
the same mesh and the same free-free frequencies, to round-off.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from flexgear.cache import CacheWarning, build_lock, load_or_build
from flexgear.fe.mesh import component_brep, component_mesh
from flexgear.fe.reduced import component_mass_properties, component_reduced_body

COMPONENT, LEVEL = "input_shaft", "coarse"
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def cached(tmp_path_factory, gearbox):
    """A cache folder holding the component's solid, meshes and reduced body, and the intact body."""
    folder = tmp_path_factory.mktemp("cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("FLEXGEAR_CACHE_DIR", str(folder))
        with warnings.catch_warnings():
            warnings.simplefilter("error", CacheWarning)  # a fresh folder: nothing to warn about
            body = component_reduced_body(gearbox, COMPONENT, LEVEL)
        yield folder, body


def _entry(folder: Path, pattern: str) -> Path:
    (path,) = folder.glob(pattern)
    return path


def _truncate(path: Path) -> None:
    with open(path, "r+b") as fh:
        fh.truncate(path.stat().st_size // 2)


def _same_body(got, expected) -> None:
    np.testing.assert_allclose(got.frequencies_hz, expected.frequencies_hz, rtol=1e-9, atol=0)
    assert got.n_modes == expected.n_modes
    # a body reduced from a mesh loaded from its .vol.gz (coordinates kept to about 1e-10 m) or from the one
    # just meshed in memory: the same nodes to the file's precision
    np.testing.assert_allclose(got.nodes, expected.nodes, rtol=0, atol=1e-9)


def _rebuilt(gearbox, damaged: Path):
    """The component's reduced body, asked for with ``damaged`` in the cache: exactly one warning, naming it."""
    with pytest.warns(CacheWarning) as record:
        body = component_reduced_body(gearbox, COMPONENT, LEVEL)
    messages = [str(w.message) for w in record if issubclass(w.category, CacheWarning)]
    assert len(messages) == 1 and str(damaged) in messages[0] and messages[0].endswith(": rebuilding it")
    assert "\n" not in messages[0]
    return body


def _reduced_path(folder: Path) -> Path:
    return _entry(folder, "reduced-*.npz")


def test_truncated_reduced_body_is_rebuilt_with_a_warning(cached, gearbox, monkeypatch):
    folder, intact = cached
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(folder))
    path = _reduced_path(folder)
    _truncate(path)
    _same_body(_rebuilt(gearbox, path), intact)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CacheWarning)  # the rebuilt file loads as it is
        _same_body(component_reduced_body(gearbox, COMPONENT, LEVEL), intact)


def test_overwritten_reduced_body_is_rebuilt_when_its_mass_is_asked_for(cached, gearbox, monkeypatch):
    folder, intact = cached
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(folder))
    path = _reduced_path(folder)
    path.write_bytes(b"\0" * 4096)
    with pytest.warns(CacheWarning, match=path.name):
        props = component_mass_properties(gearbox, COMPONENT, LEVEL)
    assert props.mass == pytest.approx(intact.props.mass, rel=1e-9)
    _same_body(component_reduced_body(gearbox, COMPONENT, LEVEL), intact)


@pytest.mark.parametrize("pattern", ["mesh-*-o1-*.npz", "mesh-*-o1-*.vol.gz", "mesh-*-o1-*.json", "solid-*.brep"])
def test_truncated_mesh_file_under_a_missing_reduced_body_is_rebuilt(cached, gearbox, monkeypatch, pattern):
    """The reduction reads the first-order mesh and the solid (Netgen would crash on the truncated ``.vol.gz``
    and OCC hang on the truncated ``.brep``: both are checked before they are read)."""
    folder, intact = cached
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(folder))
    reduced = _reduced_path(folder)
    reduced.unlink()
    damaged = _entry(folder, pattern)
    _truncate(damaged)
    _same_body(_rebuilt(gearbox, damaged), intact)
    assert reduced.exists()


def test_damaged_second_order_mesh_is_rebuilt_equal(cached, gearbox, monkeypatch):
    folder, _ = cached
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(folder))
    intact = component_mesh(gearbox, COMPONENT, LEVEL)
    assert intact.order == 2
    damaged = _entry(folder, "mesh-*-o2-*.npz")
    damaged.write_bytes(damaged.read_bytes()[:100] + b"x" * 100)
    with pytest.warns(CacheWarning, match=damaged.name):
        mesh = component_mesh(gearbox, COMPONENT, LEVEL)
    np.testing.assert_allclose(mesh.nodes, intact.nodes, rtol=0, atol=1e-12)
    assert np.array_equal(mesh.elements, intact.elements) and mesh.regions.keys() == intact.regions.keys()


def test_solid_without_its_digest_is_rebuilt(cached, gearbox, monkeypatch):
    folder, _ = cached
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(folder))
    brep = component_brep(gearbox, COMPONENT)
    Path(f"{brep}.sha256").unlink()
    with pytest.warns(CacheWarning, match="digest file"):
        assert component_brep(gearbox, COMPONENT) == brep
    assert Path(f"{brep}.sha256").exists()


# --- build once among processes ------------------------------------------------------------------------------

_WAIT_FOR = """
def wait_for(path, timeout=120.0):  # the other process has started and is about to ask for the entry
    t0 = time.monotonic()
    while not path.exists() and time.monotonic() - t0 < timeout:
        time.sleep(0.02)
    time.sleep(0.5)  # time to reach the lock
"""

_SLOW_BUILDER = """
import sys, time
from pathlib import Path
from flexgear.cache import load_or_build, atomic_write_bytes
""" + _WAIT_FOR + """
path, log, role, ready = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3], Path(sys.argv[4])
def load():
    return path.read_bytes() if path.exists() else None
def build():
    with open(log, "a") as fh:
        fh.write("build\\n")
    if role == "first":
        wait_for(ready)
    atomic_write_bytes(path, b"built by " + role.encode())
    return path.read_bytes()
if role == "second":
    print("missing" if not path.exists() else "present")
    ready.touch()
print(load_or_build(path, load, build).decode())
"""


def _python(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})


def _wait_for(path: Path, timeout: float = 120.0) -> None:
    t0 = time.monotonic()
    while not path.exists():
        assert time.monotonic() - t0 < timeout, f"{path} never appeared"
        time.sleep(0.02)


def test_an_empty_cache_variable_means_the_projects_cache(monkeypatch, tmp_path):
    """``FLEXGEAR_CACHE_DIR=`` (set, empty) is the default folder, not the working directory."""
    from flexgear.cache import cache_dir

    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FLEXGEAR_CACHE_DIR", raising=False)
    default = cache_dir()
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", "")
    assert cache_dir() == default == ROOT / "meshes"
    assert not any(tmp_path.iterdir())


def test_two_processes_build_a_missing_entry_once(tmp_path):
    """The second process asks while the first is building (the first writes its file only after the second has
    found it missing): the second waits for the lock and reads the first's file."""
    entry, log, ready = tmp_path / "entry.bin", tmp_path / "builds.log", tmp_path / "second-ready"
    first = _python("-c", _SLOW_BUILDER, str(entry), str(log), "first", str(ready))
    _wait_for(log)  # the first holds the lock and is building
    second = _python("-c", _SLOW_BUILDER, str(entry), str(log), "second", str(ready))
    outs = [p.communicate(timeout=300) for p in (first, second)]
    assert [p.returncode for p in (first, second)] == [0, 0], outs
    assert log.read_text().splitlines() == ["build"]
    assert outs[0][0].split() == ["built", "by", "first"]
    assert outs[1][0].split() == ["missing", "built", "by", "first"]


def test_lock_waits_in_threads_and_is_reentrant(tmp_path):
    import threading

    entry, order = tmp_path / "entry", []

    def hold():
        with build_lock(entry), build_lock(entry):  # a nested request does not wait for itself
            order.append("held")
            time.sleep(0.5)
            order.append("released")

    worker = threading.Thread(target=hold)
    worker.start()
    while not order:
        time.sleep(0.01)
    with build_lock(entry):
        order.append("second")
    worker.join()
    assert order == ["held", "released", "second"]


def test_load_or_build_names_the_entry_when_load_fails_without_naming_a_file(tmp_path):
    entry = tmp_path / "entry"
    entry.write_text("x")

    def load():
        raise RuntimeError("no good")

    with pytest.warns(CacheWarning, match=f"cache file {entry} cannot be read \\(RuntimeError: no good\\)"):
        assert load_or_build(entry, load, lambda: 3) == 3


_MESHER = """
import sys, time
from pathlib import Path
import flexgear.fe.mesh as fm
from flexgear.spec import load_gearbox
""" + _WAIT_FOR + """
started, ready = Path(sys.argv[1]), Path(sys.argv[2])
build = fm._build_mesh
def slow_build(*args, **kwargs):  # announce the build and hold the lock until the other process asks
    started.touch()
    wait_for(ready)
    return build(*args, **kwargs)
fm._build_mesh = slow_build
spec = load_gearbox("model_variants/gearbox.toml")
if sys.argv[3] == "second":
    ready.touch()
mesh = fm.component_mesh(spec, "input_shaft", "coarse", order=1, progress=True)
print(mesh.n_nodes, mesh.nodes.sum())
"""


def test_two_processes_mesh_a_missing_component_once(tmp_path, monkeypatch):
    """Two processes need the same missing mesh: Netgen runs once, both get its nodes (progress lines counted)."""
    started, ready = tmp_path / "started", tmp_path / "second-ready"
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(tmp_path / "cache"))
    first = _python("-c", _MESHER, str(started), str(ready), "first")
    _wait_for(started)
    second = _python("-c", _MESHER, str(tmp_path / "second-started"), str(ready), "second")
    outs = [p.communicate(timeout=300) for p in (first, second)]
    assert [p.returncode for p in (first, second)] == [0, 0], outs
    log = "".join(err for _, err in outs)
    assert log.count("meshed in") == 1 and log.count("solid built") == 1, log
    assert not (tmp_path / "second-started").exists()
    assert outs[0][0] == outs[1][0]
