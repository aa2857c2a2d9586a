"""The linearised modes checked against time integration: a force pulse on a bearing at steady state.

:func:`impulse_response` integrates the multibody model of a variant (flexgear.mbs.gearbox, mean mesh stiffness as
:func:`flexgear.modal.linear.linearize` builds it) through the load case's ramps to its steady operating point at
t_1 = T + ``settle_s``, saves the state, and continues from it twice over ``window_s``: once undisturbed and once with
a Hann force pulse on the output-shaft bearing seat,

    F(t) = J / tau (1 - cos(2 pi (t - t_1) / tau)) e,    t_1 <= t <= t_1 + tau,    int F dt = J e,

acting at the point p = (r_seat, 0, z_seat) of the output body (the outer surface of its bearing seat, at the pulse's
instant; generalized forces Q_u = F, Q_phi = p x F on the frame coordinates). The direction e = (1, 1, 1) / sqrt(3)
(radial, tangential, axial) excites the translational-tilting and the rotational-axial families alike. The response
is the difference of the two continuations (to first order in J the free response of the linearised system, without
what is left of the ramps' transients): the frame velocities of the input and the output body, rotations multiplied
by the centre distance a_w (a velocity at the planet centres' radius). In the planetary stage the in-plane pairs
(v_x, v_y) and (w_x, w_y) are read in the carrier's axes, turned by the nominal carrier angle theta_c(t) as the
linear model is (flexgear.modal.carrier_frame): with Delta x = T(theta_c) Delta x~ the ground-axes velocity is
T (Delta x~' + Omega_c J Delta x~), so T^T Delta v holds only the frequencies of the carrier-frame modes (in ground
axes each in-plane mode would show at f +- Omega_c / 2 pi). The star's carrier stands still: T = I.

The free response (t > t_1 + tau) is a sum of damped modes, v(t) = sum_k Re(a_k e^(lambda_k t)). It is read twice:

- :func:`spectrum` and :func:`clear_peaks`: the power spectrum summed over the channels; a peak is *clear* when the
  spectrum falls below half its height on both sides before it rises to a higher peak (its half-power points
  exist). For one mode the peak lies at the damped frequency, within zeta^2 of the natural one;
- :func:`damped_poles`: the poles lambda_k of the record by the multi-channel matrix pencil (Hua & Sarkar 1990):
  the shifted Hankel matrices of the samples y_j = sum_k a_k z_k^j, z_k = e^(lambda_k dt), share the signal
  subspace, whose pencil's eigenvalues are z_k; natural frequency |lambda| / 2 pi, damping ratio -Re(lambda) /
  |lambda|, both exact for a noise-free record whatever its length against the decay times (unlike a half-power
  bandwidth, which needs the record to outlast the decay).

The integrator's own damping: generalized-alpha with spectral radius rho_inf damps a mode of frequency omega by a
ratio that grows with (omega h); :func:`generalized_alpha_damping` gives it (Chung & Hulbert 1993's amplification
matrix), and ``spectral_radius = 1`` (no algorithmic damping, the trapezoidal rule's energy conservation) leaves only
the period error, of order (omega h)^2 / 12. The production radius suits a variant with flexible gears: their contact
constraints' coefficients change every step as the gears turn, and without algorithmic damping the constraints'
high-frequency oscillation is left to grow into the record.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from flexgear.spec import Variant

__all__ = ["DEFAULT_IMPULSE_N_S", "DEFAULT_NEWTON_RELATIVE_TOLERANCE", "DEFAULT_PULSE_S", "DEFAULT_SETTLE_S",
           "DEFAULT_WINDOW_S", "ImpulseResponse", "Peak", "Pole", "clear_peaks", "damped_poles",
           "generalized_alpha_damping", "impulse_response", "in_carrier_axes", "spectrum"]

DEFAULT_IMPULSE_N_S = 0.01
"""Impulse J of the pulse [N s]: a central member of some kg moves by about J / (m omega) ~ 1 um, a thousandth of
the contacts' static deflection, so that the response stays linear."""

