"""Cache folder, content hashes and atomic writes: the one home of every cached stage's file handling."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["cache_dir", "atomic_write_bytes", "remove_stale_temporaries"]

_UMASK = os.umask(0o022)
os.umask(_UMASK)
_FILE_MODE = 0o666 & ~_UMASK
"""Mode of the files written here: what open() gives under the process's umask (0644 under the usual 022);
mkstemp alone would give 0600, unreadable by others."""


def cache_dir() -> Path:
    """Cache folder: ``$FLEXGEAR_CACHE_DIR`` or ``meshes/`` of the project (created on demand)."""
    path = Path(os.environ.get("FLEXGEAR_CACHE_DIR", Path(__file__).resolve().parents[1] / "meshes"))
    path.mkdir(parents=True, exist_ok=True)
    return path


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a hidden temporary file in the same folder (``.<name>.*.tmp``),
    flushed to disk, and a rename: a reader, or a writer killed at any moment, never leaves a half-written
    ``path``. The file is readable by others (:data:`_FILE_MODE`); new folders get 0755 under umask 022."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, _FILE_MODE)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def remove_stale_temporaries(folder: str | Path) -> list[Path]:
    """Delete the temporary files (``.<name>.*.tmp``) that writers killed mid-write left in ``folder``
    and its subfolders; only for a folder no other process is writing to. Returns the deleted paths."""
    stale = [p for p in Path(folder).rglob(".*.tmp") if p.is_file()]
    for p in stale:
        p.unlink(missing_ok=True)
    return stale
