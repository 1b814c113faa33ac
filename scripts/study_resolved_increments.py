"""Do increments placed where the contact changes pay?  Issue 30 asked whether the resolved stroke's increments,
placed finer near the turning points (where the scar's edges are made) rather than evenly, buy the same accuracy
with fewer positions — fewer positions are what a resolved cycle costs.

The resolved stroke's increments are even (fretsim.cycle.coulomb.increment_path).  This study swaps in a graded
cut, the half-stroke's ends at U = −δ·cos(πk/n) (Chebyshev–Lobatto: short at the turning points, long over
mid-stroke), and runs McColl 185 N 2D (μ 0.9, stroke resolved, the paper's grid 427 × 0.7018 mm, 6 000 cycles)
with each cut and count against 33 even increments: the flat's centre-line depth, the scar width and the recorded
mid-stroke pressure's peak (the position over U = 0, whose travel the middle increment spans).

    python scripts/study_resolved_increments.py

Prints a table; writes scripts/out/resolved_increments.{txt,csv}.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report, write_csv  # noqa: E402

import fretsim.cycle.coulomb as coulomb  # noqa: E402
from fretsim.api import load_case, run  # noqa: E402

OUT = ROOT / "scripts" / "out"
CASE = ROOT / "cases" / "mccoll_185N.yaml"
BASE = ["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved",
        "grid.error_estimate=none", "loading.cycles=6000", "grid.elements=[427]", "grid.domain=[0.7018 mm]"]
EVEN = coulomb.increment_path


def graded_path(stroke: float, n: int) -> list:
    """increment_path with the half-stroke's ends at −δ·cos(πk/n), the middle increment centred on U = 0."""
    d = stroke
    ends = [-d * math.cos(math.pi * k / n) for k in range(n + 1)]
    ends[0], ends[-1] = -d, d
    if n % 2:
        ends[(n - 1) // 2] = -ends[(n + 1) // 2]
    up = [(ends[k], ends[k + 1], True) for k in range(n)]
    return [(0.0, -d, False)] + up + [(-a, -b, True) for a, b, _ in up]


def one(cut: str, n: int) -> dict:
    coulomb.increment_path = EVEN if cut == "even" else (lambda stroke, k: graded_path(stroke, k))
    try:
        out = run(load_case(CASE, [*BASE, f"model.increments={n}"]))
    finally:
        coulomb.increment_path = EVEN
    s = out.summary
    return {"cut": cut, "increments": n, "loop_s": s["wall_time_s"], "depth_um": s["centre_wear_depth_stationary_um"],
            "width_mm": s["scar_width_stationary_mm"], "peak_pressure_MPa": float(out.last.pressure.max())}


def main() -> None:
    OUT.mkdir(exist_ok=True)
    say = Report()
    say("McColl 185 N 2D, μ 0.9, stroke resolved, 427 elements over 0.7018 mm, 6 000 cycles: each cut against 33 "
        "even increments")
    ref = one("even", 33)
    rows = [ref]
    say(f"{'cut':<8}{'n':>4}{'loop s':>9}{'depth':>10}{'width':>10}{'peak p':>10}   (relative to 33 even; "
        f"reference depth {ref['depth_um']:.5f} µm, width {ref['width_mm']:.5f} mm, peak {ref['peak_pressure_MPa']:.2f} MPa)")
    for cut, n in (("even", 5), ("graded", 5), ("even", 7), ("graded", 7), ("even", 9), ("graded", 9), ("graded", 17)):
        r = one(cut, n)
        rows.append(r)
        rel = [r[k] / ref[k] - 1.0 for k in ("depth_um", "width_mm", "peak_pressure_MPa")]
        say(f"{cut:<8}{n:>4}{r['loop_s']:>9.2f}" + "".join(f"{v:>+10.2%}" for v in rel))
    say.write(OUT / "resolved_increments.txt")
    write_csv(rows, OUT / "resolved_increments.csv")


if __name__ == "__main__":
    main()
