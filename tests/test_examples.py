"""Every example runs briefly and meets hand-calculated theory (speed ratio, static mesh force).

Theory is computed here from the involute relations, independently of the examples and the package:
r_b = m_n z cos(alpha_t) / (2 cos beta), tan(alpha_t) = tan(alpha_n) / cos(beta),
sin(beta_b) = sin(beta) cos(alpha_n); normal mesh force F = T / (N r_b cos(beta_b)) for the torque T on
a gear with base radius r_b shared by N meshes. Tooth friction (mu = 0.02) shifts the mean forces by a few
tenths of a percent, hence 1 % on forces.
"""

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import flexgear as fg

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _example(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _base_radius_cos_beta_b(z: int, normal_module: float, helix_deg: float, pressure_deg: float) -> float:
    """r_b cos(beta_b) [m]."""
    beta, alpha_n = math.radians(helix_deg), math.radians(pressure_deg)
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    r_b = normal_module * z * math.cos(alpha_t) / (2 * math.cos(beta))
    return r_b * math.cos(math.asin(math.sin(beta) * math.cos(alpha_n)))


def test_helical_pair_with_flexible_wheel():
    ex = _example("helical_pair_flexible")
    s, _ = ex.main(t_end=0.1)
    late = s[s.time_s >= 0.07]
    assert late.ratio.mean() == pytest.approx(-ex.Z_PINION / ex.Z_WHEEL, rel=1e-5)
    force = ex.LOAD_TORQUE_NM / _base_radius_cos_beta_b(ex.Z_WHEEL, ex.MODULE_M, ex.HELIX_DEG, ex.PRESSURE_DEG)
    assert late.mesh_force_n.mean() == pytest.approx(force, rel=0.01)
    # power balance: the drive supplies the load's power plus a small friction loss (< 1 %)
    loss = late.input_torque_nm.mean() / (ex.LOAD_TORQUE_NM * ex.Z_PINION / ex.Z_WHEEL) - 1
    assert 0.0 < loss < 0.01


def test_planetary_stage_with_rotating_carrier():
    ex = _example("planetary_stage")
    s, _ = ex.main(t_end=0.15)
    late = s[s.time_s >= 0.11]
    ratio = ex.Z_SUN / (ex.Z_SUN + ex.Z_RING)  # ring fixed, carrier output: 24 / 108
    assert late.ratio.mean() == pytest.approx(ratio, rel=1e-5)
    force = ex.LOAD_TORQUE_NM * ratio / (ex.N_PLANETS * _base_radius_cos_beta_b(ex.Z_SUN, 2e-3, 20.0, 20.0))
    forces = np.array([[late[f"{m}{i}_force_n"].mean() for i in range(1, ex.N_PLANETS + 1)]
                       for m in ("sun_planet", "planet_ring")])
    assert forces == pytest.approx(np.full_like(forces, force), rel=0.01)
    assert np.ptp(forces, axis=1).max() < 1e-3 * force  # equal load sharing


def test_gtf_star_gearbox_with_four_planets():
    ex = _example("gtf_four_planets")
    result = ex.main(planets=4, t_end=0.25)
    late = result.signals[result.signals.time_s >= 0.2]
    assert late.transmission_ratio.mean() == pytest.approx(-44 / 136, rel=1e-5)
    force = 557.025 * 44 / 136 / (4 * _base_radius_cos_beta_b(44, 2.12e-3, 25.0, 14.5))  # 997.8 N
    for kind in ("outer", "inner"):
        for i in range(1, 5):
            assert late[f"{kind}_mesh_force_{i}_n"].mean() == pytest.approx(force, rel=0.01)


def test_pair_geometry_reproduces_the_gtf_gear_set(gearbox):
    geo = fg.gear_set_geometry(gearbox)
    g, a = gearbox.gears, gearbox.gears_assumed
    common = dict(normal_module=g.normal_module_m, helix_angle=g.helix_angle_rad,
                  pressure_angle=g.normal_pressure_angle_rad, face_width=a.face_width_m,
                  normal_backlash=a.normal_backlash_m)
    sp = fg.gear_pair_geometry(44, 45, shifts=(geo.sun.shift, geo.planet.shift), **common)
    pr = fg.gear_pair_geometry(45, 136, internal=True, centre_distance=geo.centre_distance,
                               shifts=(geo.planet.shift, 0.0), **common)
    assert sp.centre_distance == pytest.approx(geo.centre_distance, rel=1e-12)
    assert sp.operating_pressure_angle == pytest.approx(geo.sun_planet.operating_pressure_angle, rel=1e-12)
    assert pr.gear2.shift == pytest.approx(geo.ring.shift, rel=1e-12)
    assert pr.transverse_contact_ratio == pytest.approx(geo.planet_ring.transverse_contact_ratio, rel=1e-12)
    with pytest.raises(ValueError, match="centre distance"):
        fg.pair_contacts("m", "a", "b", sp, np.zeros(3), [0.1, 0.0, 0.0], gearbox.contact, gearbox.contact_assumed)


def test_carrier_rotation_leaves_the_mesh_unloaded():
    """A rigid rotation of the whole stage by eps (gears, carrier, planet orbit) does not deflect the mesh,
    to first order whatever the carrier angle the update uses; the rolling motion of the stage neither."""
    from flexgear.geometry.massprops import MassProperties
    from flexgear.mbs.carrier import Carrier, CarrierKinematics

    mesh = fg.gear_pair_geometry(24, 30, 2e-3, math.radians(20), math.radians(20), 0.03)
    ring = fg.gear_pair_geometry(30, 84, 2e-3, math.radians(20), math.radians(20), 0.03, internal=True)
    a = mesh.centre_distance
    props = MassProperties(1.0, np.zeros(3), np.eye(3))
    bodies = [fg.Body(n, 0, 0, 0, 0, np.asarray(p, float), props)
              for n, p in (("sun", [0, 0, 0]), ("ring", [0, 0, 0]), ("carrier", [0, 0, 0]), ("planet", [a, 0, 0]))]
    c = fg.load_gearbox(Path(__file__).resolve().parents[1] / "model_variants" / "gearbox.toml")
    contacts = (fg.pair_contacts("sp", "sun", "planet", mesh, [0, 0, 0], [a, 0, 0], c.contact, c.contact_assumed)
                + fg.pair_contacts("pr", "planet", "ring", ring, [a, 0, 0], [0, 0, 0], c.contact, c.contact_assumed,
                                   hand=-1, drive_sign=-1.0))
    rows = np.zeros((2, 24))
    for i, ct in enumerate(contacts):
        k1, k2 = [b.name for b in bodies].index(ct.body1), [b.name for b in bodies].index(ct.body2)
        rows[i, 6 * k1:6 * k1 + 6] += ct.gradient1[0]
        rows[i, 6 * k2:6 * k2 + 6] += ct.gradient2[0]
    ratio = 24 / 108
    kin = CarrierKinematics(0, rows, bodies, Carrier("carrier", ratio), ramp_time=1.0, drive_speed=1.0)

    def state(theta_sun: float, eps: float = 0.0) -> np.ndarray:
        """Nominal rolling state at sun angle theta_sun, then the whole stage turned by eps."""
        theta_c = ratio * theta_sun + eps
        planet = ratio * theta_sun - 24 / 30 * (1 - ratio) * theta_sun + eps
        x_p = a * np.array([math.cos(theta_c), math.sin(theta_c), 0.0])
        return np.concatenate([[0, 0, 0, 0, 0, theta_sun + eps], [0, 0, 0, 0, 0, eps],
                               [0, 0, 0, 0, 0, theta_c], [*x_p, 0, 0, planet]])

    for t in (0.0, 1.3, 2.0):  # drive angle t^3 (1 - t/2) during the ramp, t - 1/2 after it
        theta_sun = float(fg.drive_angle(t, 1.0, 1.0))
        g, offset = kin.matrix_and_offset(t)
        assert np.abs(g @ state(theta_sun) - offset).max() < 1e-12
        for eps in (1e-4, 1e-3):  # lag or wind-up of the carrier: second order only, a eps^2
            assert np.abs(g @ state(theta_sun, eps) - offset).max() < a * eps**2
