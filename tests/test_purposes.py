"""The verdict per purpose: every indicator judged alone against its own TEa (flexgear.study.purposes)."""

from __future__ import annotations

import dataclasses
import math

import pandas as pd
import pytest
from synthetic import GEARBOX

from flexgear.laws.contact import ContactLaw, effective_stiffness, static_deflection
from flexgear.spec import SpecError, load_gearbox
from flexgear.study.purposes import ALL_PURPOSES, judge_purposes, static_te_split, verdict_table
from flexgear.study.selection import DecisionLines


@pytest.fixture(scope="module")
def settings():
    return load_gearbox(GEARBOX).screening


def _indicators(settings, variant: str, bias: dict[str, float], tiny: float = 1e-3) -> list[dict]:
    """One row per reference indicator: Bias ``tiny`` x TEa unless ``bias`` gives it (in the indicator's unit)."""
    tol = settings.reference_indicators
    rows = []
    for f in dataclasses.fields(tol):
        t = getattr(tol, f.name)
        rows.append({"variant": variant, "indicator": f.name, "bias": bias.get(f.name, tiny * t.tea),
                     "cv": tiny * t.tea, "tea": t.tea, "unit": t.scale, "weight": t.weight})
    return rows


def test_one_low_weight_indicator_five_times_its_tea_fails_its_purpose_only(settings):
    """The output bearing's 1x level (weight 0.04) 5 TEa off, every other indicator at 0.1 % of its TEa: the
    weighted composite puts the variant at about 20 % of TEa ("excellent"), yet judged alone that indicator is
    outside |Bias| + 2 CV <= TEa, so the variant fails the vibration purpose and passes every other one."""
    tol = settings.reference_indicators
    key = "output_bearing_mesh1x"
    assert getattr(tol, key).weight == pytest.approx(0.04)
    bias = 5.0 * getattr(tol, key).tea
    rows = _indicators(settings, "ref", {}, tiny=0.0) + _indicators(settings, "cheap", {key: bias})
    indicators = pd.DataFrame(rows)
    table = pd.DataFrame({"variant": ["ref", "cheap"], "status": ["ok", "ok"], "time_s": [20.0, 1.0]})
    lines = DecisionLines.from_settings(settings, "ref")
    cheap = indicators[indicators["variant"] == "cheap"]
    composite = float((cheap["weight"] * cheap["bias"] / cheap["tea"]).sum() * 100.0)
    assert lines.rank(composite, float((cheap["weight"] * cheap["cv"] / cheap["tea"]).sum() * 100.0)) == 3
    zones, verdicts = judge_purposes(indicators, table, settings.purposes, lines, "ref")
    by = {v.purpose: v for v in verdicts}
    assert by["vibration"].selected == "ref"
    assert "only the reference ref is acceptable" in by["vibration"].reasoning
    assert "cheap: output bearing accel. at 1x mesh 15 db off" in by["vibration"].reasoning
    for purpose in ("mean_loads", "tooth_loads", "transmission_error"):
        assert by[purpose].selected == "cheap"
        assert by[purpose].time_ratio == pytest.approx(1.0 / 20.0)
    assert by[ALL_PURPOSES].selected == "ref"
    z = zones.set_index(["variant", "purpose"])
    assert not z.loc[("cheap", "vibration"), "acceptable"] and z.loc[("cheap", "vibration"), "weakest"] == key
    assert z.loc[("cheap", "vibration"), "zone"] == "non-conforming"
    csv = verdict_table(verdicts)
    assert list(csv["purpose"]) == [*settings.purposes, ALL_PURPOSES]
    assert csv.loc[csv["purpose"] == "vibration", "selected"].item() == "ref"


def test_the_deciding_indicator_is_the_one_with_the_smallest_margin(settings):
    """Two tooth-load indicators inside their TEa: the one closer to its line decides, with its margin
    (TEa - Bias - 2 CV) / TEa."""
    rows = _indicators(settings, "ref", {}, tiny=0.0) + _indicators(
        settings, "cheap", {"dynamic_factor": 1.2, "outer_mesh_ripple": 1.5})
    table = pd.DataFrame({"variant": ["ref", "cheap"], "status": ["ok", "ok"], "time_s": [20.0, 1.0]})
    _, verdicts = judge_purposes(pd.DataFrame(rows), table, settings.purposes,
                                 DecisionLines.from_settings(settings, "ref"), "ref")
    tooth = next(v for v in verdicts if v.purpose == "tooth_loads")
    tea = settings.reference_indicators.outer_mesh_ripple.tea
    assert tooth.selected == "cheap" and tooth.deciding_indicator == "outer_mesh_ripple"
    assert tooth.margin == pytest.approx((tea - 1.5 - 2 * 1e-3 * tea) / tea)


def test_purposes_are_checked_when_the_file_is_loaded(tmp_path):
    text = open(GEARBOX).read()
    bad = text.replace('transmission_error = ["transmission_error_mesh1x", "transmission_error_mesh2x"]',
                       'transmission_error = ["transmission_error_mesh1x", "input_speed"]')
    path = tmp_path / "gearbox.toml"
    path.write_text(bad)
    with pytest.raises(SpecError, match=r"screening\.purposes\.transmission_error.*already in purpose 'mean_loads'"):
        load_gearbox(path)
    path.write_text(text.replace('"transmission_error_mesh2x"]', '"transmission_error_mesh3x"]'))
    with pytest.raises(SpecError, match="unknown indicator 'transmission_error_mesh3x'"):
        load_gearbox(path)


def test_static_deflection_inverts_the_law_and_the_tangent_stiffness_is_its_slope():
    """Impact law F = k delta^1.5: delta = (F / k)^(2/3); its slope 1.5 k delta^0.5 against a finite difference.
    Linear law: delta = F / k, slope k."""
    law = ContactLaw(1.0e8, 1.5, 1.0e5, 1.0e-4)
    f = 798.2
    delta = static_deflection(f, law)
    assert law.stiffness * delta**1.5 == pytest.approx(f, rel=1e-12)
    h = 1e-9
    slope = law.stiffness * ((delta + h) ** 1.5 - (delta - h) ** 1.5) / (2 * h)
    assert effective_stiffness(f, law) == pytest.approx(slope, rel=1e-8)
    linear = ContactLaw(4.0e8, 1.0, 0.0, 0.0, "iso6336")
    assert static_deflection(f, linear) == pytest.approx(f / 4.0e8)
    assert effective_stiffness(f, linear) == pytest.approx(4.0e8)


def test_static_te_split_takes_both_meshes_to_the_transverse_line_of_action():
    beta_b = math.radians(23.4)
    split = static_te_split(1.0e-3, 4.0e-4, 3.0e-4, beta_b)
    assert split.meshes_m == pytest.approx(7.0e-4 / math.cos(beta_b))
    assert split.windup_m == pytest.approx(1.0e-3 - 7.0e-4 / math.cos(beta_b))
