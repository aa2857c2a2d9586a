"""Where the gearbox is supported: bearing positions from the component layout and Table 2 stiffnesses.

One home for the support assumptions both models use (every bearing at its seat): each bearing is a
:class:`flexgear.geometry.elements.BearingElement` at its place. The multibody model puts it on the body that
carries it (flexgear.mbs.elements, flexgear.mbs.joints), the lumped model condenses it to its gear-centre node
(:meth:`BearingElement.condensed_radial_stiffness`).

Bearing centres (component frames, z along the axis, origin at the gear mid-plane):

- input shaft: the middle of its bearing seat, ``bearing_seat_width_mm`` at the far (-z) end of the tube;
- output shaft: the middle of its bearing seat at the far (+z) end of the tube;
- planet: the middle of its bore (z = 0);
- the parallel-axis pair (no planet bearing): each shaft on two bearings of its Table 2 entry straddling its gear,
  the far one as above and the near one (``<shaft>_near``, interface ``bearing_seat_near``) on the tube's other end,
  just beyond the gear's other face (flexgear.geometry.layout); the output shaft's frame at the wheel's centre.
"""

from __future__ import annotations

from flexgear.geometry.elements import BearingElement
from flexgear.geometry.layout import ComponentLayout, component_layout
from flexgear.spec import GearboxSpec

__all__ = ["gearbox_supports", "seat_supports", "NEAR"]


NEAR = "_near"
"""Suffix of the parallel-axis pair's second bearing per shaft: the key ``<shaft>_near`` in the supports, on the
interface ``bearing_seat_near``."""


def _seat_centre(spec: GearboxSpec, layout: ComponentLayout, near: bool = False) -> float:
    tube = [p for p in layout.prisms if p.name == "tube"][0]
    seat = spec.components_assumed.bearing_seat_width_mm * 1e-3
    return tube.z0 + 0.5 * seat if (layout.name == "input_shaft") != near else tube.z1 - 0.5 * seat


def gearbox_supports(spec: GearboxSpec) -> dict[str, BearingElement]:
    """The Table 2 bearings of the study's gearbox ("input_shaft", "output_shaft", "planet"), each at its seat on its
    component (the shafts' "bearing_seat", the planet's "bore" interface), ground on the other side."""
    return seat_supports(spec, component_layout(spec, "input_shaft"), component_layout(spec, "output_shaft"))


def seat_supports(spec: GearboxSpec, input_shaft: ComponentLayout,
                  output_shaft: ComponentLayout) -> dict[str, BearingElement]:
    """:func:`gearbox_supports` with the shafts' layouts (flexgear.geometry.layout) given."""
    b = spec.bearings
    supports = {
        "input_shaft": BearingElement.from_bearing(b.input_shaft, "input_shaft", (0.0, 0.0, _seat_centre(
            spec, input_shaft)), "bearing_seat"),
        "output_shaft": BearingElement.from_bearing(b.output_shaft, "output_shaft", (0.0, 0.0, _seat_centre(
            spec, output_shaft)), "bearing_seat"),
    }
    if b.planet is not None:  # none in the parallel-axis pair: its wheel sits on the output shaft
        supports["planet"] = BearingElement.from_bearing(b.planet, "planet", (0.0, 0.0, 0.0), "bore")
        return supports
    for shaft, layout in (("input_shaft", input_shaft), ("output_shaft", output_shaft)):  # the pair's near bearings
        supports[shaft + NEAR] = BearingElement.from_bearing(getattr(b, shaft), shaft, (0.0, 0.0, _seat_centre(
            spec, layout, near=True)), "bearing_seat" + NEAR)
    return supports
