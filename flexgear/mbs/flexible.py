"""Flexible bodies in Exudyn: a reduced body (flexgear.fe.cms) as ``ObjectFFRFreducedOrder``, and its cache.

The body's reference frame is a ``NodeRigidBodyRxyz`` node exactly like a rigid body's
(flexgear.mbs.bodies): bushings, drives and gear contacts attach to the frame coordinates whatever the
body's form. The flexible coordinates are the reduced free-free modes, M-orthogonal to the rigid
modes (Tisserand mean axes), on a ``NodeGenericODE2``. Interfaces get ``MarkerSuperElementRigid``
markers for fixed joints. A marker over an interface's real node set (~1 400 nodes) cost 230x a
frame bushing per step in the prototype, so the marker acts on six virtual nodes that carry the
interface's RBE3 motion exactly (:func:`interface_virtual_nodes`).

Cache: ``cached_reduced_body(key, build)`` stores the reduced body as ``meshes/reduced-<key>.npz``
(atomic write); the key must hash every input (geometry, mesh, reduction settings, versions).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from flexgear.fe.cms import ReducedBody
from flexgear.mbs.bodies import Body, add_frame_inertia, matrix_container, resting_node

__all__ = ["FlexibleBody", "add_flexible_body", "interface_basis", "interface_virtual_nodes", "interface_point_modes"]

@dataclass(frozen=True)
class FlexibleBody(Body):
    """Handles of a flexible body: a :class:`flexgear.mbs.bodies.Body` plus modal node and interface markers."""

    modal_node: int = -1
    interface_markers: dict[str, int] = field(default_factory=dict)
    reduced: ReducedBody | None = None
    point_markers: dict[str, list[int]] = field(default_factory=dict)  # interface -> position markers
    # modes of the converged basis left out of the time integration (flexgear.mbs.residual.DroppedModes);
    # their static compliance returns at the contacts
    dropped: object | None = None
    # production formulation: the body's spin terms (flexgear.mbs.spin.SpinMatrices) and nominal spin [rad/s]
    spin: object | None = None
    nominal_spin_rad_s: float = 0.0
    modal_equations: int = -1  # their ObjectGenericODE2 ("linear")
    superelement: bool = True  # an ObjectFFRFreducedOrder places markers and mesh nodes (else ``obj`` is the frame)
    # ("linear") M, K and D of the modal equations at rest in the body's coordinates q~ (q = basis q~)
    modal_matrices: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    # the nodes of q~ in order and their sizes; ``basis`` T (m, m) with q = T q~ (None: q~ = q, one node,
    # ``modal_node``); with interface coordinates (:func:`interface_basis`) ``modal_node`` is -1
    modal_nodes: tuple[int, ...] = ()
    modal_sizes: tuple[int, ...] = ()
    basis: np.ndarray | None = None
    contact_nodes: tuple[int, ...] = ()  # the nodes of q~ that the gear contacts sense (all, without a basis)
    # an imported gear's contact_band selector (flexgear.fe.reduced.contact_fit_window), None: the gear data's band
    contact_band: object | None = None

    def node_columns(self, nodes: tuple[int, ...] | list[int]) -> np.ndarray:
        """Indices in q~ of the coordinates of ``nodes`` (some of ``modal_nodes``), in order."""
        starts = dict(zip(self.modal_nodes, np.cumsum([0, *self.modal_sizes[:-1]]), strict=True))
        sizes = dict(zip(self.modal_nodes, self.modal_sizes, strict=True))
        return np.concatenate([np.arange(starts[n], starts[n] + sizes[n]) for n in nodes])

    def to_coordinates(self, rows: np.ndarray) -> np.ndarray:
        """``rows`` (r, m) over the modal coordinates q as rows over the body's coordinates q~ (rows T)."""
        return rows if self.basis is None else rows @ self.basis

    def coordinates_of(self, q: np.ndarray) -> np.ndarray:
        """q~ of modal coordinates ``q`` (m,) (T^-1 q)."""
        return q if self.basis is None else np.linalg.solve(self.basis, q)

    def span(self, rows: np.ndarray) -> tuple[list[int], np.ndarray]:
        """``rows`` (r, m) over q as rows over the body's coordinates, kept only on the nodes they touch: (nodes,
        rows over those nodes' coordinates). An interface's rows then span its own six coordinates: a constraint on
        them costs Exudyn rows x 6^2, not rows x m^2 (its dense marker Jacobian). Blocks below 1e-9 of the largest
        entry are round-off of exact zeros (the interface rows of the other coordinates vanish by construction)."""
        r = self.to_coordinates(np.atleast_2d(rows))
        if self.basis is None:
            return [self.modal_node], r
        scale = np.abs(r).max()
        nodes, blocks, start = [], [], 0
        for node, size in zip(self.modal_nodes, self.modal_sizes, strict=True):
            block = r[:, start:start + size]
            start += size
            if np.abs(block).max() > 1e-9 * scale:
                nodes.append(node)
                blocks.append(block)
        return nodes, np.hstack(blocks)


