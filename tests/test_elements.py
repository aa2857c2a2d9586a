"""The bearing element (flexgear.geometry.elements): its matrices, its lever transformation, the lumped condensation,
and rigid bodies on it with the natural frequencies the analytic two-degree-of-freedom models predict, for the
production frame bearing, the reference's axis springs and the planet bearing on a carrier (Exudyn's eigenvalues).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from flexgear.geometry.elements import BearingElement, FixedJointElement
from flexgear.geometry.massprops import annulus_mass_properties
from flexgear.geometry.supports import gearbox_supports

DISC = dict(inner_radius=0.02, outer_radius=0.1, width=0.03, density=7850.0)  # a steel disc [m, kg/m^3]
LEVER_M = 0.05  # bearing centre to the disc's centre of mass along the axis [m]
FRAME_TOLERANCE = 1e-6  # axisymmetry tolerance of the production linear frame (the disc is exactly axisymmetric)


def _skew(r: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def test_element_is_the_three_axis_springs(gearbox):
    """Each Table 2 bearing's 6x6 stiffness and damping about its centre equal its three axis springs' sum,
    sum_k G_k^T diag(k) G_k with G_k = [I, -(p_k - c)~] (u = t + phi x r); both are diag(k_r, k_r, k_a, k_t, k_t, 0)
    and D = c K."""
    for name, bearing in gearbox_supports(gearbox).items():
        k6, d6 = np.zeros((6, 6)), np.zeros((6, 6))
        for spring in bearing.axis_springs():
            g = np.hstack([np.eye(3), -_skew(spring.point - bearing.centre)])
            k6 += g.T @ np.diag(spring.stiffness) @ g
            d6 += g.T @ np.diag(spring.damping) @ g
        table = getattr(gearbox.bearings, name)
        k_r, k_a, k_t = (table.radial_stiffness_n_per_m, table.axial_stiffness_n_per_m,
                         table.tilt_stiffness_nm_per_rad)
        expected = np.diag([k_r, k_r, k_a, k_t, k_t, 0.0])
        np.testing.assert_allclose(bearing.stiffness, expected, rtol=0.0, atol=0.0)
        np.testing.assert_allclose(k6, bearing.stiffness, rtol=1e-12, atol=1e-12 * k_r)
        np.testing.assert_allclose(d6, bearing.damping, rtol=1e-12, atol=1e-12 * k_r * table.damping_per_stiffness_s)
        np.testing.assert_allclose(bearing.damping, table.damping_per_stiffness_s * expected, rtol=1e-15)


def test_at_keeps_the_strain_energy_of_a_rigid_lever():
    """Seen from q, the bearing's energy 1/2 x_q^T K_q x_q equals 1/2 x_c^T K x_c for the rigid motion
    x_c = (u_q + phi x (c - q), phi) of its centre c; and moving on again is moving directly (T(a) T(b) = T(a + b))."""
    rng = np.random.default_rng(3)
    k = rng.normal(size=(6, 6))
    element = BearingElement("shaft", np.array([0.0, 0.0, -0.12]), k @ k.T, 1e-5 * k @ k.T)
    q, p = np.array([0.0, 0.0, 0.07]), np.array([0.0, 0.0, 0.3])
    seen = element.at(q)
    for x in rng.normal(size=(5, 6)):
        at_centre = np.concatenate([x[:3] + np.cross(x[3:], element.centre - q), x[3:]])
        energy = 0.5 * at_centre @ element.stiffness @ at_centre
        assert 0.5 * x @ seen.stiffness @ x == pytest.approx(energy, rel=1e-12)
        assert 0.5 * x @ seen.damping @ x == pytest.approx(0.5 * at_centre @ element.damping @ at_centre, rel=1e-12)
    np.testing.assert_allclose(seen.at(p).stiffness, element.at(p).stiffness, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(seen.at(element.centre).stiffness, element.stiffness, rtol=1e-12, atol=1e-9)
    assert seen.body == element.body and np.array_equal(seen.centre, q)


def test_lumped_condensation(gearbox):
    """The in-plane stiffness at the gear centre: 1/k = 1/k_r + L^2/k_t (a force at the gear, no moment), equal to
    the static condensation of the element seen from the gear (at(gear), its (u_x, phi_y) block inverted); the
    stiffness-proportional damping condenses to c k. The lumped model's supports are these."""
    from flexgear.lumped.model import LumpedParameters

    supports = gearbox_supports(gearbox)
    for bearing in supports.values():
        k_r, k_t = bearing.stiffness[0, 0], bearing.stiffness[3, 3]
        lever = -bearing.centre[2]
        k = bearing.condensed_radial_stiffness()
        assert k == pytest.approx(1.0 / (1.0 / k_r + lever**2 / k_t), rel=1e-15)
        block = bearing.at(np.zeros(3)).stiffness[np.ix_([0, 4], [0, 4])]
        assert k == pytest.approx(1.0 / np.linalg.inv(block)[0, 0], rel=1e-9)
        c = bearing.damping[0, 0] / k_r
        assert bearing.condensed_radial_damping() == pytest.approx(c * k, rel=1e-12)
    params = LumpedParameters.from_spec(gearbox)
    assert params.sun.bearing_stiffness_n_per_m == supports["input_shaft"].condensed_radial_stiffness()
    assert params.planet.bearing_stiffness_n_per_m == supports["planet"].condensed_radial_stiffness()
    no_tilt = BearingElement.axisymmetric("shaft", 1e8, 1e7, 0.0, 1e-5, centre=(0.0, 0.0, 0.1))
    assert no_tilt.condensed_radial_stiffness() == 0.0  # a shaft on one point bearing carries no in-plane force
    assert no_tilt.condensed_radial_stiffness(gear_z=0.1) == 1e8


