"""The planet carrier from the user's file (``[components_geometry] carrier``, flexgear.fe.carrier_part), on the spur
planetary example (24/30/84, 3 planets, m 3 mm), coarse mesh, the bodies in the examples' cache:

- round trips of the built-in carrier through ``flexgear export-geometry``: its VTU gives the same FE model (nodes,
  K, M, the seat and pin regions with their area weights); its STEP, meshed again, the same mesh (the built-in carrier
  is meshed in its STEP exchange form, a fixed point of the round trip) and so the same reduced body (mass 1e-6,
  every mode 0.1 %, the pins' compliance with the seat held 0.5 %: the import's rule);
- a carrier the parameters cannot describe (lightening holes in both plates), from STEP: its reduced body against its
  own full FE model with the seat held, every mode below 3x the mesh frequency within 1 % and the pins' compliance
  under their own loads within 2 %; the rigid carrier and the lumped model take its mass; it runs flexible;
- files that cannot serve, each refused in one line.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
from test_rigid_partner import Clamped

import flexgear as fg
from flexgear.fe.carrier import SEAT, carrier_body, carrier_fe_model, carrier_interfaces, pin_interface
from flexgear.fe.cms import rbe3_rows
from flexgear.fe.imported import GeometryFileError
from flexgear.fe.joined import body_matrices, joint_rows
from flexgear.geometry.carrier import carrier_sizes, carrier_solid
from flexgear.spec import SpecError

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary"


def _gearbox(folder: Path, entry: str | None) -> Path:
    """The example's gearbox (and its variants) in ``folder`` with ``[components_geometry] carrier = entry``."""
    folder.mkdir(parents=True, exist_ok=True)
    text = (EXAMPLE / "gearbox.toml").read_text()
    if entry is not None:
        text += f"\n[components_geometry]\ncarrier = {entry}\n"
    (folder / "gearbox.toml").write_text(text)
    rigid = (EXAMPLE / "rigid.toml").read_text()
    (folder / "rigid.toml").write_text(rigid)
    (folder / "carrier.toml").write_text(rigid.replace('name = "rigid"', 'name = "carrier"')
                                         + 'carrier = "flexible"\n')  # the carrier alone flexible
    return folder / "gearbox.toml"


@pytest.fixture(scope="module")
def parts(tmp_path_factory, example_cache):
    """(folder, the built-in gearbox) with the built-in carrier exported to ``folder / "parts"``; bodies in the
    examples' cache (conftest.example_cache: the built-in carrier is the example's)."""
    from flexgear.cli import main

    folder = tmp_path_factory.mktemp("carrier_import")
    assert main(["export-geometry", str(EXAMPLE / "gearbox.toml"), "--component", "carrier",
                 "--out", str(folder / "parts")]) == 0
    return folder, fg.load_gearbox(EXAMPLE / "gearbox.toml")


def _pin_compliance(body, planets: int) -> np.ndarray:
    """The reduced carrier's compliance (6N, 6N) [m/N, rad/(N m)] at its pins' RBE3 motions, the seat held."""
    mass, stiffness = body_matrices(body)
    basis = la.null_space(joint_rows(body, SEAT, body.interface(SEAT).point))
    rows = np.vstack([joint_rows(body, pin_interface(k), body.interface(pin_interface(k)).point)
                      for k in range(planets)]) @ basis
    return rows @ np.linalg.solve(basis.T @ stiffness @ basis, rows.T)


