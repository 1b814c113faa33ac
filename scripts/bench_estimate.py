"""How far `fretsim check`'s time estimate is from the run it estimates.

For shipped cases under both stepping families (BDF2 and the paper's linear jumps), 2D and 3D, uniform and
Coulomb slip: the solves and loop seconds `check` estimates (fretsim.plan.estimate_cost: the scheme's expected
solves times one timed solve, scaled by WARM_SOLVE for warm starts) against the run's own, in this process.

    python scripts/bench_estimate.py [--out scripts/out]

Prints a table and writes bench_estimate.csv.  The ratio real/estimate is what to read: the machine is shared.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from _study import ROOT, write_csv

from fretsim.api import load_case, run
from fretsim.plan import estimate_cost, prepare

CASES = [("mccoll_185N.yaml", []), ("mccoll_185N.yaml", ["jumping.scheme=linear", "loading.cycles=3000"]),
         ("mccoll_185N.yaml", ["model.dimension=2d"]),
         ("mccoll_185N.yaml", ["model.dimension=2d", "jumping.scheme=linear"]),
         ("kirk_450N_20Hz.yaml", []), ("ball_partial_slip.yaml", []),
         ("tube_RT.yaml", ["model.dimension=3d", "model.corrections=none"])]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out")
    args = ap.parse_args()
    rows = []
    for name, overrides in CASES:
        case = load_case(ROOT / "cases" / name, overrides + ["grid.error_estimate=none"])
        setup, _, _ = prepare(case)
        solves, seconds = estimate_cost(setup)
        out = run(case)
        real, n = out.summary["wall_time_s"], out.summary["contact_solves"]
        rows.append({"case": name, "overrides": " ".join(overrides), "estimated_solves": solves,
                     "estimated_s": round(seconds, 3), "solves": n, "loop_s": round(real, 3),
                     "real_over_estimate": round(real / seconds, 2)})
        print(f"{name:24s} {' '.join(overrides):46s} estimate {solves:5d} solves {seconds:6.2f} s | run {n:5d} "
              f"solves {real:6.2f} s | real/estimate {real / seconds:5.2f}", flush=True)
    write_csv(rows, args.out / "bench_estimate.csv")


if __name__ == "__main__":
    main()
