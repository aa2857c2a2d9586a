"""Deflection signals of a run: loaded transmission error and the flexible gears' elastic deflection per mesh.

Post-processing of the stored sensors (no Python per step), optional signal columns of
flexgear.results.signal_columns:

- ``transmission_error_m``: loaded transmission error along the line of action at the output,
  TE = r_out (theta_out,kin - theta_out) sign(omega_out) (r_out: flexgear.design.Design.output_radius),
  theta_out,kin = i theta_in (i = omega_out/omega_in
  of the theory), theta_in the prescribed drive angle at the input seat, theta_out the output's spin where the
  load acts (its seat interface for a flexible output shaft): rigid and elastic, positive when the output lags.
  Its mean at steady speed is the loaded static transmission error.
- ``{outer,inner}_deflection_{load,centrifugal}_{i}_m``: elastic deflection of the flexible gears of mesh i
  along the tooth normal at the contact (mean of the helix halves), the amount by which the gears yield away
  from each other (positive: the mesh approach is reduced), measured relative to each gear's seat interface
  (bore of sun and planet, the ring's joint interfaces to the output shaft: flexgear.fe.reduced.gear_seat), not
  its floating frame. Split:
  centrifugal = the quasi-static response to the spin with the gear's joint interfaces held (its shaft taken as
  stiff: rigid bolt patches restrain the ring's growth, an RBE3 bore or bolt circle does not, its mean motion
  being zero), K_r q_c = omega^2 Q_c - G^T mu, G q_c = 0, G the interfaces' motions, with
  Q_c,j = sum_i m_i (x_i psi_ij,x + y_i psi_ij,y) (the zz entry of the FFRF invariant mXRefTildePsiTilde);
  load = the rest (mesh, bearing and joint forces).
"""

from __future__ import annotations

import math

import numpy as np

from flexgear.fe.reduced import BOLT_PATCHES, gear_seat, is_tied
from flexgear.laws.ramps import drive_angle
from flexgear.mbs.bodies import frame_rows, normal_lever
from flexgear.spec import COMPONENT_GEOMETRY

__all__ = ["transmission_error", "centrifugal_modal_load", "centrifugal_response", "held_interfaces",
           "mesh_deflection_signals"]

def transmission_error(model, time_s: np.ndarray, output_angle: np.ndarray) -> np.ndarray:
    """TE [m] (module docstring) from the output's spin angle [rad] at the load point, at times ``time_s``."""
    spec, th = model.spec, model.theory
    lc = spec.load_case
    theta_in = np.asarray(drive_angle(np.asarray(time_s), lc.ramp_time_s, lc.input_speed_rad_s), float)
    r_out = model.design.output_radius
    sign = math.copysign(1.0, th.output_speed)
    return r_out * (th.ratio * theta_in - np.asarray(output_angle, float)) * sign


def centrifugal_modal_load(reduced) -> np.ndarray:
    """Q_c [N per (rad/s)^2 per modal unit], (m,): the modal force of spinning at omega about z is omega^2 Q_c."""
    inv = np.asarray(reduced.invariants["mXRefTildePsiTilde"], float)
    return inv[2, 2::3].copy()


def centrifugal_response(reduced, held: list[str]) -> np.ndarray:
    """q_c per (rad/s)^2 (m,): the static response to spinning with the interfaces ``held`` following one common
    rigid motion r (as their joints to a shaft hold them), free of the mean-axis frame:

        Lambda q = Q_c - P^T mu,   P q + R r = 0,   R^T mu = 0

    (P the interfaces' RBE3 motions per mode, ``reduced.interface_motion``; R = [I, -p~; 0, I] their motions per
    frame translation and rotation at their points p). One interface: the free-free deformation (a
    self-equilibrated load on a statically determinate hold). Several (a ring's twelve bolt patches): they may
    shift and turn together against the mean axes; holding each at zero (r = 0) missed a load-free 0.28 um of the
    bolt-patched ring's deflection at the meshes, which the multibody model (FFRF or linear) shows.
    """
    p = np.vstack([reduced.interface_motion(n) for n in held])
    r = np.vstack([frame_rows(reduced.interface(n).point) for n in held])
    m, k = reduced.n_modes, p.shape[0]
    a = np.zeros((m + 6 + k, m + 6 + k))
    a[:m, :m] = np.diag(reduced.stiffness)
    a[:m, m + 6:] = p.T
    a[m:m + 6, m + 6:] = r.T
    a[m + 6:, :m] = p
    a[m + 6:, m:m + 6] = r
    rhs = np.concatenate([centrifugal_modal_load(reduced), np.zeros(6 + k)])
    return np.linalg.solve(a, rhs)[:m]


