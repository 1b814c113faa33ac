"""The grid's part of the error: the run repeated on a grid twice as coarse, and what the difference says.

The stepping estimates (``error_estimate_*``) say how far a run is from the exact per-cycle model *on its grid*;
they say nothing of the grid.  Here the finished case is run again, with the same stepping, on the same domain
with half the elements along x (and along y for a point contact; a line contact keeps the paper's rows).  The
difference of each reported number between the two grids, read as a Richardson estimate, is the grid's part of
its error.  How each is read follows what ``scripts/study_grid_error.py`` measured against runs 32× finer
(Table 4 cases, 2D and 3D):

- depths converge fast (about h²) and smoothly: the difference itself, an over-estimate of about 3×;
- a scar width is where the depth crosses 0.1 % of its peak, read between element centres
  (:func:`fretsim.measures.scar_width`).  Its error is not monotone in the element: the crossing moves within
  an element as the grid changes.  Measured on a ladder of seven grids from the accuracy grid to 8× coarser
  (``scripts/study_width_error.py``, 16 cases in 2D and 3D, both bodies): within one element over the width
  on every grid (at most 0.95 dx/W; 0.28-0.49 at the default and the two grids below it).  The estimate is the
  difference plus one element over the width: never below the error on those 128 pairs of grids, 47× it in the
  median at the default (the stepping's part included).  The larger of the two alone was tried: tighter, but a
  partial-slip scar on the paper's grid reads 1.5 elements wide on it and on one twice as coarse alike, and the
  sum is what comes nearest to covering it (still short there: a known gap, a strict xfail test);
- the pressure field (L2) converges slowly (its steep flanks at the scar's edges): the difference, with the
  coarse field interpolated to the fine centres, an over-estimate of 2-7× measured;
- its peak sits on those flanks and does not converge smoothly (measured from −36 % to +8 % over 1-32× finer
  grids; McColl 1670 N in 2D: 233, 209, 217, 278, 279, 262 MPa on grids 4× coarser to 8× finer than the
  default).  A third run, twice as coarse again (cheap: a quarter or a sixteenth of the elements), says whether
  the peak is converging: where the two differences have one sign and shrink by at least √2, the peak is read as
  if it fell with √h (the nearer difference × 1/(√2 − 1)); where they do not, the peak is not yet in its
  asymptotic range and its estimate is the larger difference read the same way (the spread the grids show,
  at the coarser spacing: a scale, not a bound, and the run says so).  Never below the field's estimate.
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

COARSER = 2.0
SQRT_H = 1.0 / (math.sqrt(2.0) - 1.0)  # Richardson's factor for an error falling as √h, grids 2× apart
DEPTHS = ("max_wear_depth_moving_um", "max_wear_depth_stationary_um", "centre_wear_depth_moving_um",
          "centre_wear_depth_stationary_um")
WIDTHS = ("scar_width_moving_mm", "scar_width_stationary_mm")
KEYS = ("estimated_error_depth", "estimated_error_width", "estimated_error_pressure", "estimated_error_max_pressure")
LIMIT_KEY = "estimated_error_cycles_to_limit"


def odd(n: float) -> int:
    """The nearest odd element count of at least 3 (an automatic grid's centre is an element's)."""
    n = max(int(round(n)), 3)
    return n if n % 2 else n + 1


def companions_wanted(filled) -> bool:
    """Whether a finished case's grid error is estimated by companions: asked for, a run that wears, a grid."""
    return filled.grid_error != "none" and filled.loading.cycles > 0 and filled.elements is not None


def companion_case(filled, line_contact: bool, times: int = 1):
    """The finished case (automatic choices filled) on a grid COARSER**times coarser, otherwise unchanged."""
    e, f = filled.elements, COARSER ** times
    elements = (odd(e[0] / f),) + (() if len(e) == 1 else (e[1],) if line_contact else (odd(e[1] / f),))
    coarse = None if filled.coarse_element is None else tuple(c * f for c in filled.coarse_element)
    return filled.with_choices(elements=elements, coarse_element=coarse, grid_error="none",
                               snapshots=(filled.loading.cycles,))


def _relative(a: float, b: float) -> float:
    return abs(a - b) / abs(a) if a else 0.0


