"""The grid follows the contact: an automatic grid is widened when the contact reaches its edge, and coarsened
as the contact and its scar grow.

The planner sizes the automatic grid for the scar it predicts; a run whose contact outgrows that prediction (a
wear coefficient in a sample's high tail, a fit's trial far from its start, a load history's heavy block) used to
stop with "the contact reached the x edge".  Now the run goes back to its last accepted step, the grid gains
elements of the same size on both sides (30 % of its extent or more on each), and the loop continues from that
state on the wider grid.  Nothing is interpolated: every element of the old grid is an element of the new one, and
the new elements start unworn and unloaded, which they were (the contact had not reached them), so the worn
volumes, the pressures and the stepping's memory carry over exactly.  The results file keeps one grid, the
widest: the earlier snapshots are padded with zeros onto it, and ``/regrids`` records each widening (when, from
what to what, why).

A grid the case gives (``grid.domain`` or ``grid.elements``) is the user's: it is never changed, and the run
stops at the edge as it always did.

**Starting small.**  An automatic grid that will coarsen (below) is planned on the domain of the scar at which it
may first coarsen, not the final scar's, where that is smaller (:func:`fretsim.sizing.auto_grid`): the tube in
service starts on 1.5 mm, not 8 mm, of 1.1 µm elements, and widens three times as its scar grows to 5.7 mm,
coarsening twice on the way.  The side runs do the same (:func:`following` with ``widen``): a wear limit's pilot,
and the grid-error companions, which start on the run's first domain with half (a quarter of) its elements.

**Coarsening.**  The automatic grid resolves the *initial* contact (a tube's Hertz half-width of 6.5 µm), which is
far finer than a scar millimetres wide needs: at an accepted step where the current contact and scar allow
elements three times as long under the rules that sized the grid (the paper's 7c/40 on the current contact
half-width c, scaled to the lightest block's load, and grid.rule accuracy's third of model.accuracy of the current
scar width), the run merges its elements three to one and goes on from that state.  Three, odd, so that the
centred odd grid stays centred and each coarse element is exactly three fine ones (the grid is first padded with
unworn elements to a multiple of three, an odd one); every array of the state is averaged over its three, so the
worn volumes (and the forces) carry over to round-off.  The results keep the finest grid the run used (the
*output grid*): a snapshot on a coarser grid is written with each value repeated over its fine elements (piecewise
constant: the same volume), the checkpoint too (and read back by taking each coarse element's middle fine one,
bit for bit), and ``/coarsenings`` records when, to what and why, so that a resume goes on on the same coarse
grid.  The grid-error companions replay the run's coarsenings at the same cycles, so their estimate covers the
grids the run used.  Elements merge along x only: 2D runs and 3D line contacts coarsen (a line contact's rows are
its ends, and stay), a point contact does not (its scar grows along y too); nor do refinement's coarse grid,
partial slip's refined grid, or fatigue (its damage lives on its own grid).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from fretsim.errors import DomainError
from fretsim.grid import Grid
from fretsim.sizing import COARSEN  # elements merged into one: odd, so a centred odd grid stays centred and nested
MAX_REGRIDS = 6  # beyond the planned extent, each at least 1.6× it: 17× in all, beyond which the plan was wrong
GROWTH = 0.3  # each side gains at least this share of the extent (and the stroke's reach): a few regrids at most


@dataclass(frozen=True)
class Regrid:
    """One widening: at ``cycle`` (the state the run went back to), from ``old`` to ``new`` elements and domain."""

    cycle: int
    old_elements: tuple  # (nx, ny)
    new_elements: tuple
    old_domain: tuple  # mm, (x, y)
    new_domain: tuple
    reason: str

    @property
    def offsets(self) -> tuple[int, int]:
        """Elements added before the old grid's first (rows, columns)."""
        return (self.new_elements[1] - self.old_elements[1]) // 2, (self.new_elements[0] - self.old_elements[0]) // 2


def widenings(regrids) -> int:
    """The widenings among ``regrids`` (/regrids rows): not the paddings a coarsening makes, a few elements each,
    which MAX_REGRIDS does not count."""
    return sum(not r.reason.startswith("padded") for r in regrids)


