"""Steady harmonic response of the star gearbox to the transmission-error excitation, over a speed grid.

Excitation and the stiffness variation's coupling. Each mesh contact carries the time-varying stiffness of
eq. 11-12, k(t) = k_mean s(phi(t)), s(phi) = 1 + sum_h c_h cos(2 pi h (phi - phi_0)), with the mesh phase phi in
mesh cycles advancing at the mesh frequency f_mesh = z_sun (n_in - n_carrier) / 60 [Hz] and each planet's meshes
phased by the planet's position (the models' own phases: flexgear.mbs.gearbox.mesh_contacts,
flexgear.lumped.run.build_lumped_model). About the static operating point under the load torque (deflection
delta_0, force F_0 = F(delta_0) of the contact law, the mean stiffness) the contact force is

    F(t) = F(delta_0 + x_delta) s(phi)  ~  F_0 + k_t x_delta + c x_delta' + F_0 (s(phi) - 1) + k_t (s(phi) - 1) x_delta,

k_t = dF/d delta at delta_0 the tangent stiffness (k_mean for the linear ISO 6336 law, 1.5 k delta_0^0.5 for the
impact law), c the contact damping. The fourth term is the excitation: at harmonic h its complex amplitude is
F_h = F_0 C_h = Delta k_h delta_0 (linear law) with C_h the complex Fourier coefficient of s at +h f_mesh, acting
along the mesh's line of action (the generalised force -g F_h, g = d delta / dz). The last, parametric term couples
the harmonics of the response and shifts its mean deflection; it is kept (Hill's method, flexgear.harmonic.base:
the coupled problem solved for the contacts' deflections over twice the harmonics asked): a spur mesh varies its
stiffness by tens of percent, and the first-order response missed its 1x and 2x mesh-force harmonics by 23 and
41 %. The response stays linear in the deflection: it fails near the parametric instabilities (2 f_n / k = h f_mesh,
combination resonances), where its steady state does not exist, and where the teeth lose contact (|F_dyn|
comparable to F_0: the law's kink is not linearised). Tooth friction, as the
time model applies it (the spec's friction coefficient; none at mu = 0), adds its own first-order excitation: the
Fourier series of its generalised force at the static mesh loads, -(a^T S_h + b^T L_h) on the contacts' sliding and
relative-spin rows (flexgear.harmonic.friction); it does not enter the mesh forces' direct term.

Response at each speed of the grid and each harmonic h = 1..H, omega = 2 pi h f_mesh(speed):

    (-omega^2 M + i omega (D + G) + K) X_h = F_h - g^T P_h,    P_h the parametric force's harmonic

with M, D, G, K the linearised model at that speed (multibody: flexgear.modal.linear.linearize at two speeds and
the exact spin dependence G ~ Omega, K ~ Omega^2 between them, solved on a truncated modal basis with its
residual static part, flexgear.harmonic.reduced; lumped: flexgear.lumped.model.assemble, a dense solve).
Outputs (complex amplitudes of x(t) = Re(X e^{i omega t}); ``amplitude`` = |X|, ``phase`` = arg X [rad], time
origin at mesh phase 0):

- ``outer_mesh_force_<i>_n``, ``inner_mesh_force_<i>_n`` [N]: each mesh's dynamic normal force, the sum over its
  contacts (helix halves) of F_dyn,h = (k_t + i omega c) x_delta,h + F_0 C_h + P_h (the direct stiffness-variation
  terms included: it is what a force sensor in the mesh reads);
- ``outer_mesh_force_max_n``, ``inner_mesh_force_max_n`` [N]: the largest over the planets;
- ``{input,output}_bearing_accel_{x,y}_m_per_s2`` [m/s^2]: -omega^2 X of the frame translation of the member
  carrying the input/output bearing (flexgear.results.signal_columns: the gear-centre frame node);
- ``transmission_error_m`` [m]: dynamic transmission error at the output, TE = -r_b,out theta_out sign(omega_out)
  (flexgear.mbs.deflection.transmission_error: the input is prescribed, so its dynamic part is the output's);
  the output member's frame spin (a flexible output shaft's elastic twist to its load seat is left out);
- ``dynamic_factor`` [-] (``harmonic`` 0): K_v = max over meshes of max over a mesh cycle of
  F(phi) / F_static, F(phi) = F_static + Re sum_h F_dyn,h e^{i h phi} (the steady waveform's peak: the time
  signal's max(F)/mean(F), flexgear.study.indicators, ISO 6336-1's K_v read as a peak factor).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from flexgear.harmonic.base import (
    DEFAULT_HARMONICS,
    INDICATOR_UNITS,
    RPM,
    Operating,
    Response,
    excited_spec,
    mesh_force_name,
    mesh_frequency_hz,
    series_coefficients,
    sweep_speeds,
)
from flexgear.harmonic.reduced import MODAL_CUTOFF_RATIO

__all__ = ["Response", "harmonic_response", "linearize_same_angle", "mesh_frequency_hz", "INDICATOR_UNITS",
           "DEFAULT_HARMONICS", "LINEARIZATIONS", "frozen_operating"]


def _lagrange(nodes: np.ndarray, x: float) -> np.ndarray:
    """Lagrange interpolation weights of ``nodes`` at ``x``."""
    w = np.ones(nodes.size)
    for k in range(nodes.size):
        for j in range(nodes.size):
            if j != k:
                w[k] *= (x - nodes[j]) / (nodes[k] - nodes[j])
    return w


LINEARIZATIONS = ("spin", "quadratic", "each")
"""The ways :func:`harmonic_response` linearises a variant over the speed grid (its docstring)."""

SPIN_FIT_FRACTION = 0.5
"""The second speed of the ``"spin"`` fit as a fraction of the grid's highest (the first): any other speed fixes
eq. 1 of flexgear.harmonic.reduced; one half keeps Omega_a^2 - Omega_b^2 large."""


def linearize_same_angle(variant: Any, speed_rpm: float, reference_rpm: float) -> Any:
    """flexgear.modal.linear.linearize at ``speed_rpm`` [rpm] with the gears at the angles and with the dynamic modes
    of ``reference_rpm``: t* = T/2 + theta_ref / omega, theta_ref = omega_ref T / 2 (the STEP ramp over T: the
    same angles at every speed, flexgear.modal.campbell_diagram), and the gears' dynamic cut-off ([reduction_assumed]
    dynamic_cutoff_mesh_orders x f_mesh) at reference_rpm's mesh frequency, so that every speed has the same
    coordinates (the time model's cut-off follows its own speed: above the reference speed's mesh orders it keeps
    fewer dynamic modes than this linearisation)."""
    from flexgear.modal.linear import linearize

    if not (speed_rpm > 0.0 and reference_rpm > 0.0):
        raise ValueError(f"speeds must be > 0 rpm, got {speed_rpm}, {reference_rpm}")
    ratio = reference_rpm / speed_rpm
    t_star = 0.5 * variant.gearbox.load_case.ramp_time_s * (1.0 + ratio)
    return linearize(variant, speed_rpm=float(speed_rpm), t_star=t_star, cutoff_rpm=float(reference_rpm))


def _linear_models(variant: Any, speeds_rpm: np.ndarray, linearization: str) -> tuple[np.ndarray, list[Any]]:
    """(speeds [rpm] of the linearisations, the flexgear.modal.linear.LinearModel at each, on the first one's
    coordinates unless ``each``: then each with its own speed's dynamic cut-off, the time model's)."""
    from flexgear.modal.linear import linearize

    if linearization not in LINEARIZATIONS:
        raise ValueError(f"linearization: expected one of {', '.join(LINEARIZATIONS)}, got {linearization!r}")
    if linearization == "each":
        nodes = np.unique(speeds_rpm)
        return nodes, [linearize(variant, speed_rpm=float(n), cutoff_rpm=float(n)) for n in nodes]
    lo, hi = float(speeds_rpm.min()), float(speeds_rpm.max())
    if lo <= 0.0:
        raise ValueError(f"linearization {linearization!r}: speeds > 0 rpm expected, got {lo:g}")
    if linearization == "spin":
        nodes = np.array([hi, SPIN_FIT_FRACTION * hi])
    else:
        nodes = np.unique([lo, 0.5 * (lo + hi), hi])
    models = [linearize_same_angle(variant, float(n), hi) for n in nodes]
    return nodes, [models[0]] + [_in_coordinates(lm, models[0]) for lm in models[1:]]


SAME_COORDINATES_RTOL = 1e-6
"""Two linearisations have the same independent coordinates when the least-squares map between their null-space
bases (:func:`_in_coordinates`) reproduces one from the other within this share of its largest entry; the contact
and output rows drawn from the mapped basis then agree to the same share of the basis' largest entry."""

