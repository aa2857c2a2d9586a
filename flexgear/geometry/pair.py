"""Any gear pair, external or internal, at any centre positions: geometry and gear contacts.

Geometry (ISO 21771, as flexgear.geometry.involute): :func:`gear_pair_geometry` gives the :class:`GearMesh` of
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
:class:`flexgear.mbs.contacts.GearContact` per helix half ("single": one; "double": two halves of
opposite hand at z = +/-(b_h + gap)/2, each half the face width).
"""

from __future__ import annotations

import math

import numpy as np

from flexgear.geometry.involute import (
    Gear,
    GearMesh,
    HelixHalf,
    helix_halves,
    inv,
    inv_inverse,
    transverse_pressure_angle,
)

__all__ = ["HelixHalf", "helix_halves", "gear_pair_geometry"]

_EZ = np.array([0.0, 0.0, 1.0])


def gear_pair_geometry(z1: int, z2: int, normal_module: float, helix_angle: float, pressure_angle: float,
                       face_width: float, shifts: tuple[float, float] = (0.0, 0.0), internal: bool = False,
                       centre_distance: float | None = None, normal_backlash: float = 0.0,
                       addendum_coefficient: float = 1.0, dedendum_coefficient: float = 1.25) -> GearMesh:
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

    return GearMesh(gear(z1, x1, False), gear(z2, x2, internal), aw, alpha_w)




