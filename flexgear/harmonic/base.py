"""The frequency-domain problem shared by the multibody and the lumped harmonic response: the results object, the
linear problem at one speed and its solve over a speed grid, the mesh frequency and the excited spec (the
excitation and the outputs are described in :mod:`flexgear.harmonic.response`)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pandas as pd

from flexgear.theory import mesh_frequency_hz

__all__ = ["Response", "mesh_frequency_hz", "INDICATOR_UNITS", "DEFAULT_HARMONICS", "RPM", "ACCEL_INDICATORS",
           "excitation", "Operating", "mesh_force_name", "sweep_speeds", "excited_spec", "series_coefficients",
           "parametric_matrix", "parametric_forces"]

DEFAULT_HARMONICS = 10
"""Mesh harmonics h = 1..H of the excitation and response."""

RPM = 2.0 * math.pi / 60.0  # rad/s per rpm

INDICATOR_UNITS = {"mesh_force": "N", "bearing_accel": "m/s^2", "transmission_error": "m", "dynamic_factor": "-"}
"""Unit of each family of indicators (by a part of the name)."""

_TABLE_COLUMNS = ["speed_rpm", "harmonic", "frequency_hz", "indicator", "amplitude", "phase"]


def _unit(indicator: str) -> str:
    return next((u for key, u in INDICATOR_UNITS.items() if key in indicator), "")


@dataclass
class Response:
    """Harmonic response over a speed grid (module docstring).

    ``table``: one row per speed, harmonic and indicator: speed_rpm, harmonic (0 for sums over harmonics),
    frequency_hz (h f_mesh), indicator, amplitude (SI units of the indicator), phase [rad]. ``static_forces_n``:
    static normal force of each mesh [N]; ``mesh_frequency_hz_per_rpm``: f_mesh per input rpm [Hz/rpm];
    ``wall_time_s``: time spent (linearisation and solves).
    """

    table: pd.DataFrame
    model: str
    static_forces_n: dict[str, float] = field(default_factory=dict)
    mesh_frequency_hz_per_rpm: float = 0.0
    wall_time_s: float = 0.0

    @property
    def indicators(self) -> list[str]:
        return list(dict.fromkeys(self.table["indicator"]))

    @property
    def speeds_rpm(self) -> np.ndarray:
        return np.unique(self.table["speed_rpm"].to_numpy())

    def amplitudes(self, indicator: str) -> pd.DataFrame:
        """Amplitude of ``indicator``: one row per speed [rpm], one column per harmonic."""
        sel = self.table[self.table["indicator"] == indicator]
        if sel.empty:
            raise KeyError(f"no indicator {indicator!r}; known: {', '.join(self.indicators)}")
        return sel.pivot(index="speed_rpm", columns="harmonic", values="amplitude")

    def complex(self, indicator: str) -> pd.DataFrame:
        """Complex amplitude (amplitude e^{i phase}) of ``indicator``: rows speeds, columns harmonics."""
        sel = self.table[self.table["indicator"] == indicator]
        values = sel["amplitude"].to_numpy() * np.exp(1j * sel["phase"].to_numpy())
        return pd.DataFrame({"speed_rpm": sel["speed_rpm"].to_numpy(), "harmonic": sel["harmonic"].to_numpy(),
                             "value": values}).pivot(index="speed_rpm", columns="harmonic", values="value")

    def dynamic_factor(self) -> pd.Series:
        """K_v per speed [rpm] (module docstring)."""
        return self.amplitudes("dynamic_factor")[0]

    def plot(self, ax: Any, indicator: str, harmonics: Sequence[int] | None = None) -> Any:
        """Amplitude of ``indicator`` over the speed [rpm], one line per harmonic (``harmonics``: which, default
        all; K_v one line); a mesh-frequency axis on top. Returns ``ax``."""
        amp = self.amplitudes(indicator)
        cols = [h for h in amp.columns if harmonics is None or h in harmonics]
        for h in cols:
            ax.plot(amp.index, amp[h], lw=1.0, label="sum" if h == 0 else f"{h}x mesh")
        unit = _unit(indicator)
        ax.set_xlabel("input speed [rpm]")
        ax.set_ylabel(f"{indicator} [{unit}]" if unit else indicator)
        ax.set_title(f"{self.model}: {indicator}")
        if indicator != "dynamic_factor":
            ax.set_yscale("log")
        if len(cols) > 1:
            ax.legend(fontsize="small", ncol=2)
        if self.mesh_frequency_hz_per_rpm > 0.0:
            k = self.mesh_frequency_hz_per_rpm
            top = ax.secondary_xaxis("top", functions=(lambda n: n * k, lambda f: f / k))
            top.set_xlabel("mesh frequency f_mesh [Hz]")
        ax.grid(True, alpha=0.3)
        return ax


# --------------------------------------------------------------------------- the linear problem at one speed
@dataclass
class Operating:
    """The linearised model at one speed, with its excitation and outputs (all SI).

    ``rows`` (n_c, n): contact deflection per coordinate; ``k_t``, ``c``, ``f0`` (n_c,): tangent stiffness,
    damping, static force; ``coef`` (n_c, H): complex Fourier coefficient of s - 1 at +h f_mesh; ``mesh`` (n_c,):
    index of each contact's mesh in ``mesh_names``; ``accel`` (4, n): input x, y and output x, y translation
    per coordinate; ``te`` (n,): transmission error per coordinate; ``omega_mesh`` [rad/s]; ``solver``: None
    (a dense complex solve of the full matrices) or a callable (omegas (H,) [rad/s], c (H, n_c)) -> X (H, n)
    solving the same problem for the force rows^T c_h (flexgear.harmonic.reduced.ModalSolver.solve), or, with
    friction, for [rows; friction_rows]^T [c_h; -friction_h]. ``friction_rows`` (n_r, n), ``friction``
    (n_r, H) complex [N, N m]: the tooth-friction excitation -friction_rows^T friction_h (flexgear.harmonic.friction:
    the sliding and relative-spin rows of the n_c contacts, n_r = 2 n_c; flexgear.harmonic.lumped_friction: the
    translation and two spin rows of the lumped meshes, n_r = 3 n_m); None: no friction.
    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    rows: np.ndarray
    k_t: np.ndarray
    c: np.ndarray
    f0: np.ndarray
    coef: np.ndarray
    mesh: np.ndarray
    mesh_names: tuple[str, ...]
    accel: np.ndarray
    te: np.ndarray
    omega_mesh: float
    solver: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
    friction_rows: np.ndarray | None = None
    friction: np.ndarray | None = None


