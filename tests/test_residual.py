"""The gears' residual compliance (flexgear.mbs.residual): the modes above the dynamic cut-off leave the time
integration and return as a static compliance in series with the contact laws.

Checked against independent results: truncating a reduced body keeps exactly the floating-frame invariants
of the kept modes (flexgear.fe.cms.ffrf_invariants); the residual's seat-relative rows, summed over every
mode, give the compliance that flexgear.static_compliance computes with the gear's seat held (a constrained
solve, and within 2 % of full FE: tests/test_attachment.py); a short run of model 4 (flexible sun and ring)
with the cut-off keeps the mean mesh forces and the load deflections of the whole-basis run.
"""

from __future__ import annotations

import dataclasses
import types

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import VARIANTS

import flexgear as fg
from flexgear.fe.cms import ffrf_invariants
from flexgear.geometry.involute import gear_set_geometry
from flexgear.mbs.gearbox import mesh_contacts
from flexgear.mbs.residual import dropped_modes, residual_compliance
from flexgear.study.compare import harmonic_amplitudes


def test_truncated_body_keeps_the_invariants_of_its_lowest_modes(gearbox):
    from flexgear.fe.reduced import component_reduced_body

    body = component_reduced_body(gearbox, "sun", "coarse")
    rng = np.random.default_rng(1)
    n = 40
    nodes, modes, mass = rng.normal(size=(n, 3)), rng.normal(size=(3 * n, 7)), sp.diags(rng.uniform(1.0, 2.0, n))
    synthetic = dataclasses.replace(body, nodes=nodes, modes=modes, stiffness=np.arange(1.0, 8.0),
                                    frequencies_hz=np.arange(1.0, 8.0), invariants=ffrf_invariants(mass, nodes, modes))
    kept = synthetic.truncated(3)
    expected = ffrf_invariants(mass, nodes, modes[:, :3])
    for key, value in expected.items():
        np.testing.assert_allclose(kept.invariants[key], value, rtol=0, atol=1e-12 * max(1.0, np.abs(value).max()))
    assert kept.n_modes == 3 and body.modes_below(body.frequencies_hz[5] * (1 + 1e-9)) == 6


def _planet1_centre(gearbox) -> np.ndarray:
    """Planet 1's centre [m] in the gearbox frame: on the centre distance at its polar angle."""
    geo = gear_set_geometry(gearbox)
    psi = geo.planet_angles[0]
    return geo.centre_distance * np.array([np.cos(psi), np.sin(psi), 0.0])


@pytest.mark.parametrize("gear", ["sun", "planet", "ring"])
def test_seat_relative_rows_give_the_held_seat_compliance(gearbox, gear):
    """All modes 'dropped': C = sum_j a a^T / lambda_j must be the gear's compliance with its seat held."""
    from flexgear.fe.reduced import component_load_circles, component_reduced_body, gear_seat

    body = component_reduced_body(gearbox, gear, "coarse")
    seat = gear_seat(body, gear)  # bore; the ring's bolt patches
    contacts = mesh_contacts(gearbox)
    name = "planet1" if gear == "planet" else gear
    centre = _planet1_centre(gearbox) if gear == "planet" else np.zeros(3)
    stand_in = {name: types.SimpleNamespace(position=centre, reduced=body)}
    order = gearbox.reduction_assumed.contact_fourier_order
    # one spin angle (phi = 0): the held-seat solve below sees the gear at rest
    res = residual_compliance(contacts, stand_in, {name: dropped_modes(gearbox, body, 0, gear)}, order,
                              gearbox.gears.normal_module_m, n_angles=1)
    rows = res.rows
    points = np.array([np.asarray(contacts[i].point) - centre for i in rows])
    normals = np.array([contacts[i].normal for i in rows])
    held = fg.static_compliance(body, points, normals, seat, kernel=component_load_circles(gearbox, gear, order))
    ours = res.matrix[np.ix_(rows, rows)]
    # the two read the contact through the same order-8 kernel, one by least-squares fit of the mode shapes on
    # the band, one by its load patterns: the diagonal and the all-contacts-loaded sums agree within 3 %
    np.testing.assert_allclose(np.diag(ours), np.diag(held), rtol=0.03)
    np.testing.assert_allclose(ours.sum(axis=1), held.sum(axis=1), rtol=0.03)


