"""The Python API the CLI wraps: load a case, run it (or resume it), read the results.

    >>> from fretsim.api import load_case, run, read_results
    >>> outcome = run(load_case("cases/mccoll_185N.yaml"), "out.h5")
    >>> outcome.summary["centre_wear_depth_stationary_um"]
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from fretsim.case import Case, CaseError, load_case, parse_case
from fretsim.plan import Plan, prepare
from fretsim.results import Results, ResultsWriter, read_results
from fretsim.simulate import PhysicalLimit, ResolutionError, SimulationError, Setup, Step, simulate, summarize

__all__ = ["Case", "CaseError", "Outcome", "Results", "SimulationError", "check", "load_case", "parse_case",
           "read_results", "run", "resume"]

RESUMABLE = ("interrupted", "running")  # "running": the process was killed before it could say otherwise


@dataclass
class Outcome:
    status: str  # complete | interrupted | failed | stopped (a physical limit was reached)
    message: str
    summary: dict
    setup: Setup
    case: Case  # with the automatic choices filled
    output: Optional[Path]
    last: Optional[Step] = None
    notes: tuple = field(default_factory=tuple)
    plan: Optional[Plan] = None


class _Counter:
    """Counts solves and keeps the last step and the largest error estimates at recorded states."""

    def __init__(self, solves: int = 0, errors: tuple = (0.0, 0.0)):
        self.solves = solves
        self.last = None
        self.errors = tuple(errors)

    def on_step(self, setup, step):
        self.solves += 1
        self.last = step
        if step.is_snapshot:
            self.errors = (max(self.errors[0], step.error_depth), max(self.errors[1], step.error_pressure))


def run(case: Case, output: Optional[str | Path] = None, *, overwrite: bool = False,
        progress: Optional[Callable[[int], None]] = None, observers: tuple = ()) -> Outcome:
    """Run a case; write the results file if ``output`` is given.

    Raises :class:`CaseError` for a case that cannot be set up (nothing is written then).  A run that fails,
    stops at a physical limit or is interrupted returns an outcome with that status after writing the file;
    KeyboardInterrupt is re-raised after the file is written with status ``interrupted``.
    """
    setup, filled, plan = prepare(case)
    if output is not None and Path(output).exists() and not overwrite:
        raise CaseError(str(output), [("", "the results file exists already; choose another -o, pass "
                                           "--overwrite, or --resume it")])
    return _execute(setup, filled, plan, output, overwrite, progress, observers, resume_from=None)


def check(case: Case) -> tuple[Setup, Case, Plan]:
    """Everything a run would decide, without running: the setup, the filled case and the plan of choices."""
    return prepare(case)


def resume(output: str | Path, *, progress: Optional[Callable[[int], None]] = None,
           observers: tuple = ()) -> Outcome:
    """Continue an interrupted (or killed) run from the last state in its results file.

    The case is the one stored in the file, so the run continues exactly as it would have: the same steps,
    the same arrays.
    """
    previous = read_results(output)
    if previous.status not in RESUMABLE:
        raise CaseError(str(output), [("", f"the run's status is {previous.status!r}; only an interrupted or "
                                           f"killed run ({' or '.join(RESUMABLE)}) can be resumed")])
    if not previous.checkpoint:
        raise CaseError(str(output), [("", "the file holds no checkpoint to resume from (it was written before "
                                           "the first step completed); run the case again")])
    case = parse_case(previous.case_yaml, source=f"{output}:/case")
    setup, filled, plan = prepare(case)
    return _execute(setup, filled, plan, output, True, progress, observers, resume_from=previous)


def _execute(setup, filled, plan, output, overwrite, progress, observers, resume_from: Optional[Results]) -> Outcome:
    counter = _Counter(len(resume_from.history["cycle"]) if resume_from is not None else 0,
                       _recorded_errors(resume_from) if resume_from is not None else (0.0, 0.0))
    writer = None
    t0 = time.perf_counter()

    class _LazyWriter:
        """Creates the file at the first accepted step, so a case that fails its first solve writes nothing."""

        def on_step(self, setup_, step):
            nonlocal writer
            if writer is None and output is not None:
                writer = ResultsWriter(output, filled.to_yaml(), filled.name, setup.grid, setup.notes, overwrite,
                                       previous=resume_from, choices=plan.choices)
            if writer is not None:
                writer.on_step(setup_, step)

    status, message = "complete", ""
    state = resume_from.checkpoint if resume_from is not None else None
    try:
        simulate(setup, (counter, _LazyWriter()) + tuple(observers), progress, resume=state)
    except ResolutionError as exc:  # found before anything is written: an input problem, named as such
        given = filled.elements is not None and any(c.key == "grid.elements" and c.given for c in plan.choices)
        key = "grid.elements" if given else "grid"
        advice = ("refine grid.elements or shrink grid.domain" if given else
                  "the automatic grid should resolve it: set grid.domain and grid.elements explicitly")
        raise CaseError(filled.source, [(key, f"{exc}; {advice}")]) from None
    except PhysicalLimit as exc:
        status, message = "stopped", str(exc)
    except SimulationError as exc:
        status, message = "failed", str(exc)
    except KeyboardInterrupt:
        cycle = counter.last.cycle if counter.last else (int(state["n"]) if state else 0)
        _finish(writer, setup, counter, t0, "interrupted", f"interrupted after cycle {cycle}; resume with "
                                                           f"`fretsim run --resume {output}`")
        raise
    _finish(writer, setup, counter, t0, status, message)
    summary = _summary(setup, counter, t0)
    return Outcome(status, message, summary, setup, filled, Path(output) if output else None, counter.last,
                   setup.notes, plan)


def _recorded_errors(previous: Results) -> tuple:
    """The largest error estimates at the recorded states of an earlier part of the run."""
    h = previous.history
    if "error_estimate_depth" not in h or not len(h.get("cycle", [])):
        return (0.0, 0.0)
    at = np.isin(h["cycle"], previous.fields.get("cycle", []))
    return (float(h["error_estimate_depth"][at].max(initial=0.0)), float(h["error_estimate_pressure"][at].max(initial=0.0)))


def _summary(setup, counter, t0) -> dict:
    return summarize(setup, counter.last, counter.solves, _elapsed(counter, t0), counter.errors) if counter.last else {}


def _elapsed(counter, t0) -> float:
    return float(counter.last.state.get("elapsed", time.perf_counter() - t0)) if counter.last else 0.0


def _finish(writer, setup, counter, t0, status, message):
    if writer is not None:
        writer.finish(status, message, _summary(setup, counter, t0))
