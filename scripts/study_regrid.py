"""Does widening the grid during a run change the answer?  (Issue 32, first part: the grid follows the contact.)

The planner's scar estimate is made 30× too small in volume (as a wear coefficient in a sample's high tail
would make it), so the automatic grid is outgrown and widened during the run; the same case is then run on the
last grid given from the start.  Reported: the widenings, the depth, width and volume of both and their
relative difference, the Archard invariant, and the loop's wall time of each (the widened run spends its early
cycles on fewer elements).

    python scripts/study_regrid.py

Prints a table; writes scripts/out/regrid.txt.
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


def main() -> None:
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