def test_seat_loads_reduce_to_the_seat_relative_form_under_the_quasi_static_reaction(gearbox):
    """A planet on its own seat bearing: its dropped modes answer the contact
    forces F and the seat force F_s. With F_s the contacts' rigid reaction, F_s = sum_i s_i F_i (n_i, (x_i - c)
    x n_i), the contacts' deflection relative to the seat, e + s_i (n_i, (x_i - c) x n_i) . e_s, must be the
    seat-relative form's C F (module docstring of flexgear.mbs.residual), averaged over the spin as well."""
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.theory import theory

    body = component_reduced_body(gearbox, "planet", "coarse")
    keep = body.modes_below(8 * theory(gearbox).mesh_frequency)
    dropped = {"planet1": dropped_modes(gearbox, body, keep, "planet")}
    centre = _planet1_centre(gearbox)
    stand_in = {"planet1": types.SimpleNamespace(position=centre, reduced=body)}
    contacts = mesh_contacts(gearbox)
    args = (contacts, stand_in, dropped, gearbox.reduction_assumed.contact_fourier_order,
            gearbox.gears.normal_module_m, 4)
    held = residual_compliance(*args)
    carried = residual_compliance(*args, seats={"planet1": np.zeros(3)})
    rows = held.rows
    assert np.array_equal(carried.rows, rows) and carried.seat_bodies == ("planet1",) and rows.size == 4
    np.testing.assert_allclose(carried.seat_centres[0], centre)
    sign = np.array([1.0 if contacts[i].body1 == "planet1" else -1.0 for i in rows])
    lever = np.array([np.concatenate([contacts[i].normal, np.cross(np.asarray(contacts[i].point) - centre,
                                                                   contacts[i].normal)]) for i in rows])
    force = np.random.default_rng(3).uniform(500.0, 1000.0, rows.size)  # N
    seat_force = (sign * force) @ lever
    coords = carried.coordinates
    e = carried.matrix[np.ix_(coords, coords)] @ np.concatenate([force, seat_force])
    relative = e[:rows.size] + sign * (lever @ e[rows.size:])
    expected = held.matrix[np.ix_(rows, rows)] @ force
    np.testing.assert_allclose(relative, expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())
    # a load the seat does not react (the planet's inertia takes it) deflects the planet differently
    e = carried.matrix[np.ix_(coords, coords)][:, :rows.size] @ force
    free = e[:rows.size] + sign * (lever @ e[rows.size:])
    assert np.abs(free - expected).max() > 0.05 * np.abs(expected).max()


def test_dropped_modes_carry_most_of_a_small_gears_compliance(gearbox):
    """The sun's modes above 4x the mesh frequency carry most of its compliance at the meshes (its 4 lowest
    modes are global): leaving them out without the residual would make the sun about 5x stiffer."""
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.theory import theory

    body = component_reduced_body(gearbox, "sun", "coarse")
    keep = body.modes_below(4 * theory(gearbox).mesh_frequency)
    stand_in = {"sun": types.SimpleNamespace(position=np.zeros(3), reduced=body)}
    args = (mesh_contacts(gearbox), stand_in)
    order, band = gearbox.reduction_assumed.contact_fourier_order, gearbox.gears.normal_module_m
    whole = residual_compliance(*args, {"sun": dropped_modes(gearbox, body, 0, "sun")}, order, band)
    rest = residual_compliance(*args, {"sun": dropped_modes(gearbox, body, keep, "sun")}, order, band)
    share = np.diag(rest.matrix)[rest.rows] / np.diag(whole.matrix)[whole.rows]
    assert keep < 10 and np.all(share > 0.5) and np.all(share < 1.0)
    # the sun is nearly axisymmetric: its residual barely depends on the spin angle
    assert rest.spread < 0.1


@pytest.fixture(scope="module")
def cutoff_runs():
    """Runs of a short load case with every mode dynamic and with the variant's cut-off, keyed by the model run
    (bodies, mesh level, gearbox data without the file it was read from): variant files that describe the same model
    share one pair of runs."""
    from flexgear.mbs.run import run_variant

    done: dict[str, tuple] = {}

    def runs(v):
        g = v.gearbox
        # a short run of fixed length (a variant that continues until settled stops here too)
        lc = dataclasses.replace(g.load_case, ramp_time_s=0.006, end_time_s=0.018, end="time")
        g = g.with_changes(load_case=lc)
        unused = dataclasses.replace(lc, settle_chunk_s=None, settle_max_time_s=None)  # a run of fixed length
        key = repr((sorted(v.components.items()), v.mesh_level, v.rigid_mass_properties,
                    dataclasses.replace(g, source=None, load_case=unused)))
        if key not in done:
            cut_off = g.reduction_assumed.dynamic_cutoff_mesh_orders
            assert cut_off > 0.0
            pair = {}
            for cut in (0.0, cut_off):
                red = dataclasses.replace(g.reduction_assumed, dynamic_cutoff_mesh_orders=cut)
                pair[cut] = run_variant(dataclasses.replace(v, gearbox=g.with_changes(reduction_assumed=red)))
                assert pair[cut].ok, pair[cut].meta.get("reason")
            done[key] = g, pair[0.0], pair[cut_off]
        return done[key]

    return runs


