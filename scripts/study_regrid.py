"""Does widening the grid during a run change the answer?  (Issue 32, first part: the grid follows the contact.)

The planner's scar estimate is made 30× too small in volume (as a wear coefficient in a sample's high tail
would make it), so the automatic grid is outgrown and widened during the run; the same case is then run on the
last grid given from the start.  Reported: the widenings, the depth, width and volume of both and their
relative difference, the Archard invariant, and the loop's wall time of each (the widened run spends its early
cycles on fewer elements).

    python scripts/study_regrid.py

Prints a table; writes scripts/out/regrid.txt.

Coarsening (issue 32, second part): the tubes in service to their wall limit, each run whole (the pilot, the run,
its grid-error companions, the results file) three ways, in turn, five times each (the 3D tube once: its fine run
takes over a minute): ``fine``, one grid sized for the final scar (coarsening off: ``fretsim.regrid.rule_for``
returning None, the automatic grid sized as before 2026-11-28: the computation before issue 32's coarsening);
``coarsened``, that grid coarsened as the scar grows; ``follows``, this tree's grid that starts on the scar of its
first coarsening and widens as the scar grows (its pilot and companions too).  Medians and their ratios, and
whether the cycles and years to the limit, the wall loss and the scar width of each lie within the fine run's
estimated error.

    python scripts/study_regrid.py --coarsen      # writes scripts/results/regrid_coarsen.txt
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report  # noqa: E402

import fretsim.plan.grid as plan_grid  # noqa: E402
from fretsim.api import load_case, run  # noqa: E402

OUT = ROOT / "scripts" / "out"
SCENES = (("mccoll_185N", ["model.dimension=2d", "model.slip=uniform"], "2D, uniform slip"),
          ("mccoll_185N", ["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb",
                           "model.stroke=mid_stroke"], "2D, Coulomb μ 0.9"),
          ("seat_rail", ["loading.cycles=1000"], "3D ball, 1 000 cycles"))
KEYS = (("depth", "max_wear_depth_stationary_um"), ("width", "scar_width_stationary_mm"),
        ("volume", "wear_volume_stationary_mm3"))


COARSEN_CASES = (("tube_service_RT", [], 5), ("tube_service_90C", [], 5),
                 ("tube_service_RT", ["model.dimension=3d"], 1))  # (case, overrides, timed repeats)
COMPARED = (("cycles_to_limit", "estimated_error_cycles_to_limit", "cycles to limit"),
            ("max_wear_depth_moving_um", "estimated_error_depth", "wall loss µm"),
            ("scar_width_stationary_mm", "estimated_error_width", "flat's scar mm"))


SIDES = ("fine", "coarsened", "follows")  # the previous trees' computations, then this one's


def _side(side: str, regrid, real_rule, real_grid) -> None:
    """fine: one grid sized for the final scar (coarsening off, as before issue 32's coarsening); coarsened: that
    grid coarsened as the scar grows (before 2026-11-28); follows: the grid that starts on the scar of its first
    coarsening and widens as the scar grows, its pilot and companions too (this tree)."""
    regrid.rule_for = (lambda *a, **k: None) if side == "fine" else real_rule
    plan_grid.auto_grid = real_grid if side == "follows" else (lambda *a, **kw: real_grid(*a, **{**kw, "grows": False}))


def coarsen() -> None:
    import statistics
    import tempfile
    import fretsim.regrid as regrid
    say = Report()
    real_rule, real_grid = regrid.rule_for, plan_grid.auto_grid
    say(f"{'case':<21}{'side':<11}{'whole s':>9}{'loop s':>8}{'comp s':>8}{'solves':>8}{'final grid':>12}"
        f"{'cycles to limit':>18}{'years':>8}{'wall loss µm':>14}{'scar mm':>9}")
    for name, sets, repeats in COARSEN_CASES:
        case = load_case(ROOT / "cases" / f"{name}.yaml", sets)
        name = " ".join([name] + [s.split("=")[1].upper() for s in sets])
        times: dict = {side: [] for side in SIDES}
        outs: dict = {}
        with tempfile.TemporaryDirectory() as tmp:
            for i in range(repeats + 1):  # the first round untimed: the caches' warm-up
                for side in SIDES:
                    _side(side, regrid, real_rule, real_grid)
                    try:
                        t = time.perf_counter()
                        outs[side] = run(case, Path(tmp) / f"{side}.h5", overwrite=True)
                        if i:
                            times[side].append(time.perf_counter() - t)
                    finally:
                        regrid.rule_for, plan_grid.auto_grid = real_rule, real_grid
        for side in SIDES:
            o, m = outs[side], statistics.median(times[side])
            s = o.summary
            say(f"{name:<21}{side:<11}{m:>9.2f}{s['wall_time_s']:>8.2f}{s['grid_error_wall_time_s']:>8.2f}"
                f"{s['contact_solves']:>8}{o.setup.grid.shape[1]:>12}{s['cycles_to_limit']:>18,.0f}"
                f"{s['time_to_limit_h'] / 8766:>8.4f}{s['max_wear_depth_moving_um']:>14.4f}"
                f"{s['scar_width_stationary_mm']:>9.4f}")
        for faster in ("coarsened", "follows"):
            ratio = statistics.median(times["fine"]) / statistics.median(times[faster])
            say(f"    whole run {ratio:.2f}× faster {faster} than fine (medians of {repeats}, in turn); "
                f"loop {outs['fine'].summary['wall_time_s'] / outs[faster].summary['wall_time_s']:.2f}×, "
                f"companions {outs['fine'].summary['grid_error_wall_time_s'] / outs[faster].summary['grid_error_wall_time_s']:.2f}×")
        for key, err, label in COMPARED:
            b = outs["fine"].summary[key]
            eb = outs["fine"].summary[err]
            for side in ("coarsened", "follows"):
                a, ea = outs[side].summary[key], outs[side].summary[err]
                d = abs(a - b) / abs(b)
                say(f"    {label:<16} {side} differs from fine by {d:.1e}; estimates {ea:.1e} {side}, {eb:.1e} fine: "
                    f"{'within' if d <= max(ea, eb) else 'NOT within'} each other's")
        for n in outs["follows"].notes:
            if "coarsened at" in n or "widened along" in n:
                say(f"    {n[:200]}")
    (ROOT / "scripts" / "results").mkdir(parents=True, exist_ok=True)
    say.write(ROOT / "scripts" / "results" / "regrid_coarsen.txt")


def main() -> None:
    if "--coarsen" in sys.argv[1:]:
        return coarsen()
    say = Report()
    real = plan_grid.auto_grid

    def small(*args, **kw):
        if kw.get("volume") is not None:
            kw["volume"] = kw["volume"] / 30
        return real(*args, **kw)

    say(f"{'scene':<24}{'widenings':>10}{'grid':>12}{'depth rel':>11}{'width rel':>11}{'volume rel':>11}"
        f"{'archard':>9}{'loop s':>8}{'wide s':>8}")
    for name, sets, label in SCENES:
        case = ROOT / "cases" / f"{name}.yaml"
        base = ["grid.error_estimate=none", *sets]
        plan_grid.auto_grid = small
        try:
            run(load_case(case, base))  # once untimed: the first run in a process pays the caches' warm-up
            t = time.perf_counter()
            out = run(load_case(case, base))
            widened_s = time.perf_counter() - t
        finally:
            plan_grid.auto_grid = real
        g = out.setup.grid
        ny, nx = g.shape
        given = [f"grid.domain=[{nx * g.dx!r} mm{'' if g.plane_strain else f', {ny * g.dy!r} mm'}]",
                 f"grid.elements=[{nx}{'' if g.plane_strain else f', {ny}'}]"]
        t = time.perf_counter()
        wide = run(load_case(case, base + given))
        wide_s = time.perf_counter() - t
        count = sum("widened" in n for n in out.notes)
        rel = [abs(out.summary[k] / wide.summary[k] - 1) for _, k in KEYS]
        say(f"{label:<24}{count:>10}{f'{nx}×{ny}':>12}{rel[0]:>11.1e}{rel[1]:>11.1e}{rel[2]:>11.1e}"
            f"{out.summary['archard_volume_error']:>9.0e}{out.summary['wall_time_s']:>8.2f}"
            f"{wide.summary['wall_time_s']:>8.2f}")
        for n in out.notes:
            if "widened" in n:
                say(f"    {n}")
        say(f"    whole calls (planning included): {widened_s:.2f} s widened, {wide_s:.2f} s on the last grid")
    OUT.mkdir(parents=True, exist_ok=True)
    say.write(OUT / "regrid.txt")


if __name__ == "__main__":
    main()
