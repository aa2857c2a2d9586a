"""Attachment modes and static compliance (flexgear.fe.attachment, flexgear.fe.compliance) against
independent results: curved-beam theory of a slender ring, Timoshenko beam theory of the input shaft,
and the full FE models of the study's components (coarse level)."""

from __future__ import annotations

import numpy as np
import pytest
from test_flexible import RING_B, RING_R, RING_T, STEEL, ring_mesh

import flexgear as fg
from flexgear.fe.cms import Interface, full_free_modes, interface
from flexgear.fe.compliance import free_body_solver
from flexgear.fe.fem import fe_model


def ring_kernel_compliance(loads: int, order: int) -> float:
    """Radial deflection per load [m/N] at one of ``loads`` equal, equally spaced inward radial forces on
    a thin ring (curved beam: inextensional bending plus membrane), harmonics up to ``order``.

    With a = E A / R^2, c = E I / R^4 the ring's radial stiffness per unit length for cos(n theta) is
    k_0 = a (membrane) and k_n = (n^2 - 1)^2 a c / (a + c) (bending and stretching); N loads P excite
    n = m N with q_0 = N P / (2 pi R), q_n = N P / (pi R) and w(0) = sum q_n / k_n.
    """
    e, area, inertia, r = STEEL.youngs_modulus_pa, RING_B * RING_T, RING_B * RING_T**3 / 12, RING_R
    membrane = r**2 / (e * area)
    total = loads / (2 * np.pi * r) * membrane
    for m in range(1, order // loads + 1):
        n = m * loads
        total += loads / (np.pi * r) * (r**4 / (e * inertia) + membrane) / (n * n - 1) ** 2
    return total


def test_slender_ring_under_equal_radial_loads_matches_curved_beam_theory():
    assert RING_R / RING_T >= 20
    fe = fe_model(ring_mesh(0.004), STEEL, order=2)
    loads, order = 5, 16
    outer = RING_R + RING_T / 2
    circle = fg.LoadCircle(outer, -RING_B / 2, RING_B / 2, order)  # radial, on the outer cylinder
    psi = 2 * np.pi * np.arange(loads) / loads
    points = np.c_[outer * np.cos(psi), outer * np.sin(psi), np.zeros(loads)]
    inward = -np.c_[np.cos(psi), np.sin(psi), np.zeros(loads)]
    held = interface(fe, "top")  # the loads are self-equilibrated and symmetric: the hold carries nothing
    full = fg.static_compliance(fe, points, inward, held, kernel=circle)
    body = fg.reduce(fe, [held], 10, n_compare=0, load_circles=[circle])
    reduced = fg.static_compliance(body, points, inward, "top", kernel=circle)
    theory = ring_kernel_compliance(loads, order)
    assert full.sum(axis=1) == pytest.approx(np.full(loads, theory), rel=0.05)
    assert reduced.sum(axis=1) == pytest.approx(np.full(loads, theory), rel=0.05)
    assert np.max(np.abs(reduced - full)) < 0.02 * np.max(np.abs(full))
    # without attachment modes the same basis misses the rim's bending under the loads
    plain = fg.static_compliance(fg.reduce(fe, [held], 10, n_compare=0), points, inward, "top", kernel=circle)
    assert plain.sum(axis=1).max() < 0.5 * theory


@pytest.fixture(scope="module")
def component(gearbox, request):
    """(spec, name, full FE model, pipeline reduced body) of a gear at the coarse level."""
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.reduced import component_reduced_body

    name = request.param
    body = component_reduced_body(gearbox, name, "coarse")
    fe = fe_model(component_mesh(gearbox, name, "coarse", order=1).ngsolve_mesh(), gearbox.material_assumed,
                  gearbox.meshing_assumed["coarse"].element_order)
    assert np.allclose(fe.nodes, body.nodes)
    return gearbox, name, fe, body


@pytest.mark.parametrize("component", ["sun", "planet"], indirect=True)
def test_gear_compliance_under_kernel_loads_equals_full_fe(component):
    """Held at the bore (the ring on its rigid bolt patches is checked against full FE with the patches clamped,
    tests/test_rigid_partner.py, and as the tied ring and output shaft, tests/test_tied_pair.py)."""
    from flexgear.design import as_design
    from flexgear.fe.reduced import component_contacts, component_load_circles, gear_seat

    spec, name, fe, body = component
    points, normals = component_contacts(spec, name)
    kernel = component_load_circles(spec, name, spec.reduction_assumed.contact_fourier_order)
    held = gear_seat(body, name)  # the bore
    full = fg.static_compliance(fe, points, normals, held, kernel=kernel)
    reduced = fg.static_compliance(body, points, normals, held, kernel=kernel)
    assert np.max(np.abs(reduced - full)) < 0.02 * np.max(np.abs(full))
    assert reduced.sum(axis=1) == pytest.approx(full.sum(axis=1), rel=0.02)  # all contacts loaded together
    # every free-free mode below 3x the mesh frequency (the band the assembly is checked in) within 1 % of the full
    # model's, at or above it (a Ritz basis): the basis holds the fixed-interface modes below
    # [reduction_assumed] fixed_interface_cutoff_hz (flexgear.fe.spectrum)
    f_full = full_free_modes(fe, 8, free_body_solver(fe))[0]
    f_full = f_full[f_full < 3.0 * as_design(spec).theory.mesh_frequency]
    assert 0 < f_full.size < 8  # the eight computed reach past the band
    assert body.frequencies_hz[:f_full.size] == pytest.approx(f_full, rel=0.01)
    assert np.all(body.frequencies_hz[:f_full.size] >= f_full * (1 - 1e-7))


def timoshenko_seat_compliance(spec, shaft: str, load: tuple[float, float], held: tuple[float, float]
                               ) -> tuple[float, float]:
    """Lateral [m/N] and torsional [rad/(N m)] compliance of a tube shaft between two seats, Timoshenko beam.

    The seats are whole tube sections [z0, z1] (m) with volume weights (:func:`section_interface`). A
    unit force (torque) spread uniformly along the ``load`` seat, read as its mean lateral displacement
    (twist): the RBE3 translation (rotation) of the section; the ``held`` seat's RBE3 motion zero:
    mean v = 0 and int (z - c) v + <x^2> phi dz = 0 (its least-squares rotation, <x^2> = (r_o^2 + r_i^2) / 4
    over the annulus), mean twist = 0. Energy 1/2 int EI phi'^2 + kappa G A (v' - phi)^2 + G J
    theta'^2 dz on a fine two-node mesh (reduced-integration shear), Cowper's kappa of a hollow circle.
    """
    c, m = spec.components_assumed, spec.material_assumed
    r_o, r_i = getattr(c, f"{shaft}_outer_diameter_mm") * 0.5e-3, getattr(c, f"{shaft}_inner_diameter_mm") * 0.5e-3
    e, nu = m.youngs_modulus_pa, m.poisson_ratio
    g, area, inertia = e / (2 * (1 + nu)), np.pi * (r_o**2 - r_i**2), np.pi * (r_o**4 - r_i**4) / 4
    q = r_i / r_o
    kappa = 6 * (1 + nu) * (1 + q * q) ** 2 / ((7 + 6 * nu) * (1 + q * q) ** 2 + (20 + 12 * nu) * q * q)
    edges = sorted({*load, *held})
    pieces = [np.linspace(a, b, max(2, int((b - a) / 2e-4))) for a, b in zip(edges, edges[1:], strict=False)]
    z = np.unique(np.concatenate(pieces))
    n = len(z)

    def seat_mean(seat):  # trapezoid weights of the mean over a seat
        w = np.zeros(n)
        for k in range(n - 1):
            if seat[0] - 1e-12 <= z[k] and z[k + 1] <= seat[1] + 1e-12:
                w[[k, k + 1]] += 0.5 * (z[k + 1] - z[k])
        return w / (seat[1] - seat[0])

    kb, kt = np.zeros((2 * n, 2 * n)), np.zeros((n, n))
    for k in range(n - 1):
        h = z[k + 1] - z[k]
        dofs = [2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3]
        b = np.array([-1 / h, -0.5, 1 / h, -0.5])  # shear strain v' - phi at the element centre
        kb[np.ix_(dofs, dofs)] += kappa * g * area * h * np.outer(b, b)
        kb[np.ix_(dofs[1::2], dofs[1::2])] += e * inertia / h * np.array([[1, -1], [-1, 1]])
        kt[k:k + 2, k:k + 2] += g * 2 * inertia / h * np.array([[1, -1], [-1, 1]])
    w_load, w_held = seat_mean(load), seat_mean(held)
    centre = 0.5 * (held[0] + held[1])
    cons = np.zeros((2, 2 * n))
    cons[0, 0::2] = w_held
    cons[1, 0::2], cons[1, 1::2] = w_held * (z - centre), w_held * (r_o**2 + r_i**2) / 4

    def solve(k, c_rows, f):
        p = len(c_rows)
        big = np.block([[k, c_rows.T], [c_rows, np.zeros((p, p))]])
        return np.linalg.solve(big, np.concatenate([f, np.zeros(p)]))[:len(f)]

    f = np.zeros(2 * n)
    f[0::2] = w_load
    lateral = solve(kb, cons, f)[0::2] @ w_load
    torsion = solve(kt, w_held[None, :], w_load) @ w_load
    return lateral, torsion


def section_interface(fe, name: str, z0: float, z1: float) -> Interface:
    """All nodes of the body between z0 and z1 [m] (a whole shaft section), weighted by their volume share
    (diagonal of the scalar mass matrix, HRZ-lumped: positive)."""
    nodes = fe.nodes_where(lambda x: (x[:, 2] > z0 - 1e-6) & (x[:, 2] < z1 + 1e-6))
    w = fe.mass_scalar.diagonal()[nodes]
    w = w / w.sum()
    return Interface(name, nodes, w, w @ fe.nodes[nodes])


def interface_compliance(fe_or_body, load, held) -> np.ndarray:
    """Compliance of the RBE3 motion of interface ``load`` (or of each of a list of interfaces: 6 k x 6 k) under its
    RBE3 loads, ``held`` held: full FE by the constrained solve, a reduced body by its modes (u = Phi_h q, as
    flexgear.fe.compliance)."""
    import scipy.sparse as sp

    from flexgear.fe.cms import ReducedBody, rbe3_rows, rbe3_weights
    from flexgear.fe.fem import rigid_body_modes

    loads = list(load) if isinstance(load, list | tuple) else [load]
    if not isinstance(fe_or_body, ReducedBody):
        c_load = sp.vstack([rbe3_rows(fe_or_body, itf) for itf in loads]).tocsr()
        u = free_body_solver(fe_or_body).constrained(rbe3_rows(fe_or_body, held)).solve(
            c_load.T.toarray(), np.zeros((6, c_load.shape[0])))
        return c_load @ u
    body = fe_or_body
    rig = rigid_body_modes(body.nodes).reshape(len(body.nodes), 3, 6)

    def c_r(itf):
        return np.einsum("idc,icm->dm", rbe3_weights(body.nodes, itf), rig[itf.nodes])

    held_motion = np.linalg.solve(c_r(held), body.interface_motion(held.name))
    phi_h = np.vstack([body.interface_motion(itf.name) - c_r(itf) @ held_motion for itf in loads])
    return (phi_h / body.stiffness) @ phi_h.T


@pytest.mark.parametrize("component", ["input_shaft"], indirect=True)
def test_shaft_seat_compliance_reduced_equals_full_fe_and_beam_theory(component):
    """The input shaft between its sun seat and bearing seat (the output shaft on its rigid bolt patches: the bearing
    seat's compliance of the tied ring and output shaft, tests/test_tied_pair.py)."""
    from flexgear.geometry.layout import component_layout

    spec, name, fe, body = component
    joint, seat = body.interfaces
    full = interface_compliance(fe, joint, seat)
    reduced = interface_compliance(body, joint, seat)
    assert np.diag(reduced) == pytest.approx(np.diag(full), rel=0.02)
    # a plain tube between the sun seat and the bearing seat
    sun = component_layout(spec, "sun").prisms
    tube = component_layout(spec, name).prisms[0]
    width = spec.components_assumed.bearing_seat_width_mm * 1e-3
    load, held = (min(p.z0 for p in sun), max(p.z1 for p in sun)), (tube.z0, tube.z0 + width)
    lateral, torsion = timoshenko_seat_compliance(spec, name, load, held)
    beam = interface_compliance(fe, section_interface(fe, "sun", *load), section_interface(fe, "bearing", *held))
    assert beam[0, 0] == pytest.approx(lateral, rel=0.05)
    assert beam[1, 1] == pytest.approx(lateral, rel=0.05)
    assert beam[5, 5] == pytest.approx(torsion, rel=0.02)


def test_spinning_ring_centrifugal_growth_matches_thin_ring_solution():
    """Radial growth of a free slender ring spinning at omega: u = rho omega^2 R^3 / E (membrane hoop stress
    sigma = rho omega^2 R^2), full FE and the reduced body (free-free modes, the floating frame's
    centrifugal modal force Phi^T M (omega^2 x_perp)) with a radial load circle in its basis."""
    from flexgear.fe.cms import FreeBodySolver
    from flexgear.fe.fem import rigid_body_modes

    fe = fe_model(ring_mesh(0.004), STEEL, order=2)
    omega = 1000.0  # rad/s
    x_perp = fe.nodes * [1.0, 1.0, 0.0]
    load = (omega**2 * (fe.mass_scalar @ x_perp)).ravel()  # self-equilibrated body force [N]
    rigid = rigid_body_modes(fe.nodes)
    full = FreeBodySolver(fe).constrained((fe.M @ rigid).T).solve(load[:, None], np.zeros((6, 1)))[:, 0]
    circle = fg.LoadCircle(RING_R + RING_T / 2, -RING_B / 2, RING_B / 2, 2)
    body = fg.reduce(fe, [interface(fe, "top")], 10, n_compare=0, load_circles=[circle])
    reduced = body.modes @ ((body.modes.T @ load) / body.stiffness)
    theta = np.arctan2(fe.nodes[:, 1], fe.nodes[:, 0])
    mass = fe.mass_scalar @ np.ones(fe.n_nodes)

    def growth(u):  # mass-weighted mean radial displacement [m]
        u = u.reshape(-1, 3)
        return float(mass @ (u[:, 0] * np.cos(theta) + u[:, 1] * np.sin(theta)) / mass.sum())

    theory = STEEL.density_kg_m3 * omega**2 * RING_R**3 / STEEL.youngs_modulus_pa
    assert growth(full) == pytest.approx(theory, rel=0.02)
    assert growth(reduced) == pytest.approx(growth(full), rel=0.02)
