"""Shared helpers of the speed benchmarks (issue 16): load average, medians, the floor variant.

Every figure is measured ``repeat`` times within one run of a script and reported as its median; ratios
are ratios of medians measured side by side (rounds interleave the cases, so the machine's load hits
them alike). The machine is shared: the load average is printed before and after.
"""

from __future__ import annotations

import dataclasses
import os
import statistics
from collections.abc import Sequence

from flexgear.spec import Variant


def load_average() -> str:
    """The 1/5/15-minute load averages and the CPU count, as one line."""
    if not hasattr(os, "getloadavg"):
        return "load average: n/a"
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} on {os.cpu_count()} CPUs"


def median(values: Sequence[float]) -> float:
    return float(statistics.median(values))


def figure_line(name: str, values: Sequence[float], unit: str = "s") -> str:
    """``name``: each run's value and the median."""
    runs = " ".join(f"{v:9.3f}" for v in values)
    return f"{name:<44s} {runs}   median {median(values):9.3f} {unit}"


def ratio_line(name: str, numerator: Sequence[float], denominator: Sequence[float], goal: str = "") -> str:
    """Ratio of the medians, the median of the per-round ratios (same round = same machine load) and the ratio of
    the minima (each case's least disturbed run: a shared machine's load only ever adds time)."""
    per_round = [a / b for a, b in zip(numerator, denominator, strict=True)]
    text = (f"{name:<44s} {median(numerator) / median(denominator):9.3f} (ratio of medians), "
            f"{median(per_round):.3f} (median of per-round ratios), {min(numerator) / min(denominator):.3f} "
            "(ratio of minima)")
    return f"{text}   goal {goal}" if goal else text


def floor_variant(variant: Variant) -> Variant:
    """The formulation's floor (issue 16): ``variant`` with a constant mesh stiffness and no friction.

    Same bodies, contacts, solver and load case; only ``contact_assumed.stiffness_variation =
    "constant"`` and ``contact.friction_coefficient = 0``.
    """
    gb = variant.gearbox
    for table, fld in (("contact_assumed", "stiffness_variation"), ("contact", "friction_coefficient")):
        if not hasattr(getattr(gb, table, None), fld):
            raise SystemExit(f"floor variant: the gearbox spec has no field '{table}.{fld}' any more; "
                             "update benchmarks/speed_common.floor_variant")
    gb = gb.with_changes(
        contact_assumed=dataclasses.replace(gb.contact_assumed, stiffness_variation="constant"),
        contact=dataclasses.replace(gb.contact, friction_coefficient=0.0))
    return dataclasses.replace(variant, gearbox=gb, name=f"{variant.name}_floor")


def with_jacobian_updates(variant: Variant, updates: str) -> Variant:
    """``variant`` with ``[solver_assumed] jacobian_updates = updates`` (flexgear.mbs.newton)."""
    return dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("solver_assumed", jacobian_updates=updates))
