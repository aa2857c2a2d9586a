"""Contact lines of a helical mesh in its field of action: the mesh-stiffness series (eq. 11-12), the closed-form
integrals of the lines' length, signed length and first moment, and the friction direction and lever series that
both models take from them (flexgear.mbs.contacts, flexgear.lumped.model); :class:`MeshContactGeometry` gathers a
mesh's helix halves, their tooth normals and these series, made once per design (flexgear.design).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flexgear.geometry.involute import GearMesh, HelixHalf, helix_halves, tooth_normal_local

__all__ = ["mesh_stiffness_harmonics", "PeriodicSeries", "SPUR_OVERLAP_RATIO", "contact_line_integrals",
           "contact_line_distribution", "contact_line_series", "MeshContactGeometry", "mesh_contact_geometry"]


def mesh_stiffness_harmonics(eps_alpha: float, eps_beta: float, harmonics: int) -> np.ndarray:
    """Fourier coefficients of the normalised mesh stiffness k(phi)/k_mean (eq. 11-12).

    The mesh stiffness is taken proportional to the total length of the contact lines in the
    field of action (Maatar & Velex). One contact line's length, as the mesh advances, is the
    convolution of two boxes of widths eps_alpha and eps_beta (in base pitches); summed over all
    teeth it is periodic in the mesh phase phi (in mesh cycles) with

        k(phi)/k_mean = 1 + sum_n c_n cos(2 pi n (phi - (eps_alpha + eps_beta)/2)),
        c_n = 2 sinc(n eps_alpha) sinc(n eps_beta),   sinc(u) = sin(pi u)/(pi u).

    Returns ``c`` of shape (harmonics,) for n = 1..harmonics.
    """
    n = np.arange(1, harmonics + 1)
    return 2 * np.sinc(n * eps_alpha) * np.sinc(n * eps_beta)


@dataclass(frozen=True)
class PeriodicSeries:
    """f(phi) = mean + sum_n (cos_coeffs[n-1] cos(2 pi n phi) + sin_coeffs[n-1] sin(2 pi n phi)), phi in cycles."""

    mean: float
    cos_coeffs: np.ndarray
    sin_coeffs: np.ndarray

    def __call__(self, phi: np.ndarray | float) -> np.ndarray:
        phi = np.asarray(phi, dtype=float)
        out = np.full_like(phi, self.mean)
        for n, (a, b) in enumerate(zip(self.cos_coeffs, self.sin_coeffs, strict=True), start=1):
            out = out + a * np.cos(2 * np.pi * n * phi) + b * np.sin(2 * np.pi * n * phi)
        return out

    def packed(self) -> np.ndarray:
        """The coefficients as one row (mean, cos_coeffs, sin_coeffs), the layout of the compiled evaluator
        flexgear.laws.compiled.series_value: (1 + 2 H,), or (n, 1 + 2 H) for n series stacked harmonic-major
        (means (n,), coefficients (H, n))."""
        mean = np.asarray(self.mean, dtype=float)
        rows = np.concatenate([mean[None], np.asarray(self.cos_coeffs, float).reshape(-1, *mean.shape),
                               np.asarray(self.sin_coeffs, float).reshape(-1, *mean.shape)])
        return np.ascontiguousarray(rows.T)

    @classmethod
    def fit(cls, samples: np.ndarray, harmonics: int) -> PeriodicSeries:
        """Truncated Fourier series of samples taken at phi = k / len(samples)."""
        spec = np.fft.rfft(samples) / len(samples)
        return cls(float(spec[0].real), 2 * spec[1:harmonics + 1].real, -2 * spec[1:harmonics + 1].imag)


SPUR_OVERLAP_RATIO = 1e-9
"""Overlap ratio below which a mesh counts as spur: point contacts, one per tooth pair in contact."""


def contact_line_integrals(eps_alpha: float, eps_beta: float, pitch_position: float, phases: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Integrals along the contact lines in the field of action of a helical mesh, exact, as the mesh phase advances.

    The field of action is x in [0, eps_alpha] base pitches along the line of action (x = 0 at the start of
    contact, the pitch point at x_p = ``pitch_position``) by y in [0, 1] of the face width; the contact line of
    tooth k lies on x = phi + k - eps_beta y, so that it covers [x0, x1] = [phi + k - eps_beta, phi + k] clipped to
    the field. For every phase phi (cycles) returns, summed over the lines and in base pitches,

        L = sum_k int_x0^x1 dx,   S = sum_k int_x0^x1 sign(x - x_p) dx,   M = sum_k int_x0^x1 sign(x - x_p) x dx,

    each in closed form over the parts of [x0, x1] below and above x_p (per unit face width, a line across the
    whole face has length eps_beta). For a spur mesh (eps_beta < :data:`SPUR_OVERLAP_RATIO`) every tooth pair in
    contact (0 <= x < eps_alpha) is a point contact of weight 1. With the load uniform along the lines (as the
    stiffness model assumes) S / L is the net direction of sliding and (M - x_p S) / L the mean distance of the load
    from the pitch point: :func:`contact_line_distribution`, and the lumped model's friction arms
    (flexgear.lumped.model.friction_tables).
    """
    phases = np.asarray(phases, dtype=float)
    teeth = np.arange(-1, int(math.ceil(eps_alpha + eps_beta)) + 2)
    x = np.mod(phases, 1.0)[..., None] + teeth  # the lines' ends at y = 0 (the integrals have period 1)
    s_p = pitch_position
    if eps_beta >= SPUR_OVERLAP_RATIO:
        x0, x1 = np.clip(x - eps_beta, 0.0, eps_alpha), np.clip(x, 0.0, eps_alpha)
        b1 = np.maximum(np.minimum(x1, s_p), x0)  # [x0, b1] lies below the pitch point, [a0, x1] above it
        a0 = np.minimum(np.maximum(x0, s_p), x1)
        signed = (x1 - a0) - (b1 - x0)
        moment = 0.5 * ((x1**2 - a0**2) - (b1**2 - x0**2))
        return (x1 - x0).sum(axis=-1), signed.sum(axis=-1), moment.sum(axis=-1)
    inside = (x >= 0.0) & (x < eps_alpha)
    signed = inside * np.sign(x - s_p)
    return inside.sum(axis=-1).astype(float), signed.sum(axis=-1), (signed * x).sum(axis=-1)


