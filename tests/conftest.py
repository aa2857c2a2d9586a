"""Shared fixtures: the study's gearbox and variant files; how ``make test`` shares the tests out.

``make test`` runs the suite in two pytest-xdist worker processes (``-n 2 --dist loadgroup``). With
``--dist loadgroup`` the tests that use a module-scoped fixture of their module (a simulation run, an FE model)
go to one worker, so that the fixture is built once, and every other test is shared out on its own
(:func:`pytest_xdist_make_scheduler`); the units holding ``slow`` tests are handed out first, so that the long runs
do not start last and leave one worker running alone at the end. The mesh cache (``meshes/`` or
``$FLEXGEAR_CACHE_DIR``) is shared by the workers: a missing mesh or reduced body is built by the first worker that
needs it while the other waits for it (flexgear.cache.load_or_build). With ``--prebuild`` (``make test``) each
worker first builds its share of the cache entries the suite uses (:data:`PREBUILD_CHAINS`), so that a cold
cache is built by both workers at once instead of by one while the other waits. The FE models of
:func:`coarse_fe` are built once per worker process, and the tests that use them are one unit of work: with
``--prebuild`` it goes to the worker that builds the tied ring and output shaft, whose FE models that build
shares (:func:`_coarse_fe_model`), so that the run builds each of them once. Each worker's BLAS and OpenMP
thread pools get its share of the cores, and its allocator keeps freed memory (:func:`pytest_configure`).
"""

import ast
import dataclasses
import os
from pathlib import Path

import pytest

from flexgear.spec import load_gearbox, load_variant

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = ROOT / "model_variants"


def _fixture_of(node: ast.FunctionDef) -> tuple[str, bool] | None:
    """(scope, autouse) of a function decorated with ``pytest.fixture``, else None."""
    for dec in node.decorator_list:
        call = dec if isinstance(dec, ast.Call) else None
        if ast.unparse(call.func if call else dec).split(".")[-1] != "fixture":
            continue
        kw = {k.arg: k.value.value for k in (call.keywords if call else []) if isinstance(k.value, ast.Constant)}
        return str(kw.get("scope", "function")), bool(kw.get("autouse", False))
    return None


def _module_fixture_users(folder: Path) -> dict[str, set[str]]:
    """Per test module (its path as in node ids): the names of its test functions that use one of its
    module-scoped fixtures or one of this file's, directly or through another fixture of the module ({"*"}: all of
    them, the fixture being autouse)."""
    common = {n.name for n in ast.walk(ast.parse(Path(__file__).read_text()))
              if isinstance(n, ast.FunctionDef) and (_fixture_of(n) or ("", False))[0] == "module"}
    out: dict[str, set[str]] = {}
    for path in sorted(folder.rglob("test_*.py")):
        fixtures: dict[str, tuple[tuple[str, bool], set[str]]] = {}
        tests: dict[str, set[str]] = {}
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                args = {a.arg for a in node.args.args + node.args.kwonlyargs}
                kind = _fixture_of(node)
                if kind is not None:
                    fixtures[node.name] = (kind, args)
                elif node.name.startswith("test"):
                    tests[node.name] = args
        shared = {name for name, ((scope, _), _) in fixtures.items() if scope == "module"} | (common - set(fixtures))
        grown = True
        while grown:  # fixtures of the module that request a shared one
            extra = {name for name, (_, args) in fixtures.items() if args & shared} - shared
            shared |= extra
            grown = bool(extra)
        autouse = any(fixtures[n][0][1] for n in shared if n in fixtures)
        users = {"*"} if autouse else {t for t, args in tests.items() if args & shared}
        if users:
            out[path.relative_to(ROOT).as_posix()] = users
    return out


def _fixture_user_modules(folder: Path, fixture: str) -> set[str]:
    """The test modules (paths as in node ids) that request ``fixture`` in a test or fixture function."""
    def requests(node: ast.AST) -> bool:
        return isinstance(node, ast.FunctionDef) and fixture in {a.arg for a in node.args.args + node.args.kwonlyargs}

    return {path.relative_to(ROOT).as_posix() for path in sorted(folder.rglob("test_*.py"))
            if any(map(requests, ast.walk(ast.parse(path.read_text()))))}


