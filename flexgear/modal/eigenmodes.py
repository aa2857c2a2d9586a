"""Natural frequencies, damping ratios, mode shapes, kinds and energy shares of a linearised gearbox.

Eigenproblem of M z'' + (D + G) z' + K z = 0 (flexgear.modal.linear.LinearModel) in state space,

    [0, I; -M^-1 K, -M^-1 (D + G)] x = lambda x,     x = (phi, lambda phi),

one mode per complex-conjugate pair of roots (Im lambda > 0): natural frequency f = |lambda| / (2 pi) [Hz],
damping ratio zeta = -Re(lambda) / |lambda| (both exact for a single degree of freedom), shape phi (complex,
phi^H M phi = 1). Overdamped roots (real lambda) are no vibration modes and are left out. Without damping and
gyroscopic terms the symmetric problem K phi = omega^2 M phi is solved directly.

Energy shares per mode (time averages of a harmonic motion, over the system's coordinates q = B phi): kinetic
e_g = Re(q_g^H (M q)_g) / Re(q^H M q) and strain s_g = Re(q_g^H (K_s q)_g) / Re(q^H K_s q) (K_s the symmetric part
of K) for each group g of coordinates, so that each row sums to 1. Groups: every component's frame (its rigid motion;
a rigid body that joins a gear and its shaft shares it out by their 6x6 mass matrices), every flexible component's
elastic coordinates (``_elastic``), the sun-planet (``outer_mesh``) and planet-ring (``inner_mesh``) contact
deflections (strain only: massless) and the gears' residual compliance with its Ritz mass (``residual``, flexgear.
mbs.residual, where the variant has one). The strain of a frame is that of its bearing.

Kinds (cyclic symmetry of a planetary set with N equally spaced planets: Lin & Parker 1999 for spur gears,
Eritenel & Parker 2009 for the 6-DOF-per-body helical model), from the kinetic energy of the central members
(sun, ring and shafts; the carrier is fixed). With c the central members' frames' share of the mode's kinetic
energy and a the share of their spin and axial motion (phi_z, u_z) in it:

- ``elastic_<component>``: the elastic strain of one flexible component holds most (> 1/2) of the mode's strain;
- ``planet``: central members' frames at rest, c < ``planet_share`` (:data:`PLANET_SHARE`), multiplicity N - 3
  (N - 1 in the torsional model); an elastic central member may deform in them (Wu & Parker 2008, elastic ring);
- ``rotational``: central members only spin and move axially, (c - a) / c < ``motion_share``
  (:data:`MOTION_SHARE`; rotational-axial modes, single);
- ``translational``: central members only translate in-plane and tilt, a / c < ``motion_share``
  (translational-tilting modes, pairs);
- ``mixed``: none of these (broken symmetry: unequally spaced planets, a helical set's coupling).

With exact symmetry (rigid members, mean mesh stiffness) the shares that vanish are round-off; a flexible model's
tetrahedral meshes break the symmetry slightly, so that the central frames move a little in the planet modes and
the wrong kind of central motion enters a little, orders of magnitude below the motions that define the kinds:
the thresholds sit between the two. The pair split of a broken symmetry is the multiplet's ``split_pct``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from flexgear.modal.linear import LinearModel

__all__ = ["Modes", "modes", "state_space_roots", "CENTRAL", "PLANET_SHARE", "MOTION_SHARE"]

CENTRAL = ("input_shaft", "sun", "ring", "output_shaft", "carrier")
"""The central members: the star's (its carrier fixed) and the planetary stage's turning carrier."""

PLANET_SHARE = 1e-4
"""Share of a mode's kinetic energy in the central members' frames below which they count as at rest (a planet
mode; module docstring)."""

MOTION_SHARE = 1e-3
"""Share of the central members' kinetic energy in the other kind's motion (spin and axial, or translation and
tilt) below which a mode is rotational or translational (module docstring)."""

_SPIN_AXIAL = ("u_z", "phi_z")


@dataclass(frozen=True)
class Modes:
    """Modes of a :class:`~flexgear.modal.linear.LinearModel`, ascending in frequency (module docstring).

    ``shapes``: (n_z, n_modes) complex, over the model's independent coordinates; ``energy``: one row per mode,
    kinetic_* and strain_* shares (each family sums to 1); ``multiplicity`` and ``split_pct``: the modes of the
    same kind whose frequencies lie within ``pair_rtol`` of each other form a multiplet, 100 (f_max - f_min) /
    f_mean its split [%]; ``spread_pct``: each frequency's spread [%] over the angles of the flexible gears
    (flexgear.modal.period; zero for modes at one operating point).
    """

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    shapes: np.ndarray
    kinds: tuple[str, ...]
    multiplicity: np.ndarray
    split_pct: np.ndarray
    energy: pd.DataFrame
    model: LinearModel
    spread_pct: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.spread_pct is None:
            object.__setattr__(self, "spread_pct", np.zeros(len(self.frequencies_hz)))

    def __len__(self) -> int:
        return len(self.frequencies_hz)

    def table(self) -> pd.DataFrame:
        """One row per mode: mode (1-based), frequency_hz, damping_ratio, kind, spread_pct, multiplicity,
        split_pct and the energy shares."""
        head = pd.DataFrame({"mode": np.arange(1, len(self) + 1), "frequency_hz": self.frequencies_hz,
                             "damping_ratio": self.damping_ratios, "kind": list(self.kinds),
                             "spread_pct": self.spread_pct, "multiplicity": self.multiplicity,
                             "split_pct": self.split_pct})
        return pd.concat([head, self.energy.reset_index(drop=True)], axis=1)

    def kinetic_share(self, select) -> np.ndarray:
        """Share of each mode's kinetic energy in the system coordinates for which ``select(Coordinate)`` is true
        (e.g. ``lambda c: c.name in ("u_x", "u_y", "phi_z")``: the in-plane share)."""
        q = self.full_shapes()
        mq = self.model.full_mass @ q
        mask = np.array([bool(select(c)) for c in self.model.full_coordinates])
        total = np.real(np.einsum("im,im->m", q.conj(), mq))
        return np.real(np.einsum("im,im->m", q[mask].conj(), mq[mask])) / np.where(total > 0, total, 1.0)

    def full_shapes(self) -> np.ndarray:
        """(n_q, n_modes) shapes over all the system's coordinates (``model.basis`` @ ``shapes``)."""
        return self.model.basis @ self.shapes


