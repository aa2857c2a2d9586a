"""The study's components as reduced flexible bodies: solid -> mesh -> FE model -> Craig-Bampton -> cache.

Interfaces (where a component is connected):
- sun, planet: the bore (shaft-sun joint, planet bearing seat);
- ring: its side of the ring-output shaft joint (section 2.1: 12 bolts): "bolt_patches", the clamped discs of
  all bolts on the flange face (flexgear.fe.bolted) moving together as one rigid body (RBE2): the joint to a
  rigid output shaft, which holds every disc in one rigid motion;
- input shaft: "sun_seat", its outer surface inside the sun's bore, and "bearing_seat";
- the parallel-axis pair's output shaft: "planet_seat", its outer surface inside the wheel's bore, and
  "bearing_seat" at the far (+z) end of the tube; each of the pair's shafts also "bearing_seat_near", its second
  bearing's seat beyond the gear's other face (flexgear.geometry.supports);
- output shaft: "bolt_patches" on its web likewise (the joint to a rigid ring), and "bearing_seat"
  (``bearing_seat_width_mm`` at the far end of the tube).
When both are flexible they are one body, reduced together (flexgear.fe.ring_shaft).
Seat and joint interfaces are RBE3 (distributing) averages, the bolt patches' union rigid (RBE2).
Load circles (attachment modes, flexgear.fe.attachment): each gear's contact bands, one per mesh and
helix half, at the mesh's operating pitch radius (sun: the sun-planet mesh; planet: both meshes; ring:
the planet-ring mesh), over the half's face width, loaded along the tooth normal in the gear's local
frame, with the band the contact kernel reads (one normal module). The shafts carry their loads at
their interfaces, whose static modes the basis holds anyway.
The mesh is the component's cached mesh at the variant's level (flexgear.fe.mesh); the tooth
compliance itself is in the contact law. Results are cached by a hash of the geometry, the
mesh level and the reduction settings (:func:`cached_reduced_body`). Each basis holds every fixed-interface
mode below ``[reduction_assumed] fixed_interface_cutoff_hz``.
"""

from __future__ import annotations

import dataclasses
import math
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path

import numpy as np

from flexgear.cache import atomic_write_bytes, cache_dir, load_or_build, read_entry
from flexgear.design import Design, as_design
from flexgear.fe.attachment import LoadCircle
from flexgear.fe.bolted import clamped_patches
from flexgear.fe.cms import Interface, ReducedBody, interface, reduce
from flexgear.geometry.contact_lines import MeshContactGeometry
from flexgear.geometry.layout import geometry_hash
from flexgear.geometry.massprops import MassProperties
from flexgear.geometry.supports import NEAR
from flexgear.progress import say
from flexgear.schema_geometry import CONTACT_BAND
from flexgear.spec import COMPONENT_GEOMETRY, GearboxSpec

__all__ = ["contact_band_selector", "contact_fit_window", "component_interfaces", "component_load_circles",
           "component_contacts", "component_reduced_body",
           "component_mass_properties", "cached_component_frequencies", "component_cache_key", "COMPONENT_GEOMETRY",
           "joint_point",
           "gear_shaft_joints", "gear_seat", "is_tied", "patch_union", "BOLT_PATCHES", "RING_SEAT", "band_circles",
           "read_cached", "cached_frequencies"]

BOLT_PATCHES = "bolt_patches"
"""Name of the ring's and the output shaft's rigid interface over the clamped discs of all bolts."""
RING_SEAT = "ring_seat"
"""Name of the measuring interface of the tied ring and output shaft on the ring's side of the joint
(flexgear.fe.ring_shaft): the seat the ring's deflections are measured from."""

"""Variant component name -> geometry component name."""

_REDUCTION_VERSION = 4  # 4: attachment modes on the contact bands, whole compressed basis kept
_TOL = 1e-6  # m: nodes on an exact cylinder/plane of the OCC geometry
_INTERFACE_KIND = "rbe3"  # seat and joint interfaces: distributing averages (flexgear.fe.cms.reduce kind)
_BOLT_PATCH_KIND = "rbe2"  # the bolt patches' union: the clamped discs moving as one rigid body
_WHOLE_BASIS = 0  # cache-key term: the whole compressed basis is kept (no truncation)