_EACH_HINT = "use linearization='each' (flexgear sweep-speed --linearization each)"


def _in_coordinates(lm: Any, ref: Any, rtol: float = SAME_COORDINATES_RTOL) -> Any:
    """``lm`` in the independent coordinates of ``ref``: the constraints' column-pivoted QR may choose other
    independent coordinates at another speed, spanning the same motions q = B z. With B_ref = B T (least squares,
    checked to ``rtol``), z = T z_ref and each matrix A becomes T^T A T."""
    if lm.coordinates == ref.coordinates:
        return lm
    if lm.basis.shape[0] != ref.basis.shape[0]:
        raise ValueError(f"the model has {ref.basis.shape[0]} coordinates at {ref.speed_rpm:g} rpm and "
                         f"{lm.basis.shape[0]} at {lm.speed_rpm:g} rpm (a speed-dependent reduction): no interpolation "
                         f"between them; {_EACH_HINT}")
    t = np.linalg.lstsq(lm.basis, ref.basis, rcond=None)[0]
    basis = lm.basis @ t
    if np.abs(basis - ref.basis).max() > rtol * np.abs(ref.basis).max():
        raise ValueError(f"the linearisations at {ref.speed_rpm:g} and {lm.speed_rpm:g} rpm span different motions; "
                         f"{_EACH_HINT}")
    return dataclasses.replace(lm, mass=t.T @ lm.mass @ t, damping=t.T @ lm.damping @ t,
                               gyroscopic=t.T @ lm.gyroscopic @ t, stiffness=t.T @ lm.stiffness @ t, basis=basis,
                               coordinates=ref.coordinates)


