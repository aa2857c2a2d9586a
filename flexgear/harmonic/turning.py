"""Harmonic response over the angle of a turning asymmetric flexible body: sidebands and the quasi-static K_v.

A flexible body that turns and is not a body of revolution makes the linearised model depend on its angle. In the
star gearbox the ring and the output shaft turn at f_ring = z_s n / (60 z_r) [Hz] (carrier fixed) and carry the
B-fold bolt pattern of their joint (``[components_assumed] ring_bolt_count``, flexgear.fe.bolted); a flexible ring
or output shaft therefore gives a linearised model periodic in the time of the operating point t* with the
pattern period tau = 1 / (B f_ring) [s] (:func:`turning_pattern`).

Quasi-static in the angle. Where the pattern's passing frequency B f_ring is small against the distance from h f_mesh
to the modes that respond and against their bandwidth, the steady response at mesh harmonic h is the frozen model's
response at the current angle,

    x(t) = Re( X_h(t) e^{i 2 pi h f_mesh t} ),    X_h(t* + tau) = X_h(t*),

X_h(t*) the complex amplitude of flexgear.harmonic.response with the model linearised at t* (the time origin at
mesh phase 0 at every t*). With the Fourier series over the pattern X_h(t*) = sum_p X_{h,p} e^{i 2 pi p t* / tau}
the time signal holds lines at h f_mesh + p B f_ring with amplitudes |X_{h,p}|; the line at exactly h f_mesh is
the mean over the angles X_{h,0} (a set of planets whose phasing cancels a harmonic at one angle need not cancel
its sidebands). The amplitude of harmonic h with all its sidebands is (Parseval)

    A_h = sqrt( sum_p |X_{h,p}|^2 ) = sqrt( (1 / tau) int_0^tau |X_h(t*)|^2 dt* ),             (1)

the RMS of |X_h| over one pattern period. J equally spaced pattern phases give (1) exactly and the sidebands
X_{h,p} = (1 / J) sum_j X_h(t*_j) e^{-i 2 pi p j / J} (:func:`sideband_amplitudes`) where the orders
|p| > (J - 1) / 2 are negligible (they alias onto the resolved ones): J >= 2 P + 1 for sidebands up to order P.

The angles hold the mesh phase. A flexible gear's contact columns follow its angle within a tooth pitch too: the
linearised model also depends on the mesh phase, a parametric effect at h f_mesh (it moves response between mesh
harmonics) that is no sideband of the pattern. The operating points are therefore whole mesh cycles apart,
t*_j = T + m_j / f_mesh (T the load case's ramp time, the mesh phase of t* = T at every j): m mesh cycles turn the
pattern by m B / z [periods] (z the turning member's teeth, f_mesh = z f_rot), so the pattern phases reachable are
the multiples of 1 / N, N = z / gcd(B, z), and J divides N: m_j = j (N / J) b^-1 mod N, b = B / gcd(B, z)
(:func:`pattern_times_s`).

The static mesh forces F_s,i(t*) turn with the pattern too (the planets' load sharing); the time signal's peak
over its mean (flexgear.study.indicators) holds that slow change. The quasi-static K_v (:func:`quasi_static_peak`):

    K_v = max_i max_j ( F_s,i(t*_j) + max_phi Re sum_h F_dyn,i,h(t*_j) e^{i h phi} ) / mean_j F_s,i(t*_j),   (2)

over meshes i and angles j; J = 1 is flexgear.harmonic.base's K_v.

Where it fails. (a) Sidebands near a resonance: a mode within about B f_ring of h f_mesh (or of p B f_ring from it)
answers each line at its own frequency, not at h f_mesh; (b) orders beyond (J - 1) / 2 alias; (c) t* sets every
gear's angle: over the m_j (up to N mesh cycles) the sun and the planets turn by up to N / z_sun and N / z_planet
revolutions, so their own departures from cyclic symmetry (a flexible gear's finite-element mesh) are sampled
along, not resolved: they spread into every order p of the pattern, the time signal's lines at h f_mesh plus
their rotation frequencies are not in (1), and the slow lines of their load sharing (at their rotation frequencies
and combinations with f_ring) are in (2) only as far as the m_j sample them; free vibrations the time run still
carries are in neither; (d) the first-order limits of flexgear.harmonic.response (parametric terms, loss of
contact). A variant without a turning asymmetric flexible body (rigid ring and output shaft, or the planetary
arrangement, whose ring stands still) has J = 1 and gives flexgear.harmonic.harmonic_response's values.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from flexgear.harmonic.base import DEFAULT_HARMONICS, Response, waveform_peak

__all__ = ["TurningPattern", "TurningResponse", "turning_pattern", "turning_response", "pattern_times_s", "angle_rms",
           "sideband_amplitudes", "quasi_static_peak", "DEFAULT_SIDEBAND_ORDER"]

DEFAULT_SIDEBAND_ORDER = 6
"""Sideband orders P resolved at least by default: J the smallest admissible count >= 2 P + 1."""


@dataclass(frozen=True)
class TurningPattern:
    """A turning asymmetric flexible body: its ``components``, the pattern's ``order`` B (folds per revolution),
    its rotation frequency per input speed ``rotation_hz_per_rpm`` [Hz/rpm] and its ``teeth`` z (mesh cycles per
    revolution)."""

    components: tuple[str, ...]
    order: int
    rotation_hz_per_rpm: float
    teeth: int

    @property
    def phases(self) -> int:
        """N = z / gcd(B, z): the pattern phases reachable at whole mesh cycles (module docstring)."""
        return self.teeth // math.gcd(self.order, self.teeth)

    def admissible(self, minimum: int = 1) -> int:
        """The smallest J >= ``minimum`` that divides :attr:`phases` (N itself if none smaller)."""
        return next((j for j in range(max(int(minimum), 1), self.phases + 1) if self.phases % j == 0),
                    self.phases)

    def period_s(self, speed_rpm: float) -> float:
        """tau = 1 / (B f_rot) [s] at the input speed ``speed_rpm`` [rpm]."""
        return 1.0 / (self.order * self.rotation_hz_per_rpm * abs(speed_rpm))


def turning_pattern(variant: Any) -> TurningPattern | None:
    """The turning asymmetric flexible body of ``variant`` (flexgear.spec.Variant), or None (module docstring):
    the star's ring and output shaft, flexible either of them, with their B = ``ring_bolt_count`` bolts (B > 1)."""
    spec = variant.gearbox
    g = spec.gears
    flexible = tuple(c for c in ("ring", "output_shaft") if variant.components.get(c) == "flexible")
    bolts = int(spec.components_assumed.ring_bolt_count)
    if g.arrangement != "star" or not flexible or bolts < 2:
        return None
    return TurningPattern(flexible, bolts, g.sun_teeth / g.ring_teeth / 60.0, int(g.ring_teeth))


