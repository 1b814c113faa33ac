"""The loading a run applies: one or more blocks of load, stroke and cycles.

A block is what a fretting rig holds constant for a while: the normal load P, the stroke (slip amplitude δ of
the applied displacement, so the rig travels 4δ per cycle), the number of cycles, and the friction coefficient
and the rig's tangential stiffness where the cycle model uses them.  A constant loading is one block; a load
history (``loading.blocks``, or a spectrum of fractions of the cycles) is several, applied in order, each with
its own cycle model; the loop restarts its stepping at each block's start as it does at the run's.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import Optional


@dataclass(frozen=True)
class Block:
    """One stretch of constant loading.  Internal units: N, mm, N/mm."""

    normal_load: float  # N, total (in 2D too)
    stroke: float  # mm, the amplitude δ of the applied tangential displacement
    cycles: int
    friction_coefficient: Optional[float] = None
    tangential_stiffness: Optional[float] = None  # N/mm, the rig's; None: a rigid rig
    fraction: Optional[float] = None  # a spectrum's block: its share of the cycles (cycles then set by expand)


def expand(blocks: tuple, repeat: int = 1, cycles: Optional[int] = None, spectrum: bool = False) -> tuple:
    """The blocks in the order applied.

    Blocks: ``repeat`` passes; or, given ``cycles``, as many passes as reach that many cycles, the last cut
    short.  Spectrum: each block's share of ``cycles`` split evenly over ``repeat`` passes (the remainders to the
    first passes, so the totals are exact).
    """
    if spectrum:
        shares = [int(round(b.fraction * cycles)) for b in blocks]
        shares[-1] = cycles - sum(shares[:-1])  # exact total whatever the rounding
        out = []
        for i in range(repeat):
            for b, n in zip(blocks, shares):
                part = n // repeat + (1 if i < n % repeat else 0)
                if part:
                    out.append(replace(b, cycles=part))
        return tuple(out)
    if cycles is None:
        return tuple(b for _ in range(repeat) for b in blocks if b.cycles)
    per_pass = sum(b.cycles for b in blocks)
    out, left = [], cycles
    while left > 0 and per_pass > 0:
        for b in blocks:
            n = min(b.cycles, left)
            if n:
                out.append(replace(b, cycles=n))
            left -= n
            if left <= 0:
                break
        if len(out) > 10_001:  # the caller refuses more than MAX_BLOCKS; stop counting
            break
    return tuple(out)


@dataclass(frozen=True)
class Loading:
    """What the rig applies, one object for a constant loading and a load history alike (``Case.loading``).

    ``given`` is the loading as the case writes it: one block (``normal_load``, ``stroke``, ``cycles``), or one pass
    of ``loading.blocks`` (applied ``repeat`` times, or repeated up to ``cycles``), or a spectrum's blocks
    (fractions of ``cycles`` split over ``repeat`` passes).  ``blocks`` are the blocks in the order applied, which
    the loop steps through; a block's μ defaults to the loading's.  Internal units: N, mm, N/mm, Hz.
    """

    given: tuple[Block, ...]
    cycles: int  # the total applied
    repeat: int = 1
    spectrum: bool = False  # ``given`` came from loading.spectrum (fractions of the cycles, split in passes)
    history: bool = False  # given as loading.blocks or loading.spectrum (not one load)
    friction_coefficient: Optional[float] = None  # the loading's μ; a block may give its own
    tangential_stiffness: Optional[float] = None  # N/mm, the rig's; None: a rigid rig
    frequency: Optional[float] = None  # Hz: with it, the time to a wear limit

    def __post_init__(self):
        if not self.given:
            raise ValueError("a loading needs at least one block")

    @classmethod
    def constant(cls, normal_load: float, stroke: float, cycles: int, friction_coefficient: Optional[float] = None,
                 tangential_stiffness: Optional[float] = None, frequency: Optional[float] = None) -> "Loading":
        """One load and stroke held for ``cycles``."""
        return cls((Block(normal_load, stroke, cycles, friction_coefficient, tangential_stiffness),), cycles,
                   friction_coefficient=friction_coefficient, tangential_stiffness=tangential_stiffness,
                   frequency=frequency)

    @cached_property
    def blocks(self) -> tuple[Block, ...]:
        """The blocks in the order applied (repeats and spectrum passes expanded); one for a constant loading."""
        if not self.history:
            return (replace(self.given[0], cycles=self.cycles),)
        return expand(self.given, self.repeat, self.cycles, self.spectrum)

    def with_cycles(self, cycles: int) -> "Loading":
        """The same loading over ``cycles`` (a history is repeated, or cut short, to that many)."""
        return replace(self, cycles=cycles)

    @property
    def peak_load(self) -> float:
        """The largest normal load of any block (N): what sizes the contact's reach and its plausibility."""
        return max(b.normal_load for b in self.given)

    @property
    def peak_stroke(self) -> float:
        """The largest stroke of any block (mm)."""
        return max(b.stroke for b in self.given)

    @property
    def lightest_load(self) -> float:
        """The smallest normal load applied (N): the narrowest contact the grid must resolve."""
        return min(b.normal_load for b in self.blocks)

    def block_at(self, cycle: int) -> Block:
        """The block that cycle ``cycle`` + 1 belongs to (the last block from its start on)."""
        return self.blocks[self.index_at(cycle)]

    def index_at(self, cycle: int) -> int:
        """The index of the block that cycle ``cycle`` + 1 belongs to (the last block from its start on)."""
        start = 0
        for i, b in enumerate(self.blocks):
            if cycle < start + b.cycles:
                return i
            start += b.cycles
        return len(self.blocks) - 1

    @property
    def boundaries(self) -> tuple[int, ...]:
        """The cycles at which a block ends and the next begins."""
        ends, n = [], 0
        for b in self.blocks[:-1]:
            n += b.cycles
            ends.append(n)
        return tuple(ends)

    def worn_work(self, cycles: int) -> float:
        """Σ Pᵢ·4δᵢ·Nᵢ over the first ``cycles`` cycles of the blocks (N·mm): times k, the worn volume."""
        work, left = 0.0, cycles
        for b in self.blocks:
            n = min(b.cycles, left)
            work += b.normal_load * 4 * b.stroke * n
            left -= n
            if left <= 0:
                break
        return work
