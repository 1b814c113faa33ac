"""The contact–wear loop (paper Fig. 8, Eqs. 15–18).  Knows nothing of files or plots: observers get each step.

Per step: the pressure p for the current gap ε + h (h the total wear of both
bodies) → the flat's stroke-averaged pressure p_av → Archard increments of
both bodies → the next gap.  Each recorded step holds the wear at its cycle
and the pressure that wear produces, so histories and snapshots are
consistent.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Optional, Protocol

import numpy as np

from fretsim.case import Case, CaseError
from fretsim.compliance import Compliance
from fretsim.geometry import initial_separation
from fretsim.grid import Grid
from fretsim.jumping import (checkerboard_amplitude, default_linear_jump, explicit_stability_limit, is_checkerboard,
                             linear_schedule)
from fretsim.reference import effective_modulus
from fretsim.sizing import auto_grid
from fretsim.solvers import check_resolution, solve
from fretsim.wear import archard_depth, archard_volume, stroke_average, stroke_weights

ARCHARD_ROUND_OFF = 1e-9  # the volume is k·P·4δ·N by construction; anything larger is a bug


class SimulationError(Exception):
    """A run that had to stop: ``cycle`` is the last cycle reached."""

    exit_code = 3

    def __init__(self, message: str, cycle: int):
        super().__init__(message)
        self.cycle = cycle


class NumericalFailure(SimulationError):
    """No convergence, NaN, instability or a broken invariant."""


class DomainError(SimulationError):
    """The contact outgrew the grid."""


@dataclass(frozen=True)
class Setup:
    """Everything the loop needs, as arrays and numbers (built from a case by :func:`prepare`)."""

    grid: Grid
    compliance: Compliance
    gap: np.ndarray  # initial separation ε (mm), +inf where no contact is possible
    load: float  # on the grid: N (3D) or N/mm (2D)
    total_load: float  # N
    k_moving: float
    k_stationary: float
    stroke: float
    cycles: int
    linear_jump: int
    stability_limit: float
    method: str
    tolerance: float
    snapshots: tuple[int, ...]
    volume_factor: float  # grid volume → mm³ (the cylinder length in 2D)
    y_edges_free: bool = False  # True for a cylinder: its ends are where the contact may stop
    notes: tuple[str, ...] = ()


@dataclass
class Step:
    cycle: int
    wear_moving: np.ndarray  # mm
    wear_stationary: np.ndarray  # mm
    pressure: np.ndarray  # MPa, on the moving body at mid-stroke
    pressure_average: np.ndarray  # MPa, stroke-averaged, on the stationary body
    iterations: int
    wall_time: float  # s since the start of the run
    approach: float
    is_snapshot: bool
    volume_moving: float = 0.0  # mm³
    volume_stationary: float = 0.0
    archard_error: float = 0.0
    checkerboard: float = 0.0  # odd-even pressure amplitude / mean pressure
    extra: dict = field(default_factory=dict)


class Observer(Protocol):
    def on_step(self, setup: Setup, step: Step) -> None: ...


def prepare(case: Case) -> tuple[Setup, Case]:
    """Unpack a case into arrays and numbers; fill the automatic choices into the returned case."""
    e_star = effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                               case.stationary.youngs_modulus, case.stationary.poissons_ratio)
    k_m, k_s = case.moving.wear_coefficient, case.stationary.wear_coefficient
    plane = case.plane_strain
    notes = []
    sizing = auto_grid(case.geometry, case.dimension, case.radius, case.length, case.normal_load, case.stroke,
                       case.cycles, k_m + k_s, e_star)
    domain = case.domain
    elements = case.elements
    if domain is None and elements is None:
        domain, elements = sizing.domain, sizing.elements
        notes.append("automatic grid: " + sizing.note)
    elif elements is None:
        dx = sizing.domain[0] / sizing.elements[0]
        elements = tuple(max(1, int(round(d / dx))) | 1 for d in domain[:1]) + (
            (sizing.elements[1],) if not plane else ())
        notes.append(f"elements from the 7a/40 rule for the given domain: {elements}")
    elif domain is None:
        domain = sizing.domain
        notes.append(f"automatic domain for the given elements: {domain}")
    nx = elements[0]
    ny = 1 if plane else elements[1]
    dy = 1.0 if plane else domain[1] / ny
    grid = Grid.centred(nx, ny, domain[0] / nx, dy, plane_strain=plane)
    problems = []
    if case.stroke >= domain[0] / 2:
        problems.append(("loading.stroke", f"the stroke amplitude {case.stroke:.4g} mm is larger than half the "
                                           f"grid's x extent ({domain[0]:.4g} mm): check its unit"))
    if case.geometry == "cylinder_on_flat" and not plane and domain[1] < case.length * (1 - 1e-9):
        problems.append(("grid.domain", f"the y extent {domain[1]:.4g} mm is shorter than the cylinder "
                                        f"({case.length:.4g} mm): the contact would be cut off"))
    reach = (stroke_weights(grid.dx, case.stroke).size - 1) // 2
    if nx <= 2 * reach + 4:
        problems.append(("grid.elements", f"{nx} elements along x leave no room for the stroke "
                                          f"({reach} elements each side)"))
    if problems:
        raise CaseError(case.source, problems)
    gap = initial_separation(case.geometry, grid, case.radius, case.length)
    load = case.normal_load / case.length if plane else case.normal_load
    limit = explicit_stability_limit(grid, e_star, case.stroke, k_m, k_s)
    jump = case.linear_jump if case.linear_jump is not None else default_linear_jump(limit, case.cycles)
    if case.linear_jump is None:
        notes.append(f"linear jump {jump} cycles = half the explicit stability limit {limit:.4g}")
    elif jump > limit:
        notes.append(f"WARNING: jumping.linear = {jump} exceeds the explicit stability limit {limit:.4g} cycles "
                     f"for this grid; the run is checked for checkerboarding and stops if it appears")
    snapshots = case.snapshots
    if snapshots is None:
        snapshots = tuple(sorted({0, case.cycles // 4, case.cycles // 2, 3 * case.cycles // 4, case.cycles}))
    beyond = [s for s in snapshots if s > case.cycles]
    if beyond:
        notes.append(f"snapshots {beyond} lie beyond the run's {case.cycles} cycles and are skipped")
    snapshots = tuple(sorted({s for s in snapshots if s <= case.cycles} | {case.cycles}))
    setup = Setup(grid=grid, compliance=Compliance(grid, e_star), gap=gap, load=load, total_load=case.normal_load,
                  k_moving=k_m, k_stationary=k_s, stroke=case.stroke, cycles=case.cycles, linear_jump=jump,
                  stability_limit=limit, method=case.solver, tolerance=case.tolerance, snapshots=snapshots,
                  volume_factor=case.length if plane else 1.0,
                  y_edges_free=case.geometry == "cylinder_on_flat", notes=tuple(notes))
    filled = case.with_choices(domain=tuple(domain[:1] if plane else domain), elements=(nx,) if plane else (nx, ny),
                               linear_jump=jump, snapshots=snapshots)
    return setup, filled


def simulate(setup: Setup, observers: tuple = (), progress: Optional[Callable[[int], None]] = None) -> Step:
    """Run the loop to ``setup.cycles``; returns the last step.  Raises :class:`SimulationError` on failure."""
    t0 = time.perf_counter()
    grid = setup.grid
    reach = (stroke_weights(grid.dx, setup.stroke).size - 1) // 2
    h_m = np.zeros(grid.shape)
    h_s = np.zeros(grid.shape)

    def contact(cycle: int, guess: Optional[np.ndarray]):
        res = solve(setup.compliance, setup.gap + h_m + h_s, setup.load, method=setup.method, p0=guess,
                    tol=setup.tolerance)
        if not res.success:
            raise NumericalFailure(f"the contact solve did not converge at cycle {cycle}: {res.message}", cycle)
        if not np.isfinite(res.pressure).all():
            raise NumericalFailure(f"non-finite pressure at cycle {cycle}", cycle)
        _check_edges(res.pressure, reach, grid, cycle, setup)
        return res

    res = contact(0, None)
    try:
        check_resolution(res, grid.plane_strain)
    except ValueError as exc:
        raise CaseError("grid", [("grid.elements", str(exc))]) from None
    p = res.pressure
    p_prev, step_prev = None, None
    n = 0
    step = _record(setup, 0, h_m, h_s, p, res, t0)
    for obs in observers:
        obs.on_step(setup, step)
    for d_n in linear_schedule(setup.cycles, setup.linear_jump, setup.snapshots):
        p_av = step.pressure_average
        dh_m = archard_depth(setup.k_moving, p, d_n, setup.stroke)
        dh_s = archard_depth(setup.k_stationary, p_av, d_n, setup.stroke)
        if (dh_m < 0).any() or (dh_s < 0).any():
            raise NumericalFailure(f"negative wear increment at cycle {n + d_n}", n)
        h_m = h_m + dh_m
        h_s = h_s + dh_s
        n += d_n
        # predictor: extrapolate the pressure history so the warm start begins closer to the answer
        guess = p if p_prev is None else np.clip(p + (p - p_prev) * (d_n / step_prev), 0.0, None)
        p_prev, step_prev = p, d_n
        res = contact(n, guess)
        p = res.pressure
        step = _record(setup, n, h_m, h_s, p, res, t0)
        if step.archard_error > ARCHARD_ROUND_OFF:
            raise NumericalFailure(f"the Archard invariant is broken at cycle {n}: wear volume differs from "
                                   f"k·P·4δ·N by {step.archard_error:.2e} (relative)", n)
        if is_checkerboard(p):
            raise NumericalFailure(
                f"the pressure checkerboards at cycle {n}: the linear jump {setup.linear_jump} cycles is unstable "
                f"for this grid (explicit stability limit {setup.stability_limit:.4g} cycles); reduce "
                f"jumping.linear or leave it out for the automatic choice", n)
        for obs in observers:
            obs.on_step(setup, step)
        if progress is not None:
            progress(d_n)
    return step


def _check_edges(p: np.ndarray, reach: int, grid: Grid, cycle: int, setup: Setup) -> None:
    """Pressure within the stroke's reach of the x edges (or on the y edges of a ball) would be truncated."""
    band = reach + 1
    loaded_cols = np.flatnonzero((p > 0).any(axis=0))
    hit_x = loaded_cols.size and (loaded_cols[0] < band or loaded_cols[-1] >= grid.shape[1] - band)
    hit_y = False
    if not grid.plane_strain and not setup.y_edges_free:
        rows = np.flatnonzero((p > 0).any(axis=1))
        hit_y = rows.size and (rows[0] == 0 or rows[-1] == grid.shape[0] - 1)
    if hit_x or hit_y:
        extent = (grid.x[-1] - grid.x[0] + grid.dx) if hit_x else (grid.y[-1] - grid.y[0] + grid.dy)
        raise DomainError(f"the contact reached the {'x' if hit_x else 'y'} edge of the grid at cycle {cycle} "
                          f"(extent {extent:.4g} mm): enlarge grid.domain, or leave grid empty for automatic "
                          f"sizing", cycle)


