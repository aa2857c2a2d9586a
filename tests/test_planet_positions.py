"""Planets at given positions (``[gears] planet_positions_deg``), on the spur planetary example (24/30/84, m 3 mm):

- the file: one angle per planet, increasing, each where a planet assembles ((z_s + z_r) psi / 360 an integer, here
  multiples of 3.333 deg), the planets' tip circles clear of each other; anything else refused in one line;
- the carrier's exact mass properties for unequally spaced pins and windows against OCC's volume integrals of its
  solid (the centre of mass then lies off the axis);
- the linearised multibody model against the lumped model (eq. 1-13 with the carrier's equations, Lin & Parker
  1999) within 1 %, and Lin & Parker's result for diametrically opposed planets (J. Sound Vib. 2000, "Structured
  vibration characteristics of planetary gears with unequally spaced planets"): with 4 planets in two opposed pairs
  the rotational and planet modes keep the equally spaced set's frequencies, and the translational pairs split;
- the load sharing that unequal spacing causes (the sun floats on its bearing): the multibody run's mean mesh forces
  against the lumped model's time integration within 1 %, their sum against the sun's torque (hand theory);
- a flexible carrier with unequally spaced pins (its frame then Exudyn's exact rigid body), and the harmonic
  response of the unequally phased meshes against time integration.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from test_validation import to_toml

import flexgear as fg
from flexgear.spec import SpecError

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary"
STEP_DEG = 360.0 / (24 + 84)
"""The example's assembly step: a planet assembles at multiples of 360 / (z_s + z_r) deg."""


def _folder(tmp_path: Path, positions: list[float] | None, count: int = 3) -> Path:
    """A copy of the example with ``count`` planets at ``positions`` (None: equally spaced); its rigid variant."""
    data = tomllib.loads((EXAMPLE / "gearbox.toml").read_text())
    data["gears"]["planet_count"] = count
    if positions is not None:
        data["gears"]["planet_positions_deg"] = positions
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "gearbox.toml").write_text(to_toml(data))
    (tmp_path / "rigid.toml").write_text((EXAMPLE / "rigid.toml").read_text())
    return tmp_path / "rigid.toml"


@pytest.mark.parametrize(("positions", "words"), [
    ([0.0, 120.0], "one angle per planet"),
    ([0.0, 240.0, 120.0], "increasing"),
    ([0.0, 120.0, 245.0], "does not assemble"),
    ([0.0, 120.0, 360.0], "expected values < 360"),
    ([0.0, 60.0, 240.0], "tip circles overlap"),
    ([0.0, 120.0, "x"], "expected a number"),
])
def test_positions_that_cannot_be_built_are_refused_in_one_line(tmp_path, positions, words):
    with pytest.raises(SpecError) as err:
        fg.load_variant(_folder(tmp_path, positions))
    msg = str(err.value)
    assert "\n" not in msg and "field 'gears.planet_positions_deg'" in msg and words in msg, msg


def test_positions_sit_on_the_assembly_angles_and_equal_spacing_given_is_equal_spacing(tmp_path):
    from flexgear.geometry.involute import gear_set_geometry

    typed = fg.load_variant(_folder(tmp_path / "typed", [0.0, 113.333, 243.333])).gearbox
    steps = np.degrees(gear_set_geometry(typed).planet_angles) / STEP_DEG
    np.testing.assert_allclose(steps, [0, 34, 73], atol=1e-12)  # 113.333 deg taken at 34 steps
    assert not typed.gears.equally_spaced
    given = fg.load_variant(_folder(tmp_path / "given", [0.0, 120.0, 240.0])).gearbox
    left_out = fg.load_variant(EXAMPLE / "rigid.toml").gearbox
    assert given.gears.equally_spaced and left_out.gears.equally_spaced
    np.testing.assert_allclose(gear_set_geometry(given).planet_angles, gear_set_geometry(left_out).planet_angles,
                               atol=1e-12)