def interface_basis(reduced: ReducedBody, names: tuple[str, ...], sensing: np.ndarray | None = None
                    ) -> np.ndarray | None:
    """T (m, m) of modal coordinates q = T q~ whose first 6 k coordinates are the RBE3 motions (translation [m],
    rotation [rad]) of the k interfaces ``names``, then the r coordinates ``sensing`` q (rows (r, m): a gear's
    contact sensing, flexgear.mbs.train.contact_sensing_rows); P stacks their rows (``reduced.interface_motion``).

    Columns: A = P^T (P P^T)^-1 (the least-norm modal combinations of unit interface motions), then an orthonormal
    basis N of P's null space (the interfaces held). P A = I and P N = 0; with M = I the mass matrix in q~ is
    blockdiag((P P^T)^-1, I) (:func:`interface_mass`), as sparse as before but for one (6 k + r) block. None when P
    has rank below its row count or at least m rows (too few modes to carry the interface motions).
    """
    rows = [reduced.interface_motion(n) for n in names] + ([sensing] if sensing is not None and len(sensing) else [])
    if not rows:
        return None
    p = np.vstack(rows)
    k, m = p.shape
    if k >= m:
        return None
    # rank of the rows whatever their units; scaling rows keeps the null space, the last m - k right vectors
    _, sv, vt = np.linalg.svd(p / np.linalg.norm(p, axis=1)[:, None])
    if sv[-1] < 1e-8 * sv[0]:
        return None
    return np.hstack([p.T @ np.linalg.inv(p @ p.T), vt[k:].T])


def interface_mass(basis: np.ndarray, n_interface: int) -> np.ndarray:
    """T^T T of :func:`interface_basis` with its exact zeros: A^T N = 0 and N^T N = I (``n_interface`` = 6 k)."""
    k = n_interface
    out = np.eye(basis.shape[1])
    out[:k, :k] = basis[:, :k].T @ basis[:, :k]
    return out


def interface_virtual_nodes(reduced: ReducedBody, name: str, point=None, arm: float = 0.01):
    """Six virtual mesh nodes that carry the RBE3 motion of interface ``name`` as a rigid pattern.

    Nodes at ``point`` +- ``arm`` e_k (body frame [m]; default the interface's RBE3 point) whose
    displacements are the interface's rigid motion u = t + theta x (x - p) with (t, theta) =
    ``reduced.interface_motion(name) @ q``. A ``MarkerSuperElementRigid`` with equal weights on them
    moves exactly as the RBE3 marker over the interface's real node set (same weighted least-squares
    rotation), at the cost of six nodes instead of hundreds. Returns (positions (6, 3), modes (18, m)).
    """
    p = reduced.interface(name).point if point is None else np.asarray(point, float)
    positions = np.array([p + sign * arm * np.eye(3)[k] for k in range(3) for sign in (1.0, -1.0)])
    return positions, interface_point_modes(reduced, name, positions)


def interface_point_modes(reduced: ReducedBody, name: str, points) -> np.ndarray:
    """(3 n_points, m) displacements of ``points`` [m, body frame] moving rigidly with interface ``name``.

    u = t + theta x (x - p) per mode, (t, theta) = ``reduced.interface_motion(name)``, p its RBE3 point.
    """
    itf = reduced.interface(name)
    motion = reduced.interface_motion(name)
    t, th = motion[:3], motion[3:]
    return np.vstack([t + np.cross(th, np.asarray(x, float) - itf.point, axis=0) for x in points])