def _on(field: np.ndarray, x: np.ndarray, y: np.ndarray, xf: np.ndarray, yf: np.ndarray) -> np.ndarray:
    """A coarse field read at the fine centres (linear along x, then along y; held beyond the last centre)."""
    along_x = np.stack([np.interp(xf, x, row) for row in np.atleast_2d(field)])
    if along_x.shape[0] == 1:  # plane strain: one row on both grids
        return along_x
    return np.stack([np.interp(yf, y, col) for col in along_x.T], axis=1)


def peak_estimate(fine: float, coarse: float, coarsest: Optional[float]) -> tuple[float, bool]:
    """The grid's part of the peak pressure's relative error, and whether the three grids show it converging."""
    near = coarse - fine
    if coarsest is None:
        return SQRT_H * _relative(fine, coarse), True
    far = coarsest - coarse
    converging = near * far >= 0 and abs(far) >= math.sqrt(2.0) * abs(near)
    spread = abs(near) if converging else max(abs(near), abs(far))
    return (SQRT_H * spread / abs(fine) if fine else 0.0), converging


def stick_edge_peaks(summary: dict) -> bool:
    """Whether the run's point values at the worn stick zone's edge — the peak pressure, the SWT parameter's peak,
    Miner's sum at the end — are left unestimated: in partial slip, where refinement moves them with no limit that
    three grids can show.  The shipped Ti-6Al-4V case at 5 µm read its peak 2163, 2582, 3204 MPa on grids 4×, 2×
    and 1× its element and 4804, 6914, 9436 MPa on grids 2×, 4× and 8× finer, its SWT peak 64.8, 137, 283 MPa on
    grids 1×, 2× and 4× finer; at 4 µm the three grids looked converging (1050, 1796, 2277 MPa: a finite 51 %)
    while grids 2-8× finer read 3059, 4443, 6189; and at 10⁴ cycles, before the edge forms, they looked diverging
    (795, 845, 906) while it converges, 4.4 % higher (two reviews' runs).  The crack cycle, set before the wear
    concentrates the pressure there, converges (within 3 % of grids 4× finer) and keeps its estimate."""
    return summary.get("regime") == "partial_slip"


def grid_estimates(fine: dict, coarse: dict, p_fine: np.ndarray, grid_fine, p_coarse: np.ndarray,
                   grid_coarse, coarsest: Optional[dict] = None) -> dict:
    """The grid's part of the relative error of the depths, the widths, the pressure field (L2) and its peak
    (``coarsest``, the run on a grid twice as coarse again, tells whether the peak is converging)."""
    depth = max(_relative(fine[k], coarse[k]) for k in DEPTHS)
    width = max((_relative(fine[k], coarse[k]) + grid_fine.dx / fine[k]) if fine[k] else 0.0 for k in WIDTHS)
    pc = _on(p_coarse, grid_coarse.x, grid_coarse.y, grid_fine.x, grid_fine.y)
    norm = float(np.linalg.norm(p_fine))
    pressure = float(np.linalg.norm(np.atleast_2d(p_fine) - pc)) / norm if norm else 0.0
    peak, converging = peak_estimate(fine["max_pressure_MPa"], coarse["max_pressure_MPa"],
                                     None if coarsest is None else coarsest["max_pressure_MPa"])
    # (in partial slip only: a gross-slip peak sits on the scar's flanks and wanders before it converges — McColl
    #  1670 N 2D read 233, 209, 217, 278, 279, 262 MPa from 4× coarser to 8× finer — and its reading stands)
    unknown = stick_edge_peaks(fine)
    out = dict(zip(KEYS, (depth, width, pressure, math.nan if unknown else max(peak, pressure))))
    out["peak_converging"], out["peak_unestimated"] = converging, unknown
    return out


COARSE_GRIDS = ("4×", "2×", "1×")  # the grids of the companions' reading, in elements of the run's
FINE_GRIDS = ("1×", "½×")  # ... of a companion twice as fine's


def _seen(values, grids) -> str:
    """'a, b, c MPa on grids 4×, 2× and 1×' of the finite values (unit-less for a sum)."""
    pairs = [(v, g) for v, g in zip(values, grids) if v is not None and math.isfinite(v)]
    return (f"{', '.join(f'{v:.4g}' for v, _ in pairs)} on grids {', '.join(g for _, g in pairs[:-1])} and "
            f"{pairs[-1][1]}" if len(pairs) > 1 else "")


