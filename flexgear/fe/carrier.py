"""The planet carrier as an FE model and a reduced flexible body (flexgear.geometry.carrier).

The carrier's solid is meshed by Netgen at a mesh level of ``[meshing_assumed]``: the level's body size, its tooth
size on the pin bores (where the planets' bearing loads enter). Named faces become the FE model's regions:

- ``pin_<k>``: the two pin bores of planet k (one in each plate), the interface where the planet's pin, and through
  it the planet's bearing, acts: RBE3, its point the pin's centre on the mid-plane;
- ``seat``: the output-side plate's bore, on the output shaft: a rigid interface (the shaft's spline holds it).

A carrier from the user's file (``[components_geometry] carrier``) is meshed or read by flexgear.fe.carrier_part,
its seat and pins found there by geometry; everything below is the same for it.

The reduced body is the Craig-Bampton reduction of flexgear.fe.cms with those interfaces and every fixed-interface
mode below :data:`CUTOFF_FACTOR` times the gearbox's ``[reduction_assumed] fixed_interface_cutoff_hz``, cached by its
inputs' hash.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from flexgear.fe.carrier_part import imported_carrier_mesh, level_mesh, pin_bore_faces
from flexgear.fe.cms import ReducedBody, interface, reduce
from flexgear.fe.fem import FEModel, fe_model
from flexgear.fe.imported import IMPORT_VERSION
from flexgear.fe.parts import exchange_form
from flexgear.fe.reduced import cached_reduced_body
from flexgear.geometry.carrier import CarrierSizes, carrier_sizes, carrier_solid
from flexgear.progress import say
from flexgear.schema import CARRIER
from flexgear.spec import GearboxSpec, spec_hash

__all__ = ["carrier_fe_model", "carrier_volume_mesh", "carrier_body", "carrier_body_key", "carrier_interfaces",
           "carrier_exchange_solid",
           "pin_interface", "SEAT", "CUTOFF_FACTOR"]

CUTOFF_FACTOR = 3.0
"""The carrier's fixed-interface modes reach this multiple of the gearbox's cutoff (3.5 mesh orders). The gears carry
attachment modes of their contact loads; the carrier has none, and its pins' static modes alone leave its modes
in the band (3 mesh orders) up to 17 % stiff. The spur planetary example's carrier, seat held, modes to 3 mesh
orders against full FE: cutoff x1 (no fixed-interface mode) 17 %, x2 (6) 1.05 %, x3 (15) 0.11 %, x4 (21) 0.11 %
(benchmarks/RESULTS.md)."""
SEAT = "seat"
"""The carrier's interface on the output shaft."""


def pin_interface(k: int) -> str:
    """The name of the interface of planet ``k``'s pin (0-based, in the order of the planets' angles)."""
    return f"pin_{k}"
_VERSION = 2
"""Bump when the carrier's mesh or reduction changes without an input changing (enters the cache key). 2: meshed in
its STEP exchange form."""
_EXCHANGE_PASSES = 2
"""STEP round trips that bring the carrier's solid to its exchange form (flexgear.fe.parts.exchange_form): the
first read computes its cut faces' curve parameters anew, the second leaves every digit as it is."""
_FACE_TOL = 1e-6
"""Distance [m] within which a face's centre lies on an axis or at a height."""


def _named_solid(sizes: CarrierSizes, pin_size: float):
    """The carrier's solid in its STEP exchange form (:func:`carrier_exchange_solid`) with its pin bores named
    ``pin_<k>`` (mesh size ``pin_size`` [m]) and the output-side plate's bore named ``seat``."""
    solid = carrier_exchange_solid(sizes)
    half = sizes.gap / 2
    for k, face in pin_bore_faces(solid, sizes.pin_centres()[:, :2]):
        face.name, face.maxh = pin_interface(k), pin_size
    for face in solid.faces:  # a full cylindrical face's centre lies on its axis
        c = face.center
        if np.hypot(c.x, c.y) < _FACE_TOL and c.z > half and abs(_radius(face) - sizes.bore_radius) < _FACE_TOL:
            face.name = SEAT
    return solid


def carrier_exchange_solid(sizes: CarrierSizes):
    """The carrier's solid (flexgear.geometry.carrier.carrier_solid) as a STEP file carries it
    (flexgear.fe.parts.exchange_form): the solid it is meshed in and ``flexgear export-geometry`` writes."""
    return exchange_form(carrier_solid(sizes), _EXCHANGE_PASSES)


