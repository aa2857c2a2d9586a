"""`flexgear report` on any results folder: a PDF that says what could not be screened and why, never a traceback.

The runs are synthetic (tests/synthetic.py), saved as a matrix saves them; nothing is simulated. The rule for
paths: a results folder (saved runs, a matrix's files, or an empty directory) gives a PDF; any other path gives one
line naming it and exit code 2.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest
from pypdf import PdfReader
from synthetic import GEARBOX, failed_result, synthetic_result

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from flexgear.cli import main  # noqa: E402
from flexgear.report.data import NotResultsFolder, gather  # noqa: E402
from flexgear.report.figures import draw_table  # noqa: E402
from flexgear.report.pages import build_report  # noqa: E402
from flexgear.report.result_pages import NOT_RECORDED  # noqa: E402
from flexgear.results import RunResult, save_result  # noqa: E402

SHORT_END_S = 0.05
"""End of the short runs [s]: before the gearbox's ramps (0.5 s), so no run has a steady window."""

TE_MEAN_M, TE_RIPPLE_M = 1e-6, 1e-8
"""Loaded transmission error of the synthetic reference [m]: mean and ripple amplitude."""

MESH_HZ = 4400.0
"""Frequency of the synthetic transmission-error ripple [Hz] (the gearbox's mesh frequency)."""

INPUTS = {"gearbox.toml": Path(GEARBOX).read_bytes()}


def _save(folder: Path, *runs: RunResult, reference: str | None = None) -> Path:
    """``runs`` saved under ``folder`` as a matrix saves them (with a copy of the gearbox file); ``reference``:
    the screening reference the matrix recorded (screening.json)."""
    folder.mkdir(parents=True, exist_ok=True)
    for run in runs:
        save_result(run, folder / run.name, INPUTS)
    if reference is not None:
        (folder / "screening.json").write_text(json.dumps({"reference": reference}))
    return folder


def _short(name: str) -> RunResult:
    """A finished run that ends at SHORT_END_S, before the ramps."""
    run = synthetic_result(name, t_start=0.0)
    run.signals = run.signals[run.signals["time_s"] <= SHORT_END_S].reset_index(drop=True)
    run.meta["t_end_s"] = float(run.signals["time_s"].iloc[-1])
    return run


def _unsettled(name: str, why: str) -> RunResult:
    """A finished run whose runner's settling test failed."""
    run = synthetic_result(name)
    run.meta.update(settled=False, settle_reason=why)
    return run


def _report(folder: Path, tmp_path: Path) -> list[str]:
    """Build the report of ``folder`` (without the modal pages) and return the text of each page."""
    pdf = build_report(folder, tmp_path / "report.pdf", modal=False)
    assert pdf.is_file()
    pages = [page.extract_text() for page in PdfReader(pdf).pages]
    for number, text in enumerate(pages, start=1):
        assert f"page {number} / {len(pages)}" in text
    return pages


def test_empty_folder_gives_a_report_that_says_no_runs(tmp_path):
    folder = tmp_path / "empty"
    folder.mkdir()
    d = gather(folder)
    assert d.runs == {} and d.nothing_screened.startswith(f"no runs in {folder}")
    pages = _report(folder, tmp_path)
    assert f"No runs in {folder}" in pages[0] and "Verdict: none" in pages[0]
    assert "no runs in" in pages[2]                       # the run-time page says it instead of a chart


def test_one_failed_run(tmp_path):
    folder = _save(tmp_path / "failed", failed_result("model1", "FloatingPointError: the solution diverged"))
    d = gather(folder)
    assert d.nothing_screened == "no screened variant: model1 failed (FloatingPointError: the solution diverged)"
    pages = _report(folder, tmp_path)
    assert "model1 failed (FloatingPointError: the solution diverged)" in pages[0]
    assert "Verdict: none" in pages[0]
    screening = next(p for p in pages if "Composite point per variant" in p)
    assert "the solution diverged" in screening           # the empty Bias and CV cells come with the reason


def test_all_runs_failed_with_long_reasons(tmp_path):
    trace = "Traceback (most recent call last):\n  File 'x.py', line 1\nRuntimeError: boom\n" * 20
    folder = _save(tmp_path / "all_failed", failed_result("model1", trace), failed_result("model2", trace))
    d = gather(folder)
    assert d.nothing_screened.startswith("no screened variant: model1, model2 failed (Traceback")
    assert "\n" not in d.nothing_screened and len(d.nothing_screened) < len(trace)
    assert "no screened variant" in _report(folder, tmp_path)[0].replace("\n", " ").lower()


