"""Do `fretsim fit`'s 95 % intervals hold the truth 95 % of the time?  Synthetic measurements: the 2D McColl
185 N case's depths (both bodies) at 2 000, 6 000, 12 000 and 18 000 cycles from a run at known coefficients, each
multiplied by 1 + noise·N(0, 1) with its own seed; each draw fitted from the case's starting values.  Reported: how
many intervals hold the truth, their median half-width in ln k against the fitted values' own scatter, the bias,
and the runs a fit takes.

    python scripts/study_fit_coverage.py [--draws 30] [--noise 0.02]

Writes scripts/results/fit_coverage.txt.
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from _study import ROOT

from fretsim.api import load_case, run
from fretsim.fit import fit, read_measured

CASE = ROOT / "cases" / "mccoll_185N.yaml"
TRUTH = (2e-8, 3e-8)  # the case's own coefficients (moving, stationary), 1/MPa
CYCLES = (2000, 6000, 12000, 18000)
SETS = ["model.dimension=2d", "model.gap=stroke_average"]  # the fit's own model (fretsim.fit.STABLE_GAP)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=30)
    ap.add_argument("--noise", type=float, default=0.02)
    args = ap.parse_args()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        run(load_case(CASE, [*SETS, f"output.snapshots=[{', '.join(map(str, CYCLES))}]", "grid.error_estimate=none",
                             "jumping.tolerance=1e-3"]), Path(tmp) / "t.h5")
        depths = _depths(Path(tmp) / "t.h5")
        values, lows, highs, runs = [], [], [], []
        for seed in range(args.draws):
            rng = np.random.default_rng(seed)
            path = Path(tmp) / f"m{seed}.csv"
            path.write_text("cycle [cycles],max_wear_depth_stationary [um],max_wear_depth_moving [um]\n" + "".join(
                f"{c},{s * (1 + args.noise * rng.standard_normal())!r},"
                f"{m * (1 + args.noise * rng.standard_normal())!r}\n" for c, (s, m) in depths.items()))
            res = fit(CASE.read_text(), str(CASE), read_measured(path), overrides=SETS)
            values.append(res.values)
            lows.append(res.low)
            highs.append(res.high)
            runs.append(res.runs)
    v, lo, hi, truth_k = np.array(values), np.array(lows), np.array(highs), np.array(TRUTH)
    inside = ((lo <= truth_k) & (truth_k <= hi)).sum(axis=0)
    lines = [f"command: python scripts/study_fit_coverage.py --draws {args.draws} --noise {args.noise} "
             f"({time.strftime('%Y-%m-%d')}, {time.perf_counter() - t0:.0f} s)", "",
             f"{'':24s}{'k_m':>12s}{'k_s':>12s}",
             f"{'intervals holding truth':24s}" + "".join(f"{n:>9d}/{args.draws}" for n in inside),
             f"{'median half-width, ln':24s}" + "".join(f"{x:12.4f}" for x in np.median(np.log(hi / v), axis=0)),
             f"{'scatter of ln k (sd)':24s}" + "".join(f"{x:12.4f}" for x in np.std(np.log(v / truth_k), axis=0)),
             f"{'median bias of ln k':24s}" + "".join(f"{x:12.4f}" for x in np.median(np.log(v / truth_k), axis=0)),
             "", f"runs a fit takes: median {np.median(runs):.0f}, max {max(runs)}"]
    text = "\n".join(lines) + "\n"
    (ROOT / "scripts" / "results" / "fit_coverage.txt").write_text(text)
    print(text)


def _depths(path: Path) -> dict:
    from fretsim.results import read_results
    res = read_results(path)
    return {int(c): (float(res.fields["wear_depth_stationary"][i].max()),
                     float(res.fields["wear_depth_moving"][i].max()))
            for i, c in enumerate(res.fields["cycle"]) if int(c) in CYCLES}


if __name__ == "__main__":
    main()
