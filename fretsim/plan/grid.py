"""The planner's grid stage: the domain and elements (automatic, or the case's), the recorded states, the coarse
grid of refinement, and what the grid must hold — the scar of every block's wear, the stroke, the memory.

The automatic grid is sized by :mod:`fretsim.sizing` for the lightest load's contact and the scar of the
cycles the run will take; a partial-slip contact needs finer elements still, which the planner learns only from
the regime on a first grid (:func:`partial_slip_refinement`): it then plans again on the refined grid.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from fretsim.case import Case, CaseError
from fretsim.cycle import CYCLES
from fretsim.grid import Grid
from fretsim.plan.choices import Choice, Plan
from fretsim.plan.inputs import MEMORY_SHARE, Contact, available_memory, memory_estimate
from fretsim.plan.model import choose_gap_model
from fretsim.sizing import ELEMENTS_OVER_7A, Sizing, auto_grid
from fretsim.wear import GAP_REACH, stroke_reach

PARTIAL_SLIP_ELEMENTS = 4  # across the stick zone and across the slip annulus, at least (as across a contact)
TRANSITION_BAND = 2.0  # strokes up to this many δ_t are refined as partial slip is: the worn contact may stick
MAX_PARTIAL_SLIP_REFINEMENT = 3.0  # per axis (9× the elements in 3D): beyond, the user is told and refines by hand


@dataclass(frozen=True)
class Grids:
    """The grid stage's result."""

    dimension: str
    sizing: Sizing
    domain: tuple
    elements: tuple  # (nx,) in 2D, (nx, ny) in 3D
    grid: Grid
    coarse: Optional[Grid]  # refinement (Eqs. 11-12): the contact solved here, the pressure refined to ``grid``
    snapshots: tuple
    refine: float  # the automatic grid's refinement for partial slip (1: none)

    @property
    def plane(self) -> bool:
        return self.grid.plane_strain


def build(case: Case, plan: Plan, contact: Contact, dimension: str, sized: int, refine: float,
          expected: Optional[float] = None) -> Grids:
    """The run's grid for ``dimension``, sized for the wear of ``sized`` cycles and refined ``refine``-fold; a run
    with wear limits records states on the way to ``expected``, where it is expected to stop (None: unknown)."""
    plane = dimension == "2d"
    g = case.geometry
    if plane and g.axial_profile:
        plan.warnings.append(f"the {g.kind}'s axial profile (its drop along y) is not modelled in 2D: a 2D run is "
                             f"the plane-strain section of a straight cylinder, the same whatever the profile; use "
                             f"model.dimension: 3d for the profile's effect")
    sizing = _sizing(case, contact, plane, sized, refine)
    c_domain, c_elements = choose_grid(case, plane, sizing)
    domain, elements = plan.add(c_domain), plan.add(c_elements)
    if len(domain) < (1 if plane else 2) or len(elements) < (1 if plane else 2):
        raise CaseError(case.source, [("grid", "a 3d case needs two entries in grid.domain and grid.elements: "
                                               "[x, y]")])
    nx, ny = elements[0], 1 if plane else elements[1]
    snapshots = plan.add(choose_snapshots(case, expected))
    coarse_shape = _coarse_shape(case, plane, domain)
    _check_memory(case, plane, nx, ny, len(snapshots), coarse_shape, refine)
    grid = Grid.centred(nx, ny, domain[0] / nx, 1.0 if plane else domain[1] / ny, plane_strain=plane)
    _check_room(case, plane, grid, domain)
    coarse = None
    if coarse_shape is not None:
        cnx, cny = coarse_shape
        coarse = Grid.centred(cnx, cny, domain[0] / cnx, 1.0 if plane else domain[1] / cny, plane_strain=plane)
    return Grids(dimension, sizing, tuple(domain[:1] if plane else domain[:2]), (nx,) if plane else (nx, ny), grid,
                 coarse, snapshots, refine)


