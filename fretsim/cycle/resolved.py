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
  do not settle in MAX_ROUNDS leave the cycle to be solved increment by increment;
* **a symmetric cycle** (:func:`_symmetric`: a centred grid, even kernels, an unworn gap, worn surfaces and
  corrections that are their own mirror images along x): its up-stroke starts from its own end mirrored — the
  turning state of the cycle that runs, not of one increment from rest — and its down-stroke is its up-stroke
  mirrored: normal contacts taken, not solved (:func:`fretsim.solvers.rows.solve_mirrored_rows`, each checked
  against its pair's gap), travels and tractions mirrored.  Its deposits are mirrored too, so the state stays
  symmetric to round-off; before, the quarter's start and the solver's tolerance left the flat 3e-4 asymmetric
  after 18 000 cycles of McColl 185 N.  It pays less than half in 2D, where a stack's cost is mostly per call, not
  per layer (McColl 185 N 2D: the loop 0.89×), and lets a 3D line contact go stacked (MIRRORED_STACK_LIMIT; McColl
  185 N 3D 0.64× its loop one by one).

An implicit step (a cycle that anticipates s cycles of its own wear) solves the positions **coupled**
(:func:`coupled_positions`): each position's gap at the step's end holds the wear the whole cycle deposits — the
moving body's, the same for all, and the flat's, which every position deposits along its travel and reads along
its own, each position's deposit by one slip — so the positions are one convex problem (:func:`fretsim.solvers.rows.solve_coupled`), preconditioned
by the coupling's rank-two structure per Fourier mode (:class:`Coupling`).  Solved position by position with a
bound for the wear operator, a step needed three corrected passes and still left each position's gap off by half
the step's wear at the scar's turning edges (tests/test_coupled_step.py); coupled it needs none (4 %), and its
steps are longer (McColl 185 N 2D: 54 steps, not 90).

The tally, the implicit step's mismatches and everything the cycle returns are then the same sums, over the
stack.  This is the same discretisation as the increment-by-increment cycle (the same positions, travels to the
same tolerance); it is not bit-identical to it (tests/test_resolved_rows.py measures how close).
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.native import RowMatrix
from fretsim.solvers.rows import even_along_x, mirror_result
from fretsim.stability import odd_even_run
from fretsim.wear import Sweep, _hat_integral, sweep_read

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
MIRRORED_STACK_LIMIT = 250_000  # ... and a symmetric cycle's, which solves half its positions (the others mirrored):
#                                McColl 185 N 3D (19 × 27 × 427 = 219 000) took 74 s stacked and mirrored against 115 s
#                                increment by increment (two runs each, in both orders, a second job on the machine),
#                                its mid-stroke pressure smooth where the one by one's, from the quarter, is noisy
#                                (±1.5 MPa element to element on 71 MPa; its peak 3.6 % higher on a noise spike)
COUPLED_MIRROR = True  # a symmetric cycle's coupled step solves its up-stroke only (coupled_positions), where the run
#                        applies one load (NormalSolve.one_load): McColl 185 N 2D 1.06 s against 1.6 s unmirrored, 3D
#                        32–35 s against 67–72 s.  Across load blocks it goes unmirrored: mirrored, the tube in service
#                        (tube_service_RT, resolved, 2D) stopped 40 000 cycles after the block change at 2.3328e8 under
#                        BDF2 (92.6 % odd-even; backward Euler 43.6 %), where the unmirrored coupled step and the mirrored
#                        corrected passes complete (the odd-even wear one block's positions never read and the next
#                        block's do, ODD_EVEN_RUN; why the mirror loses the unmirrored step's margin there, whose up-stroke
#                        starts one increment from rest, is not established: scripts/results/resolved_stability_coupled.txt)
COUPLED_LIMIT = 1_000_000  # elements of a whole stack beyond which an implicit step corrects pass by pass
SINGLE = True  # the coupled preconditioner (Coupling.preconditioner) in float32: an approximate inverse,
#                half the transforms' work; the iteration's own tests use the double operator (within 5e-5 of double's
#                preconditioner, 1 710 iterations against 1 721 on McColl 185 N 3D, the results within 2e-9)
OWN_SLIP_PASSES = 3  # coupled solves again with each point's own slip lagged (Coupling.remainder), at most
OWN_SLIP_TOLERANCE = 1e-2  # ... until what it adds moves by less than this share of the step's largest wear.  What
#                            is left unsolved stays in the step's correction (its defect sees it), and the results
#                            do not feel it: against 1e-3, McColl 185/500/1670/500 N-10 µm 2D and 185 N 3D moved by
#                            at most 8e-5 (relative) in depth, width and volume, Kirk 20 Hz, S132 and the ball at
#                            25 µm (2D, 20 000 cycles) by at most 2e-4 (Kirk's width), and ran 12-34 % faster (a
#                            re-solve is 5-24 iterations of nine positions).  On all of them no step re-solved at
#                            1e-2: solving no lag at all moved them as little, but the lag is what keeps a step past a
#                            reversal implicit in its points' own slip where it is large
ODD_EVEN_RUN = 12  # a coupled step whose positions' pressures alternate element by element over this many elements
#                    (stability.odd_even_run) is taken by the corrected passes instead.  The positions read the flat
#                    at fractions of an element (the hat), so wear a load block deposits can alternate in ways none of
#                    its own positions read (no wear damps it); the next block's positions, at other fractions, read
#                    it, and an exact step answers with the pressure that wears it off in one step — 46 % odd-even
#                    over 16–40 elements on the tube in service at 233 280 000 cycles (15 N, 80 µm → 5 N, 20 µm),
#                    healed in three steps but past the watch's ceiling.  The corrected passes' bound (4δ(k_m + k_s) on
#                    each position) damps it instead.  McColl's worn positions make runs of at most 4; the tubes in
#                    service's ordinary steps up to 11 or so (at 8 the corrected passes took 311 of tube_service_90C's
#                    675 steps; at 12, 134 of 461)
MAX_ROUNDS = 4  # normal solves of the stack before the cycle goes increment by increment (2 is usual: the second
#                 re-solves the few positions whose travel the first pressure moved by more than the tolerance)


def travels(member, pressures: np.ndarray, du: np.ndarray, budget: Optional[int] = None, mirror=()):
    """Each increment's traction, travel ΔU − KΔq and stick set at ``pressures`` (m, My, Mx), from rest before the
    first, and the tangential solver's iterations.  Increments that slide entirely at ±μp are taken together;
    with a ``budget``, None where more increments than that need the tangential solver, or the first does (from
    rest over half the stroke, it sticks somewhere only below about the gross-slip stroke).  ``mirror``: pairs
    (i, j) of a symmetric cycle (:func:`positions`), whose increment j is increment i mirrored along x, not solved."""
    mu = member.friction_coefficient
    sign = np.sign(du)[:, None, None]
    cand = sign * mu * pressures  # the traction where the whole contact slides (0 outside it)
    stuck = np.zeros(pressures.shape, bool)
    if member.rigid:
        return cand, np.broadcast_to(du[:, None, None], pressures.shape).copy(), stuck, 0
    k = member.tangential
    # (a symmetric cycle's down-stroke is its up-stroke mirrored, set below: its layers' K·q are not needed)
    solved = mirror[-1][0] + 1 if mirror else pressures.shape[0]
    kq = np.zeros(pressures.shape)
    kq[:solved] = k(cand[:solved])
    kq_before = np.concatenate([np.zeros((1,) + kq.shape[1:]), kq[:-1]])
    ds = du[:, None, None] - (kq - kq_before)
    slides = ((sign * ds >= 0.0) | (pressures <= 0.0)).all(axis=(1, 2))  # no point would slip against its traction
    if budget is not None and not slides[0]:  # the first, from rest over the half stroke, sticks: partial slip
        return None
    q, iterations, count = cand, 0, 0
    exact = True  # the traction before this increment is its candidate (or rest, before the first)
    for i in range(solved):
        if exact and slides[i]:
            continue
        if not exact:  # the traction before is the solver's: this increment's sliding candidate from it
            ds[i] = du[i] - (kq[i] - k(q[i - 1]))
            if ((sign[i] * ds[i] >= 0.0) | (pressures[i] <= 0.0)).all():
                exact = True
                continue
        count += 1
        if budget is not None and count > budget:
            return None
        if q is cand:
            q = cand.copy()
        q[i], ds[i], stuck[i], its = member._tangential(q[i - 1] if i else np.zeros(q.shape[1:]), pressures[i], du[i])
        iterations += its
        exact = bool(np.array_equal(q[i], cand[i]))
    if mirror:
        q = q.copy() if q is cand else q
        for i, j in mirror:
            q[j], ds[j], stuck[j] = -q[i][..., ::-1], -ds[i][..., ::-1], stuck[i][..., ::-1]
    return q, ds, stuck, iterations


def starts(ds: np.ndarray) -> np.ndarray:
    """Where each increment's travel starts: the travels before it added up, from 0 (the loop's rest)."""
    s = np.zeros_like(ds)
    np.cumsum(ds[:-1], axis=0, out=s[1:])
    return s


def _went(member, p: np.ndarray, du: np.ndarray, a: np.ndarray, b: np.ndarray, mirror=()) -> tuple:
    """Where the points went at the pressures ``p`` (tractions, travels, stick sets, iterations, starts) and which
    positions' points went more than TRAVEL_TOLERANCE of an element from the travels (``a`` → ``b``) their
    pressures were solved over, at either end."""
    q, ds, stuck, its = travels(member, p, du, mirror=mirror)
    s = starts(ds)
    off = np.where(p > 0, np.maximum(np.abs(s - a), np.abs(s + ds - b)), 0.0).max(axis=(1, 2))
    return q, ds, stuck, its, s, off > TRAVEL_TOLERANCE * member.grid.dx


def positions(member, wear_moving, wear_stationary, normal, du: np.ndarray, guess, extra, cycle: int,
              correction=None, predicted=None):
    """Every increment of a resolved cycle solved together: (pressures, contact results, tractions, starts,
    travels, stick sets, iterations), stacks (m, My, Mx) over the increments of ``du``; None where the cycle must be
    solved increment by increment (no stacked solve here, no warm start, or positions that did not settle).

    ``correction``: an implicit step's gap correction per increment; ``predicted``: (pressures, starts, travels)
    of the step's previous pass, else the travels at ``guess`` everywhere.  A symmetric cycle (module docstring)
    solves its quarter and up-stroke only: the quarter (uncounted: it only sets the traction the up-stroke starts
    from) is the up-stroke's last position mirrored, the down-stroke the up-stroke mirrored."""
    rows = getattr(normal, "rows", None)
    m, shape = du.size, member.grid.shape
    if rows is None or not getattr(normal, "stacks", True) or (predicted is None and guess is None) or \
            predicted == () or m * member.grid.size > MIRRORED_STACK_LIMIT:
        return None  # (predicted (): the step's last pass went one by one)
    moving = wear_moving + (np.stack(correction) if correction is not None else 0.0)
    moving = np.broadcast_to(moving, (m,) + shape)
    flat = np.broadcast_to(wear_stationary, (m,) + shape)
    iterations = 0
    pairs = mirror_pairs(du)
    start = guess if predicted is None else predicted[0]
    turn = _turn(du, pairs) if pairs and _symmetric(member, normal, moving, wear_stationary, pairs, extra, start) \
        else None
    if turn is None and m * member.grid.size > STACK_LIMIT:
        return None
    if predicted is None:
        # (a symmetric cycle's from the warm start made symmetric: the quarter is the up-stroke's end mirrored, and
        #  it is where the up-stroke starts, so a prediction whose quarter is not its first position's contact puts
        #  the up-stroke's first traction elsewhere than its contact — the warm start mirrored for the quarter and
        #  the warm start for the rest did, where mid-stroke's contact, behind a compliant rig, sits 16 elements off
        #  centre: the tangential solve from it did not converge and the run failed.  The prediction's travels are
        #  also each other's mirror images then, as the pairs' gaps must be for the stack to take them mirrored.)
        p = np.repeat((0.5 * (guess + guess[..., ::-1]) if turn is not None else guess)[None], m, axis=0)
        found = travels(member, p, du, budget=m // PARTIAL_SHARE, mirror=pairs if turn is not None else ())
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
        if turn is not None:  # the turning state is the up-stroke's end mirrored, not solved
            redo[turn[0]] = False
        if sweep is not None:  # (the predicted sweep reads every position: the ones solved are taken from it)
            seen = (moving + _read(member, flat, a, b, sweep))[redo]
        else:
            seen = moving[redo] + _read(member, flat[redo], a[redo], b[redo])
        sweep = None
        where = np.cumsum(redo) - 1  # a position's row in the stack of those solved this round
        got = rows(seen, p[redo], extra, load=member.load, cycle=cycle,
                   mirrors=[(where[i], where[j]) for i, j in pairs if redo[i] and redo[j]])
        if got is None:
            return None
        p[redo] = got[0]
        for i, res in zip(np.flatnonzero(redo), got[1]):
            results[i] = res
            iterations += res.iterations
        if turn is not None:
            p[turn[0]] = p[turn[1]][..., ::-1]
            results[turn[0]] = mirror_result(results[turn[1]])
        q, ds, stuck, its, s, redo = _went(member, p, du, a, b, pairs if turn is not None else ())
        iterations += its
        if turn is not None:
            redo[turn[0]] = False
        if not redo.any():
            return p, results, q, s, ds, stuck, iterations
        a, b = np.where(redo[:, None, None], s, a), np.where(redo[:, None, None], s + ds, b)
    return None


def mirror_pairs(du: np.ndarray) -> list:
    """The positions (i, j) of a cycle whose rig increments are mirror images (the up-stroke's k-th and the
    down-stroke's k-th: U → −U): over symmetric wear their contacts are too, and one is solved for both."""
    # (increment_path's are exact negatives: U and −U are built from the same sums, and rounding is symmetric)
    ups = [i for i, d in enumerate(du) if d > 0]
    downs = [j for j, d in enumerate(du) if d < 0 and j > max(ups, default=-1)]
    if len(ups) == len(downs) and all(du[i] == -du[j] for i, j in zip(ups, downs)):
        return list(zip(ups, downs))
    return []


def _turn(du: np.ndarray, pairs: list) -> Optional[tuple]:
    """(the quarter, the up-stroke's last position) of a path that is a quarter from rest and then the loop."""
    if len(du) == 2 * len(pairs) + 1 and pairs[0][0] == 1 and du[0] < 0:
        return 0, pairs[-1][0]
    return None


def _symmetric(member, normal, moving: np.ndarray, flat: np.ndarray, pairs: list, extra, p: np.ndarray) -> bool:
    """Whether a cycle's contact problem is symmetric along x at this state: the problem itself (the unworn gap,
    the grid and the normal operators: ``normal.mirror_tolerance``; the tangential compliance's kernel), the flat's
    wear and the moving body's gap at each pair of mirrored positions (with an implicit step's corrections), within
    the mirror's tolerance.  Then the cycle is too, once its up-stroke starts from its own end mirrored
    (:func:`positions`): the down-stroke is the up-stroke mirrored, and so are their deposits (to round-off: the
    state's asymmetry does not grow)."""
    find = getattr(normal, "mirror_tolerance", None)
    within = find(extra, float(p.max())) if find is not None else 0.0
    if not member.rigid:
        kernel = getattr(member.tangential, "kernel", None)
        within = within if even_along_x(kernel) else 0.0
    return within > 0 and bool(np.abs(flat - flat[..., ::-1]).max() <= within and
                               all(np.abs(moving[i] - moving[j][..., ::-1]).max() <= within for i, j in pairs))


def mirror_images(member, low: tuple, high: tuple) -> bool:
    """Whether a cycle's turning states, (traction, pressure) at −δ and +δ, are each other's mirror image along x
    (exactly: a symmetric cycle's are, :func:`positions`) under a tangential compliance that is itself symmetric:
    then its loop's down half is its up half mirrored."""
    kernel = getattr(member.tangential, "kernel", None)
    return even_along_x(kernel) and \
        np.array_equal(high[1], low[1][..., ::-1]) and np.array_equal(high[0], -low[0][..., ::-1])


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


def coupled_positions(member, wear_moving, wear_stationary, normal, du: np.ndarray, counted: np.ndarray, guess,
                      extra, cycle: int, step: float, start: Optional[np.ndarray] = None):
    """An implicit step's resolved cycle with every position's gap at the step's end: each position solved over
    the wear the whole cycle deposits in the step (the moving body's, and the flat's read along its travel), as
    one problem (:meth:`fretsim.loop.rows.NormalSolve.coupled`) — so that the step needs no correction passes.
    (positions' tuple, and each increment's gap correction the solution implies: what an implicit pass would
    have been corrected by); None where it cannot be done (the caller corrects pass by pass).

    At fixed travels the wear a cycle deposits is linear in the pressures, p_j·ω_j with ω_j = c|ds_j| (c the law's
    sliding factor: the amount where each point slides), taken one value a position (:class:`Coupling`), and what
    position k reads of it is the transpose of what it deposits (the hat kernel reads and receives by the same
    weights), so Ω times the coupled operator is symmetric and positive; the travels then follow the pressures as
    in :func:`positions`, and the pass's defect measures what the linearisation (each point's own slip, the
    travels) missed.  ``start``: the last step's pressures at every position.  A symmetric cycle (:func:`positions`)
    solves its up-stroke coupled by its wear and its mirror image's; the rest is mirrored, as in :func:`positions`."""
    coupled = getattr(normal, "coupled", None)
    m, shape = du.size, member.grid.shape
    if coupled is None or not getattr(normal, "stacks", True) or guess is None or \
            m * member.grid.size > COUPLED_LIMIT or not step:
        return None
    # from the last step's positions where there is one (the turning positions' contacts are a third narrower
    # than mid-stroke's: from mid-stroke's pressure everywhere the coupled solve took 1.5 times the iterations)
    started = start is not None and start.shape == (m,) + shape
    p = start.copy() if started else np.repeat(guess[None], m, axis=0)
    pairs = mirror_pairs(du)
    turn = _turn(du, pairs) if pairs and COUPLED_MIRROR and getattr(normal, "one_load", True) and \
        _symmetric(member, normal, np.broadcast_to(wear_moving, (m,) + shape), wear_stationary, pairs, extra, p) else None
    mirror = pairs if turn is not None else ()
    if mirror:  # (from the warm start made symmetric, as positions() starts)
        p = _mirrored(p if started else np.repeat(0.5 * (guess + guess[..., ::-1])[None], m, axis=0), mirror, turn)
    found = travels(member, p, du, budget=m // PARTIAL_SHARE, mirror=mirror)
    if found is None:
        return None
    iterations = found[3]
    a = starts(found[1])
    b = a + found[1]
    flat = np.broadcast_to(wear_stationary, (m,) + shape)
    factor = member.law.gross_slip_factor(member.friction_coefficient)
    idx = np.array([i for i, _ in mirror], int) if mirror else np.flatnonzero(counted)  # the positions solved
    rest = np.array([], int) if mirror else np.flatnonzero(~counted)
    for _ in range(MAX_ROUNDS):
        sweep = sweep_of(member, p, a, b - a, wear_stationary, np.isin(np.arange(m), idx))
        seen = wear_moving + _read(member, flat, a, b, sweep)
        couple = Coupling(member, sweep, factor * np.abs(b - a)[idx], (a[idx], b[idx]), step, p[idx] > 0,
                          mirrored=bool(mirror))
        got, lag, its = _coupled_solve(member, coupled, couple, seen[idx], p[idx], extra, cycle, grow=started)
        if got is None:
            return None
        p[idx] = got[0]
        iterations += its
        results = [None] * m
        for i, res in zip(idx, got[1]):
            results[i] = res
        grown = None
        if rest.size:  # the uncounted quarter deposits nothing: it reads the step's wear, solved on C alone
            r_m, r_s = couple.rates(p[idx], own=True)
            grown = step * (r_m + _read(member, r_s, a[rest], b[rest]))
            got = normal.rows(seen[rest] + grown, p[rest], None, load=member.load, cycle=cycle)
            if got is None:
                return None
            p[rest] = got[0]
            for i, res in zip(rest, got[1]):
                results[i] = res
                iterations += res.iterations
        if mirror:
            p = _mirrored(p, mirror, turn, results)
        q, ds, stuck, its, s, redo = _went(member, p, du, a, b, mirror)
        iterations += its
        if not redo.any():
            if odd_even_run(p.reshape(-1, shape[-1])) >= ODD_EVEN_RUN:
                return None  # (see ODD_EVEN_RUN: the corrected passes take this step)
            correction = np.empty((m,) + shape)
            correction[idx] = couple(p[idx]) - extra(p[idx]) + lag
            if rest.size:
                correction[rest] = grown - extra(p[rest])
            if mirror:
                correction = _mirrored(correction, mirror, turn)
            return (p, results, q, s, ds, stuck, iterations), list(correction)
        a, b = s, s + ds
    return None


GROW_ELEMENTS = 3  # the warm start's contact grown by this many elements each way (grown_start)
GROW_SHARE = 0.05  # ... with this share of the largest pressure within that reach


def grown_start(stack: np.ndarray) -> np.ndarray:
    """The last step's positions' pressures (m, My, Mx) as the next coupled solve's start, each contact grown by
    GROW_ELEMENTS along x and y with a small pressure (GROW_SHARE of the largest within reach).  Between steps the
    worn contact widens by 1-7 elements at its edges (McColl 185 N 3D), and Polonsky–Keer's iteration admits
    penetrating elements one ring an iteration, restarting its conjugacy each time (two thirds of its iterations
    were such restarts); an element started in contact that is not leaves by a clip, which keeps the conjugacy.
    McColl 185 N 3D: 18 % fewer iterations (1 549 → 1 270), its depths within the solver's tolerance; in 2D no
    change (927 → 900)."""
    grown = stack.copy()
    for axis in (-1, -2):
        if stack.shape[axis] == 1:
            continue
        base = grown.copy()
        for k in range(1, GROW_ELEMENTS + 1):
            ahead = [slice(None)] * stack.ndim
            behind = [slice(None)] * stack.ndim
            ahead[axis], behind[axis] = slice(k, None), slice(None, -k)
            np.maximum(grown[tuple(ahead)], base[tuple(behind)], out=grown[tuple(ahead)])
            np.maximum(grown[tuple(behind)], base[tuple(ahead)], out=grown[tuple(behind)])
    return np.where(stack > 0, stack, GROW_SHARE * grown)


def _coupled_solve(member, coupled, couple, seen, pc, extra, cycle: int, grow: bool = False) -> tuple:
    """The coupled positions' pressures and results (None: not solved here), with each point's own slip lagged
    (:meth:`Coupling.remainder`) until it settles: (found, the lag, iterations).  ``grow``: ``pc`` is the last
    step's, whose contacts the first solve starts grown (:func:`grown_start`)."""
    lag, iterations, got = np.zeros(pc.shape), 0, None
    pc = grown_start(pc) if grow else pc
    for _ in range(1 + OWN_SLIP_PASSES):  # each point's own slip, lagged (see Coupling)
        got = coupled(seen + lag, pc, couple, None, load=member.load, cycle=cycle)
        if got is None:
            return None, lag, iterations
        pc = got[0]
        iterations += sum(res.iterations for res in got[1])
        lag, moved = couple.remainder(pc), lag
        if np.abs(lag - moved).max() <= OWN_SLIP_TOLERANCE * max(np.abs(couple(pc)).max(), 1e-300):
            break
    return got, lag, iterations


def _mirrored(stack: np.ndarray, mirror: list, turn: tuple, results: Optional[list] = None) -> np.ndarray:
    """A symmetric cycle's stack (m, My, Mx) with its down-stroke the up-stroke mirrored along x and its quarter
    the up-stroke's end mirrored (``results``: their ContactResults too, in place)."""
    out = stack.copy()
    for i, j in list(mirror) + [(turn[1], turn[0])]:
        out[j] = stack[i][..., ::-1]
        if results is not None:
            results[j] = mirror_result(results[i])
    return out


class Coupling:
    """A resolved implicit step's coupling of its counted positions (:func:`coupled_positions`): the wear the cycle
    deposits in the step, read by every position, less what the layers' own operator C + s·W already has.

    Its preconditioner inverts the coupled operator as if the contact covered the window: per Fourier mode ξ along
    x the coupling is of rank two over the positions — the moving body's wear, the same for every position, and
    the flat's, which position k reads shifted by its travel o_k (a phase e^{iξo_k}) — so C(ξ)I + s·UVᵀ inverts by
    Woodbury with a 2 × 2 solve per mode.  With each layer's own inverse instead (C + s·W)⁻¹, the modes in which
    the positions differ were taken as stiff as those they share, and the iterations grew with the step (to 90)."""

    def __init__(self, member, sweep, weight, travel: tuple, step: float, on=None, mirrored: bool = False):
        self.sweep, self.step = sweep, step
        # (``mirrored``: the positions are a symmetric cycle's up-stroke, whose mirror image, the down-stroke,
        #  deposits the mirror image of their wear: the step's wear is theirs and its mirror image)
        self.mirrored = mirrored
        self.k_m, self.k_s = member.k_moving, member.k_stationary
        m = weight.shape[0]
        # each position's c·|ds| as most of its points in contact (``on``) have it, one value a position: with
        # each point's own the coupling is not symmetric (a point deposits by its slip and reads unweighted), and
        # past a reversal, where a position's points slide 12–15 % less and unevenly, its symmetric part was
        # indefinite on the contact.  With one ω_k a position, Ω·(C + s·M) is symmetric and positive (M = GΩ, G
        # the read-deposit Gram operator): CG weights each layer's inner products by ω_k (layer_weights).  What
        # the points' own slips change is put back as a lagged gap correction (remainder).
        on = np.ones(weight.shape, bool) if on is None else on
        self.omega = np.array([float(np.median(w[o])) if o.any() else float(np.median(w)) for w, o in zip(weight, on)])
        self.weight = np.broadcast_to(self.omega[:, None, None], weight.shape)
        self.own = weight  # each point's own c·|ds|: the wear the cycle tallies
        self.layer_weights = self.omega
        self.start, self.end = (np.median(x.reshape(m, -1), axis=1) for x in travel)

    def rates(self, pc, own: bool = False):
        """The moving body's and the flat's wear per cycle from the counted positions' pressures ``pc``, each point
        by its position's slip ω_k (``own``: by its own)."""
        amount = (self.own if own else self.weight) * pc
        return self._whole(self.k_m * amount.sum(axis=0)), self._whole(self.k_s * self.sweep.deposit(amount).sum(axis=0))

    def _whole(self, rate):
        """A wear rate of the positions solved, with their mirror images' where they are a symmetric cycle's half."""
        return rate + rate[..., ::-1] if self.mirrored else rate

    def remainder(self, pc):
        """What each point's own slip adds to the step's wear that its position's ω_k leaves out, as each position
        reads it: a gap correction for the next coupled solve (a fixed point: the difference is small — the
        first increment past a reversal's points slide unevenly — so it settles in a pass or two)."""
        amount = (self.own - self.weight) * pc
        r_m, r_s = self._whole(self.k_m * amount.sum(axis=0)), self._whole(self.k_s * self.sweep.deposit(amount).sum(axis=0))
        return self.step * (r_m + self.sweep.read(np.broadcast_to(r_s, pc.shape)))

    def __call__(self, pc):
        """The step's wear as each position reads it: the coupling, which the coupled solve adds to C alone (not
        to C + s·W less s·W: two convolutions of the whole grid an iteration that cancelled, a fifth of a 3D run)."""
        r_m, r_s = self.rates(pc)
        return self.step * (r_m + self.sweep.read(np.broadcast_to(r_s, pc.shape)))

    def window(self, rows: slice, cols: slice, shape: tuple):
        """This coupling on the window (``rows``, ``cols``) of stacks ``shape`` (positions, My, Mx): what __call__
        gives on a stack that is zero outside the window, cut to it.  The sweep's shares between the window's
        elements and the flat as one sparse matrix R, built once a solve: the read is R·f and the deposit Rᵀ·a
        (the same shares: the hat kernel reads and receives alike), where scattering by bincount over the whole
        grid's stack was a fifth of a 3D run.  None where the sweep goes by running sums (long travels)."""
        entries = self.sweep.entries()
        if entries is None:  # (a sweep by running sums, over long travels: the caller pads and cuts)
            return None
        m, ny, nx = shape
        (r0, r1, _), (c0, c1, _) = rows.indices(ny), cols.indices(nx)
        wy, wx = r1 - r0, c1 - c0
        moving, flat, share = entries
        k, rest = np.divmod(moving, ny * nx)
        y, x = np.divmod(rest, nx)
        keep = (y >= r0) & (y < r1) & (x >= c0) & (x < c1)
        element = ((k * wy + y - r0) * wx + x - c0)[keep]
        # (by rows: the sweep lists its shares offset by offset, each offset's in element order — runs that a
        #  stable sort merges)
        order = np.argsort(element.astype(np.int32), kind="stable")
        element, share = element[order], share[keep][order]
        matrix = RowMatrix(element, (flat % (ny * nx))[keep][order], (m * wy * wx, ny * nx))
        # the constants folded in once: the deposit weighs position k's elements by k_s·ω_k, the read by the step
        deposit = share * np.repeat(self.k_s * self.omega, wy * wx)[element]
        read = self.step * share
        moving = self.step * self.k_m * self.omega
        # (a mirror image's moving-body wear lands on the window's mirror image: the window itself where it is
        #  symmetric about the grid's centre, as solve_coupled makes it)
        inside = not self.mirrored or c0 + c1 == nx

        def couple(pc):
            r_s = matrix.dot_transposed(deposit, pc.reshape(-1))
            out = matrix.dot(read, self._whole(r_s.reshape(ny, nx)).reshape(-1) if self.mirrored else r_s
                             ).reshape(pc.shape)
            r_m = _layer_sum(moving[:, None, None], pc)
            if inside:
                out += r_m + r_m[..., ::-1] if self.mirrored else r_m
            else:
                whole = np.zeros((ny, nx))
                whole[r0:r1, c0:c1] = r_m
                out += self._whole(whole)[r0:r1, c0:c1]
            return out
        return couple

    def preconditioner(self, win, rows: slice, cols: slice):
        """An approximate inverse of C + s·(coupling) on the window operator ``win`` (C there).  Mirrored: the
        inverse of the whole cycle's (the positions and their mirror images, each mirror image's transform had
        from its position's by symmetry: no more transforms), its positions' part of what it gives; the window is
        then symmetric about the grid's centre (solvers.rows.solve_coupled), so that mirroring in it is the
        cycle's mirror."""
        c_hat = win.hat
        c_hat = np.maximum(c_hat.real if np.iscomplexobj(c_hat) else c_hat, 1e-3 * float(np.abs(win.hat).max()))
        lx = win.fft_shape[1]
        xi = 2.0 * np.pi * np.arange(c_hat.shape[-1]) / (lx * win.grid.dx)
        m = self.omega.size
        omega, start, end = self.omega, self.start, self.end
        if self.mirrored:  # (a mirror image reads along its position's travel mirrored: −end → −start)
            omega, start, end = np.tile(omega, 2), np.concatenate([start, -start]), np.concatenate([end, -end])
            # the mirror image's transform, from its position's (real, nx wide, padded to lx): a phase times the
            # conjugate at the opposite y frequency
            turn = np.exp(-1j * xi * win.grid.dx * (win.grid.shape[1] - 1))
            flip = (-np.arange(win.fft_shape[0])) % win.fft_shape[0]
        r = read_symbol_modes(lx, start, end, win.grid.dx)
        w = omega[:, None]
        s = self.step
        g11 = c_hat + s * self.k_m * float(omega.sum())  # (the 2 × 2 system per mode: the same along y)
        g12 = s * self.k_s * (w * r).sum(axis=0)
        g21 = s * self.k_m * (w * r.conj()).sum(axis=0)
        g22 = c_hat + s * self.k_s * (w * np.abs(r) ** 2).sum(axis=0)
        det = g11 * g22 - g12 * g21
        a11, a12, a21, a22 = s * self.k_m * g22 / det, -s * self.k_m * g12 / det, -s * self.k_s * g21 / det, \
            s * self.k_s * g11 / det
        wr = w * r.conj()
        inv_c = 1.0 / c_hat
        if SINGLE:
            omega, wr, r, inv_c = omega.astype(np.float32), wr.astype(np.complex64), r.astype(np.complex64), \
                inv_c.astype(np.float32)
            a11, a12, a21, a22 = (x.astype(np.complex64) for x in (a11, a12, a21, a22))
            if self.mirrored:
                turn = turn.astype(np.complex64)

        def apply(v):
            vh = win.forward(v.astype(np.float32) if SINGLE else v)  # (m, ly, modes)
            # (the sums over the positions layer by layer: einsum took 3-5 times as long on a 3D window, and
            #  tensordot hands this small product to a multithreaded BLAS, whose threads woke for every call —
            #  4-8 ms a call, 2.2x the whole 2D McColl 185 N run on two cores)
            v1, v2 = _layer_sum(omega[:m, None, None], vh), _layer_sum(wr[:m, None, :], vh)
            if self.mirrored:  # the mirror images' sums from the positions': image k is turn·conj(vh_k) at the
                #                opposite y frequency, its ω_k the same and its read symbol conj(r_k), so each sum
                #                over the images is turn·conj(the positions' sum at −η) — not 2m layers formed
                v1 = v1 + turn * np.conj(v1[flip])
                v2 = v2 + turn * np.conj(v2[flip])
            x1 = a11 * v1
            x1 += a12 * v2
            x2 = a21 * v1
            x2 += a22 * v2
            vh -= x1
            vh -= r[:m, None, :] * x2
            vh *= inv_c
            return win.backward(vh)  # (float32 where SINGLE: the caller's product with the mask promotes it exactly)
        return apply


def _layer_sum(weights: np.ndarray, stack: np.ndarray) -> np.ndarray:
    """Σ_k weights[k]·stack[k] over a stack's first axis, one layer at a time (weights broadcast to a layer)."""
    out = weights[0] * stack[0]
    for k in range(1, stack.shape[0]):
        out += weights[k] * stack[k]
    return out


def _read_weights(start: np.ndarray, end: np.ndarray, dx: float) -> tuple:
    """The elements j (positions, span) a travel from ``start`` to ``end`` (mm) reaches, and their weights w_j: the
    hat (linear interpolation) of element j averaged over the travel, as :func:`fretsim.wear.sweep_read` reads."""
    a, b = start / dx, end / dx
    lo = np.floor(np.minimum(a, b)).astype(int) - 1
    span = int(np.max(np.ceil(np.maximum(a, b)) - lo)) + 2
    j = lo[:, None] + np.arange(span)[None]  # (m, span) elements
    length = b - a
    point = np.abs(length) < 1e-9
    averaged = (_hat_integral(b[:, None] - j) - _hat_integral(a[:, None] - j)) / np.where(point, 1.0, length)[:, None]
    return j, np.where(point[:, None], np.clip(1.0 - np.abs(a[:, None] - j), 0.0, None), averaged)


def read_symbol_modes(lx: int, start: np.ndarray, end: np.ndarray, dx: float) -> np.ndarray:
    """The Fourier symbol (positions, modes) of reading the flat along a travel from ``start`` to ``end`` (mm), as
    :func:`fretsim.wear.sweep_read` reads it with the hat kernel — Σ_j w_j·e^{iξ·j·dx} over the elements j the
    travel reaches (:func:`_read_weights`) — at the real transform's modes of a padded length ``lx`` (ξ =
    2πk/(lx·dx), k ≤ lx/2): e^{iξ·j·dx} is then e^{2πi·jk/lx}, so the symbol is the conjugate transform of the
    weights laid at j mod lx —
    one transform a position, where the exponentials of every element and mode were a tenth of a 2D resolved run."""
    j, w = _read_weights(start, end, dx)
    laid = np.zeros((w.shape[0], lx))
    if j.shape[1] <= lx:  # (a travel within the padded length: its elements land on distinct points)
        laid[np.arange(w.shape[0])[:, None], j % lx] = w
    else:
        np.add.at(laid, (np.arange(w.shape[0])[:, None], j % lx), w)
    return np.conj(np.fft.rfft(laid, axis=1))