def test_vtu_round_trip_gives_the_same_fe_model(parts):
    folder, builtin = parts
    imported = fg.load_gearbox(_gearbox(folder / "vtu", '{ file = "../parts/carrier.vtu", length_unit = "m" }'))
    fe0, fe = carrier_fe_model(builtin, "coarse"), carrier_fe_model(imported, "coarse")
    np.testing.assert_array_equal(fe.nodes, fe0.nodes)
    assert abs(fe.K - fe0.K).max() <= 1e-12 * abs(fe0.K).max()
    assert abs(fe.mass_scalar - fe0.mass_scalar).max() <= 1e-12 * abs(fe0.mass_scalar).max()
    assert sorted(fe.regions) == sorted(fe0.regions) == sorted([SEAT, *(pin_interface(k) for k in range(3))])
    for name, nodes in fe0.regions.items():
        np.testing.assert_array_equal(fe.regions[name], nodes)
        np.testing.assert_allclose(fe.region_weights[name], fe0.region_weights[name], rtol=1e-12)


def test_step_round_trip_gives_the_same_reduced_body_within_the_import_rule(parts):
    folder, builtin = parts
    imported = fg.load_gearbox(_gearbox(folder / "step", '{ file = "../parts/carrier.step", length_unit = "mm" }'))
    body0, body = carrier_body(builtin, "coarse"), carrier_body(imported, "coarse")
    np.testing.assert_array_equal(body.nodes, body0.nodes)  # meshed again, in the same exchange form
    assert body.props.mass == pytest.approx(body0.props.mass, rel=1e-6)
    elastic0, elastic = (b.frequencies_hz[b.frequencies_hz > 1.0] for b in (body0, body))
    assert elastic.size == elastic0.size >= 20
    np.testing.assert_allclose(elastic, elastic0, rtol=1e-3)
    c0, c = _pin_compliance(body0, 3), _pin_compliance(body, 3)
    np.testing.assert_allclose(np.diag(c), np.diag(c0), rtol=5e-3)


def _lightened(sizes, path: Path) -> None:
    """The carrier of ``sizes`` with lightening holes through both plates (a part its parameters cannot describe):
    three of 10 mm radius at 70 mm between the pins, six of 6 mm radius at 31 mm; written as STEP in mm."""
    from netgen import occ

    solid = carrier_solid(sizes)
    half, t = sizes.gap / 2, sizes.plate_thickness
    holes = [(0.070, math.radians(60 + 120 * k), 0.010) for k in range(3)]
    holes += [(0.031, math.radians(30 + 60 * k), 0.006) for k in range(6)]
    for r, angle, radius in holes:
        for z0 in (-half - t, half):
            solid = solid - occ.Cylinder(occ.Pnt(r * math.cos(angle), r * math.sin(angle), z0), occ.Z, radius, t)
    solid.Scale(occ.Pnt(0, 0, 0), 1000.0).WriteStep(str(path))


