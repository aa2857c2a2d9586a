"""A reduced body's basis sized by frequency (flexgear.fe.spectrum): the eigenpairs below a limit, exactly. The bodies
built by that rule against their full FE models in the band: tests/test_attachment.py (sun, planet),
tests/test_tied_pair.py (the tied ring and output shaft)."""

import numpy as np
import pytest

from flexgear.fe.spectrum import lowest_eigenpairs


def _diagonal(frequencies_hz: np.ndarray, calls: list[int]):
    """eigen(k, found) of a diagonal problem with the given ascending frequencies: the k pairs beyond those found,
    recording each k asked for."""
    lam = (2 * np.pi * frequencies_hz) ** 2

    def eigen(k: int, found: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        j = 0 if found is None else found.shape[1]
        calls.append(k)
        return lam[j:j + k], np.eye(lam.size)[:, j:j + k]

    return eigen


@pytest.mark.parametrize("density", [1.0, 1.5, 3.0])
def test_every_pair_below_the_limit_and_no_other(density):
    """Spectra as dense as a plate's (N ~ f), the growth assumed (N ~ f^1.5) and a solid's (N ~ f^3): exactly the
    pairs below the limit come back, whatever the guesses."""
    f = 100.0 * np.arange(1, 2001) ** (1.0 / density)
    calls: list[int] = []
    lam, vec = lowest_eigenpairs(_diagonal(f, calls), max_hz=1000.0, limit=f.size)
    assert lam.size == np.count_nonzero(f < 1000.0) == vec.shape[1]
    assert np.sqrt(lam[-1]) / (2 * np.pi) < 1000.0 <= f[lam.size]
    assert sum(calls) <= f.size  # no pair asked for twice


def test_count_and_limit_and_bad_arguments():
    f = np.linspace(10.0, 1000.0, 50)
    calls: list[int] = []
    assert lowest_eigenpairs(_diagonal(f, calls), n_modes=7)[0].size == 7
    assert lowest_eigenpairs(_diagonal(f, calls), max_hz=1e9, limit=50)[0].size == 50  # every pair the problem has
    assert lowest_eigenpairs(_diagonal(f, calls), n_modes=0)[0].size == 0
    for kwargs in ({}, {"n_modes": 3, "max_hz": 100.0}, {"max_hz": -1.0}, {"n_modes": -1}):
        with pytest.raises(ValueError, match="lowest_eigenpairs"):
            lowest_eigenpairs(_diagonal(f, calls), **kwargs)


def test_deflated_shift_invert_continues_where_the_last_call_stopped():
    """A fixed-free bar of 600 linear elements (E A = 1, rho A = 1, length 1): the pairs below a limit found by
    growing deflated block Lanczos calls (flexgear.fe.spectrum.shift_invert_pairs) equal the dense generalised eigen
    solution; each call asks only for pairs not found before, and the vectors come back M-orthonormal."""
    import scipy.linalg as la
    import scipy.sparse as sp
    import scipy.sparse.linalg as sla

    from flexgear.fe.spectrum import shift_invert_pairs

    n, h = 600, 1.0 / 600
    main = np.full(n, 2.0)
    main[-1] = 1.0  # the free end
    k = sp.diags([main / h, -np.ones(n - 1) / h, -np.ones(n - 1) / h], [0, -1, 1], format="csc")
    m = sp.diags([main * h / 3, np.full(n - 1, h / 6), np.full(n - 1, h / 6)], [0, -1, 1], format="csc")
    lu = sla.splu(k)
    v0 = np.random.default_rng(1).standard_normal(n)
    calls: list[int] = []

    def eigen(count: int, found: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        calls.append(count)
        return shift_invert_pairs(lu.solve, m, count, v0, found)

    exact = la.eigh(k.toarray(), m.toarray(), eigvals_only=True)
    max_hz = np.sqrt(0.5 * (exact[39] + exact[40])) / (2 * np.pi)  # between the 40th and the 41st pair
    lam, vec = lowest_eigenpairs(eigen, max_hz=max_hz)
    below = exact[:40]
    assert len(calls) > 1  # the limit needed more than the first call
    assert lam.size == below.size
    np.testing.assert_allclose(lam, below, rtol=1e-9)
    np.testing.assert_allclose(vec.T @ (m @ vec), np.eye(lam.size), atol=1e-8)


def _bar(n: int):
    """Stiffness and mass of a fixed-free bar of ``n`` linear elements (E A = 1, rho A = 1, length 1)."""
    import scipy.sparse as sp

    h = 1.0 / n
    main = np.full(n, 2.0)
    main[-1] = 1.0  # the free end
    k = sp.diags([main / h, -np.ones(n - 1) / h, -np.ones(n - 1) / h], [0, -1, 1], format="csc")
    m = sp.diags([main * h / 3, np.full(n - 1, h / 6), np.full(n - 1, h / 6)], [0, -1, 1], format="csc")
    return k, m


@pytest.mark.parametrize("count", [3, 40, 90])
def test_pairs_below_a_limit_in_one_krylov_space(count):
    """An ``eigen`` that takes ``below``: one call finds every pair below the limit (fewer, as many or more than the
    first count the limit search reads T at) and the first beyond it, equal to the dense solution."""
    import scipy.linalg as la
    import scipy.sparse.linalg as sla

    from flexgear.fe.spectrum import shift_invert_pairs

    k, m = _bar(600)
    lu = sla.splu(k)
    v0 = np.random.default_rng(1).standard_normal(600)
    calls: list[int] = []

    def eigen(n: int, found: np.ndarray | None, below: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        calls.append(n)
        return shift_invert_pairs(lu.solve, m, n, v0, found, below=below)

    exact = la.eigh(k.toarray(), m.toarray(), eigvals_only=True)
    max_hz = np.sqrt(0.5 * (exact[count - 1] + exact[count])) / (2 * np.pi)
    lam, vec = lowest_eigenpairs(eigen, max_hz=max_hz)
    assert len(calls) == 1
    np.testing.assert_allclose(lam, exact[:count], rtol=1e-9)
    np.testing.assert_allclose(vec.T @ (m @ vec), np.eye(count), atol=1e-8)


def test_block_lanczos_finds_both_members_of_double_pairs():
    """Two identical fixed-free bars side by side (as a cyclic ring's modes come in pairs): every eigenvalue is
    double, and the block Lanczos returns each twice, equal to the dense solution to 1e-10, with M-orthonormal
    vectors that span both bars' modes."""
    import scipy.linalg as la
    import scipy.sparse as sp

    from flexgear.fe.cholesky import SparseCholesky
    from flexgear.fe.spectrum import shift_invert_pairs

    n, h = 300, 1.0 / 300
    main = np.full(n, 2.0)
    main[-1] = 1.0
    k1 = sp.diags([main / h, -np.ones(n - 1) / h, -np.ones(n - 1) / h], [0, -1, 1])
    m1 = sp.diags([main * h / 3, np.full(n - 1, h / 6), np.full(n - 1, h / 6)], [0, -1, 1])
    k, m = sp.block_diag([k1, k1], format="csc"), sp.block_diag([m1, m1], format="csr")
    chol = SparseCholesky(k)
    v0 = chol.solve(m @ np.random.default_rng(2).standard_normal(2 * n))
    lam, vec = shift_invert_pairs(chol.solve, m, 20, v0)
    exact = la.eigh(k1.toarray(), m1.toarray(), eigvals_only=True)[:10]
    np.testing.assert_allclose(lam, np.repeat(exact, 2), rtol=1e-10)
    np.testing.assert_allclose(vec.T @ (m @ vec), np.eye(20), atol=1e-10)
    halves = np.linalg.norm(vec[:n], axis=0) ** 2 + np.linalg.norm(vec[n:], axis=0) ** 2
    assert np.all(halves > 0)
    for j in range(0, 20, 2):  # each pair spans one bar's mode on either bar: rank 2 over the two halves
        pair = np.vstack([vec[:n, j:j + 2], vec[n:, j:j + 2]])
        assert np.linalg.matrix_rank(pair, tol=1e-8 * np.abs(pair).max()) == 2


def test_block_lanczos_on_a_space_it_exhausts():
    """K = diag(1 ... 12), M = I, blocks of 4: asking for 10 pairs fills the whole space (12 vectors) before a
    block beyond them fits, and the start block reaches an invariant subspace (its Krylov space has dependent
    columns): the pairs are still exact and the vectors orthonormal."""
    import scipy.sparse as sp

    from flexgear.fe.spectrum import shift_invert_pairs

    d = np.arange(1.0, 13.0)
    for k in (5, 10):
        lam, vec = shift_invert_pairs(lambda y: y / d[:, None], sp.identity(12, format="csr"), k, np.ones(12),
                                      block=4)
        np.testing.assert_allclose(lam, d[:k], rtol=1e-12)
        np.testing.assert_allclose(vec.T @ vec, np.eye(k), atol=1e-12)
