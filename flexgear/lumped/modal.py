"""Natural frequencies and mode shapes of the linearised lumped model (mean mesh stiffness).

The undamped eigenproblem K phi = omega^2 M phi of :func:`flexgear.lumped.model.assemble` with the
mean mesh stiffness of eq. 10 (gyroscopic and centripetal terms of a rotating carrier neglected, as
in Lin & Parker 1999). Each mode is classified by where its kinetic energy sits (mass-normalised
shape, energy share e = m phi^2 per coordinate):

- ``planet``: the central members (sun, ring, carrier) do not move (Lin & Parker's planet modes,
  multiplicity N - 3 with equally spaced planets; N - 1 in the purely torsional model)
- ``rotational``: central members only spin (single modes)
- ``translational``: central members only translate (pairs of equal frequency)
- ``mixed``: anything else (e.g. unequally spaced planets)

The parallel-axis pair (flexgear.lumped.model: the pinion on the sun, the wheel on planet 1, ring and carrier held,
one mesh) reads the same way: ``planet`` is a mode of the wheel alone, ``rotational`` and ``translational`` those in
which the pinion only spins or only translates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.linalg import eigh

from flexgear.lumped.model import LumpedParameters, LumpedSystem, assemble
from flexgear.spec import GearboxSpec

__all__ = ["ModalResult", "modal_analysis", "classify_mode"]

_ENERGY_TOL = 1e-8  # energy share below which a group of coordinates counts as not moving
_FREQ_RTOL = 1e-6  # relative frequency difference below which modes count as repeated


@dataclass(frozen=True)
class ModalResult:
    """Natural frequencies [Hz] (ascending), mass-normalised mode shapes over all coordinates, types."""

    frequencies_hz: np.ndarray
    shapes: np.ndarray  # (n_coordinates, n_modes); held coordinates are zero
    kinds: tuple[str, ...]
    multiplicity: np.ndarray
    labels: tuple[str, ...]
    system: LumpedSystem

    def table(self) -> pd.DataFrame:
        """One row per mode: frequency, type, multiplicity and energy shares of the body groups."""
        e = _energy(self.system, self.shapes)
        return pd.DataFrame({
            "frequency_hz": self.frequencies_hz,
            "kind": self.kinds,
            "multiplicity": self.multiplicity,
            "central_spin_energy": e[0],
            "central_translation_energy": e[1],
            "planet_energy": e[2],
        })


def _energy(system: LumpedSystem, shapes: np.ndarray) -> np.ndarray:
    """Kinetic-energy shares (central spin, central translation, planets) per mode, each column sums to 1."""
    w = system.mass[:, None] * shapes**2
    total = np.maximum(w.sum(0), 1e-300)
    spin = np.zeros(system.n, bool)
    spin[[2, 5, 8]] = True
    central = np.zeros(system.n, bool)
    central[:9] = True
    return np.stack([w[central & spin].sum(0), w[central & ~spin].sum(0), w[~central].sum(0)]) / total


def classify_mode(system: LumpedSystem, shape: np.ndarray) -> str:
    """``planet``, ``rotational``, ``translational`` or ``mixed`` (see the module docstring)."""
    spin, trans, _ = _energy(system, shape[:, None])[:, 0]
    if spin + trans < _ENERGY_TOL:
        return "planet"
    if trans < _ENERGY_TOL:
        return "rotational"
    if spin < _ENERGY_TOL:
        return "translational"
    return "mixed"


def _multiplicity(freqs: np.ndarray) -> np.ndarray:
    mult = np.ones(freqs.size, dtype=int)
    for i, f in enumerate(freqs):
        scale = max(abs(f), 1e-3)
        mult[i] = int(np.sum(np.abs(freqs - f) <= _FREQ_RTOL * scale))
    return mult


def modal_analysis(model: GearboxSpec | LumpedParameters | LumpedSystem, translations: bool = True,
                   hold_input: bool = False) -> ModalResult:
    """Natural frequencies, mode shapes and mode types of the linearised lumped model.

    ``model``: a gearbox spec (parameters from :meth:`LumpedParameters.from_spec`; ``hold_input``
    holds the sun's spin as the prescribed drive of the time integration does), plain
    :class:`LumpedParameters` of any single-stage planetary set, or an assembled system.
    ``translations=False``: the purely torsional model (all translations held).
    """
    if isinstance(model, GearboxSpec):
        model = LumpedParameters.from_spec(model, hold_input=hold_input)
    system = model if isinstance(model, LumpedSystem) else assemble(model, translations=translations)
    free = np.flatnonzero(system.free)
    K = system.stiffness()[np.ix_(free, free)]
    M = np.diag(system.mass[free])
    lam, vec = eigh(K, M)
    lam = np.where(np.abs(lam) < 1e-9 * max(np.abs(lam).max(), 1.0), 0.0, lam)
    freqs = np.sqrt(np.maximum(lam, 0.0)) / (2.0 * math.pi)
    shapes = np.zeros((system.n, free.size))
    shapes[free] = vec
    kinds = tuple(classify_mode(system, shapes[:, j]) for j in range(free.size))
    return ModalResult(freqs, shapes, kinds, _multiplicity(freqs), system.labels, system)
