"""Fast solve of the harmonic problem over a speed grid: the spin-parametrised linear model on a truncated modal basis
with its residual static part.

Spin parametrisation. Linearised at the same gear angles and with the same dynamic modes at every speed
(flexgear.harmonic.response), the gearbox's matrices depend on the spin speed Omega (rad/s of the input) only
through the spin terms and the operating point moves only through the centrifugal load:

    M(Omega) = M,   D(Omega) = D,   G(Omega) = Omega G_1,   K(Omega) = K_0 + Omega^2 K_2,
    delta_0(Omega) = delta_00 + Omega^2 delta_02                                         (1)

(gyroscopic terms linear in Omega; spin softening, and the static deflections it changes, quadratic). Two
linearisations at Omega_a != Omega_b fix every term of (1): G_1 = G_a / Omega_a, K_2 = (K_b - K_a) / (Omega_b^2 -
Omega_a^2), K_0 = K_a - Omega_a^2 K_2, and the same for delta_0 (:func:`fit_spin`).

Modal solve. Let Phi (n, n) be the modes of (K_0_sym, M), Phi^T M Phi = I, Phi^T K_0 Phi = Lambda (K_0_sym the
symmetric part of K_0), in ascending frequency f_k. At excitation frequency omega only the modes below a cut-off
f_c = ``ratio`` omega / 2 pi respond dynamically; the others respond quasi-statically. The Ritz basis

    V_m = [Phi_m,  Phi_t Q_m],    Q_m = orth(Lambda_t^-1 Phi_t^T B)                     (2)

keeps the m modes below f_c and adds the residual static part of the truncated modes t (the static responses of
the modes above f_c to the excitation's force directions B, the contacts' rows g^T, and their mass corrections
Lambda_t^-j Phi_t^T B, orthonormalised: Q_m^T Q_m = I, so V_m^T M V_m = I). On V_m the problem

    (V^T K(Omega) V - omega^2 I + i omega V^T (D + Omega G_1) V) y = V^T F,    x = V y           (3)

is exact at omega = 0 (V spans K_0^-1 B through the modes kept and the static residual); of the truncated modes'
dynamic amplification 1 / (1 - (omega / omega_k)^2) it misses the terms beyond the residual's order (the coupling
of the modes through D and G is kept within V). Each harmonic of each speed gets its own m; the projected
matrices are computed once per m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["SpinFit", "fit_spin", "ModalSolver", "MODAL_CUTOFF_RATIO"]

MODAL_CUTOFF_RATIO = 1.5
"""f_c / f of the modal solve (module docstring, eq. 3): modes up to 1.5 times the excitation frequency are
dynamic; with :data:`RESIDUAL_ORDER` = 3 the others' response is exact to order (f / f_k)^6 < 1.5^-6 = 9 % of
their (quasi-static, small) share."""

RESIDUAL_ORDER = 3
"""Residual vectors per force direction (module docstring, eq. 2): the static response Lambda_t^-1 Phi_t^T B of
the truncated modes and its mass corrections Lambda_t^-j Phi_t^T B, j = 2..order: the truncated modes' response
1 / (lambda_k - omega^2) = sum_j omega^(2 j - 2) / lambda_k^j is then exact up to order (omega^2 / lambda_k)^order."""

BLOCK_STEP = 1.0 / 40.0
"""The modes kept at a frequency are rounded up to a multiple of this fraction of all modes: at most 40 + 1
projected blocks per model."""

_RANK_TOL = 1e-10  # singular values of the static residual vectors below this fraction of the largest are dropped


@dataclass
class SpinFit:
    """The spin-parametrised linear model (module docstring, eq. 1) over the independent coordinates z.

    ``mass``, ``damping``, ``g1`` [N s / m per rad/s...], ``k0``, ``k2`` [N/m per (rad/s)^2 ...]; ``delta00``,
    ``delta02``: static deflection of each contact [m] and its Omega^2 coefficient [m s^2]; ``omega_fit`` [rad/s]:
    the two spin speeds linearised.
    """

    mass: np.ndarray
    damping: np.ndarray
    g1: np.ndarray
    k0: np.ndarray
    k2: np.ndarray
    delta00: np.ndarray
    delta02: np.ndarray
    omega_fit: tuple[float, float]

    def stiffness(self, omega: float) -> np.ndarray:
        return self.k0 + omega**2 * self.k2

    def gyroscopic(self, omega: float) -> np.ndarray:
        return omega * self.g1

    def static_deflections(self, omega: float) -> np.ndarray:
        return self.delta00 + omega**2 * self.delta02


def fit_spin(omega_a: float, omega_b: float, a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> SpinFit:
    """Eq. 1's terms from the linearisations ``a`` and ``b`` at spin speeds ``omega_a`` != ``omega_b`` [rad/s] (both
    non-zero), each a dict with ``mass``, ``damping``, ``gyroscopic``, ``stiffness`` (on the same coordinates) and
    ``delta`` (static contact deflections [m]). M and D: the mean of the two (equal up to round-off)."""
    if omega_a == 0.0 or omega_b == 0.0 or abs(omega_a) == abs(omega_b):
        raise ValueError(f"fit_spin: two distinct non-zero spin speeds expected, got {omega_a}, {omega_b}")
    s = 1.0 / (omega_b**2 - omega_a**2)
    k2 = (b["stiffness"] - a["stiffness"]) * s
    d2 = (b["delta"] - a["delta"]) * s
    return SpinFit(mass=0.5 * (a["mass"] + b["mass"]), damping=0.5 * (a["damping"] + b["damping"]),
                   g1=0.5 * (a["gyroscopic"] / omega_a + b["gyroscopic"] / omega_b),
                   k0=a["stiffness"] - omega_a**2 * k2, k2=k2, delta00=a["delta"] - omega_a**2 * d2, delta02=d2,
                   omega_fit=(float(omega_a), float(omega_b)))


@dataclass
class _Block:
    """The problem projected on V_m (eq. 2): basis (n, r) in z and the r x r matrices."""

    basis: np.ndarray
    damping: np.ndarray
    g1: np.ndarray
    k0: np.ndarray
    k2: np.ndarray
    force: np.ndarray  # V^T B (r, n_c)


@dataclass
class ModalSolver:
    """Eq. 3 for the :class:`SpinFit` ``fit`` excited along the columns of ``directions`` (n, n_c): every force is
    directions @ c. ``ratio``: f_c / f (:data:`MODAL_CUTOFF_RATIO`)."""

    fit: SpinFit
    directions: np.ndarray
    ratio: float = MODAL_CUTOFF_RATIO
    residual_order: int = RESIDUAL_ORDER
    _blocks: dict[int, _Block] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        from scipy.linalg import eigh

        if not self.ratio > 1.0:
            raise ValueError(f"ratio: expected > 1, got {self.ratio}")
        k0 = self.fit.k0
        lam, phi = eigh(0.5 * (k0 + k0.T), self.fit.mass)
        if lam.size and lam[0] <= 0.0:
            raise ValueError("the linearised model at zero spin is not positively stiff: no modal solve "
                             "(a free rigid-body motion)")
        self.lam, self.phi = lam, phi
        self.frequencies_hz = np.sqrt(lam) / (2.0 * math.pi)
        t = phi.T
        self._d, self._g, self._k0, self._k2 = (t @ a @ phi for a in (self.fit.damping, self.fit.g1, k0,
                                                                      self.fit.k2))
        self._b = t @ self.directions  # modal forces per direction (n, n_c)

    def kept(self, frequency_hz: float) -> int:
        """m: modes below ``ratio`` x ``frequency_hz`` (eq. 2), rounded up to a multiple of :data:`BLOCK_STEP` of
        all modes (fewer projected blocks to compute and hold; a few more modes than needed)."""
        n = self.lam.size
        m = int(np.searchsorted(self.frequencies_hz, self.ratio * frequency_hz, side="left"))
        step = max(1, int(math.ceil(BLOCK_STEP * n)))
        return min(n, step * int(math.ceil(m / step)))

    def _block(self, m: int) -> _Block:
        if m in self._blocks:
            return self._blocks[m]
        n = self.lam.size
        if m < n:
            y = [self._b[m:] / self.lam[m:, None]]  # the truncated modes' static responses (modal coordinates)
            for _ in range(1, self.residual_order):  # and their mass corrections, scaled by lambda_m (same span)
                y.append(y[-1] * (self.lam[m] / self.lam[m:, None]))
            u, s, _ = np.linalg.svd(np.hstack(y), full_matrices=False)
            q = u[:, s > _RANK_TOL * s[0]] if s.size and s[0] > 0.0 else np.zeros((n - m, 0))
        else:
            q = np.zeros((0, 0))
        r = m + q.shape[1]
        t = np.zeros((n, r))  # V_m in modal coordinates
        t[:m, :m] = np.eye(m)
        t[m:, m:] = q
        mats = []
        for a in (self._d, self._g, self._k0, self._k2):
            p = np.empty((r, r))
            p[:m, :m] = a[:m, :m]
            p[:m, m:] = a[:m, m:] @ q
            p[m:, :m] = q.T @ a[m:, :m]
            p[m:, m:] = q.T @ a[m:, m:] @ q
            mats.append(p)
        block = _Block(np.hstack([self.phi[:, :m], self.phi[:, m:] @ q]), *mats, t.T @ self._b)
        self._blocks[m] = block
        return block

    def solve(self, spin: float, omegas: np.ndarray, coefficients: np.ndarray) -> np.ndarray:
        """x (H, n) at spin speed ``spin`` [rad/s] for the excitation frequencies ``omegas`` (H,) [rad/s] and forces
        ``directions @ coefficients[h]`` (``coefficients`` (H, n_c)); (H, n, k) for k force sets at once
        (``coefficients`` (H, n_c, k))."""
        from threadpoolctl import threadpool_limits

        out = np.empty((omegas.size, self.lam.size, *np.shape(coefficients)[2:]), complex)
        with threadpool_limits(limits=1, user_api="blas"):  # small dense solves: one thread is fastest
            for h, w in enumerate(omegas):
                out[h] = self._one(spin, w, coefficients[h])
        return out

    def _one(self, spin: float, w: float, coefficients: np.ndarray) -> np.ndarray:
        b = self._block(self.kept(w / (2.0 * math.pi)))
        r = b.k0.shape[0]
        a = (b.k0 + spin**2 * b.k2 - w**2 * np.eye(r)) + 1j * w * (b.damping + spin * b.g1)
        return b.basis @ np.linalg.solve(a, b.force @ coefficients)
