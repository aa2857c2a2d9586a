"""Modes of a variant over one revolution of its flexible gears: mean frequencies and their spread.

A flexible gear's contact columns depend on its angle: the mesh point stays where it is while the gear turns under
it, and the column is the mode shapes' Fourier series over the circumference at the material angle under the
contact (flexgear.mbs.contact_kinematics). The linearised matrices of a variant with a flexible gear therefore
depend on the angles at the operating point (the tooth-level variation is the mesh stiffness series, whose mean
the linearisation takes, flexgear.modal.linear). The angles advance together with the time of the operating point,
theta_g = Omega_g (t* - T/2) (flexgear.laws.ramps.drive_angle, T the ramp time), so sampling

    t*_j = T + j P / J,  j = 0 ... J - 1,    P = 2 pi / min_g |Omega_g|

over one revolution of the slowest-turning flexible gear (the others turn at least once in P) covers every angle
of every flexible gear. The k-th mode (ascending |lambda|, flexgear.modal.eigenmodes) is followed through the samples by
its rank: the k-th eigenvalue is a continuous function of the angles, and where two close modes exchange their
shapes between samples (the pairs of a slightly broken cyclic symmetry, whose shapes are not unique) their
frequencies still belong to the k-th and (k+1)-th curves. The ranks are matched as the assignment of least
relative frequency change (:func:`_follow`), so that a root turning overdamped between samples (no vibration mode
there) drops out of its own curve only. Reported per mode: the mean frequency and damping ratio
over the samples and the spread 100 (f_max - f_min) / f_mean [%]; its shape, energy shares and kind are those at
t*_0. A variant without a flexible gear, or at rest, has one sample and no spread.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from flexgear.modal.eigenmodes import Modes, modes
from flexgear.modal.linear import LinearModel, linearize
from flexgear.spec import Variant

__all__ = ["period_modes", "period_samples", "is_gear", "DEFAULT_SAMPLES", "NO_CONTINUATION"]

DEFAULT_SAMPLES = 12
"""Operating points J over the period: twelve angles of the slowest flexible gear (30 degrees apart)."""

NO_CONTINUATION = 1.0
"""Relative frequency change at which a mode counts as having no continuation at the next sample (its root turned
overdamped there): :func:`_follow` prefers that to any continuation that moves it further."""


def is_gear(component: str) -> bool:
    """Whether ``component`` (flexgear.modal.linear's component names) is a gear: its contact columns turn with it
    when it is flexible."""
    return component in ("sun", "ring") or component.startswith("planet_")


def _spin(model: LinearModel, component: str) -> float:
    """|Omega| [rad/s] of ``component`` relative to the carrier (its contacts' frame) at the model's speed
    (flexgear.theory): the star's carrier stands still, the planetary's turns at the output speed and holds the
    ring."""
    from flexgear.design import design

    spec = model.variant.gearbox
    th = design(spec).theory
    carrier = th.output_speed if spec.gears.arrangement == "planetary" else 0.0
    ring = 0.0 if spec.gears.arrangement == "planetary" else th.output_speed
    speed = {"sun": th.input_speed, "ring": ring}.get(component, th.planet_speed) - carrier
    return abs(speed) * model.speed_rpm / spec.load_case.input_speed_rpm


def period_samples(model: LinearModel, samples: int = DEFAULT_SAMPLES) -> np.ndarray:
    """Times t*_j [s] of the operating points over one revolution of the slowest flexible gear (module docstring);
    one (the ramp time) for a model without a flexible gear or at rest."""
    ramp = model.variant.gearbox.load_case.ramp_time_s
    spins = [_spin(model, c) for c in model.flexible if is_gear(c)]
    slowest = min(spins, default=0.0)
    if samples < 1:
        raise ValueError(f"samples: at least 1, got {samples}")
    if slowest <= 1e-6:  # no flexible gear, or (nearly) at rest: the angles do not advance
        return np.array([ramp])
    return ramp + np.arange(samples) * (2.0 * math.pi / slowest) / samples


def _follow(f0: np.ndarray, f1: np.ndarray) -> np.ndarray:
    """For each frequency of ``f0`` the index of its continuation in ``f1`` (-1: none), the assignment with the
    least sum of |f1 - f0| / f0: for two ascending lists of the same modes, the rank order; a root that turns
    overdamped (or back) between the samples is left out instead of shifting the ranks above it."""
    from scipy.optimize import linear_sum_assignment

    cost = np.abs(f1[None, :] - f0[:, None]) / np.maximum(f0[:, None], 1e-300)
    none = np.full((f0.size, f0.size), NO_CONTINUATION)  # one "no continuation" per mode
    rows, cols = linear_sum_assignment(np.hstack([cost, none]))
    out = np.full(f0.size, -1)
    real = cols < f1.size
    out[rows[real]] = cols[real]
    return out


def period_modes(variant: Variant, speed_rpm: float | None = None, f_max_hz: float | None = None, *,
                 samples: int = DEFAULT_SAMPLES, first: LinearModel | None = None) -> Modes:
    """The modes of ``variant`` at ``speed_rpm`` [rpm] (default the load case's) up to ``f_max_hz`` [Hz], their
    frequencies and damping ratios averaged over one revolution of the slowest flexible gear and ``spread_pct``
    their spread over it (module docstring). ``first``: the variant already linearised at the ramp time (the
    first sample), at ``speed_rpm``."""
    first = linearize(variant, speed_rpm) if first is None else first
    found = modes(first, f_max_hz)
    times = period_samples(first, samples)
    if times.size == 1 or len(found) == 0:
        return found
    others = [modes(linearize(variant, first.speed_rpm, t_star=float(t))) for t in times[1:]]
    f0 = found.frequencies_hz
    f, z = [f0], [found.damping_ratios]
    for m in others:
        cols = _follow(f0, m.frequencies_hz)
        f.append(np.where(cols >= 0, m.frequencies_hz[cols], np.nan))
        z.append(np.where(cols >= 0, m.damping_ratios[cols], np.nan))
    f, z = np.vstack(f), np.vstack(z)  # (samples, modes)
    freq, zeta = np.nanmean(f, axis=0), np.nanmean(z, axis=0)
    spread = 100.0 * (np.nanmax(f, axis=0) - np.nanmin(f, axis=0)) / np.where(freq > 0, freq, 1.0)
    order = np.argsort(freq, kind="stable")
    return dataclasses.replace(
        found, frequencies_hz=freq[order], damping_ratios=zeta[order], shapes=found.shapes[:, order],
        kinds=tuple(found.kinds[i] for i in order), multiplicity=found.multiplicity[order],
        split_pct=found.split_pct[order], spread_pct=spread[order],
        energy=found.energy.iloc[order].reset_index(drop=True))
