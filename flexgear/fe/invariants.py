"""Floating-frame invariants of a reduced flexible body (the constant terms of Exudyn's ObjectFFRFreducedOrder).

Split from flexgear.fe.cms (the reduction), which re-exports :func:`ffrf_invariants`.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["EPS", "ffrf_invariants"]

EPS = np.zeros((3, 3, 3))
"""The Levi-Civita symbol eps_ijk."""
EPS[0, 1, 2] = EPS[1, 2, 0] = EPS[2, 0, 1] = 1.0
EPS[0, 2, 1] = EPS[2, 1, 0] = EPS[1, 0, 2] = -1.0


def ffrf_invariants(mass_scalar: sp.spmatrix, nodes: np.ndarray, modes: np.ndarray) -> dict[str, np.ndarray]:
    """Constant terms of the floating-frame equations (names as in Exudyn's ObjectFFRFreducedOrder).

    With Phi_t = 1 (x) I_3, xRef, Psi (3n, m) and skew stacks xRefTilde, PsiTilde:
    mass = 1^T M_s 1, centerOfMass = X^T M_s 1 / mass, inertia = xRefTilde^T M xRefTilde (about the
    frame origin), mPsiTildePsi = PsiTilde^T M Psi, mPsiTildePsiTilde, mPhitTPsi, mPhitTPsiTilde,
    mXRefTildePsi, mXRefTildePsiTilde, all evaluated through M_s only.
    """
    n, m = len(nodes), modes.shape[1]
    xm = modes.reshape(n, 3, m).transpose(0, 2, 1).reshape(n, 3 * m)  # column 3j+c: component c of mode j
    ms_x = mass_scalar @ xm
    gmat = (xm.T @ ms_x).reshape(m, 3, m, 3)  # G[j, c, l, d]
    ones = mass_scalar @ np.ones(n)
    mass = float(ones.sum())
    q = nodes.T @ (mass_scalar @ nodes)
    hmat = (nodes.T @ ms_x).reshape(3, m, 3)  # H[c, l, d] = sum M_ik x_i^c psi_l^d(k)
    phit_psi = (ones @ xm).reshape(m, 3).T  # (3, m)
    psi_tilde_psi = -np.einsum("ecd,jcld->jel", EPS, gmat).reshape(3 * m, m)
    g_blocks = gmat.transpose(0, 2, 1, 3)  # (j, l, c, d)
    trace = np.trace(g_blocks, axis1=2, axis2=3)
    psi_tilde_psi_tilde = (trace[:, :, None, None] * np.eye(3) - g_blocks.transpose(0, 1, 3, 2))
    psi_tilde_psi_tilde = psi_tilde_psi_tilde.transpose(0, 2, 1, 3).reshape(3 * m, 3 * m)

    def skew(v: np.ndarray) -> np.ndarray:
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    phit_psi_tilde = np.hstack([skew(phit_psi[:, j]) for j in range(m)]) if m else np.zeros((3, 0))
    xref_tilde_psi = -np.einsum("ecd,cld->el", EPS, hmat)
    h_blocks = hmat.transpose(1, 0, 2)  # (l, c, d)
    xref_tilde_psi_tilde = np.hstack([np.trace(h) * np.eye(3) - h.T for h in h_blocks]) if m else np.zeros((3, 0))
    return {"mass": np.array(mass), "centerOfMass": nodes.T @ ones / mass,
            "inertia": np.trace(q) * np.eye(3) - q,
            "mPsiTildePsi": psi_tilde_psi, "mPsiTildePsiTilde": psi_tilde_psi_tilde,
            "mPhitTPsi": phit_psi, "mPhitTPsiTilde": phit_psi_tilde,
            "mXRefTildePsi": xref_tilde_psi, "mXRefTildePsiTilde": xref_tilde_psi_tilde}
