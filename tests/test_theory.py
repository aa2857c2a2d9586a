"""Theoretical values of the study and the gear relations they rest on."""

import math

import numpy as np
import pytest

from flexgear.geometry.contact_lines import contact_line_distribution, mesh_stiffness_harmonics
from flexgear.geometry.involute import gear_set_geometry, inv
from flexgear.laws.ramps import step, step_integral
from flexgear.theory import theory


def test_step_function_values():
    # ADAMS STEP(x, x0, h0, x1, h1): ends, midpoint (cubic is symmetric), clipping
    assert step(0.0, 0.0, 0.0, 0.5, 1.0) == 0.0
    assert step(0.25, 0.0, 0.0, 0.5, 1.0) == pytest.approx(0.5)
    assert step(0.5, 0.0, 0.0, 0.5, 6000.0) == pytest.approx(6000.0)
    assert step(0.7, 0.0, 0.0, 0.5, 557.025) == pytest.approx(557.025)
    assert step(0.1, 0.0, 2.0, 0.5, 4.0) == pytest.approx(2.0 + 2.0 * 0.04 * 2.6)


def test_step_integral_is_the_integral_of_step():
    t = np.linspace(0.0, 0.6, 60001)
    numeric = np.concatenate([[0.0], np.cumsum(0.5 * (step(t[1:], 0, 0, 0.5, 1) + step(t[:-1], 0, 0, 0.5, 1)))
                              * (t[1] - t[0])])
    assert np.max(np.abs(step_integral(t, 0.5, 1.0) - numeric)) < 1e-9
    assert step_integral(0.6, 0.5, 2.0) == pytest.approx(2.0 * (0.6 - 0.25))


def test_study_theory_values(gearbox):
    th = theory(gearbox)
    assert th.input_speed_deg_per_s == pytest.approx(36000.0)  # section 3.1
    assert th.output_speed_deg_per_s == pytest.approx(-11647.0588, abs=1e-4)  # -36000 * 44/136
    assert th.input_torque == pytest.approx(557.025 * 44 / 136)
    assert th.mesh_force == pytest.approx(798.21, abs=0.01)  # study quotes 798.1894 N
    assert th.mesh_frequency == pytest.approx(4400.0)
    assert th.planet_speed == pytest.approx(-th.input_speed * 44 / 45)


def test_profile_shifts_give_one_centre_distance_and_backlash(gearbox):
    geo = gear_set_geometry(gearbox)
    aw = geo.centre_distance
    assert aw == pytest.approx(0.10526)
    for mesh, z1, z2 in ((geo.sun_planet, 44, 45), (geo.planet_ring, 45, -136)):
        x1, x2 = mesh.gear1.shift, mesh.gear2.shift  # ISO 21771: internal gear has z2 < 0
        alpha_t = mesh.gear1.transverse_pressure_angle
        # forward no-backlash equation from the solved shifts, then the centre distance
        inv_w = inv(alpha_t) + 2 * math.tan(mesh.gear1.normal_pressure_angle) * (x1 + x2) / (z1 + z2)
        alpha_w = mesh.operating_pressure_angle
        assert inv(alpha_w) == pytest.approx(inv_w, rel=1e-12)
        a0 = abs(z1 + z2) * mesh.gear1.transverse_module / 2
        assert a0 * math.cos(alpha_t) / math.cos(alpha_w) == pytest.approx(aw, rel=1e-12)
        assert mesh.normal_backlash > 0
        assert 1.2 < mesh.transverse_contact_ratio < 2.5
    # operating pressure angles of a 105.26 mm centre distance (prototype notes: 18.02 and 13.52 deg)
    assert math.degrees(geo.sun_planet.operating_pressure_angle) == pytest.approx(18.02, abs=0.01)
    assert math.degrees(geo.planet_ring.operating_pressure_angle) == pytest.approx(13.51, abs=0.01)
    # tip clearance stays positive at the common centre distance
    assert aw - geo.sun.tip_radius - geo.planet.root_radius > 0.1e-3
    assert geo.ring.root_radius - aw - geo.planet.tip_radius > 0.1e-3


def _contact_line_length(phi: np.ndarray, eps_a: float, eps_b: float, n_y: int = 4000) -> np.ndarray:
    """Brute force: total length of the contact lines in the field of action (x: base pitches, y: face)."""
    y = (np.arange(n_y) + 0.5) / n_y
    total = np.zeros_like(phi)
    for k in range(-10, 11):
        x = phi[:, None] + k - eps_b * y[None, :]
        total += np.mean((x >= 0) & (x <= eps_a), axis=1)
    return total


