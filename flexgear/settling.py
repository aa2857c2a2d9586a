"""Has a run settled? The settling test on a run's signal table, shared by the runner (which continues a
run until it has settled, ``[load_case] end = "settled"``) and the screening (which screens settled
windows only).

After the STEP ramps the run is cut into blocks of ``block_mesh_cycles`` mesh cycles. Each settling
signal gets one value per block: the planet-mean mesh forces and the two speeds their block means (a
drift), the mesh-force ripples and bearing accelerations RMS their block values (a decaying vibration).
Its final value is the mean of the last ``final_blocks`` blocks, and must differ from the mean of the
``final_blocks`` blocks just before by at most the tolerance (else the run has not settled). A bearing RMS may
move by ``acceleration_floor`` whatever its level: a level that low is noise (the bearing of a rigid stage whose
planets mesh in phase, where the mesh forces on the sun and the carrier cancel, carries 1e-8 to 1e-6 m/s^2 of
round-off), and a relative tolerance of it would never hold. The run has
settled at the start of the first block from which the mean over every later group of ``final_blocks``
consecutive blocks of every settling signal lies within the tolerance of its final value, if at least
``min_blocks`` blocks remain: ``mean_tolerance_pct`` for the drifts, ``amplitude_tolerance_pct`` for the
vibrations. With a group of one revolution of the slowest member, a stationary modulation within a revolution
(an asymmetric bolted part, a planet-pass pattern) averages out instead of being taken for a transient. For
y = A + B e^(-t/tau) and groups of length W this is the first block start t with
|B| (tau / W)(1 - e^(-W/tau)) e^(-t/tau) <= tol |A| (to a block).

When a run has not settled, :func:`settled_start` also estimates how much longer it needs: from the
geometric decay of the differences between consecutive groups of ``final_blocks`` blocks (ratio r of the
last two differences d: the group mean still moves by d r^n after n more groups), or from the blocks
still missing when the settled part is only too short.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = ["SETTLING_SIGNALS", "Settling", "SettleRule", "segment_slices", "mesh_forces", "ripple_pct",
           "radial_rms", "settling_values", "settled_start", "mesh_kinds"]

SETTLING_SIGNALS = {"mean": ("input_speed", "output_speed", "outer_mesh_force", "inner_mesh_force"),
                    "amplitude": ("outer_mesh_ripple", "inner_mesh_ripple", "input_bearing_rms",
                                  "output_bearing_rms")}
"""Signals of the settling test: drifts (mean tolerance) and vibrations (amplitude tolerance). Not the
loaded transmission error: it integrates the output-speed error, so the last 0.01 % of the speed's creep
moves it long after the speeds and forces have settled; it is screened over the window the others set."""


@dataclass(frozen=True)
class SettleRule:
    """Parameters of the settling test (``[screening]`` settle_* fields and ``sample_count``)."""

    block_mesh_cycles: int
    final_blocks: int
    mean_tolerance_pct: float
    amplitude_tolerance_pct: float
    min_blocks: int = 1
    acceleration_floor: float = 0.0  # [m/s^2]: a bearing RMS may move by this much whatever its level

    @classmethod
    def from_settings(cls, settings) -> SettleRule:
        """From :class:`flexgear.schema.ScreeningSettings` (the settled part holds one block per sample)."""
        return cls(settings.settle_block_mesh_cycles, settings.settle_final_blocks, settings.settle_mean_tolerance_pct,
                   settings.settle_amplitude_tolerance_pct, settings.sample_count,
                   settings.settle_acceleration_floor_m_per_s2)


@dataclass(frozen=True)
class Settling:
    """Outcome of the settling test: ``start_s`` (None: not settled), the reason in words, the signal that
    settles last or still moves, and the estimated end time [s] a run needs to settle (nan: unknown)."""

    start_s: float | None
    reason: str
    signal: str = ""
    needed_end_s: float = math.nan

    @property
    def settled(self) -> bool:
        return self.start_s is not None


def segment_slices(t: np.ndarray, start: float, end: float, count: int) -> list[slice]:
    """Index ranges of ``count`` equal contiguous segments of [start, end] in the sorted times ``t``
    (the end point joins the last segment)."""
    edges = np.linspace(start, end, count + 1)
    idx = np.searchsorted(t, edges, side="left")
    idx[-1] = np.searchsorted(t, end, side="right")
    return [slice(int(a), int(b)) for a, b in zip(idx[:-1], idx[1:], strict=True)]


def mesh_forces(signals: pd.DataFrame, mesh: str) -> np.ndarray:
    """Mesh forces [N] of every planet of one mesh kind ("outer": sun-planet, "inner": planet-ring), one column
    per planet."""
    cols = [c for c in signals.columns if c.startswith(f"{mesh}_mesh_force_") and c.endswith("_n")]
    if not cols:
        raise ValueError(f"signal table has no {mesh}_mesh_force_<i>_n columns")
    return signals[cols].to_numpy()


def mesh_kinds(signals: pd.DataFrame) -> tuple[str, ...]:
    """The mesh kinds a signal table holds: "outer" and "inner", or "outer" alone (the parallel-axis pair)."""
    return tuple(m for m in ("outer", "inner") if f"{m}_mesh_force_1_n" in signals.columns)


def ripple_pct(f: np.ndarray) -> float:
    """Mesh-force ripple [% of the mean mesh force]: 100 mean_i(std_t F_i / mean_t F_i) over the planets i."""
    return float(np.mean(f.std(axis=0) / f.mean(axis=0)) * 100.0)


def radial_rms(ax: np.ndarray, ay: np.ndarray) -> float:
    """RMS of a radial acceleration about its mean, sqrt(mean((a_x - mean a_x)^2 + (a_y - mean a_y)^2))."""
    return float(np.sqrt(np.mean((ax - ax.mean()) ** 2 + (ay - ay.mean()) ** 2)))


def settling_values(signals: pd.DataFrame, slices: list[slice]) -> dict[str, np.ndarray]:
    """Each settling signal's value in each segment (module docstring): key -> array over ``slices``."""
    speed = {"input_speed": signals["input_speed_rad_per_s"].to_numpy(),
             "output_speed": signals["output_speed_rad_per_s"].to_numpy()}
    forces = {mesh: mesh_forces(signals, mesh) for mesh in mesh_kinds(signals)}
    acc = {side: (signals[f"{side}_bearing_accel_x_m_per_s2"].to_numpy(),
                  signals[f"{side}_bearing_accel_y_m_per_s2"].to_numpy()) for side in ("input", "output")}
    out: dict[str, np.ndarray] = {}
    for key, y in speed.items():
        out[key] = np.array([y[s].mean() for s in slices])
    for mesh, f in forces.items():
        out[f"{mesh}_mesh_force"] = np.array([f[s].mean() for s in slices])
        out[f"{mesh}_mesh_ripple"] = np.array([ripple_pct(f[s]) for s in slices])
    for side, (ax, ay) in acc.items():
        out[f"{side}_bearing_rms"] = np.array([radial_rms(ax[s], ay[s]) for s in slices])
    return out


