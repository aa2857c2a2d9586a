"""Time integration of the lumped-parameter model (section 2.3, eq. 1-13) for the Table 5 load case.

Equations of motion in the frame rotating with the nominal carrier speed Omega(t) (zero for the
star arrangement, where they reduce to eq. 1-9 with N planets):

    m (x'' + 2 Omega J x' + Omega' J rho - Omega^2 rho) = F_bearing + F_mesh + F_friction      (translations)
    I (theta'' + Omega')                                = T_support + T_mesh + T_friction + T_load  (spins)

with rho = nominal centre + x. Each mesh m (:func:`build_lumped_model`) has the normal deflection delta = G_m . q
and the normal force (eq. 1-13)

    F_n = k_m(t) f(delta) + c_m delta'   (damping only while the teeth touch)
    k_m(t) = k_mean (1 + sum_n c_n cos(2 pi n (phi_m - (eps_alpha + eps_beta)/2)))   (eq. 11-12)
    f(delta) = delta (delta > 0), 0 (-j_n <= delta <= 0), delta + j_n (delta < -j_n)   (backlash j_n)

with k_mean and c_m the multibody model's ISO 6336 law and eq. 13 damping under ``[contact] law = "iso6336"``
(flexgear.laws.contact.mesh_laws). Under the study's impact law (``law = "impact"``, section 2.1: again the
multibody model's law, so that both models are compared under the same law) the same mesh carries the
whole-face impact law instead (flexgear.laws.contact.impact_force; the linear analyses of the lumped model,
flexgear.lumped.modal and :func:`static_mesh_forces`, keep eq. 10's stiffness):
F_n = k s(phi) delta^e + c_max STEP(delta, 0, 0, d, 1) delta' on the driving flank, mirrored on the back
flank past the backlash.

phi_m is the mesh phase (mesh cycles) from the sun or ring spin, each planet phased by its position
(sun mesh: z_s (theta_s - psi_i) / 2 pi; ring mesh: -z_r (theta_r - psi_i) / 2 pi + outer-inner phase).
The teeth start in contact with zero load (delta = 0 on the driving flank). Tooth friction
mu F_n acts across the line of action with arms tabulated over the mesh cycle
(:class:`flexgear.lumped.model.FrictionTables`), its direction set by the running direction,
regularised as tanh(omega_1 p_bt / v_reg). The stiffness series and the friction law are the multibody
model's compiled ones (flexgear.laws.compiled.series_value, tooth_friction). The input spin follows the STEP
speed ramp exactly (prescribed); the load torque is the STEP load ramp on the output member (Table 5): the ring
(star), the carrier (planetary) or the wheel, planet 1 (the parallel-axis pair, whose one mesh is the sun-planet
mesh of planet 1: flexgear.lumped.model).

Integration: classical fixed-step Runge-Kutta 4 (``[lumped_assumed] integration_substeps`` steps per recorded
step), the right-hand side compiled with numba; at the study's highest frequency (~8 kHz) omega h << 2.8 (RK4's limit).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd

from flexgear.design import Design, as_design
from flexgear.geometry.contact_lines import mesh_stiffness_harmonics
from flexgear.laws.compiled import (
    backlash_linear_force,
    impact_normal_force,
    padded_sparse_rows,
    ramp_state,
    series_value,
    tooth_friction,
)
from flexgear.laws.contact import mesh_laws
from flexgear.lumped import kernel_layout as kl
from flexgear.lumped.model import LumpedParameters, LumpedSystem, assemble, mesh_friction_tables
from flexgear.progress import Progress
from flexgear.results import RunResult, run_metadata, signal_columns
from flexgear.spec import GearboxSpec, spec_hash

__all__ = ["LumpedModel", "LumpedRHS", "build_lumped_model", "lumped_rhs", "run_lumped", "static_mesh_forces",
           "OUTPUT_BODY"]

OUTPUT_BODY = {"star": 1, "planetary": 2, "parallel": 3}
"""Body (0 sun, 1 ring, 2 carrier, 3 + i planet i + 1) carrying the output per arrangement: its spin takes the load
and its bearing gives the output acceleration (the parallel-axis pair's wheel is planet 1)."""


@dataclass(frozen=True)
class LumpedModel:
    """Everything the compiled kernel needs, as plain arrays (built by :func:`build_lumped_model`)."""

    system: LumpedSystem
    fp: np.ndarray  # float parameters, laid out as flexgear.lumped.kernel_layout says
    ip: np.ndarray  # integer parameters (the same layout module)
    free: np.ndarray  # indices of free coordinates
    presc: np.ndarray  # indices of prescribed spins
    presc_coef: np.ndarray  # q[presc] = coef * input angle(t)
    harmonics: np.ndarray  # (meshes, H) stiffness harmonic coefficients c_n
    phase_centre: np.ndarray  # (meshes,) (eps_alpha + eps_beta)/2
    phase_index: np.ndarray  # (meshes,) coordinate that drives the mesh phase
    phase_coef: np.ndarray
    phase_offset: np.ndarray
    backlash: np.ndarray  # (meshes,) normal backlash [m]
    tables: np.ndarray  # (types, points, 3) friction force, arm1, arm2 of sun (and ring) meshes
    mesh_type: np.ndarray  # (meshes,) 0 sun mesh, 1 ring mesh
    tau: np.ndarray  # (meshes, 2) friction direction J n
    g1: np.ndarray  # (meshes,) d delta_t / d theta_1 (sign gives forward running of gear 1)
    friction_scale: np.ndarray  # (meshes,) p_bt / (|g1| v_reg)
    ground_damping: np.ndarray  # (3,) bearing damping of the central members [N s/m]
    spin_support: np.ndarray  # (n,) torsional support stiffness on spins (absolute angle)
    mesh_k: np.ndarray  # (meshes,) the law's stiffness: eq. 10 [N/m], or the impact law's [N/m^e]
    mesh_c: np.ndarray  # (meshes,) the law's damping: eq. 13 [N s/m], or the impact law's c_max [N s/m]


def build_lumped_model(spec: GearboxSpec | Design) -> LumpedModel:
    """Assemble the time-domain model of the spec or its design (flexgear.design: gear set, theory, geometry)."""
    d = as_design(spec)
    spec, geo, th = d.spec, d.gears, d.theory
    params = LumpedParameters.from_spec(d, hold_input=True)
    sysm = assemble(params)
    g, lc = spec.gears, spec.load_case
    planetary = g.arrangement == "planetary"
    r_c = g.sun_teeth / (g.sun_teeth + g.ring_teeth) if planetary else 0.0  # Omega_c / omega_in
    nplan, nm = params.planet_count, params.mesh_count
    out_body = OUTPUT_BODY[g.arrangement]
    out_spin = 3 * out_body + 2
    fp = np.zeros(kl.NFP)
    fp[kl.MU] = spec.contact.friction_coefficient
    fp[kl.W_IN] = lc.input_speed_rad_s
    fp[kl.T_RAMP] = lc.ramp_time_s
    fp[kl.R_C] = r_c
    fp[kl.T_LOAD] = lc.load_torque_nm
    fp[kl.LOAD_SIGN] = -math.copysign(1.0, th.ratio)
    ip = np.array([2, out_spin, 0, out_body], dtype=np.int64)
    mesh_k, mesh_c = sysm.mesh_stiffness, sysm.mesh_damping
    if spec.contact.law == "impact":  # the multibody model's law, whole face width, on every mesh
        law = mesh_laws(d)["outer"]
        fp[kl.IMPACT], fp[kl.EXPONENT], fp[kl.DEPTH] = 1.0, law.exponent, law.penetration_depth
        mesh_k, mesh_c = np.full_like(mesh_k, law.stiffness), np.full_like(mesh_c, law.damping_max)

    presc = np.flatnonzero(sysm.held_spin)
    coef = np.array([(1.0 - r_c) if i == 2 else -r_c for i in presc])
    psi = params.angles
    meshes = [geo.sun_planet, geo.planet_ring] if params.ring_meshes else [geo.sun_planet]  # the pair: one mesh
    nh = spec.contact_assumed.stiffness_harmonics
    eps_b = geo.sun_planet.overlap_ratio(geo.helix_face_width)
    harm, centre = [], []
    for mesh in meshes:
        ea = mesh.transverse_contact_ratio
        c = mesh_stiffness_harmonics(ea, eps_b, nh) if spec.contact_assumed.stiffness_variation != "constant" \
            else np.zeros(nh)
        harm.append(np.broadcast_to(c, (nplan, nh)))
        centre.append(np.full(nplan, 0.5 * (ea + eps_b)))
    zs, zr = g.sun_teeth, g.ring_teeth
    phase_index = np.r_[np.full(nplan, 2), np.full(nplan, 5)].astype(np.int64)[:nm]
    phase_coef = np.r_[np.full(nplan, zs / (2 * math.pi)), np.full(nplan, -zr / (2 * math.pi))][:nm]
    phase_offset = np.r_[-zs * psi / (2 * math.pi),
                         zr * psi / (2 * math.pi) + spec.gears_assumed.outer_inner_mesh_phase][:nm]
    found = mesh_friction_tables(geo, spec.lumped_assumed.friction_table_points)  # sun (and ring) mesh
    tables = np.stack([np.stack([t.force, t.arm1, t.arm2], axis=1) for t in found])
    jn = np.stack([-sysm.mesh_direction[:, 1], sysm.mesh_direction[:, 0]], axis=1)
    g1 = np.r_[np.full(nplan, geo.sun.base_radius), np.full(nplan, -geo.planet.base_radius)][:nm]
    v_reg = spec.contact_assumed.friction_regularisation_m_per_s
    fscale = geo.sun.base_pitch / (np.abs(g1) * v_reg)
    spin_support = sysm.ground_spin_stiffness
    ground = np.array([sysm.support_damping[0, 0], sysm.support_damping[3, 3], sysm.support_damping[6, 6]])
    return LumpedModel(
        sysm, fp, ip, np.flatnonzero(sysm.free), presc, coef, np.ascontiguousarray(np.vstack(harm)),
        np.concatenate(centre), phase_index, phase_coef, phase_offset,
        np.full(nm, geo.sun_planet.normal_backlash), np.ascontiguousarray(tables),
        np.r_[np.zeros(nplan), np.ones(nplan)].astype(np.int64)[:nm], np.ascontiguousarray(jn), g1, fscale, ground,
        spin_support, mesh_k, mesh_c,
    )


# --------------------------------------------------------------------------- compiled kernel
@numba.njit(cache=True, inline="always")  # inlined into _integrate's RK4 stages (no 35-array call per stage)
def _evaluate(t, y, model, work):
    """Accelerations ``acc`` (all coordinates, rotating frame), forces and the recorded signals ``out``.

    ``model``: the arrays of :func:`_kernel_args`; ``work``: (q, qd, acc, f, forces, out), written. Two tuples, not
    35 arguments: a call of more than 30 arguments compiles to a star-args call, which numba cannot inline.
    """
    (fp, ip, mass, sp_ptr, sp_idx, sp_k, sp_c, gidx, gval, km, cm, free, presc, pcoef, harm, pcentre, pidx, pcoefm,
     poff, backlash, tables, mtype, tau, g1, fscale, ground, spin_support, nominal, movable, group, gidx_q, grate,
     rot_b) = model
    q, qd, acc, f, forces, out, trig = work
    n = mass.size
    nf = free.size
    th_in, s, sd, sdd = ramp_state(t, fp[kl.T_RAMP])
    w = fp[kl.W_IN]
    r_c = fp[kl.R_C]
    om, omd = r_c * w * s, r_c * w * sd  # frame speed and acceleration
    th_c = r_c * w * th_in
    q[:] = 0.0
    qd[:] = 0.0
    for k in range(nf):
        q[free[k]] = y[k]
        qd[free[k]] = y[nf + k]
    for k in range(presc.size):
        q[presc[k]] = pcoef[k] * w * th_in
        qd[presc[k]] = pcoef[k] * w * s
    for i in range(n):  # supports: sparse rows (CSR)
        acc_i = -spin_support[i] * th_c
        for k in range(sp_ptr[i], sp_ptr[i + 1]):
            j = sp_idx[k]
            acc_i -= sp_k[k] * q[j] + sp_c[k] * qd[j]
        f[i] = acc_i
    for b in range(3):  # ground bearings damp the absolute velocity x' + Omega J x
        f[3 * b] += ground[b] * om * q[3 * b + 1]
        f[3 * b + 1] -= ground[b] * om * q[3 * b]
    f[ip[kl.OUT_SPIN]] += fp[kl.LOAD_SIGN] * fp[kl.T_LOAD] * s
    mu = fp[kl.MU]
    npts = tables.shape[1]
    for k in range(grate.size):  # A_g of each phase group (_phase_groups)
        a = 2.0 * math.pi * grate[k] * q[gidx_q[k]]
        trig[0, k], trig[1, k] = math.cos(a), math.sin(a)
    for m in range(km.size):
        d = 0.0
        dd = 0.0
        for k in range(gidx.shape[1]):  # the (at most 6) coordinates of the mesh's two gears
            d += gval[m, k] * q[gidx[m, k]]
            dd += gval[m, k] * qd[gidx[m, k]]
        phase = pcoefm[m] * q[pidx[m]] + poff[m]
        ca, sa = trig[0, group[m]], trig[1, group[m]]  # x = 2 pi (phase - centre) = A_g + B_m
        kf = series_value(harm[m], ca * rot_b[0, m] - sa * rot_b[1, m], sa * rot_b[0, m] + ca * rot_b[1, m])
        if fp[kl.IMPACT] > 0.0:  # the impact law on the driving flank, mirrored on the back flank
            if d >= 0.0:
                F = impact_normal_force(d, dd, km[m] * kf, fp[kl.EXPONENT], cm[m], fp[kl.DEPTH])
            elif d < -backlash[m]:
                F = -impact_normal_force(-d - backlash[m], -dd, km[m] * kf, fp[kl.EXPONENT], cm[m], fp[kl.DEPTH])
            else:
                F = 0.0
        else:
            F = backlash_linear_force(d, dd, km[m] * kf, cm[m], backlash[m])
        forces[m] = F
        for k in range(gidx.shape[1]):
            f[gidx[m, k]] -= F * gval[m, k]
        if mu > 0.0 and F > 0.0:
            ph = (phase - math.floor(phase)) * npts  # in [0, npts]: the table's periodic index without a division
            i0 = int(ph)
            wt = ph - i0
            if i0 >= npts:  # phase - floor(phase) rounded to 1
                i0 -= npts
            i1 = i0 + 1 if i0 + 1 < npts else 0
            ty = mtype[m]
            fa = tables[ty, i0, 0] * (1.0 - wt) + tables[ty, i1, 0] * wt
            a1 = tables[ty, i0, 1] * (1.0 - wt) + tables[ty, i1, 1] * wt
            a2 = tables[ty, i0, 2] * (1.0 - wt) + tables[ty, i1, 2] * wt
            b1 = 0 if ty == 0 else 3 + m - km.size // 2
            b2 = 3 + m if ty == 0 else 1
            ff = tooth_friction(mu, F, g1[m] * qd[3 * b1 + 2] * fscale[m])
            f[3 * b2] += ff * fa * tau[m, 0]
            f[3 * b2 + 1] += ff * fa * tau[m, 1]
            f[3 * b1] -= ff * fa * tau[m, 0]
            f[3 * b1 + 1] -= ff * fa * tau[m, 1]
            f[3 * b1 + 2] -= ff * a1
            f[3 * b2 + 2] += ff * a2
    acc[:] = 0.0
    for k in range(presc.size):
        acc[presc[k]] = pcoef[k] * w * sd
    nb = n // 3
    for b in range(nb):
        ix, iy, it = 3 * b, 3 * b + 1, 3 * b + 2
        if movable[ix]:
            rx, ry = nominal[b, 0] + q[ix], nominal[b, 1] + q[iy]
            acc[ix] = f[ix] / mass[ix] + 2.0 * om * qd[iy] + omd * ry + om * om * rx
            acc[iy] = f[iy] / mass[iy] - 2.0 * om * qd[ix] - omd * rx + om * om * ry
        if movable[it]:
            acc[it] = f[it] / mass[it] - omd
    for k in range(presc.size):  # held spins keep their prescribed motion
        acc[presc[k]] = pcoef[k] * w * sd
    # recorded signals: input/output absolute speed, drive torque, accelerations of the bearing nodes
    out[0] = qd[ip[kl.IN_SPIN]] + om
    out[1] = qd[ip[kl.OUT_SPIN]] + om
    out[2] = mass[ip[kl.IN_SPIN]] * w * sd - f[ip[kl.IN_SPIN]]
    cth, sth = math.cos(th_c), math.sin(th_c)
    for k in range(2):
        b = ip[kl.IN_BODY + k]
        ax = acc[3 * b] + 2.0 * om * (-qd[3 * b + 1]) - omd * q[3 * b + 1] - om * om * q[3 * b]
        ay = acc[3 * b + 1] + 2.0 * om * qd[3 * b] + omd * q[3 * b] - om * om * q[3 * b + 1]
        out[3 + 2 * k] = cth * ax - sth * ay
        out[4 + 2 * k] = sth * ax + cth * ay


@numba.njit(cache=True)
def _integrate(y, t0, h_out, n_out, substeps, rec, model, work):
    """RK4 from t0 over n_out recorded steps; rec[k] = signals at t0 + k h_out. Returns the final state."""
    free = model[11]
    nf = free.size
    acc, forces, out = work[2], work[4], work[5]  # work: _work(model)
    nm = forces.size
    kk = np.zeros((4, 2 * nf))
    ytmp = np.zeros(2 * nf)
    h = h_out / substeps
    for step in range(n_out):
        for sub in range(substeps):
            t = t0 + (step * substeps + sub) * h
            for stage in range(4):
                if stage == 0:
                    ts = t
                    ytmp[:] = y
                else:
                    ts = t + (h if stage == 3 else 0.5 * h)
                    fac = h if stage == 3 else 0.5 * h
                    for i in range(2 * nf):
                        ytmp[i] = y[i] + fac * kk[stage - 1, i]
                _evaluate(ts, ytmp, model, work)
                if stage == 0 and sub == 0:
                    rec[step, 0:3] = out[0:3]
                    rec[step, 3:3 + nm] = forces
                    rec[step, 3 + nm:7 + nm] = out[3:7]
                for i in range(nf):
                    kk[stage, i] = ytmp[nf + i]
                    kk[stage, nf + i] = acc[free[i]]
            for i in range(2 * nf):
                y[i] += h / 6.0 * (kk[0, i] + 2.0 * kk[1, i] + 2.0 * kk[2, i] + kk[3, i])
    return y


def _sparse_rows(*mats: np.ndarray) -> tuple[np.ndarray, ...]:
    """CSR pattern (union of the non-zeros) of same-shaped matrices: indptr, indices, one data array each."""
    pattern = np.any([m != 0.0 for m in mats], axis=0)
    rows, cols = np.nonzero(pattern)
    ptr = np.searchsorted(rows, np.arange(pattern.shape[0] + 1)).astype(np.int64)
    return (ptr, cols.astype(np.int64), *[np.ascontiguousarray(m[rows, cols]) for m in mats])


def _phase_groups(model: LumpedModel) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The meshes' stiffness-series angle x_m = 2 pi (c_m q[i_m] + offset_m - centre_m) split as A_g + B_m: A_g =
    2 pi c q[i] shared by the meshes g with the same coordinate i and rate c (the star's five sun-planet meshes),
    B_m constant. Returns the group of each mesh, each group's (coordinate, rate) and cos B_m, sin B_m: the kernel
    then takes one cosine and sine per group, not per mesh (angle addition)."""
    keys = list(zip(model.phase_index.tolist(), model.phase_coef.tolist(), strict=True))
    unique = list(dict.fromkeys(keys))
    group = np.array([unique.index(k) for k in keys], dtype=np.int64)
    index = np.array([k[0] for k in unique], dtype=np.int64)
    rate = np.array([k[1] for k in unique], dtype=float)
    b = 2.0 * np.pi * (model.phase_offset - model.phase_centre)
    return group, np.ascontiguousarray(index), rate, np.ascontiguousarray(np.stack([np.cos(b), np.sin(b)]))


def _stiffness_series(model: LumpedModel) -> np.ndarray:
    """Each mesh's stiffness factor k(t)/k_mean as a series in x = 2 pi (phi - centre) (eq. 11-12: mean 1, cosine
    coefficients c_n, no sine terms), in the layout of flexgear.laws.compiled.series_value."""
    c = model.harmonics
    return np.ascontiguousarray(np.hstack([np.ones((c.shape[0], 1)), c, np.zeros_like(c)]))


def _kernel_args(model: LumpedModel) -> tuple:
    s = model.system
    return (model.fp, model.ip, s.mass, *_sparse_rows(s.support_stiffness, s.support_damping),
            *padded_sparse_rows(s.mesh_G), model.mesh_k,
            model.mesh_c, model.free, model.presc, model.presc_coef, _stiffness_series(model), model.phase_centre,
            model.phase_index, model.phase_coef, model.phase_offset, model.backlash, model.tables, model.mesh_type,
            model.tau, model.g1, model.friction_scale, model.ground_damping, model.spin_support,
            s.nominal_position, s.free & (s.mass > 0.0), *_phase_groups(model))


def _work(model: LumpedModel) -> tuple:
    """The kernel's work arrays (q, qd, acc, f, forces, out, each phase group's cos and sin): :func:`_evaluate`."""
    n, nm = model.system.mass.size, model.system.mesh_stiffness.size
    groups = len(set(zip(model.phase_index.tolist(), model.phase_coef.tolist(), strict=True)))
    return (np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(nm), np.zeros(7), np.zeros((2, groups)))


def _simulate(model: LumpedModel, t_end: float, h_out: float, substeps: int, progress: bool) -> np.ndarray:
    """Recorded signals at 0, h_out, ..., t_end: (steps + 1, 7 + meshes)."""
    n_steps = int(round(t_end / h_out))
    nm = model.system.mesh_stiffness.size
    rec = np.zeros((n_steps + 1, 7 + nm))
    y = np.zeros(2 * model.free.size)
    args, work = _kernel_args(model), _work(model)
    chunk = max(1, n_steps // 20)
    done = 0
    with Progress(t_end, "lumped", "s", enabled=progress, fmt="{:.4g}") as bar:
        while done < n_steps:
            k = min(chunk, n_steps - done)
            y = _integrate(y, done * h_out, h_out, k, substeps, rec[done:done + k], args, work)
            done += k
            bar.update_to(done * h_out)
    _integrate(y, n_steps * h_out, h_out, 1, 1, rec[n_steps:n_steps + 1], args, work)  # record the final state
    return rec


def run_lumped(spec: GearboxSpec, t_end_s: float | str | None = None, progress: bool = False) -> RunResult:
    """Run the lumped model for the spec's load case; signals as the multibody runs (flexgear.results).

    ``t_end_s`` "settled" (or None with ``[load_case] end = "settled"``): to ``settle_max_time_s``, so that its run
    covers the multibody runs' settled windows (the lumped model costs seconds, not minutes)."""
    lc = spec.load_case
    if t_end_s == "settled" or (t_end_s is None and lc.end == "settled"):
        t_end = lc.settle_max_time_s
    else:
        t_end = lc.end_time_s if t_end_s is None else float(t_end_s)
    if t_end <= 0.0:
        raise ValueError(f"t_end_s: expected > 0, got {t_end}")
    wall0, cpu0 = time.perf_counter(), time.process_time()
    d = as_design(spec)
    model = build_lumped_model(d)
    rec = _simulate(model, t_end, lc.step_size_s, spec.lumped_assumed.integration_substeps, progress)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    n, nm = model.system.params.planet_count, model.system.params.mesh_count
    t = np.arange(rec.shape[0]) * lc.step_size_s
    w_in, w_out = rec[:, 0], rec[:, 1]  # rad/s
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(w_in != 0.0, w_out / w_in, np.nan)
    data = np.column_stack([t, w_in, w_out, ratio, rec[:, 2], rec[:, 3:3 + nm], rec[:, 3 + nm:7 + nm]])
    signals = pd.DataFrame(data, columns=signal_columns(n, inner=model.system.params.ring_meshes))
    meta = run_metadata("lumped", "lumped", spec_hash(spec, "lumped", t_end), t_end, lc, n, {}, d.theory,
                        status="ok", reason="", wall_time_s=wall, cpu_time_s=cpu,
                        integration={"method": "rk4", "substeps": spec.lumped_assumed.integration_substeps})
    return RunResult(meta, signals)


