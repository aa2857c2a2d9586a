"""Small stand-in flexible bodies for fast tests: plain annuli instead of the toothed gears.

Sun and planet: bore to reference radius; ring: reference radius to root + 8 mm. Coarse first-order
meshes (a few hundred nodes, about a second each) with the bore as the RBE3 interface "bore"; the ring's
interface "bolt_patches" as the gearbox's joint expects (flexgear.fe.reduced.gear_shaft_joints): one patch per
bolt on its outer surface, centred at the bolt's angle, as wide as its clamped disc, all patches one rigid
interface. The shafts' stand-ins serve rigid shafts (their mass properties): a flexible shaft, and so the tied
ring and output shaft, has none.
They exercise the flexible-gear machinery; the real components come from
flexgear.fe.reduced.component_reduced_body.
"""

from functools import cache

import numpy as np

from flexgear.geometry.involute import gear_set_geometry


@cache
def _annulus(r_in: float, r_out: float, width: float, interface_outer: bool, material, modes: int,
             name: str, bolts: int, patch_half_width: float):
    """Reduced annulus with one interface ``name`` on its outer (``interface_outer``) or inner surface: the whole
    surface (RBE3), or with ``bolts`` > 0 the union of one patch per bolt, rigid."""
    import ngsolve as ngs
    from netgen.occ import Cylinder, OCCGeometry, Pnt, Z

    from flexgear.fe.cms import interface, reduce
    from flexgear.fe.fem import fe_model

    solid = Cylinder(Pnt(0, 0, -width / 2), Z, r=r_out, h=width) - Cylinder(Pnt(0, 0, -width / 2), Z, r=r_in, h=width)
    fe = fe_model(ngs.Mesh(OCCGeometry(solid).GenerateMesh(maxh=0.008)), material, 1)
    r = np.hypot(fe.nodes[:, 0], fe.nodes[:, 1])
    radius = r_out if interface_outer else r_in
    sel = np.flatnonzero(np.abs(r - radius) < 1e-6)
    if bolts == 0:
        body = reduce(fe, [interface(fe, sel, name)], 20, n_compare=0)
        return body.truncated(modes) if modes else body
    angle = np.arctan2(fe.nodes[sel, 1], fe.nodes[sel, 0])
    nearest = np.round(angle / (2 * np.pi) * bolts) % bolts
    off = np.angle(np.exp(1j * (angle - 2 * np.pi * nearest / bolts)))  # from the nearest bolt's angle
    patches = sel[np.abs(off) * radius <= patch_half_width]
    body = reduce(fe, [interface(fe, patches, name)], 20, n_compare=0, rigid=(name,))
    return body.truncated(modes) if modes else body


def annulus_source(spec, component: str, level: str):
    """A ``reduced_source`` for flexgear.mbs.gearbox.build_star_gearbox: sun, planet and ring; the shafts for
    their mass properties."""
    from flexgear.fe.reduced import BOLT_PATCHES

    geo = gear_set_geometry(spec)
    half = spec.joints_assumed.bolt_clamp_diameter_mm * 0.5e-3
    width = spec.gears_assumed.face_width_m + spec.gears_assumed.half_gap_m
    modes = 0  # the whole basis
    if component == "ring":
        return _annulus(geo.ring.reference_radius, geo.ring.root_radius + 0.008, width, True,
                        spec.material_assumed, modes, BOLT_PATCHES, spec.components_assumed.ring_bolt_count, half)
    if component in ("sun", "planet"):
        gear = geo.sun if component == "sun" else geo.planet
        bore = getattr(spec.components_assumed, f"{component}_bore_diameter_mm") * 0.5e-3
        return _annulus(bore, gear.reference_radius, width, False, spec.material_assumed, modes, "bore", 0, half)
    # shafts: their mass properties for the rigid shafts (a flexible shaft would also need its bearing seat)
    c = spec.components_assumed
    outer = getattr(c, f"{component}_outer_diameter_mm") * 0.5e-3
    inner = getattr(c, f"{component}_inner_diameter_mm") * 0.5e-3
    length = getattr(c, f"{component}_length_mm") * 1e-3
    if component == "input_shaft":
        return _annulus(inner, outer, length, False, spec.material_assumed, modes, "sun_seat", 0, half)
    return _annulus(inner, outer, length, False, spec.material_assumed, modes, BOLT_PATCHES, c.ring_bolt_count, half)


STANDIN_ASYMMETRY_TOLERANCE = 3e-3
"""The coarse stand-in annuli are axisymmetric only to about 1.5e-3 (their tetrahedral meshes): the linear frames
(flexgear.mbs.bodies.add_linear_frame) drop that asymmetry, twice of it is accepted for them."""


def standin_frames(gearbox):
    """``gearbox`` whose linear frames accept the stand-in annuli's mesh asymmetry (STANDIN_ASYMMETRY_TOLERANCE)."""
    return gearbox.with_fields("solver_assumed", frame_axisymmetry_tolerance=STANDIN_ASYMMETRY_TOLERANCE)