def allowed(extent: float, planned: float) -> int:
    """The widenings a grid starting ``extent`` mm wide along x may make: those a grid that follows the contact
    plans, to reach the ``planned`` extent of the final scar (each adds at least GROWTH of the extent on both
    sides), and MAX_REGRIDS more for a scar that outgrows the plan."""
    planned_ones = math.ceil(math.log(planned / extent) / math.log(1 + 2 * GROWTH)) if planned > extent > 0 else 0
    return MAX_REGRIDS + planned_ones


def grid_is_automatic(plan) -> bool:
    """Neither grid.domain nor grid.elements given in the case (nor read back as given on a resume)."""
    return not any(c.given for c in plan.choices if c.key in ("grid.domain", "grid.elements"))


def widened(grid: Grid, axis: str, band: int, cycle: int, reason: str) -> Regrid:
    """The grid widened along ``axis`` ('x' or 'y'): an even number of elements added, half on each side, so that
    the old element centres stay element centres of the new grid."""
    ny, nx = grid.shape
    old_domain = (nx * grid.dx, ny * grid.dy)

    def more(n: int, least: int) -> int:
        return n + 2 * max(least, math.ceil(GROWTH * n))

    # along x the worn flat reaches the stroke beyond the contact (``band``): at least that much more room
    new = (more(nx, band + 2), ny) if axis == "x" else (nx, more(ny, 2))
    return Regrid(cycle, (nx, ny), new, old_domain, (new[0] * grid.dx, new[1] * grid.dy), reason)


def new_grid(old: Grid, regrid: Regrid) -> Grid:
    nx, ny = regrid.new_elements
    return Grid.centred(nx, ny, old.dx, old.dy, plane_strain=old.plane_strain)


def pad(value, regrid: Regrid):
    """``value`` on the widened grid if it is an array on the old one (or a list of them), else as it is.  The new
    elements are 0 (NaN for an array that is NaN throughout: a field the model does not know)."""
    if isinstance(value, list):
        return [pad(v, regrid) for v in value]
    old_shape = (regrid.old_elements[1], regrid.old_elements[0])
    if not isinstance(value, np.ndarray) or value.shape[-2:] != old_shape:
        return value
    rows, cols = regrid.offsets
    ny, nx = regrid.new_elements[1], regrid.new_elements[0]
    fill = np.nan if value.dtype.kind == "f" and value.size and np.isnan(value).all() else 0
    out = np.full(value.shape[:-2] + (ny, nx), fill, dtype=value.dtype)
    out[..., rows:rows + old_shape[0], cols:cols + old_shape[1]] = value
    return out


def pad_state(state: dict, regrid: Regrid) -> dict:
    """A checkpoint of the loop on the old grid as one on the widened grid."""
    return {k: pad(v, regrid) for k, v in state.items()}


def pad_record(record, regrid: Regrid):
    """A step (or a cycle) with its arrays widened, so that what is reported of the last state before the regrid
    reads on the grid the run now uses."""
    changes = {}
    for f in dataclasses.fields(record):
        value = getattr(record, f.name)
        if dataclasses.is_dataclass(value) and f.name == "cycle_result":
            changes[f.name] = pad_record(value, regrid)
        elif isinstance(value, np.ndarray):
            changes[f.name] = pad(value, regrid)
        elif f.name == "state" and isinstance(value, dict):
            changes[f.name] = pad_state(value, regrid)
    return dataclasses.replace(record, **changes)


def describe(regrid: Regrid) -> str:
    (nx0, ny0), (nx1, ny1) = regrid.old_elements, regrid.new_elements
    (dx0, dy0), (dx1, dy1) = regrid.old_domain, regrid.new_domain
    axis, n0, n1, d0, d1 = ("x", nx0, nx1, dx0, dx1) if nx1 != nx0 else ("y", ny0, ny1, dy0, dy1)
    back = "" if regrid.reason.startswith("padded") else (f"; the run went back to cycle {regrid.cycle} and went on "
                                                          f"from there")
    return (f"the automatic grid was widened along {axis} at cycle {regrid.cycle}: {n0} → {n1} elements, {d0:.4g} → "
            f"{d1:.4g} mm ({regrid.reason}{back})")


def replanned(plan, regrid: Regrid, plane: bool):
    """The plan with its grid choices moved to the widened grid, still automatic, the widening in their reason."""
    values = {"grid.domain": regrid.new_domain[:1] if plane else regrid.new_domain,
              "grid.elements": regrid.new_elements[:1] if plane else regrid.new_elements}
    choices = [dataclasses.replace(c, value=values[c.key], reason=f"{c.reason}; {describe(regrid)}")
               if c.key in values else c for c in plan.choices]
    return dataclasses.replace(plan, choices=choices)


