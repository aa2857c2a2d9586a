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

import pytest

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
