"""The planetary stage's linear model in the carrier's axes, where its coefficients do not change as it turns.

The planets of the planetary stage orbit with the carrier, so equations linearised in ground axes change with the
carrier angle: each mesh's line of action and each planet's position turn with it. In axes that turn with the
nominal carrier angle theta_c = Omega_c t they are constant (Lin & Parker 1999, J. Sound Vib. 226(5), eq. 1-11:
the planetary model in the rotating carrier frame). Every body frame's in-plane translation (u_x, u_y) and tilt
(phi_x, phi_y) are written in those axes, q = T(theta_c) q~, T the rotation by theta_c on each pair and the identity
on every other coordinate (axial motion, spins, elastic and massless coordinates). With the quarter turn J on the
same pairs and Omega_c constant,

    q' = T (q~' + Omega_c J q~),    q'' = T (q~'' + 2 Omega_c J q~' + Omega_c^2 J^2 q~),

so that M q'' + D q' + K q = C^T lambda (ground axes, at the instant theta_c) becomes

    M~ = T^T M T,    D~ = T^T D T + 2 Omega_c M~ J,    K~ = T^T K T + Omega_c (T^T D T) J + Omega_c^2 M~ J^2,
    C~ = C T:

the Coriolis terms (2 Omega_c m J on a translation pair: skew), the centripetal softening (Omega_c^2 m J^2 =
-Omega_c^2 m), and the damping of the bearings to ground turned into a circulatory stiffness (Omega_c D J), as
Lin & Parker's rotating-frame equations have them. The constraint rows (mesh kinematics, bearings on the carrier's
pins) are constant in q~, so the exact elimination of flexgear.modal.linear holds at every instant.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["frame_pairs", "orbit", "to_carrier_frame"]


def frame_pairs(mbs, model) -> list[tuple[int, int]]:
    """The system coordinates of every body frame's (u_x, u_y) and (phi_x, phi_y) pairs of the built ``model``
    (flexgear.mbs.gearbox.GearboxModel), those of the flexible planets' seat nodes on the carrier and those of the
    carrier's pins' nodes."""
    out = []
    nodes = [*(b.node for b in model.bodies.values()), *model.carrier_seat_nodes.values(),
             *model.carrier_pin_nodes.values()]
    for node in nodes:
        start = mbs.GetNodeODE2Index(node)
        out += [(start, start + 1), (start + 3, start + 4)]
    return out


def orbit(position: np.ndarray, theta_c: float, omega_c: float) -> tuple[np.ndarray, np.ndarray]:
    """(displacement (2,) [m], velocity (2,) [m/s]) of a frame whose reference ``position`` [m] (x, y) turns with
    the carrier to the angle ``theta_c`` [rad] at the rate ``omega_c`` [rad/s]."""
    c, s = math.cos(theta_c), math.sin(theta_c)
    p = np.asarray(position, float)[:2]
    turned = np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])
    return turned - p, omega_c * np.array([-turned[1], turned[0]])


def to_carrier_frame(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray, constraint: np.ndarray,
                     pairs: list[tuple[int, int]], theta_c: float, omega_c: float
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(M~, D~, K~, C~) of the module docstring from the ground-axes ``mass``, ``damping`` (the whole velocity
    matrix, gyroscopic terms included), ``stiffness`` (n, n) and ``constraint`` (m, n) linearised at the carrier
    angle ``theta_c`` [rad], the carrier turning at ``omega_c`` [rad/s]; ``pairs``: the coordinates (x, y) of each
    pair that turns with the carrier."""
    n = mass.shape[0]
    t = np.eye(n)
    quarter = np.zeros((n, n))
    c, s = math.cos(theta_c), math.sin(theta_c)
    for i, j in pairs:
        t[np.ix_((i, j), (i, j))] = [[c, -s], [s, c]]
        quarter[np.ix_((i, j), (i, j))] = [[0.0, -1.0], [1.0, 0.0]]
    m = t.T @ mass @ t
    d = t.T @ damping @ t
    k = t.T @ stiffness @ t + omega_c * d @ quarter + omega_c**2 * m @ quarter @ quarter
    d = d + 2.0 * omega_c * m @ quarter
    return m, d, k, constraint @ t if constraint.size else constraint
