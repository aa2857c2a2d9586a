"""The cold build's pieces: the sparse Cholesky factor (flexgear.fe.cholesky) against SciPy's SuperLU, an
independent factorisation, on a plain ring's free-body stiffness, and the worker schedule's inputs."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as sla
from test_flexible import STEEL, ring_mesh

from flexgear.fe.build import COLD_BUILD_ORDER, build_components, build_items
from flexgear.fe.cholesky import SparseCholesky
from flexgear.fe.fem import fe_model
from flexgear.spec import GEOMETRY_COMPONENTS


def test_cholesky_solves_the_stiffness_system_as_superlu_does():
    """K_ff (a ring's stiffness with the six support coordinates of flexgear.fe.cms removed) is positive
    definite: the Cholesky solution of K_ff u = f has a round-off residual and equals SuperLU's to round-off
    times the condition number, for one and several loads."""
    from flexgear.fe.cms import FreeBodySolver

    fe = fe_model(ring_mesh(0.004), STEEL, 2)
    free = FreeBodySolver(fe).free
    k_ff = fe.K[free][:, free]
    loads = np.random.default_rng(3).standard_normal((len(free), 3))
    expected = sla.splu(k_ff.tocsc()).solve(loads)
    chol = SparseCholesky(k_ff)
    got = chol.solve(loads)
    k_norm = sla.norm(k_ff, 1)  # normwise backward error ||K u - f|| / (||K|| ||u|| + ||f||): round-off
    for u in (got, expected):
        assert np.abs(k_ff @ u - loads).max() < 1e-14 * (k_norm * np.abs(u).max() + np.abs(loads).max())
    # forward error: round-off times the condition of the thin ring's K_ff (both factorisations differ there)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-7 * np.abs(expected).max())
    np.testing.assert_allclose(chol.solve(loads[:, 0]), got[:, 0], rtol=0, atol=1e-12 * np.abs(got).max())
    with pytest.raises(ValueError, match="rows"):
        chol.solve(loads[:-1])


def test_cholesky_refuses_a_coordinate_without_stiffness():
    """A free coordinate (a zero row and column, as a second-order mesh's unconnected mid-edge points give)
    makes K singular: the factorisation says so instead of returning a solution."""
    import scipy.sparse as sp

    from flexgear.fe.cms import FreeBodySolver

    fe = fe_model(ring_mesh(0.004), STEEL, 1)
    free = FreeBodySolver(fe).free
    k_ff = fe.K[free][:, free]
    SparseCholesky(k_ff)  # positive definite: factorises
    k = sp.block_diag([k_ff, sp.csr_matrix((1, 1))], format="csr")  # one more coordinate, without stiffness
    with pytest.raises(ValueError, match="not positive definite"):
        SparseCholesky(k)


def test_cold_build_schedules_every_component_and_checks_its_workers(gearbox):
    from flexgear.fe.ring_shaft import TIED_PAIR

    assert sorted(COLD_BUILD_ORDER) == sorted(build_items()) == sorted((*GEOMETRY_COMPONENTS, TIED_PAIR))
    assert build_items(reduce=False) == GEOMETRY_COMPONENTS
    assert build_items(arrangement="planetary") == GEOMETRY_COMPONENTS  # no tied ring and output shaft there
    with pytest.raises(ValueError, match="workers"):
        build_components(gearbox, "coarse", workers=0)


def test_cholesky_solves_a_block_of_columns_in_one_call():
    """The factorisation is CHOLMOD's own, called directly (a block of columns in one pass over the factor, not
    CVXOPT's column-by-column binding): found and loaded, and its block solve equals its solves of each column."""
    from flexgear.fe.cholesky import _cholmod

    assert _cholmod() is not None
    fe = fe_model(ring_mesh(0.004), STEEL, 1)
    from flexgear.fe.cms import FreeBodySolver

    free = FreeBodySolver(fe).free
    chol = SparseCholesky(fe.K[free][:, free])
    loads = np.random.default_rng(4).standard_normal((len(free), 9))
    block = chol.solve(loads)
    for j in range(loads.shape[1]):
        np.testing.assert_allclose(block[:, j], chol.solve(loads[:, j]), rtol=0, atol=1e-12 * np.abs(block).max())


def test_a_cold_matrix_builds_the_longest_body_first_and_runs_what_needs_it_last(tmp_path, monkeypatch):
    """With an empty cache the matrix pool gets every body its runs need as a job ahead of the runs, the tied ring
    and output shaft first (the longest build), and only the runs that need that body wait at the end: model 7's;
    model 1 (rigid) needs no body, model 4 the sun's and the ring's alone."""
    from conftest import VARIANTS

    from flexgear.fe.build import variant_build_items
    from flexgear.fe.ring_shaft import TIED_PAIR
    from flexgear.spec import load_variant
    from flexgear.study.matrix import _cold_build

    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(tmp_path))
    variants = {name: load_variant(VARIANTS / "quick" / f"{name}.toml") for name in ("model1", "model4", "model7")}
    items = {name: variant_build_items(v.gearbox, v.components) for name, v in variants.items()}
    assert items == {"model1": (), "model4": ("sun", "ring"),
                     "model7": ("input_shaft", "sun", "planet", TIED_PAIR)}
    jobs, waits = _cold_build(variants)
    built = [args[1] for _, _, args in jobs]
    assert built[0] == TIED_PAIR and sorted(built) == sorted({*items["model4"], *items["model7"]})
    assert waits == {"model7"}
