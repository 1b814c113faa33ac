"""The C heap kept warm (fretsim.heap) or glibc's defaults: whole `fretsim run` commands side by side.

Each case runs as a fresh `fretsim run` process with the heap kept warm (as shipped) and with the tuning turned off
(the same command with ``fretsim.heap`` told it is done), alternately, RUNS pairs after a warm-up pair; the table
gives the median wall times, the median of the pairs' ratios and each arm's largest resident memory.  First, the
transform behind it: the forward transform of a 3D resolved step's stack (nine positions, a 27 × 395 window
padded to 54 × 800), timed in a fresh process either way.

    python scripts/bench_heap.py [--runs 5] [--quick]     # writes scripts/results/bench_heap.txt
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

CASES = (("McColl 185 N 3D, uniform (defaults)", "cases/mccoll_185N.yaml", []),
         ("McColl 185 N 2D, mid-stroke Coulomb", "cases/mccoll_185N.yaml",
          ["model.dimension=2d", "model.slip=coulomb", "model.stroke=mid_stroke", "loading.friction_coefficient=0.9"]),
         ("McColl 185 N 3D, mid-stroke Coulomb", "cases/mccoll_185N.yaml",
          ["model.dimension=3d", "model.slip=coulomb", "model.stroke=mid_stroke", "loading.friction_coefficient=0.9",
           "grid.error_estimate=none"]),
         ("McColl 185 N 3D, resolved", "cases/mccoll_185N.yaml",
          ["model.dimension=3d", "model.slip=coulomb", "model.stroke=resolved", "loading.friction_coefficient=0.9",
           "grid.error_estimate=none"]))
QUICK = 2  # --quick: the first two cases

COLD = "import sys, fretsim.heap as h; h._done = False; from fretsim.cli import main; main(prog_name='fretsim')"
WARM = "import sys; from fretsim.cli import main; main(prog_name='fretsim')"

TRANSFORM = """
import time, numpy as np, fretsim.heap as h
from fretsim.compliance import fft
if {warm}:
    h.keep_warm()
p = np.random.default_rng(0).random((9, 27, 395))
fft.forward(p, (54, 800))
t = time.perf_counter()
for _ in range(200):
    fft.backward(fft.forward(p, (54, 800)), (54, 800), (27, 395))
print((time.perf_counter() - t) / 200 * 1e3)
"""


def timed(code: str, case: str, sets: list, out: Path) -> tuple[float, float]:
    """Wall seconds and the child's largest resident memory (MiB) of one `fretsim run`."""
    cmd = [sys.executable, "-c", code, "run", str(ROOT / case), "-o", str(out), "--overwrite", "--quiet"]
    for s in sets:
        cmd += ["--set", s]
    t = time.perf_counter()
    child = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=ROOT)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - t
    if status != 0:
        raise SystemExit(f"{case} {sets} failed: {child.stderr.read().decode()[-500:]}")
    return wall, usage.ru_maxrss / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    say = Report()
    say("a 9-layer stack's forward and backward transform (27 x 395 padded to 54 x 800), ms a pair, fresh process:")
    for warm in (True, False):
        ms = [float(subprocess.run([sys.executable, "-c", TRANSFORM.format(warm=warm)], capture_output=True,
                                   text=True, check=True, cwd=ROOT).stdout) for _ in range(3)]
        say(f"  heap {'kept warm' if warm else 'glibc default':<14}{statistics.median(ms):8.2f}")
    say()
    say(f"whole `fretsim run` commands, {args.runs} pairs each (warm, then default), medians:")
    say(f"{'case':<40}{'warm s':>8}{'default s':>10}{'ratio':>7}{'min':>6}{'max':>6}{'warm MiB':>10}{'dflt MiB':>10}")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "r.h5"
        for label, case, sets in CASES[:QUICK] if args.quick else CASES:
            pairs = []
            for i in range(args.runs + 1):
                a, b = timed(WARM, case, sets, out), timed(COLD, case, sets, out)
                if i:
                    pairs.append((a, b))
            ratios = [a[0] / b[0] for a, b in pairs]
            say(f"{label:<40}{statistics.median(a[0] for a, _ in pairs):>8.2f}"
                f"{statistics.median(b[0] for _, b in pairs):>10.2f}{statistics.median(ratios):>7.2f}"
                f"{min(ratios):>6.2f}{max(ratios):>6.2f}{max(a[1] for a, _ in pairs):>10.0f}"
                f"{max(b[1] for _, b in pairs):>10.0f}")
    (ROOT / "scripts" / "results").mkdir(parents=True, exist_ok=True)
    say.write(ROOT / "scripts" / "results" / "bench_heap.txt")


if __name__ == "__main__":
    main()
