"""The linear floating frame (flexgear.mbs.spin), gear-shaft joints and seat bearings (flexgear.mbs.joints).

Checked against an independent implementation, Exudyn's own nonlinear ``ObjectFFRFreducedOrder``: at a
spinning state with elastic coordinates and velocities, both give the same modal accelerations (the
gyroscopic, spin-softening and centrifugal terms of the linear form are exact for a body spinning about its
axis); the ramp schedule adds exactly the difference to the scheduled spin; a short run of model 4 and of
model 7 in the production formulation keeps the reference formulation's mean mesh forces (0.1 %) and 1x mesh
amplitudes (2 %), the agreement rule (flexgear.study.agreement) for a faster formulation.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import VARIANTS

import flexgear as fg
from flexgear.fe.reduced import component_reduced_body
from flexgear.study.agreement import harmonic_amplitudes


@pytest.fixture(scope="module")
def gearbox():
    return fg.load_gearbox(VARIANTS / "gearbox.toml")


def _modal_acceleration(body, reference: bool, spin: float, q: np.ndarray, q_t: np.ndarray) -> np.ndarray:
    """Accelerations of all coordinates (frame, then modal) of one free spinning body, from Exudyn's equations."""
    import exudyn as exu

    from flexgear.mbs.flexible import add_flexible_body
    from flexgear.mbs.spin import SpinSchedule

    mbs = exu.SystemContainer().AddSystem()
    b = add_flexible_body(mbs, "b", body, [0.0, 0.0, 0.0], angular_velocity=(0.0, 0.0, spin), interface_markers=[],
                          show=False, reference=reference, nominal_spin_rad_s=spin, stiffness_damping_s=1e-5)
    mbs.SetNodeParameter(b.modal_node, "initialCoordinates", list(q))
    mbs.SetNodeParameter(b.modal_node, "initialCoordinates_t", list(q_t))
    schedule = None if reference else SpinSchedule(mbs, [b], 1e-3, 1e-4)
    mbs.Assemble()
    if schedule is not None:  # after the ramp: the spin terms at the nominal spin
        schedule(mbs, 1.0)
    solver = exu.MainSolverImplicitSecondOrder()
    solver.InitializeSolver(mbs, exu.SimulationSettings())
    solver.ComputeODE2RHS(mbs)
    n = solver.GetODE2size()
    rhs = np.asarray(solver.GetSystemResidual())[:n]
    solver.ComputeMassMatrix(mbs)
    return np.linalg.solve(np.asarray(solver.GetSystemMassMatrix())[:n, :n], rhs)


@pytest.mark.parametrize("component, spin", [("ring", -203.3), ("sun", 628.3)])
def test_linear_modal_equations_equal_exudyns_floating_frame(gearbox, component, spin):
    """Ring at the output speed, sun at the input speed (Table 5), 12 modes, elastic coordinates of a few
    micrometres and velocities: the modal accelerations of the linear form equal the FFRF object's within 1e-8."""
    body = component_reduced_body(gearbox, component).truncated(12)
    rng = np.random.default_rng(7)
    q = rng.normal(size=12) * 1e-4 / np.sqrt(body.stiffness)
    q_t = rng.normal(size=12) * 1e-3
    ref = _modal_acceleration(body, True, spin, q, q_t)[6:]
    new = _modal_acceleration(body, False, spin, q, q_t)[6:]
    assert np.abs(new - ref).max() < 1e-8 * np.abs(ref).max()
    # the spin terms matter here: without them the accelerations differ by far more than that
    assert np.abs(_modal_acceleration(body, False, 0.0, q, q_t)[6:] - ref).max() > 1e-4 * np.abs(ref).max()


def test_spin_schedule_follows_the_ramp(gearbox):
    """The schedule's matrices at time t are the spin terms at the ramp's speed Omega(t) = Omega_n STEP(t):
    K = Lambda - Omega^2 S, D = D_0 + 2 Omega G; its load Omega(t)^2 c; G skew, S symmetric."""
    from types import SimpleNamespace

    from flexgear.laws.ramps import ramp_fraction
    from flexgear.mbs.spin import SpinSchedule, spin_matrices

    body = component_reduced_body(gearbox, "ring").truncated(10)
    s = spin_matrices(body)
    assert np.allclose(s.gyroscopic, -s.gyroscopic.T) and np.allclose(s.softening, s.softening.T)
    nominal, ramp = -203.3, 0.1
    m = body.n_modes
    flex = SimpleNamespace(reduced=body, spin=s, nominal_spin_rad_s=nominal,
                           modal_matrices=(np.eye(m), np.diag(body.stiffness), np.diag(1e-5 * body.stiffness)))
    sched = SpinSchedule.__new__(SpinSchedule)
    sched.ramp_time, sched.bodies, sched.cent = ramp, [flex], nominal ** 2 * s.centrifugal
    for t in (0.0, 0.03, 0.07, 0.2):
        w = nominal * ramp_fraction(t, ramp)
        (k, d), = sched.matrices(t)
        assert np.allclose(k, np.diag(body.stiffness) - w * w * s.softening, rtol=1e-12, atol=1e-9)
        assert np.allclose(d, np.diag(1e-5 * body.stiffness) + 2 * w * s.gyroscopic, rtol=1e-12, atol=1e-12)
        assert np.allclose(sched.force(t), w * w * s.centrifugal, rtol=1e-12, atol=0.0)


