"""A Ctrl-C that lands while a sweep forks its workers, many times over: does every sweep stop cleanly?

Runs the scenario of tests/test_sweep.py's ``test_a_ctrl_c_while_the_sweep_forks_its_workers_…`` (the SIGINT sent
from the parent's own at-fork hook, so it always lands during the forks) N times, P at once so that the machine is
loaded and the workers start slowly, and classifies each run: exit 130 with no traceback (right), a traceback, another
exit code, or a hang (no exit within the timeout; its process tree is then killed).  A race shows as a few bad runs
in many: 2 of 4 clean-clone CI runs failed this test before the fix of 2026-11-28, and this script found 6 tracebacks
and 2 hangs in 36 runs on that tree, none in 192 after it.

    python scripts/stress_sweep_signals.py [-n 48] [-p 4] [--timeout 60]
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import test_sweep as T  # noqa: E402 - the test's sweep file and its Ctrl-C-in-fork script


def one(i: int, timeout: float) -> tuple[int, str, float, str]:
    d = Path(tempfile.mkdtemp(prefix="fretsim-stress-"))
    spec = T.sweep_file(d, T.SLOW_POINTS)
    start = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-c", T.CTRL_C_IN_FORK, str(spec), str(d / "out")],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        said, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return i, "hang", time.monotonic() - start, ""
    if "Traceback" in said or "Exception ignored" in said:
        return i, "traceback", time.monotonic() - start, said
    return i, ("ok" if proc.returncode == 130 else f"exit {proc.returncode}"), time.monotonic() - start, said


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=48, help="runs")
    ap.add_argument("-p", type=int, default=4, help="runs at once")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds before a run counts as hung")
    args = ap.parse_args()
    counts: dict = {}
    with cf.ThreadPoolExecutor(args.p) as ex:
        for i, verdict, seconds, said in ex.map(lambda k: one(k, args.timeout), range(args.n)):
            counts[verdict] = counts.get(verdict, 0) + 1
            if verdict != "ok":
                print(f"run {i}: {verdict} after {seconds:.1f} s\n{said[-2000:]}", flush=True)
    print(f"{args.n} runs, {args.p} at once: " + ", ".join(f"{n} {v}" for v, n in sorted(counts.items())))
    sys.exit(0 if counts.get("ok", 0) == args.n else 1)


if __name__ == "__main__":
    main()