def _sizing(case: Case, contact: Contact, plane: bool, sized: int, refine: float) -> Sizing:
    """One grid whatever the stepping, so that schemes compare on it: a load history's lightest contact resolved,
    the scar of every block's wear over ``sized`` cycles held."""
    loading = case.loading
    accuracy = case.accuracy if case.grid_rule == "accuracy" else None
    k_total = contact.k_moving + contact.k_stationary
    volume = k_total * loading.worn_work(sized)
    # the grid will follow the contact (fretsim.regrid.rule_for's conditions, known before the grid is): it may then
    # start on the domain of the scar at which it first coarsens, and widen as the scar grows
    grows = (accuracy is not None and case.domain is None and case.elements is None and refine == 1.0
             and case.coarse_element is None and case.moving.fatigue is None and case.stationary.fatigue is None)

    def sizing(strokes: int = 1) -> Sizing:
        return auto_grid(case.geometry, plane, loading.lightest_load, loading.peak_stroke, loading.cycles, k_total,
                         contact.e_star, strokes=strokes, refine=refine, accuracy=accuracy,
                         pressure_accuracy=case.pressure_accuracy, volume=volume, reach_load=loading.peak_load,
                         grows=grows)

    first = sizing()
    probe = choose_gap_model(case, Grid.centred(3, 1, first.domain[0] / first.elements[0], 1.0, True))
    strokes = GAP_REACH[probe.value]  # the flat's wear seen through the stroke average reaches two strokes
    return first if strokes == 1 else sizing(strokes)


def choose_grid(case: Case, plane: bool, sizing: Sizing) -> tuple[Choice, Choice]:
    given_d, given_e = case.domain is not None, case.elements is not None
    if given_d and given_e:
        return (Choice("grid.domain", case.domain, "given in the case", True),
                Choice("grid.elements", case.elements, "given in the case", True))
    if not given_d and not given_e:
        rule = (sizing.rule if sizing.rule else
                f"the paper's rule 7a/40, refined ({sizing.note.split(' = ')[1]}) for partial slip: its stick zone "
                f"and slip annulus span {PARTIAL_SLIP_ELEMENTS} elements each (up to {TRANSITION_BAND:g} δ_t, where "
                f"a worn contact may come to stick, {2 * PARTIAL_SLIP_ELEMENTS} across the half-width; at most "
                f"{MAX_PARTIAL_SLIP_REFINEMENT:g}× per axis)")
        return (Choice("grid.domain", sizing.domain, ("automatic: holds the scar of its first coarsening and widens as "
                                                      "the scar grows: " if sizing.follows else
                                                      "automatic: holds the estimated final scar: ") + sizing.note),
                Choice("grid.elements", sizing.elements, "automatic: " + rule))
    if given_d:
        dx = sizing.domain[0] / sizing.elements[0]
        elements = tuple(max(1, int(round(d / dx))) | 1 for d in case.domain[:1]) + (
            (sizing.elements[1],) if not plane else ())
        return (Choice("grid.domain", case.domain, "given in the case", True),
                Choice("grid.elements", elements, f"the automatic element ({dx * 1e3:.3g} µm) over the given domain: "
                                                  f"{sizing.rule or 'the paper rule refined for partial slip'}"))
    return (Choice("grid.domain", sizing.domain, "automatic, for the given elements: " + sizing.note),
            Choice("grid.elements", case.elements, "given in the case", True))


