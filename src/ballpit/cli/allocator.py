"""The app keeps freed memory for reuse instead of handing it back to the kernel between steps.

A step allocates and frees array temporaries of up to several megabytes. By default glibc's malloc
returns the top of its heap to the kernel as soon as more than 128 KiB of it is free, and serves large
arrays from fresh mappings, so the next step faults the same pages in again: about a tenth of a pile's
landing went to the kernel (sys time 0.6 s of 8 s at 1,000 balls, 4 s of 37 s at 10,000). The command
line asks malloc to keep up to 1 GiB free on its heap, grow it 64 MiB at a time and serve arrays up
to 32 MiB from it. A program that embeds the engine can do the same with the environment variables
MALLOC_TRIM_THRESHOLD_, MALLOC_TOP_PAD_ and MALLOC_MMAP_THRESHOLD_, or by calling
``keep_freed_memory()``.
"""

from __future__ import annotations

import ctypes
import sys

# mallopt(3) parameters
_M_TRIM_THRESHOLD, _M_TOP_PAD, _M_MMAP_THRESHOLD = -1, -2, -3
_SETTINGS = ((_M_TRIM_THRESHOLD, 1 << 30), (_M_TOP_PAD, 64 << 20), (_M_MMAP_THRESHOLD, 32 << 20))


def keep_freed_memory() -> bool:
    """Ask glibc's malloc to keep freed memory in the process; True when every setting took (False
    elsewhere: other C libraries and systems keep their own policy)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return all(mallopt(param, value) == 1 for param, value in _SETTINGS)
