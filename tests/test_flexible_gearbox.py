"""Flexible gears in the gearbox: the contact takes the gear's elastic deflection at the mesh point.

Model 4 of Table 3 (sun and ring flexible, the study's selected model) with stand-in annulus bodies
(tests/standins.py), on a shortened load case: ramps over 0.02 s, 0.1 s simulated.
"""

import dataclasses

import numpy as np
import pytest
from conftest import VARIANTS
from standins import annulus_source, standin_frames

from flexgear.mbs.contact_kinematics import modal_contact_coefficients
from flexgear.mbs.run import run_variant
from flexgear.spec import load_variant


@pytest.fixture(scope="module")
def flex_run():
    v = load_variant(VARIANTS / "model4.toml")
    g = v.gearbox
    g = g.with_changes(load_case=dataclasses.replace(g.load_case, ramp_time_s=0.02, end_time_s=0.1))
    result = run_variant(dataclasses.replace(v, gearbox=standin_frames(g)), reduced_source=annulus_source)
    assert result.ok, result.meta.get("reason")
    return result


def test_flexible_model4_runs_at_theory(flex_run):
    s = flex_run.signals
    w = s[s.time_s >= 0.08]
    th = flex_run.meta["theory"]
    assert w.input_speed_rad_per_s.mean() == pytest.approx(np.radians(36000.0), rel=1e-9)  # 6000 rpm, Table 5
    assert w.output_speed_rad_per_s.mean() == pytest.approx(th["output_speed_rad_per_s"], rel=2e-4)
    for kind in ("outer", "inner"):
        mean = np.mean([w[f"{kind}_mesh_force_{i}_n"].mean() for i in range(1, 6)])
        # within 1 % of the rigid-gear value (friction shifts both meshes by < 0.2 %)
        assert mean == pytest.approx(th["mesh_force_n"], rel=0.01)


def test_elastic_share_is_reported_and_physical(flex_run):
    # The study's contact law (k = 1e8 N/m^1.5) penetrates 0.4 mm at 798 N, far more than a ring rim
    # deflects under one planet: the ring yields (positive share) but takes only a small part.
    inner = flex_run.meta["elastic_share_inner"]
    assert 0.0 < inner < 0.05
    assert abs(flex_run.meta["elastic_share_outer"]) < 0.01


def test_modal_coefficients_of_a_rigid_translation_mode():
    # a "mode" that translates every node along x: c(alpha) = n_b(alpha) . e_x = cos(alpha - psi) n_x - ...
    nodes = np.array([[0.05 * np.cos(a), 0.05 * np.sin(a), z] for a in np.linspace(0, 2 * np.pi, 90, endpoint=False)
                      for z in (-0.01, 0.0, 0.01)])
    modes = np.zeros((3 * len(nodes), 1))
    modes[0::3, 0] = 1.0
    normal = np.array([0.3, 0.9, 0.3]) / np.linalg.norm([0.3, 0.9, 0.3])
    psi = 0.7
    c = modal_contact_coefficients(nodes, modes, 0.05 * np.array([np.cos(psi), np.sin(psi), 0.0]), normal,
                                   0.02, 0.002, 4, n_grid=360)
    alpha = 2 * np.pi * np.arange(360) / 360
    expected = np.cos(alpha - psi) * normal[0] - np.sin(alpha - psi) * normal[1]
    assert np.max(np.abs(c[:, 0] - expected)) < 1e-10


def test_gear_shaft_joints_carry_the_shaft_torques(flex_run):
    """Model 4: the flexible sun and ring are joined to their rigid shafts at the interfaces; the drive
    and the load act on the shafts, so the sun-shaft joint carries the input torque and the
    ring-output shaft joint the load torque (Table 5), about the axis."""
    th = flex_run.meta["theory"]
    s = flex_run.signals
    drive = s[s.time_s >= 0.08].input_torque_nm.mean()  # includes the tooth-friction loss
    assert abs(flex_run.meta["joint_torque_sun_nm"]) == pytest.approx(abs(drive), rel=5e-3)
    assert abs(drive) == pytest.approx(th["input_torque_nm"], rel=5e-3)
    assert abs(flex_run.meta["joint_torque_ring_nm"]) == pytest.approx(th["output_torque_nm"], rel=5e-3)