# --- coarsening ----------------------------------------------------------------------------------------------


class Coarsen(Exception):
    """Raised by the loop after an accepted step (already handed to its observers) whose state allows elements
    COARSEN times as long: the run goes on from ``step.state`` on the coarser grid."""

    def __init__(self, step, reason: str):
        super().__init__(reason)
        self.step, self.reason = step, reason


@dataclass(frozen=True)
class Coarsening:
    """One coarsening: at ``cycle`` the run's elements became ``factor`` times the output grid's (3, 9, ...),
    ``elements`` (nx, ny) of them."""

    cycle: int
    factor: int
    elements: tuple
    reason: str


def merged_count(nx: int) -> int:
    """The smallest odd multiple of COARSEN at least ``nx`` (an odd count): the elements the grid is padded to
    before merging (an even number more, half on each side, so the centres stay centres)."""
    step = 2 * COARSEN
    return nx + (COARSEN - nx % step) % step


def padding(grid: Grid, cycle: int) -> Optional[Regrid]:
    """The widening (by unworn elements) that makes ``grid`` mergeable, None where it already is."""
    ny, nx = grid.shape
    n = merged_count(nx)
    if n == nx:
        return None
    return Regrid(cycle, (nx, ny), (n, ny), (nx * grid.dx, ny * grid.dy), (n * grid.dx, ny * grid.dy),
                  f"padded to {n} elements to merge them {COARSEN} to 1")


def _gridwise(value, shape: tuple, fn):
    """``fn`` of ``value`` if it is an array on a grid of ``shape`` (ny, nx) (of each, for a list of them); anything
    else as it is."""
    if isinstance(value, list):
        return [_gridwise(v, shape, fn) for v in value]
    if not isinstance(value, np.ndarray) or value.ndim < 2 or value.shape[-2:] != shape:
        return value
    return fn(value)


