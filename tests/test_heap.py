"""The C heap kept warm (fretsim.heap): tuned once where glibc is, and no number changes with it."""
import platform
import subprocess
import sys
from pathlib import Path

import pytest

from fretsim import heap

CASE = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
RUN = """
import hashlib, sys, fretsim.heap as h
if sys.argv[2] == "cold":
    h._done = False  # as if tuned already: glibc's defaults stay
from fretsim.api import load_case, run
o = run(load_case(sys.argv[1], ["model.dimension=2d", "loading.cycles=2000", "grid.error_estimate=none"]))
print(h._done, repr(o.summary["max_wear_depth_stationary_um"]), repr(o.summary["scar_width_stationary_mm"]),
      hashlib.sha1(o.last.wear_stationary.tobytes() + o.last.pressure.tobytes()).hexdigest())
"""


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="mallopt is glibc's; elsewhere nothing is tuned")
def test_the_heap_is_tuned_once_where_glibc_is():
    assert heap.keep_warm() is True
    assert heap.keep_warm() is True  # (the second call changes nothing)


@pytest.mark.parametrize("broken", ["no _ctypes", "CDLL(None) refused"])
def test_a_process_without_a_reachable_malloc_keeps_its_heap_and_runs(broken, monkeypatch):
    """Where ctypes is missing (a Python built without _ctypes: ImportError) or cannot open the process's own
    library (Windows' CDLL(None): TypeError), nothing is tuned and nothing is raised: run() and resume() call
    this first, and a failure here would stop every run."""
    import ctypes
    monkeypatch.setattr(heap, "_done", None)
    if broken == "no _ctypes":
        monkeypatch.setitem(sys.modules, "ctypes", None)
    else:
        def refuse(name, *a, **k):
            raise TypeError("argument of type 'NoneType' is not iterable")
        monkeypatch.setattr(ctypes, "CDLL", refuse)
    assert heap.keep_warm() is False
    assert heap.keep_warm() is False


def test_a_run_gives_the_same_numbers_bit_for_bit_with_the_heap_kept_warm_or_not():
    """Where the blocks come from changes no arithmetic: the same depth, width, worn profile and pressure field to
    the last bit."""
    out = {arm: subprocess.run([sys.executable, "-c", RUN, str(CASE), arm], capture_output=True, text=True,
                               check=True).stdout.split() for arm in ("warm", "cold")}
    assert out["cold"][0] == "False"
    if platform.libc_ver()[0] == "glibc":
        assert out["warm"][0] == "True"
    assert out["warm"][1:] == out["cold"][1:]
