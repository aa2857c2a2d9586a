"""The ring-output shaft tie over the bolts' clamped discs (flexgear.fe.bolted), as the tied body of the ring and
output shaft uses it (flexgear.fe.ring_shaft; checked against full FE in tests/test_tied_pair.py)."""


import numpy as np
import pytest
import scipy.sparse as sp


@pytest.fixture(scope="module")
def spec(gearbox):
    return gearbox


@pytest.fixture(scope="module")
def fe_pair(coarse_fe):
    return coarse_fe("ring"), coarse_fe("output_shaft")


def test_tie_carries_rigid_motions_and_mass_exactly(spec, fe_pair):
    """The multipoint tie (isoparametric on the ring's curved flange face) moves the shaft's clamped nodes with any
    rigid motion of the ring exactly, so the tied assembly has six zero-energy modes and the mass of both bodies."""
    from flexgear.fe.bolted import bolt_axes, clamped_patches, tie_matrix
    from flexgear.fe.fem import rigid_body_modes

    ring, shaft = fe_pair
    patches = clamped_patches(shaft, spec)
    assert len(patches) == spec.components_assumed.ring_bolt_count
    slaves = np.concatenate(patches)
    t = tie_matrix(ring, shaft, slaves, bolt_axes(spec)[2])
    tied = np.zeros(ring.n_nodes + shaft.n_nodes, bool)
    tied[ring.n_nodes + slaves] = True
    nodes = np.vstack([ring.nodes, shaft.nodes])
    kept = rigid_body_modes(nodes[~tied], centre=np.zeros(3))
    assert np.max(np.abs(t @ kept - rigid_body_modes(nodes, centre=np.zeros(3)))) < 1e-12
    m_t = t.T @ sp.block_diag([ring.M, shaft.M]) @ t
    k_t = t.T @ sp.block_diag([ring.K, shaft.K]) @ t
    mass = ring.mass_properties().mass + shaft.mass_properties().mass
    assert kept[:, 0] @ (m_t @ kept[:, 0]) == pytest.approx(mass, rel=1e-12)
    energy = np.abs(kept.T @ (k_t @ kept)).max()
    assert energy < 1e-9 * np.abs(k_t.diagonal()).max()
