"""The error types the command line maps to exit codes (no heavy imports: the CLI loads this at start-up).

* :class:`InputError` — input that cannot be used (a case, a sweep file, an option, an output name): exit 2.
  :class:`fretsim.case.CaseError` is one.
* :class:`ResultsFileError` — a results file or sweep table that is missing, damaged or not ours: exit 2.
  A ValueError, so callers that catch ValueError keep working.
* :class:`SimulationError` — a run that had to stop (raised by the loop, :mod:`fretsim.simulate`): a numerical
  failure or a contact that outgrew its grid (exit 3), a grid that cannot resolve the contact (2), a body worn
  through (4).
"""
from __future__ import annotations


class InputError(Exception):
    """Input that cannot be used; the message names the file, the key and what was expected."""


class ResultsFileError(ValueError):
    """A results file (or a sweep's table) that cannot be read or verified; the message names what is wrong."""


class SimulationError(Exception):
    """A run that had to stop: ``cycle`` is the last cycle reached (exit 3 unless a subclass says otherwise)."""

    exit_code = 3

    def __init__(self, message: str, cycle: int):
        super().__init__(message)
        self.cycle = cycle


class NumericalFailure(SimulationError):
    """No convergence, NaN, instability or a broken invariant."""


class GridFeedback(NumericalFailure):
    """An odd-even pressure pattern the cycle model itself grew under steps with no stability limit: where a contact
    partly sticks, more pressure means less slip and less wear, and on too coarse a grid that feedback grows at the
    stick zone's edge.  A finer grid carries it (:func:`fretsim.runner.run` refines an automatic grid)."""


class DomainError(SimulationError):
    """The contact outgrew the grid (``axis``: the edge it reached, 'x' or 'y')."""

    def __init__(self, message: str, cycle: int, axis: str = "x"):
        super().__init__(message, cycle)
        self.axis = axis


class ResolutionError(SimulationError):
    """The grid cannot resolve the contact (too few elements across it): an input problem, found at the start."""

    exit_code = 2


class PhysicalLimit(SimulationError):
    """The wear went through the body: the geometry means nothing beyond this cycle."""

    exit_code = 4
