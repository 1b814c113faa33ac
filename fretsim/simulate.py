"""The contact–wear loop (paper Fig. 8, Eqs. 15–18).  Knows nothing of files or plots: observers get each step.

Per step: the pressure p for the current gap ε + h (h the total wear of both
bodies) → the flat's stroke-averaged pressure p_av → Archard increments of
both bodies → the next gap.  Each recorded step holds the wear at its cycle
and the pressure that wear produces, so histories and snapshots are
consistent.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import Callable, Optional, Protocol

import numpy as np

from fretsim.case import Case, CaseError
from fretsim.compliance import Compliance
from fretsim.geometry import initial_separation
from fretsim.grid import Grid
from fretsim.jumping import (CHECKERBOARD_LIMIT, Q_LINEAR, ImplicitCompliance, checkerboard_amplitude, default_linear_jump,
                             explicit_stability_limit, implicit_jump_cap, is_checkerboard_amplitude,
                             next_implicit_jump,
                             taylor_extrapolate, taylor_jump)
from fretsim.refine import coarsen, refine_pressure
from fretsim.reference import effective_modulus
from fretsim.sizing import auto_grid
from fretsim.solvers import check_resolution, solve
from fretsim.wear import archard_depth, archard_volume, stroke_average, stroke_weights

ARCHARD_ROUND_OFF = 1e-9
LOAD_BALANCE = 1e-8  # every solver enforces Σp·A = P exactly; a larger error is a solver fault
MAX_STROKE_OVER_CONTACT = 50.0  # δ/a beyond this is sliding, not fretting, or a unit slip (µm → mm)
MEMORY_SHARE = 0.5  # refuse a grid that would take more than this share of the machine's memory
# A Taylor jump is accepted only if it leaves the odd-even pressure amplitude below half the failure threshold:
# the linear steps that follow damp only the shortest waves strongly, so a jump gets no benefit of the doubt.
JUMP_ACCEPT = 0.5  # the volume is k·P·4δ·N by construction; anything larger is a bug


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
    scheme: str = "linear"  # linear | adaptive | implicit
    eta: float = 0.55
    max_jump: Optional[int] = None
    step_tolerance: float = 2e-3
    implicit_cap: float = float("inf")  # largest ΔN keeping the implicit compliance positive definite
    coarse: Optional[Grid] = None  # refinement: contact solved here, pressure refined to ``grid``
    coarse_compliance: Optional[Compliance] = None
    coarse_gap: Optional[np.ndarray] = None
    stop_on_checkerboard: bool = True
    body_radius: float = 0.0  # mm: the moving body is worn through when its wear reaches this
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
    jump: int = 0  # cycles since the previous step
    rejected: int = 0  # steps rejected by the error control since the previous accepted one
    volume_moving: float = 0.0  # mm³
    volume_stationary: float = 0.0
    archard_error: float = 0.0
    checkerboard: float = 0.0  # odd-even pressure amplitude / mean pressure
    state: dict = field(default_factory=dict)  # the loop's checkpoint after this step (for resuming)


class Observer(Protocol):
    def on_step(self, setup: Setup, step: Step) -> None: ...


def available_memory() -> int:
    """Physical memory of this machine in bytes."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 8 * 2**30


def memory_estimate(elements: int, snapshots: int, solver: str) -> float:
    """Bytes a run needs: ~40 work arrays, FFT buffers (4x, complex), 4 fields per snapshot, a dense matrix."""
    from fretsim.solvers import DENSE_SOLVERS
    need = 8.0 * elements * (40 + 4 * 2 * 4 + 4 * snapshots)
    if solver in DENSE_SOLVERS:
        need += 3 * 8.0 * elements**2  # the matrix, its gathered copy, the basis factors
    return need