def stick_edge_note(values: tuple, grids: tuple = COARSE_GRIDS) -> str:
    """The note of a partial slip's peak pressure left unestimated: ``values`` (MPa) on ``grids`` (in elements of the
    run's), coarsest first."""
    return (f"the peak pressure is not estimated (NaN): in partial slip it sits at the worn stick zone's edge, where "
            f"refinement moves it with no limit a few grids can show ({_seen(values, grids)} MPa this run's element; "
            f"an elastic singularity there, where the real material yields): the reported peak is this grid's, not a "
            f"bound; the pressure field's estimate stands")


# A companion twice as fine, where the one twice as coarse stopped: the run's error e, with e − e/2^p = the
# difference d, is d/(1 − 2^−p): 3d at p = 0.58.  Such a grid is not yet in the asymptotic range: on Ti-6Al-4V with
# k_m = k_s/10, μ 1.2, 8 µm over 10⁵ cycles (its automatic 247 elements build a checkerboard at the stick edge),
# the flat's depth on 494, 988, 1976, 3953 and 7905 elements was 4.224, 4.466, 4.588, 4.684 and 4.686 µm (the
# moving body's 0.444, 0.505, 0.524, 0.533, 0.534): the run on 494 is 10 % (17 %) short, 1.7 (1.2) times its
# difference to 988, not the 1 of a second-order convergence; 3d covers both (tests/test_grid_error.py)
FINER_FACTOR = 3.0
FINER_PEAK = 1.0 / (1.0 - 1.0 / math.sqrt(2.0))  # ... and for a peak falling as √h: e = d/(1 − 2^−½)


def finer_estimates(run: dict, fine: dict, p_run: np.ndarray, grid_run, p_fine: np.ndarray, grid_fine) -> dict:
    """The grid's part of the run's relative errors from a companion on a grid twice as fine (where the one twice as
    coarse could not run): the differences over (1 − 2^−p) at an order p = 0.58 (FINER_FACTOR times them), the
    widths plus one of the run's elements, the peak pressure as falling with √h (FINER_PEAK)."""
    depth = FINER_FACTOR * max(_relative(run[k], fine[k]) for k in DEPTHS)
    width = max((FINER_FACTOR * _relative(run[k], fine[k]) + grid_run.dx / run[k]) if run[k] else 0.0
                for k in WIDTHS)
    pr = _on(p_run, grid_run.x, grid_run.y, grid_fine.x, grid_fine.y)
    norm = float(np.linalg.norm(pr))
    pressure = FINER_FACTOR * float(np.linalg.norm(np.atleast_2d(p_fine) - pr)) / norm if norm else 0.0
    peak = FINER_PEAK * _relative(run["max_pressure_MPa"], fine["max_pressure_MPa"])
    unknown = stick_edge_peaks(run)  # (as grid_estimates: a partial slip's peak is not estimated)
    out = dict(zip(KEYS, (depth, width, pressure, math.nan if unknown else max(peak, pressure))))
    out["peak_converging"], out["peak_unestimated"] = False, unknown
    return out


def finer_note(stopped: str, elements: int, estimates: dict, accuracy: float) -> str:
    over = estimates["estimated_error_depth"] > accuracy or estimates["estimated_error_width"] > accuracy
    return (f"the grid's part of the error was estimated from a companion on a grid twice as fine ({elements} "
            f"elements along x): the one twice as coarse stopped ({stopped}), a sign that this grid is close to too "
            f"coarse" + (f"; the estimated error of the depths {estimates['estimated_error_depth']:.2%} and of the "
                         f"widths {estimates['estimated_error_width']:.2%} exceeds model.accuracy ({accuracy:.2%}): "
                         f"a finer grid.elements brings it down" if over else ""))


def totals(summary: dict, grid_part: Optional[dict], model_part: float = 0.0) -> dict:
    """The reported estimates: the stepping's (``error_estimate_*``), the grid's and the model difference ``auto``
    accepted, added (each bounds its own part; adding them does not assume they cancel)."""
    step_depth, step_pressure = summary["error_estimate_depth"], summary["error_estimate_pressure"]
    stepping = dict(zip(KEYS, (step_depth, step_depth, step_pressure, step_pressure)))
    if grid_part is None:
        return {k: float("nan") for k in KEYS}
    return {k: float(stepping[k] + grid_part[k] + (model_part if k in KEYS[:2] else 0.0)) for k in KEYS}