def held_interfaces(reduced, geometry: str) -> list[str]:
    """Interfaces of a gear's reduced body held in its centrifugal response: where the multibody model holds it.
    The bore; the ring at its bolt patches, or, tied to the output shaft (flexgear.fe.ring_shaft), at the
    shaft's bearing seat."""
    if geometry != "ring":
        return ["bore"]
    return ["bearing_seat"] if is_tied(reduced) else [BOLT_PATCHES]


def _body_geometry(name: str) -> str:
    return COMPONENT_GEOMETRY.get(name.rstrip("0123456789"), name.rstrip("0123456789"))


def mesh_deflection_signals(model, time_s: np.ndarray, modal: dict[str, np.ndarray],
                            residual: np.ndarray | None = None,
                            seat_residual: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Columns ``{outer,inner}_deflection_{load,centrifugal}_{i}_m`` of the flexible gears (module docstring).

    ``modal``: {body name: (n_times, n_modes) modal coordinates}. Gear spin angles are the nominal ones
    (spin per drive angle x prescribed angle), as the contact kinematics uses them. ``residual``: (n_times,
    n) residual deflections e of the contacts ``model.residual.rows`` (flexgear.mbs.residual: the static,
    seat-relative answer of the modes above the dynamic cut-off to the mesh forces and the spin); they add
    to the load and centrifugal parts. ``seat_residual``: (n_times, 6 n_seats) the seat motions e_s of
    ``model.residual.seat_bodies`` (ground axes, at their bearing centres), whose gears' e are relative to their
    frames: their contacts' deflections are taken relative to the seat through the rigid lever (n, (x - c) x n).
    """
    kin = model.kinematics
    lc = model.spec.load_case
    t = np.asarray(time_s, float)
    theta = np.asarray(drive_angle(t, lc.ramp_time_s, lc.input_speed_rad_s), float)
    rate = np.gradient(theta, t) if len(t) > 1 else np.zeros_like(t)
    n_contacts = len(model.contacts)
    total = np.zeros((len(t), n_contacts))
    centrifugal = np.zeros((len(t), n_contacts))
    offsets = {}
    for j, contact in enumerate(model.contacts):
        for body_name, sign, spin in ((contact.body1, 1.0, contact.spin_per_drive_angle[0]),
                                      (contact.body2, -1.0, contact.spin_per_drive_angle[1])):
            body = model.bodies[body_name]
            if not body.flexible:
                continue
            red = body.reduced
            if body_name not in offsets:
                geometry = _body_geometry(body_name)
                joints = held_interfaces(red, geometry)
                dropped = getattr(body, "dropped", None)  # truncated: the whole basis' answer (flexgear.mbs.residual)
                q_c_unit = (dropped.centrifugal_held[:red.n_modes] if dropped is not None else
                            centrifugal_response(red, joints))
                seat = gear_seat(red, geometry)
                # in the body's coordinates q~, as the contact tables and the recorded coordinates
                offsets[body_name] = (body.to_coordinates(red.interface_motion(seat)), seat.point,
                                      body.coordinates_of(q_c_unit))
            motion, p_seat, q_c_unit = offsets[body_name]
            row = _column_row(kin, j, body_name)
            ang = kin.spin[row] * theta  # nominal spin angle of the body relative to the contacts (the carrier)
            rel = np.asarray(contact.point, float) - body.position
            ca, sa = np.cos(ang), np.sin(ang)
            # contact point and tooth normal in the body frame: R(-ang) x
            x_b = np.stack([ca * rel[0] + sa * rel[1], -sa * rel[0] + ca * rel[1], np.full_like(ang, rel[2])], 1)
            nrm = np.asarray(contact.normal, float)
            n_b = np.stack([ca * nrm[0] + sa * nrm[1], -sa * nrm[0] + ca * nrm[1], np.full_like(ang, nrm[2])], 1)
            g = normal_lever(x_b, n_b, p_seat)  # (T, 6) seat rigid motion -> normal at contact
            coeff = _column_values(kin, row, theta) - g @ motion  # (T, m): relative to the seat
            q = modal[body_name]
            total[:, j] += sign * np.einsum("tm,tm->t", coeff, q)
            q_c = (spin * rate)[:, None] ** 2 * q_c_unit[None, :]
            centrifugal[:, j] += sign * np.einsum("tm,tm->t", coeff, q_c)
    if residual is not None:  # e > 0 is a yield: it reduces the penetration; its centrifugal part y(t) likewise
        rows = model.residual.rows
        total[:, rows] -= residual
        # the residual coordinates carry the dropped modes' free centrifugal yield y; the split takes the whole
        # basis' joint-held answer instead (flexgear.mbs.residual: y')
        centrifugal[:, rows] -= (rate ** 2)[:, None] * model.residual.split_yield_per_drive_speed2[rows][None, :]
        _seat_relative(model, total, centrifugal, rate, seat_residual)
    out = {}
    for kind in ("outer", "inner"):
        groups: dict[int, list[int]] = {}
        for j, c in enumerate(model.contacts):
            if c.name.startswith(f"{kind}_mesh_"):
                groups.setdefault(int(c.name.split("_")[2]), []).append(j)
        for i, rows in sorted(groups.items()):
            # the elastic terms enter the penetration with the sign that reduces it when the gears yield
            cent = -centrifugal[:, rows].mean(1)
            out[f"{kind}_deflection_load_{i}_m"] = -total[:, rows].mean(1) - cent
            out[f"{kind}_deflection_centrifugal_{i}_m"] = cent
    return out


def _seat_relative(model, total: np.ndarray, centrifugal: np.ndarray, rate: np.ndarray,
                   seat_residual: np.ndarray | None) -> None:
    """Subtract the seats' residual motion e_s (seat_bodies' contacts, mesh_deflection_signals) in place."""
    res = model.residual
    if not res.seat_bodies:
        return
    split = res.split_yield_per_drive_speed2[res.n_contacts:]
    for s, (name, centre) in enumerate(zip(res.seat_bodies, res.seat_centres, strict=True)):
        cols = slice(6 * s, 6 * s + 6)
        for j, contact in enumerate(model.contacts):
            sign = 1.0 if contact.body1 == name else -1.0 if contact.body2 == name else 0.0
            if sign == 0.0:
                continue
            lever = normal_lever(contact.point, contact.normal, centre)
            total[:, j] -= sign * seat_residual[:, cols] @ lever
            centrifugal[:, j] -= sign * (rate ** 2) * (split[cols] @ lever)


def _column_row(kin, contact: int, body: str) -> int:
    """Index of the (contact, body) modal column in ``kin`` (flexgear.mbs.contact_kinematics.ContactKinematics)."""
    for k in range(len(kin.rows)):
        if kin.rows[k] == contact and kin.bodies[k] == body:
            return k
    raise KeyError(f"no modal column for contact {contact} on body {body!r}")


def _column_values(kin, k: int, theta: np.ndarray) -> np.ndarray:
    """c(alpha(t)) of modal column k, (T, m), interpolated as ContactKinematics.matrix_at does."""
    alpha = np.mod(kin.psi[k] - kin.spin[k] * theta, 2 * np.pi) * (kin.n_grid / (2 * np.pi))
    i0 = np.floor(alpha).astype(int) % kin.n_grid
    w = (alpha - np.floor(alpha))[:, None]
    table = kin.tables[k, :, :kin.n_modes[k]]
    return (1 - w) * table[i0] + w * table[(i0 + 1) % kin.n_grid]
