"""``[components_geometry]``: a component's solid or volume mesh from a file instead of its built-in layout.

    [components_geometry]
    ring = { file = "parts/ring.step", length_unit = "mm" }
    sun = { file = "parts/sun.msh", length_unit = "mm", regions = { bore = { physical_group = "bore" } } }

One entry per component of the geometry (sun, planet, ring, input_shaft, output_shaft, and a planetary stage's
carrier), the path relative to the gearbox file. Read when the gearbox is loaded: the file must exist and not be
empty, and its SHA-256 is taken then, so that its content (not its name or place) enters the spec hash and every
cache key of the component (flexgear.geometry.layout.geometry_hash): a changed file rebuilds its mesh and reduced
body. What the file holds (a solid, tetrahedra, teeth that match the gear data, the regions the reduction needs) is
checked when the component is meshed (flexgear.fe.imported).

``regions`` (optional) names where the part's interface regions are, one selector per region
(:class:`RegionSelector`; the regions of each component: :data:`SELECTABLE_REGIONS`); a region not named keeps its
built-in rule, which follows the gear data (flexgear.fe.mesh.region_nodes). Lengths are in the file's
``length_unit`` and its frame, the key's suffix saying which (``radius_mm`` for a file in mm, ``radius_m`` in m):

- ``cylinder = { radius_mm = 25.0, z_mm = [-19.0, 19.0], tolerance_mm = 0.001, axis_mm = [0.0, 0.0] }``: the
  boundary nodes within the tolerance of the cylinder of that radius about the axis parallel to z through
  ``axis`` (default the z axis), inside the axial range (default: all of it); tolerance default 1e-6 m;
- ``points = { at_mm = [[25.0, 0.0, 0.0], ...], tolerance_mm = 0.5 }``: the boundary nodes within the tolerance
  of any of the points (a point set, as a pre-processor lists a surface's nodes); tolerance default 1e-3 m;
- ``physical_group = "bore"``: the boundary nodes of the mesh file's physical group (Gmsh ``.msh``) or element or
  node set (Abaqus ``.inp``) of that name; refused for a solid or a ``.vtu``, which carry no named groups.

The selectors are part of the entry, so they enter the spec hash and the component's cache keys as its file does.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from flexgear.schema_fields import SpecError

__all__ = ["CONTACT_BAND", "ComponentGeometry", "GEOMETRY_FORMATS", "LENGTH_UNITS", "RegionSelector",
           "SELECTABLE_REGIONS", "SELECTOR_KINDS", "components_geometry_table"]

GEOMETRY_FORMATS = {".step": "step", ".stp": "step", ".brep": "brep", ".brp": "brep", ".vtu": "mesh",
                    ".msh": "mesh", ".inp": "mesh"}
"""File suffix (lower case) -> kind: an OCC solid (STEP, BREP), meshed by flexgear, or a volume mesh (meshio)."""
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}
"""Length unit of a file's coordinates -> metres per unit."""
_COMPONENTS = ("sun", "planet", "ring", "input_shaft", "output_shaft", "carrier")
SELECTABLE_REGIONS = {"sun": ("bore", "flanks", "contact_band"), "planet": ("bore", "flanks", "contact_band"),
                      "ring": ("flanks", "bolt_holes", "bolt_hole_<k>", "bolt_discs", "contact_band"),
                      "input_shaft": ("bearing_seat", "gear_seat"),
                      "output_shaft": ("bearing_seat", "bolt_holes", "bolt_hole_<k>", "bolt_discs"),
                      "carrier": ("seat", "pin_<k>")}
"""Component -> the mesh regions its reduction's interfaces and contact bands stand on (``bolt_hole_<k>``: the
k-th bolt hole alone, k = 0, 1, ...; ``bolt_discs``: the bolts' clamped discs on the flange or web face, one patch
per bolt, in place of the discs the bolt circle and ``bolt_clamp_diameter_mm`` give, flexgear.fe.bolted; ``seat``
and ``pin_<k>``: a planetary stage's carrier's bore on the output shaft and planet k's pin bores,
flexgear.fe.carrier_part; ``contact_band``: a gear's contact band, a cylinder only: ``radius`` the circle the mesh
loads act on and its modes are sensed at, ``tolerance`` the band's radial half-width (default: the gear data's, one
normal module), ``z`` its axial range (each helix half's band is cut to it; default: the gear data's halves), in
place of the operating pitch circle and the helix halves, flexgear.fe.reduced.contact_band_override)."""
CONTACT_BAND = "contact_band"
"""The selectable region that is a gear's contact band (a circle band for the reduction's loads and the contacts'
mode sensing), not a set of boundary nodes."""
SELECTOR_KINDS = ("cylinder", "points", "physical_group")
"""The kinds of a region selector (module docstring)."""
_GROUP_SUFFIXES = (".msh", ".inp")
"""Mesh files whose named groups meshio reads (Gmsh physical groups, Abaqus element and node sets)."""


