"""Where the gearbox is supported: bearing positions from the component layout and Table 2 stiffnesses.

One home for the support assumptions both models use (every bearing at its seat): the
multibody model puts its bushings, drive and load at these points (flexgear.mbs.elements), the lumped
model condenses the same bushings to its gear-centre nodes (:func:`condensed_radial_stiffness`).

Bearing centres (component frames, z along the axis, origin at the gear mid-plane):

- input shaft: the middle of its bearing seat, ``bearing_seat_width_mm`` at the far (-z) end of the tube;
- output shaft: the middle of its bearing seat at the far (+z) end of the tube;
- planet: the middle of its bore (z = 0).

A bearing of Table 2 is the 6x6 stiffness diag(k_r, k_r, k_a, k_t, k_t, 0) about its centre. It is
realised by two rows of radial springs k_r/2 at z_c +- a, a = sqrt(k_t / k_r) (2 (k_r/2) a^2 = k_t, no
coupling about the centre), and one axial spring k_a at the centre: all at points on the axis, whose
velocity the spin does not change, so stiffness and damping act exactly on translation and tilt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flexgear.geometry.layout import component_layout
from flexgear.spec import Bearing, GearboxSpec

__all__ = ["Support", "gearbox_supports", "condensed_radial_stiffness"]


@dataclass(frozen=True)
class Support:
    """One Table 2 bearing at its place."""

    component: str  # geometry component carrying it
    interface: str  # its interface in the component's reduced body (flexgear.fe.reduced)
    centre_z: float  # bearing centre on the axis, component frame [m]
    radial_stiffness: float  # N/m
    axial_stiffness: float  # N/m
    tilt_stiffness: float  # N m/rad
    damping_per_stiffness: float  # s

    @property
    def spread(self) -> float:
        """Half distance a [m] of the two radial spring rows: a = sqrt(k_t / k_r)."""
        return math.sqrt(self.tilt_stiffness / self.radial_stiffness)

    def spring_points(self) -> list[tuple[float, tuple[float, float, float]]]:
        """(z [m], stiffness (x, y, z) [N/m]) of the three springs that make the bearing (module docstring)."""
        half = 0.5 * self.radial_stiffness
        return [(self.centre_z - self.spread, (half, half, 0.0)), (self.centre_z + self.spread, (half, half, 0.0)),
                (self.centre_z, (0.0, 0.0, self.axial_stiffness))]


def _seat_centre(spec: GearboxSpec, shaft: str) -> float:
    tube = [p for p in component_layout(spec, shaft).prisms if p.name == "tube"][0]
    seat = spec.components_assumed.bearing_seat_width_mm * 1e-3
    return tube.z0 + 0.5 * seat if shaft == "input_shaft" else tube.z1 - 0.5 * seat


def _support(component: str, interface: str, z: float, bearing: Bearing) -> Support:
    return Support(component, interface, z, bearing.radial_stiffness_n_per_m, bearing.axial_stiffness_n_per_m,
                   bearing.tilt_stiffness_nm_per_rad, bearing.damping_per_stiffness_s)


def gearbox_supports(spec: GearboxSpec) -> dict[str, Support]:
    """The bearings of the study's gearbox ("input_shaft", "output_shaft", "planet"), each at its seat."""
    b = spec.bearings
    return {
        "input_shaft": _support("input_shaft", "bearing_seat", _seat_centre(spec, "input_shaft"), b.input_shaft),
        "output_shaft": _support("output_shaft", "bearing_seat", _seat_centre(spec, "output_shaft"), b.output_shaft),
        "planet": _support("planet", "bore", 0.0, b.planet),
    }


def condensed_radial_stiffness(support: Support, gear_z: float = 0.0) -> float:
    """In-plane stiffness [N/m] of a rigid shaft on ``support`` at the gear centre (axial position ``gear_z``).

    A force F at the gear, no moment: the bearing takes F and the moment F L (L = gear_z - centre_z), so the
    gear moves F (1/k_r + L^2/k_t) (static condensation of the tilt; k_t = 0 with L != 0 gives 0).
    """
    lever = gear_z - support.centre_z
    compliance = 1.0 / support.radial_stiffness
    if lever != 0.0:
        if support.tilt_stiffness <= 0.0:
            return 0.0
        compliance += lever**2 / support.tilt_stiffness
    return 1.0 / compliance
