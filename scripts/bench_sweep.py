"""What a sweep costs beyond its points' own work, and how it scales: the load × stroke sweep of the McColl case
in 2D (cases/sweeps/mccoll_load_stroke.yaml, 20 points).

* per-point overhead: the sweep's wall time over the sum of its points' simulations (each point's loop and its
  grid-error companion runs, `wall_time_s + grid_error_wall_time_s` in the table), with one worker, and over
  the loops alone; against a shell loop that starts `fretsim run` for each point (start-up and imports every time);
* parallel efficiency: one worker against two;
* the same sweep on a local Dask cluster (a scheduler and two worker processes on 127.0.0.1).

    python scripts/bench_sweep.py [--out scripts/out] [--vs OTHER_TREE]

Prints a table and writes bench_sweep.csv.  Times are wall times of whole sweeps measured one after another in
this process, the 1- and 2-worker sweeps in turn (best of three each); the machine is shared, so compare the
ratios, and the 2-worker figure with the control: the same CPU-bound numpy work in 1 and 2 processes.  fretsim's imports (~1.5 s, paid once per sweep, not
per point) are done before the clock starts, so the overheads are the steady per-point costs: mostly writing each
point's results file (an HDF5 image of ~80 datasets and ~230 attributes, timed separately below).
"""
from __future__ import annotations

import argparse
import csv
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Optional

from _study import ROOT, write_csv

import fretsim.api  # noqa: F401 - the one-off import cost stays out of the per-point figures
from fretsim.sweep import load_sweep, run_sweep

SWEEP = ROOT / "cases" / "sweeps" / "mccoll_load_stroke.yaml"


