"""`fretsim` command line: run, summary, plot.  No algorithm here: it wraps :mod:`fretsim.api`.

Exit codes: 0 complete, 2 bad input (case, options, files), 3 a run that failed numerically or outgrew its grid,
4 a run stopped at a physical limit (a body worn through), 130 interrupted (resume with --resume).
"""
from __future__ import annotations

import json
import sys
import traceback
from pathlib import Path

import click

EXIT_BAD_INPUT = 2
EXIT_FAILED = 3
EXIT_STOPPED = 4
EXIT_INTERRUPTED = 130


def _fail(message: str, code: int, debug: bool) -> None:
    if debug:
        traceback.print_exc()
    click.echo(f"fretsim: {message}", err=True)
    sys.exit(code)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="fretsim")
def main() -> None:
    """Fretting-wear simulation after Kong, Bennett & Hyde: YAML case → HDF5 results → PNG plots."""


@main.command()
@click.argument("case_file", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="Results file (default: CASE_FILE's name with .h5, in the current directory).")
@click.option("--set", "overrides", multiple=True, metavar="KEY.PATH=VALUE",
              help="Override a case value, e.g. --set loading.cycles=1000 (repeatable).")
@click.option("--overwrite", is_flag=True, help="Replace an existing results file.")
@click.option("--resume", "resume_file", type=click.Path(dir_okay=False, path_type=Path),
              help="Continue an interrupted run from its results file (no CASE_FILE then).")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
def run(case_file: Path | None, output: Path | None, overrides: tuple, overwrite: bool, resume_file: Path | None,
        debug: bool) -> None:
    """Run CASE_FILE and write an HDF5 results file (or --resume one)."""
    import signal

    from fretsim.api import CaseError, load_case, resume as resume_run, run as run_case

    if resume_file is not None and (case_file is not None or overrides or output is not None):
        _fail("--resume takes the results file alone: the case, grid and settings are the ones stored in it",
              EXIT_BAD_INPUT, debug)
    if resume_file is None and case_file is None:
        _fail("give a CASE_FILE to run, or --resume RESULTS_FILE", EXIT_BAD_INPUT, debug)
    output = resume_file or output or Path(case_file.stem + ".h5")

    def _terminate(signum, frame):  # SIGTERM ends a run as cleanly as Ctrl-C
        raise KeyboardInterrupt

    previous_handler = signal.signal(signal.SIGTERM, _terminate)
    try:
        if resume_file is not None:
            total, start = None, 0
        else:
            case = load_case(case_file, list(overrides))
            total, start = case.cycles, 0
        bar = None
        if sys.stderr.isatty() and total:
            bar = click.progressbar(length=total, label="fretsim", file=sys.stderr, show_eta=True)
            bar.__enter__()
            bar.update(start)
        try:
            if resume_file is not None:
                outcome = resume_run(resume_file, progress=bar.update if bar else None)
            else:
                outcome = run_case(case, output, overwrite=overwrite, progress=bar.update if bar else None)
        finally:
            if bar is not None:
                bar.__exit__(None, None, None)
    except CaseError as exc:
        _fail(str(exc), EXIT_BAD_INPUT, debug)
    except ValueError as exc:  # an unreadable results file for --resume
        _fail(str(exc), EXIT_BAD_INPUT, debug)
    except KeyboardInterrupt:
        _fail(f"interrupted; every accepted step so far is in {output} (status 'interrupted'); continue with "
              f"`fretsim run --resume {output}`", EXIT_INTERRUPTED, debug)
    except OSError as exc:
        _fail(f"cannot write {output}: {exc}", EXIT_BAD_INPUT, debug)
    finally:
        signal.signal(signal.SIGTERM, previous_handler)
    for note in outcome.notes:
        click.echo(f"note: {note}", err=True)
    if outcome.status == "stopped":
        click.echo(_paragraph(outcome))
        _fail(f"stopped at a physical limit: {outcome.message}", EXIT_STOPPED, debug)
    if outcome.status != "complete":
        _fail(f"run failed: {outcome.message}" + (f"; steps up to the failure are in {output} (status 'failed')"
                                                  if outcome.last is not None else ""), EXIT_FAILED, debug)
    click.echo(_paragraph(outcome))


def _paragraph(outcome) -> str:
    s, c, g = outcome.summary, outcome.case, outcome.setup.grid
    cells = f"{g.shape[1]} elements" if g.plane_strain else f"{g.shape[1]} × {g.shape[0]} elements"
    size = f"{g.dx * 1e3:.3g} µm" if g.plane_strain else f"{g.dx * 1e3:.3g} × {g.dy * 1e3:.3g} µm"
    stepping = {
        "bdf2": f"BDF2 steps (tolerance {c.step_tolerance:g})",
        "implicit": f"backward-Euler steps (tolerance {c.step_tolerance:g})",
        "linear": f"linear jump {s['linear_jump']} cycles (stability limit {s['stability_limit_linear']:.3g})",
        "adaptive": f"adaptive jumps (η {c.eta:g}, ΔN_max {c.max_jump}, ΔN_L {s['linear_jump']})",
    }[c.scheme]
    refined = f", contact on a {c.coarse_element[0] * 1e3:.3g} µm coarse grid" if c.coarse_element else ""
    text = (f"{c.name}: {s['cycles']} cycles, {c.dimension.upper()} {c.geometry.kind}, {cells} of {size}{refined}, "
            f"gap model {c.gap_model}, solver {c.solver}, {stepping}; {s['contact_solves']} contact solves in "
            f"{s['wall_time_s']:.2f} s.")
    if s["cycles"] > 0:
        text += (f" Stationary body: centre-line wear depth {s['centre_wear_depth_stationary_um']:.3g} µm "
                 f"(max {s['max_wear_depth_stationary_um']:.3g} µm), scar width {s['scar_width_stationary_mm']:.3g} mm,"
                 f" volume {s['wear_volume_stationary_mm3']:.4g} mm³. Moving body: centre-line "
                 f"{s['centre_wear_depth_moving_um']:.3g} µm (max {s['max_wear_depth_moving_um']:.3g} µm), volume "
                 f"{s['wear_volume_moving_mm3']:.4g} mm³. Archard volume error {s['archard_volume_error']:.1e}; "
                 f"estimated error at the recorded states: depth {s['error_estimate_depth']:.1e}, pressure "
                 f"{s['error_estimate_pressure']:.1e} (relative).")
    else:
        text += f" Contact only: peak pressure {s['max_pressure_MPa']:.4g} MPa."
    return text + f" Results: {outcome.output}"


