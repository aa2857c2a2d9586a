"""Sparse Cholesky factorisation of a symmetric positive-definite SciPy matrix (CHOLMOD, as CVXOPT ships it).

The reduction's stiffness systems (free body with six support coordinates removed, or the interior of a
clamped body) are symmetric positive definite. CHOLMOD's supernodal Cholesky factorisation K = L L^T of
the lower triangle (CHOLMOD's default fill-reducing ordering, dense supernode blocks through BLAS) holds one
triangular factor.

CVXOPT's wheels carry SuiteSparse's CHOLMOD library with a single-threaded BLAS. CVXOPT's own Python binding
solves a right-hand side of several columns one column at a time, so that every column reads the whole factor
(a solve is bound by memory traffic); CHOLMOD itself solves a block of columns in one pass over the factor
(dense triangular solves on each supernode). :class:`SparseCholesky` therefore calls the library through ctypes
(``cholmod_analyze``, ``cholmod_factorize``, ``cholmod_solve`` on CHOLMOD's documented ``cholmod_sparse`` and
``cholmod_dense`` structures); where the library cannot be loaded it falls back to CVXOPT's binding (the same
factorisation, column by column). The caller chooses the parallelism.
"""

from __future__ import annotations

import ctypes
import glob
import os

import numpy as np
import scipy.sparse as sp

__all__ = ["SparseCholesky"]

_CHOLMOD_REAL, _CHOLMOD_INT, _CHOLMOD_DOUBLE, _CHOLMOD_A = 1, 0, 0, 0  # cholmod_core.h / cholmod_cholesky.h codes
_INT32_LIMIT = 2**31 - 1
"""Entries of a matrix the int32 interface of CHOLMOD takes (larger ones go through CVXOPT's binding)."""
_COMMON_BYTES = 1 << 16
"""Room for a ``cholmod_common`` (CHOLMOD 3 needs a few kB; ``cholmod_start`` fills it)."""
_DEPENDENCIES = ("libquadmath", "libgfortran", "libsatlas", "libopenblas", "libsuitesparseconfig", "libamd",
                 "libcamd", "libcolamd", "libccolamd")
"""The shared libraries CVXOPT's CHOLMOD links to, loaded first (each only if the wheel carries it)."""


class _Sparse(ctypes.Structure):
    _fields_ = [("nrow", ctypes.c_size_t), ("ncol", ctypes.c_size_t), ("nzmax", ctypes.c_size_t),
                ("p", ctypes.c_void_p), ("i", ctypes.c_void_p), ("nz", ctypes.c_void_p), ("x", ctypes.c_void_p),
                ("z", ctypes.c_void_p), ("stype", ctypes.c_int), ("itype", ctypes.c_int),
                ("xtype", ctypes.c_int), ("dtype", ctypes.c_int), ("sorted", ctypes.c_int),
                ("packed", ctypes.c_int)]


class _Dense(ctypes.Structure):
    _fields_ = [("nrow", ctypes.c_size_t), ("ncol", ctypes.c_size_t), ("nzmax", ctypes.c_size_t),
                ("d", ctypes.c_size_t), ("x", ctypes.c_void_p), ("z", ctypes.c_void_p), ("xtype", ctypes.c_int),
                ("dtype", ctypes.c_int)]


class _FactorHead(ctypes.Structure):  # the first fields of cholmod_factor
    _fields_ = [("n", ctypes.c_size_t), ("minor", ctypes.c_size_t)]


_LIBRARY: list = []


def _cholmod():
    """CVXOPT's CHOLMOD library with its argument types, or None where it cannot be loaded."""
    if _LIBRARY:
        return _LIBRARY[0]
    lib = None
    try:
        import cvxopt

        folder = os.path.join(os.path.dirname(os.path.dirname(cvxopt.__file__)), "cvxopt.libs")
        for name in _DEPENDENCIES:
            for path in sorted(glob.glob(os.path.join(folder, f"{name}-*.so*")))[:1]:
                ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
        lib = ctypes.CDLL(sorted(glob.glob(os.path.join(folder, "libcholmod-*.so*")))[0])
        vp, common = ctypes.c_void_p, ctypes.c_void_p
        lib.cholmod_start.argtypes = [common]
        lib.cholmod_finish.argtypes = [common]
        lib.cholmod_analyze.argtypes, lib.cholmod_analyze.restype = [ctypes.POINTER(_Sparse), common], vp
        lib.cholmod_factorize.argtypes = [ctypes.POINTER(_Sparse), vp, common]
        lib.cholmod_solve.argtypes = [ctypes.c_int, vp, ctypes.POINTER(_Dense), common]
        lib.cholmod_solve.restype = ctypes.POINTER(_Dense)
        lib.cholmod_free_dense.argtypes = [ctypes.POINTER(ctypes.POINTER(_Dense)), common]
        lib.cholmod_free_factor.argtypes = [ctypes.POINTER(vp), common]
    except (ImportError, OSError, IndexError, AttributeError):
        lib = None
    _LIBRARY.append(lib)
    return lib