def prepare(case: Case, allow_unstable: bool = False) -> tuple[Setup, Case]:
    """Unpack a case into arrays and numbers; fill the automatic choices into the returned case.

    A linear jump beyond the explicit stability limit is refused (CaseError) unless ``allow_unstable``
    (for studies of the instability itself).
    """
    e_star = effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                               case.stationary.youngs_modulus, case.stationary.poissons_ratio)
    k_m, k_s = case.moving.wear_coefficient, case.stationary.wear_coefficient
    plane = case.plane_strain
    notes = []
    sizing = auto_grid(case.geometry, case.dimension, case.radius, case.length, case.normal_load, case.stroke,
                       case.cycles, k_m + k_s, e_star)
    problems = []
    if case.stroke > MAX_STROKE_OVER_CONTACT * sizing.hertz_half_width:
        problems.append(("loading.stroke", f"the stroke amplitude {case.stroke:.4g} mm is "
                                           f"{case.stroke / sizing.hertz_half_width:.0f} times the Hertz contact "
                                           f"half-width ({sizing.hertz_half_width:.3g} mm); fretting is a small "
                                           f"oscillation (up to {MAX_STROKE_OVER_CONTACT:g} a here): check its unit"))
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
    need = memory_estimate(nx * ny, len(case.snapshots or ()) + 5, case.solver)
    if need > MEMORY_SHARE * available_memory():
        problems.append(("grid", f"the grid of {nx} x {ny} elements{' (automatic)' if case.elements is None else ''}"
                                 f" with solver {case.solver} would need about {need / 2**30:.1f} GiB, more than "
                                 f"{MEMORY_SHARE:.0%} of this machine's {available_memory() / 2**30:.0f} GiB; "
                                 f"coarsen the grid, shorten the run, or check the case's units"))
    if problems:
        raise CaseError(case.source, problems)
    dy = 1.0 if plane else domain[1] / ny
    grid = Grid.centred(nx, ny, domain[0] / nx, dy, plane_strain=plane)
    if case.scheme == "adaptive" and case.max_jump is None:
        case = case.with_choices(max_jump=600)  # the paper's ΔN_max
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
    coarse = coarse_gap = coarse_op = None
    if case.coarse_element is not None:
        cnx = max(3, int(round(domain[0] / case.coarse_element[0])))
        cny = 1 if plane else max(1, int(round(domain[1] / case.coarse_element[1])))
        coarse = Grid.centred(cnx, cny, domain[0] / cnx, 1.0 if plane else domain[1] / cny, plane_strain=plane)
        coarse_gap = initial_separation(case.geometry, coarse, case.radius, case.length)
        coarse_op = Compliance(coarse, e_star)
        notes.append(f"refinement: contact solved on {cnx} x {cny} elements of {coarse.dx * 1e3:.3g} x "
                     f"{coarse.dy * 1e3:.3g} µm, pressure refined to the {nx} x {ny} grid (Akima weights)")
    solve_grid = coarse if coarse is not None else grid
    limit = explicit_stability_limit(solve_grid, e_star, case.stroke, k_m, k_s)
    cap = implicit_jump_cap(solve_grid, e_star, case.stroke, k_m, k_s)
    jump = case.linear_jump if case.linear_jump is not None else default_linear_jump(limit, case.cycles)
    if case.scheme == "implicit":
        notes.append(f"implicit (backward-Euler) wear steps under error control, tolerance {case.step_tolerance:g}"
                     + (f", steps at most {cap:.4g} cycles (positive-definite limit)" if np.isfinite(cap) else ""))
    elif case.linear_jump is None:
        notes.append(f"linear jump {jump} cycles = half the explicit stability limit {limit:.4g}")
    elif jump > limit and not allow_unstable:
        raise CaseError(case.source, [("jumping.linear", f"{jump} cycles exceeds the explicit stability limit "
                                      f"{limit:.4g} cycles of this grid (element {solve_grid.dx * 1e3:.3g} µm, "
                                      f"stroke {case.stroke * 1e3:.3g} µm): the pressure would checkerboard. Use at "
                                      f"most {int(limit)} (default: {default_linear_jump(limit, case.cycles)}), "
                                      f"a coarser grid, or jumping.scheme: implicit, which has no such limit")])
    elif jump > 0.5 * limit:
        notes.append(f"jumping.linear = {jump} lies between half the explicit stability limit and the limit "
                     f"({limit:.4g} cycles): stable, but wear modes oscillate while they decay; the run stops if "
                     f"the pressure checkerboards")
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
                  y_edges_free=case.geometry == "cylinder_on_flat", scheme=case.scheme, eta=case.eta,
                  max_jump=case.max_jump, step_tolerance=case.step_tolerance, implicit_cap=cap, coarse=coarse,
                  coarse_compliance=coarse_op, coarse_gap=coarse_gap, body_radius=case.radius, notes=tuple(notes))
    filled = case.with_choices(domain=tuple(domain[:1] if plane else domain), elements=(nx,) if plane else (nx, ny),
                               linear_jump=jump, snapshots=snapshots)
    return setup, filled


def simulate(setup: Setup, observers: tuple = (), progress: Optional[Callable[[int], None]] = None,
             resume: Optional[dict] = None) -> Step:
    """Run the loop to ``setup.cycles``; returns the last step.  Raises :class:`SimulationError` on failure.

    ``resume`` is a checkpoint (``Step.state`` of an earlier run of the same setup): the loop continues from
    it and produces the same steps as the uninterrupted run.
    """
    return _Loop(setup, observers, progress).run(resume)


