"""Small stand-in flexible bodies for fast tests: plain annuli instead of the toothed gears.

Sun and planet: bore to reference radius; ring: reference radius to root + 8 mm. Coarse first-order
meshes (a few hundred nodes, about a second each) with the bore (ring: outer surface) as the RBE3
interface, named as the gearbox's joints expect (flexgear.fe.reduced.gear_shaft_joints: one rigid patch per
bolt on the ring's and output shaft's interface surface, centred at the bolt's angle, as wide as its clamped
disc).
They exercise the flexible-gear machinery; the real components come from
flexgear.fe.reduced.component_reduced_body.
"""

from functools import cache

import numpy as np

from flexgear.geometry.involute import gear_set_geometry


@cache
def _annulus(r_in: float, r_out: float, width: float, interface_outer: bool, material, modes: int,
             names: tuple[str, ...], patch_half_width: float, rigid: bool):
    import ngsolve as ngs
    from netgen.occ import Cylinder, OCCGeometry, Pnt, Z

    from flexgear.fe.cms import interface, reduce
    from flexgear.fe.fem import fe_model

    solid = Cylinder(Pnt(0, 0, -width / 2), Z, r=r_out, h=width) - Cylinder(Pnt(0, 0, -width / 2), Z, r=r_in, h=width)
    fe = fe_model(ngs.Mesh(OCCGeometry(solid).GenerateMesh(maxh=0.008)), material, 1)
    r = np.hypot(fe.nodes[:, 0], fe.nodes[:, 1])
    radius = r_out if interface_outer else r_in
    sel = np.flatnonzero(np.abs(r - radius) < 1e-6)
    if len(names) == 1:
        return reduce(fe, [interface(fe, sel, names[0])], 20, n_compare=0, keep_modes=modes or None)
    angle = np.arctan2(fe.nodes[sel, 1], fe.nodes[sel, 0])
    itfs = []
    nearest = np.round(angle / (2 * np.pi) * len(names)) % len(names)
    for k, name in enumerate(names):  # bolt k at 2 pi k / n: its nearest nodes within the patch's half-width
        off = np.angle(np.exp(1j * (angle - 2 * np.pi * k / len(names))))
        itfs.append(interface(fe, sel[(nearest == k) & (np.abs(off) * radius <= patch_half_width)], name))
    return reduce(fe, itfs, 20, n_compare=0, keep_modes=modes or None, rigid=names if rigid else ())


def annulus_source(spec, component: str, level: str):
    """A ``reduced_source`` for flexgear.mbs.gearbox.build_star_gearbox."""
    from flexgear.fe.reduced import gear_shaft_joints

    geo = gear_set_geometry(spec)
    side = {"sun": 0, "input_shaft": 1, "ring": 0, "output_shaft": 1}
    pair = "sun" if component in ("sun", "input_shaft") else "ring"
    name = tuple(j[side[component]] for j in gear_shaft_joints(spec, pair)) if component in side else ("bore",)
    half = spec.joints_assumed.bolt_clamp_diameter_mm * 0.5e-3
    rigid = True  # rigid bolt patches, as flexgear.fe.reduced reduces them
    width = spec.gears_assumed.face_width_m + spec.gears_assumed.half_gap_m
    modes = 0  # the whole basis
    if component == "ring":
        return _annulus(geo.ring.reference_radius, geo.ring.root_radius + 0.008, width, True,
                        spec.material_assumed, modes, name, half, rigid)
    if component in ("sun", "planet"):
        gear = geo.sun if component == "sun" else geo.planet
        bore = getattr(spec.components_assumed, f"{component}_bore_diameter_mm") * 0.5e-3
        return _annulus(bore, gear.reference_radius, width, False, spec.material_assumed, modes, name, half, rigid)
    c = spec.components_assumed
    outer = getattr(c, f"{component}_outer_diameter_mm") * 0.5e-3
    inner = getattr(c, f"{component}_inner_diameter_mm") * 0.5e-3
    length = getattr(c, f"{component}_length_mm") * 1e-3
    return _annulus(inner, outer, length, False, spec.material_assumed, modes, name, half, rigid)


STANDIN_ASYMMETRY_TOLERANCE = 3e-3
"""The coarse stand-in annuli are axisymmetric only to about 1.5e-3 (their tetrahedral meshes): the linear frames
(flexgear.mbs.bodies.add_linear_frame) drop that asymmetry, twice of it is accepted for them."""


def standin_frames(gearbox):
    """``gearbox`` whose linear frames accept the stand-in annuli's mesh asymmetry (STANDIN_ASYMMETRY_TOLERANCE)."""
    return gearbox.with_fields("solver_assumed", frame_axisymmetry_tolerance=STANDIN_ASYMMETRY_TOLERANCE)
