"""Sizes that follow the gear set (flexgear.sizing): a gearbox file with only its gear data, bearings and load case
loads, every value it leaves out follows the gears, and a value it gives wins and is checked like any field."""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path

import pytest
from test_validation import to_toml

from flexgear.spec import REQUIRED_TABLES, SpecError, load_gearbox, load_variant

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "spur_star"


def _minimal(module_mm: float = 3.0, **gears) -> dict:
    """A gearbox file of the 24/30/84 spur set with 3 planets: gear data, bearings and load case only."""
    bearing = {"radial_stiffness_n_per_m": 5e8, "axial_stiffness_n_per_m": 5e7, "tilt_stiffness_nm_per_rad": 1e5}
    return {
        "gears": {"sun_teeth": 24, "planet_teeth": 30, "ring_teeth": 84, "planet_count": 3,
                  "normal_module_mm": module_mm, "helix_angle_deg": 0.0, "normal_pressure_angle_deg": 20.0, **gears},
        "bearings": {"input_shaft": bearing, "output_shaft": bearing, "planet": bearing},
        "load_case": {"input_speed_rpm": 3000.0, "load_torque_nm": 600.0, "ramp_time_s": 0.02, "end_time_s": 0.1},
    }


def _load(tmp_path: Path, data: dict, name: str = "gearbox.toml"):
    path = tmp_path / name
    path.write_text(to_toml(data))
    return load_gearbox(path)


def _lengths(spec) -> dict[str, float]:
    """Every derived length of ``spec`` [mm]: the fields named ``*_mm`` among ``spec.derived``."""
    out = {}
    for dotted in spec.derived:
        table, _, name = dotted.rpartition(".")
        top, _, level = table.partition(".")
        obj = spec.meshing_assumed[level] if level else getattr(spec, top)
        if name.endswith("_mm"):
            out[dotted] = getattr(obj, name)
    return out


def test_a_file_with_gears_bearings_and_load_case_loads_with_every_size_derived(tmp_path):
    """Only the required tables: the file loads (every feasibility check passes on the derived sizes) and every
    size it leaves out is listed as derived; the contact law defaults to ISO 6336, which follows any gear set."""
    spec = _load(tmp_path, _minimal())
    assert set(REQUIRED_TABLES) == {"gears", "bearings", "load_case"}
    derived = {d.split(".")[0] for d in spec.derived}
    assert {"gears_assumed", "components_assumed", "joints_assumed", "meshing_assumed"} <= derived
    assert {"coarse", "default"} <= set(spec.meshing_assumed)
    assert spec.contact.law == "iso6336"
    # the mesh frequency 24 * 3000 / 60 = 1200 Hz sets the step (24 per period) and the reduction's cutoff
    assert spec.load_case.step_size_s == pytest.approx(1 / (24 * 1200.0), rel=1e-12)
    assert spec.reduction_assumed.fixed_interface_cutoff_hz == pytest.approx(3.5 * 1200.0, rel=1e-12)
    assert spec.screening.settle_block_mesh_cycles == round(84 / 8)


@pytest.mark.parametrize("helix_deg", [0.0, 20.0])
def test_derived_sizes_scale_with_the_module(tmp_path, helix_deg):
    """Geometric similarity: the same set at twice the module has every derived length twice as large (the rules
    follow the gears, no absolute millimetre is left), and the same mesh frequency, so the same step."""
    a = _load(tmp_path, _minimal(3.0, helix_angle_deg=helix_deg), "a.toml")
    b = _load(tmp_path, _minimal(6.0, helix_angle_deg=helix_deg), "b.toml")
    la, lb = _lengths(a), _lengths(b)
    assert la.keys() == lb.keys() and len(la) >= 20
    for key in la:
        assert lb[key] == pytest.approx(2 * la[key], rel=1e-9), key
    assert b.load_case.step_size_s == pytest.approx(a.load_case.step_size_s, rel=1e-12)
    assert b.lumped_assumed.carrier_mass_kg == pytest.approx(8 * a.lumped_assumed.carrier_mass_kg, rel=1e-9)


def test_a_given_size_wins_is_checked_and_the_others_follow_it(tmp_path):
    """The sun's bore given: the input shaft (in the bore) follows it; a bore too large for the sun is refused in
    one line naming the field; a derived value that a given one makes infeasible is named as derived."""
    data = _minimal()
    data["components_assumed"] = {"sun_bore_diameter_mm": 40.0}
    spec = _load(tmp_path, data)
    c = spec.components_assumed
    assert c.sun_bore_diameter_mm == 40.0 and "components_assumed.sun_bore_diameter_mm" not in spec.derived
    assert c.input_shaft_outer_diameter_mm == 40.0
    assert c.input_shaft_inner_diameter_mm == pytest.approx(24.0, rel=1e-12)

    data["components_assumed"] = {"sun_bore_diameter_mm": 70.0}
    with pytest.raises(SpecError) as err:
        _load(tmp_path, data)
    assert err.value.field == "components_assumed.sun_bore_diameter_mm"
    assert "\n" not in str(err.value) and "derived" not in str(err.value)

    data["components_assumed"] = {"ring_bolt_count": 40}
    with pytest.raises(SpecError) as err:
        _load(tmp_path, data)
    assert err.value.field == "joints_assumed.bolt_clamp_diameter_mm"
    assert "derived from the gear set" in str(err.value) and "\n" not in str(err.value)


