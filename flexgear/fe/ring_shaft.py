"""The ring and the output shaft reduced together: one body for the bolted pair, no bolt joints between them.

Section 2.1: the ring's flange is bolted to the output shaft's web at 12 holes. Two exact, smaller forms of the
pair than two bodies joined per bolt (flexgear.fe.reduced, flexgear.fe.bolted):

- **Both flexible** (:func:`tied_pair_body`): the two FE models tied over the bolts' clamped discs as the full-FE
  reference ties them (flexgear.fe.bolted: the shaft's web nodes in each disc follow the ring's flange face,
  flexgear.fe.tied eq. 1) and reduced as one body (flexgear.fe.tied.reduce), with the reduction of every component
  body (flexgear.fe.reduced): RBE3 interfaces, every fixed-interface mode below ``[reduction_assumed]
  fixed_interface_cutoff_hz``, attachment modes of the ring's contact bands
  (``attachment_order``). Its interface is the output shaft's bearing seat ("bearing_seat"), the pair's only seat;
  the ring's contact bands are the ring's own (the ring's nodes come first, with their indices in the ring's model).
  Beside it the body carries the measuring interface "ring_seat" (no static modes of its own): the ring's side of
  the joint, the union of its clamped discs, each disc weighted equally (as flexgear.fe.reduced.gear_seat takes it
  for the ring alone), the seat the ring's deflections are measured from. Its mass properties are those of the tied
  FE model, exactly the sum of the ring's and the shaft's (flexgear.fe.tied): a rigid twin of the pair has the same.
- **One of the pair rigid**: every clamped disc moves with the one rigid part, so the flexible part is reduced
  with one rigid multi-point interface "bolt_patches" over all discs (flexgear.fe.reduced.patch_union: 6
  coordinates, not 72), its own body of flexgear.fe.reduced; one fixed joint to the rigid part replaces 12.

The tied body is cached by a hash of every input (flexgear.fe.reduced.cached_reduced_body); :func:`reduced_body`
gives it under the name :data:`TIED_PAIR`, any other component's body by its name.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

import numpy as np

from flexgear.fe.bolted import bolt_axes, clamped_patches
from flexgear.fe.cms import Interface, ReducedBody
from flexgear.fe.fem import FEModel
from flexgear.fe.reduced import (
    RING_SEAT,
    cached_reduced_body,
    component_interfaces,
    component_load_circles,
    component_reduced_body,
    patch_union,
    read_cached,
)
from flexgear.fe.tied import Tie, TiedFE, reduce, tie_parts
from flexgear.geometry.layout import geometry_hash
from flexgear.geometry.massprops import MassProperties
from flexgear.progress import say
from flexgear.spec import CARRIER, GearboxSpec

__all__ = ["PAIR", "TIED_PAIR", "part_fe_model", "pair_fe_models", "tied_pair", "tied_pair_interfaces", "ring_seat",
           "tied_pair_body", "tied_pair_key", "tied_pair_mass_properties", "reduced_body", "tied_part_matrices"]

PAIR = ("ring", "output_shaft")
"""The bolted pair's parts, in the order of the tied model (the ring first: its nodes keep their indices)."""
TIED_PAIR = "+".join(PAIR)
"""Name of the tied ring and output shaft as a reduced body source (:func:`reduced_body`)."""
_TIED_VERSION = 1
"""Bump when the tied reduction changes without an input changing (enters the cache keys)."""


def part_fe_model(spec: GearboxSpec, component: str, level: str = "coarse", progress: bool = False) -> FEModel:
    """FE model of ``component`` at mesh ``level``: the level's element order on the cached first-order mesh
    topology, as flexgear.fe.reduced builds every component's."""
    from flexgear.fe.fem import fe_model
    from flexgear.fe.mesh import component_mesh

    order = spec.meshing_assumed[level].element_order
    return fe_model(component_mesh(spec, component, level, order=1, progress=progress).ngsolve_mesh(),
                    spec.material_assumed, order)


