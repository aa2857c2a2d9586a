"""Field helpers of the schema: each field carries its check (range, integer, choices) in its metadata, applied
by :func:`flexgear.spec.load_gearbox`; :class:`SpecError` names the file, the field and what is allowed."""

from __future__ import annotations

import dataclasses
from dataclasses import field
from pathlib import Path
from typing import Any

__all__ = ["SpecError", "num_field", "numbers_field", "derived_field", "choice_field", "text_field"]


class SpecError(ValueError):
    """A specification file is wrong: the message names the file, the field and what is allowed."""

    def __init__(self, path: str | Path, fieldname: str, allowed: str, got: Any = None):
        self.path, self.field, self.allowed = str(path), fieldname, allowed
        got_text = "" if got is None else f", got {got!r}"
        super().__init__(f"{path}: field '{fieldname}': {allowed}{got_text}")


def num_field(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False,
              integer: bool = False, doc: str = "", default: Any = dataclasses.MISSING, derived: bool = False) -> Any:
    """Field with a numeric range check (validated on load); optional when ``default`` is given. ``derived``: a
    value left out of the file follows the gear data where :mod:`flexgear.sizing` gives one, else ``default``."""
    meta = {"lo": lo, "hi": hi, "lo_open": lo_open, "integer": integer, "doc": doc}
    return field(default=default, metadata={**meta, "derived": True} if derived else meta)


def numbers_field(lo: float | None = None, hi: float | None = None, *, hi_open: bool = False, doc: str = "") -> Any:
    """Optional field holding a list of numbers, each in [``lo``, ``hi``] (``hi`` excluded when ``hi_open``);
    left out, the empty tuple (validated on load, stored as a tuple of floats)."""
    return field(default=(), metadata={"lo": lo, "hi": hi, "hi_open": hi_open, "sequence": True, "doc": doc})


def derived_field(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False, doc: str = "") -> Any:
    """Numeric field that a gearbox file may leave out: its value then follows the gear data
    (:mod:`flexgear.sizing`, registered with :func:`flexgear.spec.register_derived_defaults`). Required when the
    dataclass is built in code."""
    return field(metadata={"lo": lo, "hi": hi, "lo_open": lo_open, "integer": False, "doc": doc, "derived": True})


def choice_field(*choices: str, doc: str = "", default: str | None = None) -> Any:
    """Field whose value is one of ``choices`` (validated on load); optional when ``default`` is given."""
    meta = {"choices": choices, "doc": doc}
    return field(metadata=meta) if default is None else field(default=default, metadata=meta)


def text_field(doc: str = "", default: str | None = None) -> Any:
    """Free-text field; optional when ``default`` is given."""
    if default is None:
        return field(metadata={"doc": doc})
    return field(default=default, metadata={"doc": doc})
