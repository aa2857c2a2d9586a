"""Mass properties: the dataclass every geometry, rigid body and flexible body shares, and its algebra.

Frames: a component's frame has z along the rotation axis and its origin at the gear's axial
mid-plane centre (see flexgear.geometry.layout). All values SI.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["MassProperties", "inertia_about_point", "combine_mass_properties"]


@dataclass(frozen=True)
class MassProperties:
    """Mass [kg], centre of mass [m] (3,) and inertia about the centre of mass [kg m^2] (3, 3)."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray

    def translated(self, offset: np.ndarray) -> MassProperties:
        """The same solid moved by ``offset`` [m] (a new object)."""
        return MassProperties(self.mass, np.asarray(self.com, float) + np.asarray(offset, float), self.inertia)


def inertia_about_point(props: MassProperties, point: np.ndarray | None = None) -> np.ndarray:
    """Inertia tensor about ``point`` (default origin): J_p = J_c + m (|d|^2 I - d d^T), d = com - p."""
    d = np.asarray(props.com, float) - (np.zeros(3) if point is None else np.asarray(point, float))
    return np.asarray(props.inertia, float) + props.mass * (d @ d * np.eye(3) - np.outer(d, d))


def combine_mass_properties(*parts: MassProperties) -> MassProperties:
    """Mass properties of rigidly joined parts given in one frame (parallel-axis theorem)."""
    mass = sum(p.mass for p in parts)
    com = sum(p.mass * np.asarray(p.com, float) for p in parts) / mass
    inertia = sum(inertia_about_point(p, com) for p in parts)
    return MassProperties(mass, com, inertia)


def annulus_mass_properties(inner_radius: float, outer_radius: float, width: float, density: float) -> MassProperties:
    """Mass properties of a solid annulus centred at the origin, axis z (a gear blank, an approximation) [SI].

    m = rho pi (R^2 - r^2) b,  J_z = m (R^2 + r^2) / 2,  J_x = J_y = m (3 (R^2 + r^2) + b^2) / 12.
    """
    if not (0 <= inner_radius < outer_radius and width > 0 and density > 0):
        raise ValueError("need 0 <= inner_radius < outer_radius, width > 0 and density > 0 (SI)")
    r2 = outer_radius**2 + inner_radius**2
    m = density * math.pi * (outer_radius**2 - inner_radius**2) * width
    jx = m * (3 * r2 + width**2) / 12
    return MassProperties(m, np.zeros(3), np.diag([jx, jx, 0.5 * m * r2]))