@dataclass(frozen=True)
class RegionSelector:
    """Where region ``region`` of an imported part is (module docstring), in the part's frame, SI units: ``kind``
    one of :data:`SELECTOR_KINDS`; a cylinder's ``radius`` [m], ``z_range`` (z_min, z_max) [m] or None (all of
    it) and ``axis`` (x, y) [m] of its axis; ``points`` ((x, y, z), ...) [m]; ``tolerance`` [m]; ``group`` the
    name of a mesh file's physical group."""

    region: str
    kind: str
    radius: float = 0.0
    z_range: tuple[float, float] | None = None
    axis: tuple[float, float] = (0.0, 0.0)
    points: tuple[tuple[float, float, float], ...] = ()
    tolerance: float = 0.0
    group: str = ""

    def describe(self) -> str:
        """The selector in one line, lengths in mm: ``regions.bore (cylinder r = 25 mm, z 0..38 mm)``."""
        mm = 1e3
        if self.kind == "cylinder":
            z = "" if self.z_range is None else f", z {self.z_range[0] * mm:g}..{self.z_range[1] * mm:g} mm"
            axis = "" if self.axis == (0.0, 0.0) else f", axis at ({self.axis[0] * mm:g}, {self.axis[1] * mm:g}) mm"
            what = f"cylinder r = {self.radius * mm:g} mm{z}{axis}, tolerance {self.tolerance * mm:g} mm"
        elif self.kind == "points":
            what = f"points: {len(self.points)}, tolerance {self.tolerance * mm:g} mm"
        else:
            what = f"physical_group {self.group!r}"
        return f"regions.{self.region} ({what})"


@dataclass(frozen=True)
class ComponentGeometry:
    """A component's geometry from a file: ``source`` the file (resolved; not hashed), ``length_unit`` of its
    coordinates ("m" or "mm"; a STEP file is read in millimetres, as flexgear writes it), ``kind`` "step", "brep"
    or "mesh" (from its suffix), ``sha256`` of its content when the gearbox was loaded, ``regions`` the selectors
    of its named regions (:class:`RegionSelector`, by region name; the others follow the built-in rules)."""

    source: Path
    length_unit: str
    kind: str
    sha256: str
    regions: tuple[RegionSelector, ...] = ()

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
        unknown = sorted(set(entry) - {"file", "length_unit", "regions"})
        if unknown:
            raise SpecError(path, f"{field}.{unknown[0]}", "unknown field; allowed: file, length_unit, regions")
        for key in ("file", "length_unit"):
            if key not in entry:
                raise SpecError(path, f"{field}.{key}", "missing (required)")
        unit = entry["length_unit"]
        if unit not in LENGTH_UNITS:
            raise SpecError(path, f"{field}.length_unit", f"expected one of {', '.join(map(repr, LENGTH_UNITS))}",
                            unit)
        file = _existing_file(path, f"{field}.file", entry["file"])
        kind = _kind(path, f"{field}.file", entry["file"])
        selectors = _selectors(path, f"{field}.regions", component, unit, file, entry.get("regions", {}))
        out[component] = ComponentGeometry(file, unit, kind, _digest(path, f"{field}.file", file), selectors)
    return out


def _selectors(path: Path, field: str, component: str, unit: str, file: Path, raw: Any) -> tuple[RegionSelector, ...]:
    """The ``regions`` table of a component's entry (module docstring), lengths in ``unit`` converted to metres."""
    if not isinstance(raw, dict):
        raise SpecError(path, field, "expected a table, e.g. { bore = { cylinder = { radius_mm = 25.0 } } }", raw)
    allowed = SELECTABLE_REGIONS[component]
    out = []
    for region, table in raw.items():
        where = f"{field}.{region}"
        if region not in allowed and not any(_numbered(region, pattern) for pattern in allowed):
            raise SpecError(path, where, f"unknown region of the {component}; allowed: {', '.join(allowed)}")
        if not isinstance(table, dict) or len(table) != 1 or next(iter(table)) not in SELECTOR_KINDS:
            kinds = " | ".join(f"{k} = ..." for k in SELECTOR_KINDS)
            raise SpecError(path, where, f"expected one selector: {{ {kinds} }}", table)
        ((kind, value),) = table.items()
        if region == CONTACT_BAND and kind != "cylinder":
            raise SpecError(path, where, f"expected a cylinder: {{ cylinder = {{ radius_{unit} = ..., "
                            f"tolerance_{unit} = ..., z_{unit} = [...] }} }} (a contact band is a circle band)", table)
        selector = _selector(path, f"{where}.{kind}", region, kind, value, unit, file)
        if region == CONTACT_BAND and f"tolerance_{unit}" not in value:  # the gear data's band
            selector = dataclasses.replace(selector, tolerance=0.0)
        out.append(selector)
    names = {s.region for s in out}
    if "bolt_holes" in names and any(n.startswith("bolt_hole_") for n in names):
        raise SpecError(path, field, "give bolt_holes (its holes are bolt_hole_<k>) or bolt_hole_<k>, not both")
    return tuple(sorted(out, key=lambda s: s.region))