def _slow_tests(folder: Path) -> dict[str, set[str]]:
    """Per test module (its path as in node ids): the names of its test functions marked ``slow``: by their own
    decorators (a mark on the function or on one of its parameters), by a fixture of the module they request whose
    decorator carries it (a slow fixture parameter), or by the module's ``pytestmark``."""
    out: dict[str, set[str]] = {}
    for path in sorted(folder.rglob("test_*.py")):
        tree = ast.parse(path.read_text())
        module_slow = any(isinstance(n, ast.Assign) and any(ast.unparse(t) == "pytestmark" for t in n.targets)
                          and "mark.slow" in ast.unparse(n.value) for n in tree.body)
        slow_fixtures: set[str] = set()
        tests: dict[str, tuple[bool, set[str]]] = {}
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef):
                marked = any("mark.slow" in ast.unparse(d) for d in node.decorator_list)
                if _fixture_of(node) is not None:
                    if marked:
                        slow_fixtures.add(node.name)
                elif node.name.startswith("test"):
                    tests[node.name] = marked, {a.arg for a in node.args.args + node.args.kwonlyargs}
        slow = {t for t, (marked, args) in tests.items() if module_slow or marked or args & slow_fixtures}
        if slow:
            out[path.relative_to(ROOT).as_posix()] = slow
    return out


@pytest.hookimpl(optionalhook=True)  # a pytest-xdist hook: without xdist installed, never called
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadgroup``: the tests of a module that use one of its module-scoped fixtures are one unit of work,
    every other test is a unit of its own; units with more tests are handed out first. (Replaces xdist's own
    loadgroup, which groups by ``xdist_group`` marks written into the node ids: pytest 9.2's node ids do not take
    them.)"""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    users = _module_fixture_users(Path(__file__).resolve().parent)
    slow = _slow_tests(Path(__file__).resolve().parent)
    fe_modules = _fixture_user_modules(Path(__file__).resolve().parent, "coarse_fe")
    fe_unit = "coarse_fe"
    tied_chain = next(i for i, chain in enumerate(PREBUILD_CHAINS) if "tied" in chain)

    def module_and_test(nodeid: str) -> tuple[str, str]:
        module, _, rest = nodeid.partition("::")
        return module, rest.split("::")[-1].split("[")[0]

    class ModuleFixtureScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            """A module's tests that share its module-scoped fixtures are one unit; those of the modules that use
            :func:`coarse_fe` are all one unit, so that its FE models are built in one worker process."""
            module, test = module_and_test(nodeid)
            grouped = users.get(module, set())
            if "*" in grouped or test in grouped:
                return fe_unit if module in fe_modules else module
            return nodeid

        def _may_take(self, node, scope: str) -> bool:
            """With ``--prebuild``, the :func:`coarse_fe` unit goes to the worker that builds the tied pair."""
            if scope != fe_unit or not config.getoption("prebuild"):
                return True
            return node.gateway.id == f"gw{tied_chain % max(self.numnodes, 1)}"

        def _assign_work_unit(self, node) -> None:
            """The pending unit with the most slow tests next (then the one with the most tests, then the first),
            of those this worker may take (any, when it may take none of them)."""
            def priority(scope: str) -> tuple[int, int]:
                unit = self.workqueue[scope]
                return sum(test in slow.get(module, ()) for module, test in map(module_and_test, unit)), len(unit)

            allowed = [scope for scope in self.workqueue if self._may_take(node, scope)] or list(self.workqueue)
            self.workqueue.move_to_end(max(allowed, key=priority), last=False)
            super()._assign_work_unit(node)

    return ModuleFixtureScheduling(config, log)


PREBUILD_CHAINS = (
    ("mesh:ring", "mesh:output_shaft", "tied"),
    ("mesh:planet", "mesh:sun", "mesh:input_shaft", "input_shaft", "sun", "planet", "ring", "output_shaft"),
)
"""The coarse meshes and reduced bodies of gearbox.toml that the suite uses, in chains: chain k is built by xdist
worker k (of n: chains k, k + n, ...) before its first test. The tied ring and output shaft, the costliest body by
far, has a chain of its own, which starts with the two meshes it needs; the other chain holds every other entry
(it reaches the ring and the output shaft after their meshes are built), and its worker starts testing while the
tied body is still being built.
"name": the component's reduced body, "tied": the tied ring and output shaft, "mesh:name": the component's
mesh at the level's element order."""


_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
"""The environment variables that size the BLAS and OpenMP thread pools of a worker process."""
WORKER_MALLOC = {"MALLOC_MMAP_THRESHOLD_": str(256 * 2**20), "MALLOC_TRIM_THRESHOLD_": str(512 * 2**20)}
"""glibc's allocator in a worker process: arrays up to 256 MiB come from the heap, which keeps up to 512 MiB of
freed memory for the next ones. (By default an array beyond the adaptive threshold, 128 KiB to 32 MiB, is mapped
afresh and unmapped when freed, and every page of a fresh mapping is faulted in and zeroed by the kernel: the
eigen solvers' and time runs' vectors, allocated over and over, made that a large part of the suite's kernel time.)
The CLI's build workers choose the other way, memory before time (flexgear.heap.lean_heap)."""


