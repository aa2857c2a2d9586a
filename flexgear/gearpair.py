"""Any gear pair, external or internal, at any centre positions: geometry and gear contacts.

Geometry (ISO 21771, as flexgear.involute): :func:`gear_pair_geometry` gives the :class:`Mesh` of
two gears from their parameters, either from both profile shifts (the no-backlash operating
centre distance follows) or from one shift and a required centre distance (the other shift follows):

    inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2),   z2 < 0 for an internal gear
    a_w = a_0 cos(alpha_t) / cos(alpha_wt),  a_0 = m_n |z1 + z2| / (2 cos beta)

Contacts (:func:`pair_contacts`): gear 1 is external; gear 2 external or internal. With the unit
vector e in the transverse plane (external: from centre 1 to centre 2; internal: from centre 2 to
centre 1), the pitch point is X = c1 + r_w1 e (r_w1 = a z1 / (z2 +/- z1)), the transverse line of
action t = sin(alpha_wt) e + s cos(alpha_wt) (e_z x e) and the tooth normal (force on gear 2)

    n = cos(beta_b) t - h s sin(beta_b) e_z,

where s = +1 when gear 1 pushes gear 2 counter-clockwise about +z (``drive_sign``) and h the hand of
gear 1 in the helix half (+1 right: the tooth line advances counter-clockwise seen from +z as z
grows; -1 left). Gear 2 has the opposite hand (external) or the same hand (internal). One
:class:`flexgear.connectors.GearContact` per helix half ("single": one; "double": two halves of
opposite hand at z = +/-(b_h + gap)/2, each half the face width).
"""

from __future__ import annotations

import math

import numpy as np

from flexgear.connectors import ContactLaw, GearContact, contact_gradients
from flexgear.involute import (
    Gear,
    HelixHalf,
    Mesh,
    PeriodicSeries,
    contact_line_series,
    helix_halves,
    inv,
    inv_inverse,
    tooth_normal_local,
    transverse_pressure_angle,
)
from flexgear.massprops import MassProperties
from flexgear.spec import Contact, ContactAssumed

__all__ = ["HelixHalf", "helix_halves", "gear_pair_geometry", "pair_contacts", "annulus_mass_properties"]

_EZ = np.array([0.0, 0.0, 1.0])


def gear_pair_geometry(z1: int, z2: int, normal_module: float, helix_angle: float, pressure_angle: float,
                       face_width: float, shifts: tuple[float, float] = (0.0, 0.0), internal: bool = False,
                       centre_distance: float | None = None, normal_backlash: float = 0.0,
                       addendum_coefficient: float = 1.0, dedendum_coefficient: float = 1.25) -> Mesh:
    """The mesh of gear 1 (external, z1 teeth) with gear 2 (z2 teeth, ``internal`` or not).

    SI units: module, face width (total, both helix halves), centre distance and backlash in m; helix
    and normal pressure angle in rad. ``shifts`` = (x1, x2) profile-shift coefficients. With
    ``centre_distance`` given, x2 is solved from it (``shifts[1]`` is ignored). The backlash is made
    by thinning both gears' teeth by j_n / (2 cos alpha_n) each.
    """
    for label, z in (("z1", z1), ("z2", z2)):
        if not (isinstance(z, (int, np.integer)) and z >= 3):
            raise ValueError(f"{label} must be an integer >= 3, got {z!r}")
    if internal and z2 - z1 < 3:
        raise ValueError(f"an internal gear needs more teeth than its pinion (z2 - z1 >= 3), got {z1}, {z2}")
    if not (normal_module > 0 and face_width > 0 and 0 <= helix_angle < math.pi / 2 and 0 < pressure_angle < 0.6):
        raise ValueError("normal_module and face_width must be > 0 [m], helix_angle in [0, pi/2) and "
                         f"pressure_angle in (0, 0.6) [rad]; got {normal_module}, {face_width}, {helix_angle}, "
                         f"{pressure_angle}")
    signed = -z2 if internal else z2
    alpha_t = transverse_pressure_angle(pressure_angle, helix_angle)
    a0 = abs(normal_module / math.cos(helix_angle) * (z1 + signed) / 2)
    x1, x2 = shifts
    if centre_distance is None:
        alpha_w = inv_inverse(inv(alpha_t) + 2 * math.tan(pressure_angle) * (x1 + x2) / (z1 + signed))
        aw = a0 * math.cos(alpha_t) / math.cos(alpha_w)
    else:
        cos_w = a0 * math.cos(alpha_t) / centre_distance
        if not 0.0 < cos_w < 1.0:
            raise ValueError(f"centre_distance {centre_distance} m cannot be reached (a_0 = {a0} m)")
        aw, alpha_w = centre_distance, math.acos(cos_w)
        x2 = (inv(alpha_w) - inv(alpha_t)) * (z1 + signed) / (2 * math.tan(pressure_angle)) - x1
    thinning = normal_backlash / (2 * math.cos(pressure_angle))

    def gear(z: int, x: float, is_internal: bool) -> Gear:
        return Gear(int(z), is_internal, normal_module, helix_angle, pressure_angle, x, thinning,
                    addendum_coefficient, dedendum_coefficient, face_width)

    return Mesh(gear(z1, x1, False), gear(z2, x2, internal), aw, alpha_w)


