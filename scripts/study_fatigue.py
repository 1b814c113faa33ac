"""Fretting fatigue over the wear history: how many fatigue states the damage needs, and what fatigue costs.

For the Ti-6Al-4V cylinder-on-flat case (cases/ti_fretting_fatigue.yaml) near the gross-slip limit, where cracks
start within 10⁶ cycles: the crack-initiation cycle with the fatigue states (the first step at or past each is
evaluated) at the default density and sparser and denser ones (STATES_PER_DECADE, LINEAR_STATES of
fretsim.fatigue.damage) against the densest, beside the run's own estimate of the spacing's part (Miner's sum
over every other state); the run's time with fatigue against the same run without; and the interaction: the
life against the stroke with wear and without.

    python scripts/study_fatigue.py            # → scripts/results/fatigue_states.txt
    python scripts/study_fatigue.py --cost     # the cost table alone, printed (not written)
    python scripts/study_fatigue.py --cost-3d  # 3D: the ball with the flat's fatigue → scripts/results/fatigue_3d_cost.txt
"""
from __future__ import annotations

import math
import sys
import tempfile
import time
from pathlib import Path

from fretsim.case import load_case
from fretsim.fatigue import damage
from fretsim.runner import run

ROOT = Path(__file__).resolve().parent.parent
CASE = ROOT / "cases" / "ti_fretting_fatigue.yaml"
STROKES = ("4 um", "5 um")  # near the transition, where cracks start within the run (with wear, 10⁶ cycles)
COST_STROKES = ("2 um", "5 um", "10 um", "25 um", "10 um uniform", "25 um uniform")  # uniform: model.slip
CURVE = ("1 um", "2 um", "3 um", "4 um", "5 um", "6 um", "8 um", "10 um", "15 um", "25 um")
NO_WEAR = ("materials.moving.wear_coefficient=0 1/MPa", "materials.stationary.wear_coefficient=0 1/MPa")
DENSITIES = ((2, 4), (3, 8), (6, 16), (12, 32), (24, 64))  # (per decade, linear); the last is the reference


DEFAULT = (damage.STATES_PER_DECADE, damage.LINEAR_STATES)


def _crack(stroke: str, per_decade: int, linear: int, extra=()) -> tuple:
    damage.STATES_PER_DECADE, damage.LINEAR_STATES = per_decade, linear
    case = load_case(str(CASE), [f"loading.stroke={stroke}", "grid.error_estimate=none", *extra])
    return _run(case)


def _run(case) -> tuple:
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        out = run(case, Path(tmp) / "r.h5")
        seconds = time.perf_counter() - t
    st = out.last.state
    crack = float(st["fatigue_crack"][0]) if "fatigue_crack" in st else math.nan
    _run.states_error = out.summary["fatigue_states_error"]
    return crack, float(st["fatigue_damage"].max()), seconds, out.summary["contact_solves"]


def _cost() -> list:
    """The run with fatigue against the same without, median of 3, in turn."""
    lines = ["", "cost: the shipped case (10⁵ cycles) with fatigue against the same without "
                 "(materials.stationary.fatigue null), median of 3, in turn"]
    for name in COST_STROKES:
        stroke, *slip = name.split(" um")
        extra = [f"loading.stroke={stroke} um", "grid.error_estimate=none"] + (
            ["model.slip=uniform"] if slip[0].strip() else [])
        with_f, without = [], []
        for _ in range(3):
            for fatigue, out in (((), with_f), (("materials.stationary.fatigue=null",), without)):
                case = load_case(str(CASE), [*extra, *fatigue])
                with tempfile.TemporaryDirectory() as tmp:
                    t = time.perf_counter()
                    run(case, Path(tmp) / "r.h5")
                    out.append(time.perf_counter() - t)
        a, b = sorted(with_f)[1], sorted(without)[1]
        lines.append(f"  {name:14s}: with {a:.2f} s, without {b:.2f} s, ratio {a / b:.2f}")
    return lines


