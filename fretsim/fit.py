"""Case values fitted to measured wear: bounded least squares over runs of the case.

Wear coefficients scatter by a factor of two or more between tests and are themselves fitted to tests.  Given a
case and measurements at given cycles (a CSV laid out like the history ``fretsim export`` writes:
``cycle [cycles],max_wear_depth_stationary [um],…``; any of the wear-limit quantities of :mod:`fretsim.limits`,
or whole profiles: ``cycle [cycles],x [mm],wear_depth_stationary [um]``), the chosen case values (both wear
coefficients by default) are found that make the runs reproduce them best.

The residuals are relative (model/measured − 1; a profile's against its deepest measured point), so depths,
widths and volumes weigh alike.  Positive values are fitted in logarithms (a wear coefficient is known to a
factor, not to a difference), within a factor of 1000 of the case's value.  The confidence intervals are the
usual linearised ones: the Jacobian at the optimum, the residuals' variance over the degrees of freedom, and
Student's t at 95 %; with as many values as data there are none, and the result says so.  The runs use the
case's stepping at a tolerance of at most 1e-3, so that the finite differences (5 % in each value) are not
stepping noise, on one grid and with one model throughout (those the case chooses at its starting values; the
flat's wear through the stroke-averaged gap unless the case names one, since the paper's mid-stroke gap is
unstable for some coefficients a search may try).  An automatic grid is widened (same elements, a wider domain)
and the search started again from the trial whose scar reached its edge; measured values that no run of the search
can come near (a unit slip) are refused before any run.
"""
from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from fretsim.case import LIMITS_SCHEMA, SCHEMA, Case, CaseError, Key, parse_case
from fretsim.limits import LIMIT_KEYS
from fretsim.quantities import shown_unit
from fretsim.simulate import SimulationError
from fretsim.units import UnitError, format_quantity, parse_quantity
from fretsim.sizing import _odd
from fretsim.yamlread import read_text

DEFAULT_FIT = ("materials.moving.wear_coefficient", "materials.stationary.wear_coefficient")
WEAR_KINDS = ("wear_coefficient", "energy_wear_coefficient")  # the values whose top of the search wears most
PROFILES = {"wear_depth_moving": "moving", "wear_depth_stationary": "stationary"}
FIT_TOLERANCE = 1e-3  # jumping.tolerance of the fit's runs, at most
DIFF_STEP = 0.05  # the finite differences' step: 5 % of each value (ln 1.05 in its logarithm)
RANGE = 1000.0  # a value is sought within this factor of the case's
MAX_GROWTH = 6  # the fit's grid is widened at most this many times (each at least doubles the domain)
GROWTH_MARGIN = 4.0  # a grown grid holds the wear of the trial that outgrew it with its coefficients this much larger
GRID_EDGE = "edge of the grid"  # in the message of a run whose contact reached it (fretsim.loop.checks.check_edges)


class _Outgrown(Exception):
    """A trial's contact reached the edge of the fit's grid (``logs``: the trial's ln values)."""

    def __init__(self, logs):
        super().__init__("outgrown")
        self.logs = logs
MAX_ROWS = 10_000  # rows of measurements: an exported history of a long run has a few hundred
_HEADER = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\[\s*([^\]]*)\s*\])?\s*$")


@dataclass
class Measured:
    source: str
    cycles: np.ndarray  # per datum
    keys: list  # per datum: a limit quantity, or a profile name
    values: np.ndarray  # per datum, internal units
    x: np.ndarray  # per datum: the profile's x (mm), NaN for a scalar
    units: dict = field(default_factory=dict)  # column → unit as written
    notes: list = field(default_factory=list)  # what was read but not fitted, for the user to see
    rows: list = field(default_factory=list)  # per datum: its row in the file's data, as messages number them


def _spec(key: str) -> Key:
    parts = key.split(".")
    if len(parts) == 3 and parts[0] == "materials" and parts[1] in ("moving", "stationary"):
        spec = SCHEMA["material"].get(parts[2])
    elif len(parts) == 2 and parts[0] in SCHEMA:
        spec = SCHEMA[parts[0]].get(parts[1])
    else:
        spec = None
    if spec is None or spec.kind not in ("wear_coefficient", "energy_wear_coefficient", "number", "force", "length",
                                         "pressure", "stiffness"):
        raise CaseError(key, [("--fit", f"{key} is not a numeric case value that can be fitted; e.g. "
                                        f"{', '.join(DEFAULT_FIT)} or loading.friction_coefficient")], "fit")
    return spec