def contact_line_distribution(eps_alpha: float, eps_beta: float, pitch_position: float, phases: np.ndarray
                              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The contact lines of a helical mesh as the mesh phase advances (:func:`contact_line_integrals`, same
    arguments). For every phase phi (cycles) returns

    - length(phi) = L / eps_beta: total contact-line length in units of one straight line across the face
      (spur: the number of tooth pairs in contact),
    - kappa(phi) = S / L: net direction of sliding (sign(x - x_p) averaged over the load),
    - lever(phi) = (M - x_p S) / L: mean distance |x - x_p| of the load from the pitch point [base pitches],

    with the load taken uniform along the contact lines (as the stiffness model assumes).
    """
    length, signed, moment = contact_line_integrals(eps_alpha, eps_beta, pitch_position, phases)
    lever = (moment - pitch_position * signed) / length
    lines = length / eps_beta if eps_beta >= SPUR_OVERLAP_RATIO else length
    return lines, signed / length, lever


def contact_line_series(mesh: GearMesh, face_width: float, harmonics: int, samples: int = 512
                        ) -> tuple[PeriodicSeries, PeriodicSeries, PeriodicSeries]:
    """Fourier series (in the mesh phase) of the normalised stiffness, the sliding direction and the lever.

    The stiffness series is the analytic one of :func:`mesh_stiffness_harmonics` (eq. 11-12); the
    friction series (kappa, lever [m]) are fitted to :func:`contact_line_distribution`.
    """
    eps_a, eps_b = mesh.transverse_contact_ratio, mesh.overlap_ratio(face_width)
    c = mesh_stiffness_harmonics(eps_a, eps_b, harmonics)
    n = np.arange(1, harmonics + 1)
    centre = 0.5 * (eps_a + eps_b)
    stiffness = PeriodicSeries(1.0, c * np.cos(2 * np.pi * n * centre), c * np.sin(2 * np.pi * n * centre))
    phases = np.arange(samples) / samples
    _, kappa, lever = contact_line_distribution(eps_a, eps_b, mesh.approach_length / mesh.base_pitch, phases)
    return stiffness, PeriodicSeries.fit(kappa, harmonics), PeriodicSeries.fit(lever * mesh.base_pitch, harmonics)


Normal = tuple[float, float, float]


@dataclass(frozen=True)
class MeshContactGeometry:
    """What the contacts of one mesh take from the geometry: its helix halves, their tooth normals, its series.

    ``halves``: the helix halves with the hand of gear 1 in each (flexgear.geometry.involute.helix_halves);
    ``normals``: for a drive sign of +1 and -1 (gear 1 pushing gear 2 counter-clockwise / clockwise about +z),
    each half's tooth normal (force on gear 2) at the pitch point in gear 1's local (radial, tangential, axial)
    frame (flexgear.geometry.involute.tooth_normal_local); ``stiffness``, ``sliding``, ``lever`` [m]: the
    series of :func:`contact_line_series` over one helix of ``helix_width`` [m].
    """

    mesh: GearMesh
    helix_width: float
    halves: tuple[HelixHalf, ...]
    normals: dict[int, tuple[Normal, ...]]
    stiffness: PeriodicSeries
    sliding: PeriodicSeries
    lever: PeriodicSeries


def mesh_contact_geometry(mesh: GearMesh, helix_layout: str, helix_width: float, half_gap: float, hand: int,
                          harmonics: int) -> MeshContactGeometry:
    """:class:`MeshContactGeometry` of ``mesh``: ``helix_layout`` "single" or "double", ``helix_width`` [m] of one
    helix, ``half_gap`` [m] between the halves, ``hand`` of gear 1 in the +z half, ``harmonics`` of the series."""
    halves = tuple(helix_halves(helix_layout, helix_width, half_gap, hand))
    normals = {s: tuple(tooth_normal_local(mesh, s, h.hand) for h in halves) for s in (1, -1)}
    return MeshContactGeometry(mesh, helix_width, halves, normals, *contact_line_series(mesh, helix_width, harmonics))
