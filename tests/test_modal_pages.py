"""Modal pages of the report (flexgear.report.modal_pages), built from a small results folder."""

from __future__ import annotations

import shutil

import matplotlib
import numpy as np
import pytest
from conftest import VARIANTS
from synthetic import GEARBOX, synthetic_result

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from flexgear.report.data import gather  # noqa: E402
from flexgear.report.modal_pages import _grouped, modal_pages, modal_study  # noqa: E402
from flexgear.results import save_result  # noqa: E402


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """One synthetic run named model1 whose variant file is the package's rigid model 1."""
    root = tmp_path_factory.mktemp("modal_pages")
    run = synthetic_result("model1")
    run.meta.update(variant_file=str(VARIANTS / "model1.toml"),
                    spec={"load_case": {"input_speed_rpm": 6000.0}})
    save_result(run, root / "model1", {"model1.toml": (VARIANTS / "model1.toml").read_bytes(),
                                       "gearbox.toml": open(GEARBOX, "rb").read()})
    shutil.copy(GEARBOX, root / "gearbox.toml")
    d = gather(root)
    return d, modal_study(d)


def test_pages_build(study):
    d, s = study
    pages = modal_pages(d, s)
    titles = [t for t, _ in pages]
    for key in ("Modes of model1", "Campbell diagram of model1", "Run-up order map of model1", "Speed response"):
        assert any(t.startswith(key) for t in titles), titles
    for _, draw in pages:
        fig = plt.figure(figsize=(11.69, 8.27))
        draw(fig)
        plt.close(fig)


def test_energy_bars_are_shares(study):
    """Each mode's kinetic and strain energy shares per component add up to the whole mode."""
    _, s = study
    m = s.modes["model1"]
    for prefix in ("kinetic", "strain"):
        total = _grouped(m.energy, prefix).sum(axis=1).to_numpy()
        assert np.allclose(total, 1.0, atol=1e-6), prefix


def test_response_peaks_at_a_crossing(study):
    """The input bearing's 1x response peaks where the Campbell diagram's order 1 crosses a mode (one grid step)."""
    _, s = study
    r = s.responses["model1"]
    amp = r.amplitudes("input_bearing_accel_x_m_per_s2")[1]
    speeds = amp.index.to_numpy()
    inner = np.flatnonzero((amp.to_numpy()[1:-1] > amp.to_numpy()[:-2]) & (amp.to_numpy()[1:-1] > amp.to_numpy()[2:]))
    peaks = speeds[inner + 1]
    assert peaks.size, amp
    cross = s.campbell.crossings
    first = cross[cross.order == 1].speed_rpm.to_numpy()
    step = speeds[1] - speeds[0]
    assert any(np.min(np.abs(first - p)) <= step for p in peaks), (peaks, first)
