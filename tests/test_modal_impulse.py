"""The linearised modes against time integration (flexgear.modal.impulse): models 1 and 4 at the load case's speed,
and the spur planetary example's rigid variant, whose carrier turns (its modes in the carrier's axes, Coriolis terms
included, against a record read in the same axes).

Both sides see the same variant: the production contact law (``impact``, entering the linearisation with its tangent
1.5 k delta_0^0.5 and its damping at delta_0), mean mesh stiffness (``[contact_assumed] stiffness_variation =
"constant"``), the quick load case with its ramps shortened to ``RAMP_S`` (the steady operating point does not depend
on them). The time integration runs through the ramps, then a Hann force pulse on the output-shaft bearing seat;
its free response (the difference to an undisturbed continuation from the same state) is identified as damped
modes by the matrix pencil. A mode has a clear peak when it is lightly damped (zeta below ``PEAK_DAMPING``; the
velocity spectrum of a mode has a half-power bandwidth of 2 zeta f) and carries at least ``PEAK_AMPLITUDE`` of the
largest mode's amplitude, and its linearised mode is resolvable in the record: no other lightly damped linearised
mode within ``1 / (2 WINDOW_S)`` (a cluster closer than that, e.g. model 4's planet pair between a translational
and a rotational mode within 8 Hz, comes out of the pencil as one pole whose damping belongs to none of them). The
five lowest of them lie at the linearised modes (``fg.modes`` of ``fg.linearize`` at the same operating point,
matched nearest in the complex plane of the roots): frequency within 1 %, damping ratio within 20 %.

Why not the peaks of the record's Fourier transform: a record of some tens of ms cannot resolve them. The lightest
mode (zeta ~ 0.005, rotational, ~143 Hz) decays over 0.2 s and leaks side lobes every 1 / T; with an exponential window
that removes them, the four translational modes between 680 and 750 Hz (zeta ~ 0.035, half-power bandwidths wider
than their spacing) merge into one peak. The matrix pencil reads the same record without either limit.

The integrator: the production generalized-alpha (spectral radius 0.8, the variant's step), whose algorithmic damping
ratio stays below 1 % of the tolerance at the checked frequencies (:func:`test_integrator_damping_below_tolerance`).
The planetary example's own step (1 / 56 of its mesh period, 44.6 us) lengthens the period of a 1.6 kHz mode by
1.7 % (Chung & Hulbert's period error, which its record shows: every pole below its linearised mode by that share);
it is integrated at ``PLANETARY_STEP_S``, where the period error stays below a tenth of the tolerance as for the study's
variants, and from a state ``PLANETARY_SETTLE_S`` after its shortened ramps, when their transient has died out.
Without numerical damping (spectral radius 1) model 4's continuations grow: its flexible sun and ring turn under the
contacts, so the contact constraints' coefficients change every step, and nothing damps the constraints'
high-frequency oscillation, which feeds the low modes. The growth is the integrator's, not the model's: the linearised
modes are all damped, and at spectral radius 0.8, which leaves the low modes' damping as it is, it is gone.
"""

import dataclasses
import math

import numpy as np
import pytest
from conftest import ROOT, VARIANTS

from flexgear.modal import linearize, modes
from flexgear.modal.impulse import damped_poles, generalized_alpha_damping, impulse_response
from flexgear.spec import load_variant

RAMP_S = 0.005  # s: the quick load case's ramps, shortened
WINDOW_S = 0.08  # s: each recorded continuation (resolves modes 1 / (2 WINDOW_S) = 6.25 Hz apart)
SAMPLE_S = 4.0e-5  # s: the pencil's sampling (Nyquist 12.5 kHz, beyond the pulse's band)
ORDER = 80  # signal-subspace dimension of the matrix pencil (40 modes, more than the record holds below 3 kHz)
F_MAX = 3000.0  # Hz: the band read (the pulse's spectrum is below 3 % of its impulse beyond 5 kHz)
PEAK_DAMPING = 0.1  # a mode with a clear peak: damping ratio below this ...
PEAK_AMPLITUDE = 0.05  # ... and at least this share of the largest mode's amplitude
CHECKED = 5
F_RTOL, ZETA_RTOL = 0.01, 0.20
PLANETARY = ROOT / "examples" / "spur_planetary" / "rigid.toml"
PLANETARY_STEP_S = 1.0e-5  # s: the planetary example's integration step here (module docstring)
PLANETARY_SETTLE_S = 0.05  # s: from the ramps' end to the pulse


def _variant(name: str):
    v = load_variant(PLANETARY if name == "planetary" else VARIANTS / "quick" / f"{name}.toml")
    return dataclasses.replace(v, gearbox=v.gearbox.with_fields("load_case", ramp_time_s=RAMP_S))


