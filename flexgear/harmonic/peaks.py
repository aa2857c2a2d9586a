"""The lumped model's Campbell diagram, the modes that carry each resonance peak of its harmonic response, and the
peaks against the Campbell crossings of those modes.

Modes at an input speed n. The linearised lumped model (flexgear.harmonic.lumped.lumped_linear: M, D + G, K over the
free coordinates z) in state space, as flexgear.modal.eigenmodes does for the multibody model,

    A = [0, I; -M^-1 K, -M^-1 (D + G)],    A V = V diag(lambda),    V = (psi; lambda psi),

natural frequency f = |lambda| / (2 pi) [Hz], damping ratio zeta = -Re(lambda) / |lambda|; a mode is a root with
Im(lambda) > 0 and its conjugate. The Campbell diagram (flexgear.modal.campbell_diagram.Campbell) holds the modes with
zeta < flexgear.modal.campbell_diagram.MAX_DAMPING_RATIO at each speed of a grid, tracked between speeds by the
mass-weighted MAC of their shapes psi (flexgear.modal.campbell_diagram.track) and crossed with the mesh orders k
f_mesh(n) by the same
linear interpolation. Kinds: flexgear.lumped.modal.classify_mode on |psi|.

Modal contributions. The steady response X at omega to a force F has the state s = (X, i omega X) with (i omega I -
A) s = (0, M^-1 F); with eta = V^-1 s, X = sum_j psi_j eta_j exactly. F is the contacts' force variation -g^T (F_0
C_h + P_h): the excitation and the parametric force of the coupled solution
(flexgear.harmonic.base.parametric_forces). An indicator y = r^T X + y_exc (flexgear.harmonic.base._solve: a mesh
force r = (k_t + i omega c) g summed over the mesh's contacts and y_exc = F_0 C_h + P_h, a bearing acceleration r =
-omega^2 a, the transmission error r = te) has the contribution r^T psi_j eta_j of root j. A mode's contribution is
the sum over the root and its conjugate, a multiplet's (modes of equal frequency within :data:`MULTIPLET_RTOL`: the
degenerate pairs of cyclic symmetry, whose shapes are not unique) the sum over its modes. The mode that carries the
response there is the multiplet with the largest |contribution|.

Peaks. A peak of an indicator's harmonic h over the speed grid is a local maximum of its amplitude of at least
:data:`PEAK_FRACTION` of the curve's highest, located between grid speeds by the vertex of the parabola through the
logarithm of the amplitude at the three grid speeds around it (exact for a Gaussian-shaped peak, and a resonance
|1 / (1 - r^2 + 2 i zeta r)| is close to one near r = 1). Near a lightly damped mode the peak of h f_mesh lies
where h f_mesh equals the mode's natural frequency up to a shift of order zeta^2 (a single degree of freedom's
displacement peaks at f_n sqrt(1 - 2 zeta^2)) and up to the neighbouring modes' and the direct excitation term's
share of the indicator.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from flexgear.harmonic.base import (
    ACCEL_INDICATORS,
    DEFAULT_HARMONICS,
    Operating,
    Response,
    parametric_forces,
    sweep_speeds,
)
from flexgear.harmonic.lumped import LumpedLinear, lumped_linear
from flexgear.modal.campbell_diagram import MAC_MIN, MAX_DAMPING_RATIO, MESH_ORDERS, Campbell, order_crossings, track
from flexgear.modal.eigenmodes import state_space_roots

__all__ = ["lumped_campbell", "mode_contributions", "response_peaks", "peak_crossings", "PEAK_FRACTION",
           "MULTIPLET_RTOL", "CANCELLED"]

PEAK_FRACTION = 0.1
"""A local maximum of at least this fraction of its curve's highest counts as a resonance peak (smaller ones are the
skirts of other modes' peaks and the anti-resonance shoulders)."""

MULTIPLET_RTOL = 1e-6
"""Modes whose natural frequencies differ by at most this fraction form one multiplet."""

CANCELLED = 1e-6
"""A harmonic whose highest amplitude over the grid is below this fraction of the indicator's highest over all its
harmonics is cancelled (the planets' phasing cancels it exactly, to round-off): it has no peaks."""