def _frame_row(lm: Any, components: Sequence[str], name: str) -> int:
    """Index in the system coordinates of the first of ``components`` with a frame coordinate ``name``."""
    for comp in components:
        for i, c in enumerate(lm.full_coordinates):
            if c.component == comp and c.kind == "frame" and c.name == name:
                return i
    raise ValueError(f"no frame coordinate {name} of {components} in the linearised model")


def harmonic_response(model_or_variant: Any, speeds_rpm: Sequence[float], harmonics: int = DEFAULT_HARMONICS, *,
                      linearization: str = "spin", modal_cutoff_ratio: float | None = MODAL_CUTOFF_RATIO) -> Response:
    """Harmonic response (module docstring) of a variant at ``speeds_rpm`` [rpm], mesh harmonics 1..``harmonics``.

    ``model_or_variant``: a flexgear.spec.Variant or the path of its file (the multibody model, rigid or flexible,
    through flexgear.modal.linear.linearize at the load case's torque); a flexgear.modal.linear.LinearModel (its
    matrices at its own speed for every speed of the grid: spin terms frozen); or a flexgear.spec.GearboxSpec (the
    lumped model: :func:`lumped_harmonic_response`).

    ``linearization``: ``"spin"`` (default) linearises at the grid's highest speed and at
    :data:`SPIN_FIT_FRACTION` of it, both at the same gear angles and dynamic modes (:func:`linearize_same_angle`),
    fits eq. 1 of flexgear.harmonic.reduced (M, D constant, G ~ Omega, K and the static deflections
    ~ Omega^2: exact for these models) and solves every speed from it; ``"quadratic"`` linearises at the lowest,
    middle and highest speed (same angles and modes) and interpolates every matrix by the parabola through them
    (also exact for eq. 1, one linearisation more); ``"each"`` linearises at every speed as the time model is
    built there (its own dynamic modes and the gear angles at the end of the ramp; about 1 s each for model 1,
    3-10 s for model 7).

    ``modal_cutoff_ratio``: with ``"spin"``, each harmonic is solved on the modes below this multiple of its
    frequency plus the residual static part of the others (flexgear.harmonic.reduced.ModalSolver); None: the dense
    solve of all coordinates.
    """
    from flexgear.modal.linear import LinearModel
    from flexgear.spec import GearboxSpec, load_variant

    if isinstance(model_or_variant, GearboxSpec):
        from flexgear.harmonic.lumped import lumped_harmonic_response

        return lumped_harmonic_response(model_or_variant, speeds_rpm, harmonics)
    t0 = time.perf_counter()
    speeds = np.asarray(speeds_rpm, float)
    if speeds.ndim != 1 or speeds.size == 0:
        raise ValueError("speeds_rpm: expected a non-empty list of speeds")
    if isinstance(model_or_variant, LinearModel):
        variant = model_or_variant.variant
        nodes, models = np.array([model_or_variant.speed_rpm]), [model_or_variant]
    else:
        variant = model_or_variant if not isinstance(model_or_variant, str | Path) else load_variant(model_or_variant)
        variant = dataclasses.replace(variant, gearbox=excited_spec(variant.gearbox, harmonics))
        nodes, models = _linear_models(variant, speeds, linearization)
    spin = linearization == "spin" and len(models) == 2
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):  # small matrices: one thread each is fastest on a shared machine
        return _mbs_sweep(variant, nodes, models, speeds, harmonics, t0, spin, modal_cutoff_ratio)


