"""How long does a service-life uncertainty sweep take, and what does it say?

Runs the shipped tube's 200-sample sweeps (cases/sweeps/tube_service_{RT,90C}_uncertainty.yaml: both wear
coefficients lognormal, a factor of two, Latin hypercube) with `fretsim sweep --jobs 2`, as a user would, and
prints the wall time of each (the issue's target: under a minute for 200 samples of the 2D tube) and the
P10/P50/P90 of the years to the wall limit from percentiles.csv.

    python scripts/bench_uncertainty.py [--out scripts/results]      # writes uncertainty_tube.csv

The sweep directories are made fresh in a temporary directory (a re-run would skip complete points).
"""
from __future__ import annotations

import argparse
import csv
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _study import ROOT, write_csv

TEMPERATURES = ("RT", "90C")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "scripts" / "results"))
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    rows = []
    print(f"{'sweep':34s} {'points':>6s} {'wall s':>7s} {'s/point':>8s} {'P10 y':>7s} {'P50 y':>7s} {'P90 y':>7s}")
    for temp in TEMPERATURES:
        sweep = ROOT / "cases" / "sweeps" / f"tube_service_{temp}_uncertainty.yaml"
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "band"
            t = time.perf_counter()
            proc = subprocess.run([sys.executable, "-m", "fretsim", "sweep", str(sweep), "-o", str(out), "--jobs",
                                   str(args.jobs)], capture_output=True, text=True)
            seconds = time.perf_counter() - t
            if proc.returncode != 0:
                print(proc.stderr[-2000:])
            with open(out / "percentiles.csv", newline="") as fh:
                pct = {r["key"]: r for r in csv.DictReader(fh)}
            with open(out / "table.csv", newline="") as fh:
                points = sum(1 for r in csv.DictReader(fh) if r["status"] == "complete")
        years = {q: float(pct["time_to_limit_h"][q]) / 8766 for q in ("p10", "p50", "p90")}
        row = {"sweep": sweep.name, "complete_points": points, "not_complete": int(pct["cycles"]["not_complete"]), "wall_s": seconds, "s_per_point": seconds / points,
               **{f"{q}_years": v for q, v in years.items()},
               **{f"{q}_cycles": float(pct["cycles_to_limit"][q]) for q in ("p10", "p50", "p90")}}
        rows.append(row)
        print(f"{sweep.name:34s} {points:6d} {seconds:7.1f} {seconds / points:8.3f} {years['p10']:7.3g} "
              f"{years['p50']:7.3g} {years['p90']:7.3g}", flush=True)
    write_csv(rows, Path(args.out) / "uncertainty_tube.csv")


if __name__ == "__main__":
    main()
