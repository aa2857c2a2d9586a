"""Tetrahedral meshes of the components (Netgen), named boundary regions, surface meshes, cache.

``component_mesh(spec, component, level)`` returns a :class:`ComponentMesh`: node coordinates,
tetrahedra (4 nodes, or 10 for second order: vertices then edge nodes, Netgen order), boundary
triangles (3 or 6 nodes), and node sets of the named boundary regions the flexible bodies use as
interfaces:

- sun, planet: ``bore``, ``flanks`` (involute flanks between form and tip radius)
- ring: ``flanks``, ``bolt_holes`` and ``bolt_hole_<k>`` (hole k at polar angle 2 pi k / n)
- input_shaft: ``bearing_seat`` (outer surface, far -z end), ``gear_seat`` (inside the sun bore)
- output_shaft: ``bearing_seat`` (outer surface, far +z end), ``bolt_holes``, ``bolt_hole_<k>``

Mesh sizes per level come from ``[meshing_assumed.<level>]`` of gearbox.toml: ``tooth_size_mm``
on the tooth and bolt-hole faces, ``body_size_mm`` elsewhere (the ring: ``ring_tooth_size_mm`` and
``ring_body_size_mm``), ``element_order`` 1 or 2. Second
order nodes are placed on the true (OCC) surfaces by Netgen. Any other layout (a single gear body,
flexgear.fe.toothed) is meshed and cached the same way from a :class:`MeshSource` (:func:`source_mesh`).

Cache (``meshes/``, keyed by a hash of every input): the solid as ``.brep`` with its digest
(``.brep.sha256``), the Netgen mesh as ``.vol.gz`` (reload with :meth:`ComponentMesh.ngsolve_mesh`, which
re-attaches the OCC geometry so that curved elements sit on the true surfaces), the arrays as ``.npz`` and a
JSON summary, written last. Every file is checked before use (OCC hangs on a truncated ``.brep`` and Netgen
crashes on a truncated ``.vol.gz``, so those two are checked before their readers see them); an entry that
cannot be read is rebuilt with a warning, and an entry is built by one process at a time
(flexgear.cache.load_or_build).
"""

from __future__ import annotations

import io
import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from flexgear.cache import (
    atomic_write_bytes,
    cache_dir,
    check_gzip,
    load_or_build,
    read_entry,
)
from flexgear.design import Design, as_design
from flexgear.fe.parts import cached_brep, exchange_form, file_parts, private_temporary
from flexgear.geometry.layout import ComponentLayout, geometry_hash
from flexgear.progress import say
from flexgear.spec import GEOMETRY_COMPONENTS, GearboxSpec, MeshingSettings

__all__ = [
    "mesh_arrays",
    "ComponentMesh",
    "MeshSizes",
    "MeshSource",
    "component_brep",
    "component_mesh",
    "source_mesh",
    "build_meshes",
    "region_nodes",
    "layout_regions",
    "MESH_VERSION",
    "GRADING",
]

MESH_VERSION = 2
"""Bump when the meshing procedure changes without a config value changing (enters the cache key)."""
GRADING = 0.3
"""Netgen mesh grading (0..1): how fast elements grow away from the teeth."""
_REGION_TOL = 1e-6
"""Distance [m] within which a boundary node belongs to a region's surface (Netgen places nodes
on the OCC surfaces to ~1e-9 m)."""


@dataclass
class ComponentMesh:
    """A component's volume mesh (SI units) with named boundary node sets."""

    component: str
    level: str
    order: int
    nodes: np.ndarray  # (n, 3) m
    elements: np.ndarray  # (m, 4 | 10) node indices, 0-based
    surface: np.ndarray  # (k, 3 | 6) boundary triangles, 0-based, outward
    regions: dict[str, np.ndarray] = field(default_factory=dict)
    build_time_s: float = 0.0
    vol_path: Path | None = None
    brep_path: Path | None = None

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_elements(self) -> int:
        return len(self.elements)

    def ngsolve_mesh(self):
        """The NGSolve mesh with its OCC geometry attached, curved to the element order: the ``.vol.gz`` loaded
        and the ``.brep`` re-attached, also right after a cold build, so that a model made from it is the same
        whether the mesh was built in this process or read from the cache."""
        import ngsolve

        mesh = ngsolve.Mesh(_load_netgen_mesh(self.vol_path, self.brep_path))
        if self.order > 1:
            mesh.Curve(self.order)
        return mesh


