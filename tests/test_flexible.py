"""Flexible bodies (flexgear.fe.fem, flexgear.fe.cms, flexgear.mbs.flexible) against independent results.

Coarse second-order meshes of plain rings and tubes built here with netgen.occ; each test checks
a number that theory or an independent computation predicts.
"""

from __future__ import annotations

import functools
import time

import numpy as np
import pytest
import scipy.sparse.linalg as sla

from flexgear.fe.cms import FreeBodySolver, full_free_modes, interface, rbe3_rows, reduce
from flexgear.fe.fem import fe_model, kron3_operator
from flexgear.fe.reduced import cached_reduced_body
from flexgear.mbs.flexible import add_flexible_body
from flexgear.spec import Material

STEEL = Material(density_kg_m3=7850.0, youngs_modulus_pa=2.1e11, poisson_ratio=0.3)
RING_R, RING_T, RING_B = 0.155, 0.006, 0.010  # mean radius, radial thickness, width [m] (thin: t/R = 0.04)


@functools.cache
def ring_mesh(maxh: float):
    """Plain ring (annulus of RING_* dimensions) centred at the origin, axis z; top face named. Meshed once per
    process and size: fe_model raises the order on a copy, so the tests that share it leave it unchanged."""
    import ngsolve as ngs
    from netgen.occ import Axes, Cylinder, OCCGeometry, X, Z

    axes = Axes((0, 0, -RING_B / 2), Z, X)
    ring = Cylinder(axes, RING_R + RING_T / 2, RING_B) - Cylinder(axes, RING_R - RING_T / 2, RING_B)
    ring.faces.Max(Z).name = "top"
    return ngs.Mesh(OCCGeometry(ring).GenerateMesh(maxh=maxh))


def tube_mesh(r_out: float, r_in: float, length: float, maxh: float):
    """Tube along z from 0 to length with end faces "root" (z = 0) and "tip" (z = length)."""
    import ngsolve as ngs
    from netgen.occ import Axes, Cylinder, OCCGeometry, X, Z

    axes = Axes((0, 0, 0), Z, X)
    tube = Cylinder(axes, r_out, length) - Cylinder(axes, r_in, length)
    tube.faces.Min(Z).name = "root"
    tube.faces.Max(Z).name = "tip"
    return ngs.Mesh(OCCGeometry(tube).GenerateMesh(maxh=maxh))


def thin_ring_frequency_hz(n: int) -> float:
    """In-plane flexural frequency of a free thin ring (Hoppe; Blevins, Formulas for natural frequency):
    omega_n = n (n^2 - 1) / sqrt(n^2 + 1) * sqrt(E I / (rho A R^4)), I = b t^3 / 12, A = b t."""
    e, rho = STEEL.youngs_modulus_pa, STEEL.density_kg_m3
    i_area, area = RING_B * RING_T**3 / 12, RING_B * RING_T
    return n * (n * n - 1) / np.sqrt(n * n + 1) * np.sqrt(e * i_area / (rho * area * RING_R**4)) / (2 * np.pi)


def patch_interfaces(fe, count: int, half_angle_deg: float = 3.0):
    """``count`` small patches on the ring's outer surface, equally spaced (like bolt or mesh pads)."""
    outer = fe.nodes_where(lambda x: np.hypot(x[:, 0], x[:, 1]) > RING_R + RING_T / 2 - 1e-7)
    itfs = []
    for k in range(count):
        ang = 2 * np.pi * k / count
        near = fe.nodes_where(lambda x, a=ang: np.abs(np.angle(np.exp(1j * (np.arctan2(x[:, 1], x[:, 0]) - a))))
                              < np.radians(half_angle_deg), outer)
        itfs.append(interface(fe, near, f"pad{k}"))
    return itfs


@pytest.fixture(scope="module")
def ring_fe():
    return fe_model(ring_mesh(0.004), STEEL, order=2)


@pytest.fixture(scope="module")
def coarse_ring_fe():
    return fe_model(ring_mesh(0.008), STEEL, order=2)


def _wave_number(fe, shape: np.ndarray) -> tuple[int, float]:
    """Circumferential wave number of a mode (dominant harmonic of its radial displacement) and
    its out-of-plane (z) share of the displacement norm."""
    u = shape.reshape(-1, 3)
    theta = np.arctan2(fe.nodes[:, 1], fe.nodes[:, 0])
    radial = (u[:, 0] * np.cos(theta) + u[:, 1] * np.sin(theta))
    power = [abs(np.sum(radial * np.exp(-1j * k * theta))) for k in range(9)]
    return int(np.argmax(power)), float(np.sum(u[:, 2] ** 2) / np.sum(u**2))


