"""Cold build of every component: its mesh and its reduced flexible body, in parallel worker processes.

``build_components(spec, level, reduce=True, workers=2)`` runs one task per component, each in a worker
process: mesh (one Netgen run; flexgear.fe.mesh keeps the first-order mesh in memory for the reduction),
then the reduced body (flexgear.fe.reduced, cached like any other call). With ``reduce`` one more task builds
the tied ring and output shaft (flexgear.fe.ring_shaft, :data:`~flexgear.fe.ring_shaft.TIED_PAIR`), the one
body of a variant whose ring and output shaft are both flexible. The tasks are independent (a mesh two tasks need
is built by the first and waited for by the other, flexgear.cache), so the results are those of the serial build
(same cache entries). Longest tasks are started first (:data:`COLD_BUILD_ORDER`) so that two workers finish
together. Memory: each worker holds one task at a time, and its large arrays go back to the system when freed
(flexgear.heap).
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass

from flexgear.fe.ring_shaft import PAIR, TIED_PAIR
from flexgear.heap import lean_heap
from flexgear.spec import CARRIER, COMPONENT_GEOMETRY, GEOMETRY_COMPONENTS, GearboxSpec

__all__ = ["ComponentSummary", "build_components", "build_items", "COLD_BUILD_ORDER", "variant_build_items",
           "build_key", "build_body"]

COLD_BUILD_ORDER = (TIED_PAIR, "planet", "sun", "input_shaft", "output_shaft", "ring")
"""Tasks in the order they start (coarse level, benchmarks/RESULTS.md): the tied ring and output shaft, the
longest by far (it meshes both parts first), takes one worker; the other builds the rest, the ring last, whose mesh
the tied pair's task has made by then. Only the schedule depends on it; a task missing here starts last."""


def build_items(reduce: bool = True, arrangement: str = "star") -> tuple[str, ...]:
    """The tasks of :func:`build_components`: every component, and with ``reduce`` in the star arrangement the tied
    ring and output shaft (the planetary stage holds its ring by the housing and joins its output shaft to the
    carrier: no tied body; the parallel-axis pair has no ring)."""
    components = GEOMETRY_COMPONENTS if arrangement != "parallel" else tuple(c for c in GEOMETRY_COMPONENTS
                                                                            if c != "ring")
    return (*components, *((TIED_PAIR,) if reduce and arrangement == "star" else ()))


def variant_build_items(spec: GearboxSpec, components: dict[str, str]) -> tuple[str, ...]:
    """The tasks of :func:`build_component` whose bodies a variant with Table 3 ``components`` (component -> "rigid"
    | "flexible") uses: each flexible component's geometry, and in the star arrangement the tied ring and output
    shaft in place of the two when both are flexible (as flexgear.mbs.gearbox builds them)."""
    flexible = [COMPONENT_GEOMETRY[c] for c, form in components.items() if form == "flexible"]
    if spec.gears.arrangement == "star" and set(PAIR) <= set(flexible):
        return (*(g for g in flexible if g not in PAIR), TIED_PAIR)
    return tuple(flexible)


def build_key(spec: GearboxSpec, item: str, level: str) -> str:
    """The cache key of the reduced body of build task ``item`` (a geometry, the planetary stage's carrier or
    :data:`~flexgear.fe.ring_shaft.TIED_PAIR`) at mesh ``level``."""
    from flexgear.fe.carrier import carrier_body_key
    from flexgear.fe.reduced import component_cache_key
    from flexgear.fe.ring_shaft import tied_pair_key

    if item == CARRIER:
        return carrier_body_key(spec, level)
    return tied_pair_key(spec, level) if item == TIED_PAIR else component_cache_key(spec, item, level)


@dataclass(frozen=True)
class ComponentSummary:
    """What a worker reports of one component: its mesh and, if reduced, its flexible modes."""

    component: str
    n_elements: int
    element_order: int
    n_modes: int | None = None
    first_frequency_hz: float | None = None


def build_body(spec: GearboxSpec, item: str, level: str) -> int:
    """Build (or find in the cache) the reduced body of build task ``item`` at mesh ``level`` alone (not the meshes
    of :func:`build_component`); returns its mode count (a worker process sends nothing larger back)."""
    from flexgear.fe.ring_shaft import reduced_body

    return reduced_body(spec, item, level).n_modes


def build_component(spec: GearboxSpec, component: str, level: str, reduce: bool = True) -> ComponentSummary:
    """Mesh of ``component`` at ``level`` (the level's element order) and, if ``reduce``, its reduced body;
    ``component`` :data:`~flexgear.fe.ring_shaft.TIED_PAIR`: the meshes of the ring and the output shaft (their
    elements summed) and their tied body."""
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.fe.ring_shaft import tied_pair_body

    meshes = [component_mesh(spec, c, level) for c in (PAIR if component == TIED_PAIR else (component,))]
    elements, order = sum(m.n_elements for m in meshes), meshes[0].order
    if not reduce:
        return ComponentSummary(component, elements, order)
    body = (tied_pair_body(spec, level) if component == TIED_PAIR else component_reduced_body(spec, component, level))
    return ComponentSummary(component, elements, order, body.n_modes, float(body.frequencies_hz[0]))


def build_components(spec: GearboxSpec, level: str, reduce: bool = True, workers: int = 2,
                     on_done: Callable[[ComponentSummary], None] | None = None) -> list[ComponentSummary]:
    """:func:`build_component` of every task of :func:`build_items`, in ``workers`` processes (1: in this process).

    ``on_done`` is called in this process as each task finishes. Returns the summaries in the order of
    :func:`build_items`.
    """
    if int(workers) != workers or workers < 1:
        raise ValueError(f"build_components: workers must be an integer >= 1, got {workers!r}")
    rank = {c: i for i, c in enumerate(COLD_BUILD_ORDER)}
    items = build_items(reduce, spec.gears.arrangement)
    order = sorted(items, key=lambda c: rank.get(c, len(rank)))
    done: dict[str, ComponentSummary] = {}

    def finish(summary: ComponentSummary) -> None:
        done[summary.component] = summary
        if on_done is not None:
            on_done(summary)

    if workers == 1:
        for component in order:
            finish(build_component(spec, component, level, reduce))
    else:
        # spawn: a fresh interpreter per worker (NGSolve's task threads do not survive a fork); lean_heap: the
        # large arrays a component frees go back to the system before the next one
        with ProcessPoolExecutor(max_workers=int(workers), mp_context=multiprocessing.get_context("spawn"),
                                 initializer=lean_heap) as pool:
            futures = [pool.submit(build_component, spec, c, level, reduce) for c in order]
            for future in as_completed(futures):
                finish(future.result())
    return [done[c] for c in items]
