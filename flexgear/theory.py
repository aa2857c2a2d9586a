"""The study's "theoretical values": kinematics, torques, mesh force, mesh frequency, STEP.

All in SI (rad/s, N, N·m, Hz); ``deg_per_s`` appears only in function names that say so.

- Star arrangement (carrier fixed):  omega_ring / omega_sun = -z_s / z_r
- Planetary arrangement (ring fixed): omega_carrier / omega_sun = z_s / (z_s + z_r)
- Parallel-axis pair (no ring):       omega_wheel / omega_pinion = -z_s / z_p (the sun the pinion, the planet the
  wheel)
- Power balance (loss-free):          T_in = T_out * |omega_out / omega_in|
- Normal mesh force per planet:       F_n = T_sun / (N r_b,sun cos(beta_b))
- Mesh frequency (carrier frame):     f_m = z_s |omega_sun - omega_carrier| / (2 pi)
- ADAMS STEP(x, x0, h0, x1, h1) = h0 + (h1 - h0) d^2 (3 - 2 d), d = (x - x0)/(x1 - x0) clipped to [0, 1]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flexgear.geometry.involute import GearSetGeometry, gear_set_geometry
from flexgear.spec import GearboxSpec, GearSet

__all__ = ["Theory", "theory", "gear_set_theory", "mesh_frequency_hz"]


@dataclass(frozen=True)
class Theory:
    """Steady-state theoretical values of a single-stage star or planetary gearbox or a parallel-axis pair (SI)."""

    input_speed: float  # rad/s (sun)
    output_speed: float  # rad/s (ring for star, carrier for planetary, wheel for the parallel-axis pair)
    ratio: float  # output / input speed
    input_torque: float  # N·m on the sun
    output_torque: float  # N·m load at the output
    mesh_force: float  # N, normal mesh force per planet (both meshes)
    mesh_frequency: float  # Hz
    planet_speed: float  # rad/s absolute spin of each planet

    @property
    def input_speed_deg_per_s(self) -> float:
        return math.degrees(self.input_speed)

    @property
    def output_speed_deg_per_s(self) -> float:
        return math.degrees(self.output_speed)


def theory(spec: GearboxSpec) -> Theory:
    """Theoretical values for the spec's load case at full speed and load (after the ramps)."""
    return gear_set_theory(spec, gear_set_geometry(spec))


def mesh_frequency_hz(spec: GearboxSpec | GearSet, speed_rpm: float) -> float:
    """f_m = z_s |n_sun - n_carrier| / 60 [Hz] (module docstring) at the input speed ``speed_rpm`` [rpm]: the carrier
    fixed for the star, turning at z_s / (z_s + z_r) of the input for the planetary arrangement. ``spec``: the
    gearbox or its gear set."""
    g = spec if isinstance(spec, GearSet) else spec.gears
    r_c = 0.0 if g.arrangement != "planetary" else g.sun_teeth / (g.sun_teeth + g.ring_teeth)
    return g.sun_teeth * abs(speed_rpm) * (1.0 - r_c) / 60.0


def gear_set_theory(spec: GearboxSpec, geo: GearSetGeometry) -> Theory:
    """:func:`theory` of ``spec`` with its gear set ``geo`` (flexgear.geometry.involute.gear_set_geometry) given."""
    g = spec.gears
    w_in = spec.load_case.input_speed_rad_s
    zs, zp, zr = g.sun_teeth, g.planet_teeth, g.ring_teeth
    if g.arrangement == "star":
        ratio = -zs / zr
        w_carrier = 0.0
    elif g.arrangement == "parallel":
        ratio = -zs / zp
        w_carrier = 0.0
    else:
        ratio = zs / (zs + zr)
        w_carrier = ratio * w_in
    # Planet spin: in the carrier frame omega_p - omega_c = -(z_s/z_p)(omega_s - omega_c).
    w_planet = w_carrier - zs / zp * (w_in - w_carrier)
    t_out = spec.load_case.load_torque_nm
    t_in = t_out * abs(ratio)
    cos_bb = math.cos(geo.sun.base_helix_angle)
    force = t_in / (g.planet_count * geo.sun.base_radius * cos_bb)
    f_mesh = zs * abs(w_in - w_carrier) / (2 * math.pi)
    return Theory(w_in, ratio * w_in, ratio, t_in, t_out, force, f_mesh, w_planet)