def component_interfaces(fe, spec: GearboxSpec | Design, component: str) -> list[Interface]:
    """Interface node sets of ``component`` (see the module docstring), found on the exact surfaces.
    ``spec``: a spec or its design (flexgear.design), as in every function here that takes one."""
    d = as_design(spec)
    spec = d.spec
    r = np.hypot(fe.nodes[:, 0], fe.nodes[:, 1])
    z = fe.nodes[:, 2]
    c = spec.components_assumed
    if component in ("sun", "planet"):
        bore = getattr(c, f"{component}_bore_diameter_mm") * 1e-3 / 2
        return [_interface(fe, d, component, np.abs(r - bore) < _TOL, "bore")]
    if component == "ring":
        return [patch_union(fe, d, BOLT_PATCHES, component)]
    tube = [p for p in d.layouts[component].prisms if p.name == "tube"][0]
    seat = c.bearing_seat_width_mm * 1e-3
    on_tube = np.abs(r - tube.section.outer) < _TOL
    if component == "input_shaft" or not spec.gears.has_ring:  # a shaft in its gear's bore (the pair's wheel too)
        gear = "sun" if component == "input_shaft" else "planet"
        prisms = d.layouts[gear].prisms
        z0, z1 = min(p.z0 for p in prisms), max(p.z1 for p in prisms)
        joints = [_interface(fe, d, component, on_tube & (z > z0 - _TOL) & (z < z1 + _TOL), f"{gear}_seat")]
        low, high = (z < tube.z0 + seat + _TOL), (z > tube.z1 - seat - _TOL)
        far, near = (low, high) if gear == "sun" else (high, low)
        if not spec.gears.has_ring:  # the parallel-axis pair's second bearing, beyond the gear's other face
            joints.append(_interface(fe, d, component, on_tube & near, "bearing_seat" + NEAR))
    else:
        joints = [patch_union(fe, d, BOLT_PATCHES, component)]
        far = (z > tube.z1 - seat - _TOL)
    return [*joints, _interface(fe, d, component, on_tube & far, "bearing_seat")]


SELECTED_INTERFACES = {"bore": "bore", "bearing_seat": "bearing_seat", "sun_seat": "gear_seat",
                       "planet_seat": "gear_seat", "bearing_seat" + NEAR: "bearing_seat" + NEAR}
"""Interface -> the region of ``[components_geometry] <component>.regions`` that places it on an imported part
(flexgear.schema_geometry.RegionSelector). The bolt patches are the clamped discs a ``bolt_discs`` selector picks,
else those of the bolt circle (flexgear.fe.bolted.clamped_patches); the contact bands stay on the gear data's
meshes."""


def _interface(fe, d: Design, component: str, builtin: np.ndarray, name: str) -> Interface:
    """Interface ``name`` of ``component``: on the nodes a selector of its imported part's file picks
    (flexgear.fe.selectors.picked_nodes on the FE model's nodes and boundary, checked when the part was meshed),
    else on the built-in rule's nodes ``builtin`` (a mask over the FE nodes)."""
    from flexgear.fe.selectors import named_selector, picked_nodes

    found = named_selector(d.spec.components_geometry.get(component), SELECTED_INTERFACES.get(name, ""))
    if found is None:
        return interface(fe, np.flatnonzero(builtin), name)
    return interface(fe, picked_nodes(found[0], fe.nodes, fe.surface_triangles, found[1]), name)


def patch_union(fe, spec: GearboxSpec | Design, name: str, component: str | None = None) -> Interface:
    """The clamped discs of ``fe`` (the ring's flange face or the output shaft's web face,
    flexgear.fe.bolted.clamped_patches) as one interface ``name``: their nodes in ascending order, each disc's
    nodes weighted equally and each disc in all 1 / (number of bolts), the point their weighted centroid (on the
    axis in the flange-web plane, to the mesh's asymmetry). Rigid (RBE2) as a reduction interface: the weights
    only define its RBE3 reading (flexgear.fe.cms.rbe3_weights), which for a rigid patch is its rigid motion.
    ``component``: the ring or output shaft ``fe`` models, whose imported part may select its discs
    (flexgear.fe.bolted.clamped_patches)."""
    patches = clamped_patches(fe, spec, component=component)
    nodes = np.concatenate(patches)
    weights = np.concatenate([np.full(len(p), 1.0 / len(p)) for p in patches]) / len(patches)
    order = np.argsort(nodes)
    nodes, weights = nodes[order], weights[order]
    return Interface(name, nodes, weights, weights @ fe.nodes[nodes])