def _load_netgen_mesh(vol: Path, brep: Path):
    """The Netgen mesh stored in ``vol`` with the OCC solid ``brep`` attached."""
    import netgen.meshing as nm
    from netgen.occ import OCCGeometry

    ngmesh = nm.Mesh()
    ngmesh.Load(str(vol))
    ngmesh.SetGeometry(OCCGeometry(str(brep)))
    return ngmesh


@dataclass(frozen=True)
class MeshSizes:
    """Netgen settings of a mesh: element size on the tooth (and bolt-hole) faces and elsewhere [m], Netgen's
    curvaturesafety (element size <= curvature radius / it) and optimisation passes (optsteps2d, optsteps3d)."""

    tooth: float
    body: float
    elements_per_curvature_radius: float = 0.3
    optimisation_steps: int = 3

    @classmethod
    def of(cls, settings: MeshingSettings, component: str = "") -> MeshSizes:
        """The sizes of ``component`` at a mesh level of gearbox.toml (``[meshing_assumed.<level>]``, mm;
        :meth:`MeshingSettings.sizes_mm`)."""
        tooth_mm, body_mm = settings.sizes_mm(component)
        return cls(tooth_mm * 1e-3, body_mm * 1e-3, settings.elements_per_curvature_radius,
                   settings.optimisation_steps)


@dataclass(frozen=True)
class MeshSource:
    """What a cached mesh is made of: the ``layout`` of its solid (its name names the cache files), the mesh
    ``level`` (a label) and ``sizes``, the level's ``element_order``, the solid's cache key ``solid_key``, the
    mesh's cache key per element order ``mesh_key(order)``, and its named boundary node sets
    ``regions(nodes, boundary)`` (as :func:`region_nodes`). :func:`component_mesh` meshes the study's components
    from one (:func:`_study_source`), flexgear.fe.toothed a single gear body."""

    layout: ComponentLayout
    level: str
    sizes: MeshSizes
    element_order: int
    solid_key: str
    mesh_key: Callable[[int], str]
    regions: Callable[[np.ndarray, np.ndarray], dict[str, np.ndarray]]

    @property
    def name(self) -> str:
        return self.layout.name


def component_brep(spec: GearboxSpec | Design, component: str, progress: bool = False) -> Path:
    """Path of the cached OCC solid (``.brep``) of ``component`` (``spec``: a spec or its design, flexgear.design),
    checked against its digest; built on a cache miss or when the file does not match its digest."""
    d = as_design(spec)
    if component in d.spec.components_geometry:  # the user's solid ([components_geometry])
        return file_parts()[0](d, component, progress)
    return layout_brep(d.layouts[component], geometry_hash(d.spec, component), progress)


def layout_brep(layout: ComponentLayout, key: str, progress: bool = False) -> Path:
    """Path of the cached OCC solid (``solid-<layout name>-<key>.brep``) of ``layout``
    (flexgear.geometry.solids.component_solid) in its STEP exchange form (flexgear.fe.parts.exchange_form: the
    solid exported as STEP and imported again is meshed exactly as this one), checked against its digest; built on
    a cache miss or when the file does not match its digest. ``key``: a hash of everything the layout is made
    from."""
    from flexgear.geometry.solids import component_solid

    return cached_brep(cache_dir() / f"solid-{layout.name}-{key}.brep",
                       lambda: exchange_form(component_solid(layout)), f"{layout.name}: solid built", progress)


def _say(progress: bool, text: str) -> None:
    if progress:
        say(text)


def _refine_teeth(geo, layout: ComponentLayout, size: float, mp) -> None:
    """Tooth size on tooth faces (inside the tip-root band) and bolt-hole faces, and along their edges.

    ``geo.SetFaceMeshsize`` limits the faces; the edges get the same limit through points of
    ``mp.RestrictH`` along them (a face's ``maxh`` property would cover both, but only when set
    before the OCCGeometry is built, which costs a second build of it: 2.5 s for the ring).
    """
    bands = []
    if layout.gear is not None:
        g = layout.gear
        bands.append((min(g.tip_radius, g.root_radius) - 1e-5, max(g.tip_radius, g.root_radius) + 1e-5))
    holes = [p for p in layout.prisms if p.section.holes]
    for p in holes:
        sec = p.section
        bands.append((sec.hole_circle_radius - sec.hole_radius - 1e-5, sec.hole_circle_radius + sec.hole_radius + 1e-5))
    for i, face in enumerate(geo.faces):
        xy = np.array([[v.p.x, v.p.y] for v in face.vertices])
        if len(xy) == 0:
            continue
        r = np.hypot(xy[:, 0], xy[:, 1])
        if any(lo < r.min() and r.max() < hi for lo, hi in bands):
            geo.SetFaceMeshsize(i, size)
            for edge in face.edges:
                a, b = edge.parameter_interval
                for s in np.linspace(a, b, 2 + int(2 * edge.mass / size)):  # edge.mass: length [m]
                    p = edge.Value(float(s))
                    mp.RestrictH(p.x, p.y, p.z, size)


