"""Other gear sets than the study's: spur, single- and double-helical sets build their solids and coarse meshes.

A small grid of valid sets (tooth counts 12-150, modules 1-20 mm, pressure angles 14.5-25 deg, planet shifts
-0.5 to 0.8, spur and helical, single and double) written as gearbox files from the study's ``gearbox.toml``,
every size left to follow the gear set (:func:`gear_set_gearbox`, flexgear.sizing). Seven of their gears (``GEARS``):

- its OCC solid (flexgear.geometry.solids) against the exact section integrals (flexgear.geometry.layout), 0.1 %;
- its coarse second-order mesh: flank nodes on the involute helicoid within 1 um
  (flexgear.geometry.check.flank_deviation, as tests/test_geometry.py checks the study's gears).

Sets the schema accepts but the geometry cannot build are refused at load time, in one line naming the field;
one rigid run of a spur set keeps the transmission ratio of theory. Every cache entry goes to a private folder.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from test_validation import to_toml

from flexgear.spec import SpecError, load_gearbox, load_variant

VARIANTS = Path(__file__).resolve().parents[1] / "model_variants"
STUDY = tomllib.loads((VARIANTS / "gearbox.toml").read_text())
MODEL1 = tomllib.loads((VARIANTS / "model1.toml").read_text())


@dataclasses.dataclass(frozen=True)
class GearSetCase:
    """A gear set: teeth (sun, planet, ring), planets, normal module [mm], helix [deg], normal pressure angle
    [deg], planet shift coefficient, helix layout."""

    teeth: tuple[int, int, int]
    planets: int
    module_mm: float
    helix_deg: float
    pressure_deg: float
    planet_shift: float
    layout: str


CASES = {
    "spur_double_12_18_48_m20_a25": GearSetCase((12, 18, 48), 3, 20.0, 0.0, 25.0, -0.3, "double"),
    "single_13_17_47_m10_b30_a20": GearSetCase((13, 17, 47), 3, 10.0, 30.0, 20.0, 0.0, "single"),
    "double_14_22_58_m5_b20_a20": GearSetCase((14, 22, 58), 3, 5.0, 20.0, 20.0, -0.2, "double"),
    "spur_30_58_150_m1_a14.5": GearSetCase((30, 58, 150), 3, 1.0, 0.0, 14.5, 0.8, "single"),
}


def gear_set_gearbox(case: GearSetCase) -> dict:
    """The study's gearbox file with the gear set of ``case`` and every size left to follow the gear set
    (flexgear.sizing): face width, gap and backlash, component and joint sizes, mesh levels."""
    data = copy.deepcopy(STUDY)
    zs, zp, zr = case.teeth
    data["gears"].update(sun_teeth=zs, planet_teeth=zp, ring_teeth=zr, planet_count=case.planets,
                         normal_module_mm=case.module_mm, helix_angle_deg=case.helix_deg,
                         normal_pressure_angle_deg=case.pressure_deg)
    for name in ("face_width_mm", "half_gap_mm", "normal_backlash_mm"):
        del data["gears_assumed"][name]
    data["gears_assumed"].update(helix_layout=case.layout, operating_centre_distance_mm=0.0,
                                 planet_shift_coefficient=case.planet_shift)
    for table in ("components_assumed", "joints_assumed", "meshing_assumed"):
        del data[table]
    return data


def _load(folder: Path, name: str):
    """The gearbox of case ``name``, written into ``folder`` and loaded (validated at load time like a user's
    file)."""
    path = folder / f"{name}.toml"
    path.write_text(to_toml(gear_set_gearbox(CASES[name])))
    return load_gearbox(path)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A private cache folder for the test's solids, meshes and mass properties."""
    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


GEARS = [("spur_double_12_18_48_m20_a25", "sun"), ("spur_double_12_18_48_m20_a25", "planet"),
         ("spur_double_12_18_48_m20_a25", "ring"), ("single_13_17_47_m10_b30_a20", "ring"),
         ("double_14_22_58_m5_b20_a20", "sun"), ("double_14_22_58_m5_b20_a20", "planet"),
         ("spur_30_58_150_m1_a14.5", "planet")]
"""The gears checked in the suite, about a minute of CPU: external and internal, spur, single and double helical,
modules 1-20 mm. Every gear of the whole grid is checked by ``benchmarks/bench_gear_set_grid.py``."""


