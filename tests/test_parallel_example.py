"""The parallel-axis example (examples/parallel_helical/): a single-helical pair 25/79, normal module 3 mm, helix
15 deg, whose gearbox file gives only its gear data, helix layout, bearings and load case (``[gears] arrangement =
"parallel"``: the sun the pinion, the one planet the wheel, each gear fixed to its shaft, each shaft on two bearings
straddling its gear).

- the file's refusals: a ring, a second wheel, planet positions or a planet bearing in a pair; a ring component in a
  pair's variant; a star without its planet bearing or ring;
- ``flexgear run`` of the rigid variant with frictionless teeth and its states recorded: the settled half's ratio
  within 1e-3 of -z_s / z_p, the mean mesh force within 1 % of loss-free hand theory F_n = T_in / (r_b,s cos beta_b),
  T_in = T_out z_s / z_p (and the input torque within 1 % of it); the loads the shafts really carry: the two bearings
  of each shaft together take the mesh force (in-plane F_n cos beta_b, axial F_n sin beta_b) within 1 %, each
  bearing's force from its 6 x 6 stiffness and the deflection of the rigid body's point at its centre;
- the all-flexible variant (every gear and shaft reduced from its coarse mesh): ratio and mean mesh force as above.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import flexgear as fg
from flexgear.spec import SpecError

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "parallel_helical"
STATES_EVERY = 4
"""Steps between two recorded body states."""


@pytest.fixture(scope="module")
def gearbox():
    return fg.load_gearbox(EXAMPLE / "gearbox.toml")


def _hand(spec) -> tuple[float, float, float]:
    """Loss-free (T_in [N m], F_n [N], beta_b [rad]) of the pair: T_in = T_out z_s / z_p, F_n = T_in / (r_b cos
    beta_b), r_b = m_n z_s cos(alpha_t) / (2 cos beta), sin(beta_b) = sin(beta) cos(alpha_n) (independent of the
    profile shifts)."""
    g = spec.gears
    beta, alpha_n = math.radians(g.helix_angle_deg), math.radians(g.normal_pressure_angle_deg)
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    r_b = g.normal_module_mm * 1e-3 * g.sun_teeth / (2 * math.cos(beta)) * math.cos(alpha_t)
    beta_b = math.asin(math.sin(beta) * math.cos(alpha_n))
    t_in = spec.load_case.load_torque_nm * g.sun_teeth / g.planet_teeth
    return t_in, t_in / (r_b * math.cos(beta_b)), beta_b


def _frictionless(tmp_path: Path, name: str) -> Path:
    """A copy of the example's variant ``name`` with frictionless teeth (``[overrides.contact]``)."""
    text = (EXAMPLE / f"{name}.toml").read_text().replace('gearbox = "gearbox.toml"',
                                                          f'gearbox = "{(EXAMPLE / "gearbox.toml").as_posix()}"')
    path = tmp_path / f"{name}.toml"
    path.write_text(text + "\n[overrides.contact]\nfriction_coefficient = 0.0\n")
    return path


def _check_ratio_and_force(result, spec, name: str) -> None:
    g, lc = spec.gears, spec.load_case
    s = result.signals
    late = s[s.time_s >= 0.5 * (lc.ramp_time_s + lc.end_time_s)]
    t_in, f_n, _ = _hand(spec)
    assert "inner_mesh_force_1_n" not in s.columns
    assert late.transmission_ratio.mean() == pytest.approx(-g.sun_teeth / g.planet_teeth, rel=1e-3), name
    assert late.outer_mesh_force_1_n.mean() == pytest.approx(f_n, rel=0.01), name
    assert late.input_torque_nm.mean() == pytest.approx(t_in, rel=0.01), name


def _bearing_forces(result, design, body: str, shaft: str, start: float) -> np.ndarray:
    """Mean force [N] (3,) the two bearings of ``shaft`` exert on the rigid ``body`` after ``start`` [s]: each
    -K u with K its 6 x 6 stiffness's translational block and u the displacement of the body's point at the
    bearing centre, p - p_0 + (A e_z - e_z) z_c (the centre on the body's axis at z_c)."""
    st = result.extra["states"]
    keep = st.time_s.to_numpy() >= start
    p = np.stack([st[f"{body}_p{a}_m"].to_numpy() for a in "xyz"], axis=1)
    axis = np.stack([st[f"{body}_a{i}2"].to_numpy() for i in range(3)], axis=1)  # A e_z
    total = np.zeros(3)
    for key in (shaft, shaft + "_near"):
        bearing = design.supports[key]
        u = p - p[0] + (axis - [0.0, 0.0, 1.0]) * float(bearing.centre[2])
        total += -(u[keep] @ bearing.stiffness[:3, :3].T).mean(axis=0)
    return total


