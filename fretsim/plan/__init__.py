"""The plan of a run: every automatic decision, each a small function returning its value and its reason.

:func:`prepare` turns a validated :class:`~fretsim.case.Case` into the loop's :class:`~fretsim.simulate.Setup`
(arrays, numbers, operators) and a *filled* case in which every automatic choice is written out, so the run
can be repeated — or resumed — exactly.  It reads as its stages, in order, each a module of this package:

1. :mod:`.inputs` — plausible input, the elastic model's range, the unworn contact;
2. :mod:`.model` (its pilot) — where a run with wear limits is expected to stop, and the cycles it is sized for;
3. :mod:`.grid` — the domain, the elements, the recorded states (on the way to the expected stop), the memory;
4. :mod:`.model` — the dimension, the corrections and the gap model (auto's proxies), and their operators;
5. :mod:`.cycle` — the regime of every block and the fretting-cycle member (a partial-slip contact sends the
   planner back to 3 on a finer grid), then the member built by its family for each block;
6. :mod:`.stepping` — the stability limit from the members' stiffness, the scheme, its jumps and caps;
7. :mod:`.cost` — the solves and seconds the run will take (for ``check`` and the progress bar).

The list of :class:`Choice` is stored in the results file (``/choices``) and printed by ``fretsim check``;
choices the case made itself are listed too, as "given".
"""
from __future__ import annotations

import dataclasses
import functools
from typing import Optional

from fretsim.case import Case, CaseError
from fretsim.fatigue.damage import FatigueSpec, fatigue_states
from fretsim.fatigue.history import depths
from fretsim.fatigue.swt import Basquin
from fretsim.plan import cycle, grid, inputs, model, stepping
from fretsim.plan.choices import Choice, Plan, show
from fretsim.plan.cost import estimate_cost, estimate_solves
from fretsim.plan.model import available_corrections
from fretsim.plan.runs import SideRuns
from fretsim.simulate import Setup
from fretsim.stepping.implicit import DEPTH_SHARE
from fretsim.wear import wear_reach

__all__ = ["Choice", "Plan", "SideRuns", "available_corrections", "estimate_cost", "estimate_solves", "notes_of",
           "prepare", "restore", "show"]


def prepare(case: Case, allow_unstable: bool = False, runs: Optional[SideRuns] = None, *,
            pilot: Optional[float] = None) -> tuple[Setup, Case, Plan]:
    """Unpack a case into arrays and numbers; fill the automatic choices into the returned case.

    A linear jump beyond the explicit stability limit is refused (CaseError) unless ``allow_unstable`` (for
    studies of the instability itself); so is the paper's gap model where it is unstable over the run.  ``runs``
    announces the runs planning makes besides the run (auto's proxies, a pilot) and keeps their results for the
    next plan in its keeping; ``pilot`` is a pilot's result already known (NaN: none is to be run).
    """
    runs = runs if runs is not None else SideRuns()
    plan_case = functools.partial(prepare, runs=runs)
    plan = Plan()
    case = inputs.tighten_for_pressure(case, plan)
    contact = inputs.contact(case, plan)
    expected = model.expected_stop(case, runs, plan_case, pilot)
    sized = model.cycles_to_size(case, plan, expected)
    # auto's proxies compare the models' depths and widths: at a limit the limited one is pinned, so they run
    # without the limits, over the cycles the run will take
    proxy_case = case.with_choices(limits=(), loading=case.loading.with_cycles(sized)) if case.limits else case
    start, refine = plan.copy(), 1.0
    while True:  # twice at most: a partial-slip contact is planned again on the grid it needs
        plan = start.copy()
        dimension = plan.add(model.choose_dimension(proxy_case, contact.e_star, runs, plan_case))
        grids = grid.build(case, plan, contact, dimension, sized, refine, expected)
        operators = model.build(case, plan, grids, contact.e_star, proxy_case, runs, plan_case)
        regime = cycle.regime(case, grids.grid, operators.compliance)
        finer = grid.refined(case, regime.slip.value, regime.transition, contact, refine)
        if finer is None:
            break
        refine = finer
    grid.warn_unresolved_stick(case, plan, regime.slip.value, regime.transition, contact, grids.grid)
    if case.stationary.fatigue is not None and not grids.plane:
        plan.warnings.append("fretting fatigue in 3D: the plane search over the flat's volume costs about 2.5–3.5× the "
                             "wear run in partial slip and 9–30× in gross slip (README: the cost of fatigue); "
                             "`fretsim check` includes it in its time estimate")
    cycles = cycle.build(case, plan, grids, operators, regime, proxy_case, runs, plan_case)
    steps = stepping.build(case, plan, grids, operators, cycles, allow_unstable)
    stepping.warn_near_transition(case, plan, operators.gap_model, regime, steps.scheme)
    setup = _setup(case, plan, grids, operators, regime, cycles, steps, contact)
    if expected is not None:
        setup = dataclasses.replace(setup, expected_stop=float(expected))
    return setup, _filled(case, grids, operators, cycles, steps), plan


