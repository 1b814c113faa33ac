"""The grid follows the contact: an automatic grid is widened when the contact reaches its edge.

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
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
import numpy as np

from fretsim.grid import Grid

MAX_REGRIDS = 6  # each at least 1.6× the extent: 17× the planned extent in all, beyond which the plan was wrong
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
    return (f"the automatic grid was widened along {axis} at cycle {regrid.cycle}: {n0} → {n1} elements, {d0:.4g} → "
            f"{d1:.4g} mm ({regrid.reason}; the run went back to cycle {regrid.cycle} and went on from there)")


def replanned(plan, regrid: Regrid, plane: bool):
    """The plan with its grid choices moved to the widened grid, still automatic, the widening in their reason."""
    values = {"grid.domain": regrid.new_domain[:1] if plane else regrid.new_domain,
              "grid.elements": regrid.new_elements[:1] if plane else regrid.new_elements}
    choices = [dataclasses.replace(c, value=values[c.key], reason=f"{c.reason}; {describe(regrid)}")
               if c.key in values else c for c in plan.choices]
    return dataclasses.replace(plan, choices=choices)
