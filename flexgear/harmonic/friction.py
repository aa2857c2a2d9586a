"""Tooth-friction excitation of the linearised model, first order: the Fourier series over the mesh phase of the
multibody model's friction generalised force at the static mesh loads.

The multibody model (flexgear.mbs.contacts.MeshFriction, the law flexgear.laws.contact.friction_forces) applies per
contact (helix half) i the generalised force on the frame coordinates

    Q_i(t) = -(a_i f_i kappa_i(phi) + b_i f_i lambda_i(phi)),   f_i = mu F_i tanh(Omega_i lambda_mean,i / v_reg),

a_i the pitch-point sliding row (displacement along w = e_z x t, off the line of action), b_i the relative-spin row
(a moment: the load's mean lever lambda_i(phi) [m] from the pitch point), kappa_i(phi) the net sliding direction of
the load on the contact lines (its sign reverses across the pitch point), F_i = F(delta_i) s(phi) the normal force
and Omega_i the relative spin rate [rad/s]. At the operating point's static deflection delta_0 (the law's own
F(delta_0) s(phi), F_0 s(phi) for the mean-stiffness force F_0) and nominal relative spin Omega_0 it is periodic
in the mesh phase phi [cycles]; its complex Fourier coefficients at +h f_mesh (h = 1..H),

    S_h = c_h[ mu F(delta_0) s sigma kappa ],   L_h = c_h[ mu F(delta_0) s sigma lambda ],   sigma = tanh(...),

phased by the contact's own mesh phase as the stiffness excitation (flexgear.harmonic.base.series_coefficients),
give the friction excitation: the generalised force -(a^T S_h + b^T L_h) at harmonic h, with a, b over the linear
model's independent coordinates (the frame rows times the basis q = B z). Left out, as flexgear.modal.linear leaves
them out: the friction's dependence on the response (mu kappa k_t x_delta: parametric, and a tangent term of order mu
of the mesh stiffness) and on the rates (sigma is saturated, d sigma / d Omega ~ 0, once Omega_0 lambda_mean exceeds
a few v_reg). The series kappa, lambda, s are the model's truncated ones (flexgear.geometry.contact_lines.
contact_line_series), so that the sign reversal enters exactly as the time-domain model sees it: no further
approximation of the non-smooth sign is made here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from flexgear.geometry.contact_lines import PeriodicSeries
from flexgear.harmonic.base import series_coefficients
from flexgear.modal.linear import FRAME_NAMES, component_name

__all__ = ["SAMPLES_PER_HARMONIC", "friction_harmonics", "friction_rows"]

SAMPLES_PER_HARMONIC = 4
"""Samples of one mesh cycle per retained harmonic H when fitting the friction force's series: the force is a
product of two truncated series of H harmonics (s kappa, s lambda: harmonics up to 2 H), whose discrete Fourier
coefficients at h <= H are exact when N > 3 H (the aliases of harmonic k <= 2 H fall on N - k > H); 4 H suffices."""

def friction_harmonics(contacts: Sequence[Any], deflections: np.ndarray, input_speed_rad_s: float,
                       harmonics: int) -> np.ndarray:
    """(2, n_c, H) complex: the friction forces' coefficients S_h (sliding row) and L_h (relative-spin row) [N, N m]
    of every contact (flexgear.mbs.contacts.GearContact) at harmonics h = 1..H (module docstring).

    ``deflections`` (n_c,) [m]: the static deflections the contact laws see; ``input_speed_rad_s`` [rad/s]: the
    signed drive speed (the nominal relative spin Omega_0 = (spin_1 - spin_2) times it, and the mesh phase's sense).
    Each contact's force over one cycle of its own phase x is flexgear.laws.contact.friction_forces of the normal
    force flexgear.laws.contact.normal_force(delta_0, 0, law, s(x)) with the series s, kappa, lambda of the contact,
    fitted by flexgear.geometry.contact_lines.PeriodicSeries.fit (exact: :data:`SAMPLES_PER_HARMONIC`).
    """
    from flexgear.laws.contact import friction_forces, normal_force

    x = np.arange(SAMPLES_PER_HARMONIC * harmonics) / (SAMPLES_PER_HARMONIC * harmonics)
    cos_c = np.zeros((2, len(contacts), harmonics))
    sin_c = np.zeros_like(cos_c)
    for i, (c, d) in enumerate(zip(contacts, deflections, strict=True)):
        spin = (c.spin_per_drive_angle[0] - c.spin_per_drive_angle[1]) * input_speed_rad_s
        normal = normal_force(float(d), 0.0, c.law, c.stiffness(x))
        forces = friction_forces(normal, spin, c.sliding(x), c.lever(x), c.friction_coefficient,
                                 c.friction_regularisation, float(c.lever.mean))
        for k, f in enumerate(forces):
            fit = PeriodicSeries.fit(np.asarray(f, float), harmonics)
            cos_c[k, i], sin_c[k, i] = fit.cos_coeffs, fit.sin_coeffs
    offset = -np.array([c.phase_offset for c in contacts])
    sense = np.array([c.phase_per_drive_angle for c in contacts]) * math.copysign(1.0, input_speed_rad_s)
    return np.stack([series_coefficients(cos_c[k], sin_c[k], offset, np.sign(sense)) for k in range(2)])


def friction_rows(lm: Any, contacts: Sequence[Any]) -> np.ndarray:
    """(2 n_c, n): the sliding rows a_i (first n_c) and relative-spin rows b_i of every contact over the independent
    coordinates z of the flexgear.modal.linear.LinearModel ``lm``: the contacts' gradient rows 1 and 2 on their two
    bodies' frame coordinates (where flexgear.mbs.contacts.MeshFriction applies the force) times the basis."""
    index = {(c.component, c.name): i for i, c in enumerate(lm.full_coordinates) if c.kind == "frame"}
    full = np.zeros((2, len(contacts), len(lm.full_coordinates)))
    for i, c in enumerate(contacts):
        for body, grad in ((c.body1, c.gradient1), (c.body2, c.gradient2)):
            cols = [index[(component_name(body), name)] for name in FRAME_NAMES]
            full[:, i, cols] += grad[1:3]
    return full.reshape(2 * len(contacts), -1) @ lm.basis
