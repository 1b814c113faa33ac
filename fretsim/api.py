"""The Python API the CLI wraps: load a case, run it, read the results.

    >>> from fretsim.api import load_case, run, read_results
    >>> outcome = run(load_case("cases/mccoll_185N.yaml"), "out.h5")
    >>> outcome.summary["centre_wear_depth_stationary_um"]
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from fretsim.case import Case, CaseError, load_case, parse_case
from fretsim.results import Results, ResultsWriter, read_results
from fretsim.simulate import SimulationError, Setup, Step, prepare, simulate, summarize

__all__ = ["Case", "CaseError", "Outcome", "Results", "SimulationError", "load_case", "parse_case", "read_results",
           "run"]


@dataclass
class Outcome:
    status: str  # complete | interrupted | failed
    message: str
    summary: dict
    setup: Setup
    case: Case  # with the automatic choices filled
    output: Optional[Path]
    last: Optional[Step] = None
    notes: tuple = field(default_factory=tuple)


class _Counter:
    def __init__(self):
        self.solves = 0
        self.last = None

    def on_step(self, setup, step):
        self.solves += 1
        self.last = step


def run(case: Case, output: Optional[str | Path] = None, *, overwrite: bool = False,
        progress: Optional[Callable[[int], None]] = None, observers: tuple = ()) -> Outcome:
    """Run a case; write the results file if ``output`` is given.

    Raises :class:`CaseError` for a case that cannot be set up (nothing is
    written then).  A run that fails or is interrupted returns an outcome with
    that status after marking the file; KeyboardInterrupt is re-raised after
    the file is closed.
    """
    setup, filled = prepare(case)
    if output is not None and Path(output).exists() and not overwrite:
        raise CaseError(str(output), [("", "the results file exists already; choose another -o or pass "
                                           "--overwrite")])
    counter = _Counter()
    writer = None
    t0 = time.perf_counter()

    class _LazyWriter:
        """Opens the file at the first accepted step, so a case that fails its first solve writes nothing."""

        def on_step(self, setup_, step):
            nonlocal writer
            if writer is None and output is not None:
                writer = ResultsWriter(output, filled.to_yaml(), filled.name, setup.grid, setup.notes, overwrite)
            if writer is not None:
                writer.on_step(setup_, step)

    status, message = "complete", ""
    try:
        simulate(setup, (counter, _LazyWriter()) + tuple(observers), progress)
    except SimulationError as exc:
        status, message = "failed", str(exc)
    except KeyboardInterrupt:
        status, message = "interrupted", f"interrupted at cycle {counter.last.cycle if counter.last else 0}"
        _close(writer, setup, counter, t0, status, message)
        raise
    summary = summarize(setup, counter.last, counter.solves, time.perf_counter() - t0) if counter.last else {}
    if writer is not None:
        writer.finish(status, message, summary)
    return Outcome(status, message, summary, setup, filled, Path(output) if output else None, counter.last,
                   setup.notes)


def _close(writer, setup, counter, t0, status, message):
    if writer is not None:
        summary = summarize(setup, counter.last, counter.solves, time.perf_counter() - t0) if counter.last else {}
        writer.finish(status, message, summary)