def test_a_lightened_carrier_from_step_against_its_full_fe_model(parts, tmp_path):
    from flexgear.cli import main
    from flexgear.design import as_design
    from flexgear.geometry.solids import occ_mass_properties
    from flexgear.results import load_result

    folder, builtin = parts
    sizes = carrier_sizes(builtin)
    (folder / "lightened").mkdir(exist_ok=True)
    _lightened(sizes, folder / "lightened" / "carrier.step")
    gearbox = fg.load_gearbox(_gearbox(folder / "lightened", '{ file = "carrier.step", length_unit = "mm" }'))
    fe = carrier_fe_model(gearbox, "coarse")
    body = carrier_body(gearbox, "coarse", fe=fe)
    from netgen.occ import OCCGeometry

    rho = gearbox.material_assumed.density_kg_m3
    solid_mass = occ_mass_properties(OCCGeometry(str(folder / "lightened" / "carrier.step")).shape.solids[0],
                                     rho * 1e-9)[0]
    assert fe.mass_properties().mass == pytest.approx(solid_mass, rel=1e-4)  # the meshed curved geometry
    holes = 2 * sizes.plate_thickness * math.pi * (3 * 0.010**2 + 6 * 0.006**2)  # through both plates [m^3]
    built_in_mass = as_design(builtin).carrier_disc()[0]
    assert solid_mass == pytest.approx(built_in_mass - rho * holes, rel=1e-6)  # not the built-in carrier
    # the rigid carrier and the lumped model take the part's mass and polar inertia (the file gives neither)
    assert as_design(gearbox).carrier_disc()[0] == pytest.approx(solid_mass, rel=1e-9)
    # the reduced body against its full FE model, the seat held (the rigid interface the reduction holds)
    itfs = {i.name: i for i in carrier_interfaces(fe, sizes)}
    held = Clamped(fe, itfs[SEAT].nodes)
    mass, stiffness = body_matrices(body)
    basis = la.null_space(joint_rows(body, SEAT, body.interface(SEAT).point))
    full = held.frequencies(12)
    band = 3.0 * fg.theory(gearbox).mesh_frequency
    n = int(np.sum(full < band))
    assert 3 <= n < 12, (n, full)
    reduced = np.sqrt(la.eigh(basis.T @ stiffness @ basis, basis.T @ mass @ basis, eigvals_only=True)[:n])
    np.testing.assert_allclose(reduced / (2 * np.pi), full[:n], rtol=0.01)
    loads = sp.vstack([rbe3_rows(fe, itfs[pin_interface(k)]) for k in range(3)]).T.toarray()
    c_full, c_red = held.compliance(loads), _pin_compliance(body, 3)
    assert np.max(np.abs(c_red - c_full)) < 0.02 * np.max(np.abs(c_full))
    # the flexible carrier runs: the stage's ratio and each mesh's forces against the sun's torque
    assert main(["run", str(folder / "lightened" / "carrier.toml"), "--t-end", "0.06", "--out",
                 str(tmp_path)]) == 0
    s = load_result(tmp_path / "carrier").signals
    late = s[s.time_s >= 0.04]
    assert late.transmission_ratio.mean() == pytest.approx(24 / 108, rel=1e-3)
    t_sun = gearbox.load_case.load_torque_nm * 24 / 108
    r_b = 3e-3 * 24 * math.cos(math.radians(20.0)) / 2
    total = late[[f"outer_mesh_force_{i}_n" for i in (1, 2, 3)]].mean().sum()
    assert total == pytest.approx(t_sun / r_b, rel=0.01)


def test_carrier_files_that_cannot_serve_are_refused_in_one_line(parts, tmp_path):
    from netgen import occ

    folder, builtin = parts
    step = folder / "parts" / "carrier.step"
    # a star holds its carrier
    star = _gearbox(tmp_path / "star", f'{{ file = "{step}", length_unit = "mm" }}')
    star.write_text(star.read_text().replace('arrangement = "planetary"', 'arrangement = "star"'))
    with pytest.raises(SpecError, match="components_geometry.carrier.*arrangement") as err:
        fg.load_gearbox(star)
    assert "\n" not in str(err.value)
    cases = {
        "unit": (f'{{ file = "{step}", length_unit = "m" }}', "length unit"),
        "selector": (f'{{ file = "{step}", length_unit = "mm", regions = {{ pin_1 = {{ cylinder = '
                     '{ radius_mm = 5.0, axis_mm = [0.0, 0.0] } } } }', "selector regions.pin_1"),
    }
    turned = tmp_path / "turned.step"  # the part turned by 30 degrees: no pin bore at the gear data's positions
    carrier_solid(carrier_sizes(builtin)).Rotate(occ.Axis(occ.Pnt(0, 0, 0), occ.Z), 30).Scale(
        occ.Pnt(0, 0, 0), 1000.0).WriteStep(str(turned))
    cases["turned"] = (f'{{ file = "{turned}", length_unit = "mm" }}', "do not ring it")
    for name, (entry, words) in cases.items():
        gearbox = fg.load_gearbox(_gearbox(tmp_path / name, entry))
        with pytest.raises(GeometryFileError) as err:
            carrier_fe_model(gearbox, "coarse")
        msg = str(err.value)
        assert "\n" not in msg and "[components_geometry] carrier" in msg and words in msg, (name, msg)
