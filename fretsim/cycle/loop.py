"""The fretting loop as recorded: the rig's displacement against the tangential force round one cycle, its elastic
sides cut finely enough to show them.

The wear needs few increments along a half-stroke (none at all with the pressure fixed: a monotone half-stroke's
wear does not depend on how it is cut, each point slipping one way), but evenly spaced increments (2δ/9 each)
slid the whole contact in the first increment after a reversal, and the loop they drew had sides several times
wider than 2δ_t (5.6 µm instead of 1.3 µm at McColl's ±25 µm), so a tangential stiffness read off it was that many
times too compliant.  At a recorded state each half-stroke's elastic side, the first 2δ_t of rig travel after a
reversal (Masing: twice the first loading's δ_t), is cut into LOOP_SIDE_INCREMENTS equal parts and the rest, where
the contact slides at ±μP, is one.  The side ends on an increment, so its span is exact.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

LOOP_SIDE_INCREMENTS = 12  # over each elastic side: 12 draw Mindlin's curve to ~1 % of Q*


def elastic_side(tangential, friction_coefficient: float, pressure: np.ndarray) -> float:
    """2δ_t over the whole contact (mm): the rig travel after a reversal before the last point slides again; 0
    without a contact."""
    on = pressure > 0
    if not on.any():
        return 0.0
    return 2.0 * float(tangential(friction_coefficient * pressure)[on].max())


def half_stroke(stroke: float, side: float, sign: int, increments: int) -> list[tuple[float, float]]:
    """(U at the start, U at the end) of a half-stroke from −sign·δ to sign·δ, its first ``side`` (mm) cut into
    ``increments`` equal parts and the rest into one."""
    d = stroke
    side = min(max(side, 0.0), 2.0 * d)
    offsets = [side * k / increments for k in range(increments + 1)] + (
        [2.0 * d] if side < 2.0 * d * (1 - 1e-9) else [])
    offsets[-1] = 2.0 * d  # the turning point exactly, whatever the rounding
    return [(sign * (a - d), sign * (b - d)) for a, b in zip(offsets[:-1], offsets[1:])]


def loop_path(stroke: float, side: float, increments: int) -> list[tuple[float, float, bool]]:
    """(U at the start, U at the end, counted) of a recorded cycle with the pressure fixed: 0 → −δ in one
    increment (monotone: exact), then −δ → +δ → −δ with each side finely cut."""
    return [(0.0, -stroke, False)] + [(a, b, True) for a, b in half_stroke(stroke, side, +1, increments)
                                      + half_stroke(stroke, side, -1, increments)]


def turning_loop(stroke: float, increments: int, tangential_increment: Callable, side_of: Callable, low: tuple,
                 high: tuple, area: float, mirrored: bool = False) -> tuple[list, list]:
    """A resolved stroke's recorded loop: each half-stroke drawn from its turning point (U = ∓δ; ``low`` and
    ``high`` the (traction, pressure) the cycle found there) on the pressure at that turning point.  The resolved
    stroke's increments are a quadrature along the stroke, evenly spaced; the pressure changes little over the
    side's 2δ_t (a fraction of an element), so holding it there draws the side as it is, for tangential solves
    only.  ``tangential_increment(q, p, du)`` → (q, ds, stick, iterations); ``side_of(p)`` → 2δ_t (mm).
    ``mirrored``: the cycle is symmetric along x (its turning states each other's mirror image, with the tangential
    compliance's kernel even), so the down half is the up half mirrored: its force the up half's negated."""
    us, qs = [-stroke], [float(low[0].sum()) * area]
    for (q, p), sign in ((low, +1), (high, -1)):  # the down half starts from the cycle's own state at +δ
        if sign < 0 and mirrored:
            half = len(us) - 1
            us.extend(-u for u in us[1:half + 1])
            qs.extend(-f for f in qs[1:half + 1])
            break
        for u0, u1 in half_stroke(stroke, side_of(p), sign, increments):
            q = tangential_increment(q, p, u1 - u0)[0]
            us.append(u1)
            qs.append(float(q.sum()) * area)
    return us, qs
