"""Modes of the planetary stage (ring fixed, carrier output) at rest: the linearised multibody model against the
lumped model's modal analysis (flexgear.lumped.modal, Lin & Parker 1999 with the carrier's equations), and the
refusal at speed.

With axial motion and tilts held, the multibody model of examples/spur_planetary (every component rigid, the exact
geometry's mass properties, the ISO 6336 law at its mean stiffness) is the lumped model's planar
translational-torsional model exactly, when the lumped members carry the true in-plane masses (sun + input shaft;
carrier + output shaft) and their seat bearings' radial stiffness (the lumped model condenses the tilt onto the
bearing, which the held tilts make exact at the seat's stiffness). The sun's spin is held in both (the drive).
"""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import flexgear as fg
from flexgear.design import as_design
from flexgear.modal import linearize, modes
from flexgear.spec import SpecError

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "spur_planetary"
F_MAX = 10e3  # Hz


@pytest.fixture(scope="module")
def variant():
    v = fg.load_variant(EXAMPLE / "rigid.toml")
    assert v.gearbox.gears.arrangement == "planetary" and v.gearbox.contact.law == "iso6336"
    return v


def _planar_lumped(spec):
    """The lumped model's modes with the members' true in-plane masses and their seats' radial stiffness."""
    from flexgear.lumped.modal import modal_analysis
    from flexgear.lumped.model import LumpedParameters

    masses = as_design(spec).masses
    b = spec.bearings
    p = LumpedParameters.from_spec(spec, hold_input=True)
    carrier_mass = spec.lumped_assumed.carrier_mass_kg + masses["output_shaft"].mass
    p = dataclasses.replace(
        p,
        sun=dataclasses.replace(p.sun, mass_kg=masses["sun"].mass + masses["input_shaft"].mass,
                                bearing_stiffness_n_per_m=b.input_shaft.radial_stiffness_n_per_m,
                                bearing_damping_n_s_per_m=0.0),
        carrier=dataclasses.replace(p.carrier, mass_kg=carrier_mass,
                                    bearing_stiffness_n_per_m=b.output_shaft.radial_stiffness_n_per_m,
                                    bearing_damping_n_s_per_m=0.0),
        planet=dataclasses.replace(p.planet, bearing_stiffness_n_per_m=b.planet.radial_stiffness_n_per_m,
                                   bearing_damping_n_s_per_m=0.0))
    return modal_analysis(p)


def test_planar_planetary_modes_equal_the_lumped_model_with_its_carrier(variant):
    """Every planar mode below 10 kHz: frequency within 1 % of the lumped model's and of the same kind (rotational,
    translational in pairs, planet); the turning carrier takes part in the rotational and translational modes."""
    model = linearize(variant, speed_rpm=0.0)
    m = modes(model.in_plane().undamped(), F_MAX)
    lumped = _planar_lumped(variant.gearbox)
    keep = lumped.frequencies_hz <= F_MAX
    f_l = lumped.frequencies_hz[keep]
    assert len(m) == len(f_l) >= 8
    np.testing.assert_allclose(m.frequencies_hz, f_l, rtol=0.01)
    planets = m.energy[[f"kinetic_planet_{i + 1}" for i in range(variant.gearbox.gears.planet_count)]].to_numpy()
    for j, (kind, expected) in enumerate(zip(m.kinds, np.asarray(lumped.kinds)[keep], strict=True)):
        if kind == "planet" and expected == "rotational":
            # rotational symmetry (every planet moves alike) with the central members at rest: the sun's spin
            # held, the ring fixed and no net torque on the carrier. The lumped model names a mode by its planets'
            # phase pattern, the multibody model by the central members' energy: the same mode
            np.testing.assert_allclose(planets[j], planets[j].mean(), rtol=1e-6)
        else:
            assert kind == expected, (j, m.frequencies_hz[j])
    carrier = m.energy["kinetic_carrier"].to_numpy()
    rotational = np.array([k == "rotational" for k in m.kinds])
    assert rotational.any() and carrier[rotational].max() > 0.1


def test_modes_at_speed_of_the_planetary_stage_are_refused_in_one_line(variant):
    with pytest.raises(SpecError) as err:
        linearize(variant)
    assert err.value.field == "gears.arrangement" and "\n" not in str(err.value)