@pytest.mark.parametrize("variant", ["model4.toml", "quick/model4.toml"])
def test_model4_with_the_cutoff_keeps_the_whole_basis_means(variant, cutoff_runs):
    """Model 4 (flexible sun and ring), impact law, a short run (ramps 6 ms, 18 ms): the variant's cut-off against
    every mode dynamic. Mean mesh forces within 0.1 % and their 1x mesh amplitudes within 2 % (the agreement rule),
    and so the load deflections' 1x. The study's variant and the quick one (its bodies, joints and cut-off, on its
    own load case, here replaced by the short one): one model, one pair of runs (``cutoff_runs``)."""
    g, full, cut = cutoff_runs(fg.load_variant(VARIANTS / variant))
    lc = g.load_case
    # 6 ms after the ramps: the meshes' transient has settled to the steady load sharing
    ref, new = (r.signals[r.signals.time_s >= 2 * lc.ramp_time_s] for r in (full, cut))
    assert float(ref.time_s.iloc[-1]) == pytest.approx(lc.end_time_s)
    f_mesh = fg.theory(g).mesh_frequency
    for kind in ("outer", "inner"):
        for i in range(1, 6):
            col = f"{kind}_mesh_force_{i}_n"
            assert new[col].mean() == pytest.approx(ref[col].mean(), rel=1e-3)
            dt = float(np.median(np.diff(ref.time_s)))
            amp_ref, amp_new = (harmonic_amplitudes(x[col].to_numpy(), dt, f_mesh, (1,))[0] for x in (ref, new))
            assert amp_new == pytest.approx(amp_ref, rel=2e-2)
    for col in (f"{kind}_deflection_load_{i}_m" for kind in ("outer", "inner") for i in range(1, 6)):
        amp_ref, amp_new = (harmonic_amplitudes(x[col].to_numpy(), dt, f_mesh, (1,))[0] for x in (ref, new))
        assert amp_new == pytest.approx(amp_ref, rel=2e-2), col


@pytest.mark.slow
def test_model5_planets_dropped_modes_answer_their_bearing_force():
    """Model 5 (flexible planets and shafts), impact law, a short run: cut-off 8 against every mode dynamic. A
    planet on its Table 2 bearing (about 1.6 kHz) is above resonance at the 4.4 kHz mesh frequency, so its inertia
    takes most of the 1x mesh load. With the dropped modes answering the bearing's force every mesh force keeps its
    mean within 0.1 % and every mesh force and load deflection its 1x amplitude within 2 % (the agreement rule); the
    load deflections' means move at most as far as the residual's spin dependence allows."""
    from flexgear.mbs.run import run_variant
    from flexgear.study.agreement import signal_agreement

    v = fg.load_variant(VARIANTS / "model5.toml")
    g = v.gearbox
    lc = dataclasses.replace(g.load_case, ramp_time_s=0.006, end_time_s=0.018)
    cut_off = g.reduction_assumed.dynamic_cutoff_mesh_orders
    runs = {}
    for label, cut in (("every mode", 0.0), ("dynamic", cut_off)):
        red = dataclasses.replace(g.reduction_assumed, dynamic_cutoff_mesh_orders=cut)
        runs[label] = run_variant(dataclasses.replace(v, gearbox=g.with_changes(load_case=lc, reduction_assumed=red)))
        assert runs[label].ok, runs[label].meta.get("reason")
    f_mesh = fg.theory(g).mesh_frequency
    window = (2 * lc.ramp_time_s, lc.end_time_s)
    table = signal_agreement(runs["every mode"], runs["dynamic"], window, f_mesh).table
    meshes = [c for c in table.index if "mesh_force" in c or "deflection_load" in c]
    assert len(meshes) == 20
    new = table.loc[meshes]
    forces = [c for c in meshes if "mesh_force" in c]
    assert new.loc[forces, "mean_diff"].abs().max() < 1e-3
    # the load deflections' means: the residual is the spin average of C(phi), the window 0.6 of a planet's
    # revolution, so their error is at most the residual's spread over the spin against the planet's whole
    # compliance at its contacts (of either sign planet by planet)
    deflections = [c for c in meshes if c not in forces]
    assert new.loc[deflections, "mean_diff"].abs().max() < _planet_residual_bound(g, cut_off)
    assert new["amp_diff"].abs().max() < 2e-2


