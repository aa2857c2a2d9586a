"""Linear finite-element model of one component: sparse mass and stiffness matrices from a volume mesh.

``fe_model(mesh, material, order)`` assembles, with NGSolve, the consistent mass matrix and the
linear-elastic stiffness matrix of isotropic material (Hooke's law sigma = 2 mu eps + lambda tr(eps) I)

    M = int rho N^T N dV,    K = int B^T D B dV

on nodal (Lagrange) tetrahedra of order 1 or 2, so that every degree of freedom is the displacement
of a node (what Exudyn's floating-frame bodies need). Second order uses a second-order copy of the
mesh (``ngmesh.SecondOrder()``: edge mid-nodes on the true, curved surfaces; the caller's mesh is not
changed). Coordinates are interleaved, ``[u_x0, u_y0, u_z0, u_x1, ...]``, as in Exudyn.

This is Exudyn's own route (``FEMinterface.ImportMeshFromNGsolve`` assembles the same bilinear forms)
without its triplet copies and re-sorting loops: the matrices go straight from NGSolve's COO arrays to
SciPy, and the mass matrix is kept as its scalar part ``M = M_s (x) I_3``, which is all the
floating-frame invariants need (flexgear.fe.cms).

Named boundary regions of the mesh become node sets with surface weights (HRZ-lumped surface
areas: positive, summing to the region's area) for distributing (RBE3) or rigid (RBE2) interfaces.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from flexgear.geometry.massprops import MassProperties
from flexgear.spec import Material

__all__ = ["FEModel", "fe_model", "mesh_mass_properties", "rigid_body_modes", "lame_parameters", "surface_faces",
           "kron3_operator"]


def lame_parameters(material: Material) -> tuple[float, float]:
    """Lame parameters (mu, lambda) [Pa] from Young's modulus E and Poisson's ratio nu.

    mu = E / (2 (1 + nu)),  lambda = E nu / ((1 + nu)(1 - 2 nu)).
    """
    e, nu = material.youngs_modulus_pa, material.poisson_ratio
    return e / (2.0 * (1.0 + nu)), e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))


@dataclass
class FEModel:
    """Linear FE model of a free body (SI units).

    ``nodes`` (n, 3) [m]; ``K`` (3n, 3n) [N/m] and ``mass_scalar`` (n, n) [kg] sparse CSR, the full
    mass matrix being ``M = mass_scalar (x) I_3`` (property ``M``); ``regions`` maps each named
    boundary of the mesh to its node indices and ``region_weights`` to the nodes' surface areas
    [m^2]; ``surface_triangles`` (t, 3) node indices of the boundary (flat split of second-order
    triangles), for drawing.
    """

    nodes: np.ndarray
    K: sp.csr_matrix
    mass_scalar: sp.csr_matrix
    order: int
    material: Material
    regions: dict[str, np.ndarray] = field(default_factory=dict)
    region_weights: dict[str, np.ndarray] = field(default_factory=dict)
    surface_triangles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), int))

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_dof(self) -> int:
        return 3 * len(self.nodes)

    @property
    def M(self) -> sp.csr_matrix:
        """Consistent mass matrix (3n, 3n) [kg], interleaved coordinates."""
        return sp.kron(self.mass_scalar, sp.identity(3), format="csr")

    def mass_operator(self, nodes: np.ndarray | None = None) -> sla.LinearOperator:
        """M [kg] (or its rows and columns of the coordinates of ``nodes``, ascending node indices) as a linear
        operator, without the assembled matrix (:func:`kron3_operator`)."""
        ms = self.mass_scalar if nodes is None else self.mass_scalar[nodes][:, nodes]
        return kron3_operator(ms)

    def mass_properties(self) -> MassProperties:
        """Mass, centre of mass and inertia about it, exact for the meshed (curved) geometry.

        m = 1^T M_s 1, m c = X^T M_s 1, Q = X^T M_s X - m c c^T, J_c = tr(Q) I - Q.
        """
        return _mass_properties(self.nodes, self.mass_scalar)

    def region(self, name: str) -> np.ndarray:
        """Node indices of the named boundary region (KeyError lists the names there are)."""
        try:
            return self.regions[name]
        except KeyError:
            raise KeyError(f"no boundary region {name!r}; the mesh has {sorted(self.regions)}") from None

    def nodes_where(self, mask_fn, among: np.ndarray | None = None) -> np.ndarray:
        """Indices of nodes (optionally among ``among``) whose coordinates satisfy ``mask_fn(xyz) -> bool[]``."""
        idx = np.arange(self.n_nodes) if among is None else np.asarray(among)
        return idx[np.asarray(mask_fn(self.nodes[idx]), bool)]


def rigid_body_modes(nodes: np.ndarray, centre: np.ndarray | None = None) -> np.ndarray:
    """Rigid-body displacement fields (3n, 6): translations x, y, z, then rotations e_k x (x - centre)."""
    n = len(nodes)
    r = nodes - (nodes.mean(axis=0) if centre is None else np.asarray(centre, float))
    modes = np.zeros((n, 3, 6))
    for k in range(3):
        modes[:, k, k] = 1.0
        axis = np.zeros(3)
        axis[k] = 1.0
        modes[:, :, 3 + k] = np.cross(axis, r)
    return modes.reshape(3 * n, 6)


def kron3_operator(scalar: sp.spmatrix) -> sla.LinearOperator:
    """The operator ``scalar (x) I_3`` (3n, 3n) on interleaved coordinates, without assembling it.

    x (3n, k) is read as the (n, 3 k) array of its node rows: ``scalar @ x.reshape(n, 3 k)`` forms the same
    sums, term by term in the same order, as the assembled Kronecker product would, with a third of its
    index reads and no (3n, 3n) matrix in memory.
    """
    scalar = sp.csr_matrix(scalar)
    n = scalar.shape[0]

    def matmat(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, float)
        k = x.shape[1] if x.ndim == 2 else 1
        return (scalar @ np.ascontiguousarray(x).reshape(n, 3 * k)).reshape(x.shape)

    return sla.LinearOperator((3 * n, 3 * n), matvec=matmat, matmat=matmat, dtype=float)


def _to_scipy(mat, n: int, position: np.ndarray | None = None) -> sp.csr_matrix:
    """NGSolve sparse matrix -> SciPy CSR (n, n); ``position[i]``: the row/column that NGSolve's i becomes."""
    rows, cols, vals = mat.COO()
    rows, cols = np.asarray(rows), np.asarray(cols)
    if position is not None:
        rows, cols = position[rows], position[cols]
    out = sp.csr_matrix((np.asarray(vals), (rows, cols)), shape=(n, n))
    out.sort_indices()
    return out