def _numbered(region: str, pattern: str) -> bool:
    """Whether ``region`` is one of the numbered regions ``pattern`` stands for (``bolt_hole_<k>``: ``bolt_hole_0``,
    ``bolt_hole_1``, ...)."""
    if not pattern.endswith("<k>"):
        return False
    k = region.removeprefix(pattern[:-3])
    return k != region and k.isdigit() and k == str(int(k))


def _selector(path: Path, field: str, region: str, kind: str, value: Any, unit: str, file: Path) -> RegionSelector:
    """One selector of ``kind`` (module docstring) read from ``value``."""
    if kind == "physical_group":
        if file.suffix.lower() not in _GROUP_SUFFIXES:
            raise SpecError(path, field, f"the file {file.name} carries no named groups (they are read from "
                            f"{', '.join(_GROUP_SUFFIXES)} meshes); use cylinder or points")
        if not isinstance(value, str) or not value:
            raise SpecError(path, field, "expected the name of a physical group (string)", value)
        return RegionSelector(region, kind, group=value)
    lengths = {"cylinder": ("radius", "z", "tolerance", "axis"), "points": ("at", "tolerance")}[kind]
    keys = [f"{k}_{unit}" for k in lengths]
    if not isinstance(value, dict):
        raise SpecError(path, field, f"expected a table with {', '.join(keys)}", value)
    unknown = sorted(set(value) - set(keys))
    if unknown:
        raise SpecError(path, f"{field}.{unknown[0]}", f"unknown field; allowed: {', '.join(keys)} (lengths in the "
                        f"file's length_unit {unit!r})")
    scale = LENGTH_UNITS[unit]

    def numbers(key: str, count: int, default: Any = None) -> Any:
        got = value.get(f"{key}_{unit}", default)
        items = got if isinstance(got, list) else [got]
        if got is None or len(items) != count or not all(_finite(x) for x in items):
            what = "a number" if count == 1 else f"a list of {count} numbers"
            raise SpecError(path, f"{field}.{key}_{unit}", f"expected {what} ({unit})", got)
        return tuple(float(x) * scale for x in items) if isinstance(got, list) else float(got) * scale

    tolerance = numbers("tolerance", 1) if f"tolerance_{unit}" in value else 1e-6 if kind == "cylinder" else 1e-3
    if not tolerance > 0:
        raise SpecError(path, f"{field}.tolerance_{unit}", "expected > 0", value.get(f"tolerance_{unit}"))
    if kind == "points":
        pts = value.get(f"at_{unit}")
        if not isinstance(pts, list) or not pts:
            raise SpecError(path, f"{field}.at_{unit}", f"expected a list of points [[x, y, z], ...] ({unit})", pts)
        points = []
        for k, p in enumerate(pts):
            if not (isinstance(p, list) and len(p) == 3 and all(_finite(x) for x in p)):
                raise SpecError(path, f"{field}.at_{unit}[{k}]", f"expected a point [x, y, z] ({unit})", p)
            points.append(tuple(float(x) * scale for x in p))
        return RegionSelector(region, kind, points=tuple(points), tolerance=tolerance)
    radius = numbers("radius", 1)
    if not radius > 0:
        raise SpecError(path, f"{field}.radius_{unit}", "expected > 0", value[f"radius_{unit}"])
    z_range = numbers("z", 2) if f"z_{unit}" in value else None
    if z_range is not None and not z_range[0] < z_range[1]:
        raise SpecError(path, f"{field}.z_{unit}", "expected [z_min, z_max] with z_min < z_max", value[f"z_{unit}"])
    return RegionSelector(region, kind, radius=radius, z_range=z_range, axis=numbers("axis", 2, [0.0, 0.0]),
                          tolerance=tolerance)


def _finite(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


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