DEFAULT_PULSE_S = 5.0e-4
"""Duration tau of the Hann pulse [s]: its spectrum is flat within 10 % up to about 0.3 / tau (600 Hz) and falls
below 3 % of J beyond 2.5 / tau (5 kHz), so that the modes above the band of interest stay quiet."""

DEFAULT_SETTLE_S = 5.0e-3
"""Time after the ramps [s] at which the pulse starts (the two continuations' common state)."""

DEFAULT_WINDOW_S = 0.04
"""Length of the recorded continuations [s]."""

DEFAULT_NEWTON_RELATIVE_TOLERANCE = 1.0e-9
"""Newton's relative tolerance [-] of the two continuations: the response is their difference, about a thousandth
of the static deflections (:data:`DEFAULT_IMPULSE_N_S`), so each one's Newton error (this tolerance times the
state's scale) must lie orders of magnitude below it, not at the run's own tolerance."""


@dataclass(frozen=True)
class ImpulseResponse:
    """The velocity response to the pulse (module docstring): ``time_s`` from the pulse's start [s], ``velocity``
    (n_t, n_channels) [m/s] named by ``channels``; ``step_s`` the integration step [s]; ``pulse_s`` tau [s]."""

    variant: Variant
    speed_rpm: float
    spectral_radius: float
    step_s: float
    pulse_s: float
    impulse_n_s: float
    time_s: np.ndarray
    velocity: np.ndarray
    channels: tuple[str, ...]

    def free(self, sample_s: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(time [s], velocity) of the free response, t > tau, every ``sample_s`` [s] (default every step)."""
        every = 1 if sample_s is None else max(1, round(sample_s / self.step_s))
        keep = np.flatnonzero(self.time_s > self.pulse_s + 0.5 * self.step_s)[::every]
        return self.time_s[keep], self.velocity[keep]


@dataclass(frozen=True)
class Peak:
    """A clear spectral peak: frequency [Hz] (parabolic interpolation on the oversampled spectrum) and the
    half-power points [Hz] on either side."""

    frequency_hz: float
    lower_hz: float
    upper_hz: float


@dataclass(frozen=True)
class Pole:
    """An identified mode: natural frequency [Hz], damping ratio [-] and its amplitude (root sum of squares of its
    residues over the channels at the start of the record [m/s])."""

    frequency_hz: float
    damping_ratio: float
    amplitude: float


def _pulse(t: float, t0: float, tau: float, impulse: float) -> float:
    s = t - t0
    return impulse / tau * (1.0 - math.cos(2.0 * math.pi * s / tau)) if 0.0 <= s <= tau else 0.0


def impulse_response(variant: Variant, speed_rpm: float | None = None, *, spectral_radius: float | None = None,
                     impulse_n_s: float = DEFAULT_IMPULSE_N_S, pulse_s: float = DEFAULT_PULSE_S,
                     settle_s: float = DEFAULT_SETTLE_S, window_s: float = DEFAULT_WINDOW_S,
                     step_s: float | None = None, newton_relative_tolerance: float | None = None,
                     mass_source=None, reduced_source=None, carrier_axes: bool = True) -> ImpulseResponse:
    """The response of ``variant`` to a force pulse on its output-shaft bearing at steady state (module docstring).

    ``speed_rpm``: input speed [rpm] (default the load case's); mesh stiffness constant (its mean), as
    :func:`flexgear.modal.linear.linearize` builds the variant. ``spectral_radius``: generalized-alpha's rho_inf
    (default ``[solver_assumed]``'s); ``step_s``: the step [s] (default the load case's);
    ``newton_relative_tolerance``: Newton's (default :data:`DEFAULT_NEWTON_RELATIVE_TOLERANCE`). ``mass_source``,
    ``reduced_source``: as flexgear.mbs.assemble.build_gearbox (any arrangement). ``carrier_axes``: False reads a
    planetary stage's record in ground axes (module docstring: each in-plane mode then shows at f +- the carrier's
    speed).
    """
    import exudyn as exu
    from exudyn.itemInterface import LoadCoordinate, MarkerNodeCoordinate, SensorNode
    from threadpoolctl import threadpool_limits

    from flexgear.design import design
    from flexgear.mbs.assemble import build_gearbox
    from flexgear.mbs.recording import simulation_settings
    from flexgear.mbs.run import RunGuard
    from flexgear.modal.linear import carrier_angle

    spec = variant.gearbox.with_fields("contact_assumed", stiffness_variation="constant")
    if speed_rpm is not None:
        spec = spec.with_fields("load_case", input_speed_rpm=float(speed_rpm))
    built = dataclasses.replace(variant, gearbox=spec)
    lc, sv = spec.load_case, spec.solver_assumed
    rho = sv.spectral_radius if spectral_radius is None else float(spectral_radius)
    h = lc.step_size_s if step_s is None else float(step_s)
    tol = DEFAULT_NEWTON_RELATIVE_TOLERANCE if newton_relative_tolerance is None else float(newton_relative_tolerance)
    t1 = round((lc.ramp_time_s + settle_s) / h) * h
    t2 = t1 + round(window_s / h) * h
    d = design(spec)
    support = d.supports["output_shaft"]
    r_seat = 0.5e-3 * spec.components_assumed.output_shaft_outer_diameter_mm
    point = np.array([r_seat, 0.0, support.centre[2]])
    direction = np.ones(3) / math.sqrt(3.0)
    generalized = np.concatenate([direction, np.cross(point, direction)])  # Q per unit force
    arm = d.gears.centre_distance
    pulse = {"on": False}

    sc = exu.SystemContainer()
    try:
        mbs = sc.AddSystem()
        with threadpool_limits(limits=1, user_api="blas"):
            model = build_gearbox(mbs, built, mass_source, reduced_source, design=d)
        out_node = model.bodies[model.output_body].node
        for k, q in enumerate(generalized):
            if q == 0.0:
                continue

            def load(mbs, t, value, q=q):  # noqa: ARG001 (Exudyn's signature)
                return q * _pulse(t, t1, pulse_s, impulse_n_s) if pulse["on"] else 0.0

            marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=out_node, coordinate=k))
            mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=0.0, loadUserFunction=load))
        sensors, channels = [], []
        for side, body in (("input", model.input_body), ("output", model.output_body)):
            node = model.bodies[body].node
            for kind, names in (("Velocity", ("v_x", "v_y", "v_z")), ("AngularVelocity", ("w_x", "w_y", "w_z"))):
                sensors.append(mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                                        outputVariableType=getattr(exu.OutputVariableType, kind))))
                channels += [f"{side}.{n}" for n in names]
        mbs.Assemble()
        guard = RunGuard(model, built, t2, sv.wall_time_budget_s)  # a run's guard and Jacobian economy
        mbs.SetPostStepUserFunction(guard)

        def solve(t_start: float, t_end: float) -> np.ndarray:
            s = simulation_settings(built, t_end, False)  # the variant's solver, but for these three
            ti = s.timeIntegration
            ti.generalizedAlpha.spectralRadius = rho
            ti.newton.relativeTolerance = tol
            ti.startTime = t_start
            ti.numberOfSteps = max(1, round((t_end - t_start) / h))
            s.solution.sensors.writePeriod = 0.5 * h
            if guard.economy is not None:
                guard.economy.new_solve()
            mbs.SolveDynamic(s, solverType=exu.DynamicSolverType.GeneralizedAlpha, showHints=False,
                             updateInitialValues=True, storeSolver=True)
            if guard.reason:
                raise FloatingPointError(guard.reason)
            return np.hstack([np.asarray(mbs.GetSensorStoredData(i))[:, 1:] if k else
                              np.asarray(mbs.GetSensorStoredData(i)) for k, i in enumerate(sensors)])

        was = exu.config.printToConsole
        exu.config.printToConsole = False
        try:
            solve(0.0, t1)
            state = mbs.systemData.GetSystemState()
            quiet = solve(t1, t2)
            mbs.systemData.SetSystemState(systemStateList=state, configuration=exu.ConfigurationType.Initial)
            pulse["on"] = True
            pushed = solve(t1, t2)
        finally:
            exu.config.printToConsole = was
    finally:
        sc.Reset()
    n = min(len(quiet), len(pushed))
    time = pushed[:n, 0] - t1
    scale = np.array([1.0 if c.split(".")[1].startswith("v") else arm for c in channels])
    velocity = (pushed[:n, 1:] - quiet[:n, 1:]) * scale
    if carrier_axes and "carrier" in model.bodies:  # the planetary stage: the in-plane pairs in the carrier's axes
        velocity = in_carrier_axes(velocity, channels, carrier_angle(model, spec, pushed[:n, 0])[0])
    keep = time >= -0.5 * h
    speed = lc.input_speed_rpm
    return ImpulseResponse(built, speed, rho, h, pulse_s, impulse_n_s, time[keep], velocity[keep], tuple(channels))


def in_carrier_axes(velocity: np.ndarray, channels: tuple[str, ...], theta_c: np.ndarray) -> np.ndarray:
    """``velocity`` (n_t, n_channels) with each in-plane pair of ``channels`` ("<side>.v_x", "<side>.v_y" and
    "<side>.w_x", "<side>.w_y") turned into the axes at the carrier angle ``theta_c`` (n_t,) [rad]: T(theta_c)^T v
    (module docstring); the other channels as they are."""
    out = np.array(velocity, float, copy=True)
    c, s = np.cos(theta_c), np.sin(theta_c)
    index = {name: k for k, name in enumerate(channels)}
    for name in channels:
        side, kind = name.split(".")
        if kind in ("v_x", "w_x"):
            i, j = index[name], index[f"{side}.{kind[0]}_y"]
            out[:, i] = c * velocity[:, i] + s * velocity[:, j]
            out[:, j] = -s * velocity[:, i] + c * velocity[:, j]
    return out


def spectrum(response: ImpulseResponse, oversample: int = 16,
             decay_s: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(frequency [Hz], power [(m/s)^2 s^2]) of the free response, summed over the channels: |V_c(f)|^2 of the
    record's discrete Fourier transform, zero-padded ``oversample`` times. ``decay_s``: an exponential window
    e^(-t / decay_s) [s] (it adds 1 / decay_s to every mode's decay rate and leaves its damped frequency: a lightly
    damped mode then ends within the record instead of leaking side lobes)."""
    t, v = response.free()
    dt = t[1] - t[0]
    n = oversample * len(t)
    window = np.ones_like(t) if decay_s is None else np.exp(-(t - t[0]) / decay_s)
    spec = np.fft.rfft(v * window[:, None], n=n, axis=0) * dt
    return np.fft.rfftfreq(n, dt), np.sum(np.abs(spec) ** 2, axis=1)


def clear_peaks(frequency_hz: np.ndarray, power: np.ndarray, f_min_hz: float, f_max_hz: float,
                floor: float = 1e-4) -> list[Peak]:
    """The clear peaks (module docstring) of ``power`` between ``f_min_hz`` and ``f_max_hz`` [Hz]: local maxima above
    ``floor`` times the band's largest, around which the power falls below half the peak's on both sides before
    reaching a higher value. Ascending in frequency."""
    band = np.flatnonzero((frequency_hz >= f_min_hz) & (frequency_hz <= f_max_hz))
    p = power
    top = p[band].max()
    out = []
    for i in band[1:-1]:
        if not (p[i] > p[i - 1] and p[i] >= p[i + 1] and p[i] > floor * top):
            continue
        edges = []
        for step in (-1, 1):
            j = i
            while 0 < j < len(p) - 1 and p[j] >= 0.5 * p[i] and p[j] <= p[i]:
                j += step
            if p[j] > p[i] or p[j] >= 0.5 * p[i]:
                break  # a higher peak first, or the record's end
            # linear interpolation of the half-power crossing between j and j - step
            a, b = j - step, j
            edges.append(frequency_hz[a] + (0.5 * p[i] - p[a]) * (frequency_hz[b] - frequency_hz[a]) / (p[b] - p[a]))
        if len(edges) < 2:
            continue
        y0, y1, y2 = np.log(p[i - 1:i + 2])
        shift = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2) if (y0 - 2 * y1 + y2) != 0 else 0.0
        f = frequency_hz[i] + shift * (frequency_hz[1] - frequency_hz[0])
        out.append(Peak(float(f), float(min(edges)), float(max(edges))))
    return out