def test_thin_ring_inplane_frequencies_match_classical_formula(ring_fe):
    freqs, shapes = full_free_modes(ring_fe, 12)
    found: dict[int, list[float]] = {}
    for f, shape in zip(freqs, shapes.T, strict=True):
        n, z_share = _wave_number(ring_fe, shape)
        if z_share < 0.05:  # in-plane flexural mode
            found.setdefault(n, []).append(f)
    for n in (2, 3, 4):
        assert len(found.get(n, [])) == 2, f"expected a degenerate pair for n = {n}, found {found}"
        for f in found[n]:
            assert f == pytest.approx(thin_ring_frequency_hz(n), rel=0.02)


def test_reduced_frequencies_match_full_fe_and_rigid_patches_stiffen(ring_fe):
    pads = patch_interfaces(ring_fe, 3)
    body = reduce(ring_fe, pads, 20, kind="rbe3", n_compare=8)
    # first six flexible free-free frequencies of the reduced body against the full FE model
    assert body.frequencies_hz[:6] == pytest.approx(body.full_frequencies_hz[:6], rel=0.01)
    # modes are mass-normalised, M-orthogonal to the rigid-body motion (mean axes)
    m = ring_fe.M
    assert np.allclose(body.modes.T @ (m @ body.modes), np.eye(body.n_modes), atol=1e-8)
    stiff = reduce(ring_fe, pads, 20, kind="rbe2", n_compare=0)
    assert stiff.frequencies_hz[0] > 1.01 * body.frequencies_hz[0]  # rigid pads stiffen the ring


def test_mass_operator_equals_the_assembled_mass_matrix(coarse_ring_fe):
    """M as an operator (Ms (x) I_3 on the nodes' rows) gives the assembled M's products, of the whole body and
    of a subset of its nodes, for one vector and for a block."""
    fe = coarse_ring_fe
    rng = np.random.default_rng(3)
    x = rng.standard_normal((fe.n_dof, 5))
    m = fe.M
    for got, want in ((fe.mass_operator() @ x, m @ x), (fe.mass_operator() @ x[:, 0], m @ x[:, 0])):
        np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-14 * np.abs(want).max())
    nodes = np.arange(0, fe.n_nodes, 3)
    dofs = (3 * nodes[:, None] + np.arange(3)).ravel()
    want = m[dofs][:, dofs] @ x[dofs]
    np.testing.assert_allclose(fe.mass_operator(nodes) @ x[dofs], want, rtol=1e-14, atol=1e-14 * np.abs(want).max())
    assert kron3_operator(fe.mass_scalar).shape == m.shape


def test_constrained_solve_without_load_equals_a_zero_load(coarse_ring_fe):
    """solve(None, e) skips the K_ff solve of a zero load and returns the very same displacements."""
    con = FreeBodySolver(coarse_ring_fe).constrained(rbe3_rows(coarse_ring_fe, interface(coarse_ring_fe, "top")))
    e = np.random.default_rng(4).standard_normal((6, 10))
    np.testing.assert_array_equal(con.solve(None, e), con.solve(np.zeros((coarse_ring_fe.n_dof, 10)), e))


def test_reduced_mass_properties_equal_exact_annulus(coarse_ring_fe):
    body = reduce(coarse_ring_fe, ["top"], 6, n_compare=0)
    ro, ri = RING_R + RING_T / 2, RING_R - RING_T / 2
    mass = STEEL.density_kg_m3 * np.pi * (ro**2 - ri**2) * RING_B
    i_zz = mass * (ro**2 + ri**2) / 2
    i_xx = mass * (3 * (ro**2 + ri**2) + RING_B**2) / 12
    props = body.props
    assert props.mass == pytest.approx(mass, rel=1e-3)
    assert np.allclose(np.diag(props.inertia), [i_xx, i_xx, i_zz], rtol=1e-3)
    assert np.linalg.norm(props.com) < 1e-9
    # the floating-frame terms the Exudyn body uses carry the same mass and inertia (about its origin)
    assert float(body.invariants["mass"]) == pytest.approx(mass, rel=1e-3)
    assert np.allclose(body.invariants["inertia"], props.inertia, rtol=1e-3, atol=1e-9 * i_zz)


