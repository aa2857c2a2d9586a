"""Sparse Cholesky factorisation of a symmetric positive-definite SciPy matrix (NGSolve's SparseCholesky).

The reduction's stiffness systems (free body with six support coordinates removed, or the interior of a
clamped body) are symmetric positive definite. A supernodal Cholesky factorisation K = L D L^T of its
lower triangle (fill-reducing minimum-degree ordering) holds one triangular factor where SciPy's
``splu`` (SuperLU, an unsymmetric LU) holds two plus its work space: on the coarse ring (210 k
coordinates) 0.3 GB instead of 2 GB and 2.4x less factorisation time, solutions equal to round-off
(benchmarks/bench_cold.py times the whole cold build). NGSolve is already the project's FE assembler,
so no new dependency; it runs on one thread here (no TaskManager), the caller chooses the parallelism.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["SparseCholesky"]


def _ng_array(values: np.ndarray, cls):
    """A pyngcore array (``Array_I_S`` / ``Array_D_S``) filled from ``values`` through its NumPy view."""
    out = cls(len(values))
    np.asarray(out)[:] = values
    return out


class SparseCholesky:
    """Factor of a symmetric positive-definite sparse matrix ``k`` (n, n); only its lower triangle is read
    (pass that alone to save memory).

    :meth:`solve` returns K^-1 rhs for rhs (n,) or (n, k); ``factor_bytes`` is the factor's memory [bytes].
    """

    def __init__(self, k: sp.spmatrix):
        import pyngcore
        from ngsolve import la

        if k.shape[0] != k.shape[1]:
            raise ValueError(f"SparseCholesky: matrix must be square, got shape {k.shape}")
        lower = sp.tril(k, format="csr")  # rows as run lengths: no COO copy of the row indices
        self.n = k.shape[0]
        rows = np.repeat(np.arange(self.n, dtype=np.int32), np.diff(lower.indptr))
        mat = la.SparseMatrixd.CreateFromCOO(_ng_array(rows, pyngcore.Array_I_S),
                                             _ng_array(lower.indices, pyngcore.Array_I_S),
                                             _ng_array(lower.data, pyngcore.Array_D_S), self.n, self.n)
        del lower, rows
        self._inv = mat.Inverse(inverse="sparsecholesky")
        self._x, self._y = mat.CreateColVector(), mat.CreateColVector()
        self.factor_bytes = sum(u.host for u in self._inv.GetMemoryUsage())

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """K^-1 rhs, column by column (same shape as ``rhs``)."""
        rhs = np.asarray(rhs, float)
        if rhs.shape[0] != self.n:
            raise ValueError(f"SparseCholesky.solve: rhs has {rhs.shape[0]} rows, the matrix {self.n}")
        cols = rhs.reshape(self.n, -1)
        out = np.empty_like(cols)
        x, y = self._x.FV().NumPy(), self._y.FV().NumPy()
        for j in range(cols.shape[1]):
            x[:] = cols[:, j]
            self._inv.Mult(self._x, self._y)
            out[:, j] = y
        return out.reshape(rhs.shape)
