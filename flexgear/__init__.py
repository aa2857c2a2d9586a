"""flexgear: dynamics of geared transmissions on Exudyn, rigid or flexible, screened against theory.

The public API (``__all__``) builds any gearbox in a few lines: gear geometry (``gear_pair_geometry``),
bodies (``add_rigid_body``, ``add_flexible_body`` from a mesh via ``fe_model`` and ``reduce``), bearings
(``Bushing``, ``add_planet_bearing``), fixed joints (``add_fixed_joint``, ``add_interface_joint``), gear
contacts for external and internal meshes (``pair_contacts``, assembled by ``add_gear_train``, optionally
on a rotating ``Carrier``), drive and load (``add_speed_drive``, ``add_load_torque``) and signals
(``Recorder``, ``solve``). The GTF star gearbox of the reference study is built from the same parts
(``build_star_gearbox``, ``run_variant``). Modules that pull in Exudyn, NGSolve or pandas are imported on
first use, so ``import flexgear`` stays light.
"""

from importlib import import_module

from flexgear.involute import Gear, GearSetGeometry, Mesh, gear_set_geometry, solve_profile_shifts
from flexgear.spec import GearboxSpec, SpecError, Variant, load_gearbox, load_variant, spec_hash
from flexgear.theory import Theory, step, step_integral, theory

__version__ = "0.1.0"

_LAZY = {
    # geometry
    "HelixHalf": "gearpair", "helix_halves": "gearpair", "gear_pair_geometry": "gearpair",
    "pair_contacts": "gearpair", "annulus_mass_properties": "gearpair",
    # bodies
    "MassProperties": "massprops", "combine_mass_properties": "massprops",
    "Body": "bodies", "add_rigid_body": "bodies",
    "FlexibleBody": "flexible", "add_flexible_body": "flexible",
    "fe_model": "fem", "ReducedBody": "cms", "interface": "cms", "reduce": "cms",
    "LoadCircle": "fe.attachment", "static_compliance": "fe.compliance",
    # connectors
    "Bushing": "connectors", "ContactLaw": "connectors", "GearContact": "connectors",
    "add_fixed_joint": "connectors", "add_interface_joint": "connectors", "add_speed_drive": "connectors",
    "add_load_torque": "connectors",
    "drive_angle": "connectors",
    "Carrier": "carrier", "add_planet_bearing": "carrier",
    "GearTrain": "train", "add_gear_train": "train",
    # signals and solving
    "Recorder": "recording", "solve": "recording", "solver_settings": "recording",
    # the study's gearbox
    "build_star_gearbox": "model", "mesh_contacts": "model", "run_variant": "simulate",
}

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
    *_LAZY,
]


def __getattr__(name: str):
    """Import the public names of the heavier modules on first use (PEP 562)."""
    if name in _LAZY:
        value = getattr(import_module(f"flexgear.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'flexgear' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
