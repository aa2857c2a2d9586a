"""Public names that moved: each old name stays a deprecated alias of its new one until the version that removes
it. A module lists its moved names in a ``_DEPRECATED`` table, one line each (old name -> (new name in
``flexgear``, removal version)), and answers them from its PEP 562 ``__getattr__`` through :func:`moved`."""

from __future__ import annotations

import sys
import warnings

__all__ = ["moved"]


def moved(module: str, old: str, new: str, removal: str) -> object:
    """The object ``<new>`` (a dotted path, e.g. ``"BearingElement.axisymmetric"``, looked up in the calling module
    ``module``, which has it: flexgear's public name) that the old name ``<module>.<old>`` stands for, with a
    :class:`DeprecationWarning` naming the new name and the version ``removal`` that drops the old one. Called from
    a module's ``__getattr__``: the warning points at the line that used the old name."""
    warnings.warn(f"{module}.{old} is deprecated and will be removed in flexgear {removal}: use flexgear.{new}",
                  DeprecationWarning, stacklevel=3)
    value: object = sys.modules[module]
    for part in new.split("."):
        value = getattr(value, part)
    return value
