"""What every step of the loop must satisfy; each failure says what went wrong and what to change.

These are the loop's guards against a wrong number written quietly: a contact the grid does not resolve, a
pressure cut off at the grid's edge, a contact solve that returned a non-finite, negative or unbalanced pressure,
a cycle beyond what the physics allows, a worn volume off its invariant, a growing odd-even pressure pattern, a
body worn through or a scar past where its geometry holds.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.errors import DomainError, GridFeedback, NumericalFailure, PhysicalLimit, ResolutionError

MIN_ELEMENTS_ACROSS_CONTACT = 4
ARCHARD_ROUND_OFF = 1e-9  # the volume is the invariant's (k·P·4δ·N, k·Σp|ds|A) by construction; more is a bug
LOAD_BALANCE = 1e-8  # every solver enforces Σp·A = P exactly; a larger error is a solver fault
BOUND_ROUND_OFF = 1e-6  # the tangential solve's slip is exact to ~1e-10 of the stroke; a cycle beyond its physical
#                         bound by more than this is a fault, not round-off


def check_resolution(res, grid, line_contact: bool) -> None:
    """The unworn contact must span a few elements each way the grid resolves (Hertz is then within ~1 %)."""
    across_x = int(res.contact.sum(axis=1).max())
    across_y = int(res.contact.sum(axis=0).max())
    if across_x < MIN_ELEMENTS_ACROSS_CONTACT or (not grid.plane_strain and not line_contact and
                                                   across_y < MIN_ELEMENTS_ACROSS_CONTACT):
        raise ResolutionError(f"the grid is too coarse to resolve the contact: the initial contact spans "
                              f"{across_x} element(s) of {grid.dx * 1e3:.3g} µm along x"
                              + ("" if grid.plane_strain or line_contact else
                                 f" and {across_y} of {grid.dy * 1e3:.3g} µm along y")
                              + f"; at least {MIN_ELEMENTS_ACROSS_CONTACT} are needed", 0)


def check_solution(res, op_area: float, load: float, method: str, cycle: int, n: int) -> None:
    """A contact solve's result: converged, finite, non-negative and carrying the load."""
    if not res.success:
        raise NumericalFailure(f"the contact solve did not converge at cycle {cycle}: {res.message}", n)
    if not np.isfinite(res.pressure).all():
        raise NumericalFailure(f"non-finite pressure from the {method} solver at cycle {cycle}", n)
    if (res.pressure < 0).any():
        raise NumericalFailure(f"negative pressure from the {method} solver at cycle {cycle}", n)
    imbalance = float(res.pressure.sum()) * op_area / load - 1.0
    if abs(imbalance) > LOAD_BALANCE:
        raise NumericalFailure(f"the {method} solution at cycle {cycle} violates the load balance by "
                               f"{imbalance:.1e} (relative): the Archard invariant would break", n)


def check_edges(p: np.ndarray, band: int, grid, cycle: int, y_edges_free: bool) -> None:
    """Pressure within the stroke's reach of the x edges (or on the y edges of a point contact) is truncated."""
    loaded_cols = np.flatnonzero((p > 0).any(axis=0))
    hit_x = loaded_cols.size and (loaded_cols[0] < band or loaded_cols[-1] >= grid.shape[1] - band)
    hit_y = False
    if not grid.plane_strain and not y_edges_free:
        rows = np.flatnonzero((p > 0).any(axis=1))
        hit_y = rows.size and (rows[0] == 0 or rows[-1] == grid.shape[0] - 1)
    if hit_x or hit_y:
        extent = (grid.x[-1] - grid.x[0] + grid.dx) if hit_x else (grid.y[-1] - grid.y[0] + grid.dy)
        raise DomainError(f"the contact reached the {'x' if hit_x else 'y'} edge of the grid at cycle {cycle} "
                          f"(extent {extent:.4g} mm): enlarge grid.domain, or leave grid empty for automatic "
                          f"sizing", cycle, "x" if hit_x else "y")


def check_invariant(error: float, invariant: str, n: int) -> None:
    """The worn volume against the member's invariant (its closed form, or k times the accumulated work)."""
    if error > ARCHARD_ROUND_OFF:
        raise NumericalFailure(f"the wear invariant is broken at cycle {n}: the wear volume differs from "
                               f"{invariant} by {error:.2e} (relative)", n)