def damped_poles(response: ImpulseResponse, order: int, sample_s: float = 2.0e-5, f_max_hz: float | None = None,
                 pencil_fraction: float = 1.0 / 3.0) -> list[Pole]:
    """The modes of the free response by the multi-channel matrix pencil (module docstring): ``order`` singular
    vectors of the stacked Hankel matrices (pencil parameter L = ``pencil_fraction`` N), samples every
    ``sample_s`` [s]. Poles with Im lambda > 0 only (each real mode once), up to ``f_max_hz``, ascending."""
    from scipy.linalg import lstsq, svd

    t, v = response.free(sample_s)
    dt = t[1] - t[0]
    n = len(t)
    lp = int(pencil_fraction * n)
    hankel = np.vstack([np.lib.stride_tricks.sliding_window_view(v[:, c], lp + 1) for c in range(v.shape[1])])
    _, _, vh = svd(hankel, full_matrices=False)
    basis = vh[:order].conj().T  # (L + 1, order)
    z = np.linalg.eigvals(np.linalg.pinv(basis[:-1]) @ basis[1:])
    lam = np.log(z.astype(complex)) / dt
    powers = z[None, :] ** np.arange(n)[:, None]  # (n, order) Vandermonde
    residues = lstsq(powers, v.astype(complex))[0]  # (order, channels)
    out = []
    for k in np.flatnonzero(lam.imag > 0):
        f = abs(lam[k]) / (2 * math.pi)
        if f_max_hz is not None and f > f_max_hz:
            continue
        amp = 2.0 * float(np.sqrt(np.sum(np.abs(residues[k]) ** 2)))  # the pole and its conjugate
        out.append(Pole(float(f), float(-lam[k].real / abs(lam[k])), amp))
    return sorted(out, key=lambda p: p.frequency_hz)