def read_measured(path: str | Path) -> Measured:
    """The measurements: every problem with the file, its column and its row.

    Parameters
    ----------
    path : a CSV file, ``cycle [cycles]`` and any wear-limit quantities or one profile (``x [mm]`` and a depth),
        each column with its unit; lines starting with ``#`` are comments.

    Returns
    -------
    Measured : one datum per measured cell, in internal units.  A ``CaseError`` lists every problem at once.
    """
    path = Path(path)
    source = str(path)
    rows = _csv_rows(path, source)
    problems, notes = [], []
    columns, ignored = _columns(rows[0], problems)
    names = [c[0] for c in columns]
    known = ", ".join([*LIMIT_KEYS, *PROFILES])
    if "cycle" not in names:
        problems.append(("header", "no `cycle` column"))
    if not any(n in LIMIT_KEYS or n in PROFILES for n in names):
        problems.append(("header", f"no column fretsim can fit; expected cycle and any of {known}"))
    if problems:  # refused anyway: a column it did not know may be the misspelt one it needed
        problems += [(f"column {n}", "not a quantity fretsim reports") for n in ignored]
    elif ignored:  # an exported history holds pressures, times, counts: the wear columns are what a fit uses
        notes.append(f"{source}: not fitted, not wear quantities fretsim compares with a run: {', '.join(ignored)}")
    profile = "x" in names
    if profile and not any(n in PROFILES for n in names):
        problems.append(("header", f"an x column needs a profile column ({', '.join(PROFILES)})"))
    if problems:
        raise CaseError(source, problems, "measurements")
    cyc, keys, vals, xs, where = _data(rows, columns, profile, problems, notes)
    if problems:
        raise CaseError(source, problems[:30], "measurements")
    if not vals:
        raise CaseError(source, [("", "no measured values")], "measurements")
    return Measured(source, np.array(cyc), keys, np.array(vals, float), np.array(xs, float),
                    {c[0]: c[2] for c in columns if c[0]}, notes, where)


def _csv_rows(path: Path, source: str) -> list[list[str]]:
    """The file's rows without comments: a header and at least one row of data.  Read as a case file is (a
    regular file of at most MAX_BYTES, opened without blocking): a FIFO or a device would hang the fit."""
    try:
        text = read_text(path, "measurements file", typical="measurements are a few kB")
    except (OSError, ValueError) as exc:
        raise CaseError(source, [("", str(exc))], "measurements") from None
    rows = [r for r in csv.reader(io.StringIO(text.removeprefix("\ufeff"), newline=""))
            if r and not r[0].lstrip().startswith("#")]
    if len(rows) - 1 > MAX_ROWS:
        raise CaseError(source, [("", f"{len(rows) - 1} rows of data; a fit takes at most {MAX_ROWS:,} (every "
                                      f"measured cycle is a recorded state of each of the fit's runs)")],
                        "measurements")
    if len(rows) < 2:
        raise CaseError(source, [("", "expected a header like `cycle [cycles],max_wear_depth_stationary [um]` and "
                                      "at least one row")], "measurements")
    return rows


def _columns(header: list[str], problems: list) -> tuple[list[tuple], list[str]]:
    """(name, kind, unit) of each header cell, (None, None, None) for one that cannot be read (a problem noted) or
    is not a quantity fretsim reports; and the names of those (ignored, unless no fittable column remains)."""
    columns, ignored = [], []
    for j, text in enumerate(header):
        m = _HEADER.match(text)
        if not m:
            problems.append((f"column {j + 1}", f"could not read the header {text!r}; expected `name [unit]`"))
            columns.append((None, None, None))
            continue
        name, unit = m.group(1), (m.group(2) or "").strip()
        if name == "cycle":
            columns.append((name, None, None))
        elif name == "x":
            columns.append((name, "length", unit))
        elif name in LIMIT_KEYS:
            kind = LIMITS_SCHEMA[name].kind
            columns.append((name, kind, unit))
        elif name in PROFILES:
            columns.append((name, "length", unit))
        else:
            ignored.append(name)
            columns.append((None, None, None))
            continue
        if name != "cycle" and columns[-1][1] != "fraction" and not unit:
            problems.append((f"column {name}", f"no unit; write e.g. `{name} [um]`"))
    return columns, ignored