@pytest.mark.parametrize(("eps_a", "eps_b"), [(1.69, 0.95), (2.2, 0.95), (1.4, 0.3)])
def test_mesh_stiffness_harmonics_match_contact_line_length(eps_a, eps_b):
    phi = np.arange(2000) / 2000
    length = _contact_line_length(phi, eps_a, eps_b)
    mean = length.mean()
    assert mean == pytest.approx(eps_a, rel=1e-3)  # mean number of lines = eps_alpha
    c = mesh_stiffness_harmonics(eps_a, eps_b, 3)
    model = 1 + sum(cn * np.cos(2 * np.pi * (n + 1) * (phi - 0.5 * (eps_a + eps_b))) for n, cn in enumerate(c))
    for n in range(1, 4):
        numeric = 2 * np.mean(length / mean * np.exp(-2j * np.pi * n * phi))
        analytic = 2 * np.mean(model * np.exp(-2j * np.pi * n * phi))
        assert abs(numeric - analytic) < 2e-3


def _sampled_contact_lines(phi: np.ndarray, eps_a: float, eps_b: float, x_p: float, n_y: int
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Brute force: length, sliding direction and lever of the contact lines, midpoint rule over n_y face points."""
    y = (np.arange(n_y) + 0.5) / n_y
    length, signed, lever = np.zeros_like(phi), np.zeros_like(phi), np.zeros_like(phi)
    teeth = range(-10, 11)
    for k in teeth:
        x = phi[:, None] + k - eps_b * y[None, :]
        inside = (x >= 0) & (x <= eps_a)
        length += inside.mean(axis=1)
        signed += (inside * np.sign(x - x_p)).mean(axis=1)
        lever += (inside * np.abs(x - x_p)).mean(axis=1)
    return length, signed / length, lever / length, math.ceil(eps_a + eps_b) + 1


@pytest.mark.parametrize(("eps_a", "eps_b", "x_p"), [(1.69, 0.95, 0.83), (2.2, 0.95, 1.3), (1.4, 0.3, 0.25)])
def test_contact_line_integrals_match_dense_sampling(eps_a, eps_b, x_p):
    """The closed-form contact-line integrals (both models' friction arms) against dense sampling of the face.

    Sampling error bound: per contact line the midpoint rule is exact but for the cells at its <= 3 jumps (two field
    ends, the sign change at the pitch point), each wrong by at most 1/n_y of the line times the integrand's bound;
    with at most n_lines lines in the field, |dL| <= 2 n_lines / n_y, |dS| <= 3 n_lines / n_y,
    |dLambda| <= 2 n_lines g / n_y (g = max |x - x_p|), and the ratios kappa = S/L, lambda = Lambda/L move by at most
    (|dS| + |kappa| |dL|) / L and (|dLambda| + lambda |dL|) / L.
    """
    phi = np.arange(400) / 400
    n_y = 20000
    length, kappa, lever = contact_line_distribution(eps_a, eps_b, x_p, phi)
    s_len, s_kappa, s_lever, n_lines = _sampled_contact_lines(phi, eps_a, eps_b, x_p, n_y)
    g = max(x_p, eps_a - x_p)
    assert np.all(np.abs(length - s_len) <= 2 * n_lines / n_y)
    assert np.all(np.abs(kappa - s_kappa) <= (3 + 2 * np.abs(kappa)) * n_lines / (n_y * length))
    assert np.all(np.abs(lever - s_lever) <= (2 * g + 2 * lever) * n_lines / (n_y * length))
    # mean length over the cycle eps_alpha lines; the phase grid's mean of the piecewise-linear length is off by at
    # most h^2 / 8 per slope change (at most 4 per line, each of 1/eps_beta)
    assert abs(np.mean(length) - eps_a) <= 4 * n_lines / eps_b * (phi[1] - phi[0]) ** 2 / 8
    # periodic in the mesh phase (one base pitch per cycle)
    np.testing.assert_allclose(np.column_stack(contact_line_distribution(eps_a, eps_b, x_p, phi + 3.0)),
                               np.column_stack((length, kappa, lever)), rtol=1e-12, atol=1e-12)
