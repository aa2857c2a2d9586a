"""Cache folder, content hashes and atomic writes: the one home of every cached stage's file handling."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["cache_dir", "atomic_write_bytes"]


def cache_dir() -> Path:
    """Cache folder: ``$FLEXGEAR_CACHE_DIR`` or ``meshes/`` of the project (created on demand)."""
    path = Path(os.environ.get("FLEXGEAR_CACHE_DIR", Path(__file__).resolve().parents[1] / "meshes"))
    path.mkdir(parents=True, exist_ok=True)
    return path


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
