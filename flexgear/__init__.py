"""flexgear: dynamics of geared transmissions on Exudyn, rigid or flexible, screened against theory."""

from flexgear.involute import Gear, GearSetGeometry, Mesh, gear_set_geometry, solve_profile_shifts
from flexgear.spec import GearboxSpec, SpecError, Variant, load_gearbox, load_variant, spec_hash
from flexgear.theory import Theory, step, step_integral, theory

__version__ = "0.1.0"

__all__ = [
    "Gear",
    "GearSetGeometry",
    "GearboxSpec",
    "Mesh",
    "SpecError",
    "Theory",
    "Variant",
    "gear_set_geometry",
    "load_gearbox",
    "load_variant",
    "solve_profile_shifts",
    "spec_hash",
    "step",
    "step_integral",
    "theory",
]