def _nodal_space(mesh, order: int):
    """(netgen mesh of ``order``, ngsolve.Mesh, scalar nodal space) of ``mesh`` as :func:`fe_model` takes it."""
    import ngsolve as ngs

    if order not in (1, 2):
        raise ValueError(f"fe_model: element order must be 1 or 2, got {order!r}")
    ngmesh = mesh.ngmesh if hasattr(mesh, "ngmesh") else mesh
    if order == 2 and len(ngmesh.Elements3D()[0].points) == 4:  # a second-order mesh (of a file) is used as is
        ngmesh = ngmesh.Copy()
        ngmesh.SecondOrder()
    m = ngs.Mesh(ngmesh)
    scalar = ngs.NodalFESpace(m, order=order)
    if scalar.ndof != len(ngmesh.Points()):
        raise RuntimeError(f"fe_model: {scalar.ndof} nodal dofs but {len(ngmesh.Points())} mesh points")
    return ngmesh, m, scalar


def _mass_scalar(scalar, material: Material) -> sp.csr_matrix:
    """The scalar consistent mass matrix M_s = int rho N^T N dV [kg] on the nodal space ``scalar``."""
    import ngsolve as ngs

    us, vs = scalar.TnT()
    m_form = ngs.BilinearForm(scalar, symmetric=False)
    m_form += material.density_kg_m3 * us * vs * ngs.dx
    with ngs.TaskManager():
        m_form.Assemble()
    return _to_scipy(m_form.mat, scalar.ndof)


def mesh_mass_properties(mesh, material: Material, order: int = 2) -> MassProperties:
    """Mass properties of the FE model :func:`fe_model` would assemble on ``mesh`` (:meth:`FEModel.mass_properties`,
    the same numbers), from its mass matrix alone: what a rigid twin of a flexible body needs, without K."""
    ngmesh, _, scalar = _nodal_space(mesh, order)
    return _mass_properties(np.array(ngmesh.Coordinates(), float), _mass_scalar(scalar, material))


def _mass_properties(x: np.ndarray, mass_scalar: sp.csr_matrix) -> MassProperties:
    """Mass, centre of mass and inertia about it of nodes ``x`` (n, 3) [m] with scalar mass matrix [kg]:
    m = 1^T M_s 1, m c = X^T M_s 1, Q = X^T M_s X - m c c^T, J_c = tr(Q) I - Q."""
    ms1 = mass_scalar @ np.ones(len(x))
    mass = float(ms1.sum())
    com = x.T @ ms1 / mass
    q = x.T @ (mass_scalar @ x) - mass * np.outer(com, com)
    return MassProperties(mass, com, np.trace(q) * np.eye(3) - q)


