"""The planetary arrangement through ``flexgear run`` (flexgear.mbs.planetary): the study's gear set with the ring
fixed and the carrier as output, every component rigid.

Loss-free hand theory, independent of the package: carrier / sun speed z_s / (z_s + z_r); the sun's torque
T_sun = T_carrier z_s / (z_s + z_r) shared by N planets, F_n = T_sun / (N r_b,sun cos beta_b) on every sun-planet
and planet-ring mesh (the planet is in moment balance about its pin), r_b = m_n z cos(alpha_t) / (2 cos beta).
Tooth friction (mu = 0.02) moves the mean forces by a few tenths of a percent: 1 % on forces.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from test_validation import to_toml

from flexgear.spec import load_variant

VARIANTS = Path(__file__).resolve().parents[1] / "model_variants"


def _planetary(tmp_path: Path, form: str = "rigid") -> Path:
    data = tomllib.loads((VARIANTS / "gearbox.toml").read_text())
    data["gears"]["arrangement"] = "planetary"
    data["load_case"].update(ramp_time_s=0.02, end_time_s=0.12)
    (tmp_path / "gearbox.toml").write_text(to_toml(data))
    components = dict.fromkeys(("input_shaft", "sun", "planets", "ring", "output_shaft"), "rigid")
    components["sun"] = form
    variant = {"name": "model1", "gearbox": "gearbox.toml", "mesh_level": "coarse", "rigid_mass_properties": "exact",
               "components": components}
    (tmp_path / "model1.toml").write_text(to_toml(variant))
    return tmp_path / "model1.toml"


def test_rigid_planetary_meets_hand_theory(tmp_path):
    from flexgear.cli import main
    from flexgear.results import load_result

    path = _planetary(tmp_path)
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 0
    spec = load_variant(path).gearbox
    g = spec.gears
    zs, zr, n = g.sun_teeth, g.ring_teeth, g.planet_count
    s = load_result(tmp_path / "out" / "model1").signals
    late = s[s.time_s >= 0.08]
    assert late.transmission_ratio.mean() == pytest.approx(zs / (zs + zr), rel=1e-3)
    beta, alpha_n = math.radians(g.helix_angle_deg), math.radians(g.normal_pressure_angle_deg)
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    r_b = g.normal_module_mm * 1e-3 * zs * math.cos(alpha_t) / (2 * math.cos(beta))
    beta_b = math.asin(math.sin(beta) * math.cos(alpha_n))
    force = spec.load_case.load_torque_nm * zs / (zs + zr) / (n * r_b * math.cos(beta_b))
    forces = late[[f"{mesh}_mesh_force_{i}_n" for mesh in ("outer", "inner") for i in range(1, n + 1)]].mean()
    np.testing.assert_allclose(forces, force, rtol=0.01)
    assert np.ptp(forces.to_numpy()[:n]) < 1e-3 * force  # equal load sharing


def test_spur_planetary_example_against_hand_theory_and_the_lumped_model(tmp_path):
    """examples/spur_planetary (24/30/84, 3 planets, only gears, bearings and load case given): the multibody
    run's ratio and mean mesh forces against hand theory (1e-3, 1 %) and against the lumped model (eq. 1-13) run
    alike (its mean mesh forces within 1 %)."""
    from flexgear.cli import main
    from flexgear.results import load_result

    example = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary"
    assert main(["matrix", str(example / "rigid.toml"), "--out", str(tmp_path)]) == 0
    assert main(["lpm", str(example / "rigid.toml"), "--out", str(tmp_path)]) == 0
    spec = load_variant(example / "rigid.toml").gearbox
    t_sun = spec.load_case.load_torque_nm * 24 / 108
    r_b = 3e-3 * 24 * math.cos(math.radians(20.0)) / 2
    force = t_sun / (3 * r_b)
    means = {}
    for name in ("rigid", "lumped"):
        s = load_result(tmp_path / name).signals
        late = s[s.time_s >= 0.05]
        assert late.transmission_ratio.mean() == pytest.approx(24 / 108, rel=1e-3), name
        means[name] = late[[f"{m}_mesh_force_{i}_n" for m in ("outer", "inner") for i in (1, 2, 3)]].mean()
        np.testing.assert_allclose(means[name], force, rtol=0.01, err_msg=name)
    np.testing.assert_allclose(means["rigid"].to_numpy(), means["lumped"].to_numpy(), rtol=0.01)


def test_recorded_states_name_the_planetary_stages_geometries(tmp_path):
    """The bodies' geometries for the animation (flexgear.mbs.states.state_bodies): the ring held by the housing is
    the ring alone (never the star's tied ring and output shaft), the carrier carries its merged output shaft, the
    sun its merged input shaft."""
    import exudyn as exu

    from flexgear.mbs.assemble import build_gearbox
    from flexgear.mbs.states import state_bodies

    sc = exu.SystemContainer()
    model = build_gearbox(sc.AddSystem(), load_variant(_planetary(tmp_path)))
    bodies = state_bodies(model)
    assert bodies["ring"]["geometries"] == ["ring"] and bodies["carrier"]["geometries"] == ["output_shaft"]
    assert bodies["sun"]["geometries"] == ["sun", "input_shaft"] and bodies["planet1"]["geometries"] == ["planet"]
    sc.Reset()
