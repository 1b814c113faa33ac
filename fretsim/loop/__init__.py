"""The units of the contact–wear loop besides its stepping (:mod:`fretsim.simulate` keeps the stepping core):

* :mod:`.checks` — what every step must satisfy (resolution, the grid's edges, the physical bounds and the
  invariant, a body worn through, a growing checkerboard), each failure a :class:`~fretsim.errors.SimulationError`
  that says what to change;
* :mod:`.blocks` — a load history's block switching, and the invariant summed over the blocks;
* :mod:`.landing` — landing a step on a wear limit's crossing;
* :mod:`.checkpoint` — the loop's state as a flat dict of arrays and numbers, written with every step and read back
  by ``--resume``.
"""
