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

__all__ = ["LANCZOS_BLOCK", "LANCZOS_CHUNK", "LANCZOS_TOLERANCE",
           "REORTHOGONALISE_BELOW", "lowest_eigenpairs", "shift_invert_pairs"]

LANCZOS_TOLERANCE = 1e-10
"""Relative accuracy of the eigenvalues :func:`shift_invert_pairs` returns (a Ritz pair's residual over its
eigenvalue, as ARPACK's ``tol``)."""
LANCZOS_BLOCK = 8
"""Vectors per block of :func:`shift_invert_pairs`: a block of columns is solved in one pass over the Cholesky
factor (flexgear.fe.cholesky), and a block at least as large as a multiplicity finds all its eigenvectors
(cyclic symmetry gives pairs)."""
REORTHOGONALISE_BELOW = 0.5
"""A second Gram-Schmidt pass when a column's M-norm squared fell below this share in the first (Daniel, Gragg,
Kaufman & Stewart 1976: 1 / sqrt(2) of the norm)."""
LANCZOS_CHUNK = 16
"""Blocks per chunk of stored Lanczos vectors (the basis grows a chunk at a time, without copies)."""
_FIRST_COUNT = 24
"""First count tried for a frequency limit (fewer than the lowest modes of a gear or a shaft below 6x its mesh)."""
_DENSITY_EXPONENT = 1.5
"""Growth of the mode count N with frequency f assumed for the next guess, N ~ f^1.5 (between a plate's N ~ f and
a solid's N ~ f^3, Weyl's law). The guess carries no margin: a guess that falls short costs one more call for the
pairs still missing (the found ones deflated), a guess beyond the limit costs pairs that are thrown away."""


