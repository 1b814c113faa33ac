"""The loading a run applies: one or more blocks of load, stroke and cycles.

A block is what a fretting rig holds constant for a while: the normal load P, the stroke (slip amplitude δ of
the applied displacement, so the rig travels 4δ per cycle), the number of cycles, and the friction coefficient
and the rig's tangential stiffness where the cycle model uses them.  Today a case has one block; the loop reads
the loading instead of loose numbers, so a load history is more blocks, not a new branch.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional


@dataclass(frozen=True)
class Block:
    """One stretch of constant loading.  Internal units: N, mm, N/mm."""

    normal_load: float  # N, total (in 2D too)
    stroke: float  # mm, the amplitude δ of the applied tangential displacement
    cycles: int
    friction_coefficient: Optional[float] = None
    tangential_stiffness: Optional[float] = None  # N/mm, the rig's; None: a rigid rig


@dataclass(frozen=True)
class Loading:
    """The blocks of a run, applied one after another."""

    blocks: tuple[Block, ...]

    def __post_init__(self):
        if not self.blocks:
            raise ValueError("a loading needs at least one block")

    @property
    def cycles(self) -> int:
        return sum(b.cycles for b in self.blocks)

    @property
    def block(self) -> Block:
        """The block of a single-block loading (every loading today)."""
        if len(self.blocks) != 1:
            raise ValueError(f"this loading has {len(self.blocks)} blocks; ask for one by cycle")
        return self.blocks[0]

    def block_at(self, cycle: int) -> Block:
        """The block that cycle ``cycle`` + 1 belongs to (the last block from its start on)."""
        start = 0
        for b in self.blocks:
            if cycle < start + b.cycles:
                return b
            start += b.cycles
        return self.blocks[-1]


def single(normal_load: float, stroke: float, cycles: int, friction_coefficient: Optional[float] = None,
           tangential_stiffness: Optional[float] = None) -> Loading:
    return Loading((Block(normal_load, stroke, cycles, friction_coefficient, tangential_stiffness),))
