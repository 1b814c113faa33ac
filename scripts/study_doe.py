"""The paper's design of experiments (Table 2, Fig. 13) for adaptive cycle jumping.

Factors η ∈ {0.1, 0.55, 1}, ΔN_max ∈ {100, 345, 600}, ΔN_L ∈ {10, 55, 100}: all 27 runs of the 185 N case to
10 000 cycles, in 2D on the paper's coarse grid (15.75 µm, refined to 7a/40 as in its Fig. 10), against no
jumping (ΔN_L = 1) on the same grid.  Measured: wall time and the MAPE of the total wear depth (both bodies)
over the worn elements, as the paper's Fig. 13; also the pressure MAPE, which the paper did not report and
which is where an unstable jump shows.  Prints every run and the main effects (mean per factor level);
writes CSV and PNG.

    python scripts/study_doe.py [--out scripts/out]
"""
from __future__ import annotations

import argparse
import itertools
from pathlib import Path

import numpy as np

from _study import pressure_mape, run_case, write_csv
from fretsim.refine import mape

BASE = "cases/mccoll_185N.yaml"
COMMON = ["model.dimension=2d", "loading.cycles=10000", "output.snapshots=[10000]",
          "grid.coarse_element=[15.75 um]"]
LEVELS = {"eta": (0.1, 0.55, 1.0), "max": (100, 345, 600), "linear": (10, 55, 100)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "out"))
    args = ap.parse_args()
    out = Path(args.out)
    ref = run_case(BASE, [*COMMON, "jumping.scheme=linear", "jumping.linear=1"])
    assert ref.status == "complete", ref.message
    ref_total = ref.last.wear_moving + ref.last.wear_stationary
    rows = []
    print(f"reference (no jumping): {ref.solves} solves, {ref.seconds:.2f} s")
    print(f"{'eta':>5s} {'max':>5s} {'ΔN_L':>5s} {'time s':>8s} {'solves':>7s} {'rej':>4s} {'depth MAPE %':>13s} "
          f"{'p MAPE %':>9s} status")
    for eta, mx, lin in itertools.product(*LEVELS.values()):
        r = run_case(BASE, [*COMMON, "jumping.scheme=adaptive", f"jumping.eta={eta}", f"jumping.max={mx}",
                            f"jumping.linear={lin}"])
        depth = mape(ref_total, r.last.wear_moving + r.last.wear_stationary) if r.status == "complete" \
            else float("nan")
        row = dict(eta=eta, max=mx, linear=lin, seconds=r.seconds, solves=r.solves, rejected=r.rejected,
                   depth_mape=depth, pressure_mape=pressure_mape(r, ref), status=r.status)
        rows.append(row)
        print(f"{eta:5.2f} {mx:5d} {lin:5d} {r.seconds:8.3f} {r.solves:7d} {r.rejected:4d} {depth:13.3f} "
              f"{row['pressure_mape']:9.2f} {r.status} {r.message[:50]}", flush=True)
    print("\nmain effects (mean over the other factors; failed runs excluded):")
    effects = {}
    for factor, levels in LEVELS.items():
        for level in levels:
            sub = [r for r in rows if r[factor] == level and r["status"] == "complete"]
            t = float(np.mean([r["seconds"] for r in sub])) if sub else float("nan")
            e = float(np.mean([r["depth_mape"] for r in sub])) if sub else float("nan")
            effects[(factor, level)] = (t, e)
            print(f"  {factor:6s} = {level:<6}: mean time {t:.3f} s, mean depth MAPE {e:.3f} %  ({len(sub)} runs)")
    write_csv(rows, out / "doe.csv")
    chart(effects, out / "doe.png")
    print(f"# wrote {out / 'doe.csv'} and {out / 'doe.png'}")


def chart(effects, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 3, figsize=(11, 6))
    for k, (factor, levels) in enumerate(LEVELS.items()):
        t = [effects[(factor, lv)][0] for lv in levels]
        e = [effects[(factor, lv)][1] for lv in levels]
        axes[0, k].plot(range(3), t, "o-")
        axes[1, k].plot(range(3), e, "o-", color="C1")
        for ax in (axes[0, k], axes[1, k]):
            ax.set_xticks(range(3), [f"{lv:g}" for lv in levels])
            ax.set_xlabel({"eta": "η (–)", "max": "ΔN_max (cycles)", "linear": "ΔN_L (cycles)"}[factor])
            ax.grid(alpha=0.3)
        axes[0, k].set_ylabel("mean wall time (s)")
        axes[1, k].set_ylabel("mean MAPE of total wear depth (%)")
    fig.suptitle("Adaptive cycle jumping DOE (paper Table 2, Fig. 13): main effects")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