def _setup(case: Case, plan: Plan, grids, operators, regime, cycles, steps, contact) -> Setup:
    """The loop's setup: arrays, numbers, operators, the loading and the members."""
    g, members = case.geometry, cycles.members
    first = members[0]
    return Setup(grid=grids.grid, compliance=operators.compliance, gap=g.separation(grids.grid),
                 loading=case.loading, cycle=first, block_cycles=members if len(members) > 1 else (),
                 wear_limits=dict(case.limits), wall=getattr(g, "wall", None) if case.limits else None,
                 limit_tolerance=case.step_tolerance * DEPTH_SHARE, frequency=case.loading.frequency,
                 band=wear_reach(grids.grid.dx, case.loading.peak_stroke, first.stiffness().gap_model) + 1,
                 scheme=steps.scheme, linear_jump=steps.linear_jump, stability_limit=steps.limit,
                 method=case.solver, tolerance=case.tolerance, snapshots=steps.snapshots,
                 volume_factor=g.line_length if grids.plane else 1.0, limits=g.limits, y_edges_free=g.y_edges_free,
                 eta=case.eta, max_jump=steps.max_jump, step_tolerance=case.step_tolerance,
                 implicit_cap=steps.implicit_cap, coarse=grids.coarse, coarse_compliance=operators.coarse_compliance,
                 coarse_gap=operators.coarse_gap, per_cycle=steps.per_cycle,
                 gross_slip_stroke=regime.transition if regime.transition is not None else float("nan"),
                 regime_block=regime.block if regime.transition is not None else None,
                 stick_cycles=regime.stick_cycles,
                 notes=notes_of(plan), planned_extent=grids.sizing.final_extent,
                 **_fatigue(case, grids.grid, steps.snapshots, contact))


HALF_SPACE = 0.1  # the moving body's fatigue: the largest unworn contact half-width a/R its half-space may take


def _fatigue(case: Case, grid, snapshots: tuple, contact) -> dict:
    """Each body's fatigue, where the case gives its constants ({"fatigue": the flat's, "fatigue_moving": the
    moving body's}): the curve (its endurance limit, a stress amplitude, as the SWT σ_e²/E it stands for), the
    depths — to four unworn Hertz half-widths and the stroke's reach twice, the region the moving load sweeps,
    fixed for the run so that the damage adds up at the same points, and the same for both bodies (one /fields/z)
    — and the states (those on the way to each recorded state's end)."""
    given = {body: m for body, m in (("stationary", case.stationary), ("moving", case.moving))
             if m.fatigue is not None}
    if not given:
        return {}
    deepest = 4.0 * contact.hertz.half_width_x + 2.0 * case.loading.peak_stroke
    for m in given.values():
        if m.fatigue.critical_distance is not None:
            deepest = max(deepest, 2.0 * m.fatigue.critical_distance)
    if "moving" in given:
        _check_half_space(case, contact.hertz.half_width_x)
    ends = {case.loading.cycles} | {max(snapshots, default=0)}
    states = tuple(sorted(set().union(*(fatigue_states(n, snapshots) for n in ends))))
    out = {}
    for body, m in given.items():
        f, e = m.fatigue, m.youngs_modulus
        curve = Basquin(f.strength_coefficient, f.strength_exponent, f.ductility_coefficient, f.ductility_exponent,
                        e, endurance_limit=None if f.endurance_limit is None else f.endurance_limit ** 2 / e)
        out["fatigue" if body == "stationary" else "fatigue_moving"] = FatigueSpec(
            curve=curve, poisson=m.poissons_ratio, depths=depths(grid.dx, deepest),
            critical_distance=f.critical_distance, states=states, crack_limit=case.crack_limit,
            keep_stresses=case.output_stresses, body=body)
    return out


