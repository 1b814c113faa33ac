"""The plan of a run: every automatic decision, each a small function returning its value and its reason.

:func:`prepare` turns a validated :class:`~fretsim.case.Case` into the loop's :class:`~fretsim.simulate.Setup`
(arrays, numbers, operators) and a *filled* case in which every automatic choice is written out, so the run
can be repeated — or resumed — exactly.  The list of :class:`Choice` is stored in the results file
(``/choices``) and printed by ``fretsim check``; choices the case made itself are listed too, as "given".
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from fretsim.case import PRESETS, Case, CaseError
from fretsim.compliance import HalfSpace, add
from fretsim.cycle import CoulombCycle, UniformCycle
from fretsim.cycle.coulomb import gross_slip_stroke
from fretsim.grid import Grid
from fretsim.loading import Loading
from fretsim.reference import effective_modulus
from fretsim.simulate import DEPTH_SHARE, Setup, SimulationError
from fretsim.sizing import ELEMENTS_OVER_7A, Sizing, auto_grid
from fretsim.solvers import solve
from fretsim.stability import Spectrum, default_linear_jump, wear_spectrum
from fretsim.wear import stroke_reach, stroke_symbol, wear_operator

MAX_STROKE_OVER_CONTACT = 50.0  # δ/a beyond this is sliding, not fretting, or a unit slip (µm → mm)
MEMORY_SHARE = 0.5  # refuse a grid that would take more than this share of the machine's memory
MODEL_GROWTH = math.log(1e3)  # a forced unstable model may grow a seed at most 1000-fold over the run
SHORT_RUN = 8  # runs of at most this many cycles are taken a cycle at a time: exact, and as cheap
MIN_ELEMENTS_ACROSS_CONTACT = 4
ELASTIC_P0 = 0.04  # p0/E* beyond which no metal stays elastic (bearing steel: ~4 GPa over E* = 115 GPa, 3.5 %)
# the Hertz peak pressure at first yield (von Mises, ν = 0.3, below the surface): Johnson, Contact Mechanics §6.2
YIELD_ONSET = {"point": 1.60, "line": 1.79}
SMALL_CONTACT = 0.1  # a/R beyond which the half-space (small-strain) contact model is said to be stretched


@dataclass(frozen=True)
class Choice:
    """One decision of the plan: the case key it fills, its value (as written in the filled case) and why."""

    key: str
    value: Any
    reason: str
    given: bool = False  # True when the case set it itself
    error: float = 0.0  # the relative difference from the fuller model this choice accepted (auto's simplifications)


@dataclass
class Plan:
    choices: list = field(default_factory=list)
    warnings: list = field(default_factory=list)

    def add(self, choice: Choice) -> Any:
        """Record a choice; a later choice for the same key replaces the earlier one (one line per key)."""
        self.choices = [c for c in self.choices if c.key != choice.key] + [choice]
        return choice.value


def available_memory() -> int:
    """Physical memory of this machine in bytes."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 8 * 2**30


def memory_estimate(elements: int, snapshots: int, solver: str, coarse_elements: int = 0) -> float:
    """Bytes a run needs: ~40 work arrays, FFT buffers (4x, complex), 4 fields per snapshot, the implicit
    schemes' history (3 arrays × 8 points), a dense matrix for the dense solvers (on the grid solved on)."""
    from fretsim.solvers import DENSE_SOLVERS
    solved = coarse_elements or elements
    need = 8.0 * elements * (40 + 24 + 4 * snapshots) + 8.0 * solved * 4 * 2 * 4
    if solver in DENSE_SOLVERS:
        need += 3 * 8.0 * solved**2  # the matrix, its gathered copy, the basis factors
    return need


# --- the choices ----------------------------------------------------------------------------------------------

def choose_dimension(case: Case, e_star: float) -> Choice:
    """2d or 3d.  auto: 2D where it reports the quantities of the full 3D model within model.accuracy.

    Estimated before the run by proxy runs on a coarse grid (half the x resolution, 15 rows): the case in 2D
    and in 3D, compared on the maximum depth of each body, the flat's centre-line depth and both scar widths
    (the peak pressure for a contact-only run).  The unworn contact alone is no guide: a flat-ended cylinder's
    ends draw load from its whole length (its centre line carries 93-96 % of P/L for L/a from 280 to 8300,
    falling off as 1/ln(L/a)), but wear evens that out; and a profiled roller may start balanced and end not.
    Point contacts have no 2D model.
    """
    g = case.geometry
    if case.dimension != "auto":
        return Choice("model.dimension", case.dimension, "given in the case", True)
    if not g.has_2d:
        return Choice("model.dimension", "3d", f"a {g.kind} is a point contact: it has no 2D model")
    try:
        diff, what = _dimension_proxy(case, e_star)
    except SimulationError as exc:
        return Choice("model.dimension", "3d", f"the full model: a proxy run to judge 2D stopped "
                                               f"({str(exc)[:120]}…)")
    if diff * PROXY_MARGIN <= case.accuracy:
        return Choice("model.dimension", "2d", f"a coarse 3D proxy run reports {what} within {diff:.2%} of 2D, "
                                               f"inside model.accuracy {case.accuracy:.2%} / {PROXY_MARGIN:g} (a "
                                               f"proxy's difference is itself uncertain): 2D (the ends' effect on "
                                               f"the reported quantities is small)", error=diff * PROXY_MARGIN)
    return Choice("model.dimension", "3d", f"a coarse 3D proxy run reports {what} {diff:.2%} away from 2D, "
                                           f"more than model.accuracy {case.accuracy:.2%} / {PROXY_MARGIN:g} (a "
                                           f"proxy's difference is itself uncertain): the ends matter, 3D")


PROXY_ROWS = 15
# A proxy's difference is measured on a coarse grid and is itself uncertain: mccoll_500N_10um's 2D proxy differed
# from 3D by 0.99 %, at full resolution by 1.21 % in depth and 2.5 % in the moving body's scar width.  auto
PRESSURE_TOLERANCE = 0.1  # model.pressure_accuracy: the stepping tolerance at most this share of it
# accepts a simpler model only where PROXY_MARGIN times the proxy's difference is within model.accuracy, and
# reports that product as the model's part of the error estimates.
PROXY_MARGIN = 3.0


def _full_corrections(case: Case, dimension: str):
    """The corrections of the full model a dimension proxy runs: the case's own, less the free faces in 2D (which
    has no ends); in 3D with the free faces wherever they may apply (and, under auto, a tube's ring bending)."""
    corr, g = case.corrections, case.geometry
    given = () if corr in ("auto", "none") else tuple(corr)
    if dimension == "2d":
        return corr if not given else (tuple(c for c in given if c != "free_faces") or "none")
    if not g.free_faces or not (corr == "auto" or "free_faces" in given):
        return corr
    bending = g.body_corrections if corr == "auto" else ()
    return tuple(dict.fromkeys(given + ("free_faces",) + bending))


# The runs a run makes besides its own (auto's proxies, a limit's pilot, the grid-error companions) can take a
# minute: the CLI says what each is (announce) and shows its progress (side_progress: a context manager for a
# setup that yields a progress callback, as simulate takes one).  Both None in the library: nothing is printed.
announce: Optional[Callable[[str], None]] = None
side_progress: Optional[Callable[[Any], Any]] = None


