"""Export of a component (STL surface, VTK volume) and mesh progress, on the smallest component."""

import numpy as np
import pytest
import trimesh

from flexgear.fe.export import export_component
from flexgear.fe.mesh import build_meshes
from flexgear.geometry.layout import exact_mass_properties


def test_export_roundtrip_keeps_the_volume(gearbox, tmp_path):
    stl, vtk = export_component(gearbox, "input_shaft", tmp_path, level="coarse")
    surface = trimesh.load(stl)
    assert surface.is_watertight
    exact = exact_mass_properties(gearbox, "input_shaft")
    # first-order surface of a tube: volume within 1 % of the exact one (faceted cylinders)
    assert surface.volume * gearbox.material_assumed.density_kg_m3 == pytest.approx(exact.mass, rel=0.01)
    text = vtk.read_text()
    n_points = int(text.split("POINTS")[1].split()[0])
    n_cells = int(text.split("CELLS")[1].split()[0])
    assert n_points > 100 and n_cells > 100
    assert "UNSTRUCTURED_GRID" in text
    # VTK's node order: every tetrahedron's corners right-handed (positive volume), their volumes summing to the
    # tube's within 1 % (straight-sided corner tetrahedra of the second-order mesh)
    import meshio

    grid = meshio.read(vtk)
    cells = grid.cells_dict.get("tetra10", grid.cells_dict.get("tetra"))
    p = grid.points[cells[:, :4]]
    vol = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])) / 6
    assert (vol > 0).all()
    assert vol.sum() * gearbox.material_assumed.density_kg_m3 == pytest.approx(exact.mass, rel=0.01)


def test_build_meshes_shows_progress(gearbox, capsys):
    meshes = build_meshes(gearbox, "coarse", progress=True, components=("input_shaft",))
    err = capsys.readouterr().err
    assert "[1/1] input_shaft (coarse)" in err
    mesh = meshes["input_shaft"]
    assert mesh.n_nodes == len(mesh.nodes) and np.all(mesh.elements < mesh.n_nodes)
    assert {"bearing_seat", "gear_seat"} <= set(mesh.regions)
