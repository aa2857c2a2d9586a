"""The lumped model's harmonic response (flexgear.harmonic.lumped) against its own physics, at speeds read off its own
Campbell diagram (flexgear.harmonic.peaks, flexgear.study.harmonic_check).

(1) Below the first strong crossing (flexgear.study.harmonic_check.check_speeds), the 1x and 2x amplitudes of the mesh
    forces and bearing accelerations and K_v - 1 of a settled time run (flexgear.lumped.run) within 10 %: the
    first-order excitation F_0 (s - 1) leaves out the parametric terms, of relative order c_h (c_1, c_2 ~ 0.05-0.1).
(2) Lightly damped (mesh damping ratio and bearing damping x 0.1: every mode's damping ratio below 1.5 %), each
    resonance peak of the 1x and 2x curves lies within 1 % of the Campbell crossing of the mode that carries it:
    a lightly damped peak lies at h f_mesh = f_n up to a shift of order zeta^2 (2e-4). The carrying modes are those
    the planets' phasing lets each harmonic excite (Parker 2004; z_s = 44, N = 5): translational at 1x
    ((h z_s +- 1) / N an integer), planet modes at 2x (neither h z_s / N nor (h z_s +- 1) / N).
(3) At the study's damping, the peaks of the modes whose damping shift zeta^2 is at most a quarter of the 1 %
    (damping ratio <= :data:`LIGHT`) within 1 % of their crossings.
(4) The tooth-friction excitation is the Fourier series of the time model's friction force (to round-off).
"""


import numpy as np
import pytest
from test_harmonic import _lightly_damped

from flexgear.harmonic.peaks import lumped_campbell, peak_crossings
from flexgear.study.harmonic_check import CANCELLED, COLUMNS, check_speeds, compare_lumped

TOLERANCE = 0.10  # the time-domain comparison
PEAK_TOLERANCE = 0.01  # peak speeds against crossings
LIGHT = 0.05  # damping ratio whose peak shift zeta^2 is a quarter of PEAK_TOLERANCE
GRID = np.arange(500.0, 7000.0 + 5.0, 5.0)  # 5 rpm: a grid point within 0.2 % of the lowest crossing's speed
INDICATORS = ("outer_mesh_force_1_n", "inner_mesh_force_1_n", "input_bearing_accel_x_m_per_s2",
              "output_bearing_accel_x_m_per_s2")


@pytest.fixture(scope="module")
def iso_spec(gearbox):
    """The ISO 6336 law with the contact-line stiffness variation and no friction (the linearisation's scope)."""
    spec = gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.0)
    return spec.with_fields("contact_assumed", stiffness_variation="contact_lines")


def test_frequency_domain_matches_settled_time_run_below_the_first_strong_crossing(iso_spec):
    speeds = check_speeds(iso_spec)
    assert speeds.order in (1, 2)  # the strong peaks of the study's gearbox: the 1x and 2x crossings
    check = compare_lumped(iso_spec, speeds.speeds_rpm[0])
    assert check.settling.settled
    table = check.table
    moved = table[table.judged].moved.abs().max()
    assert moved < 0.01  # the last two windows agree: settled
    judged = table[table.judged]
    # phasing: 2x moves no central member (the bearings' 2x is cancelled), everything else is judged
    assert set(judged.quantity) == set(COLUMNS) | {"dynamic_factor - 1"}
    assert (table[~table.judged].harmonic == 2).all() and table[~table.judged].quantity.str.contains("accel").all()
    assert (table[~table.judged].frequency < CANCELLED * table.frequency.max()).all()
    bad = judged[judged.difference.abs() > TOLERANCE]
    assert bad.empty, bad.to_string()


def test_campbell_of_a_star_gearbox_is_flat_and_crossings_follow_the_mesh_orders(iso_spec):
    """Carrier fixed: no gyroscopic or centripetal terms, the natural frequencies do not depend on the speed, and each
    crossing of order k lies at f_n / (k f_mesh per rpm)."""
    diagram = lumped_campbell(iso_spec, [500.0, 3000.0, 7000.0], orders=(1, 2))
    spread = diagram.table.groupby("mode").frequency_hz.agg(lambda f: f.max() / f.min() - 1.0)
    assert spread.max() < 1e-9
    c = diagram.crossings
    np.testing.assert_allclose(c.speed_rpm, c.frequency_hz / (c.order * diagram.mesh_hz_per_rpm), rtol=1e-9)