def _announce(what: str) -> None:
    if announce is not None:
        announce(what)


def side_run(what: str, setup):
    """simulate(setup) for one of the runs a run makes besides its own, announced and with progress."""
    from fretsim.simulate import simulate
    _announce(what)
    if side_progress is None:
        return simulate(setup)
    with side_progress(setup) as update:
        return simulate(setup, progress=update)


def _proxy(proxy: Case, what: Callable[[Setup], str]) -> dict:
    """The summary of one of auto's proxy runs; a proxy already run in this process (the corrections' proxies
    are asked for again once the dimension is chosen) is not run again."""
    from fretsim.simulate import summarize
    key = repr(proxy.to_dict())
    if key not in _PROXIES:
        setup, _, _ = prepare(proxy)
        if len(_PROXIES) > 64:
            _PROXIES.clear()
        _PROXIES[key] = summarize(setup, side_run(what(setup), setup), 0, 0.0)
    return dict(_PROXIES[key])


_PROXIES: dict = {}


def _dimension_proxy(case: Case, e_star: float) -> tuple[float, str]:
    from fretsim.simulate import summarize
    g = case.geometry
    k = sum(case.wear_coefficients())
    sizing = auto_grid(g, False, case.normal_load, case.stroke, case.cycles, k, e_star)
    nx = max(21, (sizing.elements[0] // 2) | 1)
    keys = (("max_wear_depth_moving_um", "max_wear_depth_stationary_um", "centre_wear_depth_stationary_um",
             "scar_width_moving_mm", "scar_width_stationary_mm") if case.cycles else ("max_pressure_MPa",))
    out = []
    for dim, domain, elements in (("2d", sizing.domain[:1], (nx,)), ("3d", sizing.domain, (nx, PROXY_ROWS))):
        corr = _full_corrections(case, dim)
        proxy = case.with_choices(dimension=dim, corrections=corr, snapshots=(case.cycles,), domain=domain,
                                  elements=elements,
                                  coarse_element=None, linear_jump=None, scheme="bdf2", preset=None,
                                  step_tolerance=max(case.step_tolerance, 0.03))
        out.append(_proxy(proxy, lambda setup: f"model.dimension auto: a {dim.upper()} proxy run "
                          f"({' × '.join(map(str, elements))} elements, {case.cycles} cycles, tolerance "
                          f"{setup.step_tolerance:g}) to compare 2D with 3D"))
    diffs = {key: abs(out[1][key] / out[0][key] - 1) if out[0][key] else 0.0 for key in keys}
    worst = max(diffs, key=diffs.get)
    names = {"max_wear_depth_moving_um": "the moving body's maximum depth", "max_wear_depth_stationary_um":
             "the flat's maximum depth", "centre_wear_depth_stationary_um": "the flat's centre-line depth",
             "scar_width_moving_mm": "the moving body's scar width", "scar_width_stationary_mm":
             "the flat's scar width", "max_pressure_MPa": "the peak pressure"}
    return diffs[worst], names[worst]


def choose_grid(case: Case, plane: bool, sizing: Sizing) -> tuple[Choice, Choice]:
    given_d, given_e = case.domain is not None, case.elements is not None
    if given_d and given_e:
        return (Choice("grid.domain", case.domain, "given in the case", True),
                Choice("grid.elements", case.elements, "given in the case", True))
    if not given_d and not given_e:
        rule = (sizing.rule if sizing.rule else
                f"the paper's rule 7a/40, refined ({sizing.note.split(' = ')[1]}) for partial slip: its stick zone "
                f"and slip annulus span {PARTIAL_SLIP_ELEMENTS} elements each (up to {TRANSITION_BAND:g} δ_t, where "
                f"a worn contact may come to stick, {2 * PARTIAL_SLIP_ELEMENTS} across the half-width; at most "
                f"{MAX_PARTIAL_SLIP_REFINEMENT:g}× per axis)")
        return (Choice("grid.domain", sizing.domain, "automatic: holds the estimated final scar: " + sizing.note),
                Choice("grid.elements", sizing.elements, "automatic: " + rule))
    if given_d:
        dx = sizing.domain[0] / sizing.elements[0]
        elements = tuple(max(1, int(round(d / dx))) | 1 for d in case.domain[:1]) + (
            (sizing.elements[1],) if not plane else ())
        return (Choice("grid.domain", case.domain, "given in the case", True),
                Choice("grid.elements", elements, f"the automatic element ({dx * 1e3:.3g} µm) over the given domain: "
                                                  f"{sizing.rule or 'the paper rule refined for partial slip'}"))
    return (Choice("grid.domain", sizing.domain, "automatic, for the given elements: " + sizing.note),
            Choice("grid.elements", case.elements, "given in the case", True))


def choose_gap_model(case: Case, grid: Grid) -> Choice:
    """mid_stroke (the paper) where it is stable, stroke_average where the paper's model itself is not."""
    k_m, k_s = case.wear_coefficients()
    b_min = float(stroke_symbol(grid.dx, case.stroke, np.linspace(0.01 * np.pi, np.pi, 400)).min())
    stable = k_m + k_s * min(b_min, 0.0) >= 0
    if case.gap_model != "auto":
        return Choice("model.gap", case.gap_model, "given in the case", True)
    if stable:
        bound = -min(b_min, 0.0)
        return Choice("model.gap", "mid_stroke", "the paper's model (Eq. 18): stable here, since "
                      + (f"k_m ≥ {bound:.3g}·k_s" if bound > 0 else "it is stable for any k_m and k_s on this grid"))
    return Choice("model.gap", "stroke_average",
                  f"the paper's mid-stroke gap is unstable when the moving body wears less than "
                  f"{-b_min:.3f} of the flat (k_m = {k_m:.3g}, k_s = {k_s:.3g} 1/MPa): wear modes shorter than "
                  f"the stroke grow in the model itself and break the pressure into spikes; the flat's wear seen "
                  f"through the stroke average is stable and equal to first order")


FACES_NOTE = ("the free faces of {what} (paper §2.1; solved as a finite block, not the paper's overlapping "
              "half-spaces)")


def available_corrections(case: Case, plane: bool) -> tuple[str, ...]:
    g = case.geometry
    return g.body_corrections + (("free_faces",) if g.free_faces and not plane else ())


def _faces_what(case: Case) -> str:
    names = {"moving": f"the {case.geometry.kind.split('_')[0]}'s ends", "stationary": "the flat's ends"}
    return " and ".join(f"{names[body]} ({length:g} mm apart)" for body, length in case.geometry.free_faces)


def choose_corrections(case: Case, grid: Grid, e_star: float, scar_half_width: float) -> Choice:
    """Compliance added to the half-spaces: the tube's ring bending, the free faces of bodies that end across the
    contact (3D).  auto: each correction whose effect on the reported quantities exceeds model.accuracy.
    Estimated before the run by quick proxy runs of the case with and without it (2D for ring bending, 3D at
    half the x resolution for free faces), compared on the maximum depths and scar widths of both bodies (and the flat's
    centre-line depth; the pressure of the unworn contact for a contact-only run).  A static estimate is not
    enough: in steady fretting wear the pressure follows from the wear (a nearly even wear rate across the
    contact), not from the compliance, so a correction that reshapes the pressure of a given worn shape may
    change the wear very little."""
    g = case.geometry
    available = available_corrections(case, grid.plane_strain)
    if case.corrections != "auto":
        chosen = () if case.corrections == "none" else tuple(case.corrections)
        for c in chosen:
            if c not in available:
                why = (" (a 2d model has no ends: use model.dimension: 3d)" if c == "free_faces" and g.free_faces
                       else "")
                raise CaseError(case.source, [("model.corrections", f"{c} does not apply to this {g.kind} model"
                                                                    f"{why}; available: "
                                                                    f"{', '.join(available) or 'none'}")])
        return Choice("model.corrections", chosen, "given in the case", True)
    if not available:
        reason = (f"none applies to a {g.kind}: both bodies are half-spaces" if not g.free_faces else
                  f"none applies to the 2D model of a {g.kind} (free faces need 3D)")
        return Choice("model.corrections", (), reason)
    chosen, reasons, dropped = [], [], 0.0
    for corr in available:
        what = ("the tube wall's ring bending (Eq. 23)" if corr == "ring_bending"
                else FACES_NOTE.format(what=_faces_what(case)))
        proxy = "a 2D proxy run" if corr == "ring_bending" else "a 3D proxy run at half the x resolution"
        try:
            diff, quantity = _proxy_difference(case, (corr,), "2d" if corr == "ring_bending" else "3d")
        except SimulationError as exc:
            chosen.append(corr)
            reasons.append(f"{what}: kept, {proxy} to judge it stopped ({str(exc)[:120]}…)")
            continue
        verb = "changes" if corr == "ring_bending" else "change"
        if diff * PROXY_MARGIN > case.accuracy:
            chosen.append(corr)
            reasons.append(f"{what} {verb} {quantity} by {diff:.2%} in {proxy}, more than model.accuracy "
                           f"{case.accuracy:.2%} / {PROXY_MARGIN:g} (a proxy's difference is itself uncertain)")
        else:
            dropped += diff * PROXY_MARGIN
            reasons.append(f"{what} {verb} {quantity} by only {diff:.2%} in {proxy}, within model.accuracy "
                           f"{case.accuracy:.2%} / {PROXY_MARGIN:g} (a proxy's difference is itself uncertain): "
                           f"left out (set model.corrections to include it)"
                           + ("; in steady wear the pressure follows the wear, not the wall's compliance"
                              if corr == "ring_bending" else ""))
    return Choice("model.corrections", tuple(chosen), "; ".join(reasons), error=dropped)


def _proxy_difference(case: Case, corrections: tuple, dimension: str = "2d") -> tuple[float, str]:
    """Largest relative difference of the reported quantities between proxy runs without and with
    ``corrections``: 2D at the automatic grid, or 3D at half its x resolution."""
    return _run_proxies(case, corrections, dimension)


def _run_proxies(case: Case, corrections: tuple, dimension: str) -> tuple[float, str]:
    from fretsim.simulate import summarize
    keys = (("max_wear_depth_moving_um", "max_wear_depth_stationary_um", "scar_width_moving_mm",
             "scar_width_stationary_mm") if case.cycles else ("max_pressure_MPa",))
    grid: dict = {"domain": None, "elements": None}
    if dimension == "3d":
        keys = keys + (("centre_wear_depth_stationary_um",) if case.cycles else ())
        e_star = effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                                   case.stationary.youngs_modulus, case.stationary.poissons_ratio)
        k = sum(case.wear_coefficients())
        sizing = auto_grid(case.geometry, False, case.normal_load, case.stroke, case.cycles, k, e_star)
        # all the rows: the faces act on the end rows, which 15 coarse rows widen and blunt (1.0 % for 1.4 %)
        grid = {"domain": sizing.domain, "elements": (max(21, (sizing.elements[0] // 2) | 1), sizing.elements[1])}
    out = []
    for corr in ((), corrections):
        proxy = case.with_choices(dimension=dimension, corrections=corr or "none", snapshots=(case.cycles,),
                                  coarse_element=None, linear_jump=None, scheme="bdf2", preset=None,
                                  step_tolerance=max(case.step_tolerance, 0.03) if dimension == "3d"
                                  else case.step_tolerance, **grid)
        out.append(_proxy(proxy, lambda setup: f"model.corrections auto: a {dimension.upper()} proxy run "
                          f"{'with ' + ', '.join(corr) if corr else 'without corrections'} ({setup.grid.shape[1]} × "
                          f"{setup.grid.shape[0]} elements, {case.cycles} cycles, tolerance {setup.step_tolerance:g})"))
    diffs = {k: abs(out[1][k] / out[0][k] - 1) if out[0][k] else 0.0 for k in keys}
    worst = max(diffs, key=diffs.get)
    names = {"max_wear_depth_moving_um": "the moving body's maximum depth", "max_wear_depth_stationary_um":
             "the flat's maximum depth", "scar_width_moving_mm": "the moving body's scar width",
             "scar_width_stationary_mm": "the flat's scar width", "max_pressure_MPa": "the peak pressure",
             "centre_wear_depth_stationary_um": "the flat's centre-line depth"}
    return diffs[worst], names[worst]


def choose_scheme(case: Case) -> Choice:
    if case.preset is not None:
        return Choice("jumping.scheme", case.scheme, f"preset {case.preset}: the paper's adaptive jumping", True)
    given = any(k.startswith("jumping.scheme=") for k in case.overrides)
    if case.cycles <= SHORT_RUN and case.scheme == "bdf2" and not given:
        return Choice("jumping.scheme", "linear", f"{case.cycles} cycles: taken one cycle at a time, which is the "
                                                  f"model itself and no dearer than steps")
    reasons = {"bdf2": f"second-order implicit steps under error control (tolerance {case.step_tolerance:g}): no "
                       f"stability limit, recorded states landed on with shrinking steps",
               "implicit": "backward-Euler steps (first order) under error control",
               "linear": "the paper's explicit linear jumps", "adaptive": "the paper's adaptive jumps (Eqs. 19-21)"}
    return Choice("jumping.scheme", case.scheme, reasons[case.scheme])


def choose_linear_jump(case: Case, scheme: str, limit: float, grid: Grid) -> Choice:
    if scheme in ("bdf2", "implicit"):
        return Choice("jumping.linear", default_linear_jump(limit, case.cycles),
                      "not used by implicit steps; half the explicit stability limit, for reference")
    if case.cycles <= SHORT_RUN and scheme == "linear" and case.linear_jump is None:
        return Choice("jumping.linear", 1, "one cycle per step: the model's own per-cycle update")
    if case.linear_jump is not None:
        return Choice("jumping.linear", case.linear_jump, "given in the case", True)
    half = default_linear_jump(limit, case.cycles)
    if case.preset is not None:
        paper = PRESETS[case.preset]["linear"]
        if paper <= half:
            return Choice("jumping.linear", paper, f"preset {case.preset}: the paper's ΔN_L = {paper}")
        return Choice("jumping.linear", half, f"preset {case.preset}: the paper's ΔN_L = {paper} exceeds this "
                                              f"grid's explicit stability limit {limit:.4g} cycles (elements "
                                              f"{grid.dx * 1e3:.3g} µm; the paper's were coarser): scaled to half "
                                              f"the limit, {half}")
    return Choice("jumping.linear", half, f"half the explicit stability limit {limit:.4g} cycles: every mode "
                                          f"decays without changing sign")


def choose_snapshots(case: Case) -> Choice:
    if case.snapshots is not None:
        return Choice("output.snapshots", case.snapshots, "given in the case", True)
    n = case.cycles
    return Choice("output.snapshots", tuple(sorted({0, n // 4, n // 2, 3 * n // 4, n})),
                  "automatic: 0, N/4, N/2, 3N/4 and N")


def estimate_solves(setup) -> int:
    """Solves a run is expected to take (measured on the shipped cases; for progress and `check`)."""
    n = setup.cycles
    if n == 0:
        return 1
    if setup.scheme in ("bdf2", "implicit"):
        # ~25 solves per decade of cycles after the first, ~7 per recorded state landed on (measured)
        return min(n + 1, int(10 + 12 * math.log10(max(n, 10)) + 7 * len(setup.snapshots)))
    if setup.scheme == "linear":
        return n // setup.linear_jump + len(setup.snapshots) + 1
    return int(n / (setup.linear_jump * 6 + 300)) * 6 + len(setup.snapshots) + 10


# a step's solve, warm-started on the contact's window, against the cold solve timed (loop time per solve over one
# cold solve, measured on McColl 185 N 2D/3D with BDF2 and linear jumps, Kirk 20 Hz, the 3D tube, the partial-slip
# ball: 0.22-0.56, the 2D runs' per-step overhead the rest; was 0.5, and 1 for friction cycles, which estimated
# those 1.9-3.6x too long)
WARM_SOLVE = 0.35


def estimate_cost(setup) -> tuple[int, float]:
    """(solves, seconds) before a run: solves from the scheme, seconds from one timed contact solve."""
    import time

    from fretsim.solvers import solve
    from fretsim.compliance import fft
    fft.forward(np.zeros((1, 3)), (1, 6))  # the FFT's import and choice, once a process: not a solve's cost
    solves = estimate_solves(setup)
    op = setup.coarse_compliance or setup.compliance
    if op.convolution is not None:
        op.convolution.hat  # its transform, made once a run: not a solve's cost
    gap = setup.coarse_gap if setup.coarse_gap is not None else setup.gap
    if setup.cycle.linear:  # a cycle is one normal solve
        t = time.perf_counter()
        solve(op, gap, setup.cycle.load, method=setup.method, tol=setup.tolerance)
        cold = time.perf_counter() - t
        return solves, solves * cold * WARM_SOLVE

    def normal(seen, guess, extra=None, load=None, cycle=0):
        res = solve(op if extra is None else add(op, extra), gap + seen, load, method=setup.method, p0=guess,
                    tol=setup.tolerance)
        return res.pressure, res

    zero = np.zeros(setup.grid.shape)
    t = time.perf_counter()
    setup.cycle.solve(zero, zero, normal, None)
    return solves, solves * (time.perf_counter() - t) * WARM_SOLVE


# --- prepare ----------------------------------------------------------------------------------------------------

PILOT_MARGIN = 1.3  # the grid of a run with wear limits holds the wear of this many times the pilot's cycles


def pilot_cycles(case: Case) -> Optional[float]:
    """Where a run with wear limits will stop, roughly: the case on the paper's grid, in 2D where the geometry
    has it, at a loose stepping tolerance, no companion (None if no limit is reached or the pilot fails).  Its
    only use is sizing: a limit's run is sized for the wear at the limit, not for loading.cycles, which is then
    only an upper bound (a scar sized for 10⁹ cycles would make the elements far too coarse for the scar at
    the limit)."""
    pilot = case.with_choices(dimension="2d" if case.geometry.has_2d else "3d", corrections="none",
                              grid_rule="paper", grid_error="none", step_tolerance=max(case.step_tolerance, 0.03),
                              pressure_accuracy=None, snapshots=(0,), scheme="bdf2")
    key = repr(pilot.to_dict())  # auto's proxies prepare variants of the case: one pilot serves them all
    if key in _PILOTS:
        return _PILOTS[key]
    try:
        setup, _, _ = prepare(pilot, _pilot=float("nan"))
        last = side_run("wear limits: a pilot run on the paper's grid to find roughly where the limit is reached",
                        setup)
        found = float(last.limit[1]) if last.limit else None
    except (SimulationError, CaseError):
        found = None
    if len(_PILOTS) > 64:
        _PILOTS.clear()
    _PILOTS[key] = found
    return found


_PILOTS: dict = {}


def prepare(case: Case, allow_unstable: bool = False, _refine: float = 1.0,
            _pilot: Optional[float] = None) -> tuple[Setup, Case, Plan]:
    """Unpack a case into arrays and numbers; fill the automatic choices into the returned case.

    A linear jump beyond the explicit stability limit is refused (CaseError) unless ``allow_unstable``
    (for studies of the instability itself); so is the paper's gap model where it is unstable over the run.
    """
    plan = Plan()
    if case.pressure_accuracy is not None and case.step_tolerance > case.pressure_accuracy * PRESSURE_TOLERANCE:
        # a worn, conforming contact's pressure is sensitive to the wear profile: at the pressure-accuracy grids the
        # stepping's part of the pressure error grows past its estimate (McColl 185 N at 1769 elements: 2.2 %
        # between tolerance 1e-2 and 1e-4, estimated 0.8 %); scripts/study_grid_error.py --pressure
        tightened = float(f"{case.pressure_accuracy * PRESSURE_TOLERANCE:.6g}")
        plan.add(Choice("jumping.tolerance", tightened, f"model.pressure_accuracy {case.pressure_accuracy:.2g}: the "
                                                        f"stepping tolerance at most {PRESSURE_TOLERANCE:g} of it "
                                                        f"(was {case.step_tolerance:g})"))
        case = case.with_choices(step_tolerance=tightened)
    g = case.geometry
    e_star = effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                               case.stationary.youngs_modulus, case.stationary.poissons_ratio)
    k_m, k_s = case.wear_coefficients()
    problems: list = []
    hertz = g.hertz(case.normal_load, e_star)
    if case.stroke > MAX_STROKE_OVER_CONTACT * hertz.half_width_x:
        problems.append(("loading.stroke", f"the stroke amplitude {case.stroke:.4g} mm is "
                                           f"{case.stroke / hertz.half_width_x:.0f} times the Hertz contact "
                                           f"half-width ({hertz.half_width_x:.3g} mm); fretting is a small "
                                           f"oscillation (up to {MAX_STROKE_OVER_CONTACT:g} a here): check its unit"))
    reach = g.limits.reach_x
    if hertz.half_width_x >= reach:
        problems.append(("loading.normal_load", f"the unworn contact alone (Hertz half-width {hertz.half_width_x:.4g} "
                                                f"mm and peak pressure p0 = {hertz.peak_pressure:.4g} MPa under "
                                                f"{case.normal_load:.4g} N) reaches beyond {reach:.4g} mm, "
                                                f"half the body's radius, where its paraboloid (Eqs. 9–10) stops "
                                                f"describing it: no elastic contact model holds; check the load "
                                                f"and the radius and their units"))
    if problems:
        raise CaseError(case.source, problems)
    p0_ratio = hertz.peak_pressure / e_star
    if p0_ratio > ELASTIC_P0:
        plan.warnings.append(f"the Hertz peak pressure p0 = {hertz.peak_pressure:.4g} MPa is {p0_ratio:.1%} of the "
                             f"contact modulus E* = {e_star:.4g} MPa: well beyond the yield of the softer body for "
                             f"any metal (hardened bearing steel stays elastic to about 4 GPa, 3.5 % of its E*); the "
                             f"elastic model is out of its range, check the load and the moduli")
    onset = YIELD_ONSET["line" if hertz.line else "point"]
    for body, m in (("moving", case.moving), ("stationary", case.stationary)):
        if m.yield_strength is not None and hertz.peak_pressure > onset * m.yield_strength:
            plan.warnings.append(f"the Hertz peak pressure p0 = {hertz.peak_pressure:.4g} MPa passes the onset of "
                                 f"yield in the {body} body ({onset:g} × its yield strength {m.yield_strength:.4g} MPa "
                                 f"= {onset * m.yield_strength:.4g} MPa for a {'line' if hertz.line else 'point'} "
                                 f"contact): it yields below the surface, where the elastic model does not follow it")
    if hertz.half_width_x > SMALL_CONTACT * reach * 2:
        plan.warnings.append(f"the Hertz half-width a = {hertz.half_width_x:.4g} mm is {hertz.half_width_x / (2 * reach):.0%}"
                             f" of the radius: the half-space model assumes a ≪ R (beyond about "
                             f"{SMALL_CONTACT:.0%} its pressures are off by more than a few per cent)")
    sized = case.cycles
    if case.limits and case.cycles > 0 and (case.elements is None or "auto" in (case.dimension, case.corrections)):
        if _pilot is None:
            _pilot = pilot_cycles(case)
            _pilot = float("nan") if _pilot is None else _pilot
        if _pilot == _pilot and PILOT_MARGIN * _pilot < case.cycles:  # reached well before loading.cycles
            sized = max(1, int(PILOT_MARGIN * _pilot))
            plan.warnings.append(f"wear limits: the grid and auto's proxies take the wear of {sized:,} cycles, "
                                 f"{PILOT_MARGIN:g}× where a pilot on the paper's grid reached a limit "
                                 f"({_pilot:,.0f}); loading.cycles ({case.cycles:,}) is the upper bound")
    # auto's proxies compare the models' depths and widths: at a limit the limited one is pinned, so they run
    # without the limits, over the cycles the run will take
    proxy_case = case.with_choices(limits=(), cycles=sized) if case.limits else case
    dimension = plan.add(choose_dimension(proxy_case, e_star))
    plane = dimension == "2d"
    if plane and g.axial_profile:
        plan.warnings.append(f"the {g.kind}'s axial profile (its drop along y) is not modelled in 2D: a 2D run is "
                             f"the plane-strain section of a straight cylinder, the same whatever the profile; use "
                             f"model.dimension: 3d for the profile's effect")
    # one grid whatever the stepping, so that schemes compare on it; an explicit scheme whose stability limit falls
    # below a cycle on it is refused with the advice of grid.rule: paper
    accuracy = case.accuracy if case.grid_rule == "accuracy" else None
    history = case.history()
    # a load history: the smallest load's contact resolved, the scar of every block's wear held
    size_load = min(b.normal_load for b in history)
    volume = (k_m + k_s) * _worn_work(history, sized)
    sizing = auto_grid(g, plane, size_load, case.stroke, case.cycles, k_m + k_s, e_star, refine=_refine,
                       accuracy=accuracy, pressure_accuracy=case.pressure_accuracy, volume=volume)
    gap_probe = choose_gap_model(case, Grid.centred(3, 1, sizing.domain[0] / sizing.elements[0], 1.0, True))
    if gap_probe.value == "stroke_average":  # its wear reaches two strokes beyond the contact
        sizing = auto_grid(g, plane, size_load, case.stroke, case.cycles, k_m + k_s, e_star, strokes=2,
                           refine=_refine, accuracy=accuracy, pressure_accuracy=case.pressure_accuracy, volume=volume)
    c_domain, c_elements = choose_grid(case, plane, sizing)
    domain, elements = plan.add(c_domain), plan.add(c_elements)
    if len(domain) < (1 if plane else 2) or len(elements) < (1 if plane else 2):
        problems.append(("grid", "a 3d case needs two entries in grid.domain and grid.elements: [x, y]"))
        raise CaseError(case.source, problems)
    nx = elements[0]
    ny = 1 if plane else elements[1]
    snapshots = plan.add(choose_snapshots(case))
    coarse_n = 0
    if case.coarse_element is not None:
        if len(case.coarse_element) < (1 if plane else 2):
            problems.append(("grid.coarse_element", "a 3d case needs two entries: [dx, dy]"))
            raise CaseError(case.source, problems)
        cnx = max(3, int(round(domain[0] / case.coarse_element[0])))
        cny = 1 if plane else max(1, int(round(domain[1] / case.coarse_element[1])))
        coarse_n = cnx * cny
    need = memory_estimate(nx * ny, len(snapshots) + 5, case.solver, coarse_n)
    if g.body_corrections and case.corrections != "none":
        need += 8.0 * nx * nx  # a body's own compliance (the tube's ring bending): a dense matrix along x
    if g.free_faces and not plane and case.corrections != "none":
        need += 8.0 * ny * ny * (2 * nx) * 3  # the free faces' kernel between every pair of rows, and its symbol
    if need > MEMORY_SHARE * available_memory():
        problems.append(("grid", f"the grid of {nx} x {ny} elements{' (automatic)' if case.elements is None else ''}"
                                 f"{f' solved on {coarse_n} coarse elements' if coarse_n else ''} with solver "
                                 f"{case.solver}{f' (refined {_refine:.3g}× per axis for the partial-slip contact)' if _refine > 1 else ''}"
                                 f" would need about {need / 2**30:.1f} GiB, more than "
                                 f"{MEMORY_SHARE:.0%} of this machine's {available_memory() / 2**30:.0f} GiB; "
                                 f"coarsen the grid, shorten the run, or check the case's units"))
    if problems:
        raise CaseError(case.source, problems)
    dy = 1.0 if plane else domain[1] / ny
    grid = Grid.centred(nx, ny, domain[0] / nx, dy, plane_strain=plane)
    if case.stroke >= domain[0] / 2:
        problems.append(("loading.stroke", f"the stroke amplitude {case.stroke:.4g} mm is larger than half the "
                                           f"grid's x extent ({domain[0]:.4g} mm): check its unit"))
    if g.line_length is not None and not plane and domain[1] < g.line_length * (1 - 1e-9):
        problems.append(("grid.domain", f"the y extent {domain[1]:.4g} mm is shorter than the contact length "
                                        f"({g.line_length:.4g} mm): the contact would be cut off"))
    reach = stroke_reach(grid.dx, case.stroke)
    if nx <= 2 * reach + 4:
        problems.append(("grid.elements", f"{nx} elements along x leave no room for the stroke "
                                          f"({reach} elements each side)"))
    if problems:
        raise CaseError(case.source, problems)

    gap_model = plan.add(choose_gap_model(case, grid))
    coarse = coarse_gap = coarse_op = None
    if case.coarse_element is not None:
        coarse = Grid.centred(cnx, cny, domain[0] / cnx, 1.0 if plane else domain[1] / cny, plane_strain=plane)
        coarse_gap = g.separation(coarse)
        coarse_op = HalfSpace(coarse, e_star)
        plan.add(Choice("grid.coarse_element", case.coarse_element, f"given: contact solved on {cnx} x {cny} "
                                                                    f"elements, pressure refined to {nx} x {ny} "
                                                                    f"(Akima weights, Eqs. 11-12)", True))
    corrections = plan.add(choose_corrections(proxy_case, grid, e_star, sizing.scar_half_width))
    nu = max(case.moving.poissons_ratio, case.stationary.poissons_ratio)
    if "free_faces" in corrections and nu > 0.45:
        plan.warnings.append(f"Poisson's ratio {nu:g}: the free faces' finite-element block (bilinear elements) "
                             f"stiffens near incompressibility (1.3 % at ν = 0.45, 4.7 % at 0.49 against the "
                             f"half-space), so their effect is understated by about that much")

    def operator(on: Grid):
        extra = [g.extra_compliance(on, case.moving.youngs_modulus, case.moving.poissons_ratio)
                 for c in corrections if c == "ring_bending"]
        if "free_faces" in corrections:
            from fretsim.compliance.free_faces import free_faces
            bodies = {"moving": case.moving, "stationary": case.stationary}
            try:
                extra.append(free_faces(on, [(length, bodies[b].youngs_modulus, bodies[b].poissons_ratio)
                                             for b, length in g.free_faces]))
            except ValueError as exc:
                raise CaseError(case.source, [("grid.domain", f"model.corrections free_faces: {exc}")]) from None
        return add(HalfSpace(on, e_star), *extra)

    compliance = operator(grid)
    if coarse is not None:
        coarse_op = operator(coarse)
    solve_op = coarse_op if coarse_op is not None else compliance
    load = case.normal_load / g.line_length if plane else case.normal_load
    volume_factor = g.line_length if plane else 1.0
    tangential = transition = None
    history = case.history()
    regime_case = case  # the block nearest partial slip decides the cycle model of a load history
    if any(b.friction_coefficient is not None for b in history):
        tangential = tangential_operator(case, grid)
        worst = None
        for b in dict.fromkeys(history):
            if b.friction_coefficient is None:
                continue
            p_b = solve(compliance, g.separation(grid), b.normal_load / g.line_length if plane else b.normal_load,
                        tol=case.tolerance).pressure
            t_b = gross_slip_stroke(tangential, p_b, b.friction_coefficient)
            if worst is None or t_b / b.stroke > worst[0]:
                worst = (t_b / b.stroke, t_b, b)
        _, transition, b = worst
        if len(history) > 1:
            regime_case = case.with_choices(normal_load=b.normal_load, stroke=b.stroke,
                                            friction_coefficient=b.friction_coefficient)
    slip = choose_slip(regime_case, transition)
    if _refine == 1.0 and case.elements is None:
        # the same case on the grid partial slip needs, within a cap: a tiny stroke's annulus would need thousands
        # (counted from the paper's element along both axes: the accuracy rule refines x alone)
        refine = partial_slip_refinement(case, slip.value, transition, hertz.half_width_x,
                                         7 * hertz.half_width_x / ELEMENTS_OVER_7A)
        if refine > 1.0:
            return prepare(case, allow_unstable, _refine=min(refine, MAX_PARTIAL_SLIP_REFINEMENT), _pilot=_pilot)
    refine = partial_slip_refinement(case, slip.value, transition, hertz.half_width_x, grid.dx)
    if refine > 1.01:  # short of the target beyond round-off
        width = PARTIAL_SLIP_ELEMENTS * grid.dx / refine
        plan.warnings.append(f"partial slip: the narrower of the stick zone and the slip annulus (about "
                             f"{width * 1e3:.3g} µm along x) spans {PARTIAL_SLIP_ELEMENTS / refine:.2g} elements of "
                             f"{grid.dx * 1e3:.3g} µm, fewer than the {PARTIAL_SLIP_ELEMENTS} it needs"
                             + (f" (the automatic grid is refined at most {MAX_PARTIAL_SLIP_REFINEMENT:g}× per axis)"
                                if case.elements is None else " (grid.elements is given)")
                             + ": the wear step at the stick edge and the depths in the annulus are grid-limited; "
                               "give a finer grid.elements to resolve them")
    slip = plan.add(slip)
    stroke_model = plan.add(choose_stroke(case, slip, grid))
    if slip == "coulomb" or stroke_model == "resolved":
        _check_cycle_model(case, coarse, corrections, plan, transition)
        if stroke_model == "resolved":
            plan.add(Choice("model.gap", case.gap_model, "not used: the stroke is resolved, each position sees the "
                                                         "flat's wear under it", case.gap_model != "auto"))
            plan.warnings.append("model.stroke resolved: the worn profiles develop kinks where the contact's edges "
                                 "turn at the stroke's ends, with pressure peaks there that grow as the grid is "
                                 "refined (the depths and widths settle; the peak pressure does not), and the "
                                 "depths move with the step size by a few per cent (README: the resolved stroke)")
            if case.increments < 5:
                plan.warnings.append(f"model.increments {case.increments} with the stroke resolved: the contact "
                                     f"is solved at only {case.increments} position(s) per half-stroke, so each "
                                     f"point's travel over the worn flat is sampled coarsely (the default 9 agrees "
                                     f"with 65 to 0.6 % in depth: README)")
    spectrum = wear_spectrum(solve_op, case.stroke, k_m, k_s, "resolved" if stroke_model == "resolved" else gap_model)
    limit = spectrum.limit
    _check_model_growth(case, gap_model, spectrum, plan)
    scheme = plan.add(choose_scheme(case))
    jump = plan.add(choose_linear_jump(case, scheme, limit, solve_op.grid))
    if scheme in ("linear", "adaptive") and jump > limit and not allow_unstable:
        raise CaseError(case.source, [("jumping.linear", f"{jump} cycles exceeds the explicit stability limit "
                                      f"{limit:.4g} cycles of this grid (element {solve_op.grid.dx * 1e3:.3g} µm, "
                                      f"stroke {case.stroke * 1e3:.3g} µm): the pressure would checkerboard. Use at "
                                      f"most {max(1, int(limit))} (default: {default_linear_jump(limit, case.cycles)}"
                                      f"), or jumping.scheme: bdf2, which has no such limit"
                                      + (" (below one cycle even an update per cycle is unstable on this grid: "
                                         "grid.rule: paper gives the paper's coarser element, and a larger limit)"
                                         if limit < 1 and case.elements is None and case.grid_rule == "accuracy"
                                         else ""))])
    if scheme in ("linear", "adaptive") and jump > 0.5 * limit:
        plan.warnings.append(f"jumping.linear = {jump} lies between half the explicit stability limit and the "
                             f"limit ({limit:.4g} cycles): stable, but wear modes oscillate while they decay")
    max_jump = case.max_jump
    if scheme == "adaptive" and max_jump is None:
        max_jump = plan.add(Choice("jumping.max", 600, "the paper's ΔN_max"))
    if scheme == "adaptive" and max_jump > limit and not allow_unstable:
        # an adaptive jump extrapolates the wear explicitly: a jump of ΔN multiplies the grid-scale wear modes by up
        # to |1 − 2ΔN/limit|.  The linear steps between jumps damp them again, so the run stays bounded, but a
        # state after a jump rings: McColl 1670 N 2D with the paper's 600 (limit 159) ended 8 % (L2) from the
        # per-cycle pressure, ±40 % element to element at the contact's edges; capped, 0.25 %
        capped = max(jump, int(limit))
        plan.add(Choice("jumping.max", capped, f"{max_jump} capped at the explicit stability limit of this grid "
                                              f"({limit:.4g} cycles): an adaptive jump extrapolates the wear "
                                              f"explicitly, and one of {max_jump} cycles would multiply the grid-scale "
                                              f"wear modes {abs(1 - 2 * max_jump / limit):.1f}-fold, leaving the "
                                              f"pressure ringing at the contact's edges"))
        max_jump = capped
    plan.add(Choice("solver.method", case.solver, "given in the case" if case.solver != "cg" else
                    "cg: FFT-based constrained conjugate gradient, O(n log n) per iteration", case.solver != "cg"))
    cap = 0.5 / spectrum.growth_rate if spectrum.growth_rate > 0 else float("inf")
    per_cycle = limit > 1.0
    if scheme in ("bdf2", "implicit") and not per_cycle:
        plan.warnings.append(f"the paper's per-cycle update is itself unstable on this grid (explicit limit "
                             f"{limit:.3g} cycles < 1): the implicit steps follow the continuous wear ODE instead; "
                             f"check the wear coefficients, or coarsen the grid")
    beyond = [s for s in snapshots if s > case.cycles]
    if beyond:
        plan.warnings.append(f"snapshots {list(beyond)} lie beyond the run's {case.cycles} cycles and are skipped")
    snapshots = tuple(sorted({s for s in snapshots if s <= case.cycles} | {case.cycles}))
    loading = loading_of(case)

    def cycle_model(block):
        """The fretting-cycle model of one block of the loading."""
        b_load = block.normal_load / g.line_length if plane else block.normal_load
        mu = block.friction_coefficient
        if slip == "uniform" and stroke_model == "mid_stroke":
            b_km, b_ks = (k_m, k_s) if case.wear_law == "archard" else (
                case.moving.energy_wear_coefficient * mu, case.stationary.energy_wear_coefficient * mu)
            return UniformCycle(grid=grid, wear_op=wear_operator(solve_op.grid, block.stroke, b_km, b_ks, gap_model),
                                stroke=block.stroke, load=b_load, total_load=block.normal_load, k_moving=b_km,
                                k_stationary=b_ks, gap_model=gap_model, friction_coefficient=mu)
        law_m, law_s = ((case.moving.wear_coefficient, case.stationary.wear_coefficient) if case.wear_law == "archard"
                        else (case.moving.energy_wear_coefficient, case.stationary.energy_wear_coefficient))
        return CoulombCycle(grid=grid, compliance=compliance, tangential=tangential, stroke=block.stroke, load=b_load,
                            total_load=block.normal_load, friction_coefficient=mu,
                            k_moving=law_m, k_stationary=law_s, law=case.wear_law, slip=slip,
                            stroke_model=stroke_model, gap_model=gap_model, increments=case.increments,
                            volume_factor=volume_factor)

    built: dict = {}  # a repeated block shares its model (and its cached operators)
    block_models = tuple(built.setdefault(b, cycle_model(b)) for b in loading.blocks)
    model = block_models[0]
    reach = stroke_reach(grid.dx, case.stroke)
    band = (2 * reach if gap_model == "stroke_average" and stroke_model == "mid_stroke" else reach) + 1
    setup = Setup(grid=grid, compliance=compliance, gap=g.separation(grid), loading=loading, cycle=model,
                  block_cycles=block_models if len(block_models) > 1 else (),
                  wear_limits=dict(case.limits), wall=getattr(g, "wall", None) if case.limits else None,
                  limit_tolerance=case.step_tolerance * DEPTH_SHARE, frequency=case.frequency, band=band,
                  scheme=scheme, linear_jump=jump, stability_limit=limit, method=case.solver,
                  tolerance=case.tolerance, snapshots=snapshots,
                  volume_factor=volume_factor, limits=g.limits, y_edges_free=g.y_edges_free,
                  eta=case.eta, max_jump=max_jump, step_tolerance=case.step_tolerance, implicit_cap=cap, coarse=coarse,
                  coarse_compliance=coarse_op, coarse_gap=coarse_gap, per_cycle=per_cycle,
                  gross_slip_stroke=transition if transition is not None else float("nan"),
                  notes=tuple(f"{c.key} = {_show(c.value)}: {c.reason}" for c in plan.choices if not c.given)
                  + tuple(plan.warnings))
    filled = case.with_choices(dimension=dimension, corrections=corrections or "none",
                               domain=tuple(domain[:1] if plane else domain[:2]),
                               elements=(nx,) if plane else (nx, ny), gap_model=gap_model, scheme=scheme,
                               slip=slip, stroke_model=stroke_model,
                               linear_jump=jump, max_jump=max_jump, snapshots=snapshots)
    return setup, filled, plan


def _worn_work(history: tuple, cycles: int) -> float:
    """Σ Pᵢ·4δᵢ·Nᵢ over the first ``cycles`` cycles of the blocks (N·mm): times k, the worn volume."""
    work, left = 0.0, cycles
    for b in history:
        n = min(b.cycles, left)
        work += b.normal_load * 4 * b.stroke * n
        left -= n
        if left <= 0:
            break
    return work


def loading_of(case: Case) -> Loading:
    """The case's loading: its blocks in the order applied (one for a constant loading)."""
    return Loading(case.history())


def tangential_operator(case: Case, grid: Grid):
    """Both bodies' tangential compliance on the grid, the 2D datum and the rig's compliance
    (:mod:`fretsim.compliance.tangential`)."""
    from fretsim.compliance.tangential import Tangential
    plane = grid.plane_strain
    volume_factor = case.geometry.line_length if plane else 1.0
    rig = grid.area * volume_factor / case.tangential_stiffness if case.tangential_stiffness else 0.0
    bodies = [(m.youngs_modulus, m.poissons_ratio) for m in (case.moving, case.stationary)]
    return Tangential(grid, bodies, case.geometry.line_length if plane else None, rig)


def choose_slip(case: Case, transition: Optional[float]) -> Choice:
    """uniform (the paper's gross slip) or coulomb (friction resolved through the cycle).

    The regime follows from the unworn contact: gross slip needs the stroke to exceed δ_t, the rig displacement
    at which the last point starts to slide (δ_t = max K·μp: every point then carries μp; with the rig's 1/k
    included).  Below it the contact partly sticks and uniform slip is refused.  Above it every point still
    slides less than the rig by its elastic tangential displacement, at most δ_t: uniform slip overestimates
    the slip, and so the wear, by up to δ_t/δ; auto keeps uniform only where that is within model.accuracy.
    """
    mu = case.friction_coefficient
    if transition is not None and case.slip in ("uniform", "auto") and case.stroke <= transition:
        if case.slip == "uniform":
            raise CaseError(case.source, [("model.slip", f"uniform slip is refused here: the stroke "
                                                         f"{case.stroke * 1e3:.4g} µm is within the partial-slip "
                                                         f"limit δ_t = {transition * 1e3:.4g} µm for μ = {mu:g}, so "
                                                         f"the contact partly sticks and uniform slip (4δ at every "
                                                         f"point) would overestimate the wear; use model.slip: "
                                                         f"coulomb (or auto)")])
        return Choice("model.slip", "coulomb", f"partial slip: the stroke {case.stroke * 1e3:.4g} µm is within the "
                                               f"gross-slip limit δ_t = {transition * 1e3:.4g} µm (μ = {mu:g}): the "
                                               f"centre sticks and only the slip annulus wears")
    if case.slip != "auto":
        return Choice("model.slip", case.slip, "given in the case", True)
    if mu is None:
        return Choice("model.slip", "uniform", "no friction coefficient: the paper's gross slip is assumed (give "
                                               "loading.friction_coefficient to judge the regime)")
    deficit = transition / case.stroke
    if deficit > case.accuracy:
        return Choice("model.slip", "coulomb", f"gross slip (the stroke is {1 / deficit:.1f}× the limit δ_t = "
                                               f"{transition * 1e3:.4g} µm), but the bodies' elastic tangential "
                                               f"displacement takes up to δ_t/δ = {deficit:.1%} of the slip, more "
                                               f"than model.accuracy {case.accuracy:.1%}: Coulomb friction through "
                                               f"the cycle")
    return Choice("model.slip", "uniform", f"gross slip far above the limit: the stroke is {1 / deficit:.0f}× "
                                           f"δ_t = {transition * 1e3:.4g} µm, so uniform slip overestimates the "
                                           f"slip by at most δ_t/δ = {deficit:.2%}, within model.accuracy "
                                           f"{case.accuracy:.1%}", error=deficit)


PARTIAL_SLIP_ELEMENTS = 4  # across the stick zone and across the slip annulus, at least (as across a contact)
TRANSITION_BAND = 2.0  # strokes up to this many δ_t are refined as partial slip is: the worn contact may stick
MAX_PARTIAL_SLIP_REFINEMENT = 3.0  # per axis (9× the elements in 3D): beyond, the user is told and refines by hand


def partial_slip_refinement(case: Case, slip: str, transition: Optional[float], half_width: float, dx: float) -> float:
    """How much finer than 7a/40 the elements must be for a partial-slip contact: its stick zone and its slip
    annulus each need PARTIAL_SLIP_ELEMENTS, or the wear step at the stick edge lives within an element or two.
    c/a ≈ √(1 − δ/δ_t): exact for a ball (Mindlin: δ/δ_t = 1 − (1 − Q/μP)^{2/3}, c/a = (1 − Q/μP)^{1/3}), and
    for a line contact to within the datum's term, which is linear in Q."""
    if slip != "coulomb" or transition is None or not case.stroke < TRANSITION_BAND * transition:
        return 1.0
    if case.stroke >= transition:
        # gross slip at the start, but a worn centre stops sliding as its pressure grows (more pressure, less slip,
        # less wear): a stick zone forms and its edge feeds back on the wear.  At 7a/40 that feedback grew an
        # element-scale pattern (1.12 δ_t, the per-cycle run too); 8 elements across the half-width settle it
        narrowest = half_width / 2
    else:
        c = half_width * math.sqrt(max(0.0, 1.0 - case.stroke / transition))
        narrowest = min(c, half_width - c)
    return max(1.0, PARTIAL_SLIP_ELEMENTS * dx / max(narrowest, 1e-3 * half_width))


def choose_stroke(case: Case, slip: str, grid: Grid) -> Choice:
    """mid_stroke (one normal solve per cycle, the paper's) or resolved (one per increment, at each position)."""
    if case.stroke_model != "auto":
        return Choice("model.stroke", case.stroke_model, "given in the case", True)
    if slip == "uniform":
        return Choice("model.stroke", "mid_stroke", "the paper's: the pressure solved at mid-stroke, the flat "
                                                    "wearing with its stroke average")
    return Choice("model.stroke", "mid_stroke", "Mindlin's setting: the normal contact at mid-stroke held through "
                                                "the cycle, each point's slip and traction resolved in increments (a "
                                                "resolved stroke wears kinks where the contact's edges turn at the "
                                                "stroke's ends: README)")


def _check_cycle_model(case: Case, coarse, corrections, plan: Plan, transition: Optional[float]) -> None:
    """What the incremental cycle does not do, refused or said."""
    if coarse is not None:
        partial = transition is not None and case.stroke <= transition
        raise CaseError(case.source, [("grid.coarse_element", "grid refinement (Eqs. 11-12) applies to the "
                                                              "uniform-slip model at mid-stroke only; remove "
                                                              "grid.coarse_element" + (
                                                                  " (this stroke is in partial slip, where uniform "
                                                                  "slip is refused)" if partial else
                                                                  ", or use model.slip: uniform"))])
    from fretsim.reference.mindlin import dundurs_beta
    beta = dundurs_beta(case.moving.youngs_modulus, case.moving.poissons_ratio, case.stationary.youngs_modulus,
                        case.stationary.poissons_ratio)
    mu = case.friction_coefficient or 0.0
    if abs(beta) * mu > case.accuracy:
        plan.warnings.append(f"dissimilar materials: Dundurs' β = {beta:.3f}, so the shear traction changes the "
                             f"normal pressure by about βμ = {abs(beta) * mu:.1%} (first order), more than "
                             f"model.accuracy {case.accuracy:.1%}; fretsim solves the normal and tangential "
                             f"problems uncoupled and neglects it")
    if corrections:
        plan.warnings.append(f"the corrections {', '.join(corrections)} add normal compliance only: the tangential "
                             f"compliance is the half-spaces'")


def _check_model_growth(case: Case, gap_model: str, spectrum: Spectrum, plan: Plan) -> None:
    """The paper's gap model forced where it is unstable: refused if its spurious modes grow over the run."""
    rate = spectrum.growth_rate
    if rate <= 0:
        return
    growth = rate * case.cycles
    if growth > MODEL_GROWTH:
        raise CaseError(case.source, [("model.gap", f"the paper's mid-stroke gap is unstable for these wear "
                                                    f"coefficients (the moving body wears too little): its "
                                                    f"fastest wear mode grows by {rate:.3g} of itself per cycle, "
                                                    f"e^{growth:.0f} over the run. Use model.gap: auto (or "
                                                    f"stroke_average), which is stable")])
    plan.warnings.append(f"the mid-stroke gap model is unstable here (growth rate {rate:.3g} per cycle), but "
                         f"over {case.cycles} cycles a seed grows at most by a factor {math.exp(growth):.3g}")


def _show(value: Any) -> str:
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return f"{value:.4g}" if isinstance(value, float) else str(value)
