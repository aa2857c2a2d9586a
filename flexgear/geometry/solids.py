"""OpenCascade solids (netgen.occ) of every component, built boundary-first from its prism layout.

- A toothed transverse section's outline is a wire of the exact curves of flexgear.geometry.profile:
  splines through ``flank_points`` roll-angle points for the involutes, circular arcs for tips,
  fillets and roots.
- A component is a stack of prisms (flexgear.geometry.layout). Its boundary is assembled face by face
  and sewn into one closed shell, with no 3D boolean on the toothed surfaces:

  - lateral faces of each boundary loop of the stack: for a toothed outline the lateral faces of
    a helical sweep of the outline wire (``occ.Pipe(spine, wire, auxspine=helix)``, an auxiliary
    helical spine turns the section at the prism's twist rate; netgen.occ's ``twist`` argument is
    not implemented), or of a straight extrusion of the section for spur teeth (twist 0: a sweep
    without auxiliary spine is a different OCC algorithm that leaves the ends open); one lateral
    face per outline curve (:func:`outline_edge_count`); a steep or long helix, or an outline with a
    curve shorter than 0.2 mm, is swept precisely: built in millimetres (OCC's approximation tolerance
    is absolute) and scaled back, in pieces of at most 0.5 rad of twist
    (:func:`flexgear.geometry.layout.helix_sweep`; the study's gears take one sweep in metres);
    for a circle one cylinder face per run of prisms with the same radius;
  - planar faces at both ends and wherever the section changes: the annulus between the two
    boundary loops that differ (e.g. toothed outline and relief-groove circle);
  - the lower half of a double helix is the mirror image (z -> -z) of the upper half (same lead,
    opposite hand), so only one sweep is computed.

  Only bolt holes are cut by booleans afterwards (analytic cylinders away from the teeth). The
  earlier construction (sweep the outline as a solid, then fuse/cut rims, grooves and bores)
  spent ~150 s in the ring's booleans: 136 x 6 swept B-spline faces intersected with planes.
- The solid's exact volume integrals (``shape.mass``, ``center``, ``inertia``) check the section
  integrals of flexgear.geometry.layout.

Lengths in metres. Solids are cached as ``.brep`` files by flexgear.fe.mesh.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import netgen.occ as occ
import numpy as np

from flexgear.geometry.layout import ComponentLayout, Prism, helix_sweep
from flexgear.geometry.profile import ArcSegment, InvoluteSegment, ToothProfile, mirror_segment

__all__ = [
    "FLANK_POINTS", "outline_edge_count", "section_face", "component_solid", "occ_mass_properties",
]

FLANK_POINTS = 25
"""Roll-angle points of the spline through each involute flank. Measured deviation of the OCC
spline from the exact involute: 25 points 0.006 um (planet, the worst gear), 10 points 0.12 um,
6 points 1.2 um; the tests require 1 um. Meshing time and element counts do not depend on it."""
_HELIX_POINTS = 16
"""Points of the spline through the auxiliary helix that steers the sweep (flank lead error of
the meshed sun/planet < 1e-5 relative, tests/test_geometry.py)."""
_OVERLAP = 1e-3
"""Axial overlap [m] of the bolt-hole cutters beyond their prism (no material there: no coplanar booleans)."""
_Z_TOL = 1e-12
"""Axial distance [m] below which two prism ends are the same plane."""
_SEW_TOL = 1e-7
"""Sewing tolerance [m]: coincident edges are shared exactly; only separately built circles need it."""


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


def _outline_pitch(profile: ToothProfile) -> list:
    """The curves of one pitch of the outline, centred on a tooth, one OCC edge each.

    Fillet, [radial line,] flank, full tip arc, flank, [radial line,] fillet, full root arc: the
    radial line below the base circle exists only where the fillet reaches below it (few teeth,
    negative shift) and the fillet only for a fillet radius > 0, so a pitch has 4 to 8 curves.
    """
    half = list(profile.half_pitch)
    tip, root = half[0], half[-1]
    full_tip = ArcSegment(0.0, 0.0, tip.radius, -tip.phi1, tip.phi1)
    full_root = ArcSegment(0.0, 0.0, root.radius, root.phi0, 2 * math.pi / profile.teeth - root.phi0)
    sides = half[1:-1]
    return [mirror_segment(seg) for seg in reversed(sides)] + [full_tip] + sides + [full_root]


def outline_edge_count(profile: ToothProfile) -> int:
    """Edges of the whole toothed outline wire: teeth x curves per pitch (the lateral faces of its prism)."""
    return profile.teeth * len(_outline_pitch(profile))


def section_face(profile: ToothProfile, z: float = 0.0, flank_points: int = FLANK_POINTS):
    """Planar face bounded by the whole toothed outline of ``profile`` in the plane ``z``.

    One pitch, centred on a tooth: fillet, flank, full tip arc, flank, fillet, full root arc
    (see :func:`_outline_pitch`), repeated ``teeth`` times.
    """
    pitch = _outline_pitch(profile)
    edges = [_edge(seg, 2 * math.pi * k / profile.teeth, z, flank_points)
             for k in range(profile.teeth) for seg in pitch]
    return occ.Face(occ.Wire(edges))


@dataclass(frozen=True)
class _Loop:
    """One boundary loop of a prism's section: a circle of ``radius`` or the toothed outline (radius None)."""

    radius: float | None
    twist: float = 0.0

    def same_at(self, other: _Loop | None, z: float) -> bool:
        """Whether ``other`` is the same curve in the plane z (then no planar face separates them)."""
        if other is None or (self.radius is None) != (other.radius is None):
            return False
        if self.radius is not None:
            return abs(self.radius - other.radius) < _Z_TOL
        return abs((self.twist - other.twist) * z) < 1e-12


