"""The STEP law (ADAMS STEP) and its integral: one home for theory, drive, load and the lumped model.

    STEP(x, x0, h0, x1, h1) = h0 + (h1 - h0) d^2 (3 - 2 d),   d = (x - x0)/(x1 - x0) clipped to [0, 1]

The study ramps the input speed and the load torque with STEP(t, 0, 0, T, 1) (Table 5). Every function
takes ``m`` = the math module of its arguments: ``numpy`` (default) or ``exudyn.symbolic`` for compiled
user functions. The compiled (numba) twin used by the lumped model is ``flexgear.laws.compiled.ramp_state``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["step", "step_integral", "ramp_fraction", "drive_angle"]


def step(x: np.ndarray | float, x0: float, h0: float, x1: float, h1: float) -> np.ndarray | float:
    """ADAMS STEP function: cubic from (x0, h0) to (x1, h1) with zero slope at both ends."""
    d = np.clip((np.asarray(x, dtype=float) - x0) / (x1 - x0), 0.0, 1.0)
    out = h0 + (h1 - h0) * d * d * (3.0 - 2.0 * d)
    return float(out) if np.ndim(out) == 0 else out


def step_integral(t: np.ndarray | float, ramp_time: float, final_value: float) -> np.ndarray | float:
    """Integral over [0, t] of STEP(tau, 0, 0, ramp_time, final_value).

    For t <= T: final_value * T * (d^3 - d^4 / 2), d = t / T; after it grows linearly:
    final_value * (t - T/2). This is the prescribed input angle for a STEP speed ramp.
    """
    tt = np.asarray(t, dtype=float)
    d = np.clip(tt / ramp_time, 0.0, 1.0)
    out = np.where(tt <= ramp_time, final_value * ramp_time * (d**3 - 0.5 * d**4),
                   final_value * (tt - 0.5 * ramp_time))
    return float(out) if np.ndim(out) == 0 else out


def ramp_fraction(t: Any, ramp_time: float, m: Any = np) -> Any:
    """STEP(t, 0, 0, T, 1) [-] in numpy or Exudyn symbolic arithmetic (``m``)."""
    if m is np:
        return step(t, 0.0, 0.0, ramp_time, 1.0)
    d = m.min(m.max(t, 0.0) / ramp_time, 1.0)
    return d * d * (3.0 - 2.0 * d)


def drive_angle(t: Any, ramp_time: float, speed: float, m: Any = np) -> Any:
    """Angle [rad] of a STEP speed ramp to ``speed`` [rad/s] over ``ramp_time`` [s] (t >= 0).

    The integral of STEP (``step_integral``): speed T d^3 (1 - d/2) with d = t/T during the ramp,
    speed (t - T/2) after it; in numpy or Exudyn symbolic arithmetic (``m``).
    """
    if m is np:
        return step_integral(t, ramp_time, speed)
    d = t * (1.0 / ramp_time)
    during = (speed * ramp_time) * d * d * d * (1.0 - 0.5 * d)
    after = speed * (t - 0.5 * ramp_time)
    return m.IfThenElse(t < ramp_time, during, after)
