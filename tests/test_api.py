"""The public API: every name of ``flexgear.__all__`` resolves, moved names stay deprecated aliases until their
removal version."""

import warnings

import numpy as np
import pytest

import flexgear


@pytest.mark.parametrize("name", flexgear.__all__)
def test_every_public_name_resolves(name):
    assert getattr(flexgear, name) is not None
    assert name in dir(flexgear)


def test_bushing_is_a_deprecated_alias_of_the_axisymmetric_bearing_element():
    """flexgear 0.1's ``Bushing(body, k_r, k_a, k_t, damping_per_stiffness)`` was BearingElement.axisymmetric (git
    log -S Bushing): old scripts keep working, with a DeprecationWarning that names the new name, at their line."""
    message = r"flexgear\.Bushing .* flexgear 0\.3: use flexgear\.BearingElement\.axisymmetric"
    with pytest.warns(DeprecationWarning, match=message) as w:
        bushing = flexgear.Bushing
    assert w[0].filename == __file__
    assert bushing == flexgear.BearingElement.axisymmetric
    with pytest.warns(DeprecationWarning):
        old = flexgear.Bushing("pinion", 4e8, 2e7, 1e6, 1e-5)
    new = flexgear.BearingElement.axisymmetric("pinion", 4e8, 2e7, 1e6, 1e-5)
    assert isinstance(old, flexgear.BearingElement)
    assert old.body == new.body and np.array_equal(old.stiffness, new.stiffness)
    assert np.array_equal(old.damping, new.damping) and np.array_equal(old.centre, new.centre)
    with pytest.warns(DeprecationWarning, match=r"flexgear\.mbs\.elements\.Bushing"):
        from flexgear.mbs.elements import Bushing
    assert Bushing == flexgear.BearingElement.axisymmetric
    assert "Bushing" not in flexgear.__all__


def test_deprecated_names_resolve_and_go_in_a_later_version():
    """Each moved name's target exists, and its removal version lies ahead of this one (else remove the alias)."""
    from flexgear.mbs import elements

    def version(text: str) -> tuple[int, ...]:
        return tuple(int(p) for p in text.split("."))

    for module in (flexgear, elements):
        for old, (new, removal) in module._DEPRECATED.items():
            assert old not in getattr(module, "__all__", ()), old
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                getattr(module, old)
            assert [str(c.message) for c in caught] == [
                f"{module.__name__}.{old} is deprecated and will be removed in flexgear {removal}: use flexgear.{new}"]
            assert version(removal) > version(flexgear.__version__), (old, removal)


def test_unknown_names_still_raise():
    with pytest.raises(AttributeError, match="no attribute 'Bushings'"):
        flexgear.Bushings  # noqa: B018


def test_api_reference_is_current():
    """docs/api.md is what docs/gen_api.py writes from today's docstrings (regenerate: make api-docs)."""
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("gen_api", root / "docs" / "gen_api.py")
    gen_api = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen_api)
    text = gen_api.render()
    assert "0x" not in text and str(root) not in text
    assert (root / "docs" / "api.md").read_text() == text, "docs/api.md is not current: run python docs/gen_api.py"
