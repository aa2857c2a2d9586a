"""How far would stationary-frame (harmonic) modal coordinates hold a spinning flexible body's coupling rows still?

Run: python benchmarks/bench_stationary_frame.py [VARIANT] [--pair-split 0.005] [--angles 12]

For each flexible body of the variant (default model 7: sun, planet, input shaft, the tied ring and output shaft),
at its mesh level and with the modes the time integration keeps:

- mode pairs: neighbours whose frequencies differ by less than ``--pair-split`` (relative);
- each pair's circumferential harmonic n and its coherence: with a, b the pair's mode shapes in cylindrical
  components (u_r, u_t, u_z) at the mesh nodes (angle t), a pure harmonic has Z = a + i b = f(r, z) e^(i (n t + g))
  per component (i f for u_t), so that |sum (Z_r^2 - Z_t^2 + Z_z^2) e^(-2 i n t)| / sum |Z|^2 is 1 at its signed n
  (uniform node weights; a test, not a mass-weighted projection);
- the pair-based generator W (W_ab = n, W_ba = -n per pair, 0 for single modes) and its rotation B(t) = exp(t W):
  the body's modal coordinates q = B(t) p in the frame that does not turn with the body;
- the largest change over one revolution (``--angles`` spin angles) of the coupling rows, relative to their largest
  entry: each interface's RBE3 motion rows in ground, Q(t) P against Q(t) P B(t) (Q = blockdiag(R_z, R_z)), and one
  contact's deflection row c(psi - t) against c(psi - t) B(t) (flexgear.mbs.contact_kinematics.modal_contact_fourier).
  In the body frame they change by about 2 (the rows turn); a body whose pairs carry its rotation holds them at
  the size of its mesh's asymmetry.

A measurement for the design of such a formulation; the production formulation does not use it.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from scipy.linalg import expm

from flexgear.design import as_design
from flexgear.fe.attachment import fourier_basis
from flexgear.fe.ring_shaft import TIED_PAIR, reduced_body
from flexgear.mbs.contact_kinematics import modal_contact_fourier
from flexgear.mbs.gearbox import dynamic_cutoff_hz, dynamic_modes, mesh_contacts
from flexgear.spec import load_variant

ROOT = Path(__file__).resolve().parents[1]
N_MAX = 30  # highest circumferential harmonic tried


def cylindrical(nodes: np.ndarray, modes: np.ndarray) -> tuple[np.ndarray, ...]:
    """(t, u_r, u_t, u_z): node angles [rad] and the modes' cylindrical components (n, m)."""
    t = np.arctan2(nodes[:, 1], nodes[:, 0])
    u = modes.reshape(len(nodes), 3, -1)
    c, s = np.cos(t)[:, None], np.sin(t)[:, None]
    return t, c * u[:, 0] + s * u[:, 1], -s * u[:, 0] + c * u[:, 1], u[:, 2]


def pair_generator(reduced, split: float) -> tuple[np.ndarray, list[tuple[int, int, float, float]]]:
    """W (m, m) of the module docstring and the pairs: (first mode, signed n, coherence, relative split)."""
    f = reduced.frequencies_hz
    m = reduced.n_modes
    t, ur, ut, uz = cylindrical(reduced.nodes, reduced.modes)
    harmonics = np.arange(-N_MAX, N_MAX + 1)
    phase = np.exp(-2j * harmonics[:, None] * t[None, :])
    w, pairs, j = np.zeros((m, m)), [], 0
    while j < m:
        if j + 1 < m and abs(f[j + 1] - f[j]) < split * f[j]:
            zr, zt, zz = (x[:, j] + 1j * x[:, j + 1] for x in (ur, ut, uz))
            total = np.sum(np.abs(zr) ** 2 + np.abs(zt) ** 2 + np.abs(zz) ** 2)
            coherence = np.abs(phase @ (zr ** 2 - zt ** 2 + zz ** 2)) / total
            n = int(harmonics[np.argmax(coherence)])
            w[j, j + 1], w[j + 1, j] = n, -n
            pairs.append((j, n, float(coherence.max()), float((f[j + 1] - f[j]) / f[j])))
            j += 2
        else:
            j += 1
    return w, pairs


