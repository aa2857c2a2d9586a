"""The ring's and the output shaft's reduced bodies (flexgear.fe.reduced: the form the multibody model joins to a
rigid partner): the part's 12 clamped discs as one rigid interface of 6 coordinates, against the full FE model of
that part with every clamped-disc node held by the rigid partner (here: held still, u = 0 on the discs), coarse
meshes. Clamped modes (the partner held) and static compliance: the ring's at its contact bands under
contact-kernel loads, the shaft's at its bearing seat under its six RBE3 loads. Each part's FE model,
factorisation and eigenpairs take 30-60 s: heavy."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from test_attachment import interface_compliance

import flexgear as fg
from flexgear.fe.bolted import clamped_patches
from flexgear.fe.cholesky import SparseCholesky
from flexgear.fe.cms import rbe3_rows
from flexgear.fe.joined import body_matrices, joint_rows

pytestmark = pytest.mark.heavy


class Clamped:
    """The full FE model with the nodes ``held`` fixed: K_ii factorised once; static solves and clamped modes."""

    def __init__(self, fe, held: np.ndarray):
        mask = np.ones(fe.n_dof, bool)
        mask[(3 * np.asarray(held)[:, None] + np.arange(3)).ravel()] = False
        self.fe, self.free = fe, np.flatnonzero(mask)
        self.kept_nodes = np.setdiff1d(np.arange(fe.n_nodes), held)
        self.chol = SparseCholesky(sp.tril(fe.K, format="csr")[self.free][:, self.free])

    def compliance(self, loads: np.ndarray) -> np.ndarray:
        """F^T K_ii^-1 F (p, p) for loads F (3n, p) [m/N]."""
        f = loads[self.free]
        return f.T @ self.chol.solve(f)

    def frequencies(self, k: int) -> np.ndarray:
        """Lowest ``k`` natural frequencies [Hz] of (K_ii, M_ii): shift-invert at 0."""
        m = self.fe.mass_operator(self.kept_nodes)
        n = len(self.free)
        op = sla.LinearOperator((n, n), matvec=self.chol.solve, dtype=float)
        v0 = self.chol.solve(m @ np.random.default_rng(0).standard_normal(n))
        lam = sla.eigsh(op, k=k, M=m, sigma=0.0, OPinv=op, which="LM", v0=v0, tol=1e-10, return_eigenvectors=False)
        return np.sqrt(np.sort(lam)) / (2 * np.pi)


def held_frequencies(body, name: str, k: int) -> np.ndarray:
    """Lowest ``k`` frequencies [Hz] of the reduced body with interface ``name``'s six motions held (its rigid
    motion included, flexgear.fe.joined eq. 2 at the interface's point): the partner held still."""
    import scipy.linalg as la

    mass, stiffness = body_matrices(body)
    basis = la.null_space(joint_rows(body, name, body.interface(name).point))
    lam = la.eigh(basis.T @ stiffness @ basis, basis.T @ mass @ basis, eigvals_only=True)
    return np.sqrt(lam[:k]) / (2 * np.pi)


