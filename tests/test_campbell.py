"""Campbell diagram of model 1 (all rigid; flexgear.modal.campbell_diagram) over a coarse speed grid.

- At zero speed the diagram is the modal analysis at rest.
- A crossing lies where a mode's frequency equals k f_m: the mode computed afresh at the crossing's speed is there
  within the linear interpolation's error (below the frequency's change over the grid interval, f monotone).
- Cyclic symmetry (Lin & Parker 1999; Eritenel & Parker 2009 for the 3D helical model): a planet mode moves every
  planet in one single-planet shape, weighted by c_i with sum c_i = sum c_i cos psi_i = sum c_i sin psi_i = 0 (the
  central members at rest feel no net force or moment), whatever that shape is. Each planet's gyroscopic terms
  (its own spin, the same for all planets) belong to the single-planet problem, so the N - 3 = 2 fold multiplicity
  holds at every speed: the planet pairs stay paired.
- Mesh phasing (Parker & Lin 2004): order k's mesh forces on the N planets are the phasors e^{i k z_s psi_i}; they
  excite a kind of mode where they have a component along its planet pattern: (1, ..., 1) for the rotational modes
  (net moment), e^{+-i psi_i} for the translational ones (net force), the rest for the planet modes.
- The central members' spin couples their two tilts (gyroscopic moment J_p Omega): a translational pair at rest
  (standing, degenerate) splits into a backward and a forward whirl, apart the more the faster they spin.
"""

import argparse

import numpy as np
import pandas as pd
import pytest
from conftest import VARIANTS

from flexgear.modal import campbell, linearize, mesh_frequency_hz, modes, resonant
from flexgear.modal.campbell_diagram import excited_kinds

SPEEDS_RPM = np.linspace(0.0, 6000.0, 7)


@pytest.fixture(scope="module")
def diagram(model1):
    return campbell(model1, SPEEDS_RPM)


def test_zero_speed_is_modes_at_rest(diagram, model1):
    at_rest = modes(linearize(model1, speed_rpm=0.0), diagram.f_max_hz)
    f = at_rest.frequencies_hz[resonant(at_rest)]
    rows = diagram.table[diagram.table.speed_rpm == 0.0]
    np.testing.assert_allclose(np.sort(rows.frequency_hz.to_numpy()), f, rtol=1e-9)
    assert f.size == len(at_rest)  # at rest every mode has a resonance peak


def test_one_line_per_mode_and_default_band(diagram, model1):
    per_speed = diagram.table.groupby("speed_rpm").size()
    assert per_speed.nunique() == 1  # every line spans the grid: all of model 1's modes lie in the band
    assert diagram.table.groupby("mode").size().eq(len(SPEEDS_RPM)).all()
    assert diagram.f_max_hz == pytest.approx(10 * mesh_frequency_hz(model1.gearbox, SPEEDS_RPM[-1]))
    assert diagram.mesh_hz_per_rpm == pytest.approx(model1.gearbox.gears.sun_teeth / 60.0)  # z_s n / 60


def test_crossings_at_mesh_orders(diagram, model1):
    c = diagram.crossings
    assert set(c.order) <= set(range(1, 11)) and len(c) > 0
    f_mesh = np.array([mesh_frequency_hz(model1.gearbox, n) for n in c.speed_rpm])
    np.testing.assert_allclose(c.frequency_hz, c.order * f_mesh, rtol=1e-9)
    first = c[c.order == 1].drop_duplicates("mode").head(4)  # a few, recomputed at their speeds
    for _, x in first.iterrows():
        line = diagram.table[diagram.table["mode"] == x["mode"]].set_index("speed_rpm").frequency_hz
        a = line.index[line.index <= x.speed_rpm].max()
        b = line.index[line.index >= x.speed_rpm].min()
        bound = abs(line[b] - line[a]) + 1e-9 * x.frequency_hz
        fresh = modes(linearize(model1, speed_rpm=x.speed_rpm), diagram.f_max_hz)
        f = fresh.frequencies_hz[resonant(fresh)]
        assert np.min(np.abs(f - x.order * mesh_frequency_hz(model1.gearbox, x.speed_rpm))) <= bound


