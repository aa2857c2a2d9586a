"""Tooth-friction excitation of the linearised lumped model, first order: the Fourier series over the mesh phase of
the lumped time model's friction generalised force at the static mesh loads.

The time model (flexgear.lumped.run._evaluate) applies at mesh m, gear 1 (sun, or planet on a ring mesh) and
gear 2 (planet, or ring), with the normal force F_m(phi) > 0 at the mesh phase phi [cycles],

    f_m = mu F_m tanh(g1_m omega_1 p_bt / (|g1_m| v_reg))          (flexgear.laws.compiled.tooth_friction)
    Q = f_m [ t(phi) (tau_m on x_2, y_2 - tau_m on x_1, y_1) - a_1(phi) e_theta1 + a_2(phi) e_theta2 ],

t, a_1, a_2 [-, m, m] the friction tables (flexgear.lumped.model.FrictionTables: force and arms per mu F_n)
interpolated linearly between their N nodes phi_j = j / N, tau_m = J n_m. At the static deflection delta_0 and the
rigid running (omega_1 the nominal spin of gear 1 in the carrier frame, delta' = 0) the normal force is the law's
F_m(phi) = F_0 s(phi) (F_0 = k delta_0^e; s(phi) = 1 + sum_n c_n cos 2 pi n (phi - centre), the stiffness series)
and f_m = mu F_0 s(phi) sigma_m with sigma_m = tanh(...) constant. The complex Fourier coefficients of
s(phi) T(phi) (T = t, a_1 or a_2) are exact: the piecewise-linear interpolant has
T^(k) = (1/N) DFT_k(T_j) sinc^2(k / N) (the hat function's transform), and

    (s T)^(h) = sum_(n=-H_s..H_s) s^(n) T^(h - n),   s^(0) = 1,   s^(+-n) = (c_n / 2) e^(-+ i 2 pi n centre).

Phased as the stiffness excitation (flexgear.harmonic.base.series_coefficients with the mesh's phase offset), the
generalised force at harmonic h is -R^T [F_t; F_1; F_2]_h with R = [-(tau rows); e_theta1; -e_theta2] over the free
coordinates and F_X,h = mu F_0 sigma (s X)_h. Left out, as for the stiffness excitation: the friction's dependence on
the response (through F = k delta, the parametric term of order mu) and on the rates (sigma saturates once the
sliding speed exceeds a few v_reg).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from flexgear.harmonic.base import series_coefficients
from flexgear.lumped.model import CENTRAL_MEMBERS

__all__ = ["LumpedFriction", "lumped_friction", "nominal_spin_rates", "CHECK_SAMPLES_PER_HARMONIC"]

CHECK_SAMPLES_PER_HARMONIC = 64
"""Samples per stiffness harmonic of the mesh cycle on which s(phi) F_0 is checked to stay positive (the time model
drops friction where the normal force vanishes, which the first-order series cannot follow)."""


@dataclass(frozen=True)
class LumpedFriction:
    """The lumped model's friction excitation (:func:`lumped_friction`).

    ``rows`` (3 n_m, n_f): translation rows -(tau on gear 2 - tau on gear 1), gear 1 spin rows +e, gear 2 spin rows
    -e of every mesh over the free coordinates; ``unit`` (3 n_m, H) complex [-, m, m]: the coefficients (s t)_h,
    (s a_1)_h, (s a_2)_h phased at +h f_mesh, per unit friction force mu F_0 sigma; ``slip_per_rad_s`` (n_m,)
    [s/rad]: the law's slip g1 omega_1 p_bt / (|g1| v_reg) per rad/s of input speed; ``f0`` (n_m,) [N]; ``mu`` [-].
    """

    rows: np.ndarray
    unit: np.ndarray
    slip_per_rad_s: np.ndarray
    f0: np.ndarray
    mu: float

    def coefficients(self, input_speed_rad_s: float) -> np.ndarray:
        """(3 n_m, H) complex [N, N m]: mu F_0 sigma times :attr:`unit` at the input speed [rad/s], sigma from
        flexgear.laws.compiled.tooth_friction (the time model's law)."""
        from flexgear.laws.compiled import tooth_friction

        ff = np.array([tooth_friction(self.mu, float(f), float(s) * input_speed_rad_s)
                       for f, s in zip(self.f0, self.slip_per_rad_s, strict=True)])
        return np.tile(ff, 3)[:, None] * self.unit


def nominal_spin_rates(model: Any) -> np.ndarray:
    """(n,) every coordinate's rate per rad/s of input speed in the rigid running, carrier frame [rad/s per rad/s]:
    prescribed spins their coefficient, translations and the carrier spin 0, the other spins from G r = 0 (every
    mesh's deflection rate zero), solved in the least-squares sense (an exact solution: the gear train's kinematics).
    ``model``: a flexgear.lumped.run.LumpedModel."""
    s = model.system
    r = np.zeros(s.n)
    r[model.presc] = model.presc_coef
    known = np.zeros(s.n, bool)
    known[model.presc] = True
    known[np.arange(s.n) % 3 != 2] = True
    known[3 * CENTRAL_MEMBERS.index("carrier") + 2] = True  # the carrier's spin (x, y, theta per member): the frame
    unknown = np.flatnonzero(~known)
    G = s.mesh_G
    r[unknown] = np.linalg.lstsq(G[:, unknown], -G[:, known] @ r[known], rcond=None)[0]
    return r


def _mesh_bodies(model: Any, m: int) -> tuple[int, int]:
    """Bodies (gear 1, gear 2) of mesh m as flexgear.lumped.run._evaluate numbers them (0 sun, 1 ring, 3 + i
    planet i)."""
    nm = model.mesh_type.size
    if model.mesh_type[m] == 0:
        return 0, 3 + m
    return 3 + m - nm // 2, 1


def _interpolant_coefficients(table: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Complex Fourier coefficients at integers ``k`` of the periodic piecewise-linear interpolant of ``table`` (N,)
    on phi_j = j / N: (1/N) DFT_k sinc^2(k / N)."""
    n = table.size
    return np.fft.fft(table)[np.mod(k, n)] / n * np.sinc(k / n) ** 2


def lumped_friction(model: Any, free: np.ndarray, f0: np.ndarray, harmonics: int,
                    rate_sign: np.ndarray) -> LumpedFriction | None:
    """The friction excitation of the lumped ``model`` (a flexgear.lumped.run.LumpedModel) at the static mesh forces
    ``f0`` (n_m,) [N] over the ``free`` coordinates at harmonics 1..``harmonics``, each mesh's phase running with
    ``rate_sign`` (n_m,) as in the stiffness excitation (module docstring); None without
    friction (mu = 0). Raises ValueError where s(phi) F_0 vanishes (the time model drops friction where F <= 0)."""
    from flexgear.lumped.kernel_layout import MU

    mu = float(model.fp[MU])
    if mu <= 0.0:
        return None
    nm = model.mesh_type.size
    pos = {int(j): k for k, j in enumerate(free)}
    rows = np.zeros((3, nm, free.size))
    unit = np.zeros((3, nm, harmonics), complex)
    h = np.arange(1, harmonics + 1)
    rate = nominal_spin_rates(model)
    slip = np.zeros(nm)
    samples = CHECK_SAMPLES_PER_HARMONIC * (model.harmonics.shape[1] + 1)
    fine = np.arange(samples) / samples
    for m in range(nm):
        b1, b2 = _mesh_bodies(model, m)
        for b, sign in ((b1, -1.0), (b2, 1.0)):  # Q = f t (tau on 2 - tau on 1): row -(tau on 2 - tau on 1)
            for a in range(2):
                if 3 * b + a in pos:
                    rows[0, m, pos[3 * b + a]] -= sign * model.tau[m, a]
        if 3 * b1 + 2 in pos:
            rows[1, m, pos[3 * b1 + 2]] = 1.0
        if 3 * b2 + 2 in pos:
            rows[2, m, pos[3 * b2 + 2]] = -1.0
        slip[m] = model.g1[m] * rate[3 * b1 + 2] * model.friction_scale[m]
        c = np.asarray(model.harmonics[m], float)
        n = np.arange(1, c.size + 1)
        if f0[m] * (1.0 + np.cos(2.0 * np.pi * np.outer(fine, n)) @ c).min() <= 0.0:
            raise ValueError("lumped friction: the normal force vanishes within the mesh cycle")
        s_hat = np.r_[(0.5 * c * np.exp(2j * np.pi * n * model.phase_centre[m]))[::-1], 1.0,
                      0.5 * c * np.exp(-2j * np.pi * n * model.phase_centre[m])]  # s^(-H_s..H_s)
        shift = np.arange(-c.size, c.size + 1)
        for k in range(3):
            t_hat = _interpolant_coefficients(model.tables[model.mesh_type[m], :, k], h[:, None] - shift[None])
            unit[k, m] = t_hat @ s_hat  # (s T)^(h), h >= 1
    # real series: a_h cos + b_h sin with a_h - i b_h = 2 (s T)^(h); phased as the stiffness excitation
    phased = [series_coefficients(2.0 * unit[k].real, -2.0 * unit[k].imag, model.phase_offset, rate_sign)
              for k in range(3)]
    return LumpedFriction(rows.reshape(3 * nm, -1), np.vstack(phased), slip, np.asarray(f0, float), mu)
