"""Static residual compliance of the modes a flexible gear leaves out of the time integration.

A gear's converged basis (flexgear.fe.reduced: fixed-interface modes plus the attachment modes of its
contact bands) has modes far above the mesh frequency: a 44-tooth sun has 4 modes below 17.6 kHz and 59
above. Those high modes answer a mesh force quasi-statically, so they can leave the dynamic
coordinates and return as a static compliance in series with the contact law (the mode-acceleration
method). The gear's seat (bore, the ring's joint interfaces: flexgear.fe.reduced.gear_seat) carries the reaction, so
the load set of a unit contact force is the force plus its rigid reaction at the seat, self-equilibrated;
with mass-normalised free-free modes psi_j (omega_j^2 = lambda_j) its modal load and the contact's
seat-relative deflection share the row

    a_ij(alpha) = s_i (c_ij(alpha) - g_i(alpha) . Psi_seat,j)

(s_i = +1 for gear 1 of the contact, -1 for gear 2; c_i(alpha) the contact's Fourier-kernel coefficients,
flexgear.mbs.contact_kinematics; g_i = (n, (x - p_seat) x n) the contact's rigid lever to the seat,
Psi_seat the seat's RBE3 motion), and the dropped modes add the compliance and the centrifugal yield

    C_ik = sum_{j dropped} a_ij a_kj / lambda_j,   y_i = -(spin Omega)^2 sum_{j dropped} a_ij Q_c,j / lambda_j

(Q_c: flexgear.mbs.deflection.centrifugal_modal_load; the dropped modes' free answer to the spin, the joint
reactions being carried by the kept modes). The deflection signals split off the centrifugal part as the
whole basis' static answer u per (rad/s)^2 with the gear's joints held (flexgear.mbs.deflection; held on the
kept modes alone it is ill-posed): its kept components u_j, j < keep, give the kept modes' part, the dropped
ones the correction y'_i = -(spin Omega)^2 sum_{j dropped} a_ij u_j. Summed over all modes, C is the full basis' static
compliance of the contacts relative to the seat. C and y depend on the gear's spin through alpha = psi -
phi; they are averaged over phi (a gear blank is nearly axisymmetric; ``spread`` says how far). The
contacts' residuals of all gears add up to one symmetric C over the contacts; its inverse is the constant
stiffness of a massless coordinate vector e (one entry per contact that has one), in series with each
contact law: the law acts on the tooth deflection delta - e, and K e = F + K y(t). The dynamic seat
reaction is taken as the quasi-static one (the gear's own inertia does not share it).

Damping. The modal coordinates carry stiffness-proportional damping D = beta K (``[reduction_assumed]
modal_stiffness_damping_s``), so a dropped mode obeys lambda_j (q_j + beta q_j') + q_j'' = a_j F: its
damping-to-stiffness ratio is beta whatever its frequency, and at the mesh frequency omega its quasi-static
answer is (1 + i beta omega)^-1 a_j F / lambda_j (beta omega = 0.28 at 4.4 kHz and beta = 1e-5 s: 4 % in
amplitude, 15 degrees in phase, for every dropped mode alike). The residual therefore keeps the dropped
modes' damping as well as their stiffness and Ritz mass, to the same order:

    M_e e'' + D_e e' + K e = F + K y,   K = C^-1,   D_e = K B K,   B_ik = sum_{j dropped} beta a_ij a_kj / lambda_j,
    M_e = K (sum_{j dropped} a_ij a_kj / lambda_j^2) K

(B = beta C when every gear has the same beta, so D_e = beta K: exact for massless dropped modes).

Seats that carry a bearing of their own (``seats``: the planets on their linear seat bearings,
flexgear.mbs.joints.LinearSeat). Above the bearing's own frequency (planet on its Table 2 bearing: about
1.6 kHz against the 4.4 kHz mesh frequency) the gear's inertia, not the seat, takes most of a load that
varies at the mesh frequency, so the quasi-static seat reaction above is wrong at 1x (model 5, planet-ring
load deflection 1x +26 % against every mode dynamic). Such a gear's dropped modes answer the loads they
really carry, the contact forces and the bearing's force F_s at the seat, with rows relative to the body frame
and six more coordinates e_s, the dropped modes' motion of the seat in ground axes (translation at the
bearing centre, rotation), on which the bearing acts in series (its seat coordinates s = kept motion + e_s):

    b_j = [a_j; -r_j],   a_ij = s_i c_ij(alpha),   r_j = blockdiag(R(phi), R(phi)) Psi_bearing,j

and [e; e_s] = (sum_j b_j b_j^T / lambda_j) [F; F_s] (the mode-acceleration method on every load the gear
carries; with F_s the quasi-static reaction it equals the seat-relative form above: tests/test_residual.py).
The gear's inertia loads only its frame: flexible free-free modes are mass-orthogonal to the rigid ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexgear.fe.reduced import contact_fit_window
from flexgear.laws.compiled import bound_entry, ramp_state
from flexgear.mbs.bodies import matrix_container, motion_at_point, normal_lever, resting_node, zero_user_jacobian
from flexgear.mbs.contact_kinematics import modal_contact_coefficients
from flexgear.mbs.deflection import centrifugal_modal_load, centrifugal_response, held_interfaces

__all__ = ["DroppedModes", "dropped_modes", "ResidualCompliance", "residual_compliance", "add_residual_coordinates",
           "CentrifugalYield"]


@dataclass(frozen=True)
class DroppedModes:
    """The modes of a gear's basis above its dynamic cut-off, with what the residual needs of them."""

    modes: np.ndarray  # (3n, m) every mode of the basis, body frame
    stiffness: np.ndarray  # lambda_j = omega_j^2 [1/s^2], (m,)
    keep: int  # modes 0..keep-1 are integrated, keep.. are dropped
    seat_motion: np.ndarray  # (6, m) RBE3 translation [m] and rotation [rad] of the seat per mode
    seat_point: np.ndarray  # (3,) [m] body frame
    centrifugal: np.ndarray  # Q_c / lambda on the dropped modes, 0 on the kept (m,) [per (rad/s)^2]
    centrifugal_held: np.ndarray  # u (m,) [modal units per (rad/s)^2], the whole basis, joints held
    stiffness_damping_s: float = 0.0  # beta of the gear's modal damping D = beta K [s]

    def motion_at(self, point: np.ndarray) -> np.ndarray:
        """(6, m): the seat's translation [m] at ``point`` (body frame) and rotation [rad] per mode."""
        return motion_at_point(self.seat_motion, self.seat_point, point)


