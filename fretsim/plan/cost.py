"""What a planned run will cost: the solves its stepping scheme takes, and seconds from one timed solve."""
from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from fretsim.compliance import add
from fretsim.compliance import fft
from fretsim.solvers import solve

# a step's solve, warm-started on the contact's window, against the cold solve timed (loop time per solve over one
# cold solve, measured on McColl 185 N 2D/3D with BDF2 and linear jumps, Kirk 20 Hz, the 3D tube, the partial-slip
# ball: 0.22-0.56, the 2D runs' per-step overhead the rest; was 0.5, and 1 for friction cycles, which estimated
# those 1.9-3.6x too long)
WARM_SOLVE = 0.35


# solves a block of a load history costs at least, up to its cycles: each block restarts the stepping (measured,
# BDF2, McColl 2D two-load histories: 400 one-cycle blocks 401 solves; 40 blocks of 500 cycles 185, 4.6 a block)
SOLVES_PER_BLOCK = 4.6
# a resolved step's pass against the warm cycle timed on the unworn contact: the worn contact's windows are wider
# and its stacks take more iterations (run over estimate, McColl 185 / 500 / 1670 / 500 N-10 µm 2D: 3.1, 3.1, 1.2,
# 1.4; 185 N 3D: 3.3; the middle taken, so the estimate is within about 1.6× either way)
RESOLVED_WORN = 2.0
BLOCK_START = 2.0  # cold solves per step of a block start (400 one-cycle blocks: 800 solves, 401 steps)


def estimate_solves(setup) -> int:
    """Solves a run is expected to take (measured on the shipped cases; for progress and `check`): the scheme's
    for the run's cycles, or, for a history of many short blocks, the blocks' restarts (they used to be left out:
    10 000 one-cycle blocks were estimated at 93 solves) — to where a pilot run reached a wear limit, where one
    did (loading.cycles is then an upper bound: the tube in service's 64 blocks, of which its pilot took 13)."""
    if setup.cycles == 0:
        return 1
    setup = _to_expected_stop(setup)
    return max(setup.stepper.estimate_solves(setup), int(round(_restarts(setup))))


def _to_expected_stop(setup):
    """The setup over the cycles the run is expected to take: to the pilot's wear limit, where it reached one."""
    stop = setup.expected_stop
    if not math.isfinite(stop) or stop >= setup.cycles:
        return setup
    return dataclasses.replace(setup, loading=setup.loading.with_cycles(max(1, int(math.ceil(stop)))))


def _restarts(setup) -> float:
    """The steps a load history's block starts take (0 for one block)."""
    blocks = setup.loading.blocks
    return sum(min(b.cycles, SOLVES_PER_BLOCK) for b in blocks) if len(blocks) > 1 else 0.0


def _seconds(setup, solves: int, unit: float) -> float:
    """Seconds for ``solves`` steps of ``unit`` seconds cold: warm-started, or, where the block starts are most of
    them, cold (a block restarts the stepping from its first cycle, BLOCK_START cold solves a step)."""
    return max(solves * unit * WARM_SOLVE, _restarts(setup) * unit * BLOCK_START)


