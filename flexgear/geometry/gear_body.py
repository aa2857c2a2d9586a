"""One toothed gear body of any gear set, described on its own: its layout and exact mass properties.

A :class:`GearBody` is everything the solid, the mesh and the reduced flexible body of one gear depend on
(SI units; a name says so where it is not): the involute gear (teeth, normal module, helix and normal pressure
angle, profile shift, tooth thinning, addendum, dedendum and root-fillet coefficients, face width), its helix
layout (one helix, or two halves of opposite hand with a relief groove between them), the body around the teeth
(an external gear's bore, an internal gear's rim), the axial width of its seat, the material and the mesh sizes.
It is built either from its values, from a :class:`flexgear.geometry.involute.Gear` of a pair
(:meth:`GearBody.from_gear`, e.g. of flexgear.geometry.pair.gear_pair_geometry), or from a gear of the study's
gear set (:meth:`GearBody.from_gear_set`: the sun's and planet's layouts are then the study's own).

The layout is the study's construction (flexgear.geometry.layout.toothed_prisms): external gear with a bore,
internal gear in a rim of ``rim_thickness`` below its tooth root; double helix with its groove. Its exact mass
properties come from the same section integrals (flexgear.geometry.layout.layout_mass_properties).

:class:`Engagement` says where the body meshes (a flexgear.geometry.involute.GearMesh, which of its two gears
the body is, the drive sense, the contacts' polar angles): the contact bands of its attachment modes
(flexgear.fe.toothed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

from flexgear.geometry.involute import Gear, GearMesh, gear_set_geometry
from flexgear.geometry.layout import ComponentLayout, layout_mass_properties, toothed_prisms
from flexgear.geometry.massprops import MassProperties
from flexgear.geometry.profile import ToothProfile, tooth_profile
from flexgear.spec import GearboxSpec, Material

__all__ = ["GearBody", "Engagement", "STEEL", "TOOTH_SIZE_PER_MODULE", "BODY_SIZE_PER_MODULE"]

STEEL = Material(density_kg_m3=7850.0, youngs_modulus_pa=2.1e11, poisson_ratio=0.3)
"""The study's gear steel ([material_assumed] of gearbox.toml)."""
TOOTH_SIZE_PER_MODULE = 1.9
"""Default tooth mesh size / normal module: the study's coarse level (4 mm at m_n = 2.12 mm)."""
BODY_SIZE_PER_MODULE = 3.8
"""Default body mesh size / normal module: the study's coarse level (8 mm at m_n = 2.12 mm)."""
_HANDS = {"sun": 1, "planet": -1, "ring": -1}  # flexgear.geometry.layout: sun +, planet -, ring -
_LAYOUTS = ("single", "double")


