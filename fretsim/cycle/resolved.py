"""The resolved stroke's positions solved together: every increment of a cycle at once, on a 2D grid.

The resolved stroke solves the normal contact at each increment with every point of the moving body over the
point of the worn flat it has reached, and the tangential contact that says where the points go next.  Taken
one increment at a time that is a score of small solves a cycle, each paying numpy's cost per call many times
over its arithmetic (McColl 185 N 2D: 30 calls an increment, no hot spot).  Here the positions are rows of one
stack:

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

import numpy as np

from fretsim.wear import Sweep, sweep_read

TRAVEL_TOLERANCE = 0.1  # of an element: a resolved increment is solved again where a point's predicted travel was off
#                         by more (the pressure follows the worn flat on that scale)
MAX_ROUNDS = 4  # normal solves of the stack before the cycle goes increment by increment (2 is usual: the second
#                 re-solves the few positions whose travel the first pressure moved by more than the tolerance)


def travels(member, pressures: np.ndarray, du: np.ndarray):
    """Each increment's traction, travel ΔU − KΔq and stick set at ``pressures`` (m, nx), from rest before the
    first, and the tangential solver's iterations.  Increments that slide entirely at ±μp are taken together."""
    mu = member.friction_coefficient
    sign = np.sign(du)[:, None]
    cand = sign * mu * pressures  # the traction where the whole contact slides (0 outside it)
    stuck = np.zeros(pressures.shape, bool)
    if member.rigid:
        return cand, np.repeat(du[:, None], pressures.shape[1], axis=1), stuck, 0
    k = member.tangential
    kq = k(cand)
    kq_before = np.vstack([np.zeros((1, kq.shape[1])), kq[:-1]])
    ds = du[:, None] - (kq - kq_before)
    slides = ((sign * ds >= 0.0) | (pressures <= 0.0)).all(axis=1)  # no point would slip against its traction
    q, iterations = cand, 0
    exact = True  # the traction before this increment is its candidate (or rest, before the first)
    for i in range(pressures.shape[0]):
        if exact and slides[i]:
            continue
        if not exact:  # the traction before is the solver's: this increment's sliding candidate from it
            before = k(q[i - 1:i])[0]
            ds[i] = du[i] - (kq[i] - before)
            if ((sign[i] * ds[i] >= 0.0) | (pressures[i] <= 0.0)).all():
                exact = True
                continue
        if q is cand:
            q = cand.copy()
        start = q[i - 1:i] if i else np.zeros((1, q.shape[1]))
        q_i, ds_i, stuck_i, its = member._tangential(start, pressures[i:i + 1], du[i])
        q[i], ds[i], stuck[i] = q_i[0], ds_i[0], stuck_i[0]
        iterations += its
        exact = bool(np.array_equal(q_i[0], cand[i]))
    return q, ds, stuck, iterations


def starts(ds: np.ndarray) -> np.ndarray:
    """Where each increment's travel starts: the travels before it added up, from 0 (the loop's rest)."""
    s = np.zeros_like(ds)
    np.cumsum(ds[:-1], axis=0, out=s[1:])
    return s


