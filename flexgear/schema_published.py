"""``[published]``: a source study's own results for the gearbox of the file, which the report sets beside the runs.

    [published]
    source = "You et al., GTF gearbox"   # who published them
    multibody_variant = "model4"         # the variant the published multibody column belongs to
    ramp_time_s = 0.5                    # the load case the published values were computed for
    simulated_time_s = 0.6
    [published.wall_time_s]              # each variant's published wall time for simulated_time_s [s]
    model1 = 371.0
    [published.table6]                   # indicator -> [theory, multibody, lumped] (nan: not given)
    outer_mesh_force_n = [798.1894, 800.7533, 798.1762]
    [published.table7]                   # mesh harmonic k -> bearing x acceleration at k x the mesh frequency
    mesh_1x = [0.0549, 0.0590, 0.0621, 0.0860]   # [multibody input, output, lumped input, output] [m/s^2]
    [published.contact]                  # the impact law as the source prints it (its numbers, in its units)
    stiffness_number = 1.0e8             # k's number, in N per (model length unit)^exponent
    exponent = 1.5
    damping_fraction = 1.0e-3            # c_max as a fraction of k's number
    printed = "1.0e8 'N·m' (section 2.1)"  # how the source writes the stiffness, with where
    penetration_depth_m = 1.0e-4
    step_size_s = 1.0e-5
    selection = "section 3"              # where the source names its selected (multibody) variant

Every part is optional but ``source``. A gearbox file without the table gets a report without published columns.
The table is report data, not a model input: it enters no hash (flexgear.spec.as_dict), so adding or changing it
reruns nothing.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flexgear.schema_fields import SpecError

__all__ = ["PublishedResults", "PublishedContact", "TABLE6_ROWS", "published_table"]

TABLE6_ROWS = ("input_speed_deg_per_s", "output_speed_deg_per_s", "outer_mesh_force_n", "inner_mesh_force_n",
               "input_bearing_peak_accel_m_per_s2", "output_bearing_peak_accel_m_per_s2")
"""The rows a ``[published.table6]`` may give: the report's Table 6 indicators (flexgear.report.result_pages)."""
_HARMONIC = re.compile(r"^mesh_(\d+)x$")


@dataclass(frozen=True)
class PublishedContact:
    """The source's impact law as it prints it (``[published.contact]``): F = k delta^e with k's ``stiffness_number``
    in N per (its model's length unit)^``exponent``, c_max ``damping_fraction`` of that number (N s per length
    unit); ``printed``: the stiffness in the source's words; ``penetration_depth_m`` [m], ``step_size_s`` [s] (NaN:
    not given); ``selection``: where the source names its selected variant. Which length unit the number is in is
    what the report's reading pages weigh (flexgear.report.reading_pages)."""

    stiffness_number: float
    exponent: float
    damping_fraction: float
    printed: str = ""
    penetration_depth_m: float = math.nan
    step_size_s: float = math.nan
    selection: str = ""

    def __repr__(self) -> str:  # NaN written out: two reads of one file compare equal (PublishedResults._key)
        return (f"PublishedContact({self.stiffness_number!r}, {self.exponent!r}, {self.damping_fraction!r}, "
                f"{self.printed!r}, {str(self.penetration_depth_m)}, {str(self.step_size_s)}, {self.selection!r})")


@dataclass(frozen=True, eq=False)
class PublishedResults:
    """A source study's results for this gearbox (module docstring), SI units: ``wall_time_s`` {variant: [s]} for
    ``simulated_time_s`` [s]; ``table6`` {row of :data:`TABLE6_ROWS`: (theory, multibody, lumped)}; ``table7``
    {mesh harmonic k: (multibody input, output, lumped input, output) [m/s^2]}; NaN where the source gives none."""

    source: str
    multibody_variant: str = ""
    ramp_time_s: float = math.nan
    simulated_time_s: float = math.nan
    wall_time_s: dict[str, float] = field(default_factory=dict)
    table6: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    table7: dict[int, tuple[float, float, float, float]] = field(default_factory=dict)
    contact: PublishedContact | None = None

    def _key(self) -> str:
        """The content with NaN written out (NaN is not equal to itself: two reads of one file must compare
        equal)."""
        return repr((self.source, self.multibody_variant, self.ramp_time_s, self.simulated_time_s,
                     sorted(self.wall_time_s.items()), sorted(self.table6.items()), sorted(self.table7.items()),
                     self.contact))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, PublishedResults) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def wall_time_per_simulated_s(self, variant: str) -> float:
        """The published wall time of ``variant`` per simulated second [s/s] (NaN when not given)."""
        return self.wall_time_s.get(variant, math.nan) / self.simulated_time_s


