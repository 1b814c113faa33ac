"""The planner's model stage: the dimension, the corrections to the half-spaces and the gap model, each the
cheapest that reports the case's quantities within model.accuracy, and the operators they make.

``auto`` judges a simplification by running the case both ways on a coarse grid (a *proxy*) and comparing the
depths and widths it reports.  A proxy's difference is measured on a coarse grid and is itself uncertain:
mccoll_500N_10um's 2D proxy differed from 3D by 0.99 %, at full resolution by 1.21 % in depth and 2.5 % in the
moving body's scar width.  So ``auto`` accepts a simpler model only where PROXY_MARGIN times the proxy's
difference is within model.accuracy, and reports that product as the model's part of the error estimates.

A run with wear limits is sized for the wear at the limit, which a *pilot* run finds (the paper's element,
coarsening and widening as its scar grows, a loose tolerance).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from fretsim.case import Case, CaseError
from fretsim.compliance import HalfSpace, add
from fretsim.compliance.free_faces import free_faces
from fretsim import regrid
from fretsim.grid import Grid
from fretsim.plan.choices import Choice, Plan
from fretsim.plan.runs import SideRuns
from fretsim.quantities import SAID
from fretsim.reference import effective_modulus
from fretsim.simulate import SimulationError, summarize
from fretsim.sizing import auto_grid
from fretsim.wear import stroke_symbol

PROXY_ROWS = 15
PROXY_MARGIN = 3.0
PILOT_ACCURACY = 0.1  # the pilot's grid coarsens as for a run of this accuracy: it finds the stop roughly (0.02 %
#                      on the tube in service, scripts/study_regrid.py --coarsen)
PILOT_MARGIN = 1.3  # the grid of a run with wear limits holds the wear of this many times the pilot's cycles
# the pilot's stepping tolerance: it needs the stop to well within PILOT_MARGIN, and its steps' error estimates
# over-state the depths' error 20-100x.  Measured on 15 cases with limits (2D and 3D, histories, Coulomb, resolved,
# the stroke-averaged gap; scripts/results/pilot_tolerance.txt): the stops at 0.3 within 0.3 % of those at 0.03
# (a review's ten more within 1 %, scar-width limits the furthest), the pilots 1.0-2.9x fewer solves (the tube in
# service's 158 -> 104)
PILOT_TOLERANCE = 0.3
FACES_NOTE = ("the free faces of {what} (paper §2.1; solved as a finite block, not the paper's overlapping "
              "half-spaces)")
# the worn state's figures a proxy compares (the peak pressure for a contact-only run)
WEAR_KEYS = ("max_wear_depth_moving_um", "max_wear_depth_stationary_um", "scar_width_moving_mm",
             "scar_width_stationary_mm")

PlanCase = Callable[[Case], tuple]  # the planner itself (fretsim.plan.prepare), for the proxies and the pilot


@dataclass(frozen=True)
class Model:
    """The model stage's result: the gap model, the corrections and the normal operators they make."""

    gap_model: str
    corrections: tuple
    compliance: object  # on the run's grid
    coarse_compliance: object  # on the coarse grid of refinement (None without)
    coarse_gap: Optional[np.ndarray]

    @property
    def solve_compliance(self):
        return self.coarse_compliance if self.coarse_compliance is not None else self.compliance


def build(case: Case, plan: Plan, grids, e_star: float, proxy_case: Case, runs: SideRuns,
          plan_case: PlanCase) -> Model:
    """The gap model and the corrections, and the operators on the run's grids."""
    g, grid, coarse = case.geometry, grids.grid, grids.coarse
    gap_model = plan.add(choose_gap_model(case, grid))
    coarse_gap = None
    if coarse is not None:
        coarse_gap = g.separation(coarse)
        plan.add(Choice("grid.coarse_element", case.coarse_element, f"given: contact solved on {coarse.shape[1]} x "
                                                                    f"{coarse.shape[0]} elements, pressure refined "
                                                                    f"to {grid.shape[1]} x {grid.shape[0]} "
                                                                    f"(Akima weights, Eqs. 11-12)", True))
    corrections = plan.add(choose_corrections(proxy_case, grid.plane_strain, runs, plan_case))
    nu = max(case.moving.poissons_ratio, case.stationary.poissons_ratio)
    if "free_faces" in corrections and nu > 0.45:
        plan.warnings.append(f"Poisson's ratio {nu:g}: the free faces' finite-element block (bilinear elements) "
                             f"stiffens near incompressibility (1.3 % at ν = 0.45, 4.7 % at 0.49 against the "
                             f"half-space), so their effect is understated by about that much")
    compliance = operator(case, corrections, grid, e_star)
    coarse_op = operator(case, corrections, coarse, e_star) if coarse is not None else None
    return Model(gap_model, corrections, compliance, coarse_op, coarse_gap)


