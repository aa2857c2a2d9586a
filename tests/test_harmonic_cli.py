"""``flexgear sweep-speed`` (flexgear.harmonic.cli): the table and one PNG per indicator."""

import argparse

import pandas as pd

from flexgear.harmonic.cli import SWEEP_SPEED


def test_sweep_speed_writes_table_and_plots(tmp_path, capsys):
    name, _, add_args, cmd = SWEEP_SPEED
    assert name == "sweep-speed"
    parser = argparse.ArgumentParser()
    add_args(parser)
    args = parser.parse_args(["model_variants/model1.toml", "--speeds-rpm", "1000:3000:1000", "--harmonics", "3",
                              "--lumped", "--out", str(tmp_path)])
    assert cmd(args) == 0
    out = tmp_path / "model1" / "sweep_speed_lumped"
    table = pd.read_csv(out / "response.csv")
    assert sorted(table["speed_rpm"].unique()) == [1000.0, 2000.0, 3000.0]
    assert set(table["harmonic"]) == {0, 1, 2, 3}
    for indicator in table["indicator"].unique():
        assert (out / f"{indicator}.png").stat().st_size > 0
    assert "K_v max" in capsys.readouterr().out
