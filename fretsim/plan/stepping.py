"""The planner's stepping stage: the explicit stability limit from the cycle members' own stiffness, the
stepping scheme (a member of :mod:`fretsim.stepping`), its jumps and caps, and the recorded states.

The explicit limit is what an explicit scheme's jump must stay below, and for the implicit schemes it says
whether the paper's per-cycle update itself is stable on this grid; a model whose own wear modes grow (the
paper's mid-stroke gap when the moving body wears too little) is refused where they would grow over the run.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from fretsim.case import PRESET_LINEAR, Case, CaseError
from fretsim.grid import Grid
from fretsim.plan.choices import Choice, Plan
from fretsim.stability import Spectrum, combined, default_linear_jump, wear_spectrum
from fretsim.cycle import CYCLES
from fretsim.stepping import DEFAULT_SCHEME, SCHEMES
from fretsim.wear import AVERAGED

MODEL_GROWTH = math.log(1e3)  # a forced unstable model may grow a seed at most 1000-fold over the run
SHORT_RUN = 8  # runs of at most this many cycles are taken a cycle at a time: exact, and as cheap


@dataclass(frozen=True)
class Stepping:
    """The stepping stage's result."""

    scheme: str
    spectrum: Spectrum
    linear_jump: int
    max_jump: Optional[int]
    implicit_cap: float  # largest s keeping C + s·W positive definite
    per_cycle: bool  # implicit schemes follow the per-cycle update (φ = h + ½r), not the continuous ODE
    snapshots: tuple

    @property
    def limit(self) -> float:
        return self.spectrum.limit


def spectrum(model, members: tuple) -> Spectrum:
    """The explicit update's spectrum for the solve grid's compliance and each distinct member's stiffness (the
    most restrictive over a load history's blocks)."""
    op = model.solve_compliance
    distinct = {id(m): m for m in members}.values()  # a repeated block shares its member
    return combined(wear_spectrum(op, m.stiffness()) for m in distinct)




# strokes from δ_t to this many δ_t (gross slip, not far from it), with the stroke-averaged gap, are warned of (below;
# in partial slip forward Euler held: 0.22 % against the run cycle by cycle, estimated 0.29 %, a review's run)
NEAR_TRANSITION = 2.0


def warn_near_transition(case: Case, plan: Plan, gap_model: str, regime, scheme: str) -> None:
    """A Coulomb cycle near the gross-slip transition with the stroke-averaged gap: the stepping's own estimate is no
    bound there (fretsim.stepping.implicit.near_transition; forward-Euler steps take over from BDF2 where the slip
    spreads, 5× nearer the run cycle by cycle, their estimate still ~10× short), which the run must say."""
    transition = regime.transition
    if (not AVERAGED.get(gap_model, False) or CYCLES[regime.slip.value].assumes_gross_slip or transition is None
            or not transition <= case.loading.peak_stroke < NEAR_TRANSITION * transition
            or not SCHEMES[scheme].implicit):
        return
    plan.warnings.append(f"near the gross-slip transition (the stroke {case.loading.peak_stroke * 1e3:.3g} µm, δ_t "
                         f"{transition * 1e3:.3g} µm) with the stroke-averaged gap (the moving body wearing under "
                         f"0.307 of the flat) the stepping's error estimate is no bound: a review measured 1.9 % "
                         f"against 0.2 % estimated (Ti-6Al-4V, k_m = k_s/10, μ 1.0, 8 µm); jumping.max: 20 brought "
                         f"it to 0.3 %, at 8× the solves — check a result that matters that way")


def build(case: Case, plan: Plan, grids, model, cycles, allow_unstable: bool) -> Stepping:
    spec = spectrum(model, cycles.members)
    limit = spec.limit
    _check_model_growth(case, spec, plan)
    scheme = plan.add(choose_scheme(case))
    stepper = SCHEMES[scheme]
    solve_grid = model.solve_compliance.grid
    jump = plan.add(choose_linear_jump(case, scheme, limit, solve_grid))
    if not stepper.implicit:
        _check_jump(case, jump, limit, solve_grid, plan, allow_unstable)
    max_jump, chosen = stepper.max_jump(case, jump, limit, allow_unstable)
    for value, reason in chosen:
        plan.add(Choice("jumping.max", value, reason))
    plan.add(Choice("solver.method", case.solver, "given in the case" if case.solver != "cg" else
                    "cg: FFT-based constrained conjugate gradient, O(n log n) per iteration", case.solver != "cg"))
    cap = 0.5 / spec.growth_rate if spec.growth_rate > 0 else float("inf")
    per_cycle = limit > 1.0
    if stepper.implicit and not per_cycle:
        plan.warnings.append(f"the paper's per-cycle update is itself unstable on this grid (explicit limit "
                             f"{limit:.3g} cycles < 1): the implicit steps follow the continuous wear ODE instead; "
                             f"check the wear coefficients, or coarsen the grid")
    cycles_n = case.loading.cycles
    beyond = [s for s in grids.snapshots if s > cycles_n]
    if beyond:
        plan.warnings.append(f"snapshots {list(beyond)} lie beyond the run's {cycles_n} cycles and are skipped")
    snapshots = tuple(sorted({s for s in grids.snapshots if s <= cycles_n} | {cycles_n}))
    return Stepping(scheme, spec, jump, max_jump, cap, per_cycle, snapshots)


