"""`fretsim` command line.  No algorithm here: it wraps :mod:`fretsim.api`.

Exit codes: 0 complete, 2 bad input (case, options, files), 3 a run that failed numerically or outgrew its grid,
4 a run stopped at a physical limit (a body worn through), 5 the results could not be written (disk full, I/O
error; resume once there is room), 130 interrupted (resume with --resume).

Each command imports what it needs when it runs, so `--help`, `summary` and `check` start quickly.  Every command
goes through one error boundary (:func:`_boundary`): a failure is one paragraph on stderr and an exit code, with
the traceback only under ``--debug``.
"""
from __future__ import annotations

import functools
import math
import os
import sys
import traceback
from typing import Optional
from pathlib import Path

# One BLAS thread, as the house runs one thread per solve: numpy's dots here are small (the norms of a grid's
# fields), and OpenBLAS's second thread made whole 3D runs 4 % slower on a quiet machine and 1.5x slower with the
# other core busy (two runs, a shell sweep; scripts/results/bench_blas_threads.txt).  Set before numpy loads (the
# commands import it when they run), and only where the user has not set it.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import click  # noqa: E402

from fretsim.errors import InputError, ResultsFileError  # noqa: E402

EXIT_BAD_INPUT = 2
EXIT_FAILED = 3
EXIT_STOPPED = 4
EXIT_IO = 5
EXIT_INTERRUPTED = 130
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, as a shell tool whose reader has gone


class Fail(Exception):
    """A command's own failure: the paragraph to print and the exit code."""

    def __init__(self, message: str, code: int = EXIT_BAD_INPUT):
        super().__init__(message)
        self.code = code


def _boundary(command):
    """The command line's one error boundary: bad input and unreadable files exit 2, a disk that refuses exit 5,
    Ctrl-C exit 130, a command's own failure its code — each as one paragraph, a traceback only with --debug."""
    @functools.wraps(command)
    def guarded(*args, **kwargs):
        try:
            return command(*args, **kwargs)
        except BrokenPipeError:  # the reader went away (`fretsim summary … | head`): quiet, as shell tools are
            try:
                os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # nothing more to flush at exit
            except OSError:
                pass
            sys.exit(EXIT_BROKEN_PIPE)
        except (Fail, InputError, ResultsFileError, KeyboardInterrupt, OSError) as exc:
            if isinstance(exc, Fail):
                code, message = exc.code, str(exc)
            elif isinstance(exc, (InputError, ResultsFileError)):
                code, message = EXIT_BAD_INPUT, str(exc)
            elif isinstance(exc, KeyboardInterrupt):
                code, message = EXIT_INTERRUPTED, "interrupted"
            else:
                where = f" {exc.filename}" if exc.filename else ""
                code, message = EXIT_IO, f"cannot write{where}: {exc.strerror or exc}"
            if kwargs.get("debug"):
                traceback.print_exc()
        click.echo(f"fretsim: {message}", err=True)
        sys.exit(code)
    return guarded


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="fretsim")
def main() -> None:
    """Fretting-wear simulation after Kong, Bennett & Hyde: YAML case → HDF5 results → figures.

    Shell completion (bash): eval "$(_FRETSIM_COMPLETE=bash_source fretsim)"
    """


LONG_RUN = 60.0  # s: a run expected to take longer says so before it starts


def long_run_note(setup) -> Optional[str]:
    """The cost estimate of a run that will take long by request (ΔN_L = 1 over 10⁹ cycles, msm on a large 3D
    grid): timed with one solve, so only where the counts alone make it plausible."""
    from fretsim.plan import estimate_cost, estimate_solves
    elements = setup.grid.shape[0] * setup.grid.shape[1]
    if estimate_solves(setup) < 2000 and elements < 20_000 and not (setup.method != "cg" and elements > 2000):
        return None
    solves, seconds = estimate_cost(setup)
    if seconds < LONG_RUN:
        return None
    return (f"estimate: about {solves:,} contact solves, {_duration(seconds)} (one timed solve; Ctrl-C stops the "
            f"run with every step so far written, and --resume continues it)")