@dataclass(frozen=True)
class GearBody:
    """One toothed gear body (SI units: lengths in m, angles in rad).

    Gear: ``teeth``, ``normal_module``, ``face_width`` (total, both helix halves), ``helix_angle``,
    ``pressure_angle`` (normal), ``shift`` (profile-shift coefficient), ``thinning`` (normal tooth-thickness
    reduction on the reference circle: half a pair's backlash j_n / (2 cos alpha_n)), ``addendum_coefficient``,
    ``dedendum_coefficient``, ``root_fillet_coefficient`` (fillet radius / m_n), ``internal``.
    Helix: ``hand`` +1 (right: the tooth line advances counter-clockwise seen from +z as z grows) or -1 of the
    helix at +z; ``helix_layout`` "single" or "double" (two halves of opposite hand, each half the face width,
    ``half_gap`` apart, a relief groove ``groove_depth`` beyond the root circle between them).
    Body: an external gear's ``bore_diameter``, an internal gear's ``rim_thickness`` below its tooth root; the
    seat (the body's interface to its bearing or shaft: the bore, or the rim's outer surface) over
    ``seat_width`` about the mid-plane (None: over the whole body, as the study's bores).
    ``material``; mesh: ``tooth_mesh_size`` on the tooth faces, ``body_mesh_size`` elsewhere (None:
    :data:`TOOTH_SIZE_PER_MODULE` and :data:`BODY_SIZE_PER_MODULE` normal modules), ``element_order`` 1 or 2,
    ``elements_per_curvature_radius`` and ``optimisation_steps`` (Netgen, as [meshing_assumed] of gearbox.toml).
    ``name`` labels the body's layout and cache files.
    """

    teeth: int
    normal_module: float
    face_width: float
    helix_angle: float = 0.0
    pressure_angle: float = math.radians(20.0)
    shift: float = 0.0
    thinning: float = 0.0
    addendum_coefficient: float = 1.0
    dedendum_coefficient: float = 1.25
    root_fillet_coefficient: float = 0.3
    internal: bool = False
    hand: int = 1
    helix_layout: str = "single"
    half_gap: float = 0.0
    groove_depth: float = 0.0
    bore_diameter: float = 0.0
    rim_thickness: float = 0.0
    seat_width: float | None = None
    material: Material = field(default=STEEL)
    tooth_mesh_size: float | None = None
    body_mesh_size: float | None = None
    element_order: int = 2
    elements_per_curvature_radius: float = 0.3
    optimisation_steps: int = 3
    name: str = "gear"

    def __post_init__(self):
        m = self.normal_module
        if self.tooth_mesh_size is None:
            object.__setattr__(self, "tooth_mesh_size", TOOTH_SIZE_PER_MODULE * m)
        if self.body_mesh_size is None:
            object.__setattr__(self, "body_mesh_size", BODY_SIZE_PER_MODULE * m)
        problems = []
        if not (isinstance(self.teeth, int) and self.teeth >= 3):
            problems.append(f"teeth must be an integer >= 3, got {self.teeth!r}")
        if not (m > 0 and self.face_width > 0 and 0 <= self.helix_angle < math.pi / 2
                and 0 < self.pressure_angle < 0.6):
            problems.append("normal_module and face_width must be > 0 [m], helix_angle in [0, pi/2) and "
                            f"pressure_angle in (0, 0.6) [rad]; got {m}, {self.face_width}, {self.helix_angle}, "
                            f"{self.pressure_angle}")
        if self.hand not in (1, -1):
            problems.append(f"hand must be +1 or -1, got {self.hand!r}")
        if self.helix_layout not in _LAYOUTS:
            problems.append(f"helix_layout must be 'single' or 'double', got {self.helix_layout!r}")
        elif self.helix_layout == "double" and not (self.half_gap >= 0 and self.groove_depth > 0):
            problems.append(f"a double helix needs half_gap >= 0 and groove_depth > 0 [m], got {self.half_gap}, "
                            f"{self.groove_depth}")
        if self.internal and not self.rim_thickness > 0:
            problems.append(f"an internal gear needs rim_thickness > 0 [m], got {self.rim_thickness}")
        if not self.internal and not self.bore_diameter > 0:
            problems.append(f"an external gear needs bore_diameter > 0 [m], got {self.bore_diameter}")
        if self.seat_width is not None and not 0 < self.seat_width <= self.length:
            problems.append(f"seat_width must be in (0, {self.length}] m (the body's length) or None, "
                            f"got {self.seat_width}")
        if not 0 < self.tooth_mesh_size <= 2 * m:
            problems.append(f"tooth_mesh_size must be in (0, 2 m_n = {2 * m}] m (Netgen fails in the tooth spaces "
                            f"above about 2.5 m_n), got {self.tooth_mesh_size}")
        if not self.body_mesh_size > 0 or self.element_order not in (1, 2):
            problems.append(f"body_mesh_size must be > 0 [m] and element_order 1 or 2, got {self.body_mesh_size}, "
                            f"{self.element_order}")
        if not self.internal and self.name == "ring":
            problems.append("the name 'ring' marks an internal gear's outline (flexgear.geometry.layout.Section)")
        if problems:
            raise ValueError("GearBody: " + "; ".join(problems))
        if not self.internal and self.bore_diameter / 2 >= self.gear.root_radius - self._groove():
            raise ValueError(f"GearBody: bore_diameter {self.bore_diameter} m does not fit inside the "
                             f"{'groove' if self._groove() else 'root'} circle (radius "
                             f"{self.gear.root_radius - self._groove()} m)")

    def _groove(self) -> float:
        return self.groove_depth if self.helix_layout == "double" else 0.0

    @property
    def gear(self) -> Gear:
        """The involute gear (flexgear.geometry.involute.Gear)."""
        return Gear(self.teeth, self.internal, self.normal_module, self.helix_angle, self.pressure_angle, self.shift,
                    self.thinning, self.addendum_coefficient, self.dedendum_coefficient, self.face_width)

    @property
    def profile(self) -> ToothProfile:
        """The transverse tooth profile (flexgear.geometry.profile), root fillet radius
        ``root_fillet_coefficient`` * m_n."""
        return _profile(self.gear, self.root_fillet_coefficient)

    @property
    def helix_width(self) -> float:
        """Face width of one helix [m]: half the total for a double helix."""
        return self.face_width / 2 if self.helix_layout == "double" else self.face_width

    @property
    def length(self) -> float:
        """Axial length of the body [m]: the face width, plus the gap of a double helix."""
        return self.face_width + (self.half_gap if self.helix_layout == "double" else 0.0)

    @property
    def section_key(self) -> str:
        """Name of the toothed sections' profile: "ring" for an internal gear (the outline flexgear.geometry.solids
        builds inside a rim), else ``name``."""
        return "ring" if self.internal else self.name

    @property
    def seat_radius(self) -> float:
        """Radius [m] of the seat's cylinder: the bore, or the rim's outer surface."""
        return self.gear.root_radius + self.rim_thickness if self.internal else self.bore_diameter / 2

    def layout(self) -> ComponentLayout:
        """The body's prisms about its axial mid-plane (flexgear.geometry.layout.toothed_prisms)."""
        return _layout(self)

    def mass_properties(self) -> MassProperties:
        """Exact mass [kg], centre of mass [m] and inertia about it [kg m^2] from the section integrals
        (flexgear.geometry.layout.layout_mass_properties)."""
        return layout_mass_properties(self.layout(), {self.section_key: self.profile}, self.material.density_kg_m3)

    @classmethod
    def from_gear(cls, gear: Gear, *, name: str = "gear", **body) -> GearBody:
        """The body of ``gear`` (its teeth, module, angles, shift, thinning, coefficients, face width and
        ``internal``); ``body``: the other fields (``bore_diameter`` or ``rim_thickness``, ``hand``,
        ``helix_layout``, ``material``, mesh sizes, ...)."""
        return cls(gear.teeth, gear.normal_module, gear.face_width, gear.helix_angle, gear.normal_pressure_angle,
                   gear.shift, gear.thinning, gear.addendum_coefficient, gear.dedendum_coefficient,
                   internal=gear.internal, name=name, **body)

    @classmethod
    def from_gear_set(cls, spec: GearboxSpec, component: str, level: str = "coarse", **changes) -> GearBody:
        """Gear ``component`` ("sun", "planet" or "ring") of ``spec``'s gear set with its bore or rim, the helix
        layout, material and mesh sizes of mesh ``level`` of the spec; ``changes`` override fields.

        The sun's and planet's layouts are the study's own (flexgear.geometry.layout.component_layout); the ring
        is its toothed rim, without the flange and bolt holes of the study's ring. The seat is the whole bore
        (the ring: the rim's outer surface).
        """
        if component not in _HANDS:
            raise ValueError(f"from_gear_set: component must be one of {', '.join(_HANDS)}, got {component!r}")
        gs, a, c = gear_set_geometry(spec), spec.gears_assumed, spec.components_assumed
        mesh = spec.meshing_assumed[level]
        gear = getattr(gs, component)
        body = dict(
            root_fillet_coefficient=a.root_fillet_coefficient, hand=_HANDS[component], helix_layout=a.helix_layout,
            half_gap=a.half_gap_m, groove_depth=c.relief_groove_depth_mm * 1e-3, material=spec.material_assumed,
            tooth_mesh_size=mesh.sizes_mm(component)[0] * 1e-3, body_mesh_size=mesh.sizes_mm(component)[1] * 1e-3,
            element_order=mesh.element_order, elements_per_curvature_radius=mesh.elements_per_curvature_radius,
            optimisation_steps=mesh.optimisation_steps)
        if component == "ring":
            body["rim_thickness"] = c.ring_rim_thickness_mm * 1e-3
        else:
            body["bore_diameter"] = getattr(c, f"{component}_bore_diameter_mm") * 1e-3
        return cls.from_gear(gear, name=component, **{**body, **changes})


