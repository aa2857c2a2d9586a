"""Gear contact on flexible gears: the elastic deflection at a contact point fixed in space.

The mesh point stays where it is while a gear spins under it, so the material point in contact
changes with the spin angle theta. A gear's elastic displacement there, projected on the tooth
normal, is a linear function of its modal coordinates q with coefficients that depend on the
material angle alpha = psi - theta (psi: angle of the contact point about the gear centre):

    delta_el = c(alpha) . q,    c_j(alpha) = (R(alpha - psi) n) . Phi_j(r, alpha, z)

(n: tooth normal in the ground frame, Phi_j: mode j in the body frame, (r, z): radius and axial
position of the contact). c(alpha) is fitted, mode by mode, as a Fourier series in alpha to the
mode shapes at the mesh nodes near the contact circle: global modes are smooth around the
circumference, and the tooth-level compliance already lives in the contact law, so a smooth fit
(rather than node-wise interpolation, which made the force noisy in the prototype) is the model.

The coefficients enter the contact's linear kinematic constraint (flexgear.mbs.contacts) as extra
columns, updated once per time step for the step's end time from the nominal spin angle of each
gear (theta = spin ratio x prescribed drive angle; the elastic vibration's own phase effect is
neglected). The deflection carried by the auxiliary coordinate is then the total one, and its
rate includes the transport of material under the contact point.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from flexgear.fe.attachment import LoadCircle, circle_band, fourier_basis, local_directions
from flexgear.laws.compiled import bound_entry, grid_position, ramp_state
from flexgear.laws.ramps import drive_angle

__all__ = ["ModalColumn", "modal_contact_coefficients", "modal_contact_fourier", "ContactKinematics", "PreStepChain"]


@dataclass(frozen=True)
class ModalColumn:
    """Coefficients of one flexible gear's modal coordinates in one contact's deflection row."""

    contact: int  # row of the contact in the kinematic constraint
    body: str
    sign: float  # +1 for gear 1 of the contact, -1 for gear 2
    contact_angle: float  # psi [rad]
    spin_per_drive_angle: float  # nominal gear spin per prescribed drive angle
    values: np.ndarray  # (n_grid, n_modes) coefficients at alpha_k = 2 pi k / n_grid [m per modal unit]


def modal_contact_fourier(nodes: np.ndarray, modes: np.ndarray, point: np.ndarray, normal: np.ndarray,
                          half_width: float, radial_band: float, order: int) -> np.ndarray:
    """Fourier coefficients (2 order + 1, n_modes) of c_j(alpha): c(alpha) = fourier_basis(alpha, order) @ them.

    ``nodes`` (n, 3) and ``modes`` (3n, m) in the body frame (gear centre at the origin, z the axis);
    ``point`` the contact point relative to the gear centre at zero spin; ``normal`` the tooth normal;
    nodes within ``radial_band`` of the contact radius and ``half_width`` of its axial position (the
    band of flexgear.fe.attachment.circle_band, the same the attachment modes load) are fitted by a
    least-squares Fourier series of ``order`` harmonics in alpha. A fit is kept with ``modes`` (while that array
    lives) and returned again, read-only, for the same arguments: a model built at many speeds or angles fits once.
    """
    fits = _fits_of(modes)
    key = (id(nodes), np.asarray(point, float).tobytes(), np.asarray(normal, float).tobytes(), float(half_width),
           float(radial_band), int(order))
    if key not in fits:
        fits[key] = _fourier_fit(nodes, modes, point, normal, half_width, radial_band, order)
        fits[key].flags.writeable = False
    return fits[key]


_FITS: dict[int, dict] = {}
"""id of a live mode array -> its fits by :func:`modal_contact_fourier`'s other arguments (dropped with the array)."""


def _fits_of(modes: np.ndarray) -> dict:
    """The fits kept for the array ``modes`` (a new dict, forgotten when the array is freed)."""
    key = id(modes)
    if key not in _FITS:
        _FITS[key] = {}
        weakref.finalize(modes, _FITS.pop, key, None)
    return _FITS[key]