ACCEL_INDICATORS = tuple(f"{s}_bearing_accel_{a}_m_per_s2" for s in ("input", "output") for a in ("x", "y"))
"""The bearing accelerations, in the order of the rows of ``Operating.accel`` (q'' of each is accel[k] @ z'')."""


def excitation(op: Operating, harmonics: int) -> tuple[np.ndarray, np.ndarray]:
    """The excitation at mesh harmonics h = 1..``harmonics`` (flexgear.harmonic.response): (F_h = F_0 C_h of every
    contact (n_c, H) [N], the generalised forces f_h = -g^T F_h - a^T S_h - b^T L_h summed over the contacts (H, n)
    [N or N m per coordinate], the friction terms where ``op.friction`` is set, flexgear.harmonic.friction); the time
    force is Re sum_h f_h e^{i 2 pi h phi} for the mesh phase phi [cycles]."""
    excite = op.f0[:, None] * op.coef[:, :harmonics]  # (n_c, H): F_0 C_h
    force = -(op.rows.T @ excite).T  # (H, n): generalised force -g F_h
    if op.friction is not None:
        force = force - (op.friction_rows.T @ op.friction[:, :harmonics]).T
    return excite, force


def parametric_matrix(coef: np.ndarray, k_t: np.ndarray) -> np.ndarray:
    """The real matrix L ((2 H + 1) n_c, (2 H + 1) n_c) of the contacts' parametric forces P = L D (Hill's method).

    With s - 1 = Re sum_k C_k e^{i k phi} and delta~ = D_0 + Re sum_j D_j e^{i j phi} (harmonics 1..H, phi the mesh
    phase [rad]; D_0 the shift of the mean deflection), the force k_t (s - 1) delta~ has the mean and harmonics

        P_0 = k_t / 2 sum_k Re(C_k conj(D_k)),
        P_h = k_t [C_h D_0 + 1/2 (sum_{k + j = h} C_k D_j + sum_{k - j = h} C_k conj(D_j)
                                  + sum_{j - k = h} conj(C_k) D_j)]

    (the harmonics above H left out: the truncation). ``coef`` (n_c, H): C_k of each contact; ``k_t`` (n_c,).
    Unknowns and results stacked as [D_0, Re D_1..D_H, Im D_1..D_H], each block harmonic-major over the contacts.
    P is real-linear in D (the conjugates), so L acts on real and imaginary parts apart."""
    n_c, n_h = coef.shape
    size = n_h * n_c
    out = np.zeros((n_c + 2 * size, n_c + 2 * size))

    def re(h: int) -> slice:
        return slice(n_c + (h - 1) * n_c, n_c + h * n_c)

    def im(h: int) -> slice:
        return slice(n_c + size + (h - 1) * n_c, n_c + size + h * n_c)

    def put(h: int, j: int, factor: np.ndarray, conj: bool) -> None:
        """P_h += factor * (D_j or conj(D_j)), factor (n_c,) complex: its 2 x 2 real blocks per contact."""
        a, b = np.diag(factor.real), np.diag(factor.imag)
        sign = -1.0 if conj else 1.0  # conj(D) = Re D - i Im D
        out[re(h), re(j)] += a
        out[re(h), im(j)] -= sign * b
        out[im(h), re(j)] += b
        out[im(h), im(j)] += sign * a

    mean = slice(0, n_c)
    for h in range(1, n_h + 1):
        c = coef[:, h - 1]
        out[mean, re(h)] += np.diag(0.5 * k_t * c.real)
        out[mean, im(h)] += np.diag(0.5 * k_t * c.imag)
        out[re(h), mean] += np.diag(k_t * c.real)
        out[im(h), mean] += np.diag(k_t * c.imag)
        for k in range(1, n_h + 1):
            c = 0.5 * k_t * coef[:, k - 1]
            if 1 <= h - k <= n_h:
                put(h, h - k, c, False)
            if 1 <= k - h <= n_h:
                put(h, k - h, c, True)
            if 1 <= h + k <= n_h:
                put(h, h + k, np.conj(c), False)
    return out


