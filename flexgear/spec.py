"""Gearbox and variant specifications: TOML files in, validated frozen dataclasses out.

The gearbox is data. ``model_variants/gearbox.toml`` holds the reference study's parameters
(each key cites its table or section) and, in tables whose names end in ``_assumed``, every value
the study does not give. A variant file (``model1.toml`` ... ``model7.toml``) names the gearbox
file and says, per component, ``"rigid"`` or ``"flexible"`` (Table 3).

Field names carry their unit where the file uses one outside SI (``_mm``, ``_deg``, ``_rpm``);
the dataclasses expose SI values through properties so that the rest of the package computes
in SI only. Any error names the file, the field and what is allowed (:class:`SpecError`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any, get_args, get_type_hints

from flexgear.derived import FIRST_TABLES, REQUIRED_TABLES, rederive, register_derived_defaults, with_derived
from flexgear.schema import (
    CARRIER,
    COMPONENT_GEOMETRY,
    COMPONENTS,
    GEAR_COMPONENTS,
    GEOMETRY_COMPONENTS,
    OPTIONAL_COMPONENTS,
    REMOVED_FIELDS,
    SHAFT_COMPONENTS,
    Bearing,
    Bearings,
    ComponentsAssumed,
    Contact,
    ContactAssumed,
    GearboxSpec,
    GearSet,
    GearSetAssumed,
    IndicatorTolerance,
    IndicatorWeights,
    JointsAssumed,
    LoadCase,
    LumpedAssumed,
    Material,
    MeshingSettings,
    ReductionSettings,
    ReferenceIndicators,
    ScreeningSettings,
    SolverSettings,
    SpecError,
    Variant,
    stage_components,
    stage_geometries,
)
from flexgear.schema_geometry import components_geometry_table
from flexgear.schema_published import published_table
from flexgear.schema_screening import PURPOSE_NAMES

__all__ = [
    "SpecError",
    "GearSet",
    "GearSetAssumed",
    "Material",
    "ComponentsAssumed",
    "Bearing",
    "Bearings",
    "Contact",
    "ContactAssumed",
    "JointsAssumed",
    "REMOVED_FIELDS",
    "LoadCase",
    "SolverSettings",
    "MeshingSettings",
    "ReductionSettings",
    "IndicatorWeights",
    "IndicatorTolerance",
    "ReferenceIndicators",
    "ScreeningSettings",
    "LumpedAssumed",
    "GearboxSpec",
    "Variant",
    "COMPONENTS",
    "stage_components",
    "stage_geometries",
    "OPTIONAL_COMPONENTS",
    "CARRIER",
    "GEAR_COMPONENTS",
    "SHAFT_COMPONENTS",
    "GEOMETRY_COMPONENTS",
    "COMPONENT_GEOMETRY",
    "load_gearbox",
    "load_variant",
    "check_carrier",
    "spec_hash",
    "as_dict",
    "register_feasibility_check",
    "register_derived_defaults",
    "REQUIRED_TABLES",
]


# --------------------------------------------------------------------------- loading
_FEASIBILITY: list[Callable[[GearboxSpec], None]] = []


def register_feasibility_check(check: Callable[[GearboxSpec], None]) -> None:
    """Run ``check(spec)`` on every loaded gearbox (it raises SpecError); see :mod:`flexgear.geometry.feasibility`."""
    if check not in _FEASIBILITY:
        _FEASIBILITY.append(check)


def _read_toml(path: Path, text: str | None = None) -> dict[str, Any]:
    """The TOML table of ``path``, or of ``text`` when given (``path`` then only names it in errors)."""
    try:
        if text is not None:
            return tomllib.loads(text)
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise SpecError(path, "<file>", "file does not exist") from None
    except IsADirectoryError:
        raise SpecError(path, "<file>", "is a folder; expected a TOML file") from None
    except (PermissionError, UnicodeDecodeError) as exc:
        raise SpecError(path, "<file>", f"cannot be read ({exc.__class__.__name__})") from None
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(path, "<file>", f"is not valid TOML ({exc})") from None


def _check_value(path: Path, name: str, value: Any, hint: Any, meta: dict) -> Any:
    if meta.get("sequence"):
        if not isinstance(value, (list, tuple)):
            raise SpecError(path, name, "expected a list of numbers", value)
        item = {k: meta[k] for k in ("lo", "hi", "lo_open") if k in meta}
        numbers = tuple(_check_value(path, name, v, float, item) for v in value)
        hi = meta.get("hi")
        if meta.get("hi_open") and hi is not None and any(v >= hi for v in numbers):
            raise SpecError(path, name, f"expected values < {hi}", value)
        return numbers
    if hint is str or "choices" in meta:
        choices = meta.get("choices")
        if not isinstance(value, str) or (choices and value not in choices):
            allowed = f"one of {', '.join(repr(c) for c in choices)}" if choices else "a string"
            raise SpecError(path, name, f"expected {allowed}", value)
        return value
    integer = meta.get("integer", False)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (
        integer and not isinstance(value, int)
    ):
        raise SpecError(path, name, "expected an integer" if integer else "expected a number", value)
    if not math.isfinite(value):
        raise SpecError(path, name, "expected a finite number", value)
    lo, hi, lo_open = meta.get("lo"), meta.get("hi"), meta.get("lo_open", False)
    if lo is not None and (value < lo or (lo_open and value == lo)):
        rng = f"> {lo}" if lo_open else f">= {lo}"
        raise SpecError(path, name, f"expected a value {rng}" + (f" and <= {hi}" if hi else ""), value)
    if hi is not None and value > hi:
        raise SpecError(path, name, f"expected a value <= {hi}", value)
    return int(value) if integer else float(value)


def _reject_removed(path: Path, name: str) -> None:
    """A one-line SpecError if the field or table ``name`` ("table.field") was removed from the schema."""
    key = name.split(".", 1)[1] if name.startswith("overrides.") else name
    if key in REMOVED_FIELDS:
        raise SpecError(path, name, f"removed ({REMOVED_FIELDS[key]}); delete it")


def _build(cls: type, data: Any, path: Path, prefix: str) -> Any:
    """Build dataclass ``cls`` from a TOML table, validating every field."""
    if not isinstance(data, dict):
        raise SpecError(path, prefix, "expected a table", data)
    hints = get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for name in data:
        _reject_removed(path, f"{prefix}.{name}")
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise SpecError(path, f"{prefix}.{unknown[0]}", f"unknown field; allowed: {', '.join(fields)}")
    values = {}
    for name, f in fields.items():
        full = f"{prefix}.{name}"
        if name not in data:
            if f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING:
                continue
            raise SpecError(path, full, "missing (required)")
        hint = next((a for a in get_args(hints[name]) if dataclasses.is_dataclass(a)), hints[name])
        if f.metadata.get("purposes"):
            values[name] = _check_purposes(path, full, data[name])
        elif dataclasses.is_dataclass(hint):
            values[name] = _build(hint, _over_default(f, data[name]), path, full)
        else:
            values[name] = _check_value(path, full, data[name], hint, dict(f.metadata))
    return cls(**values)


def _over_default(f: dataclasses.Field, data: Any) -> Any:
    """A nested table given in part: its fields over the field's default instance (e.g. one reference indicator's
    TEa given, its weight the default's)."""
    if not isinstance(data, dict) or f.default_factory is dataclasses.MISSING:
        return data
    return {**dataclasses.asdict(f.default_factory()), **data}


