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


def _check(result, kept_reduced: list[str]) -> None:
    assert result.kept_reduced == kept_reduced
    assert result.leak < 1e-9
    assert result.recovery < RECOVERY
    assert len(result.full) > 0
    assert len(result.unpaired) == 0  # every mode of the full assembly below f_max has its reduced partner
    # Ritz: in ascending order each all-modes frequency at or above the full assembly's
    assert np.all(np.sort(result.all_modes) >= np.sort(result.full) * (1 - RITZ_SLACK))
    assert np.abs(result.error).max() < TOLERANCE


@pytest.mark.slow
def test_flexible_planets_against_full_fe():
    """Model 2 (five flexible planets on their bearings), modes below 2 kHz: the planets' first free-free mode
    lies near 9 kHz, so a light case; the bearing modes near 1.6 kHz feel the planets' flexibility."""
    result = compare_full_fe(load_variant(VARIANTS / "model2.toml"), f_max_hz=2000.0)
    _check(result, [])


@pytest.mark.heavy
def test_model7_against_full_fe():
    """Model 7 (every component flexible, coarse mesh), every mode below 3x the mesh frequency, with full FE models
    of the sun, the planets and the tied ring and output shaft. The input shaft stays reduced in both: its basis
    (every fixed-interface mode below [reduction_assumed] fixed_interface_cutoff_hz) has fewer modes than its two
    seats have attachment motions, so its couplings cannot be recovered from the linearisation; its own free-free
    modes against full FE: benchmarks/bench_convergence.py --band."""
    result = compare_full_fe(load_variant(VARIANTS / "model7.toml"))
    _check(result, ["input_shaft"])


def test_held_rigid_basis_carries_the_bodys_rigid_motions():
    """T of flexgear.fe.patches.held_rigid_basis on two patches of a random cloud: a rigid motion of the whole
    body is T [R_outside; I_6; I_6], and every column of T moves each patch rigidly."""
    from flexgear.fe.fem import rigid_body_modes
    from flexgear.fe.patches import held_rigid_basis

    nodes = np.random.default_rng(3).standard_normal((40, 3))
    patches = (np.array([2, 5, 7, 11]), np.array([20, 21, 30]))
    t = held_rigid_basis(nodes, patches).toarray()
    whole = rigid_body_modes(nodes)
    held = np.concatenate([(3 * b[:, None] + np.arange(3)).ravel() for b in patches])
    outside = np.setdiff1d(np.arange(3 * len(nodes)), held)
    np.testing.assert_allclose(t @ np.vstack([whole[outside], np.eye(6), np.eye(6)]), whole, atol=1e-12)
    for b in patches:
        dofs = (3 * b[:, None] + np.arange(3)).ravel()
        shapes = t[dofs]
        q = np.linalg.qr(rigid_body_modes(nodes[b]))[0]
        np.testing.assert_allclose(shapes - q @ (q.T @ shapes), 0.0, atol=1e-12)
