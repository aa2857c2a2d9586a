"""``[published]`` (flexgear.schema_published): a source study's results in the gearbox file, checked on load, in no
hash, and the study's own (Tables 4, 6 and 7) read back as the report takes them."""

import math

import pytest
from conftest import VARIANTS

from flexgear.spec import SpecError, load_gearbox, spec_hash

STUDY = (VARIANTS / "gearbox.toml").read_text()


def _without_published() -> str:
    return STUDY[:STUDY.index("[published]")]


def test_the_studys_published_values_are_read_and_enter_no_hash(tmp_path):
    spec = load_gearbox(VARIANTS / "gearbox.toml")
    pub = spec.published
    assert pub.multibody_variant == "model4" and (pub.ramp_time_s, pub.simulated_time_s) == (0.5, 0.6)
    assert pub.table6["outer_mesh_force_n"] == (798.1894, 800.7533, 798.1762)
    assert math.isnan(pub.table6["input_bearing_peak_accel_m_per_s2"][0])
    assert list(pub.table7) == [1, 2, 4, 6, 9] and pub.table7[1] == (0.0549, 0.0590, 0.0621, 0.0860)
    assert pub.wall_time_per_simulated_s("model7") == pytest.approx(42955.0 / 0.6)
    assert math.isnan(pub.wall_time_per_simulated_s("lumped"))
    (tmp_path / "gearbox.toml").write_text(_without_published())
    bare = load_gearbox(tmp_path / "gearbox.toml")
    assert bare.published is None and spec_hash(bare) == spec_hash(spec)
    assert load_gearbox(VARIANTS / "gearbox.toml") == spec  # NaN-safe equality of two reads


@pytest.mark.parametrize(("table", "field", "words"), [
    ('source = 1', "published.source", "expected who published"),
    ('source = "x"\nheight = 2', "published.height", "unknown field"),
    ('source = "x"\n[published.table6]\nspeed = [1.0, 2.0, 3.0]', "published.table6.speed", "unknown row"),
    ('source = "x"\n[published.table6]\nouter_mesh_force_n = [1.0, 2.0]', "published.table6.outer_mesh_force_n",
     "3 numbers"),
    ('source = "x"\n[published.table7]\nmesh_0x = [1.0, 2.0, 3.0, 4.0]', "published.table7.mesh_0x", "mesh_<k>x"),
    ('source = "x"\n[published.wall_time_s]\nmodel1 = 3.0', "published.simulated_time_s", "missing"),
    ('source = "x"\nramp_time_s = -1.0', "published.ramp_time_s", "> 0"),
    ('source = "x"\n[published.contact]\nexponent = 1.5\ndamping_fraction = 1e-3', "published.contact.stiffness_number",
     "missing"),
    ('source = "x"\n[published.contact]\nstiffness_number = 1e8\nexponent = 1.5\ndamping_fraction = 1e-3\nunit = 1',
     "published.contact.unit", "unknown field"),
])
def test_a_wrong_published_table_is_refused_in_one_line(tmp_path, table, field, words):
    path = tmp_path / "gearbox.toml"
    path.write_text(_without_published() + "[published]\n" + table + "\n")
    with pytest.raises(SpecError) as err:
        load_gearbox(path)
    msg = str(err.value)
    assert "\n" not in msg and f"field '{field}'" in msg and words in msg, msg
