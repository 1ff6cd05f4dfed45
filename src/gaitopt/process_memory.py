"""The process's memory: what it holds now, what it may hold, and handing freed memory back.

gaitopt's in-memory caches (the transcriptions of :mod:`gaitopt.gait.solve.transcriptions`) are
bounded in bytes of the whole process, not in a count of entries: a compressed-form NLP on a
fine grid takes over a gigabyte, a point-wise one a few megabytes, so no count suits both.

* :func:`resident_bytes`: the resident set size now (Linux ``/proc/self/statm``; elsewhere the
  peak from ``getrusage``, an upper bound).
* :func:`memory_budget_bytes`: ``$GAITOPT_MEMORY_MB`` megabytes (default
  :data:`DEFAULT_BUDGET_MB`); an invalid value is ignored with a warning naming the variable.
* :func:`release_freed_memory`: collect garbage and ask the C allocator to return free pages
  to the system (glibc's ``malloc_trim``), so that a dropped cache entry lowers the resident
  size instead of staying as free heap the process keeps.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import gc
import os
import resource
import sys
import warnings
from collections.abc import Callable

#: The default budget of resident memory, MB, within which the caches keep the process (one
#: solve's own working memory may exceed it for its duration).
DEFAULT_BUDGET_MB = 640.0
#: The environment variable that sets the budget, MB.
BUDGET_VARIABLE = "GAITOPT_MEMORY_MB"
_MB = 2**20


def resident_bytes() -> int:
    """Resident set size of this process now, bytes (the peak where ``/proc`` is missing)."""
    try:
        with open("/proc/self/statm", encoding="ascii") as f:
            pages = int(f.read().split()[1])
        return pages * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return peak_resident_bytes()


def peak_resident_bytes() -> int:
    """The largest resident set size this process has had, bytes (``getrusage``)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return int(peak) if sys.platform == "darwin" else int(peak) * 1024  # bytes / KiB


def memory_budget_bytes() -> int:
    """``$GAITOPT_MEMORY_MB`` (a number > 0) in bytes, else :data:`DEFAULT_BUDGET_MB`."""
    raw = os.environ.get(BUDGET_VARIABLE)
    if raw is None:
        return int(DEFAULT_BUDGET_MB * _MB)
    try:
        value = float(raw)
        if not value > 0 or value == float("inf"):
            raise ValueError
    except ValueError:
        warnings.warn(f"{BUDGET_VARIABLE}={raw!r} ignored: must be a number of megabytes > 0; "
                      f"using {DEFAULT_BUDGET_MB:g}", RuntimeWarning, stacklevel=2)
        return int(DEFAULT_BUDGET_MB * _MB)
    return int(value * _MB)


@functools.cache
def _malloc_trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim``, or ``None`` where the C library has none."""
    name = ctypes.util.find_library("c")
    if name is None:
        return None
    try:
        trim: Callable[[int], int] = ctypes.CDLL(name).malloc_trim
    except (OSError, AttributeError):  # not glibc
        return None
    return trim


def release_freed_memory() -> None:
    """Collect garbage, then return the allocator's free pages to the system (glibc
    ``malloc_trim(0)``; a no-op where the C library has none)."""
    gc.collect()
    trim = _malloc_trim()
    if trim is not None:
        trim(0)
