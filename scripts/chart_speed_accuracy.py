"""The speed-accuracy chart: wall time against the error of the flat's final centre-line wear depth, and
against the error of the final pressure field (relative L2 over the grid).

Two cases, both 3D: the 185 N McColl case (18 000 cycles) and Kirk's 450 N case (1 000 000 cycles).
Every method combination: solver (cg; msm only on the coarse grid, where a dense simplex is affordable),
refinement on/off (paper Eqs. 11-12, coarse 15.75 µm × 1000 µm as in the paper's Fig. 10; msm on the 185 N case
only, see combos()), and stepping:
linear (explicit, half the stability limit), adaptive (the paper's preset, scaled to the grid), implicit (backward
Euler under error control) and bdf2 (the default: second order under error control), each at several
tolerances.  The reference is explicit stepping with small linear jumps
on the full grid (185 N: ΔN = 1, no jumping; Kirk: ΔN = 20, a third of its limit, because 10^6 single-cycle solves take hours —
on the 185 N case ΔN 21 and 1 differ by < 1e-4).  Prints a table, writes CSV and PNG with the Pareto front
marked on each accuracy axis, and a table of contact solves against cycles for the default scheme.  The default's
time is also given as a ratio to the no-jump run measured here (185 N) and to a no-jump run's cost extrapolated
from 2 000 single-cycle solves (Kirk: 10⁶ of them would take hours).

    python scripts/chart_speed_accuracy.py [--quick] [--out scripts/out]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from _study import depth_error, pareto, run_case, write_csv

COARSE = "grid.coarse_element=[15.75 um, 1000 um]"
CASES = {
    "mccoll_185N": ("cases/mccoll_185N.yaml", ["jumping.scheme=linear", "jumping.linear=1"]),
    "kirk_450N": ("cases/kirk_450N_20Hz.yaml", ["jumping.scheme=linear", "jumping.linear=20"]),
}


def combos(quick: bool, case: str):
    out = []
    for refine in (False, True):
        grid = [COARSE] if refine else []
        tag = "refined" if refine else "full grid"
        out.append((f"cg, {tag}, linear (default ΔN_L)", ["jumping.scheme=linear", *grid]))
        out.append((f"cg, {tag}, adaptive (paper preset)", ["jumping.preset=paper", *grid]))
        for scheme in ("bdf2", "implicit"):
            for tol in ((1e-2,) if quick else (1e-3, 3e-3, 1e-2, 3e-2, 1e-1)):
                out.append((f"cg, {tag}, {scheme} tol {tol:g}", [f"jumping.scheme={scheme}",
                                                                 f"jumping.tolerance={tol}", *grid]))
    if case == "mccoll_185N":
        # the dense simplex costs O(k³) a pivot in the contact size k: ~300 coarse elements in contact here, but
        # ~1500 on Kirk's 2.4 mm scar, where one solve takes minutes: it is raced on the 185 N case only
        out.append(("msm, refined, bdf2 tol 0.01", ["solver.method=msm", COARSE]))
        out.append(("msm, refined, adaptive (paper preset)", ["solver.method=msm", "jumping.preset=paper", COARSE]))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="185 N only, 2000 cycles, few combinations")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "out"))
    args = ap.parse_args()
    out = Path(args.out)
    rows = []
    cases = {"mccoll_185N": CASES["mccoll_185N"]} if args.quick else CASES
    extra = ["loading.cycles=2000", "output.snapshots=[2000]"] if args.quick else []
    for name, (path, ref_over) in cases.items():
        ref = run_case(path, [*ref_over, *extra], "reference")
        assert ref.status == "complete", ref.message
        print(f"\n{name}: reference {ref.label}: {ref.solves} solves, {ref.seconds:.1f} s, centre depth "
              f"{ref.summary['centre_wear_depth_stationary_um']:.4f} µm")
        print(f"{'method':42s} {'time s':>8s} {'solves':>7s} {'rej':>4s} {'depth err':>10s} {'p L2 err':>9s}  status")
        for label, over in combos(args.quick, name):
            r = run_case(path, [*over, *extra], label)
            row = dict(case=name, method=label, status=r.status, seconds=r.seconds, solves=r.solves,
                       rejected=r.rejected, depth_error=depth_error(r, ref), pressure_error=pressure_l2(r, ref),
                       centre_depth_um=r.summary.get("centre_wear_depth_stationary_um", math.nan),
                       default=label == DEFAULT, message=r.message[:120])
            rows.append(row)
            print(f"{label:42s} {r.seconds:8.3f} {r.solves:7d} {r.rejected:4d} {row['depth_error']:10.2e} "
                  f"{row['pressure_error']:9.2e}  {r.status} {r.message[:60]}", flush=True)
        sub = [r for r in rows if r["case"] == name]
        for axis in ("depth_error", "pressure_error"):
            front = pareto([(r["seconds"], r[axis]) for r in sub])
            print(f"Pareto front ({axis.replace('_', ' ')}):", "; ".join(sub[i]["method"] for i in front))
            for i, r in enumerate(sub):
                r[f"pareto_{axis}"] = i in front
        default = next(r for r in sub if r["default"])
        no_jump = ref.seconds if name == "mccoll_185N" and not args.quick else no_jump_estimate(path, extra)
        print(f"default: {default['seconds']:.3f} s, {default['solves']} solves; the no-jump run "
              f"{'measured' if name == 'mccoll_185N' and not args.quick else 'extrapolated'}: {no_jump:.1f} s "
              f"(ratio {no_jump / default['seconds']:.0f}×); on both fronts: "
              f"{default['pareto_depth_error'] and default['pareto_pressure_error']}")
        for r in sub:
            r["no_jump_seconds"] = no_jump
    write_csv(rows, out / "speed_accuracy.csv")
    growth = solves_vs_cycles(args.quick)
    write_csv(growth, out / "solves_vs_cycles.csv")
    chart(rows, out / "speed_accuracy.png")
    print(f"# wrote {out / 'speed_accuracy.csv'}, {out / 'solves_vs_cycles.csv'}, {out / 'speed_accuracy.png'}")


DEFAULT = "cg, full grid, bdf2 tol 0.01"


def pressure_l2(run, ref) -> float:
    if run.last is None or run.status != "complete":
        return float("nan")
    return float(np.linalg.norm(run.last.pressure - ref.last.pressure) / np.linalg.norm(ref.last.pressure))


def no_jump_estimate(path: str, extra: list[str]) -> float:
    """A no-jump run's time, extrapolated from 2 000 single-cycle solves of the same case."""
    cycles = 2000
    r = run_case(path, ["jumping.scheme=linear", "jumping.linear=1", f"loading.cycles={cycles}",
                        f"output.snapshots=[{cycles}]"])
    from fretsim.case import load_case
    total = load_case(Path(__file__).resolve().parent.parent / path, extra).loading.cycles
    return r.seconds * total / cycles


