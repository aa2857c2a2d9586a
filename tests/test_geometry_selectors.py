"""Named selectors of an imported part's regions (``[components_geometry] <component>.regions``,
flexgear.schema_geometry, flexgear.fe.selectors), on the study's sun and output shaft at the coarse level, their
built-in meshes written as files and imported again:

- a cylinder at the sun's bore selects the built-in rule's bore (same nodes, same coordinates), in m or in mm;
- a Gmsh physical group written with the mesh selects exactly the group's boundary nodes, and so does an Abaqus
  node set;
- the output shaft's bolt holes given as a point set are split into its twelve holes as the built-in rule numbers
  them; one hole by an off-axis cylinder is that hole;
- the output shaft's clamped discs selected from a node set are its bolt patches, and carry the reduction that
  another clamp diameter gives;
- a selector that finds nothing, or nodes on more than one surface (round the bore's edge onto the end face, the
  tips of every tooth), is refused in one line naming the component, the file and the selector;
- a bad table is refused on load in one line naming the file and the field (a physical group of a STEP file);
- the selectors enter the spec hash and the component's cache keys.
"""

import dataclasses
from pathlib import Path

import meshio
import numpy as np
import pytest

from flexgear.design import as_design
from flexgear.fe.imported import GeometryFileError
from flexgear.fe.mesh import component_mesh
from flexgear.fe.mesh_io import NETGEN_TO_VTK, write_vtu
from flexgear.geometry.layout import geometry_hash
from flexgear.spec import SpecError, load_gearbox, spec_hash

ROOT = Path(__file__).resolve().parents[1]
GEARBOX = ROOT / "model_variants" / "gearbox.toml"
_TRIANGLE6 = [0, 1, 2, 5, 3, 4]
"""A Netgen second-order triangle (vertices, then the nodes of edges 12, 02, 01) in VTK's order (edges 01, 12, 20)."""


def _gearbox(folder: Path, component: str, file: str, unit: str, regions: str = "") -> Path:
    """A copy of the study's gearbox file in ``folder`` whose ``component`` is ``file`` with ``regions`` (TOML)."""
    extra = f", regions = {{ {regions} }}" if regions else ""
    path = folder / "gearbox.toml"
    path.write_text(GEARBOX.read_text() + f'\n[components_geometry]\n{component} = {{ file = "{file}", '
                    f'length_unit = "{unit}"{extra} }}\n')
    return path


def _imported(folder: Path, component: str, file: str, unit: str, regions: str = ""):
    """The coarse mesh (the level's order) of ``component`` imported from ``file`` with ``regions``."""
    return component_mesh(load_gearbox(_gearbox(folder, component, file, unit, regions)), component, "coarse")


def _refused(folder: Path, component: str, file: str, unit: str, regions: str, *words: str) -> str:
    with pytest.raises(GeometryFileError) as err:
        _imported(folder, component, file, unit, regions)
    text = str(err.value)
    assert "\n" not in text and f"] {component}: " in text and str(folder / file) in text, text
    assert all(w in text for w in words), text
    return text


@pytest.fixture(scope="module")
def parts(gearbox, tmp_path_factory):
    """A folder with the study's coarse sun and output shaft (second order, the level's) as ``<name>.vtu`` in m."""
    folder = tmp_path_factory.mktemp("parts")
    for name in ("sun", "output_shaft"):
        mesh = component_mesh(gearbox, name, "coarse")
        write_vtu(folder / f"{name}.vtu", mesh.nodes, mesh.elements)
    return folder


def _bore(gearbox) -> tuple[float, float, float]:
    """The sun's bore radius and axial extent [m] from the gear data."""
    layout = as_design(gearbox).layouts["sun"]
    return layout.prisms[0].section.inner, *layout.z_range


def _copy(parts: Path, folder: Path, name: str) -> str:
    (folder / name).write_bytes((parts / name).read_bytes())
    return name