@main.command()
@click.argument("case_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--set", "overrides", multiple=True, metavar="KEY.PATH=VALUE", help="Override a case value.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
def check(case_file: Path, overrides: tuple, debug: bool) -> None:
    """Resolve CASE_FILE without running it: the filled case, the grid, every choice with its reason, the
    stability limit, an estimate of the solves and time, and every warning."""
    from fretsim.api import CaseError, check as check_case, load_case

    try:
        case = load_case(case_file, list(overrides))
        setup, filled, plan = check_case(case)
    except CaseError as exc:
        _fail(str(exc), EXIT_BAD_INPUT, debug)
    g = setup.grid
    cells = f"{g.shape[1]} elements of {g.dx * 1e3:.4g} µm" if g.plane_strain else \
        f"{g.shape[1]} × {g.shape[0]} elements of {g.dx * 1e3:.4g} × {g.dy * 1e3:.4g} µm"
    click.echo(f"{filled.name}: {filled.cycles} cycles, {filled.dimension.upper()} {filled.geometry.kind}, {cells}")
    click.echo(f"explicit stability limit: {setup.stability_limit:.4g} cycles (solve grid, gap model {setup.gap_model})")
    est = estimate_cost(setup)
    click.echo(f"estimate: about {est[0]} contact solves, {est[1]:.2g} s")
    click.echo("choices:")
    width = max(len(c.key) for c in plan.choices)
    for c in plan.choices:
        click.echo(f"  {c.key:<{width}}  {_show(c.value)}  ({c.reason})")
    for w in plan.warnings:
        click.echo(f"warning: {w}")
    click.echo("filled case:")
    click.echo("  " + filled.to_yaml().rstrip().replace("\n", "\n  "))


def estimate_cost(setup) -> tuple[int, float]:
    """(solves, seconds) before a run: solves from the scheme, seconds from one timed contact solve."""
    import math
    import time

    from fretsim.solvers import solve
    n = setup.cycles
    if n == 0:
        solves = 1
    elif setup.scheme in ("bdf2", "implicit"):
        # measured: ~25 solves per decade of cycles after the first, ~8 per recorded state landed on
        solves = int(10 + 25 * math.log10(max(n, 10)) + 8 * len(setup.snapshots))
        solves = min(solves, n + 1)
    elif setup.scheme == "linear":
        solves = n // setup.linear_jump + len(setup.snapshots) + 1
    else:
        solves = int(n / (setup.linear_jump * 6 + 300)) * 6 + len(setup.snapshots) + 10
    op = setup.coarse_compliance or setup.compliance
    gap = setup.coarse_gap if setup.coarse_gap is not None else setup.gap
    t = time.perf_counter()
    solve(op, gap, setup.load, method=setup.method, tol=setup.tolerance)
    cold = time.perf_counter() - t
    return solves, solves * cold * 0.6  # warm-started solves take about 60 % of a cold one (measured)


def _show(value) -> str:
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


@main.command()
@click.argument("results_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="Machine-readable output for sweeps.")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
def summary(results_file: Path, as_json: bool, debug: bool) -> None:
    """Print the summary figures of RESULTS_FILE (the /summary attributes)."""
    from fretsim.results import read_results

    try:
        res = read_results(results_file)
    except ValueError as exc:
        _fail(str(exc), EXIT_BAD_INPUT, debug)
    data = {"status": res.status, "case_name": res.attrs.get("case_name"), **res.summary}
    if as_json:
        click.echo(json.dumps(data, indent=2, sort_keys=False))
    else:
        width = max(len(k) for k in data)
        for k, v in data.items():
            click.echo(f"{k:<{width}}  {v:.6g}" if isinstance(v, float) else f"{k:<{width}}  {v}")


@main.command()
@click.argument("results_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--outdir", type=click.Path(file_okay=False, path_type=Path),
              help="Directory for the PNGs (default: next to RESULTS_FILE).")
@click.option("--debug", is_flag=True, help="Show tracebacks.")
def plot(results_file: Path, outdir: Path | None, debug: bool) -> None:
    """Write PNG figures of RESULTS_FILE: wear profiles, wear maps, max wear vs cycles, pressure profiles."""
    from fretsim.plotting import plot_all
    from fretsim.results import read_results

    try:
        res = read_results(results_file)
        paths = plot_all(res, outdir or results_file.parent)
    except ValueError as exc:
        _fail(str(exc), EXIT_BAD_INPUT, debug)
    except OSError as exc:
        _fail(f"cannot write plots: {exc}", EXIT_BAD_INPUT, debug)
    for p in paths:
        click.echo(str(p))


if __name__ == "__main__":
    main()
