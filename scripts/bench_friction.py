"""What friction costs, and what its increments buy.

1. The loops against a previous tree, side by side: ``python scripts/bench_friction.py --vs /path/to/old/checkout``
   (or ``FRETSIM_BASELINE=...``) runs McColl 185 N with the uniform model (3D, 18 000 cycles) and with Coulomb
   friction at mid-stroke (μ = 0.9, 2D and 3D) with this tree and with that one in turn, in fresh processes, and
   takes the ratio of the loop times pair by pair (skipped without a baseline; ``--vs-only`` stops there).
2. The loop time of McColl 185 N at μ = 0.9 under each cycle model, 2D and 3D (medians of 3).
3. Increments per half-stroke against accuracy: with the pressure at mid-stroke a half-stroke is one monotone
   increment, so the wear does not depend on their number (they only draw the loop); with the stroke resolved
   the pressure changes along it and the increments are a quadrature — the chart shows the depth error against
   the loop time (McColl 500 N, 2D, against 65 increments).

    python scripts/bench_friction.py [--quick] [--vs OLD_TREE [--vs-only] [--resolved]]

``--resolved`` adds the resolved stroke (2D and 3D, 3 pairs each) to the pairs against the old tree.

4. ``--ratio [--3d]``: issue 30's target, the resolved stroke against the mid-stroke Coulomb run on the same grid,
   side by side in this tree (McColl 185 N 2D, μ 0.9, grid.error_estimate none; 5 pairs, fresh processes, run in
   turn; ``--3d`` adds three 3D pairs, about two minutes): the ratio of the loop times, pair by pair.

Prints tables; writes scripts/out/bench_friction.{txt,csv,png}.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report, write_csv  # noqa: E402

from fretsim.api import load_case, run  # noqa: E402

OUT = ROOT / "scripts" / "out"
MU = "loading.friction_coefficient=0.9"
PROBE = ("import json, sys; from fretsim.api import load_case, run; "
         "o = run(load_case(sys.argv[1], sys.argv[2:])); print(json.dumps(o.summary['wall_time_s']))")


def loop_seconds(tree: str, case: str, overrides: list[str]) -> float:
    env = dict(os.environ, PYTHONPATH=tree)
    # (cwd: `python -c` puts the working directory first on sys.path, ahead of PYTHONPATH, so run from this repo's
    #  root both trees would import this one)
    out = subprocess.run([sys.executable, "-c", PROBE, case, *overrides], env=env, capture_output=True, text=True,
                         check=True, cwd=tree)
    return float(json.loads(out.stdout.strip().splitlines()[-1]))


VERSUS = (("uniform, 3D", []), ("coulomb (mid-stroke), 2D", [MU, "model.slip=coulomb", "model.stroke=mid_stroke", "model.dimension=2d"]),
          ("coulomb (mid-stroke), 3D", [MU, "model.slip=coulomb", "model.stroke=mid_stroke", "model.dimension=3d"]))
# with --resolved: the resolved stroke too, 3 pairs (a 3D pair takes about 3 minutes)
RESOLVED = (("coulomb (resolved), 2D", [MU, "model.slip=coulomb", "model.stroke=resolved", "model.dimension=2d",
                                        "grid.error_estimate=none"]),
            ("coulomb (resolved), 3D", [MU, "model.slip=coulomb", "model.stroke=resolved", "model.dimension=3d",
                                        "grid.error_estimate=none"]))


def versus(baseline: str, pairs: int, say: Report, rows: list, models=VERSUS) -> None:
    """This tree's loop time over the baseline's, pair by pair (each pair run back to back, this tree first)."""
    case = str(ROOT / "cases" / "mccoll_185N.yaml")
    say(f"the loop against {baseline}: McColl 185 N, 18 000 cycles, {pairs} pairs each (fresh processes)")
    say(f"{'model':<28}{'this s':>9}{'old s':>9}{'ratio':>8}{'min':>7}{'max':>7}")
    for label, sets in models:
        ratios, a_s, b_s = [], [], []
        for _ in range(pairs):
            a, b = loop_seconds(str(ROOT), case, sets), loop_seconds(baseline, case, sets)
            a_s.append(a), b_s.append(b), ratios.append(a / b)
        say(f"{label:<28}{np.median(a_s):>9.3f}{np.median(b_s):>9.3f}{np.median(ratios):>8.3f}{min(ratios):>7.3f}"
            f"{max(ratios):>7.3f}")
        rows.append({"what": f"{label} vs baseline", "this_s": float(np.median(a_s)), "baseline_s": float(np.median(b_s)),
                     "ratio_median": float(np.median(ratios)), "ratio_min": min(ratios), "ratio_max": max(ratios)})


def ratio(dims: tuple, say: Report, rows: list) -> None:
    """The resolved stroke's loop time over the mid-stroke run's, pair by pair (each pair back to back)."""
    case = str(ROOT / "cases" / "mccoll_185N.yaml")
    say("the resolved stroke against mid-stroke, McColl 185 N, μ 0.9, 18 000 cycles (fresh processes, in turn)")
    say(f"{'dim':<5}{'pairs':>6}{'resolved s':>12}{'mid s':>9}{'ratio':>8}{'min':>7}{'max':>7}")
    for dim in dims:
        pairs = 5 if dim == "2d" else 3
        base = [MU, "model.slip=coulomb", f"model.dimension={dim}", "grid.error_estimate=none"]
        res, mid = [], []
        for _ in range(pairs):
            res.append(loop_seconds(str(ROOT), case, base + ["model.stroke=resolved"]))
            mid.append(loop_seconds(str(ROOT), case, base + ["model.stroke=mid_stroke"]))
        r = [a / b for a, b in zip(res, mid)]
        say(f"{dim:<5}{pairs:>6}{np.median(res):>12.3f}{np.median(mid):>9.3f}{np.median(r):>8.2f}{min(r):>7.2f}"
            f"{max(r):>7.2f}")
        rows.append({"what": f"resolved / mid-stroke, {dim}", "this_s": float(np.median(res)),
                     "baseline_s": float(np.median(mid)), "ratio_median": float(np.median(r)),
                     "ratio_min": min(r), "ratio_max": max(r)})


def main(quick: bool = False, baseline: str = "", vs_only: bool = False, resolved: bool = False) -> None:
    say = Report()
    rows = []
    case = str(ROOT / "cases" / "mccoll_185N.yaml")
    if baseline:
        versus(baseline, 3 if quick else 7, say, rows)
        if resolved:
            versus(baseline, 3, say, rows, RESOLVED)
        if vs_only:
            OUT.mkdir(parents=True, exist_ok=True)
            say.write(OUT / "bench_friction_vs.txt")
            write_csv(rows, OUT / "bench_friction_vs.csv")
            print(f"wrote {OUT / 'bench_friction_vs.txt'}, .csv")
            return
    say("")
    say("McColl 185 N, μ = 0.9, 18 000 cycles: loop time (s, median of 3) and the flat's centre-line depth")
    say(f"{'model':<28}{'dim':<5}{'loop s':>9}{'solves':>8}{'depth µm':>10}  status")
    for label, model in (("uniform", ["model.slip=uniform"]), ("coulomb (mid-stroke)", ["model.slip=coulomb", "model.stroke=mid_stroke"]),
                         ("coulomb, stroke resolved", ["model.slip=coulomb", "model.stroke=resolved"])):
        for dim in ("2d", "3d"):
            times, last = [], None
            for _ in range(1 if quick or "resolved" in label else 3):
                last = run(load_case(case, [MU, f"model.dimension={dim}", *model]))
                times.append(last.summary["wall_time_s"])
            s = last.summary
            say(f"{label:<28}{dim:<5}{np.median(times):>9.2f}{s['contact_solves']:>8}"
                f"{s['centre_wear_depth_stationary_um']:>10.4f}  {last.status} {last.message[:60]}")
            rows.append({"what": label, "dimension": dim, "loop_s": float(np.median(times)),
                         "solves": s["contact_solves"], "depth_um": s["centre_wear_depth_stationary_um"],
                         "status": last.status})
    say("")
    say("increments per half-stroke against the depth error (against 65) and the loop time, 2D")
    chart = {}
    for label, name, model in (("mid-stroke, McColl 185 N", "mccoll_185N", ["model.slip=coulomb", "model.stroke=mid_stroke"]),
                               ("resolved, McColl 500 N", "mccoll_500N", ["model.slip=coulomb",
                                                                           "model.stroke=resolved"])):
        points = []
        ref = None
        for n in (65, 33, 17, 9, 5, 3, 1) if not quick else (17, 5, 1):
            o = run(load_case(str(ROOT / "cases" / f"{name}.yaml"), [MU, "model.dimension=2d", *model,
                                                                      f"model.increments={n}"]))
            s = o.summary
            ref = ref or s
            err = max(abs(s[k] / ref[k] - 1) for k in ("centre_wear_depth_stationary_um", "max_wear_depth_moving_um"))
            points.append((n, s["wall_time_s"], err))
            say(f"  {label:<26} n = {n:>3}: loop {s['wall_time_s']:7.2f} s, depth error {err:.2e}  {o.status}")
            rows.append({"what": f"increments, {label}", "increments": n, "loop_s": s["wall_time_s"],
                         "depth_error": err, "status": o.status})
        chart[label] = points
    OUT.mkdir(parents=True, exist_ok=True)
    say.write(OUT / "bench_friction.txt")
    write_csv(rows, OUT / "bench_friction.csv")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for label, points in chart.items():
        n, t, e = zip(*points[1:])
        ax.plot(t, np.maximum(e, 1e-16), "o-", label=label)
        for ni, ti, ei in zip(n, t, e):
            ax.annotate(str(ni), (ti, max(ei, 1e-16)), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("loop time (s)")
    ax.set_ylabel("depth error against 65 increments")
    ax.set_title("increments per half-stroke (labels): cost against accuracy, 2D")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "bench_friction.png", dpi=130)
    print(f"wrote {OUT / 'bench_friction.txt'}, .csv, .png")


if __name__ == "__main__":
    args = sys.argv[1:]
    if "--ratio" in args:
        say_, rows_ = Report(), []
        ratio(("2d", "3d") if "--3d" in args else ("2d",), say_, rows_)
        OUT.mkdir(parents=True, exist_ok=True)
        say_.write(OUT / "bench_friction_ratio.txt")
        write_csv(rows_, OUT / "bench_friction_ratio.csv")
        print(f"wrote {OUT / 'bench_friction_ratio.txt'}, .csv")
        sys.exit(0)
    vs = args[args.index("--vs") + 1] if "--vs" in args else os.environ.get("FRETSIM_BASELINE", "")
    main("--quick" in args, vs, "--vs-only" in args, "--resolved" in args)