def _planet_residual_bound(gearbox, cut_off: float) -> float:
    """The largest change of a planet's load deflection that averaging its residual compliance over the spin can
    make in any window: max_phi |C_res(phi) - C_res| (the residual's ``spread`` times its largest diagonal term)
    over the planet's whole seat-relative compliance at each contact (every mode dropped), the largest over its
    contacts."""
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.theory import theory

    body = component_reduced_body(gearbox, "planet", "coarse")
    keep = body.modes_below(cut_off * theory(gearbox).mesh_frequency)
    stand_in = {"planet1": types.SimpleNamespace(position=_planet1_centre(gearbox), reduced=body)}
    args = (mesh_contacts(gearbox), stand_in)
    order, band = gearbox.reduction_assumed.contact_fourier_order, gearbox.gears.normal_module_m
    whole = residual_compliance(*args, {"planet1": dropped_modes(gearbox, body, 0, "planet")}, order, band)
    rest = residual_compliance(*args, {"planet1": dropped_modes(gearbox, body, keep, "planet")}, order, band)
    return float(rest.spread * np.diag(rest.matrix)[rest.rows].max() / np.diag(whole.matrix)[whole.rows].min())


@pytest.mark.parametrize("orders", [4.0, 8.0])
def test_damped_residual_answers_as_the_dropped_modes_at_the_mesh_harmonics(gearbox, orders):
    """The residual coordinates' receptance (K + i w D_e - w^2 M_e)^-1 against the dropped modes' own modal
    superposition sum_j a a^T / (lambda_j (1 + i w beta) - w^2) (the modes carry D = beta K), at 1x-3x the mesh
    frequency. The Ritz residual is exact per mode; over many modes its error is of second order,
    (w^2 / lambda_min)^2. Without the damping the residual misses every dropped mode's loss factor beta w
    (0.28 at 4.4 kHz): its receptance is off by about that much at 1x."""
    from flexgear.fe.reduced import component_reduced_body
    from flexgear.mbs.contact_kinematics import modal_contact_coefficients
    from flexgear.mbs.residual import _rows_at
    from flexgear.theory import theory

    body = component_reduced_body(gearbox, "sun", "coarse")
    f_mesh = theory(gearbox).mesh_frequency
    keep = body.modes_below(orders * f_mesh)
    dropped = dropped_modes(gearbox, body, keep, "sun")
    beta = dropped.stiffness_damping_s
    assert beta == gearbox.reduction_assumed.modal_stiffness_damping_s > 0.0
    contacts = mesh_contacts(gearbox)
    order, band = gearbox.reduction_assumed.contact_fourier_order, gearbox.gears.normal_module_m
    stand_in = {"sun": types.SimpleNamespace(position=np.zeros(3), reduced=body)}
    res = residual_compliance(contacts, stand_in, {"sun": dropped}, order, band, n_angles=1)  # at phi = 0
    rows = res.rows
    k = np.linalg.inv(res.matrix[np.ix_(rows, rows)])
    m = k @ res.mass_moment[np.ix_(rows, rows)] @ k
    d = k @ res.damping_moment[np.ix_(rows, rows)] @ k
    np.testing.assert_allclose(d, beta * k, rtol=0, atol=1e-9 * beta * np.abs(k).max())  # one beta: D_e = beta K
    parts = []
    for i in rows:
        c = contacts[i]
        table = modal_contact_coefficients(body.nodes, dropped.modes, np.asarray(c.point), c.normal,
                                           0.5 * c.half_width, band, order)
        parts.append((table, 1.0, c.spin_per_drive_angle[0], np.asarray(c.point), np.asarray(c.normal, float)))
    a = _rows_at(0.0, parts, dropped)[:, keep:]
    lam = dropped.stiffness[keep:]
    for harmonic in (1, 2, 3):
        w = 2 * np.pi * f_mesh * harmonic
        modal = np.diag((a / (lam * (1 + 1j * w * beta) - w * w)) @ a.T)
        damped = np.diag(np.linalg.inv(k + 1j * w * d - w * w * m))
        undamped = np.diag(np.linalg.inv(k - w * w * m))
        scale = np.abs(modal).max()
        assert np.abs(damped - modal).max() / scale < (w * w / lam.min()) ** 2
        if harmonic == 1:
            assert np.abs(undamped - modal).max() / scale > 0.9 * beta * w