def _fourier_fit(nodes: np.ndarray, modes: np.ndarray, point: np.ndarray, normal: np.ndarray, half_width: float,
                 radial_band: float, order: int) -> np.ndarray:
    """:func:`modal_contact_fourier` computed."""
    r, z, psi = math.hypot(point[0], point[1]), point[2], math.atan2(point[1], point[0])
    circle = LoadCircle(r, z - half_width, z + half_width, order, radial_band_m=radial_band)
    sel = circle_band(nodes, circle)
    alpha = np.arctan2(nodes[sel, 1], nodes[sel, 0])
    # tooth normal carried with the material point: R(alpha - psi) n, constant in the local frame
    c, s = math.cos(psi), math.sin(psi)
    local = (c * normal[0] + s * normal[1], -s * normal[0] + c * normal[1], normal[2])
    phi = modes.reshape(len(nodes), 3, -1)[sel]  # (k, 3, m)
    samples = np.einsum("kd,kdm->km", local_directions(alpha, local), phi)
    b = fourier_basis(alpha, order)
    return np.linalg.solve(b.T @ b, b.T @ samples)  # least squares by the (2N+1)^2 normal equations: fast


def modal_contact_coefficients(nodes: np.ndarray, modes: np.ndarray, point: np.ndarray, normal: np.ndarray,
                               half_width: float, radial_band: float, order: int, n_grid: int = 720
                               ) -> np.ndarray:
    """c_j(alpha) on a grid of n_grid material angles, shape (n_grid, n_modes) (:func:`modal_contact_fourier`)."""
    coef = modal_contact_fourier(nodes, modes, point, normal, half_width, radial_band, order)
    return fourier_basis(2 * np.pi * np.arange(n_grid) / n_grid, order) @ coef


@njit(cache=True)
def interpolated_entries(buffer, t, ramp_time, drive_speed, tables, dest, n_modes, signs, psi,
                         spin):  # pragma: no cover - compiled
    """The constraint blocks' modal entries at time ``t`` [s], written straight into their flat ``buffer``: the
    numbers of flexgear.laws.compiled.interpolated_columns at the drive angle theta = ``drive_speed`` x integral of
    the STEP ramp (``ramp_time`` [s]), coefficient m of column set j going to ``buffer[dest[j, m]]`` (-1: to no
    block)."""
    theta = drive_speed * ramp_state(t, ramp_time)[0]
    for j in range(dest.shape[0]):
        i0, i1, w = grid_position(psi[j] - spin[j] * theta, tables.shape[1])
        for m in range(n_modes[j]):
            k = dest[j, m]
            if k >= 0:
                buffer[k] = signs[j] * ((1.0 - w) * tables[j, i0, m] + w * tables[j, i1, m])