@pytest.fixture(scope="module", params=["model1", pytest.param("model4", marks=pytest.mark.slow), "planetary"])
def identified(request):
    variant = _variant(request.param)
    linear = modes(linearize(variant), F_MAX)
    planetary = {"step_s": PLANETARY_STEP_S, "settle_s": PLANETARY_SETTLE_S} if request.param == "planetary" else {}
    response = impulse_response(variant, window_s=WINDOW_S, **planetary)
    poles = damped_poles(response, ORDER, sample_s=SAMPLE_S, f_max_hz=F_MAX)
    return linear, response, poles


def assert_clear_peaks_at_linearised_modes(linear, poles, window_s: float = WINDOW_S) -> None:
    """The lightly damped, resolvable poles with at least ``PEAK_AMPLITUDE`` of the largest amplitude (module
    docstring): at least ``CHECKED`` of them, and the first ``CHECKED`` at their nearest linearised mode within
    ``F_RTOL`` in frequency and ``ZETA_RTOL`` in damping ratio."""
    largest = max(p.amplitude for p in poles)
    w = 2 * math.pi * linear.frequencies_hz
    roots = w * (-linear.damping_ratios + 1j * np.sqrt(1 - linear.damping_ratios ** 2))
    light = linear.frequencies_hz[linear.damping_ratios < PEAK_DAMPING]

    def nearest(p) -> int:
        wp = 2 * math.pi * p.frequency_hz
        return int(np.argmin(np.abs(roots - wp * (-p.damping_ratio + 1j * math.sqrt(1 - p.damping_ratio ** 2)))))

    def resolvable(j: int) -> bool:
        return np.count_nonzero(np.abs(light - linear.frequencies_hz[j]) < 0.5 / window_s) <= 1

    peaks = [p for p in poles if p.damping_ratio < PEAK_DAMPING and p.amplitude >= PEAK_AMPLITUDE * largest
             and resolvable(nearest(p))]
    assert len(peaks) >= CHECKED
    for p in peaks[:CHECKED]:
        j = nearest(p)
        assert p.frequency_hz == pytest.approx(linear.frequencies_hz[j], rel=F_RTOL), (p, linear.kinds[j])
        assert p.damping_ratio == pytest.approx(linear.damping_ratios[j], rel=ZETA_RTOL), (p, linear.kinds[j])


def test_clear_peaks_at_linearised_modes(identified):
    linear, _, poles = identified
    assert_clear_peaks_at_linearised_modes(linear, poles)


def test_nothing_moves_before_the_pulse(identified):
    """Both continuations start from the same state under the same loads: their difference is zero until the
    pulse acts, and it is the pulse's doing afterwards."""
    _, response, _ = identified
    v = response.velocity
    assert np.abs(v[response.time_s <= 0.0]).max() == 0.0
    assert np.abs(v).max() > 0.0


def test_integrator_damping_below_tolerance(identified):
    """Generalized-alpha (Chung & Hulbert 1993) on the lightly damped modes at the variant's step: no algorithmic
    damping at spectral radius 1; at the record's 0.8 a damping ratio below 1 % of the tolerance on the linearised
    one. The period error (both radii, about (omega h)^2 / 12) stays below a tenth of the frequency tolerance up to
    2 kHz."""
    linear, response, _ = identified
    omega_h = 2 * math.pi * linear.frequencies_hz * response.step_s
    xi_1, _ = generalized_alpha_damping(omega_h, 1.0)
    assert np.all(np.abs(xi_1) < 1e-12)
    xi, period = generalized_alpha_damping(omega_h, 0.8)
    under = linear.damping_ratios < PEAK_DAMPING
    assert np.all(xi[under] < 0.01 * ZETA_RTOL * linear.damping_ratios[under])
    low = linear.frequencies_hz <= 2000.0
    assert np.all(np.abs(period[low]) < 0.1 * F_RTOL)


def test_in_plane_pairs_read_in_the_carrier_axes():
    """A velocity fixed in the carrier's axes, seen in ground axes as it turns (v = T(theta) u), is read back as u;
    axial and spin channels are left as they are."""
    from flexgear.modal.impulse import in_carrier_axes

    channels = ("input.v_x", "input.v_y", "input.v_z", "input.w_x", "input.w_y", "input.w_z")
    theta = np.linspace(0.0, 7.0, 50)
    u = np.array([0.3, -1.2, 0.7, 2.0, 0.5, -0.4])
    c, s = np.cos(theta), np.sin(theta)
    ground = np.column_stack([c * u[0] - s * u[1], s * u[0] + c * u[1], np.full_like(theta, u[2]),
                              c * u[3] - s * u[4], s * u[3] + c * u[4], np.full_like(theta, u[5])])
    np.testing.assert_allclose(in_carrier_axes(ground, channels, theta), np.tile(u, (50, 1)), atol=1e-14)
