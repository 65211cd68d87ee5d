"""Keep the pages of freed work arrays in the process, so that the next step reuses them.

A step at N = 30,000 makes a few dozen arrays of 240 kB and frees them. glibc serves blocks above
its mmap threshold by fresh mappings and returns them on free, and trims the heap's top once more
than its trim threshold is free, so each step pays a page fault per 4 kB again, which virtual
machines make dear (benchmarks/bench_alloc.py: 40 % of an MTPT step at N = 30,000). Raising both
thresholds makes freed arrays go back to the heap and the next step's arrays come from there:
the effect of reusing work buffers, for numpy and numba arrays alike, without threading buffers
through every function. Blocks above ``MMAP_THRESHOLD`` still get their own mapping, so large
transient arrays are still returned to the system.
"""

from __future__ import annotations

import ctypes
import ctypes.util

MMAP_THRESHOLD = 32 * 2**20  # bytes; glibc's upper bound for this setting on 64-bit systems
TRIM_THRESHOLD = 128 * 2**20  # free bytes at the heap's top before glibc gives them back
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # mallopt parameters (malloc.h)


def keep_freed_pages() -> bool:
    """Raise glibc's mmap and trim thresholds for this process -> whether both were set (False
    where the C library is not glibc: the process then keeps its allocator's defaults)."""
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))
