"""How far would stationary-frame (harmonic) modal coordinates hold a spinning flexible body's coupling rows still?

Run: python benchmarks/bench_stationary_frame.py [VARIANT] [--pair-split 0.005] [--angles 12]
     [--generator pairs|mesh|fit] [--bodies sun planet input_shaft ring]

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
  the size of its mesh's asymmetry;
- the largest change of the modal stiffness B(t)^T Lambda B(t) over the revolution, entry ij relative to
  sqrt(lambda_i lambda_j): what the modal equations would carry as a remainder that turns (the pairs' split for
  the pairs).

``--generator mesh``: W projected from the mesh instead of the pairs, W = skew(Psi^T M L Psi) with L u = e_z x u -
(e_z x x) . grad u the rotation's generator on a displacement field (grad u at each node by a least-squares linear fit
over the nodes it shares an element with: the mass matrix's pattern; M the body's FE mass matrix), and its closure:
|L Psi - Psi W|_M / |L Psi|_M, the share of the rotated modes outside the basis (each body's FE model is built from
the cached mesh: minutes for the tied ring and output shaft). ``--generator fit``: W fitted to the rows alone,
column by column, P W = -J P for each interface's rows (J the generator of Q) and F W = H F for each contact's Fourier
coefficients F (H the harmonics' generator), regularised by ``--commute`` x sum ((lambda_l - lambda_m) W_ml)^2 /
lambda_max^2 towards commuting with Lambda, then its skew part: a W that need not be the body's rotation, only hold
its sensed rows still.

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


def mesh_generator(reduced, mass_scalar, nodes: np.ndarray) -> tuple[np.ndarray, float, float]:
    """(-W, asymmetry |W + W^T| / |W|, closure |L Psi - Psi W|_M / |L Psi|_M) of ``--generator mesh``: ``mass_scalar``
    (n, n) the FE model's scalar mass matrix over ``nodes`` (n, 3) [m], the reduced body's nodes."""
    import scipy.sparse as sp

    ms = sp.csr_matrix(mass_scalar)
    n = len(nodes)
    degree = np.diff(ms.indptr)
    tangent = np.column_stack([-nodes[:, 1], nodes[:, 0], np.zeros(n)])  # e_z x x
    rows, cols, vals = [], [], []
    for k in np.unique(degree):  # nodes with k neighbours at once: d/dtheta at node i = sum_j c_ij f_j
        at = np.flatnonzero(degree == k)
        nbr = np.stack([ms.indices[ms.indptr[i]:ms.indptr[i + 1]] for i in at])  # (g, k)
        offsets = nodes[nbr] - nodes[at][:, None, :]
        design = np.concatenate([np.ones((len(at), k, 1)), offsets], axis=2)  # (g, k, 4)
        slope = np.linalg.pinv(design)[:, 1:, :]  # (g, 3, k): the fitted gradient per neighbour value
        rows.append(np.repeat(at, k))
        cols.append(nbr.ravel())
        vals.append(np.einsum("gd,gdk->gk", tangent[at], slope).ravel())
    d_theta = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    psi = reduced.modes.reshape(n, 3, -1)
    turned = np.stack([-psi[:, 1], psi[:, 0], np.zeros_like(psi[:, 2])], axis=1)  # e_z x u
    rotated = turned - np.stack([d_theta @ psi[:, c] for c in range(3)], axis=1)  # L psi, (n, 3, m)
    m_rotated = np.stack([ms @ rotated[:, c] for c in range(3)], axis=1)
    w = np.einsum("ncm,ncl->ml", psi, m_rotated)  # Psi^T M L Psi
    asym = float(np.linalg.norm(w + w.T) / np.linalg.norm(w))
    skew = 0.5 * (w - w.T)
    outside = rotated - np.einsum("ncm,ml->ncl", psi, skew)
    m_outside = np.stack([ms @ outside[:, c] for c in range(3)], axis=1)
    closure = float(np.sqrt(np.einsum("ncl,ncl->", outside, m_outside) / np.einsum("ncl,ncl->", rotated, m_rotated)))
    # the body turned by t carries the field Psi q to Psi exp(t W) q: its coordinates turned back, q = B(t) p with
    # B(t) = exp(-t W) (the pair generator's convention, B(t) = exp(t W_pairs))
    return -skew, asym, closure


def fitted_generator(rows: list[tuple[np.ndarray, np.ndarray]], stiffness: np.ndarray, commute: float
                     ) -> np.ndarray:
    """``--generator fit``: ``rows`` [(A, G)]: rows A (r, m) over q whose target is A W = G A (each set scaled to its
    largest entry); ``stiffness`` Lambda (m,) [1/s^2]. Returns the skew part of the column-wise least-squares W."""
    a = np.vstack([x / np.abs(x).max() for x, _ in rows])
    target = np.vstack([(g @ x) / np.abs(x).max() for x, g in rows])
    m = len(stiffness)
    w = np.zeros((m, m))
    normal = a.T @ a
    for col in range(m):
        penalty = commute * ((stiffness - stiffness[col]) / stiffness.max()) ** 2
        w[:, col] = np.linalg.solve(normal + np.diag(penalty) + 1e-12 * np.eye(m), a.T @ target[:, col])
    return 0.5 * (w - w.T)


def fourier_generator(order: int) -> np.ndarray:
    """H (2 order + 1, 2 order + 1): fourier_basis(psi - t) = exp(t H) fourier_basis(psi) per harmonic k."""
    h = np.zeros((2 * order + 1, 2 * order + 1))
    for k in range(1, order + 1):
        h[2 * k - 1:2 * k + 1, 2 * k - 1:2 * k + 1] = [[0.0, k], [-k, 0.0]]
    return h


def body_fe(spec, source: str, level: str):
    """(scalar mass matrix, nodes) of the FE model the reduced body ``source`` was reduced from."""
    from flexgear.fe.ring_shaft import PAIR, part_fe_model, tied_pair

    if source == TIED_PAIR:
        fe = tied_pair(*(part_fe_model(spec, c, level) for c in PAIR), spec).fe
    else:
        fe = part_fe_model(spec, source, level)
    return fe.mass_scalar, fe.nodes


def turned_axes(angle: float) -> np.ndarray:
    """Q = blockdiag(R_z, R_z) (6, 6) at ``angle`` [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return np.kron(np.eye(2), np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]))


