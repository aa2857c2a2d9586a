"""The parallel-axis pair's shafts (examples/parallel_helical: each gear fixed in the middle of its shaft, the shaft
on a bearing at each end) as reduced bodies against their full FE models under the loads they carry, coarse meshes.

- The mesh force enters at the gear's seat (the joint interface) and leaves at the two bearing seats. Compliance of
  the gear seat and the near bearing seat (their RBE3 motions under their RBE3 loads, twelve by twelve), the far
  bearing seat held: the reduced body against full FE. A Craig-Bampton basis holds the static answer to every
  interface load, so they agree to round-off.
- The full FE model itself against a Timoshenko beam between the gear seat and the far bearing (whole tube
  sections): torsion for both shafts (a circular tube twists as Saint-Venant's solution), the lateral compliance
  for the input shaft (length over diameter 3.6). The output shaft is a stub sized from the wheel's bore (length
  over diameter 1.1), where beam theory does not describe its bending, so it is not asked there.
- Free-free modes: neither shaft has one below 3x the mesh frequency (1250 Hz at 3000 rpm, 25 teeth); the full FE
  model's lowest lies above that band and the reduced body's lowest lies at or above it (Rayleigh-Ritz).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_attachment import interface_compliance, section_interface, timoshenko_seat_compliance

import flexgear as fg

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "parallel_helical" / "gearbox.toml"


@pytest.fixture(scope="module")
def gearbox():
    return fg.load_gearbox(EXAMPLE)


@pytest.fixture(scope="module", params=["input_shaft", "output_shaft"])
def shaft(request, gearbox, example_cache):
    """(name, full FE model, reduced body) of a shaft at the coarse level (the examples' cache)."""
    from flexgear.fe.fem import fe_model
    from flexgear.fe.mesh import component_mesh
    from flexgear.fe.reduced import component_reduced_body

    name = request.param
    body = component_reduced_body(gearbox, name, "coarse")
    fe = fe_model(component_mesh(gearbox, name, "coarse", order=1).ngsolve_mesh(), gearbox.material_assumed,
                  gearbox.meshing_assumed["coarse"].element_order)
    assert np.allclose(fe.nodes, body.nodes)
    return name, fe, body


def test_gear_seat_and_near_bearing_compliance_equals_full_fe(shaft):
    name, fe, body = shaft
    joint, near, far = (body.interface(n) for n in (body.interfaces[0].name, "bearing_seat_near", "bearing_seat"))
    assert joint.name == {"input_shaft": "sun_seat", "output_shaft": "planet_seat"}[name]
    full = interface_compliance(fe, [joint, near], far)
    reduced = interface_compliance(body, [joint, near], far)
    assert np.all(np.diag(full) > 0)
    assert np.abs(reduced - full).max() < 1e-6 * np.diag(full).max()


def test_full_fe_shaft_against_a_timoshenko_tube(gearbox, shaft):
    name, fe, body = shaft
    z_joint = body.nodes[body.interface(body.interfaces[0].name).nodes, 2]
    z_far = body.nodes[body.interface("bearing_seat").nodes, 2]
    load, held = (z_joint.min(), z_joint.max()), (z_far.min(), z_far.max())
    lateral, torsion = timoshenko_seat_compliance(gearbox, name, load, held)
    beam = interface_compliance(fe, section_interface(fe, "gear", *load), section_interface(fe, "bearing", *held))
    assert beam[5, 5] == pytest.approx(torsion, rel=0.01)
    if name == "input_shaft":
        assert beam[0, 0] == pytest.approx(lateral, rel=0.05)
        assert beam[1, 1] == pytest.approx(lateral, rel=0.05)


def test_no_shaft_mode_below_three_mesh_frequencies(gearbox, shaft):
    from flexgear.design import as_design
    from flexgear.fe.compliance import free_body_solver
    from flexgear.fe.spectrum import lowest_eigenpairs

    _, fe, body = shaft
    band = 3.0 * as_design(gearbox).theory.mesh_frequency
    solver = free_body_solver(fe)
    m = fe.mass_operator()
    free = solver.constrained((m @ solver.R).T)  # the flexible modes: M-orthogonal to the rigid ones
    lowest = np.sqrt(lowest_eigenpairs(lambda k, found: free.eigen(fe, k, m, found), n_modes=1)[0][0]) / (2 * np.pi)
    assert lowest > band
    assert body.frequencies_hz[0] >= lowest * (1 - 1e-9)