def _data(rows: list[list[str]], columns: list[tuple], profile: bool, problems: list,
          notes: list) -> tuple[list, ...]:
    """(cycle, key, value, x, row) of every measured cell below the header, in file order; problems noted per
    row."""
    names = [c[0] for c in columns]
    cyc, keys, vals, xs, where = [], [], [], [], []
    for i, row in enumerate(rows[1:], start=2):
        cells = dict(zip(names, row))
        try:
            n = float(cells["cycle"])
        except (KeyError, ValueError):
            problems.append((f"row {i}", f"cycle {cells.get('cycle')!r} is not a number"))
            continue
        if n == 0 and _unworn(row, columns):  # an exported history starts at the unworn state: nothing to fit
            notes.append(f"row {i}: cycle 0, the unworn start, is not fitted (a relative residual needs wear)")
            continue
        if not (math.isfinite(n) and n > 0 and n == int(n)):  # int() of inf raises, of nan too
            problems.append((f"row {i}", f"cycle {cells['cycle']!r}: expected a whole number of cycles above 0"))
            continue
        x = float("nan")
        for (name, kind, unit), text in zip(columns, row):
            if name in (None, "cycle") or text.strip() in ("", "nan", "NaN"):
                continue
            try:
                value = _cell(text, kind, unit)
            except (UnitError, ValueError) as exc:
                problems.append((f"row {i}, column {name}", str(exc)))
                continue
            if name == "x":
                x = value
                continue
            if profile != (name in PROFILES):
                continue
            if name not in PROFILES and value <= 0:
                problems.append((f"row {i}, column {name}", f"{text!r}: a measured {name} must be above 0"))
                continue
            cyc.append(int(n))
            keys.append(name)
            vals.append(value)
            xs.append(x)
            where.append(i)
        if profile and not math.isfinite(x):
            problems.append((f"row {i}", "no x for the profile's point"))
    return cyc, keys, vals, xs, where


def _unworn(row: list[str], columns: list[tuple]) -> bool:
    """Every fittable cell of the row empty or zero (a row at cycle 0 with wear in it is an error, not a start)."""
    def zero(text: str) -> bool:
        try:
            return float(text) == 0
        except ValueError:
            return not text.strip()
    return all(zero(text) for (name, _, _), text in zip(columns, row) if name in LIMIT_KEYS or name in PROFILES)


def _cell(text: str, kind: str, unit: str) -> float:
    """One cell in internal units: a fraction as a number or a percentage, anything else with its column's unit."""
    if kind == "fraction":
        return float(text.strip().rstrip("%")) / (100.0 if text.strip().endswith("%") or unit == "%" else 1.0)
    return parse_quantity(f"{text.strip()} {unit}", kind)


class _Collect:
    """Observer: the quantities of the measurements at the recorded states."""

    def __init__(self, measured: Measured, wall: Optional[float]):
        self.m, self.wall, self.at = measured, wall, {}

    def on_step(self, setup, step) -> None:
        if step.is_snapshot and step.cycle in set(self.m.cycles.tolist()):
            self.at[int(step.cycle)] = (step, setup.grid)


def _model(case: Case, measured: Measured) -> np.ndarray:
    """The run's value of every measured datum."""
    from fretsim.limits import value
    from fretsim.runner import run
    from fretsim.measures import centre_line
    wall = getattr(case.geometry, "wall", None)
    obs = _Collect(measured, wall)
    out = run(case, None, observers=(obs,))
    if out.status != "complete" and GRID_EDGE in out.message:
        raise _Outgrown(None)
    if out.status != "complete":
        raise RuntimeError(f"a run of the fit stopped: {out.message}")
    res = []
    for n, key, x in zip(measured.cycles, measured.keys, measured.x):
        step, grid = obs.at[int(n)]
        if key in PROFILES:
            h = step.wear_moving if PROFILES[key] == "moving" else step.wear_stationary
            res.append(float(np.interp(x, grid.x, centre_line(h))))
        else:
            res.append(value(key, step, grid, wall))
    return np.array(res)


def shown(value: float, key: str, measured: Measured) -> str:
    """A datum in the unit its column was written in, as the house prints units (a column in um reads µm)."""
    unit = measured.units.get(key)
    kind = "length" if key in PROFILES or key == "x" else LIMITS_SCHEMA[key].kind
    if kind == "fraction" or not unit:
        return f"{value:.5g}"
    return f"{value / parse_quantity(f'1 {unit}', kind):.5g} {shown_unit(unit)}"


def _residuals(model: np.ndarray, measured: Measured) -> np.ndarray:
    r = np.empty_like(model)
    for i, key in enumerate(measured.keys):
        if key in PROFILES:  # against the profile's deepest measured point at that cycle
            same = [j for j, (k, n) in enumerate(zip(measured.keys, measured.cycles)) if k == key and
                    n == measured.cycles[i]]
            scale = max(abs(measured.values[j]) for j in same)
            r[i] = (model[i] - measured.values[i]) / scale
        else:
            r[i] = model[i] / measured.values[i] - 1.0
    return r