def row_changes(rows_at, turns: list[tuple[float, np.ndarray]]) -> tuple[float, float]:
    """The largest change over ``turns`` [(t, B(t))] of the rows ``rows_at(t)`` over q (body frame) and of
    rows_at(t) B(t) over p (stationary), each relative to the largest entry at t = 0 (B(0) = I)."""
    start = rows_at(0.0)
    scale = float(np.abs(start).max())
    body = max(float(np.abs(rows_at(t) - start).max()) for t, _ in turns)
    fixed = max(float(np.abs(rows_at(t) @ b - start).max()) for t, b in turns)
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
    ap.add_argument("--generator", choices=("pairs", "mesh", "fit"), default="pairs",
                    help="the rotation generator: from the mode pairs, projected from the mesh, or fitted to the rows")
    ap.add_argument("--commute", type=float, default=1e-3, help="--generator fit: the weight towards commuting")
    ap.add_argument("--bodies", nargs="+", default=("sun", "planet", "input_shaft", "ring"),
                    help="the bodies to measure (ring: the tied ring and output shaft)")
    a = ap.parse_args()
    variant = load_variant(a.variant)
    d = as_design(variant.gearbox)
    spec = d.spec
    cutoff = dynamic_cutoff_hz(d)
    contacts = mesh_contacts(d, 1.0)
    order = spec.reduction_assumed.contact_fourier_order
    angles = 2.0 * np.pi * np.arange(1, a.angles + 1) / a.angles
    planet = d.gears.centre_distance * np.array([math.cos(d.gears.planet_angles[0]),
                                                 math.sin(d.gears.planet_angles[0]), 0.0])
    bodies = [("sun", "sun", "sun", np.zeros(3)), ("planet", "planet", "planet1", planet),
              ("input_shaft", "input_shaft", None, np.zeros(3)), ("ring", TIED_PAIR, "ring", np.zeros(3))]
    turn = np.kron(np.eye(2), np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))  # dQ/dt at 0
    print(f"bench_stationary_frame: {variant.name}, {variant.mesh_level} bodies, {a.generator} generator, pairs "
          f"split below {100 * a.pair_split:g} %, {a.angles} spin angles")
    for geometry, source, gear, position in (b for b in bodies if b[0] in a.bodies):
        full = reduced_body(spec, source, variant.mesh_level)
        keep = dynamic_modes(geometry, full.frequencies_hz, cutoff)
        red = full.truncated(keep) if keep < full.n_modes else full
        w, pairs = pair_generator(red, a.pair_split)
        coherent = sum(1 for p in pairs if p[2] >= 0.9)
        print(f"{geometry}: {red.n_modes} modes, {len(pairs)} pairs ({coherent} with coherence >= 0.9; harmonics "
              f"{sorted({abs(p[1]) for p in pairs})}), {red.n_modes - 2 * len(pairs)} single")
        sensed = [(f"interface {i.name}", interface_rows_at(red.interface_motion(i.name)),
                   (red.interface_motion(i.name), -turn)) for i in red.interfaces]
        for c in contacts:
            if gear in (c.body1, c.body2):
                rel = np.asarray(c.point, float) - position
                coef = modal_contact_fourier(red.nodes, red.modes, rel, np.asarray(c.normal, float),
                                             0.5 * c.half_width, spec.gears.normal_module_m, order)
                sensed.append((f"contact {c.name}", contact_row_at(coef, math.atan2(rel[1], rel[0]), order),
                               (coef, fourier_generator(order))))
        if a.generator == "mesh":
            mass_scalar, nodes = body_fe(spec, source, variant.mesh_level)
            if nodes.shape != red.nodes.shape or np.abs(nodes - red.nodes).max() > 1e-12:
                raise SystemExit(f"{geometry}: the FE model's nodes are not the reduced body's")
            w, asym, closure = mesh_generator(red, mass_scalar, nodes)
            print(f"  generator from the mesh: asymmetry {asym:.3f}, closure {closure:.3f}")
        elif a.generator == "fit":
            w = fitted_generator([target for *_, target in sensed], red.stiffness, a.commute)
        turns = [(t, expm(t * w)) for t in angles]  # B(t), once per body
        for label, rows_at, _ in sensed[:len(red.interfaces) + 1]:  # the interfaces and one contact
            body, fixed = row_changes(rows_at, turns)
            print(f"  {label}: rows change {body:.3f} in the body frame, {fixed:.3f} stationary")
        lam, scale = np.diag(red.stiffness), np.sqrt(np.outer(red.stiffness, red.stiffness))
        moved = max(float((np.abs(b.T @ lam @ b - lam) / scale).max()) for _, b in turns)
        print(f"  modal stiffness B^T Lambda B: largest change {moved:.2e} (entry ij over sqrt(lambda_i lambda_j))")


if __name__ == "__main__":
    main()
