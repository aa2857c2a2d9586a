"""Screening over the speed range (flexgear.study.speed_screening) on model 1 under the ISO 6336 law.

- A variant against itself differs by nothing at any speed: 0 dB, 0 % of the load, within TEa.
- Damping: the same model with all its damping (meshes, bearings) scaled by 0.1. A mode at resonance answers in
  proportion to 1 / zeta, so at the reference's strongest resonance of the input-bearing vibration (its most
  prominent peak, standing far above the lower of the curve's minima on either side) the light variant is
  20 log10(10) = 20 dB louder, less the non-resonant background that damping does not change: within the
  vibration TEa (3 dB). The largest difference of that curve lies at that resonance (within 1 % of its speed):
  damping matters most where the response is resonant.
"""

import dataclasses
import math

import numpy as np
import pytest

from flexgear.study.speed_screening import SPEED_INDICATORS, screen_speed_range, speed_screening

SPEEDS = 1000.0 * 1.0025 ** np.arange(int(math.log(7.0) / math.log(1.0025)) + 1)  # 1000-7000 rpm, 0.25 % steps
DAMPING_FACTOR = 0.1


@pytest.fixture(scope="module")
def screening(model1):
    from test_harmonic_speed import _lightly_damped

    spec = model1.gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    spec = spec.with_fields("contact_assumed", stiffness_variation="contact_lines")
    base = dataclasses.replace(model1, gearbox=spec, name="base")
    same = dataclasses.replace(base, name="same")
    light = dataclasses.replace(_lightly_damped(base, DAMPING_FACTOR), name="light")
    return speed_screening([base, same, light], SPEEDS, reference="base", harmonics=3)


def test_a_variant_against_itself_scores_zero(screening):
    same = screening.table[screening.table.variant == "same"]
    assert set(same.indicator) == set(SPEED_INDICATORS)
    assert np.all(same.difference == 0.0)
    row = screening.summary.set_index("variant").loc["same"]
    assert row.within and row.exceed_share_pct == 0.0


def test_less_damping_is_louder_by_one_over_zeta_at_the_resonance(screening):
    table = screening.table[screening.table.indicator == "input_bearing_rms"]
    ref = table[table.variant == "light"].reference_value.to_numpy()
    diff = table[table.variant == "light"].difference.to_numpy()
    inner = np.flatnonzero((ref[1:-1] > ref[:-2]) & (ref[1:-1] >= ref[2:])) + 1
    prominence = np.array([ref[i] / max(ref[:i].min(), ref[i:].min()) for i in inner])
    peak = int(inner[np.argmax(prominence)])  # the reference's strongest resonance: the most prominent peak
    assert prominence.max() > 5.0  # standing far above its surroundings: the background is a small part
    expected = 20.0 * math.log10(1.0 / DAMPING_FACTOR)
    assert expected - 3.0 <= diff[peak] <= expected + 3.0
    worst = int(np.argmax(np.abs(diff)))
    assert abs(SPEEDS[worst] / SPEEDS[peak] - 1.0) <= 0.01
    row = screening.summary.set_index("variant").loc["light"]
    assert not row.within
    line = next(text for text in screening.lines() if text.startswith("light:"))
    assert "exceeds TEa over" in line


def test_files_in_the_results_folder(tmp_path):
    from conftest import VARIANTS

    text = screen_speed_range([VARIANTS / "model1.toml"], tmp_path, [2000.0, 4000.0], harmonics=2)
    assert text.splitlines() == ["model1: the reference over 2000-4000 rpm"]
    assert (tmp_path / "speed_screening.txt").read_text() == text
    assert (tmp_path / "speed_screening.csv").stat().st_size > 0


def test_matrix_takes_a_speed_range():
    from flexgear.cli import _parser

    args = _parser().parse_args(["matrix", "model_variants/model1.toml", "--speeds-rpm", "1000:3000:1000"])
    assert args.speeds_rpm == [1000.0, 2000.0, 3000.0]
    assert _parser().parse_args(["matrix", "model_variants/model1.toml"]).speeds_rpm is None


def test_the_matrix_screens_each_variants_speed_curves_in_its_pool(tmp_path):
    """``flexgear matrix --speeds-rpm``: each variant's curves are a job of their own in the run pool, screened
    together when the runs are in: the same table as :func:`speed_screening` of the same variants in one process."""
    import pandas as pd
    from conftest import VARIANTS

    from flexgear.spec import load_variant
    from flexgear.study.matrix import run_matrix

    text = (VARIANTS / "quick" / "model1.toml").read_text().replace('"../gearbox.toml"',
                                                                     f'"{VARIANTS / "gearbox.toml"}"')
    (tmp_path / "base.toml").write_text(text.replace('name = "model1"', 'name = "base"'))
    (tmp_path / "frictionless.toml").write_text(text.replace('name = "model1"', 'name = "frictionless"')
                                                + "\n[overrides.contact]\nfriction_coefficient = 0.0\n")
    paths = [tmp_path / "base.toml", tmp_path / "frictionless.toml"]
    speeds = [3000.0, 6000.0]
    run_matrix(paths, tmp_path / "out", t_end_s=0.002, reference="base", speeds_rpm=speeds, progress=False)
    pooled = pd.read_csv(tmp_path / "out" / "speed_screening.csv")
    alone = speed_screening([load_variant(p) for p in paths], speeds, reference="base").table
    assert len(pooled) == len(alone) > 0
    for column in ("reference_value", "difference"):
        np.testing.assert_allclose(pooled[column].to_numpy(), alone[column].to_numpy(), rtol=1e-9, atol=1e-12)
    assert (tmp_path / "out" / "speed_screening.txt").read_text().startswith("base: the reference")
    (tmp_path / "out" / "speed_screening.csv").unlink()  # every run resumed: the pool holds the curves alone
    run_matrix(paths, tmp_path / "out", t_end_s=0.002, reference="base", speeds_rpm=speeds, progress=False)
    np.testing.assert_allclose(pd.read_csv(tmp_path / "out" / "speed_screening.csv")["difference"].to_numpy(),
                               alone["difference"].to_numpy(), rtol=1e-9, atol=1e-12)
