"""The paper's Fig. 12: error of the pressure after 10 000 cycles against 1/ΔN_L, and the predicted limit.

The four cases of the paper's Table 1 (cylinder R 6 mm at 185 N and 500 N, cylinder R 80 mm at 185 N, ball
R 6 mm at 185 N; stroke 25 µm, case 1's wear coefficients), each on its 7a/40 grid (cylinders in 2D, the
ball in 3D).  For every linear jump ΔN_L the run goes to 10 000 cycles with the stability guards off, and
the MAPE of its final pressure against ΔN_L = 1 is recorded; the explicit stability limit predicted by
fretsim.jumping.explicit_stability_limit is printed beside the first jump where the error takes off.

    python scripts/study_linear_stability.py [--quick] [--out scripts/out]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

from _study import pressure_mape, run_case, write_csv

BASE = "cases/mccoll_185N.yaml"
COMMON = ["loading.cycles=10000", "output.snapshots=[10000]", "loading.stroke=25 um", "jumping.scheme=linear"]
TABLE1 = {
    "1: cylinder R6, 185 N": ["model.dimension=2d"],
    "2: cylinder R6, 500 N": ["model.dimension=2d", "loading.normal_load=500 N"],
    "3: cylinder R80, 185 N": ["model.dimension=2d", "geometry.radius=80 mm"],
    "4: ball R6, 185 N": ["model.dimension=3d", "geometry.type=ball_on_flat", "geometry.length="],
}
JUMPS = (2, 5, 10, 20, 30, 40, 50, 60, 80, 100, 150, 200, 300, 400)
UNSTABLE_MAPE = 5.0  # % : where the error leaves the smooth O(ΔN) trend


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="case 1 only, fewer jumps, 2000 cycles")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "out"))
    args = ap.parse_args()
    out = Path(args.out)
    cases = dict(list(TABLE1.items())[:1]) if args.quick else TABLE1
    jumps = (5, 20, 40, 60, 100) if args.quick else JUMPS
    common = [c.replace("10000", "2000") for c in COMMON] if args.quick else COMMON
    rows = []
    print(f"{'case':24s} {'ΔN_L':>6s} {'1/ΔN_L':>8s} {'p MAPE %':>10s} {'time s':>7s} status")
    for name, over in cases.items():
        ref = run_case(BASE, [*common, *over, "jumping.linear=1"], allow_unstable=True, stop_on_checkerboard=False)
        assert ref.status == "complete", ref.message
        limit = ref.summary["stability_limit_linear"]
        onset = None
        for j in jumps:
            r = run_case(BASE, [*common, *over, f"jumping.linear={j}"], allow_unstable=True,
                         stop_on_checkerboard=False)
            err = pressure_mape(r, ref)
            if onset is None and (not math.isfinite(err) or err > UNSTABLE_MAPE):
                onset = j
            rows.append(dict(case=name, jump=j, inverse_jump=1 / j, pressure_mape=err, seconds=r.seconds,
                             status=r.status, predicted_limit=limit))
            print(f"{name:24s} {j:6d} {1 / j:8.4f} {err:10.3f} {r.seconds:7.2f} {r.status} {r.message[:50]}",
                  flush=True)
        print(f"{name}: predicted explicit limit {limit:.1f} cycles; observed onset (MAPE > {UNSTABLE_MAPE} % or "
              f"failure) at ΔN_L = {onset}")
        for r in rows:
            if r["case"] == name:
                r["observed_onset"] = onset if onset is not None else float("nan")
    write_csv(rows, out / "linear_stability.csv")
    chart(rows, out / "linear_stability.png")
    print(f"# wrote {out / 'linear_stability.csv'} and {out / 'linear_stability.png'}")


def chart(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for k, case in enumerate(sorted({r["case"] for r in rows})):
        sub = [r for r in rows if r["case"] == case]
        xs = [r["inverse_jump"] for r in sub]
        ys = [r["pressure_mape"] if math.isfinite(r["pressure_mape"]) else 1e3 for r in sub]
        ax.loglog(xs, ys, "o-", color=f"C{k}", label=case)
        ax.axvline(1 / sub[0]["predicted_limit"], color=f"C{k}", ls="--", alpha=0.6)
    ax.set_xlabel("1 / ΔN_L (1/cycles)")
    ax.set_ylabel("MAPE of the pressure after the run vs ΔN_L = 1 (%)")
    ax.set_title("Linear jumping: error against 1/ΔN_L (dashed: predicted stability limit;\n"
                 "failed runs plotted at 1000 %)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