BALL = ROOT / "cases" / "ball_partial_slip.yaml"
TI_FLAT = ("materials.stationary.fatigue={strength_coefficient: 2464 MPa, strength_exponent: -0.1715, "
           "ductility_coefficient: 0.0711, ductility_exponent: -0.6098, critical_distance: 20 um}")
COST_3D = (("20 N, 0.7 um (partial slip)", []), ("200 N, 5 um (partial slip)", ["loading.normal_load=200 N",
                                                                               "loading.stroke=5 um"]),
           ("20 N, 5 um (gross slip)", ["loading.stroke=5 um"]))


def _cost_3d() -> list:
    """3D: the ball on a flat (cases/ball_partial_slip.yaml, 2·10⁴ cycles) with the flat's fatigue against the same
    without, median of 3, in turn."""
    lines = ["", "cost in 3D: cases/ball_partial_slip.yaml (2·10⁴ cycles) with the flat's Ti-6Al-4V constants "
                 "against the same without, median of 3, in turn (grid.error_estimate none)"]
    for name, extra in COST_3D:
        with_f, without = [], []
        for _ in range(3):
            for fatigue, out in (((TI_FLAT,), with_f), ((), without)):
                case = load_case(str(BALL), ["grid.error_estimate=none", *extra, *fatigue])
                with tempfile.TemporaryDirectory() as tmp:
                    t = time.perf_counter()
                    res = run(case, Path(tmp) / "r.h5")
                    out.append(time.perf_counter() - t)
        a, b = sorted(with_f)[1], sorted(without)[1]
        lines.append(f"  {name:30s}: with {a:.2f} s, without {b:.2f} s, ratio {a / b:.2f} "
                     f"({res.summary['elements_x']} × {res.summary['elements_y']} elements)")
    return lines


def main() -> None:
    if "--cost" in sys.argv:
        print("\n".join(_cost()))
        return
    if "--cost-3d" in sys.argv:
        text = "\n".join(_cost_3d()) + "\n"
        print(text)
        (ROOT / "scripts" / "results" / "fatigue_3d_cost.txt").write_text(
            f"command: python scripts/study_fatigue.py --cost-3d ({time.strftime('%Y-%m-%d')})\n{text}")
        return
    lines = [__doc__.split("\n\n")[0], "", f"case {CASE.name}; grid.error_estimate none", "",
             "stroke   states/decade linear   crack cycle   damage at end   vs densest   estimated   run s   solves"]
    for stroke in STROKES:
        rows = []
        for d in DENSITIES:
            rows.append((d, _crack(stroke, *d, extra=("loading.cycles=1000000",)) + (_run.states_error,)))
        ref_crack, ref_damage = rows[-1][1][:2]
        for (per_decade, linear), (crack, dmg, sec, solves, said) in rows:
            if math.isfinite(ref_crack):
                diff = f"{crack / ref_crack - 1:+.2%}" if math.isfinite(crack) else "no crack"
            else:
                diff = f"{dmg / ref_damage - 1:+.2%} (damage)"
            lines.append(f"{stroke:8s} {per_decade:13d} {linear:6d}   {crack:11.6g}   {dmg:13.4g}   {diff:>10s}   "
                         f"{said:9.2%}   {sec:5.2f}   {solves:6d}")
        damage.STATES_PER_DECADE, damage.LINEAR_STATES = DEFAULT
    lines += _cost()
    lines += ["", "the interaction: cycles to crack initiation (10⁶ cycles run; '>' none by then, with Miner's sum)",
              "stroke    with wear                 without wear (k = 0)"]
    for stroke in CURVE:
        cells = []
        for extra in ((), NO_WEAR):
            crack, dmg, _, _ = _crack(stroke, *DEFAULT, extra=("loading.cycles=1000000", *extra))
            cells.append(f"{crack:<10.4g} " if math.isfinite(crack) else f"> 1e6 (D = {dmg:.2g})")
        lines.append(f"{stroke:8s}  {cells[0]:24s}  {cells[1]:24s}")
    text = "\n".join(lines) + "\n"
    print(text)
    if "--no-write" not in sys.argv:
        (ROOT / "scripts" / "results" / "fatigue_states.txt").write_text(text)


if __name__ == "__main__":
    main()
