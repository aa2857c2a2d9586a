"""Gear contact laws as small functions of numpy or Exudyn symbolic arrays (``m`` = the math module).

The ADAMS impact law of the study (section 2.1), the periodic mesh-stiffness series of eq. 11-12 and
tooth friction; their compiled (numba) twins are in :mod:`flexgear.laws.compiled`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from flexgear.geometry.involute import PeriodicSeries
from flexgear.spec import Contact

__all__ = ["ContactLaw", "impact_force", "backlash_linear_force", "periodic_value", "friction_forces"]


@dataclass(frozen=True)
class ContactLaw:
    """Impact-function parameters of one contact half (section 2.1)."""

    stiffness: float  # N/m^exponent
    exponent: float
    damping_max: float  # N s/m, reached at the penetration depth
    penetration_depth: float  # m

    @classmethod
    def from_contact(cls, contact: Contact, share: float = 1.0) -> ContactLaw:
        """The study's law scaled to a ``share`` of the face width (one helix half: 0.5)."""
        k = contact.stiffness * share
        return cls(k, contact.exponent, contact.damping_fraction_of_stiffness * k, contact.penetration_depth_m)


def impact_force(delta: Any, delta_t: Any, law: ContactLaw, factor: Any = 1.0, m: Any = np) -> Any:
    """Normal force of the impact law [N]; ``m`` is numpy or ``exudyn.symbolic``.

    F = max(0, k s <delta>^e + c_max STEP(delta, 0, 0, d, 1) delta_t), zero for delta <= 0.
    """
    mx = m.maximum if m is np else m.max
    mn = m.minimum if m is np else m.min
    pen = mx(delta, 0.0)
    ramp = mn(pen / law.penetration_depth, 1.0)
    damp = law.damping_max * ramp * ramp * (3.0 - 2.0 * ramp)
    if m is np:
        power = pen**law.exponent
    elif law.exponent == 1.5:
        power = pen * m.sqrt(pen)
    else:
        power = m.pow(pen, law.exponent)
    force = law.stiffness * factor * power
    return mx(force + damp * delta_t, 0.0)


def backlash_linear_force(delta: Any, delta_t: Any, stiffness: Any, damping: Any, backlash: Any) -> Any:
    """Linear mesh force with backlash [N] (lumped model, eq. 11-13): two-sided, zero inside the play.

    F = k delta + c delta_t for delta > 0 (drive flank), k (delta + j) + c delta_t for delta < -j (back flank,
    j = normal backlash [m]), 0 in between; ``stiffness`` may already carry the variation s(phi).
    """
    delta = np.asarray(delta, dtype=float)
    drive = stiffness * delta + damping * delta_t
    back = stiffness * (delta + backlash) + damping * delta_t
    out = np.where(delta > 0.0, drive, np.where(delta < -backlash, back, 0.0))
    return float(out) if np.ndim(out) == 0 else out


def periodic_value(phase_cycles: Any, series: PeriodicSeries, m: Any = np) -> Any:
    """Value of a Fourier series in the mesh phase (cycles); ``m`` is numpy or ``exudyn.symbolic``.

    Uses one cosine and one sine and the recurrences cos(n x) = 2 cos(x) cos((n-1) x) - cos((n-2) x),
    sin(n x) = sin(x) U_(n-1)(cos x) with U_n = 2 cos(x) U_(n-1) - U_(n-2): short compiled expressions.
    """
    out = series.mean
    if len(series.cos_coeffs) == 0 or not (np.any(series.cos_coeffs) or np.any(series.sin_coeffs)):
        return out
    x = 2.0 * math.pi * phase_cycles
    c1, s1 = m.cos(x), m.sin(x)
    t_prev, t_cur = 1.0, c1  # Chebyshev T_(n-1), T_n
    u_prev, u_cur = 0.0, 1.0  # U_(n-2), U_(n-1)
    for a, b in zip(series.cos_coeffs, series.sin_coeffs, strict=True):
        if np.ndim(a) == 0:  # plain numbers (symbolic expressions need Python floats)
            a, b = float(a), float(b)
        out = out + a * t_cur + b * s1 * u_cur
        t_prev, t_cur = t_cur, 2.0 * c1 * t_cur - t_prev
        u_prev, u_cur = u_cur, 2.0 * c1 * u_cur - u_prev
    return out


def friction_forces(normal_force: Any, relative_spin: Any, sliding: Any, lever: Any, mu: float,
                    regularisation: float, mean_lever: float, m: Any = np) -> tuple[Any, Any]:
    """Lumped Coulomb friction of a mesh: forces on the sliding and relative-spin coordinates.

    Each contact line at distance s from the pitch point slides with s * Omega (Omega = relative spin
    rate omega_1 - omega_2); summed over the lines with the load uniform along them, friction gives
    mu F sigma kappa(phi) on the sliding coordinate (pitch-point sliding along w = e_z x t) and
    mu F sigma lambda(phi) on the relative spin (a moment), sigma = tanh(Omega lambda_mean / v_reg)
    the regularised sign of sliding.
    """
    sigma = m.tanh(relative_spin * (mean_lever / regularisation))
    f = mu * normal_force * sigma
    return f * sliding, f * lever
