"""OpenCascade solids (netgen.occ) of every component, built from its prism layout.

- A toothed transverse section becomes a planar face whose edges are the exact curves of
  flexgear.profile: splines through ``flank_points`` roll-angle points for the involutes, circular
  arcs for tips, fillets and roots.
- A helical prism sweeps that face along the axis with an auxiliary helical spine
  (``occ.Pipe(spine, face, auxspine=helix)``), which turns the section at the rate of the
  prism's twist; netgen.occ's ``twist`` argument is not implemented. ``Pipe`` fails on faces
  with holes, so bores, rims and bolt holes are made by 3D booleans: the external gear is the
  swept outline minus the bore cylinder, the ring half is the rim cylinder minus the swept
  outline (the "plug" of its tooth spaces).
- The prisms of one component are fused into one solid, whose exact volume integrals
  (``shape.mass``, ``center``, ``inertia``) check the section integrals of flexgear.geometry.

Lengths in metres. Solids are cached as ``.brep`` files by flexgear.meshing.
"""

from __future__ import annotations

import math

import netgen.occ as occ
import numpy as np

from flexgear.geometry import ComponentLayout, Section, component_layout
from flexgear.profile import ArcSegment, InvoluteSegment, ToothProfile, _mirror
from flexgear.spec import GearboxSpec

__all__ = ["section_face", "component_solid", "occ_mass_properties"]

_OVERLAP = 1e-3
"""Axial overlap [m] of construction solids where there is no material to change (avoids coplanar booleans)."""


def _edge(seg, angle: float, z: float, flank_points: int):
    """OCC edge of one profile segment rotated by ``angle`` about the axis, in the plane z."""
    s = np.linspace(0, 1, flank_points) if isinstance(seg, InvoluteSegment) else np.array([0.0, 0.5, 1.0])
    c, si = math.cos(angle), math.sin(angle)
    pts = seg.points(s) @ np.array([[c, -si], [si, c]]).T
    p = [occ.Pnt(float(x), float(y), z) for x, y in pts]
    if isinstance(seg, InvoluteSegment):
        return occ.SplineInterpolation(p)
    if isinstance(seg, ArcSegment):
        return occ.ArcOfCircle(*p)
    return occ.Segment(p[0], p[2])


def section_face(profile: ToothProfile, z: float = 0.0, flank_points: int = 25):
    """Planar face bounded by the whole toothed outline of ``profile`` in the plane ``z``.

    One pitch, centred on a tooth: fillet, flank, full tip arc, flank, fillet, full root arc.
    """
    half = list(profile.half_pitch)
    tip, root = half[0], half[-1]
    full_tip = ArcSegment(0.0, 0.0, tip.radius, -tip.phi1, tip.phi1)
    full_root = ArcSegment(0.0, 0.0, root.radius, root.phi0, 2 * math.pi / profile.teeth - root.phi0)
    sides = half[1:-1]
    pitch = [_mirror(seg) for seg in reversed(sides)] + [full_tip] + sides + [full_root]
    edges = [_edge(seg, 2 * math.pi * k / profile.teeth, z, flank_points)
             for k in range(profile.teeth) for seg in pitch]
    return occ.Face(occ.Wire(edges))


def _cylinder(radius: float, z0: float, z1: float, x: float = 0.0, y: float = 0.0):
    return occ.Cylinder(occ.Pnt(x, y, z0), occ.Z, radius, z1 - z0)


def _helical_sweep(profile: ToothProfile, z0: float, z1: float, twist: float, flank_points: int,
                   helix_points: int = 16):
    """The toothed outline swept from z0 to z1 while turning by ``twist`` [rad/m] * z."""
    face = section_face(profile, z0, flank_points)
    face = face.Rotate(occ.Axis(occ.Pnt(0, 0, 0), occ.Z), math.degrees(twist * z0))
    spine = occ.Wire([occ.Segment(occ.Pnt(0, 0, z0), occ.Pnt(0, 0, z1))])
    if twist == 0.0:
        return occ.Pipe(spine, face)
    r_aux = 0.5 * profile.gear.base_radius
    zs = np.linspace(z0, z1, helix_points)
    helix = [occ.Pnt(r_aux * math.cos(twist * z), r_aux * math.sin(twist * z), float(z)) for z in zs]
    return occ.Pipe(spine, face, auxspine=occ.Wire([occ.SplineInterpolation(helix)]))


