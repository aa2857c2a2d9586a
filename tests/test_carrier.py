"""The planet carrier (flexgear.geometry.carrier, flexgear.fe.carrier) of the spur planetary example
(examples/spur_planetary: 24/30/84, 3 planets, m 3 mm), coarse mesh:

- its exact mass properties (section integrals, the windows' by quadrature) against OCC's volume integrals of its
  solid (1e-9, the inertia 1e-7: the windows by quadrature) and against its second-order mesh (1e-4: the curved
  faces' geometric error);
- its reduced body against its own full FE model, the seat on the output shaft held (the seat is a rigid interface,
  so the full model holds the seat's nodes): every mode below 3x the mesh frequency within 1 %, the compliance of
  the pins under their own loads (the planets' bearing forces and moments, RBE3) within 2 %;
- sizes that leave no posts between the planets are refused in one line naming the dimension.

The body is built in the examples' cache, which the example's own tests share (about half a minute of CPU).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
from test_rigid_partner import Clamped

import flexgear as fg
from flexgear.fe.carrier import SEAT, carrier_body, carrier_fe_model, carrier_interfaces
from flexgear.fe.cms import rbe3_rows
from flexgear.fe.joined import body_matrices, joint_rows
from flexgear.geometry.carrier import carrier_mass_properties, carrier_sizes, carrier_solid

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary" / "gearbox.toml"
K_MODES = 12
"""Modes of the full FE model computed: more than lie below 3x the mesh frequency."""


@pytest.fixture(scope="module")
def carrier(example_cache):
    """(gearbox, sizes, full FE model, reduced body), the body in the examples' cache (conftest.example_cache)."""
    gearbox = fg.load_gearbox(EXAMPLE)
    sizes = carrier_sizes(gearbox)
    fe = carrier_fe_model(gearbox, "coarse")
    return gearbox, sizes, fe, carrier_body(gearbox, "coarse", fe=fe)


def test_exact_mass_properties_match_the_solid_and_the_mesh(carrier):
    from flexgear.geometry.solids import occ_mass_properties

    gearbox, sizes, fe, _ = carrier
    rho = gearbox.material_assumed.density_kg_m3
    exact = carrier_mass_properties(sizes, rho)
    mass, com, inertia = occ_mass_properties(carrier_solid(sizes), rho)
    assert mass == pytest.approx(exact.mass, rel=1e-9)
    assert np.abs(com - exact.com).max() < 1e-9
    assert np.abs(inertia - exact.inertia).max() < 1e-7 * exact.inertia.max()  # the windows by quadrature
    meshed = fe.mass_properties()
    assert meshed.mass == pytest.approx(exact.mass, rel=1e-4)
    np.testing.assert_allclose(np.diag(meshed.inertia), np.diag(exact.inertia), rtol=1e-4)


def test_reduced_carrier_against_its_full_fe_model_under_pin_and_seat_loads(carrier):
    gearbox, sizes, fe, body = carrier
    assert np.array_equal(body.nodes, fe.nodes)  # the same mesh
    assert np.array_equal(carrier_fe_model(gearbox, "coarse").nodes, fe.nodes)  # which meshing gives again
    itfs = {i.name: i for i in carrier_interfaces(fe, sizes)}
    held = Clamped(fe, itfs[SEAT].nodes)  # the full model, the seat's nodes held
    mass, stiffness = body_matrices(body)
    basis = la.null_space(joint_rows(body, SEAT, body.interface(SEAT).point))
    k_h, m_h = basis.T @ stiffness @ basis, basis.T @ mass @ basis
    # modes with the seat held
    full = held.frequencies(K_MODES)
    band = 3.0 * fg.theory(gearbox).mesh_frequency
    n = int(np.sum(full < band))
    assert 3 <= n < K_MODES, (n, full)
    reduced = np.sqrt(la.eigh(k_h, m_h, eigvals_only=True)[:n]) / (2 * np.pi)
    np.testing.assert_allclose(reduced, full[:n], rtol=0.01)
    # the pins' compliance under their own RBE3 loads (6 per pin)
    pins = [f"pin_{k}" for k in range(sizes.planet_count)]
    loads = sp.vstack([rbe3_rows(fe, itfs[p]) for p in pins]).T.toarray()
    c_full = held.compliance(loads)
    rows = np.vstack([joint_rows(body, p, body.interface(p).point) for p in pins]) @ basis
    c_red = rows @ np.linalg.solve(k_h, rows.T)
    assert np.max(np.abs(c_red - c_full)) < 0.02 * np.max(np.abs(c_full))
    np.testing.assert_allclose(np.diag(c_red), np.diag(c_full), rtol=0.02)


