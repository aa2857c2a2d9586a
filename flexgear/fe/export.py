"""The meshed assembly as STL/VTK files and a PNG picture (export of the FE stage).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from flexgear.fe.mesh import component_mesh
from flexgear.fe.mesh_io import NETGEN_TO_VTK
from flexgear.fe.surface import surface_mesh
from flexgear.geometry.check import MM_PER_M, nominal_placements, transverse_section
from flexgear.geometry.involute import gear_set_geometry
from flexgear.geometry.layout import component_layout
from flexgear.spec import GEOMETRY_COMPONENTS, GearboxSpec


def assembly_trimesh(spec: GearboxSpec, level: str = "coarse") -> dict[str, trimesh.Trimesh]:
    """Surface meshes of all placed components (planets numbered planet_0 ...)."""
    out, k = {}, 0
    for place in nominal_placements(spec):
        tm = surface_mesh(component_mesh(spec, place.component, level)).copy()
        tm.apply_transform(place.matrix())
        name = place.component
        if name == "planet":
            name, k = f"planet_{k}", k + 1
        out[name] = tm
    return out


def write_vtk(path: str | Path, nodes: np.ndarray, elements: np.ndarray) -> None:
    """Legacy ASCII VTK unstructured grid of tetrahedra (VTK types 10 / 24 for 4 / 10 nodes), ``elements`` in
    Netgen's node order, written in VTK's (:data:`flexgear.fe.mesh_io.NETGEN_TO_VTK`)."""
    vtk_type = {4: 10, 10: 24}[elements.shape[1]]
    elements = np.asarray(elements)[:, NETGEN_TO_VTK[elements.shape[1]]]
    lines = ["# vtk DataFile Version 3.0", "flexgear mesh", "ASCII", "DATASET UNSTRUCTURED_GRID",
             f"POINTS {len(nodes)} double"]
    lines += [" ".join(f"{v:.9g}" for v in p) for p in nodes]
    lines.append(f"CELLS {len(elements)} {len(elements) * (elements.shape[1] + 1)}")
    lines += [f"{elements.shape[1]} " + " ".join(map(str, e)) for e in elements]
    lines.append(f"CELL_TYPES {len(elements)}")
    lines += [str(vtk_type)] * len(elements)
    Path(path).write_text("\n".join(lines) + "\n")


def export_component(spec: GearboxSpec, component: str, folder: str | Path, level: str = "coarse") -> list[Path]:
    """Write ``<component>.stl`` (surface) and ``<component>.vtk`` (volume mesh) into ``folder``."""
    if component not in GEOMETRY_COMPONENTS:
        raise ValueError(f"unknown component {component!r}; allowed: {', '.join(GEOMETRY_COMPONENTS)}")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    mesh = component_mesh(spec, component, level)
    stl, vtk = folder / f"{component}.stl", folder / f"{component}.vtk"
    surface_mesh(mesh).export(stl)
    write_vtk(vtk, mesh.nodes, mesh.elements)
    return [stl, vtk]


def render_assembly_png(spec: GearboxSpec, path: str | Path, level: str = "coarse") -> Path:
    """PNG of the assembly (matplotlib, offscreen): 3D view, transverse section and a mesh zoom."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    parts = assembly_trimesh(spec, level)
    colours = {"sun": "tab:orange", "planet": "tab:blue", "ring": "tab:gray", "input_shaft": "tab:olive",
               "output_shaft": "tab:brown"}
    fig = plt.figure(figsize=(15, 5.4))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    for name, tm in parts.items():
        if name == "output_shaft":
            continue  # hides the gears; drawn in the section view instead
        keep = tm.vertices[tm.faces].mean(axis=1)
        cut = ~((keep[:, 0] > 0) & (keep[:, 1] < 0)) if name == "ring" else np.ones(len(tm.faces), bool)
        poly = Poly3DCollection(tm.vertices[tm.faces[cut]] * MM_PER_M, linewidths=0.0)
        poly.set_facecolor(colours[name.split("_")[0] if name.startswith("planet") else name])
        poly.set_alpha(1.0)
        ax.add_collection3d(poly)
    lim = 190
    ax.set(xlim=(-lim, lim), ylim=(-lim, lim), zlim=(-140, 60), xlabel="x [mm]", ylabel="y [mm]", zlabel="z [mm]")
    ax.set_box_aspect((2 * lim, 2 * lim, 200))
    ax.view_init(elev=25, azim=-60)
    ax.set_title("assembly (ring cut away, output shaft hidden)")
    places = nominal_placements(spec)
    z = next(p for p in component_layout(spec, "planet").prisms if p.section.gear is not None).z1 - 1e-4
    for k, (axis, half) in enumerate(((fig.add_subplot(1, 3, 2), 180.0), (fig.add_subplot(1, 3, 3), 9.0))):
        for place in places:
            if place.component in ("input_shaft", "output_shaft"):
                continue
            contours = transverse_section(spec, place.component, place, z).to_polygons()
            verts = np.vstack([np.vstack([c, c[:1]]) for c in contours])
            codes = np.concatenate([[MplPath.MOVETO] + [MplPath.LINETO] * (len(c) - 1) + [MplPath.CLOSEPOLY]
                                    for c in contours])
            axis.add_patch(PathPatch(MplPath(verts, codes), fc=colours[place.component], ec="k", lw=0.3))
        centre = (0.0, 0.0) if k == 0 else (gear_set_geometry(spec).sun.reference_radius * MM_PER_M + 1.2, 0.0)
        axis.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
                 aspect="equal", xlabel="x [mm]", ylabel="y [mm]")
        axis.set_title(f"transverse section z = {z * MM_PER_M:.1f} mm" if k == 0 else "sun-planet mesh (zoom)")
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