def test_lightly_damped_peaks_lie_at_the_crossings_of_their_modes(iso_spec):
    peaks = peak_crossings(_lightly_damped(iso_spec), GRID, INDICATORS, orders=(1, 2),
                           harmonics=iso_spec.contact_assumed.stiffness_harmonics)
    assert len(peaks) >= len(INDICATORS)
    assert peaks.difference.notna().all(), peaks.to_string()
    assert (peaks.difference.abs() <= PEAK_TOLERANCE).all(), peaks.to_string()
    assert (peaks[peaks.harmonic == 1].kind == "translational").all()
    assert (peaks[peaks.harmonic == 2].kind == "planet").all()


def test_peaks_of_lightly_damped_modes_at_the_study_damping(iso_spec):
    peaks = peak_crossings(iso_spec, GRID, INDICATORS, orders=(1, 2),
                           harmonics=iso_spec.contact_assumed.stiffness_harmonics)
    light = peaks[peaks.damping_ratio <= LIGHT]
    assert len(light) >= 2, peaks.to_string()
    assert (light.difference.abs() <= PEAK_TOLERANCE).all(), light.to_string()


def test_modal_contributions_add_up_to_the_response(iso_spec):
    """X = sum_j psi_j eta_j over all roots: with no root left out (none overdamped), the multiplets' contributions
    add up to the mesh force's response part F - F_0 C_h - P_h of the direct solve."""
    from flexgear.harmonic import lumped_harmonic_response
    from flexgear.harmonic.base import parametric_forces
    from flexgear.harmonic.lumped import lumped_linear
    from flexgear.harmonic.peaks import mode_contributions

    speed, h, mesh = 2000.0, 2, "outer_mesh_force_1_n"
    lin = lumped_linear(iso_spec, 3)
    parts = mode_contributions(lin, speed, mesh, h)
    assert parts.multiplicity.sum() == lin.free.size  # every root pair kept
    op = lin.operating(speed)
    force = lumped_harmonic_response(iso_spec, [speed], 3).complex(mesh).loc[speed, h]
    response_part = force - op.f0[0] * op.coef[0, h - 1] - parametric_forces(op)[h - 1, 0]
    assert parts.contribution.sum() == pytest.approx(response_part, rel=1e-8)


