"""Where a component's solid comes from: the cached BREP of a solid (the project's own or a file's), the solid's
exchange form (as a STEP file carries it), and the reader of the user's parts (``[components_geometry]``) that
flexgear.fe.imported registers, so that the meshing (flexgear.fe.mesh) needs no import of it."""

from __future__ import annotations

import contextlib
import os
import tempfile
import time
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from flexgear.cache import check_digest, load_or_build, record_digest
from flexgear.progress import say

__all__ = ["cached_brep", "private_temporary", "register_file_parts", "file_parts", "FileParts", "STEP_UNIT_MM",
           "write_step_mm", "exchange_form", "quiet_occ"]

STEP_UNIT_MM = 1e3
"""Millimetres per metre: STEP files are written in mm, the CAD convention."""


def say_if(progress: bool, text: str) -> None:
    if progress:
        say(text)


def private_temporary(path: Path, suffix: str) -> Path:
    """A temporary name next to ``path``, unique to this process and call (two workers building the same
    cache entry must not write into one file), ending in ``suffix`` (the writers choose the format by it)."""
    return path.with_name(f".{path.name}.{os.getpid()}-{uuid.uuid4().hex[:8]}.tmp{suffix}")


@contextlib.contextmanager
def quiet_occ() -> Iterator[None]:
    """OpenCascade's own messages (on the process's stdout and stderr) silenced: a refused file ends in one line."""
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)


def write_step_mm(shape, path: Path) -> Path:
    """The OCC ``shape`` (metres) as a STEP file in millimetres at ``path``, written atomically."""
    from netgen.occ import Pnt

    tmp = private_temporary(path, ".step")
    shape.Scale(Pnt(0, 0, 0), STEP_UNIT_MM).WriteStep(str(tmp))
    tmp.replace(path)
    return path


def exchange_form(solid, passes: int = 1):
    """``solid`` (metres) as a STEP file carries it: written in mm (:func:`write_step_mm`), read back and scaled to
    metres, as a ``[components_geometry]`` STEP part is read (flexgear.fe.imported.read_solid); ``passes`` times.

    OCC's STEP reader starts some faces' edge loops at another edge than the solid built in memory (the toothed
    loops of a gear's end faces), and Netgen meshes such a face differently. The exchange form keeps its loops
    through a further round trip: the project's solids are meshed in it, so that a solid exported by ``flexgear
    export-geometry`` and imported again is meshed as the built-in one. Where the reader then leaves every digit as
    it is (swept helical teeth; the carrier, made by Boolean cuts, after a second pass) the meshes are the same node
    for node; where it computes some edges' parameters anew at each read (extruded spur teeth, at round-off) they
    differ by the mesh's round-off variation. ValueError when the file does not hold exactly one solid."""
    from netgen.occ import OCCGeometry, Pnt

    for _ in range(passes):
        with tempfile.TemporaryDirectory(prefix="flexgear-exchange-") as folder:
            path = write_step_mm(solid, Path(folder) / "solid.step")
            with quiet_occ():
                solids = OCCGeometry(str(path)).shape.solids
        if len(solids) != 1:
            raise ValueError(f"the solid's STEP exchange form holds {len(solids)} solids, expected one")
        solid = solids[0].Scale(Pnt(0, 0, 0), 1.0 / STEP_UNIT_MM)
    return solid


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
