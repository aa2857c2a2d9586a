"""The single-helical example study (examples/helical_star4/): a star stage 27/37/101 with four planets, normal module
2.5 mm, one helix of 18 deg, whose gearbox file gives only its gear data, helix layout, bearings and load case.

- ``flexgear run`` of its rigid and flexible-gears variants (sun and planets reduced from their coarse meshes) with
  the bodies' states recorded: the mean ratio of the settled half within 1e-3 of -z_s / z_r, every planet's mean
  mesh force within 1 % of loss-free hand theory F_n = T_sun / (N r_b,sun cos beta_b), T_sun = T_ring z_s / z_r
  (tooth friction mu = 0.02 moves the mean forces by a few tenths of a percent), the four planets' mean forces
  within 0.1 % of each other;
- what the helix adds: the axial mesh force. Per planet F_a = F_t tan(beta) with F_t = T_sun / (N r_sun) at the
  sun's reference (here also its operating pitch) radius, = F_n sin(beta_b) (489.5 N). The signals hold normal
  forces only, so the axial force is measured where it goes: the input bearing carries the sun's N F_a, the output
  bearing the ring's -N F_a (reaction k_a u_z of the mean axial displacement u_z [m] of the rigid body carrying
  the bearing, k_a [N/m] its axial stiffness), each within 1 % of hand theory; each planet's axial forces from sun
  and ring cancel (its bearing's axial reaction below 1 % of F_a).

The settled half still holds a lightly damped rotational-axial oscillation (the ring turning while sun and ring
slide against their axial bearings, 278 and 373 Hz, damping ratio about 1 %): the window means of the axial
reactions move by a few tenths of a percent with the window, hence 1 %.

The all-flexible variant (the ring and output shaft reduced together, about four minutes of CPU to build) is
checked the same way. Every body is built in the examples' cache, coarse meshes.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import flexgear as fg

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "helical_star4"
STATES_EVERY = 2
"""Steps between two recorded body states (37 us at the example's step: 72 samples per 373 Hz period)."""


@pytest.fixture(scope="module")
def gearbox():
    return fg.load_gearbox(EXAMPLE / "gearbox.toml")


def _hand_forces(spec) -> tuple[float, float]:
    """Loss-free (normal, axial) mesh force per planet [N]: F_n = T_sun / (N r_b cos beta_b) with
    r_b = m_n z_s cos(alpha_t) / (2 cos beta) and sin(beta_b) = sin(beta) cos(alpha_n); F_a = F_t tan(beta),
    F_t = T_sun / (N r), r = m_n z_s / (2 cos beta) the sun's reference radius (both independent of the shift)."""
    g = spec.gears
    beta, alpha_n = math.radians(g.helix_angle_deg), math.radians(g.normal_pressure_angle_deg)
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    r = g.normal_module_mm * 1e-3 * g.sun_teeth / (2 * math.cos(beta))
    beta_b = math.asin(math.sin(beta) * math.cos(alpha_n))
    t_sun = spec.load_case.load_torque_nm * g.sun_teeth / g.ring_teeth
    normal = t_sun / (g.planet_count * r * math.cos(alpha_t) * math.cos(beta_b))
    axial = t_sun / (g.planet_count * r) * math.tan(beta)
    return normal, axial


def _axial_reaction(result, geometry: str, stiffness: float, start: float) -> float:
    """Mean axial force [N] on the bearing of the rigid body that carries ``geometry`` (or is named so, "planet2")
    after ``start`` [s]:
    ``stiffness`` [N/m] times its frame's mean axial displacement from the start of the run."""
    bodies = result.meta["state_bodies"]
    (body,) = [b for b, entry in bodies.items() if geometry in entry["geometries"] or b == geometry]
    assert not bodies[body]["flexible"], body
    states = result.extra["states"]
    z = states[f"{body}_pz_m"].to_numpy()
    return stiffness * float(z[states.time_s.to_numpy() >= start].mean() - z[0])


def _check_ratio_and_mesh_forces(result, gearbox, name: str) -> np.ndarray:
    """The settled half's ratio and mean mesh forces against hand theory; returns the forces [N] (outer, inner)."""
    g, lc = gearbox.gears, gearbox.load_case
    s = result.signals
    late = s[s.time_s >= 0.5 * (lc.ramp_time_s + lc.end_time_s)]
    assert late.transmission_ratio.mean() == pytest.approx(-g.sun_teeth / g.ring_teeth, rel=1e-3), name
    forces = np.array([[late[f"{mesh}_mesh_force_{i}_n"].mean() for i in range(1, g.planet_count + 1)]
                       for mesh in ("outer", "inner")])
    np.testing.assert_allclose(forces, _hand_forces(gearbox)[0], rtol=0.01, err_msg=name)
    return forces


def test_the_example_file_gives_gears_helix_layout_bearings_and_load_case(gearbox):
    import tomllib

    raw = tomllib.loads((EXAMPLE / "gearbox.toml").read_text())
    assert set(raw) == {"title", "gears", "gears_assumed", "bearings", "load_case"}
    assert raw["gears_assumed"] == {"helix_layout": "single"}
    g = gearbox.gears
    assert g.planet_count == 4 and g.helix_angle_deg == 18.0 and gearbox.gears_assumed.helix_layout == "single"
    assert (g.sun_teeth + g.ring_teeth) % g.planet_count == 0  # equally spaced planets
    assert gearbox.contact.law == "iso6336" and "gears_assumed.face_width_mm" in gearbox.derived


@pytest.mark.slow  # two reductions and two runs: about half a minute of CPU
def test_rigid_and_flexible_gears_variants_meet_hand_theory(tmp_path, example_cache, gearbox):
    from flexgear.cli import main
    from flexgear.results import load_result

    lc, b, n = gearbox.load_case, gearbox.bearings, gearbox.gears.planet_count
    _, axial = _hand_forces(gearbox)
    half = 0.5 * (lc.ramp_time_s + lc.end_time_s)
    for name in ("rigid", "flexible_gears"):
        out = tmp_path / "out"
        assert main(["run", str(EXAMPLE / f"{name}.toml"), "--out", str(out), "--states", str(STATES_EVERY)]) == 0
        result = load_result(out / name)
        assert result.meta["status"] == "ok", result.meta["reason"]
        forces = _check_ratio_and_mesh_forces(result, gearbox, name)
        # the four planets share the load equally (equal spacing, no errors): within 0.1 % of each other
        assert np.ptp(forces, axis=1).max() < 1e-3 * forces.mean(), name
        # the helix's axial forces: the sun's N F_a on the input bearing, the ring's -N F_a on the output bearing
        sun = _axial_reaction(result, "input_shaft", b.input_shaft.axial_stiffness_n_per_m, half)
        ring = _axial_reaction(result, "output_shaft", b.output_shaft.axial_stiffness_n_per_m, half)
        assert sun / n == pytest.approx(axial, rel=0.01), name
        assert -ring / n == pytest.approx(axial, rel=0.01), name
        # each rigid planet's axial forces from sun and ring cancel (what is left comes from tooth friction)
        for i in range(1, n + 1) if not result.meta["state_bodies"]["planet1"]["flexible"] else ():
            planet = _axial_reaction(result, f"planet{i}", b.planet.axial_stiffness_n_per_m, half)
            assert abs(planet) < 0.01 * axial, (name, i)


@pytest.mark.slow  # the tied ring and output shaft's reduction: about four minutes of CPU
def test_all_flexible_variant_meets_hand_theory(tmp_path, example_cache, gearbox):
    from flexgear.cli import main
    from flexgear.results import load_result

    assert main(["matrix", str(EXAMPLE / "flexible.toml"), "--out", str(tmp_path / "out")]) == 0
    forces = _check_ratio_and_mesh_forces(load_result(tmp_path / "out" / "flexible"), gearbox, "flexible")
    assert np.ptp(forces, axis=1).max() < 1e-3 * forces.mean()