def _disc_frequencies(bearing: BearingElement, formulation: str) -> np.ndarray:
    """Squared natural frequencies [rad^2/s^2] of a rigid disc on ``bearing`` to ground (Exudyn's eigenvalues):
    production, the linear frame on its 6x6 frame bearing; reference, ObjectRigidBody on the three axis springs."""
    import exudyn as exu

    from flexgear.mbs.bodies import add_rigid_body
    from flexgear.mbs.elements import add_support

    mbs = exu.SystemContainer().AddSystem()
    props = annulus_mass_properties(**DISC)
    tolerance = FRAME_TOLERANCE if formulation == "production" else None
    body = add_rigid_body(mbs, bearing.body, props, np.zeros(3), 0.0, tolerance)
    add_support(mbs, body, bearing)
    mbs.Assemble()
    values, _ = exu.solver.ComputeODE2Eigenvalues(mbs)
    return np.sort(np.asarray(values, float))


def _coupled(m: float, tilt_inertia: float, k_r: float, k_t: float, lever: float) -> list[float]:
    """Squared frequencies of a disc (mass m, tilt inertia I about its centre of mass) on a bearing at ``lever`` L
    on its axis: (k_r - m w^2)(k_t + k_r L^2 - I w^2) = k_r^2 L^2, the roots of
    m I w^4 - (m (k_t + k_r L^2) + I k_r) w^2 + k_r k_t = 0."""
    b = m * (k_t + k_r * lever**2) + tilt_inertia * k_r
    root = math.sqrt(b**2 - 4.0 * m * tilt_inertia * k_r * k_t)
    return [(b - root) / (2.0 * m * tilt_inertia), (b + root) / (2.0 * m * tilt_inertia)]