def test_rigid_and_flexible_twins_carry_identical_mass_properties():
    """The rigid/flexible twin rule: a component has the same mass, centre of mass and inertia in either form. With
    rigid_mass_properties = "mesh" the rigid planet takes the reduced body's (FE) mass properties."""
    import exudyn as exu
    from exudyn.rigidBodyUtilities import Inertia6D2InertiaTensor

    from flexgear.mbs.gearbox import build_star_gearbox

    v = load_variant(VARIANTS / "model2.toml")  # flexible planets
    props = {}
    for form in ("rigid", "flexible"):
        sc = exu.SystemContainer()
        mbs = sc.AddSystem()
        # the reference formulation's objects carry their mass properties as parameters
        gearbox = v.gearbox.with_fields("solver_assumed", formulation="reference")
        variant = dataclasses.replace(v, components={**v.components, "planets": form}, gearbox=gearbox)
        assert variant.rigid_mass_properties == "mesh"
        planet = build_star_gearbox(mbs, variant, reduced_source=annulus_source).bodies["planet1"]
        mass, com, inertia = (np.asarray(mbs.GetObjectParameter(planet.obj, k)) for k in ("mass", "centerOfMass",
                                                                                          "inertia"))
        # inertia about the frame origin: Exudyn's 6-vector of an ObjectRigidBody, the 3x3 tensor of an
        # ObjectFFRFreducedOrder
        props[form] = mass, com, Inertia6D2InertiaTensor(inertia) if inertia.shape == (6,) else inertia
    (m_r, c_r, j_r), (m_f, c_f, j_f) = props["rigid"], props["flexible"]
    assert m_f == pytest.approx(m_r, rel=1e-12)
    assert np.abs(c_f - c_r).max() < 1e-12
    assert np.abs(j_f - j_r).max() < 1e-9 * np.abs(j_r).max()


def test_rigid_twins_read_the_cached_bodies_mass_properties():
    """With the project's own (cached) reduced bodies a rigid component reads only its body's mass properties
    from the cache file (no modes loaded): the same numbers as the whole body's, and the rigid planet of model 1
    carries them."""
    import exudyn as exu

    from flexgear.fe.reduced import component_mass_properties, component_reduced_body
    from flexgear.mbs.gearbox import build_star_gearbox

    v = load_variant(VARIANTS / "model1.toml")
    assert v.rigid_mass_properties == "mesh"
    whole = component_reduced_body(v.gearbox, "planets", v.mesh_level).props
    alone = component_mass_properties(v.gearbox, "planets", v.mesh_level)
    assert alone.mass == whole.mass and np.array_equal(alone.com, whole.com)
    assert np.array_equal(alone.inertia, whole.inertia)
    mbs = exu.SystemContainer().AddSystem()
    planet = build_star_gearbox(mbs, v).bodies["planet1"]
    assert not planet.flexible and planet.props.mass == pytest.approx(whole.mass, rel=1e-12)
    assert np.abs(planet.props.inertia - whole.inertia).max() <= 1e-12 * np.abs(whole.inertia).max()




def test_a_rigid_twin_without_its_body_takes_the_fe_meshs_mass_properties(tmp_path, monkeypatch):
    """Without a cached reduced body a rigid component's mass properties come from its FE model's mass matrix
    alone (no reduction is run, no body file written): the very numbers the body carries once it is built, and
    within the mesh's geometric error (1e-3) of the exact section integrals."""
    from flexgear.fe.reduced import component_mass_properties, component_reduced_body, reduced_cache_path
    from flexgear.geometry.layout import exact_mass_properties

    monkeypatch.setenv("FLEXGEAR_CACHE_DIR", str(tmp_path))
    g = load_variant(VARIANTS / "model1.toml").gearbox
    alone = component_mass_properties(g, "input_shaft", "coarse")
    assert not list(tmp_path.glob(reduced_cache_path("*").name)) and list(tmp_path.glob("massprops-mesh-*.npz"))
    assert alone.mass == pytest.approx(exact_mass_properties(g, "input_shaft").mass, rel=1e-3)
    whole = component_reduced_body(g, "input_shaft", "coarse").props
    assert alone.mass == pytest.approx(whole.mass, rel=1e-12)
    assert np.abs(alone.com - whole.com).max() < 1e-12
    assert np.abs(alone.inertia - whole.inertia).max() <= 1e-12 * np.abs(whole.inertia).max()
    assert component_mass_properties(g, "input_shaft", "coarse").mass == whole.mass  # the body's, once built