def solves_vs_cycles(quick: bool):
    print("\ncontact solves against cycles, default settings (bdf2), 185 N case, 3D:")
    rows = []
    for n in ((2000, 20000) if quick else (2000, 20000, 200000, 2000000)):
        r = run_case("cases/mccoll_185N.yaml", [f"loading.cycles={n}", f"output.snapshots=[{n}]"])
        rows.append(dict(cycles=n, solves=r.solves, seconds=r.seconds))
        print(f"  {n:>9d} cycles: {r.solves:4d} solves, {r.seconds:.2f} s")
    return rows


def chart(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cases = sorted({r["case"] for r in rows})
    axes_of = (("depth_error", "relative error of the flat's centre-line wear depth (–)"),
               ("pressure_error", "relative L2 error of the final pressure field (–)"))
    fig, axes = plt.subplots(2, len(cases), figsize=(7 * len(cases), 10), squeeze=False)
    for col, case in enumerate(cases):
        sub = [r for r in rows if r["case"] == case]
        for row, (axis, ylabel) in enumerate(axes_of):
            ax = axes[row][col]
            for r in sub:
                if not np.isfinite(r["seconds"]):
                    continue  # refused before running: listed in the table, not plotted
                ok = r["status"] == "complete" and np.isfinite(r[axis])
                err = max(r[axis], 1e-7) if ok else 1.0
                marker = "*" if r.get("default") else ("o" if ok else "x")
                color = "C3" if r.get(f"pareto_{axis}") else ("C0" if ok else "0.5")
                ax.loglog(r["seconds"], err, marker, color=color, ms=12 if r.get("default") else 7)
                ax.annotate(r["method"] + ("" if ok else " (failed)"), (r["seconds"], err), fontsize=6,
                            xytext=(3, 3), textcoords="offset points")
            front = sorted((r["seconds"], max(r[axis], 1e-7)) for r in sub if r.get(f"pareto_{axis}"))
            if front:
                ax.loglog(*zip(*front), "-", color="C3", alpha=0.6, label="Pareto front")
            ax.set_xlabel("wall time of the run's loop (s)")
            ax.set_ylabel(ylabel)
            ax.set_title(f"{case} (3D): ★ default (bdf2, tol 0.01), × failed (plotted at 1)", fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
