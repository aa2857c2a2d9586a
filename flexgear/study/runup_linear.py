"""The linearised model's own run-up: all its modes driven together along a run's speed history.

Equations. The variant linearised at an operating point (flexgear.modal.linear.linearize: M, D, G, K over the
independent coordinates z) and excited at mesh harmonics h = 1..H as the harmonic-response stage does
(flexgear.harmonic.base.excitation: F_h = F_0 C_h per contact, the generalised force f_h = -g^T F_h, plus tooth
friction's first-order term -(a^T S_h + b^T L_h) on the contacts' sliding and relative-spin rows where the variant's
friction coefficient is above zero, flexgear.harmonic.friction) is driven along a run's own speed history:

    M z'' + (D + G) z' + K z = s(t) Re sum_h f_h e^{i 2 pi h phi(t)},

phi the run's mesh phase (flexgear.study.runup.mesh_phase) and s(t) the run's mean mesh force relative to the
operating point's: the window-averaged sum of the recorded mesh forces divided by the sum of the static contact
forces F_0 (flexgear.study.runup.mesh_excitation with that reference), so that F_0 s(t) C_h is the stiffness
variation's force at the run's own load (first order in the variation: the parametric term of
flexgear.harmonic.response is left out; friction, mu times the normal force, scales with the load alike; its sign of
sliding is the operating point's). The output is a bearing acceleration y = a^T z''
(flexgear.harmonic.base.ACCEL_INDICATORS: the frame translation of the member carrying the bearing), the same signal
the time run records.

Integration. In the mass-normalised undamped modes of (K_sym, M) (Phi^T M Phi = I, for conditioning) the state
x = (p, p') obeys x' = A x + B u(t); with A = V diag(lambda) V^-1 each complex modal coordinate eta = V^-1 x obeys
eta_j' = lambda_j eta_j + g_j(t). The forcing g_j is sampled on the run's time grid and taken piecewise linear
(first-order hold); each step of length dt is then integrated exactly,

    eta_j(t + dt) = e^{lambda_j dt} eta_j(t) + b0_j g_j(t) + b1_j g_j(t + dt),
    b1 = dt (e^z - 1 - z) / z^2,   b0 = dt (e^z - 1) / z - b1,   z = lambda_j dt

(scipy.signal.lfilter per mode). The hold's only error is the linear interpolation of the sampled harmonic forcing:
its fundamental is scaled by sinc^2(f dt) ~ 1 - (2 pi f dt)^2 / 12, a smooth factor of the frequency that shifts
no resonance. The output is y = a^T M^-1 (u - K z - (D + G) z'): the modes' part plus the direct term a^T M^-1 u.

Load along the ramp. The impact law's tangent stiffness 1.5 k delta_0^0.5 follows the mesh load, which rises with
the ramp: with ``along_ramp`` the model is linearised at several times of the ramp (:data:`RAMP_POINTS`), each at
the run's instantaneous speed and with the load torque scaled by s(t) there (the static mesh forces are
proportional to the torque: the model's static mesh force then equals the run's mean mesh force, the drive's
inertia torque included); the matrices are held piecewise constant between the midpoints of those times and
the physical state is carried across each switch (x = V eta). The force f_h stays the operating point's (the
load enters once, through s(t)). Only the orders 1..H are tracked: a linear model responds at the harmonics it is
driven with, the higher orders hold only the switches' small transients.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from flexgear.harmonic.base import Operating
from flexgear.modal.eigenmodes import state_space_roots
from flexgear.results import RunResult
from flexgear.study.hold import SERIES_LIMIT, hold_step_coefficients
from flexgear.study.runup import (
    DEFAULT_HOP_S,
    DEFAULT_WINDOW_S,
    MIN_MESH_CYCLES,
    ORDERS,
    RPM_PER_RAD_PER_S,
    mesh_excitation,
    mesh_phase,
    order_tracks,
    ridges,
)

__all__ = ["LinearRunUp", "linear_response", "linear_runup", "match_linear", "RAMP_POINTS",
           "SERIES_LIMIT"]

RAMP_POINTS = 12
"""Linearisations along the ramp with ``along_ramp`` (module docstring), evenly spaced in time from the first
resolved track speed to the ramp's end: between two of them the mesh load changes by at most about a twelfth of
its range."""

def _modal(system: Operating, forces: np.ndarray) -> tuple[np.ndarray, ...]:
    """(lambda (2n,), V, V^-1 in the undamped modal state (p, p'), Phi (n, n), P (2n, H) = V^-1 B f_h,
    Q (2n, H) = V^-1 B conj(f_h), R (m, 2n): the outputs' modal part, and their direct term (m, H) a^T M^-1 f_h) of
    ``system`` (M, D + G, K and the outputs' rows ``accel``) under ``forces`` (H, n) f_h."""
    from scipy.linalg import eigh

    m, c, k = system.mass, system.damping, system.stiffness
    n = m.shape[0]
    _, phi = eigh(0.5 * (k + k.T), m)  # Phi^T M Phi = I
    kt, ct = phi.T @ k @ phi, phi.T @ c @ phi
    lam, v = state_space_roots(np.eye(n), ct, kt)
    vinv = np.linalg.inv(v)
    fm = forces @ phi  # (H, n): modal forces Phi^T f_h
    p = vinv[:, n:] @ fm.T
    q = vinv[:, n:] @ fm.conj().T
    ao = system.accel @ phi  # a^T z'' = a^T Phi p'', p'' = -Kt p - Ct p' + Phi^T u
    r = (ao @ np.hstack([-kt, -ct])) @ v
    direct = ao @ fm.T
    return lam, v, vinv, phi, p, q, r, direct


def linear_response(time_s: np.ndarray, phase_cycles: np.ndarray, envelope: np.ndarray,
                    systems: Sequence[Operating], forces: np.ndarray, starts: Sequence[int] = (0,)) -> np.ndarray:
    """Outputs y (m, T) [m/s^2] of the linear model(s) driven by s(t) Re sum_h f_h e^{i 2 pi h phi(t)} (module
    docstring) from rest: ``systems[j]`` (flexgear.harmonic.base.Operating: its M, D + G, K and the outputs' rows
    ``accel`` (m, n)) holds from sample ``starts[j]`` (``starts[0]`` = 0) to the next start, the state carried
    across each switch, all on the same coordinates; ``forces`` (H, n) complex: f_h of harmonics 1..H [N, N m]
    (flexgear.harmonic.base.excitation of the operating point), the same for every system."""
    from scipy.signal import lfilter

    t = np.asarray(time_s, float)
    dt = float(np.median(np.diff(t)))
    if not np.allclose(np.diff(t), dt, rtol=1e-6, atol=1e-12):
        raise ValueError("linear_response needs uniformly sampled times")
    if len(systems) != len(starts) or starts[0] != 0:
        raise ValueError("one start per system, the first at sample 0")
    s = np.asarray(envelope, float)
    h = np.arange(1, forces.shape[0] + 1)
    ends = list(starts[1:]) + [t.size - 1]
    y = np.zeros((systems[0].accel.shape[0], t.size))
    x = None  # physical state (z, z') at the segment's first sample
    for sys_, k0, k1 in zip(systems, starts, ends, strict=True):
        lam, v, vinv, phi, p, q, r, direct = _modal(sys_, forces)
        n = phi.shape[0]
        seg = slice(k0, k1 + 1)
        e = np.exp(2j * math.pi * np.outer(h, phase_cycles[seg]))  # (H, T_seg)
        env = s[seg]
        if x is None:
            eta0 = np.zeros(lam.size, complex)
        else:
            pinv = np.linalg.inv(phi)
            eta0 = vinv @ np.concatenate([pinv @ x[:n], pinv @ x[n:]])
        ep, bp0, bp1 = hold_step_coefficients(lam, dt)
        eta_end = np.empty(lam.size, complex)
        part = np.zeros((y.shape[0], k1 + 1 - k0))
        for j in range(lam.size):
            g = 0.5 * env * (p[j] @ e + q[j] @ e.conj())
            eta, _ = lfilter([bp1[j], bp0[j]], [1.0, -ep[j]], g, zi=[eta0[j] - bp1[j] * g[0]])
            part += np.outer(r[:, j], eta).real
            eta_end[j] = eta[-1]
        part += env * (0.5 * (direct @ e + direct.conj() @ e.conj())).real  # a^T M^-1 u: u real
        y[:, seg] = part  # the switch sample is overwritten by the next segment, from the same state
        xm = (v @ eta_end).real
        x = np.concatenate([phi @ xm[:n], phi @ xm[n:]])
    return y


@dataclass(frozen=True)
class LinearRunUp:
    """The linear run-up of a run (module docstring): ``signals`` (time_s, input speed, the bearing accelerations
    [m/s^2]), ``envelope`` s(t) [-], ``speeds_rpm`` and ``times_s`` of the linearisations, ``tracks`` and
    ``ridges`` per output column (flexgear.study.runup.order_tracks, ridges), ``harmonics`` H."""

    signals: pd.DataFrame
    envelope: np.ndarray
    speeds_rpm: np.ndarray
    times_s: np.ndarray
    tracks: dict[str, pd.DataFrame]
    ridges: dict[str, pd.DataFrame]
    harmonics: int


def _operating(variant: Any, harmonics: int, speeds: np.ndarray, torques: np.ndarray) -> list[Any]:
    """The operating points (flexgear.harmonic.base.Operating) at ``speeds`` [rpm] under load torques ``torques``
    [N m], on the first one's coordinates."""
    from flexgear.harmonic.response import frozen_operating
    from flexgear.modal.linear import linearize

    models = []
    for n, torque in zip(speeds, torques, strict=True):
        spec = variant.gearbox.with_fields("load_case", load_torque_nm=float(torque))
        models.append(linearize(dataclasses.replace(variant, gearbox=spec), speed_rpm=float(n),
                                cutoff_rpm=variant.gearbox.load_case.input_speed_rpm))
    return frozen_operating(models, harmonics)


def linear_runup(result: RunResult, variant: Any, along_ramp: bool = False, harmonics: int | None = None,
                 window_s: float = DEFAULT_WINDOW_S, hop_s: float = DEFAULT_HOP_S,
                 orders: Sequence[int] = ORDERS) -> LinearRunUp:
    """The linear run-up (module docstring) of ``variant`` (a flexgear.spec.Variant) along the saved run
    ``result``'s speed history and mesh load: linearised at the load case's operating point (full load torque and
    nominal speed) or, with ``along_ramp``, at :data:`RAMP_POINTS` points of the ramp; ``harmonics`` H (default
    the variant's ``[contact_assumed] stiffness_harmonics``, the run's excitation); the bearing accelerations'
    order tracks and ridges as flexgear.study.runup.runup reads the run's."""
    from flexgear.harmonic.base import ACCEL_INDICATORS, excitation

    s = result.signals
    t = s["time_s"].to_numpy()
    n = s["input_speed_rad_per_s"].to_numpy() * RPM_PER_RAD_PER_S
    lc = variant.gearbox.load_case
    per_rpm = float(result.meta["theory"]["mesh_frequency_hz"]) / lc.input_speed_rpm
    ramp = float(result.meta.get("ramp_time_s") or t[-1])
    hh = int(harmonics or variant.gearbox.contact_assumed.stiffness_harmonics)
    raw = mesh_excitation(s, window_s, reference_n=1.0)  # the window-averaged total mesh force [N]
    if raw is None:
        raise ValueError(f"run {result.name!r} recorded no mesh force")
    nominal = _operating(variant, hh, np.array([lc.input_speed_rpm]), np.array([lc.load_torque_nm]))
    forces = excitation(nominal[0], hh)[1]  # F_0 C_h s(t): the load once, in s(t), at every operating point
    envelope = raw / float(nominal[0].f0.sum())
    if along_ramp:
        t_lo = float(t[np.searchsorted(n, MIN_MESH_CYCLES / (per_rpm * window_s))])  # the first resolved speed
        times = np.linspace(t_lo, ramp, RAMP_POINTS)
        at = np.searchsorted(t, times)
        systems = _operating(variant, hh, n[at], lc.load_torque_nm * envelope[at])
        starts = [0] + [int(k) for k in 0.5 * (at[1:] + at[:-1])]
    else:
        at = np.array([t.size - 1])
        systems, starts = nominal, [0]
    y = linear_response(t, mesh_phase(t, n, per_rpm), envelope, systems, forces, starts)
    sig = pd.DataFrame({"time_s": t, "input_speed_rpm": n, **dict(zip(ACCEL_INDICATORS, y, strict=True))})
    tracks, found = {}, {}
    excited = [k for k in orders if k <= hh]  # the model is linear: the orders above H carry nothing
    for col in ACCEL_INDICATORS:
        tracks[col] = order_tracks(t, sig[col].to_numpy(), n, per_rpm, excited, window_s, hop_s, ramp_end_s=ramp)
        found[col] = ridges(tracks[col])
    speeds = n[at] if along_ramp else np.array([lc.input_speed_rpm])
    return LinearRunUp(sig, envelope, speeds, t[at], tracks, found, hh)


def match_linear(found: pd.DataFrame, linear: pd.DataFrame) -> pd.DataFrame:
    """Each ridge of ``found`` with the nearest ridge of the same order in ``linear`` (the linear run-up's ridges
    of the same signal): adds linear_rpm and linear_error_pct = 100 (n_ridge - n_linear) / n_linear (NaN where
    the linear run-up has no ridge of that order)."""
    out = found.copy()
    rpm, err = [], []
    for _, r in found.iterrows():
        same = linear[linear["order"] == r["order"]]["speed_rpm"].to_numpy()
        if same.size == 0:
            rpm.append(math.nan)
            err.append(math.nan)
            continue
        n_lin = float(same[int(np.argmin(np.abs(same - r["speed_rpm"])))])
        rpm.append(n_lin)
        err.append(100.0 * (r["speed_rpm"] - n_lin) / n_lin)
    out["linear_rpm"] = rpm
    out["linear_error_pct"] = err
    return out