@dataclass
class FitResult:
    keys: tuple
    start: np.ndarray  # internal units
    values: np.ndarray
    low: np.ndarray  # 95 % confidence interval (NaN where there are no degrees of freedom)
    high: np.ndarray
    residuals: np.ndarray  # relative, at the optimum
    model: np.ndarray
    measured: Measured
    runs: int
    dof: int
    message: str
    kinds: tuple = ()
    given: tuple = ()  # the overrides every run had (--set): the fitted case is the case with them
    choices: tuple = ()  # the model every run had (model.dimension, corrections, slip, gap): the fitted case's too
    warnings: tuple = ()  # what makes a printed value less than it looks (a value the data do not determine, ...)
    undetermined: tuple = ()  # the keys the data do not determine (their interval beyond UNDETERMINED, or none)
    notes: tuple = ()  # what the user should know of how the values were fitted (the model of the runs)

    @property
    def determined(self) -> bool:
        """Every value fitted is determined by the data (no interval wider than UNDETERMINED either side)."""
        return not self.undetermined

    @property
    def converged(self) -> bool:
        """A fit that explains the data within the search (not at a bound)."""
        return "edge of the search" not in self.message

    def overrides(self) -> list[str]:
        return [f"{k}={_written(v, kind)}" for k, v, kind in zip(self.keys, self.values, self.kinds)]


def _written(value: float, kind: str) -> str:
    return repr(float(value)) if kind == "number" else format_quantity(value, kind)


def _start(case: Case, key: str, spec: Key) -> float:
    node = case.to_dict()
    for part in key.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    if node is None:
        raise CaseError(case.source, [(key, "not set in the case: give it a starting value to fit")], "fit")
    return float(node) if spec.kind == "number" else parse_quantity(node, spec.kind)


def fit(case_text: str, source: str, measured: Measured, keys=DEFAULT_FIT, overrides=(),
        progress: Optional[Callable[[int], None]] = None, note: Optional[Callable[[str], None]] = None) -> FitResult:
    """Fit ``keys`` of the case to the measurements.

    Parameters
    ----------
    case_text, source : the case file's text and where it came from (for messages).
    measured : the measurements, from :func:`read_measured`.
    keys : dotted case keys of the values to fit, each set in the case (its starting value) and above 0.
    overrides : ``key=value`` overrides applied to every run.
    progress : called with the number of runs so far after each run.
    note : called, before the first run, with what the user should know of the fit's grid (a larger one).

    Returns
    -------
    FitResult : the values, their 95 % confidence intervals, the residuals and a message.
    """
    keys = tuple(keys)
    specs = [_spec(k) for k in keys]
    cycles = sorted(set(measured.cycles.tolist()))
    base = [*overrides, f"loading.cycles={max(cycles)}", f"output.snapshots=[{', '.join(map(str, cycles))}]",
            "grid.error_estimate=none"]
    case0 = parse_case(case_text, source=source, overrides=base)
    base.append(f"jumping.tolerance={min(case0.step_tolerance, FIT_TOLERANCE)}")
    start = np.array([_start(case0, k, s) for k, s in zip(keys, specs)])
    if (start <= 0).any():
        raise CaseError(source, [(k, "a fitted value must start above 0") for k, v in zip(keys, start) if v <= 0],
                        "fit")
    _check_columns(case0, measured)
    tops = [_top(k, v * RANGE, s) for k, v, s in zip(keys, start, specs) if s.kind in WEAR_KINDS]
    # (a fitted load or stroke would wear beyond what the coefficients bound: then only a profile's x is checked,
    #  a factor PROFILE_REACH from the widest scar its coefficients' top wears)
    _check_scale(parse_case(case_text, source=source, overrides=[*base, *tops]), measured, len(tops) == len(keys))
    grid = _Grid(case_text, source, base, case0)
    notes = _gap_notes(case0, grid.filled)
    runs = [0]
    cache: dict = {}

    def evaluate(logs: np.ndarray) -> np.ndarray:
        key = tuple(np.round(logs, 12))
        if key not in cache:
            vals = np.exp(logs)
            sets = [f"{k}={_written(v, s.kind)}" for k, v, s in zip(keys, vals, specs)]
            try:
                case = _unlimited(parse_case(case_text, source=source, overrides=[*base, *grid.choices, *sets]))
                cache[key] = _model(case, measured)
            except _Outgrown:
                raise _Outgrown(logs) from None
            except (CaseError, SimulationError) as exc:
                raise RuntimeError(f"at {', '.join(sets)}: {exc}") from None
            runs[0] += 1
            if progress is not None:
                progress(runs[0])
        return _residuals(cache[key], measured)

    x0 = np.log(start)
    lo, hi = _bounds(x0, specs)
    sol = _search(evaluate, x0, (lo, hi), grid, keys, specs, note, cache)
    r = evaluate(sol.x)
    low, high, dof, message = _intervals(sol, r, len(keys))
    at_bound = [k for k, x, a, b in zip(keys, sol.x, lo, hi) if min(x - a, b - x) < 1e-3]
    if at_bound:
        # a value the residuals hardly depend on drifts to the edge: the data do not determine it (a volume of the
        # flat alone says nothing of the moving body's coefficient), which is not the model failing the data
        size = np.linalg.norm(sol.jac, axis=0)
        idle = [k for k, s in zip(keys, size) if k in at_bound and s <= INSENSITIVE * max(size.max(), 1e-300)]
        why = (f"the data hardly depend on {', '.join(idle)}: they do not determine it (fit fewer values, or measure "
               f"what it changes)" if idle else
               f"the model cannot reproduce the data with values in that range (see the residuals)")
        message = (f"{', '.join(at_bound)} ended at the edge of the search ({RANGE:g}× from the start, or the "
                   f"value's own range): {why}; the values are not a fit" + (f"; {message}" if message else ""))
    values = np.exp(sol.x)
    loose = _undetermined(keys, values, low, high, sol.jac, dof)
    return FitResult(keys, start, values, low, high, r, cache[tuple(np.round(sol.x, 12))], measured, runs[0],
                     dof, message or sol.message, tuple(s.kind for s in specs), tuple(overrides), tuple(grid.model),
                     tuple(_warnings(keys, start, values, at_bound, loose, r if dof <= 0 else None)), tuple(loose),
                     tuple(notes))