def test_the_example_file_gives_gears_helix_layout_bearings_and_load_case(gearbox):
    import tomllib

    raw = tomllib.loads((EXAMPLE / "gearbox.toml").read_text())
    assert set(raw) == {"title", "gears", "gears_assumed", "bearings", "load_case"}
    assert set(raw["bearings"]) == {"input_shaft", "output_shaft"}
    g = gearbox.gears
    assert g.arrangement == "parallel" and not g.has_ring and g.planet_count == 1
    assert {"gears.ring_teeth", "gears.planet_count"} <= set(gearbox.derived)
    from flexgear.design import design

    d = design(gearbox)
    assert d.gears.ring is None and set(d.meshes) == {"outer"}
    assert d.theory.ratio == pytest.approx(-g.sun_teeth / g.planet_teeth, rel=1e-12)
    assert d.theory.mesh_force == pytest.approx(_hand(gearbox)[1], rel=1e-9)


@pytest.mark.parametrize(("table", "line", "field"), [
    ("gears_assumed", "operating_centre_distance_mm = 100.0", "gears_assumed.operating_centre_distance_mm"),
    ("gears", "ring_teeth = 200", "gears.ring_teeth"),
    ("gears", "planet_count = 2", "gears.planet_count"),
    ("gears", "planet_positions_deg = [0.0]", "gears.planet_positions_deg"),
])
def test_a_pair_refuses_what_it_does_not_have(tmp_path, table, line, field):
    text = (EXAMPLE / "gearbox.toml").read_text().replace(f"[{table}]\n", f"[{table}]\n{line}\n", 1)
    path = tmp_path / "gearbox.toml"
    path.write_text(text)
    with pytest.raises(SpecError, match=f"field '{field}'"):
        fg.load_gearbox(path)


def test_a_pair_refuses_a_planet_bearing_and_a_star_needs_one(tmp_path):
    text = (EXAMPLE / "gearbox.toml").read_text()
    extra = "\n[bearings.planet]\nradial_stiffness_n_per_m = 1e8\naxial_stiffness_n_per_m = 1e7\n" \
            "tilt_stiffness_nm_per_rad = 1e5\n"
    path = tmp_path / "gearbox.toml"
    path.write_text(text + extra)
    with pytest.raises(SpecError, match="field 'bearings.planet'"):
        fg.load_gearbox(path)
    star = text.replace('arrangement = "parallel"\n', "ring_teeth = 183\nplanet_count = 1\n")
    path.write_text(star)
    with pytest.raises(SpecError, match="field 'bearings.planet': missing"):
        fg.load_gearbox(path)
    path.write_text(text.replace('arrangement = "parallel"\n', "").replace("[load_case]", extra + "\n[load_case]"))
    with pytest.raises(SpecError, match="field 'gears.ring_teeth': missing"):
        fg.load_gearbox(path)


def test_a_pairs_variant_has_no_ring(tmp_path):
    text = (EXAMPLE / "rigid.toml").read_text().replace('gearbox = "gearbox.toml"',
                                                        f'gearbox = "{(EXAMPLE / "gearbox.toml").as_posix()}"')
    path = tmp_path / "v.toml"
    path.write_text(text.replace('output_shaft = "rigid"', 'output_shaft = "rigid"\nring = "rigid"'))
    with pytest.raises(SpecError, match="field 'components.ring': unknown component in the parallel arrangement"):
        fg.load_variant(path)


