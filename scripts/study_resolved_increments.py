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

``--counts``: what ``model.increments: auto`` takes with the stroke resolved (5) rests on this table — even
increments 1, 3, 5, 9 against 27 on McColl's four Table 4 cases (2D, μ 0.9, the default accuracy grid, the whole
run), and McColl 185 N in 3D (3, 5, 9 against 27; about 5 minutes): the flat's centre-line and deepest depth, its
scar width, the moving body's centre-line depth, and the loop's time.  Writes scripts/out/
resolved_increments_auto.{txt,csv}.

``--estimate``: does a default resolved run's reported error cover what its 5 increments and its grid leave?  The
four cases (2D) run as shipped with μ 0.9 and the stroke resolved (estimates on), against each on a grid four times
finer along x with 27 increments: |run − reference| / reference beside the run's ``estimated_error_depth`` and
``estimated_error_width``.  ``--3d`` adds McColl 185 N in 3D against a grid twice as fine along x with 15
increments (four times and 27 would take an hour).  Writes scripts/out/resolved_increments_estimate.txt.
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


COUNT_KEYS = (("centre_wear_depth_stationary_um", "depth"), ("max_wear_depth_stationary_um", "deepest"),
              ("scar_width_stationary_mm", "width"), ("centre_wear_depth_moving_um", "moving"))


def counts() -> None:
    """Even increments against 27, the whole run, on McColl's cases (2D) and 185 N (3D)."""
    OUT.mkdir(exist_ok=True)
    say = Report()
    say("The resolved stroke's increments per half-stroke against 27 (μ 0.9, default accuracy grid, whole run): "
        "relative differences; loop time in s")
    say(f"{'case':<18}{'dim':>4}{'n':>4}{'loop s':>8}" + "".join(f"{w:>10}" for _, w in COUNT_KEYS)
        + f"{'elements':>10}")
    rows = []
    plan = [(c, "2d", (1, 3, 5, 9)) for c in ("mccoll_185N", "mccoll_500N", "mccoll_1670N", "mccoll_500N_10um")]
    for case, dim, ns in plan + [("mccoll_185N", "3d", (3, 5, 9))]:
        sets = ["loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved",
                f"model.dimension={dim}", "grid.error_estimate=none"]
        ref = run(load_case(ROOT / "cases" / f"{case}.yaml", [*sets, "model.increments=27"])).summary
        for n in ns + (27,):
            s = ref if n == 27 else run(load_case(ROOT / "cases" / f"{case}.yaml", [*sets, f"model.increments={n}"])
                                        ).summary
            rel = [s[k] / ref[k] - 1.0 for k, _ in COUNT_KEYS]
            # (a width moves by whole elements: its difference in elements says what the percentage means)
            elements = (s["scar_width_stationary_mm"] - ref["scar_width_stationary_mm"]) * 1e3 / s["element_size_x_um"]
            say(f"{case:<18}{dim:>4}{n:>4}{s['wall_time_s']:>8.2f}" + "".join(f"{v:>+10.3%}" for v in rel)
                + f"{elements:>+10.1f}")
            rows.append({"case": case, "dimension": dim, "increments": n, "loop_s": s["wall_time_s"],
                         **{f"{w}_rel": v for (_, w), v in zip(COUNT_KEYS, rel)}, "width_elements": elements})
    say.write(OUT / "resolved_increments_auto.txt")
    write_csv(rows, OUT / "resolved_increments_auto.csv")


ESTIMATED = (("centre_wear_depth_stationary_um", "estimated_error_depth"),
             ("centre_wear_depth_moving_um", "estimated_error_depth"),
             ("scar_width_stationary_mm", "estimated_error_width"), ("scar_width_moving_mm", "estimated_error_width"))


def estimate(three_d: bool = False) -> None:
    """The default resolved run's error estimates against a reference finer in the grid and the increments."""
    OUT.mkdir(exist_ok=True)
    say = Report()
    plan = [(c, "2d", 4, 27) for c in ("mccoll_185N", "mccoll_500N", "mccoll_1670N", "mccoll_500N_10um")]
    say("The resolved stroke as shipped (auto: 5 increments, accuracy grid, estimates on) against the same case on "
        "a finer grid along x with more increments (μ 0.9): 2D 4x and 27" + (", 3D 2x and 15" if three_d else ""))
    say(f"{'case':<18}{'dim':<4}{'quantity':<34}{'run':>10}{'reference':>11}{'error':>9}{'estimate':>10}  covered")
    for case, dim, finer, increments in plan + ([("mccoll_185N", "3d", 2, 15)] if three_d else []):
        sets = ["loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved",
                f"model.dimension={dim}"]
        s = run(load_case(ROOT / "cases" / f"{case}.yaml", sets)).summary
        n = finer * s["elements_x"] + (finer * s["elements_x"] + 1) % 2  # (odd: a centred element)
        domain = f"{s['elements_x'] * s['element_size_x_um'] * 1e-3!r} mm"
        if dim == "3d":  # (the rows as the run's)
            n, domain = f"{n}, {s['elements_y']}", f"{domain}, {s['elements_y'] * s['element_size_y_um'] * 1e-3!r} mm"
        r = run(load_case(ROOT / "cases" / f"{case}.yaml", [*sets, "grid.error_estimate=none", f"grid.elements=[{n}]",
                                                            f"grid.domain=[{domain}]",
                                                            f"model.increments={increments}"])).summary
        for key, est in ESTIMATED:
            err = abs(s[key] / r[key] - 1.0)
            say(f"{case:<18}{dim:<4}{key:<34}{s[key]:>10.5f}{r[key]:>11.5f}{err:>9.3%}{s[est]:>10.3%}  "
                f"{'yes' if err <= s[est] else 'NO'}")
    say.write(OUT / "resolved_increments_estimate.txt")


if __name__ == "__main__":
    counts() if "--counts" in sys.argv else estimate("--3d" in sys.argv) if "--estimate" in sys.argv else main()
