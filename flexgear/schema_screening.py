"""Schema of the ``[screening]`` table: the Westgard screening's settings, the study's indicator weights and
each reference indicator's TEa on the scale where it matters (flexgear.study.screening reads them)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from flexgear.schema_fields import choice_field, derived_field, num_field, text_field

__all__ = ["IndicatorWeights", "IndicatorTolerance", "LoadTolerance", "LevelTolerance", "ErrorLevelTolerance",
           "ReferenceIndicators", "ScreeningSettings", "DEFAULT_PURPOSES", "PURPOSE_NAMES"]


@dataclass(frozen=True)
class IndicatorWeights:
    """Weights of the study's five screening indicators in the composite point (sum 1).

    Section 2.2: "taking 20 % of each of the five simulation indicators".
    """

    input_speed: float = num_field(0.0, 1.0, default=0.2)
    output_speed: float = num_field(0.0, 1.0, default=0.2)
    transmission_ratio: float = num_field(0.0, 1.0, default=0.2)
    outer_mesh_force: float = num_field(0.0, 1.0, default=0.2)
    inner_mesh_force: float = num_field(0.0, 1.0, default=0.2)


@dataclass(frozen=True, kw_only=True)
class _Tolerance:
    """Weight of one indicator in the reference screening and its TEa, in the unit its subclass names."""

    weight: float = num_field(0.0, 1.0)
    scale = ""
    tea_field = ""

    @property
    def tea(self) -> float:
        return float(getattr(self, self.tea_field))

    @property
    def floor(self) -> float | None:
        """Smallest amplitude taken to dB, in the signal's SI unit (None: flexgear.study.indicators' default)."""
        return None


@dataclass(frozen=True, kw_only=True)
class IndicatorTolerance(_Tolerance):
    """TEa in % of the reference's value (a quantity far from zero: speeds, ratio, mean forces)."""

    tea_pct: float = num_field(0.0, 1000.0, lo_open=True)
    scale, tea_field = "relative", "tea_pct"


@dataclass(frozen=True, kw_only=True)
class LoadTolerance(_Tolerance):
    """TEa in % of the mean tooth load (a load factor or an alternating load, as a tooth-stress rating sees it)."""

    tea_pct_of_load: float = num_field(0.0, 1000.0, lo_open=True)
    scale, tea_field = "load", "tea_pct_of_load"


@dataclass(frozen=True, kw_only=True)
class LevelTolerance(_Tolerance):
    """TEa in dB of a vibration level (20 log10 of the amplitude ratio)."""

    tea_db: float = num_field(0.0, 200.0, lo_open=True)
    scale, tea_field = "db", "tea_db"


@dataclass(frozen=True, kw_only=True)
class ErrorLevelTolerance(_Tolerance):
    """TEa in dB of a transmission-error harmonic (20 log10 of the amplitude ratio); amplitudes below ``floor_um``
    [um] count as ``floor_um`` (below what a transmission-error measurement resolves: both "no ripple")."""

    tea_db: float = num_field(0.0, 200.0, lo_open=True)
    floor_um: float = num_field(0.0, 1000.0, lo_open=True)
    scale, tea_field = "db", "tea_db"

    @property
    def floor(self) -> float:
        """The level floor in the signal's SI unit [m]."""
        return self.floor_um * 1e-6


def _tol(cls: type, **values: float) -> Any:
    """A reference indicator's tolerance field whose default is ``cls(**values)`` (the study's, gearbox.toml)."""
    return field(default_factory=lambda: cls(**values))


@dataclass(frozen=True)
class ReferenceIndicators:
    """TEa and weight of every indicator screened against a reference variant, each on the scale where it
    matters (``[screening.reference_indicators]``; flexgear.study.indicators defines each indicator)."""

    input_speed: IndicatorTolerance = _tol(IndicatorTolerance, tea_pct=0.1, weight=0.03)
    output_speed: IndicatorTolerance = _tol(IndicatorTolerance, tea_pct=0.1, weight=0.03)
    transmission_ratio: IndicatorTolerance = _tol(IndicatorTolerance, tea_pct=0.1, weight=0.03)
    outer_mesh_force: IndicatorTolerance = _tol(IndicatorTolerance, tea_pct=1.0, weight=0.03)
    inner_mesh_force: IndicatorTolerance = _tol(IndicatorTolerance, tea_pct=1.0, weight=0.03)
    outer_mesh_ripple: LoadTolerance = _tol(LoadTolerance, tea_pct_of_load=2.0, weight=0.15)
    inner_mesh_ripple: LoadTolerance = _tol(LoadTolerance, tea_pct_of_load=2.0, weight=0.15)
    load_sharing: LoadTolerance = _tol(LoadTolerance, tea_pct_of_load=2.0, weight=0.1)
    dynamic_factor: LoadTolerance = _tol(LoadTolerance, tea_pct_of_load=2.0, weight=0.1)
    input_bearing_rms: LevelTolerance = _tol(LevelTolerance, tea_db=3.0, weight=0.06)
    output_bearing_rms: LevelTolerance = _tol(LevelTolerance, tea_db=3.0, weight=0.06)
    input_bearing_mesh1x: LevelTolerance = _tol(LevelTolerance, tea_db=3.0, weight=0.04)
    output_bearing_mesh1x: LevelTolerance = _tol(LevelTolerance, tea_db=3.0, weight=0.04)
    transmission_error: IndicatorTolerance = _tol(IndicatorTolerance, tea_pct=10.0, weight=0.15)
    transmission_error_mesh1x: ErrorLevelTolerance = _tol(ErrorLevelTolerance, tea_db=3.0, floor_um=0.01, weight=0.0)
    transmission_error_mesh2x: ErrorLevelTolerance = _tol(ErrorLevelTolerance, tea_db=3.0, floor_um=0.01, weight=0.0)


