"""Where a component's solid comes from: the cached BREP of a solid (the project's own or a file's), and the
reader of the user's parts (``[components_geometry]``) that flexgear.fe.imported registers, so that the meshing
(flexgear.fe.mesh) needs no import of it."""

from __future__ import annotations

import os
import time
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

from flexgear.cache import check_digest, load_or_build, record_digest
from flexgear.progress import say

__all__ = ["cached_brep", "private_temporary", "register_file_parts", "file_parts", "FileParts"]


def say_if(progress: bool, text: str) -> None:
    if progress:
        say(text)


def private_temporary(path: Path, suffix: str) -> Path:
    """A temporary name next to ``path``, unique to this process and call (two workers building the same
    cache entry must not write into one file), ending in ``suffix`` (the writers choose the format by it)."""
    return path.with_name(f".{path.name}.{os.getpid()}-{uuid.uuid4().hex[:8]}.tmp{suffix}")


def cached_brep(path: Path, make_solid: Callable[[], object], label: str, progress: bool = False) -> Path:
    """The cached OCC solid at ``path`` (``.brep``), checked against its digest; on a cache miss (or a file that
    does not match its digest) ``make_solid()`` gives the solid, written atomically with its digest. ``label``
    opens the progress line ("ring: solid built")."""

    def load() -> Path | None:
        if not path.exists():
            return None
        check_digest(path)
        return path

    def build() -> Path:
        t0 = time.perf_counter()
        shape = make_solid()
        tmp = private_temporary(path, ".brep")
        shape.WriteBrep(str(tmp))
        tmp.replace(path)
        record_digest(path)
        say_if(progress, f"  {label} in {time.perf_counter() - t0:.1f} s")
        return path

    return load_or_build(path, load, build)


FileParts = tuple[Callable[..., Path], Callable[..., Any]]
_FILE_PARTS: list[FileParts] = []


def register_file_parts(brep: Callable[..., Path], mesh: Callable[..., Any]) -> None:
    """How a ``[components_geometry]`` part is read: ``brep(design, component, progress)`` its solid,
    ``mesh(design, component, level, order, progress)`` its mesh (flexgear.fe.imported registers them when the
    flexgear.fe package is imported)."""
    _FILE_PARTS[:] = [(brep, mesh)]


def file_parts() -> FileParts:
    """The registered (solid, mesh) readers of ``[components_geometry]`` parts."""
    if not _FILE_PARTS:
        raise RuntimeError("no reader of [components_geometry] parts is registered (import flexgear.fe.imported)")
    return _FILE_PARTS[0]