class ContactKinematics:
    """Pre-step update of the modal columns of the contact constraint's ``scalingMarker1``.

    ``base`` is the constant part (frame coordinates); ``columns`` say where each flexible gear's
    modal coefficients go (``column_offsets[body]``: first column of that body's modal coordinates).
    """

    def __init__(self, constraint, base: np.ndarray, columns: list[ModalColumn],
                 column_offsets: dict[str, int], ramp_time: float, drive_speed: float):
        self.constraint, self.base = constraint, base
        self.ramp_time, self.drive_speed = ramp_time, drive_speed
        width = max(c.values.shape[1] for c in columns)
        self.n_grid = columns[0].values.shape[0]
        self.tables = np.stack([np.pad(c.values, ((0, 0), (0, width - c.values.shape[1]))) for c in columns])
        self.rows = np.array([c.contact for c in columns])
        self.signs = np.array([c.sign for c in columns])
        self.psi = np.array([c.contact_angle for c in columns])
        self.spin = np.array([c.spin_per_drive_angle for c in columns])
        self.n_modes = np.array([c.values.shape[1] for c in columns])
        self.first = np.array([column_offsets[c.body] for c in columns])
        self.bodies = [c.body for c in columns]
        self.matrix = base.copy()
        # only the blocks (gear pairs) with modal columns change with the spin: their entries are gathered
        # from the matrix into one buffer in one call, each block's scaling matrix a view of it
        blocks = [constraint.blocks[i] for i in constraint.blocks_with_rows(self.rows)]
        flat = [(sub[0] * base.shape[1] + sub[1]).ravel() for _, _, sub in blocks]
        self._gather = np.concatenate(flat) if flat else np.zeros(0, dtype=np.int64)
        self._buffer = np.empty(self._gather.size)
        starts = np.cumsum([0] + [f.size for f in flat])
        self._views = [(obj, self._buffer[a:b].reshape(len(sub[0]), -1))
                       for (obj, _, sub), a, b in zip(blocks, starts[:-1], starts[1:], strict=True)]
        # the pre-step writes the modal entries straight into the buffer: entry m of column set j goes to
        # dest[j, m] (-1: a column that no block holds); the buffer's other entries keep the base values
        where = np.full(base.size, -1, dtype=np.int64)
        where[self._gather] = np.arange(self._gather.size)
        entries = self.rows[:, None] * base.shape[1] + self.first[:, None] + np.arange(width)[None, :]
        self._dest = np.where(np.arange(width)[None, :] < self.n_modes[:, None],
                              where[np.minimum(entries, base.size - 1)], -1)
        np.take(base.ravel(), self._gather, out=self._buffer)
        self._args = (float(ramp_time), float(drive_speed), self.tables, self._dest, self.n_modes, self.signs,
                      self.psi, self.spin)
        self._kernel = None  # the kernel's compiled entry for these arguments (first call)
        self.time = 0.0  # the time [s] whose entries the buffer holds

    @property
    def buffer(self) -> np.ndarray:
        """The constraint blocks' entries, flat (their scaling matrices are views of it, :attr:`views`)."""
        return self._buffer

    @property
    def views(self) -> list[tuple[int, str, np.ndarray]]:
        """(constraint, parameter, its scaling matrix: a view of :attr:`buffer`) of every gear pair's block."""
        return [(obj, "scalingMarker1", view) for obj, view in self._views]

    def buffer_at(self, t: float, out: np.ndarray) -> np.ndarray:
        """The buffer's values at time ``t`` [s] written into ``out`` (an array of its size): the entries a Jacobian
        evaluated then would hold (flexgear.mbs.newton.MidlifeJacobian)."""
        np.copyto(out, self._buffer)  # the frame columns and other constant entries
        self._bound(out, t)(out, float(t), *self._args)
        return out

    def _bound(self, buffer: np.ndarray, t: float):
        """The kernel's compiled entry for these arguments (bound at the first call)."""
        if self._kernel is None:
            self._kernel = bound_entry(interpolated_entries, (buffer, float(t), *self._args))
        return self._kernel

    def matrix_at(self, t: float) -> np.ndarray:
        """The constraint's scaling matrix (frame + modal columns) at time t (compiled; the returned
        array is overwritten by the next call)."""
        from flexgear.laws.compiled import interpolated_columns

        theta = self.drive_speed * ramp_state(float(t), self.ramp_time)[0]
        interpolated_columns(self.matrix, theta, self.tables, self.rows, self.first, self.n_modes, self.signs,
                             self.psi, self.spin)
        return self.matrix

    def reference_matrix_at(self, t: float) -> np.ndarray:
        """Same as :meth:`matrix_at` in numpy (the reference implementation); a new array."""
        theta = float(drive_angle(t, self.ramp_time, self.drive_speed))
        alpha = np.mod(self.psi - self.spin * theta, 2 * np.pi) * (self.n_grid / (2 * np.pi))
        i0 = np.floor(alpha).astype(int) % self.n_grid
        w = (alpha - np.floor(alpha))[:, None]
        i1 = (i0 + 1) % self.n_grid
        k = np.arange(len(alpha))
        values = (1 - w) * self.tables[k, i0] + w * self.tables[k, i1]
        out = self.matrix.copy()
        for j in range(len(alpha)):
            out[self.rows[j], self.first[j]:self.first[j] + self.n_modes[j]] = (
                self.signs[j] * values[j, :self.n_modes[j]])
        return out

    def __call__(self, mbs, t: float) -> bool:
        """Pre-step: each gear pair's block at the step's time t (the entries of :meth:`matrix_at`)."""
        kernel = self._kernel
        if kernel is None:
            kernel = self._bound(self._buffer, t)
        kernel(self._buffer, t, *self._args)
        self.time = t
        set_parameter = mbs.SetObjectParameter
        for obj, scaling in self._views:
            set_parameter(obj, "scalingMarker1", scaling)
        return True


class PreStepChain:
    """Several pre-step functions as one (Exudyn takes a single pre-step user function).

    A function with a ``finished`` attribute leaves the chain once that is true (the spin schedule after the
    ramp: flexgear.mbs.spin.SpinSchedule), so that the steady part of a run does not call it every step.
    """

    def __init__(self, functions: list[Callable]):
        self.functions = [f for f in functions if f is not None]
        self._finishing = [f for f in self.functions if hasattr(f, "finished")]

    def __call__(self, mbs, t: float) -> bool:
        ok = True
        for f in self.functions:
            ok = f(mbs, t) and ok
        for f in self._finishing:
            if f.finished:
                self.functions.remove(f)
                self._finishing.remove(f)
                break  # the others at the next step
        return ok
