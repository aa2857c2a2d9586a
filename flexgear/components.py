"""The study's components as reduced flexible bodies: solid -> mesh -> FE model -> Craig-Bampton -> cache.

Interfaces (where a component is connected; RBE3, distributing, by default):
- sun, planet: the bore (shaft-sun joint, planet bearing seat);
- ring: the 12 bolt holes of the flange (ring-output shaft joint, section 2.1);
- shafts: both end faces.
The mesh is the component's cached mesh at the variant's level (flexgear.meshing); the tooth
compliance itself is in the contact law. Results are cached by a hash of the geometry, the
mesh level and the reduction settings (flexgear.flexible.cached_reduced_body).
"""

from __future__ import annotations

import numpy as np

from flexgear.cms import Interface, ReducedBody, interface, reduce
from flexgear.geometry import component_layout, geometry_hash
from flexgear.spec import GearboxSpec

__all__ = ["component_interfaces", "component_reduced_body", "COMPONENT_GEOMETRY"]

COMPONENT_GEOMETRY = {"sun": "sun", "planets": "planet", "planet": "planet", "ring": "ring",
                      "input_shaft": "input_shaft", "output_shaft": "output_shaft"}
"""Variant component name -> geometry component name."""

_REDUCTION_VERSION = 2
_TOL = 1e-6  # m: nodes on an exact cylinder/plane of the OCC geometry


def component_interfaces(fe, spec: GearboxSpec, component: str) -> list[Interface]:
    """Interface node sets of ``component`` (see the module docstring), found on the exact surfaces."""
    r = np.hypot(fe.nodes[:, 0], fe.nodes[:, 1])
    z = fe.nodes[:, 2]
    if component in ("sun", "planet"):
        bore = getattr(spec.components_assumed, f"{component}_bore_diameter_mm") * 1e-3 / 2
        return [interface(fe, np.flatnonzero(np.abs(r - bore) < _TOL), "bore")]
    if component == "ring":
        flange = [p for p in component_layout(spec, "ring").prisms if p.section.holes][0].section
        out = []
        for k in range(flange.holes):
            a = 2 * np.pi * k / flange.holes
            d = np.hypot(fe.nodes[:, 0] - flange.hole_circle_radius * np.cos(a),
                         fe.nodes[:, 1] - flange.hole_circle_radius * np.sin(a))
            out.append(interface(fe, np.flatnonzero(np.abs(d - flange.hole_radius) < _TOL), f"bolt{k}"))
        return out
    return [interface(fe, np.flatnonzero(np.abs(z - z.min()) < _TOL), "end_min"),
            interface(fe, np.flatnonzero(np.abs(z - z.max()) < _TOL), "end_max")]


def component_reduced_body(spec: GearboxSpec, component: str, level: str = "coarse",
                           progress: bool = False) -> ReducedBody:
    """The reduced flexible body of a component (cached): ``component`` as in Table 3 or the geometry."""
    from flexgear.flexible import cached_reduced_body

    name = COMPONENT_GEOMETRY[component]
    mesh_settings = spec.meshing_assumed[level]
    red = spec.reduction_assumed
    key = geometry_hash(spec, name, mesh_settings, red.fixed_interface_modes, red.interface,
                        red.simulation_modes, _REDUCTION_VERSION)

    def build() -> ReducedBody:
        from flexgear.fem import fe_model
        from flexgear.meshing import component_mesh

        if progress:
            print(f"[flexgear] building reduced body of {name} ({level} mesh) ...", flush=True)
        # first-order mesh topology; fe_model raises the order itself (a second-order Netgen mesh loaded
        # as is carries its mid-edge points as unconnected vertices: a singular stiffness matrix)
        mesh = component_mesh(spec, name, level, order=1, progress=progress)
        fe = fe_model(mesh.ngsolve_mesh(), spec.material_assumed, mesh_settings.element_order)
        return reduce(fe, component_interfaces(fe, spec, name), red.fixed_interface_modes, kind=red.interface,
                      n_compare=0, keep_modes=red.simulation_modes)

    return cached_reduced_body(f"{name}-{level}-{key}", build)