def operator(case: Case, corrections: tuple, on: Grid, e_star: float):
    """The normal compliance on a grid: both half-spaces, plus each correction's own."""
    g = case.geometry
    extra = [g.extra_compliance(on, case.moving.youngs_modulus, case.moving.poissons_ratio)
             for c in corrections if c == "ring_bending"]
    if "free_faces" in corrections:
        bodies = {"moving": case.moving, "stationary": case.stationary}
        try:
            extra.append(free_faces(on, [(length, bodies[b].youngs_modulus, bodies[b].poissons_ratio)
                                         for b, length in g.free_faces]))
        except ValueError as exc:
            raise CaseError(case.source, [("grid.domain", f"model.corrections free_faces: {exc}")]) from None
    return add(HalfSpace(on, e_star), *extra)


# --- the gap model -------------------------------------------------------------------------------------------

def choose_gap_model(case: Case, grid: Grid) -> Choice:
    """mid_stroke (the paper) where it is stable, stroke_average where the paper's model itself is not."""
    k_m, k_s = case.wear_coefficients()
    b_min = float(stroke_symbol(grid.dx, case.loading.peak_stroke, np.linspace(0.01 * np.pi, np.pi, 400)).min())
    stable = k_m + k_s * min(b_min, 0.0) >= 0
    if case.gap_model != "auto":
        return Choice("model.gap", case.gap_model, "given in the case", True)
    if stable:
        bound = -min(b_min, 0.0)
        return Choice("model.gap", "mid_stroke", "the paper's model (Eq. 18): stable here, since "
                      + (f"k_m ≥ {bound:.3g}·k_s" if bound > 0 else "it is stable for any k_m and k_s on this grid"))
    return Choice("model.gap", "stroke_average",
                  f"the paper's mid-stroke gap is unstable when the moving body wears less than "
                  f"{-b_min:.3f} of the flat (k_m = {k_m:.3g}, k_s = {k_s:.3g} 1/MPa): wear modes shorter than "
                  f"the stroke grow in the model itself and break the pressure into spikes; the flat's wear seen "
                  f"through the stroke average is stable and equal to first order")


# --- auto's proxies ------------------------------------------------------------------------------------------

def proxy_summary(proxy: Case, what: Callable, runs: SideRuns, plan_case: PlanCase) -> dict:
    """The summary of one of auto's proxy runs; a proxy already run in ``runs``' keeping is not run again."""
    def compute():
        setup, _, _ = plan_case(proxy)
        return summarize(setup, runs.run(what(setup), setup), 0, 0.0)
    return dict(runs.remembered(runs.proxies, repr(proxy.to_dict()), compute))


def _worst(out: list, keys: tuple) -> tuple[float, str]:
    """The largest relative difference between two proxies' figures, and how to name it."""
    diffs = {key: abs(out[1][key] / out[0][key] - 1) if out[0][key] else 0.0 for key in keys}
    worst = max(diffs, key=diffs.get)
    return diffs[worst], SAID[worst]


def choose_dimension(case: Case, e_star: float, runs: SideRuns, plan_case: PlanCase) -> Choice:
    """2d or 3d.  auto: 2D where it reports the quantities of the full 3D model within model.accuracy.

    Estimated before the run by proxy runs on a coarse grid (half the x resolution, 15 rows): the case in 2D
    and in 3D, compared on the maximum depth of each body, the flat's centre-line depth and both scar widths
    (the peak pressure for a contact-only run).  The unworn contact alone is no guide: a flat-ended cylinder's
    ends draw load from its whole length (its centre line carries 93-96 % of P/L for L/a from 280 to 8300,
    falling off as 1/ln(L/a)), but wear evens that out; and a profiled roller may start balanced and end not.
    Point contacts have no 2D model.
    """
    g = case.geometry
    if case.dimension != "auto":
        return Choice("model.dimension", case.dimension, "given in the case", True)
    if not g.has_2d:
        return Choice("model.dimension", "3d", f"a {g.kind} is a point contact: it has no 2D model")
    try:
        diff, what = _dimension_proxy(case, e_star, runs, plan_case)
    except SimulationError as exc:
        return Choice("model.dimension", "3d", f"the full model: a proxy run to judge 2D stopped "
                                               f"({str(exc)[:120]}…)")
    if diff * PROXY_MARGIN <= case.accuracy:
        return Choice("model.dimension", "2d", f"a coarse 3D proxy run reports {what} within {diff:.2%} of 2D, "
                                               f"inside model.accuracy {case.accuracy:.2%} / {PROXY_MARGIN:g} (a "
                                               f"proxy's difference is itself uncertain): 2D (the ends' effect on "
                                               f"the reported quantities is small)", error=diff * PROXY_MARGIN)
    return Choice("model.dimension", "3d", f"a coarse 3D proxy run reports {what} {diff:.2%} away from 2D, "
                                           f"more than model.accuracy {case.accuracy:.2%} / {PROXY_MARGIN:g} (a "
                                           f"proxy's difference is itself uncertain): the ends matter, 3D")


