"""Flexible bodies in Exudyn: a reduced body (flexgear.cms) as ``ObjectFFRFreducedOrder``, and its cache.

The body's reference frame is a ``NodeRigidBodyRxyz`` node exactly like a rigid body's
(flexgear.bodies): bushings, drives and gear contacts attach to the frame coordinates whatever the
body's form. The flexible coordinates are the reduced free-free modes, M-orthogonal to the rigid
modes (Tisserand mean axes), on a ``NodeGenericODE2``. Interfaces get ``MarkerSuperElementRigid``
markers (weighted node sets) for fixed joints; keep drives and bushings off them (a marker over
~1 400 nodes cost 230x a frame bushing per step in the prototype).

Cache: ``cached_reduced_body(key, build)`` stores the reduced body as ``meshes/reduced-<key>.npz``
(atomic write); the key must hash every input (geometry, mesh, reduction settings, versions).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from flexgear.bodies import Body
from flexgear.cms import ReducedBody
from flexgear.results import atomic_write_bytes

__all__ = ["FlexibleBody", "add_flexible_body", "cached_reduced_body", "reduced_cache_path"]

CACHE_FORMAT_VERSION = 1  # bump when ReducedBody's content or the reduction changes


@dataclass(frozen=True)
class FlexibleBody(Body):
    """Handles of a flexible body: a :class:`flexgear.bodies.Body` plus modal node and interface markers."""

    modal_node: int = -1
    interface_markers: dict[str, int] = field(default_factory=dict)
    reduced: ReducedBody | None = None


def add_flexible_body(mbs, name: str, reduced: ReducedBody, position, rotation_matrix=None,
                      velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
                      stiffness_damping_s: float = 0.0, mass_damping_per_s: float = 0.0,
                      interface_markers: list[str] | None = None, show: bool = True) -> FlexibleBody:
    """Add ``reduced`` as an ``ObjectFFRFreducedOrder`` whose frame node sits at ``position`` [m].

    ``rotation_matrix`` (3, 3) body-to-ground (default identity); ``velocity`` [m/s] and
    ``angular_velocity`` [rad/s, ground frame] are initial values of the frame. Damping of the
    flexible coordinates D = mass_damping_per_s * M_r + stiffness_damping_s * K_r (Rayleigh).
    ``interface_markers``: names of interfaces that get a ``MarkerSuperElementRigid`` (default all).
    """
    import exudyn as exu
    from exudyn.itemInterface import (
        MarkerNodeCoordinates,
        MarkerNodeRigid,
        MarkerSuperElementRigid,
        NodeGenericODE2,
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
    modal = mbs.AddNode(NodeGenericODE2(name=f"{name}_modes", numberOfODE2Coordinates=m,
                                        referenceCoordinates=[0.0] * m, initialCoordinates=[0.0] * m,
                                        initialCoordinates_t=[0.0] * m))

    def container(diag: np.ndarray):
        mc = exu.MatrixContainer()
        mc.SetWithDenseMatrix(np.diag(diag), useDenseMatrix=False)
        return mc

    damping = mass_damping_per_s + stiffness_damping_s * reduced.stiffness
    inv = reduced.invariants
    obj = mbs.AddObject(ObjectFFRFreducedOrder(
        name=name, nodeNumbers=[node, modal],
        massMatrixReduced=container(np.ones(m)), stiffnessMatrixReduced=container(reduced.stiffness),
        dampingMatrixReduced=container(damping) if np.any(damping) else [],
        modeBasis=reduced.modes, referencePositions=reduced.nodes.ravel(),
        mass=float(inv["mass"]), inertia=inv["inertia"], centerOfMass=inv["centerOfMass"],
        mPsiTildePsi=inv["mPsiTildePsi"], mPsiTildePsiTilde=inv["mPsiTildePsiTilde"],
        mPhitTPsi=inv["mPhitTPsi"], mPhitTPsiTilde=inv["mPhitTPsiTilde"],
        mXRefTildePsi=inv["mXRefTildePsi"], mXRefTildePsiTilde=inv["mXRefTildePsiTilde"],
        computeFFRFterms=True,
        visualization=VObjectFFRFreducedOrder(show=show, triangleMesh=reduced.surface_triangles if show else []),
    ))
    markers = {}
    names = [i.name for i in reduced.interfaces] if interface_markers is None else interface_markers
    for itf_name in names:
        itf = reduced.interface(itf_name)
        markers[itf_name] = mbs.AddMarker(MarkerSuperElementRigid(
            name=f"{name}_{itf_name}", bodyNumber=obj, offset=[0.0, 0.0, 0.0],  # at the weighted mean
            meshNodeNumbers=np.asarray(itf.nodes, np.int64), weightingFactors=np.asarray(itf.weights, float),
            useAlternativeApproach=True, visualization={"show": False, "showMarkerNodes": False}))
    m_rigid = mbs.AddMarker(MarkerNodeRigid(nodeNumber=node))
    m_coords = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=node))
    return FlexibleBody(name, node, obj, m_rigid, m_coords, np.asarray(position, float), reduced.props, True,
                        modal, markers, reduced)


def reduced_cache_path(key: str, directory: str | Path | None = None) -> Path:
    """``<directory or $FLEXGEAR_CACHE_DIR or meshes/>/reduced-<key>.npz``."""
    if directory is None:
        directory = os.environ.get("FLEXGEAR_CACHE_DIR", Path(__file__).resolve().parents[1] / "meshes")
    return Path(directory) / f"reduced-v{CACHE_FORMAT_VERSION}-{key}.npz"


def cached_reduced_body(key: str, build: Callable[[], ReducedBody],
                        directory: str | Path | None = None) -> ReducedBody:
    """Load the reduced body cached under ``key``, or ``build()`` it and store it atomically.

    ``key`` must be a hash of every input (flexgear.spec.spec_hash of geometry, mesh and reduction
    settings): a changed input gives a new key and a rebuild; an unreadable file is rebuilt.
    """
    path = reduced_cache_path(key, directory)
    if path.exists():
        try:
            return ReducedBody.load(path.read_bytes())
        except (OSError, ValueError, KeyError):
            pass  # damaged entry: rebuild and overwrite
    body = build()
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, body.save())
    return body
