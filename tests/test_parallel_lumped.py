"""The lumped model of the parallel-axis pair (examples/parallel_helical: pinion 25, wheel 79, helical) against its
own hand theory.

The pair in the lumped model (flexgear.lumped.model): the pinion + input shaft on the sun, the wheel + output shaft
on planet 1 at the centre distance a on the x axis, ring and carrier held, one mesh; each shaft on its two bearings
condensed to its gear centre. The model's mesh convention: the mesh stiffness k_m acts along the tooth normal, whose
deflection is delta_n = cos(beta_b) delta_t (delta_t along the transverse line of action), so on transverse
coordinates the mesh is a spring k_m cos^2(beta_b). Loss-free hand theory of the pair (the wheel's load torque T):

- ratio omega_wheel / omega_pinion = -z_s / z_p; pinion torque T_in = T z_s / z_p; normal mesh force
  F_n = T_in / (r_b,s cos(beta_b)) = T / (r_b,p cos(beta_b));
- pinion spin held (the prescribed drive), spins only: one mode, omega^2 = k_m cos^2(beta_b) r_b,p^2 / I_p; the
  pinion free as well: a rigid-body mode and omega^2 = k_m cos^2(beta_b) (r_b,s^2 / I_s + r_b,p^2 / I_p);
- with translations, the mesh loads neither gear across its line of action: each gear's translation along
  t = J n (n the line of action) is a mode of its own on its isotropic support, omega^2 = k_b / m;
- the loaded static transmission error at the wheel (along its line of action, lever r_b,p): the mesh's own
  deflection F_n / (k_m cos(beta_b)) plus both centres' give F_n cos(beta_b) / k_b along n (the transverse mesh
  force on each support in series);
- a rigid shaft on two bearings (radial k_1, k_2, no tilt stiffness) at distances a and b either side of the gear,
  a force F at the gear: the reactions F b / (a + b), F a / (a + b), the gear point between the two bearing
  deflections by the lever rule, u = F (b^2 / k_1 + a^2 / k_2) / (a + b)^2.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from flexgear.design import design
from flexgear.geometry.elements import (
    BearingElement,
    condensed_radial_damping_of,
    condensed_radial_stiffness_of,
    lever_rows,
)
from flexgear.lumped.modal import modal_analysis
from flexgear.lumped.model import LumpedParameters, assemble
from flexgear.lumped.run import run_lumped, static_mesh_forces
from flexgear.results import signal_columns
from flexgear.spec import load_variant

ROOT = Path(__file__).resolve().parents[1]
PAIR = ROOT / "examples" / "parallel_helical" / "rigid.toml"
STAR = ROOT / "model_variants" / "quick" / "model1.toml"

EXACT = 1e-9  # closed forms of the linear model: round-off only
SETTLED_WINDOW_S = 0.02  # the last 0.02 s of the example's run: 25 mesh cycles at 3000 rpm (f_m = 1250 Hz)


@pytest.fixture(autouse=True)
def _private_cache(example_cache):
    """Every cache entry (the exact mass properties) in the examples' cache of the run, not the project's."""
    return example_cache


@pytest.fixture(scope="module")
def pair():
    """The pair without tooth friction (the loss-free theory's scope)."""
    return load_variant(PAIR).gearbox.with_fields("contact", friction_coefficient=0.0)


def test_time_run_carries_the_torque_at_the_theoretical_ratio_and_mesh_force(pair):
    """flexgear lpm of the pair: after the ramps the ratio is -z_s / z_p (1e-3), the mean mesh force
    T_in / (r_b,s cos(beta_b)) and the drive torque T z_s / z_p (1 %); the signal table has no ring-mesh column."""
    g, geo, lc = pair.gears, design(pair).gears, pair.load_case
    res = run_lumped(pair)
    assert res.ok and list(res.signals.columns) == signal_columns(1, inner=False)
    w = res.signals[res.signals["time_s"] >= lc.end_time_s - SETTLED_WINDOW_S]
    t_in = lc.load_torque_nm * g.sun_teeth / g.planet_teeth
    force = t_in / (geo.sun.base_radius * math.cos(geo.sun.base_helix_angle))
    ratio = w["output_speed_rad_per_s"].mean() / w["input_speed_rad_per_s"].mean()
    assert ratio == pytest.approx(-g.sun_teeth / g.planet_teeth, rel=1e-3)
    assert w["outer_mesh_force_1_n"].mean() == pytest.approx(force, rel=0.01)
    assert w["input_torque_nm"].mean() == pytest.approx(t_in, rel=0.01)
    # the static linear problem: the wheel's torque balance alone, T = F_n cos(beta_b) r_b,p
    outer, inner = static_mesh_forces(pair)
    assert inner.size == 0
    assert outer[0] == pytest.approx(lc.load_torque_nm / (geo.planet.base_radius * math.cos(geo.sun.base_helix_angle)),
                                     rel=EXACT)


def _mesh_spring(p: LumpedParameters) -> float:
    """k_m cos^2(beta_b) [N/m]: the mesh on transverse coordinates (module docstring)."""
    return p.sun_mesh_stiffness_n_per_m * math.cos(p.base_helix_angle_rad) ** 2


def test_torsional_modes_are_the_two_spin_chain(pair):
    """Spins only: pinion held, omega^2 = k cos^2(beta_b) r_b,p^2 / I_p; pinion free, a rigid-body mode and
    omega^2 = k cos^2(beta_b) (r_b,s^2 / I_s + r_b,p^2 / I_p)."""
    held = LumpedParameters.from_spec(pair, hold_input=True)
    k, rs, rp = _mesh_spring(held), held.sun.radius_m, held.planet.radius_m
    i_s, i_p = held.sun.inertia_kg_m2, held.planet.inertia_kg_m2
    res = modal_analysis(held, translations=False)
    assert res.frequencies_hz.size == 1
    assert (2 * math.pi * res.frequencies_hz[0]) ** 2 == pytest.approx(k * rp**2 / i_p, rel=1e-6)
    free = modal_analysis(LumpedParameters.from_spec(pair), translations=False)
    assert free.frequencies_hz.size == 2 and free.frequencies_hz[0] == 0.0
    assert (2 * math.pi * free.frequencies_hz[1]) ** 2 == pytest.approx(k * (rs**2 / i_s + rp**2 / i_p), rel=1e-6)


def test_translations_across_the_line_of_action_are_the_supports_own_modes(pair):
    """With translations (pinion spin held): each gear's translation along t = J n is a mode at
    omega^2 = k_b / m of its condensed support, untouched by the mesh."""
    p = LumpedParameters.from_spec(pair, hold_input=True)
    res = modal_analysis(p)
    assert res.frequencies_hz.size == 5  # pinion x, y; wheel x, y, spin
    omega2 = (2 * math.pi * res.frequencies_hz) ** 2
    for member in (p.sun, p.planet):
        own = member.bearing_stiffness_n_per_m / member.mass_kg
        assert np.abs(omega2 / own - 1.0).min() < EXACT


def test_static_transmission_error_is_the_mesh_and_both_supports_in_series(pair):
    """The lumped linearisation's loaded static TE at the wheel (lever design.output_radius = r_b,p):
    F_n / (k_m cos(beta_b)) + F_n cos(beta_b) (1/k_s + 1/k_p), with F_n = T / (r_b,p cos(beta_b))."""
    from flexgear.harmonic.lumped import lumped_linear

    lin = lumped_linear(pair, 1)
    assert design(pair).output_radius == design(pair).gears.planet.base_radius
    p = lin.system.params
    cb = math.cos(p.base_helix_angle_rad)
    force = pair.load_case.load_torque_nm / (p.planet.radius_m * cb)
    te = (force / (p.sun_mesh_stiffness_n_per_m * cb)
          + force * cb * (1.0 / p.sun.bearing_stiffness_n_per_m + 1.0 / p.planet.bearing_stiffness_n_per_m))
    op = lin.operating(pair.load_case.input_speed_rad_s * 60.0 / (2.0 * math.pi))
    assert op.mesh_names == ("outer_mesh_force_1_n",)
    assert float(op.te @ lin.static) == pytest.approx(te, rel=EXACT)
    assert float(op.f0[0]) == pytest.approx(force, rel=EXACT)


def _bearing(radial: float, tilt: float, z: float, damping_per_stiffness: float = 0.0) -> BearingElement:
    return BearingElement.axisymmetric("shaft", radial, 0.1 * radial, tilt, damping_per_stiffness, (0.0, 0.0, z))


def test_two_bearings_condense_by_the_lever_rule():
    """No tilt stiffness: k = (a + b)^2 / (b^2 / k_1 + a^2 / k_2) (module docstring); symmetric and equal: 2 k_r;
    the damping entries condense alike (c K for stiffness-proportional damping)."""
    k1, k2, a, b, c = 3.0e8, 5.0e8, 0.04, 0.07, 1e-5
    pair_of = [_bearing(k1, 0.0, -a, c), _bearing(k2, 0.0, b, c)]
    lever = (a + b) ** 2 / (b**2 / k1 + a**2 / k2)
    assert condensed_radial_stiffness_of(pair_of) == pytest.approx(lever, rel=1e-12)
    assert condensed_radial_damping_of(pair_of) == pytest.approx(c * lever, rel=1e-12)
    assert condensed_radial_stiffness_of([_bearing(k1, 0.0, -a), _bearing(k1, 0.0, a)]) == pytest.approx(2 * k1,
                                                                                                        rel=1e-12)
    # the gear point elsewhere on the shaft: the same rule with the distances measured from it
    shifted = [_bearing(k1, 0.0, -a + 0.01), _bearing(k2, 0.0, b + 0.01)]
    assert condensed_radial_stiffness_of(shifted, gear_z=0.01) == pytest.approx(lever, rel=1e-12)


def test_two_bearings_with_tilt_stiffness_condense_as_their_six_by_six_matrices():
    """With tilt stiffness: each bearing's 6 x 6 moved to the gear point (K' = T^T K T, flexgear.geometry.elements
    .lever_rows), summed, the in-plane (u_x, phi_y) block inverted: k = 1 / C_uu (a force, no moment)."""
    bearings = [_bearing(3.0e8, 2.0e5, -0.075), _bearing(3.0e8, 2.0e5, 0.037)]
    total = np.zeros((6, 6))
    for br in bearings:
        t = lever_rows(br.centre)  # d = centre - gear point, the gear at the origin
        total += t.T @ br.stiffness @ t
    block = total[np.ix_([0, 4], [0, 4])]
    assert condensed_radial_stiffness_of(bearings) == pytest.approx(1.0 / np.linalg.inv(block)[0, 0], rel=1e-12)


@pytest.mark.parametrize("tilt", [2.0e5, 0.0])
def test_one_bearing_reduces_to_the_single_bearing_rule(tilt):
    """One bearing: 1/k = 1/k_r + L^2/k_t, BearingElement.condensed_radial_stiffness (k_t = 0, L != 0: 0)."""
    br = _bearing(3.0e8, tilt, -0.075, 1e-5)
    expected = 0.0 if tilt == 0.0 else 1.0 / (1.0 / 3.0e8 + 0.075**2 / tilt)
    assert condensed_radial_stiffness_of([br]) == pytest.approx(expected, rel=1e-12, abs=1e-6)
    assert condensed_radial_stiffness_of([br]) == pytest.approx(br.condensed_radial_stiffness(), rel=1e-12, abs=1e-6)
    assert condensed_radial_damping_of([br]) == pytest.approx(br.condensed_radial_damping(), rel=1e-12, abs=1e-12)


def test_the_pairs_shafts_sit_on_both_their_bearings(pair):
    """from_spec: pinion and wheel each on its two Table 2 bearings at their seats, condensed together (hand 2 x 2
    condensation); ring and carrier held with no mass and no mesh."""
    d = design(pair)
    p = LumpedParameters.from_spec(d)
    for member, shaft in ((p.sun, "input_shaft"), (p.planet, "output_shaft")):
        seats = [d.supports[shaft], d.supports[shaft + "_near"]]
        k_r, _, k_t = seats[0].axisymmetric_entries()
        levers = [float(s.centre[2]) for s in seats]
        assert levers[0] * levers[1] < 0.0  # the bearings straddle the gear
        kuu, kup, kpp = 2 * k_r, k_r * sum(levers), k_r * sum(v**2 for v in levers) + 2 * k_t
        assert member.bearing_stiffness_n_per_m == pytest.approx(kuu - kup**2 / kpp, rel=1e-12)
    for held in (p.ring, p.carrier):
        assert held.mass_kg == 0.0 and math.isinf(held.bearing_stiffness_n_per_m)
    assert p.mesh_count == 1 and assemble(p).mesh_G.shape[0] == 1
    assert p.carrier.radius_m == d.gears.centre_distance


def test_the_star_keeps_its_single_bearing_supports():
    """The star (model_variants/quick/model1.toml): sun and ring on their one bearing each, 1/k = 1/k_r + L^2/k_t
    (the gear at z = 0); both meshes per planet."""
    spec = load_variant(STAR).gearbox
    d = design(spec)
    p = LumpedParameters.from_spec(d)
    for member, seat in ((p.sun, "input_shaft"), (p.ring, "output_shaft")):
        k_r, _, k_t = d.supports[seat].axisymmetric_entries()
        lever = float(d.supports[seat].centre[2])
        assert member.bearing_stiffness_n_per_m == pytest.approx(1.0 / (1.0 / k_r + lever**2 / k_t), rel=1e-12)
    assert p.ring_meshes and assemble(p).mesh_G.shape[0] == 2 * p.planet_count
