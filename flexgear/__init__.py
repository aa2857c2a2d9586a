"""flexgear: dynamics of geared transmissions on Exudyn, rigid or flexible, screened against theory.

The public API (``__all__``) builds any gearbox in a few lines: gear geometry (``gear_pair_geometry``),
bodies (``add_rigid_body``, ``add_flexible_body`` from a mesh via ``fe_model`` and ``reduce``; parts bolted or
bonded together tied into one body first, ``reduce([fe_a, fe_b], ..., ties=[Tie(...)])``; any gear as a toothed
body built as the study's gears, ``GearBody`` -> ``toothed_body`` (flexible, its high modes as residual
compliance through ``dropped_modes``) or ``toothed_mass_properties`` (rigid); a planetary stage's carrier,
``carrier_sizes`` -> ``carrier_body`` or ``carrier_mass_properties``), bearings
(``BearingElement``: a 6x6 stiffness and damping about a point on an axis, on a body frame or an interface,
``add_planet_bearing``), fixed joints (``FixedJointElement``, ``add_fixed_joint``, ``add_interface_joint``), gear
contacts for external and internal meshes (``pair_contacts``, assembled by ``add_gear_train``, optionally
on a rotating ``Carrier``), drive and load (``add_speed_drive``, ``add_load_torque``) and signals
(``Recorder``, ``solve``). A gearbox file's gearbox is built from the same parts (``build_gearbox``: the star,
or the planetary stage with rigid components; ``run_variant``). Modules that pull in Exudyn, NGSolve or pandas
are imported on first use, so ``import flexgear`` stays light. Names that moved stay deprecated aliases until
their removal version (``_DEPRECATED``).
"""

from importlib import import_module

from flexgear import sizing as _sizing  # noqa: F401  (registers the sizes that follow the gear set)
from flexgear.deprecation import moved
from flexgear.geometry import feasibility as _feasibility  # noqa: F401  (registers the load-time feasibility checks)
from flexgear.geometry.involute import Gear, GearMesh, GearSetGeometry, Mesh, gear_set_geometry, solve_profile_shifts
from flexgear.laws.ramps import step, step_integral
from flexgear.spec import GearboxSpec, SpecError, Variant, load_gearbox, load_variant, spec_hash
from flexgear.theory import Theory, theory

__version__ = "0.1.0"

_LAZY = {
    # geometry
    "HelixHalf": "geometry.pair", "helix_halves": "geometry.pair", "gear_pair_geometry": "geometry.pair",
    "annulus_mass_properties": "geometry.massprops",
    "MassProperties": "geometry.massprops", "combine_mass_properties": "geometry.massprops",
    "BearingElement": "geometry.elements", "FixedJointElement": "geometry.elements",
    # FE and reduction
    "fe_model": "fe.fem", "ReducedBody": "fe.cms", "interface": "fe.cms", "reduce": "fe.tied",
    "Tie": "fe.tied", "TiedFE": "fe.tied", "tie_parts": "fe.tied",
    "LoadCircle": "fe.attachment", "static_compliance": "fe.compliance",
    # toothed bodies of any gear set, rigid or flexible, built as the study's gears
    "GearBody": "geometry.gear_body", "Engagement": "geometry.gear_body",
    "toothed_body": "fe.toothed", "toothed_mass_properties": "fe.toothed", "toothed_fe_model": "fe.toothed",
    "toothed_contacts": "fe.toothed", "toothed_load_circles": "fe.toothed",
    # a planetary stage's carrier: its sizes, solid, exact mass properties, FE model and reduced body
    "CarrierSizes": "geometry.carrier", "carrier_sizes": "geometry.carrier", "carrier_solid": "geometry.carrier",
    "carrier_mass_properties": "geometry.carrier", "carrier_fe_model": "fe.carrier", "carrier_body": "fe.carrier",
    # laws
    "ContactLaw": "laws.contact", "drive_angle": "laws.ramps",
    # multibody: bodies, elements, contacts
    "Body": "mbs.bodies", "add_rigid_body": "mbs.bodies", "LinearFrame": "mbs.bodies", "add_linear_frame": "mbs.bodies",
    "FlexibleBody": "mbs.flexible", "add_flexible_body": "mbs.flexible", "SpinSchedule": "mbs.spin",
    "add_fixed_joint": "mbs.elements", "add_interface_joint": "mbs.elements",
    "add_speed_drive": "mbs.elements", "add_load_torque": "mbs.elements",
    "GearContact": "mbs.contacts", "pair_contacts": "mbs.contacts", "dropped_modes": "mbs.residual",
    "Carrier": "mbs.carrier", "add_planet_bearing": "mbs.carrier",
    "GearTrain": "mbs.train", "add_gear_train": "mbs.train",
    # signals and solving
    "Recorder": "mbs.recording", "solve": "mbs.recording", "solver_settings": "mbs.recording",
    # the study's gearbox
    "build_gearbox": "mbs.assemble", "build_star_gearbox": "mbs.gearbox", "mesh_contacts": "mbs.gearbox",
    "run_variant": "mbs.run",
    # the facade: a gearbox and its flexible components in; runs, linear models, modes, reports out
    "Simulation": "simulation",
    # modal analysis at the operating point
    "linearize": "modal.linear", "LinearModel": "modal.linear",
    "modes": "modal.eigenmodes", "Modes": "modal.eigenmodes",
    "period_modes": "modal.period",
}

__all__ = [
    "Gear",
    "GearMesh",
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


_DEPRECATED = {
    # old name: (new name in flexgear, the version that removes the old one); one line per moved name
    "Bushing": ("BearingElement.axisymmetric", "0.3"),  # 0.1's Bushing(body, k_r, k_a, k_t, damping_per_stiffness)
}


def __getattr__(name: str):
    """Import the public names of the heavier modules on first use (PEP 562); a moved name (``_DEPRECATED``) gives
    its new object with a DeprecationWarning."""
    if name in _LAZY:
        value = getattr(import_module(f"flexgear.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    if name in _DEPRECATED:
        return moved(__name__, name, *_DEPRECATED[name])
    raise AttributeError(f"module 'flexgear' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
