"""ParaView animation: the VTK series opens in meshio with the right steps and points, and a deformed node
sits where Exudyn's own FFRF kinematics put it (SensorSuperElement), at true scale and scaled."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from conftest import VARIANTS

from flexgear.fe.reduced import component_reduced_body
from flexgear.mbs.run import run_variant
from flexgear.report.animate import body_meshes, write_animation
from flexgear.results import save_result
from flexgear.spec import load_variant

meshio = pytest.importorskip("meshio")


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """Model 4 (sun and ring flexible), quick variant, first 2 ms with states every 50 steps (5 states)."""
    variant = load_variant(VARIANTS / "quick" / "model4.toml")
    result = run_variant(variant, t_end_s=0.002, record_states_every=50)
    assert result.ok, result.meta.get("reason")
    return save_result(result, tmp_path_factory.mktemp("anim") / "model4")


@pytest.mark.slow
def test_vtk_series_steps_points_and_node_positions(run_dir, tmp_path):
    from flexgear.results import load_result

    result = load_result(run_dir)
    states = result.extra["states"]
    assert len(states) == 5 and states["time_s"].iloc[-1] == pytest.approx(0.002)
    pvd = write_animation(run_dir, tmp_path / "one", scale=1.0)
    entries = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    assert [float(e.get("timestep")) for e in entries] == pytest.approx(list(states["time_s"]))
    # points: the boundary nodes of every body's component meshes, counted from the reduced bodies
    variant = load_variant(VARIANTS / "quick" / "model4.toml")
    expected = 0
    for info in result.meta["state_bodies"].values():
        for geometry in info["geometries"]:
            red = component_reduced_body(variant.gearbox, geometry, variant.mesh_level)
            used = set(np.unique(red.surface_triangles).tolist()) | (
                {info["probe_node"]} if info["flexible"] else set())
            expected += len(used)
    meshes = body_meshes(result)
    offsets = np.cumsum([0] + [len(m.points) for m in meshes])
    for k, entry in enumerate(entries):
        grid = meshio.read(pvd.parent / entry.get("file"))
        assert len(grid.points) == expected and grid.cells[0].type == "triangle"
        # the flexible bodies' probe node against Exudyn's global position of that mesh node
        for i, m in enumerate(meshes):
            if m.probe < 0:
                continue
            probe = states[[f"{m.name}_probe_{a}_m" for a in "xyz"]].iloc[k].to_numpy()
            assert np.abs(grid.points[offsets[i] + m.probe] - probe).max() < 1e-12
    # the check is not trivial: the ring and sun have deformed by about 0.1 um at the last state
    elastic = grid.point_data["elastic_displacement_m"]
    for name in ("sun", "ring"):
        i = [m.name for m in meshes].index(name)
        assert np.linalg.norm(elastic[offsets[i] + meshes[i].probe]) > 5e-8
    # a deformation scale s moves every node by (s - 1) times its elastic displacement
    scaled = write_animation(run_dir, tmp_path / "scaled", scale=100.0)
    big = meshio.read(scaled.parent / entries[-1].get("file"))
    assert np.allclose(big.points - grid.points, 99.0 * elastic, rtol=1e-9, atol=1e-13)