def _search(evaluate, x0, bounds, grid: "_Grid", keys, specs, note, cache: dict):
    """The least-squares search, started again on a wider grid whenever a trial outgrows the fit's (the runs so
    far, on another grid, are forgotten)."""
    from scipy.optimize import least_squares
    while True:
        try:
            return least_squares(evaluate, x0, jac=lambda x: _jacobian(evaluate, x, bounds), bounds=bounds,
                                 x_scale=1.0, xtol=1e-6, ftol=1e-8, max_nfev=200)
        except _Outgrown as exc:
            trial = np.exp(exc.logs)
            tops = [_top(k, v * GROWTH_MARGIN, s) for k, v, s in zip(keys, trial, specs) if s.kind in WEAR_KINDS]
            said = grid.grow(tops) if len(tops) == len(keys) else ""
            if not said:
                raise RuntimeError(f"a run of the fit stopped: the contact reached the edge of the grid at "
                                   f"{', '.join(f'{k}={v:.4g}' for k, v in zip(keys, trial))}; give grid.domain "
                                   f"(wider) and grid.elements") from None
            if note is not None:
                note(said)
            cache.clear()
            x0 = np.clip(exc.logs, *bounds)


STABLE_GAP = "stroke_average"  # the gap model of a fit's runs unless the case names one (_Grid)
PROFILE_REACH = 10.0  # a profile's x this many times beyond the widest scar the search can wear: a unit slip
INSENSITIVE = 1e-3  # a value at the edge whose residuals' derivative is below this share of the largest: undetermined
UNDETERMINED = 10.0  # a value whose 95 % interval reaches this factor either side is not determined by the data
FAR = 100.0  # a value fitted this factor from its start: a unit slip in the measured file would do this
UNMATCHED = 1e-3  # a residual left by a fit with no degrees of freedom beyond this: the model cannot match the data


def _undetermined(keys, values, low, high, jac, dof: int) -> list[str]:
    """The keys the data do not determine: all of them where there are fewer data than values (dof < 0: a
    combination is fitted, no value alone) or the Jacobian's columns are dependent (its rank short: those whose
    derivative is below INSENSITIVE of the largest, else all); an interval that spans more than UNDETERMINED either
    side (the data would fit as well with another value); an interval to 0 or inf."""
    size = np.linalg.norm(jac, axis=0)
    idle = [k for k, s in zip(keys, size) if s <= INSENSITIVE * max(size.max(), 1e-300)]
    if dof < 0 or np.linalg.matrix_rank(jac) < len(keys):
        return idle if idle and dof >= 0 else list(keys)
    out = []
    for k, v, lo, hi in zip(keys, values, low, high):
        bounded = bool(np.isfinite(lo) and np.isfinite(hi) and lo > 0)
        if bounded and (hi / v > UNDETERMINED or v / lo > UNDETERMINED):
            out.append(k)
        elif not bounded and (np.isfinite(lo) or k in idle):  # an interval to 0 or inf; or none, and idle
            out.append(k)
    return out


