"""Why the pressure of a worn contact cannot be matched to 1 % at one instant: the exact model's sawtooth.

Runs the exact per-cycle model (jumping.linear = 1) of a shipped case in 2D and keeps the pressure of the last
400 cycles.  As wear widens the contact, its edge crosses one element at a time: the edge element loads up
over a few hundred cycles, then the next element comes into contact and it unloads.  The pressure field
therefore changes by several per cent over tens of cycles, and a stepped run whose contact front is a few
dozen cycles out of phase is that far off at that instant, however accurate its depths.  Prints the L2
distance between p(N) and p(N − k), and the edge element's pressure over the last cycles.

    python scripts/study_contact_front.py [CASE] [--cycles N]
"""
from __future__ import annotations

import argparse

import numpy as np

from _study import run_case


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default="mccoll_500N_10um")
    ap.add_argument("--cycles", type=int, default=18000)
    args = ap.parse_args()
    n = args.cycles
    keep = {}

    class Keep:
        def on_step(self, setup, step):
            if step.cycle >= n - 400:
                keep[step.cycle] = step.pressure[0].copy()

    run_case(f"cases/{args.case}.yaml", ["model.dimension=2d", f"loading.cycles={n}", "jumping.scheme=linear",
                                         "jumping.linear=1"], observers=(Keep(),))
    last = keep[n]
    print(f"{args.case}, 2D, exact per-cycle model: relative L2 distance between the pressure at cycle {n} and "
          f"at cycle {n} − k")
    for k in (1, 2, 5, 10, 20, 50, 100, 200, 400):
        if n - k in keep:
            print(f"  k = {k:4d}: {np.linalg.norm(keep[n - k] - last) / np.linalg.norm(last):.2%}")
    edge = int(np.flatnonzero(last > 0)[0])
    series = np.array([keep[c][edge] for c in sorted(keep)])
    print(f"edge element {edge}: pressure over the last 400 cycles from {series.min():.1f} to {series.max():.1f} "
          f"MPa; the last 10: {np.round(series[-10:], 1).tolist()}")


if __name__ == "__main__":
    main()
