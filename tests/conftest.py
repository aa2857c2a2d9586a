"""Shared fixtures: the study's gearbox and variant files.

``make test`` runs the suite in two pytest-xdist worker processes (``-n 2 --dist loadscope``: the tests of a
module go to one worker, so that a module-scoped fixture, a simulation run or an FE model, is built once).
The mesh cache (``meshes/`` or ``$FLEXGEAR_CACHE_DIR``) is shared by the workers: a missing mesh or reduced
body is built by the first worker that needs it while the other waits for it (flexgear.cache.load_or_build).
"""

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