def _warnings(keys, start, values, at_bound, loose, exact=None) -> list[str]:
    """What the user must know before trusting a printed value: a value the data do not determine (its interval
    spans more than UNDETERMINED either side: the data would fit as well with another), one fitted FAR from its
    start (a depth written in mm under a µm header moved both coefficients about 225× in opposite directions and
    fitted to 0.3 %)."""
    out = []
    if loose:
        out.append(f"the data do not determine {', '.join(loose)}: other values fit them as well (a 95 % interval "
                   f"wider than {UNDETERMINED:g}× either side, or none); measure a quantity that depends on "
                   f"{'them' if len(loose) > 1 else 'it'} (each body's depth for its own coefficient), or fit fewer "
                   f"values")
    far = [f"{k} {v / s:.3g}×" for k, s, v in zip(keys, start, values) if k not in at_bound and k not in loose
           and abs(math.log(v / s)) > math.log(FAR)]
    if far:
        out.append(f"fitted far from the start ({', '.join(far)} the starting value): if that is unexpected, check the "
                   f"measured file's units (a depth in mm headed µm reads 1000× too small)")
    if exact is not None and exact.size and np.abs(exact).max() > UNMATCHED:  # as many values as data, not matched
        out.append(f"as many values fitted as measured, yet residuals of up to {np.abs(exact).max():.1%} remain: the "
                   f"model cannot reproduce these data with any values in the search")
    return out


def _gap_notes(case0: Case, filled: Case) -> list[str]:
    """The model the fit's runs use where it is not the one the case would choose: the stroke-averaged gap."""
    if case0.gap_model != "auto" or filled.gap_model == STABLE_GAP:
        return []
    return [f"the fit's runs take the flat's wear through the stroke-averaged gap (model.gap {STABLE_GAP}), stable "
            f"for any coefficients the search may try; the case alone would choose {filled.gap_model} (0.3 % apart in "
            f"the coefficients on McColl 185 N, a review's): the fitted case says model.gap {STABLE_GAP}"]


def _bounds(x0: np.ndarray, specs) -> tuple[np.ndarray, np.ndarray]:
    """The search in ln(value): within RANGE of each start and within its key's own range and plausible range
    (a friction coefficient searched to 1000× its start ran 6 minutes and stopped at μ = 18.3, out of [0, 10])."""
    lo, hi = x0 - math.log(RANGE), x0 + math.log(RANGE)
    for j, spec in enumerate(specs):
        tops = [spec.hi] + ([spec.plausible[1]] if spec.plausible else [])
        bottoms = [spec.lo] + ([spec.plausible[0]] if spec.plausible else [])
        top, bottom = min(tops), max(bottoms)
        if math.isfinite(top) and top > 0:
            hi[j] = min(hi[j], math.log(top))
        if math.isfinite(bottom) and bottom > 0:
            lo[j] = max(lo[j], math.log(bottom))
    return np.minimum(lo, x0 - 1e-9), np.maximum(hi, x0 + 1e-9)  # (the start itself always inside)


def _jacobian(evaluate, x: np.ndarray, bounds: tuple) -> np.ndarray:
    """The residuals' derivatives in ln(value), by forward differences of DIFF_STEP in each value (backward where
    that would leave the search).  scipy's own ``diff_step`` is relative to x itself, here a logarithm (ln 2e-8 =
    −17.7): its 5 % was a step of 0.89 in ln k, a factor of 2.4, and the confidence intervals from it 1.4× too
    wide (a review's central differences of 1 %)."""
    h = math.log1p(DIFF_STEP)
    r0 = evaluate(x)
    out = np.empty((r0.size, x.size))
    for j in range(x.size):
        step = h if x[j] + h <= bounds[1][j] else -h
        moved = x.copy()
        moved[j] += step
        out[:, j] = (evaluate(moved) - r0) / step
    return out


def _unlimited(case: Case) -> Case:
    """The case without its limits: a fit's run goes to the last measured cycle, where a trial that wears faster
    than the measurements would stop at a wear limit before it (and planning a limited case runs a pilot)."""
    return case.with_choices(limits=(), crack_limit=False) if case.limits or case.crack_limit else case


def _top(key: str, value: float, spec: Key) -> str:
    """``key=value`` for a case that bounds the search's wear, capped at the key's plausible top: the case reader
    refuses beyond it, and no run of the search can go there either (its runs are cases too)."""
    cap = spec.plausible[1] if spec.plausible else math.inf
    return f"{key}={_written(min(value, cap), spec.kind)}"


def _check_columns(case: Case, measured: Measured) -> None:
    """Refuse a measured quantity the case's geometry does not have (a wall loss is a tube's)."""
    if "wall_loss" in measured.keys and getattr(case.geometry, "wall", None) is None:
        raise CaseError(measured.source, [("column wall_loss", f"a wall loss is a tube's deepest wear over its wall "
                                                               f"(tube_on_flat); a {case.geometry.kind} has no wall: "
                                                               f"measure max_wear_depth_moving")], "measurements")