def _contact_bands(d: Design, component: str) -> list[tuple[LoadCircle, np.ndarray]]:
    """(load circle of order 0, angles of the contacts on it [rad]) per contact band of a gear.

    From the design's mesh contact geometry (flexgear.design ``meshes``), meshes as
    flexgear.mbs.gearbox.mesh_contacts builds them: sun-planet with the sun (gear 1) of hand +1
    pushing in the drive sense, planet-ring with the planet (gear 1) of hand -1 against it; planet 1
    (at angle 0) meets the sun at angle pi and the ring at 0 about its own centre.
    """
    if component not in ("sun", "planet", "ring"):
        return []
    geo, spec = d.gears, d.spec
    sigma = int(math.copysign(1.0, spec.load_case.input_speed_rad_s))
    planets = np.asarray(geo.planet_angles, float)
    outer, inner = d.meshes["outer"], d.meshes.get("inner")
    # (mesh contact geometry, drive sign, is this component gear 1, contact angles on this component)
    meshes = {"sun": [(outer, sigma, True, planets)],
              "planet": [(outer, sigma, False, np.array([math.pi])), (inner, -sigma, True, np.array([0.0]))],
              "ring": [(inner, -sigma, False, planets)]}[component]
    meshes = [m for m in meshes if m[0] is not None]  # the parallel-axis pair: no planet-ring mesh
    out = []
    for contact, drive, first, angles in meshes:
        out += [(circle, angles) for circle in band_circles(contact, drive, first, spec.gears.normal_module_m)]
    selector = contact_band_selector(d, component)
    if selector is None:
        return out
    moved = []
    for circle, angles in out:  # the circle at the selector's radius, its band cut to the selector's (one window)
        z = 0.5 * (circle.z_min_m + circle.z_max_m)
        point, half, radial = contact_fit_window(selector, np.array([circle.radius_m, 0.0, z]),
                                                 0.5 * (circle.z_max_m - circle.z_min_m), circle.radial_band_m)
        moved.append((dataclasses.replace(circle, radius_m=float(point[0]), z_min_m=float(point[2] - half),
                                          z_max_m=float(point[2] + half), radial_band_m=radial), angles))
    return moved


def contact_band_selector(spec: GearboxSpec | Design, component: str):
    """The ``[components_geometry] <component>.regions.contact_band`` selector of an imported gear
    (flexgear.schema_geometry.RegionSelector), None for a built-in component or one without it."""
    entry = (getattr(as_design(spec).spec, "components_geometry", None) or {}).get(component)
    return next((s for s in entry.regions if s.region == CONTACT_BAND), None) if entry is not None else None


def contact_fit_window(band, point: np.ndarray, half_width: float, radial_band: float
                       ) -> tuple[np.ndarray, float, float]:
    """The contact band's (point [m], axial half-width [m], radial half-width [m]) of a contact at ``point`` with
    the gear data's ``half_width`` and ``radial_band``, moved by a ``contact_band`` selector ``band`` (None: as
    given): the point's radius the selector's, its axial range cut to the selector's, the radial half-width the
    selector's tolerance where it gives one. An axial range that misses the contact's raises ValueError."""
    if band is None:
        return np.asarray(point, float), float(half_width), float(radial_band)
    p = np.asarray(point, float)
    r = math.hypot(p[0], p[1])
    z0, z1 = p[2] - half_width, p[2] + half_width
    if band.z_range is not None:
        z0, z1 = max(z0, band.z_range[0]), min(z1, band.z_range[1])
        if z1 < z0:
            raise ValueError(f"{band.describe()} misses the contact's axial range "
                             f"{1e3 * (p[2] - half_width):g}..{1e3 * (p[2] + half_width):g} mm")
    moved = np.array([p[0] * band.radius / r, p[1] * band.radius / r, 0.5 * (z0 + z1)])
    return moved, 0.5 * (z1 - z0), float(band.tolerance or radial_band)


