"""The gearbox's design (flexgear.design): made once per spec content, equal to what the geometry stage gives."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from flexgear.design import as_design, design
from flexgear.geometry.involute import gear_set_geometry
from flexgear.geometry.layout import component_layout, component_mass_properties
from flexgear.geometry.supports import gearbox_supports
from flexgear.spec import GEOMETRY_COMPONENTS
from flexgear.theory import theory


def test_design_holds_what_the_geometry_stage_derives(gearbox):
    d = design(gearbox)
    assert d.spec is gearbox
    assert d.gears == gear_set_geometry(gearbox)
    assert d.theory == theory(gearbox)
    supports = gearbox_supports(gearbox)
    assert d.supports.keys() == supports.keys()
    for name, bearing in supports.items():
        mine = d.supports[name]
        assert mine.interface == bearing.interface and np.array_equal(mine.centre, bearing.centre)
        assert np.array_equal(mine.stiffness, bearing.stiffness)
    for component in GEOMETRY_COMPONENTS:
        assert d.layout(component) == component_layout(gearbox, component)
        mine, theirs = d.mass_properties(component), component_mass_properties(gearbox, component)
        assert mine.mass == theirs.mass and np.array_equal(mine.inertia, theirs.inertia)


def test_design_is_made_once_per_spec_content(gearbox):
    d = design(gearbox)
    assert design(gearbox) is d and as_design(d) is d and as_design(gearbox) is d
    moved = dataclasses.replace(gearbox, source=Path("elsewhere.toml"))  # same content, another file
    other = design(moved)
    assert other.spec is moved and other.gears is d.gears and other.theory is d.theory
    changed = gearbox.with_fields("load_case", input_speed_rpm=2 * gearbox.load_case.input_speed_rpm)
    assert design(changed).theory.mesh_frequency == 2 * d.theory.mesh_frequency
