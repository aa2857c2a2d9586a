"""How many fixed-interface modes a reduction keeps: a count, or every mode below a frequency.

Craig-Bampton bases converge from below: a reduced body's free-free frequencies approach the full FE model's
as fixed-interface modes are added, and the usual rule keeps every fixed-interface mode up to a margin above the
highest frequency the body must reproduce. :func:`lowest_eigenpairs` gives a sparse eigen solver's lowest pairs
either as a count or as every pair below ``max_hz``; the count of the second is not known in advance, so the
solver is called for more pairs until the highest pair found lies above ``max_hz``, each call deflating the
pairs found before (:func:`shift_invert_pairs`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

__all__ = ["ARPACK_TOLERANCE", "LANCZOS_EXTRA_MIN", "LANCZOS_EXTRA_SHARE", "lowest_eigenpairs", "shift_invert_pairs"]

ARPACK_TOLERANCE = 1e-10
"""Relative accuracy of the eigenvalues ARPACK returns (its ``tol``)."""
_FIRST_COUNT = 24
"""First count tried for a frequency limit (fewer than the lowest modes of a gear or a shaft below 6x its mesh)."""
_DENSITY_EXPONENT = 1.5
"""Growth of the mode count N with frequency f assumed for the next guess, N ~ f^1.5 (between a plate's N ~ f and
a solid's N ~ f^3, Weyl's law). The guess carries no margin: a guess that falls short costs one more call for the
pairs still missing (the found ones deflated), a guess beyond the limit costs pairs that are thrown away."""
LANCZOS_EXTRA_SHARE = 0.5
LANCZOS_EXTRA_MIN = 20
"""ARPACK's Lanczos basis for k pairs: k + max(LANCZOS_EXTRA_SHARE k, LANCZOS_EXTRA_MIN) vectors (its ``ncv``;
scipy's default 2 k + 1). In shift-invert mode about 0 the wanted 1 / lambda are the largest and well separated, so
the smaller basis converges them to the same tolerance in fewer operations per restart (O(n ncv^2))."""


def lowest_eigenpairs(eigen: Callable[[int, np.ndarray | None], tuple[np.ndarray, np.ndarray]],
                      n_modes: int | None = None, max_hz: float | None = None,
                      limit: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lowest eigenpairs (lambda = omega^2 [1/s^2] ascending, vectors as columns) of ``eigen(k, found)``, which
    returns the lowest ``k`` pairs ascending beyond the pairs whose vectors are the columns of ``found`` (None: none
    found yet), e.g. :func:`shift_invert_pairs`.

    Exactly one of ``n_modes`` (the count) and ``max_hz`` (every pair with omega / 2 pi below it [Hz]) is given.
    ``limit``: the most pairs the problem has; a frequency limit beyond them returns them all. A frequency limit
    asks for more pairs until the highest found lies above it; each further call asks only for the pairs beyond
    those already found, so that no pair is computed twice.
    """
    if (n_modes is None) == (max_hz is None):
        raise ValueError("lowest_eigenpairs: give exactly one of n_modes and max_hz")
    if n_modes is not None:
        if n_modes < 0:
            raise ValueError(f"lowest_eigenpairs: n_modes must be >= 0, got {n_modes}")
        return eigen(min(n_modes, limit) if limit is not None else n_modes, None) if n_modes else _none()
    if not max_hz > 0.0:
        raise ValueError(f"lowest_eigenpairs: max_hz must be > 0, got {max_hz}")
    lam_max = (2.0 * math.pi * max_hz) ** 2
    k = _FIRST_COUNT if limit is None else min(_FIRST_COUNT, limit)
    lam, vec = eigen(k, None)
    while not (lam[-1] >= lam_max or (limit is not None and k >= limit)):
        ratio = math.sqrt(lam_max / max(lam[-1], 1e-300))  # frequency ratio still to go
        k_next = math.ceil(k * ratio ** _DENSITY_EXPONENT)
        k_next = max(k_next, k + 8) if limit is None else min(max(k_next, k + 8), limit)
        more, more_vec = eigen(k_next - k, vec)
        lam, vec, k = np.concatenate([lam, more]), np.hstack([vec, more_vec]), k_next
        order = np.argsort(lam, kind="stable")
        lam, vec = lam[order], vec[:, order]
    keep = lam < lam_max
    return lam[keep], vec[:, keep]


def shift_invert_pairs(solve: Callable[[np.ndarray], np.ndarray], mass, k: int, v0: np.ndarray,
                       found: np.ndarray | None = None, tol: float = ARPACK_TOLERANCE
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` lowest eigenpairs of K x = lambda M x beyond the M-orthonormal eigenvectors ``found`` (n, j):
    ARPACK (Lanczos) in shift-invert mode about 0 on the deflated operator

        OP = (I - V V^T M) K^-1 M,   V = ``found``,

    which has the found pairs' eigenvalues 1 / lambda moved to 0 and every other pair unchanged (K^-1 M keeps the
    M-orthogonal complement of its eigenvectors), so that its largest eigenvalues are the next lowest pairs.
    ``solve(y)`` = K^-1 y (n,) [the problem's units]; ``mass`` M (n, n), anything with ``@``; ``v0`` (n,) the
    start vector. Returns lambda ascending and M-orthonormal vectors (n, k).
    """
    import scipy.sparse.linalg as sla

    n = v0.size
    if found is not None and found.shape[1]:
        v = found

        def project(y: np.ndarray) -> np.ndarray:
            return y - v @ (v.T @ (mass @ y))

        op_inv = sla.LinearOperator((n, n), matvec=lambda y: project(solve(y)), dtype=float)
        v0 = project(v0)
    else:
        op_inv = sla.LinearOperator((n, n), matvec=solve, dtype=float)
    ncv = min(n - 1, k + max(math.ceil(LANCZOS_EXTRA_SHARE * k), LANCZOS_EXTRA_MIN))
    lam, vec = sla.eigsh(op_inv, k=k, M=mass, sigma=0.0, OPinv=op_inv, which="LM", v0=v0, ncv=ncv, tol=tol)
    order = np.argsort(lam)
    return lam[order], vec[:, order]


def _none() -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(0), np.zeros((0, 0))
