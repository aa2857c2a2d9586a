"""Cold build of every component: its mesh and its reduced flexible body, in parallel worker processes.

``build_components(spec, level, reduce=True, workers=2)`` runs one task per component, each in a worker
process: mesh (one Netgen run; flexgear.fe.mesh keeps the first-order mesh in memory for the reduction),
then the reduced body (flexgear.fe.reduced, cached like any other call). The components are independent,
so the results are those of the serial build (same cache entries). Longest tasks are started first
(:data:`COLD_BUILD_ORDER`) so that two workers finish together. Memory: each worker holds one
component at a time, and its large arrays go back to the system when freed (flexgear.heap); at the coarse
level with the default bolt-patch joint the largest process (the ring's) peaks at 1.45 GB and the whole
process tree at 2.06 GB (sum of proportional set sizes; benchmarks/bench_cold.py measures both).
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass

from flexgear.heap import lean_heap
from flexgear.spec import GEOMETRY_COMPONENTS, GearboxSpec

__all__ = ["ComponentSummary", "build_components", "COLD_BUILD_ORDER"]

COLD_BUILD_ORDER = ("ring", "planet", "sun", "output_shaft", "input_shaft")
"""Components longest cold build first (coarse level, measured with benchmarks/bench_cold.py: ring about
twice the planet or the sun, the output shaft half of those, the input shaft a few seconds). Only the
schedule depends on it; a component missing here is built last."""


@dataclass(frozen=True)
class ComponentSummary:
    """What a worker reports of one component: its mesh and, if reduced, its flexible modes."""

    component: str
    n_elements: int
    element_order: int
    n_modes: int | None = None
    first_frequency_hz: float | None = None


def build_component(spec: GearboxSpec, component: str, level: str, reduce: bool = True) -> ComponentSummary:
    """Mesh of ``component`` at ``level`` (the level's element order) and, if ``reduce``, its reduced body."""
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.reduced import component_reduced_body

    mesh = component_mesh(spec, component, level)
    if not reduce:
        return ComponentSummary(component, mesh.n_elements, mesh.order)
    body = component_reduced_body(spec, component, level)
    return ComponentSummary(component, mesh.n_elements, mesh.order, body.n_modes, float(body.frequencies_hz[0]))


def build_components(spec: GearboxSpec, level: str, reduce: bool = True, workers: int = 2,
                     on_done: Callable[[ComponentSummary], None] | None = None) -> list[ComponentSummary]:
    """:func:`build_component` of every component, in ``workers`` processes (1: in this process).

    ``on_done`` is called in this process as each component finishes. Returns the summaries in the order
    of flexgear.spec.GEOMETRY_COMPONENTS.
    """
    if int(workers) != workers or workers < 1:
        raise ValueError(f"build_components: workers must be an integer >= 1, got {workers!r}")
    rank = {c: i for i, c in enumerate(COLD_BUILD_ORDER)}
    order = sorted(GEOMETRY_COMPONENTS, key=lambda c: rank.get(c, len(rank)))
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
    return [done[c] for c in GEOMETRY_COMPONENTS]