@pytest.mark.parametrize(("name", "component"), GEARS)
def test_gear_builds_its_solid_and_coarse_mesh(tmp_path, cache, name, component):
    """The sewn OCC solid's volume integrals against Green's-theorem section integrals within 0.1 % (measured: OCC
    integrates some spur extrusions only to 1.3e-4, whose meshed volume agrees to 1e-5, the sweeps to 1e-6); the
    second-order coarse mesh's flank nodes on the involute helicoid within 1 um, on both flanks of every tooth."""
    from netgen.occ import OCCGeometry

    from flexgear.fe.mesh import component_brep, component_mesh
    from flexgear.geometry.check import flank_deviation
    from flexgear.geometry.layout import component_layout, exact_mass_properties
    from flexgear.geometry.solids import occ_mass_properties

    spec = _load(tmp_path, name)
    exact = exact_mass_properties(spec, component)
    shape = OCCGeometry(str(component_brep(spec, component))).shape
    assert len(shape.solids) == 1
    mass, com, inertia = occ_mass_properties(shape, spec.material_assumed.density_kg_m3)
    assert mass == pytest.approx(exact.mass, rel=1e-3)
    np.testing.assert_allclose(np.diag(inertia), np.diag(exact.inertia), rtol=1e-3)
    assert np.linalg.norm(com - exact.com) < 1e-3 * spec.gears.normal_module_m

    layout = component_layout(spec, component)
    mesh = component_mesh(spec, component, "coarse", order=2)
    points = mesh.nodes[mesh.regions["flanks"]]
    dist, _, _ = flank_deviation(layout, points)
    assert np.abs(dist).max() < 1e-6
    # one flank in each half pitch k pi / z <= theta - twist z < (k + 1) pi / z (a flank's nodes span less)
    twist = np.array([next(q.twist for q in layout.prisms if q.section.gear and q.z0 - 1e-9 <= z <= q.z1 + 1e-9)
                      for z in points[:, 2]])
    phase = np.arctan2(points[:, 1], points[:, 0]) - twist * points[:, 2]
    half_pitch = np.floor(phase / (math.pi / layout.gear.teeth))
    assert len(np.unique(half_pitch % (2 * layout.gear.teeth))) == 2 * layout.gear.teeth


def _sweeps(spec) -> list:
    """flexgear.geometry.layout.helix_sweep of the toothed prism of sun, planet and ring."""
    from flexgear.geometry.layout import component_layout, helix_sweep

    out = []
    for component in ("sun", "planet", "ring"):
        layout = component_layout(spec, component)
        prism = next(q for q in layout.prisms if q.section.gear)
        out.append(helix_sweep(prism.twist, prism.length, layout.profile))
    return out


def test_steep_helices_are_swept_precisely_and_the_study_as_before(tmp_path):
    """The 13-tooth sun of m_n = 10 mm, beta = 30 deg turns 0.69 rad over its face (0.6 d_sun): one sweep in metres
    would leave its faces about 45 um off the involute helicoid (2.6e-3 r theta^4), so it is swept in millimetres,
    in pieces; the study's gears (at most 0.136 rad per helix half, every outline curve >= 1.2 mm) keep their sweep
    in metres."""
    from flexgear.geometry.layout import HelixSweep

    steep = _load(tmp_path, "single_13_17_47_m10_b30_a20")
    assert _sweeps(steep)[0].scale == 1000.0
    assert _sweeps(load_gearbox(VARIANTS / "gearbox.toml")) == [HelixSweep(1, 1.0)] * 3


def test_a_short_radial_flank_is_swept_precisely(tmp_path, cache):
    """24/30/84, m_n 3 mm, beta 10 deg, alpha_n 20 deg: the planet's fillet meets its flank 26 um below the base
    circle, a radial flank too short for a sweep in metres (OCC's tolerance there is 0.1 mm; the sweep failed). It
    is swept in millimetres: one solid whose volume integrals match the exact ones."""
    from netgen.occ import OCCGeometry

    from flexgear.fe.mesh import component_brep
    from flexgear.geometry.layout import HelixSweep, exact_mass_properties, gear_profiles
    from flexgear.geometry.solids import occ_mass_properties

    path = tmp_path / "gearbox.toml"
    path.write_text(to_toml(_with(dataclasses.replace(SPUR, helix_deg=10.0))))
    spec = load_gearbox(path)
    assert dict(gear_profiles(spec)["planet"].outline_curves())["radial flank"] == pytest.approx(25.9e-6, abs=1e-7)
    assert _sweeps(spec)[1] == HelixSweep(1, 1000.0)
    shape = OCCGeometry(str(component_brep(spec, "planet"))).shape
    mass, _, inertia = occ_mass_properties(shape, spec.material_assumed.density_kg_m3)
    exact = exact_mass_properties(spec, "planet")
    assert len(shape.solids) == 1
    assert mass == pytest.approx(exact.mass, rel=1e-6)
    assert inertia[2, 2] == pytest.approx(exact.inertia[2, 2], rel=1e-6)