@pytest.mark.parametrize("formulation", ["production", "reference"])
@pytest.mark.parametrize("lever", [0.0, LEVER_M])
def test_rigid_disc_on_its_bearing_has_the_analytic_frequencies(gearbox, formulation, lever):
    """Bearing at the centre of mass: w^2 = k_r/m (twice), k_a/m, k_t/I_t (twice) and the free spin 0, decoupled.
    Bearing a lever L off it: translation and tilt couple (:func:`_coupled`), the axial mode stays k_a/m."""
    table = gearbox.bearings.output_shaft
    bearing = BearingElement.from_bearing(table, "disc", (0.0, 0.0, lever))
    props = annulus_mass_properties(**DISC)
    m, tilt_inertia = props.mass, props.inertia[0, 0]
    k_r, k_a, k_t = (table.radial_stiffness_n_per_m, table.axial_stiffness_n_per_m, table.tilt_stiffness_nm_per_rad)
    pair = _coupled(m, tilt_inertia, k_r, k_t, lever)
    expected = np.sort([0.0, k_a / m, *pair, *pair])
    if lever == 0.0:
        np.testing.assert_allclose(sorted(pair), sorted([k_r / m, k_t / tilt_inertia]), rtol=1e-12)
    values = _disc_frequencies(bearing, formulation)
    assert abs(values[0]) < 1e-9 * expected[-1]
    np.testing.assert_allclose(values[1:], expected[1:], rtol=1e-9)


def test_planet_bearing_on_a_held_carrier_has_the_analytic_frequencies(gearbox):
    """A planet disc on its bearing on a carrier held in place: the same frequencies as on ground, w^2 = k_r/m,
    k_a/m, k_t/I_t and its free spin (the carrier's six held coordinates removed from the problem)."""
    import exudyn as exu

    from flexgear.mbs.bodies import add_rigid_body
    from flexgear.mbs.carrier import add_planet_bearing

    table = gearbox.bearings.planet
    props = annulus_mass_properties(**DISC)
    mbs = exu.SystemContainer().AddSystem()
    carrier = add_rigid_body(mbs, "carrier", annulus_mass_properties(0.02, 0.3, 0.02, DISC["density"]), np.zeros(3))
    planet = add_rigid_body(mbs, "planet1", props, np.array([0.2, 0.0, 0.0]))
    add_planet_bearing(mbs, carrier, planet, BearingElement.from_bearing(table, "planet1", other="carrier"))
    mbs.Assemble()
    held = [mbs.GetNodeODE2Index(carrier.node) + k for k in range(6)]
    values, _ = exu.solver.ComputeODE2Eigenvalues(mbs, constrainedCoordinates=held)
    m, tilt_inertia = props.mass, props.inertia[0, 0]
    k_r, k_a, k_t = (table.radial_stiffness_n_per_m, table.axial_stiffness_n_per_m, table.tilt_stiffness_nm_per_rad)
    expected = np.sort([0.0, k_r / m, k_r / m, k_a / m, k_t / tilt_inertia, k_t / tilt_inertia])
    values = np.sort(np.asarray(values, float))
    assert abs(values[0]) < 1e-9 * expected[-1]
    np.testing.assert_allclose(values[1:], expected[1:], rtol=1e-9)
    with pytest.raises(ValueError, match="placed"):
        add_planet_bearing(mbs, carrier, planet, BearingElement.from_bearing(table, "planet2", other="carrier"))


def test_fixed_joint_element_names_the_gear_shaft_joint(gearbox):
    """The gear-shaft joints (flexgear.fe.reduced.gear_shaft_joints) as elements: gear and shaft interfaces and the
    point on the axis."""
    from flexgear.fe.reduced import gear_shaft_joints

    for gear, shaft in (("sun", "input_shaft"), ("ring", "output_shaft")):
        for found in gear_shaft_joints(gearbox, gear):
            joint = FixedJointElement.gear_shaft(gear, shaft, found)
            assert (joint.body, joint.other, joint.interfaces) == (gear, shaft, (found[0], found[1]))
            np.testing.assert_array_equal(joint.point, found[2])
            assert math.hypot(joint.point[0], joint.point[1]) == 0.0