def _loops(prism: Prism) -> tuple[_Loop | None, _Loop]:
    """(inner, outer) boundary loops of a prism's section; inner None for a full disc."""
    sec = prism.section
    if sec.gear == "ring":
        return _Loop(None, prism.twist), _Loop(sec.outer)
    if sec.gear is not None:
        return (_Loop(sec.inner) if sec.inner > 0 else None), _Loop(None, prism.twist)
    return (_Loop(sec.inner) if sec.inner > 0 else None), _Loop(sec.outer)


def _key(z: float) -> int:
    """Axial position as an integer key (units of 1e-12 m): prism ends computed differently still match."""
    return round(z / _Z_TOL)


def _flat(face) -> bool:
    lo, hi = face.bounding_box
    return hi.z - lo.z < 1e-6


class _Boundary:
    """Lateral faces of the stack and the end wires of each lateral run, keyed by (side, z)."""

    def __init__(self, layout: ComponentLayout, flank_points: int):
        self.layout, self.flank_points = layout, flank_points
        self.faces: list = []
        self.wires: dict[tuple[str, int, str], object] = {}
        self._sweeps: dict[tuple[int, int, float], tuple[list, object, object]] = {}

    def add_run(self, side: str, loop: _Loop, z0: float, z1: float) -> None:
        if loop.radius is None:
            lateral, w0, w1 = self._toothed(z0, z1, loop.twist)
            self.faces += lateral
        else:
            cyl = occ.Cylinder(occ.Pnt(0, 0, z0), occ.Z, loop.radius, z1 - z0)
            mantle = next(f for f in cyl.faces if not _flat(f))
            self.faces.append(mantle)
            ends = {round(e.start.z, 12): e for e in mantle.edges if abs(e.start.z - e.end.z) < 1e-12}
            w0, w1 = occ.Wire([ends[round(z0, 12)]]), occ.Wire([ends[round(z1, 12)]])
        # a run's bottom wire is seen from the prism above the plane z0, its top wire from below z1
        self.wires[(side, _key(z0), "above")], self.wires[(side, _key(z1), "below")] = w0, w1

    def _toothed(self, z0: float, z1: float, twist: float) -> tuple[list, object, object]:
        """Lateral faces of the toothed outline swept from z0 to z1, and its end wires at z0, z1."""
        mirror = self._sweeps.get((_key(-z1), _key(-z0), -twist))
        if mirror is not None:  # the other half of a double helix: z -> -z of a computed sweep
            plane = occ.Axes(occ.Pnt(0, 0, 0), occ.Z, occ.X)
            lateral, w0, w1 = mirror
            out = ([f.Mirror(plane) for f in lateral], occ.Wire([w1.Mirror(plane)]), occ.Wire([w0.Mirror(plane)]))
        else:
            out = self._sweep(z0, z1, twist)
        self._sweeps[(_key(z0), _key(z1), twist)] = out
        return out

    def _sweep(self, z0: float, z1: float, twist: float) -> tuple[list, object, object]:
        """Lateral faces and end wires of the toothed outline from z0 to z1 at ``twist`` [rad/m].

        Spur teeth (twist 0) are a straight extrusion of the section face. Helical teeth are swept along the axis
        as :func:`flexgear.geometry.layout.helix_sweep` says: in one or more consecutive sweeps, each in metres
        or, precise, in millimetres and scaled back; in each an auxiliary helical spine, at radius r_b / 2, turns
        the section by ``twist * z``. The section at z0 is the outline rotated by ``twist * z0``; each further
        sweep starts from the previous one's end wire, so that neighbouring sweeps share their edges.
        """
        profile = self.layout.profile
        face = section_face(profile, z0, self.flank_points)
        expected = outline_edge_count(profile)
        if twist == 0.0:
            ends = [z0, z1]
            plugs = [face.Extrude(occ.Vec(0, 0, z1 - z0))]
        else:
            face = face.Rotate(occ.Axis(occ.Pnt(0, 0, 0), occ.Z), math.degrees(twist * z0))
            plan = helix_sweep(twist, z1 - z0, profile)
            ends = list(np.linspace(z0, z1, plan.pieces + 1))
            wire, plugs = face.wires[0], []
            for a, b in zip(ends[:-1], ends[1:], strict=True):
                plugs.append(self._pipe(wire, float(a), float(b), twist, plan.scale))
                wire = sorted((f for f in plugs[-1].faces if _flat(f)), key=lambda f: f.center.z)[-1].wires[0]
        lateral, bottom, top = [], None, None
        for (a, b), plug in zip(zip(ends[:-1], ends[1:], strict=True), plugs, strict=True):
            caps = sorted((f for f in plug.faces if _flat(f)), key=lambda f: f.center.z)
            sides = [f for f in plug.faces if not _flat(f)]
            if len(caps) != 2 or len(sides) != expected:
                kind = "extrusion" if twist == 0.0 else "helical sweep"
                raise RuntimeError(f"{kind} of the {profile.gear.teeth}-tooth outline from z = {a:.6g} to {b:.6g} m "
                                   f"gave {len(caps)} caps and {len(sides)} lateral faces (expected 2 and {expected})")
            lateral += sides
            bottom = bottom or caps[0].wires[0]
            top = caps[1].wires[0]
        return lateral, bottom, top

    def _pipe(self, wire, z0: float, z1: float, twist: float, scale: float = 1.0):
        """The closed sweep of ``wire`` (the outline in the plane z0) to z1, turned at ``twist`` [rad/m], built at
        ``scale`` (the wire, spine and helix scaled by it about the origin, the result scaled back)."""
        origin = occ.Pnt(0, 0, 0)
        if scale != 1.0:
            wire = wire.Scale(origin, scale)
        spine = occ.Wire([occ.Segment(occ.Pnt(0, 0, scale * z0), occ.Pnt(0, 0, scale * z1))])
        r_aux = 0.5 * self.layout.profile.gear.base_radius * scale
        helix = [occ.Pnt(r_aux * math.cos(twist * z), r_aux * math.sin(twist * z), float(scale * z))
                 for z in np.linspace(z0, z1, _HELIX_POINTS)]
        # netgen's Pipe with an auxiliary spine closes the ends (MakeSolid): the caps' wires are the sweep's own
        # edges
        plug = occ.Pipe(spine, wire, auxspine=occ.Wire([occ.SplineInterpolation(helix)]))
        return plug if scale == 1.0 else plug.Scale(origin, 1.0 / scale)