def state_space_roots(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """All 2n roots lambda and right eigenvectors (2n, 2n) of M z'' + D z' + K z = 0 in state space,
    [0, I; -M^-1 K, -M^-1 D] x = lambda x with x = (phi, lambda phi) (module docstring); ``damping`` includes any
    gyroscopic part. The roots come in the order LAPACK's dgeev returns them."""
    n = mass.shape[0]
    minv_kd = np.linalg.solve(mass, np.hstack([stiffness, damping]))  # [M^-1 K, M^-1 D]
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv_kd]])
    return np.linalg.eig(a)


def _eigen(model: LinearModel) -> tuple[np.ndarray, np.ndarray]:
    """(roots lambda with Im > 0, ascending |lambda|; their shapes phi, mass-normalised)."""
    from scipy.linalg import eigh

    m, d, k = model.mass, model.damping + model.gyroscopic, model.stiffness
    n = m.shape[0]
    scale = max(np.abs(k).max(), 1e-300)
    if not np.any(d) and np.abs(k - k.T).max() <= 1e-12 * scale:
        w2, phi = eigh(0.5 * (k + k.T), m)
        lam = 1j * np.sqrt(np.maximum(w2, 0.0))
        phi = phi.astype(complex)
    else:
        lam, x = state_space_roots(m, d, k)
        pick = lam.imag > 1e-9 * np.abs(lam).max()
        lam, phi = lam[pick], x[:n, pick]
    order = np.argsort(np.abs(lam))
    lam, phi = lam[order], phi[:, order]
    norm = np.sqrt(np.real(np.einsum("im,ij,jm->m", phi.conj(), m, phi)))
    return lam, phi / norm


def _groups(model: LinearModel) -> dict[str, np.ndarray]:
    """Column name (without kinetic_/strain_) -> boolean mask over the system coordinates."""
    coords = model.full_coordinates
    comp = np.array([c.component for c in coords])
    kind = np.array([c.kind for c in coords])
    out = {}
    for c in model.components:
        out[c] = (comp == c) & (kind == "frame")
        if c in model.flexible:
            out[f"{c}_elastic"] = (comp == c) & (kind == "elastic")
    deflection = kind == "deflection"
    out["outer_mesh"] = deflection & np.array([x.startswith("sun_") for x in comp])
    out["inner_mesh"] = deflection & np.array([x.endswith("_ring") for x in comp])
    out["residual"] = kind == "residual"
    covered = np.any(list(out.values()), axis=0)
    if not covered.all():
        raise ValueError(f"coordinates without an energy group: {[coords[i].label for i in np.flatnonzero(~covered)]}")
    return out