def check_bounds(model, cyc, work: float, cycle: int, work_max: Optional[float] = None) -> None:
    """The cycle's work and energy, and the work accumulated to ``cycle`` (at most ``work_max``: the blocks' bounds
    times their cycles so far), within what the physics allows."""
    w_max, e_max = model.bounds
    top = 1.0 + BOUND_ROUND_OFF
    what = None
    if not (0.0 <= cyc.work <= w_max * top):
        what = f"the cycle's wear work {cyc.work:.6g} N·mm lies outside [0, {w_max:.6g}] (no point slides further " \
               f"than the rig travels, 4δ)"
    elif np.isfinite(cyc.energy) and not (0.0 <= cyc.energy <= e_max * top):
        what = f"the dissipated energy per cycle {cyc.energy:.6g} N·mm lies outside [0, μ·P·4δ = {e_max:.6g}]"
    elif not (0.0 <= work <= (w_max * max(cycle, 1) if work_max is None else max(work_max, w_max)) * top):
        bound = w_max * cycle if work_max is None else work_max
        what = f"the accumulated wear work {work:.6g} N·mm lies outside [0, {bound:.6g}] ({cycle} cycles)"
    if what:
        raise NumericalFailure(f"a physical bound is broken at cycle {cycle}: {what}", cycle)


def growth_failure(n: int, amplitude: float, cause: str, on_grid: bool = False) -> NumericalFailure:
    """The failure of a run whose pressure grew an odd-even pattern; ``cause`` is the stepping scheme's reading,
    ``on_grid`` whether the cycle model grew it on too coarse a grid (:func:`grows_on_grid`: a GridFeedback)."""
    kind = GridFeedback if on_grid else NumericalFailure
    return kind(f"the pressure checkerboards at cycle {n}: an odd-even pattern grew over the last steps "
                f"(amplitude {abs(amplitude):.1%} of the mean pressure); {cause}", n)


def grows_on_grid(model, implicit: bool) -> bool:
    """Whether a growing odd-even pattern is the cycle model's feedback on its grid, which a finer grid carries:
    a Coulomb cycle at the mid-stroke (its stick zone's edge) under steps with no stability limit — not an
    explicit step past its limit, nor the resolved stroke's reading of the flat between its positions."""
    return implicit and not model.linear and not (getattr(model, "resolved", False)
                                                  and not getattr(model, "rigid", False))


def model_growth_cause(model, setup) -> str:
    """Why a checkerboard grows under steps that have no stability limit: the cycle model itself."""
    if getattr(model, "resolved", False) and not getattr(model, "rigid", False):
        return ("the implicit steps have no stability limit, so the resolved stroke itself grew it: its positions "
                "read the flat at fractions of an element, so wear one load block lays down can alternate in a way "
                "none of its positions read, and a later block's positions, at other fractions, answer it with an "
                "alternating pressure (the tube in service does this at jumping.tolerance 0.001 and completes at the "
                "default 0.01: docs/verification.md); where the contact partly sticks, a coarse grid grows such a "
                "pattern at the stick zone's edge. Loosen jumping.tolerance, refine the grid (grid.elements) where "
                "the contact sticks, or set model.stroke: mid_stroke, which reads no positions")
    if not model.linear:
        return (f"the implicit steps have no stability limit, so the {model.name} cycle itself grew it: where the "
                f"contact partly sticks, more pressure means less slip and less wear, and on a coarse grid that "
                f"feedback grows at the stick zone's edge (the per-cycle run does it too). Refine the grid "
                f"(grid.elements) so that the contact's half-width spans more elements")
    return (f"the implicit steps have no stability limit, so the model itself is unstable here (explicit limit "
            f"{setup.stability_limit:.4g} cycles, gap model {model.gap_model}): check the wear coefficients and "
            f"their units")


def check_body(limits, grid, h_m: np.ndarray, p: np.ndarray, n: int) -> None:
    """Stop where the geometry stops meaning anything: worn through, or a scar past the limits of Eqs. 9-10."""
    if limits is None:
        return
    depth = float(h_m.max())
    if depth >= limits.wear_depth:
        raise PhysicalLimit(f"the moving body's wear depth {depth:.4g} mm reached {limits.wear_what} at cycle "
                            f"{n}: the body is worn through", n)
    X, Y = grid.mesh()
    on = p > 0
    reach_x = float(np.abs(X[on]).max()) + grid.dx / 2
    reach_y = float(np.abs(Y[on]).max()) + grid.dy / 2 if limits.reach_y is not None else 0.0
    if reach_x >= limits.reach_x or (limits.reach_y is not None and reach_y >= limits.reach_y):
        r = max(limits.reach_x, limits.reach_y or 0)
        raise PhysicalLimit(f"the contact reached {max(reach_x, reach_y):.4g} mm from the centre at cycle "
                            f"{n} (wear depth {depth * 1e3:.4g} µm), half of the radius of {2 * r:.4g} mm: beyond "
                            f"it the body's worn shape is no longer the paraboloid this model assumes", n)