def _band(loop: _Loop | None, layout: ComponentLayout) -> tuple[float, float]:
    """Radial extent [m] of a loop (a point for a circle, tip..root band for the teeth)."""
    if loop is None:
        return 0.0, 0.0
    if loop.radius is not None:
        return loop.radius, loop.radius
    g = layout.gear
    return min(g.tip_radius, g.root_radius), max(g.tip_radius, g.root_radius)


def _annulus_face(outer_wire, inner_wire=None):
    """Planar face inside ``outer_wire`` and outside ``inner_wire`` (any orientation of either)."""
    disc = occ.Face(outer_wire)
    if inner_wire is None:
        return disc
    face = occ.Face(disc, [disc.wires[0], inner_wire.Reversed()])
    if face.mass > disc.mass:  # the hole was taken with the wrong sense: area added instead of removed
        face = occ.Face(disc, [disc.wires[0], inner_wire])
    return face


def _planar_faces(boundary: _Boundary, z: float, below: Prism | None, above: Prism | None) -> list:
    """Faces in the plane z between the sections below and above (symmetric difference)."""
    layout = boundary.layout
    if below is None or above is None:
        inner, outer = _loops(above if below is None else below)
        where = "above" if below is None else "below"
        pairs = [((inner, "inner", where), (outer, "outer", where))]
    else:
        (ib, ob), (ia, oa) = _loops(below), _loops(above)
        if _band(ia, layout)[1] >= _band(ob, layout)[0] or _band(ib, layout)[1] >= _band(oa, layout)[0]:
            raise ValueError(f"{layout.name}: prisms {below.name!r} and {above.name!r} do not overlap at z = {z} m")
        pairs = []
        for lb, la, side in ((ib, ia, "inner"), (ob, oa, "outer")):
            if (lb is None and la is None) or (lb is not None and lb.same_at(la, z)):
                continue
            lo, hi = sorted(((lb, side, "below"), (la, side, "above")), key=lambda t: _band(t[0], layout)[0])
            if lo[0] is not None and _band(lo[0], layout)[1] >= _band(hi[0], layout)[0]:
                raise ValueError(f"{layout.name}: {side} boundaries of {below.name!r} and {above.name!r} cross")
            pairs.append((lo, hi))
    faces = []
    for (inner, inner_side, inner_where), (_, outer_side, outer_where) in pairs:
        inner_wire = None if inner is None else boundary.wires[(inner_side, _key(z), inner_where)]
        faces.append(_annulus_face(boundary.wires[(outer_side, _key(z), outer_where)], inner_wire))
    return faces