def peak_note(fine: float, coarse: float, coarsest: float, estimate: float) -> str:
    return (f"the peak pressure is not yet converging on these grids ({coarsest:.4g}, {coarse:.4g}, {fine:.4g} MPa "
            f"on grids 4×, 2× and 1× this run's element): its estimate ({estimate:.1%}) is the spread they show, a "
            f"scale rather than a bound; model.pressure_accuracy sizes a grid that resolves it")


def cycles_to_limit_estimate(fine: dict, coarse: Optional[dict], limit: Optional[tuple],
                             model_part: float = 0.0, factor: float = 1.0) -> float:
    """The relative error of ``cycles_to_limit``: the depths' stepping and model parts over the quantity's growth
    exponent d ln q / d ln N (an error ε in a depth growing as √N is one of 2ε in its cycle), the crossing's
    interpolation spread, and the grid's part read directly from the companion's own crossing.  NaN where there
    is no crossing, no companion, or the companion reached no limit.  ``factor``: FINER_FACTOR where the companion
    is twice as fine (the difference to a better answer, not to a worse one)."""
    n = fine.get("cycles_to_limit", float("nan"))
    if limit is None or coarse is None or not math.isfinite(n) or n <= 0:
        return float("nan")
    _, _, spread, exponent = limit
    exponent = max(exponent, 0.1)  # a quantity that has all but stopped growing: its crossing is ill-defined
    n_coarse = coarse.get("cycles_to_limit", float("nan"))
    if not math.isfinite(n_coarse):
        return float("nan")
    return float((fine["error_estimate_depth"] + model_part) / exponent + spread / n + factor * abs(n - n_coarse) / n)


FATIGUE_KEYS = ("estimated_error_cycles_to_crack", "estimated_error_swt_max", "estimated_error_fatigue_damage")


def fatigue_over(fine: dict, coarse: dict, estimates: dict, accuracy: float) -> list:
    """A note where the crack cycle's estimated error (or, without a crack, Miner's sum's) exceeds model.accuracy,
    with its three parts and what narrows each: [] where it does not (or is not known)."""
    crack = math.isfinite(fine.get("cycles_to_crack_initiation", math.nan))
    if crack and not math.isfinite(coarse.get("cycles_to_crack_initiation", math.nan)):
        return [f"the crack cycle's error was not estimated: the companion run on a grid twice as coarse had no crack "
                f"within the run (Miner's sum there {coarse.get('fatigue_damage', math.nan):.3g}, here "
                f"{fine.get('fatigue_damage', math.nan):.3g}): whether and when a crack starts depends on the grid here "
                f"(a finer grid.elements says which)"]
    key, what, value = (("estimated_error_cycles_to_crack", "the crack cycle", "cycles_to_crack_initiation") if crack
                        else ("estimated_error_fatigue_damage", "Miner's sum at the end", "fatigue_damage"))
    total = estimates.get(key, math.nan)
    if not (math.isfinite(total) and total > accuracy):
        return []
    states = fine.get("fatigue_states_error", math.nan)
    # the grid's part as the estimate took it (Miner's sum: read as a peak, fatigue_estimates)
    grid = (abs(fine[value] - coarse.get(value, math.nan)) / fine[value] if crack else
            total - fine["error_estimate_depth"] - (states if math.isfinite(states) else 0.0))
    spacing = f"{states:.1%}" if math.isfinite(states) else "not measured (too few states)"
    return [f"the estimated error of {what} {total:.1%} exceeds model.accuracy ({accuracy:.2%}): the fatigue states' "
            f"spacing {spacing} (the sum over every other state; more output.snapshots where the damage grows add "
            f"states), the companion grid's {grid:.1%} (a finer grid.elements), the stepping's "
            f"{fine['error_estimate_depth']:.1%}"]


FATIGUE_PEAKS = (("swt_max_MPa", "the SWT parameter's peak"), ("fatigue_damage", "Miner's sum at the end"))


