"""The resolved stroke's positions solved together: every increment of a cycle at once, as layers of one stack.

The resolved stroke solves the normal contact at each increment with every point of the moving body over the
point of the worn flat it has reached, and the tangential contact that says where the points go next.  Taken
one increment at a time that is a score of small solves a cycle, each paying numpy's cost per call many times
over its arithmetic (McColl 185 N 2D: 30 calls an increment, no hot spot).  Here the positions are layers of
one stack (where the stack is small enough to gain: STACK_LIMIT):

* **where the points go** (:func:`travels`): in gross slip the whole contact slides at μp after the first
  increment or two past a reversal, so each increment's traction is ±μp and its travel ΔU − KΔq follows from one
  convolution of the stack; an increment where that would leave a point slipping against its traction (it
  sticks: near a reversal, in partial slip) is given to the tangential solver, in order, from the traction
  before it;
* **the normal contacts** (:meth:`fretsim.loop.rows.NormalSolve.rows`): all positions, each over the flat at
  its predicted travel — the previous pass's, or on a step's first pass the travels at the last pressure;
* **agreement** (:func:`positions`): the travels the new pressures give are compared with the predicted; a
  position whose points went more than TRAVEL_TOLERANCE of an element elsewhere is solved again over where they
  went — the same rule the increment-by-increment cycle applies, on both ends of each travel.  Positions that
  do not settle in MAX_ROUNDS leave the cycle to be solved increment by increment.

The tally, the implicit step's mismatches and everything the cycle returns are then the same sums, over the
stack.  This is the same discretisation as the increment-by-increment cycle (the same positions, travels to the
same tolerance); it is not bit-identical to it (tests/test_resolved_rows.py measures how close).
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.wear import Sweep, sweep_read

TRAVEL_TOLERANCE = 0.1  # of an element: a resolved increment is solved again where a point's predicted travel was off
#                         by more (the pressure follows the worn flat on that scale)
PARTIAL_SHARE = 4  # a step's passes go increment by increment where predicting the first one's travels needs the
#                    tangential solver on more than 1/4 of the increments (partial slip: a solve per increment, as the
#                    pass one by one does, and the stack then saves little; the ball at 0.7 µm was 1.25× slower
#                    stacked); gross slip needs it only just past the reversals
STACK_LIMIT = 60_000  # elements of a whole stack (positions × grid) beyond which a cycle goes increment by increment:
#                      the stacked arrays then leave the cache and numpy's cost per call no longer dominates — McColl
#                      185 N 3D (19 × 27 × 263 = 135 000) took 97.9 s stacked against 87.5 s one by one (84 s with
#                      the normal solves in chunks), where 2D (19 × 427) is 4.2× faster stacked and the ball in gross
#                      slip (19 × 25 × 85 = 40 000) 1.5×
MAX_ROUNDS = 4  # normal solves of the stack before the cycle goes increment by increment (2 is usual: the second
#                 re-solves the few positions whose travel the first pressure moved by more than the tolerance)


def travels(member, pressures: np.ndarray, du: np.ndarray, budget: Optional[int] = None):
    """Each increment's traction, travel ΔU − KΔq and stick set at ``pressures`` (m, My, Mx), from rest before the
    first, and the tangential solver's iterations.  Increments that slide entirely at ±μp are taken together;
    with a ``budget``, None where more increments than that need the tangential solver, or the first does (from
    rest over half the stroke, it sticks somewhere only below about the gross-slip stroke)."""
    mu = member.friction_coefficient
    sign = np.sign(du)[:, None, None]
    cand = sign * mu * pressures  # the traction where the whole contact slides (0 outside it)
    stuck = np.zeros(pressures.shape, bool)
    if member.rigid:
        return cand, np.broadcast_to(du[:, None, None], pressures.shape).copy(), stuck, 0
    k = member.tangential
    kq = k(cand)
    kq_before = np.concatenate([np.zeros((1,) + kq.shape[1:]), kq[:-1]])
    ds = du[:, None, None] - (kq - kq_before)
    slides = ((sign * ds >= 0.0) | (pressures <= 0.0)).all(axis=(1, 2))  # no point would slip against its traction
    if budget is not None and not slides[0]:  # the first, from rest over the half stroke, sticks: partial slip
        return None
    q, iterations, solved = cand, 0, 0
    exact = True  # the traction before this increment is its candidate (or rest, before the first)
    for i in range(pressures.shape[0]):
        if exact and slides[i]:
            continue
        if not exact:  # the traction before is the solver's: this increment's sliding candidate from it
            ds[i] = du[i] - (kq[i] - k(q[i - 1]))
            if ((sign[i] * ds[i] >= 0.0) | (pressures[i] <= 0.0)).all():
                exact = True
                continue
        solved += 1
        if budget is not None and solved > budget:
            return None
        if q is cand:
            q = cand.copy()
        q[i], ds[i], stuck[i], its = member._tangential(q[i - 1] if i else np.zeros(q.shape[1:]), pressures[i], du[i])
        iterations += its
        exact = bool(np.array_equal(q[i], cand[i]))
    return q, ds, stuck, iterations


def starts(ds: np.ndarray) -> np.ndarray:
    """Where each increment's travel starts: the travels before it added up, from 0 (the loop's rest)."""
    s = np.zeros_like(ds)
    np.cumsum(ds[:-1], axis=0, out=s[1:])
    return s


def positions(member, wear_moving, wear_stationary, normal, du: np.ndarray, guess, extra, cycle: int,
              correction=None, predicted=None):
    """Every increment of a resolved cycle solved together: (pressures, contact results, tractions, starts,
    travels, stick sets, iterations), stacks (m, My, Mx) over the increments of ``du``; None where the cycle must be
    solved increment by increment (no stacked solve here, no warm start, or positions that did not settle).

    ``correction``: an implicit step's gap correction per increment; ``predicted``: (pressures, starts, travels)
    of the step's previous pass, else the travels at ``guess`` everywhere."""
    rows = getattr(normal, "rows", None)
    m, shape = du.size, member.grid.shape
    if rows is None or not getattr(normal, "stacks", True) or (predicted is None and guess is None) or \
            predicted == () or m * member.grid.size > STACK_LIMIT:
        return None  # (predicted (): the step's last pass went one by one)
    moving = wear_moving + (np.stack(correction) if correction is not None else 0.0)
    moving = np.broadcast_to(moving, (m,) + shape)
    flat = np.broadcast_to(wear_stationary, (m,) + shape)
    iterations = 0
    if predicted is None:
        p = np.repeat(guess[None], m, axis=0)
        found = travels(member, p, du, budget=m // PARTIAL_SHARE)
        if found is None:  # partial slip: the prediction alone would cost what the pass one by one costs
            return None
        ds, a, iterations = found[1], starts(found[1]), found[3]
    else:
        p, a, ds = (x.copy() for x in predicted[:3])
    b = a + ds
    sweep = predicted[3] if predicted is not None else None  # along exactly the predicted travels
    results = [None] * m
    redo = np.ones(m, bool)
    for _ in range(MAX_ROUNDS):
        seen = moving[redo] + _read(member, flat[redo], a[redo], b[redo], sweep)
        sweep = None
        got = rows(seen, p[redo], extra, load=member.load, cycle=cycle)
        if got is None:
            return None
        p[redo] = got[0]
        for i, res in zip(np.flatnonzero(redo), got[1]):
            results[i] = res
            iterations += res.iterations
        q, ds, stuck, its = travels(member, p, du)
        iterations += its
        s = starts(ds)
        off = np.where(p > 0, np.maximum(np.abs(s - a), np.abs(s + ds - b)), 0.0).max(axis=(1, 2))
        redo = off > TRAVEL_TOLERANCE * member.grid.dx
        if not redo.any():
            return p, results, q, s, ds, stuck, iterations
        a, b = np.where(redo[:, None, None], s, a), np.where(redo[:, None, None], s + ds, b)
    return None


class StackSweep(Sweep):
    """A :class:`~fretsim.wear.Sweep` of the layers ``index`` of a stack (m, My, Mx): rows along x are independent,
    so the layers are its rows, (k·My, Mx); what it deposits and reads comes back as stacks of those layers."""

    def __init__(self, start, end, dx, kernel, cols=slice(None), index=None):
        self.index = np.arange(start.shape[0]) if index is None else index
        start, end = start[self.index], end[self.index]
        self.layers = start.shape
        super().__init__(start.reshape(-1, start.shape[-1]), end.reshape(-1, end.shape[-1]), dx, kernel, cols)

    def deposit(self, amount):
        return super().deposit(amount).reshape(self.layers)

    def read(self, field):
        return super().read(np.ascontiguousarray(field)).reshape(self.layers)


def _read(member, flat, a, b, sweep: Optional[StackSweep] = None):
    """sweep_read of ``flat`` (a stack, or one field for every layer) along each layer's travel from ``a`` to
    ``b``: the layers ``sweep`` covers through it (its travels are theirs), the others on their own."""
    nx = a.shape[-1]
    flat = np.broadcast_to(flat, a.shape)
    rest = np.ones(a.shape[0], bool)
    out = np.empty(a.shape)
    if sweep is not None:
        out[sweep.index] = sweep.read(flat[sweep.index])
        rest[sweep.index] = False
    if rest.any():
        out[rest] = sweep_read(np.ascontiguousarray(flat[rest]).reshape(-1, nx), a[rest].reshape(-1, nx),
                               b[rest].reshape(-1, nx), member.grid.dx, member.kernel).reshape(out[rest].shape)
    return out


def sweep_of(member, p, s, ds, wear_stationary, counted: np.ndarray) -> StackSweep:
    """The shares of every counted increment's travel (layers of the stacks), over every column that deposits (in
    contact), reads the flat's wear or reads what the cycle deposits (the rates): one Sweep for the tally, the
    mismatches and the next pass's first read of the flat, which go along the same travels.  Not the first
    quarter's: its travel is the whole stroke's half, and with it every layer's shares would span four times the
    elements (in 3D the sweeps were then a third of a resolved run)."""
    index = np.flatnonzero(counted)
    nx = p.shape[-1]
    reach = int(np.ceil(max(np.abs(s).max(), np.abs(s + ds).max()) / member.grid.dx)) + 2
    on, worn = np.flatnonzero((p > 0).any(axis=(0, 1))), np.flatnonzero(wear_stationary.any(axis=0))
    ends = ([(on[0] - 2 * reach, on[-1] + 2 * reach)] if on.size else []) + (
        [(worn[0] - reach, worn[-1] + reach)] if worn.size else [])
    if not ends:
        return StackSweep(s, s + ds, member.grid.dx, member.kernel, slice(0, 0), index)
    lo, hi = min(e[0] for e in ends), max(e[1] for e in ends)
    return StackSweep(s, s + ds, member.grid.dx, member.kernel, slice(max(lo, 0), min(hi + 1, nx)), index)


def add_rows(tally, member, sweep: StackSweep, p, q, ds, shares: np.ndarray) -> None:
    """The tally's :meth:`add` for every counted increment at once (the layers ``sweep`` covers); ``shares`` each
    increment's share of the rig's travel."""
    k = sweep.index  # the counted increments
    p, q, ds, shares = p[k], q[k], ds[k], shares[k]
    amount = member.law.amount(p, q, ds)
    tally.rate_m += member.k_moving * amount.sum(axis=0)
    tally.rate_s += member.k_stationary * sweep.deposit(amount).sum(axis=0)
    slid = np.where(p > 0, np.abs(ds), 0.0)
    tally.slip_m += slid.sum(axis=0)
    tally.slip_s += sweep.deposit(slid).sum(axis=0)
    tally.p_seen += (shares[:, None, None] * sweep.deposit(p)).sum(axis=0)
    tally.energy += float((np.abs(q) * np.abs(ds)).sum()) * tally.area
    tally.work += float(amount.sum()) * tally.area
    tally.shear = np.maximum(tally.shear, np.abs(q).max(axis=0))


def mismatch_rows(tally, member, sweep: StackSweep, p, s, ds, step: float, w_lin) -> list:
    """For a resolved step's next pass, each increment's own mismatch (as coulomb._mismatches), all at once."""
    return list(step * (tally.rate_m + _read(member, tally.rate_s, s, s + ds, sweep) - w_lin(p)))
