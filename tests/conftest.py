"""Shared fixtures: the study's gearbox and variant files; how ``make test`` shares the tests out.

``make test`` runs the suite in two pytest-xdist worker processes (``-n 2 --dist loadgroup``). With
``--dist loadgroup`` the tests of a module that defines a module-scoped fixture (a simulation run, an FE model)
go to one worker, so that the fixture is built once, and every other test is shared out on its own
(:func:`pytest_xdist_make_scheduler`). The mesh cache (``meshes/`` or ``$FLEXGEAR_CACHE_DIR``) is shared by the
workers: a missing mesh or reduced body is built by the first worker that needs it while the other waits for it
(flexgear.cache.load_or_build).
"""

import ast
import dataclasses
from pathlib import Path

import pytest

from flexgear.spec import load_gearbox, load_variant

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = ROOT / "model_variants"


def _module_fixture_files(folder: Path) -> set[str]:
    """Paths (relative to the project, as in node ids) of the test modules that define a module-scoped fixture."""
    out = set()
    for path in folder.rglob("test_*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and any(
                    k.arg == "scope" and isinstance(k.value, ast.Constant) and k.value.value == "module"
                    for k in node.keywords) and ast.unparse(node.func).endswith("fixture"):
                out.add(path.relative_to(ROOT).as_posix())
                break
    return out


def pytest_xdist_make_scheduler(config, log):
    """``--dist loadgroup``: a module that defines a module-scoped fixture is one unit of work, every other test
    is a unit of its own; units with more tests are handed out first. (Replaces xdist's own loadgroup, which
    groups by ``xdist_group`` marks written into the node ids: pytest 9.2's node ids do not take them.)"""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    grouped = _module_fixture_files(Path(__file__).resolve().parent)

    class ModuleFixtureScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            module = nodeid.split("::", 1)[0]
            return module if module in grouped else nodeid

    return ModuleFixtureScheduling(config, log)


@pytest.fixture(scope="session")
def gearbox():
    return load_gearbox(VARIANTS / "gearbox.toml")


@pytest.fixture(scope="session")
def model1():
    """Table 3's model 1 with the exact geometry's mass properties: no meshes needed for rigid tests."""
    return dataclasses.replace(load_variant(VARIANTS / "model1.toml"), rigid_mass_properties="exact")