def test_ffrf_invariants_equal_exudyn_reference(coarse_ring_fe):
    from exudyn.FEM import FEMinterface, ObjectFFRFreducedOrderInterface

    body = reduce(coarse_ring_fe, ["top"], 8, n_compare=0)
    fem = FEMinterface()
    fem.nodes = {"Position": coarse_ring_fe.nodes}
    fem.massMatrix, fem.stiffnessMatrix = coarse_ring_fe.M, coarse_ring_fe.K
    fem.modeBasis = {"matrix": body.modes}
    fem.surface = [{"Name": "surface", "Trigs": coarse_ring_fe.surface_triangles}]
    ref = ObjectFFRFreducedOrderInterface(fem)
    expected = {"mass": ref.totalMass, "centerOfMass": ref.chiU, "inertia": ref.inertiaLocal,
                "mPsiTildePsi": ref.mPsiTildePsi, "mPsiTildePsiTilde": ref.mPsiTildePsiTilde,
                "mPhitTPsi": ref.mPhitTPsi, "mPhitTPsiTilde": ref.mPhitTPsiTilde,
                "mXRefTildePsi": ref.mXRefTildePsi, "mXRefTildePsiTilde": ref.mXRefTildePsiTilde}
    for key, value in expected.items():
        value = np.asarray(value)
        assert np.allclose(body.invariants[key], value, atol=1e-12 * max(1.0, np.abs(value).max())), key
    assert np.allclose(ref.stiffnessMatrixReduced, np.diag(body.stiffness), atol=1e-8 * body.stiffness.max())


def test_tube_static_bending_matches_beam_theory_and_full_fe():
    import exudyn as exu
    from exudyn.itemInterface import GenericJoint, LoadForceVector, MarkerBodyRigid, ObjectGround

    r_out, r_in, length, force = 0.025, 0.015, 0.15, 1000.0  # input shaft tube (gearbox.toml)
    fe = fe_model(tube_mesh(r_out, r_in, length, 0.006), STEEL, order=2)
    e, nu = STEEL.youngs_modulus_pa, STEEL.poisson_ratio
    i_area, area, m2 = np.pi / 4 * (r_out**4 - r_in**4), np.pi * (r_out**2 - r_in**2), (r_in / r_out) ** 2
    kappa = 6 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)  # Cowper 1966
    timoshenko = force * length**3 / (3 * e * i_area) + force * length / (kappa * e / (2 * (1 + nu)) * area)

    # full FE, root face clamped, tip force distributed over the tip face: plane-section beam theory
    tip = interface(fe, "tip")
    clamped = np.ones(fe.n_dof, bool)
    clamped[(3 * fe.region("root")[:, None] + np.arange(3)).ravel()] = False
    load = np.zeros(fe.n_dof)
    load[3 * tip.nodes] = force * tip.weights
    u = np.zeros(fe.n_dof)
    k_cc = fe.K[clamped][:, clamped].tocsc()
    u[clamped] = sla.splu(k_cc, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True}).solve(load[clamped])
    assert tip.weights @ u[3 * tip.nodes] == pytest.approx(timoshenko, rel=0.02)

    # reduced body in Exudyn: root interface fixed to ground, force on the tip marker. Craig-Bampton
    # is exact for static interface loads, so it must equal the full FE model under the same
    # distributing (RBE3) root constraint; that root is a little softer than a clamp (warping).
    body = reduce(fe, ["root", "tip"], 6, n_compare=0)
    solver = FreeBodySolver(fe)
    u_rbe3 = solver.constrained(rbe3_rows(fe, body.interface("root"))).solve(load, np.zeros((6, 1)))[:, 0]
    full_rbe3 = tip.weights @ u_rbe3[3 * tip.nodes]

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    flex = add_flexible_body(mbs, "tube", body, [0.0, 0.0, 0.0], show=False, reference=True)
    ground = mbs.AddObject(ObjectGround())
    m_ground = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=list(body.interface("root").point)))
    mbs.AddObject(GenericJoint(markerNumbers=[m_ground, flex.interface_markers["root"]], constrainedAxes=[1] * 6))
    mbs.AddLoad(LoadForceVector(markerNumber=flex.interface_markers["tip"], loadVector=[force, 0.0, 0.0]))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.staticSolver.verboseMode = 0
    exu.SolveStatic(mbs, settings)
    tip_x = mbs.GetMarkerOutput(flex.interface_markers["tip"], exu.OutputVariableType.Position)[0] - tip.point[0]
    assert tip_x == pytest.approx(full_rbe3, rel=1e-4)
    assert tip_x == pytest.approx(timoshenko, rel=0.03)


