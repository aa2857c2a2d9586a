"""``[components_geometry]``: a component's solid or volume mesh from a file instead of its built-in layout.

    [components_geometry]
    ring = { file = "parts/ring.step", length_unit = "mm" }

One entry per component of the geometry (sun, planet, ring, input_shaft, output_shaft), the path relative to the
gearbox file. Read when the gearbox is loaded: the file must exist and not be empty, and its SHA-256 is taken
then, so that its content (not its name or place) enters the spec hash and every cache key of the component
(flexgear.geometry.layout.geometry_hash): a changed file rebuilds its mesh and reduced body. What the file holds
(a solid, tetrahedra, teeth that match the gear data, the regions the reduction needs) is checked when the
component is meshed (flexgear.fe.imported).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from flexgear.schema_fields import SpecError

__all__ = ["ComponentGeometry", "GEOMETRY_FORMATS", "LENGTH_UNITS", "components_geometry_table"]

GEOMETRY_FORMATS = {".step": "step", ".stp": "step", ".brep": "brep", ".brp": "brep", ".vtu": "mesh",
                    ".msh": "mesh", ".inp": "mesh"}
"""File suffix (lower case) -> kind: an OCC solid (STEP, BREP), meshed by flexgear, or a volume mesh (meshio)."""
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}
"""Length unit of a file's coordinates -> metres per unit."""
_COMPONENTS = ("sun", "planet", "ring", "input_shaft", "output_shaft")


@dataclass(frozen=True)
class ComponentGeometry:
    """A component's geometry from a file: ``source`` the file (resolved; not hashed), ``length_unit`` of its
    coordinates ("m" or "mm"; a STEP file is read in millimetres, as flexgear writes it), ``kind`` "step", "brep"
    or "mesh" (from its suffix), ``sha256`` of its content when the gearbox was loaded."""

    source: Path
    length_unit: str
    kind: str
    sha256: str

    @property
    def scale(self) -> float:
        """Metres per unit of the file's coordinates."""
        return LENGTH_UNITS[self.length_unit]


def components_geometry_table(path: Path, raw: Any) -> dict[str, ComponentGeometry]:
    """The ``[components_geometry]`` table of the gearbox file ``path`` ({} when absent), each entry checked:
    a known component, ``file`` an existing non-empty file of a supported kind, ``length_unit`` "m" or "mm".
    Every error is one SpecError line naming the file, the field and what is allowed."""
    name = "components_geometry"
    if not isinstance(raw, dict):
        raise SpecError(path, name, 'expected a table, e.g. ring = { file = "parts/ring.step", length_unit = "mm" }')
    out = {}
    for component, entry in raw.items():
        field = f"{name}.{component}"
        if component not in _COMPONENTS:
            raise SpecError(path, field, f"unknown component; allowed: {', '.join(_COMPONENTS)}")
        if not isinstance(entry, dict):
            raise SpecError(path, field, 'expected a table { file = "...", length_unit = "mm" }', entry)
        unknown = sorted(set(entry) - {"file", "length_unit"})
        if unknown:
            raise SpecError(path, f"{field}.{unknown[0]}", "unknown field; allowed: file, length_unit")
        for key in ("file", "length_unit"):
            if key not in entry:
                raise SpecError(path, f"{field}.{key}", "missing (required)")
        unit = entry["length_unit"]
        if unit not in LENGTH_UNITS:
            raise SpecError(path, f"{field}.length_unit", f"expected one of {', '.join(map(repr, LENGTH_UNITS))}",
                            unit)
        file = _existing_file(path, f"{field}.file", entry["file"])
        kind = _kind(path, f"{field}.file", entry["file"])
        out[component] = ComponentGeometry(file, unit, kind, _digest(path, f"{field}.file", file))
    return out


def _existing_file(path: Path, field: str, value: Any) -> Path:
    if not isinstance(value, str) or not value:
        raise SpecError(path, field, "expected a path (string) relative to the gearbox file", value)
    file = (Path(path).parent / value).resolve()
    if not file.exists():
        raise SpecError(path, field, f"file does not exist ({file})", value)
    if not file.is_file():
        raise SpecError(path, field, f"is not a file ({file})", value)
    if file.stat().st_size == 0:
        raise SpecError(path, field, f"file is empty ({file})", value)
    return file


def _kind(path: Path, field: str, value: str) -> str:
    suffix = Path(value).suffix.lower()
    if suffix not in GEOMETRY_FORMATS:
        raise SpecError(path, field, f"unsupported file type {suffix or '(none)'!r}; allowed: "
                        f"{', '.join(GEOMETRY_FORMATS)} (a solid, or a volume mesh of tetrahedra)", value)
    return GEOMETRY_FORMATS[suffix]


def _digest(path: Path, field: str, file: Path) -> str:
    """SHA-256 (hex) of the content of ``file``."""
    digest = hashlib.sha256()
    try:
        with open(file, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                digest.update(block)
    except OSError as exc:
        raise SpecError(path, field, f"cannot be read ({exc.__class__.__name__})") from None
    return digest.hexdigest()