def _check_purposes(path: Path, name: str, value: Any) -> dict[str, tuple[str, ...]]:
    """``[screening.purposes]``: a table of purpose -> list of reference indicator names, each indicator in at most
    one purpose, every purpose of PURPOSE_NAMES present."""
    known = [f.name for f in dataclasses.fields(ReferenceIndicators)]
    if not isinstance(value, dict):
        raise SpecError(path, name, "expected a table of purpose = [indicator names]", value)
    out, seen = {}, {}
    for purpose, keys in value.items():
        if not isinstance(keys, list) or not keys or not all(isinstance(k, str) for k in keys):
            raise SpecError(path, f"{name}.{purpose}", "expected a non-empty list of indicator names", keys)
        for k in keys:
            if k not in known:
                raise SpecError(path, f"{name}.{purpose}", f"unknown indicator {k!r}; allowed: {', '.join(known)}")
            if k in seen:
                raise SpecError(path, f"{name}.{purpose}", f"indicator {k!r} is already in purpose {seen[k]!r}; "
                                "each indicator serves one purpose")
            seen[k] = purpose
        out[str(purpose)] = tuple(keys)
    missing = [p for p in PURPOSE_NAMES if p not in out]
    if missing:
        raise SpecError(path, f"{name}.{missing[0]}", f"missing (required purposes: {', '.join(PURPOSE_NAMES)})")
    return out