def _check_contacts(lm: Any, names: list[str]) -> None:
    """The linearised model's contacts (static deflections, deflection coordinates) are ``names``, in order."""
    if list(lm.static_deflections) != names:
        raise ValueError("the linearised model's contacts differ from flexgear.mbs.gearbox.mesh_contacts")
    rows = [i for i, c in enumerate(lm.full_coordinates) if c.kind == "deflection"]
    if len(rows) != len(names):
        raise ValueError(f"{len(rows)} deflection coordinates for {len(names)} contacts")
    for i, name in zip(rows, names, strict=True):  # outer_mesh_<i>_half<k> -> sun_planet_<i>.delta_<k>
        kind, _, planet, half = name.split("_")
        comp = f"sun_planet_{planet}" if kind == "outer" else f"planet_{planet}_ring"
        if lm.full_coordinates[i].component != comp or lm.full_coordinates[i].name != f"delta_{half[4:]}":
            raise ValueError(f"contact {name}: deflection coordinate {lm.full_coordinates[i].label}")


def _mbs_sweep(variant: Any, nodes: np.ndarray, models: list[Any], speeds: np.ndarray, harmonics: int,
               t0: float, spin: bool = False, modal_cutoff_ratio: float | None = None) -> Response:
    operating = _mbs_operating(variant, nodes, models, harmonics, spin, modal_cutoff_ratio)
    return sweep_speeds(operating, speeds, harmonics, variant.name, mesh_frequency_hz(variant.gearbox, 1.0), t0)


def frozen_operating(models: Sequence[Any], harmonics: int = DEFAULT_HARMONICS) -> list[Operating]:
    """The linear problem (flexgear.harmonic.base.Operating: M, D + G, K, the contacts' excitation F_h and the
    outputs' rows) of each flexgear.modal.linear.LinearModel of ``models`` at its own speed and operating point,
    all on the first model's independent coordinates (the matrices of each frozen at its linearisation)."""
    ref = models[0]
    variant = dataclasses.replace(ref.variant, gearbox=excited_spec(ref.variant.gearbox, harmonics))
    out = []
    for lm in [ref] + [_in_coordinates(m, ref) for m in models[1:]]:
        out.append(_mbs_operating(variant, np.array([lm.speed_rpm]), [lm], harmonics)(float(lm.speed_rpm)))
    return out