def add_flexible_body(mbs, name: str, reduced: ReducedBody, position, rotation_matrix=None,
                      velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
                      stiffness_damping_s: float = 0.0, mass_damping_per_s: float = 0.0,
                      interface_markers: list[str] | dict[str, np.ndarray] | None = None,
                      point_markers: dict[str, list] | None = None, show: bool = True,
                      reference: bool = False, nominal_spin_rad_s: float = 0.0,
                      superelement: bool = True, interface_coordinates: tuple[str, ...] = (),
                      sensing_rows: np.ndarray | None = None, linear_frame_tolerance: float | None = None
                      ) -> FlexibleBody:
    """Add ``reduced`` as an ``ObjectFFRFreducedOrder`` whose frame node sits at ``position`` [m].

    ``rotation_matrix`` (3, 3) body-to-ground (default identity); ``velocity`` [m/s] and
    ``angular_velocity`` [rad/s, ground frame] are initial values of the frame. Damping of the
    flexible coordinates D = mass_damping_per_s * M_r + stiffness_damping_s * K_r (Rayleigh).
    ``interface_markers``: interfaces that get a ``MarkerSuperElementRigid`` (default all), as names
    (marker at the interface's RBE3 point) or as {name: marker point in the body frame [m]}. The
    markers act on six virtual nodes per interface (:func:`interface_virtual_nodes`) appended to the
    mode basis; the floating-frame inertia terms come from the real mesh only. ``point_markers``:
    {interface: points [m, body frame]}: one virtual node per point moving rigidly with the interface
    (:func:`interface_point_modes`) and a ``MarkerSuperElementPosition`` on it (bearing springs at a seat).
    Production formulation: the floating frame is linear (flexgear.mbs.spin: the frame a rigid body, the modes
    linear equations at ``nominal_spin_rad_s`` about the body's z axis; the object then only places the markers;
    add a flexgear.mbs.spin.SpinSchedule for the ramp). ``reference``: Exudyn's nonlinear floating-frame terms
    (``computeFFRFterms``) instead. ``superelement`` False (production only): no ``ObjectFFRFreducedOrder`` at
    all (no interface or point markers,
    no mesh-node sensors; its zero mass matrix cost ~7 % of model 7's step); ``obj`` is then the frame's rigid body.
    ``interface_coordinates`` (without superelement): interfaces whose RBE3 motions become coordinates of their own
    six-coordinate node (:func:`interface_basis`; the other coordinates on one more node), for constraints on them
    (flexgear.mbs.joints); ignored when the basis cannot carry them. ``sensing_rows`` (r, m) with them: the gear
    contacts' sensed coordinates on one more node (``contact_nodes``; flexgear.mbs.train.contact_sensing_rows), so
    that a mesh constraint spans r columns, not m. ``linear_frame_tolerance`` (production only; None: Exudyn's
    ``ObjectRigidBody``): the frame's inertia as constant matrices (flexgear.mbs.bodies.add_linear_frame) with
    this axisymmetry tolerance.
    """
    import exudyn as exu
    from exudyn.itemInterface import (
        MarkerNodeCoordinates,
        MarkerNodeRigid,
        MarkerSuperElementPosition,
        MarkerSuperElementRigid,
        ObjectFFRFreducedOrder,
        VObjectFFRFreducedOrder,
    )
    from exudyn.rigidBodyUtilities import GetRigidBodyNode

    rot = np.eye(3) if rotation_matrix is None else np.asarray(rotation_matrix, float)
    node_item = GetRigidBodyNode(nodeType=exu.NodeType.RotationRxyz, position=list(map(float, position)),
                                 velocity=list(map(float, velocity)), rotationMatrix=rot,
                                 angularVelocity=list(map(float, angular_velocity)))
    node_item.name = f"{name}_node"
    node = mbs.AddNode(node_item)
    m = reduced.n_modes
    if not superelement and (reference or interface_markers or point_markers):
        raise ValueError(f"{name}: a body without superelement needs the production formulation and no markers")
    names = tuple(interface_coordinates)
    sensing = None if sensing_rows is None or not len(sensing_rows) else np.asarray(sensing_rows, float)
    basis = None if superelement else interface_basis(reduced, names, sensing)
    if basis is None and not superelement and sensing is not None:  # too few modes for both: the interfaces
        sensing = None
        basis = interface_basis(reduced, names)
    blocks = [(n, 6) for n in names] + ([("contact", len(sensing))] if sensing is not None else [])
    if basis is None:
        blocks = []
    blocks.append(("modes", m - sum(n for _, n in blocks)))
    labels, sizes = (tuple(x) for x in zip(*blocks, strict=True))
    modal_nodes = tuple(resting_node(mbs, f"{name}_{label}", n) for label, n in zip(labels, sizes, strict=True))
    modal = modal_nodes[0] if basis is None else -1
    contact_nodes = tuple(n for n, label in zip(modal_nodes, labels, strict=True) if label == "contact") or modal_nodes
    if not superelement:
        interface_markers = []
    if interface_markers is None:
        interface_markers = [i.name for i in reduced.interfaces]
    points = (dict(interface_markers) if isinstance(interface_markers, dict)
              else {n: None for n in interface_markers})
    positions, modes, first = [reduced.nodes], [reduced.modes], {}
    count = len(reduced.nodes)
    for itf_name, point in points.items():
        x, rows = interface_virtual_nodes(reduced, itf_name, point)
        first[itf_name] = count
        positions.append(x)
        modes.append(rows)
        count += len(x)
    point_first = {}
    for itf_name, pts in (point_markers or {}).items():
        point_first[itf_name] = (count, len(pts))
        positions.append(np.asarray(pts, float).reshape(-1, 3))
        modes.append(interface_point_modes(reduced, itf_name, pts))
        count += len(pts)
    damping = mass_damping_per_s + stiffness_damping_s * reduced.stiffness
    inv = reduced.invariants
    obj = -1 if not superelement else mbs.AddObject(ObjectFFRFreducedOrder(
        name=name, nodeNumbers=[node, modal],
        massMatrixReduced=matrix_container(np.eye(m)),
        stiffnessMatrixReduced=matrix_container(np.diag(reduced.stiffness)),
        dampingMatrixReduced=matrix_container(np.diag(damping)) if np.any(damping) else [],
        modeBasis=np.vstack(modes), referencePositions=np.vstack(positions).ravel(),
        mass=float(inv["mass"]), inertia=inv["inertia"], centerOfMass=inv["centerOfMass"],
        mPsiTildePsi=inv["mPsiTildePsi"], mPsiTildePsiTilde=inv["mPsiTildePsiTilde"],
        mPhitTPsi=inv["mPhitTPsi"], mPhitTPsiTilde=inv["mPhitTPsiTilde"],
        mXRefTildePsi=inv["mXRefTildePsi"], mXRefTildePsiTilde=inv["mXRefTildePsiTilde"],
        computeFFRFterms=reference,
        visualization=VObjectFFRFreducedOrder(show=show, triangleMesh=reduced.surface_triangles if show else []),
    ))
    spin, equations, matrices, linear_frame = None, -1, None, None
    if not reference:
        from flexgear.mbs.spin import add_linear_modal_equations, spin_matrices, transformed

        # the inertia about the frame origin, as flexgear.mbs.bodies.add_rigid_body
        frame, linear_frame = add_frame_inertia(mbs, f"{name}_frame", node, float(inv["mass"]), inv["centerOfMass"],
                                                inv["inertia"], nominal_spin_rad_s, linear_frame_tolerance)
        spin = spin_matrices(reduced)
        matrices = (np.eye(m), np.diag(reduced.stiffness), np.diag(np.broadcast_to(damping, (m,))))
        if basis is not None:
            spin = transformed(spin, basis)
            matrices = (interface_mass(basis, m - sizes[-1]),
                        *(basis.T @ a @ basis for a in matrices[1:]))
        # at rest: flexgear.mbs.spin.SpinSchedule moves the spin terms with the ramp
        equations = add_linear_modal_equations(mbs, name, modal_nodes, matrices, spin, 0.0)
        obj = obj if superelement else frame
    markers = {}
    for itf_name, start in first.items():
        markers[itf_name] = mbs.AddMarker(MarkerSuperElementRigid(
            name=f"{name}_{itf_name}", bodyNumber=obj, offset=[0.0, 0.0, 0.0],
            meshNodeNumbers=np.arange(start, start + 6, dtype=np.int64), weightingFactors=np.full(6, 1.0 / 6.0),
            useAlternativeApproach=True, visualization={"show": False, "showMarkerNodes": False}))
    points = {itf_name: [mbs.AddMarker(MarkerSuperElementPosition(
        name=f"{name}_{itf_name}_point{k}", bodyNumber=obj, meshNodeNumbers=[start + k], weightingFactors=[1.0],
        visualization={"show": False, "showMarkerNodes": False})) for k in range(n)]
        for itf_name, (start, n) in point_first.items()}
    m_rigid = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node))
    m_coords = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=node))
    return FlexibleBody(name, node, obj, m_rigid, m_coords, np.asarray(position, float), reduced.props, True,
                        linear_frame, modal, markers, reduced, points, spin=spin,
                        nominal_spin_rad_s=float(nominal_spin_rad_s), modal_equations=equations,
                        superelement=superelement, modal_matrices=matrices, modal_nodes=modal_nodes,
                        modal_sizes=sizes, basis=basis, contact_nodes=contact_nodes)