# --------------------------------------------------------------------------- what they select
def test_cylinder_selects_the_built_in_bore(gearbox, parts, tmp_path):
    radius, z0, z1 = _bore(gearbox)
    reference = component_mesh(gearbox, "sun", "coarse")
    file = _copy(parts, tmp_path, "sun.vtu")
    mesh = _imported(tmp_path, "sun", file, "m", f"bore = {{ cylinder = {{ radius_m = {radius!r}, z_m = [{z0!r}, "
                     f"{z1!r}] }} }}")
    np.testing.assert_array_equal(mesh.regions["bore"], reference.regions["bore"])
    np.testing.assert_array_equal(mesh.nodes[mesh.regions["bore"]], reference.nodes[reference.regions["bore"]])
    bore = mesh.nodes[mesh.regions["bore"]]
    assert len(bore) == 440 and np.abs(np.hypot(bore[:, 0], bore[:, 1]) - radius).max() < 1e-6
    assert np.isclose(bore[:, 2].min(), z0) and np.isclose(bore[:, 2].max(), z1)
    np.testing.assert_array_equal(mesh.regions["flanks"], reference.regions["flanks"])  # not named: built-in
    # the same part in mm, the selector in mm: the same nodes
    meshio.write(tmp_path / "sun.msh", meshio.Mesh(mesh.nodes * 1e3, meshio.read(tmp_path / file).cells),
                 file_format="gmsh")
    in_mm = _imported(tmp_path, "sun", "sun.msh", "mm", f"bore = {{ cylinder = {{ radius_mm = {radius * 1e3!r}, "
                      f"z_mm = [{z0 * 1e3!r}, {z1 * 1e3!r}], tolerance_mm = 0.001 }} }}")
    np.testing.assert_array_equal(in_mm.regions["bore"], reference.regions["bore"])


def _bore_faces(mesh) -> np.ndarray:
    """The boundary triangles (6 nodes, Netgen order) of the built-in bore."""
    on = np.zeros(mesh.n_nodes, bool)
    on[mesh.regions["bore"]] = True
    return mesh.surface[on[mesh.surface[:, :3]].all(axis=1)]


def test_physical_group_selects_the_groups_boundary_nodes(gearbox, tmp_path):
    """A Gmsh file with the bore's triangles as physical group "inner": the group's nodes, which are the bore's."""
    mesh = component_mesh(gearbox, "sun", "coarse")
    faces = _bore_faces(mesh)
    cells = [("tetra10", mesh.elements[:, NETGEN_TO_VTK[10]]), ("triangle6", faces[:, _TRIANGLE6])]
    tags = [np.full(len(mesh.elements), 1), np.full(len(faces), 2)]
    meshio.write(tmp_path / "sun.msh", meshio.Mesh(mesh.nodes * 1e3, cells, cell_data={
        "gmsh:physical": tags, "gmsh:geometrical": tags}, field_data={"body": np.array([1, 3]),
                                                                       "inner": np.array([2, 2])}),
                 file_format="gmsh22", binary=False)
    got = _imported(tmp_path, "sun", "sun.msh", "mm", 'bore = { physical_group = "inner" }')
    np.testing.assert_array_equal(got.regions["bore"], np.unique(faces))
    np.testing.assert_array_equal(got.regions["bore"], mesh.regions["bore"])
    _refused(tmp_path, "sun", "sun.msh", "mm", 'bore = { physical_group = "hub" }', "regions.bore",
             "physical_group 'hub'", "no group of that name", "body, inner")
    # an Abaqus node set: its nodes on the boundary
    meshio.write(tmp_path / "sun.inp", meshio.Mesh(mesh.nodes, [cells[0]], point_sets={
        "BORE": mesh.regions["bore"]}), file_format="abaqus")
    got = _imported(tmp_path, "sun", "sun.inp", "m", 'bore = { physical_group = "BORE" }')
    np.testing.assert_array_equal(got.regions["bore"], mesh.regions["bore"])


