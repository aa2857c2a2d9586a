"""Shared fixtures: the study's gearbox and variant files."""

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
    return load_variant(VARIANTS / "model1.toml")