def _groups_to_settle(v: np.ndarray, final_blocks: int, tol: float) -> float:
    """More groups of ``final_blocks`` blocks until the group mean of ``v`` moves by at most ``tol`` (absolute):
    n = ln(tol / d) / ln r from the last two group-to-group differences d_prev, d (r = d / d_prev < 1);
    nan when the decay cannot be told from the data (fewer than three groups, or no decay)."""
    groups = len(v) // final_blocks
    if groups < 3:
        return math.nan
    g = v[len(v) - groups * final_blocks:].reshape(groups, final_blocks).mean(axis=1)
    d_prev, d = abs(g[-2] - g[-3]), abs(g[-1] - g[-2])
    if d <= tol:
        return 0.0
    if d_prev == 0.0 or d >= d_prev:
        return math.nan
    return math.log(tol / d) / math.log(d / d_prev)


def settled_start(signals: pd.DataFrame, after_s: float, mesh_frequency_hz: float, rule: SettleRule) -> Settling:
    """The settled part of a run (module docstring); ``after_s`` is the end of the ramps [s]."""
    t = signals["time_s"].to_numpy()
    block = rule.block_mesh_cycles / mesh_frequency_hz
    count = int((t[-1] - after_s) // block)
    needed_blocks = max(2 * rule.final_blocks, rule.min_blocks)
    if count < needed_blocks:
        return Settling(None, f"not settled: only {max(count, 0)} blocks of {rule.block_mesh_cycles} mesh cycles "
                              f"({1e3 * block:.3g} ms) after the ramps at {after_s:g} s; the settling test needs "
                              f"{needed_blocks}", "", after_s + needed_blocks * block)
    starts = t[-1] - block * np.arange(count, 0, -1)
    slices = [slice(int(a), int(b)) for a, b in zip(np.searchsorted(t, starts), np.searchsorted(t, starts + block),
                                                    strict=True)]
    values = settling_values(signals, slices)
    first_ok, slowest = 0, ""
    for kind, tol_pct in (("mean", rule.mean_tolerance_pct), ("amplitude", rule.amplitude_tolerance_pct)):
        for key in SETTLING_SIGNALS[kind]:
            if key not in values:  # a mesh the stage does not have (the parallel-axis pair's inner mesh)
                continue
            v = values[key]
            final = v[-rule.final_blocks:].mean()
            tol = tol_pct / 100.0 * abs(final)
            if key.endswith("_bearing_rms"):  # a level at the noise floor (rigid in-phase planets: 1e-6 m/s^2)
                tol = max(tol, rule.acceleration_floor)
            moved = abs(final - v[-2 * rule.final_blocks:-rule.final_blocks].mean())
            if moved > tol:
                groups = _groups_to_settle(v, rule.final_blocks, tol)
                # once the group mean stops moving, the settled part still needs its min_blocks
                needed = t[-1] + (groups * rule.final_blocks + rule.min_blocks) * block
                when = f"; about {needed:.3g} s needed" if math.isfinite(needed) else "; time needed unknown"
                moved_pct = 100 * moved / abs(final)
                return Settling(None, f"not settled: the final value of {key} still moves by {moved_pct:.2g} "
                                      f"% (> {tol_pct:g} %) between the last two groups of {rule.final_blocks} "
                                      f"blocks of {rule.block_mesh_cycles} mesh cycles at {t[-1]:.4g} s" + when,
                                key, needed)
            # the band test on the group-averaged value (a group of final_blocks blocks: one revolution of the
            # slowest member with the default settings), so that a stationary modulation within a revolution is
            # not taken for a transient
            group_mean = np.convolve(v, np.full(rule.final_blocks, 1.0 / rule.final_blocks), mode="valid")
            bad = np.flatnonzero(np.abs(group_mean - final) > tol)
            k = int(bad[-1]) + 1 if bad.size else 0
            if k > first_ok:
                first_ok, slowest = k, key
    if count - first_ok < rule.min_blocks:
        needed = t[-1] + (rule.min_blocks - (count - first_ok)) * block
        return Settling(None, f"not settled: {slowest} settles {count - first_ok} blocks of {rule.block_mesh_cycles} "
                              f"mesh cycles before the end ({t[-1]:.4g} s); the window needs {rule.min_blocks}; "
                              f"about {needed:.3g} s needed", slowest, needed)
    start = float(starts[first_ok])
    why = (f"settled at {start:.4g} s: from there every mean over {rule.final_blocks} blocks of "
           f"{rule.block_mesh_cycles} mesh cycles within {rule.mean_tolerance_pct:g} % (speeds, mean forces) and "
           f"{rule.amplitude_tolerance_pct:g} % (ripple, bearing RMS) of its final value"
           + (f"; slowest: {slowest}" if slowest else ""))
    return Settling(start, why, slowest, float(t[-1]))