def pair_contacts(name: str, body1: str, body2: str, mesh: Mesh, centre1, centre2, contact: Contact,
                  contact_assumed: ContactAssumed, *, helix_layout: str = "single", half_gap: float = 0.0,
                  hand: int = 1, drive_sign: float = 1.0, spins: tuple[float, float] | None = None,
                  carrier_spin: float = 0.0, phase_offset: float = 0.0,
                  phase_per_drive_angle: float | None = None) -> list[GearContact]:
    """Gear contacts (one per helix half) of ``mesh`` between bodies ``body1`` and ``body2``.

    ``centre1``/``centre2``: gear centres in the ground frame [m] at the reference configuration; their
    distance must be the mesh's operating centre distance. ``contact`` and ``contact_assumed``: the
    impact law, friction and stiffness variation (flexgear.spec). ``hand``: helix hand of gear 1 in
    the (first, +z) half, +1 right / -1 left. ``drive_sign``: +1 when gear 1 pushes gear 2
    counter-clockwise about +z (gear 1 driving in its positive sense), -1 clockwise.
    ``spins``: nominal spin of gear 1 and gear 2 per drive angle (default for fixed centres:
    (1, -z1/z2) external, (1, z1/z2) internal); ``carrier_spin``: that of the carrier holding the
    centres (0 when fixed). The mesh phase in cycles is phase_per_drive_angle * theta - phase_offset,
    by default z1 (spin1 - carrier_spin) drive_sign / (2 pi) mesh cycles per drive angle theta.
    Names: ``f"{name}_half{k}"``.
    """
    g1, g2 = mesh.gear1, mesh.gear2
    c1, c2 = np.asarray(centre1, float), np.asarray(centre2, float)
    d = (c2 - c1) * [1.0, 1.0, 0.0]
    a = float(np.linalg.norm(d))
    if not math.isclose(a, mesh.centre_distance, rel_tol=1e-9, abs_tol=1e-12):
        raise ValueError(f"{name}: gear centres are {a} m apart, the mesh needs its operating centre distance "
                         f"{mesh.centre_distance} m")
    s = 1.0 if drive_sign >= 0 else -1.0
    if mesh.internal:
        e = -d / a
    else:
        e = d / a
    r_w1 = mesh.operating_pitch_radii[0]
    alpha = mesh.operating_pressure_angle
    t_dir = math.sin(alpha) * e + s * math.cos(alpha) * np.cross(_EZ, e)
    helix_width = g1.face_width / (2 if helix_layout == "double" else 1)
    n_harm = contact_assumed.stiffness_harmonics
    stiffness, sliding, lever = contact_line_series(mesh, helix_width, n_harm)
    if contact_assumed.stiffness_variation == "constant":
        stiffness = PeriodicSeries(1.0, np.zeros(n_harm), np.zeros(n_harm))
    if spins is None:
        spins = (1.0, g1.teeth / g2.teeth if mesh.internal else -g1.teeth / g2.teeth)
    if phase_per_drive_angle is None:
        phase_per_drive_angle = g1.teeth * (spins[0] - carrier_spin) * s / (2 * math.pi)
    out = []
    for k, half in enumerate(helix_halves(helix_layout, helix_width, half_gap, hand), start=1):
        n_r, n_t, n_z = tooth_normal_local(mesh, s, half.hand)
        normal = n_r * e + n_t * np.cross(_EZ, e) + n_z * _EZ
        point = c1 + r_w1 * e + [0.0, 0.0, half.z]
        grad1, grad2 = contact_gradients(c1, c2, point, normal, t_dir)
        out.append(GearContact(
            f"{name}_half{k}", body1, body2, grad1, grad2, ContactLaw.from_contact(contact, half.share),
            stiffness, sliding, lever, contact.friction_coefficient,
            contact_assumed.friction_regularisation_m_per_s, phase_offset, phase_per_drive_angle,
            point, normal, (float(spins[0]), float(spins[1])), helix_width))
    return out


def annulus_mass_properties(inner_radius: float, outer_radius: float, width: float, density: float) -> MassProperties:
    """Mass properties of a solid annulus centred at the origin, axis z (a gear blank, an approximation) [SI].

    m = rho pi (R^2 - r^2) b,  J_z = m (R^2 + r^2) / 2,  J_x = J_y = m (3 (R^2 + r^2) + b^2) / 12.
    """
    if not (0 <= inner_radius < outer_radius and width > 0 and density > 0):
        raise ValueError("need 0 <= inner_radius < outer_radius, width > 0 and density > 0 (SI)")
    r2 = outer_radius**2 + inner_radius**2
    m = density * math.pi * (outer_radius**2 - inner_radius**2) * width
    jx = m * (3 * r2 + width**2) / 12
    return MassProperties(m, np.zeros(3), np.diag([jx, jx, 0.5 * m * r2]))
