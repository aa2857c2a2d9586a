"""Sparse Cholesky factorisation of a symmetric positive-definite SciPy matrix (CHOLMOD, through CVXOPT).

The reduction's stiffness systems (free body with six support coordinates removed, or the interior of a
clamped body) are symmetric positive definite. CHOLMOD's supernodal Cholesky factorisation K = L L^T of
the lower triangle (CHOLMOD's default fill-reducing ordering, dense supernode blocks through BLAS) holds one
triangular factor. Against NGSolve's ``sparsecholesky``, which the project used before, on the coarse
planet's free body (121 k coordinates): factorisation 1.6 s instead of 2.6 s, one solve 48 ms instead of
108 ms; the cold build of the planet 49.7 s -> 39.1 s and of the ring 75.4 s ->
54.4 s (the ring's process peaks at 1.44 GB either way), first frequencies equal to 1e-11
(benchmarks/bench_cold.py times the whole cold build). CVXOPT's
wheels carry SuiteSparse and a single-threaded OpenBLAS: the caller chooses the parallelism. CHOLMOD's
supernodal mode is CVXOPT's process-wide option; :class:`SparseCholesky` asks for it on each factorisation.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["SparseCholesky"]


class SparseCholesky:
    """Factor of a symmetric positive-definite sparse matrix ``k`` (n, n); only its lower triangle is read
    (pass that alone to save memory).

    :meth:`solve` returns K^-1 rhs for rhs (n,) or (n, k). Raises ``ValueError`` if ``k`` is not square
    or not positive definite (a zero or negative pivot: an unsupported or unconnected coordinate).
    """

    def __init__(self, k: sp.spmatrix):
        import cvxopt
        from cvxopt import cholmod

        if k.shape[0] != k.shape[1]:
            raise ValueError(f"SparseCholesky: matrix must be square, got shape {k.shape}")
        lower = sp.tril(k, format="coo")
        self.n = k.shape[0]
        a = cvxopt.spmatrix(cvxopt.matrix(np.asarray(lower.data, float)),
                            cvxopt.matrix(lower.row.astype(np.int64)), cvxopt.matrix(lower.col.astype(np.int64)),
                            (self.n, self.n))
        del lower
        cholmod.options["supernodal"] = 2  # CHOLMOD_SUPERNODAL: L L^T in dense blocks
        self._factor = cholmod.symbolic(a, uplo="L")
        try:
            cholmod.numeric(a, self._factor)
        except ArithmeticError as err:
            raise ValueError(f"SparseCholesky: matrix is not positive definite (CHOLMOD stopped at column "
                             f"{err}): a coordinate without stiffness?") from None
        self._solve = cholmod.solve
        self._matrix = cvxopt.matrix

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """K^-1 rhs (same shape as ``rhs``)."""
        rhs = np.asarray(rhs, float)
        if rhs.shape[0] != self.n:
            raise ValueError(f"SparseCholesky.solve: rhs has {rhs.shape[0]} rows, the matrix {self.n}")
        b = self._matrix(np.asfortranarray(rhs.reshape(self.n, -1)))
        self._solve(self._factor, b)  # in place
        return np.array(b).reshape(rhs.shape)
