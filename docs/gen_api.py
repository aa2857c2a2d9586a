"""Write docs/api.md, the API reference of flexgear, from the docstrings: every name of ``flexgear.__all__`` (the
lazily loaded ones included), grouped by the module it comes from, with its signature and the first paragraph of
its docstring.

    python docs/gen_api.py            # (re)write docs/api.md; make api-docs does the same
    python docs/gen_api.py --check    # exit 1 when docs/api.md differs from what this script writes now

The text depends only on the code: names and modules in sorted order, no absolute paths or memory addresses.
"""

from __future__ import annotations

import argparse
import inspect
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUTPUT = ROOT / "docs" / "api.md"
HEADER = """# flexgear API reference

Generated from the docstrings by `docs/gen_api.py`: do not edit by hand; regenerate with
`python docs/gen_api.py` (or `make api-docs`). The names are those of `flexgear.__all__` (import them as
`import flexgear as fg; fg.NAME`), grouped by the module that defines them. Moved names are listed in
[CHANGELOG.md](../CHANGELOG.md).
"""


class _Text:
    """An annotation or default shown as given (no quotes around string annotations)."""

    def __init__(self, text: str):
        self.text = text

    def __repr__(self) -> str:
        return self.text


def _clean(text: str) -> str:
    """No machine-dependent text: memory addresses dropped, the checkout's path made relative."""
    text = re.sub(r" at 0x[0-9a-fA-F]+", "", text)
    return text.replace(str(ROOT) + "/", "").replace(str(ROOT), ".")


def signature(obj: object) -> str | None:
    """``name(params) -> return`` of a callable, None for anything else or a signature Python cannot give."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return None

    def shown(annotation: object) -> object:
        if annotation is inspect.Parameter.empty:
            return annotation
        return _Text(annotation if isinstance(annotation, str) else inspect.formatannotation(annotation))

    def default(value: object) -> object:
        if value is inspect.Parameter.empty:
            return value
        return _Text(value.__name__ if inspect.ismodule(value) else _clean(repr(value)))  # a module: its name

    params = [p.replace(annotation=shown(p.annotation), default=default(p.default)) for p in sig.parameters.values()]
    returns = inspect.Signature.empty if inspect.isclass(obj) else shown(sig.return_annotation)
    sig = sig.replace(parameters=params, return_annotation=returns)
    return _clean(str(sig))


def first_paragraph(obj: object) -> str:
    """The docstring's first paragraph (its own lines), or a note that there is none."""
    doc = inspect.getdoc(obj)
    if not doc:
        return "(no docstring)"
    return _clean(doc.strip().split("\n\n")[0].strip())


def public_names() -> dict[str, object]:
    """Every public name of flexgear (``__all__`` and the lazily loaded ones) -> its object."""
    import flexgear

    names = sorted(set(flexgear.__all__) | set(getattr(flexgear, "_LAZY", {})))
    return {name: getattr(flexgear, name) for name in names}


def home(obj: object) -> str:
    """The module that defines ``obj``."""
    module = getattr(obj, "__module__", None)
    return module if isinstance(module, str) else "flexgear"


def deprecated_names() -> list[str]:
    """One line per moved name of ``flexgear._DEPRECATED``: old name, new name, removal version."""
    import flexgear

    return [f"- `{old}`: use `{new}` (the old name goes in {removal})"
            for old, (new, removal) in sorted(getattr(flexgear, "_DEPRECATED", {}).items())]


def render() -> str:
    """The whole of docs/api.md."""
    groups: dict[str, list[tuple[str, object]]] = {}
    for name, obj in public_names().items():
        groups.setdefault(home(obj), []).append((name, obj))
    out = [HEADER, "## Contents", ""]
    out += [f"- `{module}`: " + ", ".join(f"`{name}`" for name, _ in groups[module]) for module in sorted(groups)]
    for module in sorted(groups):
        out += ["", f"## `{module}`"]
        for name, obj in groups[module]:
            kind = "class" if inspect.isclass(obj) else "function" if callable(obj) else "value"
            out += ["", f"### `{name}` ({kind})", ""]
            sig = signature(obj) if callable(obj) else None
            if sig is not None:
                out += ["```python", f"{name}{sig}", "```", ""]
            out.append(first_paragraph(obj))
    moved = deprecated_names()
    if moved:
        out += ["", "## Deprecated names", "", "Still answered, with a DeprecationWarning:", "", *moved]
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 when docs/api.md is not current")
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        current = OUTPUT.read_text() if OUTPUT.exists() else ""
        if current != text:
            print(f"{OUTPUT.relative_to(ROOT)} is not current: run python docs/gen_api.py", file=sys.stderr)
            return 1
        return 0
    OUTPUT.write_text(text)
    print(f"wrote {OUTPUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
