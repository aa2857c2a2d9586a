"""A gearbox linearised at its operating point: mass, damping, gyroscopic and stiffness matrices.

:func:`linearize` builds a variant into an Exudyn system exactly as a run does (flexgear.mbs.assemble.
build_gearbox: the star at any speed, the planetary stage at rest), brings it to its steady operating point and lets
Exudyn differentiate the assembled equations there (``ComputeLinearizedSystem``). The operating point is the static
equilibrium at the time t* = T (the end of the load case's STEP ramps of speed and load): the drive holds the input
at its prescribed angle, the load torque acts in full, and the per-step updates (spin terms, turning joints and
contact columns, friction) are those of t* at the nominal speeds. Mesh stiffness is its mean: the variant is built
with ``[contact_assumed] stiffness_variation = "constant"`` (s(phi) = 1, the mean of eq. 11-12's series). Each
contact law then enters with its tangent at its static deflection delta_0 (the study's impact law: dF/d delta = 1.5
k delta_0^0.5; the ISO 6336 law: k).

The linearised equations over all ODE2 coordinates q (frames, modal and auxiliary coordinates) are

    M q'' + D_x q' + K q = C^T lambda,    C q = 0         (Exudyn: K = -df/dq, D_x = -df/dq')

with the constraint Jacobian C (mesh kinematics, drive, linear joints and seats). They are reduced in two exact
steps to independent coordinates z, q = B z:

1. constraints: C = [C_d C_i] over dependent and independent coordinates, q_d = -C_d^+ C_i q_i; the dependent ones
   are chosen by column-pivoted QR, massless coordinates (the contacts' deflections) first, so that z stays a
   subset of the physical coordinates with their labels;
2. massless coordinates left among the independent ones (the residual compliances of flexgear.mbs.residual) are
   condensed statically: z_0 = -K_00^-1 K_0m z_m (Guyan; exact for massless coordinates without damping, their
   damping is carried along the same transformation).

The reduced D_x splits into damping D (its symmetric part) and the gyroscopic matrix G (its skew part: the body
frames' Omega J_p E, the flexible bodies' 2 Omega G of flexgear.mbs.spin); K holds the spin softening -Omega^2 S
where it belongs. Left out: tooth friction's dependence on the state (it loads the operating point, a term of
order mu = 0.02 of the mesh stiffness in the tangent) and geometric stiffness of constraint reactions (all the
model's constraints are linear in the coordinates).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from flexgear.modal.carrier_frame import frame_pairs, orbit, to_carrier_frame
from flexgear.spec import Variant

__all__ = ["Coordinate", "LinearModel", "linearize", "ZERO_SPEED_RPM", "component_name", "with_speed",
           "coordinate_labels", "operating_point", "static_solver_settings"]

ZERO_SPEED_RPM = 1e-9
"""Speed [rpm] that stands for zero: the builder needs a drive sense and divides by the input speed. The spin
terms scale with Omega (gyroscopic, 1e-10 rad/s) and Omega^2: far below any tolerance."""

_MASSLESS = 1e-12  # diagonal mass, relative to the largest, below which a coordinate counts as massless
_RANK_TOL = 1e-10  # singular values of the constraint Jacobian below this fraction of the largest are redundant


@dataclass(frozen=True)
class Coordinate:
    """One ODE2 coordinate: its component (input_shaft, sun, planet_1..planet_N, ring, output_shaft, a mesh
    ``sun_planet_i`` / ``planet_i_ring``, or ``residual``), its kind (``frame``, ``elastic``, ``deflection``,
    ``residual``) and its name within the node (frame: u_x, u_y, u_z, phi_x, phi_y, phi_z [m, rad])."""

    component: str
    kind: str
    name: str

    @property
    def label(self) -> str:
        return f"{self.component}.{self.name}"


FRAME_NAMES = ("u_x", "u_y", "u_z", "phi_x", "phi_y", "phi_z")


@dataclass
class LinearModel:
    """The linearised gearbox (module docstring) in the independent coordinates z (q = ``basis`` z).

    ``mass``, ``damping``, ``gyroscopic``, ``stiffness``: M (symmetric), D (symmetric), G (skew), K on z [SI: kg,
    N s/m, N/m and their rotational counterparts]; ``coordinates``: the label of each z (a subset of the system's
    coordinates). ``full_*``: the same over all ODE2 coordinates q (for energies: the contact springs act on the
    deflection coordinates, which z leaves out). ``parts``: {frame node's first coordinate: [(component, 6x6 mass
    matrix)]} where one frame carries two components (a rigid gear and its rigid shaft as one body, or the tied
    ring and output shaft). ``elastic_parts``: {component: (indices in ``full_coordinates`` of its body's elastic
    coordinates q~, [(part, M_p, K_p)])} where one flexible body is two components (the tied ring and output
    shaft, flexgear.fe.ring_shaft.tied_part_matrices): each part's share of the body's modal mass and stiffness
    on q~, to split a mode's elastic energy between the parts. ``full_constraint`` (r, n): the constraint Jacobian
    C over q before the elimination (C q = 0); ``bodies`` and ``contacts``: the built model's bodies and gear
    contacts (flexgear.mbs.gearbox.GearboxModel), for the couplings of the full-FE check (flexgear.modal.full_fe).
    """

    variant: Variant
    speed_rpm: float
    mass: np.ndarray
    damping: np.ndarray
    gyroscopic: np.ndarray
    stiffness: np.ndarray
    coordinates: tuple[Coordinate, ...]
    basis: np.ndarray
    full_coordinates: tuple[Coordinate, ...]
    full_mass: np.ndarray
    full_stiffness: np.ndarray
    components: tuple[str, ...]
    flexible: tuple[str, ...] = ()
    parts: dict[int, list[tuple[str, np.ndarray]]] = field(default_factory=dict)
    static_deflections: dict[str, float] = field(default_factory=dict)  # contact name -> delta_0 [m]
    # contact name -> index in full_coordinates of its residual deflection e (flexgear.mbs.residual: the contact law
    # acts on delta - e where a flexible gear's dropped modes return as residual compliance); absent: none
    contact_residuals: dict[str, int] = field(default_factory=dict)
    static_residuals: dict[str, float] = field(default_factory=dict)  # contact name -> e_0 [m] at the operating point
    elastic_parts: dict[str, tuple[np.ndarray, list[tuple[str, np.ndarray, np.ndarray]]]] = field(
        default_factory=dict)
    full_constraint: np.ndarray | None = None
    bodies: dict = field(default_factory=dict)
    contacts: list = field(default_factory=list)

    @property
    def n(self) -> int:
        return self.mass.shape[0]

    @property
    def labels(self) -> tuple[str, ...]:
        return tuple(c.label for c in self.coordinates)

    def held(self, keep: np.ndarray) -> LinearModel:
        """The model with every independent coordinate outside the boolean mask ``keep`` held at zero (its rows and
        columns dropped): e.g. a planar model with axial motion and tilts held."""
        keep = np.asarray(keep, bool)
        ix = np.ix_(keep, keep)
        return dataclasses.replace(self, mass=self.mass[ix], damping=self.damping[ix], gyroscopic=self.gyroscopic[ix],
                                   stiffness=self.stiffness[ix], basis=self.basis[:, keep],
                                   coordinates=tuple(c for c, k in zip(self.coordinates, keep, strict=True) if k))

    def in_plane(self) -> LinearModel:
        """The planar model: frame translations u_x, u_y and spin phi_z kept, axial motion and tilts held (flexible
        bodies' elastic coordinates kept)."""
        return self.held(np.array([c.kind != "frame" or c.name in ("u_x", "u_y", "phi_z") for c in self.coordinates]))

    def undamped(self) -> LinearModel:
        """The same model without damping (D = 0; gyroscopic terms kept)."""
        return dataclasses.replace(self, damping=np.zeros_like(self.damping))


def component_name(body: str) -> str:
    """The component name of a body of the built gearbox: ``planet1`` -> ``planet_1``, any other name unchanged."""
    return f"planet_{body[len('planet'):]}" if body.startswith("planet") else body


def with_speed(variant: Variant, speed_rpm: float | None,
               cutoff_rpm: float | None = None) -> tuple[Variant, float]:
    """The variant with mean mesh stiffness and, if given, the input speed ``speed_rpm``; the gears' dynamic cut-off
    (``[reduction_assumed] dynamic_cutoff_mesh_orders`` x f_mesh, flexgear.mbs.gearbox) held at the mesh frequency
    of ``cutoff_rpm`` [rpm] (default: the load case's speed), so that the modes a gear keeps do not change with the
    speed analysed (at rest the cut-off would otherwise fall to zero)."""
    spec = variant.gearbox
    lc = spec.load_case
    speed = lc.input_speed_rpm if speed_rpm is None else float(speed_rpm)
    built = ZERO_SPEED_RPM if speed == 0.0 else speed
    reference = lc.input_speed_rpm if cutoff_rpm is None else float(cutoff_rpm)
    if not reference > 0.0:
        raise ValueError(f"cutoff_rpm must be > 0 rpm, got {cutoff_rpm!r}")
    spec = spec.with_fields("contact_assumed", stiffness_variation="constant")
    orders = spec.reduction_assumed.dynamic_cutoff_mesh_orders
    if orders > 0.0 and built != reference:  # f_mesh is proportional to the input speed
        spec = spec.with_fields("reduction_assumed", dynamic_cutoff_mesh_orders=orders * reference / built)
    spec = spec.with_fields("load_case", input_speed_rpm=built)
    return dataclasses.replace(variant, gearbox=spec), speed


def coordinate_labels(mbs, model, n: int) -> list[Coordinate]:
    """The label of every ODE2 coordinate of the built ``model`` (flexgear.mbs.gearbox.GearboxModel)."""
    out: list[Coordinate | None] = [None] * n

    def put(node: int, make) -> None:
        start = mbs.GetNodeODE2Index(node)
        size = len(mbs.GetNode(node)["referenceCoordinates"])
        for k in range(size):
            out[start + k] = make(k)

    for name, body in model.bodies.items():
        comp = component_name(name)
        put(body.node, lambda k, comp=comp: Coordinate(comp, "frame", FRAME_NAMES[k]))
        if body.flexible:
            offset = 0
            for node in getattr(body, "modal_nodes", ()) or ((body.modal_node,) if body.modal_node >= 0 else ()):
                put(node, lambda k, comp=comp, o=offset: Coordinate(comp, "elastic", f"q{o + k}"))
                offset += len(mbs.GetNode(node)["referenceCoordinates"])
    for node in model.aux_nodes:
        pair = mbs.GetNode(node)["name"].removeprefix("mesh_deflections_")
        comp = "_".join(component_name(p) for p in pair.split("_"))
        put(node, lambda k, comp=comp: Coordinate(comp, "deflection", f"delta_{k + 1}"))
    for i in range(n):  # residual compliances and anything else: by node name
        if out[i] is None:
            out[i] = Coordinate("residual", "residual", f"x{i}")
    return out  # type: ignore[return-value]


def _independent(constraint: np.ndarray, massless: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(T (n, n - r), independent coordinates (n - r,)): C T = 0 with T's rows of the independent coordinates the
    identity (module docstring, step 1). ``constraint``: C (m, n); ``massless``: (n,) bool, preferred as
    dependent coordinates."""
    from scipy.linalg import qr

    n = constraint.shape[1]
    if constraint.size == 0:
        return np.eye(n), np.arange(n)
    weight = np.where(massless, 1e6, 1.0)
    _, r, piv = qr(constraint * weight, pivoting=True, mode="economic")
    d = np.abs(np.diag(r))
    rank = int(np.count_nonzero(d > _RANK_TOL * d[0])) if d.size else 0
    dep, ind = piv[:rank], np.sort(piv[rank:])
    t = np.zeros((n, ind.size))
    t[ind, np.arange(ind.size)] = 1.0
    t[dep] = -np.linalg.lstsq(constraint[:, dep], constraint[:, ind], rcond=None)[0]
    return t, ind


def _condense(mass: np.ndarray, stiffness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Static condensation (step 2 of the module docstring): (basis (n, n - n_0), kept coordinates) eliminating
    the massless coordinates of ``mass``."""
    diag = np.abs(np.diag(mass))
    zero = diag <= _MASSLESS * diag.max()
    n = mass.shape[0]
    keep = np.flatnonzero(~zero)
    out = np.zeros((n, keep.size))
    out[keep, np.arange(keep.size)] = 1.0
    if zero.any():
        z = np.flatnonzero(zero)
        out[z] = -np.linalg.solve(stiffness[np.ix_(z, z)], stiffness[np.ix_(z, keep)])
    return out, keep


def _mass_parts(variant: Variant, model, mbs) -> dict[int, list[tuple[str, np.ndarray]]]:
    """6x6 frame mass matrix of each part of a rigid body that joins a gear and its shaft (flexgear.mbs.bodies.
    axisymmetric_frame_mass of each part's mass properties), keyed by the frame's first system coordinate."""
    from flexgear.geometry.massprops import inertia_about_point
    from flexgear.mbs.bodies import axisymmetric_frame_mass

    spec = variant.gearbox
    out = {}
    for gear, end in (("sun", model.input_body), ("ring", model.output_body)):
        if end != gear or (model.bodies[gear].flexible and not _tied(model.bodies[gear])):
            continue
        shaft = "input_shaft" if gear == "sun" else "output_shaft"
        if variant.rigid_mass_properties == "exact":
            props = {c: model.design.masses[c] for c in (gear, shaft)}
        else:
            from flexgear.fe.reduced import component_mass_properties as mesh_props

            props = {c: mesh_props(spec, c, variant.mesh_level) for c in (gear, shaft)}
        out[mbs.GetNodeODE2Index(model.bodies[gear].node)] = [
            (c, axisymmetric_frame_mass(p.mass, p.com, inertia_about_point(p), math.inf, c)[0])
            for c, p in props.items()]
    return out


def _tied(body) -> bool:
    """Whether ``body`` is the tied ring and output shaft (flexgear.fe.ring_shaft: its "ring_seat" interface)."""
    from flexgear.fe.reduced import is_tied

    return bool(body.flexible) and is_tied(body.reduced)


def _elastic_parts(variant: Variant, model, mbs) -> dict[str, tuple[np.ndarray, list]]:
    """The tied body's parts' shares of its modal mass and stiffness on its coordinates q~ (LinearModel)."""
    from flexgear.fe.ring_shaft import tied_part_matrices

    out = {}
    for name, body in model.bodies.items():
        if not _tied(body):
            continue
        nodes = getattr(body, "modal_nodes", ()) or (body.modal_node,)
        index = np.concatenate([mbs.GetNodeODE2Index(nd) + np.arange(len(mbs.GetNode(nd)["referenceCoordinates"]))
                                for nd in nodes])
        t = np.eye(body.reduced.n_modes) if body.basis is None else body.basis  # q = T q~
        parts = tied_part_matrices(variant.gearbox, variant.mesh_level)
        out[component_name(name)] = (index, [(part, t.T @ m_p @ t, t.T @ k_p @ t)
                                             for part, (m_p, k_p) in parts.items()])
    return out


def operating_point(mbs, model, variant: Variant, t_star: float, passes: int = 3) -> None:
    """Static equilibrium at time ``t_star`` (module docstring), left in the system's initial configuration."""
    import exudyn as exu

    from flexgear.laws.ramps import drive_angle

    spec = variant.gearbox
    th, lc = model.theory, spec.load_case
    theta = float(drive_angle(t_star, lc.ramp_time_s, lc.input_speed_rad_s))
    q0 = np.array(mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Initial))
    v0 = np.zeros_like(q0)
    shafts = {"sun": th.input_speed, "input_shaft": th.input_speed, "ring": th.output_speed,
              "output_shaft": th.output_speed}
    if "carrier" in model.bodies:  # planetary: the ring held, the carrier turning, the planets orbiting with it
        shafts.update(ring=0.0, carrier=th.output_speed)
        theta_c, omega_c = carrier_angle(model, spec, t_star)
    for name, body in model.bodies.items():  # the nominal kinematics at t*: spin angle and speed of every frame
        w = shafts.get(name, th.planet_speed)
        i = mbs.GetNodeODE2Index(body.node)
        q0[i + 5], v0[i + 5] = theta * w / th.input_speed, w
        if name.startswith("planet") and "carrier" in model.bodies:
            q0[i:i + 2], v0[i:i + 2] = orbit(body.position, theta_c, omega_c)
            if name in model.carrier_seat_nodes:  # its seat node (at the bore centre, on the planet's axis) too
                j = mbs.GetNodeODE2Index(model.carrier_seat_nodes[name])
                q0[j:j + 2], v0[j:j + 2] = q0[i:i + 2], v0[i:i + 2]
                q0[j + 5], v0[j + 5] = q0[i + 5], v0[i + 5]
    for node in model.carrier_pin_nodes.values():  # the carrier's pins (their nodes) orbit and turn with it
        j = mbs.GetNodeODE2Index(node)
        q0[j:j + 2], v0[j:j + 2] = orbit(np.asarray(mbs.GetNode(node)["referenceCoordinates"][:3]), theta_c, omega_c)
        q0[j + 5], v0[j + 5] = theta_c, omega_c
    mbs.systemData.SetODE2Coordinates(q0, exu.ConfigurationType.Initial)
    mbs.systemData.SetODE2Coordinates_t(v0, exu.ConfigurationType.Initial)
    pre = mbs.GetPreStepUserFunction()
    pre = pre.get("function") if isinstance(pre, dict) else pre
    pre = pre if callable(pre) else None
    mbs.SetPreStepUserFunction(0)
    ss = static_solver_settings(t_star)
    was = exu.config.printToConsole
    exu.config.printToConsole = False
    try:
        for _ in range(passes):  # the per-step updates (friction: from the state) and the equilibrium, alternately
            mbs.systemData.SetODE2Coordinates(q0, exu.ConfigurationType.Current)
            mbs.systemData.SetODE2Coordinates_t(v0, exu.ConfigurationType.Current)
            if pre is not None:
                pre(mbs, t_star)
            if not _solve_static(mbs, ss):
                raise RuntimeError(f"{variant.name}: no static equilibrium at t = {t_star:g} s")
            q0 = np.array(mbs.systemData.GetODE2Coordinates())
            if pre is None:
                break
    finally:
        exu.config.printToConsole = was
    mbs.systemData.SetODE2Coordinates(q0, exu.ConfigurationType.Initial)
    mbs.systemData.SetODE2Coordinates_t(v0, exu.ConfigurationType.Initial)


def carrier_angle(model, spec, t_star: float | np.ndarray) -> tuple[float | np.ndarray, float]:
    """(angle [rad], rate [rad/s]) of the planetary stage's nominal carrier at ``t_star`` [s] (a time, or an array
    of times and then their angles): the drive's angle and speed times the carrier's ratio z_s / (z_s + z_r)."""
    from flexgear.laws.ramps import drive_angle

    th, lc = model.theory, spec.load_case
    ratio = th.output_speed / th.input_speed
    angle = ratio * np.asarray(drive_angle(np.asarray(t_star, float), lc.ramp_time_s, lc.input_speed_rad_s))
    return (float(angle) if angle.ndim == 0 else angle), th.output_speed


RETRY_RELATIVE_TOLERANCES = (1e-10, 1e-8)
"""Newton's relative tolerances of further static solves where the first (1e-12) stalls at round-off, whose level
follows the model's conditioning (flexible gears, at some of their angles): a residual 1e-8 of the load moves the
operating point by about that share, far below any modal quantity."""


def _solve_static(mbs, ss) -> bool:
    """Exudyn's static solve with :func:`static_solver_settings`, again at each of :data:`RETRY_RELATIVE_TOLERANCES`
    while Newton stalls at round-off, each attempt from the same start; False when none converges."""
    import exudyn as exu

    start = np.array(mbs.systemData.GetODE2Coordinates())
    newton = ss.staticSolver.newton
    for tolerance in (newton.relativeTolerance, *RETRY_RELATIVE_TOLERANCES):
        newton.relativeTolerance = max(newton.relativeTolerance, tolerance)
        mbs.systemData.SetODE2Coordinates(start, exu.ConfigurationType.Current)
        try:
            if mbs.SolveStatic(ss, showHints=False):
                return True
        except exu.SolverError:
            pass
    return False


def static_solver_settings(t_star: float):
    """Static-solver settings: full Newton at the quasi-time ``t_star``, load steps with a vanishing mass
    stabiliser (a contact law whose tangent vanishes at zero deflection, the impact law's, starts regular)."""
    import exudyn as exu

    ss = exu.SimulationSettings()
    st = ss.staticSolver
    st.loadStepStart = t_star
    st.loadStepDuration = 1e-12
    st.numberOfLoadSteps = 10
    st.stabilizerODE2term = 1.0
    st.newton.relativeTolerance = 1e-12
    st.newton.absoluteTolerance = 1e-10
    st.newton.useModifiedNewton = False
    st.newton.maxIterations = 50
    ss.linearSolver.solverType = exu.LinearSolverType.EigenDense
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = math.inf
    return ss


def linearize(variant: Variant, speed_rpm: float | None = None, *, t_star: float | None = None,
              cutoff_rpm: float | None = None, mass_source=None, reduced_source=None) -> LinearModel:
    """The variant linearised at its operating point (module docstring).

    ``speed_rpm``: input speed [rpm] (default the load case's; 0 stands for :data:`ZERO_SPEED_RPM`); the load
    torque is the load case's. ``cutoff_rpm`` [rpm]: the speed whose mesh frequency sets the gears' dynamic
    cut-off (default the load case's: the same modes at every speed analysed). ``t_star`` [s]: the time of the
    operating point (default the ramp time; it sets the gears' angles, on which flexible gears' contact columns
    depend). ``mass_source``, ``reduced_source``: as
    flexgear.mbs.gearbox.build_star_gearbox.
    """
    import exudyn as exu
    from threadpoolctl import threadpool_limits

    from flexgear.mbs.assemble import build_gearbox

    built, speed = with_speed(variant, speed_rpm, cutoff_rpm)
    spec = built.gearbox
    t_star = spec.load_case.ramp_time_s if t_star is None else float(t_star)
    sc = exu.SystemContainer()
    try:
        mbs = sc.AddSystem()
        with threadpool_limits(limits=1, user_api="blas"):
            model = build_gearbox(mbs, built, mass_source, reduced_source)
        mbs.Assemble()
        operating_point(mbs, model, built, t_star)
        ss = static_solver_settings(t_star)
        m, k, dx, c = (np.asarray(a, float) for a in exu.solver.ComputeLinearizedSystem(
            mbs, ss, returnConstraintJacobian=True, autoAssemble=False))
        n = m.shape[0]
        if "carrier" in model.bodies:  # the planetary stage: its equations in the carrier's axes
            theta_c, omega_c = carrier_angle(model, spec, t_star)
            m, dx, k, c = to_carrier_frame(m, dx, k, c.T if c.size else c, frame_pairs(mbs, model), theta_c, omega_c)
            c = c.T if c.size else c
        labels = coordinate_labels(mbs, model, n)
        q = np.array(mbs.systemData.GetODE2Coordinates())
        rows = [mbs.GetNodeODE2Index(node) + k for node in model.aux_nodes
                for k in range(len(mbs.GetNode(node)["referenceCoordinates"]))]  # contacts in order
        static = {contact.name: float(q[i]) for contact, i in zip(model.contacts, rows, strict=True)}
        residuals: dict[str, int] = {}
        if int(model.residual_node) >= 0 and model.residual is not None:  # the laws act on delta - e (residual.py)
            first = mbs.GetNodeODE2Index(model.residual_node)
            residuals = {model.contacts[int(r)].name: first + k for k, r in enumerate(model.residual.rows)}
        static_residuals = {name: float(q[i]) for name, i in residuals.items()}
        parts = _mass_parts(built, model, mbs)
        elastic_parts = _elastic_parts(built, model, mbs)
    finally:
        sc.Reset()
    c = c.T if c.size else np.zeros((0, n))  # (constraints, coordinates)
    diag = np.abs(np.diag(m))
    t1, ind = _independent(c, diag <= _MASSLESS * diag.max())
    t2, keep = _condense(t1.T @ m @ t1, t1.T @ k @ t1)
    basis = t1 @ t2
    coords = [labels[i] for i in ind[keep]]  # z_j is the system coordinate ind[keep[j]]
    mr, kr, dr = (basis.T @ a @ basis for a in (m, k, dx))
    flexible = tuple(component_name(nm) for nm, b in model.bodies.items() if b.flexible)
    flexible += tuple(part for _, split in elastic_parts.values() for part, _, _ in split if part not in flexible)
    components = _components(spec.gears.planet_count, "carrier" in model.bodies)
    return LinearModel(variant, speed, 0.5 * (mr + mr.T), 0.5 * (dr + dr.T), 0.5 * (dr - dr.T), kr, tuple(coords),
                       basis, tuple(labels), m, k, components, flexible, parts, static, residuals,
                       static_residuals, elastic_parts, c, model.bodies, model.contacts)


def _components(planets: int, carrier: bool = False) -> tuple[str, ...]:
    """The components whose energy shares the modes report: the gearbox file's, and the turning carrier of the
    planetary stage."""
    return ("input_shaft", "sun", *(f"planet_{i + 1}" for i in range(planets)), "ring", "output_shaft",
            *(("carrier",) if carrier else ()))