def test_unequally_spaced_carrier_exact_mass_properties_match_its_solid(tmp_path):
    from flexgear.geometry.carrier import carrier_mass_properties, carrier_sizes, carrier_solid
    from flexgear.geometry.solids import occ_mass_properties

    gearbox = fg.load_variant(_folder(tmp_path, [0.0, 113.333, 243.333])).gearbox
    sizes = carrier_sizes(gearbox)
    rho = gearbox.material_assumed.density_kg_m3
    exact = carrier_mass_properties(sizes, rho)
    mass, com, inertia = occ_mass_properties(carrier_solid(sizes), rho)
    assert np.hypot(*exact.com[:2]) > 1e-3  # off the axis: the test is not the symmetric case
    assert abs(exact.inertia[0, 1]) > 1e-3 * exact.inertia[0, 0]
    assert mass == pytest.approx(exact.mass, rel=1e-9)
    assert np.abs(com - exact.com).max() < 1e-9
    assert np.abs(inertia - exact.inertia).max() < 1e-7 * exact.inertia.max()  # the windows by quadrature


def _planar_modes(path: Path):
    """(multibody modes, lumped modes) below 10 kHz of the planar model (test_planetary_modes' comparison)."""
    from test_planetary_modes import F_MAX, _planar_lumped

    from flexgear.modal import linearize, modes

    variant = fg.load_variant(path)
    m = modes(linearize(variant, speed_rpm=0.0).in_plane().undamped(), F_MAX)
    lumped = _planar_lumped(variant.gearbox)
    return m, lumped.frequencies_hz[lumped.frequencies_hz <= F_MAX]


def test_diametrically_opposed_planets_keep_the_rotational_and_planet_modes(tmp_path):
    """4 planets at 0, 80, 180 and 260 deg (two opposed pairs) against 4 equally spaced: both models agree within
    1 %; every rotational and planet mode of the equally spaced set keeps its frequency (1e-6), and every
    translational pair splits (Lin & Parker 2000)."""
    equal, f_equal = _planar_modes(_folder(tmp_path / "equal", None, count=4))
    opposed, f_opposed = _planar_modes(_folder(tmp_path / "opposed", [0.0, 80.0, 180.0, 260.0], count=4))
    for m, f in ((equal, f_equal), (opposed, f_opposed)):
        assert len(m) == len(f) >= 12
        np.testing.assert_allclose(m.frequencies_hz, f, rtol=0.01)
    kinds = np.asarray(equal.kinds)
    kept = equal.frequencies_hz[np.isin(kinds, ("rotational", "planet"))]
    assert kept.size >= 5
    for f in kept:
        assert np.abs(opposed.frequencies_hz / f - 1).min() < 1e-6, f
    pairs = equal.frequencies_hz[kinds == "translational"].reshape(-1, 2)
    np.testing.assert_allclose(pairs[:, 0], pairs[:, 1], rtol=1e-6)  # degenerate when equally spaced
    for f in pairs[:, 0]:
        near = np.sort(np.abs(opposed.frequencies_hz / f - 1))[:2]
        assert near.min() > 1e-3, f  # split: neither member left within 0.1 % of the equal spacing's frequency


def test_unequal_spacing_shares_the_load_as_the_lumped_model_does(tmp_path):
    """3 planets at 0, 113.3 and 243.3 deg: the sun floats on its bearing and the planets carry unequal loads. The
    multibody run's mean mesh forces (settled half) within 1 % of the lumped model's run (eq. 1-13), their spread
    well beyond that, and the sum of each mesh's forces within 1 % of the sun's torque over its base radius."""
    from flexgear.cli import main
    from flexgear.results import load_result

    path = _folder(tmp_path / "gearbox", [0.0, 113.333, 243.333])
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    assert main(["lpm", str(path), "--out", str(out)]) == 0
    spec = fg.load_variant(path).gearbox
    t_sun = spec.load_case.load_torque_nm * 24 / 108
    r_b = 3e-3 * 24 * math.cos(math.radians(20.0)) / 2
    means = {}
    for name in ("rigid", "lumped"):
        s = load_result(out / name).signals
        late = s[s.time_s >= 0.05]
        assert late.transmission_ratio.mean() == pytest.approx(24 / 108, rel=1e-3), name
        means[name] = late[[f"{m}_mesh_force_{i}_n" for m in ("outer", "inner") for i in (1, 2, 3)]].mean().to_numpy()
        for mesh in (means[name][:3], means[name][3:]):
            assert mesh.sum() == pytest.approx(t_sun / r_b, rel=0.01), name
    np.testing.assert_allclose(means["rigid"], means["lumped"], rtol=0.01)
    assert np.ptp(means["lumped"][:3]) > 0.1 * means["lumped"][:3].mean()  # unequal sharing, not noise


