"""The package layout: the one-way data flow is declared in pyproject.toml and kept; modules stay small."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_import_layers_contract_is_kept(monkeypatch):
    """spec -> cache -> results -> geometry -> theory -> design -> fe -> laws -> mbs | lumped -> study -> report
    -> cli."""
    cli = pytest.importorskip("importlinter.cli")
    monkeypatch.chdir(ROOT)
    assert cli.lint_imports(config_filename=str(ROOT / "pyproject.toml"), no_cache=True, no_logo=True) == 0


PENDING_SPLIT: set[str] = set()  # spec.py is split: the tables are in schema.py


def test_no_module_over_450_lines():
    sizes = {p.relative_to(ROOT).as_posix(): len(p.read_text().splitlines()) for p in (ROOT / "flexgear").rglob("*.py")}
    assert not {k: v for k, v in sizes.items() if v > 460 and k not in PENDING_SPLIT}, sizes


def test_one_step_law_and_its_compiled_twin_agree():
    """laws.ramps (numpy) and laws.compiled.ramp_state (numba) give the same STEP, its integral and slope."""
    import numpy as np

    from flexgear.laws.compiled import ramp_state
    from flexgear.laws.ramps import drive_angle, ramp_fraction, step_integral

    T = 0.02
    for t in np.linspace(-0.001, 0.03, 31):
        integral, value, rate, _ = ramp_state(float(t), T)
        assert integral == pytest.approx(float(step_integral(max(t, 0.0), T, 1.0)), abs=1e-15)
        assert value == pytest.approx(float(ramp_fraction(t, T)), abs=1e-15)
        assert drive_angle(max(t, 0.0), T, 3.0) == pytest.approx(3.0 * integral, abs=1e-14)
        eps = 1e-7  # slope against a central difference of STEP
        if eps < t < T - eps:
            fd = (float(ramp_fraction(t + eps, T)) - float(ramp_fraction(t - eps, T))) / (2 * eps)
            assert rate == pytest.approx(fd, rel=1e-5)


PRIVATE_NAME_EXEMPTIONS: set[tuple[str, str]] = set()
"""(using module, module.name) pairs allowed to use another module's underscore name. Empty: every shared name is
public (with a docstring, in its module's ``__all__``) or lives with the stage that owns it."""


def _module_name(path: Path, root: Path = ROOT) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _private_uses(path: Path, modules: set[str], root: Path = ROOT) -> list[tuple[int, str]]:
    """(line, module.name) of every underscore name of another flexgear module that ``path`` imports
    (``from x import _y``, relative imports included) or reads as an attribute (``import x; x._y``)."""
    import ast

    name = _module_name(path, root)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    tree = ast.parse(path.read_text())
    aliases: dict[str, str] = {}  # local name -> the flexgear module it is bound to
    uses = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            source = ".".join(base + ([node.module] if node.module else []))
            for alias in node.names:
                if f"{source}.{alias.name}" in modules:  # a submodule, read as module.name below
                    aliases[alias.asname or alias.name] = f"{source}.{alias.name}"
                if alias.name.startswith("_") and source.startswith("flexgear") and source != name:
                    uses.append((node.lineno, f"{source}.{alias.name}"))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in modules:
                    aliases[alias.asname or alias.name.split(".")[0]] = alias.name if alias.asname else "flexgear"
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")):
            continue
        chain, value = [], node.value
        while isinstance(value, ast.Attribute):
            chain.append(value.attr)
            value = value.value
        if isinstance(value, ast.Name) and value.id in aliases:
            target = ".".join([aliases[value.id], *reversed(chain)])
            if target in modules and target != name:
                uses.append((node.lineno, f"{target}.{node.attr}"))
    return uses


def test_no_module_uses_another_modules_private_names():
    """A name shared between modules is public: no module of flexgear imports, or reads as ``module._name``, an
    underscore name of another module (tests may; :data:`PRIVATE_NAME_EXEMPTIONS` lists deliberate exceptions)."""
    paths = sorted((ROOT / "flexgear").rglob("*.py"))
    modules = {_module_name(p) for p in paths}
    found = [f"{_module_name(p)}:{line}: {target}" for p in paths for line, target in _private_uses(p, modules)
             if (_module_name(p), target) not in PRIVATE_NAME_EXEMPTIONS]
    assert not found, "\n".join(found)


def test_private_name_scan_sees_every_form(tmp_path):
    """The scan above finds ``from x import _y`` (in a multi-line list too, and relative), ``import x as m; m._y``,
    ``from pkg import x; x._y`` and ``import pkg.x; pkg.x._y``, and leaves a module's own names and dunders alone."""
    pkg = tmp_path / "flexgear"
    (pkg / "sub").mkdir(parents=True)
    for init in (pkg / "__init__.py", pkg / "sub" / "__init__.py"):
        init.write_text("")
    (pkg / "sub" / "a.py").write_text("_x = 1\ny = _x\n")
    (pkg / "b.py").write_text("from flexgear.sub.a import (\n    y,\n    _x,\n)\nfrom .sub.a import _x as z\n"
                              "import flexgear.sub.a as m\nfrom flexgear.sub import a\nimport flexgear.sub.a\n"
                              "m._x, a._x, flexgear.sub.a._x, a.__name__\n")
    modules = {_module_name(p, tmp_path) for p in pkg.rglob("*.py")}
    assert _private_uses(pkg / "sub" / "a.py", modules, tmp_path) == []
    lines = [line for line, target in sorted(_private_uses(pkg / "b.py", modules, tmp_path))
             if target == "flexgear.sub.a._x"]
    assert lines == [1, 5, 9, 9, 9]


def test_benchmarks_and_examples_import_names_that_exist():
    """Every ``from flexgear... import name`` of a script under benchmarks/ or examples/ (at any depth of the
    script, imports inside functions too) names something the module has: a renamed name breaks no script
    silently (those scripts run outside the test suite)."""
    import ast
    import importlib

    missing = []
    for path in sorted([*(ROOT / "benchmarks").rglob("*.py"), *(ROOT / "examples").rglob("*.py")]):
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.ImportFrom) and node.level == 0 and node.module
                    and node.module.split(".")[0] == "flexgear"):
                continue
            module = importlib.import_module(node.module)
            for alias in node.names:
                if not hasattr(module, alias.name):
                    try:
                        importlib.import_module(f"{node.module}.{alias.name}")
                    except ImportError:
                        missing.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.module}.{alias.name}")
    assert not missing, "\n".join(missing)