def positions(member, wear_moving, wear_stationary, normal, du: np.ndarray, guess, extra, cycle: int,
              correction=None, predicted=None):
    """Every increment of a resolved cycle solved together: (pressures, contact results, tractions, starts,
    travels, stick sets, iterations), stacks (m, nx) over the increments of ``du``; None where the cycle must be
    solved increment by increment (no stacked solve here, no warm start, or positions that did not settle).

    ``correction``: an implicit step's gap correction per increment; ``predicted``: (pressures, starts, travels)
    of the step's previous pass, else the travels at ``guess`` everywhere."""
    rows = getattr(normal, "rows", None)
    m, nx = du.size, member.grid.shape[1]
    if rows is None or member.grid.shape[0] != 1 or (predicted is None and guess is None):
        return None
    dx, kernel = member.grid.dx, member.kernel
    moving = wear_moving + (np.vstack(correction) if correction is not None else 0.0)
    moving = np.broadcast_to(moving, (m, nx))
    flat = np.repeat(wear_stationary, m, axis=0)
    iterations = 0
    if predicted is None:
        p = np.repeat(guess, m, axis=0)
        _, ds, _, its = travels(member, p, du)
        a = starts(ds)
        iterations += its
    else:
        p, a, ds = (x.copy() for x in predicted[:3])
    b = a + ds
    sweep = predicted[3] if predicted is not None else None  # along exactly the predicted travels
    results = [None] * m
    redo = np.ones(m, bool)
    for _ in range(MAX_ROUNDS):
        seen = moving[redo] + (sweep.read(flat) if sweep is not None else
                               sweep_read(flat[redo], a[redo], b[redo], dx, kernel))
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
        off = np.where(p > 0, np.maximum(np.abs(s - a), np.abs(s + ds - b)), 0.0).max(axis=1)
        redo = off > TRAVEL_TOLERANCE * dx
        if not redo.any():
            return p, results, q, s, ds, stuck, iterations
        a, b = np.where(redo[:, None], s, a), np.where(redo[:, None], s + ds, b)
    return None


def sweep_of(member, p, s, ds, wear_stationary) -> Sweep:
    """The shares of every increment's travel (rows of the stacks), over every column that deposits (in contact),
    reads the flat's wear or reads what the cycle deposits (the rates): one Sweep for the tally, the mismatches
    and the next pass's first read of the flat, which go along the same travels."""
    nx = p.shape[1]
    reach = int(np.ceil(max(np.abs(s).max(), np.abs(s + ds).max()) / member.grid.dx)) + 2
    on, worn = np.flatnonzero((p > 0).any(axis=0)), np.flatnonzero(wear_stationary.any(axis=0))
    ends = ([(on[0] - 2 * reach, on[-1] + 2 * reach)] if on.size else []) + (
        [(worn[0] - reach, worn[-1] + reach)] if worn.size else [])
    if not ends:
        return Sweep(s, s + ds, member.grid.dx, member.kernel, slice(0, 0))
    lo, hi = min(e[0] for e in ends), max(e[1] for e in ends)
    return Sweep(s, s + ds, member.grid.dx, member.kernel, slice(max(lo, 0), min(hi + 1, nx)))


def add_rows(tally, member, sweep: Sweep, p, q, ds, shares: np.ndarray) -> None:
    """The tally's :meth:`add` for every increment at once (rows of the stacks along ``sweep``); ``shares`` each
    increment's share of the rig's travel, 0 for one that is not counted (the first quarter)."""
    counted = (shares > 0)[:, None]
    amount = member.law.amount(p, q, ds) * counted
    tally.rate_m += member.k_moving * amount.sum(axis=0, keepdims=True)
    tally.rate_s += member.k_stationary * sweep.deposit(amount).sum(axis=0, keepdims=True)
    slid = np.where((p > 0) & counted, np.abs(ds), 0.0)
    tally.slip_m += slid.sum(axis=0, keepdims=True)
    tally.slip_s += sweep.deposit(slid).sum(axis=0, keepdims=True)
    tally.p_seen += (shares[:, None] * sweep.deposit(p)).sum(axis=0, keepdims=True)
    tally.energy += float((np.abs(q) * np.abs(ds) * counted).sum()) * tally.area
    tally.work += float(amount.sum()) * tally.area
    tally.shear = np.maximum(tally.shear, np.abs(q[counted[:, 0]]).max(axis=0, keepdims=True))


def mismatch_rows(tally, sweep: Sweep, p, step: float, w_lin) -> list:
    """For a resolved step's next pass, each increment's own mismatch (as coulomb._mismatches), all at once."""
    m = p.shape[0]
    seen = sweep.read(np.repeat(tally.rate_s, m, axis=0))
    found = step * (tally.rate_m + seen - w_lin(p))
    return [found[i:i + 1] for i in range(m)]
