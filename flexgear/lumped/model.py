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

:class:`LumpedParameters` holds plain per-member values as the literature gives them (mass, I/r^2,
radius, bearing stiffness, torsional support stiffness in N/m = k_theta / r^2), the two mesh
stiffnesses, pressure angles, planet count and the members whose spin is held;
:meth:`LumpedParameters.from_spec` builds them from a :class:`~flexgear.spec.GearboxSpec`.
:func:`assemble` turns them into mass, support stiffness/damping and mesh-deflection matrices
shared by the modal analysis (flexgear.lumped.modal) and the time integration (flexgear.lumped.run).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from flexgear.design import Design, as_design
from flexgear.geometry.contact_lines import contact_line_integrals
from flexgear.geometry.involute import GearSetGeometry
from flexgear.geometry.massprops import combine_mass_properties
from flexgear.laws.contact import mesh_damping, mesh_laws
from flexgear.spec import GEOMETRY_COMPONENTS, GearboxSpec

__all__ = [
    "CENTRAL_MEMBERS",
    "MemberParameters",
    "LumpedParameters",
    "LumpedSystem",
    "assemble",
    "mesh_damping",
    "FrictionTables",
    "friction_tables",
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

    ``fixed``: members (of sun, ring, carrier) whose spin is held (star: carrier; planetary: ring).
    Mesh stiffnesses are mean values along the tooth normal (eq. 10); mesh damping per mesh (eq. 13)
    is optional (modal analysis ignores damping). ``planet_angles_rad`` defaults to equal spacing.
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
          shaft belongs to the carrier, whose own mass is ``[lumped_assumed]`` carrier_*)
        - bearing stiffness: the Table 2 bearing at its seat (flexgear.geometry.supports)
          condensed to the gear centre, 1/k = 1/k_r + L^2/k_t (L: gear to bearing centre; the tilt statically
          condensed); damping condensed likewise (c = k * damping_per_stiffness_s)
        - mesh stiffness: eq. 10, k_m = C_gamma b with b the total active face width
        - mesh damping: eq. 13, c = 2 xi sqrt(k_m m_1 m_2 / (m_1 + m_2)) with the gear masses
          (the study prints k in place of sqrt(k), a dimensional slip: c must be in N s/m)
        - with ``[contact] law = "iso6336"`` both from flexgear.laws.contact.mesh_laws, the multibody model's law
        - pressure angles: operating transverse pressure angles of the two meshes (flexgear.geometry.involute)
        """
        d = as_design(spec)
        spec, geo = d.spec, d.gears
        la = spec.lumped_assumed
        names = GEOMETRY_COMPONENTS
        props = {c: d.masses[c] for c in names}
        star = spec.gears.arrangement == "star"
        supports = d.supports

        def member(mass: float, inertia: float, radius: float, bearing, held: bool = False) -> MemberParameters:
            if held:
                return MemberParameters.from_inertia(max(mass, 0.0), inertia, radius, math.inf)
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


@dataclass(frozen=True)
class LumpedSystem:
    """Assembled linear structure of the model (full coordinate set, 3 per body).

    Coordinates: body b in (sun, ring, carrier, planet 1..N) owns indices 3b (x), 3b+1 (y), 3b+2 (theta).
    ``free``: coordinates that move; a held spin (``fixed``) is prescribed, a held translation is zero.
    Mesh m (sun meshes 0..N-1, ring meshes N..2N-1): normal deflection delta_n = G[m] . q.
    """

    params: LumpedParameters
    labels: tuple[str, ...]
    mass: np.ndarray  # (n,) diagonal mass matrix: m, m, I
    support_stiffness: np.ndarray  # (n, n) bearings and torsional supports
    support_damping: np.ndarray  # (n, n)
    ground_damping: np.ndarray  # (n, n) bearing damping of members supported on the ground (rotating-frame term)
    ground_spin_stiffness: np.ndarray  # (n,) torsional supports to the ground (act on the absolute spin)
    mesh_G: np.ndarray  # (2N, n) normal deflection per unit coordinate (cos(beta_b) included)
    mesh_stiffness: np.ndarray  # (2N,) mean, along the normal
    mesh_damping: np.ndarray  # (2N,)
    mesh_direction: np.ndarray  # (2N, 2) transverse line of action n (force on gear 2)
    mesh_bodies: np.ndarray  # (2N, 2) int: body of gear 1 (driving side) and gear 2
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
    return LumpedSystem(p, labels, mass, ks, cs, cg, kspin, G, km, cm, direction, bodies, free, held, nominal)


# --------------------------------------------------------------------------- tooth friction
@dataclass(frozen=True)
class FrictionTables:
    """Tooth-friction resultants of one mesh per unit normal force, over one mesh cycle.

    Phase phi in [0, 1) (mesh cycles), the convention of flexgear.geometry.contact_lines.mesh_stiffness_harmonics:
    a tooth with phase u = phi + k has its contact line from transverse position s = u (one face end)
    to s = u - eps_beta (other end), s in base pitches from the start of active contact A, and is
    in contact on 0 <= s <= eps_alpha. The normal load is spread uniformly over all contact-line
    length; friction mu*w acts along tau = J n, opposing the sliding of gear 1 on gear 2, whose
    sign flips at the pitch point.

    - ``length``: total contact-line length / its mean (the mesh stiffness shape)
    - ``force``: (1/L) int sg dl  (friction force on gear 2 along tau, per mu F_n, for forward running)
    - ``arm1``, ``arm2`` [m]: (1/L) int sg d_j dl, d_j = (C - O_j) . n the signed arm about gear j's centre;
      the friction moment on gear 1 is -mu F_n arm1, on gear 2 +mu F_n arm2.
    """

    phase: np.ndarray
    length: np.ndarray
    force: np.ndarray
    arm1: np.ndarray
    arm2: np.ndarray


def friction_tables(d1_start: float, d1_end: float, d1_pitch: float, d2_offset: float, base_pitch: float,
                    eps_beta: float, sign_slope: float, points: int) -> FrictionTables:
    """Tabulate :class:`FrictionTables` of one mesh from the integrals along its contact lines
    (flexgear.geometry.contact_lines.contact_line_integrals, the multibody model's friction series too).

    ``d1_start``, ``d1_end``, ``d1_pitch``: arm d1 = (C - O_1) . n [m] at the start and end of active
    contact and at the pitch point; ``d2_offset`` = (O_1 - O_2) . n, so d2 = d1 + d2_offset;
    ``sign_slope`` = +1 if the sliding velocity of gear 1 on gear 2 (forward running) grows with s. With
    sg = sign_slope sign(s - s_p), d1 = d1_start + p_bt s and the integrals L, S, M (s in base pitches):
    force = (1/L) int sg dl = sign_slope S / L, arm1 = (1/L) int sg d1 dl = sign_slope (d1_start S + p_bt M) / L.
    """
    phase = np.arange(points) / points
    length, signed, moment = contact_line_integrals((d1_end - d1_start) / base_pitch, eps_beta,
                                                    (d1_pitch - d1_start) / base_pitch, phase)
    i0, i1 = sign_slope * signed, sign_slope * moment
    arm1 = (d1_start * i0 + base_pitch * i1) / length
    force = i0 / length
    return FrictionTables(phase, length / length.mean(), force, arm1, arm1 + d2_offset * force)


def mesh_friction_tables(spec_geo: GearSetGeometry, points: int) -> tuple[FrictionTables, FrictionTables]:
    """Friction tables of the sun-planet and planet-ring meshes (geometry as in the module docstring)."""
    sun, planet, ring = spec_geo.sun, spec_geo.planet, spec_geo.ring
    a = spec_geo.centre_distance
    eps_b = spec_geo.sun_planet.overlap_ratio(spec_geo.helix_face_width)
    ga = math.sqrt(sun.tip_radius**2 - sun.base_radius**2)
    gp = math.sqrt(planet.tip_radius**2 - planet.base_radius**2)
    gr = math.sqrt(ring.tip_radius**2 - ring.base_radius**2)
    al_s = spec_geo.sun_planet.operating_pressure_angle
    al_r = spec_geo.planet_ring.operating_pressure_angle
    pb = sun.base_pitch
    # sun (gear 1) - planet (gear 2), external: d1 from the sun's tangency, d2 = d1 - a sin(alpha)
    k_s = -sun.base_radius / planet.base_radius  # kinematic omega_2 / omega_1
    slope_s = math.copysign(1.0, 1.0 - k_s)
    sun_t = friction_tables(a * math.sin(al_s) - gp, ga, sun.base_radius * math.tan(al_s), -a * math.sin(al_s),
                            pb, eps_b, slope_s, points)
    # planet (gear 1, driving clockwise) - ring (gear 2), internal: d2 = d1 + a sin(alpha)
    k_r = planet.base_radius / ring.base_radius
    slope_r = -math.copysign(1.0, 1.0 - k_r)  # forward running is omega_planet < 0
    ring_t = friction_tables(-a * math.sin(al_r) + gr, gp, planet.base_radius * math.tan(al_r), a * math.sin(al_r),
                             pb, eps_b, slope_r, points)
    return sun_t, ring_t
