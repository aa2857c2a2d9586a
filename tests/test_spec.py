"""Configuration: the study's values load, and bad files get one clear error."""

from pathlib import Path

import pytest

from flexgear.spec import COMPONENTS, REMOVED_FIELDS, SpecError, load_gearbox, load_variant, spec_hash

VARIANTS = Path(__file__).resolve().parents[1] / "model_variants"


def test_study_values_load(gearbox):
    g = gearbox.gears
    assert (g.sun_teeth, g.planet_teeth, g.ring_teeth, g.planet_count) == (44, 45, 136, 5)  # Table 1
    assert g.normal_module_m == pytest.approx(2.12e-3)
    assert gearbox.bearings.output_shaft.radial_stiffness_n_per_m == pytest.approx(1.2e8)  # Table 2
    assert gearbox.contact.stiffness == pytest.approx(1e8) and gearbox.contact.exponent == pytest.approx(1.5)
    assert gearbox.load_case.input_speed_rpm == pytest.approx(6000.0)  # Table 5
    assert gearbox.load_case.load_torque_nm == pytest.approx(557.025)


TABLE3 = {1: "RRRRR", 2: "RRFRR", 3: "FRRRF", 4: "RFRFR", 5: "FRFRF", 6: "RFFFR", 7: "FFFFF"}


@pytest.mark.parametrize("n", range(1, 8))
def test_variant_files_are_table3(n):
    v = load_variant(VARIANTS / f"model{n}.toml")
    assert "".join("R" if v.components[c] == "rigid" else "F" for c in COMPONENTS) == TABLE3[n]


