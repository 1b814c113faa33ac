"""How far is each reported number from the converged one, on the default grid, and does the run say so?

For the Table 4 cases, in 2D and 3D, three grids along x are run at the default stepping: the paper's rule
(7a/40, `grid.rule: paper`), the default (`grid.rule: accuracy`: the element a third of model.accuracy of the
estimated scar width) and the default's elements doubled.  Each is compared with a converged reference made
here: the default grid's elements ×REF along x (in 3D the rows along the line are kept) at a tenth of the
stepping tolerance.  Reported for each quantity the summary prints — the deepest point of either body, both
scar widths, the final pressure field (L2, at the coarser grid's centres) and its peak — the actual error, the
run's own estimate (``estimated_error_*``, stepping + grid from the companion run) and the run's time,
companion included for the default.

    python scripts/study_grid_error.py [--dims 2d,3d] [--cases mccoll_185N,...] [--out scripts/results]

Prints a table and writes grid_error.csv and grid_error.png (each quantity's actual error against the run's
cost, the default marked; the estimate beside it).
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from _study import ROOT, write_csv

CASES = ["mccoll_185N", "mccoll_500N", "mccoll_1670N", "mccoll_500N_10um", "kirk_450N_20Hz", "kirk_450N_100Hz",
         "kirk_450N_200Hz", "s132_250N_100um"]  # the paper's Table 4
QUANTITIES = ("depth", "width", "pressure", "max_pressure")
REF = 4


def run(name: str, overrides: list[str]):
    from fretsim.api import load_case, run as run_case
    t = time.perf_counter()
    out = run_case(load_case(ROOT / "cases" / f"{name}.yaml", overrides), None)
    if out.status != "complete":
        raise RuntimeError(f"{name} {overrides}: {out.status} {out.message}")
    return out, time.perf_counter() - t


def on_grid(p: np.ndarray, x_from: np.ndarray, x: np.ndarray) -> np.ndarray:
    """A field read at other centres along x (same rows), linearly."""
    return np.stack([np.interp(x, x_from, row) for row in np.atleast_2d(p)])


def numbers(out) -> dict:
    s = out.summary
    return {"depth": max(s["max_wear_depth_stationary_um"], s["max_wear_depth_moving_um"]),
            "width_s": s["scar_width_stationary_mm"], "width_m": s["scar_width_moving_mm"],
            "max_pressure": s["max_pressure_MPa"]}


def errors(out, ref) -> dict:
    a, r = numbers(out), numbers(ref)
    e = {"depth": abs(a["depth"] / r["depth"] - 1),
         "width": max(abs(a["width_s"] / r["width_s"] - 1), abs(a["width_m"] / r["width_m"] - 1)),
         "max_pressure": abs(a["max_pressure"] / r["max_pressure"] - 1)}
    x = out.setup.grid.x
    pr = on_grid(ref.last.pressure, ref.setup.grid.x, x)
    e["pressure"] = float(np.linalg.norm(out.last.pressure - pr) / np.linalg.norm(pr))
    return e


def at_elements(name: str, dim: str, base, factor: float, tolerance: float, extra=()) -> list[str]:
    f = base.case
    elements = [int(round(f.elements[0] * factor)) | 1] + list(f.elements[1:])
    return [f"model.dimension={dim}", f"jumping.tolerance={tolerance}", "grid.error_estimate=none",
            f"grid.domain=[{', '.join(f'{d!r} mm' for d in f.domain)}]",
            f"grid.elements=[{', '.join(map(str, elements))}]", *extra]


def study(name: str, dim: str, pressures=()) -> list[dict]:
    default, t_default = run(name, [f"model.dimension={dim}"])
    paper, t_paper = run(name, [f"model.dimension={dim}", "grid.rule=paper", "grid.error_estimate=none"])
    alone, t_alone = run(name, [f"model.dimension={dim}", "grid.error_estimate=none"])
    double, t_double = run(name, at_elements(name, dim, default, 2, default.case.step_tolerance))
    runs = [("paper 7a/40", paper, t_paper), ("default", default, t_default),
            ("default, no companion", alone, t_alone), ("default ×2", double, t_double)]
    for q in pressures:
        out, seconds = run(name, [f"model.dimension={dim}", f"model.pressure_accuracy={q}"])
        runs.append((f"pressure_accuracy {q:g}", out, seconds))
    # the reference at least REF× the default's elements along x and twice the finest run's
    factor = max(REF, 2 * max(out.case.elements[0] for _, out, _ in runs) / default.case.elements[0])
    ref, _ = run(name, at_elements(name, dim, default, factor, default.case.step_tolerance / 10))
    rows = []
    for label, out, seconds in runs:
        e = errors(out, ref)
        rows.append({"case": name, "dim": dim, "grid": label, "elements": "x".join(map(str, out.case.elements)),
                     "seconds": seconds, "cost_vs_paper": seconds / t_paper,
                     **{f"actual_{q}": e[q] for q in QUANTITIES},
                     **{f"estimated_{q}": out.summary.get(f"estimated_error_{q}", float("nan")) for q in QUANTITIES}})
    return rows


def chart(rows: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(16, 4), constrained_layout=True)
    marks = {"paper 7a/40": "s", "default": "o", "default ×2": "^",
             **{g: "D" for g in dict.fromkeys(r["grid"] for r in rows) if g.startswith("pressure_accuracy")}}
    for ax, q in zip(axes, QUANTITIES):
        for label, m in marks.items():
            sel = [r for r in rows if r["grid"] == label]
            ax.scatter([r["cost_vs_paper"] for r in sel], [r[f"actual_{q}"] for r in sel], marker=m, label=label)
        sel = [r for r in rows if r["grid"] == "default"]
        ax.scatter([r["cost_vs_paper"] for r in sel], [r[f"estimated_{q}"] for r in sel], marker="x", c="k",
                   label="default: its estimate")
        ax.axhline(0.01, color="grey", lw=0.8, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("run time / the paper grid's run (1)")
        ax.set_ylabel(f"relative error of {q.replace('_', ' ')} (1)")
        ax.set_title(q.replace("_", " "))
    axes[0].legend(fontsize=7)
    fig.savefig(path, dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dims", default="2d,3d")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--out", default=str(ROOT / "scripts" / "results"))
    ap.add_argument("--pressure", default="", help="model.pressure_accuracy values to add, e.g. 0.05,0.02")
    args = ap.parse_args()
    grid_axis(args.cases.split(","), args.dims.split(","), [float(q) for q in args.pressure.split(",") if q],
              Path(args.out))


def grid_axis(cases: list[str], dims: list[str], pressures: list[float], out: Path) -> list[dict]:
    """The study itself (also `calibrate_stepping.py --grid`): prints the table, writes the CSV and the chart."""
    rows = []
    print(f"{'case':17s} {'dim':3s} {'grid':22s} {'elements':>9s} {'cost':>5s}  "
          + "  ".join(f"{q:>19s}" for q in QUANTITIES))
    print(f"{'':60s}  " + "  ".join(f"{'actual':>9s} {'estim.':>9s}" for _ in QUANTITIES))
    for dim in dims:
        for name in cases:
            for row in study(name, dim, pressures):
                rows.append(row)
                print(f"{name:17s} {dim:3s} {row['grid']:22s} {row['elements']:>9s} {row['cost_vs_paper']:5.2f}  "
                      + "  ".join(f"{row['actual_' + q]:9.2e} {row['estimated_' + q]:9.2e}" for q in QUANTITIES),
                      flush=True)
    out.mkdir(parents=True, exist_ok=True)
    stem = "grid_error_pressure" if pressures else "grid_error"
    write_csv(rows, out / f"{stem}.csv")
    chart(rows, out / f"{stem}.png")
    for q in pressures:
        p = [r for r in rows if r["grid"] == f"pressure_accuracy {q:g}"]
        print(f"pressure_accuracy {q:g}: the field's actual error ≤ {q:g} in {sum(r['actual_pressure'] <= q for r in p)}"
              f" of {len(p)}, its estimate ≤ {q:g} in {sum(r['estimated_pressure'] <= q for r in p)}, estimate ≥ actual"
              f" in {sum(r['actual_pressure'] <= r['estimated_pressure'] for r in p)}; cost against the default "
              f"(both with companions): median {np.median([r['seconds'] / d['seconds'] for r, d in zip(p, [r for r in rows if r['grid'] == 'default'])]):.2f}×")
    d = [r for r in rows if r["grid"] == "default"]
    honest = {q: sum(r[f"actual_{q}"] <= r[f"estimated_{q}"] for r in d) for q in QUANTITIES}
    within4 = {q: sum(r[f"estimated_{q}"] <= 4 * r[f"actual_{q}"] for r in d) for q in QUANTITIES}
    print(f"\ndefaults, {len(d)} runs: actual ≤ estimate {honest}; estimate ≤ 4× actual {within4}")
    print(f"cost of the default (companion included) against the paper's grid: median "
          f"{np.median([r['cost_vs_paper'] for r in d]):.2f}×; without the companion "
          f"{np.median([r['cost_vs_paper'] for r in rows if r['grid'] == 'default, no companion']):.2f}×")
    return rows


if __name__ == "__main__":
    main()