def turned_axes(angle: float) -> np.ndarray:
    """Q = blockdiag(R_z, R_z) (6, 6) at ``angle`` [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.kron(np.eye(2), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))


def row_changes(rows_at, w: np.ndarray, angles: np.ndarray) -> tuple[float, float]:
    """The largest change over ``angles`` of the rows ``rows_at(t)`` over q (body frame) and of rows_at(t) B(t) over
    p (stationary), each relative to the largest entry at t = 0 (B(0) = I)."""
    start = rows_at(0.0)
    scale = float(np.abs(start).max())
    body = max(float(np.abs(rows_at(t) - start).max()) for t in angles)
    fixed = max(float(np.abs(rows_at(t) @ expm(t * w) - start).max()) for t in angles)
    return body / scale, fixed / scale


def interface_rows_at(p: np.ndarray):
    """t -> Q(t) p: an interface's RBE3 motion rows (6, m) in ground at the spin angle t."""
    return lambda t: turned_axes(t) @ p


def contact_row_at(coef: np.ndarray, psi: float, order: int):
    """t -> c(psi - t): a contact's deflection row (1, m) at the spin angle t (its Fourier coefficients ``coef``)."""
    return lambda t: fourier_basis(np.array([psi - t]), order) @ coef


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("variant", nargs="?", default=str(ROOT / "model_variants" / "model7.toml"))
    ap.add_argument("--pair-split", type=float, default=0.005, help="relative frequency split of a pair")
    ap.add_argument("--angles", type=int, default=12, help="spin angles over one revolution")
    a = ap.parse_args()
    variant = load_variant(a.variant)
    d = as_design(variant.gearbox)
    spec = d.spec
    cutoff = dynamic_cutoff_hz(d)
    contacts = mesh_contacts(d, 1.0)
    angles = 2.0 * np.pi * np.arange(1, a.angles + 1) / a.angles
    planet = d.gears.centre_distance * np.array([math.cos(d.gears.planet_angles[0]),
                                                 math.sin(d.gears.planet_angles[0]), 0.0])
    bodies = [("sun", "sun", "sun", np.zeros(3)), ("planet", "planet", "planet1", planet),
              ("input_shaft", "input_shaft", None, np.zeros(3)), ("ring", TIED_PAIR, "ring", np.zeros(3))]
    print(f"bench_stationary_frame: {variant.name}, {variant.mesh_level} bodies, pairs split below "
          f"{100 * a.pair_split:g} %, {a.angles} spin angles")
    for geometry, source, gear, position in bodies:
        full = reduced_body(spec, source, variant.mesh_level)
        keep = dynamic_modes(geometry, full.frequencies_hz, cutoff)
        red = full.truncated(keep) if keep < full.n_modes else full
        w, pairs = pair_generator(red, a.pair_split)
        coherent = sum(1 for p in pairs if p[2] >= 0.9)
        print(f"{geometry}: {red.n_modes} modes, {len(pairs)} pairs ({coherent} with coherence >= 0.9; harmonics "
              f"{sorted({abs(p[1]) for p in pairs})}), {red.n_modes - 2 * len(pairs)} single")
        for itf in red.interfaces:
            body, fixed = row_changes(interface_rows_at(red.interface_motion(itf.name)), w, angles)
            print(f"  interface {itf.name}: rows change {body:.3f} in the body frame, {fixed:.3f} stationary")
        for c in contacts:
            if gear not in (c.body1, c.body2):
                continue
            rel = np.asarray(c.point, float) - position
            order = spec.reduction_assumed.contact_fourier_order
            coef = modal_contact_fourier(red.nodes, red.modes, rel, np.asarray(c.normal, float), 0.5 * c.half_width,
                                         spec.gears.normal_module_m, order)
            body, fixed = row_changes(contact_row_at(coef, math.atan2(rel[1], rel[0]), order), w, angles)
            print(f"  contact {c.name}: row changes {body:.3f} in the body frame, {fixed:.3f} stationary")
            break


if __name__ == "__main__":
    main()