def test_one_unsettled_run(tmp_path):
    why = "mean speed drifts 2 % between the last two chunks"
    folder = _save(tmp_path / "unsettled", _unsettled("model1", why))
    d = gather(folder)
    assert d.study.table.loc[0, "status"] == "unsettled"
    assert d.nothing_screened == f"no screened variant: model1 unsettled ({why})"
    pages = _report(folder, tmp_path)
    assert "model1 unsettled" in pages[0] and why in pages[0]


def test_two_variant_short_matrix(tmp_path):
    """Runs that end before the ramps: nothing screened, every table row says why, the figures still drawn."""
    folder = _save(tmp_path / "short", _short("model1"), _short("model4"))
    d = gather(folder)
    assert d.indicators.empty and not (d.screening["status"] == "ok").any()
    assert "model1, model4 unsettled" in d.nothing_screened and "before the ramps" in d.nothing_screened
    pages = _report(folder, tmp_path)
    assert "No screened variant: model1, model4 unsettled" in pages[0]
    screening = next(p for p in pages if "Composite point per variant" in p)
    assert "before the ramps" in screening
    assert any("NOT settled: model1, model4" in p for p in pages)   # the overlays say the window is not settled


def test_missing_reference_is_refused_with_its_reason(tmp_path):
    folder = _save(tmp_path / "no_reference", _short("model1"), _short("model4"), reference="model7")
    d = gather(folder)
    assert d.reference is None
    assert d.refused == "not screened: reference model7 is not among the runs (model1, model4)"
    assert d.nothing_screened == d.refused
    pages = _report(folder, tmp_path)
    assert "Verdict: none" in pages[0] and "model7 is not among the runs" in pages[0]
    assert any("against the reference: not drawn" in p for p in pages)


@pytest.mark.parametrize("reference", [failed_result("model7", "diverged"), _unsettled("model7", "drift")],
                         ids=["failed", "unsettled"])
def test_unusable_reference_is_refused(tmp_path, reference):
    folder = _save(tmp_path / "bad_reference", synthetic_result("model1"), reference, reference="model7")
    d = gather(folder)
    assert d.reference is None and d.refused.startswith("not screened: reference model7")
    assert "model7" in _report(folder, tmp_path)[0]


def test_single_run(tmp_path):
    folder = _save(tmp_path / "single", synthetic_result("model1"))
    d = gather(folder)
    assert d.nothing_screened == "" and d.selection.variant == "model1"
    assert "Verdict: model1" in _report(folder, tmp_path)[0]


def test_indicator_a_run_lacks_reads_not_recorded(tmp_path):
    """Against a reference that records the transmission error, a run without ``transmission_error_m`` has no
    value for it: its indicator cells read "not recorded", never a bare dash."""
    reference = synthetic_result("model7", wall_time_s=5.0)
    t = reference.signals["time_s"].to_numpy()
    reference.signals["transmission_error_m"] = TE_MEAN_M + TE_RIPPLE_M * np.sin(2 * np.pi * MESH_HZ * t)
    folder = _save(tmp_path / "reference", synthetic_result("model1"), reference, reference="model7")
    d = gather(folder)
    assert d.refused == "" and d.reference is not None
    assert "transmission_error" not in set(d.indicators.loc[d.indicators["variant"] == "model1", "indicator"])
    pages = _report(folder, tmp_path)
    screening = [p for p in pages if "Composite point per variant" in p]   # against theory, then the reference
    assert len(screening) == 2 and NOT_RECORDED in screening[-1]


def test_modal_pages_without_a_selected_variant(tmp_path, monkeypatch):
    """The modal pages of a folder with nothing selected: a part that cannot be computed is named, no traceback."""
    import flexgear.harmonic.lumped as lumped

    def refuse(*args, **kwargs):
        raise RuntimeError("not computed in this test")

    monkeypatch.setattr(lumped, "lumped_harmonic_response", refuse)
    folder = _save(tmp_path / "short", _short("model1"))
    pdf = build_report(folder, tmp_path / "report.pdf")
    text = "\n".join(page.extract_text() for page in PdfReader(pdf).pages)
    assert "Modal analysis: parts not computed" in text