def _with(case: GearSetCase, **fields) -> dict:
    """The gearbox file of ``case`` with single fields given (a field of [gears_assumed] or [components_assumed];
    ``coarse_<field>`` of [meshing_assumed.coarse])."""
    from flexgear.schema import ComponentsAssumed

    data = gear_set_gearbox(case)
    components = {f.name for f in dataclasses.fields(ComponentsAssumed)}
    for key, value in fields.items():
        if key.startswith("coarse_"):
            data.setdefault("meshing_assumed", {}).setdefault("coarse", {})[key.removeprefix("coarse_")] = value
            continue
        data.setdefault("components_assumed" if key in components else "gears_assumed", {})[key] = value
    return data


SPUR = GearSetCase((24, 30, 84), 3, 3.0, 0.0, 20.0, 0.0, "single")
"""The spur variant of the 24/30/84 set (3 planets, m 3 mm) that failed in the helical sweep before."""

REFUSED = {
    "fillet_too_large_for_the_ring": (_with(GearSetCase((12, 18, 48), 3, 20.0, 0.0, 25.0, -0.2, "single"),
                                            root_fillet_coefficient=0.38),
                                      "gears_assumed.root_fillet_coefficient", ("ring's root fillets", "< 0.303")),
    # the 12-tooth sun at 25 deg needs x >= 0.005; a planet shift of +0.3 leaves it -0.3
    # x_p -0.5 gives the ring +0.5 (its tips inwards): they reach into the planet's base circle
    "ring_tips_interfere": (_with(GearSetCase((12, 18, 48), 3, 20.0, 0.0, 25.0, -0.5, "single")),
                            "gears_assumed.addendum_coefficient", ("ring's tips interfere", "planet-ring")),
    "sun_undercut": (_with(GearSetCase((12, 18, 48), 3, 20.0, 0.0, 25.0, 0.3, "single")),
                     "gears_assumed.operating_centre_distance_mm", ("sun (12 teeth) is undercut", "< 0.005")),
    "ring_spaces_close_above_the_root": (_with(dataclasses.replace(SPUR, pressure_deg=25.0), dedendum_coefficient=2.0),
                                         "gears_assumed.dedendum_coefficient", ("ring's tooth spaces", "< 1.2")),
    "mean_centre_distance_unreachable": (_with(GearSetCase((20, 40, 82), 3, 2.0, 0.0, 20.0, 0.0, "single")),
                                         "gears_assumed.operating_centre_distance_mm", ("51.000 mm", "56.382 mm")),
    "groove_depth_zero": (_with(SPUR, relief_groove_depth_mm=0.0), "components_assumed.relief_groove_depth_mm",
                          ("touches the tooth roots",)),
    "tooth_elements_coarser_than_two_modules": (_with(SPUR, coarse_tooth_size_mm=7.0, coarse_body_size_mm=14.0),
                                                "meshing_assumed.coarse.tooth_size_mm", ("<= 6.000 mm",)),
    "planet_tip_inside_its_base_circle": (_with(GearSetCase((30, 12, 56), 2, 2.0, 0.0, 20.0, -1.0, "single"),
                                                addendum_coefficient=0.5),
                                          "gears_assumed.planet_shift_coefficient", ("planet's tip circle",)),
    "radial_flank_sliver": (_with(dataclasses.replace(SPUR, helix_deg=10.0), root_fillet_coefficient=0.308),
                            "gears_assumed.root_fillet_coefficient",
                            ("planet's radial flank is 2.4 um long", "< 0.304", "> 0.308")),
    "single_helix_bore_in_the_groove": (_with(SPUR, sun_bore_diameter_mm=63.9, input_shaft_outer_diameter_mm=40.0),
                                        "components_assumed.sun_bore_diameter_mm", ("relief groove",)),
}