def band_circles(contact: MeshContactGeometry, drive: int, first: bool, band: float) -> list[LoadCircle]:
    """Load circles of order 0 on a gear's contact bands in one mesh, one per helix half: at the gear's operating
    pitch radius, over the half's width, along the half's tooth normal in the gear's local (radial, tangential,
    axial) frame, with the radial half-width ``band`` [m] the contact kernel reads (one normal module).

    ``contact``: the mesh's contact geometry (flexgear.geometry.contact_lines.MeshContactGeometry); ``drive``: +1
    or -1 (gear 1 pushing gear 2 counter-clockwise / clockwise about +z); ``first``: the gear is gear 1 of the
    mesh (else gear 2: an external one sees the normal's radial and tangential parts reversed).
    """
    mesh, width = contact.mesh, contact.helix_width
    radius = mesh.operating_pitch_radii[0 if first else 1]
    out = []
    for half, (n_r, n_t, n_z) in zip(contact.halves, contact.normals[drive], strict=True):
        direction = (n_r, n_t, n_z) if first or mesh.internal else (-n_r, -n_t, n_z)
        out.append(LoadCircle(radius, half.z - width / 2, half.z + width / 2, 0, direction, band))
    return out


def component_load_circles(spec: GearboxSpec | Design, component: str, order: int) -> list[LoadCircle]:
    """Load circles of ``order`` on ``component``'s contact bands (module docstring); [] for shafts or order 0."""
    if order == 0:
        return []
    return [dataclasses.replace(c, order=order) for c, _ in _contact_bands(as_design(spec), component)]


def component_contacts(spec: GearboxSpec | Design, component: str) -> tuple[np.ndarray, np.ndarray]:
    """Contact points (p, 3) [m] and tooth normals (p, 3) of a gear in its body frame, per band and angle.

    Sun and ring: the five planets' contacts on each helix half; planet: its sun and ring contacts.
    """
    points, normals = [], []
    for circle, angles in _contact_bands(as_design(spec), component):
        z = 0.5 * (circle.z_min_m + circle.z_max_m)
        for a in angles:
            e_r, e_t = np.array([math.cos(a), math.sin(a), 0.0]), np.array([-math.sin(a), math.cos(a), 0.0])
            d = circle.direction
            points.append(circle.radius_m * e_r + [0.0, 0.0, z])
            normals.append(d[0] * e_r + d[1] * e_t + [0.0, 0.0, d[2]])
    return np.array(points).reshape(-1, 3), np.array(normals).reshape(-1, 3)


def joint_point(spec: GearboxSpec | Design, gear: str) -> np.ndarray:
    """Point [m] (component frame = gearbox frame) where ``gear`` ("sun" or "ring") is joined to its shaft.

    Sun-input shaft (the parallel-axis pair's wheel and output shaft): on the axis, mid-way along the gear, in its
    frame. Ring-output shaft: on the axis, in the plane
    where the ring's flange meets the shaft's web.
    """
    prisms = as_design(spec).layouts[gear].prisms
    if gear in ("sun", "planet"):  # the planet: the parallel-axis pair's wheel on the output shaft
        return np.array([0.0, 0.0, 0.5 * (min(p.z0 for p in prisms) + max(p.z1 for p in prisms))])
    if gear == "ring":
        return np.array([0.0, 0.0, [p for p in prisms if p.section.holes][0].z1])
    raise ValueError(f"joint_point: gear must be 'sun', 'planet' or 'ring', got {gear!r}")


def gear_shaft_joints(spec: GearboxSpec | Design, gear: str) -> list[tuple[str, str, np.ndarray]]:
    """The fixed joint of ``gear`` ("sun", "ring"; "planet": the parallel-axis pair's wheel) and its shaft: [(gear
    interface, shaft interface, point [m], the gear's frame)].

    Sun-input shaft: at :func:`joint_point` between the sun's "bore" and the shaft's "sun_seat" (the wheel and its
    output shaft likewise, "bore" and "planet_seat"). Ring-output
    shaft (one of them rigid; both flexible they are one body, flexgear.fe.ring_shaft): at :func:`joint_point`
    between the two "bolt_patches" interfaces (every clamped disc in the rigid part's motion).
    """
    if gear == "ring":
        return [(BOLT_PATCHES, BOLT_PATCHES, joint_point(spec, gear))]
    if gear in ("sun", "planet"):
        return [("bore", f"{gear}_seat", joint_point(spec, gear))]
    raise ValueError(f"gear_shaft_joints: gear must be 'sun', 'planet' or 'ring', got {gear!r}")


def is_tied(body: ReducedBody) -> bool:
    """Whether ``body`` is the ring and the output shaft reduced together (flexgear.fe.ring_shaft): it carries the
    measuring interface "ring_seat"."""
    return any(i.name == RING_SEAT for i in body.interfaces)


