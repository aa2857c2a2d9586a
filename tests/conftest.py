"""Shared fixtures: the study's gearbox and variant files."""

import dataclasses
from pathlib import Path

import pytest

from flexgear.spec import load_gearbox, load_variant

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = ROOT / "model_variants"


@pytest.fixture(scope="session")
def gearbox():
    return load_gearbox(VARIANTS / "gearbox.toml")


@pytest.fixture(scope="session")
def model1():
    """Table 3's model 1 with the exact geometry's mass properties: no meshes needed for rigid tests."""
    return dataclasses.replace(load_variant(VARIANTS / "model1.toml"), rigid_mass_properties="exact")