class PhysicalLimit(SimulationError):
    """The wear went through the body: the geometry means nothing beyond this cycle."""

    exit_code = 4


MAX_RETRIES = 8  # a failed solve is retried with a smaller jump this many times (implicit, adaptive)


class _Loop:
    """The loop's only mutable state: wear of both bodies, pressure, cycle, and the stepping scheme's memory.

    All of it is in the attributes listed in ``STATE``, which every emitted step carries as a checkpoint.
    """

    STATE = ("n", "h_m", "h_s", "p", "p_prev", "d_prev", "jump", "rejected", "batch", "elapsed")

    def __init__(self, setup: Setup, observers, progress):
        self.s = setup
        self.observers = observers
        self.progress = progress
        self.t0 = time.perf_counter()
        self.reach = (stroke_weights(setup.grid.dx, setup.stroke).size - 1) // 2
        self.stops = sorted(set(setup.snapshots) | {setup.cycles})
        self.n, self.d_prev, self.rejected, self.elapsed = 0, 1, 0, 0.0
        self.h_m = np.zeros(setup.grid.shape)
        self.h_s = np.zeros(setup.grid.shape)
        self.p = self.p_prev = None
        self.jump = float(min(setup.linear_jump, setup.implicit_cap))
        self.batch: list = []

    def state(self) -> dict:
        st = {k: getattr(self, k) for k in self.STATE}
        st["elapsed"] = self.elapsed + time.perf_counter() - self.t0
        st["batch"] = [a for pair in self.batch for a in pair]  # flat list of arrays: m0, s0, m1, s1, ...
        st["scheme"] = self.s.scheme
        return st

    def restore(self, st: dict) -> None:
        if st.get("scheme") != self.s.scheme:
            raise ValueError(f"the checkpoint is of scheme {st.get('scheme')!r}, the case of {self.s.scheme!r}")
        for k in self.STATE:
            if k in st:
                setattr(self, k, st[k])
        self.n, self.d_prev, self.rejected = int(self.n), int(self.d_prev), int(self.rejected)
        self.jump, self.elapsed = float(self.jump), float(self.elapsed)
        flat = list(st.get("batch", []))
        self.batch = [(flat[i], flat[i + 1]) for i in range(0, len(flat), 2)]
        self.t0 = time.perf_counter()

    # -- the contact solve, on the fine grid or on the coarse one with refinement (Eqs. 11-12) --
    def contact(self, cycle: int, guess, implicit_cycles: float = 0.0):
        s = self.s
        h = self.h_m + self.h_s
        if s.coarse is not None:
            op, gap = s.coarse_compliance, s.coarse_gap + coarsen(h, s.grid, s.coarse)
            guess = None if guess is None else coarsen(guess, s.grid, s.coarse)
        else:
            op, gap = s.compliance, s.gap + h
        if implicit_cycles:
            op = ImplicitCompliance(op, implicit_cycles, s.stroke, s.k_moving, s.k_stationary)
        res = solve(op, gap, s.load, method=s.method, p0=guess, tol=s.tolerance)
        if not res.success:
            raise NumericalFailure(f"the contact solve did not converge at cycle {cycle}: {res.message}", self.n)
        if not np.isfinite(res.pressure).all():
            raise NumericalFailure(f"non-finite pressure from the {s.method} solver at cycle {cycle}", self.n)
        if (res.pressure < 0).any():
            raise NumericalFailure(f"negative pressure from the {s.method} solver at cycle {cycle}", self.n)
        imbalance = float(res.pressure.sum()) * op.grid.area / s.load - 1.0
        if abs(imbalance) > LOAD_BALANCE:
            raise NumericalFailure(f"the {s.method} solution at cycle {cycle} violates the load balance by "
                                   f"{imbalance:.1e} (relative): the Archard invariant would break", self.n)
        p = res.pressure if s.coarse is None else refine_pressure(res.pressure, s.coarse, s.grid)
        _check_edges(p, self.reach, s.grid, cycle, s)
        return p, res

    def rates(self, p):
        """Wear per cycle of the moving and the stationary body for pressure p (Eqs. 15-16 with ΔN = 1)."""
        s = self.s
        return (archard_depth(s.k_moving, p, 1.0, s.stroke),
                archard_depth(s.k_stationary, stroke_average(p, s.grid.dx, s.stroke), 1.0, s.stroke))

    def next_stop(self) -> int:
        return next(t for t in self.stops if t > self.n)

    def emit(self, p, res, jump: int) -> Step:
        s = self.s
        self.p = p
        step = _record(s, self.n, self.h_m, self.h_s, p, res, self.t0 - self.elapsed)
        step.jump, step.rejected = jump, self.rejected
        self.rejected = 0
        if step.archard_error > ARCHARD_ROUND_OFF:
            raise NumericalFailure(f"the Archard invariant is broken at cycle {self.n}: wear volume differs from "
                                   f"k·P·4δ·N by {step.archard_error:.2e} (relative)", self.n)
        if s.stop_on_checkerboard and self.n > 0 and is_checkerboard_amplitude(step.checkerboard):
            what = (f"the linear jump {s.linear_jump} cycles is unstable" if s.scheme == "linear" else
                    f"the {s.scheme} step of {jump} cycles (linear jump {s.linear_jump}) is unstable")
            raise NumericalFailure(
                f"the pressure checkerboards at cycle {self.n}: {what} for this grid (explicit stability limit "
                f"{s.stability_limit:.4g} cycles); reduce jumping.linear (or jumping.max), leave them out for the "
                f"automatic choice, or use jumping.scheme: implicit", self.n)
        step.state = self.state()
        for obs in self.observers:
            obs.on_step(s, step)
        if self.progress is not None and jump:
            self.progress(jump)
        self._check_body(p)
        return step

    def _check_body(self, p) -> None:
        """Stop where the geometry stops meaning anything: worn through, or a scar past half the radius, where
        the paraboloid gap of Eqs. 9-10 departs from the circle by more than 7 %."""
        s = self.s
        if not s.body_radius:
            return
        depth = float(self.h_m.max())
        X, Y = s.grid.mesh()
        reach = float(np.sqrt(X**2 + (0 if s.y_edges_free else Y**2))[p > 0].max()) + s.grid.dx / 2
        if depth >= s.body_radius:
            raise PhysicalLimit(f"the moving body's wear depth {depth:.4g} mm reached its radius "
                                f"{s.body_radius:.4g} mm at cycle {self.n}: the body is worn through", self.n)
        if reach >= s.body_radius / 2:
            raise PhysicalLimit(f"the contact reached {reach:.4g} mm from the centre at cycle {self.n}, half the "
                                f"radius {s.body_radius:.4g} mm (wear depth {depth * 1e3:.4g} µm): beyond it the "
                                f"body's worn shape is no longer the paraboloid this model assumes", self.n)

    def advance(self, dh_m, dh_s, d_n: int) -> None:
        if (dh_m < 0).any() or (dh_s < 0).any():
            raise NumericalFailure(f"negative wear increment at cycle {self.n + d_n}", self.n)
        self.h_m = self.h_m + dh_m
        self.h_s = self.h_s + dh_s
        self.n += d_n

    def run(self, resume: Optional[dict] = None) -> Step:
        s = self.s
        step = None
        if resume is None:
            p, res = self.contact(0, None)
            try:
                check_resolution(res, (s.coarse or s.grid).plane_strain)
            except ValueError as exc:
                raise CaseError("grid", [("grid.elements", str(exc))]) from None
            step = self.emit(p, res, 0)
        else:
            self.restore(resume)
        if s.cycles == 0 or self.n >= s.cycles:
            return step
        return {"linear": self._linear, "adaptive": self._adaptive, "implicit": self._implicit}[s.scheme]() or step

    def _explicit_step(self, d_n):
        r_m, r_s = self.rates(self.p)
        self.advance(r_m * d_n, r_s * d_n, d_n)
        # predictor: extrapolate the pressure history so the warm start begins closer to the answer
        p = self.p
        guess = p if self.p_prev is None else np.clip(p + (p - self.p_prev) * (d_n / self.d_prev), 0.0, None)
        p_new, res = self.contact(self.n, guess)
        self.p_prev, self.d_prev = p, d_n
        return p_new, res

    def _linear(self) -> Step:
        step = None
        while self.n < self.s.cycles:
            d_n = min(self.s.linear_jump, self.next_stop() - self.n)
            p, res = self._explicit_step(d_n)
            step = self.emit(p, res, d_n)
        return step

    def _adaptive(self) -> Step:
        """Batches of Q_LINEAR linear steps, then a Taylor jump (paper Eqs. 19-21, Fig. 8), under control.

        The jump extrapolates with the current wear rates, so past the explicit stability limit it excites the
        odd-even pressure mode like a too-long linear step (measured: depth still within 1 %, pressure 14-26 %
        off).  A jump after which the pressure checkerboards, or whose solve fails, is undone and retried at
        half the length (counted as rejected); below the linear jump it becomes a linear step.  Jumps never
        end on a snapshot or the last cycle: those are reached by linear steps, so recorded states are
        stabilised.
        """
        s = self.s
        lin = s.linear_jump
        step = None
        if not self.batch:
            self.batch = [(self.h_m, self.h_s)]
        while self.n < s.cycles:
            room = self.next_stop() - self.n
            if len(self.batch) > Q_LINEAR and room > (Q_LINEAR + 1) * lin:
                (m2, s2), (m1, s1), (m0, s0) = self.batch[-3:]
                jump = min(taylor_jump([(m2, m1, m0), (s2, s1, s0)], lin, s.eta, s.max_jump or 600),
                           room - Q_LINEAR * lin)
                while jump > lin:
                    new_m = taylor_extrapolate(m2, m1, m0, lin, jump)
                    new_s = taylor_extrapolate(s2, s1, s0, lin, jump)
                    if not ((new_m >= m0).all() and (new_s >= s0).all()):
                        jump //= 2  # the quadratic term must not make an increment negative
                        continue
                    saved = (self.h_m, self.h_s, self.n)
                    self.advance(new_m - m0, new_s - s0, jump)
                    try:
                        p_jump, res = self.contact(self.n, self.p)
                        unstable = checkerboard_amplitude(res.pressure) > JUMP_ACCEPT * CHECKERBOARD_LIMIT
                    except NumericalFailure:
                        unstable = True
                    if unstable:
                        self.h_m, self.h_s, self.n = saved
                        self.rejected += 1
                        jump //= 2
                        continue
                    self.p_prev = None
                    self.batch = [(self.h_m, self.h_s)]
                    step = self.emit(p_jump, res, jump)
                    break
                else:
                    self.batch = [(self.h_m, self.h_s)]
                if jump > lin:
                    continue
            d_n = min(lin, room)
            p, res = self._explicit_step(d_n)
            # a shortened step breaks the equal spacing the differences need: restart the batch
            self.batch = self.batch + [(self.h_m, self.h_s)] if d_n == lin else [(self.h_m, self.h_s)]
            step = self.emit(p, res, d_n)
        return step

    def _implicit(self) -> Step:
        """Backward-Euler wear steps, each a contact solve with C + ΔN·4δ·(k_m I + k_s B), under error control.

        The local error of a backward-Euler step is about (ΔN/2)·(r_{n+1} − r_n) (r the wear rate per cycle);
        its root-mean-square over the grid, relative to that of the body's depth after the step, must stay
        below the tolerance, else the step is redone smaller.  (A maximum norm would be ruled by the few
        elements entering contact at the scar's edge, whose share of the depth error is small.)  Accepted
        steps grow geometrically while the scar settles.  A solve that fails is retried with a quarter step.
        """
        s = self.s
        step = None
        r_old = self.rates(self.p)
        retries = 0
        while self.n < s.cycles:
            d_n = int(max(1, min(self.jump, self.next_stop() - self.n, s.implicit_cap, s.max_jump or np.inf)))
            p = self.p
            guess = p if self.p_prev is None else np.clip(p + (p - self.p_prev) * (d_n / self.d_prev), 0.0, None)
            try:
                p_new, res = self.contact(self.n + d_n, guess, implicit_cycles=d_n)
            except NumericalFailure:
                if d_n == 1 or retries >= MAX_RETRIES:
                    raise
                retries += 1
                self.rejected += 1
                self.jump = max(1.0, d_n / 4)
                continue
            r_new = self.rates(p_new)
            error = 0.0
            for (old, new), h in zip(zip(r_old, r_new), (self.h_m, self.h_s)):
                depth = float(np.linalg.norm(h + d_n * new))
                if depth > 0:
                    error = max(error, 0.5 * d_n * float(np.linalg.norm(new - old)) / depth)
            if error > 1.5 * s.step_tolerance and d_n > 1:
                self.rejected += 1
                self.jump = next_implicit_jump(d_n, error, s.step_tolerance)
                continue
            retries = 0
            self.advance(r_new[0] * d_n, r_new[1] * d_n, d_n)
            self.p_prev, self.d_prev = p, d_n
            r_old = r_new
            self.jump = next_implicit_jump(d_n, error, s.step_tolerance)
            step = self.emit(p_new, res, d_n)
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
                volume_moving=v_m, volume_stationary=v_s, archard_error=err,
                # on the grid the contact is solved on: with refinement the fine pressure is smooth by construction
                checkerboard=checkerboard_amplitude(res.pressure))


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
