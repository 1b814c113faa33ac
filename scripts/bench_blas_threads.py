"""One BLAS thread or two for `fretsim run`: whole commands timed side by side, on a quiet machine and with the
other core busy (a second process spinning, as a second run or a shell sweep would).

`fretsim run` pins OpenBLAS (and OpenMP, MKL) to one thread unless the user has set the variables: numpy's dots in
the loop are small (the norms of a grid's fields), and a second BLAS thread that has to wait for a busy core costs
far more than it gives.  Here each case is run with OPENBLAS_NUM_THREADS=1 and =2 alternately, RUNS times after a
warm-up, and the medians and their ratio are printed.

    python scripts/bench_blas_threads.py [--runs 5]      # writes scripts/results/bench_blas_threads.txt
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _study import ROOT, Report

CASES = (("tube_service_RT 3D to 1 % wall loss", "cases/tube_service_RT.yaml",
          ["model.dimension=3d", "grid.error_estimate=none", "limits.wall_loss=1 %"]),
         ("McColl 185 N 3D (defaults)", "cases/mccoll_185N.yaml", []))
SPIN = "import time\nt = time.time()\nwhile time.time() - t < 3600: pass\n"


def timed(case: str, sets: list, threads: str, out: Path) -> float:
    env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads, MKL_NUM_THREADS=threads)
    cmd = [sys.executable, "-m", "fretsim", "run", str(ROOT / case), "-o", str(out), "--overwrite", "--quiet"]
    for s in sets:
        cmd += ["--set", s]
    t = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    runs = ap.parse_args().runs
    say = Report()
    say(f"{'case':<38}{'machine':<12}{'1 thread s':>12}{'2 threads s':>13}{'2/1':>7}")
    with tempfile.TemporaryDirectory() as tmp:
        for busy in (False, True):
            spinner = subprocess.Popen([sys.executable, "-c", SPIN]) if busy else None
            try:
                for label, case, sets in CASES:
                    times: dict = {"1": [], "2": []}
                    for i in range(runs + 1):
                        for threads in ("1", "2"):
                            t = timed(case, sets, threads, Path(tmp) / "r.h5")
                            if i:
                                times[threads].append(t)
                    one, two = statistics.median(times["1"]), statistics.median(times["2"])
                    say(f"{label:<38}{'other busy' if busy else 'quiet':<12}{one:>12.2f}{two:>13.2f}"
                        f"{two / one:>7.2f}")
            finally:
                if spinner is not None:
                    spinner.kill()
    (ROOT / "scripts" / "results").mkdir(parents=True, exist_ok=True)
    say.write(ROOT / "scripts" / "results" / "bench_blas_threads.txt")


if __name__ == "__main__":
    main()
