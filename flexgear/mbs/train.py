"""A gear train in an Exudyn system: linear elements, gear contacts, and their per-step updates.

:func:`add_gear_train` is the one assembly step every gearbox shares (the GTF star gearbox of
flexgear.mbs.gearbox and the examples alike). Given the bodies (rigid or flexible, each on its frame
node), the bearings on body frames (flexgear.geometry.elements.BearingElement) and the gear contacts, it adds

- one ``ObjectGenericODE2`` with all bearing matrices over the frame coordinates,
- the contacts (flexgear.mbs.contacts.add_gear_contacts): one auxiliary deflection coordinate each,
  their linear kinematics (one constraint per gear pair), one compiled impact law each,
- for flexible gears, the per-step modal columns of the constraint (flexgear.mbs.contact_kinematics),
- for a rotating carrier, the per-step turning of the contact geometry (flexgear.mbs.carrier),
- tooth friction as a per-step generalized load (flexgear.mbs.contacts.MeshFriction), if mu > 0,

and chains the pre-step functions. The nominal drive (ramp time, final speed) fixes the mesh phase
and the nominal angles the updates use.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexgear.mbs.bodies import Body
from flexgear.mbs.carrier import Carrier, CarrierKinematics
from flexgear.mbs.contacts import GearContact, MeshFriction, add_gear_contacts
from flexgear.mbs.elements import add_linear_elements
from flexgear.mbs.mesh_constraint import MeshConstraint

__all__ = ["GearTrain", "add_gear_train", "contact_sensing_rows", "modal_columns"]


@dataclass
class GearTrain:
    """Handles of an assembled gear train."""

    bodies: dict[str, Body]
    contacts: list[GearContact]
    springs: list[int]  # per contact: spring-damper whose Force output is the normal force [N]
    aux_nodes: list[int]  # nodes of the contacts' deflection coordinates, one per gear pair, consecutive
    constraint: MeshConstraint  # the linear mesh kinematics (one Exudyn constraint per gear pair)
    frame_elements: int  # ObjectGenericODE2 of the bearings on body frames
    coordinates_marker: int
    kinematics: object | None = None  # flexgear.mbs.contact_kinematics.ContactKinematics (flexible gears)
    carrier: CarrierKinematics | None = None
    friction: MeshFriction | None = None
    residual: object | None = None  # flexgear.mbs.residual.ResidualCompliance of the gears' dropped modes
    residual_node: int = -1  # node of the residual deflections e (one per contact in residual.rows)
    seat_residual_nodes: tuple[int, ...] = ()  # e_s node of each of residual.seat_bodies, in order

    def springs_named(self, prefix: str) -> list[int]:
        """Spring-dampers of the contacts whose name starts with ``prefix`` (e.g. all helix halves of a mesh)."""
        out = [s for s, c in zip(self.springs, self.contacts, strict=True) if c.name.startswith(prefix)]
        if not out:
            raise KeyError(f"no contact named {prefix!r}...; contacts: {[c.name for c in self.contacts]}")
        return out


def modal_columns(contacts: list[GearContact], bodies: dict[str, Body], order: int, radial_band: float,
                  carrier_spin: float = 0.0) -> list:
    """Contact-deflection coefficients of the flexible gears' modal coordinates (contact_kinematics).

    ``carrier_spin``: the carrier's nominal spin per drive angle. The contact points turn with the carrier, so the
    material angle of a contact on a gear is alpha = psi - (spin - carrier_spin) theta (theta the drive angle), for
    the central gears and for the planets, whose contact points sit still in the carrier's frame."""
    from flexgear.fe.reduced import contact_fit_window
    from flexgear.mbs.contact_kinematics import ModalColumn, modal_contact_coefficients

    columns = []
    for row, c in enumerate(contacts):
        for name, sign, spin in ((c.body1, 1.0, c.spin_per_drive_angle[0]), (c.body2, -1.0, c.spin_per_drive_angle[1])):
            body = bodies[name]
            if not body.flexible:
                continue
            rel = np.asarray(c.point) - body.position
            point, half, band = contact_fit_window(getattr(body, "contact_band", None), rel, 0.5 * c.half_width,
                                                   radial_band)
            values = body.to_coordinates(modal_contact_coefficients(body.reduced.nodes, body.reduced.modes, point,
                                                                    c.normal, half, band, order))
            columns.append(ModalColumn(row, name, sign, float(np.arctan2(rel[1], rel[0])), spin - carrier_spin,
                                       values))
    return columns


def contact_sensing_rows(reduced, name: str, position: np.ndarray, contacts: list[GearContact], order: int,
                         radial_band: float, band: object | None = None) -> np.ndarray:
    """Orthonormal rows (r, m) spanning the Fourier coefficients (flexgear.mbs.contact_kinematics.
    modal_contact_fourier) of every contact of body ``name`` (a flexgear.fe.cms.ReducedBody at ``position``
    [m]): each contact's deflection c(alpha) . q is then a combination of these r sensed coordinates only
    (flexgear.mbs.flexible.interface_basis). r <= 2 (2 order + 1) per distinct band and normal (the planets'
    contacts on a ring are turned copies). Singular values below 1e-9 of the largest are round-off. ``band``: the
    gear's ``contact_band`` selector (flexgear.fe.reduced.contact_fit_window), None for the gear data's band."""
    from flexgear.fe.reduced import contact_fit_window
    from flexgear.mbs.contact_kinematics import modal_contact_fourier

    coefs = [modal_contact_fourier(reduced.nodes, reduced.modes, point, c.normal, half, width, order)
             for c in contacts if name in (c.body1, c.body2)
             for point, half, width in [contact_fit_window(band, np.asarray(c.point) - position, 0.5 * c.half_width,
                                                           radial_band)]]
    if not coefs:
        return np.zeros((0, reduced.n_modes))
    _, sv, vt = np.linalg.svd(np.vstack(coefs), full_matrices=False)
    return vt[:int(np.count_nonzero(sv > 1e-9 * sv[0]))]