def fatigue_estimates(fine: dict, coarse: dict, factor: float = 1.0, coarsest: Optional[dict] = None) -> dict:
    """The grid's part of the fatigue figures' relative error, plus the depths' stepping part and the fatigue states'
    spacing part (Miner's sum over every other state) for the crack cycle (NaN where either run has no crack) and,
    the same three parts, for Miner's sum at the run's end (fatigue_damage: what a run without a crack reports of its
    fatigue).  The crack cycle's grid part is the companion's difference as it is (it is set early, before the wear
    concentrates the pressure: within 2.5-3 % of grids 4× finer, estimated 3.4-6 %).  The SWT's peak and Miner's sum
    at the end are read as the peak pressure is (:func:`peak_estimate`: as if falling with √h, from the nearer
    difference where the three grids show them converging, the larger where not), and NaN in partial slip
    (:func:`fatigue_unestimated`): read as the plain difference, they were 15-25 % short where they converge
    (Ti-6Al-4V at 6 µm, in gross slip: the SWT 18 % below grids 8× finer, estimated 15.8 %) and a constant ~50 % in
    partial slip, where the SWT doubles with each halving of the element (a review's runs).
    ``factor``: FINER_FACTOR where the companion is twice as fine (those two then as FINER_PEAK times the
    difference)."""
    crack, crack_c = fine.get("cycles_to_crack_initiation", math.nan), coarse.get("cycles_to_crack_initiation",
                                                                                 math.nan)
    states = fine.get("fatigue_states_error", math.nan)
    states = states if math.isfinite(states) else 0.0
    out = {"estimated_error_cycles_to_crack": (factor * abs(crack - crack_c) / crack + fine["error_estimate_depth"]
                                               + states)
           if math.isfinite(crack) and math.isfinite(crack_c) and crack > 0 else math.nan}
    unestimated = fatigue_unestimated(fine, coarse)
    grid = {}
    for key, _ in FATIGUE_PEAKS:
        v, v_c = fine.get(key, math.nan), coarse.get(key, math.nan)
        v_cc = coarsest.get(key, math.nan) if coarsest is not None else math.nan
        if not (math.isfinite(v) and math.isfinite(v_c) and v > 0) or key in unestimated:
            grid[key] = math.nan
        elif factor != 1.0:
            grid[key] = FINER_PEAK * _relative(v, v_c)
        else:
            grid[key] = peak_estimate(v, v_c, v_cc if math.isfinite(v_cc) else None)[0]
    out["estimated_error_swt_max"] = grid["swt_max_MPa"]
    out["estimated_error_fatigue_damage"] = grid["fatigue_damage"] + fine["error_estimate_depth"] + states
    return out


def fatigue_unestimated(run: dict, *others: Optional[dict]) -> dict:
    """{key: its values, the grids' in the order given} of the fatigue figures left unestimated: in partial slip
    (:func:`stick_edge_peaks`), the SWT's peak and Miner's sum at the end (Ti-6Al-4V at 5 µm: the SWT peak 64.8,
    137, 283 MPa on grids 1×, 2× and 4× finer; Miner's sum 165, 223, 288).  ``others``: the companions' summaries
    (None: not run), their values listed in the order given, then ``run``'s (as COARSE_GRIDS)."""
    if not stick_edge_peaks(run):
        return {}
    values = {key: tuple(o.get(key, math.nan) if o is not None else math.nan for o in others) + (run.get(key, math.nan),)
              for key, _ in FATIGUE_PEAKS}
    return {key: v for key, v in values.items() if math.isfinite(v[-1])}


def fatigue_unestimated_note(unestimated: dict, grids: tuple = COARSE_GRIDS) -> list:
    if not unestimated:
        return []
    names = dict(FATIGUE_PEAKS)
    seen = "; ".join(f"{names[k]} {_seen(v, grids)}" for k, v in unestimated.items())
    return [f"{' and '.join(names[k] for k in unestimated)} {'are' if len(unestimated) > 1 else 'is'} not estimated "
            f"(NaN): in partial slip they are point values at the worn stick zone's edge, where the elastic field is "
            f"singular (and passes yield) and refinement moves them with no limit a few grids can show ({seen}, in "
            f"this run's elements): reported as this grid's; the crack cycle, set before the wear concentrates the "
            f"pressure there, keeps its estimate"]