def pair_fe_models(spec: GearboxSpec, level: str = "coarse", progress: bool = False) -> tuple[FEModel, FEModel]:
    """FE models of the ring and the output shaft (:func:`part_fe_model`)."""
    return tuple(part_fe_model(spec, name, level, progress) for name in PAIR)


def tied_pair(ring: FEModel, shaft: FEModel, spec: GearboxSpec, clamp_radius: float | None = None) -> TiedFE:
    """Ring and output shaft tied over the bolts' clamped discs (flexgear.fe.bolted.clamped_patches of the shaft's
    web face as slave nodes, the ring's flange face the master, the plane z = z_j): the tie of
    flexgear.fe.bolted.tie_matrix, as a flexgear.fe.tied.TiedFE with parts named as :data:`PAIR`."""
    _, _, z_j = bolt_axes(spec)
    slaves = np.concatenate(clamped_patches(shaft, spec, clamp_radius, component="output_shaft"))
    return tie_parts([ring, shaft], [Tie(0, 1, slaves, (0.0, 0.0, z_j))], PAIR)


def ring_seat(ring: FEModel, spec: GearboxSpec) -> Interface:
    """The ring's side of the joint: the union of its clamped discs (node indices of ``ring``), each disc's nodes
    weighted equally and each disc in all 1 / (number of bolts)."""
    return patch_union(ring, spec, RING_SEAT, "ring")


def tied_pair_interfaces(tied: TiedFE, shaft: FEModel, spec: GearboxSpec) -> list[Interface]:
    """The reduction interfaces of the tied pair: the output shaft's bearing seat (flexgear.fe.reduced), its node
    indices mapped into the tied model."""
    seat = next(i for i in component_interfaces(shaft, spec, "output_shaft") if i.name == "bearing_seat")
    return [tied.interface("output_shaft", seat)]


def tied_pair_key(spec: GearboxSpec, level: str = "coarse") -> str:
    """The cache key of :func:`tied_pair_body` (flexgear.fe.reduced.reduced_cache_path names its file)."""
    return _tied_key(spec, level)


def _tied_key(spec: GearboxSpec, level: str) -> str:
    red = spec.reduction_assumed
    circles = component_load_circles(spec, "ring", red.attachment_order)
    key = geometry_hash(spec, "tied", PAIR, spec.meshing_assumed[level], red.fixed_interface_cutoff_hz,
                        [c.key() for c in circles], spec.joints_assumed.bolt_clamp_diameter_mm, _TIED_VERSION)
    return f"ring_output_shaft_tied-{level}-{key}"


def _tied_build(spec: GearboxSpec, level: str, progress: bool,
                fe_source: Callable[[str], FEModel] | None = None) -> Callable[[], ReducedBody]:
    def build() -> ReducedBody:
        if progress:
            say(f"  ring + output_shaft ({level}): building the tied pair's reduced body")
        t0 = time.perf_counter()
        ring, shaft = pair_fe_models(spec, level, progress) if fe_source is None else map(fe_source, PAIR)
        tied = tied_pair(ring, shaft, spec)
        seat = tied.interface("ring", ring_seat(ring, spec))
        itfs = tied_pair_interfaces(tied, shaft, spec)
        n_ring = ring.n_nodes
        del ring, shaft  # the parts' matrices: the reduction holds the tied model's alone
        red = spec.reduction_assumed
        circles = component_load_circles(spec, "ring", red.attachment_order)
        t_tie = time.perf_counter() - t0
        body = reduce(tied, itfs, n_compare=0, load_circles=circles, max_hz=red.fixed_interface_cutoff_hz)
        info = {**body.info, "n_nodes_ring": float(n_ring), "fe_and_tie_time_s": t_tie}
        return dataclasses.replace(body, interfaces=[*body.interfaces, seat], info=info)

    return build


