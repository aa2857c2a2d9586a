"""Command line: help on every argument, compare (run or results folders, load-case guard, --out),
run (ramp warning, inputs saved), one-line errors."""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import pandas as pd
import pytest
from synthetic import synthetic_result

from flexgear.cli import SUBCOMMANDS, _parser, main
from flexgear.results import load_result, save_result

VARIANTS = Path(__file__).resolve().parents[1] / "model_variants"


def test_every_argument_has_help_text_and_no_markup():
    parser = _parser()
    assert "`" not in parser.format_help()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert set(sub.choices) == {name for name, *_ in SUBCOMMANDS}
    for name, p in sub.choices.items():
        for action in p._actions:
            assert action.help, f"{name} {action.dest}: no help text"


def _results(folder: Path, names: list[str], **meta) -> Path:
    for n in names:
        r = synthetic_result(n, {"outer_mesh_force": 0.01}, {})
        r.meta.update(meta)
        save_result(r, folder / n)
    return folder


def test_compare_run_folders_writes_its_tables(tmp_path, capsys):
    a, b = _results(tmp_path / "A", ["m1"]), _results(tmp_path / "B", ["m1"])
    assert main(["compare", str(a / "m1"), str(b / "m1"), "--out", str(tmp_path / "t")]) == 0
    t6 = pd.read_csv(tmp_path / "t" / "m1_vs_m1_table6.csv")
    assert t6.shape[0] >= 5 and (tmp_path / "t" / "m1_vs_m1_table7.parquet").exists()
    # results folders: every common run
    assert main(["compare", str(a), str(b), "--out", str(tmp_path / "u")]) == 0
    assert (tmp_path / "u" / "m1_table6.csv").exists()


def test_compare_refuses_unequal_load_cases(tmp_path, capsys):
    a = _results(tmp_path / "A", ["m1"], t_end_s=0.6)
    b = _results(tmp_path / "B", ["m1"], t_end_s=0.05)
    assert main(["compare", str(a / "m1"), str(b / "m1")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "end time [s] 0.6 vs 0.05" in err
    assert main(["compare", str(a / "m1"), str(b / "m1"), "--allow-unequal"]) == 0
    assert "warning" in capsys.readouterr().err


def test_compare_takes_two_settled_runs_whatever_their_end_times(tmp_path):
    """Runs continued until they settled end where each settles: the same load case all the same."""
    a = _results(tmp_path / "A", ["m1"], t_end_s=0.2028, settled=True)
    b = _results(tmp_path / "B", ["m1"], t_end_s=0.2034, settled=True)
    assert main(["compare", str(a / "m1"), str(b / "m1")]) == 0
    c = _results(tmp_path / "C", ["m1"], t_end_s=0.2034, settled=True, ramp_time_s=0.05)
    assert main(["compare", str(a / "m1"), str(c / "m1")]) == 2  # a load case that differs is still refused


def test_compare_names_a_wrong_folder_in_one_line(tmp_path, capsys):
    assert main(["compare", str(tmp_path), str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(tmp_path) in err and "run folder" in err


def test_a_computation_that_fails_ends_in_one_line(monkeypatch, capsys):
    """A solver that gives up (Exudyn's errors are RuntimeErrors) ends the command with exit code 1 and one line
    naming it, not a traceback."""
    import exudyn

    import flexgear.modal.period

    def fails(*args, **kwargs):
        raise exudyn.SolverError("SolveStatic terminated due to errors\n  more")

    monkeypatch.setattr(flexgear.modal.period, "period_modes", fails)
    assert main(["modes", str(VARIANTS / "model1.toml")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: SolverError: SolveStatic terminated due to errors more")


def test_run_warns_inside_the_ramps_and_saves_its_inputs(tmp_path, capsys):
    pytest.importorskip("exudyn")
    shutil.copy(VARIANTS / "gearbox.toml", tmp_path / "gearbox.toml")
    v = tmp_path / "m1.toml"
    v.write_text('rigid_mass_properties = "exact"\n' + (VARIANTS / "model1.toml").read_text())
    assert main(["run", str(v), "--t-end", "0.002", "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "warning" in err and "inside the load ramps" in err and "\r" not in err
    saved = load_result(tmp_path / "out" / "model1")
    assert saved.ok and saved.signals["time_s"].iloc[-1] == pytest.approx(0.002)
    assert (tmp_path / "out" / "model1" / "inputs" / "m1.toml").read_text() == v.read_text()
    assert (tmp_path / "out" / "model1" / "inputs" / "gearbox.toml").exists()