def _check_half_space(case: Case, half_width: float) -> None:
    """The moving body's stresses are a half-space's: refused where its shape is clearly not one.  A cylinder's
    surface leaves the plane by x²/2R; over the field the stresses are computed on (|x| ≲ 2a, the depths to
    ``deepest``) that is of order a/R of the contact's own scale, and Hertz's theory, whose pressure the run
    starts from, has the same O(a/R) error: beyond a/R = HALF_SPACE the two are no longer small.  A tube (its wall
    bends as a ring: a bending stress under the contact that no half-space carries) is refused as well; a cylinder
    held at geometry.moving_height is held ten contact widths away at least (the case's own check), beyond the
    fatigue's depths."""
    g = case.geometry
    radius = getattr(g, "radius", None)
    problem = None
    if radius is None:
        problem = (f"a {g.kind}'s moving body is not a half-space (a tube's wall bends as a ring under the "
                   f"contact); fretsim computes the moving body's fatigue for a cylinder_on_flat only")
    elif half_width > HALF_SPACE * radius:
        problem = (f"the unworn contact's half-width {half_width * 1e3:.4g} µm is {half_width / radius:.3g} of the "
                   f"cylinder's radius {radius:.4g} mm, above {HALF_SPACE:g}: its stresses are not a half-space's "
                   f"(the half-space approximation's error is of order a/R)")
    if problem is not None:
        raise CaseError(case.source, [("materials.moving.fatigue", problem)])


def notes_of(plan: Plan) -> tuple:
    """The results file's notes: each automatic choice with its reason, then the plan's warnings."""
    return tuple(f"{c.key} = {show(c.value)}: {c.reason}" for c in plan.choices if not c.given) + tuple(plan.warnings)


def restore(setup: Setup, plan: Plan, provenance: list, notes: str = "") -> tuple[Setup, Plan]:
    """A resumed run's plan with the provenance its first part recorded (``Results.provenance``: key, value text,
    reason, given, error).  Planned again from the filled case, every choice reads "given in the case" and auto's
    accepted model differences (part of the error estimates) are gone; the values are the same (a given one as the
    case gave it: the filled case trims, e.g., recorded states past the last cycle), the reasons the first plan's,
    and so are the results file's ``notes`` where given (the first plan's warnings too: the skipped recorded
    states' is not raised again by the trimmed case)."""
    recorded = {key: (value, reason, given, error) for key, value, reason, given, error in provenance
                if given is not None}
    choices = []
    for c in plan.choices:
        if c.key in recorded:
            value, reason, given, error = recorded[c.key]
            # an automatic choice whose accepted model difference was not recorded: unknown, so are the totals
            error = 0.0 if given else float("nan") if error is None else float(error)
            c = dataclasses.replace(c, value=value if given else c.value, reason=reason, given=bool(given), error=error)
        choices.append(c)
    plan = dataclasses.replace(plan, choices=choices)
    return dataclasses.replace(setup, notes=tuple(notes.split("\n")) if notes else notes_of(plan)), plan


def _filled(case: Case, grids, operators, cycles, steps) -> Case:
    """The case with every automatic choice written out: it runs again (or resumes) exactly."""
    return case.with_choices(dimension=grids.dimension, corrections=operators.corrections or "none",
                             domain=grids.domain, elements=grids.elements, gap_model=operators.gap_model,
                             scheme=steps.scheme, slip=cycles.slip, stroke_model=cycles.stroke_model, increments=cycles.increments,
                             linear_jump=steps.linear_jump, max_jump=steps.max_jump, snapshots=steps.snapshots)