TOOTH_RETRY_FACTORS = (1.0, 0.8, 0.64)
"""Tooth sizes tried in turn, relative to the level's, where Netgen's surface mesher fails on a solid ("Meshing
failed!": a few valid gear sets' tooth spaces at the coarse level, benchmarks/RESULTS.md, gear-set grid). The
first that meshes is kept (deterministic: the same solid fails the same way), and its factor is recorded in the
entry's summary."""


def _netgen_mesh_retried(brep: Path, layout: ComponentLayout, sizes: MeshSizes):
    """(first-order Netgen mesh, tooth factor): :func:`_netgen_mesh` at the level's tooth size, else at the next of
    :data:`TOOTH_RETRY_FACTORS` (the body size never finer than the teeth); the last failure is raised."""
    from netgen.libngpy._meshing import NgException

    for k, factor in enumerate(TOOTH_RETRY_FACTORS):
        try:
            return _netgen_mesh(brep, layout, replace(sizes, tooth=factor * sizes.tooth)), factor
        except NgException:
            if k == len(TOOTH_RETRY_FACTORS) - 1:
                raise
    raise AssertionError("unreachable")


def _netgen_mesh(brep: Path, layout: ComponentLayout, sizes: MeshSizes):
    """The first-order Netgen mesh of the solid of ``layout``, its OCC geometry attached (a second order is raised
    from it)."""
    import netgen.meshing as nm
    from netgen.occ import OCCGeometry

    geo = OCCGeometry(str(brep))
    mp = nm.MeshingParameters(
        maxh=sizes.body, curvaturesafety=sizes.elements_per_curvature_radius,
        grading=GRADING, segmentsperedge=0.0, closeedgefac=None, optsteps2d=sizes.optimisation_steps,
        optsteps3d=sizes.optimisation_steps)
    _refine_teeth(geo, layout, sizes.tooth, mp)
    return geo.GenerateMesh(mp=mp)


def mesh_arrays(ngmesh, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nodes (n, 3), tetrahedra (e, 4 or 10), boundary triangles (t, 3 or 6)) of a Netgen mesh of ``order``, node
    indices from 0 in Netgen's numbering and node order."""
    nodes = np.array(ngmesh.Coordinates(), float)
    n_el, n_tri = (10, 6) if order > 1 else (4, 3)
    elements = np.array([[p.nr - 1 for p in el.points] for el in ngmesh.Elements3D()], np.int64)
    surface = np.array([[p.nr - 1 for p in el.points] for el in ngmesh.Elements2D()], np.int64)
    if elements.shape[1] != n_el or surface.shape[1] != n_tri:
        raise RuntimeError(f"unexpected element sizes {elements.shape}, {surface.shape} for order {order}")
    return nodes, elements, surface


def region_nodes(d: Design, component: str, nodes: np.ndarray, boundary: np.ndarray) -> dict[str, np.ndarray]:
    """Named boundary node sets of ``component`` of design ``d`` (indices into ``nodes``, among ``boundary``): those
    of its layout (:func:`layout_regions`), and a shaft's ``bearing_seat`` and ``gear_seat``."""
    spec, layout = d.spec, d.layouts[component]
    out = layout_regions(layout, nodes, boundary)
    if component in ("input_shaft", "output_shaft"):
        p = nodes[boundary]
        r, z, tol = np.hypot(p[:, 0], p[:, 1]), p[:, 2], _REGION_TOL
        tube = next(q for q in layout.prisms if q.name == "tube")
        width = spec.components_assumed.bearing_seat_width_mm * 1e-3
        outer = np.abs(r - tube.section.outer) < tol
        if component == "input_shaft":
            out["bearing_seat"] = boundary[outer & (z < tube.z0 + width + tol)]
            sun = d.layouts["sun"].z_range
            out["gear_seat"] = boundary[outer & (z > sun[0] - tol)]
        else:
            out["bearing_seat"] = boundary[outer & (z > tube.z1 - width - tol)]
    return {k: np.unique(v) for k, v in out.items()}