def gear_seat(body: ReducedBody, gear: str) -> Interface:
    """The interface of a gear's reduced body that its deflections are measured from.

    Sun, planet: the bore. Ring: its side of the joint to the output shaft: "bolt_patches", or on the tied ring
    and output shaft (flexgear.fe.ring_shaft) the measuring interface "ring_seat" over the same discs.
    """
    if gear != "ring":
        return body.interface("bore")
    return body.interface(RING_SEAT if is_tied(body) else BOLT_PATCHES)


def component_reduced_body(spec: GearboxSpec | Design, component: str, level: str = "coarse",
                           progress: bool = False) -> ReducedBody:
    """The reduced flexible body of a component (cached): ``component`` as in Table 3 or the geometry."""
    key, build = _component_reduction(spec, component, level, progress)
    return cached_reduced_body(key, build)


def component_mass_properties(spec: GearboxSpec | Design, component: str, level: str = "coarse",
                              progress: bool = False) -> MassProperties:
    """The mass properties of :func:`component_reduced_body` (those of its FE mesh), which a rigid twin needs
    without modes: read alone from the cache when the body is there (a damaged body file is named and rebuilt),
    else those of the FE model's mass matrix alone (flexgear.fe.fem.mesh_mass_properties: the numbers the body
    will carry, without its reduction), cached beside it."""
    key, build = _component_reduction(spec, component, level, progress)
    if reduced_cache_path(key).exists():
        props = read_cached(key, _load_mass_properties)
        return props if props is not None else cached_reduced_body(key, build).props
    return _mesh_mass_properties(as_design(spec), component, level, key, progress)


def _mesh_mass_properties(d: Design, component: str, level: str, key: str, progress: bool) -> MassProperties:
    """:func:`component_mass_properties` of a component whose body is not built: its FE mesh's, cached as
    ``massprops-mesh-<body key>.npz``."""
    from flexgear.fe.fem import mesh_mass_properties
    from flexgear.fe.mesh import component_mesh

    path = cache_dir() / f"massprops-mesh-{key}.npz"

    def load() -> MassProperties | None:
        return read_entry(path, _load_mass_properties) if path.exists() else None

    def build() -> MassProperties:
        import io

        name = COMPONENT_GEOMETRY[component]
        mesh = component_mesh(d, name, level, order=1, progress=progress)
        props = mesh_mass_properties(mesh.ngsolve_mesh(), d.spec.material_assumed,
                                     d.spec.meshing_assumed[level].element_order)
        buf = io.BytesIO()
        np.savez(buf, mass=props.mass, com=props.com, inertia=props.inertia)
        atomic_write_bytes(path, buf.getvalue())
        return props

    return load_or_build(path, load, build)


def component_cache_key(spec: GearboxSpec | Design, component: str, level: str = "coarse") -> str:
    """The cache key of :func:`component_reduced_body` (flexgear.fe.reduced.reduced_cache_path names its file)."""
    return _component_reduction(spec, component, level, False)[0]


def cached_component_frequencies(spec: GearboxSpec | Design, component: str,
                                 level: str = "coarse") -> np.ndarray | None:
    """Free-free frequencies [Hz] of :func:`component_reduced_body`, read alone from the cache; None when the
    body is not cached yet (nothing is built)."""
    return cached_frequencies(_component_reduction(spec, component, level, False)[0])


def cached_frequencies(key: str) -> np.ndarray | None:
    """Free-free frequencies [Hz] of the reduced body cached under ``key``, read alone; None when it is not
    cached (or cannot be read)."""
    return read_cached(key, _load_frequencies)


def _load_mass_properties(path: Path) -> MassProperties:
    """The mass properties of a body saved by ReducedBody.save, read alone from its file (``np.load`` reads an
    ``.npz`` member only when asked: a rigid twin needs three small arrays, not the modes)."""
    with np.load(path, allow_pickle=False) as z:
        return MassProperties(float(z["mass"]), z["com"], z["inertia"])


def _load_frequencies(path: Path) -> np.ndarray:
    """``frequencies_hz`` of a body saved by ReducedBody.save, read alone from its file."""
    with np.load(path, allow_pickle=False) as z:
        return np.asarray(z["frequencies_hz"], float)


def read_cached(key: str, read: Callable[[Path], object]) -> object | None:
    """``read(path)`` of the reduced body cached under ``key``; None if it is missing or cannot be read (a
    damaged file is reported and rebuilt by :func:`cached_reduced_body`)."""
    path = reduced_cache_path(key)
    if not path.exists():
        return None
    try:
        return read(path)
    except Exception:
        return None