def _radius(face) -> float:
    """Radius [m] of a cylindrical face about the z axis: the largest distance of its vertices from it."""
    return max(float(np.hypot(v.p.x, v.p.y)) for v in face.vertices)


def _carrier_netgen_mesh(spec: GearboxSpec, level: str, sizes: CarrierSizes):
    """The carrier's first-order Netgen mesh at mesh ``level`` (module docstring)."""
    settings = spec.meshing_assumed[level]
    return level_mesh(_named_solid(sizes, settings.tooth_size_mm * 1e-3), settings)


def carrier_fe_model(spec: GearboxSpec, level: str = "coarse", sizes: CarrierSizes | None = None) -> FEModel:
    """The carrier's FE model (module docstring) at mesh ``level``, the level's element order; ``sizes`` default
    :func:`flexgear.geometry.carrier.carrier_sizes`."""
    return carrier_volume_mesh(spec, level, sizes)[0]


def carrier_volume_mesh(spec: GearboxSpec, level: str = "coarse",
                        sizes: CarrierSizes | None = None) -> tuple[FEModel, np.ndarray]:
    """(the carrier's FE model, its tetrahedra (e, 4 or 10) in the FE model's node numbering, Netgen's node order):
    :func:`carrier_fe_model` and the elements it is assembled on (a second-order mesh raised from the first-order
    one, as flexgear.fe.fem.fe_model raises a mesh, and taken by it as it is); from the carrier's file where the
    gearbox names one (flexgear.fe.carrier_part)."""
    from flexgear.fe.mesh import mesh_arrays

    sizes = sizes or carrier_sizes(spec)
    if CARRIER in spec.components_geometry:
        return imported_carrier_mesh(spec, level, sizes, SEAT, pin_interface)
    order = spec.meshing_assumed[level].element_order
    mesh = _carrier_netgen_mesh(spec, level, sizes)
    if order == 2:
        mesh.SecondOrder()
    fe = fe_model(mesh, spec.material_assumed, order)
    missing = [pin_interface(k) for k in range(sizes.planet_count) if pin_interface(k) not in fe.regions] + (
        [SEAT] if SEAT not in fe.regions else [])
    if missing:
        raise RuntimeError(f"carrier: the meshed solid lacks the faces {missing}")
    return fe, mesh_arrays(mesh, order)[1]


def carrier_interfaces(fe: FEModel, sizes: CarrierSizes) -> list:
    """The seat and the pins' interfaces (module docstring), the pins' points their centres on the mid-plane."""
    seat = interface(fe, SEAT)
    pins = [replace(interface(fe, pin_interface(k)), point=centre) for k, centre in enumerate(sizes.pin_centres())]
    return [seat, *pins]


def carrier_body(spec: GearboxSpec, level: str = "coarse", sizes: CarrierSizes | None = None,
                 progress: bool = False, fe: FEModel | None = None) -> ReducedBody:
    """The carrier's reduced flexible body (module docstring), cached; ``sizes`` default
    :func:`flexgear.geometry.carrier.carrier_sizes`; ``fe``: its FE model when the body must be built, exactly as
    :func:`carrier_fe_model` builds it for ``spec``, ``level`` and ``sizes`` (e.g. one the caller holds already)."""
    sizes = sizes or carrier_sizes(spec)

    def build() -> ReducedBody:
        if progress:
            say(f"  carrier ({level}): building the reduced body")
        model = fe if fe is not None else carrier_fe_model(spec, level, sizes)
        return reduce(model, carrier_interfaces(model, sizes), n_compare=0, rigid=(SEAT,),
                      max_hz=_max_hz(spec))

    return cached_reduced_body(carrier_body_key(spec, level, sizes), build)


def _max_hz(spec: GearboxSpec) -> float:
    """The carrier's fixed-interface cutoff [Hz]: :data:`CUTOFF_FACTOR` times the gearbox's."""
    return CUTOFF_FACTOR * spec.reduction_assumed.fixed_interface_cutoff_hz


def carrier_body_key(spec: GearboxSpec, level: str = "coarse", sizes: CarrierSizes | None = None) -> str:
    """The cache key of :func:`carrier_body` (flexgear.fe.reduced.reduced_cache_path names its file): every input
    of the carrier's mesh and reduction hashed."""
    sizes = sizes or carrier_sizes(spec)
    imported = spec.components_geometry.get(CARRIER)  # the file's content and selectors, when it comes from one
    key = spec_hash(sizes, spec.meshing_assumed[level], spec.material_assumed, _max_hz(spec), _VERSION,
                    *(() if imported is None else (imported, IMPORT_VERSION)))
    return f"carrier-{level}-{key}"
