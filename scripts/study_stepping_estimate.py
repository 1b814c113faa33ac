"""Is the stepping's depth estimate of the size of the depth error?  Each run's `error_estimate_depth` against its
actual error from the exact model on the same grid (the per-cycle update: jumping.scheme linear, jumping.linear 1),
the ratio estimate/error, over short and long runs, 2D and 3D, each stepping scheme.

The error is the largest relative difference of the reported depths (the flat's centre-line, each body's
deepest).  A ratio of 1 is an estimate of the right size; below 1 it under-states (the tests hold it to at least
0.5: a local-error estimate, not a bound); far above 1 it is the sum of every step's local error while the wear
relaxed the shape errors the earlier steps made (docs/verification.md, *The stepping estimate's size*).

    python scripts/study_stepping_estimate.py [--quick]

Prints a table; writes scripts/out/stepping_estimate.{txt,csv}.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report, write_csv  # noqa: E402

from fretsim.api import load_case, run  # noqa: E402

OUT = ROOT / "scripts" / "out"
KEYS = ("centre_wear_depth_stationary_um", "max_wear_depth_moving_um", "max_wear_depth_stationary_um")
RUNS = [  # (case, dimension, cycles, extra overrides)
    ("mccoll_185N", "3d", 10, ["model.slip=uniform"]),
    ("mccoll_185N", "3d", 100, ["model.slip=uniform"]),
    ("mccoll_185N", "3d", 1000, ["model.slip=uniform"]),
    ("mccoll_185N", "2d", 100, ["model.slip=uniform"]),
    ("mccoll_185N", "2d", 18000, ["model.slip=uniform"]),
    ("mccoll_185N", "2d", 30, ["loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved"]),
    ("mccoll_185N", "2d", 300, ["loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved"]),
    ("mccoll_1670N", "3d", 30, []),
    ("mccoll_1670N", "3d", 300, []),
    ("kirk_450N_20Hz", "2d", 300, []),
]
SCHEMES = [("bdf2 0.01", ["jumping.scheme=bdf2"]), ("bdf2 0.001", ["jumping.scheme=bdf2", "jumping.tolerance=0.001"]),
           ("implicit 0.01", ["jumping.scheme=implicit"]), ("linear", ["jumping.scheme=linear"])]


def main(quick: bool) -> None:
    say = Report()
    rows = []
    say(f"{'case':<16}{'dim':<5}{'cycles':>7}  {'scheme':<14}{'error':>10}{'estimate':>10}{'ratio':>8}  extra")
    for case, dim, cycles, extra in RUNS[:3] if quick else RUNS:
        path = ROOT / "cases" / f"{case}.yaml"
        base = [f"model.dimension={dim}", "grid.error_estimate=none", f"loading.cycles={cycles}",
                f"output.snapshots=[0, {cycles}]", *extra]
        exact = run(load_case(path, base + ["jumping.scheme=linear", "jumping.linear=1"])).summary
        for label, sets in SCHEMES:
            s = run(load_case(path, base + sets)).summary
            error = max(abs(s[k] / exact[k] - 1.0) for k in KEYS if exact[k] > 0)
            ratio = s["error_estimate_depth"] / error if error > 0 else float("inf")
            say(f"{case:<16}{dim:<5}{cycles:>7}  {label:<14}{error:>10.2e}{s['error_estimate_depth']:>10.2e}"
                f"{ratio:>8.2f}  {' '.join(extra)}")
            rows.append({"case": case, "dimension": dim, "cycles": cycles, "scheme": label, "error": error,
                         "estimate": s["error_estimate_depth"], "ratio": ratio, "overrides": " ".join(extra)})
    OUT.mkdir(parents=True, exist_ok=True)
    write_csv(rows, OUT / "stepping_estimate.csv")
    say.write(OUT / "stepping_estimate.txt")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the three 3D uniform runs only")
    main(ap.parse_args().quick)
