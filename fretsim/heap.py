"""The C heap kept warm for the solver's temporaries.

A solve allocates arrays of a few megabytes thousands of times (a 3D resolved step's stack of nine positions is
3 MB per transform).  glibc's malloc hands such blocks out by mmap, or from the heap top which it trims back to
the system once 128 KB lie free there; either way the next block of the same size comes back as fresh pages, and
the kernel faults and zeroes each of them again: that stack's forward and backward transform took 6.6 ms in a fresh
process, 2.4 ms from a warm heap, and whole McColl runs (uniform 3D, mid-stroke 2D and 3D) ran 5-7 % faster, the
resolved 3D run no faster (its blocks stay in the heap anyway), peak memory the same (scripts/bench_heap.py).
Serving blocks up to 32 MB from the heap and trimming only beyond 32 MB free keeps the pages; the process holds at
most that much more than it uses.  Elsewhere than glibc (musl, macOS) nothing is changed: mallopt is glibc's.
"""
from __future__ import annotations

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's malloc.h
KEEP_BYTES = 32 << 20

_done: bool | None = None


def keep_warm() -> bool:
    """Tune this process's malloc once (the first run): whether it was (False where there is no glibc)."""
    global _done
    if _done is None:
        _done = False
        try:
            import ctypes
            libc = ctypes.CDLL(None)
            mallopt = getattr(libc, "mallopt", None)
            if mallopt is not None and getattr(libc, "gnu_get_libc_version", None) is not None:
                # (mallopt returns 1 on success; both are set: setting either one stops glibc adjusting the other,
                #  and the trim threshold alone left blocks above 128 KB to mmap, slower than the default)
                _done = bool(mallopt(M_MMAP_THRESHOLD, KEEP_BYTES)) and bool(mallopt(M_TRIM_THRESHOLD, KEEP_BYTES))
        except Exception:  # noqa: BLE001 - any failure to reach malloc (no _ctypes: ImportError; Windows'
            #                    CDLL(None): TypeError) leaves the default heap: slower, the same numbers
            _done = False
    return _done