def _write(tmp_path: Path, text: str, name: str = "gearbox.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def _gearbox_text() -> str:
    return (VARIANTS / "gearbox.toml").read_text()


@pytest.mark.parametrize(
    ("old", "new", "field", "allowed"),
    [
        ("sun_teeth = 44", "sun_teeth = -4", "gears.sun_teeth", ">= 3"),
        ("sun_teeth = 44", "sun_teeth = 44.5", "gears.sun_teeth", "integer"),
        ('helix_layout = "double"', 'helix_layout = "triple"', "gears_assumed.helix_layout", "'double', 'single'"),
        ("exponent = 1.5", 'exponent = "x"', "contact.exponent", "number"),
        ("planet_count = 5", "planet_count = 7", "gears.planet_count", "divisible"),
        ("step_size_s = 1.0e-5", "step_size_s = 0.0", "load_case.step_size_s", "> 0"),
        ("exponent = 1.5", "exponent = 1.5\nexponant = 2", "contact.exponant", "unknown field"),
    ],
)
def test_bad_gearbox_names_file_field_and_allowed(tmp_path, old, new, field, allowed):
    path = _write(tmp_path, _gearbox_text().replace(old, new, 1))
    with pytest.raises(SpecError) as err:
        load_gearbox(path)
    msg = str(err.value)
    assert str(path) in msg and f"'{field}'" in msg and allowed in msg


@pytest.mark.parametrize("removed", sorted(REMOVED_FIELDS))
def test_removed_field_is_named_in_one_line(tmp_path, removed):
    """A gearbox file, or a variant's override, with a field or table the schema no longer has: a one-line error
    naming the file and the field, saying it was removed and what replaced it."""
    table, _, name = removed.partition(".")
    text = _gearbox_text()
    text = text.replace(f"[{table}]", f'[{table}]\n{name} = "x"', 1) if name else text + f"\n[{table}]\nx = 1\n"
    path = _write(tmp_path, text)
    with pytest.raises(SpecError) as err:
        load_gearbox(path)
    msg = str(err.value)
    assert "\n" not in msg and str(path) in msg and f"'{removed}': removed (" in msg
    _write(tmp_path, _gearbox_text())
    variant = 'name = "v"\ngearbox = "gearbox.toml"\n[components]\n' + "".join(f'{c} = "rigid"\n' for c in COMPONENTS)
    variant += f"[overrides.{table}]\n" + (f'{name} = "x"\n' if name else "")
    with pytest.raises(SpecError, match=rf"v.toml: field 'overrides.{removed}': removed \("):
        load_variant(_write(tmp_path, variant, "v.toml"))


def test_missing_table_and_bad_toml(tmp_path):
    text = _gearbox_text()
    start = text.index("[load_case]")
    end = text.index("[solver_assumed]")
    with pytest.raises(SpecError, match="'load_case': missing"):
        load_gearbox(_write(tmp_path, text[:start] + text[end:]))
    with pytest.raises(SpecError, match="not valid TOML"):
        load_gearbox(_write(tmp_path, "title = "))


def test_bad_variant(tmp_path):
    _write(tmp_path, _gearbox_text())
    good = 'name = "x"\ngearbox = "gearbox.toml"\n[components]\n' + "".join(f'{c} = "rigid"\n' for c in COMPONENTS)
    assert load_variant(_write(tmp_path, good, "v.toml")).is_rigid()
    bad = good.replace('sun = "rigid"', 'sun = "elastic"')
    with pytest.raises(SpecError, match=r"'components.sun': expected one of 'rigid', 'flexible'"):
        load_variant(_write(tmp_path, bad, "v.toml"))
    with pytest.raises(SpecError, match="'components.housing': unknown component"):
        load_variant(_write(tmp_path, good + 'housing = "rigid"\n', "v.toml"))
    with pytest.raises(SpecError, match="file does not exist"):
        load_variant(_write(tmp_path, good.replace("gearbox.toml", "nope.toml"), "v.toml"))


def test_hash_tracks_content(gearbox, model1):
    import dataclasses

    assert spec_hash(model1) == spec_hash(dataclasses.replace(load_variant(VARIANTS / "model1.toml"),
                                                              rigid_mass_properties="exact"))
    assert spec_hash(model1) != spec_hash(load_variant(VARIANTS / "model1.toml"))
    other = gearbox.with_changes(load_case=dataclasses.replace(gearbox.load_case, load_torque_nm=500.0))
    assert spec_hash(other) != spec_hash(gearbox)
    assert spec_hash(model1, 0.1) != spec_hash(model1, 0.2)


def test_variant_overrides(tmp_path):
    _write(tmp_path, _gearbox_text())
    base = 'name = "q"\ngearbox = "gearbox.toml"\n[components]\n' + "".join(f'{c} = "rigid"\n' for c in COMPONENTS)
    quick = base + "[overrides.load_case]\nramp_time_s = 0.02\nend_time_s = 0.06\n"
    v = load_variant(_write(tmp_path, quick, "q.toml"))
    lc = v.gearbox.load_case
    assert lc.ramp_time_s == pytest.approx(0.02) and lc.end_time_s == pytest.approx(0.06)
    assert v.gearbox.load_case.load_torque_nm == pytest.approx(557.025)  # untouched fields stay the study's
    with pytest.raises(SpecError, match=r"'overrides.load_case.ramp_time_s': expected a value > 0"):
        load_variant(_write(tmp_path, quick.replace("0.02", "-1.0"), "q.toml"))
    with pytest.raises(SpecError, match=r"'overrides.load_case.ramp': unknown field"):
        load_variant(_write(tmp_path, quick.replace("ramp_time_s", "ramp"), "q.toml"))
    with pytest.raises(SpecError, match=r"'overrides.nothing': expected one of the tables"):
        load_variant(_write(tmp_path, base + "[overrides.nothing]\nx = 1\n", "q.toml"))


def test_quick_variants_match_table3():
    for n in range(1, 8):
        quick = load_variant(VARIANTS / "quick" / f"model{n}.toml")
        full = load_variant(VARIANTS / f"model{n}.toml")
        # quick: 0.2 s, long enough after its 0.02 s ramps for a settled window (flexgear.study.indicators)
        assert quick.components == full.components and quick.gearbox.load_case.end_time_s <= 0.2


def test_the_carrier_is_an_optional_component_flexible_only_where_it_turns(tmp_path):
    """``[components] carrier``: optional (rigid when left out, as Table 3's files do); "flexible" in the planetary
    arrangement only, refused in one line naming the field elsewhere (the star holds its carrier)."""
    from flexgear.simulation import Simulation

    text = (VARIANTS / "model7.toml").read_text().replace("gearbox = \"gearbox.toml\"",
                                                         f"gearbox = \"{VARIANTS / 'gearbox.toml'}\"")
    assert "carrier" not in load_variant(VARIANTS / "model7.toml").components
    path = tmp_path / "v.toml"
    path.write_text(text + 'carrier = "rigid"\n')
    assert load_variant(path).components["carrier"] == "rigid"
    path.write_text(text + 'carrier = "flexible"\n')
    with pytest.raises(SpecError, match=r"components\.carrier.*arrangement = 'planetary'") as err:
        load_variant(path)
    assert "\n" not in str(err.value)
    planetary = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary"
    assert load_variant(planetary / "flexible.toml").components["carrier"] == "flexible"
    sim = Simulation.from_gearbox(planetary / "gearbox.toml", flexible=["carrier"])
    assert sim.variant.components["carrier"] == "flexible" and sim.variant.components["sun"] == "rigid"
    with pytest.raises(SpecError, match=r"components\.carrier"):
        Simulation.from_gearbox(VARIANTS / "gearbox.toml", flexible=["carrier"])