def test_draw_table_of_an_empty_frame_is_a_sentence():
    fig = plt.figure(figsize=(11.69, 8.27))
    ax = fig.add_axes([0.05, 0.05, 0.9, 0.9])
    for empty in (pd.DataFrame(), pd.DataFrame(columns=["variant", "bias"])):
        bottom = draw_table(ax, empty, top=0.8, empty="no screened variant: model1 failed (diverged)")
        assert 0.0 < bottom < 0.8
    assert [t.get_text() for t in ax.texts] == ["no screened variant: model1 failed (diverged)"] * 2
    plt.close(fig)


def test_cli_report_of_an_empty_folder_writes_a_pdf(tmp_path, capsys):
    folder = tmp_path / "empty"
    folder.mkdir()
    assert main(["report", str(folder), "--output", str(tmp_path / "r.pdf")]) == 0
    assert (tmp_path / "r.pdf").is_file() and "report ->" in capsys.readouterr().out


@pytest.mark.parametrize("kind", ["missing", "file", "not_results"])
def test_cli_report_of_a_non_results_path_is_one_line(tmp_path, capsys, kind):
    path = tmp_path / kind
    if kind == "file":
        path.write_text("not a folder")
    elif kind == "not_results":
        path.mkdir()
        (path / "notes.txt").write_text("no runs here")
    output = tmp_path / "r.pdf"
    assert main(["report", str(path), "--output", str(output)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "expected a results folder" in err
    assert "Traceback" not in err and not output.exists()
    with pytest.raises(NotResultsFolder):
        gather(path)


def test_results_written_with_speeds_in_deg_per_s_load_in_rad_per_s(tmp_path):
    """A run folder of an earlier version (speed columns and theory keys in deg/s) loads in the SI schema, the
    values converted exactly, and screens as the same run written now."""
    from flexgear.results import LEGACY_SPEED_COLUMNS, load_result
    from flexgear.study.indicators import indicator_segments

    now = synthetic_result("model1", bias={"output_speed": 2e-4})
    old_signals = now.signals.rename(columns={new: old for old, new in LEGACY_SPEED_COLUMNS.items()})
    for old in LEGACY_SPEED_COLUMNS:
        old_signals[old] = np.degrees(old_signals[old].to_numpy())
    theory = {({v: k for k, v in LEGACY_SPEED_COLUMNS.items()}.get(k, k)): (np.degrees(v) if "speed" in k else v)
              for k, v in now.meta["theory"].items()}
    save_result(RunResult(dict(now.meta, theory=theory), old_signals), tmp_path / "old")
    loaded = load_result(tmp_path / "old")
    assert list(loaded.signals.columns) == list(now.signals.columns)
    for new in LEGACY_SPEED_COLUMNS.values():
        np.testing.assert_allclose(loaded.signals[new], now.signals[new], rtol=1e-14)
        assert loaded.meta["theory"][new] == pytest.approx(now.meta["theory"][new], rel=1e-14)
    slices = [slice(0, len(now.signals))]
    f_mesh = now.meta["theory"]["mesh_frequency_hz"]
    a, b = (indicator_segments(r.signals, slices, f_mesh) for r in (loaded, now))
    assert a.keys() == b.keys() and all(np.allclose(a[k], b[k], rtol=1e-12) for k in a)


def test_the_report_screens_with_the_gearbox_file_saved_with_the_runs(tmp_path):
    """A matrix of another gearbox (the spur planetary example: its settling blocks follow its 84-tooth ring) is
    screened with that gearbox's own settings, read from the copy saved with its runs, not the study's."""
    from flexgear.cli import main
    from flexgear.report.data import gather
    from flexgear.spec import load_gearbox

    example = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary"
    assert main(["matrix", str(example / "rigid.toml"), "--out", str(tmp_path)]) == 0
    data = gather(tmp_path)
    assert data.gearbox_file == tmp_path / "rigid" / "inputs" / "gearbox.toml", data.gearbox_note
    assert data.gearbox.gears.arrangement == "planetary" and data.gearbox.gears.ring_teeth == 84
    own = load_gearbox(example / "gearbox.toml").screening
    assert data.settings.settle_block_mesh_cycles == own.settle_block_mesh_cycles != 17  # the study's: 136 / 8
    # its report sets no other study's published values beside its runs (the study's are data of its own file)
    from pypdf import PdfReader

    from flexgear.report.pages import build_report

    text = "\n".join(p.extract_text() for p in PdfReader(build_report(tmp_path, tmp_path / "r.pdf",
                                                                        modal=False)).pages)
    for study in ("published", "ADAMS", "798.1894", "You et al"):
        assert study not in text, study
    assert "Table 6" in text and "Run time per simulated second" in text
