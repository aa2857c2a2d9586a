"""Gear contact laws as small functions of numpy or Exudyn symbolic arrays (``m`` = the math module).

Two normal laws, chosen by ``[contact] law``: the ADAMS impact law of the study (section 2.1,
"impact") and a linear mesh stiffness from ISO 6336-1 with the damping of eq. 13 ("iso6336",
:func:`linear_force`, stiffness from :mod:`flexgear.laws.iso6336`), and tooth friction. These numpy forms are
the references the tests hold the per-step kernels to; the kernels of both models (multibody and lumped) evaluate
the laws, the mesh-stiffness series of eq. 11-12 and tooth friction with the compiled functions of
:mod:`flexgear.laws.compiled` (the series' numpy reference is flexgear.geometry.contact_lines.PeriodicSeries).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from flexgear.design import Design, as_design
from flexgear.geometry.contact_lines import MeshContactGeometry
from flexgear.spec import Contact, GearboxSpec

__all__ = ["ContactLaw", "static_deflection", "effective_stiffness", "impact_force",
           "linear_force", "normal_force", "backlash_linear_force", "friction_forces",
           "mesh_damping", "mesh_laws", "half_laws"]

LAWS = ("impact", "iso6336")


@dataclass(frozen=True)
class ContactLaw:
    """Normal-law parameters of one contact (helix half).

    ``kind`` "impact" (section 2.1): stiffness [N/m^exponent], damping_max [N s/m] reached at
    penetration_depth [m]. ``kind`` "iso6336": linear, exponent 1, stiffness [N/m] and constant damping
    ``damping_max`` [N s/m] while the teeth touch (penetration_depth unused, 0).
    """

    stiffness: float
    exponent: float
    damping_max: float
    penetration_depth: float
    kind: str = "impact"

    @classmethod
    def from_contact(cls, contact: Contact, share: float = 1.0) -> ContactLaw:
        """The study's law scaled to a ``share`` of the face width (one helix half: 0.5)."""
        k = contact.stiffness * share
        return cls(k, contact.exponent, contact.damping_fraction_of_stiffness * k, contact.penetration_depth_m)

    def share(self, share: float) -> ContactLaw:
        """The law of a ``share`` of the face width: stiffness and damping scale with it."""
        return ContactLaw(self.stiffness * share, self.exponent, self.damping_max * share, self.penetration_depth,
                          self.kind)


def static_deflection(force_n: float, law: ContactLaw) -> float:
    """Static normal deflection [m] of a mesh carrying ``force_n`` [N] under ``law`` at the mean of its stiffness
    series (s = 1): delta = (F / k)^(1 / e) (impact law), F / k (linear law); the elastic term inverted, no damping."""
    if force_n <= 0.0:
        return 0.0
    return (force_n / law.stiffness) ** (1.0 / law.exponent)


def effective_stiffness(force_n: float, law: ContactLaw) -> float:
    """Tangent stiffness [N/m] of ``law`` at the static deflection under ``force_n`` [N]: dF/d delta = e k
    delta^(e - 1) = e F / delta (k for the linear law)."""
    delta = static_deflection(force_n, law)
    return law.exponent * force_n / delta if delta > 0.0 else math.nan


def mesh_damping(stiffness_n_per_m: float, mass1_kg: float, mass2_kg: float, damping_ratio: float) -> float:
    """Eq. 13: c = 2 xi sqrt(k m1 m2 / (m1 + m2)) [N s/m] (mesh damping from the damping ratio xi).

    The study prints k in place of sqrt(k), a dimensional slip: c must be in N s/m.
    """
    return 2.0 * damping_ratio * math.sqrt(stiffness_n_per_m * mass1_kg * mass2_kg / (mass1_kg + mass2_kg))


def mesh_laws(spec: GearboxSpec | Design) -> dict[str, ContactLaw]:
    """The whole-face-width law of the sun-planet ("outer") and planet-ring ("inner", none in the parallel-axis pair)
    meshes.

    ``[contact] law = "impact"``: the study's law for both. ``"iso6336"``: k = c_gamma_alpha b / cos^2(beta_b)
    along the tooth normal (flexgear.laws.iso6336, b = total active face width, line load from the
    theoretical input torque shared by the planets, K_A = ``[contact_assumed] application_factor``) and
    c from eq. 13 with ``[contact_assumed] mesh_damping_ratio`` and the gears' exact masses. ``spec``: a spec or
    its design (flexgear.design).
    """
    d = as_design(spec)
    spec = d.spec
    if spec.contact.law == "impact":
        law = ContactLaw.from_contact(spec.contact)
        return {"outer": law, "inner": law}
    from flexgear.laws.iso6336 import tooth_stiffness

    geo = d.gears
    ga, ca = spec.gears_assumed, spec.contact_assumed
    b = ga.face_width_m
    f_t = abs(d.theory.input_torque) / (geo.planet_count * geo.sun.reference_radius)  # either flank
    line_load = ca.application_factor * f_t / (b * 1e3)
    mass = {c: d.masses[c].mass for c, _ in geo.named_gears}
    out = {}
    for kind, ((g1, g2), mesh) in zip(("outer", "inner"), geo.named_meshes, strict=False):
        gear1, gear2 = mesh.gear1, mesh.gear2
        iso = tooth_stiffness(gear1.teeth, gear2.teeth, gear1.shift, gear2.shift, gear1.helix_angle,
                              gear1.base_helix_angle, gear1.normal_pressure_angle, ga.dedendum_coefficient,
                              mesh.transverse_contact_ratio, line_load, internal=mesh.internal)
        k = iso.normal_stiffness_n_per_m(b, gear1.base_helix_angle)
        out[kind] = ContactLaw(k, 1.0, mesh_damping(k, mass[g1], mass[g2], ca.mesh_damping_ratio), 0.0, "iso6336")
    return out


