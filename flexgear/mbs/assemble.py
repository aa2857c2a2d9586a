"""A gearbox file's gearbox in an Exudyn system, in its ``[gears] arrangement``: the one entry the run, the
matrix and the facade use (flexgear.mbs.run, flexgear.simulation)."""

from __future__ import annotations

from flexgear.design import Design, as_design
from flexgear.mbs.gearbox import GearboxModel, MassSource, ReducedSource, build_star_gearbox
from flexgear.mbs.parallel import build_parallel_gearbox
from flexgear.mbs.planetary import build_planetary_gearbox
from flexgear.spec import Variant

__all__ = ["build_gearbox"]


def build_gearbox(mbs, variant: Variant, mass_source: MassSource | None = None,
                  reduced_source: ReducedSource | None = None, superelements: bool = False,
                  design: Design | None = None) -> GearboxModel:
    """Assemble the gearbox of ``variant`` into ``mbs`` in its ``[gears] arrangement``: the star
    (flexgear.mbs.gearbox.build_star_gearbox, every rigid/flexible combination) or the planetary stage
    (flexgear.mbs.planetary.build_planetary_gearbox, likewise) or the parallel-axis pair
    (flexgear.mbs.parallel.build_parallel_gearbox, likewise). Call ``mbs.Assemble()`` afterwards."""
    d = as_design(variant.gearbox if design is None else design)
    if d.spec.gears.arrangement == "parallel":
        return build_parallel_gearbox(mbs, variant, mass_source, reduced_source, superelements, design=d)
    if d.spec.gears.arrangement == "planetary":
        return build_planetary_gearbox(mbs, variant, mass_source, design=d, reduced_source=reduced_source,
                                       superelements=superelements)
    return build_star_gearbox(mbs, variant, mass_source, reduced_source, superelements, design=d)
