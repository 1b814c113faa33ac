"""Running one case: plan it, claim its output, run the loop with the results writer, resume an interrupted run.

The public face of this module is :mod:`fretsim.api`; sweeps (:mod:`fretsim.sweep`) run their points through it.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import signal
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Callable, Optional

import numpy as np

from fretsim import grid_error, heap, regrid
from fretsim.case import GEOMETRY_KEYS, Case, CaseError, parse_case
from fretsim.errors import GridFeedback
from fretsim.plan import Plan, SideRuns, estimate_cost, notes_of, prepare, restore
from fretsim.plan.cycle import strip_compliances
from fretsim.reference import effective_modulus
from fretsim.results import (OutputBusy, OutputClaim, Results, ResultsIOError, ResultsWriter, check_output_path,
                             read_results)
from fretsim.results.layout import in_summary_order
from fretsim.simulate import (DomainError, PhysicalLimit, ResolutionError, SimulationError, Setup, Step, simulate,
                              summarize)

RESUMABLE = ("interrupted", "running")  # "running": the process was killed before it could say otherwise


@dataclass
class Outcome:
    status: str  # complete | interrupted | failed | stopped (a physical limit) | io_error (the disk refused)
    message: str
    summary: dict
    setup: Setup
    case: Case  # with the automatic choices filled
    output: Optional[Path]
    last: Optional[Step] = None
    notes: tuple = field(default_factory=tuple)
    plan: Optional[Plan] = None
    written: bool = False  # whether the results file holds this run's steps
    failure: Optional[Exception] = None  # what stopped a failed run (the loop's SimulationError)


# a step's odd-even pressure pattern, relative to its mean, worth a note: the growth watcher stops only a
# pattern that keeps growing, and one that grew and then stayed (explicit steps too long near the partial/gross-slip
# transition: 15-29 % at 1.25-2 times a stable cap) completed without a word; the shipped cases stay below 0.8 %
CHECKERBOARD_NOTE = 0.05
_BOARD_NOTE = "the pressure carries an odd-even pattern of"


class _Counter:
    """Counts solves and keeps the last step and the largest error estimates at recorded states."""

    def __init__(self, solves: int = 0, errors: tuple = (0.0, 0.0)):
        self.extra = None  # the total error estimates, once the run is complete
        self.notes = []  # what the estimates found, for the results file and the outcome
        self.solves = solves
        self.last = None
        self.errors = tuple(errors)
        self.board = 0.0  # the largest odd-even pressure amplitude of a step past CHECKERBOARD_NOTE
        self.failure: Optional[Exception] = None  # what stopped the loop, where it failed

    def on_step(self, setup, step):
        self.solves += 1
        self.last = step
        if step.is_snapshot:
            self.errors = (max(self.errors[0], step.error_depth), max(self.errors[1], step.error_pressure))
        board = abs(step.checkerboard)
        if board > CHECKERBOARD_NOTE and board > self.board:
            self.board = board
            self.notes[:] = [n for n in self.notes if not n.startswith(_BOARD_NOTE)]
            self.notes.append(f"{_BOARD_NOTE} {board:.1%} of its mean at cycle {step.cycle:,} (the largest of the "
                              f"run's steps, /history/checkerboard_amplitude): steps near their stability limit (a "
                              f"smaller jumping.linear or jumping.max), or a model unstable on this grid; read the "
                              f"pressure and the wear it drove there with caution")


def check(case: Case, runs: Optional[SideRuns] = None) -> tuple[Setup, Case, Plan]:
    """Everything a run would decide, without running: the setup, the filled case and the plan of choices."""
    return prepare(case, runs=runs)


def inputs_of(case: Case) -> dict:
    """The resolved inputs of a filled case: name → (value, units, long name), as recorded in /inputs."""
    g, loading = case.geometry, case.loading
    values: dict = {"geometry": (g.kind, "", "contact geometry")}
    for key, spec in GEOMETRY_KEYS[g.kind].items():
        value = getattr(g, key, None)
        if value is None or isinstance(value, tuple):  # absent options; a profile table is in /case
            continue
        values[f"geometry_{key}"] = (value, "mm" if spec.kind == "length" else "", f"geometry {key.replace('_', ' ')}")
    for body in ("moving", "stationary"):
        m = getattr(case, body)
        values[f"{body}_youngs_modulus"] = (m.youngs_modulus / 1e3, "GPa", f"Young's modulus, {body} body")
        values[f"{body}_poissons_ratio"] = (m.poissons_ratio, "1", f"Poisson's ratio, {body} body")
        if m.wear_coefficient is not None:
            values[f"{body}_wear_coefficient"] = (m.wear_coefficient, "1/MPa", f"wear coefficient, {body} body")
        if m.energy_wear_coefficient is not None:
            values[f"{body}_energy_wear_coefficient"] = (m.energy_wear_coefficient * 1e3, "mm^3/J",
                                                          f"energy wear coefficient, {body} body")
    values.update({
        "normal_load": (loading.peak_load, "N", "normal load"),
        "stroke": (loading.peak_stroke * 1e3, "um", "slip amplitude"),
        "cycles": (loading.cycles, "cycles", "fretting cycles"),
        "dimension": (case.dimension, "", "model dimension"),
        "gap_model": (case.gap_model, "", "how the flat's wear enters the gap"),
        "solver": (case.solver, "", "contact solver"),
        "solver_tolerance": (case.tolerance, "1", "contact solver tolerance"),
        "scheme": (case.scheme, "", "cycle-jumping scheme"),
        "step_tolerance": (case.step_tolerance, "1", "target relative error (implicit schemes)"),
        "linear_jump": (case.linear_jump or 0, "cycles", "linear cycle jump"),
        "slip_model": (case.slip, "", "the fretting cycle: uniform (gross slip assumed) or coulomb"),
        "stroke_model": (case.stroke_model, "", "the normal contact at mid-stroke or resolved along the stroke"),
        "wear_law": (case.wear_law, "", "archard (k·p·|ds|) or energy (α·|q|·|ds|)"),
        "increments": (case.increments, "1", "increments per half-stroke (coulomb)"),
    })
    if loading.friction_coefficient is not None:
        values["friction_coefficient"] = (loading.friction_coefficient, "1", "friction coefficient")
    if loading.tangential_stiffness is not None:
        values["tangential_stiffness"] = (loading.tangential_stiffness * 1e-3, "N/um", "the rig's tangential stiffness")
    for body, u in zip(("moving", "stationary"),
                       strip_compliances(case) if loading.friction_coefficient is not None else ()):
        if u is not None:
            values[f"tangential_compliance_{body}"] = (u * 1e3, "um/(N/mm)", f"the {body} body's tangential "
                                                       f"compliance from its shape: the contact strip's mean "
                                                       f"displacement per unit force per unit length")
    e_star = effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                               case.stationary.youngs_modulus, case.stationary.poissons_ratio)
    h = g.hertz(loading.peak_load, e_star)
    values.update({"contact_modulus": (e_star / 1e3, "GPa", "contact modulus E*"),
                   "hertz_half_width_x": (h.half_width_x, "mm", "Hertz contact half-width along x"),
                   "hertz_half_width_y": (h.half_width_y, "mm", "Hertz contact half-width along y"),
                   "hertz_peak_pressure": (h.peak_pressure, "MPa", "Hertz peak pressure"),
                   "hertz_line_contact": (int(h.line), "1", "1 for a line contact (2D Hertz), 0 for a point contact")})
    return {"values": values, "overrides": list(case.overrides), "case_file": case.source}


def run(case: Case, output: Optional[str | Path] = None, *, overwrite: bool = False,
        progress: Optional[Callable[[int], None]] = None, observers: tuple = (),
        on_plan: Optional[Callable[[Setup, Case, Plan], None]] = None, runs: Optional[SideRuns] = None) -> Outcome:
    """Run a case; write the results file if ``output`` is given.

    Raises :class:`CaseError` for a case or an output that cannot be used (nothing is written then).  A run
    that fails, stops at a physical limit or cannot write returns an outcome with that status; KeyboardInterrupt
    is re-raised after the file is written with status ``interrupted``.  ``on_plan`` is called with the plan
    before the first solve (the CLI prints the choices then).  ``runs`` (:class:`fretsim.plan.SideRuns`)
    announces the runs made besides this one (auto's proxies, a pilot, the grid-error companions) and keeps
    the proxies for the next plan in its keeping.
    """
    heap.keep_warm()
    runs = runs if runs is not None else SideRuns()
    setup, filled, plan = prepare(case, runs=runs)
    claim = None
    if output is not None:
        try:
            path = check_output_path(output, protect=(case.source,))
        except ValueError as exc:
            raise CaseError(str(output), [("", str(exc).removeprefix(f"{output} ").strip())], "output") from None
        if path.exists() and not overwrite:
            raise CaseError(str(output), [("", "the results file exists already; choose another -o, pass "
                                               "--overwrite, or --resume it")], "output")
        claim = _claim(path)
        if path.exists() and not overwrite:  # appeared while we were claiming it
            claim.release()
            raise CaseError(str(output), [("", "the results file appeared while this run started; choose "
                                               "another -o or pass --overwrite")], "output")
    try:
        if on_plan is not None:
            on_plan(setup, filled, plan)
        sink = _Sink(output, setup, filled, plan, overwrite, None, case.fingerprint())
        outcome = _execute(setup, filled, plan, sink, progress, observers, None, runs)
        return _refining(outcome, (setup, filled, plan), output, overwrite, case.fingerprint(), progress, observers,
                         runs, 0)
    finally:
        if claim is not None:
            claim.release()


def _refining(outcome: Outcome, planned: tuple, output, overwrite: bool, fingerprint: str, progress, observers,
              runs: SideRuns, done: int) -> Outcome:
    """The run again from its start on a finer automatic grid while it fails with a GridFeedback (:func:`_refined`),
    ``done`` refinements made before (a resumed run's); the last attempt's outcome.  The failed attempt's results
    file is removed before anything else (planning the finer grid included): a kill before the next attempt's first
    write then leaves no file (the CLI says nothing was written, and the case runs again), never a 'failed' one that
    the next attempt was about to replace.  A Ctrl-C or SIGTERM that came while the failed attempt was written (its
    signals deferred, :func:`_ignore_signals`) stops the run there.  The refinements' notes go into each attempt's
    plan notes, so its file says them from its first write (and a resume keeps them)."""
    setup, filled, plan = planned
    notes = [n for n in setup.notes if n.startswith(REFINED)]  # (a resumed run's earlier ones)
    made = done
    while _refinable(outcome, setup, plan, made):
        _stop_if_deferred()
        if output is not None and outcome.written:
            Path(output).unlink(missing_ok=True)
            outcome.written = False
        again = _refined(outcome, setup, filled, plan, runs)
        if again is None:
            break
        made += 1
        setup, filled, plan, note = again
        notes.append(f"{note}; the discarded attempt's {outcome.summary.get('contact_solves', 0)} solves are not in "
                     f"contact_solves")
        setup = dataclasses.replace(setup, notes=tuple(setup.notes) + tuple(notes))
        sink = _Sink(output, setup, filled, plan, True, None, fingerprint)  # (the file is gone or this run's own)
        runs.say(note)  # (the owner's bar for the first attempt stops here; the next attempt gets one of its own)
        with runs._progress(setup) as bar:
            outcome = _execute(setup, filled, plan, sink, bar or progress, observers, None, runs)
    if made > done and outcome.status == "failed":
        outcome.message += f" (on the automatic grid refined {made}× already: its notes)"
    return outcome


REFINED = "the automatic grid was refined from"


def _refinements_made(plan: Plan) -> int:
    """How many times a resumed run's automatic grid was refined already (its grid.elements choice says)."""
    return sum(c.reason.count(REFINED) for c in plan.choices if c.key == "grid.elements")


MAX_REFINEMENTS = (2, 1)  # an automatic grid refined 2× per time for a GridFeedback: in 2D, in 3D (4× the elements)


def _refinable(outcome: Outcome, setup: Setup, plan: Plan, done: int) -> bool:
    """Whether a run on an automatic grid failed with an odd-even pattern its cycle model grew on that grid (a
    :class:`~fretsim.errors.GridFeedback`: a partial slip's stick edge on too coarse a grid), ``done`` refinements
    short of MAX_REFINEMENTS."""
    return (isinstance(outcome.failure, GridFeedback) and regrid.grid_is_automatic(plan)
            and done < MAX_REFINEMENTS[not setup.grid.plane_strain])


def _refined(outcome: Outcome, setup: Setup, filled: Case, plan: Plan, runs: SideRuns):
    """The case of a :func:`_refinable` failure on a grid twice as fine along x (and y for a point contact), to run
    again from the start: (setup, filled case, plan with the refined choice, the note that says so); None where the
    planner refuses it."""
    exc, plane = outcome.failure, setup.grid.plane_strain
    line_contact = setup.y_edges_free and not plane
    e = filled.elements  # (a Coulomb cycle refuses refinement's coarse grid: grid.coarse_element is None here)
    elements = (grid_error.odd(2 * e[0]),) + (() if len(e) == 1 else (e[1],) if line_contact else
                                               (grid_error.odd(2 * e[1]),))
    try:
        new_setup, new_filled, new_plan = prepare(filled.with_choices(elements=elements), runs=runs)
    except CaseError:  # e.g. more memory than the machine has: the failure stands
        return None
    old, new = " × ".join(map(str, e)), " × ".join(map(str, elements))
    note = (f"the automatic grid was refined from {old} to {new} elements and the run started again: on {old} the "
            f"pressure checkerboarded at cycle {exc.cycle:,} (the Coulomb cycle's feedback at its stick zone's edge, "
            f"which a finer grid carries)")
    # the choices as a resume plans them (fretsim.plan.restore): the first plan's provenance, the values of the
    # refined grid where they were automatic (the stability limit's reference jump moves with the element)
    first = {c.key: c for c in plan.choices}
    choices = []
    for c in new_plan.choices:
        o = first.get(c.key)
        if o is not None:
            c = dataclasses.replace(c, value=o.value if o.given else c.value, reason=o.reason, given=o.given,
                                    error=o.error)
        choices.append(dataclasses.replace(c, reason=f"{c.reason}; {note}") if c.key == "grid.elements" else c)
    # the refined plan's warnings, of the refined grid (an unresolved stick zone's says which grid it means)
    warnings = [w.replace("(grid.elements is given)", "(the automatic grid, refined)") for w in new_plan.warnings]
    plan = dataclasses.replace(new_plan, choices=choices, warnings=warnings)
    return dataclasses.replace(new_setup, notes=notes_of(plan)), new_filled, plan, note


def _claim(path: Path) -> OutputClaim:
    try:
        return OutputClaim(path).acquire()
    except OutputBusy as exc:
        raise CaseError(str(path), [("", str(exc).removeprefix(f"{path}: "))], "output") from None
    except OSError as exc:
        raise CaseError(str(path), [("", f"cannot write in {path.parent or '.'}: {exc.strerror}")], "output") from None


def resume(output: str | Path, *, progress: Optional[Callable[[int], None]] = None,
           observers: tuple = (), runs: Optional[SideRuns] = None) -> Outcome:
    """Continue an interrupted (or killed) run from the last state in its results file.

    The case is the one stored in the file, so the run continues exactly as it would have: the same steps,
    the same arrays.  The file is verified first (structure, shapes, checksums): a damaged one is refused.
    """
    heap.keep_warm()
    runs = runs if runs is not None else SideRuns()
    path = Path(output)
    claim = _claim(path) if path.exists() else None
    try:
        try:
            previous = read_results(output, for_resume=True)
        except ValueError as exc:
            raise CaseError(str(output), [("", str(exc).removeprefix(f"{output}: "))], "results file") from None
        if previous.status not in RESUMABLE:
            raise CaseError(str(output), [("", f"the run's status is {previous.status!r}; only an interrupted or "
                                               f"killed run ({' or '.join(RESUMABLE)}) can be resumed")])
        case = parse_case(previous.case_yaml, source=f"{output}:/case")
        setup, filled, plan = prepare(case, runs=runs)
        # the first part's reasons and notes, not "given in the case" for every automatic choice
        setup, plan = restore(setup, plan, previous.provenance, str(previous.attrs.get("notes", "")))
        n = previous.checkpoint.get("n")
        if not isinstance(n, int) or not 0 <= n <= setup.cycles:
            raise CaseError(str(output), [("", f"/checkpoint: the cycle {str(n)[:20]} does not fit the case's "
                                               f"{setup.cycles} cycles")], "results file")
        sink = _Sink(output, setup, filled, plan, True, previous)
        if previous.regrids:  # the grid the run started on (its companions start there): before its first change
            first = previous.regrids[0]
            plane = setup.grid.plane_strain
            sink.first_filled = filled.with_choices(domain=first.old_domain[:1] if plane else first.old_domain,
                                                    elements=first.old_elements[:1] if plane else first.old_elements)
            sink.allowed = regrid.allowed(first.old_domain[0], setup.planned_extent)
        if previous.coarsenings:  # on the grid the run had coarsened to, from its checkpoint's coarse elements
            factor = sink.factor
            g = setup.grid
            run_setup, run_filled, _ = prepare(regrid.along_x(filled, g, g.shape[1] // factor),
                                               runs=runs)
            sink.follow(dataclasses.replace(run_setup, per_cycle=setup.per_cycle), run_filled)  # (regrid.step_down)
            previous = dataclasses.replace(previous, checkpoint={
                k: regrid.restrict(v, setup.grid.shape, factor) for k, v in previous.checkpoint.items()})
            setup = sink.setup
        outcome = _execute(setup, filled, plan, sink, progress, observers, previous, runs)
        # (an attempt interrupted before its grid was refined refines on resuming, as the whole run would have)
        return _refining(outcome, (setup, filled, plan), output, True,
                         str(previous.attrs.get("input_sha256", "")), progress, observers, runs,
                         _refinements_made(plan))
    finally:
        if claim is not None:
            claim.release()


class _Sink:
    """The results file of a run, created at its first accepted step (a case that fails its first solve writes
    nothing), and finished whatever ends the run."""

    def __init__(self, output, setup, filled, plan, overwrite: bool, previous: Optional[Results],
                 input_sha256: str = ""):
        self.output, self.setup, self.filled, self.plan = output, setup, filled, plan
        self.overwrite, self.previous, self.input_sha256 = overwrite, previous, input_sha256
        self.writer: Optional[ResultsWriter] = None
        self.regrids: list = list(previous.regrids) if previous is not None else []  # the grid's widenings so far
        self.coarsenings: list = list(previous.coarsenings) if previous is not None else []  # ... its coarsenings
        # the output grid (the finest the run used: the results' /grid), and the run's own case on its grid
        self.out_grid, self.run_filled = setup.grid, filled
        self.first_filled = filled  # the case on the grid the run started on (its companions start there too)
        self.allowed = regrid.allowed(setup.grid.shape[1] * setup.grid.dx, setup.planned_extent)  # widenings
        self.rule = regrid.rule_for(filled, setup, plan)  # when the grid may coarsen (None: never)

    @property
    def factor(self) -> int:
        """The run's element along x in output elements."""
        return self.coarsenings[-1].factor if self.coarsenings else 1

    def follow(self, setup, run_filled) -> None:
        """The run goes on on ``setup``'s grid (coarser than the output grid; its own filled case ``run_filled``)."""
        self.setup, self.run_filled = dataclasses.replace(setup, notes=tuple(self.setup.notes)), run_filled

    def coarsen(self, made, pad_r, setup, run_filled, plan, state: dict, note: str, runs) -> None:
        """The run moves onto a coarser grid (``made``), from ``state``; the output grid is first widened by the
        padding ``pad_r`` (of the run's grid) where the merge needed it.  A Ctrl-C before the next step resumes on
        the coarser grid."""
        self.open(self.overwrite)
        if pad_r is not None:
            r_out = regrid.scaled(pad_r, self.factor)
            out_setup, out_filled, _ = prepare(regrid.along_x(self.filled, self.out_grid, r_out.new_elements[0],
                                                              r_out.new_domain[0]), runs=runs)
            self.regrids.append(r_out)
            self.out_grid, self.filled = out_setup.grid, out_filled
            self.plan = regrid.replanned(plan, r_out, self.out_grid.plane_strain)
            if self.writer is not None:
                self.writer.regrid(r_out, self.out_grid, out_filled.to_yaml(), self.plan.choices, self.writer.notes)
        self.coarsenings.append(made)
        self.follow(setup, run_filled)
        if self.writer is not None:
            self.writer.coarsen(made)
            self.writer.notes = tuple(dict.fromkeys(self.writer.notes + (note,)))
            self.writer.state = state

    def regrid(self, r, setup, filled, plan, state: dict, note: str) -> None:
        """The run moves onto a widened grid, from ``state`` (the last step's, widened): so does what the results
        file holds of it, its checkpoint included (a Ctrl-C before the next step resumes on the wider grid), and
        its notes gain ``note`` at once (a killed run's last flush says so too)."""
        self.open(self.overwrite)  # a resumed run may widen before its first step: the file's snapshots go too
        self.regrids.append(r)
        self.setup, self.filled, self.plan = setup, filled, plan
        self.out_grid, self.run_filled = setup.grid, filled
        if self.writer is not None:
            self.writer.regrid(r, setup.grid, filled.to_yaml(), plan.choices,
                               tuple(dict.fromkeys(self.writer.notes + (note,))))
            self.writer.state = state

    def open(self, overwrite: bool) -> None:
        if self.writer is None and self.output is not None:
            self.writer = ResultsWriter(self.output, self.filled.to_yaml(), self.filled.name, self.out_grid,
                                        self.setup.notes, overwrite, previous=self.previous,
                                        choices=self.plan.choices, inputs=inputs_of(self.filled),
                                        input_sha256=self.input_sha256, regrids=self.regrids,
                                        coarsenings=self.coarsenings)

    def on_step(self, setup_, step) -> None:
        self.open(self.overwrite)
        if self.writer is not None:
            self.writer.on_step(setup_, step)

    def cycle_on_disk(self) -> Optional[int]:
        writer = self.writer
        if writer is None or not writer.path.exists() or not writer._placed:
            return None
        try:
            return int(read_results(writer.path).history["cycle"][-1])
        except (ValueError, IndexError):
            return None

    def finish(self, counter, t0, status: str, message: str) -> None:
        if self.writer is not None:
            self.writer.notes = tuple(dict.fromkeys(self.writer.notes + tuple(counter.notes)))
            self.writer.finish(status, message, _summary(self.setup, counter, t0))

    def finish_interrupted(self, counter, t0, message: Callable[[], str]) -> None:
        """Record an interruption: signals are ignored first thing, so that a second Ctrl-C cannot interrupt the write
        that records the first, and a disk that refuses leaves the last good flush (status 'running'), still
        resumable."""
        previous = _ignore_signals()
        try:
            self.finish(counter, t0, "interrupted", message())
        except ResultsIOError:
            pass
        finally:
            _restore_signals(previous)


def _io_outcome(exc, sink: "_Sink", setup, filled, plan, counter, t0) -> Outcome:
    """A disk that refused the results: what the file on disk holds (the last flush that went through), or that
    nothing was written (the disk refused the first, at the run's end for a short run: it said "cycle None")."""
    cycle, output = sink.cycle_on_disk(), sink.output
    where = (f"the file holds every step up to cycle {cycle} (status 'running'); when there is room, continue with "
             f"`fretsim run --resume {output}`" if cycle is not None else "nothing was written")
    return Outcome("io_error", f"{exc.strerror}; {where}", _summary(setup, counter, t0), setup, filled, Path(output),
                   counter.last, setup.notes, plan, cycle is not None)


def _execute(setup, filled, plan, sink: _Sink, progress, observers, resume_from: Optional[Results],
             runs: SideRuns) -> Outcome:
    counter = _Counter(len(resume_from.history["cycle"]) if resume_from is not None else 0,
                       _recorded_errors(resume_from) if resume_from is not None else (0.0, 0.0))
    t0 = time.perf_counter()
    state = resume_from.checkpoint if resume_from is not None else None
    output = sink.output
    try:
        status, message = _simulate(counter, sink, observers, progress, state, runs)
    except ResultsIOError as exc:
        return _io_outcome(exc, sink, sink.setup, sink.filled, sink.plan, counter, t0)
    except KeyboardInterrupt:
        sink.finish_interrupted(counter, t0, lambda: f"interrupted after cycle "
                                f"{counter.last.cycle if counter.last else (int(state['n']) if state else 0)}; "
                                f"resume with `fretsim run --resume {output}`")
        raise
    setup, filled, plan = sink.setup, sink.filled, sink.plan  # (on the grid the run ended on)
    if counter.last is not None and setup.fatigue_specs:
        summary = _summary(setup, counter, t0)
        _yield_note(filled, summary, counter)
        counter.notes.extend(_either_edge_notes(counter.last.state, summary))
    if counter.last is not None:
        counter.notes.extend(_end_notes(setup, filled, counter.last))
    if status == "complete" and counter.last is not None:
        _estimate_errors(setup, filled, plan, counter, sink, t0, runs)
    previous = _ignore_signals()  # a Ctrl-C in the last instant must not make a complete run look interrupted
    try:
        sink.finish(counter, t0, status, message)
    except ResultsIOError as exc:
        return _io_outcome(exc, sink, setup, filled, plan, counter, t0)
    finally:
        _restore_signals(previous)
    return Outcome(status, message, _summary(setup, counter, t0), setup, filled, Path(output) if output else None,
                   counter.last, tuple(setup.notes) + tuple(counter.notes), plan, sink.writer is not None,
                   counter.failure)


def _simulate(counter, sink: _Sink, observers, progress, state, runs: SideRuns) -> tuple[str, str]:
    """The loop, its ending as a status and a message (a grid that cannot resolve the contact is bad input); an
    automatic grid the contact outgrows is widened and the loop goes on from its last step (:mod:`fretsim.regrid`)."""
    state = _resumed_coarsening(counter, sink, state, runs)
    while True:
        try:
            return _simulate_on(sink.setup, sink.plan, counter, sink, observers, progress, state)
        except DomainError as exc:
            state, why = _widen(exc, counter, sink, runs, state)
            if state is None:
                return "failed", _unwidened(exc, sink.setup.grid, why)
            if state is _FROM_START:
                state = None
        except regrid.Coarsen as exc:
            state = _coarsen(exc, counter, sink, runs)


def _resumed_coarsening(counter, sink: _Sink, state: Optional[dict], runs: SideRuns) -> Optional[dict]:
    """A resumed run's checkpoint, on the coarser grid where its rule allows it there.  The loop asks the rule only
    after a step it takes, so a run interrupted at the step that allowed a coarsening (its observers had the step,
    the re-planning was not done) would otherwise coarsen a step later than the uninterrupted run did."""
    if state is None or sink.rule is None or "limit_key" in state:
        return state
    n = int(state["n"])
    if not 0 < n < sink.setup.cycles or any(c.cycle == n for c in sink.coarsenings):  # (already coarsened here)
        return state
    # what the rule and the merge read of a step: its pressure and wear are the checkpoint's (Step from emit)
    step = SimpleNamespace(cycle=n, state=state, pressure=state["p"], wear_stationary=state["h_s"])
    why = sink.rule(sink.setup, step)
    return _coarsen(regrid.Coarsen(step, why), counter, sink, runs) if why else state


def _coarsen(exc: "regrid.Coarsen", counter, sink: _Sink, runs: SideRuns) -> dict:
    """The state of the step that allowed it on the grid three times coarser, the run's setup and its results file
    moved onto it (:mod:`fretsim.regrid`); the same state, no longer coarsening, where the planner refuses the
    coarser grid."""
    setup = sink.setup
    try:
        new_setup, run_filled, plan, state, pad_r, made = regrid.step_down(
            setup, sink.run_filled, exc, functools.partial(prepare, runs=runs), sink.factor)
    except CaseError as err:
        sink.rule = None
        counter.notes.append(f"the automatic grid was not coarsened at cycle {exc.step.cycle}: "
                             f"{str(err).splitlines()[-1][:200]}")
        return exc.step.state
    if counter.last is not None:
        counter.last = regrid.coarsened_record(counter.last, setup.grid, pad_r)
    note = regrid.describe_coarsening(made, setup.grid.shape[1])
    counter.notes.append(note)
    held = _ignore_signals()  # the file's grid, fields and checkpoint move together: a Ctrl-C between them would
    try:                      # write a checkpoint of one grid beside fields of another
        sink.coarsen(made, pad_r, new_setup, run_filled, sink.plan, state, note, runs)
    finally:
        _restore_signals(held)
    return state


def _unwidened(exc: DomainError, grid, why: str) -> str:
    """A run stopped at the edge of its grid: the loop's words for the user's grid (enlarge it), why an automatic
    grid was not widened for an automatic one (its advice, to leave the grid empty, was what the case had done)."""
    if not why:
        return str(exc)
    ny, nx = grid.shape
    extent = nx * grid.dx if exc.axis == "x" else ny * grid.dy
    return (f"the contact reached the {exc.axis} edge of the automatic grid at cycle {exc.cycle} (extent "
            f"{extent:.4g} mm) and {why}; give grid.domain and grid.elements for a domain that holds the scar")


_FROM_START = object()  # _widen's state where the first solve reached the edge: the run starts again, wider


def _widen(exc: DomainError, counter, sink: _Sink, runs: SideRuns, resumed: Optional[dict]):
    """The last step's state (or the one the run was ``resumed`` from, before its first step) on a grid widened
    where the contact reached its edge, the run's setup and its results file moved onto it (_FROM_START where the
    first solve reached it: a crowned roller's contact is wider than the straight one the grid was sized for);
    None where the grid may not or cannot grow (the user's grid, too many widenings, a grid the planner refuses),
    with why an automatic grid was not widened ("" for the user's grid).  The widening is one of the run's notes
    (as the refusals are), so `fretsim run` prints it after the plan's."""
    setup, filled, plan = sink.setup, sink.filled, sink.plan
    base = counter.last.state if counter.last is not None else resumed
    if not regrid.grid_is_automatic(plan):
        return None, ""
    if regrid.widenings(sink.regrids) >= sink.allowed:
        times = f"{sink.allowed} time{'s' if sink.allowed != 1 else ''}"
        why = (f"the automatic grid was widened {times}, the most allowed: the scar outgrew the planned one far "
               f"beyond its estimate")
        counter.notes.append(why)
        return None, why
    run_r = regrid.widened(setup.grid, exc.axis, setup.band, int(base["n"]) if base else 0,
                           f"the contact reached the {exc.axis} edge at cycle {exc.cycle}")
    r = regrid.scaled(run_r, sink.factor)  # the output grid's widening (the same where the grid never coarsened)
    plane = setup.grid.plane_strain
    wider = filled.with_choices(domain=r.new_domain[:1] if plane else r.new_domain,
                                elements=r.new_elements[:1] if plane else r.new_elements)
    try:
        new_setup, new_filled, _ = prepare(wider, runs=runs)
        if sink.factor > 1:
            run_setup, run_filled, _ = prepare(regrid.along_x(sink.run_filled, setup.grid, run_r.new_elements[0],
                                                              run_r.new_domain[0]), runs=runs)
    except CaseError as err:  # e.g. more memory than the machine has
        why = f"the automatic grid could not be widened: {str(err).splitlines()[-1][:200]}"
        counter.notes.append(why)
        return None, why
    state = regrid.pad_state(base, run_r) if base else None
    if counter.last is not None:
        counter.last = regrid.pad_record(counter.last, run_r)
    note = regrid.describe(r)
    if sink.factor > 1:  # (in elements of /grid, as /regrids is; the coarsening notes count the run's)
        note += (f"; {run_r.old_elements[0]} → {run_r.new_elements[0]} of the run's, each {sink.factor} of "
                 f"these")
    if setup.coarse is not None and new_setup.coarse is not None:  # refinement: not nested, so not exact
        note += (f"; the coarse grid of refinement is re-derived on the wider domain, its element "
                 f"{setup.coarse.dx * 1e3:.4g} → {new_setup.coarse.dx * 1e3:.4g} µm, so from here the pressure is "
                 f"solved on slightly different coarse elements")
    counter.notes.append(note)
    held = _ignore_signals()  # as in _coarsen: the grid, fields and checkpoint move together
    try:
        sink.regrid(r, dataclasses.replace(new_setup, notes=tuple(setup.notes)), new_filled,
                    regrid.replanned(plan, r, plane), state, note)
        if sink.factor > 1:
            sink.follow(dataclasses.replace(run_setup, per_cycle=setup.per_cycle), run_filled)  # (regrid.step_down)
    finally:
        _restore_signals(held)
    return (state if base else _FROM_START), ""


def _simulate_on(setup, plan, counter, sink: _Sink, observers, progress, state) -> tuple[str, str]:
    """One stretch of the loop on one grid (a DomainError passes through to be widened)."""
    try:
        last = simulate(setup, (counter, sink) + tuple(observers), progress, resume=state, coarsen=sink.rule)
    except DomainError:
        raise
    except ResolutionError as exc:  # found before anything is written: an input problem, named as such
        given = any(c.key == "grid.elements" and c.given for c in plan.choices)
        key = "grid.elements" if given else "grid"
        advice = ("refine grid.elements or shrink grid.domain" if given else
                  "the automatic grid should resolve it: set grid.domain and grid.elements explicitly")
        raise CaseError(sink.filled.source, [(key, f"{exc}; {advice}")]) from None
    except PhysicalLimit as exc:
        return "stopped", str(exc)
    except SimulationError as exc:
        counter.failure = exc
        return "failed", str(exc)
    if counter.last is None and last is not None:  # resumed at its end: nothing left to do
        counter.last = last
        if sink.output is not None and sink.writer is None:
            sink.open(True)
            sink.writer.state = state
    return "complete", ""


def _estimate_errors(setup, filled, plan, counter, sink: _Sink, t0, runs: SideRuns) -> None:
    """The complete run's error estimates into ``counter.extra``; whatever stops them must not cost the run its
    file: the estimates are then unknown, and it says why."""
    started = time.perf_counter()
    try:
        counter.extra = _error_estimates(setup, filled, plan, counter, runs, tuple(sink.coarsenings),
                                         sink.first_filled)
    except KeyboardInterrupt:
        sink.finish_interrupted(counter, t0, lambda: "interrupted while estimating the grid's error (the run itself "
                                f"is complete); resume with `fretsim run --resume {sink.output}`")
        raise
    except Exception as exc:  # noqa: BLE001 - the run is complete: whatever stops its error estimate must not
        #                                      cost it its file; the estimates are then unknown, and it says why
        counter.notes.append(f"the grid's error was not estimated: {type(exc).__name__}: {str(exc)[:160]}")
        counter.extra = {k: float("nan") for k in grid_error.KEYS + (grid_error.LIMIT_KEY,)}
    counter.extra["grid_error_wall_time_s"] = time.perf_counter() - started


def _end_notes(setup: Setup, filled: Case, last: Step) -> list[str]:
    """A 3D line contact with square ends (no axial profile) whose bodies wear deepest in an end row: said, as a
    warning.  The pressure at a square end is singular, and that row's depth grows as the rows are refined (McColl
    185 N 3D, the README's first command: the moving body 2.048, 2.061, 2.072, 2.080 µm and the flat 3.062, 3.081,
    3.098, 3.109 µm on 13, 27, 55 and 109 rows, where the centre lines agree to 1e-4; found by a review), while the
    grid-error companions keep a line contact's rows: its estimate covers the x grid only."""
    if setup.grid.plane_strain or not setup.y_edges_free or filled.geometry.axial_profile:
        return []
    found = []
    for body, h in (("the moving body", last.wear_moving), ("the flat", last.wear_stationary)):
        rows = h.max(axis=1)
        worn = np.flatnonzero(rows > 0)  # (a grid wider than the line: its end rows are the last worn ones)
        # (deeper than the centre line beyond round-off: rows alike along y pick the first as argmax)
        if (worn.size >= 3 and int(np.argmax(rows)) in (worn[0], worn[-1])
                and rows.max() > rows[rows.size // 2] * (1 + 1e-9)):
            found.append(f"{body} ({rows.max() * 1e3:.4g} µm, {rows.max() / rows[rows.size // 2] - 1:.1%} over its "
                         f"centre line)")
    if not found:
        return []
    rounded = ("; geometry type roller_on_flat models a real edge's rounding"
               if filled.geometry.kind == "cylinder_on_flat" else "")
    return [f"the deepest wear of {' and of '.join(found)} is in an end row of the line contact, where a square "
            f"end's pressure is singular: it grows as grid.elements refines the rows (McColl 185 N in gross slip: "
            f"0.4-0.6 % a doubling of 13 to 109 rows), which is not covered by its estimate (the companions keep "
            f"the rows); the centre-line depths converge{rounded}"]


def _yield_note(filled: Case, summary: dict, counter: "_Counter") -> None:
    """A fatigue run whose body's largest shear stress passes Tresca's yield (σ_y/2, with that body's yield
    strength given): said, since the elastic stresses there, and the SWT life from them, are beyond the model's
    range (a worn partial-slip contact concentrates its pressure on the stick zone's edge)."""
    from fretsim.quantities import keyed
    for body, m, whose in (("stationary", filled.stationary, "the flat's"),
                           ("moving", filled.moving, "the moving body's")):
        sy, shear = m.yield_strength, summary.get(keyed("max_shear_stress_MPa", body), float("nan"))
        if sy is not None and math.isfinite(shear) and shear > 0.5 * sy:
            counter.notes.append(f"{whose} largest shear stress {shear:.4g} MPa (at a recorded state, "
                                 f"{summary[keyed('max_shear_stress_depth_um', body)]:.3g} µm deep) passes Tresca's "
                                 f"yield σ_y/2 = {0.5 * sy:.4g} MPa: {whose[:-2]} yields there, where the elastic "
                                 f"stresses and the fatigue life from them do not follow it (the life is the "
                                 f"elastic model's)")


EITHER_EDGE = 0.99  # the two halves' largest damage this close: the crack could start at either edge


def _either_edge_notes(state: dict, summary: dict) -> list:
    """Where a body's crack could as well start at the other edge (a fully reversed cycle damages its two edges
    alike): its largest Miner's sum on the side of x < 0 and on x > 0 within EITHER_EDGE of each other at the run's
    end.  A review saw crack_location_x_mm change sign under refinement (−0.110, −0.114, +0.113 mm) while |x| held
    within 4 µm."""
    from fretsim.fatigue.damage import PREFIX
    from fretsim.quantities import keyed
    out = []
    for body, prefix in PREFIX.items():
        damage, x = state.get(f"{prefix}_damage"), summary.get(keyed("crack_location_x_mm", body), math.nan)
        if damage is None or not math.isfinite(x):
            continue
        half = damage.shape[-1] // 2
        left, right = float(damage[..., :half].max()), float(damage[..., -half:].max())
        if half and min(left, right) >= EITHER_EDGE * max(left, right):
            out.append(f"the {'flat' if body == 'stationary' else 'moving body'}'s crack could start at either edge "
                       f"(x = ±{abs(x):.4g} mm): the largest Miner's sums on the two sides are within "
                       f"{1 - min(left, right) / max(left, right):.2%} of each other, and crack_location_x_mm's sign "
                       f"is the side that reached 1 first on this grid")
    return out


_DEFERRED: list = []  # signals that came while ignored (_ignore_signals): a refinement's next attempt stops for them


def _ignore_signals() -> dict:
    """Hold off SIGINT and SIGTERM (main thread only), noting any that come (:func:`_stop_if_deferred`); returns the
    handlers to restore."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    _DEFERRED.clear()
    return {sig: signal.signal(sig, lambda signum, frame: _DEFERRED.append(signum))
            for sig in (signal.SIGINT, signal.SIGTERM)}


def _stop_if_deferred() -> None:
    """A Ctrl-C (or SIGTERM) held off while a failed attempt's file was written: the run stops before the next
    attempt, as it would have had the signal come a moment later."""
    if _DEFERRED:
        _DEFERRED.clear()
        raise KeyboardInterrupt


def _restore_signals(previous: dict) -> None:
    for sig, handler in previous.items():
        signal.signal(sig, handler)


def _recorded_errors(previous: Results) -> tuple:
    """The largest error estimates at the recorded states of an earlier part of the run."""
    h = previous.history
    if "error_estimate_depth" not in h or not len(h.get("cycle", [])):
        return (0.0, 0.0)
    at = np.isin(h["cycle"], previous.fields.get("cycle", []))
    return (float(h["error_estimate_depth"][at].max(initial=0.0)),
            float(h["error_estimate_pressure"][at].max(initial=0.0)))


def _summary(setup, counter, t0) -> dict:
    if counter.last is None:
        return {}
    out = summarize(setup, counter.last, counter.solves, _elapsed(counter, t0), counter.errors)
    out.update(counter.extra or {**{k: float("nan") for k in grid_error.KEYS + (grid_error.LIMIT_KEY,)},
                                 "grid_error_wall_time_s": 0.0})
    if setup.fatigue is not None:  # not estimated (no companion, or it stopped): said so, not left out
        out.update({k: out.get(k, float("nan")) for k in grid_error.FATIGUE_KEYS})
    return in_summary_order(out)


def _error_estimates(setup: Setup, filled: Case, plan: Plan, counter: "_Counter", runs: SideRuns,
                     coarsenings: tuple = (), first: Optional[Case] = None) -> dict:
    """The total error estimates of the reported numbers: the stepping's, the grid's (from a companion run on a
    grid twice as coarse, see :mod:`fretsim.grid_error`, which coarsens where the run did: ``coarsenings``, and
    starts on the domain the run started on, ``first``'s, widening as the run did where its contact reaches the
    edge) and the model difference ``auto`` accepted."""
    summary = summarize(setup, counter.last, counter.solves, 0.0, counter.errors)
    model_part = sum(c.error for c in plan.choices)
    if not _estimated(filled):
        return {**grid_error.totals(summary, None, model_part), grid_error.LIMIT_KEY: float("nan")}
    companion, coarsest_case = _companions(setup, first if first is not None else filled)
    replay = tuple(c.cycle for c in coarsenings)
    widen = regrid.grid_is_automatic(plan)  # the companions' grids follow their contact as the run's did
    try:
        c_setup, c_filled, _ = prepare(companion, runs=runs)
        last, c_setup = _side_run(runs, f"grid error: the case again on a grid twice as coarse "
                                        f"({c_setup.grid.shape[1]} × {c_setup.grid.shape[0]} elements"
                                        f"{', coarsened where the run was' if replay else ''}) to estimate the grid's "
                                        f"part of the error", c_setup, c_filled, replay, widen)
    except (SimulationError, CaseError) as exc:  # e.g. the mid-stroke gap, stable on the run's grid, is not on
        #  the coarser one, or a partial slip's stick edge breaks into a checkerboard there: the run stands, and a
        #  companion twice as fine says how far it is from the converged answer
        return _finer_estimates(setup, filled, counter, runs, summary, model_part, first, replay, widen, exc)
    coarse = summarize(c_setup, last, 0, 0.0)
    coarsest = _coarsest(coarsest_case, runs, replay, widen)
    part = grid_error.grid_estimates(summary, coarse, counter.last.pressure, setup.grid, last.pressure,
                                     c_setup.grid, coarsest)
    out = grid_error.totals(summary, part, model_part)
    out[grid_error.LIMIT_KEY] = grid_error.cycles_to_limit_estimate(summary, coarse, counter.last.limit, model_part)
    if setup.fatigue is not None:
        out.update(grid_error.fatigue_estimates(summary, coarse, coarsest=coarsest))
        unknown = grid_error.fatigue_unestimated(summary, coarsest, coarse)
        counter.notes.extend(grid_error.fatigue_unestimated_note(unknown))
        counter.notes.extend(grid_error.fatigue_over(summary, coarse, out, filled.accuracy))
        counter.notes.extend(_moving_fatigue_note(summary))
    if counter.last.limit is not None and not math.isfinite(out[grid_error.LIMIT_KEY]):
        counter.notes.append("the grid's part of cycles_to_limit was not estimated: the companion run on a grid "
                             "twice as coarse reached no limit within loading.cycles")
    if part["peak_unestimated"]:
        counter.notes.append(grid_error.stick_edge_note((None if coarsest is None else coarsest["max_pressure_MPa"],
                                                        coarse["max_pressure_MPa"], summary["max_pressure_MPa"])))
    elif not part["peak_converging"]:
        counter.notes.append(grid_error.peak_note(summary["max_pressure_MPa"], coarse["max_pressure_MPa"],
                                                  coarsest["max_pressure_MPa"], out["estimated_error_max_pressure"]))
    over = [f"{what} {out[key]:.2%}" for key, what in (("estimated_error_depth", "the depths"),
                                                        ("estimated_error_width", "the scar widths"))
            if out[key] > filled.accuracy]
    if filled.pressure_accuracy is not None and out["estimated_error_pressure"] > filled.pressure_accuracy:
        counter.notes.append(f"the estimated error of the pressure field {out['estimated_error_pressure']:.2%} "
                             f"exceeds model.pressure_accuracy ({filled.pressure_accuracy:.2%})")
    if over:
        counter.notes.append(f"the estimated error of {' and of '.join(over)} exceeds model.accuracy "
                             f"({filled.accuracy:.2%}); a finer grid.elements (the companion grid's difference is "
                             f"most of it) or a smaller jumping.tolerance brings it down")
    return out


def _finer_estimates(setup: Setup, filled: Case, counter: "_Counter", runs: SideRuns, summary: dict,
                     model_part: float, first: Optional[Case], replay: tuple, widen: bool, why: Exception) -> dict:
    """The grid's part of the error where the companion twice as coarse stopped: from a companion twice as fine
    (:func:`fretsim.grid_error.finer_estimates`); unknown, and said so as a warning, where that stops too.  A coarse
    companion that breaks down is itself a sign that the run's grid is close to too coarse: its numbers may be far
    from converged, which is why they are not left without an estimate."""
    stopped = str(why).splitlines()[0][:160]
    line_contact = setup.y_edges_free and not setup.grid.plane_strain
    finer = grid_error.companion_case(first if first is not None else filled, line_contact, times=-1)
    try:
        f_setup, f_filled, _ = prepare(finer, runs=runs)
        last, f_setup = _side_run(runs, f"grid error: the companion on a grid twice as coarse stopped; the case again "
                                        f"on a grid twice as fine ({f_setup.grid.shape[1]} × {f_setup.grid.shape[0]} "
                                        f"elements) instead", f_setup, f_filled, replay, widen)
    except (SimulationError, CaseError) as exc:
        counter.notes.append(f"the grid's error was not estimated: its companion run on a grid twice as "
                             f"coarse stopped ({stopped}), and one on a grid twice as fine stopped too "
                             f"({str(exc).splitlines()[0][:160]}); this grid may be too coarse for the numbers to "
                             f"have converged: compare with a run on a finer grid.elements")
        return {**grid_error.totals(summary, None, model_part), grid_error.LIMIT_KEY: float("nan")}
    fine = summarize(f_setup, last, 0, 0.0)
    part = grid_error.finer_estimates(summary, fine, counter.last.pressure, setup.grid, last.pressure, f_setup.grid)
    out = grid_error.totals(summary, part, model_part)
    out[grid_error.LIMIT_KEY] = grid_error.cycles_to_limit_estimate(summary, fine, counter.last.limit, model_part,
                                                                    grid_error.FINER_FACTOR)
    if setup.fatigue is not None:
        out.update(grid_error.fatigue_estimates(summary, fine, grid_error.FINER_FACTOR))
        counter.notes.extend(grid_error.fatigue_unestimated_note(grid_error.fatigue_unestimated(summary, fine),
                                                               grid_error.FINE_GRIDS[::-1]))
        counter.notes.extend(_moving_fatigue_note(summary))
    counter.notes.append(grid_error.finer_note(stopped, f_setup.grid.shape[1], out, filled.accuracy))
    if part["peak_unestimated"]:
        counter.notes.append(grid_error.stick_edge_note((summary["max_pressure_MPa"], fine["max_pressure_MPa"]),
                                                       grid_error.FINE_GRIDS))
    return out


def _moving_fatigue_note(summary: dict) -> list:
    """The moving body's fatigue figures, where it has constants: not estimated (the estimates are the flat's)."""
    if not math.isfinite(summary.get("fatigue_damage_moving", math.nan)):
        return []
    return ["the moving body's fatigue figures (cycles_to_crack_initiation_moving, swt_max_moving_MPa, "
            "fatigue_damage_moving) carry no error estimate: the estimated_error_* of the fatigue are the flat's"]


def estimate(setup: Setup, filled: Case, runs: Optional[SideRuns] = None) -> dict:
    """What a run of this plan will cost besides its planning (auto's proxies, a limit's pilot: timed where they
    run): ``solves`` and ``run_s`` of its own loop, and ``companions_s`` of its grid-error companion runs, each
    from one timed solve on its grid (:func:`fretsim.plan.estimate_cost`)."""
    solves, seconds = estimate_cost(setup)
    out = {"solves": solves, "run_s": seconds, "companions_s": 0.0, "companions": 0}
    if not _estimated(filled):
        return out
    for case in _companions(setup, filled):
        try:
            c_setup, _, _ = prepare(case, runs=runs)
        except (SimulationError, CaseError):
            continue
        # a companion stops at the run's wear limit as the run does (it plans without a pilot of its own)
        c_setup = dataclasses.replace(c_setup, expected_stop=min(c_setup.expected_stop, setup.expected_stop))
        out["companions_s"] += estimate_cost(c_setup)[1]
        out["companions"] += 1
    return out


def _estimated(filled: Case) -> bool:
    """Whether the grid's part of a run's error is estimated (by companion runs on coarser grids)."""
    return grid_error.companions_wanted(filled)


def _companions(setup: Setup, filled: Case) -> tuple[Case, Case]:
    """The grid-error companions: the case on a grid twice as coarse, and four times as coarse (a line contact's
    rows kept: its ends are where 3D differs)."""
    line_contact = setup.y_edges_free and not setup.grid.plane_strain
    return tuple(grid_error.companion_case(filled, line_contact, times=times) for times in (1, 2))


def _coarsest(case: Case, runs: SideRuns, replay: tuple = (), widen: bool = False) -> Optional[dict]:
    """The summary of the run on a grid four times as coarse (whether the peak pressure converges), or None where
    that grid cannot carry the run (too few elements for the contact, an unstable gap): the peak is then read
    from two grids."""
    try:
        c_setup, c_filled, _ = prepare(case, runs=runs)
        last, c_setup = _side_run(runs, f"grid error: the case again on a grid four times as coarse "
                                        f"({c_setup.grid.shape[1]} × {c_setup.grid.shape[0]} elements"
                                        f"{', coarsened where the run was' if replay else ''}) to see whether the "
                                        f"peak pressure converges", c_setup, c_filled, replay, widen)
        return summarize(c_setup, last, 0, 0.0)
    except (SimulationError, CaseError):
        return None


def _side_run(runs: SideRuns, what: str, setup: Setup, filled: Case, replay: tuple,
              widen: bool = False) -> tuple[Step, Setup]:
    """A companion run and the setup it ended on: coarsened at the first step at or past each of the ``replay``
    cycles, where the run coarsened (so that its estimate covers the grids the run used), and widened where its
    contact reaches the edge of its automatic grid, as the run's."""
    if not replay and not widen:
        return runs.run(what, setup), setup
    last, setup, _ = runs.run_following(what, setup, filled, regrid.Replay(replay),
                                        functools.partial(prepare, runs=runs), widen=widen)
    return last, setup


def _elapsed(counter, t0) -> float:
    return float(counter.last.state.get("elapsed", time.perf_counter() - t0)) if counter.last else 0.0
