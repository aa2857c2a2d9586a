"""Schema of the ``[screening]`` table: the Westgard screening's settings, the study's indicator weights and
each reference indicator's TEa on the scale where it matters (flexgear.study.screening reads them)."""

from __future__ import annotations

from dataclasses import dataclass

from flexgear.schema_fields import _choice, _num, _text

__all__ = ["IndicatorWeights", "IndicatorTolerance", "LoadTolerance", "LevelTolerance",
           "ReferenceIndicators", "ScreeningSettings"]


@dataclass(frozen=True)
class IndicatorWeights:
    """Weights of the study's five screening indicators in the composite point (sum 1).

    Section 2.2: "taking 20 % of each of the five simulation indicators".
    """

    input_speed: float = _num(0.0, 1.0)
    output_speed: float = _num(0.0, 1.0)
    transmission_ratio: float = _num(0.0, 1.0)
    outer_mesh_force: float = _num(0.0, 1.0)
    inner_mesh_force: float = _num(0.0, 1.0)


@dataclass(frozen=True)
class _Tolerance:
    """Weight of one indicator in the reference screening and its TEa, in the unit its subclass names."""

    weight: float = _num(0.0, 1.0)
    scale = ""
    tea_field = ""

    @property
    def tea(self) -> float:
        return float(getattr(self, self.tea_field))


@dataclass(frozen=True)
class IndicatorTolerance(_Tolerance):
    """TEa in % of the reference's value (a quantity far from zero: speeds, ratio, mean forces)."""

    tea_pct: float = _num(0.0, 1000.0, lo_open=True)
    scale, tea_field = "relative", "tea_pct"


@dataclass(frozen=True)
class LoadTolerance(_Tolerance):
    """TEa in % of the mean tooth load (a load factor or an alternating load, as a tooth-stress rating sees it)."""

    tea_pct_of_load: float = _num(0.0, 1000.0, lo_open=True)
    scale, tea_field = "load", "tea_pct_of_load"


@dataclass(frozen=True)
class LevelTolerance(_Tolerance):
    """TEa in dB of a vibration level (20 log10 of the amplitude ratio)."""

    tea_db: float = _num(0.0, 200.0, lo_open=True)
    scale, tea_field = "db", "tea_db"


@dataclass(frozen=True)
class ReferenceIndicators:
    """TEa and weight of every indicator screened against a reference variant, each on the scale where it
    matters (``[screening.reference_indicators]``; flexgear.study.indicators defines each indicator)."""

    input_speed: IndicatorTolerance
    output_speed: IndicatorTolerance
    transmission_ratio: IndicatorTolerance
    outer_mesh_force: IndicatorTolerance
    inner_mesh_force: IndicatorTolerance
    outer_mesh_ripple: LoadTolerance
    inner_mesh_ripple: LoadTolerance
    load_sharing: LoadTolerance
    dynamic_factor: LoadTolerance
    input_bearing_rms: LevelTolerance
    output_bearing_rms: LevelTolerance
    input_bearing_mesh1x: LevelTolerance
    output_bearing_mesh1x: LevelTolerance
    transmission_error: IndicatorTolerance


@dataclass(frozen=True)
class ScreeningSettings:
    """Westgard screening of the variants (section 2.2); TEa and the rules are assumptions.

    See ``[screening]`` in gearbox.toml and :mod:`flexgear.study.screening` for each value's meaning.
    """

    allowable_total_error_pct: float = _num(0.0, 100.0, lo_open=True)
    lines: str = _choice("westgard", "six_sigma")
    window: str = _choice("settled", "after_ramps", "fixed")
    after_ramp_delay_s: float = _num(0.0)
    window_start_s: float = _num(0.0)
    window_end_s: float = _num(0.0, lo_open=True)
    short_run_fraction: float = _num(0.0, 1.0, lo_open=True)
    sample_count: int = _num(2, 10000, integer=True)
    selection: str = _choice("fastest_in_best_zone", "closest_to_origin", "fastest_acceptable")
    weights: IndicatorWeights
    reference_indicators: ReferenceIndicators
    # settled window (flexgear.settling.settled_start): blocks of whole mesh cycles, tolerances in %
    settle_block_mesh_cycles: int = _num(1, 100000, integer=True)
    settle_final_blocks: int = _num(1, 1000, integer=True)
    settle_mean_tolerance_pct: float = _num(0.0, 100.0, lo_open=True)
    settle_amplitude_tolerance_pct: float = _num(0.0, 100.0, lo_open=True)
    # "" = the study's mode (Bias against theory); a variant name = Bias against that variant's values
    reference: str = _text(default="")
    # numerical error bars: the reference's final state solved over this window at h and at h/2 (0: none)
    error_window_s: float = _num(0.0, default=0.05)