def dropped_modes(spec, full, keep: int, geometry: str) -> DroppedModes:
    """Modes ``keep:`` of gear ``geometry``'s reduced body ``full`` (flexgear.fe.cms.ReducedBody) as dropped."""
    from flexgear.fe.reduced import gear_seat

    seat = gear_seat(full, geometry)
    held = held_interfaces(full, geometry)
    whole = centrifugal_response(full, held)
    free = centrifugal_modal_load(full) / full.stiffness
    free[:keep] = 0.0
    return DroppedModes(full.modes, full.stiffness, keep, full.interface_motion(seat), np.asarray(seat.point, float),
                        free, whole, float(spec.reduction_assumed.modal_stiffness_damping_s))


@dataclass(frozen=True)
class ResidualCompliance:
    """The contacts' residual compliance [m/N], ``matrix`` (n_contacts, n_contacts), spin-averaged, and their
    centrifugal yield per (rad/s)^2 of the drive, ``yield_per_drive_speed2`` (n_contacts,) [m s^2].

    ``spread``: max |C(phi) - C| over the sampled spin angles phi, relative to max diag(C) (0 for an
    axisymmetric gear); ``rows``: contacts with a residual (the coordinate vector e spans them).
    """

    matrix: np.ndarray
    yield_per_drive_speed2: np.ndarray
    spread: float
    split_yield_per_drive_speed2: np.ndarray | None = None  # y' per (rad/s)^2 of the drive (module docstring)
    mass_moment: np.ndarray | None = None  # sum_j a_ij a_kj / lambda_j^2 [m s^2/N]; C^-1 (this) C^-1: Ritz mass [kg]
    damping_moment: np.ndarray | None = None  # sum_j beta a_ij a_kj / lambda_j [m s/N]; C^-1 (this) C^-1: damping
    # bodies whose seat has coordinates e_s of its own (module docstring), in order: six rows each after the
    # contacts', translation at the bearing centre ``seat_centres`` [m] (ground) and rotation, ground axes
    seat_bodies: tuple[str, ...] = ()
    seat_centres: np.ndarray | None = None  # (n_seats, 3) [m]

    @property
    def n_contacts(self) -> int:
        return self.matrix.shape[0] - 6 * len(self.seat_bodies)

    @property
    def rows(self) -> np.ndarray:
        """Contacts with a residual (the contact part of the coordinates)."""
        return np.flatnonzero(np.diag(self.matrix)[:self.n_contacts] > 0.0)

    @property
    def coordinates(self) -> np.ndarray:
        """Rows of ``matrix`` that are coordinates: the contacts :attr:`rows`, then six per seat."""
        return np.concatenate([self.rows, self.n_contacts + np.arange(6 * len(self.seat_bodies))])


