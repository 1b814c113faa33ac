"""How quickly the command line answers, and the figure set of a 3D run (issue #11).

Times whole commands as a user starts them (a fresh Python process each, median of several runs after a
warm-up): `python -c pass` as the floor any Python command pays, `fretsim --help`, `summary`, `check`,
`plot` of a 3D results file, and `run` of the 185 N case in 3D beside its own loop time.  Then draws the
figures of that run into DIR/figures (the README shows them).

    python scripts/bench_cli.py [--runs 7] [--out scripts/out] [--figures docs/figures]

Prints a table and writes bench_cli.csv.  The machine is shared: read the medians, and the ratios to the
`python -c pass` floor.
"""
from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _study import ROOT, write_csv

CASE = ROOT / "cases" / "mccoll_185N.yaml"


def timed(cmd: list[str], runs: int, cwd: Path) -> list[float]:
    subprocess.run(cmd, cwd=cwd, capture_output=True)  # warm-up: the file cache, matplotlib's font cache
    out = []
    for _ in range(runs):
        t = time.perf_counter()
        r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
        out.append(time.perf_counter() - t)
        if r.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} failed: {r.stderr[-500:]}")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out")
    ap.add_argument("--figures", type=Path, default=None, help="also keep the figures here (e.g. docs/figures)")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench-cli-"))
    fretsim = [sys.executable, "-m", "fretsim"]
    subprocess.run([*fretsim, "run", str(CASE), "-o", "r.h5", "--quiet"], cwd=tmp, check=True, capture_output=True)
    commands = {
        "python -c pass (the floor)": [sys.executable, "-c", "pass"],
        "fretsim --help": [*fretsim, "--help"],
        "fretsim summary r.h5": [*fretsim, "summary", "r.h5"],
        "fretsim check mccoll_185N.yaml": [*fretsim, "check", str(CASE)],
        "fretsim plot r.h5 (3D, 4 PNG figures)": [*fretsim, "plot", "r.h5", "-o", "figs"],
        "fretsim plot r.h5 --jobs 1 (one process)": [*fretsim, "plot", "r.h5", "-o", "figs1", "--jobs", "1"],
        "fretsim run mccoll_185N.yaml (3D, 18 000 cycles)": [*fretsim, "run", str(CASE), "-o", "run.h5",
                                                            "--overwrite", "--quiet"],
    }
    rows = []
    floor = None
    print(f"{'command':52s} {'median s':>9s} {'min s':>7s} {'max s':>7s} {'over floor s':>12s}")
    for label, cmd in commands.items():
        times = timed(cmd, args.runs, tmp)
        med = statistics.median(times)
        floor = med if floor is None else floor
        rows.append({"command": label, "median_s": round(med, 3), "min_s": round(min(times), 3),
                     "max_s": round(max(times), 3), "over_floor_s": round(med - floor, 3), "runs": args.runs})
        print(f"{label:52s} {med:9.3f} {min(times):7.3f} {max(times):7.3f} {med - floor:12.3f}", flush=True)
    from fretsim.results import read_results
    loop = read_results(tmp / "run.h5").summary["wall_time_s"]
    print(f"  (the run's own loop: {loop:.2f} s of it)")
    write_csv(rows, args.out / "bench_cli.csv")
    if args.figures is not None:
        args.figures.mkdir(parents=True, exist_ok=True)
        subprocess.run([*fretsim, "plot", "r.h5", "-o", str(args.figures.resolve()), "--dpi", "100"], cwd=tmp,
                       check=True, capture_output=True)
        print(f"figures in {args.figures}: {', '.join(sorted(p.name for p in args.figures.glob('*.png')))}")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