def _record(setup: Setup, cycle: int, h_m, h_s, p, res, t0) -> Step:
    area = setup.grid.area * setup.volume_factor
    v_m = float(h_m.sum()) * area
    v_s = float(h_s.sum()) * area
    err = 0.0
    if cycle > 0:
        expect_m = archard_volume(setup.k_moving, setup.total_load, cycle, setup.stroke)
        expect_s = archard_volume(setup.k_stationary, setup.total_load, cycle, setup.stroke)
        err = max(abs(v_m / expect_m - 1) if expect_m else abs(v_m),
                  abs(v_s / expect_s - 1) if expect_s else abs(v_s))
    return Step(cycle=cycle, wear_moving=h_m, wear_stationary=h_s, pressure=p,
                pressure_average=stroke_average(p, setup.grid.dx, setup.stroke), iterations=res.iterations,
                wall_time=time.perf_counter() - t0, approach=res.approach, is_snapshot=cycle in setup.snapshots,
                volume_moving=v_m, volume_stationary=v_s, archard_error=err, checkerboard=checkerboard_amplitude(p))


def centre_line(field_2d: np.ndarray) -> np.ndarray:
    """Values along y = 0: the middle row, or the mean of the two middle rows when My is even."""
    ny = field_2d.shape[0]
    return field_2d[ny // 2] if ny % 2 else 0.5 * (field_2d[ny // 2 - 1] + field_2d[ny // 2])


def summarize(setup: Setup, step: Step, solves: int, wall_time: float) -> dict:
    """The /summary figures (names are a contract; see README)."""
    h_s_c = centre_line(step.wear_stationary)
    worn = np.flatnonzero(h_s_c > 1e-3 * h_s_c.max()) if h_s_c.max() > 0 else np.array([], int)
    scar = (worn[-1] - worn[0] + 1) * setup.grid.dx if worn.size else 0.0
    return {
        "cycles": int(step.cycle),
        "contact_solves": int(solves),
        "wall_time_s": float(wall_time),
        "max_wear_depth_moving_um": float(step.wear_moving.max()) * 1e3,
        "max_wear_depth_stationary_um": float(step.wear_stationary.max()) * 1e3,
        "centre_wear_depth_moving_um": float(centre_line(step.wear_moving).max()) * 1e3,
        "centre_wear_depth_stationary_um": float(h_s_c.max()) * 1e3,
        "scar_width_stationary_mm": float(scar),
        "wear_volume_moving_mm3": step.volume_moving,
        "wear_volume_stationary_mm3": step.volume_stationary,
        "archard_volume_error": float(step.archard_error),
        "max_pressure_MPa": float(step.pressure.max()),
        "linear_jump": int(setup.linear_jump),
        "stability_limit_linear": float(setup.stability_limit),
        "element_size_x_um": setup.grid.dx * 1e3,
        "element_size_y_um": setup.grid.dy * 1e3 if not setup.grid.plane_strain else float("nan"),
        "elements_x": int(setup.grid.shape[1]),
        "elements_y": int(setup.grid.shape[0]),
    }