def parametric_forces(op: Operating, harmonics: int | None = None) -> np.ndarray:
    """The contacts' parametric forces P_h (H, n_c) [N] at one speed, harmonics 1..``harmonics`` (default all of
    ``op.coef``): the harmonics of k_t (s - 1) delta~ in the coupled solution (:func:`_coupled`)."""
    return _response(op, op.coef.shape[1] if harmonics is None else harmonics)[1]


HILL_HARMONICS_FACTOR = 2
"""The coupled solution carries this many times the harmonics asked, the extra ones as unknowns only (no
excitation): the products of the stiffness's and the deflection's harmonics reach up to their sum, and a
truncation at the harmonics asked would distort the highest of them."""


def _response(op: Operating, harmonics: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(X (H, n), P (H, n_c), F_0 C_h (n_c, H), omegas (H,) [rad/s]) at one speed, harmonics 1..``harmonics``
    (:func:`_coupled` over :data:`HILL_HARMONICS_FACTOR` times as many)."""
    total = HILL_HARMONICS_FACTOR * harmonics
    coef = np.zeros((op.coef.shape[0], total), complex)
    coef[:, :min(harmonics, op.coef.shape[1])] = op.coef[:, :harmonics]
    friction = None
    if op.friction is not None:
        friction = np.zeros((op.friction.shape[0], total), complex)
        friction[:, :min(harmonics, op.friction.shape[1])] = op.friction[:, :harmonics]
    x, p, excite, w = _coupled(replace(op, coef=coef, friction=friction), total)
    return x[:harmonics], p[:harmonics], excite[:, :harmonics], w[:harmonics]


def _coupled(op: Operating, harmonics: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(X (H, n), P (H, n_c), F_0 C_h (n_c, H), omegas (H,) [rad/s]) at one speed, harmonics 1..``harmonics``.

    The stiffness variation acts twice: on the static deflection, the excitation F_0 C_h, and on the dynamic one, the
    parametric force k_t (s - 1) delta~, which couples the harmonics and shifts the mean deflection (Hill's method,
    :func:`parametric_matrix`). Both act through the contacts only, so the coupled problem is solved for the
    contacts' deflections: D = D_1 - G P(D), G_h = g A_h^-1 g^T (n_c, n_c) each harmonic's contact compliance (the
    static one, A_0 = K, for the mean), D_1 the response to the excitation alone; then every coordinate from the
    forces F_0 C_h + P_h. A spur mesh varies its stiffness by tens of percent: without P the 1x and 2x mesh-force
    harmonics came out 23 and 41 % low against time integration."""
    h = np.arange(1, harmonics + 1)
    w = h * op.omega_mesh
    w0 = np.concatenate([[0.0], w])  # the mean, then the harmonics
    n, n_c = op.mass.shape[0], op.rows.shape[0]
    excite, f = excitation(op, harmonics)
    friction = None if op.friction is None else op.friction[:, :harmonics]
    # one factorisation per frequency: the excitation's response x1 and the unit contact forces' (unit, H + 1)
    unit_forces = -np.broadcast_to(np.eye(n_c), (harmonics + 1, n_c, n_c)).astype(complex)
    if op.solver is not None:
        first = (-excite.T if friction is None else np.hstack([-excite.T, -friction.T]))[..., None]
        rest = unit_forces if friction is None else np.concatenate(
            [unit_forces, np.zeros((harmonics + 1, friction.shape[0], n_c), complex)], axis=1)
        both = op.solver(w, np.concatenate([first, rest[1:]], axis=2))  # (H, n, 1 + n_c)
        x1, unit = both[..., 0], np.concatenate([op.solver(w0[:1], rest[:1]), both[..., 1:]])
    else:
        a = (op.stiffness[None] - (w0**2)[:, None, None] * op.mass[None]
             + 1j * w0[:, None, None] * op.damping[None])  # (H + 1, n, n): the mean, then each harmonic
        loads = op.rows.T @ unit_forces  # (H + 1, n, n_c)
        rhs = np.concatenate([np.concatenate([np.zeros((1, n, 1)), f[..., None]]), loads], axis=2)
        both = np.linalg.solve(a, rhs) if n else np.zeros((harmonics + 1, 0, 1 + n_c), complex)
        x1, unit = both[1:, :, 0], both[..., 1:]
    compliance = np.einsum("cn,hnk->hck", op.rows, unit)  # -G_h: contact deflections per unit contact force
    d1 = x1 @ op.rows.T  # (H, n_c)
    lmat = parametric_matrix(op.coef[:, :harmonics], op.k_t)
    size = harmonics * n_c
    gmat = np.zeros_like(lmat)
    gmat[:n_c, :n_c] = compliance[0].real  # the mean: a real static compliance
    for k in range(1, harmonics + 1):  # the complex product -G_h P_h as a real 2 x 2 block matrix
        r = slice(n_c + (k - 1) * n_c, n_c + k * n_c)
        i = slice(n_c + size + (k - 1) * n_c, n_c + size + k * n_c)
        gmat[r, r], gmat[r, i] = compliance[k].real, -compliance[k].imag
        gmat[i, r], gmat[i, i] = compliance[k].imag, compliance[k].real
    rhs = np.concatenate([np.zeros(n_c), d1.real.ravel(), d1.imag.ravel()])
    p_real = lmat @ np.linalg.solve(np.eye(lmat.shape[0]) - gmat @ lmat, rhs)
    p = (p_real[n_c:n_c + size] + 1j * p_real[n_c + size:]).reshape(harmonics, n_c)  # (H, n_c); the mean left
    x = x1 + np.einsum("hnk,hk->hn", unit[1:], p)  # unit holds the response to -g^T e_k: P acts as -g^T P
    return x, p, excite, w


def _solve(op: Operating, harmonics: int) -> dict[str, np.ndarray]:
    """Complex amplitudes (H,) of every indicator at one speed (module docstring; :func:`_response`)."""
    x, p, excite, w = _response(op, harmonics)
    delta = x @ op.rows.T  # (H, n_c)
    contact = (op.k_t[None] + 1j * w[:, None] * op.c[None]) * delta + excite.T + p
    out: dict[str, np.ndarray] = {}
    for m, name in enumerate(op.mesh_names):
        out[name] = contact[:, op.mesh == m].sum(axis=1)
    acc = -(w**2)[:, None] * (x @ op.accel.T)
    for k, name in enumerate(ACCEL_INDICATORS):
        out[name] = acc[:, k]
    out["transmission_error_m"] = x @ op.te
    return out


def mesh_force_name(kind: str, i: int) -> str:
    """Indicator name of the force of mesh ``i`` (1-based planet) of ``kind`` "outer" or "inner"."""
    return f"{kind}_mesh_force_{i}_n"


def sweep_speeds(operating: Callable[[float], Operating], speeds_rpm: Sequence[float], harmonics: int, model: str,
                 per_rpm: float, t0: float) -> Response:
    """Solve every speed and gather the table."""
    if harmonics < 1:
        raise ValueError(f"harmonics: expected >= 1, got {harmonics}")
    speeds = np.asarray(speeds_rpm, float)
    if speeds.ndim != 1 or speeds.size == 0:
        raise ValueError("speeds_rpm: expected a non-empty list of speeds")
    h = np.arange(1, harmonics + 1)
    columns: dict[str, list] = {c: [] for c in _TABLE_COLUMNS}
    static: dict[str, float] = {}

    def put(speed: float, harm: np.ndarray, freq: np.ndarray, name: str, values: np.ndarray) -> None:
        columns["speed_rpm"].append(np.full(harm.size, speed))
        columns["harmonic"].append(harm)
        columns["frequency_hz"].append(freq)
        columns["indicator"].append(np.full(harm.size, name, dtype=object))
        columns["amplitude"].append(np.abs(values))
        columns["phase"].append(np.angle(values))

    for speed in speeds:
        op = operating(float(speed))
        out = _solve(op, harmonics)
        static = {name: float(op.f0[op.mesh == m].sum()) for m, name in enumerate(op.mesh_names)}
        for kind in ("outer", "inner"):  # the largest over the planets, per harmonic
            names = [nm for nm in op.mesh_names if nm.startswith(f"{kind}_")]
            if names:
                stack = np.stack([out[nm] for nm in names])
                out[f"{kind}_mesh_force_max_n"] = stack[np.abs(stack).argmax(axis=0), np.arange(harmonics)]
        freq = h * op.omega_mesh / (2.0 * math.pi)
        for name, values in out.items():
            put(float(speed), h, freq, name, values)
        kv = max(waveform_peak(out[nm], static[nm]) / static[nm] for nm in op.mesh_names)
        put(float(speed), np.zeros(1, int), np.zeros(1), "dynamic_factor", np.array([kv]))
    table = pd.DataFrame({c: np.concatenate(v) for c, v in columns.items()})
    return Response(table, model, static, per_rpm, time.perf_counter() - t0)


WAVEFORM_SAMPLES_PER_HARMONIC = 64
"""Samples of one mesh cycle per harmonic in :func:`waveform_peak`: the highest harmonic's cosine is sampled 64
times per period, its peak found to a relative 1 - cos(pi / 64) ~ 1.2e-3 of its own amplitude."""


def waveform_peak(amplitudes: np.ndarray, mean: float = 0.0) -> float:
    """max over one mesh cycle of mean + Re sum_h X_h e^{i h phi}, phi in [0, 2 pi), for the complex amplitudes
    X_h (H,) of harmonics h = 1..H (sampled, :data:`WAVEFORM_SAMPLES_PER_HARMONIC`)."""
    x = np.asarray(amplitudes, complex)
    h = np.arange(1, x.size + 1)
    phi = np.linspace(0.0, 2.0 * math.pi, WAVEFORM_SAMPLES_PER_HARMONIC * max(x.size, 1), endpoint=False)
    return float(mean + (np.exp(1j * np.outer(phi, h)) @ x).real.max())


def excited_spec(spec: Any, harmonics: int) -> Any:
    """The spec with ``harmonics`` stiffness harmonics from the contact lines (eq. 11-12)."""
    spec = spec.with_fields("contact_assumed", stiffness_harmonics=int(harmonics))
    if spec.contact_assumed.stiffness_variation == "constant":
        spec = spec.with_fields("contact_assumed", stiffness_variation="contact_lines")
    return spec


def series_coefficients(cos_c: np.ndarray, sin_c: np.ndarray, offset_cycles: np.ndarray,
                        rate_sign: np.ndarray) -> np.ndarray:
    """Complex coefficients (n_c, H) at +h f_mesh of s(phi) - 1 = sum_h a_h cos 2 pi h phi + b_h sin 2 pi h phi,
    phi = rate t + offset: (a_h - i b_h) e^{i 2 pi h offset}, conjugated where the phase runs backwards."""
    h = np.arange(1, cos_c.shape[1] + 1)
    c = (cos_c - 1j * sin_c) * np.exp(2j * np.pi * h[None] * offset_cycles[:, None])
    return np.where(rate_sign[:, None] >= 0, c, c.conj())
