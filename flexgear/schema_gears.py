"""Schema of the gearbox files' gear set (``[gears]``) and the component names of each arrangement.

Part of :mod:`flexgear.schema` (which re-exports every name here): Table 1 of the study as the ``[gears]`` table,
checked on load by :func:`flexgear.spec.load_gearbox`, and the Table 3 components a variant makes rigid or
flexible in the star, planetary and parallel-axis arrangements.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flexgear.schema_fields import choice_field, num_field, numbers_field

__all__ = ["GearSet", "COMPONENTS", "stage_components", "stage_geometries", "GEAR_COMPONENTS", "SHAFT_COMPONENTS",
           "GEOMETRY_COMPONENTS", "COMPONENT_GEOMETRY", "CARRIER", "OPTIONAL_COMPONENTS",
           "PLANET_POSITION_TOLERANCE_STEPS"]

COMPONENTS = ("input_shaft", "sun", "planets", "ring", "output_shaft")
"""Component names of Table 3, in its column order (a variant sets each rigid or flexible)."""


def stage_components(gears: GearSet) -> tuple[str, ...]:
    """The Table 3 components of ``gears``' arrangement: :data:`COMPONENTS`, the ring left out of a parallel-axis
    pair."""
    return COMPONENTS if gears.has_ring else tuple(c for c in COMPONENTS if c != "ring")


def stage_geometries(gears: GearSet) -> tuple[str, ...]:
    """The geometry components of ``gears``' arrangement: :data:`GEOMETRY_COMPONENTS`, the ring left out of a
    parallel-axis pair."""
    return GEOMETRY_COMPONENTS if gears.has_ring else tuple(c for c in GEOMETRY_COMPONENTS if c != "ring")

GEAR_COMPONENTS = ("sun", "planet", "ring")
SHAFT_COMPONENTS = ("input_shaft", "output_shaft")
GEOMETRY_COMPONENTS = GEAR_COMPONENTS + SHAFT_COMPONENTS
"""Distinct component geometries (one planet geometry serves every planet)."""

CARRIER = "carrier"
"""The planet carrier: a component of the planetary arrangement (rigid by default, flexible when a variant says so,
flexgear.fe.carrier); the star holds it."""
OPTIONAL_COMPONENTS = (CARRIER,)
"""Components a variant may leave out of ``[components]`` (then rigid)."""

COMPONENT_GEOMETRY = {**{c: c for c in GEOMETRY_COMPONENTS}, "planets": "planet", CARRIER: CARRIER}
"""Table 3 component (or geometry) name -> its geometry name."""


PLANET_POSITION_TOLERANCE_STEPS = 0.01
"""A given planet position may lie this share of an assembly step (360 deg / (z_s + z_r)) off an angle where the
planet assembles; it is taken at that angle (:attr:`GearSet.planet_positions_rad`)."""


# --------------------------------------------------------------------------- gearbox tables
@dataclass(frozen=True)
class GearSet:
    """Table 1 of the study (and the planet count and arrangement of section 2.1)."""

    sun_teeth: int = num_field(3, integer=True)
    planet_teeth: int = num_field(3, integer=True)
    ring_teeth: int = num_field(0, integer=True, derived=True,
                                doc="0 in the parallel-axis stage (no ring); required in the star and planetary ones")
    planet_count: int = num_field(1, 12, integer=True, derived=True,
                                  doc="1 in the parallel-axis stage (the wheel); required in the star and planetary "
                                      "ones")
    normal_module_mm: float = num_field(0.0, lo_open=True)
    helix_angle_deg: float = num_field(0.0, 45.0)
    normal_pressure_angle_deg: float = num_field(10.0, 30.0)
    arrangement: str = choice_field(
        "star", "planetary", "parallel", default="star",
        doc="star: carrier held, ring output; planetary: ring held, carrier output; parallel: a parallel-axis "
            "pair, the sun the pinion (input) and the one planet the wheel (output) on axes held by the housing")
    planet_positions_deg: tuple[float, ...] = numbers_field(
        0.0, 360.0, hi_open=True,
        doc="polar angle of each planet's centre [deg], increasing; left out: equally spaced from 0")

    @property
    def assembly_step_rad(self) -> float:
        """Angle between neighbouring positions at which a planet assembles, 2 pi / (z_s + z_r) [rad]: at polar
        angle psi a planet meshes with sun and ring only if (z_s + z_r) psi / (2 pi) is an integer."""
        return 2.0 * math.pi / (self.sun_teeth + self.ring_teeth)

    @property
    def planet_positions_rad(self) -> tuple[float, ...]:
        """Each planet's polar angle [rad]: the given positions on the nearest assembly angle
        (:attr:`assembly_step_rad`; flexgear.spec refuses a position farther off, :meth:`position_problem`), else N
        equally spaced from 0."""
        if not self.planet_positions_deg:
            return tuple(2.0 * math.pi * k / self.planet_count for k in range(self.planet_count))
        step = self.assembly_step_rad
        return tuple(step * round(math.radians(a) / step) for a in self.planet_positions_deg)

    def position_problem(self) -> str | None:
        """What is wrong with the given planet positions (None: nothing): one angle per planet, increasing, each
        where a planet assembles within ``PLANET_POSITION_TOLERANCE_STEPS`` of a step, no two on one angle."""
        given = self.planet_positions_deg
        step = math.degrees(self.assembly_step_rad)
        off = [a for a in given if abs(a / step - round(a / step)) > PLANET_POSITION_TOLERANCE_STEPS]
        if len(given) != self.planet_count:
            return f"expected one angle per planet ({self.planet_count}, gears.planet_count)"
        if any(b <= a for a, b in zip(given, given[1:], strict=False)):
            return "expected increasing angles"
        if off:
            return (f"a planet at {off[0]:g} deg does not assemble: expected multiples of 360 / (sun_teeth + "
                    f"ring_teeth) = {step:.6g} deg")
        if len(set(self.planet_positions_rad)) < len(given):
            return f"expected distinct assembly angles (multiples of {step:.6g} deg)"
        return None

    def pair_problem(self, planet_bearing: bool = False) -> tuple[str, str, object] | None:
        """(field, what is allowed, value) of what a parallel-axis pair's gear data must leave out: a ring, more than
        one wheel, planet positions, a planet bearing (``planet_bearing``: one is given); None: nothing."""
        if planet_bearing:
            return ("bearings.planet", "a parallel-axis pair's wheel sits on the output shaft's bearing: leave "
                    "[bearings.planet] out", "given")
        if self.ring_teeth:
            return "gears.ring_teeth", "a parallel-axis pair has no ring: leave ring_teeth out", self.ring_teeth
        if self.planet_count != 1:
            return ("gears.planet_count", "a parallel-axis pair has one wheel (the planet): expected 1 or left out",
                    self.planet_count)
        if self.planet_positions_deg:
            return ("gears.planet_positions_deg", "a parallel-axis pair's wheel sits at 0 deg: leave it out",
                    list(self.planet_positions_deg))
        return None

    @property
    def has_ring(self) -> bool:
        """Whether the stage has a ring gear (the star and planetary stages; not the parallel-axis pair)."""
        return self.arrangement != "parallel"

    @property
    def equally_spaced(self) -> bool:
        """Whether the planets are equally spaced (left out, or given so)."""
        psi, n = self.planet_positions_rad, self.planet_count
        return all(abs(a - psi[0] - 2.0 * math.pi * k / n) < 1e-9 for k, a in enumerate(psi))

    @property
    def normal_module_m(self) -> float:
        return self.normal_module_mm * 1e-3

    @property
    def helix_angle_rad(self) -> float:
        return math.radians(self.helix_angle_deg)

    @property
    def normal_pressure_angle_rad(self) -> float:
        return math.radians(self.normal_pressure_angle_deg)