def ring_against_full_fe(gearbox, k_modes: int) -> int:
    """The coarse ring of ``gearbox`` (flexgear.fe.reduced.component_reduced_body) held on its clamped discs, as
    the rigid output shaft holds it, against its full FE model held alike: every clamped mode below 3 x the mesh
    frequency within 1 % (of the lowest ``k_modes`` computed), the compliance under the contact kernel's loads at
    all its contacts within 2 %. Returns how many modes lie in the band."""
    from flexgear.fe.compliance import _kernel_loads
    from flexgear.fe.reduced import component_contacts, component_load_circles, component_reduced_body
    from flexgear.fe.ring_shaft import part_fe_model
    from flexgear.theory import theory

    fe = part_fe_model(gearbox, "ring", "coarse")
    body = component_reduced_body(gearbox, "ring", "coarse")
    assert np.array_equal(body.nodes, fe.nodes)
    clamped = Clamped(fe, body.interface("bolt_patches").nodes)
    full = clamped.frequencies(k_modes)
    n = int(np.sum(full < 3.0 * theory(gearbox).mesh_frequency))
    np.testing.assert_allclose(held_frequencies(body, "bolt_patches", n), full[:n], rtol=0.01)
    points, normals = component_contacts(gearbox, "ring")
    kernel = component_load_circles(gearbox, "ring", gearbox.reduction_assumed.contact_fourier_order)
    full_c = clamped.compliance(_kernel_loads(fe.nodes, kernel, points, normals))
    reduced = fg.static_compliance(body, points, normals, "bolt_patches", kernel=kernel)
    assert np.max(np.abs(reduced - full_c)) < 0.02 * np.max(np.abs(full_c))
    assert reduced.sum(axis=1) == pytest.approx(full_c.sum(axis=1), rel=0.02)
    return n


@pytest.fixture(scope="module", params=["ring", "output_shaft"])
def part(gearbox, coarse_fe, request):
    """(name, FE model, reduced body with one rigid bolt-patch interface, the full model clamped on the discs)."""
    from flexgear.fe.reduced import component_reduced_body

    name = request.param
    fe = coarse_fe(name)
    body = component_reduced_body(gearbox, name, "coarse")
    assert np.array_equal(body.nodes, fe.nodes)
    return name, fe, body, Clamped(fe, body.interface("bolt_patches").nodes)


def test_one_rigid_interface_of_six_coordinates_replaces_twelve_patches(gearbox, part):
    name, fe, body, clamped = part
    names = [i.name for i in body.interfaces]
    assert names == (["bolt_patches"] if name == "ring" else ["bolt_patches", "bearing_seat"])
    patches = body.interface("bolt_patches")
    assert len(patches.nodes) == sum(len(p) for p in clamped_patches(fe, gearbox))
    # the discs move as one rigid body in every mode: u_i = t + theta x (x_i - p) of their RBE3 motion (t, theta)
    r = fe.nodes[patches.nodes] - patches.point
    motion = body.interface_motion("bolt_patches")
    rigid = motion[None, :3] + np.cross(motion[3:].T[None], r[:, None, :]).transpose(0, 2, 1)
    shapes = body.modes.reshape(fe.n_nodes, 3, -1)[patches.nodes]
    assert np.abs(shapes - rigid).max() < 1e-9 * np.abs(shapes).max()
    assert body.props.mass == pytest.approx(fe.mass_properties().mass, rel=1e-12)


def test_clamped_modes_within_1_percent_of_full_fe(part):
    _, _, body, clamped = part
    np.testing.assert_allclose(held_frequencies(body, "bolt_patches", 10), clamped.frequencies(10), rtol=0.01)


def test_compliance_within_2_percent_of_full_fe(gearbox, part):
    from flexgear.fe.reduced import component_contacts, component_load_circles

    name, fe, body, clamped = part
    if name == "ring":
        points, normals = component_contacts(gearbox, name)
        kernel = component_load_circles(gearbox, name, gearbox.reduction_assumed.contact_fourier_order)
        from flexgear.fe.compliance import _kernel_loads

        full = clamped.compliance(_kernel_loads(fe.nodes, kernel, points, normals))
        reduced = fg.static_compliance(body, points, normals, "bolt_patches", kernel=kernel)
        assert np.max(np.abs(reduced - full)) < 0.02 * np.max(np.abs(full))
        assert reduced.sum(axis=1) == pytest.approx(full.sum(axis=1), rel=0.02)
    else:
        seat = body.interface("bearing_seat")
        rows = rbe3_rows(fe, seat)
        full = clamped.compliance(rows.T.toarray())
        reduced = interface_compliance(body, seat, body.interface("bolt_patches"))
        assert np.diag(reduced) == pytest.approx(np.diag(full), rel=0.02)