@lru_cache(maxsize=32)
def _profile(gear: Gear, fillet_coefficient: float) -> ToothProfile:
    """The tooth profile as flexgear.geometry.layout.tooth_profiles makes the study's (the same curves)."""
    return tooth_profile(gear, fillet_coefficient * gear.normal_module)


@lru_cache(maxsize=32)
def _layout(body: GearBody) -> ComponentLayout:
    gear = body.gear
    inner, outer = (0.0, body.seat_radius) if body.internal else (body.bore_diameter / 2, 0.0)
    prisms = toothed_prisms(body.section_key, gear, inner, outer, body.hand, body.helix_layout, body.face_width,
                            body.half_gap, body.groove_depth)
    return ComponentLayout(body.name, tuple(prisms), gear, body.profile)


@dataclass(frozen=True)
class Engagement:
    """Where a toothed body meshes: in ``mesh`` (flexgear.geometry.involute.GearMesh, gear 1 external) as its gear
    ``gear`` (1 or 2), gear 1 pushing gear 2 counter-clockwise about +z (``drive_sign`` +1) or clockwise (-1),
    its contacts at the polar ``angles`` [rad] about the body's centre (in its frame: where the partners sit).

    The body's hand is that of its own helix at +z; gear 1's there follows (the same for an internal gear 2, the
    opposite for an external one). The mesh's gear must be the body's gear.
    """

    mesh: GearMesh
    gear: int = 1
    drive_sign: int = 1
    angles: tuple[float, ...] = (0.0,)

    def __post_init__(self):
        if self.gear not in (1, 2) or self.drive_sign not in (1, -1):
            raise ValueError(f"Engagement: gear must be 1 or 2 and drive_sign +1 or -1, got {self.gear!r}, "
                             f"{self.drive_sign!r}")
        object.__setattr__(self, "angles", tuple(float(a) for a in self.angles))

    def gear_of(self) -> Gear:
        """The body's gear in the mesh."""
        return self.mesh.gear1 if self.gear == 1 else self.mesh.gear2

    def first_hand(self, body: GearBody) -> int:
        """The hand of gear 1 at +z when ``body`` is this engagement's gear."""
        if self.gear == 1 or self.mesh.internal:
            return body.hand
        return -body.hand