def test_planet_pairs_stay_paired(diagram, model1):
    planets = diagram.table[diagram.table.kind == "planet"]
    counts = planets.groupby("speed_rpm").size()
    n = model1.gearbox.gears.planet_count
    assert len(counts) == len(SPEEDS_RPM) and counts.nunique() == 1 and counts.iloc[0] % (n - 3) == 0
    for _, rows in planets.groupby("speed_rpm"):
        f = np.sort(rows.frequency_hz.to_numpy()).reshape(-1, n - 3)
        np.testing.assert_allclose(f[:, 1:], f[:, :1], rtol=1e-3)


def test_translational_pair_splits_with_speed(diagram):
    rest = diagram.table[(diagram.table.speed_rpm == 0.0) & (diagram.table.kind == "translational")]
    lowest = rest.nsmallest(2, "frequency_hz")
    f0 = lowest.frequency_hz.to_numpy()
    assert f0[1] - f0[0] <= 1e-4 * f0[0]  # a degenerate pair at rest
    lines = diagram.table[diagram.table["mode"].isin(lowest["mode"])]
    split = lines.groupby("speed_rpm").frequency_hz.agg(lambda f: f.max() - f.min())
    assert split.index.tolist() == SPEEDS_RPM.tolist()
    assert np.all(np.diff(split.to_numpy()) > 0.0)


def test_campbell_command_writes_files(tmp_path, capsys):
    from flexgear.modal.cli import CAMPBELL, add_parsers

    variant = tmp_path / "model1_exact.toml"  # model 1 on the exact geometry's mass properties: no meshes
    text = (VARIANTS / "model1.toml").read_text().replace('name = "model1"', 'name = "model1_exact"')
    text = text.replace('gearbox = "gearbox.toml"', f'gearbox = "{(VARIANTS / "gearbox.toml").as_posix()}"')
    variant.write_text(text.replace('mesh_level = "coarse"', 'rigid_mass_properties = "exact"'))
    parser = argparse.ArgumentParser(prog="flexgear")
    add_parsers(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args([CAMPBELL[0], str(variant), "--speeds-rpm", "0:6000:3000", "--f-max-hz", "2000",
                              "--out", str(tmp_path / "out")])
    assert args.speeds_rpm == [0.0, 3000.0, 6000.0]
    assert args.func(args) == 0
    out = tmp_path / "out" / "model1_exact"
    table = pd.read_csv(out / "campbell.csv")
    assert list(table.columns[:4]) == ["speed_rpm", "mode", "frequency_hz", "damping_ratio"]
    assert table.frequency_hz.max() <= 2000 and set(table.speed_rpm) == {0.0, 3000.0, 6000.0}
    crossings = pd.read_csv(out / "crossings.csv")
    assert list(crossings.columns[:4]) == ["speed_rpm", "order", "mode", "kind"]
    assert (out / "campbell.png").stat().st_size > 0
    assert "crossings" in capsys.readouterr().out


@pytest.mark.parametrize(("sun_teeth", "planets"), [(44, 5), (30, 3), (33, 4), (41, 6), (27, 7)])
def test_mesh_phasing_rule_from_the_phasors(sun_teeth, planets):
    psi = 2 * np.pi * np.arange(planets) / planets
    for k in range(1, 11):
        p = np.exp(1j * k * sun_teeth * psi)
        patterns = np.stack([np.ones(planets), np.exp(1j * psi), np.exp(-1j * psi)], 1) / np.sqrt(planets)
        along = patterns.conj().T @ p
        rest = np.linalg.norm(p - patterns @ along)
        expected = ({"rotational"} if abs(along[0]) > 1e-9 else set()) | (
            {"translational"} if np.max(np.abs(along[1:])) > 1e-9 else set()) | ({"planet"} if rest > 1e-9 else set())
        assert excited_kinds(k, sun_teeth, planets) == expected, (k, sun_teeth, planets)


def test_crossings_carry_damping_and_excitation(diagram, model1):
    c = diagram.crossings
    for _, x in c.head(20).iterrows():
        line = diagram.table[diagram.table["mode"] == x["mode"]]
        assert line.damping_ratio.min() - 1e-12 <= x.damping_ratio <= line.damping_ratio.max() + 1e-12
    g = model1.gearbox.gears
    for _, x in c.iterrows():
        assert x.excited == (x.kind in excited_kinds(int(x.order), g.sun_teeth, g.planet_count)
                             or x.kind not in ("rotational", "translational", "planet"))
    assert set(c[(c.order == 1) & c.excited].kind) <= {"translational", "mixed"}  # 44 = -1 mod 5