def _component_reduction(spec: GearboxSpec | Design, component: str, level: str,
                         progress: bool) -> tuple[str, Callable[[], ReducedBody]]:
    """Cache key and build function of a component's reduced body (:func:`component_reduced_body`)."""
    d = as_design(spec)
    spec = d.spec
    name = COMPONENT_GEOMETRY[component]
    mesh_settings = spec.meshing_assumed[level]
    red = spec.reduction_assumed
    circles = component_load_circles(d, name, red.attachment_order)
    patches = name in ("ring", "output_shaft")
    # the bolt patches' union, its kind and clamped disc enter the key of the bodies that have it
    extra = [(BOLT_PATCHES, "union", _BOLT_PATCH_KIND, spec.joints_assumed.bolt_clamp_diameter_mm)] if patches else []
    max_hz = red.fixed_interface_cutoff_hz

    def build() -> ReducedBody:
        from flexgear.fe.fem import fe_model
        from flexgear.fe.mesh import component_mesh

        if progress:
            say(f"  {name} ({level}): building the reduced body (order-{mesh_settings.element_order} FE model "
                "on the first-order mesh topology)")
        # first-order mesh topology; fe_model raises the order itself (a second-order Netgen mesh loaded
        # as is carries its mid-edge points as unconnected vertices: a singular stiffness matrix)
        mesh = component_mesh(d, name, level, order=1, progress=progress)
        fe = fe_model(mesh.ngsolve_mesh(), spec.material_assumed, mesh_settings.element_order)
        itfs = component_interfaces(fe, d, name)
        return reduce(fe, itfs, kind=_INTERFACE_KIND, n_compare=0, load_circles=circles,
                      rigid=tuple(i.name for i in itfs if i.name == BOLT_PATCHES), max_hz=max_hz)

    key = geometry_hash(spec, name, mesh_settings.for_component(name), max_hz, _INTERFACE_KIND, _WHOLE_BASIS,
                        [c.key() for c in circles], _REDUCTION_VERSION, *extra)
    return f"{name}-{level}-{key}", build


CACHE_FORMAT_VERSION = 1  # bump when ReducedBody's content or the reduction changes
LOADED_BODIES_KEPT = 8
"""Reduced bodies one process keeps loaded (:func:`cached_reduced_body`): a Campbell diagram, a period's modes or a
report builds the same model at many speeds and angles, and would read each body's file every time."""
_LOADED: OrderedDict[tuple, ReducedBody] = OrderedDict()


def reduced_cache_path(key: str, directory: str | Path | None = None) -> Path:
    """``<directory or $FLEXGEAR_CACHE_DIR or meshes/>/reduced-<key>.npz``."""
    return Path(cache_dir() if directory is None else directory) / f"reduced-v{CACHE_FORMAT_VERSION}-{key}.npz"


def cached_reduced_body(key: str, build: Callable[[], ReducedBody],
                        directory: str | Path | None = None) -> ReducedBody:
    """Load the reduced body cached under ``key``, or ``build()`` it and store it atomically.

    ``key`` must be a hash of every input (flexgear.spec.spec_hash of geometry, mesh and reduction
    settings): a changed input gives a new key and a rebuild. A file that cannot be read (every member is
    read, its zip checksum checked) is rebuilt with a flexgear.cache.CacheWarning naming it; a missing body is
    built by one process at a time, the others load its file (flexgear.cache.load_or_build). A body loaded from
    its file is kept in the process (:data:`LOADED_BODIES_KEPT`), and the same object is returned while the file is
    unchanged: callers do not modify it.
    """
    path = reduced_cache_path(key, directory)
    try:  # the file's identity: a file rebuilt or replaced is read again
        stat = path.stat()
        seen = (str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    except OSError:
        seen = None
    if seen in _LOADED:
        _LOADED.move_to_end(seen)
        return _LOADED[seen]

    def load() -> ReducedBody | None:
        # np.load reads each member from the file: no copy of the whole file
        return read_entry(path, ReducedBody.load) if path.exists() else None

    def store() -> ReducedBody:
        body = build()
        atomic_write_bytes(path, body.save())
        return body

    body = load_or_build(path, load, store)
    if seen is not None:  # loaded from its file: kept for the next call (the least recently used one dropped)
        _LOADED[seen] = body
        while len(_LOADED) > LOADED_BODIES_KEPT:
            _LOADED.popitem(last=False)
    return body
