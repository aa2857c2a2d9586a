"""Modal analysis of a flexible variant (model 4: sun and ring flexible, coarse mesh) against model 1.

Model 1's rigid bodies carry the reduced bodies' mass properties (rigid_mass_properties = "mesh"), so model 1 is
model 4 with the flexible bodies' elastic coordinates held. Holding coordinates can only raise natural frequencies
(Rayleigh's theorem of constraint, for the undamped, non-gyroscopic problem at rest): every frequency of model 4
lies at or below the frequency of the same order of model 1. The ISO 6336 law keeps the mesh stiffness the same in
both (it does not depend on the static deflection, which the gears' compliance changes).
"""

import dataclasses

import numpy as np
import pytest
from conftest import VARIANTS

from flexgear.modal import linearize, modes
from flexgear.spec import load_variant


def _undamped_at_rest(name: str):
    v = load_variant(VARIANTS / f"{name}.toml")
    v = dataclasses.replace(v, gearbox=v.gearbox.with_fields("contact", law="iso6336"))
    return modes(linearize(v, speed_rpm=0.0).undamped())


@pytest.mark.slow
def test_flexible_frequencies_interlace_below_rigid():
    rigid, flexible = _undamped_at_rest("model1"), _undamped_at_rest("model4")
    assert set(flexible.model.flexible) == {"sun", "ring"}
    n = len(rigid)
    assert len(flexible) > n
    assert np.all(flexible.frequencies_hz[:n] <= rigid.frequencies_hz * (1 + 1e-6))
    for family in ("kinetic", "strain"):
        np.testing.assert_allclose(flexible.energy.filter(regex=f"^{family}_").sum(axis=1), 1.0, atol=1e-8)
    assert "elastic_ring" in flexible.kinds
    elastic = flexible.energy["strain_ring_elastic"].to_numpy()
    ring_modes = np.array([k == "elastic_ring" for k in flexible.kinds])
    assert np.all(elastic[ring_modes] > 0.5)
