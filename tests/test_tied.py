"""Tied FE assemblies (flexgear.fe.tied, flexgear.fe.ring_shaft): parts tied over mating faces reduced as one body.

Two tubes tied end to end against one tube of their joint length (continuum: the tie of non-matching meshes
converges to the uncut tube), and the study's ring and output shaft tied as flexgear.fe.bolted ties them for the
full-FE reference (coarse meshes). The reduced tied pair against the full FE of the tied pair: tests/
test_tied_pair.py (heavy) and benchmarks/bench_tied.py.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from test_flexible import STEEL

import flexgear as fg
from flexgear.fe.cms import full_free_modes
from flexgear.fe.fem import fe_model, rigid_body_modes
from flexgear.geometry.massprops import combine_mass_properties

R_OUT, R_IN, LENGTH, MAXH = 0.02, 0.014, 0.08, 0.008  # m: a stocky tube, cut in two halves of LENGTH


def tube(z0: float, length: float):
    """Tube along z from z0 to z0 + length, end faces "root" (z0) and "tip"."""
    import ngsolve as ngs
    from netgen.occ import Axes, Cylinder, OCCGeometry, X, Z

    axes = Axes((0, 0, z0), Z, X)
    shape = Cylinder(axes, R_OUT, length) - Cylinder(axes, R_IN, length)
    shape.faces.Min(Z).name = "root"
    shape.faces.Max(Z).name = "tip"
    return fe_model(ngs.Mesh(OCCGeometry(shape).GenerateMesh(maxh=MAXH)), STEEL, order=2)


@pytest.fixture(scope="module")
def tubes():
    """(lower half, upper half, whole tube) as FE models, second order."""
    return tube(0.0, LENGTH), tube(LENGTH, LENGTH), tube(0.0, 2 * LENGTH)


def test_two_tied_halves_reduce_to_the_whole_tube(tubes):
    """fg.reduce on a list of FE models and their tie: the body's free-free modes are the uncut tube's (full FE) to
    the mesh's discretisation error, its mass properties the sum of the halves' (exactly: the tie carries linear
    fields), and the tied model's rigid motions have no energy."""
    lower, upper, whole = tubes
    tie = fg.Tie(master=0, slave=1, slave_nodes=upper.region("root"), plane_point=(0.0, 0.0, LENGTH))
    tied = fg.tie_parts([lower, upper], [tie], names=("lower", "upper"))
    assert tied.fe.n_nodes == lower.n_nodes + upper.n_nodes - len(upper.region("root"))
    rigid = rigid_body_modes(tied.fe.nodes)
    assert np.abs(rigid.T @ (tied.fe.K @ rigid)).max() < 1e-9 * tied.fe.K.diagonal().max()
    parts = combine_mass_properties(lower.mass_properties(), upper.mass_properties())
    props = tied.fe.mass_properties()
    assert props.mass == pytest.approx(parts.mass, rel=1e-12)
    np.testing.assert_allclose(props.com, parts.com, atol=1e-12 * LENGTH)
    np.testing.assert_allclose(props.inertia, parts.inertia, atol=1e-12 * np.abs(parts.inertia).max())

    body = fg.reduce([lower, upper], ["lower.root", "upper.tip"], 20, n_compare=0, ties=[tie],
                     names=("lower", "upper"))
    assert body.props.mass == pytest.approx(parts.mass, rel=1e-12)
    assert [i.name for i in body.interfaces] == ["lower.root", "upper.tip"]
    f_whole = full_free_modes(whole, 6)[0]
    np.testing.assert_allclose(body.frequencies_hz[:6], f_whole, rtol=0.01)
    # the same body from the TiedFE, and the single-model call form unchanged
    again = fg.reduce(tied, ["lower.root", "upper.tip"], 20, n_compare=0)
    np.testing.assert_allclose(again.frequencies_hz, body.frequencies_hz, rtol=1e-9)
    single = fg.reduce(whole, ["root", "tip"], 20, n_compare=0)
    np.testing.assert_allclose(single.frequencies_hz[:6], f_whole, rtol=0.01)