@dataclass(frozen=True)
class _Roots:
    """The roots of the state-space problem at one speed (module docstring): eigenvalues ``lam`` (2n,), right
    eigenvectors ``vec`` (2n, 2n); ``modes``: indices of the roots with Im(lambda) > 0 and zeta below the bound,
    ascending in |lambda|; ``pair``: index of each root's conjugate (itself for a real root)."""

    lam: np.ndarray
    vec: np.ndarray
    modes: np.ndarray
    pair: np.ndarray

    @property
    def frequencies_hz(self) -> np.ndarray:
        return np.abs(self.lam[self.modes]) / (2.0 * math.pi)

    @property
    def damping_ratios(self) -> np.ndarray:
        lam = self.lam[self.modes]
        return -lam.real / np.abs(lam)


def _roots(op: Operating, max_damping_ratio: float = MAX_DAMPING_RATIO) -> _Roots:
    lam, vec = state_space_roots(op.mass, op.damping, op.stiffness)
    scale = np.abs(lam).max()
    pair = np.array([int(np.argmin(np.abs(lam - lj.conjugate()))) for lj in lam])
    zeta = -lam.real / np.maximum(np.abs(lam), 1e-300)
    keep = np.flatnonzero((lam.imag > 1e-12 * scale) & (zeta < max_damping_ratio))
    keep = keep[np.argsort(np.abs(lam[keep]), kind="stable")]
    return _Roots(lam, vec, keep, pair)


def _multiplets(freqs: np.ndarray, rtol: float = MULTIPLET_RTOL) -> list[np.ndarray]:
    """Groups of positions in the ascending ``freqs`` whose neighbours lie within ``rtol``."""
    groups: list[list[int]] = []
    for i, f in enumerate(freqs):
        if groups and f - freqs[groups[-1][-1]] <= rtol * max(f, 1e-300):
            groups[-1].append(i)
        else:
            groups.append([i])
    return [np.array(g) for g in groups]


def _indicator_row(op: Operating, indicator: str, omega: float) -> np.ndarray:
    """r (n,) with indicator = r^T X + excitation term (module docstring)."""
    if indicator in op.mesh_names:
        sel = op.mesh == op.mesh_names.index(indicator)
        return ((op.k_t[sel] + 1j * omega * op.c[sel])[:, None] * op.rows[sel]).sum(axis=0)
    if indicator in ACCEL_INDICATORS:
        return -(omega**2) * op.accel[ACCEL_INDICATORS.index(indicator)]
    if indicator == "transmission_error_m":
        return op.te.astype(complex)
    raise KeyError(f"no modal contribution for indicator {indicator!r}")


def _contributions(op: Operating, roots: _Roots, indicator: str, harmonic: int) -> tuple[np.ndarray, complex]:
    """(contribution of each mode of ``roots.modes`` (its root and the conjugate), the indicator's response part
    r^T X) at harmonic ``harmonic`` (module docstring)."""
    n = op.mass.shape[0]
    omega = harmonic * op.omega_mesh
    # generalised force -g (F_0 C_h + P_h): the excitation and the parametric force of the coupled solution
    # (flexgear.harmonic.base.parametric_forces), which the modes answer alike
    force = -(op.rows.T @ (op.f0 * op.coef[:, harmonic - 1] + parametric_forces(op)[harmonic - 1]))
    if op.friction is not None:  # the tooth-friction excitation (flexgear.harmonic.base.excitation)
        force = force - op.friction_rows.T @ op.friction[:, harmonic - 1]
    a_dyn = op.stiffness - omega**2 * op.mass + 1j * omega * op.damping
    x = np.linalg.solve(a_dyn, force)
    eta = np.linalg.solve(roots.vec, np.concatenate([x, 1j * omega * x]))
    r = _indicator_row(op, indicator, omega)
    per_root = (r @ roots.vec[:n]) * eta
    modes = roots.modes
    partner = roots.pair[modes]
    return per_root[modes] + np.where(partner != modes, per_root[partner], 0.0), complex(r @ x)


