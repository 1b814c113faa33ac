"""Automatic domain and grid: hold the final wear scar, resolve the initial Hertz contact.

The element size follows the paper's convergence rule (Table 1): 40 elements
over 7a, i.e. dx = 7a/40 with a the Hertz half-width along x; across a line
contact the paper's 370 µm rows (27 over a 10 mm cylinder); across a point
contact the same rule on the y half-width (square elements for a ball, as in
the paper).  The domain must hold the scar the run will make, which grows far
beyond 2a: the worn volume of both bodies (k_m + k_s)·P·4δ·N, held by the
geometry's worn shape (see ``Geometry.scar_half_widths``), with a margin, plus
the stroke along x, over which the flat's scar extends.  The run still stops
with an error if the pressure ever reaches the edge.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from fretsim.geometry import Geometry

ELEMENTS_OVER_7A = 40  # paper Table 1
# The reported scar widths are where the depth crosses 0.1 % of its peak, read between element centres
# (fretsim.measures.scar_width) to within an element: at most 0.28-0.49 element widths of error at the accuracy
# grid and the two grids below it, 0.95 on grids 8× coarser (scripts/study_width_error.py).  The width's estimate
# (fretsim.grid_error) is the stepping's part plus one element over the width plus the companion's difference,
# so a width within model.accuracy needs an element of at most accuracy/WIDTH_SHARE of the scar: a third of the
# accuracy for the element, the rest for the stepping and a companion twice as coarse (measured: estimates 0.68 %
# in the median at accuracy 1 %, 3 of 32 over it).
WIDTH_SHARE = 3.0
MAX_ACCURACY_REFINEMENT = 4.0  # per axis, over the paper's rule: beyond it the cost grows faster than it pays
# The pressure field's L2 error, as the companion grid estimates it, falls about as the element along x over the
# scar width: measured at the accuracy grid (scripts/study_grid_error.py, Table 4 cases), estimate ≈ 20-25·dx/W.
# model.pressure_accuracy q asks for dx ≤ q·W/PRESSURE_SHARE.  A point contact's companion halves y too, so its
# element along y is refined by the same factor over the paper's.
PRESSURE_SHARE = 30.0
MAX_PRESSURE_REFINEMENT = (16.0, 4.0)  # per axis over the paper's rule: along x; along y for a point contact
LINE_ROWS = 27  # paper section 2.1.1: 370 µm across a 10 mm cylinder
SCAR_MARGIN = 1.3
COARSEN = 3  # elements an automatic grid that follows the contact merges into one (fretsim.regrid)


@dataclass(frozen=True)
class Sizing:
    half_width_x: float  # Hertz a along x (mm)
    half_width_y: float
    scar_half_width: float  # mm, estimated, along x
    domain: tuple[float, ...]  # mm
    elements: tuple[int, ...]
    note: str
    rule: str = "the paper's convergence rule, dx = 7a/40"  # which rule sized the element along x, and why ("": the
    #                                                          partial-slip refinement, said by the plan)
    follows: bool = False  # the domain holds the scar of the first coarsening, not the final one: it widens
    final_extent: float = 0.0  # mm along x: the extent that holds the final scar (the domain, unless it follows)


def _odd(n: float) -> int:
    n = max(int(math.ceil(n)), 1)
    return n if n % 2 else n + 1


def _across(geometry: Geometry, h, wide, scar_y: float, refine_y: float) -> tuple[int, float]:
    """The elements and extent (mm) along y of a 3D grid: a line contact's rows over its length, a point contact's
    7b/40 (refined ``refine_y``-fold) over its scar with the margin."""
    if h.line:
        return LINE_ROWS, geometry.line_length
    scar_y = min(scar_y, 2 * (geometry.limits.reach_y or scar_y))
    dy = 7 * h.half_width_y / ELEMENTS_OVER_7A / refine_y
    ny = _odd(2 * (SCAR_MARGIN * max(scar_y, wide.half_width_y) + 3 * dy) / dy)
    return ny, ny * dy


def _held(scar_x: float, dx: float, accuracy: Optional[float]) -> float:
    """The scar half-width (mm) the domain holds: the final scar's, or, for a grid that follows the contact (its
    ``accuracy`` given: a 2D or line-contact grid sized by the accuracy rule, which coarsens COARSEN-fold as the
    scar allows and widens where the contact reaches its edge, :mod:`fretsim.regrid`), the smaller one at which
    the accuracy rule first allows elements COARSEN times as long.  A tube's 6 µm Hertz contact wears a scar
    millimetres wide over 10⁹ cycles: elements of the first micrometres over the final scar's extent made the
    early cycles cost as much as the rest of the run."""
    return min(scar_x, 0.5 * COARSEN * dx * WIDTH_SHARE / accuracy) if accuracy else scar_x


def auto_grid(geometry: Geometry, plane_strain: bool, load: float, stroke: float, cycles: int, k_total: float,
              e_star: float, strokes: int = 1, refine: float = 1.0, accuracy: Optional[float] = None,
              pressure_accuracy: Optional[float] = None, volume: Optional[float] = None,
              reach_load: Optional[float] = None, grows: bool = False) -> Sizing:
    """The paper's element size and a domain holding the estimated final scar (both bodies' volume), plus
    ``strokes`` stroke amplitudes along x (the flat's wear reaches one stroke beyond the contact; seen through
    the stroke average, two).  Given ``accuracy``, the element along x is also at most accuracy/WIDTH_SHARE of
    the estimated scar width (at most MAX_ACCURACY_REFINEMENT times finer than the paper's).  ``load`` sets the
    element (a load history's lightest contact, the narrowest to resolve); ``reach_load`` (default ``load``) the
    domain (its heaviest, the widest to hold: a short history wears too little for the scar to outgrow it);
    ``grows``: the grid will follow the contact (:func:`_held`)."""
    h = geometry.hertz(load, e_star)
    a = h.half_width_x
    wide = geometry.hertz(reach_load, e_star) if reach_load is not None and reach_load > load else h
    if volume is None:  # both bodies' worn volume (a load history gives its own sum over the blocks)
        volume = k_total * load * 4 * stroke * cycles
    scar_x, scar_y = geometry.scar_half_widths(volume)
    # no contact is wider than the body: beyond that the run stops at the physical limit
    limits = geometry.limits
    scar_x = min(scar_x, 2 * limits.reach_x)
    paper = 7 * a / ELEMENTS_OVER_7A
    dx = paper / refine
    rule = "7a/40" if refine == 1.0 else f"7a/40 ÷ {refine:.3g}"
    why = ("" if refine != 1.0 else "the paper's convergence rule, dx = 7a/40" if accuracy is None else
           f"grid.rule accuracy: the paper's convergence rule, dx = 7a/40, already under a third of model.accuracy "
           f"({accuracy:.2g}) of the estimated scar width")
    if accuracy is not None and cycles > 0:
        width = 2 * max(scar_x, a)
        for_width = max(accuracy * width / WIDTH_SHARE, paper / MAX_ACCURACY_REFINEMENT)
        if for_width < dx:
            dx = for_width
            capped = for_width == paper / MAX_ACCURACY_REFINEMENT
            rule = (f"7a/40 ÷ {MAX_ACCURACY_REFINEMENT:g}" if capped else
                    f"{accuracy:.2g} × the scar width {width:.3g} mm / {WIDTH_SHARE:g}")
            why = (f"grid.rule accuracy: the element along x a third of model.accuracy ({accuracy:.2g}) of the "
                   f"estimated scar width {width:.3g} mm (a width is known to about an element), finer than the "
                   f"paper's 7a/40 = {paper * 1e3:.3g} µm"
                   + (f", capped at {MAX_ACCURACY_REFINEMENT:g}× finer (the widths would need "
                      f"{accuracy * width / WIDTH_SHARE * 1e3:.3g} µm; the companion grid's estimate says how far "
                      f"they are)" if capped else ""))
    refine_y = refine
    if pressure_accuracy is not None and cycles > 0:
        width = 2 * max(scar_x, a)
        cap_x, cap_y = MAX_PRESSURE_REFINEMENT
        for_pressure = pressure_accuracy * width / PRESSURE_SHARE
        if for_pressure < dx:
            dx = max(for_pressure, paper / cap_x)
            capped = dx > for_pressure
            refine_y = max(refine, min(paper / dx, cap_y))
            rule = f"7a/40 ÷ {cap_x:g}" if capped else (f"{pressure_accuracy:.2g} × the scar width {width:.3g} mm / "
                                                        f"{PRESSURE_SHARE:g}")
            why = (f"model.pressure_accuracy ({pressure_accuracy:.2g}): the element along x "
                   f"{pressure_accuracy:.2g}/{PRESSURE_SHARE:g} of the estimated scar width {width:.3g} mm "
                   f"(the pressure field's L2 error is about {PRESSURE_SHARE:g}·dx/width at most, measured)"
                   + (f", capped at {cap_x:g}× finer than the paper's 7a/40 (it would need "
                      f"{for_pressure * 1e3:.3g} µm; the companion grid's estimate says how far the field is)"
                      if capped else "")
                   + ("" if plane_strain or h.line else
                      f"; along y the paper's rule refined ÷ {refine_y:.3g}"
                      + (f" (capped at {cap_y:g})" if refine_y == cap_y else "")))
    if refine != 1.0 and why and refine_y == refine:
        why += f"; along y the paper's rule refined ÷ {refine:.3g} for partial slip"
    # (as fretsim.regrid.rule_for: a point contact's scar grows along y too, and it does not coarsen)
    grows = grows and (plane_strain or geometry.y_edges_free)
    held = _held(scar_x, dx, accuracy if grows and cycles > 0 else None)
    def elements_holding(half: float) -> int:  # a scar of this half-width, with the margin and the stroke's reach
        return _odd(2 * (SCAR_MARGIN * max(half, wide.half_width_x) + strokes * stroke + 3 * dx) / dx)

    nx = elements_holding(held)
    note = f"dx = {rule} = {dx * 1e3:.3g} µm (a = {a * 1e3:.3g} µm), x extent {nx * dx:.3g} mm for " + (
        f"an estimated scar half-width {scar_x:.3g} mm" if held == scar_x else
        f"the scar half-width {held:.3g} mm at which the grid may first coarsen {COARSEN}-fold (the estimated "
        f"final scar's is {scar_x:.3g} mm: the grid widens as the scar grows)")
    follows = held < scar_x
    final = elements_holding(scar_x) * dx
    if plane_strain:
        return Sizing(a, h.half_width_y, scar_x, (nx * dx,), (nx,), note, why, follows, final)
    ny, ly = _across(geometry, h, wide, scar_y, refine_y)
    return Sizing(a, h.half_width_y, scar_x, (nx * dx, ly), (nx, ny),
                  note + f"; dy = {ly / ny * 1e3:.3g} µm, y extent {ly:.3g} mm", why, follows, final)
