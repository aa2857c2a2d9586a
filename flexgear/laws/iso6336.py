"""Tooth stiffness of ISO 6336-1 (Method B): single stiffness c' and mean mesh stiffness c_gamma_alpha.

ISO 6336-1:2006 clause 9 ("Tooth stiffness parameters c' and c_gamma"), Method B (clause 9.3), for
solid steel gears; the formulas are unchanged in the 2019 edition:

    q'      = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1^2 + C9 x2^2
              [mm um/N], C1..C9 from the standard's table (below); z_n = z / (cos^2 beta_b cos beta)
              the virtual numbers of teeth; for an internal pair z_n2 = infinity (its 1/z_n2 terms vanish)
    c'_th   = 1 / q'                                                    [N/(mm um)]
    c'      = c'_th C_M C_R C_B cos(beta) * min(1, (K_A F_t / b / 100 N/mm)^0.25)
              C_M = 0.8 (theoretical to measured), C_R = 1 (solid gear blank),
              C_B = (1 + 0.5 (1.2 - h_fP/m_n)) (1 - 0.02 (20 deg - alpha_n)) (basic rack),
              the last factor for light loads F_t K_A / b < 100 N/mm
    c_gamma_alpha = c' (0.75 eps_alpha + 0.25)                          [N/(mm um)]

c' and c_gamma are per unit face width and, as the standard uses them (resonance speed of K_v with
the reduced mass on the base circle), relate the transverse load to the deflection along the
transverse line of action. The mesh stiffness along the tooth normal (the deflection coordinate
of flexgear's contacts) is k_n = c_gamma_alpha b / cos^2(beta_b): F_n = F_bt / cos(beta_b) and
delta_n = delta_t cos(beta_b).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["ISO6336_Q_COEFFICIENTS", "ToothStiffness", "tooth_stiffness"]

ISO6336_Q_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
"""C1..C9 of q' (ISO 6336-1:2006, Method B, clause 9.3)."""

C_M = 0.8  # correction factor, theoretical to measured stiffness (ISO 6336-1 9.3)
C_R = 1.0  # gear blank factor, solid disc gears (ISO 6336-1 9.3)


@dataclass(frozen=True)
class ToothStiffness:
    """ISO 6336-1 stiffness of one gear pair [N/(mm um)] and the factors behind it."""

    q_min: float  # q' [mm um / N]
    c_th: float  # c'_th
    basic_rack_factor: float  # C_B
    load_factor: float  # (F_t K_A / b / 100)^0.25, at most 1
    single: float  # c'
    mesh: float  # c_gamma_alpha

    def normal_stiffness_n_per_m(self, face_width_m: float, base_helix_angle_rad: float) -> float:
        """Mean mesh stiffness along the tooth normal [N/m]: c_gamma_alpha b / cos^2(beta_b).

        1 N/(mm um) = 1e9 N/m^2.
        """
        return self.mesh * 1e9 * face_width_m / math.cos(base_helix_angle_rad) ** 2


def tooth_stiffness(z1: int, z2: int, x1: float, x2: float, helix_angle_rad: float, base_helix_angle_rad: float,
                    normal_pressure_angle_rad: float, dedendum_coefficient: float, eps_alpha: float,
                    line_load_n_per_mm: float, internal: bool = False) -> ToothStiffness:
    """c' and c_gamma_alpha of ISO 6336-1 Method B (see the module docstring for every formula).

    ``z1``, ``x1``: pinion (the external gear of an internal pair); ``line_load_n_per_mm``: K_A F_t / b
    (transverse tangential force on the reference circle per face width); ``dedendum_coefficient`` =
    h_fP / m_n of the basic rack; ``eps_alpha``: transverse contact ratio.
    """
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = ISO6336_Q_COEFFICIENTS
    virtual = math.cos(base_helix_angle_rad) ** 2 * math.cos(helix_angle_rad)
    zn1 = z1 / virtual
    inv_zn2 = 0.0 if internal else virtual / z2
    q = (c1 + c2 / zn1 + c3 * inv_zn2 + c4 * x1 + c5 * x1 / zn1 + c6 * x2 + c7 * x2 * inv_zn2
         + c8 * x1**2 + c9 * x2**2)
    c_th = 1.0 / q
    c_b = (1.0 + 0.5 * (1.2 - dedendum_coefficient)) * (1.0 - 0.02 * (20.0 - math.degrees(normal_pressure_angle_rad)))
    load = min(1.0, (line_load_n_per_mm / 100.0) ** 0.25)
    single = c_th * C_M * C_R * c_b * math.cos(helix_angle_rad) * load
    return ToothStiffness(q, c_th, c_b, load, single, single * (0.75 * eps_alpha + 0.25))