def load_gearbox(path: str | Path, text: str | None = None) -> GearboxSpec:
    """Load and validate a gearbox TOML file (see ``model_variants/gearbox.toml``).

    ``text``: the file's content, already read (``path`` then only names it in messages). Only the tables of
    :data:`REQUIRED_TABLES` are required; a value left out takes its documented default, fixed or derived from the
    gear data (:mod:`flexgear.sizing`; ``GearboxSpec.derived`` lists those). Every field is checked, then the
    consistency of the tables and the geometric feasibility (:mod:`flexgear.geometry.feasibility`).
    """
    path = Path(path)
    raw = _read_toml(path, text)
    tables = {f.name for f in dataclasses.fields(GearboxSpec)} - {"source", "derived"}
    for name in raw:
        _reject_removed(path, name)
    unknown = sorted(set(raw) - set(tables))
    if unknown:
        raise SpecError(path, unknown[0], f"unknown table; allowed: {', '.join(sorted(tables))}")
    for name in REQUIRED_TABLES:
        if name not in raw:
            raise SpecError(path, name, "missing (required)")
    title = raw.get("title", path.stem)
    if not isinstance(title, str):
        raise SpecError(path, "title", "expected a string", title)
    meshing = raw.get("meshing_assumed", {})
    if not isinstance(meshing, dict) or not all(isinstance(v, dict) for v in meshing.values()):
        raise SpecError(path, "meshing_assumed", "expected a table of levels, e.g. [meshing_assumed.coarse]")
    hints = get_type_hints(GearboxSpec)
    built: dict[str, Any] = {}
    derived: list[str] = []
    rest = sorted(tables - set(FIRST_TABLES) - {"title", "meshing_assumed", "components_geometry", "published"})
    for name in (*FIRST_TABLES, *rest):
        data = with_derived(path, name, hints[name], raw.get(name, {}), built, derived)
        built[name] = _build(hints[name], data, path, name)
    levels = {"coarse": {}, "default": {}, **meshing}
    built["meshing_assumed"] = {
        level: _build(MeshingSettings, with_derived(path, f"meshing_assumed.{level}", MeshingSettings, table, built,
                                                     derived), path, f"meshing_assumed.{level}")
        for level, table in levels.items()
    }
    built["components_geometry"] = components_geometry_table(path, raw.get("components_geometry", {}))
    built["published"] = published_table(path, raw.get("published"))
    spec = GearboxSpec(source=path, title=title, derived=tuple(derived), **built)
    _check_loaded(spec)
    return spec


def _check_loaded(spec: GearboxSpec) -> None:
    """Consistency and feasibility; a value the file left out is named as derived, with how to set it."""
    try:
        _check_consistency(spec)
        for check in _FEASIBILITY:
            check(spec)
    except SpecError as exc:
        if exc.field not in spec.derived:
            raise
        raise SpecError(spec.source, exc.field, f"{exc.allowed} (the default derived from the gear set, "
                        "flexgear.sizing; give the field in the file)") from None