def residual_compliance(contacts, bodies: dict, dropped: dict[str, DroppedModes], order: int,
                        radial_band: float, n_angles: int = 72,
                        seats: dict[str, np.ndarray] | None = None) -> ResidualCompliance:
    """Residual compliance and centrifugal yield of the contacts (module docstring) from the gears' dropped modes.

    ``contacts``: flexgear.mbs.contacts.GearContact list (rows of the contact constraint); ``bodies``: {name:
    Body}; ``dropped``: {body name: :class:`DroppedModes`}; ``order`` and ``radial_band`` [m]: the contact
    kernel's Fourier order and band (as the dynamic modal columns). ``n_angles`` spin angles over one
    revolution are averaged. ``seats``: {body name: bearing centre [m], body frame} of the gears whose seat
    bearing carries their dropped modes' seat motion (module docstring); the others' rows are seat-relative.
    """
    seats = seats or {}
    seat_bodies = tuple(seats)
    bare = [b for b in seat_bodies if b not in dropped or not any(b in (c.body1, c.body2) for c in contacts)]
    if bare:  # their seat coordinates would have no stiffness
        raise ValueError(f"seats {bare} carry residual coordinates but have no dropped modes at a contact")
    n_contacts = len(contacts)
    n_c = n_contacts + 6 * len(seat_bodies)
    total, cent, second = np.zeros((n_c, n_c)), np.zeros(n_c), np.zeros((n_c, n_c))
    damped = np.zeros((n_c, n_c))
    split = np.zeros(n_c)
    spread = 0.0
    for name, d in dropped.items():
        body = bodies[name]
        rows, parts = [], []
        for i, c in enumerate(contacts):
            for body_name, sign, spin in ((c.body1, 1.0, c.spin_per_drive_angle[0]),
                                          (c.body2, -1.0, c.spin_per_drive_angle[1])):
                if body_name != name:
                    continue
                rel = np.asarray(c.point) - body.position
                point, half, width = contact_fit_window(getattr(body, "contact_band", None), rel, 0.5 * c.half_width,
                                                        radial_band)
                table = modal_contact_coefficients(body.reduced.nodes, d.modes, point, c.normal, half, width, order)
                rows.append(i)
                parts.append((table, sign, spin, rel, np.asarray(c.normal, float)))
        if not rows:
            continue
        centre = seats.get(name)
        n_rows = len(rows)
        if centre is not None:
            first = n_contacts + 6 * seat_bodies.index(name)
            rows += list(range(first, first + 6))
        samples = [_rows_at(p, parts, d, centre) for p in 2 * np.pi * np.arange(n_angles) / n_angles]
        k = d.keep
        comp = np.stack([(a[:, k:] / d.stiffness[k:]) @ a[:, k:].T for a in samples])
        mean = comp.mean(axis=0)
        contact_part = (comp - mean)[:, :n_rows, :n_rows]
        spread = max(spread, float(np.abs(contact_part).max() / np.abs(np.diag(mean)[:n_rows]).max()))
        total[np.ix_(rows, rows)] += mean
        damped[np.ix_(rows, rows)] += d.stiffness_damping_s * mean
        second[np.ix_(rows, rows)] += np.mean([(a[:, k:] / d.stiffness[k:] ** 2) @ a[:, k:].T for a in samples],
                                              axis=0)
        spins2 = np.array([p[2] ** 2 for p in parts] + [parts[0][2] ** 2] * (len(rows) - n_rows))
        cent[rows] -= spins2 * np.mean([a @ d.centrifugal for a in samples], axis=0)
        split[rows] -= spins2 * np.mean([a[:, k:] @ d.centrifugal_held[k:] for a in samples], axis=0)
    centres = np.array([bodies[b].position + np.asarray(seats[b], float) for b in seat_bodies]).reshape(-1, 3)
    return ResidualCompliance(0.5 * (total + total.T), cent, spread, split, 0.5 * (second + second.T),
                              0.5 * (damped + damped.T), seat_bodies, centres)


def _rows_at(phi: float, parts: list, d: DroppedModes, seat_centre: np.ndarray | None = None) -> np.ndarray:
    """Rows a_i(phi) (module docstring) of one gear's contacts at its spin angle phi [rad]; with a
    ``seat_centre`` (body frame) [m] the rows relative to the body frame, then the seat's six rows -r_j."""
    c, s = np.cos(phi), np.sin(phi)
    rot = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # ground -> body frame at spin phi
    out = []
    for table, sign, _, rel, normal in parts:
        n_grid = table.shape[0]
        x = np.mod(np.arctan2(rel[1], rel[0]) - phi, 2 * np.pi) * n_grid / (2 * np.pi)
        i0 = int(np.floor(x)) % n_grid
        w = x - np.floor(x)
        kernel = (1 - w) * table[i0] + w * table[(i0 + 1) % n_grid]
        if seat_centre is not None:
            out.append(sign * kernel)
            continue
        out.append(sign * (kernel - normal_lever(rot @ rel, rot @ normal, d.seat_point) @ d.seat_motion))
    if seat_centre is None:
        return np.array(out)
    motion = d.motion_at(seat_centre)  # body frame -> ground axes: R(phi)^T = rot.T
    return np.vstack([np.array(out), -rot.T @ motion[:3], -rot.T @ motion[3:]])