def test_sizes_without_posts_are_refused_in_one_line():
    gearbox = fg.load_gearbox(EXAMPLE)
    sizes = carrier_sizes(gearbox)
    with pytest.raises(ValueError, match="windows .* overlap") as err:
        carrier_sizes(gearbox, window_radius=sizes.pin_circle_radius)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="unknown sizes"):
        carrier_sizes(gearbox, plate_diameter=0.1)


def test_the_planetary_stages_rigid_carrier_carries_the_solids_mass_properties(tmp_path):
    """The derived ``[lumped_assumed] carrier_mass_kg`` / ``carrier_inertia_kg_m2`` of a planetary stage are the
    carrier solid's mass and polar inertia (the multibody and the lumped model's rigid carrier); a file that gives
    them keeps its values; the star's carrier (held) keeps the planets' estimate."""
    gearbox = fg.load_gearbox(EXAMPLE)
    exact = carrier_mass_properties(carrier_sizes(gearbox), gearbox.material_assumed.density_kg_m3)
    la = gearbox.lumped_assumed
    assert la.carrier_mass_kg == pytest.approx(exact.mass, rel=1e-12)
    assert la.carrier_inertia_kg_m2 == pytest.approx(exact.inertia[2, 2], rel=1e-12)
    given = tmp_path / "gearbox.toml"
    given.write_text(EXAMPLE.read_text() + "\n[lumped_assumed]\ncarrier_mass_kg = 7.5\ncarrier_inertia_kg_m2 = 0.05\n")
    assert fg.load_gearbox(given).lumped_assumed.carrier_mass_kg == 7.5
    star = tmp_path / "star.toml"
    star.write_text(EXAMPLE.read_text().replace('arrangement = "planetary"', 'arrangement = "star"'))
    assert fg.load_gearbox(star).lumped_assumed.carrier_mass_kg < 0.5 * exact.mass  # the planets' estimate


def test_export_writes_the_carriers_solid_and_its_fe_mesh(carrier, tmp_path):
    """``flexgear export-geometry`` on the planetary example: the carrier's STEP (mm) holds its solid (volume x
    density against the exact mass, 1e-9: the STEP's 13 significant digits); its VTU holds the FE model's nodes and
    second-order tetrahedra, and its seat and pins as point sets on their bores' cylinders."""
    import meshio
    from netgen.occ import OCCGeometry

    from flexgear.cli import main
    from flexgear.geometry.solids import occ_mass_properties

    gearbox, sizes, fe, _ = carrier
    assert main(["export-geometry", str(EXAMPLE), "--component", "carrier", "--out", str(tmp_path)]) == 0
    solid = OCCGeometry(str(tmp_path / "carrier.step")).shape.solids[0]
    rho = gearbox.material_assumed.density_kg_m3
    exact = carrier_mass_properties(sizes, rho).mass
    assert occ_mass_properties(solid, rho * 1e-9)[0] == pytest.approx(exact, rel=1e-9)  # mm^3
    vtu = meshio.read(tmp_path / "carrier.vtu")
    np.testing.assert_array_equal(vtu.points, fe.nodes)
    (cells,) = vtu.cells
    assert cells.type == "tetra10" and len(vtu.points) == fe.n_nodes
    seat = np.flatnonzero(vtu.point_data["interface_seat"])
    np.testing.assert_allclose(np.hypot(*fe.nodes[seat, :2].T), sizes.bore_radius, rtol=1e-6)
    for k, centre in enumerate(sizes.pin_centres()):
        pin = np.flatnonzero(vtu.point_data[f"interface_pin_{k}"])
        assert np.array_equal(pin, fe.regions[f"pin_{k}"])
        np.testing.assert_allclose(np.hypot(*(fe.nodes[pin, :2] - centre[:2]).T), sizes.pin_radius, rtol=1e-6)