def _check_scale(top: Case, measured: Measured, values: bool = True) -> None:
    """Refuse a measured depth, width or volume that no run of the search can come near, a unit slip (mm for µm
    is a factor of 1000): ``top`` is the case at the top of the search.  Its worn volume (Archard's, both bodies)
    at each measured cycle, held in a scar of the geometry's shape (its own sizing estimate), bounds the depth
    from above (2V over the scar's area: 1.7× the cylinder's segment depth, the cap's own), and the width (the
    scar and two strokes, as the grid is sized); no width is a tenth of the unworn contact's half-width a.  A
    profile's x is refused PROFILE_REACH times beyond that scar; only x where ``values`` is False (a fitted value
    besides the coefficients, whose top is not the search's)."""
    from fretsim.plan.choices import Plan
    from fretsim.plan.inputs import contact
    from fretsim.sizing import SCAR_MARGIN
    c, loading, g = contact(top, Plan()), top.loading, top.geometry
    k = c.k_moving + c.k_stationary
    a_min = g.hertz(loading.lightest_load, c.e_star).half_width_x
    a_max = g.hertz(loading.peak_load, c.e_star).half_width_x
    problems: dict = {}
    for i, (n, key, v) in enumerate(zip(measured.cycles, measured.keys, measured.values)):
        volume = k * loading.worn_work(int(n))
        wx, wy = g.scar_half_widths(volume)
        kind = "volume" if key.startswith("wear_volume") else "width" if key.startswith("scar_width") else (
            "depth" if key in PROFILES or LIMITS_SCHEMA[key].kind == "length" else None)
        bound = {"volume": volume, "depth": 2 * volume / (math.pi * wx * wy),
                 "width": 2 * (SCAR_MARGIN * max(wx, a_max) + 2 * loading.peak_stroke)}.get(kind)
        x = measured.x[i]
        if key in PROFILES and "x" not in problems and abs(x) > PROFILE_REACH * (SCAR_MARGIN * max(wx, a_max)
                                                                                 + 2 * loading.peak_stroke):
            problems["x"] = (f"column x [{measured.units.get('x')}]",
                             f"{shown(x, 'x', measured)} (row {measured.rows[i]}) is more than {PROFILE_REACH:g}× "
                             f"as far from the centre as any run of the fit can wear by cycle {n:,}: is the column's "
                             f"unit right? (an x in µm headed mm reads 1000× too far)")
        if not values or key in problems or bound is None or not (v > bound or (kind == "width" and v < a_min / 10)):
            continue
        small = v <= bound
        where = (f"less than a tenth of the unworn contact's half-width a = {shown(a_min, key, measured)}" if small
                 else f"more than any run of the fit can reach by cycle {n:,} (at most {shown(bound, key, measured)}"
                      f", with the wear coefficients {RANGE:g}× their starting values)")
        problems[key] = (f"column {key} [{measured.units.get(key)}]",
                         f"{shown(v, key, measured)} (row {measured.rows[i]}) is {where}: is the column's unit "
                         f"right? (" + ("a width in mm headed µm reads 1000× too narrow)" if small else
                                        "a value in µm headed mm reads 1000× too large)"))
    if problems:
        raise CaseError(measured.source, list(problems.values()), "measurements")


class _Grid:
    """The fit's grid and automatic choices, fixed at the starting values so that every run compares like with
    like, and grown (the starting element over a wider domain) when a trial's scar outgrows it: sizing it for the
    top of the search up front cost every 3D fit about its elements' ratio (McColl 185 N 3D: 3991 × 27 elements
    instead of 427 × 27, 2.6× a run; a ball ~28×), where a search from a fair guess never goes there."""

    def __init__(self, case_text: str, source: str, base: list, case0: Case):
        from fretsim.plan import prepare
        _, self.filled, _ = prepare(_unlimited(parse_case(case_text, source=source, overrides=base)))
        f = self.filled
        corrections = "none" if not f.corrections or f.corrections == "none" else list(f.corrections)
        self.model = [f"model.dimension={f.dimension}", f"model.corrections={corrections}", f"model.slip={f.slip}",
                      # the paper's mid-stroke gap is unstable where the moving body wears too little, which a search
                      # over the coefficients can reach: the stroke-averaged gap is stable for any (unless named)
                      f"model.gap={case0.gap_model if case0.gap_model != 'auto' else STABLE_GAP}"]
        self.given = case0.domain is not None or case0.elements is not None  # a grid the case gives stays its own
        self.case_text, self.source, self.base = case_text, source, base
        self.domain, self.elements, self.grown = f.domain, f.elements, 0

    @property
    def choices(self) -> list[str]:
        return [*self.model, f"grid.domain=[{', '.join(f'{d!r} mm' for d in self.domain)}]",
                f"grid.elements=[{', '.join(map(str, self.elements))}]"]

    def grow(self, tops: list) -> str:
        """Widen the domain to hold the wear of ``tops`` (``key=value`` of the wear coefficients, beyond the trial
        that outgrew the grid); what it did, for a note ("" where the grid is the case's or at its limit)."""
        if self.given or self.grown >= MAX_GROWTH:
            return ""
        top = parse_case(self.case_text, source=self.source, overrides=[*self.base, *self.model, *tops])
        holding, _ = _holding(top, self.filled)
        wider = [h > d * (1 + 1e-9) for h, d in zip(holding, self.domain)]
        if not any(wider):  # the estimate holds it, the run did not: along the stroke, where scars grow
            wider[0] = True
        # each axis that grows at least doubles: a search that creeps outward restarts a few times, not many
        domain = [max(h, 2.0 * d) if w else d for h, d, w in zip(holding, self.domain, wider)]
        steps = [d / n for d, n in zip(self.filled.domain, self.filled.elements)]
        self.elements = tuple(max(_odd(d / h), n) for d, h, n in zip(domain, steps, self.elements))
        self.domain = tuple(n * h for n, h in zip(self.elements, steps))
        self.grown += 1
        return (f"a trial's scar reached the edge of the fit's grid: the fit starts again on "
                f"{' × '.join(map(str, self.elements))} elements of the same size (give grid.domain and "
                f"grid.elements to choose the grid)")