def choose_snapshots(case: Case, expected: Optional[float] = None) -> Choice:
    """The recorded states: the case's, or automatically 0, quarters of the run and its end.

    With wear limits loading.cycles is only an upper bound: the run stops where a limit is reached, often far
    earlier (the tube in service: near 10⁹ of 5·10⁹ cycles), and quarters of the bound all lay past the stop, so
    the history's profiles showed cycle 0 and the stop alone.  The quarters are then of ``expected``, the stop a
    pilot predicts (:func:`fretsim.plan.model.expected_stop`), and N is kept should the run go that far; the
    predicted stop itself is left out, since the run records the state at its limit whenever it reaches one.
    Where nothing predicts the stop, the decades 10, 100, … below N: geometric, because the stop may fall
    anywhere from the first steps to N, and decades put the states a factor ten apart on the way to it wherever it
    falls, at round cycles, as a log-cycles history reads.  A state past the actual stop is harmless: the run ends
    at its limit, which is recorded, and never reaches it.
    """
    if case.snapshots is not None:
        return Choice("output.snapshots", case.snapshots, "given in the case", True)
    n = case.loading.cycles
    quarters = "automatic: 0, N/4, N/2, 3N/4 and N"
    if not case.limits or n <= 0:
        return Choice("output.snapshots", tuple(sorted({0, n // 4, n // 2, 3 * n // 4, n})), quarters)
    if expected is None:
        decades = [10 ** k for k in range(1, len(str(n))) if 10 ** k < n]
        return Choice("output.snapshots", tuple(sorted({0, *decades, n})),
                      "automatic, for a run with wear limits and no predicted stop (no pilot run, or it failed): 0, "
                      "the decades 10, 100, … below N, and N: states on the way to wherever a limit stops the run "
                      "(the stop itself is recorded)")
    if expected >= n:
        return Choice("output.snapshots", tuple(sorted({0, n // 4, n // 2, 3 * n // 4, n})),
                      quarters + " (a pilot run reached no wear limit before N)")
    stop = round(expected)
    return Choice("output.snapshots", tuple(sorted({0, stop // 4, stop // 2, 3 * stop // 4, n})),
                  f"automatic, for a run with wear limits: 0, S/4, S/2 and 3S/4 on the way to S = {stop:,} cycles, "
                  f"where a pilot run reached a limit, and N (loading.cycles, the upper bound); the "
                  f"stop itself is recorded when reached")


def _coarse_shape(case: Case, plane: bool, domain: tuple) -> Optional[tuple[int, int]]:
    """The coarse grid's elements (refinement, grid.coarse_element), or None."""
    if case.coarse_element is None:
        return None
    if len(case.coarse_element) < (1 if plane else 2):
        raise CaseError(case.source, [("grid.coarse_element", "a 3d case needs two entries: [dx, dy]")])
    cnx = max(3, int(round(domain[0] / case.coarse_element[0])))
    cny = 1 if plane else max(1, int(round(domain[1] / case.coarse_element[1])))
    return cnx, cny


def _check_memory(case: Case, plane: bool, nx: int, ny: int, snapshots: int, coarse_shape, refine: float) -> None:
    coarse_n = coarse_shape[0] * coarse_shape[1] if coarse_shape is not None else 0
    g = case.geometry
    need = memory_estimate(nx * ny, snapshots + 5, case.solver, coarse_n)
    if g.body_corrections and case.corrections != "none":
        need += 8.0 * nx * nx  # a body's own compliance (the tube's ring bending): a dense matrix along x
    if g.free_faces and not plane and case.corrections != "none":
        need += 8.0 * ny * ny * (2 * nx) * 3  # the free faces' kernel between every pair of rows, and its symbol
    if need > MEMORY_SHARE * available_memory():
        raise CaseError(case.source, [("grid", f"the grid of {nx} x {ny} elements"
                                               f"{' (automatic)' if case.elements is None else ''}"
                                               f"{f' solved on {coarse_n} coarse elements' if coarse_n else ''} with "
                                               f"solver {case.solver}"
                                               f"{f' (refined {refine:.3g}× per axis for the partial-slip contact)' if refine > 1 else ''}"
                                               f" would need about {need / 2**30:.1f} GiB, more than "
                                               f"{MEMORY_SHARE:.0%} of this machine's "
                                               f"{available_memory() / 2**30:.0f} GiB; coarsen the grid, shorten the "
                                               f"run, or check the case's units")])


def _check_room(case: Case, plane: bool, grid: Grid, domain: tuple) -> None:
    """The grid holds the stroke and the contact's length."""
    problems = []
    g, stroke = case.geometry, case.loading.peak_stroke
    if stroke >= domain[0] / 2:
        problems.append(("loading.stroke", f"the stroke amplitude {stroke:.4g} mm is larger than half the "
                                           f"grid's x extent ({domain[0]:.4g} mm): check its unit"))
    if g.line_length is not None and not plane and domain[1] < g.line_length * (1 - 1e-9):
        problems.append(("grid.domain", f"the y extent {domain[1]:.4g} mm is shorter than the contact length "
                                        f"({g.line_length:.4g} mm): the contact would be cut off"))
    reach = stroke_reach(grid.dx, stroke)
    nx = grid.shape[1]
    if nx <= 2 * reach + 4:
        problems.append(("grid.elements", f"{nx} elements along x leave no room for the stroke "
                                          f"({reach} elements each side)"))
    if problems:
        raise CaseError(case.source, problems)


def partial_slip_refinement(case: Case, slip: str, transition: Optional[float], half_width: float, dx: float) -> float:
    """How much finer than 7a/40 the elements must be for a partial-slip contact: its stick zone and its slip
    annulus each need PARTIAL_SLIP_ELEMENTS, or the wear step at the stick edge lives within an element or two.
    c/a ≈ √(1 − δ/δ_t): exact for a ball (Mindlin: δ/δ_t = 1 − (1 − Q/μP)^{2/3}, c/a = (1 − Q/μP)^{1/3}), and
    for a line contact to within the datum's term, which is linear in Q."""
    stroke = case.loading.peak_stroke
    if CYCLES[slip].assumes_gross_slip or transition is None or not stroke < TRANSITION_BAND * transition:
        return 1.0
    if stroke >= transition:
        # gross slip at the start, but a worn centre stops sliding as its pressure grows (more pressure, less slip,
        # less wear): a stick zone forms and its edge feeds back on the wear.  At 7a/40 that feedback grew an
        # element-scale pattern (1.12 δ_t, the per-cycle run too); 8 elements across the half-width settle it
        narrowest = half_width / 2
    else:
        c = half_width * math.sqrt(max(0.0, 1.0 - stroke / transition))
        narrowest = min(c, half_width - c)
    return max(1.0, PARTIAL_SLIP_ELEMENTS * dx / max(narrowest, 1e-3 * half_width))


def refined(case: Case, slip: str, transition: Optional[float], contact: Contact, refine: float) -> Optional[float]:
    """The refinement the automatic grid needs for partial slip, if it has not had it yet (None: plan on)."""
    if refine != 1.0 or case.elements is not None:
        return None
    # the same case on the grid partial slip needs, within a cap: a tiny stroke's annulus would need thousands
    # (counted from the paper's element along both axes: the accuracy rule refines x alone)
    a = contact.hertz.half_width_x
    need = partial_slip_refinement(case, slip, transition, a, 7 * a / ELEMENTS_OVER_7A)
    return min(need, MAX_PARTIAL_SLIP_REFINEMENT) if need > 1.0 else None


def warn_unresolved_stick(case: Case, plan: Plan, slip: str, transition: Optional[float], contact: Contact,
                          grid: Grid) -> None:
    """Where even the refined grid falls short of PARTIAL_SLIP_ELEMENTS across the stick zone or the annulus."""
    refine = partial_slip_refinement(case, slip, transition, contact.hertz.half_width_x, grid.dx)
    if refine > 1.01:  # short of the target beyond round-off
        width = PARTIAL_SLIP_ELEMENTS * grid.dx / refine
        plan.warnings.append(f"partial slip: the narrower of the stick zone and the slip annulus (about "
                             f"{width * 1e3:.3g} µm along x) spans {PARTIAL_SLIP_ELEMENTS / refine:.2g} elements of "
                             f"{grid.dx * 1e3:.3g} µm, fewer than the {PARTIAL_SLIP_ELEMENTS} it needs"
                             + (f" (the automatic grid is refined at most {MAX_PARTIAL_SLIP_REFINEMENT:g}× per axis)"
                                if case.elements is None else " (grid.elements is given)")
                             + ": the wear step at the stick edge and the depths in the annulus are grid-limited; "
                               "give a finer grid.elements to resolve them")
