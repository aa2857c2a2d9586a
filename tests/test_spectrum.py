"""A reduced body's basis sized by frequency (flexgear.fe.spectrum): the eigenpairs below a limit, exactly. The bodies
built by that rule against their full FE models in the band: tests/test_attachment.py (sun, planet),
tests/test_tied_pair.py (the tied ring and output shaft)."""

import numpy as np
import pytest

from flexgear.fe.spectrum import lowest_eigenpairs


def _diagonal(frequencies_hz: np.ndarray, calls: list[int]):
    """eigen(k) of a diagonal problem with the given ascending frequencies, recording each k asked for."""
    lam = (2 * np.pi * frequencies_hz) ** 2

    def eigen(k: int) -> tuple[np.ndarray, np.ndarray]:
        calls.append(k)
        return lam[:k], np.eye(lam.size)[:, :k]

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
    assert calls == sorted(calls)


def test_count_and_limit_and_bad_arguments():
    f = np.linspace(10.0, 1000.0, 50)
    calls: list[int] = []
    assert lowest_eigenpairs(_diagonal(f, calls), n_modes=7)[0].size == 7
    assert lowest_eigenpairs(_diagonal(f, calls), max_hz=1e9, limit=50)[0].size == 50  # every pair the problem has
    assert lowest_eigenpairs(_diagonal(f, calls), n_modes=0)[0].size == 0
    for kwargs in ({}, {"n_modes": 3, "max_hz": 100.0}, {"max_hz": -1.0}, {"n_modes": -1}):
        with pytest.raises(ValueError, match="lowest_eigenpairs"):
            lowest_eigenpairs(_diagonal(f, calls), **kwargs)