def test_spin_schedule_writes_its_own_numbers():
    """The pre-step writes, bit for bit, :meth:`SpinSchedule.force` every step and :meth:`SpinSchedule.matrices`
    when due: a dense body's matrices as arrays (Exudyn stores them as dense matrices), a sparse body's as the
    triplets of flexgear.mbs.bodies.matrix_container."""
    from types import SimpleNamespace

    from flexgear.mbs.bodies import matrix_container
    from flexgear.mbs.spin import SpinMatrices, SpinSchedule

    rng = np.random.default_rng(7)

    def body(m: int, dense: bool, nominal: float, obj: int):
        g = rng.normal(size=(m, m)) if dense else np.zeros((m, m))
        s = rng.normal(size=(m, m)) if dense else np.diag(rng.uniform(1.0, 2.0, m))
        lam = rng.uniform(1e6, 1e8, m)
        spin = SpinMatrices(g - g.T, s + s.T, rng.normal(size=m))
        return SimpleNamespace(reduced=SimpleNamespace(n_modes=m), spin=spin, nominal_spin_rad_s=nominal,
                               modal_nodes=[obj], modal_equations=obj,
                               modal_matrices=(np.eye(m), np.diag(lam), np.diag(1e-5 * lam)))

    class Recorder:
        def __init__(self):
            self.written = {}

        def AddObject(self, item):  # noqa: N802 (Exudyn's name)
            return 99

        def SetObjectParameter(self, obj, param, value):  # noqa: N802 (Exudyn's name)
            self.written[obj, param] = value

    bodies = [body(5, True, 203.3, 1), body(4, False, -71.9, 2)]
    rec = Recorder()
    sched = SpinSchedule(rec, bodies, 0.1, 0.015)
    for t, due in ((0.0, True), (0.013, False), (0.019, True), (0.031, False), (0.1, True)):
        rec.written.clear()
        sched(rec, t)
        assert np.array_equal(rec.written[99, "forceVector"], sched.force(t))
        if not due:
            assert sorted(rec.written) == [(99, "forceVector")]
            continue
        (k0, d0), (k1, d1) = sched.matrices(t)
        assert np.array_equal(rec.written[1, "stiffnessMatrix"], k0)
        assert np.array_equal(rec.written[1, "dampingMatrix"], d0)
        for param, a in (("stiffnessMatrix", k1), ("dampingMatrix", d1)):
            triplets = rec.written[2, param].GetPythonObject()["triplets"]
            assert np.array_equal(triplets, matrix_container(a).GetPythonObject()["triplets"])
    assert sched.finished


def _short_runs(case: str, formulations: tuple[str, ...]):
    """``case`` on a short load case in each formulation, on the modes production keeps dynamic and with no dropped
    modes: each flexible body truncated to its modes below the dynamic cut-off (``[reduction_assumed]
    dynamic_cutoff_mesh_orders`` x the mesh frequency), every one of them dynamic (the reference's generic joints and
    marker seats have no residual seat coordinates, and this compares formulations, not the residual reduction,
    tests/test_residual.py). Both formulations get the same bodies."""
    from flexgear.fe.ring_shaft import reduced_body
    from flexgear.mbs.run import run_variant

    v = fg.load_variant(VARIANTS / f"{case}.toml")
    g = v.gearbox
    f_mesh = fg.theory(g).mesh_frequency
    cutoff_hz = g.reduction_assumed.dynamic_cutoff_mesh_orders * f_mesh
    assert cutoff_hz > 0.0

    def truncated(spec, component: str, level: str):
        body = reduced_body(spec, component, level)
        return body.truncated(body.modes_below(cutoff_hz))

    lc = dataclasses.replace(g.load_case, ramp_time_s=0.006, end_time_s=0.024)
    runs = []
    for formulation in formulations:
        spec = g.with_changes(load_case=lc).with_fields("solver_assumed", formulation=formulation)
        spec = spec.with_fields("reduction_assumed", dynamic_cutoff_mesh_orders=0.0)
        run = run_variant(dataclasses.replace(v, gearbox=spec), reduced_source=truncated)
        assert run.ok, run.meta.get("reason")
        runs.append(run)
    return runs, f_mesh


