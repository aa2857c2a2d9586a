"""Modal analysis of model 1 (all rigid) at its operating point: against the lumped model, and cyclic symmetry.

(a) The linearised multibody model against the lumped model's modal analysis (flexgear.lumped.modal) with the same
law (ISO 6336, mean stiffness), supports and mass properties:

- planar: with axial motion and tilts held, the multibody model is the lumped model's planar translational-torsional
  model exactly, if the lumped members carry the gear-and-shaft mass and the seat bearing's radial stiffness;
- 3D: the modes whose kinetic energy is in-plane (rotational and planet modes) equal the lumped model's. Its
  translational modes do not: the lumped model condenses a central member's tilt statically onto its bearing
  (flexgear.lumped.model.LumpedParameters.from_spec: apparent mass, bearing compliance 1/k_r + L^2/k_t) and leaves
  out the tilt stiffness of the double-helical meshes (the two halves' forces act at +-z), which holds the sun's
  tilt in the multibody model; there its in-plane translation always moves the tilts.

(b) Cyclic symmetry (Lin & Parker 1999; Eritenel & Parker 2009): planet modes in pairs (N - 3 = 2) with the central
members at rest, translational modes in pairs at zero speed, single planet modes with four planets.
"""

import dataclasses

import numpy as np
import pytest

from flexgear.modal import linearize, modes
from flexgear.modal.eigenmodes import CENTRAL

F_MAX = 10e3  # Hz
IN_PLANE = ("u_x", "u_y", "phi_z")


def _iso(variant):
    """The variant on the ISO 6336 law (the lumped model's law with it, flexgear.lumped.model)."""
    return dataclasses.replace(variant, gearbox=variant.gearbox.with_fields("contact", law="iso6336"))


@pytest.fixture(scope="module")
def iso_model(model1):
    return linearize(_iso(model1), speed_rpm=0.0)


def _lumped(spec, planar: bool):
    """The lumped model's modes; ``planar``: members with the true mass and the seat's radial stiffness."""
    from flexgear.geometry.layout import component_mass_properties
    from flexgear.lumped.modal import modal_analysis
    from flexgear.lumped.model import LumpedParameters, MemberParameters

    params = LumpedParameters.from_spec(spec, hold_input=True)
    if not planar:
        return modal_analysis(params)

    def member(old: MemberParameters, parts: tuple[str, ...], k: float) -> MemberParameters:
        mass = sum(component_mass_properties(spec, p).mass for p in parts)
        return dataclasses.replace(old, mass_kg=mass, bearing_stiffness_n_per_m=k,
                                   bearing_damping_n_s_per_m=0.0)

    b = spec.bearings
    params = dataclasses.replace(
        params, sun=member(params.sun, ("sun", "input_shaft"), b.input_shaft.radial_stiffness_n_per_m),
        ring=member(params.ring, ("ring", "output_shaft"), b.output_shaft.radial_stiffness_n_per_m),
        planet=member(params.planet, ("planet",), b.planet.radial_stiffness_n_per_m))
    return modal_analysis(params)


def test_planar_model_equals_lumped(iso_model):
    m = modes(iso_model.in_plane().undamped(), F_MAX)
    lumped = _lumped(iso_model.variant.gearbox, planar=True)
    f_l = lumped.frequencies_hz[lumped.frequencies_hz <= F_MAX]
    assert len(m) == len(f_l)
    np.testing.assert_allclose(m.frequencies_hz, f_l, rtol=0.01)
    assert list(m.kinds) == list(np.asarray(lumped.kinds)[lumped.frequencies_hz <= F_MAX])


def test_in_plane_modes_equal_lumped(iso_model):
    m = modes(iso_model.undamped(), F_MAX)
    lumped = _lumped(iso_model.variant.gearbox, planar=False)
    in_plane = m.kinetic_share(lambda c: c.kind == "frame" and c.name in IN_PLANE) > 1 - 1e-6
    matched = set()
    for f, kind in zip(m.frequencies_hz[in_plane], np.asarray(m.kinds)[in_plane], strict=True):
        distance = np.abs(lumped.frequencies_hz - f)
        distance[list(matched)] = np.inf  # each lumped mode once (the planet pairs)
        j = int(np.argmin(distance))
        assert lumped.frequencies_hz[j] == pytest.approx(f, rel=0.01)
        assert lumped.kinds[j] == kind
        matched.add(j)
    # every lumped rotational and planet mode below F_MAX is one of them
    expected = {j for j, (f, k) in enumerate(zip(lumped.frequencies_hz, lumped.kinds, strict=True))
                if f <= F_MAX and k in ("rotational", "planet")}
    assert expected <= matched
    # the 3D model's translational modes all move the tilts (module docstring)
    translational = np.array([k == "translational" for k in m.kinds])
    assert translational.any() and not np.any(in_plane & translational)