def half_laws(geometry: MeshContactGeometry, contact: Contact, law: ContactLaw | None = None) -> list[ContactLaw]:
    """The normal law of each helix half of a mesh (``geometry``, flexgear.geometry.contact_lines): ``law`` (whole
    face width, :func:`mesh_laws`; default the study's impact law from ``contact``) scaled to the half's share of
    the face width."""
    if law is None:
        return [ContactLaw.from_contact(contact, half.share) for half in geometry.halves]
    return [law.share(half.share) for half in geometry.halves]


def impact_force(delta: Any, delta_t: Any, law: ContactLaw, factor: Any = 1.0, m: Any = np) -> Any:
    """Normal force of the impact law [N]; ``m`` is numpy or ``exudyn.symbolic``.

    F = max(0, k s <delta>^e + c_max STEP(delta, 0, 0, d, 1) delta_t), zero for delta <= 0.
    """
    mx = m.maximum if m is np else m.max
    mn = m.minimum if m is np else m.min
    pen = mx(delta, 0.0)
    ramp = mn(pen / law.penetration_depth, 1.0)
    damp = law.damping_max * ramp * ramp * (3.0 - 2.0 * ramp)
    if m is np:
        power = pen**law.exponent
    elif law.exponent == 1.5:
        power = pen * m.sqrt(pen)
    else:
        power = m.pow(pen, law.exponent)
    force = law.stiffness * factor * power
    return mx(force + damp * delta_t, 0.0)


def linear_force(delta: Any, delta_t: Any, law: ContactLaw, factor: Any = 1.0, m: Any = np) -> Any:
    """Normal force of the linear ISO 6336 law [N]; ``m`` is numpy or ``exudyn.symbolic``.

    F = max(0, k s(phi) delta + c delta_t) while the teeth touch (delta > 0), 0 otherwise (eq. 11-13 on the
    drive flank; the teeth cannot pull).
    """
    force = law.stiffness * factor * delta + law.damping_max * delta_t
    if m is np:
        return np.where(np.asarray(delta) > 0.0, np.maximum(force, 0.0), 0.0)
    return m.IfThenElse(delta > 0.0, m.max(force, 0.0), m.Real(0.0))


def normal_force(delta: Any, delta_t: Any, law: ContactLaw, factor: Any = 1.0, m: Any = np) -> Any:
    """Normal force [N] of ``law`` (its ``kind``): :func:`impact_force` or :func:`linear_force`."""
    if law.kind == "iso6336":
        return linear_force(delta, delta_t, law, factor, m)
    return impact_force(delta, delta_t, law, factor, m)


def backlash_linear_force(delta: Any, delta_t: Any, stiffness: Any, damping: Any, backlash: Any) -> Any:
    """Linear mesh force with backlash [N] (lumped model, eq. 11-13): two-sided, zero inside the play.

    F = k delta + c delta_t for delta > 0 (drive flank), k (delta + j) + c delta_t for delta < -j (back flank,
    j = normal backlash [m]), 0 in between; ``stiffness`` may already carry the variation s(phi).
    """
    delta = np.asarray(delta, dtype=float)
    drive = stiffness * delta + damping * delta_t
    back = stiffness * (delta + backlash) + damping * delta_t
    out = np.where(delta > 0.0, drive, np.where(delta < -backlash, back, 0.0))
    return float(out) if np.ndim(out) == 0 else out


def friction_forces(normal_force: Any, relative_spin: Any, sliding: Any, lever: Any, mu: float,
                    regularisation: float, mean_lever: float, m: Any = np) -> tuple[Any, Any]:
    """Lumped Coulomb friction of a mesh: forces on the sliding and relative-spin coordinates.

    Each contact line at distance s from the pitch point slides with s * Omega (Omega = relative spin
    rate omega_1 - omega_2); summed over the lines with the load uniform along them, friction gives
    mu F sigma kappa(phi) on the sliding coordinate (pitch-point sliding along w = e_z x t) and
    mu F sigma lambda(phi) on the relative spin (a moment), sigma = tanh(Omega lambda_mean / v_reg)
    the regularised sign of sliding.
    """
    sigma = m.tanh(relative_spin * (mean_lever / regularisation))
    f = mu * normal_force * sigma
    return f * sliding, f * lever
