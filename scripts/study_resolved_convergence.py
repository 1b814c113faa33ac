"""Does the resolved stroke converge?  Grid and increment halving for model.stroke: resolved (issue 30's baseline).

For McColl's four Table 4 cases (μ = 0.9, 2D; with --3d also in 3D, slower) this runs the resolved stroke on the
automatic (accuracy) grid, on the same domain with twice and four times the elements, and with 9, 19 and 37
increments per half-stroke, and the mid-stroke Coulomb cycle on the same grids beside it.  It reports the flat's
centre-line depth, its scar width, its worn volume, the largest pressure over the recorded states and the loop
time, and each quantity's change when the grid or the increments are halved, as a share of model.accuracy/3 (the
issue's bar: below 1 means converged enough).  Report, do not tune.

    python scripts/study_resolved_convergence.py [--quick] [--3d] [--bodies] [--ball]

``--bodies`` adds McColl's FE bodies (flat 12 × 6 mm, cylinder held 6 mm up).  ``--ball`` runs the partial-slip
ball instead (3D, its own μ 0.8; both axes' elements doubled; the deepest point, since the stuck centre does not
wear).  Prints a table; writes scripts/out/resolved_convergence{,_bodies,_ball}.{txt,csv}.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report, write_csv  # noqa: E402

from fretsim.api import load_case, run  # noqa: E402
from fretsim.plan import prepare  # noqa: E402

OUT = ROOT / "scripts" / "out"
CASES = ("mccoll_185N", "mccoll_500N", "mccoll_1670N", "mccoll_500N_10um")
BODIES = ["geometry.flat_width=12 mm", "geometry.flat_thickness=6 mm", "geometry.moving_height=6 mm"]
QUANTITIES = (("depth_um", "centre_wear_depth_stationary_um"), ("width_mm", "scar_width_stationary_mm"),
              ("volume_mm3", "wear_volume_stationary_mm3"))
BALL_QUANTITIES = (("depth_um", "max_wear_depth_stationary_um"),) + QUANTITIES[1:]


def one(name: str, overrides: list[str], quantities: tuple = QUANTITIES) -> dict:
    t = time.perf_counter()
    try:
        out = run(load_case(ROOT / "cases" / f"{name}.yaml", overrides))
    except Exception as exc:  # a refused or failed configuration is a result here
        return {"status": f"error: {exc}".splitlines()[0][:60], "seconds": time.perf_counter() - t}
    s = out.summary
    row = {"status": out.status, "seconds": s.get("wall_time_s", np.nan)}
    for key, summary_key in quantities:
        row[key] = s.get(summary_key, np.nan)
    row["peak_pressure_mpa"] = s.get("max_pressure_MPa", np.nan)  # the largest over the recorded states
    return row


def main(quick: bool = False, three_d: bool = False, bodies: bool = False, ball: bool = False) -> None:
    say = Report()
    rows = []
    dims = ("3d",) if ball else ("2d", "3d") if three_d else ("2d",)
    for name in ("ball_partial_slip",) if ball else CASES[:1] if quick else CASES:
        for dim in dims:
            base = [f"model.dimension={dim}", "model.slip=coulomb", "grid.error_estimate=none",
                    *([] if ball else ["loading.friction_coefficient=0.9"]), *(BODIES if bodies else [])]
            case = load_case(ROOT / "cases" / f"{name}.yaml", base)
            grid = prepare(case)[0].grid
            accuracy = case.accuracy
            nx, ny = grid.shape[1], grid.shape[0]
            domain = [f"{grid.x[-1] - grid.x[0] + grid.dx:.9g} mm"] + (
                [] if dim == "2d" else [f"{grid.y[-1] - grid.y[0] + grid.dy:.9g} mm"])
            say(f"\n{name} {dim}: automatic grid {nx} × {ny}, dx {grid.dx * 1e3:.3g} µm; model.accuracy {accuracy:g}")
            say(f"{'model':<12}{'elements':>9}{'incr':>6}{'status':>10}{'depth µm':>10}{'width mm':>10}"
                f"{'volume mm3':>12}{'p max MPa':>11}{'s':>7}")
            grids = (1, 2) if quick or dim == "3d" else (1, 2, 4)
            results = {}
            for stroke, incs in (("mid_stroke", (9,)), ("resolved", (9, 19) if quick or ball else (9, 19, 37))):
                for g in grids:
                    for inc in incs:
                        if stroke == "resolved" and g == 4 and inc == 37:
                            continue
                        elements = [str(g * nx)] + ([] if dim == "2d" else [str((g if ball else 1) * ny)])
                        r = one(name, [*base, f"model.stroke={stroke}", f"model.increments={inc}",
                                       f"grid.domain=[{', '.join(domain)}]", f"grid.elements=[{', '.join(elements)}]"],
                                BALL_QUANTITIES if ball else QUANTITIES)
                        r.update({"case": name, "dimension": dim, "stroke": stroke, "elements": g * nx,
                                  "increments": inc, "bodies": bodies})
                        results[(stroke, g, inc)] = r
                        rows.append(r)
                        label = f"{g * nx}×{g * ny}" if ball else str(g * nx)
                        say(f"{stroke:<12}{label:>9}{inc:>6}{r['status'][:10]:>10}{r.get('depth_um', np.nan):>10.4g}"
                            f"{r.get('width_mm', np.nan):>10.4g}{r.get('volume_mm3', np.nan):>12.4g}"
                            f"{r.get('peak_pressure_mpa', np.nan):>11.4g}{r['seconds']:>7.1f}")
            say("  change on halving, as a share of model.accuracy/3 (< 1: converged enough):")
            for label, a, b in (("grid 1→2, 9 incr", ("resolved", 1, 9), ("resolved", 2, 9)),
                                ("grid 2→4, 9 incr", ("resolved", 2, 9), ("resolved", 4, 9)),
                                ("incr 9→19, grid 1", ("resolved", 1, 9), ("resolved", 1, 19)),
                                ("incr 19→37, grid 1", ("resolved", 1, 19), ("resolved", 1, 37)),
                                ("mid-stroke grid 1→2", ("mid_stroke", 1, 9), ("mid_stroke", 2, 9))):
                if a in results and b in results:
                    parts = []
                    for key, _ in QUANTITIES:
                        x, y = results[a].get(key, np.nan), results[b].get(key, np.nan)
                        parts.append(f"{key.split('_')[0]} {abs(y - x) / abs(y) / (accuracy / 3):.2f}"
                                     if np.isfinite(x) and np.isfinite(y) and y else f"{key.split('_')[0]} –")
                    say(f"  {label:<22}" + ", ".join(parts))
    OUT.mkdir(parents=True, exist_ok=True)
    suffix = "_ball" if ball else "_bodies" if bodies else ""
    write_csv(rows, OUT / f"resolved_convergence{suffix}.csv")
    say.write(OUT / f"resolved_convergence{suffix}.txt")


if __name__ == "__main__":
    main("--quick" in sys.argv, "--3d" in sys.argv, "--bodies" in sys.argv, "--ball" in sys.argv)