def add_gear_train(mbs, bodies: list[Body], elements: list, contacts: list[GearContact], ramp_time: float,
                   drive_speed: float, *, friction: bool = True,
                   carrier: Carrier | None = None, contact_fourier_order: int = 8,
                   radial_band: float | None = None, extra_pre_steps: list | None = None,
                   seat_residuals: dict[str, tuple[int, np.ndarray]] | None = None) -> GearTrain:
    """Add the bearings ``elements`` (flexgear.geometry.elements.BearingElement, on body frames), the gear
    ``contacts`` and their per-step updates for ``bodies``.

    ``ramp_time`` [s] and ``drive_speed`` [rad/s]: the prescribed STEP speed ramp whose angle
    (flexgear.mbs.contacts.drive_angle) drives the mesh phase. ``friction``: add tooth friction for
    contacts with mu > 0. ``carrier``: a rotating carrier (planetary stage; the carrier rigid or flexible): the
    contacts' geometry turns with it (flexgear.mbs.carrier), and the flexible gears' material angles under the
    contacts follow their spin relative to it (:func:`modal_columns`).
    Flexible gears: ``contact_fourier_order`` harmonics fit their mode shapes round the contact circle,
    from mesh nodes within ``radial_band`` [m] of it (required then; about one normal module, half the
    tooth height). ``extra_pre_steps``: further pre-step callables (mbs, t) -> bool, run first.
    ``seat_residuals``: {body: (node of its seat's residual motion e_s, bearing centre [m] in the body frame)}
    of the gears whose seat bearing carries their dropped modes' seat motion (flexgear.mbs.residual). Sets the
    system's pre-step user function if any update is needed.
    """
    by_name = {b.name: b for b in bodies}
    if len(by_name) != len(bodies):
        raise ValueError(f"body names must be unique: {[b.name for b in bodies]}")
    for c in contacts:
        for name in (c.body1, c.body2):
            if name not in by_name:
                raise KeyError(f"contact {c.name!r} names unknown body {name!r}; bodies: {sorted(by_name)}")
    flexible = [b for b in bodies if b.flexible]
    offsets, n_total = {}, 6 * len(bodies)
    for b in flexible:
        offsets[b.name] = n_total
        n_total += b.reduced.n_modes
    if flexible and radial_band is None:
        raise ValueError(f"flexible bodies {[b.name for b in flexible]} need radial_band [m] (about one normal module)")
    frame_elements, coords = add_linear_elements(mbs, bodies, elements)
    dropped = {b.name: b.dropped for b in flexible if getattr(b, "dropped", None) is not None}
    residual, residual_node, markers, seat_nodes = None, -1, None, ()
    seats = seat_residuals or {}
    if dropped or seats:
        from flexgear.mbs.residual import add_residual_coordinates, residual_compliance

        residual = residual_compliance(contacts, by_name, dropped, contact_fourier_order, radial_band,
                                       seats={b: centre for b, (_, centre) in seats.items()})
        seat_nodes = tuple(seats[b][0] for b in residual.seat_bodies)
        if residual.rows.size:
            residual_node, residual_obj, markers = add_residual_coordinates(mbs, residual, seat_nodes)
        else:
            residual = None
    springs, aux, constraint, base, schedule = add_gear_contacts(mbs, bodies, contacts, ramp_time, drive_speed,
                                                                 offsets, n_total, markers)
    train = GearTrain(by_name, contacts, springs, aux, constraint, frame_elements, coords,
                      residual=residual, residual_node=residual_node, seat_residual_nodes=seat_nodes)
    pre_steps = [*(extra_pre_steps or []), *([schedule] if schedule is not None else [])]
    if markers:
        from flexgear.mbs.residual import CentrifugalYield

        pre_steps.append(CentrifugalYield(residual, residual_obj, ramp_time, drive_speed))
    carrier_spin = 0.0 if carrier is None else carrier.spin_per_drive_angle
    columns = modal_columns(contacts, by_name, contact_fourier_order, radial_band, carrier_spin) if flexible else []
    if columns:
        from flexgear.mbs.contact_kinematics import ContactKinematics

        train.kinematics = ContactKinematics(constraint, base, columns, offsets, ramp_time, drive_speed)
        constraint.set(mbs, train.kinematics.matrix_at(0.0))
        pre_steps.append(train.kinematics)
    if friction and any(c.friction_coefficient > 0.0 for c in contacts):
        train.friction = MeshFriction(mbs, bodies, frame_elements, aux, contacts, ramp_time, drive_speed,
                                      (residual_node, residual.rows) if markers else None)
    if carrier is not None:
        extra = [train.friction.sliding_rows] if train.friction is not None else []
        train.carrier = CarrierKinematics(constraint, base, bodies, carrier, ramp_time, drive_speed, extra)
        g, offset = train.carrier.matrix_and_offset(0.0)
        constraint.set(mbs, g, offset, modal=not train.carrier.modal)
        pre_steps.append(train.carrier)  # before friction: friction uses the turned sliding rows
    if train.friction is not None and schedule is not None and carrier is None:
        from flexgear.mbs.mesh_updates import MeshUpdates

        pre_steps.remove(schedule)  # both in one compiled call per step
        pre_steps.append(MeshUpdates(schedule, train.friction))
    elif train.friction is not None:
        pre_steps.append(train.friction)
    if pre_steps:
        from flexgear.mbs.contact_kinematics import PreStepChain

        mbs.SetPreStepUserFunction(PreStepChain(pre_steps) if len(pre_steps) > 1 else pre_steps[0])
    return train