class SparseCholesky:
    """Factor of a symmetric positive-definite sparse matrix ``k`` (n, n); only its lower triangle is read
    (pass that alone to save memory).

    :meth:`solve` returns K^-1 rhs for rhs (n,) or (n, k), a block of columns in one pass over the factor.
    Raises ``ValueError`` if ``k`` is not square or not positive definite (a zero or negative pivot: an
    unsupported or unconnected coordinate).
    """

    def __init__(self, k: sp.spmatrix):
        if k.shape[0] != k.shape[1]:
            raise ValueError(f"SparseCholesky: matrix must be square, got shape {k.shape}")
        self.n = k.shape[0]
        self._lib = _cholmod() if k.nnz < _INT32_LIMIT else None  # the binding uses CHOLMOD's int32 interface
        if self._lib is None:
            self._cvxopt_factor(k)
            return
        lower = sp.tril(k, format="csc")
        lower.sort_indices()
        self._p = lower.indptr.astype(np.int32)
        self._i = lower.indices.astype(np.int32)
        self._x = np.ascontiguousarray(lower.data, dtype=float)
        del lower
        self._common = ctypes.create_string_buffer(_COMMON_BYTES)
        self._lib.cholmod_start(self._common)
        a = _Sparse(self.n, self.n, self._x.size, self._p.ctypes.data, self._i.ctypes.data, None,
                    self._x.ctypes.data, None, -1, _CHOLMOD_INT, _CHOLMOD_REAL, _CHOLMOD_DOUBLE, 1, 1)
        self._factor = ctypes.c_void_p(self._lib.cholmod_analyze(ctypes.byref(a), self._common))
        if not self._factor.value:
            raise MemoryError("SparseCholesky: CHOLMOD could not analyse the matrix")
        self._lib.cholmod_factorize(ctypes.byref(a), self._factor, self._common)
        del self._p, self._i, self._x  # the factor holds its own copy
        minor = _FactorHead.from_address(self._factor.value).minor
        if minor < self.n:
            raise ValueError(f"SparseCholesky: matrix is not positive definite (CHOLMOD stopped at column "
                             f"{minor}): a coordinate without stiffness?")

    def _cvxopt_factor(self, k: sp.spmatrix) -> None:
        import cvxopt
        from cvxopt import cholmod

        lower = sp.tril(k, format="coo")
        a = cvxopt.spmatrix(cvxopt.matrix(np.asarray(lower.data, float)),
                            cvxopt.matrix(lower.row.astype(np.int64)), cvxopt.matrix(lower.col.astype(np.int64)),
                            (self.n, self.n))
        del lower
        cholmod.options["supernodal"] = 2  # CHOLMOD_SUPERNODAL: L L^T in dense blocks
        self._cvx = cholmod.symbolic(a, uplo="L")
        try:
            cholmod.numeric(a, self._cvx)
        except ArithmeticError as err:
            raise ValueError(f"SparseCholesky: matrix is not positive definite (CHOLMOD stopped at column "
                             f"{err}): a coordinate without stiffness?") from None

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """K^-1 rhs (same shape as ``rhs``)."""
        rhs = np.asarray(rhs, float)
        if rhs.shape[0] != self.n:
            raise ValueError(f"SparseCholesky.solve: rhs has {rhs.shape[0]} rows, the matrix {self.n}")
        b = np.asfortranarray(rhs.reshape(self.n, -1))
        if self._lib is None:
            import cvxopt
            from cvxopt import cholmod

            out = cvxopt.matrix(b)
            cholmod.solve(self._cvx, out)  # in place, column by column
            return np.array(out).reshape(rhs.shape)
        cols = b.shape[1]
        dense = _Dense(self.n, cols, self.n * cols, self.n, b.ctypes.data, None, _CHOLMOD_REAL, _CHOLMOD_DOUBLE)
        x = self._lib.cholmod_solve(_CHOLMOD_A, self._factor, ctypes.byref(dense), self._common)
        if not x:
            raise MemoryError("SparseCholesky.solve: CHOLMOD returned no solution")
        try:
            lead = x.contents.d  # the leading dimension of CHOLMOD's column-major result
            values = np.ctypeslib.as_array(ctypes.cast(x.contents.x, ctypes.POINTER(ctypes.c_double)),
                                           shape=(cols, lead))
            out = values[:, :self.n].T.copy(order="F")
        finally:
            self._lib.cholmod_free_dense(ctypes.byref(x), self._common)
        return out.reshape(rhs.shape)

    def __del__(self) -> None:
        lib, factor = getattr(self, "_lib", None), getattr(self, "_factor", None)
        if lib is not None and factor is not None and factor.value:
            lib.cholmod_free_factor(ctypes.byref(factor), self._common)
            lib.cholmod_finish(self._common)