def _proxy_grid(case: Case, e_star: float):
    """The automatic grid's sizing of a proxy (the case's largest load and stroke), and its x elements halved."""
    loading = case.loading
    sizing = auto_grid(case.geometry, False, loading.peak_load, loading.peak_stroke, loading.cycles,
                       sum(case.wear_coefficients()), e_star)
    return sizing, max(21, (sizing.elements[0] // 2) | 1)


def _dimension_proxy(case: Case, e_star: float, runs: SideRuns, plan_case: PlanCase) -> tuple[float, str]:
    cycles = case.loading.cycles
    sizing, nx = _proxy_grid(case, e_star)
    keys = (WEAR_KEYS[:2] + ("centre_wear_depth_stationary_um",) + WEAR_KEYS[2:] if cycles
            else ("max_pressure_MPa",))
    out = []
    for dim, domain, elements in (("2d", sizing.domain[:1], (nx,)), ("3d", sizing.domain, (nx, PROXY_ROWS))):
        corr = _full_corrections(case, dim)
        proxy = case.with_choices(dimension=dim, corrections=corr, snapshots=(cycles,), domain=domain,
                                  elements=elements, coarse_element=None, linear_jump=None, scheme="bdf2",
                                  preset=None, step_tolerance=max(case.step_tolerance, 0.03))
        out.append(proxy_summary(proxy, lambda setup: f"model.dimension auto: a {dim.upper()} proxy run "
                                 f"({' × '.join(map(str, elements))} elements, {cycles} cycles, tolerance "
                                 f"{setup.step_tolerance:g}) to compare 2D with 3D", runs, plan_case))
    return _worst(out, keys)


def _full_corrections(case: Case, dimension: str):
    """The corrections of the full model a dimension proxy runs: the case's own, less the free faces in 2D (which
    has no ends); in 3D with the free faces wherever they may apply (and, under auto, a tube's ring bending)."""
    corr, g = case.corrections, case.geometry
    given = () if corr in ("auto", "none") else tuple(corr)
    if dimension == "2d":
        return corr if not given else (tuple(c for c in given if c != "free_faces") or "none")
    if not g.free_faces or not (corr == "auto" or "free_faces" in given):
        return corr
    bending = g.body_corrections if corr == "auto" else ()
    return tuple(dict.fromkeys(given + ("free_faces",) + bending))


def available_corrections(case: Case, plane: bool) -> tuple[str, ...]:
    g = case.geometry
    return g.body_corrections + (("free_faces",) if g.free_faces and not plane else ())


def _faces_what(case: Case) -> str:
    names = {"moving": f"the {case.geometry.kind.split('_')[0]}'s ends", "stationary": "the flat's ends"}
    return " and ".join(f"{names[body]} ({length:g} mm apart)" for body, length in case.geometry.free_faces)


def choose_corrections(case: Case, plane: bool, runs: SideRuns, plan_case: PlanCase) -> Choice:
    """Compliance added to the half-spaces: the tube's ring bending, the free faces of bodies that end across the
    contact (3D).  auto: each correction whose effect on the reported quantities exceeds model.accuracy.
    Estimated before the run by quick proxy runs of the case with and without it (2D for ring bending, 3D at
    half the x resolution for free faces), compared on the maximum depths and scar widths of both bodies (and the
    flat's centre-line depth; the pressure of the unworn contact for a contact-only run).  A static estimate is not
    enough: in steady fretting wear the pressure follows from the wear (a nearly even wear rate across the
    contact), not from the compliance, so a correction that reshapes the pressure of a given worn shape may
    change the wear very little."""
    g = case.geometry
    available = available_corrections(case, plane)
    if case.corrections != "auto":
        chosen = () if case.corrections == "none" else tuple(case.corrections)
        for c in chosen:
            if c not in available:
                why = (" (a 2d model has no ends: use model.dimension: 3d)" if c == "free_faces" and g.free_faces
                       else "")
                raise CaseError(case.source, [("model.corrections", f"{c} does not apply to this {g.kind} model"
                                                                    f"{why}; available: "
                                                                    f"{', '.join(available) or 'none'}")])
        return Choice("model.corrections", chosen, "given in the case", True)
    if not available:
        reason = (f"none applies to a {g.kind}: both bodies are half-spaces" if not g.free_faces else
                  f"none applies to the 2D model of a {g.kind} (free faces need 3D)")
        return Choice("model.corrections", (), reason)
    chosen, reasons, dropped = [], [], 0.0
    for corr in available:
        kept, reason, error = _judge_correction(case, corr, runs, plan_case)
        chosen += [corr] if kept else []
        reasons.append(reason)
        dropped += error
    return Choice("model.corrections", tuple(chosen), "; ".join(reasons), error=dropped)


def _judge_correction(case: Case, corr: str, runs: SideRuns, plan_case: PlanCase) -> tuple[bool, str, float]:
    """Whether auto keeps a correction, why, and the model difference accepted where it is left out."""
    bending = corr == "ring_bending"
    what = "the tube wall's ring bending (Eq. 23)" if bending else FACES_NOTE.format(what=_faces_what(case))
    proxy = "a 2D proxy run" if bending else "a 3D proxy run at half the x resolution"
    try:
        diff, quantity = _correction_proxies(case, (corr,), "2d" if bending else "3d", runs, plan_case)
    except SimulationError as exc:
        return True, f"{what}: kept, {proxy} to judge it stopped ({str(exc)[:120]}…)", 0.0
    verb = "changes" if bending else "change"
    if diff * PROXY_MARGIN > case.accuracy:
        return True, (f"{what} {verb} {quantity} by {diff:.2%} in {proxy}, more than model.accuracy "
                      f"{case.accuracy:.2%} / {PROXY_MARGIN:g} (a proxy's difference is itself uncertain)"), 0.0
    return False, (f"{what} {verb} {quantity} by only {diff:.2%} in {proxy}, within model.accuracy "
                   f"{case.accuracy:.2%} / {PROXY_MARGIN:g} (a proxy's difference is itself uncertain): "
                   f"left out (set model.corrections to include it)"
                   + ("; in steady wear the pressure follows the wear, not the wall's compliance" if bending
                      else "")), diff * PROXY_MARGIN


def _correction_proxies(case: Case, corrections: tuple, dimension: str, runs: SideRuns,
                        plan_case: PlanCase) -> tuple[float, str]:
    """Largest relative difference of the reported quantities between proxy runs without and with
    ``corrections``: 2D at the automatic grid, or 3D at half its x resolution."""
    cycles = case.loading.cycles
    keys = WEAR_KEYS if cycles else ("max_pressure_MPa",)
    grid: dict = {"domain": None, "elements": None}
    if dimension == "3d":
        keys = keys + (("centre_wear_depth_stationary_um",) if cycles else ())
        e_star = _e_star(case)
        sizing, nx = _proxy_grid(case, e_star)
        # all the rows: the faces act on the end rows, which 15 coarse rows widen and blunt (1.0 % for 1.4 %)
        grid = {"domain": sizing.domain, "elements": (nx, sizing.elements[1])}
    out = []
    for corr in ((), corrections):
        proxy = case.with_choices(dimension=dimension, corrections=corr or "none", snapshots=(cycles,),
                                  coarse_element=None, linear_jump=None, scheme="bdf2", preset=None,
                                  step_tolerance=max(case.step_tolerance, 0.03) if dimension == "3d"
                                  else case.step_tolerance, **grid)
        out.append(proxy_summary(proxy, lambda setup: f"model.corrections auto: a {dimension.upper()} proxy run "
                                 f"{'with ' + ', '.join(corr) if corr else 'without corrections'} "
                                 f"({setup.grid.shape[1]} × {setup.grid.shape[0]} elements, {cycles} cycles, "
                                 f"tolerance {setup.step_tolerance:g})", runs, plan_case))
    return _worst(out, keys)


def stroke_proxies(case: Case, runs: SideRuns, plan_case: PlanCase) -> tuple[float, str, str]:
    """The largest relative difference of the reported quantities between the mid-stroke and the resolved stroke
    in 2D proxy runs at half the automatic grid's x resolution, how to name it, and what the proxies were."""
    cycles = case.loading.cycles
    sizing, nx = _proxy_grid(case, _e_star(case))
    dim, domain, elements = "2d", sizing.domain[:1], (nx,)
    keys = WEAR_KEYS[:2] + ("centre_wear_depth_stationary_um",) + WEAR_KEYS[2:]
    out = []
    for stroke in ("mid_stroke", "resolved"):
        proxy = case.with_choices(dimension=dim, corrections=_full_corrections(case, dim), snapshots=(cycles,),
                                  domain=domain, elements=elements, coarse_element=None, linear_jump=None,
                                  scheme="bdf2", preset=None, stroke_model=stroke, grid_error="none")
        out.append(proxy_summary(proxy, lambda setup: f"model.stroke auto: a {dim.upper()} proxy run, stroke "
                                 f"{stroke.replace('_', '-')} ({' × '.join(map(str, elements))} elements, {cycles} "
                                 f"cycles)", runs, plan_case))
    diff, what = _worst(out, keys)
    return diff, what, f"{dim.upper()} proxy runs ({' × '.join(map(str, elements))} elements)"


def _e_star(case: Case) -> float:
    return effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                             case.stationary.youngs_modulus, case.stationary.poissons_ratio)


# --- a wear limit's pilot ------------------------------------------------------------------------------------

def expected_stop(case: Case, runs: SideRuns, plan_case: PlanCase, pilot: Optional[float]) -> Optional[float]:
    """Where a run with wear limits is expected to stop: the cycle where a pilot run reached a limit (inf where it
    reached none by loading.cycles); None where nothing is known — no limits, a pilot that failed, or none run
    because nothing is sized from it (the grid given and the model chosen).  ``pilot``: a pilot's result already
    known (NaN: none is to be run)."""
    if not (case.limits and case.loading.cycles > 0 and (case.elements is None or "auto" in (case.dimension,
                                                                                          case.corrections))):
        return None
    if pilot is None:
        pilot = pilot_cycles(case, runs, plan_case)
    return None if pilot is None or pilot != pilot else pilot


def cycles_to_size(case: Case, plan: Plan, expected: Optional[float]) -> int:
    """The cycles the grid and auto's proxies take the wear of: loading.cycles, or, with wear limits, PILOT_MARGIN
    times ``expected``, where a pilot run reached a limit (loading.cycles is then only an upper bound: a scar
    sized for 10⁹ cycles would make the elements far too coarse for the scar at the limit)."""
    loading = case.loading
    if expected is not None and PILOT_MARGIN * expected < loading.cycles:  # reached well before loading.cycles
        sized = max(1, int(PILOT_MARGIN * expected))
        plan.warnings.append(f"wear limits: the grid and auto's proxies take the wear of {sized:,} cycles, "
                             f"{PILOT_MARGIN:g}× where a pilot run reached a limit "
                             f"({expected:,.0f}); loading.cycles ({loading.cycles:,}) is the upper bound")
        return sized
    return loading.cycles


def pilot_cycles(case: Case, runs: SideRuns, plan_case: PlanCase) -> Optional[float]:
    """Where a run with wear limits will stop, roughly: the case on the paper's element (its grid following the
    contact where it may coarsen), in 2D where the geometry has it, at a loose stepping tolerance, no companion
    (inf if no limit is reached, None if the pilot fails).  It sizes the grid and places the automatic recorded
    states."""
    # the paper's element (the accuracy rule at PILOT_ACCURACY asks no finer where the scar is wide enough to matter),
    # on a grid that follows the contact: it starts on the scar of its first coarsening and widens as it grows
    accuracy = max(case.accuracy, PILOT_ACCURACY)
    pilot = case.with_choices(dimension="2d" if case.geometry.has_2d else "3d", corrections="none",
                              grid_rule="accuracy", accuracy=accuracy, grid_error="none",
                              step_tolerance=max(case.step_tolerance, PILOT_TOLERANCE), pressure_accuracy=None,
                              snapshots=(0,), scheme="bdf2")

    def compute() -> Optional[float]:
        try:
            setup, filled, plan = plan_case(pilot, pilot=float("nan"))
            what = ("wear limits: a pilot run (the paper's element, a loose tolerance) to find roughly where the "
                    "limit is reached")
            # coarsened as its contact grows (fretsim.regrid): a tube's 6 µm Hertz contact grows to a scar
            # millimetres wide
            rule = regrid.rule_for(filled, setup, plan)
            if rule is None:
                last = runs.run(what, setup)
            else:
                last, _, _ = runs.run_following(what, setup, filled, rule,
                                                lambda c: plan_case(c, pilot=float("nan")), widen=True)
            return float(last.limit[1]) if last.limit else math.inf
        except (SimulationError, CaseError):
            return None
    # auto's proxies prepare variants of the case: one pilot serves them all
    return runs.remembered(runs.pilots, repr(pilot.to_dict()), compute)
