"""How quickly the command line answers, and the figure set of a 3D run (issue #11).

Times whole commands as a user starts them (a fresh Python process each, median of several runs after a
warm-up): `python -c pass` as the floor any Python command pays, `fretsim --help`, `summary`, `check`,
`plot` of a 3D results file, and `run` of the 185 N case in 3D beside its own loop time.  Then draws the
figures of that run into DIR/figures (the README shows them).

    python scripts/bench_cli.py [--runs 7] [--out scripts/out] [--figures docs/figures] [--vs OTHER_TREE]

The package is byte-compiled first, as an installed one is.  With --vs, another source tree (a git worktree of
an earlier commit) is timed in the same run, the two interleaved run by run, and the ratio printed.

Prints a table and writes bench_cli.csv.  The machine is shared: read the medians, and the ratios to the
`python -c pass` floor.
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Optional

from _study import ROOT, write_csv

CASE = ROOT / "cases" / "mccoll_185N.yaml"


def _run(cmd: list[str], cwd: Path, env: dict) -> float:
    t = time.perf_counter()
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env)
    spent = time.perf_counter() - t
    if r.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed: {r.stderr[-500:]}")
    return spent


def _env(tree: Optional[Path]) -> dict:
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = str(tree) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _compile(env: dict, cwd: Path) -> Path:
    """Byte-compile the fretsim that ``env`` imports, as `pip install` does: a user's commands do not compile
    the package's sources at every start (this machine sets PYTHONDONTWRITEBYTECODE, so nothing else would)."""
    where = subprocess.run([sys.executable, "-c", "import fretsim, os; print(os.path.dirname(fretsim.__file__))"],
                           env=env, cwd=cwd, capture_output=True, text=True, check=True).stdout.strip()
    subprocess.run([sys.executable, "-m", "compileall", "-q", where], env=env, check=True, capture_output=True)
    return Path(where)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out")
    ap.add_argument("--figures", type=Path, default=None, help="also keep the figures here (e.g. docs/figures)")
    ap.add_argument("--vs", type=Path, default=None,
                    help="another fretsim source tree (e.g. `git worktree add /tmp/prev HEAD~1`): each command is "
                         "timed for both, runs interleaved, and the ratio printed")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench-cli-"))
    fretsim = [sys.executable, "-m", "fretsim"]
    trees = {"this": None} if args.vs is None else {"this": None, "other": args.vs.resolve()}
    envs = {k: _env(v) for k, v in trees.items()}
    for k, env in envs.items():
        print(f"{k}: fretsim from {_compile(env, tmp)} (byte-compiled)")
        subprocess.run([*fretsim, "run", str(CASE), "-o", f"r_{k}.h5", "--quiet"], cwd=tmp, check=True,
                       capture_output=True, env=env)
    commands = {
        "python -c pass (the floor)": [sys.executable, "-c", "pass"],
        "fretsim --help": [*fretsim, "--help"],
        "fretsim summary r.h5": [*fretsim, "summary", "r_{k}.h5"],
        "fretsim check mccoll_185N.yaml": [*fretsim, "check", str(CASE)],
        "fretsim plot r.h5 (3D, 4 PNG figures)": [*fretsim, "plot", "r_{k}.h5", "-o", "figs"],
        "fretsim plot r.h5 --jobs 1 (one process)": [*fretsim, "plot", "r_{k}.h5", "-o", "figs1", "--jobs", "1"],
        "fretsim run mccoll_185N.yaml (3D, 18 000 cycles)": [*fretsim, "run", str(CASE), "-o", "run_{k}.h5",
                                                            "--overwrite", "--quiet"],
    }
    rows = []
    floor = None
    head = f"{'command':50s} {'median s':>9s} {'min s':>7s} {'max s':>7s} {'over floor s':>12s}"
    print(head + (f" {'other s':>8s} {'this/other':>10s}" if args.vs else ""))
    for label, cmd in commands.items():
        times: dict = {k: [] for k in trees}
        for k in trees:  # warm-up: the file cache, matplotlib's font cache
            _run([c.format(k=k) for c in cmd], tmp, envs[k])
        for _ in range(args.runs):
            for k in trees:
                times[k].append(_run([c.format(k=k) for c in cmd], tmp, envs[k]))
        med = {k: statistics.median(v) for k, v in times.items()}
        floor = med["this"] if floor is None else floor
        row = {"command": label, "median_s": round(med["this"], 3), "min_s": round(min(times["this"]), 3),
               "max_s": round(max(times["this"]), 3), "over_floor_s": round(med["this"] - floor, 3),
               "runs": args.runs}
        line = (f"{label:50s} {med['this']:9.3f} {min(times['this']):7.3f} {max(times['this']):7.3f} "
                f"{med['this'] - floor:12.3f}")
        if args.vs:
            row.update(other_median_s=round(med["other"], 3), ratio=round(med["this"] / med["other"], 3))
            line += f" {med['other']:8.3f} {med['this'] / med['other']:10.2f}"
        rows.append(row)
        print(line, flush=True)
    from fretsim.results import read_results
    loop = read_results(tmp / "run_this.h5").summary["wall_time_s"]
    print(f"  (the run's own loop: {loop:.2f} s of it)")
    write_csv(rows, args.out / "bench_cli.csv")
    if args.figures is not None:
        args.figures.mkdir(parents=True, exist_ok=True)
        subprocess.run([*fretsim, "plot", "r_this.h5", "-o", str(args.figures.resolve()), "--dpi", "100"], cwd=tmp,
                       check=True, capture_output=True)
        for p in args.figures.glob("r_this_*.png"):  # the README's names
            p.replace(p.with_name(p.name.replace("r_this_", "r_")))
        print(f"figures in {args.figures}: {', '.join(sorted(p.name for p in args.figures.glob('*.png')))}")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