DEFAULT_PURPOSES: dict[str, tuple[str, ...]] = {
    "mean_loads": ("input_speed", "output_speed", "transmission_ratio", "outer_mesh_force", "inner_mesh_force"),
    "tooth_loads": ("dynamic_factor", "load_sharing", "outer_mesh_ripple", "inner_mesh_ripple"),
    "vibration": ("input_bearing_rms", "output_bearing_rms", "input_bearing_mesh1x", "output_bearing_mesh1x"),
    "transmission_error": ("transmission_error_mesh1x", "transmission_error_mesh2x"),
}
"""The questions a gear engineer asks of a model, each with the reference indicators that answer it
(``[screening.purposes]``; a file without that table gets these). The mean loaded transmission error
(``transmission_error``) is in no purpose: a static offset, reported beside the transmission-error verdict with
its split into the meshes' share and the rest (flexgear.study.purposes.static_te_split), never deciding it."""

PURPOSE_NAMES = tuple(DEFAULT_PURPOSES)
"""The purposes every ``[screening.purposes]`` table holds; a file may add more."""


@dataclass(frozen=True, kw_only=True)
class ScreeningSettings:
    """Westgard screening of the variants (section 2.2); TEa and the rules are assumptions.

    See ``[screening]`` in gearbox.toml and :mod:`flexgear.study.screening` for each value's meaning.
    """

    allowable_total_error_pct: float = num_field(0.0, 100.0, lo_open=True, default=1.0)
    lines: str = choice_field("westgard", "six_sigma", default="westgard")
    window: str = choice_field("settled", "after_ramps", "fixed", default="settled")
    after_ramp_delay_s: float = num_field(0.0, default=0.0)
    # window = "fixed" only: from the ramps' end to the load case's end when left out (flexgear.sizing)
    window_start_s: float = derived_field(0.0)
    window_end_s: float = derived_field(0.0, lo_open=True)
    short_run_fraction: float = num_field(0.0, 1.0, lo_open=True, default=0.5)
    sample_count: int = num_field(2, 10000, integer=True, default=10)
    selection: str = choice_field("fastest_in_best_zone", "closest_to_origin", "fastest_acceptable",
                                  default="fastest_in_best_zone")
    weights: IndicatorWeights = field(default_factory=IndicatorWeights)
    reference_indicators: ReferenceIndicators = field(default_factory=ReferenceIndicators)
    # settled window (flexgear.settling.settled_start): blocks of whole mesh cycles, tolerances in %; the block
    # follows the ring's tooth count when left out (flexgear.sizing)
    settle_block_mesh_cycles: int = field(metadata={"lo": 1, "hi": 100000, "integer": True, "derived": True})
    settle_final_blocks: int = num_field(1, 1000, integer=True, default=8)
    settle_mean_tolerance_pct: float = num_field(0.0, 100.0, lo_open=True, default=0.05)
    settle_amplitude_tolerance_pct: float = num_field(0.0, 100.0, lo_open=True, default=5.0)
    # a bearing-acceleration RMS that moves by less than this [m/s^2] counts as settled (a level below it is noise)
    settle_acceleration_floor_m_per_s2: float = num_field(0.0, default=1e-3)
    # "" = the study's mode (Bias against theory); a variant name = Bias against that variant's values
    reference: str = text_field(default="")
    # numerical error bars: the reference's final state solved over this window at h and at h/2 (0: none)
    error_window_s: float = num_field(0.0, default=0.05)
    # reference mode: purpose -> the indicators judged for it, each alone (flexgear.study.purposes)
    purposes: dict[str, tuple[str, ...]] = field(default_factory=lambda: dict(DEFAULT_PURPOSES),
                                                  metadata={"purposes": True})
