"""The linearised flexible variants against the same assembly with full FE bodies (flexgear.modal.full_fe).

The reference replaces each reduced body's dynamic flexibility at its attachment motions by the full FE model's
(exact substructuring, at zero speed); the couplings come from the all-modes linearisation and are checked twice:
they lie in the row space of the attachment motions (``leak``), and recomputed from them the frequencies of that
linearisation come back (``recovery``). The reduced bodies are Ritz approximations of the full FE ones: each
frequency of the all-modes model lies at or above the full assembly's of the same order (up to the solver's
precision), once every full-assembly mode below f_max has its reduced partner.
"""

import numpy as np
import pytest
from conftest import VARIANTS

from flexgear.modal.full_fe_check import compare_full_fe
from flexgear.spec import load_variant

TOLERANCE = 0.01  # every mode below 3x the mesh frequency within 1 % of the full FE assembly
RECOVERY = 1e-7  # couplings recovered exactly: frequencies back to round-off of the dense eigen solves
RITZ_SLACK = 1e-7  # relative: an all-modes frequency may sit this far below the full FE one (solver precision)


def _check(result) -> None:
    assert result.leak < 1e-9
    assert result.recovery < RECOVERY
    assert len(result.full) > 0
    assert len(result.unpaired) == 0  # every mode of the full assembly below f_max has its reduced partner
    assert np.all(result.basis_error > -RITZ_SLACK)
    assert np.abs(result.error).max() < TOLERANCE


@pytest.mark.slow
def test_flexible_planets_against_full_fe():
    """Model 2 (five flexible planets on their bearings), modes below 2 kHz: the planets' first free-free mode
    lies near 9 kHz, so a light case; the bearing modes near 1.6 kHz feel the planets' flexibility."""
    result = compare_full_fe(load_variant(VARIANTS / "model2.toml"), f_max_hz=2000.0)
    _check(result)


@pytest.mark.heavy
@pytest.mark.xfail(strict=True, reason="the tied ring and output shaft's basis ([reduction_assumed] "
                   "fixed_interface_modes) converges its 12 lowest free-free modes, not its spectrum up to 3x the "
                   "mesh frequency: its full FE model has modes there that the reduced body lacks")
def test_model7_against_full_fe():
    """Model 7 (every component flexible, coarse mesh), every mode below 3x the mesh frequency."""
    result = compare_full_fe(load_variant(VARIANTS / "model7.toml"))
    _check(result)
