"""Campbell diagram of a gearbox variant: natural frequencies against input speed, with the mesh orders.

At each input speed n [rpm] of a grid the variant is linearised at its operating point (flexgear.modal.linear:
mean mesh stiffness, spin softening and gyroscopic terms of that speed) and its modes are computed up to a band
f_max [Hz] (flexgear.modal.eigenmodes). Roots with a damping ratio zeta >= 1/sqrt(2) are left out: a mode without a
resonance peak (the amplification 1/sqrt((1 - r^2)^2 + (2 zeta r)^2) has its maximum at r = 0 for zeta >= 1/sqrt(2))
cannot resonate at a crossing; at speed these are the overdamped roots that the gyroscopic coupling makes
complex by a small imaginary part.

Tracking. Each line of the diagram is one mode followed across the grid by its shape: between neighbouring speeds
a and b the modes are paired by the modal assurance criterion over the bodies' frame and elastic coordinates q
(the system's coordinates that every speed shares; mass-weighted, complex shapes)

    MAC_ij = |q_a,i^H M q_b,j|^2 / ((q_a,i^H M q_a,i) (q_b,j^H M q_b,j)),    M = (M_a + M_b) / 2,

as the assignment that maximises the sum of the MACs (Hungarian method); a pair with MAC below ``mac_min`` is no
continuation (the line ends, the mode at b starts a new line). Degenerate pairs (cyclic symmetry: Lin & Parker
1999) have no unique shapes, but their subspace is: the MAC matrix of two pairs spanning the same subspace is doubly
stochastic, so the best assignment pairs each member with MAC >= 1/2 of the other pair, exactly 1/2 where a
standing pair at rest becomes the forward and backward whirl at speed; ``mac_min`` lies below that, by the
perturbation of the subspace between grid speeds. Lines are numbered by the speed at which they start and then by
frequency.

Operating points at one angle. A flexible gear's elastic coordinates are fixed in the body, its meshes fixed in
space: the same mode has other elastic coordinates where the gear stands at another angle. The gears' angles at the
operating point are theta = omega (t* - T/2) (the input's STEP ramp over T, flexgear.laws.ramps.drive_angle, the
other members' in proportion), so every speed n > 0 is linearised at t* = T/2 + theta_ref / omega(n), with
theta_ref = omega(n_max) T / 2 (the highest speed's angle at the end of its ramp: t* >= T at every speed); the
gears then stand at the same angles at every speed. At zero speed the gears stand at the load case's start (theta
= 0), and a flexible variant's lines may start anew at the first speed above it.

Mesh orders. The mesh frequency is flexgear.theory's, f_m = z_s |omega_sun - omega_carrier| / (2 pi) (carrier
fixed in the star arrangement: f_m = z_s n / 60), linear in n. Order k's line is k f_m(n); a crossing of a mode with
it is a sign change of g(n) = f(n) - k f_m(n) between two grid speeds, placed by linear interpolation:
n* = n_a + (n_b - n_a) g_a / (g_a - g_b), where the interpolated frequency equals k f_m(n*). The interpolation
error is below |f_b - f_a| where f is monotone between grid speeds. Each crossing carries the line's damping
ratio interpolated the same way.

Which crossings an order excites (mesh phasing, Parker & Lin 2004). The N planets stand equally spaced at
psi_i = 2 pi i / N; planet i's meshes run z_s psi_i / (2 pi) mesh cycles apart from planet 0's (the ring meshes
alike: the assembly condition (z_s + z_r) / N integer makes z_r = -z_s mod N). Order k's mesh forces on the planets
are then the phasors e^{i 2 pi k z_s i / N}; their net force on the central members is
sum_i e^{i 2 pi k z_s i / N} e^{+-i psi_i}, their net moment about the axis sum_i e^{i 2 pi k z_s i / N}, so with
l = k z_s mod N:

    l = 0: rotational modes only;   l = 1 or N - 1: translational modes only;   otherwise: planet modes only.

A crossing of order k with a mode of another kind makes no resonance (the order does not excite it), and a planet
mode (central members at rest) none at the bearings of the central members. Modes of other kinds (``mixed``,
``elastic_*``: symmetry broken) are taken as excited by every order, and so is every mode when the planets are not
equally spaced (gears.planet_positions_deg): the rule needs the cyclic symmetry.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from flexgear.modal import LinearModel, Modes
from flexgear.schema import Variant
from flexgear.theory import mesh_frequency_hz

__all__ = ["Campbell", "campbell", "excited_kinds", "mesh_frequency_hz", "track", "MESH_ORDERS", "MAX_DAMPING_RATIO",
           "MAC_MIN", "order_crossings"]

MESH_ORDERS = tuple(range(1, 11))
"""Mesh orders k of the diagram: the harmonics k f_m of the mesh excitation, 1x to 10x."""

MAX_DAMPING_RATIO = 1.0 / math.sqrt(2.0)
"""Damping ratio from which a root has no resonance peak (module docstring)."""

MAC_MIN = 0.3
"""Lowest MAC that continues a line between neighbouring speeds (module docstring: the members of a degenerate
pair reach 1/2, less where the speed step perturbs the pair's subspace)."""


SYMMETRIC_KINDS = ("rotational", "translational", "planet")
"""Mode kinds of a cyclically symmetric planet set, to which the mesh-phasing rule applies (module docstring)."""


def excited_kinds(order: int, sun_teeth: int, planet_count: int) -> frozenset[str]:
    """Kinds of modes that mesh order ``order`` excites with ``planet_count`` equally spaced planets and
    ``sun_teeth`` sun teeth (module docstring: l = k z_s mod N)."""
    n = int(planet_count)
    if n < 2:
        return frozenset(SYMMETRIC_KINDS)
    ell = (int(order) * int(sun_teeth)) % n
    if ell == 0:
        return frozenset({"rotational"})
    if ell in (1, n - 1):
        return frozenset({"translational"})
    return frozenset({"planet"})


def resonant(m: Modes, max_damping_ratio: float = MAX_DAMPING_RATIO) -> np.ndarray:
    """Indices of the modes of ``m`` with a resonance peak (damping ratio below ``max_damping_ratio``)."""
    return np.flatnonzero(m.damping_ratios < max_damping_ratio)


def _mac(qa: np.ndarray, qb: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Mass-weighted MAC matrix (module docstring) between the columns of ``qa`` and ``qb``."""
    cross = np.abs(qa.conj().T @ mass @ qb) ** 2
    na = np.real(np.einsum("im,ij,jm->m", qa.conj(), mass, qa))
    nb = np.real(np.einsum("im,ij,jm->m", qb.conj(), mass, qb))
    return cross / np.outer(na, nb)


def _common(a: Sequence[str], b: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """Positions in ``a`` and in ``b`` of the labels that both hold, in ``a``'s order."""
    where = {label: j for j, label in enumerate(b)}
    both = [(i, where[label]) for i, label in enumerate(a) if label in where]
    return np.array([i for i, _ in both], int), np.array([j for _, j in both], int)


def track(shapes: Sequence[np.ndarray], masses: Sequence[np.ndarray], labels: Sequence[Sequence[str]],
          mac_min: float = MAC_MIN) -> tuple[list[dict[int, int]], np.ndarray]:
    """Lines through a grid of mode sets (module docstring).

    ``shapes[i]``: (n_i, m_i) mode shapes over coordinates labelled ``labels[i]`` at grid point i; ``masses[i]``:
    the mass matrix over them. The MAC between neighbouring points is taken over the labels that both hold (the
    bodies' frames and elastic coordinates: a flexible gear's contact coordinates change with its angle). Returns
    (lines: one {grid point: mode index} per line, numbered by start and then by the order of the modes at the
    start; the MAC of each continuation, for diagnostics).
    """
    from scipy.optimize import linear_sum_assignment

    lines: list[dict[int, int]] = [{0: j} for j in range(shapes[0].shape[1])]
    macs = []
    for i in range(1, len(shapes)):
        active = [line for line in lines if i - 1 in line]
        started = set()
        if active and shapes[i].shape[1]:
            a, b = _common(labels[i - 1], labels[i])
            qa = shapes[i - 1][np.ix_(a, [line[i - 1] for line in active])]
            mass = 0.5 * (masses[i - 1][np.ix_(a, a)] + masses[i][np.ix_(b, b)])
            mac = _mac(qa, shapes[i][b], mass)
            rows, cols = linear_sum_assignment(-mac)
            for r, c in zip(rows, cols, strict=True):
                if mac[r, c] >= mac_min:
                    active[r][i] = int(c)
                    started.add(int(c))
                    macs.append(mac[r, c])
        lines.extend({i: j} for j in range(shapes[i].shape[1]) if j not in started)
    return lines, np.asarray(macs)


@dataclass(frozen=True)
class Campbell:
    """A Campbell diagram (module docstring).

    ``table``: one row per line and speed: speed_rpm, mode (the line's number, from 1), frequency_hz,
    damping_ratio, kind; ``crossings``: speed_rpm, order, mode, kind, frequency_hz, one row per crossing of a line
    with a mesh order, with the line's damping_ratio there and whether the order excites the mode (excited);
    ``mesh_hz_per_rpm``: f_m / n [Hz/rpm]; ``f_max_hz``: the band [Hz]; ``mac_min``: the lowest
    MAC that continued a line (1 with a single speed).
    """

    variant_name: str
    table: pd.DataFrame
    crossings: pd.DataFrame
    mesh_hz_per_rpm: float
    f_max_hz: float
    orders: tuple[int, ...]
    mac_min: float

    def plot(self, ax=None):
        """Frequencies [Hz] against input speed [rpm], each line one mode coloured by its kind at the highest speed,
        the mesh orders k f_m (dashed, labelled kx) and the crossings (circles). Returns the axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(9, 6))
        kinds = sorted(set(self.table.kind))
        colours = {k: plt.get_cmap("tab10")(i % 10) for i, k in enumerate(kinds)}
        for _, line in self.table.groupby("mode", sort=True):
            ax.plot(line.speed_rpm, line.frequency_hz, "-", lw=1.0, color=colours[line.kind.iloc[-1]])
        n = np.array([self.table.speed_rpm.min(), self.table.speed_rpm.max()])
        top = self.f_max_hz
        for k in self.orders:
            f = k * self.mesh_hz_per_rpm * n
            ax.plot(n, f, "--", lw=0.7, color="0.5")
            if f[-1] > 0:
                n_label = min(n[-1], top / (k * self.mesh_hz_per_rpm))
                ax.annotate(f"{k}x", (n_label, k * self.mesh_hz_per_rpm * n_label), fontsize=7, color="0.3",
                            xytext=(2, -8 if n_label < n[-1] else 0), textcoords="offset points")
        if len(self.crossings):
            ax.plot(self.crossings.speed_rpm, self.crossings.frequency_hz, "o", mfc="none", color="k", ms=4,
                    label="crossing")
        for k in kinds:
            ax.plot([], [], "-", color=colours[k], label=k)
        ax.set_xlim(n[0], n[-1])
        ax.set_ylim(0.0, top)
        ax.set_xlabel("input speed [rpm]")
        ax.set_ylabel("natural frequency [Hz]")
        ax.set_title(f"Campbell diagram: {self.variant_name}, mesh orders 1x-{max(self.orders)}x")
        ax.legend(fontsize=7, loc="upper left")
        ax.grid(alpha=0.3)
        return ax


def order_crossings(table: pd.DataFrame, per_rpm: float, orders: Sequence[int], sun_teeth: int | None = None,
                    planet_count: int | None = None) -> pd.DataFrame:
    """Crossings of each line of ``table`` with the mesh orders (module docstring); ``excited``: whether the order
    excites the mode's kind (:func:`excited_kinds`; every crossing without ``sun_teeth`` and ``planet_count``)."""
    rows = []
    for mode, line in table.groupby("mode", sort=True):
        n, f, kind = line.speed_rpm.to_numpy(), line.frequency_hz.to_numpy(), line.kind.to_numpy()
        zeta = line.damping_ratio.to_numpy()
        for k in orders:
            g = f - k * per_rpm * n
            for a in range(len(n) - 1):
                b = a + 1
                if not (g[a] * g[b] < 0.0 or (g[b] == 0.0 and g[a] != 0.0)):
                    continue
                t = g[a] / (g[a] - g[b])
                kd = kind[a] if t < 0.5 else kind[b]
                excited = (sun_teeth is None or planet_count is None or kd not in SYMMETRIC_KINDS
                           or kd in excited_kinds(k, sun_teeth, planet_count))
                rows.append({"speed_rpm": n[a] + t * (n[b] - n[a]), "order": k, "mode": int(mode), "kind": kd,
                             "frequency_hz": f[a] + t * (f[b] - f[a]),
                             "damping_ratio": zeta[a] + t * (zeta[b] - zeta[a]), "excited": bool(excited)})
    columns = ["speed_rpm", "order", "mode", "kind", "frequency_hz", "damping_ratio", "excited"]
    out = pd.DataFrame(rows, columns=columns)
    return out.sort_values(["speed_rpm", "order", "mode"], ignore_index=True)


def campbell(variant: Variant, speeds_rpm: Sequence[float], f_max_hz: float | None = None, *,
             orders: Sequence[int] = MESH_ORDERS, mac_min: float = MAC_MIN,
             max_damping_ratio: float = MAX_DAMPING_RATIO,
             progress: Callable[[float, LinearModel, Modes], None] | None = None) -> Campbell:
    """The Campbell diagram of ``variant`` over the input speeds ``speeds_rpm`` [rpm] (module docstring).

    ``f_max_hz`` [Hz]: the band (default: the highest order's mesh frequency at the highest speed, max(orders)
    f_m(n_max): no order crosses above it); ``progress(speed_rpm, model, modes)`` is called after each speed.
    """
    from flexgear.modal import linearize, modes

    speeds = np.sort(np.asarray(speeds_rpm, float))
    if speeds.size == 0 or np.any(speeds < 0.0) or np.any(np.diff(speeds) == 0.0):
        raise ValueError(f"speeds_rpm: distinct speeds >= 0 rpm expected, got {list(speeds_rpm)}")
    spec = variant.gearbox
    per_rpm = mesh_frequency_hz(spec, 1.0)
    band = max(orders) * per_rpm * speeds[-1] if f_max_hz is None else float(f_max_hz)
    ramp = spec.load_case.ramp_time_s
    omega = speeds * (2.0 * math.pi / 60.0)  # rad/s
    theta_ref = omega[-1] * ramp / 2.0  # rad
    found: list[Modes] = []
    picks: list[np.ndarray] = []
    for n, w in zip(speeds, omega, strict=True):
        t_star = ramp / 2.0 + theta_ref / w if w > 0.0 else None
        model = linearize(variant, speed_rpm=float(n), t_star=t_star)
        m = modes(model, band)
        found.append(m)
        picks.append(resonant(m, max_damping_ratio))
        if progress is not None:
            progress(float(n), model, m)
    stable = [np.array([c.kind in ("frame", "elastic") for c in m.model.full_coordinates]) for m in found]
    shapes = [m.full_shapes()[np.ix_(s, p)] for m, s, p in zip(found, stable, picks, strict=True)]
    masses = [m.model.full_mass[np.ix_(s, s)] for m, s in zip(found, stable, strict=True)]
    labels = [[c.label for c, k in zip(m.model.full_coordinates, s, strict=True) if k]
              for m, s in zip(found, stable, strict=True)]
    lines, macs = track(shapes, masses, labels, mac_min)
    rows = []
    for number, line in enumerate(lines, start=1):
        for i, j in sorted(line.items()):
            m, jj = found[i], int(picks[i][j])
            rows.append({"speed_rpm": speeds[i], "mode": number, "frequency_hz": m.frequencies_hz[jj],
                         "damping_ratio": m.damping_ratios[jj], "kind": m.kinds[jj]})
    table = pd.DataFrame(rows, columns=["speed_rpm", "mode", "frequency_hz", "damping_ratio", "kind"])
    table = table.sort_values(["speed_rpm", "frequency_hz"], ignore_index=True)
    crossings = order_crossings(table, per_rpm, orders, spec.gears.sun_teeth,
                                spec.gears.planet_count if spec.gears.equally_spaced else None)
    return Campbell(variant.name, table, crossings, per_rpm, band, tuple(orders),
                    float(macs.min()) if macs.size else 1.0)
