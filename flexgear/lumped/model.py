"""Lumped-parameter (translational-torsional) model of a single-stage planetary set: parameters and assembly.

Section 2.3 of the study (eq. 1-13), generalised after Lin & Parker (1999): sun, ring and carrier
("central members") and N planets, each a rigid body with x, y (in-plane translation) and theta
(spin) coordinates. All coordinates live in the frame that rotates with the nominal carrier
speed (fixed for the star arrangement): translations are displacements of a body's centre from
its nominal position, spins are angles measured from that frame [rad].

Geometry (transverse plane, sun at the origin, planet i at a e_i, e_i = (cos psi_i, sin psi_i),
J = rotation by +90 deg, the sun driving counter-clockwise):

- sun-planet mesh i, line of action  n_s = cos(alpha_s) J e_i + sin(alpha_s) e_i (force on the planet)
  delta_t = (x_s - x_p) . n_s + r_bs theta_s + r_bp theta_p
- planet-ring mesh i, line of action n_r = -cos(alpha_r) J e_i + sin(alpha_r) e_i (force on the ring)
  delta_t = (x_p - x_r) . n_r - r_bp theta_p + r_br theta_r
- helical teeth: the deflection along the tooth normal is delta_n = cos(beta_b) delta_t and the
  normal force F_n acts with its transverse part F_n cos(beta_b) (the cos(beta_b) factors of eq. 1-9);
  the mesh stiffness k_m = C_gamma b of eq. 10 is taken along the normal.
- planet bearings connect the planet centre to its pin on the carrier, a e_i + (x_c, y_c) + a theta_c J e_i.

The parallel-axis pair (``[gears] arrangement = "parallel"``) is the star's sun-planet mesh of one planet: the sun is
the pinion (input), planet 1 the wheel (output) at a e_1 = (a, 0) on its own shaft; the carrier is held, so the
wheel's "planet bearing" (its two shaft bearings condensed) ties it to the ground; the ring is detached (held, no
mass, no mesh: :attr:`LumpedParameters.ring_meshes` is False and :func:`assemble` leaves its mesh rows out).

:class:`LumpedParameters` holds plain per-member values as the literature gives them (mass, I/r^2,
radius, bearing stiffness, torsional support stiffness in N/m = k_theta / r^2), the two mesh
stiffnesses, pressure angles, planet count and the members whose spin is held;
:meth:`LumpedParameters.from_spec` builds them from a :class:`~flexgear.spec.GearboxSpec`.
:func:`assemble` turns them into mass, support stiffness/damping and mesh-deflection matrices
shared by the modal analysis (flexgear.lumped.modal) and the time integration (flexgear.lumped.run). The tooth
friction tables live in flexgear.lumped.friction (re-exported here).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from flexgear.design import Design, as_design
from flexgear.geometry.elements import condensed_radial_damping_of, condensed_radial_stiffness_of
from flexgear.geometry.massprops import combine_mass_properties
from flexgear.geometry.supports import NEAR
from flexgear.laws.contact import mesh_damping, mesh_laws
from flexgear.lumped.friction import FrictionTables, friction_tables, mesh_friction_tables
from flexgear.spec import GearboxSpec

__all__ = [
    "CENTRAL_MEMBERS",
    "MemberParameters",
    "LumpedParameters",
    "LumpedSystem",
    "assemble",
    "mesh_damping",
    "FrictionTables",
    "friction_tables",
    "mesh_friction_tables",
]

CENTRAL_MEMBERS = ("sun", "ring", "carrier")
"""Central members in coordinate order; planets follow (body index 3 + i)."""

_J = np.array([[0.0, -1.0], [1.0, 0.0]])


@dataclass(frozen=True)
class MemberParameters:
    """One member of the set (SI).

    ``radius_m`` is the base radius for sun, ring and planet and the planet centre distance for
    the carrier. ``bearing_stiffness_n_per_m`` is the isotropic radial support (x and y), to the
    ground for the central members and to the carrier pin for a planet; ``math.inf`` holds the
    translation. ``torsional_stiffness_n_per_m`` is a spin support to the ground expressed, as in
    Lin & Parker, on the radius: k_theta = k_u r^2.
    """

    mass_kg: float
    inertia_per_radius2_kg: float
    radius_m: float
    bearing_stiffness_n_per_m: float
    torsional_stiffness_n_per_m: float = 0.0
    bearing_damping_n_s_per_m: float = 0.0

    @property
    def inertia_kg_m2(self) -> float:
        return self.inertia_per_radius2_kg * self.radius_m**2

    @classmethod
    def from_inertia(cls, mass_kg: float, inertia_kg_m2: float, radius_m: float, bearing_stiffness_n_per_m: float,
                     **kwargs: float) -> MemberParameters:
        """Same, from the spin inertia I [kg m^2] instead of I/r^2."""
        return cls(mass_kg, inertia_kg_m2 / radius_m**2, radius_m, bearing_stiffness_n_per_m, **kwargs)


@dataclass(frozen=True)
class LumpedParameters:
    """Plain lumped parameters of any single-stage planetary set (SI, angles in rad).

    ``fixed``: members (of sun, ring, carrier) whose spin is held (star: carrier; planetary: ring; the parallel-axis
    pair: carrier and ring). Mesh stiffnesses are mean values along the tooth normal (eq. 10); mesh damping per mesh
    (eq. 13) is optional (modal analysis ignores damping). ``planet_angles_rad`` defaults to equal spacing. Planet-ring
    meshes of zero stiffness and zero damping carry no force: the set has none (:attr:`ring_meshes`).
    """

    sun: MemberParameters
    ring: MemberParameters
    carrier: MemberParameters
    planet: MemberParameters
    planet_count: int
    sun_mesh_stiffness_n_per_m: float
    ring_mesh_stiffness_n_per_m: float
    sun_pressure_angle_rad: float
    ring_pressure_angle_rad: float
    fixed: tuple[str, ...] = ("carrier",)
    base_helix_angle_rad: float = 0.0
    planet_angles_rad: tuple[float, ...] | None = None
    sun_mesh_damping_n_s_per_m: float = 0.0
    ring_mesh_damping_n_s_per_m: float = 0.0
    source: str = field(default="plain parameters", compare=False)

    def __post_init__(self) -> None:
        for name in self.fixed:
            if name not in CENTRAL_MEMBERS:
                raise ValueError(f"fixed: unknown member {name!r}; allowed: {', '.join(CENTRAL_MEMBERS)}")
        if self.planet_count < 1:
            raise ValueError(f"planet_count: expected >= 1, got {self.planet_count}")
        if self.planet_angles_rad is not None and len(self.planet_angles_rad) != self.planet_count:
            raise ValueError("planet_angles_rad: expected one angle per planet")
        for name in (*CENTRAL_MEMBERS, "planet"):
            m: MemberParameters = getattr(self, name)
            if m.radius_m <= 0.0 or m.mass_kg < 0.0 or m.inertia_per_radius2_kg < 0.0:
                raise ValueError(f"{name}: expected radius > 0, mass >= 0 and I/r^2 >= 0")

    @property
    def ring_meshes(self) -> bool:
        """Whether the set has planet-ring meshes: False where both their stiffness and damping are zero (the
        parallel-axis pair's detached ring), whose force F = k delta + c delta' is then zero whatever the motion."""
        return self.ring_mesh_stiffness_n_per_m != 0.0 or self.ring_mesh_damping_n_s_per_m != 0.0

    @property
    def mesh_count(self) -> int:
        """Number of meshes: N sun-planet meshes, and N planet-ring meshes where the set has them."""
        return self.planet_count * (2 if self.ring_meshes else 1)

    @property
    def angles(self) -> np.ndarray:
        if self.planet_angles_rad is None:
            return 2.0 * math.pi * np.arange(self.planet_count) / self.planet_count
        return np.asarray(self.planet_angles_rad, dtype=float)

    @classmethod
    def from_spec(cls, spec: GearboxSpec | Design, hold_input: bool = False) -> LumpedParameters:
        """Parameters of the spec's gearbox, from the spec or its design (flexgear.design) (``hold_input``: also hold
        the sun's spin, as the prescribed drive does).

        - masses and spin inertias: flexgear.geometry.layout.component_mass_properties (sun + input shaft,
          the in-plane mass the apparent mass at the gear centre of the joined parts, see ``mi``;
          ring + output shaft for the star arrangement; for the planetary arrangement the output
          shaft belongs to the carrier, whose own mass is ``[lumped_assumed]`` carrier_*; for the parallel-axis
          pair wheel + output shaft on the planet, the ring detached and the carrier held, module docstring)
        - bearing stiffness: the Table 2 bearing at its seat (flexgear.geometry.supports)
          condensed to the gear centre, 1/k = 1/k_r + L^2/k_t (L: gear to bearing centre; the tilt statically
          condensed); damping condensed likewise (c = k * damping_per_stiffness_s); the parallel-axis pair's shafts
          on their two bearings condensed together, k = K_uu - K_uphi^2 / K_phiphi
          (flexgear.geometry.elements.condensed_radial_stiffness_of)
        - mesh stiffness: eq. 10, k_m = C_gamma b with b the total active face width
        - mesh damping: eq. 13, c = 2 xi sqrt(k_m m_1 m_2 / (m_1 + m_2)) with the gear masses
          (the study prints k in place of sqrt(k), a dimensional slip: c must be in N s/m)
        - with ``[contact] law = "iso6336"`` both from flexgear.laws.contact.mesh_laws, the multibody model's law
        - pressure angles: operating transverse pressure angles of the two meshes (flexgear.geometry.involute)
        """
        d = as_design(spec)
        spec, geo = d.spec, d.gears
        la = spec.lumped_assumed
        props = d.masses
        arrangement = spec.gears.arrangement
        star = arrangement == "star"
        supports = d.supports

        def member(mass: float, inertia: float, radius: float, bearing: str | tuple[str, ...] | None,
                   held: bool = False) -> MemberParameters:
            if held:
                return MemberParameters.from_inertia(max(mass, 0.0), inertia, radius, math.inf)
            if isinstance(bearing, tuple):  # a shaft on several bearings (the parallel-axis pair), condensed together
                seats = [supports[b] for b in bearing]
                return MemberParameters.from_inertia(mass, inertia, radius, condensed_radial_stiffness_of(seats),
                                                     bearing_damping_n_s_per_m=condensed_radial_damping_of(seats))
            # the bearing at its seat condensed to the gear centre (flexgear.geometry.supports)
            k = supports[bearing].condensed_radial_stiffness()
            return MemberParameters.from_inertia(mass, inertia, radius, k,
                                                 bearing_damping_n_s_per_m=supports[bearing].condensed_radial_damping())

        def mi(*names: str) -> tuple[float, float]:
            """Apparent in-plane mass at the gear centre and spin inertia of the rigidly joined parts.

            A rigid shaft and gear whose centre of mass lies d off the gear plane answer an in-plane force at
            the gear centre with translation and tilt: m_app = 1 / (1/m + d^2/I_t) (I_t: tilt inertia about
            the centre of mass), the mass the multibody model's gear centre shows (d = 0: m).
            """
            body = combine_mass_properties(*(props[n] for n in names))
            d = float(body.com[2])
            tilt = 0.5 * float(body.inertia[0, 0] + body.inertia[1, 1])
            apparent = body.mass if d == 0.0 else 1.0 / (1.0 / body.mass + d**2 / tilt)
            return apparent, sum(props[n].inertia[2, 2] for n in names)

        if arrangement == "parallel":
            return cls._parallel(d, member, mi, hold_input)
        sun = member(*mi("sun", "input_shaft"), geo.sun.base_radius, "input_shaft")
        planet = member(*mi("planet"), geo.planet.base_radius, "planet")
        if star:
            ring = member(*mi("ring", "output_shaft"), geo.ring.base_radius, "output_shaft")
            carrier = member(0.0, 0.0, geo.centre_distance, None, held=True)
            fixed: tuple[str, ...] = ("carrier",)
        else:
            ring = member(*mi("ring"), geo.ring.base_radius, None, held=True)
            m_out, i_out = mi("output_shaft")
            m_c, i_c = d.carrier_disc()
            carrier = member(m_c + m_out, i_c + i_out, geo.centre_distance, "output_shaft")
            fixed = ("ring",)
        if hold_input:
            fixed = (*fixed, "sun")
        m_s, m_p, m_r = props["sun"].mass, props["planet"].mass, props["ring"].mass
        if spec.contact.law == "iso6336":  # the multibody model's law and damping (flexgear.laws.contact.mesh_laws)
            laws = mesh_laws(d)
            k_s, k_r = laws["outer"].stiffness, laws["inner"].stiffness
            c_s, c_r = laws["outer"].damping_max, laws["inner"].damping_max
        else:  # the study's lumped model: eq. 10 with an assumed C_gamma, eq. 13
            k_s = k_r = la.mesh_stiffness_per_width_n_per_m2 * spec.gears_assumed.face_width_m
            c_s = mesh_damping(k_s, m_s, m_p, la.mesh_damping_ratio)
            c_r = mesh_damping(k_r, m_p, m_r, la.mesh_damping_ratio)
        return cls(
            sun=sun, ring=ring, carrier=carrier, planet=planet, planet_count=geo.planet_count,
            sun_mesh_stiffness_n_per_m=k_s, ring_mesh_stiffness_n_per_m=k_r,
            sun_pressure_angle_rad=geo.sun_planet.operating_pressure_angle,
            ring_pressure_angle_rad=geo.planet_ring.operating_pressure_angle,
            fixed=fixed, base_helix_angle_rad=geo.sun.base_helix_angle,
            planet_angles_rad=tuple(float(a) for a in geo.planet_angles),
            sun_mesh_damping_n_s_per_m=c_s, ring_mesh_damping_n_s_per_m=c_r,
            source=str(spec.source),
        )

    @classmethod
    def _parallel(cls, d: Design, member: Callable[..., MemberParameters],
                  mi: Callable[..., tuple[float, float]], hold_input: bool) -> LumpedParameters:
        """:meth:`from_spec` of the parallel-axis pair (module docstring): the pinion + input shaft on the sun, the
        wheel + output shaft on planet 1, each on its shaft's two bearings condensed to its gear centre; the carrier
        held (the wheel's axis fixed at the centre distance); the ring detached: held, massless, its meshes of zero
        stiffness and damping (any positive radius: no mesh reads it, the wheel's base radius is taken). The one
        mesh as the star's sun-planet meshes (its law's stiffness and damping, or eq. 10 and 13)."""
        spec, geo = d.spec, d.gears
        la = spec.lumped_assumed
        sun = member(*mi("sun", "input_shaft"), geo.sun.base_radius, ("input_shaft", "input_shaft" + NEAR))
        planet = member(*mi("planet", "output_shaft"), geo.planet.base_radius, ("output_shaft", "output_shaft" + NEAR))
        ring = member(0.0, 0.0, geo.planet.base_radius, None, held=True)
        carrier = member(0.0, 0.0, geo.centre_distance, None, held=True)
        if spec.contact.law == "iso6336":
            law = mesh_laws(d)["outer"]
            k_s, c_s = law.stiffness, law.damping_max
        else:
            k_s = la.mesh_stiffness_per_width_n_per_m2 * spec.gears_assumed.face_width_m
            c_s = mesh_damping(k_s, d.masses["sun"].mass, d.masses["planet"].mass, la.mesh_damping_ratio)
        alpha = geo.sun_planet.operating_pressure_angle
        return cls(
            sun=sun, ring=ring, carrier=carrier, planet=planet, planet_count=geo.planet_count,
            sun_mesh_stiffness_n_per_m=k_s, ring_mesh_stiffness_n_per_m=0.0,
            sun_pressure_angle_rad=alpha, ring_pressure_angle_rad=alpha,  # the ring's: unused (no ring mesh)
            fixed=("carrier", "ring", "sun") if hold_input else ("carrier", "ring"),
            base_helix_angle_rad=geo.sun.base_helix_angle,
            planet_angles_rad=tuple(float(a) for a in geo.planet_angles),
            sun_mesh_damping_n_s_per_m=c_s, ring_mesh_damping_n_s_per_m=0.0, source=str(spec.source),
        )


@dataclass(frozen=True)
class LumpedSystem:
    """Assembled linear structure of the model (full coordinate set, 3 per body).

    Coordinates: body b in (sun, ring, carrier, planet 1..N) owns indices 3b (x), 3b+1 (y), 3b+2 (theta).
    ``free``: coordinates that move; a held spin (``fixed``) is prescribed, a held translation is zero.
    Mesh m (sun meshes 0..N-1, ring meshes N..2N-1 where the set has them, :attr:`LumpedParameters.ring_meshes`;
    M = :attr:`LumpedParameters.mesh_count` meshes): normal deflection delta_n = G[m] . q.
    """

    params: LumpedParameters
    labels: tuple[str, ...]
    mass: np.ndarray  # (n,) diagonal mass matrix: m, m, I
    support_stiffness: np.ndarray  # (n, n) bearings and torsional supports
    support_damping: np.ndarray  # (n, n)
    ground_damping: np.ndarray  # (n, n) bearing damping of members supported on the ground (rotating-frame term)
    ground_spin_stiffness: np.ndarray  # (n,) torsional supports to the ground (act on the absolute spin)
    mesh_G: np.ndarray  # (M, n) normal deflection per unit coordinate (cos(beta_b) included)
    mesh_stiffness: np.ndarray  # (M,) mean, along the normal
    mesh_damping: np.ndarray  # (M,)
    mesh_direction: np.ndarray  # (M, 2) transverse line of action n (force on gear 2)
    mesh_bodies: np.ndarray  # (M, 2) int: body of gear 1 (driving side) and gear 2
    free: np.ndarray  # (n,) bool
    held_spin: np.ndarray  # (n,) bool: spins held (prescribed)
    nominal_position: np.ndarray  # (bodies, 2) nominal centre in the carrier frame [m]

    @property
    def n(self) -> int:
        return self.mass.size

    def stiffness(self) -> np.ndarray:
        """Full linear stiffness with mean mesh stiffness: K = K_support + sum_m k_m G_m G_m^T."""
        g = self.mesh_G
        return self.support_stiffness + (g.T * self.mesh_stiffness) @ g

    def damping(self) -> np.ndarray:
        g = self.mesh_G
        return self.support_damping + (g.T * self.mesh_damping) @ g


def assemble(params: LumpedParameters, translations: bool = True) -> LumpedSystem:
    """Mass, support and mesh matrices of ``params`` (``translations=False``: the purely torsional model)."""
    p = params
    nb = 3 + p.planet_count
    n = 3 * nb
    members = [p.sun, p.ring, p.carrier] + [p.planet] * p.planet_count
    names = list(CENTRAL_MEMBERS) + [f"planet{i + 1}" for i in range(p.planet_count)]
    labels = tuple(f"{nm}.{c}" for nm in names for c in ("x", "y", "theta"))
    mass = np.zeros(n)
    ks, cs, cg = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    kspin = np.zeros(n)
    free = np.ones(n, dtype=bool)
    held = np.zeros(n, dtype=bool)
    a = p.carrier.radius_m
    psi = p.angles
    e = np.stack([np.cos(psi), np.sin(psi)], axis=1)
    nominal = np.zeros((nb, 2))
    nominal[3:] = a * e

    def add_spring(mat: np.ndarray, g: np.ndarray, k: float) -> None:
        mat += k * np.outer(g, g)

    for b, m in enumerate(members):
        ix, iy, it = 3 * b, 3 * b + 1, 3 * b + 2
        mass[[ix, iy]] = m.mass_kg
        mass[it] = m.inertia_kg_m2
        if b < 3:  # central member on the ground
            if math.isinf(m.bearing_stiffness_n_per_m) or not translations:
                free[[ix, iy]] = False
            else:
                for i in (ix, iy):
                    ks[i, i] += m.bearing_stiffness_n_per_m
                    cs[i, i] += m.bearing_damping_n_s_per_m
                    cg[i, i] += m.bearing_damping_n_s_per_m
            kspin[it] = m.torsional_stiffness_n_per_m * m.radius_m**2
            ks[it, it] += kspin[it]
            if names[b] in p.fixed:
                free[it] = False
                held[it] = True
        else:  # planet bearing to its carrier pin: pin = (x_c, y_c) + a theta_c J e_i
            if not translations:
                free[[ix, iy]] = False
                continue
            if math.isinf(m.bearing_stiffness_n_per_m):
                raise ValueError("planet bearing stiffness must be finite")
            jei = _J @ e[b - 3]
            for d in (np.array([1.0, 0.0]), np.array([0.0, 1.0])):
                g = np.zeros(n)
                g[[ix, iy]] = d
                g[[6, 7]] -= d
                g[8] -= a * (d @ jei)
                add_spring(ks, g, m.bearing_stiffness_n_per_m)
                add_spring(cs, g, m.bearing_damping_n_s_per_m)
    for i in range(n):  # translations of a massless member cannot move
        if free[i] and mass[i] <= 0.0:
            raise ValueError(f"{labels[i]}: a free coordinate needs a positive mass/inertia")

    nm = 2 * p.planet_count
    G = np.zeros((nm, n))
    direction = np.zeros((nm, 2))
    bodies = np.zeros((nm, 2), dtype=np.int64)
    cb = math.cos(p.base_helix_angle_rad)
    rs, rr, rp = p.sun.radius_m, p.ring.radius_m, p.planet.radius_m
    for i in range(p.planet_count):
        b = 3 + i
        jei = _J @ e[i]
        ns = math.cos(p.sun_pressure_angle_rad) * jei + math.sin(p.sun_pressure_angle_rad) * e[i]
        nr = -math.cos(p.ring_pressure_angle_rad) * jei + math.sin(p.ring_pressure_angle_rad) * e[i]
        g = G[i]
        g[[0, 1]] += ns
        g[[3 * b, 3 * b + 1]] -= ns
        g[2] += rs
        g[3 * b + 2] += rp
        g = G[p.planet_count + i]
        g[[3 * b, 3 * b + 1]] += nr
        g[[3, 4]] -= nr
        g[3 * b + 2] -= rp
        g[5] += rr
        direction[i], direction[p.planet_count + i] = ns, nr
        bodies[i] = (0, b)
        bodies[p.planet_count + i] = (b, 1)
    if not translations:
        G[:, ~free & ~held] = 0.0
    G *= cb
    km = np.r_[np.full(p.planet_count, p.sun_mesh_stiffness_n_per_m),
               np.full(p.planet_count, p.ring_mesh_stiffness_n_per_m)]
    cm = np.r_[np.full(p.planet_count, p.sun_mesh_damping_n_s_per_m),
               np.full(p.planet_count, p.ring_mesh_damping_n_s_per_m)]
    if not p.ring_meshes:  # no planet-ring meshes (a detached ring): their rows left out
        keep = slice(0, p.mesh_count)
        G, km, cm, direction, bodies = G[keep], km[keep], cm[keep], direction[keep], bodies[keep]
    return LumpedSystem(p, labels, mass, ks, cs, cg, kspin, G, km, cm, direction, bodies, free, held, nominal)
