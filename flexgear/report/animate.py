"""ParaView animation of a run: ``flexgear animate RUN_DIR`` writes a VTK time series (.pvd + .vtu).

The run must have recorded its body states (``flexgear run VARIANT --states N``, flexgear.mbs.states).
Every body is drawn by the boundary triangles of its component meshes (the reduced bodies of the
run's mesh level, from the cache): a mesh node at body-frame position X sits at

    x(t) = p(t) + A(t) (X + s Phi_X q(t)),

p and A the body frame's position and rotation, q the modal coordinates (flexible bodies; zero for
rigid ones), Phi_X the node's mode-shape rows and s the deformation scale factor (``--scale``, 1 =
true deformation). Point data: ``elastic_displacement_m`` = A Phi_X q (true size, ground frame);
cell data: ``body`` (index into the bodies listed in the .pvd's comment). Each step is one
``<stem>_<k>.vtu`` (XML unstructured grid, float64 base64 binary); ``<stem>.pvd`` lists them with
their times. Open the .pvd in ParaView, colour by elastic_displacement_m and play.
"""

from __future__ import annotations

import base64
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flexgear.cache import atomic_write_bytes
from flexgear.results import RunResult, load_result

__all__ = ["BodyMesh", "body_meshes", "write_animation", "vtu_text"]


@dataclass(frozen=True)
class BodyMesh:
    """Boundary of one body: body-frame points (n, 3), triangles (t, 3), mode rows (3n, m) or None,
    and the index of the probe node among the points (-1 if none)."""

    name: str
    points: np.ndarray
    triangles: np.ndarray
    modes: np.ndarray | None
    probe: int = -1


def _surface(nodes: np.ndarray, triangles: np.ndarray, modes: np.ndarray | None, keep_node: int = -1
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, int]:
    """Only the nodes the triangles use (and ``keep_node``), renumbered."""
    used = np.unique(np.append(triangles.ravel(), [keep_node] if keep_node >= 0 else []).astype(int))
    index = np.full(len(nodes), -1)
    index[used] = np.arange(len(used))
    rows = None if modes is None else modes.reshape(len(nodes), 3, -1)[used].reshape(3 * len(used), -1)
    return nodes[used], index[triangles], rows, int(index[keep_node]) if keep_node >= 0 else -1


def body_meshes(result: RunResult, reduced_source=None) -> list[BodyMesh]:
    """The bodies of a run with recorded states, as boundary meshes in their body frames."""
    from flexgear.spec import load_variant

    bodies = result.meta.get("state_bodies")
    if not bodies or "states" not in result.extra:
        raise ValueError(f"run {result.name!r} has no recorded states: run it with `flexgear run VARIANT --states N`")
    variant = load_variant(result.meta["source"])
    if reduced_source is None:
        from flexgear.fe.ring_shaft import reduced_body as reduced_source
    out = []
    for name, info in bodies.items():
        if not info["geometries"]:  # a body without a component's geometry (a planetary stage's own carrier)
            continue
        parts, tris, rows, probe, count = [], [], [], -1, 0
        for geometry in info["geometries"]:
            red = reduced_source(variant.gearbox, geometry, variant.mesh_level)
            flexible = info["flexible"]
            keep = info.get("probe_node", -1) if flexible else -1
            pts, tri, modes, local_probe = _surface(red.nodes, red.surface_triangles, red.modes if flexible else None,
                                                    keep)
            if local_probe >= 0:
                probe = count + local_probe
            parts.append(pts)
            tris.append(tri + count)
            rows.append(modes)
            count += len(pts)
        modes = None if rows[0] is None else np.vstack(rows)
        out.append(BodyMesh(name, np.vstack(parts), np.vstack(tris), modes, probe))
    return out


def _b64(values: np.ndarray, dtype: str) -> str:
    raw = np.ascontiguousarray(values, dtype=dtype).tobytes()
    return base64.b64encode(struct.pack("<I", len(raw)) + raw).decode()


