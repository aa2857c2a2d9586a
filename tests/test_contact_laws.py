"""Contact law, stiffness variation and drive angle: pure functions, numpy and compiled forms agree."""

import math

import numpy as np
import pytest

from flexgear.connectors import ContactLaw, drive_angle, impact_force, stiffness_factor
from flexgear.theory import step, step_integral

LAW = ContactLaw(stiffness=1e8, exponent=1.5, damping_max=1e5, penetration_depth=1e-4)


def test_impact_law_values():
    # separated teeth carry nothing, also when approaching
    assert impact_force(-1e-5, 1.0, LAW) == 0.0
    # static penetration: k delta^e (study's mesh force needs ~0.4 mm at k = 1e8)
    delta = (798.21 / 1e8) ** (1 / 1.5)
    assert impact_force(delta, 0.0, LAW) == pytest.approx(798.21)
    # damping ramps with STEP(delta, 0, 0, d, c_max): half way -> half of c_max
    assert impact_force(0.5e-4, 1e-3, LAW) - impact_force(0.5e-4, 0.0, LAW) == pytest.approx(0.5 * 1e5 * 1e-3)
    # full damping beyond the penetration depth, no adhesion when separating fast
    assert impact_force(2e-4, 1e-3, LAW) - impact_force(2e-4, 0.0, LAW) == pytest.approx(100.0)
    assert impact_force(1e-6, -1.0, LAW) == 0.0


def test_stiffness_factor_chebyshev_equals_cosine_sum():
    c = np.array([-0.0158, 0.0087, -0.0012, 0.004])
    phi = np.linspace(0, 3, 301)
    direct = 1 + sum(cn * np.cos(2 * np.pi * (n + 1) * (phi - 0.37)) for n, cn in enumerate(c))
    assert np.max(np.abs(stiffness_factor(phi, c, 0.37) - direct)) < 1e-12
    assert stiffness_factor(phi, np.zeros(3), 0.0) == 1.0


def test_drive_angle_is_step_integral():
    t = np.linspace(0, 0.6, 1201)
    w = 6000 * 2 * math.pi / 60
    assert np.allclose(drive_angle(t, 0.5, w), step_integral(t, 0.5, w), rtol=0, atol=1e-9)
    h = 1e-7
    assert (drive_angle(0.3 + h, 0.5, w) - drive_angle(0.3 - h, 0.5, w)) / (2 * h) == pytest.approx(
        step(0.3, 0, 0, 0.5, w), rel=1e-6)


def test_compiled_forms_match_numpy():
    from exudyn import symbolic as esym

    d, v, t = esym.Real(2.5e-4), esym.Real(3e-3), esym.Real(0.31)
    c = np.array([-0.0158, 0.0087, -0.0012])
    f_sym = impact_force(d, v, LAW, stiffness_factor(drive_angle(t, 0.5, 628.3) * 7.0, c, 0.2, esym), esym)
    f_np = impact_force(2.5e-4, 3e-3, LAW, stiffness_factor(drive_angle(0.31, 0.5, 628.3) * 7.0, c, 0.2))
    assert f_sym.Evaluate() == pytest.approx(float(f_np), rel=1e-12)
