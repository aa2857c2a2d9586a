"""Tooth-friction tables of the lumped model (flexgear.lumped.model, flexgear.lumped.run): the friction force and
its arms per unit normal force over one mesh cycle, from the integrals along the contact lines
(flexgear.geometry.contact_lines.contact_line_integrals). Geometry and sign conventions: flexgear.lumped.model's
module docstring (transverse plane, sun at the origin, planet i at a e_i, the sun driving counter-clockwise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flexgear.geometry.contact_lines import contact_line_integrals
from flexgear.geometry.involute import GearSetGeometry

__all__ = ["FrictionTables", "friction_tables", "mesh_friction_tables"]


@dataclass(frozen=True)
class FrictionTables:
    """Tooth-friction resultants of one mesh per unit normal force, over one mesh cycle.

    Phase phi in [0, 1) (mesh cycles), the convention of flexgear.geometry.contact_lines.mesh_stiffness_harmonics:
    a tooth with phase u = phi + k has its contact line from transverse position s = u (one face end)
    to s = u - eps_beta (other end), s in base pitches from the start of active contact A, and is
    in contact on 0 <= s <= eps_alpha. The normal load is spread uniformly over all contact-line
    length; friction mu*w acts along tau = J n, opposing the sliding of gear 1 on gear 2, whose
    sign flips at the pitch point.

    - ``length``: total contact-line length / its mean (the mesh stiffness shape)
    - ``force``: (1/L) int sg dl  (friction force on gear 2 along tau, per mu F_n, for forward running)
    - ``arm1``, ``arm2`` [m]: (1/L) int sg d_j dl, d_j = (C - O_j) . n the signed arm about gear j's centre;
      the friction moment on gear 1 is -mu F_n arm1, on gear 2 +mu F_n arm2.
    """

    phase: np.ndarray
    length: np.ndarray
    force: np.ndarray
    arm1: np.ndarray
    arm2: np.ndarray


def friction_tables(d1_start: float, d1_end: float, d1_pitch: float, d2_offset: float, base_pitch: float,
                    eps_beta: float, sign_slope: float, points: int) -> FrictionTables:
    """Tabulate :class:`FrictionTables` of one mesh from the integrals along its contact lines
    (flexgear.geometry.contact_lines.contact_line_integrals, the multibody model's friction series too).

    ``d1_start``, ``d1_end``, ``d1_pitch``: arm d1 = (C - O_1) . n [m] at the start and end of active
    contact and at the pitch point; ``d2_offset`` = (O_1 - O_2) . n, so d2 = d1 + d2_offset;
    ``sign_slope`` = +1 if the sliding velocity of gear 1 on gear 2 (forward running) grows with s. With
    sg = sign_slope sign(s - s_p), d1 = d1_start + p_bt s and the integrals L, S, M (s in base pitches):
    force = (1/L) int sg dl = sign_slope S / L, arm1 = (1/L) int sg d1 dl = sign_slope (d1_start S + p_bt M) / L.
    """
    phase = np.arange(points) / points
    length, signed, moment = contact_line_integrals((d1_end - d1_start) / base_pitch, eps_beta,
                                                    (d1_pitch - d1_start) / base_pitch, phase)
    i0, i1 = sign_slope * signed, sign_slope * moment
    arm1 = (d1_start * i0 + base_pitch * i1) / length
    force = i0 / length
    return FrictionTables(phase, length / length.mean(), force, arm1, arm1 + d2_offset * force)


def mesh_friction_tables(spec_geo: GearSetGeometry, points: int) -> tuple[FrictionTables, ...]:
    """Friction tables of the sun-planet and planet-ring meshes (geometry as in flexgear.lumped.model's module
    docstring); the sun-planet mesh's alone where the set has no ring (the parallel-axis pair)."""
    sun, planet, ring = spec_geo.sun, spec_geo.planet, spec_geo.ring
    a = spec_geo.centre_distance
    eps_b = spec_geo.sun_planet.overlap_ratio(spec_geo.helix_face_width)
    ga = math.sqrt(sun.tip_radius**2 - sun.base_radius**2)
    gp = math.sqrt(planet.tip_radius**2 - planet.base_radius**2)
    al_s = spec_geo.sun_planet.operating_pressure_angle
    pb = sun.base_pitch
    # sun (gear 1) - planet (gear 2), external: d1 from the sun's tangency, d2 = d1 - a sin(alpha)
    k_s = -sun.base_radius / planet.base_radius  # kinematic omega_2 / omega_1
    slope_s = math.copysign(1.0, 1.0 - k_s)
    sun_t = friction_tables(a * math.sin(al_s) - gp, ga, sun.base_radius * math.tan(al_s), -a * math.sin(al_s),
                            pb, eps_b, slope_s, points)
    if ring is None or spec_geo.planet_ring is None:
        return (sun_t,)
    gr = math.sqrt(ring.tip_radius**2 - ring.base_radius**2)
    al_r = spec_geo.planet_ring.operating_pressure_angle
    # planet (gear 1, driving clockwise) - ring (gear 2), internal: d2 = d1 + a sin(alpha)
    k_r = planet.base_radius / ring.base_radius
    slope_r = -math.copysign(1.0, 1.0 - k_r)  # forward running is omega_planet < 0
    ring_t = friction_tables(-a * math.sin(al_r) + gr, gp, planet.base_radius * math.tan(al_r), a * math.sin(al_r),
                             pb, eps_b, slope_r, points)
    return sun_t, ring_t