@pytest.mark.parametrize("speed_rpm", [0.0, None])
def test_planet_modes_in_pairs_central_members_at_rest(model1, speed_rpm):
    m = modes(linearize(model1, speed_rpm=speed_rpm))
    planet = np.flatnonzero([k == "planet" for k in m.kinds])
    n = model1.gearbox.gears.planet_count
    assert planet.size > 0 and planet.size % (n - 3) == 0
    central = m.energy[[f"kinetic_{c}" for c in CENTRAL if f"kinetic_{c}" in m.energy]].to_numpy().sum(axis=1)
    assert np.all(central[planet] < 1e-6)
    f = m.frequencies_hz[planet].reshape(-1, n - 3)
    np.testing.assert_allclose(f[:, 1:], f[:, :1], rtol=1e-4)
    assert np.all(np.abs(np.diff(f[:, 0])) / f[1:, 0] > 1e-3)  # distinct pairs
    shares = m.energy.filter(regex="^kinetic_").to_numpy()
    np.testing.assert_allclose(shares.sum(axis=1), 1.0, atol=1e-9)
    np.testing.assert_allclose(m.energy.filter(regex="^strain_").to_numpy().sum(axis=1), 1.0, atol=1e-9)


def test_translational_modes_in_pairs_at_zero_speed(model1):
    m = modes(linearize(model1, speed_rpm=0.0))
    f = m.frequencies_hz[[k == "translational" for k in m.kinds]]
    assert f.size > 0 and f.size % 2 == 0
    np.testing.assert_allclose(f[1::2], f[0::2], rtol=1e-4)
    assert "mixed" not in m.kinds


def test_four_planets_single_planet_modes(model1):
    g = model1.gearbox
    four = dataclasses.replace(model1, gearbox=g.with_fields("gears", planet_count=4))
    m = modes(linearize(four, speed_rpm=0.0))
    f = m.frequencies_hz[[k == "planet" for k in m.kinds]]
    assert f.size > 0
    assert np.all(np.diff(f) / f[1:] > 1e-3)  # multiplicity N - 3 = 1
    assert set(m.kinds) <= {"planet", "rotational", "translational"}


def test_operating_point_and_impact_law_tangent(model1):
    """Zero speed (no friction): each helix half carries half the theoretical mesh force F_n = T_sun / (N r_b
    cos beta_b) at its static deflection, F = k_h delta^1.5, and enters with its tangent 1.5 k_h delta^0.5."""
    from flexgear.theory import theory

    lm = linearize(model1, speed_rpm=0.0)
    law = model1.gearbox.contact
    k_half = 0.5 * law.stiffness
    rows = [i for i, c in enumerate(lm.full_coordinates) if c.kind == "deflection"]
    assert len(rows) == len(lm.static_deflections) == 4 * model1.gearbox.gears.planet_count
    delta = np.array(list(lm.static_deflections.values()))
    force = k_half * delta.reshape(-1, 2) ** law.exponent  # (mesh, half)
    # measured 3.3e-6 (outer and inner meshes 7.5e-7 apart: the 3D model's arms, not exactly r_b cos beta_b)
    np.testing.assert_allclose(force.sum(axis=1), theory(model1.gearbox).mesh_force, rtol=1e-5)
    np.testing.assert_allclose(np.diag(lm.full_stiffness)[rows], law.exponent * k_half * delta ** (law.exponent - 1),
                               rtol=1e-5)


def test_state_space_roots_of_damped_oscillators():
    """Two uncoupled oscillators m x'' + c x' + k x = 0: the roots -zeta omega +- i omega sqrt(1 - zeta^2), omega =
    sqrt(k / m), zeta = c / (2 sqrt(k m)); each right vector (phi, lambda phi)."""
    from flexgear.modal.eigenmodes import state_space_roots

    m, c, k = np.diag([2.0, 0.5]), np.diag([40.0, 3.0]), np.diag([2.0e6, 8.0e5])
    lam, vec = state_space_roots(m, c, k)
    omega = np.sqrt(np.diag(k) / np.diag(m))
    zeta = np.diag(c) / (2.0 * np.sqrt(np.diag(k) * np.diag(m)))
    expected = np.concatenate([-zeta * omega + 1j * omega * np.sqrt(1 - zeta**2),
                               -zeta * omega - 1j * omega * np.sqrt(1 - zeta**2)])
    assert np.sort_complex(lam) == pytest.approx(np.sort_complex(expected), rel=1e-12)
    assert np.allclose(vec[2:], vec[:2] * lam, rtol=1e-10, atol=1e-12 * np.abs(vec).max())
