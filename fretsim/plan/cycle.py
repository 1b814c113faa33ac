"""The planner's cycle stage: the fretting regime of every block, the fretting-cycle member that models it and
where the normal contact is solved, then the member built by its family for each block of the loading.

The regime follows from the unworn contact: gross slip needs the stroke to exceed δ_t, the rig displacement
at which the last point starts to slide (δ_t = max K·μp: every point then carries μp; with the rig's 1/k
included).  A load history's regime is that of its block nearest partial slip.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from fretsim import cycle as family
from fretsim.case import Case, CaseError
from fretsim.compliance import bodies
from fretsim.compliance.tangential import Tangential
from fretsim.cycle import CYCLES, STROKES
from fretsim.cycle.coulomb import gross_slip_stroke
from fretsim.grid import Grid
from fretsim.loading import Block
from fretsim.plan.choices import Choice, Plan
from fretsim.reference import effective_modulus
from fretsim.reference.mindlin import dundurs_beta
from fretsim.solvers import solve


@dataclass(frozen=True)
class Regime:
    """The regime of the unworn contact: the tangential operator, δ_t and the block it was judged on."""

    tangential: object  # K on the run's grid (None without any friction coefficient)
    transition: Optional[float]  # δ_t of the block nearest partial slip (mm; None without μ)
    block: Block  # the block nearest partial slip (the first without μ)
    slip: Choice
    stick_cycles: int = 0  # the loading's cycles in blocks whose stroke is below their own δ_t (unworn)


@dataclass(frozen=True)
class Cycles:
    """The cycle stage's result: the member's name, where the contact is solved, a member per block."""

    slip: str
    stroke_model: str
    increments: int  # per half-stroke
    members: tuple  # one per block of the loading, in the order applied (a repeated block shares its member)


def tangential_operator(case: Case, grid: Grid):
    """Both bodies' tangential compliance on the grid, the 2D datum (or each body's from its shape) and the rig's
    compliance (:mod:`fretsim.compliance.tangential`)."""
    plane = grid.plane_strain
    volume_factor = case.geometry.line_length if plane else 1.0
    k_t = case.loading.tangential_stiffness
    rig = grid.area * volume_factor / k_t if k_t else 0.0
    bodies_ = [(m.youngs_modulus, m.poissons_ratio) for m in (case.moving, case.stationary)]
    logs = log_datums(case)
    return Tangential(grid, bodies_, case.geometry.line_length if plane or any(x is not None for x in logs) else None,
                      rig, log_datums=logs)


def _shapes(case: Case) -> tuple:
    """Each body's shape (None: a half-space) and the loaded strip's half-width (mm): the unworn contact at the peak
    load; shapes not much larger than that contact refused."""
    e_star = effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                               case.stationary.youngs_modulus, case.stationary.poissons_ratio)
    shapes, strip = case.geometry.tangential_shapes(case.geometry.hertz(case.loading.peak_load, e_star).half_width_x)
    problems = [(key, f"{value * 1e3:.4g} µm is less than {SHAPE_TO_CONTACT:g}× the contact's width "
                      f"{2e3 * strip:.4g} µm (at {case.loading.peak_load:.4g} N): the body's share of the stroke is "
                      f"modelled as a half-plane's near the contact with the rest of the body adding a uniform "
                      f"displacement, which holds for a body much larger than its contact; expected at least "
                      f"{SHAPE_TO_CONTACT * 2 * strip:.3g} mm, or leave the shape out (a half-space)")
                for key, value in case.geometry.shape_sizes() if value < SHAPE_TO_CONTACT * 2 * strip]
    if problems:
        raise CaseError(case.source, problems)
    return shapes, strip


def log_datums(case: Case) -> tuple:
    """ln of each body's datum distance (mm) from its shape (geometry.flat_width/flat_thickness, moving_height),
    None where it is a half-space."""
    shapes, strip = _shapes(case)
    return tuple(None if shape is None else bodies.log_datum(shape, m.youngs_modulus, m.poissons_ratio, strip)
                 for shape, m in zip(shapes, (case.moving, case.stationary)))


def strip_compliances(case: Case) -> tuple:
    """Each body's mean strip displacement per unit tangential force per unit length (mm per N/mm) from its shape,
    None where it is a half-space (what /inputs records)."""
    shapes, strip = _shapes(case)
    return tuple(None if shape is None else bodies.strip_compliance(shape, m.youngs_modulus, m.poissons_ratio, strip)
                 for shape, m in zip(shapes, (case.moving, case.stationary)))


SHAPE_TO_CONTACT = 10  # a body's sizes over its contact's width: the datum then moves by < 1 % with the strip


def grid_load(case: Case, grid: Grid, normal_load: float) -> float:
    """A load on the grid: N in 3D, N/mm (over the line length) in 2D."""
    return normal_load / case.geometry.line_length if grid.plane_strain else normal_load


def regime(case: Case, grid: Grid, compliance) -> Regime:
    """The unworn contact's regime on the run's grid: each distinct block with a μ solved once, the one whose
    stroke is nearest δ_t kept."""
    blocks = case.loading.blocks
    tangential = transition = None
    nearest = blocks[0]
    if any(b.friction_coefficient is not None for b in blocks):
        tangential = tangential_operator(case, grid)
        worst, sticks = None, set()
        for b in dict.fromkeys(blocks):
            if b.friction_coefficient is None:
                continue
            p_b = solve(compliance, case.geometry.separation(grid), grid_load(case, grid, b.normal_load),
                        tol=case.tolerance).pressure
            t_b = gross_slip_stroke(tangential, p_b, b.friction_coefficient)
            if b.stroke < t_b:
                sticks.add(b)
            if worst is None or t_b / b.stroke > worst[0]:
                worst = (t_b / b.stroke, t_b, b)
        _, transition, nearest = worst
        # (a history's partial-slip blocks take forward-Euler steps: what `check` counts of them)
        stick = sum(b.cycles for b in blocks if b in sticks)
        return Regime(tangential, transition, nearest, choose_slip(case, nearest, transition), stick)
    return Regime(tangential, transition, nearest, choose_slip(case, nearest, transition))


def choose_slip(case: Case, block: Block, transition: Optional[float]) -> Choice:
    """The fretting-cycle member: the paper's uniform gross slip, or friction resolved through the cycle.

    Below δ_t the contact partly sticks and a member that assumes gross slip is refused.  Above it every point
    still slides less than the rig by its elastic tangential displacement, at most δ_t: uniform slip
    overestimates the slip, and so the wear, by up to δ_t/δ; auto keeps the paper's member only where that is
    within model.accuracy.
    """
    mu, stroke = block.friction_coefficient, block.stroke
    given = CYCLES.get(case.slip)  # None: auto
    if transition is not None and (given is None or given.assumes_gross_slip) and stroke <= transition:
        if given is not None:
            raise CaseError(case.source, [("model.slip", f"{case.slip} slip is refused here: the stroke "
                                                         f"{stroke * 1e3:.4g} µm is within the partial-slip "
                                                         f"limit δ_t = {transition * 1e3:.4g} µm for μ = {mu:g}, so "
                                                         f"the contact partly sticks and uniform slip (4δ at every "
                                                         f"point) would overestimate the wear; use model.slip: "
                                                         f"{family.FRICTION} (or auto)")])
        return Choice("model.slip", family.FRICTION, f"partial slip: the stroke {stroke * 1e3:.4g} µm is within the "
                                                     f"gross-slip limit δ_t = {transition * 1e3:.4g} µm (μ = {mu:g}): "
                                                     f"the centre sticks and only the slip annulus wears")
    if given is not None:
        return Choice("model.slip", case.slip, "given in the case", True)
    if mu is None:
        return Choice("model.slip", family.PAPER, "no friction coefficient: the paper's gross slip is assumed (give "
                                                  "loading.friction_coefficient to judge the regime)")
    if transition == 0.0:  # μ = 0
        return Choice("model.slip", family.PAPER, "frictionless (μ = 0): no shear traction, so nothing sticks and the "
                                                  "bodies take none of the stroke elastically; every point slides the "
                                                  "whole stroke, as the paper's uniform slip assumes (exact here)")
    deficit = transition / stroke
    if deficit > case.accuracy:
        return Choice("model.slip", family.FRICTION, f"gross slip (the stroke is {1 / deficit:.1f}× the limit δ_t = "
                                                     f"{transition * 1e3:.4g} µm), but the bodies' elastic tangential "
                                                     f"displacement takes up to δ_t/δ = {deficit:.1%} of the slip, "
                                                     f"more than model.accuracy {case.accuracy:.1%}: Coulomb friction "
                                                     f"through the cycle")
    return Choice("model.slip", family.PAPER, f"gross slip far above the limit: the stroke is {1 / deficit:.0f}× "
                                              f"δ_t = {transition * 1e3:.4g} µm, so uniform slip overestimates the "
                                              f"slip by at most δ_t/δ = {deficit:.2%}, within model.accuracy "
                                              f"{case.accuracy:.1%}", error=deficit)


def choose_stroke(case: Case, slip: str, regime_: Regime, runs, plan_case) -> Choice:
    """mid_stroke (one normal solve per cycle, the paper's) or resolved (one per increment, at each position).

    auto: the paper's member keeps the paper's mid-stroke.  With friction resolved through the cycle, a pair of
    2D proxy runs at half the x resolution compares the two on the depths and widths the
    run reports: resolved where they differ by more than model.accuracy/PROXY_MARGIN (the proxy's difference is
    itself uncertain), mid-stroke elsewhere, with the difference as the model's share of the error.  A point
    contact, which has no 2D model, is not judged (its 3D proxies would cost about the run).  In partial
    slip the moving body stays within δ ≤ δ_t of mid-stroke, a small share of the contact's width, and the
    two coincide (a 4 µm stroke on McColl's cylinder: within 0.1 %): no proxy is run."""
    if case.stroke_model != "auto":
        return Choice("model.stroke", case.stroke_model, "given in the case", True)
    if CYCLES[slip].assumes_gross_slip:
        return Choice("model.stroke", family.MID_STROKE, "the paper's: the pressure solved at mid-stroke, the flat "
                                                         "wearing with its stroke average")
    held = ("Mindlin's setting: the normal contact at mid-stroke held through the cycle, each point's slip and "
            "traction resolved in increments")
    if not case.loading.cycles:
        return Choice("model.stroke", family.MID_STROKE, held + " (no wear: the stroke moves no worn surface)")
    if regime_.transition is not None and all(
            b.stroke <= regime_.transition for b in case.loading.blocks if b.friction_coefficient is not None):
        return Choice("model.stroke", family.MID_STROKE, held + "; in partial slip the contact barely moves "
                                                                "over the flat, resolving the stroke changes nothing")
    if not case.geometry.has_2d:
        return Choice("model.stroke", family.MID_STROKE, held + f"; not judged against the resolved stroke: a "
                                                                f"{case.geometry.kind} has no 2D model for a cheap "
                                                                f"proxy (a 3D one costs about the run): set "
                                                                f"model.stroke: resolved to compare")
    from fretsim.errors import SimulationError
    from fretsim.plan.model import PROXY_MARGIN, stroke_proxies
    try:
        diff, what, proxy = stroke_proxies(case, runs, plan_case)
    except SimulationError as exc:
        return Choice("model.stroke", family.RESOLVED, f"the contact over the worn flat at each position of the "
                                                       f"stroke: a proxy run to judge mid-stroke stopped "
                                                       f"({str(exc)[:120]}…)")
    if diff * PROXY_MARGIN > case.accuracy:
        return Choice("model.stroke", family.RESOLVED,
                      f"{proxy} report {what} {diff:.2%} away from the mid-stroke model, more than model.accuracy "
                      f"{case.accuracy:.2%} / {PROXY_MARGIN:g} (a proxy's difference is itself uncertain): the "
                      f"contact over the worn flat at each position of the stroke (its loop about 2.5× the cost in "
                      f"2D, 3× in 3D)")
    return Choice("model.stroke", family.MID_STROKE,
                  f"{held}: {proxy} report {what} within {diff:.2%} of the resolved stroke, within "
                  f"model.accuracy {case.accuracy:.2%} / {PROXY_MARGIN:g}", error=diff * PROXY_MARGIN)


def build(case: Case, plan: Plan, grids, model, regime_: Regime, proxy_case: Case, runs, plan_case) -> Cycles:
    """The member and the stroke model recorded, then a member for each block of the loading."""
    slip = plan.add(regime_.slip)
    stroke_model = plan.add(choose_stroke(proxy_case, slip, regime_, runs, plan_case))
    increments = plan.add(choose_increments(case, stroke_model, regime_))
    grid = grids.grid
    built: dict = {}  # a repeated block shares its member (and its cached operators)

    def member(block: Block):
        return family.build(slip, stroke_model, dict(
            grid=grid, solve_grid=model.solve_compliance.grid, compliance=model.compliance,
            tangential=regime_.tangential, block=block, load=grid_load(case, grid, block.normal_load),
            law=case.law, moving=case.moving, stationary=case.stationary, gap_model=model.gap_model,
            increments=increments,
            volume_factor=case.geometry.line_length if grid.plane_strain else 1.0))

    members = tuple(built.setdefault(b, member(b)) for b in case.loading.blocks)
    shapes = [key for key, _ in case.geometry.shape_sizes()]
    if shapes and not CYCLES[slip].needs_friction:
        effect = ("sets only δ_t (the regime), not the wear" if regime_.transition is not None else
                  "plays no part (there is no loading.friction_coefficient)")
        plan.warnings.append(f"{', '.join(shapes)} given, but the {slip} cycle has every point slide with the rig: "
                             f"the bodies' tangential compliance, which their shapes set, {effect}; model.slip: "
                             f"{family.FRICTION} lets it take up the stroke")
    if not members[0].linear:
        _check_incremental(case, grids, model, plan, regime_.transition)
    if STROKES[stroke_model]:
        _warn_resolved(case, plan, increments)
    return Cycles(slip, stroke_model, increments, members)


def _check_incremental(case: Case, grids, model, plan: Plan, transition: Optional[float]) -> None:
    """What the incremental cycle does not do, refused or said."""
    if grids.coarse is not None:
        partial = transition is not None and case.loading.peak_stroke <= transition
        raise CaseError(case.source, [("grid.coarse_element", "grid refinement (Eqs. 11-12) applies to the "
                                                              "uniform-slip model at mid-stroke only; remove "
                                                              "grid.coarse_element" + (
                                                                  " (this stroke is in partial slip, where uniform "
                                                                  "slip is refused)" if partial else
                                                                  ", or use model.slip: uniform"))])
    beta = dundurs_beta(case.moving.youngs_modulus, case.moving.poissons_ratio, case.stationary.youngs_modulus,
                        case.stationary.poissons_ratio)
    mu = case.loading.friction_coefficient or 0.0
    if abs(beta) * mu > case.accuracy:
        plan.warnings.append(f"dissimilar materials: Dundurs' β = {beta:.3f}, so the shear traction changes the "
                             f"normal pressure by about βμ = {abs(beta) * mu:.1%} (first order), more than "
                             f"model.accuracy {case.accuracy:.1%}; fretsim solves the normal and tangential "
                             f"problems uncoupled and neglects it")
    if model.corrections:
        plan.warnings.append(f"the corrections {', '.join(model.corrections)} add normal compliance only: the "
                             f"tangential compliance is the half-spaces'"
                             + (" (or the bodies' shapes, where given)" if case.geometry.shape_sizes() else ""))


RESOLVED_INCREMENTS = 5  # auto, the stroke resolved in gross slip: scripts/results/resolved_increments_auto.txt
HELD_INCREMENTS = 9  # auto otherwise: they draw the loop and sample a fatigue state's cycle (and partial slip's)


def choose_increments(case: Case, stroke_model: str, regime_: Regime) -> Choice:
    """The increments per half-stroke.  With the stroke resolved they are the quadrature of each point's travel
    over the worn flat, and each costs a normal solve of the stack: 5 where every block's elastic side (2δ_t after
    a reversal, Masing) fits in one of them (δ ≥ 5δ_t), so that after it the contact slides whole — McColl's four
    Table 4 cases (2D) and 185 N (3D) come within 0.1 % in depth and two elements in width of 27 increments, at
    two thirds of 9's cost in 3D, and the runs' estimates cover it; 9 otherwise (a resolved stroke in partial slip,
    the Ti-6Al-4V fretting-fatigue case: 5 moved its depth by 0.5 % and its damage by 2 %), and 9 wherever fatigue is
    computed, whose stress history they sample (the same case in gross slip, 40 µm: Miner's sum 32 % low at 5).  With the contact held
    at mid-stroke a half-stroke is one monotone increment for the wear, whatever their number: 9, which draw the
    recorded loop and sample a fatigue state's cycle, as before."""
    if case.increments is not None:
        return Choice("model.increments", case.increments, "given in the case", True)
    if STROKES[stroke_model] and (case.stationary.fatigue is not None or case.moving.fatigue is not None):
        # (a fatigue state's stress history is sampled at the increments: the Ti-6Al-4V case at 40 µm, gross slip,
        #  had its Miner's sum 32 % low at 5 against 27, 2.6 % at 9)
        return Choice("model.increments", HELD_INCREMENTS,
                      f"{HELD_INCREMENTS} positions a half-stroke with the stroke resolved and fatigue: a fatigue "
                      f"state's stress history is sampled at them (5 put a gross-slip Miner's sum 32 % low)")
    if STROKES[stroke_model]:
        # (the block nearest partial slip is the one whose elastic side takes the largest share of its stroke)
        if regime_.transition is not None and regime_.block.stroke >= RESOLVED_INCREMENTS * regime_.transition:
            return Choice("model.increments", RESOLVED_INCREMENTS,
                          f"{RESOLVED_INCREMENTS} positions a half-stroke with the stroke resolved in gross slip (δ ≥ "
                          f"{RESOLVED_INCREMENTS}δ_t: the elastic side fits in one): McColl's cases come within 0.1 % "
                          f"in depth over their 18 000 cycles (0.3 % at 10⁶) and two elements in width of 27 (2D and 3D; "
                          f"scripts/results/resolved_increments_auto.txt)")
        return Choice("model.increments", HELD_INCREMENTS,
                      f"{HELD_INCREMENTS} positions a half-stroke with the stroke resolved: a stroke below "
                      f"{RESOLVED_INCREMENTS}δ_t spends more than one of 5 increments on its elastic side")
    return Choice("model.increments", HELD_INCREMENTS,
                  f"{HELD_INCREMENTS}: the contact held at mid-stroke, they draw the recorded loop and sample a "
                  f"fatigue state's cycle (the wear does not depend on them)")


def _warn_resolved(case: Case, plan: Plan, increments: int) -> None:
    plan.add(Choice("model.gap", case.gap_model, "not used: the stroke is resolved, each position sees the "
                                                 "flat's wear under it", case.gap_model != "auto"))
    plan.warnings.append("model.stroke resolved: the cost estimate times a cycle on the unworn contact and doubles "
                         "it for the worn contact's wider windows; McColl's cases took 0.6–1.6× their estimates "
                         "(README: the resolved stroke)")
    if increments < 5:
        plan.warnings.append(f"model.increments {increments} with the stroke resolved: the contact "
                             f"is solved at only {increments} position(s) per half-stroke, so each "
                             f"point's travel over the worn flat is sampled coarsely (McColl 185 N 2D: 3 "
                             f"increments 0.26 % below 19 in depth, 9 within 0.03 %: README)")
