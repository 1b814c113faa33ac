"""Landing on a wear limit: the step that passes a limit is taken again from the state before it, ending at the
estimated crossing, until the crossing is placed within the run's tolerance (:mod:`fretsim.limits` interpolates
it).  The state at the limit is the one reported, and the run ends there."""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim import limits

MAX_RETAKES = 6  # steps taken again to land on a wear limit's crossing (each lands closer: one or two suffice)


class Reached(Exception):
    """A wear limit was reached at ``step``: the loop ends there."""

    def __init__(self, step):
        super().__init__("wear limit reached")
        self.step = step


class Landing:
    """The wear limits' values at the last accepted steps, the steps retaken so far and the crossing found."""

    def __init__(self):
        self.track: list = []  # (cycle, {key: value}) of the last accepted steps
        self.retakes = 0  # steps taken again to land on a limit's crossing
        self.crossing: Optional[limits.Crossing] = None

    def check(self, loop, step) -> Optional[str]:
        """Wear limits at a new step: None to go on; "retake" when a limit was passed within a step too long to
        place the crossing (the loop is rolled back to the previous step, with a stop at the estimated
        crossing); "reached" when the crossing is placed (``self.crossing``)."""
        s = loop.s
        values = {k: limits.value(k, step, s.grid, s.wall) for k in s.wear_limits}
        points = self.track + [(float(loop.n), values)]
        found = limits.first(s.wear_limits, {k: [(n, v[k]) for n, v in points] for k in s.wear_limits})
        if found is None:
            self.track = points[-3:]
            return None
        before = points[-2][0] if len(points) > 1 else 0.0
        tolerance = max(1.0, s.limit_tolerance * found.cycle)
        # half the tolerance past the estimated crossing: the landing then passes it for certain (an estimate a
        # few cycles short would leave the landing just below the limit, and the next step far past it again)
        target = int(np.ceil(found.cycle + 0.5 * (tolerance - 1.0)))
        # taken again unless it ends at the crossing (within the tolerance): the state at the limit is the one
        # reported, and a crossing placed from a step that ends there is interpolated over the least
        if (loop.n - found.cycle > tolerance and loop.n - before > 1 and self.retakes < MAX_RETAKES and
                loop.last_state is not None and before < target < loop.n):
            retakes = self.retakes + 1
            loop.restore(loop.last_state)
            self.retakes = retakes  # after the restore, which would count it back
            loop.stops = sorted(set(loop.stops) | {target})
            return "retake"
        self.crossing = found
        return "reached"

    def growth_exponent(self) -> float:
        """d ln q / d ln N of the limited quantity over the last two tracked states (1 when unknown): a relative
        error ε in q is one of ε/exponent in the cycle at which q reaches its limit."""
        key = self.crossing.key
        pts = [(n, v[key]) for n, v in self.track if n > 0 and v[key] > 0]
        if len(pts) < 2 or pts[-1][0] == pts[-2][0] or pts[-1][1] == pts[-2][1]:
            return 1.0
        (n0, q0), (n1, q1) = pts[-2:]
        return float(np.log(q1 / q0) / np.log(n1 / n0))

    def reached(self) -> tuple:
        """(key, crossing cycle, its interpolation spread, the quantity's growth exponent) of the limit reached."""
        return self.crossing.key, self.crossing.cycle, self.crossing.spread, self.growth_exponent()
