"""The study's contact stiffness under both readings of its unit (section 2.1, ``[published.contact]`` of the study's
gearbox file), without simulation: the millimetre reading's variant files against the analytic unit conversion, both
readings' static deflection, and the report page of flexgear.report.reading_pages on synthetic results folders."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pandas as pd
import pytest
from conftest import VARIANTS
from matplotlib.figure import Figure
from synthetic import synthetic_result

from flexgear.laws.contact import ContactLaw, effective_stiffness, static_deflection
from flexgear.report.data import gather
from flexgear.report.reading_pages import (
    READING_M,
    READING_MM,
    contact_reading_pages,
    damping_n_s_per_m,
    log_distance,
    reading_of,
    reading_values,
    stiffness_n_per_m_exp,
)
from flexgear.results import save_result
from flexgear.spec import load_variant

MM_FOLDER = VARIANTS / "quick_mm_reading"
QUICK_FOLDER = VARIANTS / "quick"
PUBLISHED = load_variant(QUICK_FOLDER / "model1.toml").gearbox.published.contact
STUDY_NUMBER = 1.0e8                       # section 2.1: "1.0x10^8 N*m"
EXPONENT, FRACTION = 1.5, 1.0e-3           # section 2.1: "nonlinear coefficient" 1.5, damping "0.1 %" of stiffness
K_MM_ANALYTIC = 1.0e8 * 10.0**4.5          # 1e8 N/mm^1.5 = 1e8 (1e3)^1.5 N/m^1.5 = 3.1622776601683795e12
C_MM_ANALYTIC = 1.0e8                      # 0.1 % of 1e8 = 1e5 N s/mm = 1e8 N s/m
STUDY_FORCE_N = load_variant(QUICK_FOLDER / "model1.toml").gearbox.published.table6["outer_mesh_force_n"][0]
"""Table 6 ([published] of the study's gearbox file): the theoretical mesh force, 798.1894 N."""


@pytest.mark.parametrize("n", range(1, 8))
def test_mm_reading_variant_holds_the_converted_law(n: int) -> None:
    """Each millimetre-reading variant: k = 1e8 (1000)^1.5 N/m^1.5, c_max = 1e8 N s/m, the study's exponent and
    cutting depth; the quick variant's components and ramps, half its step."""
    mm = load_variant(MM_FOLDER / f"model{n}.toml")
    quick = load_variant(QUICK_FOLDER / f"model{n}.toml")
    c = mm.gearbox.contact
    assert c.stiffness == pytest.approx(K_MM_ANALYTIC, rel=1e-12)
    assert c.stiffness == pytest.approx(stiffness_n_per_m_exp(STUDY_NUMBER, 1e-3, EXPONENT), rel=1e-12)
    assert c.stiffness == pytest.approx(3.162e12, rel=1e-3)
    law = ContactLaw.from_contact(c)
    assert law.damping_max == pytest.approx(C_MM_ANALYTIC, rel=1e-12)
    assert law.damping_max == pytest.approx(damping_n_s_per_m(STUDY_NUMBER, 1e-3, FRACTION), rel=1e-12)
    assert c.damping_fraction_of_stiffness == pytest.approx(3.162e-5, rel=1e-3)
    assert (c.exponent, c.penetration_depth_m, c.law) == (1.5, 1.0e-4, "impact")
    assert c.friction_coefficient == quick.gearbox.contact.friction_coefficient
    assert mm.name == quick.name and mm.components == quick.components and mm.mesh_level == quick.mesh_level
    lc_mm, lc_q = mm.gearbox.load_case, quick.gearbox.load_case
    assert dataclasses.replace(lc_mm, step_size_s=lc_q.step_size_s) == lc_q
    assert lc_mm.step_size_s == pytest.approx(0.5 * lc_q.step_size_s)
    assert dataclasses.replace(mm.gearbox, contact=quick.gearbox.contact, load_case=lc_q,
                               source=quick.gearbox.source) == quick.gearbox


def test_project_reading_is_the_study_number_in_si() -> None:
    """The project's reading: k = 1e8 N/m^1.5 and c_max = 0.1 % of it, 1e5 N s/m (unit conversions with a 1 m
    length unit are the identity)."""
    c = load_variant(QUICK_FOLDER / "model1.toml").gearbox.contact
    assert c.stiffness == stiffness_n_per_m_exp(STUDY_NUMBER, 1.0, EXPONENT) == 1.0e8
    assert ContactLaw.from_contact(c).damping_max == pytest.approx(damping_n_s_per_m(STUDY_NUMBER, 1.0, FRACTION)) \
        == 1.0e5


def test_the_study_file_publishes_its_law_as_printed() -> None:
    """``[published.contact]`` of the study's gearbox file: section 2.1's number, exponent and damping fraction."""
    assert (PUBLISHED.stiffness_number, PUBLISHED.exponent, PUBLISHED.damping_fraction) == (
        STUDY_NUMBER, EXPONENT, FRACTION)
    assert (PUBLISHED.penetration_depth_m, PUBLISHED.step_size_s) == (1.0e-4, 1.0e-5)


@pytest.mark.parametrize("folder", [QUICK_FOLDER, MM_FOLDER])
def test_static_deflection_at_the_study_force_is_the_inverted_law(folder: Path) -> None:
    """At Table 6's 798.19 N normal mesh force both readings deflect (F / k)^(2/3), with tangent stiffness
    1.5 F / delta; the millimetre reading's is 1000 times smaller (0.399 mm against 0.399 um)."""
    law = ContactLaw.from_contact(load_variant(folder / "model1.toml").gearbox.contact)
    delta = static_deflection(STUDY_FORCE_N, law)
    assert delta == pytest.approx((STUDY_FORCE_N / law.stiffness) ** (2.0 / 3.0), rel=1e-12)
    assert effective_stiffness(STUDY_FORCE_N, law) == pytest.approx(1.5 * STUDY_FORCE_N / delta, rel=1e-12)
    expected_m = (STUDY_FORCE_N / 1.0e8) ** (2.0 / 3.0)           # 3.993e-4 m
    assert delta == pytest.approx(expected_m / (1000.0 if folder == MM_FOLDER else 1.0), rel=1e-12)


def test_log_distance_is_the_mean_absolute_decimal_log_ratio() -> None:
    assert log_distance({"a": 10.0, "b": -0.01, "c": 5.0}, {"a": 1.0, "b": -0.1, "c": math.nan}) == pytest.approx(1.0)
    assert log_distance({"a": 2.0}, {"a": 2.0}) == 0.0
    assert math.isnan(log_distance({}, {"a": 1.0}))


# --------------------------------------------------------------------------- the report page on synthetic folders
TE_M = {READING_M: 9.0e-4, READING_MM: 1.5e-5}     # the reference's static TE of each synthetic folder [m]
ACCEL_SCALE = {READING_M: 10.0, READING_MM: 1.0}   # the N/m^1.5 folder's bearing accelerations 10x the study's


def _folder(root: Path, reading: str) -> Path:
    """A results folder of synthetic runs (model4, model7 and a lumped run) under ``reading``: the study's Table 7
    amplitudes scaled by ACCEL_SCALE, a constant TE, a verdict.csv."""
    k = stiffness_n_per_m_exp(STUDY_NUMBER, {READING_M: 1.0, READING_MM: 1e-3}[reading], EXPONENT)
    contact = {"stiffness": k, "exponent": 1.5, "damping_fraction_of_stiffness": 1e8 / k if reading == READING_MM
               else 1e-3, "penetration_depth_m": 1e-4, "friction_coefficient": 0.02, "law": "impact"}
    out = root / reading.replace("/", "_").replace("^", "")
    for name in ("model4", "model7", "lumped"):
        r = synthetic_result(name)
        accel = r.signals.filter(regex=r"_bearing_accel_").columns
        r.signals[accel] = r.signals[accel] * ACCEL_SCALE[reading]
        r.signals["transmission_error_m"] = TE_M[reading]
        r.meta["spec"] = {"contact": contact}
        if name == "lumped":
            r.meta["backend"] = "lumped"
        save_result(r, out / name)
    (out / "screening.json").write_text('{"reference": "model7"}')  # screened against model 7, as `make` does
    selected = "model4" if reading == READING_M else "model7"
    pd.DataFrame({"purpose": ["mean_loads", "all purposes"], "selected": [selected, ""], "zone": ["excellent", ""],
                  "resolved": [True, False]}).to_csv(out / "verdict.csv", index=False)
    return out


@pytest.fixture(scope="module")
def folders(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("readings")
    return {reading: _folder(root, reading) for reading in (READING_M, READING_MM)}


def test_contact_reading_pages_on_synthetic_folders(folders: dict[str, Path]) -> None:
    """The page shows only with a millimetre-reading folder; it gives each reading's static TE, the law's
    deflection at the mean force, Tables 6-7 beside the study's, the verdicts, and names the closer reading."""
    m, mm = gather(folders[READING_M]), gather(folders[READING_MM])
    assert (reading_of(m), reading_of(mm)) == (READING_M, READING_MM)
    assert contact_reading_pages(m, []) == []
    assert contact_reading_pages(m, [m]) == []

    for case, reading in ((m, READING_M), (mm, READING_MM)):
        v = reading_values(case, reading)
        assert v.law["model7: static loaded TE (window mean) [µm]"] == pytest.approx(1e6 * TE_M[reading])
        force = v.law["model7: mean outer mesh force [N]"]
        k = stiffness_n_per_m_exp(STUDY_NUMBER, {READING_M: 1.0, READING_MM: 1e-3}[reading], EXPONENT)
        assert v.law["law: static outer mesh deflection (F/k)^(1/1.5) [µm]"] == pytest.approx(
            1e6 * (force / k) ** (2.0 / 3.0), rel=1e-9)
        t7 = v.tables["T7 model4 vs source multibody: input bearing 1× mesh [m/s²]"]
        assert t7 == pytest.approx(ACCEL_SCALE[reading] * v.study["T7 model4 vs source multibody: input bearing 1× "
                                                                  "mesh [m/s²]"], rel=1e-3)
        assert v.verdicts["all purposes"] == "none, NOT RESOLVED"
    assert reading_values(m, READING_M).verdicts["mean_loads"] == "model4 (excellent)"
    assert reading_values(mm, READING_MM).verdicts["mean_loads"] == "model7 (excellent)"

    for d, others in ((m, [mm]), (mm, [m])):     # either folder may be the report's own
        pages = contact_reading_pages(d, others)
        assert pages and all("both readings" in title for title, _ in pages)
        texts = []
        for _, draw in pages:
            fig = Figure(figsize=(11.69, 8.27))
            draw(fig)
            texts += [t.get_text() for ax in fig.axes for t in ax.texts]
            texts += [c.get_text().get_text() for ax in fig.axes for tab in ax.tables for c in tab.get_celld().values()]
        text = " ".join(" ".join(texts).split())
        assert "the N/mm^1.5 reading reproduces the source better" in text
        assert "model7 (excellent)" in text and "model4 (excellent)" in text
        assert "900" in text and "15" in text    # both static TEs [um]
