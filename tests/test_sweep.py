"""Sweeps: a grid of two face widths x two variants runs, resumes after SIGKILL, and is tabulated and reported."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from synthetic import fake_runner

from flexgear.spec import SpecError, load_gearbox, load_variant
from flexgear.study.sweep import load_sweep, run_sweep, sweep_points, write_variants

ROOT = Path(__file__).resolve().parents[1]


def _sweep_file(tmp_path: Path, extra: str = "") -> Path:
    path = tmp_path / "fw.toml"
    quick = ROOT / "model_variants" / "quick"
    path.write_text(f'variants = ["{quick / "model1.toml"}", "{quick / "model4.toml"}"]\n{extra}\n'
                    '[parameters]\n"gears_assumed.face_width_mm" = [20.0, 40.0]\n')
    return path


def test_grid_product_zip_and_all_combinations(tmp_path):
    plan = load_sweep(_sweep_file(tmp_path))
    assert sweep_points(plan) == [{"gears_assumed.face_width_mm": 20.0}, {"gears_assumed.face_width_mm": 40.0}]
    paths, rows = write_variants(plan, tmp_path / "out")
    assert [r["variant"] for r in rows] == ["model1__face_width_mm_20", "model1__face_width_mm_40",
                                            "model4__face_width_mm_20", "model4__face_width_mm_40"]
    v = load_variant(paths[3])
    assert v.gearbox.gears_assumed.face_width_mm == pytest.approx(40.0)
    assert v.gearbox.load_case.ramp_time_s == pytest.approx(0.02)        # the base's own overrides are kept
    assert v.gearbox.load_case.end == "settled"
    assert v.components["sun"] == "flexible" and v.components["input_shaft"] == "rigid"
    combos = load_sweep(_sweep_file(tmp_path), all_combinations=True)
    paths, rows = write_variants(combos, tmp_path / "all")
    assert len(paths) == 2 * 32 * 2
    assert {load_variant(p).components["ring"] for p in paths[:64]} == {"rigid", "flexible"}
    zipped = tmp_path / "zip.toml"
    zipped.write_text(f'variants = ["{ROOT / "model_variants/quick/model1.toml"}"]\ngrid = "zip"\n[parameters]\n'
                      '"gears_assumed.face_width_mm" = [20.0, 40.0]\n"contact.stiffness" = [5e7, 1e8]\n')
    assert len(sweep_points(load_sweep(zipped))) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text(f'variants = ["{ROOT / "model_variants/quick/model1.toml"}"]\n[parameters]\n'
                   '"gears_assumed.face_width_mm" = [-5.0]\n')
    with pytest.raises(SpecError, match="face_width_mm"):
        write_variants(load_sweep(bad), tmp_path / "bad")


def test_sweep_runs_resumes_after_sigkill_and_appears_in_the_report(tmp_path):
    sweep = _sweep_file(tmp_path)
    out = tmp_path / "out"
    code = ("import sys; from synthetic import slow_runner; from flexgear.study.sweep import load_sweep, run_sweep; "
            f"run_sweep(load_sweep({str(sweep)!r}), {str(out)!r}, workers=1, runner=slow_runner, progress=False)")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "tests"), str(ROOT)]))
    proc = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, env=env, process_group=0)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not list(out.glob("*/run.json")):
        time.sleep(0.1)
    os.killpg(proc.pid, signal.SIGKILL)                  # the sweep and its worker die mid-way
    proc.wait()
    done_before = {p.parent.name for p in out.glob("*/run.json")}
    assert 1 <= len(done_before) < 4 and not (out / "sweep.csv").exists()
    table = run_sweep(load_sweep(sweep), out, workers=1, runner=fake_runner, progress=False)
    matrix = pd.read_csv(out / "matrix_results.csv").set_index("variant")
    assert (table["status"] == "ok").all() and len(table) == 4
    assert set(matrix.index[matrix["resumed"]]) == done_before           # killed sweep's runs kept
    # eps_beta of one helix half, b/2 sin(beta) / (pi m_n), from the gearbox's Table 1
    g = load_gearbox(ROOT / "model_variants" / "gearbox.toml").gears
    for _, row in table.iterrows():
        b = row["gears_assumed.face_width_mm"]
        expect = b / 2 * math.sin(math.radians(g.helix_angle_deg)) / (math.pi * g.normal_module_mm)
        assert row["eps_beta"] == pytest.approx(expect, rel=1e-9)
    from pypdf import PdfReader

    from flexgear.report.pages import build_report

    # the sweep's pages (the modal pages, which would linearise a face-width variant whose bodies no other test
    # builds, are checked on a matrix's report: tests/test_report.py, tests/test_modal_pages.py)
    pdf = build_report(out, tmp_path / "report.pdf", modal=False)
    text = "\n".join(page.extract_text() for page in PdfReader(pdf).pages)
    assert "Sweep" in text and "face_width_mm" in text