def test_friction_excitation_is_the_time_models_friction_force_series(gearbox):
    """(4) The lumped tooth-friction excitation (flexgear.harmonic.lumped_friction) is the Fourier series of the time
    model's own friction generalised force: the compiled right-hand side with mu minus that with mu = 0, times the
    masses, at the static deflection over one mesh cycle of the rigid running (the kernel's friction path, nothing
    else differs). Integrated exactly up to round-off: Gauss-Legendre on every interval between the tables' nodes
    of all meshes, where the integrand is a straight line times a trigonometric polynomial of degree
    H_s + H <= 8 over at most 1/64 of a cycle (4-point error ~ (2 pi 8 / 64)^8 / 8! ~ 1e-8 relative to the
    interval's share 1/64 ... below 1e-13 of the total). The series leaves the ring's static rotation out of the
    ring meshes' phase, as the stiffness excitation does; the time model's phase has it: the comparison adds it.
    At mu = 0 the excitation is the stiffness excitation alone, unchanged."""
    from dataclasses import replace

    from flexgear.harmonic.base import RPM, excitation, excited_spec
    from flexgear.harmonic.lumped import lumped_linear
    from flexgear.harmonic.lumped_friction import nominal_spin_rates
    from flexgear.lumped.kernel_layout import T_RAMP, W_IN
    from flexgear.lumped.run import build_lumped_model, lumped_rhs

    harm = 4
    spec = gearbox.with_fields("contact", law="iso6336", friction_coefficient=0.06)
    spec = spec.with_fields("contact_assumed", stiffness_variation="contact_lines")
    spec = spec.with_fields("lumped_assumed", friction_table_points=64)
    dry = spec.with_fields("contact", friction_coefficient=0.0)
    model = build_lumped_model(excited_spec(spec, harm))
    w = float(model.fp[W_IN])  # the time model's prescribed input speed [rad/s]
    speed = w / RPM
    lin = lumped_linear(spec, harm)
    op, op0 = lin.operating(speed), lumped_linear(dry, harm).operating(speed)
    assert op0.friction is None
    for a, b in zip(excitation(op0, harm), excitation(replace(op, friction=None, friction_rows=None), harm),
                    strict=True):
        np.testing.assert_array_equal(a, b)
    series = excitation(op, harm)[1] - excitation(op0, harm)[1]  # (H, n_f)

    rhs, rhs0 = lumped_rhs(model), lumped_rhs(build_lumped_model(excited_spec(dry, harm)))
    free, s = model.free, model.system
    mass = s.mass[free]
    assert np.all(mass > 0.0)
    pos = {int(j): k for k, j in enumerate(free)}
    r = nominal_spin_rates(model)
    np.testing.assert_allclose(s.mesh_G @ r, 0.0, atol=1e-12)
    rate = model.phase_coef * r[model.phase_index]  # mesh cycles per rad of input, all one sense here
    np.testing.assert_allclose(np.abs(rate), abs(rate[0]), rtol=1e-12)
    sense = np.sign(rate)
    static_phase = np.array([model.phase_coef[m] * lin.static[pos[int(i)]] if int(i) in pos else 0.0
                             for m, i in enumerate(model.phase_index)])
    t0 = model.fp[T_RAMP]  # the ramp done: input angle w (t - t_ramp / 2)
    psi0 = abs(rate[0]) * w * 0.5 * t0  # global mesh phase at t0 [cycles]
    phase0 = model.phase_coef * r[model.phase_index] * w * 0.5 * t0 + static_phase + model.phase_offset
    npts = model.tables.shape[1]
    nodes = np.arange(npts) / npts
    breaks = np.unique(np.r_[0.0, 1.0, np.mod((nodes[None] - phase0[:, None]) * sense[:, None], 1.0).ravel()])
    gx, gw = np.polynomial.legendre.leggauss(4)
    coef = np.zeros((harm, free.size), complex)
    peak, amp = np.zeros(free.size), 0.0
    h = np.arange(1, harm + 1)
    g_abs = np.abs(s.mesh_G)
    delta0 = op.f0 / model.mesh_k
    for lo, hi in zip(breaks[:-1], breaks[1:], strict=True):
        for xi, wi in zip(0.5 * (lo + hi) + 0.5 * (hi - lo) * gx, 0.5 * (hi - lo) * gw, strict=True):
            t = t0 + xi / (abs(rate[0]) * w)
            th = t - 0.5 * t0
            y = np.r_[lin.static + r[free] * w * th, r[free] * w]
            force = (rhs(t, y)[free.size:] - rhs0(t, y)[free.size:]) * mass
            coef += 2.0 * wi * np.exp(-2j * np.pi * h * (psi0 + xi))[:, None] * force[None]
            peak = np.maximum(peak, np.abs(force))
            q = np.zeros(s.n)
            q[free], q[model.presc] = y[:free.size], model.presc_coef * w * th
            amp = max(amp, float(np.max(g_abs @ np.abs(q) / delta0)))
    # the series with the ring's static rotation in the ring meshes' phase (the time model's phase)
    fr = op.friction * np.exp(2j * np.pi * h[None] * np.tile(static_phase * sense, 3)[:, None])
    shifted = -(op.friction_rows.T @ fr).T
    # round-off: the kernel's deflection G q at the running angle carries ~ eps sum |G_k q_k| (angles of tens of
    # rad against deflections of um), relative eps * amp in F and in the friction force Q (linear in F); the
    # difference of the two right-hand sides adds ~ eps per term of the ~20-term accelerations (each of order
    # the mesh forces F_0, the arms below 1 m); the quadrature's weights sum to 1 (times 2): per coordinate
    # 2 * 16 eps (amp max|Q| + 20 max F_0)
    eps = np.finfo(float).eps
    tol = 32 * eps * (amp * peak + 20.0 * op.f0.max())
    assert np.abs(series).max() > 1e6 * tol.max()  # the friction excitation is there
    assert np.all(np.abs(coef - shifted) <= tol[None]), np.abs(coef - shifted).max(0) / tol