def test_bolt_holes_as_points_and_one_hole_as_a_cylinder(gearbox, parts, tmp_path):
    reference = component_mesh(gearbox, "output_shaft", "coarse")
    file = _copy(parts, tmp_path, "output_shaft.vtu")
    at = ", ".join(f"[{x!r}, {y!r}, {z!r}]" for x, y, z in reference.nodes[reference.regions["bolt_holes"]].tolist())
    mesh = _imported(tmp_path, "output_shaft", file, "m", f"bolt_holes = {{ points = {{ at_m = [{at}], "
                     "tolerance_m = 1e-9 } }")
    holes = sorted(k for k in reference.regions if k.startswith("bolt_hole"))
    assert len(holes) == 13 and sorted(k for k in mesh.regions if k.startswith("bolt_hole")) == holes
    for name in holes:
        np.testing.assert_array_equal(mesh.regions[name], reference.regions[name])
    web = as_design(gearbox).layouts["output_shaft"].prisms[0]
    angle = 2 * np.pi * 3 / web.section.holes
    centre = (web.section.hole_circle_radius * np.array([np.cos(angle), np.sin(angle)])).tolist()
    mesh = _imported(tmp_path, "output_shaft", file, "m", f"bolt_hole_3 = {{ cylinder = {{ radius_m = "
                     f"{web.section.hole_radius!r}, axis_m = [{centre[0]!r}, {centre[1]!r}] }} }}")
    np.testing.assert_array_equal(mesh.regions["bolt_hole_3"], reference.regions["bolt_hole_3"])
    np.testing.assert_array_equal(mesh.regions["bolt_holes"], reference.regions["bolt_holes"])


# --------------------------------------------------------------------------- refused
def test_a_selector_that_finds_nothing_is_refused_in_one_line(gearbox, parts, tmp_path):
    radius, _, _ = _bore(gearbox)
    file = _copy(parts, tmp_path, "sun.vtu")
    _refused(tmp_path, "sun", file, "m", f"bore = {{ cylinder = {{ radius_m = {radius!r}, z_m = [0.5, 0.6] }} }}",
             "selector regions.bore (cylinder r = 25 mm, z 500..600 mm", "finds no boundary node")
    _refused(tmp_path, "sun", file, "m", "bore = { points = { at_m = [[0.025, 0.0, 0.0], [0.0, 0.0, 0.0]] } }",
             "regions.bore (points: 2", "point 1 (0, 0, 0) mm finds no boundary node")


def test_a_selector_on_more_than_one_surface_is_refused(gearbox, parts, tmp_path):
    radius, _, _ = _bore(gearbox)
    file = _copy(parts, tmp_path, "sun.vtu")
    # 12 mm either side of the bore: the end faces' triangles next to it too, at a right angle to it
    _refused(tmp_path, "sun", file, "m", f"bore = {{ cylinder = {{ radius_m = {radius!r}, tolerance_m = 0.012 }} }}",
             "regions.bore (cylinder r = 25 mm, tolerance 12 mm)", "more than one surface: its faces turn by 9",
             "round the edge at")
    tip = as_design(gearbox).layouts["sun"].gear.tip_radius  # the tips of every tooth: separate lands
    text = _refused(tmp_path, "sun", file, "m", f"bore = {{ cylinder = {{ radius_m = {tip!r} }} }}",
                    "separate surfaces; expected 1")
    assert int(text.split("finds nodes on ")[1].split()[0]) >= gearbox.gears.sun_teeth
    # three bore nodes, not a surface
    mesh = component_mesh(gearbox, "sun", "coarse")
    at = ", ".join(f"[{x!r}, {y!r}, {z!r}]" for x, y, z in mesh.nodes[mesh.regions["bore"][:3]].tolist())
    _refused(tmp_path, "sun", file, "m", f"bore = {{ points = {{ at_m = [{at}], tolerance_m = 1e-9 }} }}",
             "finds 3 boundary nodes but no whole boundary face")