def tied_pair_body(spec: GearboxSpec, level: str = "coarse", progress: bool = False,
                   fe_source: Callable[[str], FEModel] | None = None) -> ReducedBody:
    """The reduced body of the ring and the output shaft tied together (module docstring), cached.
    ``fe_source(part)``: the part's FE model when the body must be built, exactly as :func:`part_fe_model` builds
    it for ``spec`` and ``level`` (e.g. one the caller holds already); default :func:`part_fe_model`."""
    return cached_reduced_body(_tied_key(spec, level), _tied_build(spec, level, progress, fe_source))


def tied_pair_mass_properties(spec: GearboxSpec, level: str = "coarse", progress: bool = False,
                              fe_source: Callable[[str], FEModel] | None = None) -> MassProperties:
    """Mass properties of :func:`tied_pair_body` (of the tied FE model: the sum of the ring's and the shaft's),
    read alone from the cache when the body is there, else from the body built (``fe_source``: as there) and
    cached."""
    def read(path) -> MassProperties:
        with np.load(path, allow_pickle=False) as z:
            return MassProperties(float(z["mass"]), z["com"], z["inertia"])

    props = read_cached(_tied_key(spec, level), read)
    return props if props is not None else tied_pair_body(spec, level, progress, fe_source).props


def tied_part_matrices(spec: GearboxSpec, level: str = "coarse", progress: bool = False
                       ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each part's share of the tied body's modal mass and stiffness: {part: (M_p, K_p)}, (m, m) over the body's
    modal coordinates q, with M_ring + M_shaft = I and K_ring + K_shaft = diag(omega^2).

    The ring's nodes are the tied model's first ones, untouched by the tie (flexgear.fe.tied), so its part is exact:
    M_ring = Phi_r^T M_r Phi_r, K_ring = Phi_r^T K_r Phi_r with Phi_r the modes' rows of the ring's nodes and M_r,
    K_r the ring's own FE matrices; the shaft's is the rest. A mode's kinetic (strain) energy splits as
    q^T M_p q (q^T K_p q) between the parts. Cached beside the body.
    """
    from flexgear.cache import atomic_write_bytes, cache_dir, load_or_build, read_entry

    path = cache_dir() / f"tied-parts-v2-{_tied_key(spec, level)}.npz"

    def read(file) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        with np.load(file, allow_pickle=False) as z:
            return {part: (z[f"mass_{part}"], z[f"stiffness_{part}"]) for part in PAIR}

    def load():
        return read_entry(path, read) if path.exists() else None

    def build():
        import io

        body = tied_pair_body(spec, level, progress)
        ring = part_fe_model(spec, "ring", level, progress)
        n = ring.n_nodes
        if not np.allclose(body.nodes[:n], ring.nodes, rtol=0.0, atol=1e-12):
            raise ValueError("tied_part_matrices: the tied body's first nodes are not the ring's")
        phi = body.modes[:3 * n]
        m_r, k_r = phi.T @ (ring.M @ phi), phi.T @ (ring.K @ phi)
        m_r, k_r = 0.5 * (m_r + m_r.T), 0.5 * (k_r + k_r.T)
        buf = io.BytesIO()
        np.savez(buf, mass_ring=m_r, stiffness_ring=k_r, mass_output_shaft=np.eye(body.n_modes) - m_r,
                 stiffness_output_shaft=np.diag(body.stiffness) - k_r)
        atomic_write_bytes(path, buf.getvalue())
        return read(path)

    return load_or_build(path, load, build)


def reduced_body(spec: GearboxSpec, component: str, level: str = "coarse", progress: bool = False) -> ReducedBody:
    """The reduced body of ``component`` (flexgear.fe.reduced.component_reduced_body), or of the tied ring and
    output shaft for :data:`TIED_PAIR` (:func:`tied_pair_body`), or the planetary stage's carrier
    (flexgear.fe.carrier.carrier_body); cached."""
    if component == TIED_PAIR:
        return tied_pair_body(spec, level, progress)
    if component == CARRIER:
        from flexgear.fe.carrier import carrier_body

        return carrier_body(spec, level, progress=progress)
    return component_reduced_body(spec, component, level, progress)
