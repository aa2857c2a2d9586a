"""Rigid patches of a body: node sets that a reduction holds rigid (RBE2, flexgear.fe.cms ``rigid=``), found again
from a reduced body's modes, and the basis that holds them rigid in its full FE model.

A patch of k nodes moves rigidly when its displacements u_b lie in the span of its rigid motions R_b (3k, 6); the
basis T of :func:`held_rigid_basis` writes u = T u_t with u_b = R_b r per patch, so that K_t = T^T K T and
M_t = T^T M T are the full model with the patches held rigid, as the reduction holds them.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from flexgear.fe.fem import rigid_body_modes

__all__ = ["RIGID_PATCH_TOL", "held_rigid_basis", "rigid_interfaces"]

RIGID_PATCH_TOL = 1e-9
"""An interface is a rigid patch of a reduced body when every mode's shape on its nodes lies in their rigid motions'
span to this share of its norm (a rigid patch's modes do to round-off, 1e-15; an RBE3 interface's by far not)."""


def _rigid_complement(points: np.ndarray) -> np.ndarray:
    """(3k, 3k - 6): an orthonormal basis of the motions of the ``points`` (k, 3) that are not rigid."""
    q = np.linalg.qr(rigid_body_modes(points), mode="complete")[0]
    return q[:, 6:]


def rigid_interfaces(reduced) -> list:
    """The interfaces of ``reduced`` (flexgear.fe.cms.ReducedBody) that move as rigid patches in every mode
    (:data:`RIGID_PATCH_TOL`)."""
    shapes = reduced.modes.reshape(len(reduced.nodes), 3, -1)
    out = []
    for itf in reduced.interfaces:
        on = shapes[itf.nodes].reshape(3 * len(itf.nodes), -1)
        free = _rigid_complement(reduced.nodes[itf.nodes])
        if np.linalg.norm(free.T @ on) <= RIGID_PATCH_TOL * np.linalg.norm(on):
            out.append(itf)
    return out


def held_rigid_basis(nodes: np.ndarray, patches: tuple[np.ndarray, ...]) -> sp.csr_matrix:
    """T (3n, 3n - 3 sum k_b + 6 p): the coordinates of every node outside the ``patches`` (node index arrays of
    ``nodes`` (n, 3), disjoint) as they are, in order, then six rigid motions r per patch, u_b = R_b r (translations
    and rotations about the nodes' mean, flexgear.fe.fem.rigid_body_modes, so that a rigid motion R of the whole
    body is T [R_outside; I_6; ...])."""
    n = 3 * len(nodes)
    held = np.concatenate([(3 * np.asarray(b)[:, None] + np.arange(3)).ravel() for b in patches])
    keep = np.setdiff1d(np.arange(n), held)
    rows, cols, vals = [keep], [np.arange(len(keep))], [np.ones(len(keep))]
    centre = nodes.mean(axis=0)
    for j, b in enumerate(patches):
        dofs = (3 * np.asarray(b)[:, None] + np.arange(3)).ravel()
        modes = rigid_body_modes(nodes[b], centre)
        rows.append(np.repeat(dofs, 6))
        cols.append(np.tile(len(keep) + 6 * j + np.arange(6), len(dofs)))
        vals.append(modes.ravel())
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n, len(keep) + 6 * len(patches)))
