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

from fretsim.geometry import Geometry

ELEMENTS_OVER_7A = 40  # paper Table 1
LINE_ROWS = 27  # paper section 2.1.1: 370 µm across a 10 mm cylinder
SCAR_MARGIN = 1.3


@dataclass(frozen=True)
class Sizing:
    half_width_x: float  # Hertz a along x (mm)
    half_width_y: float
    scar_half_width: float  # mm, estimated, along x
    domain: tuple[float, ...]  # mm
    elements: tuple[int, ...]
    note: str


def _odd(n: float) -> int:
    n = max(int(math.ceil(n)), 1)
    return n if n % 2 else n + 1


def auto_grid(geometry: Geometry, plane_strain: bool, load: float, stroke: float, cycles: int, k_total: float,
              e_star: float, strokes: int = 1, refine: float = 1.0) -> Sizing:
    """The paper's element size and a domain holding the estimated final scar (both bodies' volume), plus
    ``strokes`` stroke amplitudes along x (the flat's wear reaches one stroke beyond the contact; seen through
    the stroke average, two)."""
    h = geometry.hertz(load, e_star)
    a = h.half_width_x
    volume = k_total * load * 4 * stroke * cycles
    scar_x, scar_y = geometry.scar_half_widths(volume)
    # no contact is wider than the body: beyond that the run stops at the physical limit
    limits = geometry.limits
    scar_x = min(scar_x, 2 * limits.reach_x)
    dx = 7 * a / ELEMENTS_OVER_7A / refine
    reach = SCAR_MARGIN * max(scar_x, a) + strokes * stroke + 3 * dx
    nx = _odd(2 * reach / dx)
    rule = "7a/40" if refine == 1.0 else f"7a/40 ÷ {refine:.3g}"
    note = (f"dx = {rule} = {dx * 1e3:.3g} µm (a = {a * 1e3:.3g} µm), x extent {nx * dx:.3g} mm for an estimated "
            f"scar half-width {scar_x:.3g} mm")
    if plane_strain:
        return Sizing(a, h.half_width_y, scar_x, (nx * dx,), (nx,), note)
    if h.line:
        ny, ly = LINE_ROWS, geometry.line_length
    else:
        scar_y = min(scar_y, 2 * (limits.reach_y or scar_y))
        dy = 7 * h.half_width_y / ELEMENTS_OVER_7A / refine
        ny = _odd(2 * (SCAR_MARGIN * max(scar_y, h.half_width_y) + 3 * dy) / dy)
        ly = ny * dy
    return Sizing(a, h.half_width_y, scar_x, (nx * dx, ly), (nx, ny),
                  note + f"; dy = {ly / ny * 1e3:.3g} µm, y extent {ly:.3g} mm")