def _assert_same_mesh_signals(ref, new, f_mesh: float, mean_rel: float, amp_rel: float) -> None:
    """Every mesh force of ``new`` against ``ref`` (signal frames): means within ``mean_rel``, 1x mesh amplitudes
    within ``amp_rel``."""
    dt = float(np.median(np.diff(ref.time_s.to_numpy())))
    for kind in ("outer", "inner"):
        for i in range(1, 6):
            col = f"{kind}_mesh_force_{i}_n"
            assert new[col].mean() == pytest.approx(ref[col].mean(), rel=mean_rel), col
            a_ref, a_new = (harmonic_amplitudes(s[col].to_numpy(), dt, f_mesh, (1,))[0] for s in (ref, new))
            assert a_new == pytest.approx(a_ref, rel=amp_rel), col


@pytest.mark.parametrize("case", [pytest.param("model4", marks=pytest.mark.slow),
                                  pytest.param("model7", marks=pytest.mark.heavy)])
def test_production_keeps_the_reference_signals(case):
    """The reference formulation (Exudyn's FFRF and rigid bodies, generic joints, seat springs on virtual nodes,
    Exudyn's Newton policy) against the production one (linear floating frames, body frames, joints and seat
    bearings, the Jacobian economy), the study's law, 6-18 ms after the ramps: mean mesh forces within 0.1 %, their
    1x mesh amplitudes within 2 % (the agreement rule); model 7's ring joint torque (twelve bolts off the axis)
    within 0.1 % (model 7's reference, every mode dynamic, takes minutes: heavy)."""
    runs, f_mesh = _short_runs(case, ("reference", "production"))
    ref, new = (r.signals[r.signals.time_s >= 0.012] for r in runs)
    _assert_same_mesh_signals(ref, new, f_mesh, 1e-3, 0.02)
    ring = "joint_torque_ring_nm"
    if ring in runs[0].meta:
        assert abs(runs[1].meta[ring]) == pytest.approx(abs(runs[0].meta[ring]), rel=1e-3)


def test_seat_bearing_matrix_is_the_three_springs(gearbox):
    """The linear seat's 6x6 stiffness (the bearing element's, flexgear.geometry.elements) equals the three
    springs' sum the reference formulation puts on the axis: radial k_r, axial k_a, tilt k_t about the centre (two
    rows of k_r/2 at +-sqrt(k_t/k_r)), no translation-tilt coupling; damping the springs' dampers summed."""
    from flexgear.geometry.supports import gearbox_supports
    from flexgear.mbs.bodies import frame_rows

    sup = gearbox_supports(gearbox)["output_shaft"]
    k6, d6 = sup.stiffness, sup.damping
    springs, dampers = np.zeros((6, 6)), np.zeros((6, 6))
    for spring in sup.axis_springs():
        b = frame_rows(spring.point - sup.centre)[:3]
        springs += b.T @ np.diag(spring.stiffness) @ b
        dampers += b.T @ np.diag(spring.damping) @ b
    table = gearbox.bearings.output_shaft
    expected = np.diag([table.radial_stiffness_n_per_m, table.radial_stiffness_n_per_m,
                        table.axial_stiffness_n_per_m, table.tilt_stiffness_nm_per_rad,
                        table.tilt_stiffness_nm_per_rad, 0.0])
    assert np.allclose(k6, expected, rtol=1e-12, atol=1e-9 * table.radial_stiffness_n_per_m)
    assert np.allclose(springs, k6, rtol=1e-12, atol=1e-9 * table.radial_stiffness_n_per_m)
    assert np.allclose(d6, table.damping_per_stiffness_s * k6)
    assert np.allclose(dampers, d6, rtol=1e-12, atol=1e-9 * np.abs(d6).max())