def test_spinning_ring_expands_and_keeps_angular_momentum(coarse_ring_fe):
    """Free ring spun at omega: hoop stress rho omega^2 R^2 stretches it by dR = rho omega^2 R^3 / E;
    with no torque, I omega is conserved, so omega drops by 2 dR / R (thin ring)."""
    import exudyn as exu
    from exudyn.itemInterface import SensorNode

    body = reduce(coarse_ring_fe, ["top"], 40, n_compare=0)  # 40 modes reach the breathing mode (5.3 kHz)
    omega = 600.0
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    flex = add_flexible_body(mbs, "ring", body, [0.0, 0.0, 0.0], angular_velocity=[0.0, 0.0, omega], reference=True,
                             stiffness_damping_s=2e-5, show=False)
    sensor = mbs.AddSensor(SensorNode(nodeNumber=flex.node, storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.AngularVelocity))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.endTime = 0.01
    settings.timeIntegration.numberOfSteps = 500
    settings.timeIntegration.generalizedAlpha.spectralRadius = 0.5
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False
    exu.SolveDynamic(mbs, settings)
    q = mbs.GetNodeOutput(flex.modal_node, exu.OutputVariableType.Coordinates)
    u = (body.modes @ q).reshape(-1, 3)
    theta = np.arctan2(body.nodes[:, 1], body.nodes[:, 0])
    growth = np.mean(u[:, 0] * np.cos(theta) + u[:, 1] * np.sin(theta))
    expected = STEEL.density_kg_m3 * omega**2 * RING_R**3 / STEEL.youngs_modulus_pa
    assert growth == pytest.approx(expected, rel=0.02)
    w = mbs.GetSensorStoredData(sensor)
    assert w[-1, 3] / omega - 1 == pytest.approx(-2 * growth / RING_R, rel=0.05)
    assert np.abs(w[:, 1:3]).max() < 1e-9 * omega  # no wobble of a balanced ring


def test_cache_builds_once_and_loads_fast(coarse_ring_fe, tmp_path):
    calls = []

    def build():
        calls.append(1)
        return reduce(coarse_ring_fe, ["top"], 4, n_compare=2)

    first = cached_reduced_body("abc123", build, tmp_path)
    t0 = time.perf_counter()
    again = cached_reduced_body("abc123", build, tmp_path)
    assert len(calls) == 1 and time.perf_counter() - t0 < 1.0
    assert np.array_equal(first.modes, again.modes) and again.interface("top").name == "top"
    assert np.allclose(first.full_frequencies_hz, again.full_frequencies_hz)
    cached_reduced_body("def456", build, tmp_path)  # another key (changed input) rebuilds
    assert len(calls) == 2


def test_virtual_interface_marker_moves_as_rbe3_marker_over_the_real_nodes(coarse_ring_fe):
    """The six-node interface marker equals Exudyn's own weighted marker over the interface's
    real node set (same RBE3 weights) in position and rotation, for a deformed, moved body."""
    import exudyn as exu
    from exudyn.itemInterface import MarkerSuperElementRigid

    body = reduce(coarse_ring_fe, ["top"], 8, n_compare=0)
    itf = body.interface("top")
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    flex = add_flexible_body(mbs, "ring", body, [0.01, -0.02, 0.03], rotation_matrix=_rot_z(0.7), show=False,
                             reference=True)
    real = mbs.AddMarker(MarkerSuperElementRigid(bodyNumber=flex.obj, offset=[0.0, 0.0, 0.0],
                                                 meshNodeNumbers=itf.nodes, weightingFactors=itf.weights,
                                                 useAlternativeApproach=True))
    q = 1.0 * np.random.default_rng(1).standard_normal(body.n_modes)
    assert np.abs(body.interface_motion("top") @ q).max() > 1e-5  # the modes move and turn the interface
    mbs.SetNodeParameter(flex.modal_node, "initialCoordinates", list(q))
    mbs.Assemble()
    ovt = exu.OutputVariableType
    virtual = flex.interface_markers["top"]
    for var in (ovt.Position, ovt.RotationMatrix):
        a = np.asarray(mbs.GetMarkerOutput(real, var, exu.ConfigurationType.Initial))
        b = np.asarray(mbs.GetMarkerOutput(virtual, var, exu.ConfigurationType.Initial))
        assert np.abs(a - b).max() < 1e-12 + 1e-9 * np.abs(a).max()


def _rot_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