def _shares(model: LinearModel, q: np.ndarray, matrix: np.ndarray, groups: dict[str, np.ndarray],
            parts: bool) -> dict[str, np.ndarray]:
    """Energy share of each group in each mode (module docstring); ``parts``: split joined frames by their parts'
    masses (kinetic energy; else the frame's energy goes to the shaft, which carries the bearing). A flexible body
    of two components (LinearModel.elastic_parts) splits its elastic energy by its parts' shares of its modal mass
    (``parts``) or stiffness."""
    mq = matrix @ q
    per = np.real(q.conj() * mq)  # (n_q, modes): each coordinate's part of q^H A q
    total = per.sum(axis=0)
    total = np.where(np.abs(total) > 0, total, 1.0)
    out = {name: per[mask].sum(axis=0) / total for name, mask in groups.items()}
    for start, split in model.parts.items():  # a joined frame's bearing sits on the shaft (the second part)
        if not parts:
            joined, shaft = model.full_coordinates[start].component, split[-1][0]
            out[shaft], out[joined] = out[shaft] + out[joined], np.zeros_like(out[joined])
    for component, (index, split) in model.elastic_parts.items():
        whole = out[f"{component}_elastic"]
        raw = [np.real(np.einsum("im,ij,jm->m", q[index].conj(), m_p if parts else k_p, q[index]))
               for _, m_p, k_p in split]
        s = np.sum(raw, axis=0)
        s = np.where(np.abs(s) > 0, s, 1.0)
        for (name, _, _), r in zip(split, raw, strict=True):
            out[f"{name}_elastic"] = whole * r / s
    if parts:
        for start, split in model.parts.items():
            frame = q[start:start + 6]
            raw = [np.real(np.einsum("im,ij,jm->m", frame.conj(), m6, frame)) for _, m6 in split]
            whole = per[start:start + 6].sum(axis=0) / total
            joined = model.full_coordinates[start].component
            out[joined] = np.zeros_like(whole)
            s = np.sum(raw, axis=0)
            s = np.where(np.abs(s) > 0, s, 1.0)
            for (name, _), r in zip(split, raw, strict=True):
                out[name] = out.get(name, 0.0) + whole * r / s
    return out


def _kind(model: LinearModel, kinetic: dict[str, np.ndarray], spin_axial: np.ndarray, strain: dict[str, np.ndarray],
          j: int, planet_share: float, motion_share: float) -> str:
    elastic = {c: strain[f"{c}_elastic"][j] for c in model.flexible}
    if elastic:
        best = max(elastic, key=elastic.get)
        if elastic[best] > 0.5:
            return f"elastic_{best}"
    frame = sum(kinetic[c][j] for c in CENTRAL if c in kinetic)
    if frame < planet_share:
        return "planet"
    if frame - spin_axial[j] < motion_share * frame:
        return "rotational"
    if spin_axial[j] < motion_share * frame:
        return "translational"
    return "mixed"


def _multiplets(freqs: np.ndarray, kinds: tuple[str, ...], rtol: float) -> tuple[np.ndarray, np.ndarray]:
    mult = np.ones(freqs.size, dtype=int)
    spread = np.zeros(freqs.size)
    for i, f in enumerate(freqs):
        same = np.array([k == kinds[i] for k in kinds]) & (np.abs(freqs - f) <= rtol * max(f, 1e-12))
        group = freqs[same]
        mult[i] = group.size
        spread[i] = 100.0 * (group.max() - group.min()) / group.mean() if group.mean() > 0 else 0.0
    return mult, spread


def modes(model: LinearModel, f_max_hz: float | None = None, *, planet_share: float = PLANET_SHARE,
          motion_share: float = MOTION_SHARE, pair_rtol: float = 1e-3) -> Modes:
    """The modes of ``model`` up to ``f_max_hz`` [Hz] (all by default), with kinds and energy shares (module
    docstring). ``planet_share``, ``motion_share``: the kinds' thresholds; ``pair_rtol``: relative frequency
    distance within a multiplet."""
    lam, phi = _eigen(model)
    freqs = np.abs(lam) / (2.0 * math.pi)
    zeta = -lam.real / np.maximum(np.abs(lam), 1e-300)
    if f_max_hz is not None:
        keep = freqs <= f_max_hz
        lam, phi, freqs, zeta = lam[keep], phi[:, keep], freqs[keep], zeta[keep]
    q = model.basis @ phi
    groups = _groups(model)
    kinetic = _shares(model, q, model.full_mass, groups, parts=True)
    stiffness = 0.5 * (model.full_stiffness + model.full_stiffness.T)
    strain = _shares(model, q, stiffness, groups, parts=False)
    coords = model.full_coordinates
    axial = np.array([c.kind == "frame" and c.component in CENTRAL and c.name in _SPIN_AXIAL for c in coords])
    mq = model.full_mass @ q
    total = np.real(np.einsum("im,im->m", q.conj(), mq))
    spin_axial = np.real(np.einsum("im,im->m", q[axial].conj(), mq[axial])) / np.where(total > 0, total, 1.0)
    kinds = tuple(_kind(model, kinetic, spin_axial, strain, j, planet_share, motion_share) for j in range(freqs.size))
    mult, split = _multiplets(freqs, kinds, pair_rtol)
    columns = {}
    for prefix, shares in (("kinetic", kinetic), ("strain", strain)):
        for name, values in shares.items():
            if prefix == "kinetic" and name in ("outer_mesh", "inner_mesh"):
                continue  # massless
            if name == "residual" and not groups["residual"].any():
                continue
            columns[f"{prefix}_{name}"] = values
    return Modes(freqs, zeta, phi, kinds, mult, split, pd.DataFrame(columns), model)