def test_a_variant_that_changes_the_module_derives_the_sizes_again(tmp_path):
    """A variant's ``[overrides.gears]`` normal module doubled: the derived sizes double with it; a size the
    variant overrides keeps its value."""
    (tmp_path / "gearbox.toml").write_text(to_toml(_minimal()))
    components = dict.fromkeys(("input_shaft", "sun", "planets", "ring", "output_shaft"), "rigid")
    base = {"name": "rigid", "gearbox": "gearbox.toml", "components": components}
    (tmp_path / "a.toml").write_text(to_toml(base))
    over = dict(base, overrides={"gears": {"normal_module_mm": 6.0},
                                 "components_assumed": {"sun_bore_diameter_mm": 90}})
    (tmp_path / "b.toml").write_text(to_toml(over))
    a, b = load_variant(tmp_path / "a.toml").gearbox, load_variant(tmp_path / "b.toml").gearbox
    assert b.components_assumed.sun_bore_diameter_mm == 90.0
    assert "components_assumed.sun_bore_diameter_mm" not in b.derived
    for name in ("ring_rim_thickness_mm", "ring_flange_outer_diameter_mm", "planet_bore_diameter_mm"):
        assert getattr(b.components_assumed, name) == pytest.approx(2 * getattr(a.components_assumed, name), rel=1e-9)
    assert b.meshing_assumed["coarse"].tooth_size_mm == pytest.approx(2 * a.meshing_assumed["coarse"].tooth_size_mm)
    assert b.gears_assumed.face_width_mm == pytest.approx(2 * a.gears_assumed.face_width_mm, rel=1e-9)


def test_the_study_gives_every_size_and_keeps_them():
    """The study's file gives all its assumed values: nothing is derived, each value is the file's."""
    path = Path(__file__).resolve().parents[1] / "model_variants" / "gearbox.toml"
    spec = load_gearbox(path)
    raw = tomllib.loads(path.read_text())
    assert spec.derived == ()
    for table in ("components_assumed", "joints_assumed", "gears_assumed"):
        for name, value in raw[table].items():
            assert getattr(getattr(spec, table), name) == value, f"{table}.{name}"
    # the derived rules stay near the study's own assumptions (docstring of flexgear.sizing): within 8 %
    data = {k: raw[k] for k in REQUIRED_TABLES}
    data["gears_assumed"] = {"helix_layout": "double", "operating_centre_distance_mm": 105.26}
    derived = load_gearbox(path, to_toml(data))
    for name, value in raw["components_assumed"].items():
        got = getattr(derived.components_assumed, name)
        assert math.isclose(got, value, rel_tol=0.08), (name, got, value)
    assert dataclasses.asdict(derived.bearings) == dataclasses.asdict(spec.bearings)


def test_the_ring_is_meshed_finer_than_the_solid_gears_and_a_given_ring_size_wins(tmp_path):
    """The ring's own sizes: teeth at most 1.2 normal modules (and no coarser than the level's teeth), at least
    two elements through its rim (and no finer than its teeth); a file's value wins and is checked: a ring body
    finer than its teeth is refused in one line naming the ring's field."""
    spec = _load(tmp_path, _minimal(3.0))
    coarse, rim = spec.meshing_assumed["coarse"], spec.components_assumed.ring_rim_thickness_mm
    assert coarse.ring_tooth_size_mm == pytest.approx(min(coarse.tooth_size_mm, 1.2 * 3.0), rel=1e-12)
    assert coarse.ring_body_size_mm == pytest.approx(max(coarse.ring_tooth_size_mm, min(coarse.body_size_mm, rim / 2)),
                                                     rel=1e-12)
    assert coarse.ring_body_size_mm <= rim / 2 + 1e-12 and coarse.ring_tooth_size_mm < coarse.tooth_size_mm
    assert coarse.sizes_mm("ring") == (coarse.ring_tooth_size_mm, coarse.ring_body_size_mm)
    assert coarse.sizes_mm("sun") == (coarse.tooth_size_mm, coarse.body_size_mm)

    data = _minimal(3.0)
    data["meshing_assumed"] = {"coarse": {"ring_tooth_size_mm": 3.5}}
    given = _load(tmp_path, data).meshing_assumed["coarse"]
    assert given.ring_tooth_size_mm == 3.5 and given.ring_body_size_mm == pytest.approx(max(3.5, min(
        given.body_size_mm, rim / 2)), rel=1e-12)
    data["meshing_assumed"] = {"coarse": {"ring_tooth_size_mm": 4.0, "ring_body_size_mm": 3.0}}
    with pytest.raises(SpecError) as err:
        _load(tmp_path, data)
    assert err.value.field == "meshing_assumed.coarse.ring_body_size_mm" and "\n" not in str(err.value)
