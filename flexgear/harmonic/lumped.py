"""Harmonic response of the lumped model (flexgear.lumped): the time model's equations linearised about the
static equilibrium under the load, excited at each mesh harmonic (the approximation and the outputs are those of
flexgear.harmonic.response)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flexgear.harmonic.base import (
    DEFAULT_HARMONICS,
    RPM,
    Operating,
    Response,
    excited_spec,
    mesh_force_name,
    mesh_frequency_hz,
    series_coefficients,
    sweep_speeds,
)
from flexgear.harmonic.lumped_friction import lumped_friction

__all__ = ["lumped_harmonic_response", "LumpedLinear", "lumped_linear"]


@dataclass(frozen=True)
class LumpedLinear:
    """The lumped model linearised about its static equilibrium under the load (:func:`lumped_linear`).

    ``operating(speed_rpm)``: the linear problem at that input speed [rpm] (flexgear.harmonic.base.Operating: M,
    D + G, K over the free coordinates, contact rows, excitation, outputs); ``labels``: the free coordinates'
    names (flexgear.lumped.model.LumpedSystem.labels); ``free``: their indices among all coordinates;
    ``system``: the assembled flexgear.lumped.model.LumpedSystem; ``per_rpm``: f_mesh per input rpm [Hz/rpm];
    ``name``: the model's name in a :class:`~flexgear.harmonic.base.Response`; ``static`` (n_f,): the static
    equilibrium under the load [m, rad] the model is linearised about (input spin at zero).
    """

    operating: Callable[[float], Operating]
    labels: tuple[str, ...]
    free: np.ndarray
    system: Any
    per_rpm: float
    name: str
    static: np.ndarray | None = None


def lumped_harmonic_response(spec: Any, speeds_rpm: Sequence[float], harmonics: int = DEFAULT_HARMONICS) -> Response:
    """Harmonic response of the lumped model of ``spec`` (a flexgear.spec.GearboxSpec) at ``speeds_rpm`` [rpm]
    (the linearisation: :func:`lumped_linear`)."""
    t0 = time.perf_counter()
    lin = lumped_linear(spec, harmonics)
    return sweep_speeds(lin.operating, speeds_rpm, harmonics, lin.name, lin.per_rpm, t0)


def lumped_linear(spec: Any, harmonics: int = DEFAULT_HARMONICS) -> LumpedLinear:
    """The lumped model of ``spec`` (a flexgear.spec.GearboxSpec) linearised, with ``harmonics`` stiffness harmonics.

    The time model's equations (flexgear.lumped.run) linearised about the static equilibrium under the load
    torque: input spin held (the prescribed drive), mean mesh stiffness, no friction in the static solution. The
    contact law is the spec's (``[contact] law``): ISO 6336 (F = k delta, k_t = k, damping of eq. 13) or the impact
    law (F = k delta^e, k_t = e F_0 / delta_0, damping c_max STEP(delta_0, 0, 0, d, 1)). The stiffness harmonics c_h
    (h = 1..``harmonics``) are eq. 11-12's from the contact lines; mesh i is phased as in the time model, whose
    phase follows the gear's angle coordinate: the nominal spin plus the static deflection's rotation. A
    rotating carrier (planetary arrangement) adds its Coriolis, centripetal and bearing-damping terms; then the
    bearing accelerations are in the carrier frame. The parallel-axis pair has its one mesh (no planet-ring rows), the
    output on the wheel; the transmission error's lever is flexgear.design.Design.output_radius. With mu > 0 the
    tooth friction at the static mesh forces adds its first-order excitation (flexgear.harmonic.lumped_friction),
    phased as the stiffness excitation.
    """
    from flexgear.design import as_design
    from flexgear.lumped.kernel_layout import DEPTH, EXPONENT, IMPACT, IN_BODY, LOAD_SIGN, OUT_BODY, OUT_SPIN, T_LOAD
    from flexgear.lumped.run import build_lumped_model
    from flexgear.theory import theory

    spec = excited_spec(spec, harmonics)
    model = build_lumped_model(spec)
    s = model.system
    p = s.params
    g = spec.gears
    r_c = g.sun_teeth / (g.sun_teeth + g.ring_teeth) if g.arrangement == "planetary" else 0.0
    free = model.free
    nf = free.size
    rows = s.mesh_G[:, free]
    nmesh = rows.shape[0]
    impact = model.fp[IMPACT] > 0.0
    exponent = float(model.fp[EXPONENT]) if impact else 1.0
    depth = float(model.fp[DEPTH])
    k_law, c_law = model.mesh_k, model.mesh_c

    # static equilibrium under the load (mean stiffness, no friction): K_s q + G^T F(G q) = T (Newton)
    load = np.zeros(s.n)
    load[model.ip[OUT_SPIN]] = model.fp[LOAD_SIGN] * model.fp[T_LOAD]
    ks = s.support_stiffness[np.ix_(free, free)]
    q = np.linalg.solve(s.stiffness()[np.ix_(free, free)], load[free])
    for _ in range(100):
        d = np.maximum(rows @ q, 0.0)
        force = k_law * d**exponent
        tangent = exponent * k_law * d ** (exponent - 1.0) if impact else k_law
        resid = ks @ q + rows.T @ force - load[free]
        step = np.linalg.solve(ks + (rows.T * tangent) @ rows, resid)
        q = q - step
        if np.abs(step).max() <= 1e-13 * max(np.abs(q).max(), 1e-30):
            break
    delta0 = rows @ q
    if np.any(delta0 <= 0.0):
        raise ValueError("lumped model: a mesh is unloaded at the operating point")
    f0 = k_law * delta0**exponent
    k_t = exponent * f0 / delta0
    if impact:
        ramp = np.minimum(delta0 / depth, 1.0)
        c = c_law * ramp * ramp * (3.0 - 2.0 * ramp)
    else:
        c = np.asarray(c_law, float)

    # mesh phases: phase_m = coef_m q[index_m] + offset_m, the spin's nominal rate relative to the carrier frame
    zs, zr = g.sun_teeth, g.ring_teeth
    rel = {2: 1.0 - r_c}  # sun and (where the stage has one) ring spin per input angle, carrier frame
    if p.ring_meshes:
        rel[5] = -(zs / zr) * (1.0 - r_c)
    rate = np.array([model.phase_coef[m] * rel[int(model.phase_index[m])] for m in range(nmesh)])
    # the static deflection turns the gears too: a mesh's phase at the operating point includes coef_m q0[index_m]
    q_static = np.zeros(s.n)
    q_static[free] = q
    offset = model.phase_offset - model.phase_centre + model.phase_coef * q_static[model.phase_index]
    cos_c = np.asarray(model.harmonics, float)
    coef = series_coefficients(cos_c, np.zeros_like(cos_c), offset, np.sign(rate))
    friction = lumped_friction(model, free, f0, harmonics, np.sign(rate))  # None at mu = 0

    n_pl = p.planet_count
    names = tuple([mesh_force_name("outer", i + 1) for i in range(n_pl)]
                  + [mesh_force_name("inner", i + 1) for i in range(n_pl) if p.ring_meshes])
    pos = {int(j): k for k, j in enumerate(free)}
    accel = np.zeros((4, nf))
    for k, b in enumerate((int(model.ip[IN_BODY]), int(model.ip[OUT_BODY]))):
        for a in range(2):
            if 3 * b + a in pos:
                accel[2 * k + a, pos[3 * b + a]] = 1.0
    th = theory(spec)
    r_out = as_design(spec).output_radius  # ring base radius, planet centre distance, wheel base radius
    te = np.zeros(nf)
    out_spin = int(model.ip[OUT_SPIN])
    if out_spin in pos:
        te[pos[out_spin]] = -r_out * math.copysign(1.0, th.output_speed)
    mass = np.diag(s.mass[free])
    base_k = ks + (rows.T * k_t) @ rows
    base_d = s.support_damping[np.ix_(free, free)] + (rows.T * c) @ rows

    def operating(speed_rpm: float) -> Operating:
        w_in = speed_rpm * RPM
        om = r_c * w_in
        gyro = np.zeros((nf, nf))
        kk = base_k.copy()
        if om != 0.0:  # rotating frame: m (x'' - 2 Om y' - Om^2 x), ground bearings damp x' + Om J x
            for j in free:
                if j % 3 == 0 and j + 1 in pos and s.mass[j] > 0.0:
                    ix, iy = pos[j], pos[j + 1]
                    m = s.mass[j]
                    gyro[ix, iy], gyro[iy, ix] = -2.0 * m * om, 2.0 * m * om
                    kk[ix, ix] -= m * om**2
                    kk[iy, iy] -= m * om**2
                    cg = s.ground_damping[j, j]
                    kk[ix, iy] -= cg * om
                    kk[iy, ix] += cg * om
        omega_mesh = 2.0 * math.pi * mesh_frequency_hz(spec, speed_rpm)
        rubbing = {} if friction is None else {"friction_rows": friction.rows,
                                                "friction": friction.coefficients(w_in)}
        return Operating(mass, base_d + gyro, kk, rows, k_t, c, f0, coef, np.arange(nmesh), names, accel, te,
                         omega_mesh, **rubbing)

    return LumpedLinear(operating, tuple(s.labels[j] for j in free), free, s, mesh_frequency_hz(spec, 1.0),
                        f"lumped ({Path(str(spec.source)).stem})", q)
