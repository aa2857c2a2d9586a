"""The ring and the output shaft reduced as one tied body (flexgear.fe.ring_shaft.tied_pair_body) against the full FE
of the tied pair (the tie of flexgear.fe.bolted, checked equal in tests/test_tied.py), coarse meshes: free-free
modes, and static compliance at the ring's contact bands (contact-kernel loads, bearing seat held) and at the
bearing seat (its six RBE3 loads, the ring's side of the joint held). The full FE model has 3e5 coordinates: one
factorisation and ten eigenpairs take about a minute and 3 GB, hence heavy."""

import numpy as np
import pytest
from test_attachment import interface_compliance

import flexgear as fg
from flexgear.fe.compliance import free_body_solver

pytestmark = pytest.mark.heavy


@pytest.fixture(scope="module")
def pair(gearbox):
    """(tied FE model of ring + output shaft, the reduced tied body, the ring's side of the joint on the FE model)."""
    from flexgear.fe.ring_shaft import pair_fe_models, ring_seat, tied_pair, tied_pair_body

    ring, shaft = pair_fe_models(gearbox, "coarse")
    tied = tied_pair(ring, shaft, gearbox)
    body = tied_pair_body(gearbox, "coarse")
    assert np.array_equal(body.nodes, tied.fe.nodes)
    return tied.fe, body, tied.interface("ring", ring_seat(ring, gearbox))


def test_tied_body_mass_properties_are_the_sum_of_the_parts(gearbox, pair):
    """The rigid/flexible twin rule for the joined body: its mass properties (read alone from the cache, as a rigid
    twin reads them) equal the ring's and the shaft's bodies' combined."""
    from flexgear.fe.reduced import component_mass_properties
    from flexgear.fe.ring_shaft import PAIR, tied_pair_mass_properties
    from flexgear.geometry.massprops import combine_mass_properties

    parts = combine_mass_properties(*(component_mass_properties(gearbox, c, "coarse") for c in PAIR))
    for props in (tied_pair_mass_properties(gearbox, "coarse"), pair[1].props):
        assert props.mass == pytest.approx(parts.mass, rel=1e-12)
        np.testing.assert_allclose(props.com, parts.com, atol=1e-12)
        np.testing.assert_allclose(props.inertia, parts.inertia, atol=1e-12 * np.abs(parts.inertia).max())


def test_tied_body_free_free_modes_in_the_band_within_1_percent_of_full_fe(gearbox, pair):
    """Every free-free mode of the full FE pair below 3x the mesh frequency (the band the assembly is checked in,
    tests/test_modal_full_fe.py) has its reduced partner within 1 %: the basis holds every fixed-interface mode
    below [reduction_assumed] fixed_interface_cutoff_hz."""
    from flexgear.design import as_design
    from flexgear.fe.spectrum import lowest_eigenpairs

    fe, body, _ = pair
    band = 3.0 * as_design(gearbox).theory.mesh_frequency
    solver = free_body_solver(fe)
    m = fe.mass_operator()
    free = solver.constrained((m @ solver.R).T)  # the flexible modes: M-orthogonal to the rigid ones
    lam = lowest_eigenpairs(lambda k, found, below=None: free.eigen(fe, k, m, found, below), max_hz=band)[0]
    full = np.sqrt(lam) / (2 * np.pi)
    assert full.size > 100  # a thin ring and a long tube: a dense spectrum
    np.testing.assert_allclose(body.frequencies_hz[:full.size], full, rtol=0.01)


def test_tied_body_compliance_at_contact_bands_and_bearing_seat_within_2_percent(gearbox, pair):
    from flexgear.fe.reduced import component_contacts, component_load_circles

    fe, body, ring_side = pair
    points, normals = component_contacts(gearbox, "ring")
    kernel = component_load_circles(gearbox, "ring", gearbox.reduction_assumed.contact_fourier_order)
    seat = body.interface("bearing_seat")
    full = fg.static_compliance(fe, points, normals, seat, kernel=kernel)
    reduced = fg.static_compliance(body, points, normals, "bearing_seat", kernel=kernel)
    assert np.max(np.abs(reduced - full)) < 0.02 * np.max(np.abs(full))
    assert reduced.sum(axis=1) == pytest.approx(full.sum(axis=1), rel=0.02)  # all contacts loaded together
    assert np.array_equal(body.interface("ring_seat").nodes, ring_side.nodes)
    full_seat = interface_compliance(fe, seat, ring_side)
    reduced_seat = interface_compliance(body, seat, body.interface("ring_seat"))
    assert np.diag(reduced_seat) == pytest.approx(np.diag(full_seat), rel=0.02)


def test_part_shares_of_the_tied_body_add_up_from_each_parts_own_fe(gearbox):
    """Each part's share of a mode's energy (flexgear.fe.ring_shaft.tied_part_matrices: the ring's from its own
    nodes, the shaft's the rest) equals the shaft's energy computed from its own FE matrices on its nodes' motion
    through the tie, u_s = T_s u (the tie conserves energy: K = T^T blockdiag(K_r, K_s) T): within 1e-8 of the
    largest entry; both parts' shares are positive semi-definite."""
    import scipy.sparse as sp

    from flexgear.fe.ring_shaft import pair_fe_models, tied_pair, tied_pair_body, tied_part_matrices

    ring, shaft = pair_fe_models(gearbox, "coarse")
    tied = tied_pair(ring, shaft, gearbox)
    body = tied_pair_body(gearbox, "coarse")
    parts = tied_part_matrices(gearbox, "coarse")
    rows = tied.scalar_tie[tied.offsets[1]:tied.offsets[2]]
    u_s = sp.kron(rows, sp.identity(3), format="csr") @ body.modes
    for k, (fe_matrix, own) in enumerate(((shaft.M, parts["output_shaft"][0]), (shaft.K, parts["output_shaft"][1]))):
        direct = u_s.T @ (fe_matrix @ u_s)
        assert np.abs(direct - own).max() < 1e-8 * np.abs(own).max(), k
    for m_p, k_p in parts.values():
        assert np.linalg.eigvalsh(m_p).min() > -1e-10 and np.linalg.eigvalsh(k_p).min() > -1e-10 * body.stiffness.max()