def _runs(prisms: list[Prism], side: int) -> list[tuple[_Loop, float, float]]:
    """Maximal runs of consecutive prisms with the same circle on ``side`` (0 inner, 1 outer); a
    toothed loop is a run of its own (one sweep per prism)."""
    runs: list[tuple[_Loop, float, float]] = []
    for p in prisms:
        loop = _loops(p)[side]
        if loop is None:
            continue
        if runs and loop.radius is not None and loop.same_at(runs[-1][0], p.z0) and abs(runs[-1][2] - p.z0) < _Z_TOL:
            runs[-1] = (runs[-1][0], runs[-1][1], p.z1)
        else:
            runs.append((loop, p.z0, p.z1))
    return runs


def _holes(solid, prisms: list[Prism]):
    """The solid with the bolt holes of every prism cut through it."""
    cutters = [occ.Cylinder(occ.Pnt(float(x), float(y), p.z0 - _OVERLAP), occ.Z, p.section.hole_radius,
                            p.length + 2 * _OVERLAP)
               for p in prisms for x, y in p.section.hole_centres()]
    if not cutters:
        return solid
    return solid - (occ.Fuse(cutters) if len(cutters) > 1 else cutters[0])


def component_solid(layout: ComponentLayout, flank_points: int = FLANK_POINTS):
    """One OCC solid of a component's ``layout`` in its component frame (see flexgear.geometry.layout).

    The prisms of the layout must stack along z without gaps; consecutive sections must overlap
    radially and their differing boundaries must not cross (ValueError otherwise).
    """
    prisms = sorted(layout.prisms, key=lambda p: p.z0)
    pairs = list(zip(prisms[:-1], prisms[1:], strict=True))
    for a, b in pairs:
        if abs(a.z1 - b.z0) > _Z_TOL:
            raise ValueError(f"{layout.name}: prisms {a.name!r} and {b.name!r} leave a gap or overlap along z")
    boundary = _Boundary(layout, flank_points)
    for side, name in ((0, "inner"), (1, "outer")):
        for loop, z0, z1 in _runs(prisms, side):
            boundary.add_run(name, loop, z0, z1)
    faces = list(boundary.faces)
    levels = [(prisms[0].z0, None, prisms[0])] + [(b.z0, a, b) for a, b in pairs] + [(prisms[-1].z1, prisms[-1], None)]
    for z, below, above in levels:
        faces += _planar_faces(boundary, z, below, above)
    sewn = occ.Sew(faces, tolerance=_SEW_TOL)
    if sewn.type != occ.SHELL or len(sewn.faces) != len(faces):
        raise RuntimeError(f"{layout.name}: sewing {len(faces)} faces gave {sewn.type} with {len(sewn.faces)} faces")
    solid = occ.Solid(sewn)
    if solid.mass < 0:  # shell oriented inwards
        solid = occ.Solid(sewn.Reversed())
    return _holes(solid, [p for p in prisms if p.section.holes])


def occ_mass_properties(shape, density: float) -> tuple[float, np.ndarray, np.ndarray]:
    """Exact (OCC) mass [kg], centre of mass [m] and inertia about it [kg m^2] of a solid."""
    # each property is one volume integration of the whole solid: read every one once
    c, mass, inertia = shape.center, shape.mass, shape.inertia
    if not isinstance(inertia, np.ndarray):
        inertia = np.array([[inertia[i, j] for j in range(3)] for i in range(3)])
    return density * mass, np.array([c.x, c.y, c.z]), density * np.asarray(inertia, float)