def test_bad_selector_tables_are_refused_on_load_in_one_line(tmp_path):
    (tmp_path / "part.step").write_text("solid")
    (tmp_path / "part.vtu").write_text("mesh")
    cylinder = "cylinder = { radius_mm = 25.0 }"
    cases = {
        ("part.step", "mm", 'bore = { physical_group = "bore" }'): "part.step carries no named groups",
        ("part.vtu", "m", 'bore = { physical_group = "bore" }'): "part.vtu carries no named groups",
        ("part.step", "mm", f"hub = {{ {cylinder} }}"): "unknown region of the sun; allowed: bore, flanks",
        ("part.step", "m", f"bore = {{ {cylinder} }}"): "regions.bore.cylinder.radius_mm': unknown field; "
                                                        "allowed: radius_m, z_m, tolerance_m, axis_m",
        ("part.step", "mm", "bore = { cylinder = { radius_mm = -1.0 } }"): "radius_mm': expected > 0",
        ("part.step", "mm", "bore = { cylinder = { radius_mm = 25.0, z_mm = [5.0, 1.0] } }"): "z_min < z_max",
        ("part.step", "mm", f'bore = {{ {cylinder}, physical_group = "a" }}'): "expected one selector",
        ("part.step", "mm", "bore = { points = { at_mm = [[1.0, 2.0]] } }"): "at_mm[0]': expected a point",
    }
    for (file, unit, regions), message in cases.items():
        path = _gearbox(tmp_path, "sun", file, unit, regions)
        with pytest.raises(SpecError) as err:
            load_gearbox(path)
        text = str(err.value)
        assert message in text and str(path) in text and "components_geometry.sun.regions" in text, text
        assert "\n" not in text, text
    both = f"bolt_holes = {{ {cylinder} }}, bolt_hole_2 = {{ {cylinder} }}"
    path = _gearbox(tmp_path, "ring", "part.step", "mm", both)
    with pytest.raises(SpecError, match="bolt_holes .* or bolt_hole_<k>, not both"):
        load_gearbox(path)


def test_selectors_enter_the_spec_hash_and_cache_keys(gearbox, tmp_path):
    (tmp_path / "sun.vtu").write_text("mesh")

    def spec(regions: str):
        return load_gearbox(_gearbox(tmp_path, "sun", "sun.vtu", "m", regions))

    plain, bore, wider, again = (spec(""), spec("bore = { cylinder = { radius_m = 0.025 } }"),
                                 spec("bore = { cylinder = { radius_m = 0.025, tolerance_m = 1e-5 } }"),
                                 spec("bore = { cylinder = { radius_m = 0.025 } }"))
    keys = [geometry_hash(s, "sun") for s in (plain, bore, wider)]
    assert len(set(keys)) == 3 and len({spec_hash(s) for s in (plain, bore, wider)}) == 3
    assert geometry_hash(again, "sun") == keys[1] and spec_hash(again) == spec_hash(bore)
    assert geometry_hash(bore, "ring") == geometry_hash(plain, "ring") == geometry_hash(gearbox, "ring")


# --------------------------------------------------------------------------- what the reduction stands on
def test_a_selected_bore_carries_the_reduction_of_a_part_the_gear_data_do_not_describe(tmp_path):
    """A sun whose bore (40 mm) is not the gearbox file's (50 mm): imported without a selector it is refused (the
    built-in bore finds no surface); with a cylinder selector at its bore, its reduced body is the one the gear data
    of a 40 mm bore give: the same modes (the free-free frequencies of the reduced and of the full FE model within
    1e-9) on the same bore interface (its nodes at 20 mm)."""
    from flexgear.fe.reduced import component_reduced_body

    study = load_gearbox(GEARBOX)
    other = study.with_fields("components_assumed", sun_bore_diameter_mm=40.0)
    mesh = component_mesh(other, "sun", "coarse")
    write_vtu(tmp_path / "sun40.vtu", mesh.nodes, mesh.elements)
    _refused(tmp_path, "sun", "sun40.vtu", "m", "", "bore")
    _, z0, z1 = _bore(study)
    selector = f"bore = {{ cylinder = {{ radius_m = 0.020, z_m = [{z0}, {z1}] }} }}"
    imported = component_reduced_body(load_gearbox(_gearbox(tmp_path, "sun", "sun40.vtu", "m", selector)), "sun")
    built_in = component_reduced_body(other, "sun")
    bore = next(i for i in imported.interfaces if i.name == "bore")
    reference = next(i for i in built_in.interfaces if i.name == "bore")
    assert len(bore.nodes) == len(reference.nodes) > 0
    np.testing.assert_allclose(np.hypot(*imported.nodes[bore.nodes][:, :2].T), 0.020, atol=1e-6)
    np.testing.assert_allclose(imported.frequencies_hz, built_in.frequencies_hz, rtol=1e-9)
    np.testing.assert_allclose(imported.full_frequencies_hz, built_in.full_frequencies_hz, rtol=1e-9)