def test_tie_errors_name_the_problem(tubes):
    lower, upper, _ = tubes
    off_plane = fg.Tie(0, 1, upper.region("tip"), plane_point=(0.0, 0.0, LENGTH))
    with pytest.raises(ValueError, match="off the mating plane"):
        fg.tie_parts([lower, upper], [off_plane])
    no_face = fg.Tie(0, 1, upper.region("root"), plane_point=(0.0, 0.0, LENGTH), plane_normal=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="off the mating plane|no boundary face"):
        fg.tie_parts([lower, upper], [no_face])
    tied = fg.tie_parts([lower, upper], [fg.Tie(0, 1, upper.region("root"), (0.0, 0.0, LENGTH))])
    with pytest.raises(ValueError, match="tied slave nodes"):
        tied.nodes_of(1, upper.region("root"))
    with pytest.raises(ValueError, match="ties need a list"):
        fg.reduce(lower, ["root"], 5, ties=[fg.Tie(0, 1, upper.region("root"), (0.0, 0.0, LENGTH))])


@pytest.fixture(scope="module")
def pair(coarse_fe):
    """flexgear.fe.ring_shaft.pair_fe_models(gearbox, "coarse")."""
    from flexgear.fe.ring_shaft import PAIR

    return tuple(coarse_fe(name) for name in PAIR)


def test_ring_and_shaft_tied_as_the_full_fe_reference_ties_them(gearbox, pair):
    """The tied pair's K and M are flexgear.fe.bolted's T^T K T and T^T M T (the full-FE reference), the mass
    properties the sum of the ring's and the shaft's (the rigid-twin rule for the joined body), and the reduction
    interfaces and the ring's contact bands are those of the parts alone."""
    from flexgear.fe.attachment import circle_band
    from flexgear.fe.bolted import bolt_axes, clamped_patches, tie_matrix
    from flexgear.fe.reduced import component_interfaces, component_load_circles
    from flexgear.fe.ring_shaft import ring_seat, tied_pair, tied_pair_interfaces

    ring, shaft = pair
    tied = tied_pair(ring, shaft, gearbox)
    t = tie_matrix(ring, shaft, np.concatenate(clamped_patches(shaft, gearbox)), bolt_axes(gearbox)[2])
    for mine, parts in ((tied.fe.K, [ring.K, shaft.K]), (tied.fe.M, [ring.M, shaft.M])):
        ref = t.T @ sp.block_diag(parts, format="csr") @ t
        assert abs(ref - mine).max() < 1e-12 * abs(ref).max()
    props = tied.fe.mass_properties()
    parts = combine_mass_properties(ring.mass_properties(), shaft.mass_properties())
    assert props.mass == pytest.approx(parts.mass, rel=1e-12)
    np.testing.assert_allclose(props.com, parts.com, atol=1e-12)
    np.testing.assert_allclose(props.inertia, parts.inertia, atol=1e-12 * np.abs(parts.inertia).max())
    (seat,) = tied_pair_interfaces(tied, shaft, gearbox)
    alone = next(i for i in component_interfaces(shaft, gearbox, "output_shaft") if i.name == "bearing_seat")
    np.testing.assert_array_equal(tied.fe.nodes[seat.nodes], shaft.nodes[alone.nodes])
    np.testing.assert_array_equal(seat.weights, alone.weights)
    np.testing.assert_array_equal(tied.fe.nodes[:ring.n_nodes], ring.nodes)  # the ring's nodes keep their indices
    ring_side = ring_seat(ring, gearbox)
    assert len(ring_side.nodes) == sum(len(p) for p in clamped_patches(ring, gearbox))
    for circle in component_load_circles(gearbox, "ring", gearbox.reduction_assumed.attachment_order):
        np.testing.assert_array_equal(circle_band(tied.fe.nodes, circle), circle_band(ring.nodes, circle))