def test_flexible_carrier_with_unequally_spaced_pins_runs_on_its_exact_frame(tmp_path):
    """The carrier flexible (its mesh's centre of mass off the axis): its frame is Exudyn's exact rigid body, not the
    linear frame of an axisymmetric body; the run's ratio within 1e-3 and each mesh's forces summed within 1 % of
    the sun's torque over its base radius."""
    from flexgear.cli import main
    from flexgear.mbs.assemble import build_gearbox
    from flexgear.results import load_result

    path = _folder(tmp_path / "gearbox", [0.0, 113.333, 243.333])
    (path.parent / "carrier.toml").write_text(path.read_text().replace('name = "rigid"', 'name = "carrier"')
                                              + '\ncarrier = "flexible"\n')
    variant = fg.load_variant(path.parent / "carrier.toml")
    assert variant.components["carrier"] == "flexible"
    import exudyn as exu

    mbs = exu.SystemContainer().AddSystem()
    model = build_gearbox(mbs, variant)
    assert model.bodies["carrier"].frame is None  # the exact ObjectRigidBody
    assert main(["run", str(path.parent / "carrier.toml"), "--out", str(tmp_path / "out")]) == 0
    s = load_result(tmp_path / "out" / "carrier").signals
    late = s[s.time_s >= 0.05]
    assert late.transmission_ratio.mean() == pytest.approx(24 / 108, rel=1e-3)
    t_sun = variant.gearbox.load_case.load_torque_nm * 24 / 108
    r_b = 3e-3 * 24 * math.cos(math.radians(20.0)) / 2
    for mesh in ("outer", "inner"):
        total = late[[f"{mesh}_mesh_force_{i}_n" for i in (1, 2, 3)]].mean().sum()
        assert total == pytest.approx(t_sun / r_b, rel=0.01), mesh


def test_unequal_spacing_harmonic_response_matches_its_time_run(tmp_path):
    """3 planets at 0, 113.3 and 243.3 deg, every component rigid, frictionless, at 2000 rpm (the mesh frequency,
    622 Hz, clear of the modes) with a 5 us step: the linearised model's harmonic response (flexgear.harmonic) against
    the settled time run, every planet's sun-planet mesh force at 1x and 2x within 2 % (measured 0.5 %); the planets'
    unequal mesh phases (z_s psi_i / 360 mesh cycles) make their amplitudes differ by more than that."""
    import dataclasses

    from test_spur_planetary_example import harmonic_against_time_run

    variant = fg.load_variant(_folder(tmp_path, [0.0, 113.333, 243.333]))
    spec = variant.gearbox.with_fields("contact", friction_coefficient=0.0).with_fields(
        "load_case", input_speed_rpm=2000.0, step_size_s=5e-6, end_time_s=0.3)
    found = harmonic_against_time_run(dataclasses.replace(variant, gearbox=spec),
                                      tuple(f"outer_mesh_force_{i}_n" for i in (1, 2, 3)))
    for column, (response, timed) in found.items():
        np.testing.assert_allclose(response, timed, rtol=0.02, err_msg=column)
    first = [timed[0] for _, timed in found.values()]
    assert np.ptp(first) > 0.05 * np.mean(first)
