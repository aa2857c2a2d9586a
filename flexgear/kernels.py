"""Compiled (numba) kernels for per-step work that cannot be an Exudyn symbolic function.

Each kernel re-implements, for speed, laws defined as plain functions elsewhere; tests check that
both give the same numbers (tests/test_contact_laws.py).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["mesh_friction_forces", "periodic_values"]


@njit(cache=True)
def mesh_friction_forces(phase, delta, delta_t, q_t, stiffness, exponent, damping_max, depth,  # noqa: PLR0913
                         means, cos_c, sin_c, mu, reg, sliding_rows, spin_rows):  # pragma: no cover - compiled
    """Generalized friction forces Q = -(A^T f_slide + B^T f_spin) of all contacts.

    Same law as connectors.impact_force (normal force with the stiffness series), connectors.periodic_value
    (series index 0: stiffness factor, 1: sliding direction kappa, 2: lever lambda [m]) and
    connectors.friction_forces (f = mu F tanh(Omega lambda_mean / v_reg) (kappa, lambda)).
    """
    n_c, n_h = cos_c.shape[1], cos_c.shape[2]
    spin_rate = spin_rows @ q_t
    q = np.zeros(sliding_rows.shape[1])
    for i in range(n_c):
        val = np.empty(3)
        for k in range(3):
            v = means[k, i]
            for h in range(n_h):
                x = 2.0 * math.pi * (h + 1) * phase[i]
                v += cos_c[k, i, h] * math.cos(x) + sin_c[k, i, h] * math.sin(x)
            val[k] = v
        pen = max(delta[i], 0.0)
        ramp = min(pen / depth[i], 1.0)
        normal = max(stiffness[i] * val[0] * pen ** exponent[i]
                     + damping_max[i] * ramp * ramp * (3.0 - 2.0 * ramp) * delta_t[i], 0.0)
        f = mu[i] * normal * math.tanh(spin_rate[i] * means[2, i] / reg[i])
        q -= sliding_rows[i] * (f * val[1]) + spin_rows[i] * (f * val[2])
    return q


@njit(cache=True)
def periodic_values(phase, means, cos_c, sin_c):  # pragma: no cover - compiled
    """Fourier series values per contact, as connectors.periodic_value: cos_c, sin_c (n_contacts, n_harmonics)."""
    out = means.copy()
    for i in range(phase.shape[0]):
        for h in range(cos_c.shape[1]):
            x = 2.0 * math.pi * (h + 1) * phase[i]
            out[i] += cos_c[i, h] * math.cos(x) + sin_c[i, h] * math.sin(x)
    return out