def estimate_cost(setup) -> tuple[int, float]:
    """(solves, seconds) before a run: solves from the scheme, seconds from one timed contact solve."""
    fft.forward(np.zeros((1, 3)), (1, 6))  # the FFT's import and choice, once a process: not a solve's cost
    solves = estimate_solves(setup)
    setup = _to_expected_stop(setup)
    op = setup.coarse_compliance or setup.compliance
    if op.convolution is not None:
        op.convolution.hat  # its transform, made once a run: not a solve's cost
    gap = setup.coarse_gap if setup.coarse_gap is not None else setup.gap
    if setup.cycle.linear:  # a cycle is one normal solve
        t = time.perf_counter()
        solve(op, gap, setup.cycle.load, method=setup.method, tol=setup.tolerance)
        cold = time.perf_counter() - t
        return solves, _seconds(setup, solves, cold) + _fatigue_seconds(setup, op, gap, solves)

    normal = _Normal(setup, op, gap)
    zero = np.zeros(setup.grid.shape)
    t = time.perf_counter()
    cyc = setup.cycle.solve(zero, zero, normal, None)
    unit = time.perf_counter() - t
    if getattr(setup.cycle, "resolved", False):
        # a resolved cycle from a warm start solves its positions as one stack (cycle.resolved), the cold one
        # increment by increment: the run's steps are warm, so the warm cycle is timed (it is the run's per-pass
        # cost, not a cold solve to be scaled by WARM_SOLVE; timed cold, McColl 185 N 2D was estimated at 2×)
        setup.cycle.solve(zero, zero, normal, cyc.pressure, detail=False)  # (the stack's windows' symbols: once)
        t = time.perf_counter()
        setup.cycle.solve(zero, zero, normal, cyc.pressure, detail=False)  # (a step draws no loop)
        unit = (time.perf_counter() - t) * RESOLVED_WORN / WARM_SOLVE
    passes = setup.cycle.passes(setup.stepper.implicit)
    return solves, _seconds(setup, solves, unit) * passes + _fatigue_seconds(setup, op, gap, solves)


class _Normal:
    """The normal contact as a cycle member asks for it, on the unworn gap (cold-started unless guessed): one gap,
    or the layers of a stack (as the loop's, :mod:`fretsim.loop.rows`)."""

    def __init__(self, setup, op, gap):
        self.setup, self.op, self.gap = setup, op, gap

    def __call__(self, seen, guess, extra=None, load=None, cycle=0):
        res = solve(self.op if extra is None else add(self.op, extra), self.gap + seen, load, method=self.setup.method,
                    p0=guess, tol=self.setup.tolerance)
        return res.pressure, res

    def rows(self, seen, guess, extra=None, load=None, cycle=0, mirrors=()):
        from fretsim.compliance.operator import Convolution
        from fretsim.solvers.rows import solve_mirrored_rows
        op = self.op if extra is None else add(self.op, extra)
        if self.setup.coarse_compliance is not None or self.setup.method != "cg" or not isinstance(op, Convolution):
            return None
        found = solve_mirrored_rows(op, self.gap + seen, load, guess, self.setup.tolerance, mirrors,
                                    lambda k: self(seen[k], guess[k], extra, load)[1])
        return np.stack([r.pressure for r in found]), found


def _fatigue_seconds(setup, op, gap, solves: int) -> float:
    """Fretting fatigue's share: one fatigue state timed on the unworn contact (its cycle detailed for the
    tractions, the flat's stresses and the plane search), times the states the run will evaluate — the fatigue
    states up to its cycles, at most one a step, and the recorded states in full.  The worn contact is wider than
    the unworn: a low estimate, as the solves' own."""
    if not setup.fatigue_specs:
        return 0.0
    from fretsim.cycle.result import TRACTIONS
    from fretsim.fatigue.damage import evaluate

    zero = np.zeros(setup.grid.shape)
    t = time.perf_counter()
    cyc = setup.cycle.solve(zero, zero, _Normal(setup, op, gap), None, detail=TRACTIONS)
    if cyc.tractions is None:
        return 0.0
    cycle_s = time.perf_counter() - t
    one = cycle_s * WARM_SOLVE
    for spec in setup.fatigue_specs:  # each body's stresses and plane search
        args = (spec, setup.grid.x, setup.grid.dx, spec.curve.youngs_modulus, cyc)
        grid = {"y": setup.grid.y, "dy": setup.grid.dy}
        evaluate(*args, full=False, **grid)  # (the first pays scipy's imports and the depths' kernels, once a run)
        t = time.perf_counter()
        evaluate(*args, full=False, **grid)
        one += time.perf_counter() - t
    states = sum(1 for n in setup.fatigue_specs[0].states if n <= setup.cycles)
    return one * min(states, max(solves, 1)) + 3.0 * one * len(setup.snapshots)  # (a recorded state: every layer)