def loop_seconds(outdir: Path) -> tuple[float, float]:
    """The points' own loops, and their loops with the grid-error companion runs (the simulations a point needs
    for its numbers and their error bars): what is left of a sweep's time is its overhead."""
    with open(outdir / "table.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    loops = sum(float(r["wall_time_s"]) for r in rows)
    return loops, loops + sum(float(r.get("grid_error_wall_time_s") or 0.0) for r in rows)


def image_ms(sweep, tmp: Path, count: int = 5) -> float:
    """Mean time to build a point's results file in memory (its run's final flush), over a few points run here."""
    from fretsim.results import ResultsWriter
    from fretsim.sweep import run_point
    spent = []
    real = ResultsWriter.image

    def timed(self):
        t = time.perf_counter()
        data = real(self)
        spent.append(time.perf_counter() - t)
        return data

    ResultsWriter.image = timed
    try:
        for p in sweep.points[:count]:
            run_point((p.name, sweep.base_text, sweep.base_source, (*sweep.shared, *p.overrides),
                       tmp / f"image-{p.name}.h5", "run"))
    finally:
        ResultsWriter.image = real
    return 1e3 * sum(spent) / len(spent)


_BREAKDOWN = r"""
import json, sys, time
from pathlib import Path
import fretsim.api, fretsim.runner as R, fretsim.results as RS, fretsim.simulate as SM
from fretsim.sweep import load_sweep, run_point
sweep = load_sweep(sys.argv[1])
spent = {"simulations": 0.0, "flush": 0.0}
def timed(real, key):
    def wrapper(*a, **k):
        t = time.perf_counter()
        try:
            return real(*a, **k)
        finally:
            spent[key] += time.perf_counter() - t
    return wrapper
R.simulate = SM.simulate = timed(SM.simulate, "simulations")  # the run's loop and its companions (any version)
RS.ResultsWriter.flush = timed(RS.ResultsWriter.flush, "flush")
def point(i, p):
    run_point((p.name, sweep.base_text, sweep.base_source, (*sweep.shared, *p.overrides),
               Path(sys.argv[2]) / f"{i}.h5", "run"))
point(-1, sweep.points[0])  # warm-up
spent.update(simulations=0.0, flush=0.0)
t = time.perf_counter()
for i, p in enumerate(sweep.points):
    point(i, p)
spent["total"] = time.perf_counter() - t
print(json.dumps({k: 1e3 * v / len(sweep.points) for k, v in spent.items()}))
"""


def per_point(tree: Optional[Path], tmp: Path) -> dict:
    """ms a point in one process (no pool): in all, in its simulations (the loop and the grid-error companions),
    in writing its file; with ``tree``, of the fretsim in that source tree."""
    import json
    import os
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = str(tree) + os.pathsep + env.get("PYTHONPATH", "")
    work = Path(tempfile.mkdtemp(dir=tmp))
    out = subprocess.run([sys.executable, "-c", _BREAKDOWN, str(SWEEP), str(work)], env=env, cwd=tmp,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _fft_work(n: int) -> float:
    import numpy as np
    a = np.random.default_rng(0).random((256, 256))
    t = time.perf_counter()
    for _ in range(n):
        np.fft.rfft2(a)
    return time.perf_counter() - t


def machine_ceiling(n: int = 2000) -> float:
    """How much faster two processes do two equal CPU-bound jobs than one process does both: what the machine
    itself allows (two vCPUs of a shared host need not give 2×)."""
    import multiprocessing as mp
    t = time.perf_counter()
    _fft_work(n), _fft_work(n)
    serial = time.perf_counter() - t
    with mp.get_context("fork").Pool(2) as pool:
        t = time.perf_counter()
        pool.map(_fft_work, [n, n])
        parallel = time.perf_counter() - t
    return serial / parallel


def timed_sweep(outdir: Path, **kw) -> float:
    shutil.rmtree(outdir, ignore_errors=True)
    t = time.perf_counter()
    run_sweep(load_sweep(SWEEP), outdir, **kw)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out")
    ap.add_argument("--vs", type=Path, default=None,
                    help="another fretsim source tree (e.g. `git worktree add /tmp/prev HEAD~1`): a point's cost "
                         "broken down for both, in turns")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    sweep = load_sweep(SWEEP)
    rows: list = []
    if args.vs is not None:
        trees = {"this": None, "other": args.vs.resolve()}
        got: dict = {k: [] for k in trees}
        for _ in range(2):
            for k, tree in trees.items():
                got[k].append(per_point(tree, tmp))
        print("a point in one process, ms (best of 2):   in all   simulations   writing its file   overhead")
        for k in trees:
            best = min(got[k], key=lambda d: d["total"])
            over = best["total"] / best["simulations"] - 1
            print(f"  {k:5s} {'' if trees[k] is None else str(trees[k]):34s} {best['total']:7.0f} {best['simulations']:13.0f}"
                  f" {best['flush']:18.0f} {over:10.0%}")
            rows.append({"how": f"a point in one process, {k}", "seconds": round(best["total"] / 1e3, 4),
                         "points": len(sweep.points), "overhead_over_work": round(over, 3)})
    # one and two workers in turn, best of three each: the machine's speed drifts from minute to minute
    ones, twos = [], []
    for _ in range(3):
        ones.append(timed_sweep(tmp / "one", jobs=1))
        twos.append(timed_sweep(tmp / "two", jobs=2))
    one, two = min(ones), min(twos)
    loops, work = loop_seconds(tmp / "one")
    rows.append({"how": "sweep, 1 worker", "seconds": round(one, 2), "points": len(sweep.points),
                 "overhead_over_loops": round(one / loops - 1, 3), "overhead_over_work": round(one / work - 1, 3)})
    write_ms = image_ms(sweep, tmp)
    rows.append({"how": "sweep, 2 workers", "seconds": round(two, 2), "points": len(sweep.points),
                 "speed_up": round(one / two, 2)})
    ceiling = machine_ceiling()
    rows.append({"how": "control: numpy FFTs, 2 processes vs 1", "seconds": float("nan"), "points": 0,
                 "speed_up": round(ceiling, 2)})
    t = time.perf_counter()
    for p in sweep.points:  # what users did before: one process per point
        subprocess.run([sys.executable, "-m", "fretsim", "run", str(ROOT / "cases" / "mccoll_185N.yaml"), "-o",
                        str(tmp / f"{p.name}.h5"), "--quiet", *[a for o in (*sweep.shared, *p.overrides)
                                                                for a in ("--set", o)]],
                       check=True, capture_output=True)
    shell = time.perf_counter() - t
    rows.append({"how": "shell loop of fretsim run, 1 process each", "seconds": round(shell, 2),
                 "points": len(sweep.points), "overhead_over_loops": round(shell / loops - 1, 3),
                 "overhead_over_work": round(shell / work - 1, 3)})
    try:
        import distributed
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None) as cluster:
            with distributed.Client(cluster.scheduler_address) as client:  # an existing cluster's workers
                client.run(__import__, "fretsim.api")  # have their imports done: not a per-sweep cost
            dask = min(timed_sweep(tmp / "dask", dask=cluster.scheduler_address) for _ in range(2))
        rows.append({"how": "local Dask cluster, 2 workers", "seconds": round(dask, 2), "points": len(sweep.points),
                     "speed_up": round(one / dask, 2)})
    except ImportError:
        print("distributed is not installed: no Dask figure (pip install 'fretsim[dask]')")
    print(f"{len(sweep.points)} points of {SWEEP.name}; the points' own loops take {loops:.2f} s in all "
          f"({1e3 * loops / len(sweep.points):.0f} ms a point), {work:.2f} s with their grid-error companions "
          f"({1e3 * work / len(sweep.points):.0f} ms a point); building a point's results file takes {write_ms:.0f} ms "
          f"({write_ms * len(sweep.points) / 1e3 / work:.0%} of the simulations)")
    rows.append({"how": "results file image per point (ms)", "seconds": round(write_ms / 1e3, 4),
                 "points": len(sweep.points), "overhead_over_loops": round(write_ms * len(sweep.points) / 1e3 / loops, 3),
                 "overhead_over_work": round(write_ms * len(sweep.points) / 1e3 / work, 3)})
    for r in rows:
        extra = (f"overhead {r['overhead_over_work']:.0%} over the simulations ({r['overhead_over_loops']:.0%} "
                 f"over the loops alone)" if "overhead_over_loops" in r else
                 f"overhead {r['overhead_over_work']:.0%} over the simulations" if "overhead_over_work" in r else
                 f"{r['speed_up']:.2f}× one worker")
        secs = f"{r['seconds']:7.2f} s" if r["seconds"] == r["seconds"] else " " * 9
        print(f"  {r['how']:44s} {secs}  {extra}")
    write_csv(rows, args.out / "bench_sweep.csv")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