def mode_contributions(lin: LumpedLinear, speed_rpm: float, indicator: str, harmonic: int) -> pd.DataFrame:
    """Each multiplet's contribution to ``indicator`` at mesh harmonic ``harmonic`` and input speed ``speed_rpm``
    [rpm] (module docstring), largest first: frequency_hz, damping_ratio, multiplicity, contribution (complex, the
    indicator's unit), share (|contribution| / the indicator's response part |r^T X|)."""
    op = lin.operating(float(speed_rpm))
    roots = _roots(op)
    contrib, total = _contributions(op, roots, indicator, harmonic)
    freqs, zeta = roots.frequencies_hz, roots.damping_ratios
    rows = []
    for g in _multiplets(freqs):
        c = complex(contrib[g].sum())
        rows.append({"frequency_hz": float(freqs[g].mean()), "damping_ratio": float(zeta[g].mean()),
                     "multiplicity": int(g.size), "contribution": c,
                     "share": abs(c) / max(abs(total), 1e-300), "modes": tuple(int(i) for i in g)})
    out = pd.DataFrame(rows)
    return out.reindex(out["contribution"].abs().sort_values(ascending=False).index).reset_index(drop=True)


def _campbell_of(lin: LumpedLinear, speeds: np.ndarray, f_max_hz: float, orders: Sequence[int],
                 mac_min: float) -> tuple[Campbell, list[dict[int, int]], list[_Roots]]:
    from flexgear.lumped.modal import classify_mode

    found = [_roots(lin.operating(float(n))) for n in speeds]
    nf = lin.free.size
    mass = lin.operating(float(speeds[0])).mass
    shapes = [r.vec[:nf][:, r.modes] for r in found]
    lines, _ = track(shapes, [mass] * len(found), [lin.labels] * len(found), mac_min)
    full = np.zeros(lin.system.n, complex)
    rows = []
    for number, line in enumerate(lines, start=1):
        for i, j in sorted(line.items()):
            f = found[i].frequencies_hz[j]
            if f > f_max_hz:
                continue
            full[lin.free] = shapes[i][:, j]
            rows.append({"speed_rpm": float(speeds[i]), "mode": number, "frequency_hz": float(f),
                         "damping_ratio": float(found[i].damping_ratios[j]),
                         "kind": classify_mode(lin.system, np.abs(full))})
    table = pd.DataFrame(rows, columns=["speed_rpm", "mode", "frequency_hz", "damping_ratio", "kind"])
    table = table.sort_values(["speed_rpm", "frequency_hz"], ignore_index=True)
    diagram = Campbell(lin.name, table, order_crossings(table, lin.per_rpm, orders), lin.per_rpm, f_max_hz,
                       tuple(orders), mac_min)
    return diagram, lines, found


def lumped_campbell(spec: Any, speeds_rpm: Sequence[float], f_max_hz: float | None = None, *,
                    orders: Sequence[int] = MESH_ORDERS, mac_min: float = MAC_MIN) -> Campbell:
    """The Campbell diagram of the lumped model of ``spec`` over ``speeds_rpm`` [rpm] (module docstring), in the
    band ``f_max_hz`` [Hz] (default: the highest order's mesh frequency at the highest speed)."""
    speeds = np.sort(np.asarray(speeds_rpm, float))
    if speeds.size == 0 or np.any(np.diff(speeds) == 0.0) or speeds[0] < 0.0:
        raise ValueError(f"speeds_rpm: distinct speeds >= 0 rpm expected, got {list(speeds_rpm)}")
    lin = lumped_linear(spec, 1)
    band = max(orders) * lin.per_rpm * speeds[-1] if f_max_hz is None else float(f_max_hz)
    return _campbell_of(lin, speeds, band, orders, mac_min)[0]