def _holding(top: Case, filled: Case) -> tuple[tuple, tuple]:
    """The starting grid's elements over a domain that holds the scar of ``top``, the most wear the search may
    try: a search from a low first guess goes well beyond it, and a run whose contact reaches the grid's edge
    stops the fit; the element stays the one planned at the starting values, so the fit is as resolved."""
    from fretsim.plan.choices import Plan
    from fretsim.plan.inputs import contact
    from fretsim.sizing import auto_grid
    from fretsim.wear import GAP_REACH
    c, loading = contact(top, Plan()), top.loading
    k = c.k_moving + c.k_stationary
    sizing = auto_grid(top.geometry, len(filled.elements) == 1, loading.lightest_load, loading.peak_stroke,
                       loading.cycles, k, c.e_star, strokes=GAP_REACH[top.gap_model],
                       volume=k * loading.worn_work(loading.cycles))
    steps = [d / n for d, n in zip(filled.domain, filled.elements)]
    elements = tuple(_odd(max(d, wide) / step) for d, wide, step in zip(filled.domain, sizing.domain, steps))
    return tuple(n * step for n, step in zip(elements, steps)), elements


def _intervals(sol, r: np.ndarray, p: int) -> tuple[np.ndarray, np.ndarray, int, str]:
    """The linearised 95 % confidence intervals of the fitted values (Student's t over the degrees of freedom).

    Returns low and high (NaN without degrees of freedom or with a singular Jacobian), the degrees of freedom,
    and a message saying why there are no intervals ("" when there are).
    """
    from scipy.stats import t as student
    m = r.size
    dof = m - p
    low = high = np.full(p, np.nan)
    if dof > 0:
        jac = sol.jac
        s2 = float(r @ r) / dof
        try:
            cov = s2 * np.linalg.inv(jac.T @ jac)
            half = student.ppf(0.975, dof) * np.sqrt(np.clip(np.diag(cov), 0, None))
            with np.errstate(over="ignore", under="ignore"):  # an undetermined value's interval: 0 to inf, said so
                low, high = np.exp(sol.x - half), np.exp(sol.x + half)
        except np.linalg.LinAlgError:
            pass
    message = ("" if dof > 0 else f"{m} measured value(s) for {p} fitted value(s): no degrees of freedom left, so no "
                                  f"confidence interval (measure more, or fit fewer values)")
    if dof > 0 and not np.isfinite(low).all():
        message = "the data do not determine every value (the Jacobian is singular): fit fewer values"
    return low, high, dof, message


def fitted_case_text(case_text: str, result: FitResult) -> str:
    """The case file's mapping with the overrides the fit ran with and the fitted values set (comments are not
    kept): the case the fitted values are the fit of, which reruns to the fitted numbers."""
    import yaml

    from fretsim.case import _apply_override
    from fretsim.yamlread import loads
    raw = loads(case_text)
    problems: list = []
    for item in [*result.given, *result.choices, *result.overrides()]:
        _apply_override(raw, item, problems)
    header = "# fitted by fretsim fit to " + Path(result.measured.source).name + ": " + ", ".join(
        f"{k} = {_written(v, kind)}" for k, v, kind in zip(result.keys, result.values, result.kinds)) + "\n"
    if result.given:
        header += "# with the overrides it ran with: " + ", ".join(result.given) + "\n"
    if result.choices:  # (the model planned at the starting values, the stroke-averaged gap unless the case named one)
        header += "# and the model its runs used: " + ", ".join(result.choices) + "\n"
    return header + yaml.safe_dump(raw, sort_keys=False, allow_unicode=True)
