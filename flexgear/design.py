"""The gearbox's design: what a spec fixes for every later stage, derived from it once.

A :class:`Design` holds the spec and what the geometry stage makes of it: the gear set (profile-shifted gears
and meshes, flexgear.geometry.involute.gear_set_geometry), the theoretical values (flexgear.theory), the Table 2
bearings at their seats (flexgear.geometry.supports), the gears' tooth profiles and, on demand, each component's
layout and exact mass properties (flexgear.geometry.layout). The FE, contact-law, multibody and lumped stages take
the design and read these from it; what they cache on disk stays keyed by the spec it carries.

:func:`design` makes it, once per spec content (flexgear.spec.spec_hash: file paths excluded).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

from flexgear.geometry.elements import BearingElement
from flexgear.geometry.involute import GearSetGeometry, gear_set_geometry
from flexgear.geometry.layout import (
    ComponentLayout,
    cached_mass_properties,
    gear_set_layout,
    layout_mass_properties,
    tooth_profiles,
)
from flexgear.geometry.massprops import MassProperties
from flexgear.geometry.profile import ToothProfile
from flexgear.geometry.supports import seat_supports
from flexgear.spec import GearboxSpec, spec_hash
from flexgear.theory import Theory, gear_set_theory

__all__ = ["Design", "design", "as_design"]


@dataclass(frozen=True, eq=False)
class Design:
    """A spec and its gear set and theory; bearings, profiles, layouts and mass properties derived on first use."""

    spec: GearboxSpec
    gears: GearSetGeometry
    theory: Theory

    @cached_property
    def profiles(self) -> dict[str, ToothProfile]:
        """Tooth profiles of sun, planet and ring (flexgear.geometry.layout.tooth_profiles)."""
        return tooth_profiles(self.gears, self.spec.gears_assumed.root_fillet_coefficient)

    @cached_property
    def supports(self) -> dict[str, BearingElement]:
        """The Table 2 bearings at their seats (flexgear.geometry.supports.gearbox_supports)."""
        return seat_supports(self.spec, self.layout("input_shaft"), self.layout("output_shaft"))

    def layout(self, component: str) -> ComponentLayout:
        """The prisms of ``component`` in its frame (flexgear.geometry.layout.component_layout)."""
        return gear_set_layout(self.spec, self.gears, component)

    def mass_properties(self, component: str) -> MassProperties:
        """Mass [kg], centre of mass [m], inertia [kg m^2] of ``component`` from the exact section integrals
        (flexgear.geometry.layout.component_mass_properties, cached on disk under the same key)."""
        rho = self.spec.material_assumed.density_kg_m3
        return cached_mass_properties(self.spec, component,
                                      lambda: layout_mass_properties(self.layout(component), self.profiles, rho))


_DESIGNS: dict[str, Design] = {}
_MAX_DESIGNS = 64


def design(spec: GearboxSpec) -> Design:
    """The design of ``spec``, made once per spec content (its file path aside: the design returned carries
    ``spec`` itself, and is the one returned for that spec object until another of the same content asks)."""
    key = spec_hash(spec)
    made = _DESIGNS.get(key)
    if made is None:
        geo = gear_set_geometry(spec)
        made = Design(spec, geo, gear_set_theory(spec, geo))
        if len(_DESIGNS) >= _MAX_DESIGNS:
            _DESIGNS.pop(next(iter(_DESIGNS)))
        _DESIGNS[key] = made
    if made.spec is not spec:  # the same content from another spec object: its geometry, this spec
        made = _DESIGNS[key] = replace(made, spec=spec)
    return made


def as_design(spec_or_design: GearboxSpec | Design) -> Design:
    """``spec_or_design`` itself if it is a design, else :func:`design` of the spec."""
    return spec_or_design if isinstance(spec_or_design, Design) else design(spec_or_design)
