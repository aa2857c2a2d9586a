"""Compiled (numba) kernels for per-step work that cannot be an Exudyn symbolic function.

The home of the per-step laws that both the multibody kernels (:func:`mesh_step`, :func:`mesh_friction_forces`,
:func:`periodic_values`) and the lumped model's right-hand side (flexgear.lumped.run) evaluate: the normal laws
(:func:`impact_normal_force`, :func:`linear_normal_force`, :func:`backlash_linear_force`), the mesh-stiffness and
contact-line Fourier series (:func:`series_value`) and tooth friction (:func:`tooth_friction`). numba compiles a
call of one njit function from another into the caller, so a kernel pays nothing for calling them. The numpy forms
in flexgear.laws.contact and flexgear.geometry.contact_lines.PeriodicSeries are the tests' references
(tests/test_contact_laws.py).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["impact_normal_force", "linear_normal_force", "backlash_linear_force", "series_value", "tooth_friction",
           "mesh_friction_forces", "periodic_values", "ramp_state", "interpolated_columns", "grid_position",
           "turn_columns", "mesh_step", "bound_entry", "padded_sparse_rows"]

TANH_SATURATION = 19.1
"""|x| beyond which tanh(x) rounds to +-1 in double precision (1 - tanh(19.1) = 5e-17 < 2^-54)."""


@njit(cache=True)
def impact_normal_force(delta: float, delta_t: float, stiffness: float, exponent: float, damping_max: float,
                        depth: float) -> float:  # pragma: no cover - compiled
    """Compiled twin of ``flexgear.laws.contact.impact_force`` [N] (stiffness already times s(phi))."""
    pen = max(delta, 0.0)
    ramp = min(pen / depth, 1.0)
    return max(stiffness * pen**exponent + damping_max * ramp * ramp * (3.0 - 2.0 * ramp) * delta_t, 0.0)


@njit(cache=True)
def linear_normal_force(delta: float, delta_t: float, stiffness: float, damping: float) -> float:  # pragma: no cover
    """Compiled twin of ``flexgear.laws.contact.linear_force`` [N] (stiffness already times s(phi))."""
    if delta <= 0.0:
        return 0.0
    return max(stiffness * delta + damping * delta_t, 0.0)


@njit(cache=True)
def backlash_linear_force(delta: float, delta_t: float, stiffness: float, damping: float,
                          backlash: float) -> float:  # pragma: no cover - compiled
    """Compiled twin of ``flexgear.laws.contact.backlash_linear_force`` [N]."""
    if delta > 0.0:
        return stiffness * delta + damping * delta_t
    if delta < -backlash:
        return stiffness * (delta + backlash) + damping * delta_t
    return 0.0


@njit(cache=True)
def series_value(coeffs, cos_x: float, sin_x: float) -> float:  # pragma: no cover - compiled
    """Value of a truncated Fourier series, f = a_0 + sum_(n=1..H) (a_n cos(n x) + b_n sin(n x)), at the angle x
    given by its cosine and sine (x = 2 pi phi for the mesh phase phi in cycles).

    ``coeffs`` = (a_0, a_1 .. a_H, b_1 .. b_H) (flexgear.geometry.contact_lines.PeriodicSeries.packed): the
    mesh-stiffness factor s(phi) of eq. 11-12 and the contact-line friction series kappa(phi), lambda(phi)
    (flexgear.geometry.contact_lines.contact_line_series).
    cos(n x), sin(n x) by the angle-addition recurrence from cos x, sin x: no further trigonometric call.
    """
    n_h = (coeffs.size - 1) // 2
    value = coeffs[0]
    ch, sh = cos_x, sin_x  # cos, sin of h x
    for h in range(1, n_h + 1):
        value += coeffs[h] * ch + coeffs[n_h + h] * sh
        ch, sh = ch * cos_x - sh * sin_x, sh * cos_x + ch * sin_x
    return value


@njit(cache=True)
def tooth_friction(mu: float, normal: float, slip: float) -> float:  # pragma: no cover - compiled
    """Regularised Coulomb tooth friction [N]: f = mu F tanh(slip), slip = v_slide / v_reg (the sliding speed
    over the regularisation speed, signed: the running direction). tanh is not called where it rounds to +-1
    (|slip| > :data:`TANH_SATURATION`): the same number, cheaper at speed."""
    if slip > TANH_SATURATION:
        sign = 1.0
    elif slip < -TANH_SATURATION:
        sign = -1.0
    else:
        sign = math.tanh(slip)
    return mu * normal * sign


@njit(cache=True)
def mesh_friction_forces(phase, delta, delta_t, q_t, stiffness, exponent, damping_max, depth,  # noqa: PLR0913
                         series, mu, reg, sliding_rows, spin_rows, linear=False):  # pragma: no cover
    """Generalized friction forces Q = -(A^T f_slide + B^T f_spin) of all contacts.

    Per contact i at the mesh phase ``phase[i]`` [cycles]: the normal force :func:`impact_normal_force`
    (``linear``: :func:`linear_normal_force`) with the stiffness times s(phi), the series ``series[k, i]``
    (:func:`series_value`; k = 0: stiffness factor s, 1: sliding direction kappa, 2: lever lambda [m]) and the
    friction f = :func:`tooth_friction` (mu, F, Omega lambda_mean / v_reg) acting as f kappa on the sliding row
    ``sliding_rows[i]`` and f lambda on the relative-spin row ``spin_rows[i]`` (dense, (n_contacts, n_q)).
    """
    n_c, n_q = phase.shape[0], sliding_rows.shape[1]
    q = np.zeros(n_q)
    for i in range(n_c):  # explicit loops: no temporary arrays per contact (a per-step hot path)
        x = 2.0 * math.pi * phase[i]
        c1, s1 = math.cos(x), math.sin(x)
        factor = series_value(series[0, i], c1, s1)
        sliding, lever = series_value(series[1, i], c1, s1), series_value(series[2, i], c1, s1)
        if linear:
            normal = linear_normal_force(delta[i], delta_t[i], stiffness[i] * factor, damping_max[i])
        else:
            normal = impact_normal_force(delta[i], delta_t[i], stiffness[i] * factor, exponent[i], damping_max[i],
                                         depth[i])
        spin_rate = 0.0
        for j in range(n_q):
            spin_rate += spin_rows[i, j] * q_t[j]
        f = tooth_friction(mu[i], normal, spin_rate * series[2, i, 0] / reg[i])
        for j in range(n_q):
            q[j] -= sliding_rows[i, j] * (f * sliding) + spin_rows[i, j] * (f * lever)
    return q


@njit(cache=True)
def periodic_values(phase, series):  # pragma: no cover - compiled
    """:func:`series_value` of each contact's series ``series[i]``
    (flexgear.geometry.contact_lines.PeriodicSeries.packed) at its mesh phase ``phase[i]`` [cycles]."""
    out = np.empty(phase.shape[0])
    for i in range(phase.shape[0]):
        x = 2.0 * math.pi * phase[i]
        out[i] = series_value(series[i], math.cos(x), math.sin(x))
    return out


@njit(cache=True)
def ramp_state(t: float, T: float) -> tuple[float, float, float, float]:
    """Integral of STEP(t, 0, 0, T, 1) [s], STEP itself and its first two derivatives [1/s, 1/s^2].

    Compiled twin of ``flexgear.laws.ramps.step_integral`` / ``ramp_fraction``.
    """
    if t <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    if t >= T:
        return t - 0.5 * T, 1.0, 0.0, 0.0
    d = t / T
    return T * (d**3 - 0.5 * d**4), d * d * (3.0 - 2.0 * d), 6.0 * d * (1.0 - d) / T, (6.0 - 12.0 * d) / T**2


@njit(cache=True)
def interpolated_columns(matrix, theta, tables, rows, first, n_modes, signs, psi, spin):  # pragma: no cover
    """Write each column set's coefficients at spin angle ``theta`` [rad] into ``matrix`` (in place).

    Compiled twin of flexgear.mbs.contact_kinematics.ContactKinematics.reference_matrix_at: set j's
    coefficients c(alpha) at alpha = psi_j - spin_j theta, linearly interpolated on the periodic grid
    ``tables[j]`` (n_grid, width), times signs_j, go to row rows_j, columns first_j .. first_j + n_modes_j.
    """
    for j in range(rows.shape[0]):
        i0, i1, w = grid_position(psi[j] - spin[j] * theta, tables.shape[1])
        for m in range(n_modes[j]):
            matrix[rows[j], first[j] + m] = signs[j] * ((1.0 - w) * tables[j, i0, m] + w * tables[j, i1, m])


@njit(cache=True)
def grid_position(alpha, n_grid):  # pragma: no cover - compiled
    """Where angle ``alpha`` [rad] falls on a periodic grid of ``n_grid`` equal steps over one turn: the two
    neighbouring grid indices and the linear-interpolation weight of the second."""
    a = (alpha % (2.0 * math.pi)) * (n_grid / (2.0 * math.pi))
    fl = math.floor(a)
    i0 = int(fl) % n_grid
    return i0, (i0 + 1) % n_grid, a - fl


@njit(cache=True)
def turn_columns(buffer, const, cos_part, sin_part, spin_index, spins, target, theta):  # pragma: no cover - compiled
    """Write const[:, j] + cos(a_j) cos_part[:, j] + sin(a_j) sin_part[:, j], a_j = spins[spin_index[j]] theta, into
    ``buffer[target[:, j]]`` for every column j: coefficients that turn with a spin angle (``theta`` [rad]).

    ``const``, ``cos_part``, ``sin_part`` (6, W); the few distinct spins per drive angle ``spins`` give one
    cosine and sine each; ``target`` (6, W) places every entry in the flat ``buffer`` (each constraint's block
    contiguous there). Compiled twin of flexgear.mbs.joints.TurningBlocks.turned.
    """
    cos_a = np.empty(spins.size)
    sin_a = np.empty(spins.size)
    for k in range(spins.size):
        cos_a[k] = math.cos(spins[k] * theta)
        sin_a[k] = math.sin(spins[k] * theta)
    for j in range(const.shape[1]):
        c = cos_a[spin_index[j]]
        s = sin_a[spin_index[j]]
        for r in range(const.shape[0]):
            buffer[target[r, j]] = const[r, j] + c * cos_part[r, j] + s * sin_part[r, j]


@njit(cache=True)
def mesh_step(t, ramp_time, drive_speed, q, q_t, index, frames, law, series, columns, rows,  # noqa: PLR0913
              factor_rows, out, linear=False):  # pragma: no cover - compiled
    """One step's mesh updates in one call, without temporaries: the friction forces on the frame coordinates
    (written into ``out[:frames.size]``) and the stiffness factors s(phi) of the contacts ``factor_rows``
    (written into ``out[frames.size:frames.size + factor_rows.size]``; the rest of ``out``, four entries per
    contact, is work space).

    Per contact i: phi = rate theta(t) - offset with the drive angle theta = drive_speed x integral of STEP
    (:func:`ramp_state`); ``law[:, i]``: stiffness, exponent, damping_max, penetration depth, mu, v_reg, rate,
    offset; ``series[k, i]``: series k (flexgear.geometry.contact_lines.PeriodicSeries.packed; 0: stiffness factor,
    1: sliding direction kappa, 2: lever lambda [m]), evaluated by :func:`series_value`; friction by
    :func:`tooth_friction`. ``q``, ``q_t``: all ODE2 coordinates and rates (read
    only); the contact's tooth deflection is q[index[0, i]] less q[index[1, i]] when index[1, i] >= 0 (its
    residual deflection, flexgear.mbs.residual). Contact i takes its series values and its friction slip
    Omega lambda_mean / v_reg from contact index[2, i] <= i (the first of the contacts that share
    phase, series, spin row and v_reg, such as the helix halves of one mesh), which computes them once.
    ``frames``: the bodies' frame coordinates. The sliding and spin rows of contact i are sparse (each touches
    the 12 frame coordinates of its two gears): ``rows[0, i, k]`` and ``rows[1, i, k]`` are their entries at
    frame coordinate ``columns[i, k]`` (:func:`padded_sparse_rows`). Same numbers as :func:`periodic_values`
    plus :func:`mesh_friction_forces` with the dense rows.
    """
    theta = drive_speed * ramp_state(t, ramp_time)[0]
    n_c, n_f = law.shape[1], frames.size
    w = n_f + factor_rows.size  # work: v0, v1, v2 and the friction slip of contact i at w + 4 i
    for j in range(n_f):
        out[j] = 0.0
    for i in range(n_c):
        lead = w + 4 * index[2, i]
        if index[2, i] == i:
            x = 2.0 * math.pi * (law[6, i] * theta - law[7, i])
            c1, s1 = math.cos(x), math.sin(x)
            spin_rate = 0.0
            for k in range(columns.shape[1]):
                spin_rate += rows[1, i, k] * q_t[frames[columns[i, k]]]
            out[lead] = series_value(series[0, i], c1, s1)
            out[lead + 1] = series_value(series[1, i], c1, s1)
            out[lead + 2] = series_value(series[2, i], c1, s1)
            out[lead + 3] = spin_rate * series[2, i, 0] / law[5, i]
        v0, v1, v2, slip = out[lead], out[lead + 1], out[lead + 2], out[lead + 3]
        d, d_t = q[index[0, i]], q_t[index[0, i]]
        if index[1, i] >= 0:
            d -= q[index[1, i]]
            d_t -= q_t[index[1, i]]
        if linear:
            normal = linear_normal_force(d, d_t, law[0, i] * v0, law[2, i])
        else:
            normal = impact_normal_force(d, d_t, law[0, i] * v0, law[1, i], law[2, i], law[3, i])
        f = tooth_friction(law[4, i], normal, slip)
        for k in range(columns.shape[1]):
            out[columns[i, k]] -= rows[0, i, k] * (f * v1) + rows[1, i, k] * (f * v2)
    for k in range(factor_rows.size):
        out[n_f + k] = out[w + 4 * factor_rows[k]]


def bound_entry(kernel, args: tuple):
    """``kernel``'s compiled entry point for the types of ``args``, for a hot loop that calls it with arguments of
    exactly those types (numba's dispatcher resolves every argument's type on every call, about 60-80 ns each:
    half of mesh_step's call). Falls back to the dispatcher itself where numba offers no entry point."""
    import numba

    try:
        return kernel.compile(tuple(numba.typeof(a) for a in args))
    except (AttributeError, TypeError):
        return kernel


def padded_sparse_rows(*rows: np.ndarray) -> tuple[np.ndarray, ...]:
    """The kernels' layout of sparse rows: for (n, m) matrices ``rows`` of one pattern, the union of each row's
    nonzero columns, padded (column 0, value 0: a padded entry adds exactly nothing) to equal width, and each
    matrix's entries there. Returns ``columns`` (n, w) int64 and one (n, w) array per matrix."""
    nonzero = np.any([r != 0.0 for r in rows], axis=0)
    width = max(1, int(nonzero.sum(axis=1).max()))
    columns = np.zeros((nonzero.shape[0], width), dtype=np.int64)
    values = [np.zeros((nonzero.shape[0], width)) for _ in rows]
    for i, row in enumerate(nonzero):
        cols = np.flatnonzero(row)
        columns[i, :cols.size] = cols
        for v, r in zip(values, rows, strict=True):
            v[i, :cols.size] = r[i, cols]
    return (columns, *values)