def _annulus(sec: Section, z0: float, z1: float):
    """Annulus prism (with its bolt holes): only simple solids, so the booleans are cheap."""
    solid = _cylinder(sec.outer, z0, z1)
    cutters = [_cylinder(sec.inner, z0 - _OVERLAP, z1 + _OVERLAP)] if sec.inner > 0 else []
    for x, y in sec.hole_centres():
        cutters.append(_cylinder(sec.hole_radius, z0 - _OVERLAP, z1 + _OVERLAP, float(x), float(y)))
    return solid - occ.Fuse(cutters) if len(cutters) > 1 else (solid - cutters[0] if cutters else solid)


def _fuse(solids: list):
    return solids[0] if len(solids) == 1 else occ.Fuse(solids)


def component_solid(spec: GearboxSpec | ComponentLayout, component: str | None = None, flank_points: int = 25):
    """One OCC solid of ``component`` in its component frame (see flexgear.geometry).

    Few booleans touch the toothed sweeps (they are the slow ones), and none has coplanar faces:
    external gear = (sweeps + groove core reaching ``_OVERLAP`` into the sweeps) - bore;
    ring = (rim cylinder + flange with holes) - tooth-space plugs (reaching ``_OVERLAP`` into the
    groove and the flange bore, where there is no material) - groove.
    """
    layout = spec if isinstance(spec, ComponentLayout) else component_layout(spec, component)
    toothed = [p for p in layout.prisms if p.section.gear is not None]
    plain = [p for p in layout.prisms if p.section.gear is None]
    if not toothed:
        return _fuse([_annulus(p.section, p.z0, p.z1) for p in plain])
    if layout.gear.internal and any(p.section.inner <= layout.gear.root_radius for p in plain):
        raise ValueError("ring: relief_groove_depth_mm must be > 0 (groove and flange bore beyond the tooth root)")
    z_lo, z_hi = min(p.z0 for p in toothed), max(p.z1 for p in toothed)
    if not layout.gear.internal:
        parts = [_helical_sweep(layout.profile, p.z0, p.z1, p.twist, flank_points) for p in toothed]
        parts += [_cylinder(p.section.outer, p.z0 - _OVERLAP, p.z1 + _OVERLAP) for p in plain]
        return _fuse(parts) - _cylinder(toothed[0].section.inner, z_lo - _OVERLAP, z_hi + _OVERLAP)
    body_z = [p for p in plain if z_lo <= p.z0 and p.z1 <= z_hi]  # the groove
    others = [p for p in plain if p not in body_z]  # the flange
    solid = _fuse([_cylinder(toothed[0].section.outer, z_lo, z_hi)] + [_annulus(p.section, p.z0, p.z1) for p in others])
    for p in toothed:
        solid = solid - _helical_sweep(layout.profile, p.z0 - _OVERLAP, p.z1 + _OVERLAP, p.twist, flank_points)
    for p in body_z:
        solid = solid - _cylinder(p.section.inner, p.z0, p.z1)
    return solid


def occ_mass_properties(shape, density: float) -> tuple[float, np.ndarray, np.ndarray]:
    """Exact (OCC) mass [kg], centre of mass [m] and inertia about it [kg m^2] of a solid."""
    c = shape.center
    inertia = np.array([[shape.inertia[i, j] for j in range(3)] for i in range(3)]) \
        if not isinstance(shape.inertia, np.ndarray) else shape.inertia
    return density * shape.mass, np.array([c.x, c.y, c.z]), density * np.asarray(inertia, float)
