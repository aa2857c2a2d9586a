"""Components from the user's own geometry (``[components_geometry]``, flexgear.fe.imported) and the export that
writes them (``flexgear export-geometry``, flexgear.fe.geometry_export), on the study's ring at the coarse level:

- export: STEP in mm, VTU in m with VTK's ``tetra10`` node order and the regions as point data;
- the ring's mesh exported as VTU and imported again gives the built-in FE model exactly (same nodes, K, M,
  interfaces and contact bands, so the same reduced body);
- the ring's solid exported as STEP and imported again (meshed anew by flexgear) gives the built-in reduced body:
  mass within 1e-6, the modes clamped on the bolt patches (as the multibody model holds the ring) below 3x the
  mesh frequency within 0.1 %, the compliance at the contact bands under the contact kernel's loads within 0.5 %;
- every bad file is refused in one line naming the component and the file.
"""

import shutil
from pathlib import Path

import meshio
import numpy as np
import pytest

from flexgear.cli import main
from flexgear.fe.mesh import component_mesh
from flexgear.spec import SpecError, load_gearbox, spec_hash

ROOT = Path(__file__).resolve().parents[1]
GEARBOX = ROOT / "model_variants" / "gearbox.toml"


def _gearbox_with(folder: Path, table: str) -> Path:
    """A copy of the study's gearbox file in ``folder`` with ``table`` appended (its ``[components_geometry]``)."""
    path = folder / "gearbox.toml"
    path.write_text(GEARBOX.read_text() + "\n" + table + "\n")
    return path


def _ring_entry(folder: Path, file: str, unit: str) -> Path:
    return _gearbox_with(folder, f'[components_geometry]\nring = {{ file = "{file}", length_unit = "{unit}" }}')


@pytest.fixture(scope="module")
def exported(tmp_path_factory) -> Path:
    """The folder where ``flexgear export-geometry`` wrote the study ring's ``ring.step`` and ``ring.vtu`` (coarse)."""
    folder = tmp_path_factory.mktemp("export")
    assert main(["export-geometry", str(GEARBOX), "--component", "ring", "--level", "coarse", "--out",
                 str(folder)]) == 0
    return folder


# --------------------------------------------------------------------------- export
def test_export_writes_step_in_mm_and_vtu_in_vtk_order_with_regions(gearbox, exported):
    mesh = component_mesh(gearbox, "ring", "coarse")
    step = (exported / "ring.step").read_text(errors="replace")
    assert "SI_UNIT(.MILLI.,.METRE.)" in step
    vtu = meshio.read(exported / "ring.vtu")
    (cells,) = vtu.cells
    assert cells.type == "tetra10" and len(cells.data) == len(mesh.elements)
    np.testing.assert_array_equal(vtu.points, mesh.nodes)  # metres
    x, el = vtu.points, cells.data
    v = x[el[:, :4]]
    assert (np.einsum("ij,ij->i", v[:, 1] - v[:, 0], np.cross(v[:, 2] - v[:, 0], v[:, 3] - v[:, 0])) > 0).all()
    for k, (a, b) in enumerate(((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3))):  # VTK's edge order
        length = np.linalg.norm(x[el[:, a]] - x[el[:, b]], axis=1)
        off = np.linalg.norm(x[el[:, 4 + k]] - (x[el[:, a]] + x[el[:, b]]) / 2, axis=1)
        assert np.median(off / length) < 1e-3 and (off < 0.25 * length).all()
    for name, nodes in mesh.regions.items():
        assert np.array_equal(np.flatnonzero(vtu.point_data[name]), nodes)
    assert vtu.point_data["interface_bolt_patches"].sum() > 0
    assert vtu.point_data["contact_band_0"].sum() > 0


def test_export_errors_are_one_line(capsys, tmp_path):
    assert main(["export-geometry", str(GEARBOX), "--component", "carrier", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown component 'carrier'" in err
    assert main(["export-geometry", str(GEARBOX), "--level", "fine", "--out", str(tmp_path)]) == 2
    assert "unknown mesh level 'fine'" in capsys.readouterr().err


# --------------------------------------------------------------------------- the table
def test_table_is_checked_on_load_in_one_line(tmp_path):
    cases = {
        'ring = { file = "missing.step", length_unit = "mm" }': "file does not exist",
        'ring = { file = "empty.step", length_unit = "mm" }': "file is empty",
        'ring = { file = "part.step", length_unit = "inch" }': "expected one of 'm', 'mm'",
        'ring = { file = "part.iges", length_unit = "mm" }': "unsupported file type '.iges'",
        'ring = { file = "part.step" }': "components_geometry.ring.length_unit': missing",
        'carrier = { file = "part.step", length_unit = "mm" }': "unknown component",
        'ring = { file = "part.step", length_unit = "mm", scale = 2 }': "unknown field",
    }
    (tmp_path / "empty.step").write_bytes(b"")
    (tmp_path / "part.step").write_text("solid")
    (tmp_path / "part.iges").write_text("solid")
    for entry, message in cases.items():
        path = _gearbox_with(tmp_path, "[components_geometry]\n" + entry)
        with pytest.raises(SpecError) as err:
            load_gearbox(path)
        text = str(err.value)
        assert message in text and str(path) in text and "\n" not in text, text


def test_file_content_enters_the_spec_hash_and_cache_keys(gearbox, tmp_path):
    from flexgear.geometry.layout import geometry_hash

    part = tmp_path / "ring.vtu"
    part.write_text("first")
    spec = load_gearbox(_ring_entry(tmp_path, "ring.vtu", "m"))
    assert spec_hash(gearbox) != spec_hash(spec)
    assert geometry_hash(gearbox, "sun") == geometry_hash(spec, "sun")  # the other components keep their caches
    ring_key, tied_key = geometry_hash(spec, "ring"), geometry_hash(spec, "tied", ("ring", "output_shaft"))
    part.write_text("second")
    changed = load_gearbox(_ring_entry(tmp_path, "ring.vtu", "m"))
    assert spec_hash(changed) != spec_hash(spec)
    assert geometry_hash(changed, "ring") != ring_key
    assert geometry_hash(changed, "tied", ("ring", "output_shaft")) != tied_key
    shutil.move(part, tmp_path / "moved.vtu")  # the content is hashed, not the name
    moved = load_gearbox(_ring_entry(tmp_path, "moved.vtu", "m"))
    assert spec_hash(moved) == spec_hash(changed)
