"""Validation at load time: a corpus of broken files, one field broken in each, that together touch every
field of the schema. Each must fail on loading (before any meshing) with one line naming the file, the field
and what is allowed.

The corpus is generated from the real ``gearbox.toml`` and ``model1.toml``: for every field a value of the
wrong type or outside its range, a missing required field, an unknown field, and the geometric and physical
impossibilities of :mod:`flexgear.geometry.feasibility` (with the numbers they must quote).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path
from typing import Any, get_args, get_type_hints

import pytest

from flexgear.spec import REQUIRED_TABLES, GearboxSpec, MeshingSettings, SpecError, load_gearbox, load_variant

VARIANTS = Path(__file__).resolve().parents[1] / "model_variants"
GEARBOX = tomllib.loads((VARIANTS / "gearbox.toml").read_text())
MODEL1 = tomllib.loads((VARIANTS / "model1.toml").read_text())


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    return repr(v)


def to_toml(data: dict[str, Any], prefix: str = "") -> str:
    """A minimal TOML writer for the gearbox and variant files (scalars and nested tables)."""
    lines = [f"{k} = {_toml_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            lines += ["", f"[{prefix}{k}]", to_toml(v, f"{prefix}{k}.")]
    return "\n".join(lines)


def _table(hint: Any) -> type | None:
    """The dataclass of a table field (``Bearing`` or ``Bearing | None``), None for a leaf."""
    return next((a for a in (hint, *get_args(hint)) if dataclasses.is_dataclass(a)), None)


def _leaves(cls: type, prefix: str) -> list[tuple[str, dataclasses.Field, Any]]:
    hints = get_type_hints(cls)
    out = []
    for f in dataclasses.fields(cls):
        if _table(hints[f.name]) is not None:
            out += _leaves(_table(hints[f.name]), f"{prefix}{f.name}.")
        else:
            out.append((f"{prefix}{f.name}", f, hints[f.name]))
    return out


def schema_fields() -> list[tuple[str, dataclasses.Field | None, Any]]:
    """Every leaf field of the gearbox file (meshing levels as in gearbox.toml) and of a variant file."""
    hints = get_type_hints(GearboxSpec)
    out: list[tuple[str, dataclasses.Field | None, Any]] = [("title", None, str)]
    for name, hint in hints.items():
        if dataclasses.is_dataclass(hint):
            out += _leaves(hint, f"{name}.")
    for level in GEARBOX["meshing_assumed"]:
        out += _leaves(MeshingSettings, f"meshing_assumed.{level}.")
    return out


def _broken_value(f: dataclasses.Field | None, hint: Any) -> tuple[Any, str]:
    """A value ``f`` must refuse and a word the refusal must contain."""
    meta = {} if f is None else dict(f.metadata)
    if meta.get("purposes"):
        return "fast", "expected a table"
    if "choices" in meta:
        return "bogus", "one of"
    if meta.get("sequence"):
        return [meta["lo"] - 1.0], "expected a value"
    if hint is str:
        return 5, "string"
    if meta.get("integer"):
        return 2.5, "integer"
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is not None:
        return (lo if meta.get("lo_open") else lo - 1.0), "expected a value"
    if hi is not None:
        return hi + 1.0, "expected a value"
    return "fast", "number"


def _set(data: dict, dotted: str, value: Any) -> dict:
    out = tomllib.loads(to_toml(data))
    *tables, name = dotted.split(".")
    node = out
    for t in tables:
        node = node[t]
    if value is _DELETE:
        node.pop(name, None)  # a field the file does not give is left out already
    else:
        node[name] = value
    return out


_DELETE = object()
FIELD_CASES = [pytest.param(path, *_broken_value(f, hint), id=path) for path, f, hint in schema_fields()]


def _has_default(f: dataclasses.Field) -> bool:
    """Whether a file may leave ``f`` out: a fixed default, or one that follows the gear set (flexgear.sizing)."""
    return (f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING
            or bool(f.metadata.get("derived")))


ARRANGEMENT_REQUIRED = ("gears.ring_teeth", "gears.planet_count", "bearings.planet")
"""Required by the star and planetary arrangements (the study's file is a star), left out of a parallel-axis pair's
file (the schema gives them a default or a derived value for it): required here."""


def _optional_ancestor(path: str) -> bool:
    """Whether a table above the leaf ``path`` has a default (its own fields then come from that default)."""
    *tables, _ = path.split(".")
    if not tables:
        return False
    if tables[0] not in REQUIRED_TABLES:
        return True
    cls = get_type_hints(GearboxSpec)[tables[0]]
    for k, name in enumerate(tables[1:], 1):
        f = next(x for x in dataclasses.fields(cls) if x.name == name)
        if _has_default(f) and ".".join(tables[:k + 1]) not in ARRANGEMENT_REQUIRED:
            return True
        cls = _table(get_type_hints(cls)[name])
    return False


def _optional(path: str, f: dataclasses.Field | None) -> bool:
    return f is None or (_has_default(f) and path not in ARRANGEMENT_REQUIRED) or _optional_ancestor(path)


REQUIRED = [path for path, f, _ in schema_fields() if not _optional(path, f)]
FIELDS = {path: f for path, f, _ in schema_fields()}
OPTIONAL = [path for path, f, _ in schema_fields() if _optional(path, f)]


def _expect(tmp_path: Path, data: dict, field: str, words: tuple[str, ...], name: str = "gearbox.toml") -> str:
    path = tmp_path / name
    path.write_text(to_toml(data))
    with pytest.raises(SpecError) as err:
        (load_gearbox if name == "gearbox.toml" else load_variant)(path)
    msg = str(err.value)
    assert "\n" not in msg, msg
    assert str(path) in msg and f"field '{field}'" in msg, msg
    for w in words:
        assert w in msg, msg
    return msg


def test_the_generator_reproduces_the_real_files(tmp_path):
    (tmp_path / "gearbox.toml").write_text(to_toml(GEARBOX))
    assert load_gearbox(tmp_path / "gearbox.toml") == dataclasses.replace(
        load_gearbox(VARIANTS / "gearbox.toml"), source=tmp_path / "gearbox.toml")


@pytest.mark.parametrize(("field", "value", "word"), FIELD_CASES)
def test_every_field_refuses_a_wrong_value(tmp_path, field, value, word):
    _expect(tmp_path, _set(GEARBOX, field, value), field, (word,))


@pytest.mark.parametrize("field", REQUIRED)
def test_every_required_field_is_required(tmp_path, field):
    _expect(tmp_path, _set(GEARBOX, field, _DELETE), field, ("missing",))


def test_the_required_fields_are_those_of_the_gears_bearings_and_load_case():
    assert {p.split(".")[0] for p in REQUIRED} == set(REQUIRED_TABLES)
    assert "load_case.input_speed_rpm" in REQUIRED and "load_case.step_size_s" not in REQUIRED


@pytest.mark.parametrize("field", OPTIONAL)
def test_every_other_field_may_be_left_out(tmp_path, field):
    """A leaf left out takes its default (fixed, or derived from the gear set: then listed in ``derived``)."""
    path = tmp_path / "gearbox.toml"
    path.write_text(to_toml(_set(GEARBOX, field, _DELETE)))
    spec = load_gearbox(path)
    f = FIELDS[field]
    if f is None:
        assert spec.title == "gearbox"
    elif f.metadata.get("derived"):
        assert field in spec.derived
    else:
        assert spec.derived == ()


@pytest.mark.parametrize("table", ["gears", "contact", "load_case", "bearings.planet", "screening.weights"])
def test_unknown_fields_are_named(tmp_path, table):
    _expect(tmp_path, _set(GEARBOX, f"{table}.stiffnes", 1.0), f"{table}.stiffnes", ("unknown field", "allowed"))


def _with(**changes: Any) -> dict:
    data = GEARBOX
    for dotted, value in changes.items():
        data = _set(data, dotted.replace("__", "."), value)
    return data


# (changes, field named, words the message must contain)
FEASIBILITY = {
    # 44 + 136 = 180 is divisible by 6, but 2 a_w sin(30 deg) = 105.26 mm < planet tip diameter 109.50 mm
    "planets_overlap": ({"gears__planet_count": 6}, "gears.planet_count", ("overlap", "105.26", "109.50", "at most 5")),
    "planets_not_equally_spaced": ({"gears__planet_count": 7}, "gears.planet_count", ("divisible",)),
    "ring_too_small": ({"gears__ring_teeth": 60}, "gears.ring_teeth", ("ring_teeth >",)),
    # a_0 cos(alpha_t) of the planet-ring mesh: 106.43 mm * cos(alpha_t) = 102.35 mm
    "centre_distance_unreachable": ({"gears_assumed__operating_centre_distance_mm": 90.0},
                                    "gears_assumed.operating_centre_distance_mm", ("cannot be reached", "102.347")),
    "centre_distance_points_the_sun": ({"gears_assumed__operating_centre_distance_mm": 120.0},
                                       "gears_assumed.operating_centre_distance_mm", ("sun tooth pointed",)),
    "shift_points_the_planet": ({"gears_assumed__planet_shift_coefficient": 1.5,
                                 "gears_assumed__addendum_coefficient": 1.5},
                                "gears_assumed.planet_shift_coefficient", ("planet tooth pointed",)),
    "backlash_above_module": ({"gears_assumed__normal_backlash_mm": 2.5}, "gears_assumed.normal_backlash_mm",
                              ("normal module",)),
    "backlash_points_the_planet": ({"gears_assumed__planet_shift_coefficient": 1.0,
                                    "gears_assumed__addendum_coefficient": 1.5,
                                    "gears_assumed__normal_backlash_mm": 2.0},
                                   "gears_assumed.normal_backlash_mm", ("planet tooth pointed",)),
    "sun_bore_beyond_root": ({"components_assumed__sun_bore_diameter_mm": 100.0},
                             "components_assumed.sun_bore_diameter_mm", ("98.11",)),
    "planet_bore_beyond_root": ({"components_assumed__planet_bore_diameter_mm": 101.0},
                                "components_assumed.planet_bore_diameter_mm", ("root diameter",)),
    "input_shaft_bore": ({"components_assumed__input_shaft_inner_diameter_mm": 60.0},
                         "components_assumed.input_shaft_inner_diameter_mm", ("input_shaft_outer_diameter_mm",)),
    "output_shaft_bore": ({"components_assumed__output_shaft_inner_diameter_mm": 95.0},
                          "components_assumed.output_shaft_inner_diameter_mm", ("output_shaft_outer_diameter_mm",)),
    "input_shaft_outside_the_sun_bore": ({"components_assumed__input_shaft_outer_diameter_mm": 55.0},
                                         "components_assumed.input_shaft_outer_diameter_mm", ("sun's bore",)),
    "output_shaft_beyond_the_flange": ({"components_assumed__output_shaft_outer_diameter_mm": 380.0},
                                       "components_assumed.output_shaft_outer_diameter_mm", ("370.0",)),
    "flange_inside_the_rim": ({"components_assumed__ring_flange_outer_diameter_mm": 300.0},
                              "components_assumed.ring_flange_outer_diameter_mm", ("337.25",)),
    "groove_through_the_rim": ({"components_assumed__relief_groove_depth_mm": 9.0},
                               "components_assumed.relief_groove_depth_mm", ("ring_rim_thickness_mm",)),
    "bolts_do_not_fit": ({"components_assumed__ring_bolt_count": 200}, "components_assumed.ring_bolt_count",
                         ("bolt circle",)),
    "seat_longer_than_shaft": ({"components_assumed__bearing_seat_width_mm": 200.0},
                               "components_assumed.bearing_seat_width_mm", ("length_mm",)),
    "output_shaft_shorter_than_flange": ({"components_assumed__output_shaft_length_mm": 5.0},
                                         "components_assumed.output_shaft_length_mm", ("ring_flange_thickness_mm",)),
    "density_in_g_per_cm3": ({"material_assumed__density_kg_m3": 7.85}, "material_assumed.density_kg_m3", (">= 500",)),
    "modulus_in_gpa": ({"material_assumed__youngs_modulus_pa": 210.0}, "material_assumed.youngs_modulus_pa",
                       (">= 100000000",)),
    "step_longer_than_the_run": ({"load_case__step_size_s": 0.7}, "load_case.step_size_s", ("ramp_time_s",)),
    "weights_do_not_sum_to_one": ({"screening__weights__input_speed": 0.5}, "screening.weights", ("sum to 1",)),
    "fixed_window_backwards": ({"screening__window": "fixed", "screening__window_end_s": 0.4},
                               "screening.window_end_s", ("window_start_s",)),
    "body_finer_than_teeth": ({"meshing_assumed__coarse__body_size_mm": 2.0},
                              "meshing_assumed.coarse.body_size_mm", ("tooth_size_mm",)),
}


@pytest.mark.parametrize("case", FEASIBILITY)
def test_infeasible_gearboxes_are_refused_at_load_time(tmp_path, case):
    changes, field, words = FEASIBILITY[case]
    _expect(tmp_path, _with(**changes), field, words)


def test_the_bases_of_the_two_field_cases_are_feasible(tmp_path):
    """The pointed-tooth cases break one field of a feasible gearbox: the base itself loads."""
    base = _with(gears_assumed__planet_shift_coefficient=1.0, gears_assumed__addendum_coefficient=1.5)
    (tmp_path / "gearbox.toml").write_text(to_toml(base))
    load_gearbox(tmp_path / "gearbox.toml")


def _variant_dir(tmp_path: Path) -> Path:
    (tmp_path / "gearbox.toml").write_text(to_toml(GEARBOX))
    (tmp_path / "folder.toml").mkdir()
    return tmp_path


VARIANT_CASES = {
    "gearbox_is_a_folder": ({"gearbox": "folder.toml"}, "gearbox", ("is a folder",)),
    "gearbox_missing": ({"gearbox": "nowhere.toml"}, "gearbox", ("does not exist",)),
    "gearbox_not_a_string": ({"gearbox": 3}, "gearbox", ("path",)),
    "name_empty": ({"name": ""}, "name", ("non-empty",)),
    "component_unknown": ({"components.sun": "elastic"}, "components.sun", ("'rigid', 'flexible'",)),
    "component_missing": ({"components.ring": None}, "components.ring", ("missing",)),
    "component_extra": ({"components.housing": "rigid"}, "components.housing", ("unknown component",)),
    "mesh_level_unknown": ({"mesh_level": "fine"}, "mesh_level", ("coarse", "default")),
    "mass_source_unknown": ({"rigid_mass_properties": "cad"}, "rigid_mass_properties", ("'mesh', 'exact'",)),
    "unknown_key": ({"descripton": "x"}, "descripton", ("unknown field",)),
    "override_table_unknown": ({"overrides": {"gear": {"sun_teeth": 40}}}, "overrides.gear", ("tables",)),
    "override_out_of_range": ({"overrides": {"load_case": {"end_time_s": -1.0}}}, "overrides.load_case.end_time_s",
                              ("> 0",)),
    # an override that is valid on its own but makes the gearbox infeasible names the variant file and the override
    "override_infeasible": ({"overrides": {"gears": {"planet_count": 6}}}, "overrides.gears.planet_count",
                            ("overlap",)),
}


@pytest.mark.parametrize("case", VARIANT_CASES)
def test_broken_variant_files(tmp_path, case):
    changes, field, words = VARIANT_CASES[case]
    folder = _variant_dir(tmp_path)
    data = tomllib.loads(to_toml(MODEL1))
    for key, value in changes.items():
        data = _set(data, key, _DELETE if value is None else value)
    _expect(folder, data, field, words, name="variant.toml")


def test_the_corpus_touches_every_field_of_the_schema():
    named = {p.values[0] for p in FIELD_CASES} | {c[1] for c in FEASIBILITY.values()}
    named |= {c[1] for c in VARIANT_CASES.values()}
    assert {path for path, _, _ in schema_fields()} <= named
    variant_fields = {"name", "gearbox", "components.sun", "components.ring", "mesh_level", "rigid_mass_properties"}
    assert variant_fields | {"overrides.gears.planet_count"} <= named
    corpus = len(FIELD_CASES) + len(REQUIRED) + 5 + len(FEASIBILITY) + len(VARIANT_CASES)
    assert corpus >= 40
