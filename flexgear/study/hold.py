"""Exact integration of linear modes driven by sampled forces: the input taken linear between its samples.

A mode in first-order form, eta' = lambda eta + g(t), with g linear over each step of length dt (a first-order
hold, as scipy.signal.lsim's default), advances exactly by

    eta(t + dt) = e^z eta(t) + b0 g(t) + b1 g(t + dt),   z = lambda dt,
    b1 = dt (e^z - 1 - z) / z^2,   b0 = dt (e^z - 1) / z - b1,

one recursive filter over the whole record (scipy.signal.lfilter). The run-up's swept predictions
(flexgear.study.runup.swept_peak: one mode) and the linearised model's run-up (flexgear.study.runup_linear: all its
modes) integrate so.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SERIES_LIMIT", "hold_step_coefficients", "single_mode_acceleration"]

SERIES_LIMIT = 1e-3
"""|z| = |lambda dt| below which the step coefficients b0, b1 are evaluated by their Taylor series (their closed
forms lose digits to cancellation as z -> 0; the series' truncation error is below |z|^4 / 120)."""


def hold_step_coefficients(lam: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(e^z, b0, b1), z = ``lam`` ``dt``, of the exact step of eta' = lambda eta + g(t) over ``dt`` [s] with g linear
    between its samples (first-order hold): eta(t + dt) = e^z eta(t) + b0 g(t) + b1 g(t + dt),
    b1 = dt (e^z - 1 - z) / z^2, b0 = dt (e^z - 1) / z - b1."""
    z = lam * dt
    small = np.abs(z) < SERIES_LIMIT
    zs = np.where(small, 1.0, z)
    e1 = np.expm1(z)
    r0 = np.where(small, 1.0 + z / 2 + z**2 / 6 + z**3 / 24, e1 / zs)  # (e^z - 1) / z
    r1 = np.where(small, 0.5 + z / 6 + z**2 / 24 + z**3 / 120, (e1 - z) / zs**2)  # (e^z - 1 - z) / z^2
    return e1 + 1.0, dt * (r0 - r1), dt * r1


def single_mode_acceleration(time_s: np.ndarray, force: np.ndarray, mode_hz: float, damping_ratio: float
                             ) -> np.ndarray:
    """q'' [force unit] of q'' + 2 zeta omega q' + omega^2 q = f(t) from rest (omega = 2 pi ``mode_hz``, zeta =
    ``damping_ratio`` < 1) on the uniform grid ``time_s`` [s], f = ``force`` taken linear between its samples.

    With lambda = -zeta omega + i omega sqrt(1 - zeta^2), q = 2 Re(eta) for eta' = lambda eta + f / (lambda -
    conj(lambda)), integrated exactly per step (:func:`hold_step_coefficients`; one recursive filter), and q'' = f +
    2 Re(lambda^2 eta) (lambda^2 = -omega^2 - 2 zeta omega lambda)."""
    from scipy.signal import lfilter

    t = np.asarray(time_s, float)
    f = np.asarray(force, float)
    if not 0.0 <= damping_ratio < 1.0:
        raise ValueError(f"single_mode_acceleration: damping ratio {damping_ratio} outside [0, 1)")
    dt = float(t[1] - t[0])
    if not np.allclose(np.diff(t), dt, rtol=1e-6, atol=1e-12):
        raise ValueError("single_mode_acceleration needs uniformly sampled times")
    w = 2.0 * math.pi * mode_hz
    lam = complex(-damping_ratio * w, w * math.sqrt(1.0 - damping_ratio**2))
    gain = 1.0 / (lam - lam.conjugate())
    e, b0, b1 = (complex(x[0]) for x in hold_step_coefficients(np.array([lam]), dt))
    g = gain * f
    eta, _ = lfilter([b1, b0], [1.0, -e], g, zi=[-b1 * g[0]])  # eta(t_0) = 0
    return f + 2.0 * (lam * lam * eta).real