def add_residual_coordinates(mbs, residual: ResidualCompliance,
                             seat_nodes: tuple[int, ...] = ()) -> tuple[int, int, dict[int, int]]:
    """A coordinate per contact with a residual, held by the constant stiffness K = C^-1 with the dropped modes'
    Ritz mass and damping (one ``ObjectGenericODE2``, module docstring). ``seat_nodes``: the six-coordinate node
    e_s of each of ``residual.seat_bodies`` (made by flexgear.mbs.joints.LinearSeat). Returns the contacts' node,
    the object (its ``forceVector`` K y(t) carries the centrifugal yield: :class:`CentrifugalYield`) and {contact
    row: marker of its coordinate}: the contact law's spring acts between that marker and the contact's
    deflection coordinate."""
    from exudyn.itemInterface import MarkerNodeCoordinate, ObjectGenericODE2

    if len(seat_nodes) != len(residual.seat_bodies):
        raise ValueError(f"{len(residual.seat_bodies)} seats with a residual ({residual.seat_bodies}) but "
                         f"{len(seat_nodes)} seat nodes")
    rows, coords = residual.rows, residual.coordinates
    n = len(coords)
    stiffness = np.linalg.inv(residual.matrix[np.ix_(coords, coords)])
    stiffness = 0.5 * (stiffness + stiffness.T)

    def through_stiffness(moment: np.ndarray | None) -> np.ndarray:
        """K (moment) K on the coordinates, symmetric (zero without a moment)."""
        if moment is None:
            return np.zeros((n, n))
        out = stiffness @ moment[np.ix_(coords, coords)] @ stiffness
        return 0.5 * (out + out.T)

    mass = through_stiffness(residual.mass_moment)  # Ritz mass of the static residual shapes (module docstring)
    damping = through_stiffness(residual.damping_moment)  # the dropped modes' beta K damping (module docstring)
    node = resting_node(mbs, "mesh_residual_deflections", len(rows))
    dense = bool(seat_nodes)  # K = C^-1 fills the block: Exudyn's dense product is the cheaper then
    obj = mbs.AddObject(ObjectGenericODE2(name="mesh_residual_compliance", nodeNumbers=[node, *seat_nodes],
                                          massMatrix=matrix_container(mass, dense),
                                          stiffnessMatrix=matrix_container(stiffness, dense),
                                          dampingMatrix=matrix_container(damping, dense),
                                          forceVector=np.zeros(n), jacobianUserFunction=zero_user_jacobian(n, dense)))
    markers = {int(r): mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=k)) for k, r in enumerate(rows)}
    return node, obj, markers


class CentrifugalYield:
    """Pre-step function: the residual coordinates' force vector K y(t), y = Omega_drive(t)^2 y_1 (module
    docstring), Omega_drive the prescribed STEP speed ramp [rad/s] at the step's end time."""

    def __init__(self, residual: ResidualCompliance, obj: int, ramp_time: float, drive_speed: float):
        coords = residual.coordinates
        self.obj, self.ramp_time, self.drive_speed = obj, float(ramp_time), drive_speed
        self.unit = np.linalg.solve(residual.matrix[np.ix_(coords, coords)], residual.yield_per_drive_speed2[coords])
        self._steady = False
        self._force = np.empty_like(self.unit)  # the step's load, written in place (Exudyn copies it)
        self._ramp = None  # ramp_state's compiled entry (first call)

    def force(self, t: float) -> np.ndarray:
        """K y(t) [N]."""
        return (self.drive_speed * ramp_state(float(t), self.ramp_time)[1]) ** 2 * self.unit

    def __call__(self, mbs, t: float) -> bool:
        if t > self.ramp_time and self._steady:  # constant after the ramp: written once
            return True
        ramp = self._ramp
        if ramp is None:
            ramp = self._ramp = bound_entry(ramp_state, (float(t), float(self.ramp_time)))
        # the numbers of :meth:`force`, without temporaries
        np.multiply((self.drive_speed * ramp(t, self.ramp_time)[1]) ** 2, self.unit, out=self._force)
        mbs.SetObjectParameter(self.obj, "forceVector", self._force)
        self._steady = t > self.ramp_time
        return True