def merge(value, shape: tuple):
    """``value`` on a grid of ``shape``, nx a multiple of COARSEN, as the mean of each COARSEN elements along x."""
    def mean(a):
        out = a.reshape(a.shape[:-1] + (shape[1] // COARSEN, COARSEN)).mean(axis=-1)
        return out if a.dtype.kind == "f" else out.astype(a.dtype)
    return _gridwise(value, shape, mean)


def prolong(value, shape: tuple, factor: int):
    """``value`` on the run's grid of ``shape`` written on the output grid ``factor`` times finer along x: each
    value repeated over its fine elements (piecewise constant: the same volume)."""
    return value if factor == 1 else _gridwise(value, shape, lambda a: np.repeat(a, factor, axis=-1))


def restrict(value, shape: tuple, factor: int):
    """A prolonged array (on the output grid of ``shape``) back on the run's grid: each coarse element's middle
    fine one, so prolong then restrict is the identity, bit for bit."""
    return value if factor == 1 else _gridwise(value, shape,
                                               lambda a: np.ascontiguousarray(a[..., factor // 2::factor]))


def coarsened_state(state: dict, grid: Grid, pad_r: Optional[Regrid]) -> dict:
    """A checkpoint on ``grid`` as one on the grid COARSEN times coarser (padded first by ``pad_r``): every array
    averaged over its merged elements.  The growth watch starts afresh: an odd-even pattern's amplitude is not
    comparable across grids."""
    st = pad_state(state, pad_r) if pad_r is not None else dict(state)
    shape = (grid.shape[0], pad_r.new_elements[0] if pad_r is not None else grid.shape[1])
    out = {k: merge(v, shape) for k, v in st.items()}
    out["watch"] = np.zeros(0)
    return out


def coarsened_record(record, grid: Grid, pad_r: Optional[Regrid]):
    """A step (or a cycle) with its arrays on the coarser grid (what is reported of the last state before it); its
    state is the one the run goes on from (:func:`coarsened_state`), which a widening at the next step goes back
    to."""
    state = getattr(record, "state", None)
    if pad_r is not None:
        record = pad_record(record, pad_r)
    shape = (grid.shape[0], pad_r.new_elements[0] if pad_r is not None else grid.shape[1])
    changes = {}
    for f in dataclasses.fields(record):
        value = getattr(record, f.name)
        if dataclasses.is_dataclass(value) and f.name == "cycle_result":
            changes[f.name] = coarsened_record(value, Grid.centred(shape[1], shape[0], grid.dx, grid.dy,
                                                                  grid.plane_strain), None)
        elif isinstance(value, np.ndarray):
            changes[f.name] = merge(value, shape)
        elif f.name == "state" and isinstance(state, dict):
            changes[f.name] = coarsened_state(state, grid, pad_r)
    return dataclasses.replace(record, **changes)


def along_x(case, grid: Grid, nx: int, extent: Optional[float] = None):
    """The case on ``nx`` elements along x over ``extent`` (mm; None: the case's own domain, bit for bit), its rows
    across (3D) as on ``grid``."""
    rows = () if grid.plane_strain else (grid.shape[0],)
    if extent is None:
        return case.with_choices(elements=(nx,) + rows)
    return case.with_choices(domain=(extent,) + tuple(case.domain[1:2] if rows else ()), elements=(nx,) + rows)


def coarse_case(case, grid: Grid, pad_r: Optional[Regrid]):
    """The case (its grid automatic, its choices filled) on the merged grid.  Its domain is the case's, or the
    padding's (both the output grid's too): a resume plans the run's grid from the output grid's domain, which n·dx
    of a grid planned as domain/n may miss by its last bit."""
    n = pad_r.new_elements[0] if pad_r is not None else grid.shape[1]
    return along_x(case, grid, n // COARSEN, pad_r.new_domain[0] if pad_r is not None else None)


@dataclass(frozen=True)
class CoarsenRule:
    """When a run's state allows elements COARSEN times as long along x: both rules that sized the automatic grid
    hold for the longer element on the current contact and scar (:mod:`fretsim.sizing`)."""

    accuracy: float  # grid.rule accuracy's model.accuracy
    pressure_accuracy: Optional[float]
    lightest_load: float  # N (N per mm in 2D): the load the contact is narrowest under

    def __call__(self, setup, step) -> Optional[str]:
        if step.cycle == 0:
            return None
        from fretsim import measures, sizing
        grid = setup.grid
        inside = np.flatnonzero((step.pressure > 0).any(axis=0))
        if inside.size == 0:
            return None
        half = 0.5 * (inside[-1] - inside[0] + 1) * grid.dx
        load = float(step.pressure.sum()) * grid.area
        # a heavier block's contact is wider than the lightest's: scaled as a Hertz line contact (√P)
        half *= min(1.0, math.sqrt(self.lightest_load / load)) if load > 0 else 1.0
        width = measures.centre_width(step.wear_stationary, grid.x) or 2 * half
        allowed = [(7 * half / sizing.ELEMENTS_OVER_7A, f"7c/40 of the contact half-width c {half * 1e3:.4g} µm"),
                   (self.accuracy * width / sizing.WIDTH_SHARE,
                    f"a third of model.accuracy of the scar width {width * 1e3:.4g} µm")]
        if self.pressure_accuracy is not None:
            allowed.append((self.pressure_accuracy * width / sizing.PRESSURE_SHARE,
                            f"model.pressure_accuracy's share of the scar width {width * 1e3:.4g} µm"))
        element, why = min(allowed)
        new = COARSEN * grid.dx
        if new > element:
            return None
        return (f"elements {grid.dx * 1e3:.4g} → {new * 1e3:.4g} µm at cycle {step.cycle}: {why} allows "
                f"{element * 1e3:.4g} µm")


def rule_for(case, setup, plan, accuracy: Optional[float] = None) -> Optional[CoarsenRule]:
    """The coarsening rule of a run planned as ``plan``, None where its grid may not coarsen: the user's grid, the
    paper's rule asked for (grid.rule paper; a pilot passes the run's ``accuracy``), a point contact in 3D (its
    scar grows along y too; a line contact's rows stay), refinement's coarse grid, a grid refined for partial slip
    (its stick zone needs the elements), fatigue."""
    accuracy = accuracy if accuracy is not None else case.accuracy if case.grid_rule == "accuracy" else None
    refined = any(c.key == "grid.elements" and "partial slip" in c.reason for c in plan.choices)
    line = setup.grid.plane_strain or setup.y_edges_free
    if (accuracy is None or not grid_is_automatic(plan) or not line or setup.coarse is not None
            or refined or setup.fatigue_specs or case.loading.cycles == 0):
        return None
    return CoarsenRule(accuracy, case.pressure_accuracy, case.loading.lightest_load / setup.volume_factor)


@dataclass(frozen=True)
class Replay:
    """A companion's coarsenings: at the first step at or past each cycle the main run coarsened at."""

    cycles: tuple
    done: int = 0  # coarsenings already made (a companion's grid starts at the first level)

    def __call__(self, setup, step) -> Optional[str]:
        if self.done < len(self.cycles) and step.cycle >= self.cycles[self.done]:
            return f"replaying the run's coarsening at cycle {self.cycles[self.done]}"
        return None


def step_down(setup, case, exc: Coarsen, prepare_fn: Callable, factor: int):
    """The run after ``exc`` on the grid COARSEN times coarser: (setup, case, plan, state, padding, coarsening).
    ``case`` is the run's filled case on its current grid, ``factor`` its element over the output grid's."""
    grid = setup.grid
    pad_r = padding(grid, exc.step.cycle)
    new_setup, new_case, plan = prepare_fn(coarse_case(case, grid, pad_r))
    # the state's stepping memory is of the wear model the run started with: a fine grid on which the per-cycle
    # update was unstable follows the continuous ODE, and a coarse one would plan the per-cycle update again
    new_setup = dataclasses.replace(new_setup, per_cycle=setup.per_cycle)
    state = coarsened_state(exc.step.state, grid, pad_r)
    made = Coarsening(exc.step.cycle, factor * COARSEN, (new_setup.grid.shape[1], new_setup.grid.shape[0]),
                      exc.reason)
    return new_setup, new_case, plan, state, pad_r, made


class _Last:
    """An observer that keeps the last accepted step's checkpoint (a side run widens from it)."""

    def __init__(self, state: Optional[dict] = None):
        self.state = state

    def on_step(self, setup, step) -> None:
        self.state = step.state


def following(run: Callable, setup, case, rule: Callable, prepare_fn: Callable, widen: bool = False):
    """``run(setup, resume, coarsen, observers)`` (a side run: a pilot, a companion) carried through its
    coarsenings, and, ``widen``, through the widenings of its automatic grid where the contact reaches its edge
    (from its last accepted step, as the run's own: :mod:`fretsim.runner`), at most :func:`allowed` of them: its
    last step, the setup it ended on and the coarsenings made."""
    state, made, factor, widenings, start = None, [], 1, 0, setup
    while True:
        last = _Last(state)
        try:
            return run(setup, state, rule, (last,)), setup, made
        except Coarsen as exc:
            setup, case, _, state, _, c = step_down(setup, case, exc, prepare_fn, factor)
            factor = c.factor
            made.append(c)
            if isinstance(rule, Replay):
                rule = dataclasses.replace(rule, done=rule.done + 1)
        except DomainError as exc:
            if not widen or widenings >= allowed(start.grid.shape[1] * start.grid.dx, start.planned_extent):
                raise
            base = last.state
            r = widened(setup.grid, exc.axis, setup.band, int(base["n"]) if base else 0,
                        f"the contact reached the {exc.axis} edge at cycle {exc.cycle}")
            if exc.axis == "x":
                wider = along_x(case, setup.grid, r.new_elements[0], r.new_domain[0])
            else:
                wider = case.with_choices(domain=r.new_domain, elements=r.new_elements)
            new_setup, case, _ = prepare_fn(wider)
            setup = dataclasses.replace(new_setup, per_cycle=setup.per_cycle)
            state = pad_state(base, r) if base else None
            widenings += 1


def scaled(r: Regrid, factor: int) -> Regrid:
    """A widening of the run's grid (elements ``factor`` output elements long) as one of the output grid."""
    n = r.new_elements[0] * factor
    reason = r.reason
    if factor > 1 and reason.startswith("padded"):  # its count is of the run's elements: the row's are the output's
        reason = (f"padded to {n} elements ({r.new_elements[0]} of the run's, each {factor} of them) to merge them "
                  f"{COARSEN} to 1")
    return dataclasses.replace(r, old_elements=(r.old_elements[0] * factor,) + r.old_elements[1:],
                               new_elements=(n,) + r.new_elements[1:], reason=reason)


def describe_coarsening(c: Coarsening, old_elements: int) -> str:
    return (f"the automatic grid was coarsened at cycle {c.cycle}: {old_elements} → {c.elements[0]} elements, "
            f"each {c.factor}× the first ({c.reason})")
