"""ISO 6336-1 contact law: c'/c_gamma against a hand calculation, the linear law and its compiled twin, spec choice."""

import dataclasses
import math

import pytest
from conftest import VARIANTS

from flexgear.laws.contact import ContactLaw, linear_force, mesh_laws, normal_force
from flexgear.laws.iso6336 import tooth_stiffness
from flexgear.spec import SpecError, load_gearbox, load_variant

GEARBOX = str(VARIANTS / "gearbox.toml")


def test_single_and_mesh_stiffness_hand_calculation():
    """Sun-planet mesh of the study's gearbox, ISO 6336-1 Method B worked by hand (calculator, 5 digits).

    z1 = 44, z2 = 45, x1 = 0.58658, x2 = 0, beta = 25 deg, beta_b = 24.152 deg, alpha_n = 14.5 deg,
    h_fP/m_n = 1.25, eps_alpha = 1.6873, F_t/b = 700.39 N / 30 mm = 23.346 N/mm.
    cos^2(beta_b) cos(beta) = 0.83270 * 0.90631 = 0.75468 -> z_n1 = 58.303, z_n2 = 59.628
    q' = 0.04723 + 0.15551/58.303 + 0.25791/59.628 - 0.00635*0.58658 - 0.11654*0.58658/58.303
         + 0.00529*0.58658^2 = 0.051145 mm um/N -> c'_th = 19.552
    C_B = (1 + 0.5 (1.2 - 1.25)) (1 - 0.02 (20 - 14.5)) = 0.975 * 0.89 = 0.86775
    (23.346/100)^0.25 = 0.69511
    c' = 19.552 * 0.8 * 1 * 0.86775 * 0.90631 * 0.69511 = 8.5505 N/(mm um)
    c_gamma_alpha = 8.5505 * (0.75 * 1.6873 + 0.25) = 12.958 N/(mm um)
    """
    r = tooth_stiffness(44, 45, 0.58658, 0.0, math.radians(25.0), math.radians(24.152), math.radians(14.5), 1.25,
                        1.6873, 23.346)
    assert r.q_min == pytest.approx(0.051145, rel=2e-4)
    assert r.basic_rack_factor == pytest.approx(0.86775, rel=1e-5)
    assert r.single == pytest.approx(8.5505, rel=1e-3)
    assert r.mesh == pytest.approx(12.958, rel=1e-3)
    # textbook check of the formula: z1 = 20, z2 = 40, x = 0, spur, full load -> c' ~ 13, c_gamma ~ 19 (ISO's 14/20)
    spur = tooth_stiffness(20, 40, 0.0, 0.0, 0.0, 0.0, math.radians(20.0), 1.2, 1.6, 200.0)
    assert 12.0 < spur.single < 14.5 and 17.5 < spur.mesh < 21.0


def test_spec_law_choice_and_mesh_laws():
    base = load_gearbox(GEARBOX)
    assert base.contact.law == "impact"
    iso = base.with_changes(contact=dataclasses.replace(base.contact, law="iso6336"))
    laws = mesh_laws(iso)
    # sun-planet: c_gamma_alpha b / cos^2(beta_b) along the normal, with the hand value above
    geo_beta_b = iso.gears.helix_angle_rad  # only its order of magnitude matters for the bound below
    assert laws["outer"].kind == "iso6336" and laws["outer"].exponent == 1.0
    assert laws["outer"].stiffness == pytest.approx(12.958e9 * 0.030 / math.cos(math.radians(24.152)) ** 2, rel=2e-3)
    assert 0.5 < laws["inner"].stiffness / laws["outer"].stiffness / math.cos(geo_beta_b) < 2.0
    # eq. 13 damping: c = 2 xi sqrt(k m1 m2/(m1+m2)), xi = 0.10; ratio to stiffness ~ 1e-5 s
    assert 1e-6 < laws["outer"].damping_max / laws["outer"].stiffness < 1e-4


def test_variant_override_and_invalid_law(tmp_path):
    (tmp_path / "gearbox.toml").write_text(open(GEARBOX).read().replace('law = "impact"', 'law = "hertz"'))
    with pytest.raises(SpecError, match=r"gearbox.toml: field 'contact.law': expected one of 'impact', 'iso6336'"):
        load_gearbox(tmp_path / "gearbox.toml")
    v = tmp_path / "v.toml"
    v.write_text(f'name = "m1"\ngearbox = "{GEARBOX_ABS}"\nmesh_level = "coarse"\n'
                 '[components]\ninput_shaft = "rigid"\nsun = "rigid"\nplanets = "rigid"\nring = "rigid"\n'
                 'output_shaft = "rigid"\n[overrides.contact]\nlaw = "iso6336"\n')
    assert load_variant(v).gearbox.contact.law == "iso6336"


GEARBOX_ABS = str(__import__("pathlib").Path(GEARBOX).resolve())


def test_linear_law_and_compiled_twin_agree():
    from exudyn import symbolic as esym

    from flexgear.laws.compiled import linear_normal_force

    law = ContactLaw(4.7e8, 1.0, 4.2e3, 0.0, "iso6336")
    for delta in (-1e-5, 0.0, 1e-7, 1.7e-6, 5e-6):
        for rate in (-1e-1, 0.0, 3e-3):
            ref = float(linear_force(delta, rate, law, 1.02))
            expect = max(4.7e8 * 1.02 * delta + 4.2e3 * rate, 0.0) if delta > 0 else 0.0
            assert ref == pytest.approx(expect, abs=1e-12)
            assert linear_normal_force(delta, rate, 4.7e8 * 1.02, 4.2e3) == pytest.approx(ref, rel=1e-13, abs=1e-12)
            assert float(normal_force(delta, rate, law, 1.02)) == pytest.approx(ref, abs=1e-12)
            d, v = esym.Real(delta), esym.Real(rate)
            assert float(normal_force(d, v, law, 1.02, esym).Evaluate()) == pytest.approx(ref, rel=1e-12, abs=1e-9)