def test_selected_bolt_discs_carry_the_reduction_of_another_clamp_diameter(gearbox, tmp_path):
    """The study's output shaft in an Abaqus file with node sets of its web face: "DISCS27", the clamped discs that a
    27 mm clamp diameter gives (the gearbox file says 21 mm). Selected as ``bolt_discs``, they are the shaft's bolt
    patches, and its reduced body is the one the gear data with a 27 mm clamp diameter give (the same free-free
    frequencies, reduced and full FE, within 1e-9); the wider discs hold the shaft more stiffly than the file's
    21 mm ones (its lowest mode with the patches held is higher). A set that also takes the hole walls is refused
    (two surfaces), as is one that misses a bolt."""
    from flexgear.fe.bolted import clamped_patches
    from flexgear.fe.reduced import component_reduced_body

    wide = gearbox.with_fields("joints_assumed", bolt_clamp_diameter_mm=27.0)
    mesh = component_mesh(gearbox, "output_shaft", "coarse")
    discs = clamped_patches(mesh, wide)
    walls = mesh.regions["bolt_holes"]
    cells = [("tetra10", mesh.elements[:, NETGEN_TO_VTK[10]])]
    sets = {"DISCS27": np.concatenate(discs), "WITH_WALLS": np.union1d(np.concatenate(discs), walls),
            "ELEVEN": np.concatenate(discs[1:])}
    meshio.write(tmp_path / "shaft.inp", meshio.Mesh(mesh.nodes, cells, point_sets=sets), file_format="abaqus")
    spec = load_gearbox(_gearbox(tmp_path, "output_shaft", "shaft.inp", "m", 'bolt_discs = { physical_group = '
                                 '"DISCS27" }'))
    imported = component_reduced_body(spec, "output_shaft")
    built_in = component_reduced_body(wide, "output_shaft")
    patches = next(i for i in imported.interfaces if i.name == "bolt_patches")
    np.testing.assert_array_equal(patches.nodes, np.sort(np.concatenate(discs)))
    np.testing.assert_allclose(imported.frequencies_hz, built_in.frequencies_hz, rtol=1e-9)
    np.testing.assert_allclose(imported.full_frequencies_hz, built_in.full_frequencies_hz, rtol=1e-9)
    assert _held_lowest_hz(imported) > _held_lowest_hz(component_reduced_body(gearbox, "output_shaft"))
    _refused(tmp_path, "output_shaft", "shaft.inp", "m", 'bolt_discs = { physical_group = "WITH_WALLS" }',
             "regions.bolt_discs", "more than one surface")
    _refused(tmp_path, "output_shaft", "shaft.inp", "m", 'bolt_discs = { physical_group = "ELEVEN" }',
             "regions.bolt_discs", "11 separate surfaces; expected 12")


def _held_lowest_hz(body) -> float:
    """The lowest frequency [Hz] of a reduced body with its bolt patches held (flexgear.fe.joined)."""
    import scipy.linalg as la

    from flexgear.fe.joined import body_matrices, joint_rows

    mass, stiffness = body_matrices(body)
    basis = la.null_space(joint_rows(body, "bolt_patches", body.interface("bolt_patches").point))
    return float(np.sqrt(la.eigh(basis.T @ stiffness @ basis, basis.T @ mass @ basis, eigvals_only=True)[0])
                 / (2 * np.pi))


