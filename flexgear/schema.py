"""Schema of the gearbox and variant files: one frozen dataclass per TOML table.

Each field carries its check in its metadata (range, integer, choices), applied by
:func:`flexgear.spec.load_gearbox`. Field names carry their unit where the file uses one outside SI
(``_mm``, ``_deg``, ``_rpm``); the dataclasses expose SI values through properties. The loading,
consistency checks and hashing are in :mod:`flexgear.spec`, which re-exports every name here.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flexgear.schema_fields import SpecError, choice_field, derived_field, num_field
from flexgear.schema_gears import (
    CARRIER,
    COMPONENT_GEOMETRY,
    COMPONENTS,
    GEAR_COMPONENTS,
    GEOMETRY_COMPONENTS,
    OPTIONAL_COMPONENTS,
    PLANET_POSITION_TOLERANCE_STEPS,
    SHAFT_COMPONENTS,
    GearSet,
    stage_components,
    stage_geometries,
)
from flexgear.schema_geometry import ComponentGeometry
from flexgear.schema_published import PublishedResults
from flexgear.schema_screening import (
    IndicatorTolerance,
    IndicatorWeights,
    LevelTolerance,
    LoadTolerance,
    ReferenceIndicators,
    ScreeningSettings,
)

__all__ = [
    "SpecError", "GearSet", "GearSetAssumed", "Material", "ComponentsAssumed", "Bearing", "Bearings", "Contact",
    "ContactAssumed", "JointsAssumed", "REMOVED_FIELDS", "LoadCase", "SolverSettings", "MeshingSettings",
    "ReductionSettings", "IndicatorWeights", "IndicatorTolerance", "LoadTolerance",
    "LevelTolerance", "ReferenceIndicators", "ScreeningSettings",
    "LumpedAssumed", "GearboxSpec", "Variant", "COMPONENTS", "stage_components", "stage_geometries",
    "GEAR_COMPONENTS", "SHAFT_COMPONENTS", "GEOMETRY_COMPONENTS", "COMPONENT_GEOMETRY", "CARRIER",
    "OPTIONAL_COMPONENTS", "PLANET_POSITION_TOLERANCE_STEPS",
]
@dataclass(frozen=True, kw_only=True)
class GearSetAssumed:
    """Gear data the study does not give (documented in gearbox.toml). Fields marked ``derived`` follow the gear
    data when the file leaves them out (:mod:`flexgear.sizing`); the others have fixed defaults."""

    face_width_mm: float = derived_field(0.0, lo_open=True, doc="mm per helix half")
    helix_layout: str = choice_field("double", "single", default="single")
    half_gap_mm: float = derived_field(0.0, doc="mm, half the axial gap between the helix halves")
    operating_centre_distance_mm: float = num_field(0.0, default=0.0, doc="mm; 0 = mean of the standard distances")
    planet_shift_coefficient: float = num_field(-1.0, 1.5, default=0.0)
    addendum_coefficient: float = num_field(0.5, 1.5, default=1.0, doc="ISO 53 basic rack")
    dedendum_coefficient: float = num_field(0.8, 2.0, default=1.25, doc="ISO 53 basic rack")
    root_fillet_coefficient: float = num_field(0.0, 0.6, default=0.3)
    normal_backlash_mm: float = derived_field(0.0, doc="mm along the normal, per mesh")
    outer_inner_mesh_phase: float = num_field(0.0, 1.0, default=0.0)

    @property
    def face_width_m(self) -> float:
        return self.face_width_mm * 1e-3

    @property
    def half_gap_m(self) -> float:
        return self.half_gap_mm * 1e-3

    @property
    def operating_centre_distance_m(self) -> float:
        return self.operating_centre_distance_mm * 1e-3

    @property
    def normal_backlash_m(self) -> float:
        return self.normal_backlash_mm * 1e-3


@dataclass(frozen=True)
class Material:
    """Gear and shaft material (assumed: through-hardened gear steel)."""

    # ranges of any engineering solid: outside them the value is a unit slip (g/cm^3, GPa, MPa)
    density_kg_m3: float = num_field(500.0, 25000.0, default=7850.0)
    youngs_modulus_pa: float = num_field(1e8, 1e13, default=2.1e11)
    poisson_ratio: float = num_field(0.0, 0.5, default=0.3)


@dataclass(frozen=True, kw_only=True)
class ComponentsAssumed:
    """Bores, rim, flange and shaft dimensions [mm] (assumed: the study gives no drawing). Every size left out of
    the file follows the gear set (:mod:`flexgear.sizing`)."""

    sun_bore_diameter_mm: float = derived_field(0.0, lo_open=True)
    planet_bore_diameter_mm: float = derived_field(0.0, lo_open=True, doc="mm, the planet bearing's seat")
    ring_rim_thickness_mm: float = derived_field(0.0, lo_open=True, doc="mm, radial, below the tooth root")
    ring_flange_outer_diameter_mm: float = derived_field(0.0, lo_open=True)
    ring_flange_thickness_mm: float = derived_field(0.0, lo_open=True)
    ring_bolt_count: int = num_field(1, integer=True, default=12)
    ring_bolt_hole_diameter_mm: float = derived_field(0.0, lo_open=True)
    input_shaft_outer_diameter_mm: float = derived_field(0.0, lo_open=True)
    input_shaft_inner_diameter_mm: float = derived_field(0.0)
    input_shaft_length_mm: float = derived_field(0.0, lo_open=True)
    output_shaft_outer_diameter_mm: float = derived_field(0.0, lo_open=True)
    output_shaft_inner_diameter_mm: float = derived_field(0.0)
    output_shaft_length_mm: float = derived_field(0.0, lo_open=True)
    relief_groove_depth_mm: float = derived_field(0.0, doc="mm beyond the root circle")
    bearing_seat_width_mm: float = derived_field(0.0, lo_open=True)


@dataclass(frozen=True)
class Bearing:
    """One bearing (bushing) of Table 2.

    The study's "torsional stiffness" is read as the tilting stiffness about the two axes
    normal to the shaft (N·m/rad): a bearing leaves the spin free. Damping is assumed
    stiffness-proportional, c = k · damping_per_stiffness_s.
    """

    radial_stiffness_n_per_m: float = num_field(0.0)
    axial_stiffness_n_per_m: float = num_field(0.0)
    tilt_stiffness_nm_per_rad: float = num_field(0.0)
    damping_per_stiffness_s: float = num_field(0.0, default=1e-5)


@dataclass(frozen=True)
class Bearings:
    """Table 2: input-shaft, output-shaft and planet bearings."""

    input_shaft: Bearing
    output_shaft: Bearing
    planet: Bearing | None = None  # required in the star and planetary stages; none in the parallel-axis pair


@dataclass(frozen=True)
class Contact:
    """Gear contact of section 2.1 (ADAMS impact function), one value for both mesh types."""

    stiffness: float = num_field(0.0, lo_open=True, doc="N/m^exponent", default=1e8)
    exponent: float = num_field(1.0, 3.0, default=1.5)
    damping_fraction_of_stiffness: float = num_field(0.0, default=1e-3)
    penetration_depth_m: float = num_field(0.0, lo_open=True, default=1e-4)
    friction_coefficient: float = num_field(0.0, 1.0, default=0.02)
    # "impact": the study's ADAMS law (section 2.1, the fields above, whose defaults are the study's values);
    # "iso6336": linear mesh stiffness of ISO 6336-1 from the gear geometry (flexgear.laws.iso6336) with eq. 13
    # damping ([contact_assumed] mesh_damping_ratio), the default: it follows any gear set
    law: str = field(default="iso6336", metadata={"choices": ("impact", "iso6336"), "doc": "contact law"})


@dataclass(frozen=True)
class ContactAssumed:
    """Contact modelling choices the study does not give."""

    stiffness_harmonics: int = num_field(0, 10, integer=True, default=3)
    stiffness_variation: str = choice_field("contact_lines", "constant", default="contact_lines")
    friction_regularisation_m_per_s: float = num_field(0.0, lo_open=True, default=0.01)
    mesh_damping_ratio: float = field(default=0.10, metadata={"lo": 0.0, "hi": 1.0,
                                                              "doc": "xi of eq. 13 (iso6336 law)"})
    application_factor: float = field(default=1.0, metadata={"lo": 1.0, "doc": "K_A of ISO 6336-1 (iso6336 law)"})


@dataclass(frozen=True, kw_only=True)
class LoadCase:
    """Table 5: input speed and load torque as STEP ramps."""

    input_speed_rpm: float = num_field()
    load_torque_nm: float = num_field()
    ramp_time_s: float = num_field(0.0, lo_open=True)
    end_time_s: float = num_field(0.0, lo_open=True)
    step_size_s: float = derived_field(0.0, lo_open=True, doc="s, a 24th of the mesh period when left out")
    # "time": stop at end_time_s; "settled": from end_time_s on, continue in chunks of settle_chunk_s until the
    # settling test (flexgear.settling, [screening] settle_*) passes or settle_max_time_s is reached
    end: str = choice_field("time", "settled", default="time")
    settle_chunk_s: float = num_field(0.0, lo_open=True, default=0.1)
    settle_max_time_s: float = num_field(0.0, lo_open=True, default=2.0)

    @property
    def input_speed_rad_s(self) -> float:
        return self.input_speed_rpm * 2.0 * math.pi / 60.0


@dataclass(frozen=True)
class SolverSettings:
    """Time-integration settings (assumed; the study used ADAMS GSTIFF)."""

    spectral_radius: float = num_field(0.0, 1.0, default=0.8)
    newton_max_modified_iterations: int = num_field(1, 50, integer=True, default=3)
    newton_relative_tolerance: float = num_field(0.0, 1e-2, lo_open=True, default=1e-6)
    # warm-started Newton's absolute tolerance over newton_relative_tolerance x N F_n (flexgear.mbs.newton)
    newton_warm_start_tolerance_factor: float = num_field(1.0, 100.0, default=5.0)
    record_every_steps: int = num_field(1, integer=True, default=1)
    # "production": the package's formulation (linear body frames and floating frames about the prescribed spin,
    # linear joint and seat equations, Jacobian economy); "reference": Exudyn's nonlinear objects (ObjectRigidBody,
    # ObjectFFRFreducedOrder, ObjectJointGeneric, marker seats), for the tests that check the production one
    formulation: str = choice_field("production", "reference", default="production")
    # divergence guard (flexgear.mbs.run.RunGuard)
    wall_time_budget_s: float = num_field(0.0, lo_open=True, default=7200.0)
    runaway_speed_factor: float = num_field(1.0, lo_open=True, default=3.0)
    # interval [s] of the spin-term updates in the ramps (flexgear.mbs.spin.SpinSchedule)
    spin_update_interval_s: float = num_field(0.0, lo_open=True, default=5e-4)
    # bodies axisymmetric within this relative tolerance take the linear frame (flexgear.mbs.bodies.add_linear_frame)
    frame_axisymmetry_tolerance: float = num_field(0.0, 1.0, default=1e-4)
    # a Jacobian's cost in Newton iterations (flexgear.mbs.newton.JacobianEconomy)
    jacobian_cost_iterations: float = num_field(1.0, default=12.0)

    @property
    def reference(self) -> bool:
        """Whether the run uses the reference formulation (Exudyn's nonlinear objects) instead of production's."""
        return self.formulation == "reference"


@dataclass(frozen=True, kw_only=True)
class MeshingSettings:
    """Mesh sizes per level (assumed); the levels ``coarse`` and ``default`` exist in every gearbox, their sizes
    following the normal module when the file leaves them out (:mod:`flexgear.sizing`)."""

    tooth_size_mm: float = derived_field(0.0, lo_open=True)
    body_size_mm: float = derived_field(0.0, lo_open=True)
    # The ring's own sizes (tooth and bolt-hole faces / elsewhere): its thin rim and the teeth on it set its
    # bending modes, which need finer elements than the solid gears' (flexgear.sizing, docs/configuration.md).
    ring_tooth_size_mm: float = derived_field(0.0, lo_open=True)
    ring_body_size_mm: float = derived_field(0.0, lo_open=True)
    element_order: int = num_field(1, 2, integer=True, default=2)
    # Netgen curvaturesafety: element size <= curvature radius / this on curved faces and edges.
    elements_per_curvature_radius: float = num_field(0.0, lo_open=True, default=0.3, derived=True)
    # Netgen optsteps2d and optsteps3d: smoothing/swapping passes after surface and volume meshing.
    optimisation_steps: int = num_field(0, 10, integer=True, default=3, derived=True)

    def sizes_mm(self, component: str) -> tuple[float, float]:
        """(tooth, body) element size [mm] of ``component``: the ring's own, the level's for every other."""
        if component == "ring":
            return self.ring_tooth_size_mm, self.ring_body_size_mm
        return self.tooth_size_mm, self.body_size_mm

    def for_component(self, component: str) -> dict[str, float | int]:
        """The settings ``component`` is meshed with, its sizes under the level's names (``tooth_size_mm``,
        ``body_size_mm``): what its mesh and reduced body depend on, so what their cache keys hash (another
        component's sizes do not rebuild them)."""
        tooth, body = self.sizes_mm(component)
        return {"tooth_size_mm": tooth, "body_size_mm": body, "element_order": self.element_order,
                "elements_per_curvature_radius": self.elements_per_curvature_radius,
                "optimisation_steps": self.optimisation_steps}


@dataclass(frozen=True, kw_only=True)
class ReductionSettings:
    """Component-mode synthesis settings for flexible bodies (assumed)."""

    # every fixed-interface mode below this frequency [Hz] joins each body's basis
    fixed_interface_cutoff_hz: float = derived_field(0.0, lo_open=True, doc="Hz, 3.5 mesh orders when left out")
    modal_stiffness_damping_s: float = num_field(0.0, default=1e-5)
    contact_fourier_order: int = num_field(1, 60, integer=True, default=8)
    # Fourier order of the attachment load patterns on each gear's contact bands (0: none).
    attachment_order: int = num_field(0, 60, integer=True, default=8)
    # gears: modes above this multiple of the mesh frequency become static residual compliance (0: all dynamic)
    dynamic_cutoff_mesh_orders: float = num_field(0.0, 1000.0, default=0.0)


@dataclass(frozen=True, kw_only=True)
class LumpedAssumed:
    """Lumped-parameter model only (flexgear.lumped.run, section 2.3): values the study does not give.

    See ``[lumped_assumed]`` in gearbox.toml for each value's source.
    """

    mesh_stiffness_per_width_n_per_mm_um: float = num_field(0.0, lo_open=True, doc="C_gamma of eq. 10", default=20.0)
    mesh_damping_ratio: float = num_field(0.0, 1.0, doc="xi of eq. 13", default=0.10)
    integration_substeps: int = num_field(1, 64, integer=True, default=2)
    friction_table_points: int = num_field(16, 65536, integer=True, default=512)
    carrier_mass_kg: float = derived_field(0.0, lo_open=True)
    carrier_inertia_kg_m2: float = derived_field(0.0, lo_open=True)

    @property
    def mesh_stiffness_per_width_n_per_m2(self) -> float:
        """C_gamma in SI: 1 N/(mm um) = 1e9 N/m^2."""
        return self.mesh_stiffness_per_width_n_per_mm_um * 1e9


@dataclass(frozen=True)
class JointsAssumed:
    """The bolted joint of the ring and the output shaft (section 2.1: 12 bolts), flexgear.fe.bolted."""

    bolt_clamp_diameter_mm: float = derived_field(0.0, lo_open=True, doc="mm, clamped disc under each bolt head")


_REFERENCE = 'the production formulation is the only one; formulation = "reference" selects Exudyn\'s'
REMOVED_FIELDS: dict[str, str] = {
    "reduction_assumed.fixed_interface_modes": ("a basis is sized by frequency, not by count: every fixed-interface "
                                                "mode below fixed_interface_cutoff_hz"),
    "solver_assumed.linear_solver": "Eigen's sparse LU is the only linear solver",
    "solver_assumed.frame_equations": f"{_REFERENCE} ObjectRigidBody",
    "solver_assumed.sparse_ordering": "the sparse LU keeps its ordering while the pattern holds (production)",
    "solver_assumed.jacobian_updates": "the Jacobian economy is production's rule; the reference uses Exudyn's",
    "reduction_assumed.interface": "seat and joint interfaces are RBE3 averages, bolt patches rigid",
    "reduction_assumed.simulation_modes": "the whole basis is kept; gears drop modes by dynamic_cutoff_mesh_orders",
    "reduction_assumed.floating_frame": f"{_REFERENCE} ObjectFFRFreducedOrder",
    "reduction_assumed.modal_coordinates": "linear joints and seats always have interface coordinates (production)",
    "reduction_assumed.residual_seat_loads": "a gear's dropped modes answer its seat's own load (production)",
    "supports_assumed": "bearings, drive and load act at the bearing seats, the only placement",
    "joints_assumed.ring_output_shaft": ("the ring and the output shaft are tied over the bolts' clamped discs "
                                          "(section 2.1): one body when both are flexible, one rigid bolt-patch "
                                          "interface and one joint otherwise"),
    "joints_assumed.bolt_patch": ("the clamped discs move with the rigid partner, or are tied node to face when both "
                                  "parts are flexible"),
    "joints_assumed.joint_equations": f"{_REFERENCE} ObjectJointGeneric",
    "joints_assumed.joint_axes": "a joint is written in body axes where its shaft is flexible, else in ground axes",
}
"""Fields and tables that no longer exist, each with what replaced it (flexgear.spec names them in its error)."""


@dataclass(frozen=True)
class GearboxSpec:
    """The whole gearbox: the study's tables plus documented assumptions."""

    source: Path
    title: str
    gears: GearSet
    gears_assumed: GearSetAssumed
    material_assumed: Material
    components_assumed: ComponentsAssumed
    bearings: Bearings
    contact: Contact
    contact_assumed: ContactAssumed
    load_case: LoadCase
    solver_assumed: SolverSettings
    meshing_assumed: dict[str, MeshingSettings]
    reduction_assumed: ReductionSettings
    screening: ScreeningSettings
    lumped_assumed: LumpedAssumed
    joints_assumed: JointsAssumed
    # "table.field" of every value the file left out that followed the gear data (flexgear.sizing); not hashed
    derived: tuple[str, ...] = ()
    # components whose solid or volume mesh comes from a file (flexgear.schema_geometry); the files' content hashed
    components_geometry: dict[str, ComponentGeometry] = field(default_factory=dict)
    published: PublishedResults | None = None  # a source study's results, for the report (flexgear.schema_published)

    def with_changes(self, **tables: Any) -> GearboxSpec:
        """A new spec with whole tables replaced (``spec.with_changes(load_case=lc)``)."""
        return dataclasses.replace(self, **tables)

    def with_fields(self, table: str, **fields: Any) -> GearboxSpec:
        """A new spec with single fields of one table replaced (``spec.with_fields("solver_assumed",
        formulation="reference")``)."""
        return dataclasses.replace(self, **{table: dataclasses.replace(getattr(self, table), **fields)})


@dataclass(frozen=True)
class Variant:
    """One row of Table 3: the gearbox plus rigid/flexible per component."""

    source: Path
    name: str
    gearbox: GearboxSpec
    components: dict[str, str]
    mesh_level: str = "default"
    # Mass properties of the rigid components: "mesh" = those of the reduced flexible body built from
    # the same mesh at mesh_level (rigid and flexible twins identical, the variant matrix compares like
    # with like); "exact" = the exact geometry's volume integrals (no mesh needed).
    rigid_mass_properties: str = "mesh"

    def is_rigid(self) -> bool:
        return all(v == "rigid" for v in self.components.values())
