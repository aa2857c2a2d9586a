"""Linear elements of a gearbox: a bearing and a fixed joint, each with its DOF map.

Element contract (as rotordynamic codes such as ROSS state theirs): an element is a constant 6 x 6 stiffness
and damping on the small motion (u_x, u_y, u_z, phi_x, phi_y, phi_z) of a point, in the axes of the body it acts
on, together with where it acts (body, interface, the other side). The multibody model realises a
:class:`BearingElement` on a rigid body's frame, on a flexible body's seat, on a planet's pin or as springs on the
axis (flexgear.mbs); the lumped model condenses the same element to its gear-centre node (flexgear.lumped).

Moving the reference point. The motion at a point p of a rigid lever is, at first order in the rotations,

    (u_p, phi) = T(d) (u_q, phi),    T(d) = [I, -d~; 0, I],    d = p - q

(u_p = u_q + phi x d; d~ the cross-product matrix of d). The strain energy 1/2 x_p^T K x_p is the same seen from
q when K_q = T^T K T, and likewise for damping: :meth:`BearingElement.at`.

A Table 2 bearing is diag(k_r, k_r, k_a, k_t, k_t, 0) about its centre: radial k_r [N/m], axial k_a [N/m], tilt
k_t [N m/rad], the spin free; its damping stiffness-proportional, D = c K with c = damping_per_stiffness [s].
On the axis it is three springs (:meth:`BearingElement.axis_springs`): two rows of radial springs k_r/2 at
z_c -+ a, a = sqrt(k_t / k_r), so 2 (k_r/2) a^2 = k_t with no translation-tilt coupling about z_c, and one axial
spring k_a at z_c; the dampers sit at the same points (the same spread needs d_t / d_r = k_t / k_r).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from flexgear.spec import Bearing

__all__ = ["AxisSpring", "BearingElement", "FixedJointElement", "condensed_radial_damping_of",
           "condensed_radial_stiffness_of", "lever_rows"]

_AXISYMMETRIC_RTOL = 1e-12
"""Relative tolerance [-] of the checks that a bearing's matrices have the axisymmetric diagonal form about its
centre (exact by construction for Table 2 bearings: only rounding is allowed)."""


def lever_rows(arm) -> np.ndarray:
    """T(d) (6, 6) = [I, -d~; 0, I]: translation at p and rotation per translation at q and rotation, d = p - q [m]
    (u_p = u_q + phi x d)."""
    x, y, z = (float(v) for v in arm)
    out = np.eye(6)
    out[:3, 3:] = -np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return out


def _frozen(a, shape: tuple[int, ...], label: str) -> np.ndarray:
    out = np.array(a, dtype=float)
    if out.shape != shape:
        raise ValueError(f"{label}: shape {out.shape}, expected {shape}")
    out.setflags(write=False)
    return out


class AxisSpring(NamedTuple):
    """One spring-damper of a bearing realised on its axis: ``point`` [m, body frame], ``stiffness`` (x, y, z)
    [N/m] and ``damping`` (x, y, z) [N s/m] in the body axes."""

    point: np.ndarray
    stiffness: tuple[float, float, float]
    damping: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class BearingElement:
    """A bearing: ``stiffness`` (6, 6) [N/m, N/rad, N m/m, N m/rad] and ``damping`` (6, 6) [N s/m, ...] on the motion
    (u_x, u_y, u_z, phi_x, phi_y, phi_z) of ``centre`` [m] (a point on the body's axis, body = component frame)
    relative to ground, or to ``other``'s motion at the same point.

    DOF map: it acts on body ``body`` (a component name, :meth:`on` moves it to the body that carries it), through
    its interface ``interface`` when that body is flexible (None: the body frame); ``other`` None is ground.
    Generalised force on the centre's motion x: f = -K x - D x'.
    """

    body: str
    centre: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    interface: str | None = None
    other: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "centre", _frozen(self.centre, (3,), f"bearing on {self.body!r}: centre"))
        object.__setattr__(self, "stiffness", _frozen(self.stiffness, (6, 6), f"bearing on {self.body!r}: stiffness"))
        object.__setattr__(self, "damping", _frozen(self.damping, (6, 6), f"bearing on {self.body!r}: damping"))

    @classmethod
    def axisymmetric(cls, body: str, radial: float, axial: float, tilt: float, damping_per_stiffness: float,
                     centre=(0.0, 0.0, 0.0), interface: str | None = None, other: str | None = None
                     ) -> BearingElement:
        """K = diag(k_r, k_r, k_a, k_t, k_t, 0) about ``centre`` (``radial`` k_r, ``axial`` k_a [N/m], ``tilt`` k_t
        [N m/rad], the spin free) and D = c K (``damping_per_stiffness`` c [s])."""
        k = np.diag([radial, radial, axial, tilt, tilt, 0.0]).astype(float)
        return cls(body, np.asarray(centre, float), k, damping_per_stiffness * k, interface, other)

    @classmethod
    def from_bearing(cls, bearing: Bearing, body: str, centre=(0.0, 0.0, 0.0), interface: str | None = None,
                     other: str | None = None) -> BearingElement:
        """The Table 2 ``bearing`` (flexgear.spec.Bearing) at ``centre`` [m] of ``body`` (:meth:`axisymmetric`)."""
        return cls.axisymmetric(body, bearing.radial_stiffness_n_per_m, bearing.axial_stiffness_n_per_m,
                                bearing.tilt_stiffness_nm_per_rad, bearing.damping_per_stiffness_s, centre,
                                interface, other)

    def on(self, body: str) -> BearingElement:
        """The same element acting on ``body`` (e.g. the rigid body a shaft is merged into; same frame)."""
        return replace(self, body=body)

    def at(self, point) -> BearingElement:
        """The same bearing seen from ``point`` [m, body frame]: K' = T^T K T, D' = T^T D T, T = T(centre - point)
        (:func:`lever_rows`); exact for a rigid lever (the strain energy is unchanged)."""
        point = np.asarray(point, float)
        t = lever_rows(self.centre - point)
        return replace(self, centre=point, stiffness=t.T @ self.stiffness @ t, damping=t.T @ self.damping @ t)

    def axisymmetric_entries(self, matrix: np.ndarray | None = None) -> tuple[float, float, float]:
        """(radial, axial, tilt) diagonal entries of ``matrix`` (default the stiffness), which must be
        diag(r, r, a, t, t, 0) about the centre (ValueError otherwise)."""
        m = self.stiffness if matrix is None else matrix
        r, a, t = float(m[0, 0]), float(m[2, 2]), float(m[3, 3])
        expected = np.diag([r, r, a, t, t, 0.0])
        if np.abs(m - expected).max(initial=0.0) > _AXISYMMETRIC_RTOL * np.abs(m).max(initial=0.0):
            raise ValueError(f"bearing on {self.body!r}: matrix is not diag(r, r, a, t, t, 0) about its centre")
        return r, a, t

    @property
    def spread(self) -> float:
        """Half distance a [m] of the two radial spring rows: a = sqrt(k_t / k_r)."""
        radial, _, tilt = self.axisymmetric_entries()
        return math.sqrt(tilt / radial)

    def axis_springs(self) -> list[AxisSpring]:
        """The bearing as three spring-dampers on its axis (module docstring): radial rows at z_c - a and z_c + a,
        then the axial spring at z_c. Raises ValueError when the matrices are not of the axisymmetric form about
        the centre or the damping's spread differs from the stiffness's."""
        k_r, k_a, k_t = self.axisymmetric_entries()
        d_r, d_a, d_t = self.axisymmetric_entries(self.damping)
        if abs(d_t * k_r - k_t * d_r) > _AXISYMMETRIC_RTOL * abs(k_t * d_r):
            raise ValueError(f"bearing on {self.body!r}: damping d_t/d_r differs from k_t/k_r (springs and dampers "
                             "on the axis share their points)")
        a = self.spread
        axis = np.array([0.0, 0.0, 1.0])
        half_k, half_d = 0.5 * k_r, 0.5 * d_r
        return [AxisSpring(self.centre - a * axis, (half_k, half_k, 0.0), (half_d, half_d, 0.0)),
                AxisSpring(self.centre + a * axis, (half_k, half_k, 0.0), (half_d, half_d, 0.0)),
                AxisSpring(self.centre.copy(), (0.0, 0.0, k_a), (0.0, 0.0, d_a))]

    def check_to_ground(self, body: str) -> None:
        """Raise ValueError unless the element acts between ``body`` and ground (:meth:`on` moves it to a body)."""
        if self.body != body or self.other is not None:
            raise ValueError(f"bearing on {self.body!r} (other side {self.other!r}) placed on body {body!r} to ground")

    @property
    def tag(self) -> str:
        """What the bearing's objects' names add to its body's name: "" for a body's one bearing (at its
        "bearing_seat" or "bore"), else the rest of its interface's name (``_near``: the parallel-axis pair's second
        bearing on a shaft, flexgear.geometry.supports)."""
        name = self.interface or ""
        return name.removeprefix("bearing_seat") if name.startswith("bearing_seat") else ""

    def condensed_radial_stiffness(self, gear_z: float = 0.0) -> float:
        """In-plane stiffness [N/m] at the point (0, 0, ``gear_z``) [m] of a rigid shaft on this bearing: a force F
        there, no moment; the bearing takes F and the moment F L (L = gear_z - z_c), so the point moves
        F (1/k_r + L^2/k_t) (static condensation of the tilt; k_t = 0 with L != 0 gives 0)."""
        return _condensed(*self.axisymmetric_entries(), gear_z - float(self.centre[2]))

    def condensed_radial_damping(self, gear_z: float = 0.0) -> float:
        """In-plane damping [N s/m] at (0, 0, ``gear_z``), the same condensation of the damping entries:
        1/c = 1/d_r + L^2/d_t (exact for stiffness-proportional damping, where it is c K condensed)."""
        return _condensed(*self.axisymmetric_entries(self.damping), gear_z - float(self.centre[2]))


def _condensed(radial: float, _axial: float, tilt: float, lever: float) -> float:
    compliance = 1.0 / radial
    if lever != 0.0:
        if tilt <= 0.0:
            return 0.0
        compliance += lever**2 / tilt
    return 1.0 / compliance


def condensed_radial_stiffness_of(bearings: Sequence[BearingElement], gear_z: float = 0.0) -> float:
    """In-plane stiffness [N/m] at the point (0, 0, ``gear_z``) [m] of a rigid shaft on all ``bearings`` together
    (e.g. the parallel-axis pair's two bearings straddling a gear): a force F there, no moment.

    Bearing i (radial k_r,i [N/m], tilt k_t,i [N m/rad] about its centre z_i) seen from the point, with the lever
    L_i = z_i - gear_z [m], adds [[k_r,i, k_r,i L_i], [k_r,i L_i, k_r,i L_i^2 + k_t,i]] on (translation u, tilt phi);
    summed to K and the tilt statically condensed (no moment at the point):

        k = K_uu - K_uphi^2 / K_phiphi   (k = K_uu where K_phiphi = 0: no lever and no tilt stiffness).

    One bearing: k = 1 / (1/k_r + L^2/k_t), :meth:`BearingElement.condensed_radial_stiffness`."""
    return _condensed_sum([(*b.axisymmetric_entries(), float(b.centre[2]) - gear_z) for b in bearings])


def condensed_radial_damping_of(bearings: Sequence[BearingElement], gear_z: float = 0.0) -> float:
    """In-plane damping [N s/m] at (0, 0, ``gear_z``) [m] of a rigid shaft on all ``bearings``: the condensation of
    :func:`condensed_radial_stiffness_of` on the damping entries (radial d_r, tilt d_t); exact for
    stiffness-proportional damping of one ratio c [s] for all bearings, where it is c times the condensed stiffness.
    One bearing: :meth:`BearingElement.condensed_radial_damping`."""
    return _condensed_sum([(*b.axisymmetric_entries(b.damping), float(b.centre[2]) - gear_z) for b in bearings])


def _condensed_sum(entries: list[tuple[float, float, float, float]]) -> float:
    """k = K_uu - K_uphi^2 / K_phiphi of the summed (translation, tilt) matrices of (radial, axial, tilt, lever)
    entries (:func:`condensed_radial_stiffness_of`); never negative (rounding where K is singular)."""
    if not entries:
        raise ValueError("condensed stiffness: expected at least one bearing")
    k_uu = sum(radial for radial, _, _, _ in entries)
    k_up = sum(radial * lever for radial, _, _, lever in entries)
    k_pp = sum(radial * lever**2 + tilt for radial, _, tilt, lever in entries)
    if k_pp == 0.0:
        return k_uu
    return max((k_uu * k_pp - k_up**2) / k_pp, 0.0)


@dataclass(frozen=True, eq=False)
class FixedJointElement:
    """A fixed joint: all six relative motions of ``body`` (through ``interface``) and ``other`` (through
    ``other_interface``) at ``point`` [m, ground frame at the reference, on the bodies' common axis] held zero.

    DOF map only (a rigid constraint carries no matrices): the interface of a flexible body, a body-fixed point of a
    rigid one (flexgear.mbs.elements.add_interface_joint, flexgear.mbs.joints.LinearInterfaceJoint)."""

    body: str
    interface: str
    other: str
    other_interface: str
    point: np.ndarray

    def __post_init__(self):
        object.__setattr__(self, "point", _frozen(self.point, (3,), f"joint {self.body!r}-{self.other!r}: point"))

    @classmethod
    def gear_shaft(cls, gear: str, shaft: str, joint: tuple[str, str, np.ndarray]) -> FixedJointElement:
        """The joint of ``gear`` and ``shaft`` from (gear interface, shaft interface, point [m])
        (flexgear.fe.reduced.gear_shaft_joints)."""
        gear_interface, shaft_interface, point = joint
        return cls(gear, gear_interface, shaft, shaft_interface, np.asarray(point, float))

    @property
    def interfaces(self) -> tuple[str, str]:
        """(``interface``, ``other_interface``)."""
        return self.interface, self.other_interface

    def check_bodies(self, body: str, other: str) -> None:
        """Raise ValueError unless the joint's DOF map names ``body`` and ``other``, in that order."""
        if (self.body, self.other) != (body, other):
            raise ValueError(f"joint of {self.body!r} and {self.other!r} placed on {body!r} and {other!r}")
