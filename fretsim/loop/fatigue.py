"""Fretting fatigue in the loop: each body's Miner's sum over the fatigue states, and the crack limit.

Both bodies' fatigue comes from the same detailed cycle (its tractions) at the same states, so the states are
taken once for both (the specs share them, and their depths: :func:`fretsim.plan._fatigue`).  The loop keeps
``miners`` ({body: :class:`~fretsim.fatigue.damage.Miner`}, empty without fatigue); each body's fatigue state of
the step goes into ``Step.fatigue`` (the flat's, as always) or ``Step.fatigue_moving``.
"""
from __future__ import annotations

import math
from typing import Optional

from fretsim.fatigue.damage import PREFIX, Miner, evaluate

ATTRIBUTE = {"stationary": "fatigue", "moving": "fatigue_moving"}  # the Step's field of each body's state


def miners(setup) -> dict:
    return {spec.body: Miner() for spec in setup.fatigue_specs}


def state(setup, spec, cyc, full: bool = True):
    """One body's fatigue state from a detailed cycle (its own elastic constants: the curve's E, the spec's ν)."""
    g = setup.grid
    return evaluate(spec, g.x, g.dx, spec.curve.youngs_modulus, cyc, full=full, y=g.y, dy=g.dy)


def due(loop, cycle: int) -> bool:
    """Whether a step ending at ``cycle`` reaches the next fatigue state: the fatigue is evaluated at the first
    step at or past each (the states are not stops: the stepping takes its own steps, each detailed as due)."""
    if not loop.miners:
        return False
    miner = next(iter(loop.miners.values()))  # (the bodies' sums move together)
    if miner.damage is None or cycle in loop.s.loading.boundaries:  # (a block's end: the rate jumps there)
        return True
    return cycle >= next((n for n in loop.s.fatigue_specs[0].states if n > miner.cycle), math.inf)


def restart(loop, cyc) -> None:
    """A block's start: the new block's cycle at the same wear restarts each body's Miner's sums."""
    if loop.miners and cyc.tractions is not None:
        for spec in loop.s.fatigue_specs:
            loop.miners[spec.body].restart(loop.n, state(loop.s, spec, cyc, full=False))


def count(loop, step) -> Optional[tuple]:
    """Each body's fatigue at a detailed state (or at a wear limit's, detailed now) added to its Miner's sum;
    (crack cycle, body) of the first crack that just started where the case stops there (limits.crack_initiation),
    else None.  Where both bodies crack in the same interval, the earlier crossing names the body."""
    s, cyc = loop.s, step.cycle_result
    first = next(iter(loop.miners.values()))
    if first.damage is not None and loop.n <= first.cycle:
        return None  # (a resumed run's first state: counted already)
    if cyc.tractions is None:
        if not step.is_snapshot:
            return None
        cyc = loop.cycle_at(loop.n, loop.p, detail=True)
    cracks = []
    for spec in s.fatigue_specs:
        miner, fs = loop.miners[spec.body], state(s, spec, cyc, full=step.is_snapshot)
        had = miner.crack is not None
        miner.add(loop.n, fs, s.grid.x, s.grid.y)
        if spec.crack_limit and not had and miner.crack is not None:
            cracks.append((miner.crack[0], spec.body))
        setattr(step, ATTRIBUTE[spec.body], fs)
    if cracks and not step.is_snapshot:  # the run ends here: this state is recorded, with its fields in full
        for spec in s.fatigue_specs:
            fs = state(s, spec, cyc)
            setattr(step, ATTRIBUTE[spec.body], fs)
            loop.miners[spec.body].peak(fs)  # (its largest shear: the state's every layer)
    return min(cracks) if cracks else None


def to_state(loop) -> dict:
    """The checkpoint's entries of every body's Miner."""
    out = {}
    for body, miner in loop.miners.items():
        out.update(miner.to_state(PREFIX[body]))
    return out


def restore(loop, st: dict) -> None:
    loop.miners = {spec.body: Miner.from_state(st, PREFIX[spec.body]) for spec in loop.s.fatigue_specs}
