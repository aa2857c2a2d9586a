"""The example study with another gear set (examples/spur_star/): a spur star stage whose gearbox file gives only its
gear data, bearings and load case, every other value following the gear set (flexgear.sizing).

- ``flexgear matrix`` of its rigid and all-flexible variants at the coarse level: the mean ratio of the settled
  half within 1e-3 of -z_s / z_r, every planet's mean mesh force within 1 % of loss-free hand theory
  F_n = T_sun / (N r_b,sun cos beta_b), T_sun = T_ring z_s / z_r (tooth friction mu = 0.02 moves the mean forces
  by a few tenths of a percent);
- its flexible spur ring, held on its bolts' clamped discs as the rigid output shaft holds it, against the ring's
  full FE model: every clamped mode below 3x the mesh frequency within 1 %, the compliance under the mesh loads
  (the contact kernel's loads at every contact of the ring) within 2 %.

Every body is built in the examples' cache (conftest.example_cache), coarse meshes (about two minutes of CPU in all).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import flexgear as fg

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "spur_star"


@pytest.fixture(scope="module")
def gearbox():
    return fg.load_gearbox(EXAMPLE / "gearbox.toml")


def _hand_mesh_force(spec) -> float:
    """F_n = T_sun / (N r_b cos beta_b) [N], r_b = m_n z_s cos(alpha_t) / (2 cos beta) (independent of the shift)."""
    g = spec.gears
    beta, alpha_n = math.radians(g.helix_angle_deg), math.radians(g.normal_pressure_angle_deg)
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    r_b = g.normal_module_mm * 1e-3 * g.sun_teeth * math.cos(alpha_t) / (2 * math.cos(beta))
    beta_b = math.asin(math.sin(beta) * math.cos(alpha_n))
    t_sun = spec.load_case.load_torque_nm * g.sun_teeth / g.ring_teeth
    return t_sun / (g.planet_count * r_b * math.cos(beta_b))


def test_the_example_file_gives_only_gears_bearings_and_load_case(gearbox):
    import tomllib

    raw = tomllib.loads((EXAMPLE / "gearbox.toml").read_text())
    assert set(raw) == {"title", "gears", "bearings", "load_case"}
    assert gearbox.gears.helix_angle_deg == 0.0 and gearbox.contact.law == "iso6336"
    assert "components_assumed.ring_rim_thickness_mm" in gearbox.derived


def test_rigid_and_all_flexible_variants_meet_hand_theory(tmp_path, example_cache, gearbox):
    from flexgear.cli import main
    from flexgear.results import load_result

    variants = [str(EXAMPLE / f"{name}.toml") for name in ("rigid", "flexible")]
    assert main(["matrix", *variants, "--out", str(tmp_path / "out")]) == 0
    g = gearbox.gears
    force = _hand_mesh_force(gearbox)
    half = 0.5 * (gearbox.load_case.ramp_time_s + gearbox.load_case.end_time_s)
    for name in ("rigid", "flexible"):
        s = load_result(tmp_path / "out" / name).signals
        late = s[s.time_s >= half]
        assert late.transmission_ratio.mean() == pytest.approx(-g.sun_teeth / g.ring_teeth, rel=1e-3), name
        forces = late[[f"{mesh}_mesh_force_{i}_n" for mesh in ("outer", "inner")
                       for i in range(1, g.planet_count + 1)]].mean()
        np.testing.assert_allclose(forces, force, rtol=0.01, err_msg=name)


@pytest.mark.heavy  # the ring's own reduction and its full FE factorisation and modes: make test-heavy
def test_flexible_spur_ring_against_its_full_fe_model(example_cache, gearbox):
    from test_rigid_partner import ring_against_full_fe

    n = ring_against_full_fe(gearbox, 12)
    assert 4 <= n < 12  # the ring's lowest bending pairs lie in the band (measured: 5.3-5.6 kHz below 7.2 kHz)