def _mbs_operating(variant: Any, nodes: np.ndarray, models: list[Any], harmonics: int, spin: bool = False,
                   modal_cutoff_ratio: float | None = None) -> Any:
    """The linear problem at any speed [rpm] (a callable returning flexgear.harmonic.base.Operating) from the
    linearisations ``models`` at ``nodes`` [rpm] (Lagrange interpolation, or the spin fit where ``spin``)."""
    from flexgear.design import design
    from flexgear.harmonic.friction import friction_harmonics, friction_rows
    from flexgear.laws.contact import normal_force
    from flexgear.mbs.gearbox import mesh_contacts
    from flexgear.theory import theory

    spec = excited_spec(variant.gearbox, harmonics)
    lc = spec.load_case
    contacts = mesh_contacts(spec, math.copysign(1.0, lc.input_speed_rad_s))
    names = [c.name for c in contacts]
    for lm in models:
        _check_contacts(lm, names)
    contact_mesh = [mesh_force_name(c.name.split("_")[0], int(c.name.split("_")[2])) for c in contacts]
    mesh_names = tuple(sorted(set(contact_mesh), key=lambda nm: (not nm.startswith("outer"), int(nm.split("_")[3]))))
    mesh = np.array([mesh_names.index(nm) for nm in contact_mesh])
    rate = np.array([c.phase_per_drive_angle for c in contacts]) * math.copysign(1.0, lc.input_speed_rad_s)
    cos_c = np.stack([np.asarray(c.stiffness.cos_coeffs, float)[:harmonics] for c in contacts])
    sin_c = np.stack([np.asarray(c.stiffness.sin_coeffs, float)[:harmonics] for c in contacts])
    offset = -np.array([c.phase_offset for c in contacts])
    coef = series_coefficients(cos_c, sin_c, offset, np.sign(rate))
    means = np.array([c.stiffness.mean for c in contacts])
    rubbing = any(c.friction_coefficient > 0.0 for c in contacts)

    def rubbed(delta0: np.ndarray, speed_rpm: float) -> np.ndarray | None:
        """Tooth friction's forces (2 n_c, H) at the law deflections ``delta0`` and ``speed_rpm`` (rows: the
        contacts' sliding, then relative spin; flexgear.harmonic.friction); None without friction."""
        if not rubbing:
            return None
        forces = friction_harmonics(contacts, delta0, speed_rpm * math.copysign(RPM, lc.input_speed_rad_s), harmonics)
        return forces.reshape(2 * len(contacts), harmonics)

    def selectors(lm: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Contact deflections, bearing-node translations and output spin per z; static deflections. Where a
        contact's law acts on delta - e (a flexible gear's residual compliance, LinearModel.contact_residuals),
        the deflection is delta - e."""
        rows = [i for i, c in enumerate(lm.full_coordinates) if c.kind == "deflection"]
        residual = getattr(lm, "contact_residuals", {})
        law_rows = lm.basis[rows].copy()
        delta0 = np.array([lm.static_deflections[nm] for nm in names])
        for j, nm in enumerate(names):
            if nm in residual:
                law_rows[j] -= lm.basis[residual[nm]]
                delta0[j] -= lm.static_residuals[nm]
        full = [c.component for c in lm.full_coordinates if c.kind == "frame"]
        in_comp = ("input_shaft", "sun") if "input_shaft" in full else ("sun",)
        # the output member: the star's ring (its shaft where separate), the planetary stage's carrier, the
        # parallel-axis pair's wheel (its shaft where separate)
        if "carrier" in full:
            out_comp = ("carrier",)
        elif not spec.gears.has_ring:
            out_comp = ("output_shaft", "planet_1") if "output_shaft" in full else ("planet_1",)
        else:
            out_comp = ("output_shaft", "ring") if "output_shaft" in full else ("ring",)
        accel_rows = [_frame_row(lm, comp, a) for comp in (in_comp, out_comp) for a in ("u_x", "u_y")]
        out_row = _frame_row(lm, out_comp, "phi_z")
        return law_rows, lm.basis[accel_rows], te_scale * lm.basis[out_row], delta0

    th = theory(spec)
    r_out = design(spec).output_radius
    te_scale = -r_out * math.copysign(1.0, th.output_speed)

    def law_terms(delta0: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """F_0, k_t, c of every contact at its static deflection."""
        f0, kt, cc = (np.zeros(len(contacts)) for _ in range(3))
        for j, (c, d) in enumerate(zip(contacts, delta0, strict=True)):
            f = float(normal_force(d, 0.0, c.law, means[j]))
            eps = 1e-6 * d
            kt[j] = float(normal_force(d + eps, 0.0, c.law, means[j]) - normal_force(d - eps, 0.0, c.law,
                                                                                     means[j])) / (2 * eps)
            v = 1e-9
            cc[j] = float(normal_force(d, v, c.law, means[j]) - f) / v
            f0[j] = f
        if np.any(f0 <= 0.0):
            raise ValueError("a contact is unloaded at the operating point: no first-order excitation")
        return f0, kt, cc

    if spin:
        rows = friction_rows(models[0], contacts) if rubbing else None
        return _spin_operating(models, nodes, selectors, law_terms, coef, mesh, mesh_names, spec, modal_cutoff_ratio,
                               (rows, rubbed))
    parts = [(m.mass, m.damping + m.gyroscopic, m.stiffness, *selectors(m),
              friction_rows(m, contacts) if rubbing else 0.0) for m in models]
    cache: dict[tuple[float, ...], tuple] = {}

    def operating(speed_rpm: float) -> Operating:
        at = np.flatnonzero(np.isclose(nodes, speed_rpm, rtol=0.0, atol=1e-9))
        w = np.eye(nodes.size)[at[0]] if at.size else _lagrange(nodes, speed_rpm)
        key = tuple(np.round(w, 15))
        if key not in cache:
            used = [(wk, part) for wk, part in zip(w, parts, strict=True) if wk != 0.0]
            mixed = [sum(wk * part[i] for wk, part in used) for i in range(8)]
            cache.clear()
            cache[key] = (*mixed[:6], *law_terms(mixed[6]), mixed[6], mixed[7] if rubbing else None)
        mass, damp, stiff, g, acc, te, f0, kt, cc, delta0, fr = cache[key]
        omega_mesh = 2.0 * math.pi * mesh_frequency_hz(spec, speed_rpm)
        return Operating(mass, damp, stiff, g, kt, cc, f0, coef, mesh, mesh_names, acc, te, omega_mesh,
                         friction_rows=fr, friction=rubbed(delta0, speed_rpm))

    return operating


def _spin_operating(models: list[Any], nodes: np.ndarray, selectors: Any, law_terms: Any, coef: np.ndarray,
                    mesh: np.ndarray, mesh_names: tuple[str, ...], spec: Any,
                    modal_cutoff_ratio: float | None, friction: tuple[np.ndarray | None, Any]) -> Any:
    """The operating point at each speed from the spin fit (flexgear.harmonic.reduced eq. 1) of the two
    linearisations ``models`` at ``nodes`` [rpm]; solved on the modal basis unless ``modal_cutoff_ratio`` is None.
    ``friction``: (the friction rows (2 n_c, n) or None, their forces at (deflections, speed [rpm]))."""
    from flexgear.harmonic.reduced import ModalSolver, fit_spin

    a, b = models
    sel_a, sel_b = selectors(a), selectors(b)
    scale = SAME_COORDINATES_RTOL * np.abs(a.basis).max()  # the rows are drawn from the mapped basis
    for x, y in zip(sel_a[:3], sel_b[:3], strict=True):
        if np.abs(np.asarray(x) - np.asarray(y)).max() > scale:
            raise ValueError(f"the two linearisations select different contact or output coordinates: {_EACH_HINT}")
    rows, acc, te, _ = sel_a

    def terms(lm: Any, sel: tuple) -> dict[str, np.ndarray]:
        return {"mass": lm.mass, "damping": lm.damping, "gyroscopic": lm.gyroscopic, "stiffness": lm.stiffness,
                "delta": sel[3]}

    fit = fit_spin(nodes[0] * RPM, nodes[1] * RPM, terms(a, sel_a), terms(b, sel_b))
    rubs, rubbed = friction
    directions = rows.T if rubs is None else np.hstack([rows.T, rubs.T])
    modal = None if modal_cutoff_ratio is None else ModalSolver(fit, directions, modal_cutoff_ratio)

    def operating(speed_rpm: float) -> Operating:
        w = speed_rpm * RPM
        delta0 = fit.static_deflections(w)
        f0, kt, cc = law_terms(delta0)
        omega_mesh = 2.0 * math.pi * mesh_frequency_hz(spec, speed_rpm)
        solver = None if modal is None else (lambda om, c: modal.solve(w, om, c))
        return Operating(fit.mass, fit.damping + fit.gyroscopic(w), fit.stiffness(w), rows, kt, cc, f0, coef, mesh,
                         mesh_names, acc, te, omega_mesh, solver, rubs, rubbed(delta0, speed_rpm))

    return operating
