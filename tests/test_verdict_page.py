"""Page 1's verdict per purpose, from a reference-screened matrix of synthetic variants (known Bias by construction:
flexgear's synthetic runs are off by 1 % / (1 + flexible components) in output speed and mean mesh forces)."""

from __future__ import annotations

import shutil
from pathlib import Path

import matplotlib
import pandas as pd
import pytest
from synthetic import GEARBOX, fake_runner

from flexgear.report.data import gather
from flexgear.report.verdict_page import (
    band_difference_lines,
    case_difference_lines,
    verdict_lines,
    verdict_page,
    verdict_rows,
)
from flexgear.study.matrix import run_matrix
from flexgear.study.purposes import VERDICT_COLUMNS

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

_COMPONENTS = ("input_shaft", "sun", "planets", "ring", "output_shaft")


def _variant(root: Path, name: str, flexible: tuple[str, ...]) -> Path:
    path = root / f"{name}.toml"
    path.write_text(f'name = "{name}"\ngearbox = "gearbox.toml"\nmesh_level = "coarse"\n\n[components]\n'
                    + "".join(f'{c} = "{"flexible" if c in flexible else "rigid"}"\n' for c in _COMPONENTS))
    return path


@pytest.fixture(scope="module")
def folders(tmp_path_factory) -> tuple[Path, Path]:
    """Two reference-screened matrices of the same synthetic variants (a quick and a 'full' case)."""
    root = tmp_path_factory.mktemp("verdict")
    shutil.copy(GEARBOX, root / "gearbox.toml")
    files = [_variant(root, "model1", ()), _variant(root, "model3", ("input_shaft", "output_shaft")),
             _variant(root, "model7", _COMPONENTS)]
    out = []
    for case in ("quick", "full"):
        run_matrix(files, root / case, t_end_s=0.6, workers=1, progress=False, runner=fake_runner,
                   reference="model7")
        out.append(root / case)
    return out[0], out[1]


def test_verdict_csv_and_page_one_table_per_purpose(folders):
    """Mean loads: every synthetic run scatters its output speed by CV 0.2 % between samples, so with the speed's
    TEa of 0.1 % no variant, the reference included, meets |Bias| + 2 CV <= TEa: nothing is selected, and page 1
    says so. The other purposes' indicators are equal in every variant: the cheapest, model1 (1 s of CPU against
    model7's 6 s)."""
    quick, full = folders
    verdict = pd.read_csv(quick / "verdict.csv")
    assert list(verdict.columns[:len(VERDICT_COLUMNS)]) == VERDICT_COLUMNS
    by = verdict.set_index("purpose")
    assert verdict["selected"].isna().sum() == 2            # mean loads and all purposes: none
    assert pd.isna(by.loc["mean_loads", "selected"]) and "no variant is acceptable" in by.loc["mean_loads",
                                                                                              "reasoning"]
    assert by.loc["tooth_loads", "selected"] == "model1" and by.loc["vibration", "selected"] == "model1"
    assert by.loc["tooth_loads", "time_ratio"] == pytest.approx(1.0 / 6.0)
    assert pd.isna(by.loc["all purposes", "selected"])
    assert "purpose" in pd.read_csv(quick / "screening_indicators.csv").columns
    d, o = gather(quick), gather(full)
    rows = verdict_rows(d, [o]).set_index("purpose")
    assert rows.loc["mean loads", "selected"] == "none" and rows.loc["mean loads", "full"] == "none"
    assert rows.loc["tooth loads", "selected"] == "model1"
    assert "mean loads none" in verdict_lines(d)[0]
    assert case_difference_lines(d, [o]) == []          # the same selections in both cases
    pd.DataFrame({"purpose": ["tooth_loads", "vibration"], "selected": ["model1", "model1"],
                  "low_rpm": [3000.0, 5156.2], "high_rpm": [9000.0, 6290.3], "grid_low_rpm": [3000.0, 3000.0],
                  "grid_high_rpm": [9000.0, 9000.0]}).to_csv(quick / "speed_bands.csv", index=False)
    bands = verdict_rows(d, []).set_index("purpose")["speed band"]
    assert bands["tooth loads"] == "≤ 3000 to ≥ 9000 rpm" and bands["vibration"] == "5156 to 6290 rpm"
    pd.DataFrame({"purpose": ["tooth_loads", "vibration"], "selected": ["model1", "model1"],
                  "low_rpm": [3000.0, 5500.0], "high_rpm": [9000.0, 6290.3], "grid_low_rpm": [3000.0, 3000.0],
                  "grid_high_rpm": [9000.0, 9000.0]}).to_csv(full / "speed_bands.csv", index=False)
    moved = band_difference_lines(d, [o])          # the same variant, another band in the other load case
    assert len(moved) == 1 and moved[0].startswith("vibration speed band of model1: 5156 to 6290 rpm here, 5500")
    assert "NOT RESOLVED over speed" in moved[0]
    (quick / "speed_bands.csv").unlink()
    (full / "speed_bands.csv").unlink()
    fig = plt.figure(figsize=(11.69, 8.27))
    verdict_page(d, [o], "synthetic case")(fig)          # draws without error
    text = " ".join(t.get_text() for ax in fig.axes for t in ax.texts) + " ".join(t.get_text() for t in fig.texts)
    plt.close(fig)
    assert "mean loads: no variant is acceptable, the reference included" in text
    assert "model7 output speed 0 % off" in text and "For all purposes: none." in text
    assert "Bias / CV / TEa" in " ".join(
        c.get_text().get_text() for ax in fig.axes for t in ax.tables for c in t.get_celld().values())
