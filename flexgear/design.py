"""The gearbox's design: what a spec fixes for every later stage, derived from it once.

A :class:`Design` holds the spec and what the geometry stage makes of it, all made in :func:`design`: the gear
set (profile-shifted gears and meshes, flexgear.geometry.involute.gear_set_geometry), the theoretical values
(flexgear.theory), the gears' tooth profiles, every component's layout and exact mass properties
(flexgear.geometry.layout; the mass properties cached on disk), the Table 2 bearings at their seats
(flexgear.geometry.supports) and each mesh's contact geometry (helix halves, tooth normals and contact-line
series, flexgear.geometry.contact_lines). The FE, contact-law, multibody and lumped stages take the design and
read these from it; what they cache on disk stays keyed by the spec it carries.

:func:`design` makes it, once per spec content (flexgear.spec.spec_hash: file paths excluded).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from flexgear.geometry.contact_lines import MeshContactGeometry, mesh_contact_geometry
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
from flexgear.spec import CARRIER, GearboxSpec, spec_hash, stage_geometries
from flexgear.theory import Theory, gear_set_theory

__all__ = ["Design", "design", "as_design", "register_part_masses"]


@dataclass(frozen=True, eq=False)
class Design:
    """A spec and everything the later stages take from its geometry (SI units).

    ``gears``: the gear set; ``theory``: its theoretical values; ``profiles``: tooth profiles of sun, planet and
    ring (flexgear.geometry.layout.tooth_profiles); ``layouts``: every geometry component's prisms in its frame
    (flexgear.spec.GEOMETRY_COMPONENTS); ``masses``: each one's mass [kg], centre of mass [m] and inertia about it
    [kg m^2] from the exact section integrals (flexgear.geometry.layout.component_mass_properties, cached on disk
    under the same key), or for a part from a file its own geometry's (flexgear.fe.imported_mass; a carrier from a
file too); ``supports``: the
    Table 2 bearings at their seats (flexgear.geometry.supports.gearbox_supports); ``meshes``: the contact geometry
    of the sun-planet ("outer", sun = gear 1 of hand +1 in the +z half) and the planet-ring ("inner", planet = gear
    1 of hand -1) mesh, with ``[contact_assumed] stiffness_harmonics`` harmonics in the contact-line series.
    """

    spec: GearboxSpec
    gears: GearSetGeometry
    theory: Theory
    profiles: dict[str, ToothProfile]
    layouts: dict[str, ComponentLayout]
    masses: dict[str, MassProperties]
    supports: dict[str, BearingElement]
    meshes: dict[str, MeshContactGeometry]

    def layout(self, component: str) -> ComponentLayout:
        """The prisms of ``component`` in its frame (``layouts[component]``)."""
        return self.layouts[component]

    def mass_properties(self, component: str) -> MassProperties:
        """The exact mass properties of ``component`` (``masses[component]``: kg, m, kg m^2)."""
        return self.masses[component]

    @property
    def output_radius(self) -> float:
        """The radius [m] that turns the output's spin into a displacement along the line of action (the
        transmission error's lever): the ring's base radius (star), the planets' centre distance on the carrier
        (planetary), the wheel's base radius (the parallel-axis pair)."""
        arrangement = self.spec.gears.arrangement
        if arrangement == "planetary":
            return self.gears.centre_distance
        return (self.gears.ring if arrangement == "star" else self.gears.planet).base_radius

    def carrier_disc(self) -> tuple[float, float]:
        """(mass [kg], polar inertia [kg m^2]) of a planetary stage's carrier as its rigid body and the lumped model
        take it (a centred disc): ``[lumped_assumed] carrier_mass_kg`` and ``carrier_inertia_kg_m2``, but where the
        carrier comes from a file (``[components_geometry] carrier``) and the gearbox file leaves them out, the
        part's own (``masses["carrier"]``)."""
        la, derived = self.spec.lumped_assumed, self.spec.derived
        part = self.masses.get(CARRIER)
        mass = part.mass if part is not None and "lumped_assumed.carrier_mass_kg" in derived else la.carrier_mass_kg
        inertia = (float(part.inertia[2, 2]) if part is not None and "lumped_assumed.carrier_inertia_kg_m2" in derived
                   else la.carrier_inertia_kg_m2)
        return mass, inertia


_DESIGNS: dict[str, Design] = {}
_PART_MASSES: list[Callable[[Design, str], MassProperties]] = []


def register_part_masses(compute: Callable[[Design, str], MassProperties]) -> None:
    """How the exact mass properties of a ``[components_geometry]`` part are found: ``compute(design, component)``
    (flexgear.fe.imported_mass registers it when flexgear.fe is imported)."""
    _PART_MASSES[:] = [compute]
_MAX_DESIGNS = 64


def design(spec: GearboxSpec) -> Design:
    """The design of ``spec``, made once per spec content (its file path aside: the design returned carries
    ``spec`` itself, and is the one returned for that spec object until another of the same content asks)."""
    key = spec_hash(spec)
    made = _DESIGNS.get(key)
    if made is None:
        geo = gear_set_geometry(spec)
        th = gear_set_theory(spec, geo)
        profiles = tooth_profiles(geo, spec.gears_assumed.root_fillet_coefficient)
        components = stage_geometries(spec.gears)
        layouts = {c: gear_set_layout(spec, geo, c) for c in components}
        rho = spec.material_assumed.density_kg_m3
        imported = [c for c in (*components, CARRIER) if c in spec.components_geometry]
        masses = {c: cached_mass_properties(spec, c, lambda c=c: layout_mass_properties(layouts[c], profiles, rho))
                  for c in components if c not in imported}
        supports = seat_supports(spec, layouts["input_shaft"], layouts["output_shaft"])
        harmonics = spec.contact_assumed.stiffness_harmonics
        meshes = {kind: mesh_contact_geometry(mesh, geo.helix_layout, geo.helix_face_width, geo.half_gap, hand,
                                              harmonics)
                  for kind, mesh, hand in (("outer", geo.sun_planet, 1), ("inner", geo.planet_ring, -1))
                  if mesh is not None}
        made = Design(spec, geo, th, profiles, layouts, masses, supports, meshes)
        if len(_DESIGNS) >= _MAX_DESIGNS:
            _DESIGNS.pop(next(iter(_DESIGNS)))
        _DESIGNS[key] = made
        if imported:  # the parts from files: their own geometry's (the readers take this design without them)
            if not _PART_MASSES:
                raise RuntimeError("no mass reader of [components_geometry] parts is registered (import flexgear.fe)")
            for c in imported:
                masses[c] = cached_mass_properties(spec, c, lambda c=c: _PART_MASSES[0](made, c),
                                                   "the file's geometry (flexgear.fe.imported_mass)")
            made = _DESIGNS[key] = replace(made, masses=masses)
    if made.spec is not spec:  # the same content from another spec object: its geometry, this spec
        made = _DESIGNS[key] = replace(made, spec=spec)
    return made


def as_design(spec_or_design: GearboxSpec | Design) -> Design:
    """``spec_or_design`` itself if it is a design, else :func:`design` of the spec."""
    return spec_or_design if isinstance(spec_or_design, Design) else design(spec_or_design)