def generalized_alpha_damping(omega_h: np.ndarray | float, spectral_radius: float) -> tuple[np.ndarray, np.ndarray]:
    """(algorithmic damping ratio [-], relative period error [-]) of generalized-alpha (Chung & Hulbert 1993,
    alpha_m = (2 rho - 1) / (rho + 1), alpha_f = rho / (rho + 1), gamma = 1/2 - alpha_m + alpha_f,
    beta = (1 - alpha_m + alpha_f)^2 / 4) on the undamped oscillator x'' + omega^2 x = 0 at Omega = omega h.

    The amplification matrix A maps (x, h v, h^2 a) of one step to the next; its complex pair
    lambda = exp(Omega_bar (-xi +- i sqrt(1 - xi^2))) gives xi = -ln|lambda| / Omega_bar with Omega_bar the
    discrete frequency |ln lambda|, and the period error Omega / (Omega_bar) - 1."""
    rho = float(spectral_radius)
    am, af = (2 * rho - 1) / (rho + 1), rho / (rho + 1)
    gamma, beta = 0.5 - am + af, 0.25 * (1 - am + af) ** 2
    out_xi, out_t = [], []
    for om in np.atleast_1d(np.asarray(omega_h, float)):
        w2 = om * om
        # step equations: (1 - am) a1 + am a0 = -w2 ((1 - af) x1 + af x0),
        # x1 = x0 + v0 + (1/2 - beta) a0 + beta a1, v1 = v0 + (1 - gamma) a0 + gamma a1   (h = 1 units)
        lhs = np.array([[1.0, 0.0, -beta], [0.0, 1.0, -gamma], [w2 * (1 - af), 0.0, 1 - am]])
        rhs = np.array([[1.0, 1.0, 0.5 - beta], [0.0, 1.0, 1 - gamma], [-w2 * af, 0.0, -am]])
        lam = np.linalg.eigvals(np.linalg.solve(lhs, rhs))
        pair = lam[np.argmax(np.abs(lam.imag))]
        s = np.log(pair.astype(complex))
        out_xi.append(-s.real / abs(s))
        out_t.append(om / abs(s.imag) - 1.0)
    return np.array(out_xi), np.array(out_t)