def static_mesh_forces(spec: GearboxSpec) -> tuple[np.ndarray, np.ndarray]:
    """Normal mesh forces [N] (sun meshes, ring meshes: none in the parallel-axis pair) of the linear static problem
    at full load.

    Mean mesh stiffness, input spin held, load torque on the output member, no friction:
    K_ff q_f = F_f, F_m = k_m G_m . q.
    """
    model = build_lumped_model(spec)
    s = model.system
    K = s.stiffness()
    free = model.free
    load = np.zeros(s.n)
    load[model.ip[kl.OUT_SPIN]] = model.fp[kl.LOAD_SIGN] * model.fp[kl.T_LOAD]
    q = np.zeros(s.n)
    q[free] = np.linalg.solve(K[np.ix_(free, free)], load[free])
    forces = s.mesh_stiffness * (s.mesh_G @ q)
    n = s.params.planet_count
    return forces[:n], forces[n:]


class LumpedRHS:
    """The compiled right-hand side dy/dt = f(t, y) of :func:`_integrate`, callable from Python.

    ``y`` = (free coordinates, their rates), as in the kernel. For other integrators
    (``scipy.integrate.solve_ivp``) driving the same compiled equations; ``record(t, y)`` gives the
    row the kernel records (input/output speed [rad/s], drive torque [N m], mesh forces [N], bearing
    accelerations [m/s^2]).
    """

    def __init__(self, model: LumpedModel, kernel: Callable | None = None):
        self.model, self.args = model, _kernel_args(model)
        self.kernel = _evaluate if kernel is None else kernel
        self.nf = model.free.size
        self._work = _work(model)

    def _eval(self, t: float, y: np.ndarray) -> None:
        self.kernel(float(t), np.ascontiguousarray(y, dtype=float), self.args, self._work)

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        self._eval(t, y)
        return np.concatenate([y[self.nf:], self._work[2][self.model.free]])

    def record(self, t: float, y: np.ndarray) -> np.ndarray:
        self._eval(t, y)
        forces, out = self._work[4], self._work[5]
        return np.concatenate([out[:3], forces, out[3:7]])


def lumped_rhs(model: LumpedModel, compiled: bool = True) -> LumpedRHS:
    """f(t, y) of the lumped model on its compiled kernel (``compiled=False``: the same kernel
    interpreted by Python, numba's ``py_func``: a plain-Python/numpy baseline)."""
    return LumpedRHS(model, None if compiled else _evaluate.py_func)
