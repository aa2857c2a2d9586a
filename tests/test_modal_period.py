"""Modes over one revolution of the flexible gears (flexgear.modal.period), on model 4 with only the ring flexible.

A flexible gear's contact columns turn with it, so the linearised system depends on its angle and is periodic in
one revolution of it: the modes at t* and t* + P are the same (P = 2 pi / Omega_ring, the star gearbox's ring at
z_s / z_r of the input speed), those half a revolution on are not. The spread over the samples covers both.
"""

import dataclasses
import math

import numpy as np
import pytest
from conftest import VARIANTS

from flexgear.modal import linearize, modes
from flexgear.modal.period import period_modes, period_samples
from flexgear.spec import load_variant

F_MAX = 5000.0  # Hz


@pytest.fixture(scope="module")
def ring_only():
    v = load_variant(VARIANTS / "model4.toml")
    return dataclasses.replace(v, components={**v.components, "sun": "rigid"})


def test_one_revolution_of_the_ring_is_the_period(ring_only):
    first = linearize(ring_only)
    assert first.flexible == ("ring",)
    times = period_samples(first, 4)
    period = 4 * (times[1] - times[0])
    g, lc = ring_only.gearbox.gears, ring_only.gearbox.load_case
    assert period == pytest.approx(60.0 / (lc.input_speed_rpm * g.sun_teeth / g.ring_teeth), rel=1e-12)
    f0 = modes(first, F_MAX).frequencies_hz
    f_full = modes(linearize(ring_only, t_star=float(times[0] + period)), F_MAX).frequencies_hz
    f_half = modes(linearize(ring_only, t_star=float(times[2])), F_MAX).frequencies_hz
    assert len(f_full) == len(f0) == len(f_half)
    np.testing.assert_allclose(f_full, f0, rtol=1e-9)
    moved = np.abs(f_half - f0) / f0
    assert moved.max() > 1e-4  # the angle matters: the periodicity is not that of a constant

    m = period_modes(ring_only, None, F_MAX, samples=4)
    assert np.all(m.spread_pct >= 100.0 * moved * f0 / m.frequencies_hz * (1 - 1e-9))


def test_rigid_gears_one_operating_point(model1):
    assert period_samples(linearize(model1), 12).size == 1
    assert math.isclose(float(period_modes(model1, None, F_MAX).spread_pct.max()), 0.0)
