"""A single toothed gear body, rigid or reduced flexible, built by the study's own pipeline.

Any gear of a set (flexgear.geometry.gear_body.GearBody: external or internal, spur or helical, single or double
helix, with its bore or rim and its seat) goes through the stages that build the study's sun, planets and ring:

1. its layout (flexgear.geometry.layout.toothed_prisms) -> OCC solid (flexgear.geometry.solids.component_solid),
   cached as ``solid-<name>-<key>.brep``;
2. Netgen mesh at the body's sizes (flexgear.fe.mesh.source_mesh: tooth size on the tooth faces, body size
   elsewhere; first order meshed, second order raised from it; cached as ``mesh-<name>-toothed-o<order>-<key>``,
   the FE stages reading the stored files);
3. FE model of the body's element order on the first-order topology (flexgear.fe.fem.fe_model);
4. Craig-Bampton reduction (flexgear.fe.cms.reduce): one distributing (RBE3) seat interface, ``"bore"`` for an
   external gear (its bore over ``seat_width``), ``"rim"`` for an internal one (the rim's outer surface); every
   fixed-interface mode below ``cutoff_hz``; attachment modes of the contact bands of the body's engagements
   (flexgear.geometry.gear_body.Engagement), one load circle per mesh and helix half at the operating pitch radius
   along the tooth normal, band one normal module (flexgear.fe.reduced.band_circles, as the study's gears), up to
   harmonic ``attachment_order``; cached as ``reduced-v1-<name>-<key>.npz`` (flexgear.fe.reduced.cached_reduced_body).

In the multibody model the body is added with flexgear.mbs.flexible.add_flexible_body; the modes above a dynamic
cut-off leave the time integration and return as the residual compliance in series with the contact law
(flexgear.mbs.residual.dropped_modes with the body's name as its geometry: an external gear's seat is its
"bore", as the study's sun and planets). A rigid body takes :func:`toothed_mass_properties`: the exact section
integrals, or the mesh's (those of the reduced body).

Keys hash every field of the body that the stage depends on, the construction versions of the layout (with its
helix sweeps, flexgear.geometry.layout.helix_sweep) and of the meshing, and the reduction settings.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from flexgear.fe.attachment import LoadCircle
from flexgear.fe.cms import Interface, ReducedBody, interface, reduce
from flexgear.fe.fem import FEModel
from flexgear.fe.mesh import GRADING, MESH_VERSION, ComponentMesh, MeshSizes, MeshSource, layout_regions, source_mesh
from flexgear.fe.reduced import band_circles, cached_reduced_body
from flexgear.geometry.contact_lines import mesh_contact_geometry
from flexgear.geometry.gear_body import Engagement, GearBody
from flexgear.geometry.layout import GEOMETRY_VERSION, helix_sweep
from flexgear.geometry.massprops import MassProperties
from flexgear.progress import say
from flexgear.spec import spec_hash

__all__ = ["SEAT", "LEVEL", "toothed_mesh", "toothed_fe_model", "toothed_interfaces", "toothed_load_circles",
           "toothed_contacts", "toothed_body", "toothed_mass_properties"]

SEAT = {False: "bore", True: "rim"}
"""Name of the seat interface of an external (False) and an internal (True) gear body."""
LEVEL = "toothed"
"""Mesh level label of a gear body's cache files."""
_TOL = 1e-6  # m: nodes on an exact cylinder of the OCC geometry (as flexgear.fe.reduced)
_INTERFACE_KIND = "rbe3"  # the seat: a distributing average, as the study's bores
_TOOTHED_VERSION = 1  # bump when this module's construction changes without a body field changing
_MESH_FIELDS = ("material", "seat_width", "tooth_mesh_size", "body_mesh_size", "element_order",
                "elements_per_curvature_radius", "optimisation_steps", "name")
"""Fields of a GearBody that do not change its solid."""


def _solid_key(body: GearBody) -> str:
    """Hash of what the body's solid is made of: its geometric fields, the layout's construction version and the
    helix sweeps of its toothed prisms."""
    layout = body.layout()
    sweeps = [dataclasses.astuple(helix_sweep(p.twist, p.length, layout.profile))
              for p in layout.prisms if p.section.gear is not None and p.twist != 0.0]
    geometry = {f.name: getattr(body, f.name) for f in dataclasses.fields(body) if f.name not in _MESH_FIELDS}
    return spec_hash(geometry, "toothed solid", GEOMETRY_VERSION, _TOOTHED_VERSION, sweeps)


def _source(body: GearBody) -> MeshSource:
    sizes = MeshSizes(body.tooth_mesh_size, body.body_mesh_size, body.elements_per_curvature_radius,
                      body.optimisation_steps)
    solid = _solid_key(body)
    layout = body.layout()
    return MeshSource(layout, LEVEL, sizes, body.element_order, solid,
                      lambda order: spec_hash(solid, sizes, order, GRADING, MESH_VERSION),
                      lambda nodes, boundary: layout_regions(layout, nodes, boundary))


def toothed_mesh(body: GearBody, order: int | None = None, progress: bool = False) -> ComponentMesh:
    """The (cached) tetrahedral mesh of ``body`` (element ``order``, default the body's): nodes [m], elements,
    boundary triangles, regions ``flanks`` (between form and tip radius) and, external, ``bore``."""
    return source_mesh(_source(body), body.element_order if order is None else order, progress)


def toothed_fe_model(body: GearBody, progress: bool = False) -> FEModel:
    """The FE model of ``body`` that :func:`toothed_body` reduces: its element order on the cached first-order
    mesh topology (as flexgear.fe.reduced builds every study body)."""
    from flexgear.fe.fem import fe_model

    return fe_model(toothed_mesh(body, 1, progress).ngsolve_mesh(), body.material, body.element_order)


