"""Agreement of two runs of the same variant: a faster formulation or solver setting against the reference.

The acceptance rule: every signal's mean within 0.1 % and its amplitude at the mesh frequency
(1x, windowed DTFT as Table 7, flexgear.study.compare.harmonic_amplitudes) within 2 % of the
reference run, over a common analysis window.

Relative differences are taken against a scale that does not vanish: for the mean, the larger of
the reference mean's magnitude and the reference signal's standard deviation in the window (the
bearing accelerations oscillate about zero, their mean is noise); for the 1x amplitude, the reference
amplitude, but at least ``NOISE_FLOOR`` times the mean's scale: a 1x amplitude below that (the prescribed
input speed's) is at the level of the solver's Newton tolerance, noise rather than a signal.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from flexgear.results import RunResult
from flexgear.study.compare import harmonic_amplitudes

__all__ = ["SignalAgreement", "signal_agreement"]

MEAN_TOLERANCE = 1e-3  # means within 0.1 %
AMPLITUDE_TOLERANCE = 2e-2  # 1x mesh amplitudes within 2 %
NOISE_FLOOR = 1e-6  # amplitudes below this fraction of the mean's scale: the reference Newton tolerance, noise


@dataclass(frozen=True)
class SignalAgreement:
    """Per-signal relative differences (new - reference) / scale, and whether all are within tolerance."""

    table: pd.DataFrame  # index: signal; columns: ref_mean, new_mean, mean_diff, ref_amp_1x, new_amp_1x, amp_diff

    @property
    def worst_mean(self) -> float:
        return float(self.table["mean_diff"].abs().max())

    @property
    def worst_amplitude(self) -> float:
        return float(self.table["amp_diff"].abs().max())

    def ok(self, mean_tol: float = MEAN_TOLERANCE, amp_tol: float = AMPLITUDE_TOLERANCE) -> bool:
        return self.worst_mean <= mean_tol and self.worst_amplitude <= amp_tol


def signal_agreement(reference: RunResult, new: RunResult, window: tuple[float, float],
                     mesh_frequency_hz: float) -> SignalAgreement:
    """Compare every signal of ``new`` with ``reference`` over ``window`` [s] (means and 1x mesh amplitudes)."""
    if reference.signals is None or new.signals is None:
        raise ValueError("signal_agreement: both runs need signals (a failed run has none)")
    rows = {}
    sel = {}
    for label, run in (("ref", reference), ("new", new)):
        s = run.signals
        sel[label] = s[(s.time_s >= window[0]) & (s.time_s <= window[1])]
    if len(sel["ref"]) != len(sel["new"]) or len(sel["ref"]) < 16:
        raise ValueError(f"signal_agreement: windows hold {len(sel['ref'])} and {len(sel['new'])} samples "
                         "(need the same step size and at least 16 samples)")
    dt = float(np.median(np.diff(sel["ref"]["time_s"].to_numpy())))
    for col in reference.signals.columns:
        if col in ("time_s", "transmission_ratio"):  # the ratio is output/input speed, both compared
            continue
        a, b = sel["ref"][col].to_numpy(), sel["new"][col].to_numpy()
        scale = max(abs(a.mean()), a.std(), 1e-300)
        amp_a = float(harmonic_amplitudes(a, dt, mesh_frequency_hz, (1,))[0])
        amp_b = float(harmonic_amplitudes(b, dt, mesh_frequency_hz, (1,))[0])
        rows[col] = {"ref_mean": a.mean(), "new_mean": b.mean(), "mean_diff": (b.mean() - a.mean()) / scale,
                     "ref_amp_1x": amp_a, "new_amp_1x": amp_b,
                     "amp_diff": (amp_b - amp_a) / max(amp_a, NOISE_FLOOR * scale)}
    return SignalAgreement(pd.DataFrame.from_dict(rows, orient="index"))