def _check_consistency(spec: GearboxSpec) -> None:
    g, p = spec.gears, spec.source
    if not g.has_ring:
        if (problem := g.pair_problem(spec.bearings.planet is not None)) is not None:
            raise SpecError(p, problem[0], problem[1], problem[2])
    elif spec.bearings.planet is None:
        raise SpecError(p, "bearings.planet", f"missing (required in the {g.arrangement} arrangement)")
    elif g.ring_teeth <= g.planet_teeth + g.sun_teeth // 2:
        raise SpecError(p, "gears.ring_teeth", "expected ring_teeth > sun_teeth/2 + planet_teeth", g.ring_teeth)
    if g.planet_positions_deg and (problem := g.position_problem()):
        raise SpecError(p, "gears.planet_positions_deg", problem, list(g.planet_positions_deg))
    if g.has_ring and not g.planet_positions_deg and (g.sun_teeth + g.ring_teeth) % g.planet_count:
        raise SpecError(
            p, "gears.planet_count",
            "equally spaced planets need (sun_teeth + ring_teeth) divisible by planet_count "
            "(or give gears.planet_positions_deg)",
            g.planet_count,
        )
    if CARRIER in spec.components_geometry and g.arrangement != "planetary":
        raise SpecError(p, f"components_geometry.{CARRIER}", "a carrier from a file needs [gears] arrangement = "
                        "'planetary' (the star holds its carrier)", g.arrangement)
    weights = dataclasses.astuple(spec.screening.weights)
    if abs(sum(weights) - 1.0) > 1e-9:
        raise SpecError(p, "screening.weights", "expected weights that sum to 1", sum(weights))
    ref = spec.screening.reference_indicators
    ref_weights = [getattr(ref, f.name).weight for f in dataclasses.fields(ref)]
    if abs(sum(ref_weights) - 1.0) > 1e-9:
        raise SpecError(p, "screening.reference_indicators", "expected weights that sum to 1", sum(ref_weights))
    if spec.screening.window == "fixed" and spec.screening.window_end_s <= spec.screening.window_start_s:
        raise SpecError(p, "screening.window_end_s", "expected a value > window_start_s",
                        spec.screening.window_end_s)
    lc = spec.load_case
    if lc.end == "settled" and lc.settle_max_time_s < lc.end_time_s:
        raise SpecError(p, "load_case.settle_max_time_s", "expected >= end_time_s (the settled run's maximum time)",
                        lc.settle_max_time_s)
    if lc.step_size_s >= min(lc.end_time_s, lc.ramp_time_s):
        raise SpecError(p, "load_case.step_size_s", "expected < ramp_time_s and < end_time_s", lc.step_size_s)
    for level, m in spec.meshing_assumed.items():
        for prefix in ("", "ring_"):
            if getattr(m, f"{prefix}body_size_mm") < getattr(m, f"{prefix}tooth_size_mm"):
                raise SpecError(p, f"meshing_assumed.{level}.{prefix}body_size_mm",
                                f"expected >= {prefix}tooth_size_mm", getattr(m, f"{prefix}body_size_mm"))


def _apply_overrides(gearbox: GearboxSpec, overrides: Any, path: Path) -> GearboxSpec:
    """The gearbox with some fields of its tables replaced (``[overrides.load_case]`` etc.), validated."""
    if not isinstance(overrides, dict):
        raise SpecError(path, "overrides", "expected tables, e.g. [overrides.load_case]")
    hints = get_type_hints(GearboxSpec)
    changes = {}
    for table, values in overrides.items():
        _reject_removed(path, f"overrides.{table}")
        if table == "components_geometry":  # per component, the file relative to the variant file
            try:
                entries = components_geometry_table(path, values)
            except SpecError as exc:
                raise SpecError(path, f"overrides.{exc.field}", str(exc).split(f"'{exc.field}': ", 1)[1]) from None
            changes[table] = {**gearbox.components_geometry, **entries}
            continue
        current = getattr(gearbox, table, None)
        if table in ("source", "published") or not dataclasses.is_dataclass(current) or not isinstance(values, dict):
            allowed = sorted(n for n, h in hints.items() if dataclasses.is_dataclass(h))
            raise SpecError(path, f"overrides.{table}", f"expected one of the tables {', '.join(allowed)}")
        merged = {f.name: getattr(current, f.name) for f in dataclasses.fields(current)}
        merged = {k: (dataclasses.asdict(v) if dataclasses.is_dataclass(v) else v) for k, v in merged.items()}
        merged.update(values)
        changes[table] = _build(type(current), merged, path, f"overrides.{table}")
    kept = {f"{table}.{name}" for table, values in overrides.items() if table != "components_geometry"
            for name in values}
    return rederive(gearbox.with_changes(**changes), kept)


def _variant_gearbox(path: Path, raw: dict[str, Any], gearbox_text: str | None) -> GearboxSpec:
    """The variant's gearbox with its overrides, validated; an infeasible override names the variant file."""
    if not isinstance(raw["gearbox"], str) or not raw["gearbox"]:
        raise SpecError(path, "gearbox", "expected a path (string) relative to this file", raw["gearbox"])
    gearbox_path = path.parent / raw["gearbox"]
    if gearbox_text is None and gearbox_path.is_dir():
        raise SpecError(path, "gearbox", f"is a folder ({gearbox_path}); expected a TOML file", raw["gearbox"])
    if gearbox_text is None and not gearbox_path.exists():
        raise SpecError(path, "gearbox", f"file does not exist ({gearbox_path})", raw["gearbox"])
    gearbox = load_gearbox(gearbox_path, gearbox_text)
    if "overrides" not in raw:
        return gearbox
    gearbox = _apply_overrides(gearbox, raw["overrides"], path)
    try:
        _check_loaded(gearbox)
    except SpecError as exc:
        table, _, name = exc.field.partition(".")
        if name.split(".")[0] in raw["overrides"].get(table, {}):
            raise SpecError(path, f"overrides.{exc.field}", str(exc).split(f"'{exc.field}': ", 1)[1]) from None
        raise SpecError(path, "overrides", f"make the gearbox infeasible: {exc}") from None
    return gearbox