def toothed_interfaces(fe: FEModel, body: GearBody) -> list[Interface]:
    """The seat interface of ``body``'s FE model ``fe``: the nodes on the bore (external; :data:`SEAT` "bore") or on
    the rim's outer surface (internal; "rim") within ``seat_width`` / 2 of the mid-plane (None: all of them)."""
    on = np.abs(np.hypot(fe.nodes[:, 0], fe.nodes[:, 1]) - body.seat_radius) < _TOL
    if body.seat_width is not None:
        on &= np.abs(fe.nodes[:, 2]) < body.seat_width / 2 + _TOL
    return [interface(fe, np.flatnonzero(on), SEAT[body.internal])]


def _check(body: GearBody, engagement: Engagement) -> None:
    g, b = engagement.gear_of(), body.gear
    same = (g.teeth == b.teeth and g.internal == b.internal
            and all(math.isclose(getattr(g, f), getattr(b, f), rel_tol=1e-12, abs_tol=1e-15)
                    for f in ("normal_module", "helix_angle", "normal_pressure_angle", "shift")))
    if not same:
        raise ValueError(f"engagement: gear {engagement.gear} of the mesh ({g.teeth} teeth, internal {g.internal}, "
                         f"m_n {g.normal_module} m, shift {g.shift}) is not the body's gear ({b.teeth} teeth, "
                         f"internal {b.internal}, m_n {b.normal_module} m, shift {b.shift})")


def _bands(body: GearBody, engagements: Sequence[Engagement]) -> list[tuple[LoadCircle, tuple[float, ...]]]:
    """(load circle of order 0, contact angles [rad]) per engagement and helix half."""
    out = []
    for e in engagements:
        _check(body, e)
        contact = mesh_contact_geometry(e.mesh, body.helix_layout, body.helix_width, body.half_gap,
                                        e.first_hand(body), 0)
        out += [(c, e.angles) for c in band_circles(contact, e.drive_sign, e.gear == 1, body.normal_module)]
    return out


def toothed_load_circles(body: GearBody, engagements: Sequence[Engagement], order: int) -> list[LoadCircle]:
    """Load circles of harmonic ``order`` on ``body``'s contact bands, one per engagement and helix half ([] for
    order 0): the attachment modes' loads, and the contact kernel's (flexgear.fe.compliance)."""
    if order == 0:
        return []
    return [dataclasses.replace(c, order=order) for c, _ in _bands(body, engagements)]


def toothed_contacts(body: GearBody, engagements: Sequence[Engagement]) -> tuple[np.ndarray, np.ndarray]:
    """Contact points (p, 3) [m] at the operating pitch radius in each helix half's mid-plane and their tooth
    normals (p, 3), in the body frame, per engagement, helix half and contact angle."""
    points, normals = [], []
    for circle, angles in _bands(body, engagements):
        z = 0.5 * (circle.z_min_m + circle.z_max_m)
        d = circle.direction
        for a in angles:
            e_r, e_t = np.array([math.cos(a), math.sin(a), 0.0]), np.array([-math.sin(a), math.cos(a), 0.0])
            points.append(circle.radius_m * e_r + [0.0, 0.0, z])
            normals.append(d[0] * e_r + d[1] * e_t + [0.0, 0.0, d[2]])
    return np.array(points).reshape(-1, 3), np.array(normals).reshape(-1, 3)


def toothed_body(body: GearBody, engagements: Sequence[Engagement] = (), *, cutoff_hz: float,
                 attachment_order: int = 8, n_compare: int = 0, fe: FEModel | None = None,
                 progress: bool = False) -> ReducedBody:
    """The reduced flexible body of ``body`` (cached; module docstring): Craig-Bampton on its seat interface with
    every fixed-interface mode below ``cutoff_hz`` [Hz] and the attachment modes of its ``engagements``' contact
    bands to harmonic ``attachment_order`` (the study: 3.5 x the mesh frequency, order 8). ``n_compare``: lowest
    free-free frequencies of the full FE model stored beside the body's (``full_frequencies_hz``; 0: none).
    ``fe``: the body's FE model if already made (:func:`toothed_fe_model`). Frame: the gear's centre on its axial
    mid-plane, z the axis."""
    if not cutoff_hz > 0:
        raise ValueError(f"toothed_body: cutoff_hz must be > 0, got {cutoff_hz!r}")
    circles = toothed_load_circles(body, engagements, attachment_order)
    source = _source(body)
    key = spec_hash(source.mesh_key(1), body.material, body.element_order, body.seat_width, cutoff_hz,
                    _INTERFACE_KIND, [c.key() for c in circles], n_compare, _TOOTHED_VERSION)

    def build() -> ReducedBody:
        if progress:
            say(f"  {body.name}: building the reduced body (order-{body.element_order} FE model on the first-order "
                "mesh topology)")
        model = toothed_fe_model(body, progress) if fe is None else fe
        return reduce(model, toothed_interfaces(model, body), kind=_INTERFACE_KIND, n_compare=n_compare,
                      load_circles=circles, max_hz=cutoff_hz)

    return cached_reduced_body(f"{body.name}-{key}", build)


def toothed_mass_properties(body: GearBody, source: str = "exact") -> MassProperties:
    """Mass [kg], centre of mass [m] and inertia about it [kg m^2] of ``body`` as a rigid body, in the frame of
    :func:`toothed_body`: ``source`` "exact" from the section integrals (GearBody.mass_properties), "mesh" those of
    its FE model (the reduced body's, so that rigid and flexible twins are identical)."""
    if source == "exact":
        return body.mass_properties()
    if source == "mesh":
        return toothed_fe_model(body).mass_properties()
    raise ValueError(f"toothed_mass_properties: source must be 'exact' or 'mesh', got {source!r}")
