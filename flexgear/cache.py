"""Cache folder, content hashes, atomic writes, damaged-entry detection and the build-once lock: the one home
of every cached stage's file handling.

A cache entry is read through :func:`load_or_build`: an entry that cannot be read (truncated or overwritten by a
killed copy, a full disk, a network disk) is rebuilt with a one-line :class:`CacheWarning` naming the file, and
a missing or damaged entry is built under a lock file (``<path>.lock``, ``fcntl.flock``) so that processes that
need the same entry at once (matrix workers, pytest-xdist workers) build it once: the others wait for the lock
and then load the file the first one wrote. With ``$FLEXGEAR_BUILD_LOG`` set, every build appends one JSON line to
that file: the entry, its wall and CPU time [s], the process and the running test (``$PYTEST_CURRENT_TEST``);
a nested build (a mesh inside a reduced body) is counted in both.
"""

from __future__ import annotations

import contextlib
import gzip
import hashlib
import json
import os
import tempfile
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TypeVar

__all__ = ["cache_dir", "atomic_write_bytes", "remove_stale_temporaries", "CacheWarning", "UnreadableEntry",
           "read_entry", "load_or_build", "build_lock", "file_digest", "record_digest", "check_digest",
           "check_gzip"]

T = TypeVar("T")

_UMASK = os.umask(0o022)
os.umask(_UMASK)
_FILE_MODE = 0o666 & ~_UMASK
"""Mode of the files written here: what open() gives under the process's umask (0644 under the usual 022);
mkstemp alone would give 0600, unreadable by others."""


def cache_dir() -> Path:
    """Cache folder: ``$FLEXGEAR_CACHE_DIR`` or, where it is unset or empty, ``meshes/`` of the project (created on
    demand)."""
    path = Path(os.environ.get("FLEXGEAR_CACHE_DIR") or Path(__file__).resolve().parents[1] / "meshes")
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


class CacheWarning(UserWarning):
    """A cache file could not be read and is being rebuilt."""


class UnreadableEntry(Exception):
    """A cache file that exists but cannot be read: ``path`` and the ``reason`` (one line)."""

    def __init__(self, path: Path, reason: str) -> None:
        self.path, self.reason = Path(path), " ".join(str(reason).split())
        super().__init__(f"cache file {self.path} cannot be read ({self.reason})")


def read_entry(path: Path, read: Callable[[Path], T]) -> T:
    """``read(path)``, any exception raised as :class:`UnreadableEntry` naming ``path``."""
    try:
        return read(path)
    except UnreadableEntry:
        raise
    except Exception as exc:
        raise UnreadableEntry(path, f"{type(exc).__name__}: {exc}") from exc


def load_or_build(path: Path, load: Callable[[], T | None], build: Callable[[], T]) -> T:
    """The cache entry whose main file is ``path``: ``load()``, or ``build()`` (which stores it) when missing or
    damaged, once among all processes.

    ``load`` returns None for a missing entry and raises for one that cannot be read (an :class:`UnreadableEntry`
    names the damaged file; any other exception names ``path``). A first ``load`` runs without the lock; when it
    gives nothing, the entry is looked at again under :func:`build_lock` (another process may have built it
    meanwhile, or be rebuilding it), a damaged one is reported by a :class:`CacheWarning` ("cache file <path>
    cannot be read (<reason>): rebuilding it") and ``build()`` runs while the lock is held.
    """
    with contextlib.suppress(Exception):  # judged under the lock: a builder may be replacing the files
        value = load()
        if value is not None:
            return value
    with build_lock(path):
        try:
            value = load()
        except Exception as exc:
            bad = exc if isinstance(exc, UnreadableEntry) else UnreadableEntry(path, f"{type(exc).__name__}: {exc}")
            warnings.warn(f"{bad}: rebuilding it", CacheWarning, stacklevel=2)
            value = None
        return value if value is not None else _logged(path, build)


def _logged(path: Path, build: Callable[[], T]) -> T:
    """``build()``, its times appended to ``$FLEXGEAR_BUILD_LOG`` when that is set (module docstring)."""
    log = os.environ.get("FLEXGEAR_BUILD_LOG")
    if not log:
        return build()
    wall, cpu = time.perf_counter(), time.process_time()
    value = build()
    line = {"entry": str(path), "wall_s": round(time.perf_counter() - wall, 3),
            "cpu_s": round(time.process_time() - cpu, 3), "pid": os.getpid(),
            "test": os.environ.get("PYTEST_CURRENT_TEST", "")}
    with open(log, "a") as fh:  # one short line per write: lines of several processes do not interleave
        fh.write(json.dumps(line) + "\n")
    return value


_HELD = threading.local()
"""Per thread: the lock paths it holds (a nested request for one of them does not wait for itself)."""


@contextlib.contextmanager
def build_lock(path: Path) -> Iterator[None]:
    """Hold the exclusive lock of ``path`` (``fcntl.flock`` on ``<path>.lock``, created on demand and left in
    place): other processes, and other threads of this one, wait here until it is released. Re-entrant within a
    thread. Without ``fcntl`` (not POSIX) no lock is taken."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    key = Path(path).resolve()
    held: set[Path] = _HELD.__dict__.setdefault("paths", set())
    if key in held:
        yield
        return
    key.parent.mkdir(parents=True, exist_ok=True)
    with open(key.with_name(key.name + ".lock"), "a") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        held.add(key)
        try:
            yield
        finally:
            held.discard(key)
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def file_digest(path: Path) -> str:
    """SHA-256 of the file's bytes (hex)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _digest_path(path: Path) -> Path:
    return path.with_name(path.name + ".sha256")


def record_digest(path: Path) -> None:
    """Store the digest of ``path`` beside it (``<path>.sha256``) for :func:`check_digest`: for files whose
    reader cannot be trusted with a damaged copy (OCC hangs on a truncated ``.brep``)."""
    atomic_write_bytes(_digest_path(path), f"{file_digest(path)}  {path.name}\n".encode())


def check_digest(path: Path) -> None:
    """Raise :class:`UnreadableEntry` unless ``path`` matches the digest :func:`record_digest` stored."""
    stored = _digest_path(path)
    if not stored.exists():
        raise UnreadableEntry(path, f"its digest file {stored.name} is missing")
    expected = stored.read_text().split()[:1]
    if expected != [file_digest(path)]:
        raise UnreadableEntry(path, f"its content does not match the digest in {stored.name}")


def check_gzip(path: Path) -> None:
    """Raise :class:`UnreadableEntry` unless ``path`` is a complete gzip stream (its CRC and length checked by
    decompressing it): Netgen's own reader crashes the process on a truncated ``.vol.gz``."""
    def read(p: Path) -> None:
        with gzip.open(p, "rb") as fh:
            while fh.read(1 << 22):
                pass

    read_entry(path, read)
