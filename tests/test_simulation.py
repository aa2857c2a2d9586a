"""The facade (flexgear.Simulation): a gearbox file and its flexible components in, a run out, for both
arrangements; the run meets loss-free theory (ratio -z_s/z_r for the star, z_s/(z_s + z_r) for the planetary)."""

from __future__ import annotations

from pathlib import Path

import pytest

import flexgear as fg

ROOT = Path(__file__).resolve().parents[1]


def test_a_rigid_star_from_its_gearbox_file_in_two_lines():
    sim = fg.Simulation.from_gearbox(ROOT / "examples" / "spur_star" / "gearbox.toml", rigid_mass_properties="exact")
    run = sim.run(t_end_s=0.06)
    late = run.signals[run.signals.time_s >= 0.04]
    assert sim.theory.ratio == pytest.approx(-24 / 84, rel=1e-12)
    assert late.transmission_ratio.mean() == pytest.approx(-24 / 84, rel=1e-3)


def test_the_planetary_arrangement_through_the_facade():
    sim = fg.Simulation.from_gearbox(ROOT / "model_variants" / "gearbox.toml", rigid_mass_properties="exact")
    sim = sim.with_gearbox("gears", arrangement="planetary").with_gearbox("load_case", ramp_time_s=0.02)
    run = sim.run(t_end_s=0.1)
    late = run.signals[run.signals.time_s >= 0.07]
    assert late.transmission_ratio.mean() == pytest.approx(44 / 180, rel=1e-3)
    lumped = sim.lumped(t_end_s=0.1).signals
    assert lumped[lumped.time_s >= 0.07].transmission_ratio.mean() == pytest.approx(44 / 180, rel=1e-3)


def test_unknown_components_and_levels_are_named():
    path = ROOT / "examples" / "spur_star" / "gearbox.toml"
    with pytest.raises(fg.SpecError, match="components.carrier"):
        fg.Simulation.from_gearbox(path, flexible=("carrier",))
    with pytest.raises(fg.SpecError, match="mesh_level"):
        fg.Simulation.from_gearbox(path, mesh_level="fine")
