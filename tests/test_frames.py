"""Linear body frames of the production formulation (flexgear.mbs.bodies.add_linear_frame) against Exudyn's
``ObjectRigidBody`` (the reference formulation)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import flexgear as fg
from flexgear.mbs.bodies import add_linear_frame, axisymmetric_frame_mass, matrix_container, zero_user_jacobian

VARIANTS = Path(__file__).resolve().parents[1] / "model_variants"

# a rotor with its centre of mass on the axis above the frame origin, on tilt and translation springs
MASS, J_T, J_P, C_Z, K_TILT, K_TRANS, SPIN = 3.0, 0.02, 0.03, 0.04, 2e5, 1e8, 600.0


def _rotor_tilts(linear: bool) -> np.ndarray:
    """Frame coordinates over 20 ms of the rotor spinning at SPIN [rad/s], started with a tilt rate about x."""
    import exudyn as exu
    from exudyn.itemInterface import NodeRigidBodyRxyz, ObjectGenericODE2, ObjectRigidBody, SensorNode
    from exudyn.rigidBodyUtilities import InertiaTensor2Inertia6D

    j_origin = np.diag([J_T + MASS * C_Z**2, J_T + MASS * C_Z**2, J_P])
    mbs = exu.SystemContainer().AddSystem()
    node = mbs.AddNode(NodeRigidBodyRxyz(referenceCoordinates=[0.0] * 6,
                                         initialVelocities=[0.0, 0.0, 0.0, 1e-2, 0.0, SPIN]))
    if linear:
        frame = add_linear_frame(mbs, "rotor", node, MASS, [0.0, 0.0, C_Z], j_origin, SPIN, 1e-9)
        mbs.SetObjectParameter(frame.obj, "dampingMatrix", matrix_container(frame.gyroscopic(SPIN)))
    else:
        mbs.AddObject(ObjectRigidBody(nodeNumber=node, mass=MASS, inertia=InertiaTensor2Inertia6D(j_origin),
                                      centerOfMass=[0.0, 0.0, C_Z]))
    k = np.diag([K_TRANS] * 3 + [K_TILT, K_TILT, 0.0])
    mbs.AddObject(ObjectGenericODE2(nodeNumbers=[node], stiffnessMatrix=matrix_container(k),
                                    dampingMatrix=matrix_container(np.zeros((6, 6))),
                                    jacobianUserFunction=zero_user_jacobian(6)))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=exu.OutputVariableType.Coordinates,
                                      storeInternal=True))
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.timeIntegration.endTime, s.timeIntegration.numberOfSteps = 0.02, 4000
    s.timeIntegration.newton.relativeTolerance = 1e-10
    s.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    s.solution.file.write, s.timeIntegration.verboseMode = False, 0
    mbs.SolveDynamic(s)
    return mbs.GetSensorStoredData(sensor)[:, 1:]


def test_linear_frame_follows_exudyns_rigid_body():
    """A spinning rotor (600 rad/s, centre of mass 40 mm up the axis) on springs, kicked about x: the linear frame's
    translations and tilts equal Exudyn's nonlinear ``ObjectRigidBody`` within 1e-6 of their amplitudes (second
    order in the micro-radian tilts), so its gyroscopic term and mass coupling are right."""
    exact, linear = _rotor_tilts(False), _rotor_tilts(True)
    for col in (0, 1, 3, 4):
        amplitude = np.abs(exact[:, col]).max()
        assert amplitude > 0
        assert np.abs(linear[:, col] - exact[:, col]).max() < 1e-6 * amplitude, col
    assert linear[-1, 5] == pytest.approx(exact[-1, 5], rel=1e-9)  # the free spin


def test_gyroscopic_whirl_frequencies():
    """The frame's linear equations on tilt springs have the rigid rotor's whirl frequencies (centre of mass at the
    origin): J_t w^2 -+ J_p Omega w - k_t = 0, forward and backward."""
    m6, polar = axisymmetric_frame_mass(MASS, np.zeros(3), np.diag([J_T, J_T, J_P]), 1e-9)
    frame = fg.LinearFrame(-1, polar, SPIN)
    tilt = [3, 4]
    m, d = m6[np.ix_(tilt, tilt)], frame.gyroscopic(SPIN)[np.ix_(tilt, tilt)]
    k = K_TILT * np.eye(2)
    # first-order form of M q'' + D q' + K q = 0
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(m, k), -np.linalg.solve(m, d)]])
    computed = np.sort(np.abs(np.linalg.eigvals(a).imag))[::2]
    root = np.sqrt((J_P * SPIN) ** 2 + 4 * J_T * K_TILT)
    expected = np.sort([(root - J_P * SPIN) / (2 * J_T), (root + J_P * SPIN) / (2 * J_T)])
    assert computed == pytest.approx(expected, rel=1e-10)


def test_asymmetric_body_is_refused():
    """A body whose centre of mass sits off the axis by 1 % of its radius of gyration: a clear error, not a silently
    dropped imbalance."""
    r_g = np.sqrt(J_P / MASS)
    with pytest.raises(ValueError, match="frame_axisymmetry_tolerance"):
        axisymmetric_frame_mass(MASS, [0.01 * r_g, 0.0, 0.0], np.diag([J_T, J_T, J_P]), 1e-4)


def test_asymmetric_body_takes_the_exact_frame():
    """The same body added as a frame (flexgear.mbs.bodies.add_frame_inertia): Exudyn's exact ``ObjectRigidBody``,
    which keeps the imbalance, instead of the linear frame; an axisymmetric one gets the linear frame."""
    import exudyn as exu
    from exudyn.itemInterface import NodeRigidBodyRxyz

    from flexgear.mbs.bodies import add_frame_inertia

    r_g = np.sqrt(J_P / MASS)
    mbs = exu.SystemContainer().AddSystem()
    for offset, linear in ((0.01 * r_g, False), (0.0, True)):
        node = mbs.AddNode(NodeRigidBodyRxyz(referenceCoordinates=[0.0] * 6))
        obj, frame = add_frame_inertia(mbs, f"body_{linear}", node, MASS, [offset, 0.0, 0.0],
                                       np.diag([J_T, J_T, J_P]), SPIN, 1e-4)
        assert (frame is not None) == linear
        assert ("GenericODE2" if linear else "RigidBody") in str(mbs.GetObject(obj)["objectType"])


def _model1_runs(ramp_time_s: float, end_time_s: float) -> list:
    """Model 1 on a shortened load case in the reference and the production formulation."""
    from flexgear.mbs.run import run_variant

    v = fg.load_variant(VARIANTS / "model1.toml")
    g = v.gearbox
    lc = dataclasses.replace(g.load_case, ramp_time_s=ramp_time_s, end_time_s=end_time_s)
    runs = []
    for value in ("reference", "production"):
        solver = dataclasses.replace(g.solver_assumed, formulation=value)
        run = run_variant(dataclasses.replace(v, gearbox=g.with_changes(load_case=lc, solver_assumed=solver)))
        assert run.ok, run.meta.get("reason")
        runs.append(run)
    return runs


def test_model1_signals_with_linear_frames():
    """Model 1 (every body rigid, bearings at their seats) in the production formulation (linear frames, the
    Jacobian economy, a reused sparse ordering) against the reference (Exudyn's rigid bodies and Newton policy),
    20 ms ramps, steady window 40-60 ms: every signal's mean within 0.1 % and 1x mesh amplitude within 2 % (the
    agreement rule, flexgear.study.agreement)."""
    from flexgear.study.agreement import signal_agreement

    runs = _model1_runs(0.02, 0.06)
    agreement = signal_agreement(*runs, (0.04, 0.06), runs[0].meta["theory"]["mesh_frequency_hz"])
    assert agreement.ok(), agreement.table.sort_values("mean_diff").to_string()
