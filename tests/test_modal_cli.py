"""``flexgear modes`` (flexgear.modal.cli): the table on stdout and OUT/<variant>/modes.csv."""

import argparse

import numpy as np
import pandas as pd
from conftest import VARIANTS

from flexgear.modal.cli import add_parsers


def test_modes_command_writes_table(tmp_path, capsys):
    variant = tmp_path / "model1_exact.toml"
    variant.write_text(f'name = "model1_exact"\ngearbox = "{(VARIANTS / "gearbox.toml").as_posix()}"\n'
                       'rigid_mass_properties = "exact"\n[components]\ninput_shaft = "rigid"\nsun = "rigid"\n'
                       'planets = "rigid"\nring = "rigid"\noutput_shaft = "rigid"\n')
    parser = argparse.ArgumentParser(prog="flexgear")
    add_parsers(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["modes", str(variant), "--speed-rpm", "0", "--f-max-hz", "3000",
                              "--out", str(tmp_path / "out")])
    assert args.func(args) == 0
    table = pd.read_csv(tmp_path / "out" / "model1_exact" / "modes.csv")
    head = ["mode", "frequency_hz", "damping_ratio", "kind", "spread_pct", "multiplicity", "split_pct"]
    assert list(table.columns[:7]) == head
    assert (table.spread_pct == 0.0).all()  # rigid gears: the matrices do not depend on their angles
    components = ["input_shaft", "sun", *(f"planet_{i}" for i in range(1, 6)), "ring", "output_shaft"]
    for family in ("kinetic", "strain"):
        assert all(f"{family}_{c}" in table.columns for c in components)
        np.testing.assert_allclose(table.filter(regex=f"^{family}_").sum(axis=1), 1.0, atol=1e-9)
    assert table.frequency_hz.is_monotonic_increasing and table.frequency_hz.max() <= 3000
    assert {"planet", "rotational", "translational"} <= set(table.kind)
    out = capsys.readouterr().out
    assert out.count("\n") == len(table) + 3