def published_table(path: Path, raw: Any) -> PublishedResults | None:
    """The ``[published]`` table of the gearbox file ``path`` (None when absent), checked: each error one SpecError
    line naming the file, the field and what is allowed."""
    if raw is None:
        return None
    name = "published"
    if not isinstance(raw, dict):
        raise SpecError(path, name, "expected a table (module flexgear.schema_published)", raw)
    allowed = ("source", "multibody_variant", "ramp_time_s", "simulated_time_s", "wall_time_s", "table6", "table7",
               "contact")
    unknown = sorted(set(raw) - set(allowed))
    if unknown:
        raise SpecError(path, f"{name}.{unknown[0]}", f"unknown field; allowed: {', '.join(allowed)}")
    source = raw.get("source")
    if not isinstance(source, str) or not source:
        raise SpecError(path, f"{name}.source", "expected who published the values (a string)", source)
    variant = raw.get("multibody_variant", "")
    if not isinstance(variant, str):
        raise SpecError(path, f"{name}.multibody_variant", "expected a variant name (a string)", variant)
    times = {k: _number(path, f"{name}.{k}", raw[k], positive=True) for k in ("ramp_time_s", "simulated_time_s")
             if k in raw}
    walls = {str(k): _number(path, f"{name}.wall_time_s.{k}", v, positive=True)
             for k, v in _table(path, f"{name}.wall_time_s", raw.get("wall_time_s", {})).items()}
    if walls and "simulated_time_s" not in times:
        raise SpecError(path, f"{name}.simulated_time_s", "missing: the wall times are for how long a simulation?")
    table6 = {}
    for row, values in _table(path, f"{name}.table6", raw.get("table6", {})).items():
        if row not in TABLE6_ROWS:
            raise SpecError(path, f"{name}.table6.{row}", f"unknown row; allowed: {', '.join(TABLE6_ROWS)}")
        table6[row] = _numbers(path, f"{name}.table6.{row}", values, 3)
    table7 = {}
    for key, values in _table(path, f"{name}.table7", raw.get("table7", {})).items():
        match = _HARMONIC.match(key)
        if match is None or int(match.group(1)) < 1:
            raise SpecError(path, f"{name}.table7.{key}", "expected mesh_<k>x, k >= 1 the mesh harmonic")
        table7[int(match.group(1))] = _numbers(path, f"{name}.table7.{key}", values, 4)
    return PublishedResults(source, variant, *(times.get(k, math.nan) for k in ("ramp_time_s", "simulated_time_s")),
                            walls, table6, dict(sorted(table7.items())), _contact(path, f"{name}.contact",
                                                                                   raw.get("contact")))


def _contact(path: Path, field_name: str, raw: Any) -> PublishedContact | None:
    """``[published.contact]`` (None when absent), checked."""
    if raw is None:
        return None
    raw = _table(path, field_name, raw)
    numbers = ("stiffness_number", "exponent", "damping_fraction", "penetration_depth_m", "step_size_s")
    texts = ("printed", "selection")
    unknown = sorted(set(raw) - set(numbers) - set(texts))
    if unknown:
        raise SpecError(path, f"{field_name}.{unknown[0]}", f"unknown field; allowed: {', '.join(numbers + texts)}")
    for key in numbers[:3]:
        if key not in raw:
            raise SpecError(path, f"{field_name}.{key}", "missing (required in [published.contact])")
    values = {k: _number(path, f"{field_name}.{k}", raw[k], positive=True) for k in numbers if k in raw}
    for key in texts:
        if key in raw and not isinstance(raw[key], str):
            raise SpecError(path, f"{field_name}.{key}", "expected a string", raw[key])
    return PublishedContact(**values, **{k: raw[k] for k in texts if k in raw})


def _table(path: Path, field_name: str, raw: Any) -> dict:
    if not isinstance(raw, dict):
        raise SpecError(path, field_name, "expected a table", raw)
    return raw


def _number(path: Path, field_name: str, value: Any, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (positive and not value > 0):
        raise SpecError(path, field_name, "expected a number > 0" if positive else "expected a number", value)
    return float(value)


def _numbers(path: Path, field_name: str, value: Any, count: int) -> tuple[float, ...]:
    """``count`` numbers (nan allowed: a value the source does not give)."""
    if not isinstance(value, list) or len(value) != count or any(
            isinstance(v, bool) or not isinstance(v, (int, float)) for v in value):
        raise SpecError(path, field_name, f"expected a list of {count} numbers (nan where not given)", value)
    return tuple(float(v) for v in value)