def pytest_configure(config):
    """Under pytest-xdist, each worker's BLAS and OpenMP pools get the worker's share of the cores (at least one):
    with one worker per core, pools of one thread per core in every worker only contend for the cores; and the
    workers' allocator keeps freed memory (:data:`WORKER_MALLOC`). Set in the controller before it starts the
    workers, which inherit its environment; a variable already set is kept."""
    import os

    workers = getattr(config.option, "numprocesses", None)
    if not isinstance(workers, int) or workers < 1 or hasattr(config, "workerinput"):
        return
    share = str(max(1, (os.cpu_count() or 1) // workers))
    for name, value in {**dict.fromkeys(_THREAD_VARIABLES, share), **WORKER_MALLOC}.items():
        os.environ.setdefault(name, value)


def pytest_addoption(parser):
    parser.addoption("--prebuild", action="store_true", help="under pytest-xdist, each worker builds its share of "
                     "the mesh cache the suite uses before its first test (tests/conftest.py PREBUILD_CHAINS)")


def _prebuild(spec, task: str) -> None:
    """Build (or find cached) one entry of :data:`PREBUILD_CHAINS`; a cached body is not loaded."""
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.reduced import cached_component_frequencies, component_reduced_body
    from flexgear.fe.ring_shaft import tied_pair_mass_properties

    if task == "tied":  # the tied build's FE models are coarse_fe's
        tied_pair_mass_properties(spec, "coarse", fe_source=_coarse_fe_model)
    elif task.startswith("mesh:"):
        component_mesh(spec, task.removeprefix("mesh:"), "coarse")
    elif cached_component_frequencies(spec, task, "coarse") is None:
        component_reduced_body(spec, task, "coarse")


@pytest.fixture(scope="session", autouse=True)
def prebuilt_cache(request):
    """``--prebuild`` on an xdist worker: its share of :data:`PREBUILD_CHAINS`, before its first test."""
    worker = getattr(request.config, "workerinput", None)
    if not request.config.getoption("prebuild") or worker is None:
        return
    index, count = int(worker["workerid"].removeprefix("gw")), int(worker["workercount"])
    spec = load_gearbox(VARIANTS / "gearbox.toml")
    for chain in PREBUILD_CHAINS[index::count]:
        for task in chain:
            _prebuild(spec, task)


@pytest.fixture(scope="session")
def gearbox():
    return load_gearbox(VARIANTS / "gearbox.toml")


@pytest.fixture(scope="session")
def model1():
    """Table 3's model 1 with the exact geometry's mass properties: no meshes needed for rigid tests."""
    return dataclasses.replace(load_variant(VARIANTS / "model1.toml"), rigid_mass_properties="exact")


_COARSE_FE: dict[str, object] = {}
"""The FE models of :func:`coarse_fe`, by component, of this process."""


def _coarse_fe_model(name: str):
    """The FE model of component ``name`` of gearbox.toml at the coarse level (flexgear.fe.ring_shaft.part_fe_model),
    built once per process."""
    if name not in _COARSE_FE:
        from flexgear.fe.ring_shaft import part_fe_model

        _COARSE_FE[name] = part_fe_model(load_gearbox(VARIANTS / "gearbox.toml"), name, "coarse")
    return _COARSE_FE[name]


@pytest.fixture(scope="session")
def coarse_fe():
    """``coarse_fe(name)``: the FE model of component ``name`` at the coarse level as every reduced body is built on
    it (flexgear.fe.ring_shaft.part_fe_model), built once per worker process for the test modules that compare
    against full FE (and shared with the tied pair's build of ``--prebuild``); the functions those tests and that
    build call leave a model unchanged."""
    return _coarse_fe_model


@pytest.fixture(scope="module")
def example_cache(tmp_path_factory):
    """The cache folder (``FLEXGEAR_CACHE_DIR``) of the example studies' test modules, one for the whole run and
    shared by its workers (a body another module or worker is building is waited for, flexgear.cache.load_or_build):
    the modules share the examples' bodies, and the project's cache stays untouched."""
    base = tmp_path_factory.getbasetemp()
    path = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "examples_cache"
    path.mkdir(exist_ok=True)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("FLEXGEAR_CACHE_DIR", str(path))
        yield path