def layout_regions(layout: ComponentLayout, nodes: np.ndarray, boundary: np.ndarray) -> dict[str, np.ndarray]:
    """Named boundary node sets of a component's ``layout`` (indices into ``nodes``, among ``boundary``, ascending):
    a gear's ``flanks`` (between form and tip radius, inside its toothed prisms) and an external gear's ``bore``;
    every prism's bolt holes, ``bolt_hole_<k>`` and ``bolt_holes``."""
    p = nodes[boundary]
    r = np.hypot(p[:, 0], p[:, 1])
    z = p[:, 2]
    tol = _REGION_TOL
    out: dict[str, np.ndarray] = {}

    def on_cylinder(radius: float) -> np.ndarray:
        return np.abs(r - radius) < tol

    if layout.gear is not None:
        g, prof = layout.gear, layout.profile
        toothed = [q for q in layout.prisms if q.section.gear is not None]
        inside = np.zeros(len(p), bool)
        for q in toothed:
            inside |= (z > q.z0 + tol) & (z < q.z1 - tol)
        lo, hi = sorted((prof.form_radius, g.tip_radius))
        out["flanks"] = boundary[inside & (r > lo + tol) & (r < hi - tol)]
        if not g.internal:
            out["bore"] = boundary[on_cylinder(toothed[0].section.inner)]
    for q in layout.prisms:
        if q.section.holes:
            sets = []
            in_z = (z > q.z0 - tol) & (z < q.z1 + tol)
            for k, (cx, cy) in enumerate(q.section.hole_centres()):
                dist = np.hypot(p[:, 0] - cx, p[:, 1] - cy)
                sets.append(boundary[in_z & (np.abs(dist - q.section.hole_radius) < tol)])
                out[f"bolt_hole_{k}"] = sets[-1]
            out["bolt_holes"] = np.concatenate(sets)
    return {k: np.unique(v) for k, v in out.items()}


def component_mesh(spec: GearboxSpec | Design, component: str, level: str = "coarse", order: int | None = None,
                   progress: bool = False) -> ComponentMesh:
    """The (cached) tetrahedral mesh of ``component`` at mesh ``level``; ``order`` overrides the level's. A component
    of ``[components_geometry]`` is meshed from its file (flexgear.fe.imported)."""
    spec = (d := as_design(spec)).spec
    if component not in GEOMETRY_COMPONENTS:
        raise ValueError(f"unknown component {component!r}; allowed: {', '.join(GEOMETRY_COMPONENTS)}")
    if level not in spec.meshing_assumed:
        raise ValueError(f"unknown mesh level {level!r}; gearbox.toml [meshing_assumed] has "
                         f"{', '.join(sorted(spec.meshing_assumed))}")
    order = spec.meshing_assumed[level].element_order if order is None else order
    if component in spec.components_geometry:  # the user's solid or volume mesh ([components_geometry])
        return file_parts()[1](d, component, level, order, progress)
    return source_mesh(_study_source(d, component, level), order, progress)


def _study_source(d: Design, component: str, level: str) -> MeshSource:
    """The :class:`MeshSource` of a study component: its design's layout, the level's settings; the solid keyed by
    the geometry, the mesh by the geometry, the level's settings, the order and the meshing procedure."""
    spec = d.spec
    settings = spec.meshing_assumed[level]
    return MeshSource(d.layouts[component], level, MeshSizes.of(settings, component), settings.element_order,
                      geometry_hash(spec, component),
                      lambda order: geometry_hash(spec, component, settings.for_component(component), order, GRADING,
                                                MESH_VERSION),
                      lambda nodes, boundary: region_nodes(d, component, nodes, boundary))


def source_mesh(source: MeshSource, order: int, progress: bool = False) -> ComponentMesh:
    """The cached mesh of ``source`` of element ``order`` (:func:`_cached_mesh`), or the one built and stored
    (:func:`_build_mesh`) when it is missing or cannot be read, by one process at a time (the lock of its JSON
    summary). Files ``mesh-<name>-<level>-o<order>-<mesh_key(order)>.*`` in the cache folder."""
    component, level = source.name, source.level
    brep = layout_brep(source.layout, source.solid_key, progress)
    stem = cache_dir() / f"mesh-{component}-{level}-o{order}-{source.mesh_key(order)}"
    paths = {"npz": stem.with_suffix(".npz"), "vol": stem.with_suffix(".vol.gz"), "json": stem.with_suffix(".json")}

    def load() -> ComponentMesh | None:
        return _cached_mesh(paths, component, level, order, brep)

    def build() -> ComponentMesh:
        return _build_mesh(source, order, paths, brep, progress)[0]

    return load_or_build(paths["json"], load, build)


