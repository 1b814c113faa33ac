"""How loose may a wear limit's pilot step?  The pilot (fretsim.plan.model.pilot_cycles) finds roughly where a run
with wear limits stops, to size its grid (PILOT_MARGIN = 1.3 times that wear) and place its automatic recorded
states; it needs the stop to well within that margin.  Each case's pilot at stepping tolerances 0.03 (before
2026-11-28) to 0.3, side by side in one process: the stop, its difference from the tightest, the pilot's solves
and seconds.

    python scripts/study_pilot_tolerance.py [--tolerances 0.03,0.1,0.3]

Writes scripts/results/pilot_tolerance.txt.
"""
from __future__ import annotations

import argparse
import math
import time

from _study import ROOT

import fretsim.simulate as simulate
from fretsim.api import load_case
from fretsim.plan import model, prepare
from fretsim.plan.runs import SideRuns

CASES = [  # (case, overrides): every shipped case with limits, and limits set on the others across the scenes
    ("tube_service_RT", []),
    ("tube_service_90C", []),
    ("mccoll_185N", ["model.dimension=2d", "limits.max_wear_depth_stationary=2 um", "loading.cycles=100000"]),
    ("mccoll_185N", ["limits.max_wear_depth_stationary=2 um", "loading.cycles=100000", "model.corrections=auto",
                     "model.dimension=auto"]),
    ("mccoll_185N", ["model.dimension=2d", "limits.scar_width_stationary=0.6 mm", "loading.cycles=100000",
                     "loading.friction_coefficient=0.9", "model.slip=coulomb"]),
    ("mccoll_185N", ["model.dimension=2d", "limits.max_wear_depth_stationary=2 um", "loading.cycles=100000",
                     "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved"]),
    ("mccoll_185N", ["model.dimension=2d", "limits.max_wear_depth_stationary=2 um", "loading.cycles=100000",
                     "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.gap=stroke_average"]),
    ("mccoll_500N_10um", ["model.dimension=2d", "limits.max_wear_depth_moving=3 um", "loading.cycles=1000000",
                          "loading.friction_coefficient=0.8", "model.slip=coulomb"]),
    ("mccoll_1670N", ["limits.centre_wear_depth_stationary=5 um", "loading.cycles=1000000",
                      "loading.friction_coefficient=0.9"]),
    ("kirk_450N_100Hz", ["model.dimension=2d", "limits.wear_volume_stationary=0.01 mm3", "loading.cycles=10000000"]),
    ("s132_250N_100um", ["model.dimension=2d", "limits.max_wear_depth_moving=20 um", "loading.cycles=10000000"]),
    ("roller_edge_rounded", ["limits.max_wear_depth_stationary=1 um", "loading.cycles=10000000"]),
    ("seat_rail", ["limits.max_wear_depth_stationary=10 um", "loading.cycles=100000"]),
    ("wire_rope", ["limits.max_wear_depth_stationary=5 um"]),
    ("ti_fretting_fatigue", ["materials.stationary.fatigue=null", "limits.max_wear_depth_stationary=1 um",
                             "loading.cycles=1000000"]),
]


def _pilot(case, tolerance: float) -> tuple:
    """(stop, solves, seconds) of the case's pilot at ``tolerance``."""
    count = [0]
    solve = simulate.solve  # (the loop's own reference to fretsim.solvers.solve)

    def counted(*args, **kw):
        count[0] += 1
        return solve(*args, **kw)

    old = model.PILOT_TOLERANCE
    model.PILOT_TOLERANCE, simulate.solve = tolerance, counted
    try:
        t = time.perf_counter()
        stop = model.pilot_cycles(case, SideRuns(), lambda c, pilot=None: prepare(c, pilot=pilot))
        return stop, count[0], time.perf_counter() - t
    finally:
        model.PILOT_TOLERANCE, simulate.solve = old, solve


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tolerances", default="0.03,0.1,0.3")
    args = ap.parse_args()
    tolerances = [float(t) for t in args.tolerances.split(",")]
    lines = [f"command: python scripts/study_pilot_tolerance.py --tolerances {args.tolerances} "
             f"({time.strftime('%Y-%m-%d')}); the pilot's stop (cycles), its difference from the first tolerance's, "
             f"its solves and seconds", "",
             f"{'case':22s} {'overrides':58s} " + "  ".join(f"{'tol ' + str(t):>34s}" for t in tolerances)]
    worst = {t: 0.0 for t in tolerances}
    for name, sets in CASES:
        case = load_case(ROOT / "cases" / f"{name}.yaml", sets)
        got = [_pilot(case, t) for t in tolerances]
        ref = got[0][0]
        cells = []
        for t, (stop, solves, seconds) in zip(tolerances, got):
            rel = abs(stop / ref - 1) if ref and math.isfinite(ref) and stop and math.isfinite(stop) else 0.0
            worst[t] = max(worst[t], rel)
            shown = "failed" if stop is None else "inf" if not math.isfinite(stop) else f"{stop:.6g}"
            cells.append(f"{shown:>12s} {rel:8.1e} {solves:6d} {seconds:5.2f}s")
        line = f"{name:22s} {' '.join(sets)[:58]:58s} " + "  ".join(cells)
        print(line, flush=True)
        lines.append(line)
    lines += ["", "largest difference from the first tolerance's stop: "
              + ", ".join(f"{t}: {worst[t]:.1e}" for t in tolerances)]
    text = "\n".join(lines) + "\n"
    (ROOT / "scripts" / "results" / "pilot_tolerance.txt").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