def lowest_eigenpairs(eigen: Callable[[int, np.ndarray | None], tuple[np.ndarray, np.ndarray]],
                      n_modes: int | None = None, max_hz: float | None = None,
                      limit: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lowest eigenpairs (lambda = omega^2 [1/s^2] ascending, vectors as columns) of ``eigen(k, found)``, which
    returns the lowest ``k`` pairs ascending beyond the pairs whose vectors are the columns of ``found`` (None: none
    found yet), e.g. :func:`shift_invert_pairs`.

    Exactly one of ``n_modes`` (the count) and ``max_hz`` (every pair with omega / 2 pi below it [Hz]) is given.
    ``limit``: the most pairs the problem has; a frequency limit beyond them returns them all. A frequency limit
    asks for more pairs until the highest found lies above it; each further call asks only for the pairs beyond
    those already found, so that no pair is computed twice. An ``eigen`` that takes the keyword ``below``
    (lambda [1/s^2], e.g. :func:`shift_invert_pairs`) is asked once for every pair below the limit and the first
    beyond it, in one Krylov space instead of one per call.
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
    lam, vec = eigen(k, None, below=lam_max) if _takes_limit(eigen) else eigen(k, None)
    k = lam.size
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


def _takes_limit(eigen: Callable) -> bool:
    """Whether ``eigen`` takes the keyword ``below`` (:func:`lowest_eigenpairs`)."""
    import inspect

    try:
        return "below" in inspect.signature(eigen).parameters
    except (TypeError, ValueError):
        return False


def shift_invert_pairs(solve: Callable[[np.ndarray], np.ndarray], mass, k: int, v0: np.ndarray,
                       found: np.ndarray | None = None, tol: float = LANCZOS_TOLERANCE,
                       block: int = LANCZOS_BLOCK, below: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` lowest eigenpairs of K x = lambda M x beyond the M-orthonormal eigenvectors ``found`` (n, j):
    block Lanczos in shift-invert mode about 0 on the deflated operator

        OP = (I - V V^T M) K^-1 M,   V = ``found``,

    which has the found pairs' eigenvalues 1 / lambda moved to 0 and every other pair unchanged (K^-1 M keeps the
    M-orthogonal complement of its eigenvectors), so that its largest eigenvalues theta = 1 / lambda are the next
    lowest pairs. OP is self-adjoint in the M inner product: blocks Q_j of ``block`` M-orthonormal vectors,
    W = OP Q_j orthogonalised against Q_j and Q_(j-1) (the three-term recurrence, whose large coefficients would
    otherwise call for a second pass every time), then against every block before (classical Gram-Schmidt, a
    second pass where the first took more than :data:`REORTHOGONALISE_BELOW` of a column's M-norm squared) and
    M-orthonormalised,
    W = Q_(j+1) B_(j+1) (Cholesky QR, twice), make T = Q^T M OP Q block tridiagonal; its eigenpairs (theta, s)
    give the Ritz pairs (1 / theta, Q s), converged when the residual ||B_(j+1) s_last|| (M norm) is at most
    ``tol`` theta, as ARPACK's test. A block of vectors costs one solve of ``block`` columns and dense products.

    ``solve(y)`` = K^-1 y for y (n, c) [the problem's units]; ``mass`` M (n, n), anything with ``@`` on (n, c);
    ``v0`` (n,) the first start vector (the others are seeded random). Returns lambda ascending and M-orthonormal
    vectors (n, k).

    ``below`` (lambda [the problem's units]): instead of ``k`` pairs, every pair below it and the first pair beyond
    (which shows that no other lies below), ``k`` only the count at which T is first read. The Krylov space grows
    until the Ritz pairs with theta > 1 / ``below`` and the next one have converged: Ritz values approach the
    extreme theta from inside (Cauchy interlacing), so an unconverged pair beyond the limit may still come below it,
    and a converged one beyond it closes the count. (Without a space of its own per count, as deflated calls with
    growing ``k`` need, no Krylov vector is built twice.)
    """
    import scipy.linalg as la

    n = v0.size
    v = found if found is not None and found.shape[1] else None
    free = n - (0 if v is None else v.shape[1])
    if not 0 < k < free:
        raise ValueError(f"shift_invert_pairs: k must lie in 1 ... {free - 1}, got {k}")
    b = max(1, min(block, free // 2))

    mv = None if v is None else np.asarray(mass @ v)

    def op(mq: np.ndarray) -> np.ndarray:
        """OP q from M q (n, c)."""
        y = solve(mq).reshape(n, -1)
        return y if v is None else y - v @ (mv.T @ y)

    start = np.column_stack([v0, np.random.default_rng(0).standard_normal((n, b - 1))])
    q, mq, _ = _m_orthonormal(op(np.asarray(mass @ start)), mass)
    chunks: list[np.ndarray] = []  # the Lanczos vectors, in chunks of LANCZOS_CHUNK blocks (never copied)
    t = np.zeros((k + 3 * b,) * 2)  # T to its first reading (k + b vectors) and one block beyond; doubled as needed
    m = 0
    recent: list[tuple[int, np.ndarray, np.ndarray]] = []  # the last two blocks: (first column, Q_j, M Q_j)
    while True:
        if m % (LANCZOS_CHUNK * b) == 0:
            chunks.append(np.empty((n, LANCZOS_CHUNK * b)))
        if m + 2 * b > t.shape[0]:
            t = np.pad(t, ((0, t.shape[0]), (0, t.shape[0])))
        j = m % (LANCZOS_CHUNK * b)
        chunks[-1][:, j:j + b] = q
        recent = [*recent[-1:], (m, chunks[-1][:, j:j + b], mq)]
        w = op(mq)
        h = np.zeros((m + b, b))
        mw = np.asarray(mass @ w)
        for first, qj, mqj in recent:  # the recurrence's own terms first, M W kept by the blocks' M Q_j
            coef = qj.T @ mw
            w -= qj @ coef
            mw -= mqj @ coef
            h[first:first + b] += coef
        for _ in range(2):  # full reorthogonalisation: classical Gram-Schmidt, a second pass where needed
            before = np.einsum("ij,ij->j", w, mw)
            for i, c in enumerate(_filled(chunks, m + b, LANCZOS_CHUNK * b)):
                coef = c.T @ mw
                w -= c @ coef
                h[i * LANCZOS_CHUNK * b:i * LANCZOS_CHUNK * b + c.shape[1]] += coef
            mw = np.asarray(mass @ w)
            if np.all(np.einsum("ij,ij->j", w, mw) > REORTHOGONALISE_BELOW * before):
                break  # no column lost more than this share of its M-norm squared: orthogonal to round-off
        t[:m + b, m:m + b] = h
        done = _filled(chunks, m + b, LANCZOS_CHUNK * b)
        q, mq, r = _m_orthonormal(w, mass, mw, lambda x, done=done: _cleared(x, mass, done))
        t[m + b:m + 2 * b, m:m + b] = r
        m += b
        if m < k + b and m + b <= free:  # T is first read with a block beyond the k pairs (or all there is)
            continue
        theta, s_ = la.eigh(t[:m, :m], lower=False)  # T's upper triangle: the coefficients as computed
        if below is not None:  # every Ritz pair below the limit and the first beyond it
            k = min(int(np.count_nonzero(theta * below > 1.0)) + 1, m)
        top = np.arange(m - k, m)  # the k largest theta: the lowest lambda
        resid = np.linalg.norm(r @ s_[m - b:m, top], axis=0)
        if np.all(resid <= tol * np.abs(theta[top])):
            break
        if m + b > free and below is not None:
            break  # the whole space: T's pairs are the problem's
        if m + b > free:
            raise RuntimeError(f"shift_invert_pairs: {k} pairs not converged in {m} Lanczos vectors")
    vec = sum(c @ s_[i * LANCZOS_CHUNK * b:i * LANCZOS_CHUNK * b + c.shape[1], top]
              for i, c in enumerate(_filled(chunks, m, LANCZOS_CHUNK * b)))
    lam = 1.0 / theta[top]
    order = np.argsort(lam)
    return lam[order], vec[:, order]


def _cleared(x: np.ndarray, mass, basis: list[np.ndarray]) -> np.ndarray:
    """``x`` without its M-projection on the M-orthonormal columns of ``basis`` (chunks of columns)."""
    mx = np.asarray(mass @ x)
    return x - sum(c @ (c.T @ mx) for c in basis)


def _filled(chunks: list[np.ndarray], m: int, width: int) -> list[np.ndarray]:
    """The first ``m`` columns of the chunks (views)."""
    return [c[:, :min(width, m - i * width)] for i, c in enumerate(chunks) if m > i * width]


def _m_orthonormal(w: np.ndarray, mass, mw: np.ndarray | None = None,
                  clear: Callable[[np.ndarray], np.ndarray] | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Q, M Q, R with W = Q R, Q^T M Q = I, R upper triangular (c, c): Cholesky QR twice, on M W (``mw``, computed
    if not given). Where W has dependent columns (an invariant subspace reached), R is square but not triangular
    and the missing directions are seeded random vectors, first passed through ``clear`` (which removes what they
    must be M-orthogonal to, e.g. the Lanczos vectors so far), M-orthogonal to the rest."""
    import scipy.linalg as la

    q, mq, r_total = w, np.asarray(mass @ w) if mw is None else mw, np.eye(w.shape[1])
    for _ in range(2):
        g = q.T @ mq
        try:
            r = la.cholesky(0.5 * (g + g.T), lower=False)
        except la.LinAlgError:
            return _m_orthonormal_rank_revealing(w, mass, clear)
        r_inv = la.solve_triangular(r, np.eye(r.shape[0]), lower=False)
        q, mq, r_total = q @ r_inv, mq @ r_inv, r @ r_total
    return q, mq, r_total


def _m_orthonormal_rank_revealing(w: np.ndarray, mass, clear: Callable[[np.ndarray], np.ndarray] | None
                                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_m_orthonormal` for a W without full rank: by the eigen decomposition of W^T M W."""
    g = w.T @ np.asarray(mass @ w)
    mu, u = np.linalg.eigh(0.5 * (g + g.T))
    keep = mu > 1e-14 * max(mu.max(), 1e-300)
    q = w @ (u[:, keep] / np.sqrt(mu[keep]))
    rng = np.random.default_rng(1)
    while q.shape[1] < w.shape[1]:
        x = rng.standard_normal((w.shape[0], 1))
        for _ in range(2):
            x = x if clear is None else clear(x)
            x -= q @ (q.T @ np.asarray(mass @ x))
        x /= np.sqrt(float(x.T @ np.asarray(mass @ x)))
        q = np.hstack([q, x])
    mq = np.asarray(mass @ q)
    return q, mq, mq.T @ w  # W = Q R exactly on the kept directions, zero on the added ones


def _none() -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(0), np.zeros((0, 0))