@pytest.mark.slow  # a rigid run with states: a few seconds
def test_rigid_pair_meets_hand_theory_and_its_bearings_carry_the_mesh_force(tmp_path, example_cache, gearbox):
    from flexgear.cli import main
    from flexgear.design import design
    from flexgear.results import load_result

    variant = _frictionless(tmp_path, "rigid")
    out = tmp_path / "out"
    assert main(["run", str(variant), "--out", str(out), "--states", str(STATES_EVERY)]) == 0
    result = load_result(out / "rigid")
    assert result.meta["status"] == "ok", result.meta["reason"]
    _check_ratio_and_force(result, gearbox, "rigid")
    d = design(gearbox)
    _, f_n, beta_b = _hand(gearbox)
    lc = gearbox.load_case
    half = 0.5 * (lc.ramp_time_s + lc.end_time_s)
    for body, shaft in (("sun", "input_shaft"), ("planet1", "output_shaft")):
        assert result.meta["state_bodies"][body]["geometries"] == [body.rstrip("1"), shaft]
        force = _bearing_forces(result, d, body, shaft, half)
        assert math.hypot(force[0], force[1]) == pytest.approx(f_n * math.cos(beta_b), rel=0.01), body
        assert abs(force[2]) == pytest.approx(f_n * math.sin(beta_b), rel=0.01), body


@pytest.mark.slow  # the four coarse reductions (about a minute of CPU, once per run of the tests) and a run
def test_all_flexible_pair_meets_hand_theory(tmp_path, example_cache, gearbox):
    from flexgear.cli import main
    from flexgear.results import load_result

    variant = _frictionless(tmp_path, "flexible")
    out = tmp_path / "out"
    assert main(["run", str(variant), "--out", str(out)]) == 0
    result = load_result(out / "flexible")
    assert result.meta["status"] == "ok", result.meta["reason"]
    _check_ratio_and_force(result, gearbox, "flexible")


@pytest.mark.slow  # the matrix of both variants to their settled end, its screenings and the report: about a minute
def test_the_workflow_takes_the_pair(tmp_path, example_cache, gearbox):
    """``flexgear matrix`` (settled runs, the Westgard screening against the flexible pair, the modal screening of the
    pair's components), ``flexgear lpm`` and ``flexgear report``; the mean mesh force of both variants and of the
    lumped model within 1 % of hand theory."""
    import pandas as pd

    from flexgear.cli import main

    out = tmp_path / "m"
    assert main(["matrix", str(EXAMPLE / "rigid.toml"), str(EXAMPLE / "flexible.toml"), "--t-end", "settled",
                 "--reference", "flexible", "--out", str(out)]) == 0
    runs = pd.read_csv(out / "matrix_results.csv")
    assert list(runs.status) == ["ok", "ok"] and runs.ring.isna().all()
    means = pd.read_csv(out / "screening_indicators.csv")
    _, f_n, _ = _hand(gearbox)
    force = means[means.indicator == "outer_mesh_force"]
    assert len(force) == 2 and np.allclose(force["mean"], f_n, rtol=0.01)  # tooth friction: a few 0.1 %
    assert "inner_mesh_force" not in set(means.indicator)
    assert len(pd.read_csv(out / "verdict.csv")) == 5  # four purposes and all
    modal = pd.read_csv(out / "modal_screening.csv")
    assert "ring" not in set(modal.component)
    assert main(["lpm", str(EXAMPLE / "rigid.toml"), "--out", str(out)]) == 0  # the lumped model beside the runs
    from flexgear.results import load_result

    lumped = load_result(out / "lumped").signals
    late = lumped[lumped.time_s >= 0.5 * (gearbox.load_case.ramp_time_s + gearbox.load_case.end_time_s)]
    assert late.outer_mesh_force_1_n.mean() == pytest.approx(f_n, rel=0.01)
    assert main(["report", str(out), "--output", str(tmp_path / "report.pdf")]) == 0
    assert (tmp_path / "report.pdf").stat().st_size > 0


@pytest.mark.slow  # a 0.3 s rigid run at a 5 us step and three linearisations: about half a minute
def test_rigid_pairs_harmonic_response_matches_its_time_run(tmp_path, example_cache):
    """Every component rigid, frictionless, at 2000 rpm (the mesh frequency, 833 Hz, and its double clear of the
    pair's modes, `flexgear modes`) with a 5 us step: the linearised model's harmonic response (flexgear.harmonic,
    linearised as the time model is built) against the settled time run, the mesh force and both bearings'
    accelerations at 1x and 2x the mesh frequency within 2 %."""
    import dataclasses

    from test_spur_planetary_example import harmonic_against_time_run

    variant = fg.load_variant(_frictionless(tmp_path, "rigid"))
    spec = variant.gearbox.with_fields("load_case", input_speed_rpm=2000.0, step_size_s=5e-6, end_time_s=0.3)
    columns = ("outer_mesh_force_1_n", "input_bearing_accel_y_m_per_s2", "output_bearing_accel_y_m_per_s2")
    found = harmonic_against_time_run(dataclasses.replace(variant, gearbox=spec), columns)
    for column, (response, timed) in found.items():
        np.testing.assert_allclose(response, timed, rtol=0.02, err_msg=column)