def _cached_mesh(paths: dict[str, Path], component: str, level: str, order: int, brep: Path) -> ComponentMesh | None:
    """The cached mesh stored at ``paths``, or None when a file is missing; raises
    flexgear.cache.UnreadableEntry naming a file that cannot be read (the JSON summary and every array read,
    the node count of both compared, the ``.vol.gz`` read through to its checksum)."""
    if not (paths["npz"].exists() and paths["vol"].exists() and paths["json"].exists()):
        return None
    info = read_entry(paths["json"], lambda p: json.loads(p.read_text()))
    build_time = read_entry(paths["json"], lambda _: float(info["build_time_s"]))

    def arrays(path: Path) -> dict[str, np.ndarray]:
        with np.load(path, allow_pickle=False) as data:
            out = {k: data[k] for k in data.files}
        if len(out["nodes"]) != info.get("nodes", len(out["nodes"])):
            raise ValueError(f"{len(out['nodes'])} nodes, the summary {paths['json'].name} says {info['nodes']}")
        return out

    data = read_entry(paths["npz"], arrays)
    check_gzip(paths["vol"])
    regions = {k[len("region_"):]: v for k, v in data.items() if k.startswith("region_")}
    return ComponentMesh(component, level, order, data["nodes"], data["elements"], data["surface"], regions,
                         build_time, paths["vol"], brep)


def _build_mesh(source: MeshSource, order: int, paths: dict[str, Path], brep: Path, progress: bool):
    """Mesh ``source`` (cache miss), store it at ``paths`` (its cache entry, :func:`source_mesh`); (ComponentMesh,
    its Netgen mesh with the OCC geometry). ``brep``: the component's solid (:func:`layout_brep`).

    Netgen meshes once per component and level: a second-order mesh is the first-order mesh (the cached
    one, or meshed and stored here) raised by ``SecondOrder()``, edge nodes on the true surfaces, the same
    topology the reduction's FE model is built on (flexgear.fe.fem raises the order the same way).
    """
    component, level = source.name, source.level
    paths["json"].unlink(missing_ok=True)  # written last: until then readers find no entry, not a mixed one
    t0 = time.perf_counter()
    factor = 1.0
    if order == 1:
        ngmesh, factor = _netgen_mesh_retried(brep, source.layout, source.sizes)
    else:
        first = source_mesh(source, 1, progress)
        ngmesh = _load_netgen_mesh(first.vol_path, brep)  # as stored: the same raised mesh cold or warm
        ngmesh.SecondOrder()
    nodes, elements, surface = mesh_arrays(ngmesh, order)
    build = time.perf_counter() - t0
    surface = _orient_outward(nodes, surface)
    regions = source.regions(nodes, np.unique(surface))
    mesh = ComponentMesh(component, level, order, nodes, elements, surface, regions, build, paths["vol"], brep)
    tmp_vol = private_temporary(paths["vol"], ".vol.gz")
    ngmesh.Save(str(tmp_vol))
    tmp_vol.replace(paths["vol"])
    buf = io.BytesIO()
    np.savez_compressed(buf, nodes=nodes, elements=elements, surface=surface,
                        **{f"region_{k}": v for k, v in regions.items()})
    atomic_write_bytes(paths["npz"], buf.getvalue())
    info = {"component": component, "level": level, "order": order, "nodes": mesh.n_nodes,
            "elements": mesh.n_elements, "build_time_s": build, "tooth_size_factor": factor,
            "regions": {k: len(v) for k, v in regions.items()}}
    atomic_write_bytes(paths["json"], json.dumps(info, indent=1).encode())
    role = "" if order == source.element_order else " (topology for the reduction)"
    _say(progress, f"  {component} ({level}): {mesh.n_elements} tetrahedra, {mesh.n_nodes} nodes, "
                   f"order {order}{role}, meshed in {build:.1f} s")
    return mesh, ngmesh


def build_meshes(spec: GearboxSpec, level: str = "default", progress: bool = True,
                 components: tuple[str, ...] = GEOMETRY_COMPONENTS) -> dict[str, ComponentMesh]:
    """Meshes of all components at ``level`` (cached), with progress on stderr."""
    out = {}
    for i, name in enumerate(components, 1):
        _say(progress, f"[{i}/{len(components)}] {name} ({level})")
        out[name] = component_mesh(spec, name, level, progress=progress)
    return out


def _orient_outward(nodes: np.ndarray, surface: np.ndarray) -> np.ndarray:
    """Boundary triangles oriented so that the enclosed (divergence-theorem) volume is positive."""
    tri = nodes[surface[:, :3]]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    if volume >= 0:
        return surface
    flipped = surface.copy()
    flipped[:, [1, 2]] = flipped[:, [2, 1]]
    if surface.shape[1] == 6:  # edge nodes follow their vertex pairs
        flipped[:, 3:] = surface[:, [3, 5, 4]]
    return flipped