@pytest.mark.parametrize("case", REFUSED)
def test_sets_the_geometry_cannot_build_are_refused_at_load_time(tmp_path, case):
    """Accepted field by field, but no tooth profile or solid could be built: one line naming the field."""
    data, field, words = REFUSED[case]
    path = tmp_path / "gearbox.toml"
    path.write_text(to_toml(data))
    with pytest.raises(SpecError) as err:
        load_gearbox(path)
    assert err.value.field == field
    text = str(err.value)
    assert "\n" not in text and str(path) in text
    for word in words:
        assert word in text


def test_fillet_less_outline_reaches_the_root_circle_and_closes():
    """Without a fillet an external gear's flank runs radially from the base circle down to the root circle: the
    outline is closed, and its OCC face has the area of the exact section integrals."""
    from flexgear.geometry.layout import gear_profiles
    from flexgear.geometry.solids import section_face

    path = Path(__file__)  # only names the file in messages
    spec = load_gearbox(path, to_toml(_with(SPUR, root_fillet_coefficient=0.0)))
    for name, profile in gear_profiles(spec).items():
        gear = profile.gear
        if not gear.internal:
            assert gear.root_radius < gear.base_radius, name
        segments = profile.pitch_segments()
        ends = np.array([seg.points(np.array([1.0]))[0] for seg in segments])
        starts = np.array([seg.points(np.array([0.0]))[0] for seg in segments])
        assert np.abs(np.roll(starts, -1, axis=0)[:-1] - ends[:-1]).max() < 1e-12, name
        assert section_face(profile).mass == pytest.approx(profile.outline_integrals[0], rel=1e-7)


def test_rigid_run_of_a_spur_set_keeps_the_ratio(tmp_path, cache):
    """flexgear run of the rigid star variant on the spur 24/30/84 set (exact mass properties: no meshing): after
    0.01 s ramps, the mean ratio of the last half of 0.1 s is -z_sun / z_ring within 1e-3."""
    from flexgear.cli import main
    from flexgear.results import load_result

    data = gear_set_gearbox(SPUR)
    data["load_case"].update(ramp_time_s=0.01, end_time_s=0.1)
    (tmp_path / "gearbox.toml").write_text(to_toml(data))
    variant = dict(MODEL1, rigid_mass_properties="exact")
    (tmp_path / "model1.toml").write_text(to_toml(variant))
    assert load_variant(tmp_path / "model1.toml").gearbox.gears.helix_angle_deg == 0.0
    assert main(["run", str(tmp_path / "model1.toml"), "--out", str(tmp_path / "out")]) == 0
    run = load_result(tmp_path / "out" / "model1")
    s = run.signals
    ratio = s[s.time_s >= 0.05].transmission_ratio.mean()
    assert run.meta["theory"]["ratio"] == pytest.approx(-24 / 84, rel=1e-12)
    assert ratio == pytest.approx(-24 / 84, rel=1e-3)


def test_a_solid_netgen_fails_on_is_meshed_again_with_finer_teeth(monkeypatch, tmp_path):
    """Netgen's surface mesher fails on a few valid sets' tooth spaces at the coarse level (the grid's 67/31/128,
    m_n 6.32 mm, single helix 15 deg, planet shift -0.249: its planet). The mesh is then made with the next finer
    tooth size of flexgear.fe.mesh.TOOTH_RETRY_FACTORS, and the factor is recorded: here a mesher that fails at the
    level's size and at 0.8 of it meshes at 0.64, the body size unchanged."""
    from netgen.libngpy._meshing import NgException

    import flexgear.fe.mesh as fm

    tried = []

    def mesher(brep, layout, sizes):
        tried.append((sizes.tooth, sizes.body))
        if len(tried) < 3:
            raise NgException("Meshing failed!")
        return "mesh"

    monkeypatch.setattr(fm, "_netgen_mesh", mesher)
    sizes = fm.MeshSizes(4e-3, 8e-3)
    assert fm._netgen_mesh_retried(tmp_path / "x.brep", None, sizes) == ("mesh", 0.64)
    np.testing.assert_allclose(tried, [(4e-3, 8e-3), (3.2e-3, 8e-3), (2.56e-3, 8e-3)])
    tried.clear()
    monkeypatch.setattr(fm, "TOOTH_RETRY_FACTORS", (1.0, 0.8))
    with pytest.raises(NgException):
        fm._netgen_mesh_retried(tmp_path / "x.brep", None, sizes)
