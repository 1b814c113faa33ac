"""Wear limits: the cycle at which a run has worn what its service allows.

A tube is plugged when its wall has thinned past a limit, a rope retired at a loss of section, a rail at a
depth.  ``limits:`` in a case names such quantities by the summary's names without their unit suffix
(``max_wear_depth_stationary: 2 um``, ``wear_volume_moving: 0.01 mm3``, ``scar_width_stationary: 1 mm``) and,
for a tube, ``wall_loss`` (its deepest wear over its wall thickness, ``40 %``).  The loop evaluates each on
every step; when one is passed it finds the crossing cycle within the step and stops there.

The crossing: a quantity q(N) known at the steps' cycles is interpolated through the last three (quadratic in
N) and through the last two (linear); where their crossings differ by more than the run's tolerance the step is
taken again from the state before it, landing on the estimated crossing, until they agree.  Wear quantities
grow smoothly and monotonically (depths as about N^(1/2) to N), so this converges in one or two repeats.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from fretsim.quantities import WEAR, wear_value

# name -> (the case's unit kind, the unit the summary reports it in, factor internal → that unit): the wear
# quantities of fretsim.quantities, which a limit may name
LIMIT_KEYS: dict[str, tuple[str, str, float]] = {q.key: (q.kind, q.unit, q.factor) for q in WEAR.values()}


def value(key: str, step, grid, wall: Optional[float]) -> float:
    """The quantity ``key`` at a step, in internal units (mm, mm³, fraction)."""
    return wear_value(key, step, grid.x, wall)


@dataclass
class Crossing:
    key: str
    cycle: float  # the interpolated crossing
    spread: float  # |quadratic − linear| crossing, cycles: the interpolation's own error estimate


def _linear(n0, q0, n1, q1, limit) -> float:
    return n0 + (n1 - n0) * (limit - q0) / (q1 - q0) if q1 != q0 else float(n1)


def _quadratic(ns, qs, limit) -> Optional[float]:
    """The crossing of the parabola through three points within [ns[1], ns[2]] (None if it has none there)."""
    coef = np.polyfit(np.asarray(ns, float) - ns[2], np.asarray(qs, float) - limit, 2)
    roots = np.roots(coef) if abs(coef[0]) > 0 else np.array([-coef[2] / coef[1]])
    lo, hi = ns[1] - ns[2], 0.0
    inside = [float(r.real) + ns[2] for r in np.atleast_1d(roots)
              if abs(r.imag) < 1e-12 and lo - 1e-9 * max(1.0, abs(lo)) <= r.real <= hi + 1e-9]
    return min(inside) if inside else None


def crossing(key: str, limit: float, points: list) -> Optional[Crossing]:
    """Where ``key`` reaches ``limit`` between the last two of ``points`` ((cycle, value), oldest first), or None
    if it has not."""
    (n1, q1) = points[-1]
    if q1 < limit:
        return None
    (n0, q0) = points[-2] if len(points) > 1 else (0, 0.0)
    if q0 >= limit:  # already at the limit at the earlier state (a limit at or below the start)
        return Crossing(key, float(n0), 0.0)
    lin = _linear(n0, q0, n1, q1, limit)
    if len(points) < 3:
        return Crossing(key, lin, abs(n1 - n0) if n1 - n0 > 1 else 0.0)
    quad = _quadratic([p[0] for p in points[-3:]], [p[1] for p in points[-3:]], limit)
    if quad is None:
        return Crossing(key, lin, abs(n1 - n0))
    return Crossing(key, quad, abs(quad - lin))


def first(limits: dict, history: dict) -> Optional[Crossing]:
    """The earliest crossing of any limit over its points (``history``: key → [(cycle, value), ...])."""
    found = [c for key, lim in limits.items() if (c := crossing(key, lim, history[key])) is not None]
    return min(found, key=lambda c: c.cycle) if found else None

