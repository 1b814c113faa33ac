"""A load history in the loop: each block's cycle model takes over at the block's start, and the invariant is
summed over the blocks.

The wear state carries over a block's start smoothly; only its rate jumps (a new load or stroke changes the wear's
course at once).  So the new block's cycle at the current wear gives the rates, and the stepping restarts as at
the run's start — the implicit schemes' history, the adaptive batch, the predictor and the growth watch — with
a first step of BLOCK_RESTART of the last one rather than one cycle; the error control shrinks it if the new
rates change fast.
"""
from __future__ import annotations

BLOCK_RESTART = 1 / 4  # a block's first step, as a share of the step before its start


def enter_block(loop) -> None:
    """At a block's start, the next block's cycle model takes over (nothing to do within a block)."""
    s = loop.s
    if not s.block_cycles:
        return
    i = s.loading.index_at(loop.n)
    if i == loop.block:
        return
    w_max = loop.model.bounds[0]
    loop.work_bound += w_max * (loop.n - loop.block_start)
    loop.block, loop.block_start, loop.model = i, loop.n, s.block_cycles[i]
    loop.memory = {}
    # a cold start: the last block's pressure scaled to the new load made cg diverge on a worn, conforming
    # tube contact (7247 elements, load 15 N → 5 N), where the cold start converges
    cyc = loop.cycle_at(loop.n, None)
    loop.cyc = cyc
    loop.fatigue_restart(cyc)  # (the fatigue damage's rate jumps with the block)
    loop.p, loop.r_m, loop.r_s, loop.memory = cyc.pressure, cyc.rate_moving, cyc.rate_stationary, cyc.memory
    loop.rate_work = cyc.work
    loop.rate_energy = loop.energy_rate(cyc)
    c = 0.5 if s.per_cycle else 0.0
    loop.history = [(loop.n, loop.h_m + c * cyc.rate_moving, loop.h_s + c * cyc.rate_stationary, cyc.pressure,
                     loop.work + c * cyc.work, loop.energy + c * loop.rate_energy)]
    loop.batch = [(loop.h_m, loop.h_s, loop.work, loop.energy)]
    loop.p_prev, loop.d_prev, loop.jump, loop.lag = None, 1, max(1.0, loop.jump * BLOCK_RESTART), 0.0
    loop.watch.reset()


def work_bound(loop) -> float:
    """The largest wear work the blocks so far allow (N·mm): each block's bound times its cycles."""
    return loop.work_bound + loop.model.bounds[0] * (loop.n - loop.block_start)


def expected_volumes(setup, cycle: int, work: float) -> tuple[float, float]:
    """The invariant's volumes after ``cycle`` cycles: a closed-form member's summed over the blocks so far
    (Σ kᵢ·Pᵢ·4δᵢ·Nᵢ), any other's from the accumulated work."""
    if not setup.block_cycles or not setup.cycle.closed_form:
        return setup.cycle.expected_volumes(cycle, work)
    moving = stationary = 0.0
    start = 0
    for block, model in zip(setup.loading.blocks, setup.block_cycles):
        n = min(max(cycle - start, 0), block.cycles)
        start += block.cycles
        if n:
            v_m, v_s = model.expected_volumes(n, 0.0)
            moving, stationary = moving + v_m, stationary + v_s
        if start >= cycle:
            break
    return moving, stationary
