"""The loop's normal contact as the cycle members call it: one gap at a time, or a stack of them at once.

A resolved fretting cycle solves the contact at every position of the stroke; the positions are solved together
(:func:`fretsim.solvers.rows.solve_rows`), each checked as the loop checks one solve.  Where they cannot be
(refinement's coarse grid, an operator that is not a convolution, a solver other than cg), :meth:`NormalSolve.rows`
says so (None) and the member solves them one by one.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.compliance import add
from fretsim.compliance.operator import Convolution
from fretsim.loop import checks
from fretsim.solvers.rows import solve_rows


class NormalSolve:
    """``normal(seen, guess, extra, load=, cycle=)`` is the loop's :meth:`~fretsim.simulate._Loop.normal`;
    ``normal.rows(...)`` the same for the rows of a stack."""

    def __init__(self, loop):
        self.loop = loop
        self._summed = (None, None, None)

    def __call__(self, seen, guess, extra=None, load: Optional[float] = None, cycle: int = 0):
        return self.loop.normal(seen, guess, extra, load=load, cycle=cycle)

    @property
    def stacks(self) -> bool:
        """Whether :meth:`rows` can solve here (asked before the member predicts where the points go)."""
        s = self.loop.s
        return s.coarse is None and s.method == "cg" and isinstance(s.compliance, Convolution)

    def rows(self, seen: np.ndarray, guess: np.ndarray, extra=None, load: Optional[float] = None, cycle: int = 0):
        """(pressures (m, My, Mx), a ContactResult per layer) for the gaps ε + ``seen`` (m, My, Mx), warm-started
        from ``guess`` (m, My, Mx); None where they cannot be solved together.  A row the stack did not settle is
        solved alone, with the single solve's fallbacks and checks; every row is checked as a single solve is."""
        loop = self.loop
        s = loop.s
        if not self.stacks:
            return None
        op = s.compliance
        if extra is not None:
            if self._summed[0] is not extra or self._summed[1] is not op:
                self._summed = (extra, op, add(op, extra))
            op = self._summed[2]
        if not isinstance(op, Convolution):
            return None
        found = solve_rows(op, s.gap + seen, load, guess, s.tolerance)
        pressures, results = np.zeros(seen.shape), []
        for k, res in enumerate(found):
            if res is None:
                p, res = loop.normal(seen[k], guess[k], extra, load=load, cycle=cycle)
            else:
                checks.check_solution(res, op.grid.area, load, s.method, cycle, loop.n)
                p = res.pressure
            pressures[k] = p
            results.append(res)
        checks.check_edges(pressures.max(axis=0), s.band, s.grid, cycle, s.y_edges_free)  # every layer's at once
        return pressures, results