def pattern_times_s(pattern: TurningPattern, speed_rpm: float, count: int, start_s: float) -> np.ndarray:
    """t*_j = ``start_s`` + m_j / f_mesh [s], j = 0..J-1 (J = ``count``, a divisor of N): whole mesh cycles apart,
    at the pattern phases j / J (module docstring); f_mesh = z f_rot at ``speed_rpm`` [rpm]."""
    n = pattern.phases
    if count < 1 or n % count:
        raise ValueError(f"angles: J must divide {n} (the pattern phases at whole mesh cycles), got {count}")
    b = pattern.order // math.gcd(pattern.order, pattern.teeth)
    m = (np.arange(count) * (n // count) * pow(b, -1, n)) % n
    return start_s + m / (pattern.teeth * pattern.rotation_hz_per_rpm * abs(speed_rpm))


def angle_rms(values: np.ndarray) -> np.ndarray:
    """Eq. 1: sqrt(mean_j |X_j|^2) over the first axis (the angles) of the complex amplitudes ``values``."""
    v = np.asarray(values, complex)
    return np.sqrt(np.mean(np.abs(v) ** 2, axis=0))


def sideband_amplitudes(values: Sequence[complex]) -> pd.Series:
    """|X_p| of the complex amplitudes ``values`` (J,) at J equally spaced angles over one pattern period, orders
    p = -(J - 1) / 2 .. J / 2 (module docstring); index p."""
    v = np.asarray(values, complex)
    spectrum = np.fft.fft(v) / v.size  # X_p = (1/J) sum_j X_j e^{-i 2 pi p j / J}
    orders = np.fft.fftfreq(v.size, 1.0 / v.size).astype(int)
    out = pd.Series(np.abs(spectrum), index=orders, name="amplitude")
    return out.sort_index()


def quasi_static_peak(static: np.ndarray, dynamic: np.ndarray) -> float:
    """Eq. 2: ``static`` (J, m) static forces [N] of m meshes at J angles, ``dynamic`` (J, m, H) their complex
    dynamic amplitudes at harmonics 1..H [N]; K_v [-]."""
    s = np.atleast_2d(np.asarray(static, float))
    d = np.asarray(dynamic, complex).reshape(s.shape + (-1,))
    peaks = np.array([[waveform_peak(d[j, i], s[j, i]) for i in range(s.shape[1])] for j in range(s.shape[0])])
    return float((peaks.max(axis=0) / s.mean(axis=0)).max())


@dataclass
class TurningResponse:
    """The harmonic response at J angles over one pattern period at each speed (module docstring).

    ``angles``: {speed [rpm]: [flexgear.harmonic.Response at that speed, one per angle t*_j]}; ``pattern``: the
    turning body (None: one angle). :meth:`amplitudes` (eq. 1), :meth:`complex_mean` (the line at exactly
    h f_mesh), :meth:`sidebands` and :meth:`dynamic_factor` (eq. 2) mirror flexgear.harmonic.Response.
    """

    angles: dict[float, list[Response]]
    pattern: TurningPattern | None
    model: str

    @property
    def speeds_rpm(self) -> np.ndarray:
        return np.array(sorted(self.angles))

    @property
    def count(self) -> int:
        """J, the angles per speed."""
        return len(next(iter(self.angles.values())))

    @property
    def sideband_order(self) -> int:
        """P = (J - 1) // 2, the highest sideband order resolved."""
        return (self.count - 1) // 2

    @property
    def indicators(self) -> list[str]:
        return next(iter(self.angles.values()))[0].indicators

    def _stack(self, indicator: str, speed: float) -> np.ndarray:
        """Complex amplitudes (J, H) of ``indicator`` at ``speed`` [rpm]."""
        return np.stack([r.complex(indicator).iloc[0].to_numpy() for r in self.angles[speed]])

    def _frame(self, indicator: str, reduce: Any) -> pd.DataFrame:
        rows = {n: reduce(self._stack(indicator, n)) for n in self.speeds_rpm}
        harmonics = self.angles[self.speeds_rpm[0]][0].complex(indicator).columns
        out = pd.DataFrame.from_dict(rows, orient="index", columns=list(harmonics))
        out.index.name, out.columns.name = "speed_rpm", "harmonic"
        return out

    def amplitudes(self, indicator: str) -> pd.DataFrame:
        """Eq. 1 of ``indicator``: rows speeds [rpm], columns harmonics (SI units of the indicator)."""
        return self._frame(indicator, angle_rms)

    def complex_mean(self, indicator: str) -> pd.DataFrame:
        """The mean over the angles X_{h,0}: the line at exactly h f_mesh; rows speeds [rpm], columns harmonics."""
        return self._frame(indicator, lambda z: z.mean(axis=0))

    def sidebands(self, indicator: str, speed_rpm: float, harmonic: int) -> pd.Series:
        """|X_{h,p}| of ``indicator`` at ``speed_rpm`` [rpm] and harmonic h: the line at h f_mesh + p B f_rot;
        index p."""
        return sideband_amplitudes(self._stack(indicator, float(speed_rpm))[:, harmonic - 1])

    def static_forces_n(self, speed_rpm: float) -> pd.DataFrame:
        """Static mesh forces [N] at ``speed_rpm`` [rpm]: rows the angles j, columns the meshes."""
        return pd.DataFrame([r.static_forces_n for r in self.angles[float(speed_rpm)]])

    def dynamic_factor(self) -> pd.Series:
        """Eq. 2 per speed [rpm]."""
        out = {}
        for n in self.speeds_rpm:
            static = self.static_forces_n(n)
            dyn = np.stack([self._stack(m, n) for m in static.columns], axis=1)  # (J, m, H)
            out[n] = quasi_static_peak(static.to_numpy(), dyn)
        return pd.Series(out, name="dynamic_factor").rename_axis("speed_rpm")


def turning_response(variant: Any, speeds_rpm: Sequence[float], harmonics: int = DEFAULT_HARMONICS, *,
                     angles: int | None = None, linearization: str = "spin") -> TurningResponse:
    """The harmonic response of ``variant`` (flexgear.spec.Variant) at ``speeds_rpm`` [rpm] over its turning
    pattern (module docstring): at each speed flexgear.modal.linear.linearize at the J = ``angles`` times
    :func:`pattern_times_s` (default: the smallest admissible J >= 2 :data:`DEFAULT_SIDEBAND_ORDER` + 1), each
    solved by flexgear.harmonic.harmonic_response at its own speed (one linearisation per angle and speed: the
    time model's dynamic modes at that speed).

    Without a turning pattern (:func:`turning_pattern` None) one angle: flexgear.harmonic.harmonic_response at
    each speed with ``linearization``, its values (eq. 1 and 2 with J = 1)."""
    from flexgear.harmonic.response import harmonic_response
    from flexgear.modal.linear import linearize

    speeds = [float(n) for n in np.atleast_1d(np.asarray(speeds_rpm, float))]
    if not speeds or any(not math.isfinite(n) or n <= 0.0 for n in speeds):
        raise ValueError(f"speeds_rpm: expected speeds > 0 rpm, got {speeds_rpm}")
    pattern = turning_pattern(variant)
    if pattern is None:
        per = {n: [harmonic_response(variant, [n], harmonics, linearization=linearization)] for n in speeds}
        return TurningResponse(per, None, variant.name)
    count = pattern.admissible(2 * DEFAULT_SIDEBAND_ORDER + 1) if angles is None else int(angles)
    ramp = variant.gearbox.load_case.ramp_time_s
    per = {}
    for n in speeds:
        per[n] = [harmonic_response(linearize(variant, speed_rpm=n, t_star=float(ts), cutoff_rpm=n), [n], harmonics)
                  for ts in pattern_times_s(pattern, n, count, ramp)]
    return TurningResponse(per, pattern, variant.name)