def test_turning_blocks_kernel_equals_the_rotation():
    """The compiled kernel that turns the linear joints' and seats' coefficients writes, at each column's own
    spin a, blockdiag(R_z(a), R_z(a)) rows for modal columns and the constant [I, -p~; 0, I] for the frame
    columns of a point p on the axis, each into its constraint's matrix; numpy reference TurningBlocks.turned."""
    from flexgear.laws.ramps import drive_angle
    from flexgear.mbs.joints import TurningBlocks, frame_form, turning_form

    rng = np.random.default_rng(5)
    rows = rng.normal(size=(6, 3))
    point = np.array([0.0, 0.0, 0.03])
    joint = (1, "scalingMarker0", *(np.hstack([f, m]) for f, m in zip(frame_form(point), turning_form(rows),
                                                                       strict=True)), 1.0)
    seat = (2, "scalingMarker1", *turning_form(rows[:, :2]), -0.3)
    blocks = TurningBlocks([joint, seat], 0.5, 628.3)

    class Recorder:
        written: dict = {}

        def SetObjectParameter(self, obj, param, value):  # noqa: N802 (Exudyn's name)
            self.written[obj, param] = np.array(value)

    def rz(a):
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    rec = Recorder()
    for t in (0.0, 0.21, 0.7):
        blocks(rec, t)
        theta = float(drive_angle(t, 0.5, 628.3))
        r6 = np.kron(np.eye(2), rz(theta))
        x = rz(theta) @ point
        frame = np.eye(6)
        frame[:3, 3:] = -np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])
        assert np.allclose(rec.written[1, "scalingMarker0"], np.hstack([frame, r6 @ rows]), rtol=1e-12, atol=1e-12)
        assert np.allclose(rec.written[2, "scalingMarker1"], np.kron(np.eye(2), rz(-0.3 * theta)) @ rows[:, :2],
                           rtol=1e-12, atol=1e-12)
        assert np.allclose(blocks.turned(t), np.hstack([rec.written[1, "scalingMarker0"],
                                                        rec.written[2, "scalingMarker1"]]), rtol=1e-13, atol=1e-13)


def test_interface_coordinates_are_an_exact_change_of_coordinates(gearbox):
    """The output shaft's basis with its ring joint (bolt patches) and bearing seat as coordinates
    (flexgear.mbs.flexible.interface_basis): the first twelve coordinates are the two interfaces' RBE3 motions
    (P T = [I, 0]), the mass matrix is blockdiag((P P^T)^-1, I) exactly, and the free frequencies in the new
    coordinates are the modal ones (generalised eigenvalues of T^T Lambda T, T^T T) within 1e-9."""
    import scipy.linalg

    from flexgear.fe.reduced import gear_shaft_joints
    from flexgear.mbs.flexible import interface_basis, interface_mass

    body = component_reduced_body(gearbox, "output_shaft")
    names = (gear_shaft_joints(gearbox, "ring")[0][1], "bearing_seat")
    t = interface_basis(body, names)
    p = np.vstack([body.interface_motion(n) for n in names])
    expected = np.hstack([np.eye(12), np.zeros((12, body.n_modes - 12))])
    assert np.abs(p @ t - expected).max() < 1e-9
    mass = interface_mass(t, 12)
    assert np.allclose(mass, t.T @ t, rtol=0.0, atol=1e-9 * np.abs(mass).max())
    lam = scipy.linalg.eigh(t.T @ np.diag(body.stiffness) @ t, mass, eigvals_only=True)
    assert np.allclose(np.sort(lam), np.sort(body.stiffness), rtol=1e-9)
    assert interface_basis(body.truncated(10), names) is None  # ten modes cannot carry twelve interface motions


def test_interface_coordinates_shrink_model7s_constraints(gearbox):
    """Model 7 on interface coordinates: the ring and the output shaft are one body (no joint between them), the
    ring's mesh constraints span its sensed coordinates only (its contact tables vanish on every other coordinate);
    model 4 (flexible ring, rigid output shaft): the ring joint's constraint spans the ring's frame and the six
    coordinates of its bolt patches, and the shaft's frame."""
    import exudyn as exu

    from flexgear.mbs.gearbox import build_star_gearbox

    v = fg.load_variant(VARIANTS / "model7.toml")
    spec = v.gearbox
    mbs = exu.SystemContainer().AddSystem()
    model = build_star_gearbox(mbs, v)
    assert "output_shaft" not in model.bodies and "ring" not in model.joints
    mbs4 = exu.SystemContainer().AddSystem()
    build_star_gearbox(mbs4, fg.load_variant(VARIANTS / "model4.toml"))
    joint = mbs4.GetObject(mbs4.GetObjectNumber("joint_ring_output_shaft"))
    assert np.shape(joint["scalingMarker0"]) == (6, 12) and np.shape(joint["scalingMarker1"]) == (6, 6)
    # the ring's contacts sense one node: at most 2 x (2 x 8 + 1) coordinates (two helix halves, Fourier order 8)
    ring = model.bodies["ring"]
    sensed = ring.node_columns(ring.contact_nodes)
    assert len(sensed) <= 2 * (2 * spec.reduction_assumed.contact_fourier_order + 1) < ring.reduced.n_modes
    kin = model.kinematics
    tables = kin.tables[[k for k, b in enumerate(kin.bodies) if b == "ring"]]
    other = np.setdiff1d(np.arange(ring.reduced.n_modes), sensed)
    assert np.abs(tables[:, :, other]).max() < 1e-8 * np.abs(tables).max()
    mesh = mbs.GetObject(mbs.GetObjectNumber("mesh_kinematics_planet1_ring"))
    assert np.shape(mesh["scalingMarker1"]) == (2, model.bodies["planet1"].reduced.n_modes + len(sensed))
