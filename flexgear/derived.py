"""Defaults that follow the gear data: the registry of their providers and how a gearbox file's tables get them.

A provider (:func:`register_derived_defaults`; :mod:`flexgear.sizing` is the package's) gives, per table, the
values of the fields marked ``derived`` in the schema that the file leaves out, from the tables already built
(:data:`FIRST_TABLES` first) and the values the file gives in that table. :func:`with_derived` fills a table while
it is loaded (flexgear.spec.load_gearbox); :func:`rederive` fills them again when a variant's overrides change
the tables they follow.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import Any

from flexgear.schema import GearboxSpec

__all__ = ["REQUIRED_TABLES", "FIRST_TABLES", "register_derived_defaults", "with_derived", "rederive"]

_DERIVED: list[Callable[[str, dict[str, Any], dict[str, Any]], dict[str, Any]]] = []

REQUIRED_TABLES = ("gears", "bearings", "load_case")
"""The tables every gearbox file gives; every other table and field has a documented default, fixed or derived
from the gear data (:mod:`flexgear.sizing`)."""

FIRST_TABLES = ("gears", "gears_assumed", "load_case", "material_assumed", "components_assumed")
"""Tables built first, in this order: the derived defaults of the others follow from them."""


def register_derived_defaults(provider: Callable[[str, dict[str, Any], dict[str, Any]], dict[str, Any]]) -> None:
    """``provider(table, built, given)`` gives the derived defaults of ``table`` ("components_assumed",
    "meshing_assumed.coarse", ...) from the tables already ``built`` (name -> dataclass) and the values the file
    ``given`` in that table (raw, unchecked); see :mod:`flexgear.sizing`."""
    if provider not in _DERIVED:
        _DERIVED.append(provider)


def with_derived(path: Path, table: str, cls: type, data: Any, built: dict[str, Any], derived: list[str]) -> Any:
    """``data`` with every derived field it leaves out filled by the registered providers (recorded in
    ``derived``); fields no provider gives stay missing (then required)."""
    if not isinstance(data, dict):
        return data
    missing = [f.name for f in dataclasses.fields(cls) if f.metadata.get("derived") and f.name not in data]
    if not missing:
        return data
    given: dict[str, Any] = {}
    for provider in _DERIVED:
        given.update(provider(table, built, data))
    filled = {name: given[name] for name in missing if name in given}
    derived.extend(f"{table}.{name}" for name in filled)
    return {**data, **filled}


def rederive(spec: GearboxSpec, kept: set[str]) -> GearboxSpec:
    """``spec`` with its derived values derived again from its (overridden) tables, except those in ``kept``."""
    redo = [d for d in spec.derived if d not in kept]
    if not redo:
        return spec
    built = {name: getattr(spec, name) for name in FIRST_TABLES}
    changes: dict[str, Any] = {}

    def order(table: str) -> tuple[int, str]:
        top = table.partition(".")[0]
        return (FIRST_TABLES.index(top) if top in FIRST_TABLES else len(FIRST_TABLES), table)

    for table in sorted({d.rsplit(".", 1)[0] for d in redo}, key=order):
        top, _, level = table.partition(".")
        current = spec.meshing_assumed[level] if level else changes.get(top, getattr(spec, top))
        names = {d.rsplit(".", 1)[1] for d in redo if d.rsplit(".", 1)[0] == table}
        given = {k: v for k, v in dataclasses.asdict(current).items() if k not in names}
        values: dict[str, Any] = {}
        for provider in _DERIVED:
            values.update(provider(table, built, given))
        new = dataclasses.replace(current, **{n: values[n] for n in names if n in values})
        if level:
            changes["meshing_assumed"] = {**changes.get("meshing_assumed", spec.meshing_assumed), level: new}
        else:
            changes[top] = built[top] = new
    return dataclasses.replace(spec.with_changes(**changes), derived=tuple(d for d in spec.derived if d not in kept))