def fe_model(mesh, material: Material, order: int = 2, regions: list[str] | None = None) -> FEModel:
    """Assemble the FE model of ``mesh`` (ngsolve.Mesh or netgen mesh) with nodal elements of ``order``: a
    first-order mesh is raised to second order (edge nodes on its geometry's surfaces), a mesh of second-order
    elements (flexgear.fe.mesh_io.netgen_mesh of an imported file) is taken with its edge nodes as they are.

    ``regions``: boundary names to turn into node sets (default: every named boundary except
    "default"). Raises ValueError for an order other than 1 or 2.
    """
    import ngsolve as ngs

    ngmesh, m, scalar = _nodal_space(mesh, order)
    n = scalar.ndof
    vector = scalar**3
    mu, lam = lame_parameters(material)
    u, v = vector.TnT()
    eps_u, eps_v = ngs.Sym(ngs.Grad(u)), ngs.Sym(ngs.Grad(v))
    k_form = ngs.BilinearForm(vector, symmetric=False)
    k_form += (2.0 * mu * ngs.InnerProduct(eps_u, eps_v) + lam * ngs.Trace(eps_u) * ngs.Trace(eps_v)) * ngs.dx
    us, vs = scalar.TnT()
    with ngs.TaskManager():
        k_form.Assemble()
    block = np.arange(3 * n)  # NGSolve order: all x, all y, all z -> interleaved position 3 i + c
    k_inter = _to_scipy(k_form.mat, 3 * n, 3 * (block % n) + block // n)
    del k_form
    k_inter = (k_inter + k_inter.T).tocsr()  # remove round-off asymmetry: (K + K^T) / 2, halved in place
    k_inter.data *= 0.5
    mass_scalar = _mass_scalar(scalar, material)
    # node coordinates: NGSolve's point order equals the nodal dof order (checked: same count)
    nodes = np.array(ngmesh.Coordinates(), float)

    names = [b for b in dict.fromkeys(m.GetBoundaries()) if b != "default"] if regions is None else regions
    region_nodes, region_weights = {}, {}
    for name in names:
        dofs = np.flatnonzero(np.array(scalar.GetDofs(m.Boundaries(name)), bool))
        if not len(dofs):
            have = sorted(set(m.GetBoundaries()))
            raise ValueError(f"fe_model: boundary region {name!r} has no nodes; the mesh has {have}")
        b_form = ngs.BilinearForm(scalar, symmetric=False)
        b_form += us * vs * ngs.ds(definedon=m.Boundaries(name))
        b_form.Assemble()
        diag = _to_scipy(b_form.mat, n).diagonal()[dofs]
        area = float(ngs.Integrate(ngs.CoefficientFunction(1.0), m, definedon=m.Boundaries(name)))
        region_nodes[name] = dofs
        region_weights[name] = diag * (area / diag.sum())  # HRZ lumping: positive, sums to the area

    tri = ngmesh.Elements2D().NumPy()["nodes"].astype(np.int64) - 1
    if order == 2 and tri.shape[1] >= 6:  # corners 0,1,2; mid-nodes 3:(1,2) 4:(0,2) 5:(0,1) in Netgen
        c0, c1, c2, m12, m02, m01 = (tri[:, k] for k in range(6))
        tri = np.concatenate([np.c_[c0, m01, m02], np.c_[m01, c1, m12], np.c_[m01, m12, m02], np.c_[m02, m12, c2]])
    else:
        tri = tri[:, :3]
    return FEModel(nodes, k_inter, mass_scalar, order, material, region_nodes, region_weights, tri)


def surface_faces(fe: FEModel) -> np.ndarray:
    """Boundary faces of ``fe`` as element faces: (t, 3) corners, or for order 2 (t, 6) corners then the
    mid-nodes of edges 01, 12, 20, rebuilt from the flat split of :func:`fe_model` (four blocks of t:
    [c0, m01, m02], [m01, c1, m12], [m01, m12, m02], [m02, m12, c2])."""
    tri = fe.surface_triangles
    if fe.order != 2:
        return tri
    t = len(tri) // 4
    c0, m01, m02 = tri[:t, 0], tri[:t, 1], tri[:t, 2]
    c1, m12, c2 = tri[t:2 * t, 1], tri[t:2 * t, 2], tri[3 * t:, 2]
    return np.column_stack([c0, c1, c2, m01, m12, m02])