def check_carrier(path: str | Path, components: dict[str, str], gearbox: GearboxSpec) -> None:
    """SpecError naming ``components.carrier`` in ``path`` when ``components`` make the carrier flexible in an
    arrangement other than the planetary stage's (the star holds its carrier)."""
    if components.get(CARRIER) == "flexible" and gearbox.gears.arrangement != "planetary":
        raise SpecError(path, f"components.{CARRIER}", f"a flexible carrier needs [gears] arrangement = 'planetary' "
                        f"(the {gearbox.gears.arrangement} arrangement holds it); expected 'rigid'", "flexible")


def load_variant(path: str | Path, text: str | None = None, gearbox_text: str | None = None) -> Variant:
    """Load a variant file: ``gearbox = "gearbox.toml"`` plus ``[components]`` rigid/flexible.

    Optional ``[overrides.<table>]`` replace single fields of the gearbox's tables for this variant
    (e.g. a shortened ``load_case`` for a quick run), validated like the gearbox file;
    ``[overrides.components_geometry]`` gives or replaces whole entries (a component from a file, its path relative
    to the variant file) and keeps the gearbox file's others. ``text`` and
    ``gearbox_text``: the two files' contents, already read (e.g. shipped to a worker without the files);
    the paths then only name them in messages.
    """
    path = Path(path)
    raw = _read_toml(path, text)
    allowed = {"name", "gearbox", "components", "mesh_level", "rigid_mass_properties", "description", "overrides"}
    unknown = sorted(set(raw) - allowed)
    if unknown:
        raise SpecError(path, unknown[0], f"unknown field; allowed: {', '.join(sorted(allowed))}")
    for key in ("name", "gearbox", "components"):
        if key not in raw:
            raise SpecError(path, key, "missing (required)")
    gearbox = _variant_gearbox(path, raw, gearbox_text)
    comps = raw["components"]
    if not isinstance(comps, dict):
        raise SpecError(path, "components", "expected a table")
    known = stage_components(gearbox.gears) + OPTIONAL_COMPONENTS
    for name in comps:
        if name not in known:
            raise SpecError(path, f"components.{name}", f"unknown component in the {gearbox.gears.arrangement} "
                            f"arrangement; allowed: {', '.join(known)}")
    components = {}
    for name in known:
        if name not in comps:
            if name in OPTIONAL_COMPONENTS:
                continue
            raise SpecError(path, f"components.{name}", "missing; expected 'rigid' or 'flexible'")
        components[name] = _check_value(path, f"components.{name}", comps[name], str,
                                        {"choices": ("rigid", "flexible")})
    check_carrier(path, components, gearbox)

    level = raw.get("mesh_level", "default")
    if level not in gearbox.meshing_assumed:
        raise SpecError(path, "mesh_level", f"expected one of {sorted(gearbox.meshing_assumed)}", level)
    if not isinstance(raw["name"], str) or not raw["name"]:
        raise SpecError(path, "name", "expected a non-empty string", raw["name"])
    masses = _check_value(path, "rigid_mass_properties", raw.get("rigid_mass_properties", "mesh"), str,
                          {"choices": ("mesh", "exact")})
    return Variant(path, raw["name"], gearbox, components, level, masses)


def as_dict(obj: Any) -> Any:
    """A spec (or any of its tables) as plain JSON-able data; file paths are left out, and so are an empty
    ``components_geometry`` (a gearbox without it hashes as before the table existed) and ``published`` (report
    data, not a model input)."""
    if dataclasses.is_dataclass(obj):
        return {f.name: as_dict(getattr(obj, f.name)) for f in dataclasses.fields(obj)
                if f.name not in ("source", "derived", "published")
                and (f.name != "components_geometry" or obj.components_geometry)}
    if isinstance(obj, dict):
        return {k: as_dict(v) for k, v in sorted(obj.items())}
    if isinstance(obj, Path):
        return None
    return obj


def spec_hash(obj: GearboxSpec | Variant | Any, *extra: Any) -> str:
    """SHA-256 (16 hex digits) of a spec's content (file paths excluded) and any extra values."""
    payload = json.dumps([as_dict(obj), [as_dict(e) for e in extra]], sort_keys=True, default=str)
    return hashlib.sha256(payload.encode()).hexdigest()[:16]