def vtu_text(points: np.ndarray, triangles: np.ndarray, point_data: dict[str, np.ndarray],
             cell_data: dict[str, np.ndarray]) -> str:
    """An XML VTK unstructured grid of triangles (VTK type 5), base64 binary with UInt32 headers."""
    n, t = len(points), len(triangles)

    def array(name: str, values: np.ndarray, dtype: str, vtk: str) -> str:
        comps = 1 if values.ndim == 1 else values.shape[1]
        return (f'<DataArray type="{vtk}" Name="{name}" NumberOfComponents="{comps}" format="binary">'
                f"{_b64(values, dtype)}</DataArray>")

    pd_xml = "".join(array(k, v, "<f8", "Float64") for k, v in point_data.items())
    cd_xml = "".join(array(k, v, "<i4", "Int32") for k, v in cell_data.items())
    return ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
            'header_type="UInt32">\n<UnstructuredGrid>\n'
            f'<Piece NumberOfPoints="{n}" NumberOfCells="{t}">\n'
            f"<Points>{array('Points', points, '<f8', 'Float64')}</Points>\n"
            f"<Cells>{array('connectivity', triangles.ravel(), '<i4', 'Int32')}"
            f"{array('offsets', 3 * np.arange(1, t + 1), '<i4', 'Int32')}"
            f"{array('types', np.full(t, 5), '<u1', 'UInt8')}</Cells>\n"
            f"<PointData>{pd_xml}</PointData>\n<CellData>{cd_xml}</CellData>\n"
            "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")


def write_animation(run_dir: str | Path, out_dir: str | Path | None = None, scale: float = 1.0,
                    reduced_source=None) -> Path:
    """Write ``<out_dir>/<variant>.pvd`` and one .vtu per recorded state (default out_dir:
    ``RUN_DIR/animation``); returns the .pvd path. ``scale``: factor on the elastic deformation."""
    run_dir = Path(run_dir)
    result = load_result(run_dir)
    meshes = body_meshes(result, reduced_source)
    states = result.extra["states"]
    out = Path(out_dir) if out_dir is not None else run_dir / "animation"
    out.mkdir(parents=True, exist_ok=True)
    triangles = np.vstack([m.triangles + sum(len(o.points) for o in meshes[:i]) for i, m in enumerate(meshes)])
    body_id = np.concatenate([np.full(len(m.triangles), i) for i, m in enumerate(meshes)])
    entries = []
    for k, row in enumerate(states.itertuples(index=False)):
        row = row._asdict()
        points, elastic = [], []
        for m in meshes:
            p = np.array([row[f"{m.name}_p{a}_m"] for a in "xyz"])
            a = np.array([row[f"{m.name}_a{i}{j}"] for i in range(3) for j in range(3)]).reshape(3, 3)
            u = np.zeros_like(m.points)
            if m.modes is not None:
                # the integrated modes only: a gear's modes above the dynamic cut-off were not recorded (their
                # static residual acts at the contacts, flexgear.mbs.residual)
                n = sum(1 for j in range(m.modes.shape[1]) if f"{m.name}_q{j}" in row)
                q = np.array([row[f"{m.name}_q{j}"] for j in range(n)])
                u = (m.modes[:, :n] @ q).reshape(-1, 3)
            points.append(p + (m.points + scale * u) @ a.T)
            elastic.append(u @ a.T)
        name = f"{result.name}_{k:04d}.vtu"
        text = vtu_text(np.vstack(points), triangles, {"elastic_displacement_m": np.vstack(elastic)},
                        {"body": body_id})
        atomic_write_bytes(out / name, text.encode())
        entries.append(f'<DataSet timestep="{row["time_s"]:.9g}" part="0" file="{name}"/>')
    bodies = ", ".join(f"{i}: {m.name}" for i, m in enumerate(meshes))
    pvd = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
           f"<!-- flexgear animate: {result.name}, deformation scale {scale:g}, bodies {bodies} -->\n<Collection>\n"
           + "\n".join(entries) + "\n</Collection>\n</VTKFile>\n")
    path = out / f"{result.name}.pvd"
    atomic_write_bytes(path, pvd.encode())
    return path