@pytest.mark.parametrize("speed_rpm", [0.0, 3000.0])
def test_planar_pair_modes_equal_the_lumped_models(example_cache, speed_rpm):
    """The rigid pair linearised at rest and at its operating speed, axial motion and tilts held (``in_plane``):
    every mode below 10 kHz equals the lumped model's (flexgear.lumped.modal) within 1e-9, when the lumped members
    carry the gears' and shafts' true in-plane masses and, the tilts held, both bearings' radial stiffness 2 k_r (the
    lumped model otherwise condenses the shaft's tilt onto its two bearings); same kinds. The carrier holds still: no
    rotating-frame term at speed."""
    import dataclasses

    from flexgear.design import as_design
    from flexgear.lumped.modal import modal_analysis
    from flexgear.lumped.model import LumpedParameters
    from flexgear.modal import linearize, modes

    variant = fg.load_variant(EXAMPLE / "rigid.toml")
    spec = variant.gearbox
    m = modes(linearize(variant, speed_rpm=speed_rpm).in_plane().undamped(), 10e3)
    masses, b = as_design(spec).masses, spec.bearings
    p = LumpedParameters.from_spec(spec, hold_input=True)
    p = dataclasses.replace(
        p, sun=dataclasses.replace(p.sun, mass_kg=masses["sun"].mass + masses["input_shaft"].mass,
                                   bearing_stiffness_n_per_m=2 * b.input_shaft.radial_stiffness_n_per_m),
        planet=dataclasses.replace(p.planet, mass_kg=masses["planet"].mass + masses["output_shaft"].mass,
                                   bearing_stiffness_n_per_m=2 * b.output_shaft.radial_stiffness_n_per_m))
    lumped = modal_analysis(p)
    keep = lumped.frequencies_hz <= 10e3
    assert len(m) == np.count_nonzero(keep) >= 4
    np.testing.assert_allclose(m.frequencies_hz, lumped.frequencies_hz[keep], rtol=1e-9)
    assert list(m.kinds) == list(np.asarray(lumped.kinds)[keep])


def test_flexible_pairs_modes_over_one_revolution(example_cache):
    """With only the wheel flexible the pair's linearisation is periodic in one revolution of the wheel (its contact
    columns turn with it; z_w mesh periods): the modes at t* + P equal those at t* within 1e-9, half a revolution on
    they do not. The example's all-flexible pair (`flexgear modes`): the static equilibrium is found at every
    sample of the revolution (Newton stalls at round-off, a few 1e-10 of the load, at some of the gears' angles)."""
    import dataclasses

    from flexgear.modal import linearize, modes
    from flexgear.modal.period import period_modes, period_samples

    variant = fg.load_variant(EXAMPLE / "flexible.toml")
    wheel = dataclasses.replace(variant, components={k: "flexible" if k == "planets" else "rigid"
                                                     for k in variant.components})
    first = linearize(wheel)
    times = period_samples(first, 4)
    period = 4 * (times[1] - times[0])
    g, lc = variant.gearbox.gears, variant.gearbox.load_case
    assert period == pytest.approx(60.0 / (lc.input_speed_rpm * g.sun_teeth / g.planet_teeth), rel=1e-12)
    f0 = modes(first, 5000.0).frequencies_hz
    f_full = modes(linearize(wheel, t_star=float(times[0] + period)), 5000.0).frequencies_hz
    f_half = modes(linearize(wheel, t_star=float(times[2])), 5000.0).frequencies_hz
    np.testing.assert_allclose(f_full, f0, rtol=1e-9)
    assert len(f_half) == len(f0) and np.max(np.abs(f_half - f0) / f0) > 1e-6  # the angle matters
    found = period_modes(variant, None, 5000.0)
    assert len(found) > 0 and np.all(np.isfinite(found.frequencies_hz)) and np.all(np.isfinite(found.spread_pct))
