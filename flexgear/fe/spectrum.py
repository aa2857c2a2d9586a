"""How many fixed-interface modes a reduction keeps: a count, or every mode below a frequency.

Craig-Bampton bases converge from below: a reduced body's free-free frequencies approach the full FE model's
as fixed-interface modes are added, and the usual rule keeps every fixed-interface mode up to a margin above the
highest frequency the body must reproduce. :func:`lowest_eigenpairs` gives a sparse eigen solver's lowest pairs
either as a count or as every pair below ``max_hz``; the count of the second is not known in advance, so the
solver is called with a growing count until the highest pair found lies above ``max_hz``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

__all__ = ["lowest_eigenpairs"]

_FIRST_COUNT = 24
"""First count tried for a frequency limit (fewer than the lowest modes of a gear or a shaft below 6x its mesh)."""
_DENSITY_EXPONENT = 1.5
"""Growth of the mode count N with frequency f assumed for the next guess, N ~ f^1.5 (between a plate's N ~ f and
a solid's N ~ f^3, Weyl's law); a guess that falls short only costs another call."""
_GUESS_MARGIN = 1.15
"""Extra share of modes asked beyond the guess, so that one call usually reaches the limit."""


def lowest_eigenpairs(eigen: Callable[[int], tuple[np.ndarray, np.ndarray]], n_modes: int | None = None,
                      max_hz: float | None = None, limit: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Lowest eigenpairs (lambda = omega^2 [1/s^2] ascending, vectors as columns) of ``eigen(k)``, which returns
    the lowest ``k`` pairs ascending.

    Exactly one of ``n_modes`` (the count) and ``max_hz`` (every pair with omega / 2 pi below it [Hz]) is given.
    ``limit``: the most pairs the problem has; a frequency limit beyond them returns them all.
    """
    if (n_modes is None) == (max_hz is None):
        raise ValueError("lowest_eigenpairs: give exactly one of n_modes and max_hz")
    if n_modes is not None:
        if n_modes < 0:
            raise ValueError(f"lowest_eigenpairs: n_modes must be >= 0, got {n_modes}")
        return eigen(min(n_modes, limit) if limit is not None else n_modes) if n_modes else _none()
    if not max_hz > 0.0:
        raise ValueError(f"lowest_eigenpairs: max_hz must be > 0, got {max_hz}")
    lam_max = (2.0 * math.pi * max_hz) ** 2
    k = _FIRST_COUNT if limit is None else min(_FIRST_COUNT, limit)
    while True:
        lam, vec = eigen(k)
        if lam[-1] >= lam_max or (limit is not None and k >= limit):
            keep = lam < lam_max
            return lam[keep], vec[:, keep]
        ratio = math.sqrt(lam_max / max(lam[-1], 1e-300))  # frequency ratio still to go
        k_next = math.ceil(k * ratio ** _DENSITY_EXPONENT * _GUESS_MARGIN)
        k = max(k_next, k + 8) if limit is None else min(max(k_next, k + 8), limit)


def _none() -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(0), np.zeros((0, 0))