def _duration(seconds: float) -> str:
    for unit, size in (("years", 3.156e7), ("days", 86400.0), ("hours", 3600.0), ("minutes", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


@main.command()
@click.argument("case_file", required=False, type=click.Path(path_type=Path))
@click.option("-o", "--output", type=click.Path(),  # text, not a Path: a trailing '/' (a directory) must survive
              help="Results file (default: CASE_FILE's name with .h5, in the current directory).")
@click.option("--set", "overrides", multiple=True, metavar="KEY.PATH=VALUE",
              help="Override a case value, e.g. --set loading.cycles=1000 (repeatable).")
@click.option("--overwrite", is_flag=True, help="Replace an existing results file.")
@click.option("--resume", "resume_file", type=click.Path(path_type=Path),
              help="Continue an interrupted run from its results file (no CASE_FILE then).")
@click.option("--quiet", is_flag=True, help="No notes, no progress bar: the summary paragraph, and the warnings "
              "(a model out of its range, an estimated error above model.accuracy), which always print.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def run(case_file: Path | None, output: str | None, overrides: tuple, overwrite: bool, resume_file: Path | None,
        quiet: bool, debug: bool) -> None:
    """Run CASE_FILE and write an HDF5 results file (or --resume one)."""
    import signal

    from fretsim.api import load_case, resume as resume_run, run as run_case

    if resume_file is not None and (case_file is not None or overrides or output is not None):
        raise Fail("--resume takes the results file alone: the case, grid and settings are the ones stored in it")
    if resume_file is None and case_file is None:
        raise Fail("give a CASE_FILE to run, or --resume RESULTS_FILE")
    if case_file is not None:
        _not_results(case_file)
        _text_path(case_file, "case file")
    if resume_file is not None:
        _case_not_results(resume_file, "run --resume")
    output = resume_file or output or Path(case_file.stem + ".h5")
    progress = _Progress(quiet or not sys.stderr.isatty())

    def _terminate(signum, frame):  # SIGTERM ends a run as cleanly as Ctrl-C
        raise KeyboardInterrupt

    def _on_plan(setup, filled, plan):
        for note in setup.notes:  # the plan's warnings as check shows them: the model may be out of its range
            if note in plan.warnings or not quiet:  # a warning is about the results, not progress: --quiet keeps it
                click.echo(f"{'warning' if note in plan.warnings else 'note'}: {note}", err=True)
        if not quiet:
            long = long_run_note(setup)
            if long:
                click.echo(long, err=True)
        progress.start(setup)

    from fretsim.plan import SideRuns
    # the proxies, a pilot and the companions can take a minute: say what is running, and how far
    runs = SideRuns() if quiet else _side_runs(progress.stop)[0]
    try:
        previous_handler = signal.signal(signal.SIGTERM, _terminate)
    except ValueError:  # not the main thread (the CLI called from a thread): SIGTERM keeps its handler
        previous_handler = None
    outcome, before = None, _file_id(output)
    try:
        if resume_file is not None:
            outcome = resume_run(resume_file, progress=progress.update, runs=runs)
        else:
            case = load_case(case_file, list(overrides))
            outcome = run_case(case, output, overwrite=overwrite, progress=progress.update, on_plan=_on_plan,
                               runs=runs)
    except KeyboardInterrupt:
        _interrupted(output, before, resume_file is not None)
        return
    except OSError as exc:  # before any step: the output's place cannot be written
        raise Fail(f"cannot write {output}: {exc.strerror or exc}") from None
    finally:
        progress.stop()
        try:
            signal.signal(signal.SIGTERM, previous_handler)
        except (ValueError, TypeError):
            pass
    if outcome.status == "io_error":
        raise Fail(f"could not write the results: {outcome.message}", EXIT_IO)
    if outcome.status == "stopped":
        click.echo(_said(outcome))
        raise Fail(f"stopped at a physical limit: {outcome.message}", EXIT_STOPPED)
    if outcome.status != "complete":
        raise Fail(f"run failed: {outcome.message}" + (f"; steps up to the failure are in {output} (status 'failed')"
                                                       if outcome.written else ""), EXIT_FAILED)
    for note in outcome.notes[len(outcome.setup.notes):]:
        if _beyond_accuracy(note):  # the results are less accurate than asked: said even with --quiet
            click.echo(f"warning: {note}", err=True)
        elif not quiet:
            click.echo(f"note: {note}", err=True)
    click.echo(_said(outcome))


def _beyond_accuracy(note: str) -> bool:
    """A run's note that an estimated error exceeds model.accuracy or model.pressure_accuracy (the runner's
    words), as opposed to how the estimates were made."""
    return ("exceeds model.accuracy" in note or "exceeds model.pressure_accuracy" in note
            or "too coarse for the numbers to have converged" in note or "is not estimated (NaN)" in note
            or "are not estimated (NaN)" in note or "not covered by its estimate" in note)


HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _is_hdf5(path: Path) -> bool:
    """Whether ``path`` is a regular file with HDF5's signature (at offset 0, or after a user block of 512 · 2ⁿ
    bytes), read from a few bytes: `check` and `summary` must not pay for importing h5py to say so."""
    try:
        if not path.is_file():  # a FIFO would block the open
            return False
        with open(path, "rb") as fh:
            for offset in (0, 512, 1024, 2048, 4096):
                fh.seek(offset)
                if fh.read(8) == HDF5_SIGNATURE:
                    return True
    except OSError:
        return False
    return False


def _not_results(path: Path) -> None:
    """A results file given where a case (YAML) is expected: say what it is and what reads it, rather than that it
    is not UTF-8 text or is megabytes long."""
    if not _is_hdf5(path):
        return
    status = _status_of(path)
    if status is None:
        raise Fail(f"{path} is an HDF5 file, not a case (YAML); a case file is the YAML text `fretsim init` writes")
    resume = f"continue it with `fretsim run --resume {path}`, or " if status in ("interrupted", "running") else ""
    raise Fail(f"{path} is a results file (HDF5, status {status!r}), not a case (YAML): {resume}read it with "
               f"`fretsim summary {path}` or `fretsim plot {path}`; its case is inside it (/case)")


def _case_not_results(path: Path, command: str) -> None:
    """A case (YAML) given where a results file is expected: say which command makes one (ResultsFileError, so
    that `summary` of several files lists it among the unreadable ones)."""
    if _is_hdf5(path) or not path.is_file() or path.suffix.lower() not in (".yaml", ".yml"):
        return  # the reader's own message then says what is wrong
    if command == "run --resume":
        raise ResultsFileError(f"{path} is a case file (YAML): --resume continues an interrupted run from its "
                               f"results file (HDF5); to run the case, `fretsim run {path}`")
    raise ResultsFileError(f"{path} is a case file (YAML), not a results file: `fretsim {command}` reads the HDF5 "
                           f"files that `fretsim run` writes; run it first with `fretsim run {path}` (which writes "
                           f"{Path(path.stem + '.h5')}), then `fretsim {command} {Path(path.stem + '.h5')}`")


def _read_results(path: Path, command: str):
    from fretsim.results import read_results
    _case_not_results(Path(path), command)
    return read_results(path)


def _text_path(path: Path, what: str) -> None:
    """A file name that is not text (bytes that are not UTF-8, which Python keeps as lone surrogates) is refused
    before the run: the results file records the case file's name as UTF-8, and h5py fails on it half-way."""
    try:
        str(path).encode("utf-8")
    except UnicodeEncodeError:
        shown = os.fsencode(path).decode("utf-8", "backslashreplace")
        raise Fail(f"{shown}: the {what}'s name is not UTF-8 text, and the results file records it as UTF-8; "
                   f"rename the file (or copy it to a name of Unicode characters)") from None


def _side_runs(before=lambda: None) -> tuple:
    """The runs a run makes besides its own, saying what they are, when (seconds since now) and how far they are
    (a bar on a terminal): a :class:`fretsim.plan.SideRuns`, and the list of what it said.  ``before`` ends what
    was shown before (the run's own bar)."""
    import contextlib
    import time

    from fretsim.plan import SideRuns
    started = time.perf_counter()
    said: list = []

    def announce(what: str) -> None:
        before()
        said.append(what)
        try:
            click.echo(f"[{time.perf_counter() - started:5.1f} s] {what}", err=True)
        except OSError:  # only information: a closed stderr must not cost the run its file
            pass

    @contextlib.contextmanager
    def side_progress(setup):
        bar = _Progress(not sys.stderr.isatty())
        bar.start(setup)
        try:
            yield bar.update
        finally:
            bar.stop()

    return SideRuns(announce, side_progress), said


def _file_id(path) -> Optional[tuple]:
    """What tells one version of a file from another (None: no file)."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_ino, st.st_mtime_ns, st.st_size


def _interrupted(output, before: Optional[tuple], resuming: bool) -> None:
    """What an interrupted `run` says, true to what is on disk: the run complete after all, nothing of it written
    (interrupted while planning, e.g. in auto's proxy runs: an earlier file of that name is as it was), or its
    accepted steps kept for --resume."""
    written = _file_id(output) != before
    status = _status_of(output) if written else None
    if status == "complete":  # the interrupt came after the last write
        click.echo(f"interrupted after the run had completed: {output} holds the whole run (status 'complete')")
        return
    if not written and not resuming:
        kept = f"; {output} is as it was before this run" if before is not None else ""
        raise Fail(f"interrupted before the run's first step was written (while planning or in its first solve): "
                   f"nothing was written{kept}; run the case again", EXIT_INTERRUPTED) from None
    if written and _file_id(output) is None:  # a refinement removed a failed attempt's file (fretsim.runner)
        raise Fail(f"interrupted before the run's first step on its refined grid was written: nothing of it is on "
                   f"disk{' (the earlier ' + str(output) + ' was replaced)' if before is not None else ''}; run the "
                   f"case again", EXIT_INTERRUPTED) from None
    if status not in (None, "interrupted", "running"):  # e.g. an attempt that failed before its grid was refined
        raise Fail(f"interrupted; {output} holds an attempt that ended {status!r}, which cannot be resumed: run the "
                   f"case again with --overwrite", EXIT_INTERRUPTED) from None
    raise Fail(f"interrupted; every accepted step so far is in {output} (status 'interrupted'); continue with "
               f"`fretsim run --resume {output}`", EXIT_INTERRUPTED) from None


def _status_of(path) -> Optional[str]:
    from fretsim.results import read_results
    try:
        return read_results(path).status
    except (ValueError, OSError):
        return None


class _Progress:
    """A progress bar in cycles whose time estimate counts solves (steps grow, so cycles/s is no guide)."""

    def __init__(self, off: bool):
        self.off = off
        self.bar = None
        self.done = 0

    def start(self, setup) -> None:
        if self.off or not setup.cycles:
            return
        import time
        from fretsim.plan import estimate_solves
        self.solves_expected = max(1, estimate_solves(setup))
        self.solves = 0
        self.t0 = time.perf_counter()
        self.total = setup.cycles
        self.bar = click.progressbar(length=setup.cycles, label="cycles", file=sys.stderr, show_eta=False,
                                     show_percent=True, item_show_func=self._text)
        self._safely(self.bar.__enter__)

    def _text(self, _item) -> str:
        import time
        if not self.solves:
            return ""
        spent = time.perf_counter() - self.t0
        left = max(0.0, spent / self.solves * (max(self.solves_expected, self.solves + 1) - self.solves))
        return f"{self.done}/{self.total}, about {left:.0f} s left"

    def update(self, cycles: int) -> None:
        if self.bar is None:
            return
        self.solves += 1
        self.done += cycles
        self._safely(self.bar.update, cycles, self.done)

    def stop(self) -> None:
        if self.bar is not None:
            bar, self.bar = self.bar, None
            self._safely(bar.__exit__, None, None, None)

    def _safely(self, call, *args) -> None:
        """A bar is only information: a terminal that has gone (a closed pipe, a hung-up tty) turns it off rather
        than ending the run before its file is written."""
        try:
            call(*args)
        except OSError:
            self.bar = None


def _check_regime(setup, loading) -> str:
    """`check`'s regime line: the stroke of the block δ_t was judged on (the one nearest partial slip) against it."""
    d_t, block, mu = setup.gross_slip_stroke, setup.regime_block, loading.friction_coefficient
    stroke, mu = (block.stroke, block.friction_coefficient) if block is not None else (loading.peak_stroke, mu)
    which = " of the block nearest partial slip" if len({(b.stroke, b.normal_load) for b in loading.given}) > 1 else ""
    if d_t == 0.0:
        return f"regime: gross slip — frictionless (μ = 0{which}): nothing sticks, every point slides the whole stroke"
    regime = "gross slip" if stroke > d_t else "partial slip"
    return (f"regime: {regime} at the start — the stroke{which} {stroke * 1e3:.4g} µm is {stroke / d_t:.3g}× the "
            f"gross-slip limit δ_t = {d_t * 1e3:.4g} µm (μ = {mu:g}, the unworn contact)")


def _summary_value(key: str, value, row: dict) -> str:
    """A value as `summary` prints it: "–" where none applies (JSON keeps null), the regime marked "(assumed)"
    where no friction coefficient judged it."""
    if value is None or value == "":
        return "–"
    if isinstance(value, float):
        return f"{value:.6g}"
    if key == "regime" and row.get("inputs", {}).get("friction_coefficient") is None:
        return f"{value} (assumed)"
    return str(value)


def _regime(s: dict, c) -> str:
    """The regime sentence of the summary: measured (coulomb) or assumed (uniform slip)."""
    from fretsim.cycle import CYCLES
    if CYCLES[c.slip].assumes_gross_slip:
        d_t, strokes = s.get("gross_slip_stroke_um"), {b.stroke for b in c.loading.given}
        if c.loading.friction_coefficient is None or d_t is None or not math.isfinite(d_t):
            return "Gross slip assumed."
        if d_t == 0.0:
            return "Gross slip: frictionless (μ = 0), every point slides the whole stroke."
        if len(strokes) > 1:  # δ_t is the block's nearest partial slip: no one stroke to set it against
            return f"Gross slip assumed (the gross-slip limit {d_t:.3g} µm on the block nearest partial slip)."
        return (f"Gross slip assumed (the stroke is {strokes.pop() / (d_t * 1e-3):.3g}× the gross-slip limit "
                f"{d_t:.3g} µm).")
    where = (f"stick zone ±{s['stick_half_width_x_mm'] * 1e3:.3g} µm along x" if s["regime"] == "partial_slip"
             else "the whole contact slides")
    return (f"{s['regime'].replace('_', ' ').capitalize()} ({where}): tangential force amplitude "
            f"{s['tangential_force_amplitude_N']:.4g} N, {s['dissipated_energy_per_cycle_J'] * 1e3:.4g} mJ "
            f"dissipated per cycle.")


def _estimates(s: dict) -> str:
    """The error sentence: the totals (stepping, grid and accepted model difference) and the stepping's part."""
    import math
    stepping = (f"the stepping's part at the recorded states: depth {s['error_estimate_depth']:.1e}, pressure "
                f"{s['error_estimate_pressure']:.1e}")
    if math.isnan(s.get("estimated_error_depth", float("nan"))):
        return f"Estimated error (relative): the grid's part not estimated; {stepping}."
    peak = s["estimated_error_max_pressure"]
    peak = "not estimated (partial slip: the stick zone's edge)" if math.isnan(peak) else f"{peak:.1e}"
    return (f"Estimated error (relative; stepping, grid and model): depth {s['estimated_error_depth']:.1e}, scar "
            f"width {s['estimated_error_width']:.1e}, pressure field {s['estimated_error_pressure']:.1e}, its peak "
            f"{peak} ({stepping}).")


def _limits(s: dict, c) -> str:
    """The wear-limit sentence: which limit was reached and when (cycles, and time at loading.frequency), or how
    near each came."""
    import math
    from fretsim.limits import LIMIT_KEYS
    from fretsim.quantities import shown_unit
    if not c.limits:
        return ""

    def shown(key, v):
        kind, unit, f = LIMIT_KEYS[key]
        return f"{v:.1%}" if kind == "fraction" else f"{v * f:.4g} {shown_unit(unit)}"
    limits = dict(c.limits)
    if s.get("limit_reached") == "crack_initiation":
        return ""  # (the fatigue sentence says it)
    if s.get("limit_reached"):
        key, n = s["limit_reached"], s["cycles_to_limit"]
        err = s.get("estimated_error_cycles_to_limit", float("nan"))
        text = f" Wear limit reached: {key} = {shown(key, limits[key])} at cycle {n:,.0f}"
        if math.isfinite(err):
            text += f" (± {err:.1e} relative)"
        if c.loading.frequency:
            hours = s["time_to_limit_h"]
            text += (f", {hours:,.4g} h at {c.loading.frequency:g} Hz" + (f" ({hours / 8766:.3g} years of continuous "
                                                                  f"fretting)" if hours > 24 * 30 else ""))
        return text + "."
    return f" No wear limit reached within {s['cycles']:,} cycles ({', '.join(f'{k} = {shown(k, v)}' for k, v in limits.items())})."


def _fatigue(s: dict, c) -> str:
    """The fretting-fatigue sentence: when and where a crack starts in each body with constants (or the damage
    reached), and what comes first."""
    if "damage_mode" not in s:
        return ""
    bodies = [(body, m.fatigue) for body, m in (("stationary", c.stationary), ("moving", c.moving))
              if m.fatigue is not None]
    text = ". ".join(_body_fatigue(s, body, f, len(bodies) > 1) for body, f in bodies)
    stopped = s.get("limit_reached") == "crack_initiation"
    whose = {"stationary": "at the flat's crack", "moving": "at the moving body's crack"}.get(s.get("crack_body"), "")
    where = whose if len(bodies) > 1 and whose else "there"
    return f" {text}; damage mode: {s['damage_mode']}" + (f" (the run stopped {where})." if stopped else ".")


def _body_fatigue(s: dict, body: str, f, both: bool) -> str:
    import math
    from fretsim.quantities import keyed
    v = lambda key: s.get(keyed(key, body), float("nan"))  # noqa: E731
    n = v("cycles_to_crack_initiation")
    err = s.get("estimated_error_cycles_to_crack", float("nan")) if body == "stationary" else float("nan")
    err_d = s.get("estimated_error_fatigue_damage", float("nan")) if body == "stationary" else float("nan")
    crit = f.critical_distance
    across = lambda key: (f", y = {v(key) * 1e3:.4g} µm" if math.isfinite(v(key)) else "")  # noqa: E731  (3D)
    where = (f"the largest point SWT {v('swt_max_MPa'):.3g} MPa at x = {v('swt_location_x_mm') * 1e3:.4g} µm"
             f"{across('swt_location_y_mm')}, {v('swt_depth_um'):.3g} µm deep"
             + (f"; the damage counts its mean over the {crit * 1e3:.3g} µm below each surface point" if crit else ""))
    head = "Fretting fatigue" + (f" of the {'flat' if body == 'stationary' else 'moving body'}" if both or
                                 body == "moving" else "")
    if math.isfinite(n):
        return (f"{head}: a crack starts at cycle {n:,.0f}" + (f" (± {err:.1e} relative)" if math.isfinite(err)
                                                               else "")
                + f" at x = {v('crack_location_x_mm') * 1e3:.4g} µm{across('crack_location_y_mm')} ({where})")
    return (f"{head}: no crack within the run (Miner's sum reached {v('fatigue_damage'):.3g} of 1"
            + (f", ± {err_d:.1e} relative" if math.isfinite(err_d) else "") + f"; {where})")


def _said(outcome) -> str:
    """The paragraph after a run, which never turns a run that ended well into a failure: a fault in composing it
    (μ = 0 once divided by δ_t = 0 there, exit 1 after a complete file) is said, and the file stands."""
    try:
        return _paragraph(outcome)
    except Exception as exc:  # noqa: BLE001 - a run's end is no place for a traceback
        click.echo(f"warning: the paragraph about the run could not be composed ({type(exc).__name__}: {exc}); "
                   f"the results file is as the run left it", err=True)
        return (f"{outcome.case.name}: {outcome.status}; results in {outcome.output}; `fretsim summary "
                f"{outcome.output}` shows every number.")


def _paragraph(outcome) -> str:
    s, c, g = outcome.summary, outcome.case, outcome.setup.grid
    cells = f"{g.shape[1]} elements" if g.plane_strain else f"{g.shape[1]} × {g.shape[0]} elements"
    size = f"{g.dx * 1e3:.3g} µm" if g.plane_strain else f"{g.dx * 1e3:.3g} × {g.dy * 1e3:.3g} µm"
    stepping = outcome.setup.stepper.describe(c, s)
    refined = f", contact on a {c.coarse_element[0] * 1e3:.3g} µm coarse grid" if c.coarse_element else ""
    model = outcome.setup.cycle.describe()
    reached = (outcome.last.block + 1) if outcome.last is not None else 0
    blocks = "" if not c.loading.history else f" ({reached} of the loading's {len(c.loading.blocks)} blocks)"
    text = (f"{c.name}: {s['cycles']} cycles{blocks}, {c.dimension.upper()} {c.geometry.kind}, {cells} of {size}{refined}, "
            f"{model}, solver {c.solver}, {stepping}; {s['contact_solves']} contact solves in "
            f"{s['wall_time_s']:.2f} s" + (f" (and {s['grid_error_wall_time_s']:.2f} s for the grid-error companions)"
                                          if s.get("grid_error_wall_time_s", 0) >= 0.005 else "") + ".")
    text += " " + _regime(s, c)
    if s["cycles"] > 0:
        text += (f" Stationary body: centre-line wear depth {s['centre_wear_depth_stationary_um']:.3g} µm "
                 f"(max {s['max_wear_depth_stationary_um']:.3g} µm), scar width {s['scar_width_stationary_mm']:.3g} mm,"
                 f" volume {s['wear_volume_stationary_mm3']:.4g} mm³. Moving body: centre-line "
                 f"{s['centre_wear_depth_moving_um']:.3g} µm (max {s['max_wear_depth_moving_um']:.3g} µm), volume "
                 f"{s['wear_volume_moving_mm3']:.4g} mm³. Volume against its invariant "
                 f"({outcome.setup.cycle.invariant}): {s['archard_volume_error']:.1e}. "
                 + _estimates(s) + _limits(s, c) + _fatigue(s, c))
    else:
        text += f" Contact only: peak pressure {s['max_pressure_MPa']:.4g} MPa."
    return text + f" Results: {outcome.output}"


@main.command()
@click.argument("case_file", type=click.Path(path_type=Path))
@click.option("--set", "overrides", multiple=True, metavar="KEY.PATH=VALUE", help="Override a case value.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def check(case_file: Path, overrides: tuple, debug: bool) -> None:
    """Resolve CASE_FILE without running it: the filled case, the grid, every choice with its reason, the
    stability limit, an estimate of the solves and time, and every warning."""
    import time

    from fretsim.api import check as check_case, load_case

    _not_results(case_file)
    _text_path(case_file, "case file")
    started = time.perf_counter()
    runs, said = _side_runs()
    setup, filled, plan = check_case(load_case(case_file, list(overrides)), runs)
    planning = time.perf_counter() - started
    g = setup.grid
    cells = f"{g.shape[1]} elements of {g.dx * 1e3:.4g} µm" if g.plane_strain else \
        f"{g.shape[1]} × {g.shape[0]} elements of {g.dx * 1e3:.4g} × {g.dy * 1e3:.4g} µm"
    loading = filled.loading
    click.echo(f"{filled.name}: {loading.cycles} cycles, {filled.dimension.upper()} {filled.geometry.kind}, {cells}")
    from fretsim.reference import effective_modulus
    e_star = effective_modulus(filled.moving.youngs_modulus, filled.moving.poissons_ratio,
                               filled.stationary.youngs_modulus, filled.stationary.poissons_ratio)
    h = filled.geometry.hertz(loading.peak_load, e_star)
    click.echo(f"unworn contact (Hertz): peak pressure p0 = {h.peak_pressure:.4g} MPa, half-width a = "
               f"{h.half_width_x * 1e3:.4g} µm" + ("" if h.line else f" × {h.half_width_y * 1e3:.4g} µm")
               + f", E* = {e_star / 1e3:.4g} GPa")
    click.echo(f"explicit stability limit: {setup.stability_limit:.4g} cycles (solve grid, gap model {filled.gap_model})")
    if loading.friction_coefficient is not None:
        click.echo(_check_regime(setup, loading))
    for f in setup.fatigue_specs:
        line = "line method over " + f"{f.critical_distance * 1e3:.3g} µm" if f.critical_distance else "point values"
        whose = "the flat's" if f.body == "stationary" else "the moving body's (its own half-space)"
        click.echo(f"fretting fatigue: {whose} SWT on the critical plane ({line}) at {len(f.states)} fatigue "
                   f"states, {len(f.depths)} depths to {f.depths[-1] * 1e3:.3g} µm; Miner's sum over the wear history"
                   + ("; the run stops where it reaches 1" if f.crack_limit else ""))
    from fretsim.runner import estimate
    cost = estimate(setup, filled, runs)
    total = cost["run_s"] + cost["companions_s"] + (planning if planning > 1.0 else 0.0)
    click.echo(f"estimate: about {cost['solves']} contact solves, {_duration(cost['run_s'])} for the run "
               f"(jumping.tolerance {filled.step_tolerance:g})"
               + (f"; its grid-error companions ({cost['companions']} run{'s' if cost['companions'] > 1 else ''} "
                  f"on coarser grids) about "
                  f"{_duration(cost['companions_s'])} more" if cost["companions"] else "")
               + (f"; planning took {_duration(planning)} here ({_planning_runs(said)}), which a run repeats"
                  if planning > 1.0 else "") + f": about {_duration(total)} in all")
    click.echo("choices:")
    width = max(len(c.key) for c in plan.choices)
    for c in plan.choices:
        click.echo(f"  {c.key:<{width}}  {_show(c.value)}  ({c.reason})")
    for w in plan.warnings:
        click.echo(f"warning: {w}")
    click.echo("filled case (numbers to 6 significant digits; a results file's /case holds them exactly):")
    click.echo("  " + _rounded(filled.to_yaml()).rstrip().replace("\n", "\n  "))


def _points_of_sweeps(paths: tuple) -> tuple:
    """A sweep's directory stands for its points' results files, in its table's order (as `plot DIR` draws it)."""
    from fretsim.results import read_sweep_table
    out: list = []
    for path in paths:
        if Path(path).is_dir() and (Path(path) / "table.csv").exists():
            table = read_sweep_table(path)
            out.extend(Path(path) / "points" / f"{row['point']}.h5" for row in table.rows)
        else:
            out.append(path)
    return tuple(out)


def _planning_runs(said: list) -> str:
    proxies = sum(w.startswith("model.") for w in said)
    pilot = any(w.startswith("wear limits") for w in said)
    runs = ([f"auto's {proxies} proxy run{'s' if proxies > 1 else ''}"] if proxies else []) + \
        (["a pilot run for the wear limits"] if pilot else [])
    return " and ".join(runs) or "sizing the grid"


def _rounded(text: str) -> str:
    """A YAML text's numbers (a value, or a list item, alone or with its unit) to 6 significant digits:
    3.0000000000000004e-08 is 3e-08 to a reader.  Names and paths are left as written."""
    import re

    def shorter(m) -> str:
        number = m.group(2)
        short = f"{float(number):.6g}"
        return m.group(1) + (number if "e" in short and "e" not in number else short) + m.group(3)
    return re.sub(r"(?m)^(\s*(?:[\w.]+: |- )(?:- )?)(-?\d+\.\d+(?:e[-+]?\d+)?)((?: [^\s:]+)?)$", shorter, text)


def _show(value) -> str:
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


@main.command()
@click.argument("results_files", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="Machine-readable output (strict JSON; null for NaN).")
@click.option("--csv", "as_csv", is_flag=True, help="One CSV row per file: inputs and summary figures.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def summary(results_files: tuple, as_json: bool, as_csv: bool, debug: bool) -> None:
    """Print the summary figures of RESULTS_FILES (the /summary attributes), with the inputs of each run; a
    sweep's directory stands for its points."""
    import json

    from fretsim.results import summary_json

    if as_json and as_csv:
        raise Fail("--json and --csv are two formats of the same figures; choose one")
    results_files = _points_of_sweeps(results_files)
    rows, bad = [], []
    for path in results_files:
        try:
            rows.append(summary_json(_read_results(path, "summary")))
        except ResultsFileError as exc:
            if len(results_files) == 1:
                raise
            bad.append(str(exc))
            rows.append({"path": str(path), "status": "unreadable", "message": str(exc)})
    if as_json:
        click.echo(json.dumps(rows[0] if len(rows) == 1 else rows, indent=2, allow_nan=False))
    elif as_csv:
        import csv
        def inputs(r):  # each input with a column of its unit beside it (the names users' scripts read stay)
            out = {}
            for k, v in r.get("inputs", {}).items():
                out[f"input_{k}"] = v
                unit = r.get("input_units", {}).get(k)
                if unit and unit != "1":
                    out[f"input_{k}_units"] = unit
            return out
        flat = [{**{k: v for k, v in r.items() if not isinstance(v, (dict, list))}, **inputs(r),
                 "overrides": " ".join(r.get("overrides", []))} for r in rows]
        keys = list(dict.fromkeys(k for r in flat for k in r))
        w = csv.DictWriter(sys.stdout, fieldnames=keys)
        w.writeheader()
        w.writerows(flat)
    else:
        for r in rows:
            data = {k: v for k, v in r.items() if not isinstance(v, (dict, list))}
            width = max(len(k) for k in data)
            for k, v in data.items():
                click.echo(f"{k:<{width}}  {_summary_value(k, v, r)}")
            if r.get("inputs"):
                click.echo("inputs  " + ", ".join(f"{k} {f'{v:.6g}' if isinstance(v, float) else v}"
                                                  f"{' ' + r['input_units'][k] if r['input_units'].get(k) and r['input_units'][k] != '1' else ''}"
                                                  for k, v in r["inputs"].items()))
            if r.get("overrides"):
                click.echo("overrides  " + " ".join(r["overrides"]))
            if len(rows) > 1:
                click.echo("")
    if bad:
        for b in bad:
            click.echo(f"fretsim: {b}", err=True)
        sys.exit(EXIT_BAD_INPUT)


@main.command()
@click.argument("results_files", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("-o", "--outdir", type=click.Path(file_okay=False, path_type=Path),
              help="Directory for the figures (default: next to RESULTS_FILE, or in a sweep's directory).")
@click.option("--format", "fmt", type=click.Choice(["png", "pdf", "svg"]), default="png", show_default=True)
@click.option("--dpi", type=click.IntRange(50, 1200), default=150, show_default=True)
@click.option("--log", "log_cycles", is_flag=True, help="Logarithmic cycle axis for the histories.")
@click.option("--jobs", type=click.IntRange(1, 2), default=None,
              help="Processes rendering the figures: 2 on a machine with 2 or more cores (default), else 1.")
@click.option("--expected", is_flag=True,
              help="Overlay each case's published values (its `expected:` data: experiment, FEA, the paper).")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def plot(results_files: tuple, outdir: Path | None, fmt: str, dpi: int, log_cycles: bool, jobs: int | None,
         expected: bool, debug: bool) -> None:
    """Write figures of RESULTS_FILE: wear profiles across and along the contact, wear and pressure maps,
    pressure profiles with the initial Hertz solution, depth and volume against cycles.  Given several files
    (or --expected): one overlay.png of their worn profiles and depth histories on common axes, each run labelled
    by the values that differ between the runs.  Given a sweep's directory: response curves, each output against
    each swept axis, one line per value of the others; for a sweep over loading.normal_load and loading.stroke
    with a friction coefficient, in their place the fretting map (regime and wear over load × stroke, with δ_t),
    the energy per cycle against stroke and chosen points' fretting loops; for a sampled sweep, the depth band
    (P10–P90, P50) and the histogram of the time to the wear limit with its P10, P50 and P90."""
    if len(results_files) > 1 or expected:
        if any(p.is_dir() for p in results_files):
            raise Fail("overlaying takes results files, not a sweep's directory (plot that alone)")
        runs = [_read_results(p, "plot") for p in results_files]
        from fretsim.plotting import plot_overlay, run_status
        for p, res in zip(results_files, runs):
            if run_status(res):  # drawn as far as it got, and marked so in the legend
                click.echo(f"note: {p}: {run_status(res)}; drawn as far as it got", err=True)
        _write_and_list(lambda: plot_overlay(runs, outdir or results_files[0].parent, expected, fmt, dpi),
                        "the overlay")
        return
    results_file = results_files[0]

    if results_file.is_dir():
        from fretsim.results import read_sweep_table
        table = read_sweep_table(results_file)
        from fretsim.plotting import plot_sweep
        _write_and_list(lambda: plot_sweep(table, outdir or results_file, fmt=fmt, dpi=dpi), "figures")
        return

    res = _read_results(results_file, "plot")
    from fretsim.plotting import plot_all, skipped
    for why in skipped(res):
        click.echo(f"note: {why}", err=True)
    jobs = jobs or (2 if (os.cpu_count() or 1) > 1 else 1)
    _write_and_list(lambda: plot_all(res, outdir or results_file.parent, fmt=fmt, dpi=dpi, log_cycles=log_cycles,
                                     jobs=jobs), "figures")


def _write_and_list(write, what: str) -> None:
    """Run a writer of files and print their paths; a refusing disk is exit 5, naming what could not be written."""
    try:
        paths = write()
    except OSError as exc:
        raise Fail(f"cannot write {what}: {exc.strerror or exc}", EXIT_IO) from None
    for p in paths:
        click.echo(str(p))


@main.command()
@click.argument("results_file", type=click.Path(path_type=Path))
@click.option("--csv", "csv_dir", required=True, type=click.Path(file_okay=False, path_type=Path),
              help="Directory for history.csv, summary.csv, inputs.csv and fields.csv.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def export(results_file: Path, csv_dir: Path, debug: bool) -> None:
    """Write RESULTS_FILE as CSV files for spreadsheets (units in the column names); a sweep's directory writes
    each of its points' into a directory of the point's name (its table.csv already has one row per point)."""
    from fretsim.export import export_csv

    points = _points_of_sweeps((results_file,))
    if points == (results_file,):
        res = _read_results(results_file, "export")
        _write_and_list(lambda: export_csv(res, csv_dir), str(csv_dir))
        return
    for point in points:  # each read (and checked) before its files are written, as for one file
        res = _read_results(point, "export")
        _write_and_list(lambda: export_csv(res, csv_dir / point.stem), str(csv_dir / point.stem))


def _not_an_input(output: Path, inputs: dict) -> None:
    """Refuse an output that is one of the command's inputs, by path or by inode (a hard link, a symbolic link
    to it): writing it would replace what the command read, and the next run would read the replacement."""
    for what, path in inputs.items():
        same = os.path.abspath(output) == os.path.abspath(path)
        try:
            same = same or os.path.samefile(output, path)
        except OSError:  # one of them does not exist (yet): then they are not one file
            pass
        if same:
            raise Fail(f"-o {output} is the {what} this fit reads ({path}); writing the fitted case there would "
                       f"replace it: choose another name for the fitted case")


@main.command()
@click.argument("case_file", type=click.Path(path_type=Path))
@click.option("--measured", "measured_file", required=True, type=click.Path(path_type=Path),
              help="CSV of measured wear at given cycles: `cycle [cycles],max_wear_depth_stationary [um],…` (any "
                   "wear-limit quantity), or profiles: `cycle [cycles],x [mm],wear_depth_stationary [um]`.")
@click.option("--fit", "fit_keys", multiple=True, metavar="KEY.PATH",
              help="A case value to fit (repeatable); default: both wear coefficients.")
@click.option("--set", "overrides", multiple=True, metavar="KEY.PATH=VALUE", help="Override a case value.")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="Write the case with the fitted values to this file.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def fit(case_file: Path, measured_file: Path, fit_keys: tuple, overrides: tuple, output: Path | None,
        debug: bool) -> None:
    """Fit case values (both wear coefficients by default) to measured wear by bounded least squares over runs
    of CASE_FILE; print them with 95 % confidence intervals and the residuals.  Exit 3, and -o not written, where
    there is no fit: a value at the edge of the search, or one the data do not determine."""
    import numpy as np

    from fretsim.fit import DEFAULT_FIT, fit as fit_case, fitted_case_text, read_measured, shown
    from fretsim.units import INTERNAL
    from fretsim.yamlread import read_text

    if output is not None:
        _not_an_input(output, {"case file": case_file, "measured file": measured_file})
    try:
        _not_results(Path(case_file))  # a results file where the case goes: say what it is
        text = read_text(case_file, "case file")
    except (OSError, ValueError) as exc:  # not a write: the boundary's OSError would say "cannot write", exit 5
        raise Fail(f"{case_file}: {exc}") from None
    measured = read_measured(measured_file)
    for note in measured.notes:
        click.echo(f"note: {note}", err=True)
    click.echo(f"fitting {', '.join(fit_keys or DEFAULT_FIT)} to {measured.values.size} measured value(s) of "
               f"{measured_file}", err=True)
    live = sys.stderr.isatty()  # a counter rewritten in place; off a terminal (a sweep's log) the total only
    try:
        res = fit_case(text, str(case_file), measured, fit_keys or DEFAULT_FIT, overrides,
                       progress=(lambda n: click.echo(f"\r  {n} runs", nl=False, err=True)) if live else None,
                       note=lambda text: click.echo(("\n" if live else "") + f"note: {text}", err=True))
    except RuntimeError as exc:
        raise Fail(f"the fit stopped: {exc}", 3) from None
    if live:
        click.echo("", err=True)
    for note in res.notes:
        click.echo(f"note: {note}", err=True)
    for k, v0, v, lo, hi, kind in zip(res.keys, res.start, res.values, res.low, res.high, res.kinds):
        def short(x):
            return f"{x:.4g}" + ("" if kind == "number" else f" {INTERNAL[kind]}")
        ci = f"95 % CI [{short(lo)}, {short(hi)}]" if np.isfinite(lo) else "no CI"
        click.echo(f"{k} = {short(v)}  ({ci}; started at {short(v0)})")
    said = res.message if res.converged and (res.dof <= 0 or "determine" in res.message) else ""
    click.echo(f"{res.runs} runs, {res.dof} degree(s) of freedom. " + said)
    click.echo("residuals (model/measured − 1; a profile's against its deepest point):")
    for n, key, x, meas, mod, r in zip(measured.cycles, measured.keys, measured.x, measured.values, res.model,
                                       res.residuals):
        where = f" at x = {x:.4g} mm" if np.isfinite(x) else ""
        click.echo(f"  cycle {n:>10,}  {key}{where}: measured {shown(meas, key, measured)}, model "
                   f"{shown(mod, key, measured)}, {r:+.2%}")
    for warning in res.warnings:
        click.echo(f"warning: {warning}", err=True)
    unwritten = f"; {output} was not written" if output else ""
    if not res.converged:  # values at the edge of the search are not a fit: no fitted case, and a failing exit
        raise Fail(f"the fit did not converge: {res.message}{unwritten}", 3)
    if not res.determined:  # printed values the data would fit as well with others: not a fit either
        raise Fail(f"the data do not determine {', '.join(res.undetermined)} (above){unwritten}", 3)
    if output is not None:
        tmp = output.with_name(f".{output.name}.part")
        try:
            tmp.write_text(fitted_case_text(text, res), encoding="utf-8")
            os.replace(tmp, output)
        finally:
            if tmp.exists():
                tmp.unlink()
        click.echo(f"fitted case: {output}")


class _InitCommand(click.Command):
    """`init --help` lists what it accepts, read when asked (not at start-up, which every sweep point pays)."""

    def format_epilog(self, ctx, formatter):
        from fretsim.templates import GEOMETRY_KEYS, shipped
        with formatter.section("Shipped cases"):
            formatter.write_text(", ".join(shipped()))
        with formatter.section("Geometry templates"):
            formatter.write_text(", ".join(GEOMETRY_KEYS))


def _complete_kind(ctx, param, incomplete):
    from fretsim.templates import available
    return [k for k in available() if k.startswith(incomplete)]


@main.command(cls=_InitCommand)
@click.argument("kind", required=False, default="mccoll_185N", shell_complete=_complete_kind)
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="Where to write the case (default: KIND.yaml in the current directory).")
@_boundary
def init(kind: str, output: Path | None) -> None:
    """Write a case to start from: a shipped case by name (e.g. mccoll_185N) or a commented template of a
    geometry (e.g. ball_on_flat).  `fretsim init --help` lists both."""
    from fretsim.templates import available, template_text

    names = available()
    if kind not in names:
        import difflib
        hint = difflib.get_close_matches(kind, names, n=1)
        raise Fail(f"unknown case or geometry {kind!r}" + (f" (did you mean {hint[0]!r}?)" if hint else "")
                   + f"; choose one of {', '.join(names)}")
    output = output or Path(f"{kind}.yaml")
    if output.exists():
        raise Fail(f"{output} exists; choose another -o")
    output.write_text(template_text(kind))
    click.echo(str(output))


@main.command()
@click.argument("cases", nargs=-1)
@click.option("-o", "--outdir", type=click.Path(file_okay=False, path_type=Path), default=Path("validation"),
              show_default=True, help="Directory for report.md and its figures.")
@click.option("--jobs", type=click.IntRange(0, 256), default=0, help="Parallel runs; 0 (the default): the number of cores.")
@click.option("--quick", is_flag=True, help="Line contacts in 2D and point contacts short: the check in a minute.")
@click.option("--friction", is_flag=True, help="Add McColl's cases under the FE model's friction (μ 0.9) and bodies, "
              "uniform, mid-stroke and resolved (2D and 3D: several minutes more).")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def validate(cases: tuple, outdir: Path, jobs: int, quick: bool, friction: bool, debug: bool) -> None:
    """Run the published cases of the paper (default: every shipped case with expected values) and write a
    report against experiment, FEA and the paper.  Exit 0 when every case runs."""
    from fretsim.validate import shipped_with_expected, validate as run_validation

    names = list(cases) or shipped_with_expected()
    unknown = [n for n in names if n not in shipped_with_expected()]
    if unknown:
        raise Fail(f"no shipped case with expected values named {', '.join(unknown)}; choose from "
                   f"{', '.join(shipped_with_expected())}")
    out = run_validation(names, outdir, jobs, quick, friction=friction)
    click.echo(f"{len(out['results'])} runs; report: {out['report']}")
    if not out["ok"]:
        raise Fail("some cases did not complete: see the report", EXIT_FAILED)


@main.command()
@click.argument("sweep_file", type=click.Path(path_type=Path))
@click.option("-o", "--outdir", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Directory for the points' results files and the table.")
@click.option("--jobs", type=click.IntRange(0, 1024), default=0, help="Local worker processes; 0 (the default): the number of cores.")
@click.option("--dask", "dask_address", metavar="tcp://HOST:PORT", help="Run the points on this Dask scheduler.")
@click.option("--overwrite", is_flag=True, help="Run every point again, complete ones too.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@_boundary
def sweep(sweep_file: Path, outdir: Path, jobs: int, dask_address: str | None, overwrite: bool, debug: bool) -> None:
    """Run every point of SWEEP_FILE (long-lived workers, or a Dask cluster) and write one table.

    Re-running skips complete points and resumes interrupted ones.  Exit 0 when every point completed, 3 when
    some failed or were refused (see DIR/table.csv), 2 for a bad sweep file, 5 when the disk refused a point's
    results or the table, 130 interrupted."""
    from fretsim.sweep import load_sweep, run_sweep  # (one BLAS thread per worker: set at the module's top)

    if dask_address:
        from fretsim.sweep import check_dask_address
        check_dask_address(dask_address)  # before seconds of checking points

    def _checking(done, total):  # a large sweep takes seconds to check: say so
        click.echo(f"checking the sweep's points: {done} of {total}", err=True)
    if _is_hdf5(Path(sweep_file)):  # a sweep's table.h5 or a run's results: not a sweep file
        raise Fail(f"{sweep_file} is an HDF5 file (a results file or a sweep's table), not a sweep file (YAML): "
                   f"`fretsim plot` and `fretsim summary` read it; a sweep file lists base, set and axes")
    spec = load_sweep(sweep_file, progress=_checking)
    failures = {"n": 0}
    bar = None
    if sys.stderr.isatty():
        bar = click.progressbar(length=len(spec.points), label="points", file=sys.stderr,
                                item_show_func=lambda _: f"{failures['n']} failed" if failures["n"] else "")
        bar.__enter__()

    def _progress(row):
        if row["status"] != "complete":
            failures["n"] += 1
        if bar is not None:
            bar.update(1)

    def _terminate(signum, frame):  # SIGTERM ends a sweep as Ctrl-C does: points interrupted, the table written
        raise KeyboardInterrupt
    import signal
    import threading
    if threading.current_thread() is threading.main_thread():  # (a sweep started from a thread cannot)
        signal.signal(signal.SIGTERM, _terminate)
    try:
        out = run_sweep(spec, outdir, jobs, dask_address, overwrite, _progress)
    except KeyboardInterrupt:
        raise Fail(f"interrupted; the points done so far are in {outdir} and its table; run the same command again "
                   f"to continue", EXIT_INTERRUPTED) from None
    except OSError as exc:  # the table (or the directory): the points' own files say how far each got
        import errno
        where = f" {exc.filename}" if exc.filename else ""
        when = " once there is room" if exc.errno in (errno.ENOSPC, errno.EDQUOT) else ""
        raise Fail(f"cannot write{where}: {exc.strerror or exc}; the points written so far are kept in {outdir}; "
                   f"run the same command again{when}", EXIT_IO) from None
    finally:
        if bar is not None:
            bar.__exit__(None, None, None)
    counts = ", ".join(f"{n} {s}" for s, n in sorted(out.counts.items()))
    click.echo(f"{len(out.rows)} points: {counts}. Table: {out.table_csv}, {out.table_h5}")
    refused = out.counts.get("io_error", 0)
    if refused:  # as for a run: the disk, not the model, stopped them, and a re-run resumes them
        raise Fail(f"{refused} point(s) could not write their results (see {out.table_csv}); run the same command "
                   f"again once there is room", EXIT_IO)
    if not out.all_complete:
        raise Fail(f"not every point completed: see {out.table_csv}", EXIT_FAILED)


@main.command("case-reference")
def case_reference() -> None:
    """Print every case key with its unit, default and meaning (Markdown), from the parser's own schema."""
    from fretsim.templates import case_reference_markdown
    click.echo(case_reference_markdown(), nl=False)


if __name__ == "__main__":
    main()