# --------------------------------------------------------------------------- the contact band
def test_a_contact_band_selector_places_the_loads_and_the_sensing(gearbox, parts, tmp_path):
    """``regions.contact_band`` of an imported gear: a cylinder at the gear data's band (operating pitch radius,
    one normal module, the helix halves) gives the gear data's load circles and contact sensing exactly; moved half
    a module towards the root it loads and senses the teeth there, which yield less (the static compliance under
    the contact kernel's loads, bore held, is smaller on every contact); a band that misses the mesh, or that is not a
    cylinder, is refused in one line."""
    import flexgear as fg
    from flexgear.fe.reduced import component_contacts, component_load_circles, component_reduced_body
    from flexgear.mbs.train import contact_sensing_rows

    d = as_design(gearbox)
    r_p = d.meshes["outer"].mesh.operating_pitch_radii[0]
    m = gearbox.gears.normal_module_m
    order = gearbox.reduction_assumed.contact_fourier_order
    file = _copy(parts, tmp_path, "sun.vtu")
    specs = {}
    for label, radius in (("data", r_p), ("root", r_p - 0.5 * m)):
        folder = tmp_path / label
        folder.mkdir()
        _copy(parts, folder, "sun.vtu")
        specs[label] = load_gearbox(_gearbox(folder, "sun", file, "m", f"contact_band = {{ cylinder = {{ "
                                                                       f"radius_m = {radius!r} }} }}"))
    plain = component_load_circles(gearbox, "sun", order)
    same = component_load_circles(specs["data"], "sun", order)
    assert [(c.radius_m, c.z_min_m, c.z_max_m, c.radial_band_m) for c in same] == [
        (c.radius_m, c.z_min_m, c.z_max_m, c.radial_band_m) for c in plain]
    root = component_load_circles(specs["root"], "sun", order)
    assert all(abs(c.radius_m - (r_p - 0.5 * m)) < 1e-12 for c in root)
    bodies = {label: component_reduced_body(spec, "sun", "coarse") for label, spec in specs.items()}
    contacts = fg.mesh_contacts(gearbox)
    for label, spec in specs.items():  # the sensing follows the band the reduction loads
        band = next(s for s in spec.components_geometry["sun"].regions if s.region == "contact_band")
        rows = contact_sensing_rows(bodies[label], "sun", np.zeros(3), contacts, order, m, band)
        plain_rows = contact_sensing_rows(bodies[label], "sun", np.zeros(3), contacts, order, m)
        same_span = np.linalg.svd(rows @ plain_rows.T, compute_uv=False).min() > 1 - 1e-9
        assert same_span == (label == "data"), label
    compliance = {}
    for label, spec in specs.items():
        points, normals = component_contacts(spec, "sun")
        compliance[label] = np.diag(fg.static_compliance(bodies[label], points, normals, "bore",
                                                         kernel=component_load_circles(spec, "sun", order)))
    assert np.all(compliance["root"] < compliance["data"]), (compliance["root"], compliance["data"])
    # the multibody model's flexible sun takes the band: its contact columns are those of the moved band
    import exudyn as exu

    from flexgear.mbs.assemble import build_gearbox
    from flexgear.spec import load_variant

    base = load_variant(ROOT / "model_variants" / "model1.toml")
    columns = {}
    for label, spec in specs.items():
        variant = dataclasses.replace(base, gearbox=spec, rigid_mass_properties="exact",
                                      components={**base.components, "sun": "flexible"})
        sc = exu.SystemContainer()
        model = build_gearbox(sc.AddSystem(), variant)
        assert model.bodies["sun"].contact_band.region == "contact_band"
        kin = model.kinematics
        columns[label] = kin.tables[[b == "sun" for b in kin.bodies]]
        sc.Reset()
    assert not np.allclose(columns["root"], columns["data"])
    _refused(tmp_path, "sun", file, "m", "contact_band = { cylinder = { radius_m = 0.5 } }", "contact_band",
             "finds no node")
    with pytest.raises(SpecError) as err:
        load_gearbox(_gearbox(tmp_path, "sun", file, "m", "contact_band = { points = { at_m = [[0.05, 0.0, 0.0]] } }"))
    assert err.value.field == "components_geometry.sun.regions.contact_band" and "cylinder" in str(err.value)