def _check_model_growth(case: Case, spectrum: Spectrum, plan: Plan) -> None:
    """The paper's gap model forced where it is unstable: refused if its spurious modes grow over the run."""
    rate = spectrum.growth_rate
    if rate <= 0:
        return
    growth = rate * case.loading.cycles
    if growth > MODEL_GROWTH:
        raise CaseError(case.source, [("model.gap", f"the paper's mid-stroke gap is unstable for these wear "
                                                    f"coefficients (the moving body wears too little): its "
                                                    f"fastest wear mode grows by {rate:.3g} of itself per cycle, "
                                                    f"e^{growth:.0f} over the run. Use model.gap: auto (or "
                                                    f"stroke_average), which is stable")])
    plan.warnings.append(f"the mid-stroke gap model is unstable here (growth rate {rate:.3g} per cycle), but "
                         f"over {case.loading.cycles} cycles a seed grows at most by a factor {math.exp(growth):.3g}")


def choose_scheme(case: Case) -> Choice:
    if case.preset is not None:
        return Choice("jumping.scheme", case.scheme, f"preset {case.preset}: the paper's adaptive jumping", True)
    given = any(k.startswith("jumping.scheme=") for k in case.overrides)
    cycles = case.loading.cycles
    if cycles <= SHORT_RUN and case.scheme == DEFAULT_SCHEME and not given:
        return Choice("jumping.scheme", "linear", f"{cycles} cycles: taken one cycle at a time, which is the "
                                                  f"model itself and no dearer than steps")
    return Choice("jumping.scheme", case.scheme, SCHEMES[case.scheme].reason(case))


def choose_linear_jump(case: Case, scheme: str, limit: float, grid: Grid) -> Choice:
    cycles = case.loading.cycles
    stepper = SCHEMES[scheme]
    if stepper.implicit:
        return Choice("jumping.linear", default_linear_jump(limit, cycles),
                      "not used by implicit steps; half the explicit stability limit, for reference")
    if cycles <= SHORT_RUN and stepper.per_cycle_short_runs and case.linear_jump is None:
        return Choice("jumping.linear", 1, "one cycle per step: the model's own per-cycle update")
    if case.linear_jump is not None:
        return Choice("jumping.linear", case.linear_jump, "given in the case", True)
    half = default_linear_jump(limit, cycles)
    if case.preset is not None:
        paper = PRESET_LINEAR[case.preset]
        if paper <= half:
            return Choice("jumping.linear", paper, f"preset {case.preset}: the paper's ΔN_L = {paper}")
        return Choice("jumping.linear", half, f"preset {case.preset}: the paper's ΔN_L = {paper} exceeds this "
                                              f"grid's explicit stability limit {limit:.4g} cycles (elements "
                                              f"{grid.dx * 1e3:.3g} µm; the paper's were coarser): scaled to half "
                                              f"the limit, {half}")
    return Choice("jumping.linear", half, f"half the explicit stability limit {limit:.4g} cycles: every mode "
                                          f"decays without changing sign")


def _check_jump(case: Case, jump: int, limit: float, grid: Grid, plan: Plan, allow_unstable: bool) -> None:
    """An explicit jump beyond the stability limit is refused (unless studying the instability itself)."""
    if jump > limit and not allow_unstable:
        raise CaseError(case.source, [("jumping.linear", f"{jump} cycles exceeds the explicit stability limit "
                                      f"{limit:.4g} cycles of this grid (element {grid.dx * 1e3:.3g} µm, "
                                      f"stroke {case.loading.peak_stroke * 1e3:.3g} µm): the pressure would "
                                      f"checkerboard. Use at most {max(1, int(limit))} (default: "
                                      f"{default_linear_jump(limit, case.loading.cycles)}), or jumping.scheme: "
                                      f"bdf2, which has no such limit"
                                      + (" (below one cycle even an update per cycle is unstable on this grid: "
                                         "grid.rule: paper gives the paper's coarser element, and a larger limit)"
                                         if limit < 1 and case.elements is None and case.grid_rule == "accuracy"
                                         else ""))])
    if jump > 0.5 * limit:
        plan.warnings.append(f"jumping.linear = {jump} lies between half the explicit stability limit and the "
                             f"limit ({limit:.4g} cycles): stable, but wear modes oscillate while they decay")
