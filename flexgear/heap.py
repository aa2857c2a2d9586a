"""The heap of worker processes: large arrays go back to the system when freed (peak memory of a matrix).

glibc's malloc serves a request of at least its mmap threshold with a mapping of its own, which ``free``
unmaps, and smaller ones from the heap, which keeps freed memory for reuse. The threshold starts at
128 KiB but rises (up to 32 MiB on 64-bit systems) each time such a mapping is freed, so after the first
freed temporaries a worker's large NumPy arrays come from the heap and stay there after ``del``: a
cold-build worker held 0.15-0.3 GB it no longer used, on top of the next component's peak, and the
coarse ring's reduction peaked 0.1 GB higher (benchmarks/bench_cold.py measures the process tree).
:func:`lean_heap` fixes the threshold at :data:`MMAP_THRESHOLD_BYTES`, which also stops the rise. The
arithmetic is untouched: only where the arrays live changes.
"""

from __future__ import annotations

import ctypes
import ctypes.util

__all__ = ["MMAP_THRESHOLD_BYTES", "lean_heap"]

MMAP_THRESHOLD_BYTES = 128 * 1024
"""Allocations of at least this size [bytes] get their own mapping, unmapped when freed: glibc's initial
threshold (M_MMAP_THRESHOLD's default), kept instead of letting it rise."""

_M_MMAP_THRESHOLD = -3  # mallopt's parameter number for the mmap threshold (glibc's <malloc.h>)


def lean_heap() -> bool:
    """Fix the C library's mmap threshold at :data:`MMAP_THRESHOLD_BYTES` in this process (a worker
    process's initializer). Returns whether it applied: glibc only; elsewhere it does nothing."""
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):
        return False  # no C library by that name, or one without mallopt (macOS, Windows, musl)
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES) == 1
