"""Automatic domain and grid: hold the final wear scar, resolve the initial Hertz contact.

The element size follows the paper's convergence rule (Table 1): 40 elements
over 7a, i.e. dx = 7a/40 with a the Hertz half-width.  The domain must hold
the scar the run will make, which grows far beyond 2a: the worn volume per
unit length V' = (k_m + k_s)·P'·4δ·N shared by a cylinder worn to a circular
segment of half-width b gives V' ≈ 2b³/(3R), so b ≈ (3RV'/2)^(1/3) (for a ball,
a cap: V ≈ πb⁴/(4R)).  The domain spans that, with a margin, plus the stroke,
over which the flat's scar extends; the run still stops with an error if the
pressure ever reaches the edge.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from fretsim.reference import hertz_line, hertz_point

ELEMENTS_OVER_7A = 40  # paper Table 1
CYLINDER_ROWS = 27  # paper section 2.1.1: 370 µm across a 10 mm cylinder
SCAR_MARGIN = 1.3


@dataclass(frozen=True)
class Sizing:
    hertz_half_width: float  # mm
    scar_half_width: float  # mm, estimated
    domain: tuple[float, ...]  # mm
    elements: tuple[int, ...]
    note: str


def _odd(n: float) -> int:
    n = max(int(math.ceil(n)), 1)
    return n if n % 2 else n + 1


def auto_grid(geometry: str, dimension: str, radius: float, length: float | None, load: float, stroke: float,
              cycles: int, k_total: float, e_star: float) -> Sizing:
    if geometry == "cylinder_on_flat":
        a = hertz_line(load / length, radius, e_star).half_width
        scar = (1.5 * radius * k_total * (load / length) * 4 * stroke * cycles) ** (1 / 3)
    else:
        a = hertz_point(load, radius, e_star).radius
        scar = (4 * radius * k_total * load * 4 * stroke * cycles / math.pi) ** 0.25
    # no contact is wider than the body: beyond that the run stops at the physical limit (worn through)
    scar = min(scar, radius)
    dx = 7 * a / ELEMENTS_OVER_7A
    reach = SCAR_MARGIN * max(scar, a) + stroke + 3 * dx
    nx = _odd(2 * reach / dx)
    if dimension == "2d":
        return Sizing(a, scar, (nx * dx,), (nx,), f"dx = 7a/40 = {dx * 1e3:.3g} µm (a = {a * 1e3:.3g} µm), "
                      f"x extent {nx * dx:.3g} mm for an estimated scar half-width {scar:.3g} mm")
    if geometry == "cylinder_on_flat":
        ny, ly = CYLINDER_ROWS, length
    else:
        half = SCAR_MARGIN * max(scar, a) + 3 * dx
        ny = _odd(2 * half / dx)
        ly = ny * dx
    return Sizing(a, scar, (nx * dx, ly), (nx, ny),
                  f"dx = 7a/40 = {dx * 1e3:.3g} µm (a = {a * 1e3:.3g} µm), dy = {ly / ny * 1e3:.3g} µm, "
                  f"domain {nx * dx:.3g} × {ly:.3g} mm for an estimated scar half-width {scar:.3g} mm")