def response_peaks(response: Response, indicator: str, harmonic: int,
                   fraction: float = PEAK_FRACTION) -> pd.DataFrame:
    """The peaks of ``indicator``'s harmonic ``harmonic`` over the response's speed grid (module docstring):
    speed_rpm (the parabola's vertex), grid_rpm (the grid's local maximum), amplitude (at the grid point)."""
    amp = response.amplitudes(indicator)[harmonic]
    n, y = amp.index.to_numpy(float), amp.to_numpy(float)
    inner = np.flatnonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:])) + 1
    inner = inner[y[inner] >= fraction * y.max()] if inner.size else inner
    rows = []
    for i in inner:
        x, ly = n[i - 1:i + 2], np.log(y[i - 1:i + 2])
        a, b, _ = np.polyfit(x - x[1], ly, 2)
        vertex = x[1] - b / (2.0 * a) if a < 0.0 else x[1]
        rows.append({"speed_rpm": float(np.clip(vertex, x[0], x[2])), "grid_rpm": float(n[i]),
                     "amplitude": float(y[i])})
    return pd.DataFrame(rows, columns=["speed_rpm", "grid_rpm", "amplitude"])


def peak_crossings(spec: Any, speeds_rpm: Sequence[float], indicators: Sequence[str], orders: Sequence[int] = (1, 2),
                   harmonics: int = DEFAULT_HARMONICS, fraction: float = PEAK_FRACTION) -> pd.DataFrame:
    """Each resonance peak of the lumped model's response against the Campbell crossing of the mode that carries it.

    For each indicator and mesh order h in ``orders``: the peaks of its harmonic h over ``speeds_rpm`` [rpm]
    (:func:`response_peaks`), the multiplet that carries the response at the grid speed of each peak
    (:func:`mode_contributions`' largest), that multiplet's Campbell lines on the same grid and their crossings
    with order h, the one nearest the peak. A harmonic the planets' phasing cancels (:data:`CANCELLED`) is left
    out. Columns: indicator, harmonic, peak_rpm, amplitude, frequency_hz, damping_ratio and kind of the carrying
    multiplet, share (its |contribution| over the indicator's response part), crossing_rpm, difference
    (peak_rpm / crossing_rpm - 1; nan where the lines do not cross order h in the grid).
    """
    speeds = np.sort(np.asarray(speeds_rpm, float))
    lin = lumped_linear(spec, harmonics)
    response = sweep_speeds(lin.operating, speeds, harmonics, lin.name, lin.per_rpm, time.perf_counter())
    band = max(orders) * lin.per_rpm * speeds[-1] * (1.0 + 1e-9)
    diagram, lines, found = _campbell_of(lin, speeds, band, orders, MAC_MIN)
    crossings = diagram.crossings
    kinds = diagram.table.set_index(["speed_rpm", "mode"])["kind"]
    rows = []
    for indicator in indicators:
        amp = response.amplitudes(indicator)
        for h in orders:
            if amp[h].max() < CANCELLED * amp.to_numpy().max():
                continue
            for _, peak in response_peaks(response, indicator, h, fraction).iterrows():
                i = int(np.searchsorted(speeds, peak.grid_rpm))
                top = mode_contributions(lin, float(speeds[i]), indicator, h).iloc[0]
                numbers = [k + 1 for k, line in enumerate(lines) if line.get(i) in top["modes"]]
                near = crossings[(crossings.order == h) & crossings["mode"].isin(numbers)]
                row = {"indicator": indicator, "harmonic": h, "peak_rpm": float(peak.speed_rpm),
                       "amplitude": float(peak.amplitude), "frequency_hz": float(top.frequency_hz),
                       "damping_ratio": float(top.damping_ratio),
                       "kind": kinds.get((float(speeds[i]), numbers[0]), "") if numbers else "",
                       "share": float(top.share), "crossing_rpm": math.nan, "difference": math.nan}
                if len(near):
                    best = near.iloc[int(np.argmin(np.abs(near.speed_rpm.to_numpy() - peak.speed_rpm)))]
                    row["crossing_rpm"] = float(best.speed_rpm)
                    row["difference"] = float(peak.speed_rpm / best.speed_rpm - 1.0)
                rows.append(row)
    return pd.DataFrame(rows, columns=["indicator", "harmonic", "peak_rpm", "amplitude", "frequency_hz",
                                       "damping_ratio", "kind", "share", "crossing_rpm", "difference"])
