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
from fretsim.solvers.rows import mirror_symmetric, mirror_tolerance, solve_coupled, solve_mirrored_rows


class NormalSolve:
    """``normal(seen, guess, extra, load=, cycle=)`` is the loop's :meth:`~fretsim.simulate._Loop.normal`;
    ``normal.rows(...)`` the same for the rows of a stack."""

    def __init__(self, loop):
        self.loop = loop
        self._summed = (None, None, None)
        self._symmetric = (None, False)

    @property
    def one_load(self) -> bool:
        """Whether the run applies one load throughout, no load block changing to another (a symmetric cycle's
        coupled step is mirrored only then: resolved.COUPLED_MIRROR)."""
        return not self.loop.s.loading.boundaries

    def mirror_tolerance(self, extra, peak: float) -> float:
        """How far (mm) a worn gap may be from its mirror image and its contact still be taken as the mirrored one
        (:func:`fretsim.solvers.rows.mirror_tolerance`); 0 where the problem itself is not symmetric along x
        (the unworn gap on a centred grid, the operator), to round-off."""
        s = self.loop.s
        key = (id(s.gap), id(s.compliance))
        if self._symmetric[0] != key:
            self._symmetric = (key, self.stacks and mirror_symmetric(s.compliance, s.gap, s.grid.x))
        op = self._operator(extra) if self._symmetric[1] else None
        return mirror_tolerance(op, s.tolerance, peak) if op is not None else 0.0

    def __call__(self, seen, guess, extra=None, load: Optional[float] = None, cycle: int = 0):
        return self.loop.normal(seen, guess, extra, load=load, cycle=cycle)

    @property
    def stacks(self) -> bool:
        """Whether :meth:`rows` can solve here (asked before the member predicts where the points go)."""
        s = self.loop.s
        return s.coarse is None and s.method == "cg" and isinstance(s.compliance, Convolution)

    def _operator(self, extra):
        op = self.loop.s.compliance
        if extra is not None:
            if self._summed[0] is not extra or self._summed[1] is not op:
                self._summed = (extra, op, add(op, extra))
            op = self._summed[2]
        return op if isinstance(op, Convolution) else None

    def coupled(self, seen: np.ndarray, guess: np.ndarray, couple, extra=None, load: Optional[float] = None,
                cycle: int = 0):
        """(pressures, a ContactResult per layer) of the layers of ``seen`` solved as one problem whose gaps also
        grow by ``couple(p)`` (:func:`fretsim.solvers.rows.solve_coupled`), every layer checked as a single solve
        is; None where that cannot be done here or did not converge (the member then corrects pass by pass)."""
        s = self.loop.s
        op = self._operator(extra) if self.stacks else None
        if op is None:
            return None
        found = solve_coupled(op, s.gap + seen, load, guess, s.tolerance, couple)
        if found is None:
            return None
        for res in found:
            checks.check_solution(res, op.grid.area, load, s.method, cycle, self.loop.n)
        pressures = np.stack([res.pressure for res in found])
        checks.check_edges(pressures.max(axis=0), s.band, s.grid, cycle, s.y_edges_free)
        return pressures, found

    def rows(self, seen: np.ndarray, guess: np.ndarray, extra=None, load: Optional[float] = None, cycle: int = 0,
             mirrors=()):
        """(pressures (m, My, Mx), a ContactResult per layer) for the gaps ε + ``seen`` (m, My, Mx), warm-started
        from ``guess`` (m, My, Mx); None where they cannot be solved together.  A row the stack did not settle is
        solved alone, with the single solve's fallbacks and checks; every row is checked as a single solve is.
        ``mirrors``: pairs of rows that may be mirror images along x (:func:`fretsim.solvers.rows.solve_mirrored_rows`)."""
        loop = self.loop
        s = loop.s
        if not self.stacks:
            return None
        op = self._operator(extra)
        if op is None:
            return None
        alone = {}

        def single(k):  # a row the stack did not settle: the single solve, its fallbacks and its own checks
            alone[k] = True
            return loop.normal(seen[k], guess[k], extra, load=load, cycle=cycle)[1]
        found = solve_mirrored_rows(op, s.gap + seen, load, guess, s.tolerance, mirrors, single)
        pressures, results = np.zeros(seen.shape), []
        for k, res in enumerate(found):
            if k not in alone:
                checks.check_solution(res, op.grid.area, load, s.method, cycle, loop.n)
            pressures[k] = res.pressure
            results.append(res)
        checks.check_edges(pressures.max(axis=0), s.band, s.grid, cycle, s.y_edges_free)  # every layer's at once
        return pressures, results
