"""The contact–wear loop (paper Fig. 8, Eqs. 15–18).  Knows nothing of files or plots: observers get each step.

Per step: one representative fretting cycle at the current wear (a member of :mod:`fretsim.cycle`: the
pressure, each body's slip and wear per cycle) → the stepping scheme (a member of :mod:`fretsim.stepping`)
advances the wear → the next cycle.  The loop never looks inside the cycle: it steps the wear with the rates the
cycle returns and checks the member's invariant.  Each recorded step holds the wear at its cycle and the cycle
that wear produces, so histories and snapshots are consistent.  The loop takes a :class:`Setup` — arrays,
numbers, operators, the loading and the cycle model, built from a case by :func:`fretsim.plan.prepare`.

This module keeps the loop's state and its one step (solve, record, check); what the state is on disk
(:mod:`fretsim.loop.checkpoint`), a load history's block switching (:mod:`fretsim.loop.blocks`), landing on a
wear limit (:mod:`fretsim.loop.landing`) and the guards every step passes (:mod:`fretsim.loop.checks`) are
units of their own.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Optional, Protocol

import numpy as np

from fretsim.compliance import add
from fretsim.cycle import Cycle, CycleError
from fretsim.cycle.result import TRACTIONS
from fretsim.errors import DomainError, NumericalFailure, PhysicalLimit, ResolutionError, SimulationError
from fretsim.fatigue.damage import summary as fatigue_summary
from fretsim.geometry import Limits
from fretsim.grid import Grid
from fretsim.loading import Loading
from fretsim.loop import blocks, checkpoint, checks, fatigue
from fretsim.loop.landing import Landing, Reached
from fretsim.loop.rows import NormalSolve
from fretsim.quantities import wear_summary
from fretsim.refine import coarsen, refine_pressure
from fretsim.regrid import Coarsen
from fretsim.solvers import solve
from fretsim.stability import GrowthWatch, checkerboard_signed
from fretsim.stepping import SCHEMES, relative_change
from fretsim.stepping.implicit import DEPTH_SHARE, at_deepest, relative_to_deepest

__all__ = ["DEPTH_SHARE", "DomainError", "NumericalFailure", "Observer", "PhysicalLimit", "ResolutionError", "Setup",
           "SimulationError", "Step", "simulate", "summarize"]


@dataclass(frozen=True)
class Setup:
    """Everything the loop needs, as arrays, numbers and operators (built from a case by ``plan.prepare``)."""

    grid: Grid
    compliance: object  # the influence operator on ``grid`` (fretsim.compliance)
    gap: np.ndarray  # initial separation ε (mm), +inf where no contact is possible
    loading: Loading
    cycle: object  # the fretting-cycle model (fretsim.cycle): what one cycle does at a wear state
    band: int  # elements from the x edges the pressure must keep clear of (the flat's wear reaches that far)
    scheme: str  # bdf2 | implicit | linear | adaptive
    linear_jump: int
    stability_limit: float
    method: str
    tolerance: float
    snapshots: tuple[int, ...]
    volume_factor: float  # grid volume → mm³ (the line length in 2D)
    limits: Optional[Limits] = None
    y_edges_free: bool = False  # True for a line contact: its ends are where the contact may stop
    eta: float = 0.55
    max_jump: Optional[int] = None
    step_tolerance: float = 1e-2
    implicit_cap: float = float("inf")  # largest s keeping C + s·W positive definite
    coarse: Optional[Grid] = None  # refinement: contact solved here, pressure refined to ``grid``
    coarse_compliance: object = None
    coarse_gap: Optional[np.ndarray] = None
    watch_growth: bool = True  # stop when an odd-even pressure pattern grows (off only to study instability)
    per_cycle: bool = True  # implicit schemes follow the per-cycle update (φ = h + ½r), not the continuous ODE
    gross_slip_stroke: float = float("nan")  # mm: δ_t of the unworn contact (NaN without a friction coefficient)
    regime_block: Optional[object] = None  # the block δ_t is of (the one nearest partial slip)
    stick_cycles: int = 0  # cycles of the blocks in partial slip (unworn): what the stepping's estimate counts
    notes: tuple[str, ...] = ()
    planned_extent: float = 0.0  # mm along x: the grid that holds the final scar the plan expects (a grid that
    #                              follows the contact starts smaller and widens to it: fretsim.regrid.allowed)
    expected_stop: float = float("inf")  # cycles: where a pilot run reached a wear limit (the cost estimate's end)
    block_cycles: tuple = ()  # a load history: the cycle model of each block of ``loading`` (empty: ``cycle``)
    wear_limits: dict = field(default_factory=dict)  # fretsim.limits: key -> limit (internal units)
    wall: Optional[float] = None  # mm, a tube's wall thickness (the wall_loss limit)
    limit_tolerance: float = 1e-3  # relative: the crossing cycle of a limit is found to this
    frequency: Optional[float] = None  # Hz: the time to a limit
    fatigue: Optional[object] = None  # fretting fatigue of the flat (fretsim.fatigue.damage.FatigueSpec), opt-in
    fatigue_moving: Optional[object] = None  # ... of the moving body (its own half-space), opt-in

    @property
    def fatigue_specs(self) -> tuple:
        """The bodies' fatigue specs given (the flat's first): what the loop counts the damage of."""
        return tuple(f for f in (self.fatigue, self.fatigue_moving) if f is not None)

    @property
    def solve_grid(self) -> Grid:
        return self.coarse if self.coarse is not None else self.grid

    @property
    def stepper(self):
        """The stepping scheme (a member of fretsim.stepping)."""
        return SCHEMES[self.scheme]

    @property
    def cycles(self) -> int:
        return self.loading.cycles


@dataclass
class Step:
    cycle: int
    wear_moving: np.ndarray  # mm
    wear_stationary: np.ndarray  # mm
    pressure: np.ndarray  # MPa, on the moving body at mid-stroke
    pressure_average: np.ndarray  # MPa, stroke-averaged, on the stationary body
    cycle_result: Cycle  # the representative cycle at this state: slips, shear, energy, loop
    iterations: int
    wall_time: float  # s since the start of the run
    approach: float
    is_snapshot: bool
    jump: int = 0  # cycles since the previous step
    rejected: int = 0  # steps rejected by the error control since the previous accepted one
    volume_moving: float = 0.0  # mm³
    volume_stationary: float = 0.0
    archard_error: float = 0.0
    checkerboard: float = 0.0  # signed odd-even pressure amplitude / mean pressure
    error_depth: float = 0.0  # the run's estimate of the relative depth error (accumulated)
    error_pressure: float = 0.0  # the run's estimate of the relative pressure error (L2) of this state
    work: float = 0.0  # the member's invariant accumulated to this cycle (volume = k·work), N·mm
    energy: float = 0.0  # the energy dissipated by friction from cycle 0 to this one, N·mm (NaN: no μ)
    block: int = 0  # the loading's block whose cycles led to this state (0 at the start)
    limit: Optional[tuple] = None  # (key, crossing cycle, its interpolation spread): the wear limit reached here
    fatigue: Optional[object] = None  # the flat's fatigue at this state (fretsim.fatigue.damage.FatigueState)
    fatigue_moving: Optional[object] = None  # the moving body's
    state: dict = field(default_factory=dict)  # the loop's checkpoint after this step (for resuming)


class Observer(Protocol):
    def on_step(self, setup: Setup, step: Step) -> None: ...


def simulate(setup: Setup, observers: tuple = (), progress: Optional[Callable[[int], None]] = None,
             resume: Optional[dict] = None, coarsen: Optional[Callable] = None) -> Step:
    """Run the loop to ``setup.cycles``; returns the last step.  Raises :class:`SimulationError` on failure.

    ``resume`` is a checkpoint (``Step.state`` of an earlier run of the same setup): the loop continues from
    it and produces the same steps as the uninterrupted run.  ``coarsen(setup, step)``, given, is asked after
    each accepted step whether the grid may coarsen (a reason, or None); where it may, :class:`fretsim.regrid.
    Coarsen` is raised with the step, which the observers have already had (:mod:`fretsim.regrid`).
    """
    loop = _Loop(setup, observers, progress)
    loop.coarsen = coarsen
    return loop.run(resume)


class _Loop:
    """The loop's only mutable state: wear of both bodies, the current cycle's pressure and rates, cycle, and the
    stepping scheme's memory (the implicit schemes' ``history``, the adaptive ``batch``).

    All of it goes into the checkpoint every emitted step carries (:mod:`fretsim.loop.checkpoint`).  Besides the
    wear, the loop carries ``work``: the member's invariant (volume = k·work) advanced by the same formulas as
    the wear, so a broken spatial update shows as a volume off its invariant; and ``energy``, the energy dissipated
    by friction (Fouvry's abscissa), advanced by the same formulas again from each cycle's, so it is the sum over
    the cycles the wear is, under any cycle jumping.  Where a cycle knows no energy (no friction coefficient) the
    rate counts 0 and ``energy_known`` is cleared: what the loop reports from then on is NaN.
    """

    def __init__(self, setup: Setup, observers, progress):
        self.s = setup
        self.model = setup.block_cycles[0] if setup.block_cycles else setup.cycle
        self.observers = observers
        self.progress = progress
        self.t0 = time.perf_counter()
        self.base_stops = sorted(set(setup.snapshots) | {setup.cycles} | set(setup.loading.boundaries))
        self.stops = list(self.base_stops)  # and, with wear limits, the crossings a retaken step lands on
        # block ends that are not also recorded states (snapshots, the last cycle)
        self.boundaries = set(setup.loading.boundaries) - set(setup.snapshots) - {setup.cycles}
        self.n, self.rejected, self.elapsed = 0, 0, 0.0
        self.block, self.block_start = 0, 0  # the block whose cycle model gives the current rates, and its start
        self.work_bound = 0.0  # the largest wear work the blocks before the current one allow (N·mm)
        self.landing = Landing()
        self.reached: Optional[tuple] = None  # the wear limit the run ended at (Step.limit), once it has
        self.last_state: Optional[dict] = None
        self.h_m = np.zeros(setup.grid.shape)
        self.h_s = np.zeros(setup.grid.shape)
        self.p = self.p_prev = None
        self.r_m = self.r_s = None  # wear per cycle at the current state (the current cycle's)
        self.work = self.rate_work = 0.0  # accumulated invariant, and its rate per cycle at the current state
        self.energy = self.rate_energy = 0.0  # dissipated energy accumulated (N·mm), and per cycle at the state
        self.energy_known = 1  # 0 once a cycle without a friction coefficient counted (the checkpoint holds no NaN)
        self.memory: dict = {}  # the cycle model's own memory (its lagged slips)
        self.cyc: Optional[Cycle] = None
        self.d_prev = 1
        self.jump = 1.0
        self.lag = 0.0  # pressure lag per cycle of step (the last step's estimate / its length)
        self.err_abs_m = self.err_abs_s = 0.0  # accumulated local depth errors (mm, the largest element's)
        self.history: list = []  # implicit schemes: (N, φ_m, φ_s, p, φ_work, φ_energy)
        self.batch: list = []  # adaptive scheme: (wear m, wear s, work, energy) at the last linear steps
        self.watch = GrowthWatch()
        self._summed = (None, None, None)  # (extra, compliance, their sum) of the last implicit solve
        self.miners = fatigue.miners(setup)  # each body's fatigue damage so far (loop.fatigue)
        self.coarsen: Optional[Callable] = None  # asked after each step whether the grid may coarsen (regrid)
        self.solves = NormalSolve(self)  # what the cycle members call: normal, one gap or a stack (loop.rows)

    def restore(self, st: dict) -> None:
        checkpoint.restore(self, st)

    def enter_block(self) -> None:
        blocks.enter_block(self)

    # -- the contact solve, on the fine grid or on the coarse one with refinement (Eqs. 11-12) ----------------
    def normal(self, seen, guess, extra=None, load: Optional[float] = None, cycle: int = 0):
        """The normal contact for the gap ε + ``seen`` (mm, on the fine grid): its pressure on the fine grid and the
        solver's result.  ``extra`` is an operator added to the compliance (an implicit step's wear term s·W on
        the solve grid); ``load`` on the grid.  Every failure is a :class:`NumericalFailure`."""
        s = self.s
        if s.coarse is not None:
            op, gap = s.coarse_compliance, s.coarse_gap + coarsen(seen, s.grid, s.coarse)
            guess = None if guess is None else coarsen(guess, s.grid, s.coarse)
        else:
            op, gap = s.compliance, s.gap + seen
        if extra is not None:  # one sum per step's term: a resolved cycle solves with it at every increment
            if self._summed[0] is not extra or self._summed[1] is not op:
                self._summed = (extra, op, add(op, extra))
            op = self._summed[2]
        res = solve(op, gap, load, method=s.method, p0=guess, tol=s.tolerance)
        if not res.success and guess is not None and s.stepper.implicit:
            # (not for the explicit schemes: an adaptive jump's failed solve is its rejection, retried shorter)
            # a warm start can stall cg on a worn, conforming contact where a cold one converges (seen on the
            # tube in service: 7247 elements, a 400 µm scar): the cold start is the fallback, not the failure
            res = solve(op, gap, load, method=s.method, p0=None, tol=s.tolerance)
        checks.check_solution(res, op.grid.area, load, s.method, cycle, self.n)
        p = res.pressure if s.coarse is None else refine_pressure(res.pressure, s.coarse, s.grid)
        checks.check_edges(p, s.band, s.grid, cycle, s.y_edges_free)
        return p, res

    def cycle_at(self, cycle: int, guess, h_m=None, h_s=None, implicit: float = 0.0, detail: bool = False) -> Cycle:
        """One representative cycle at the wear (h_m, h_s) (default: the current state).

        With ``implicit`` = s > 0 it is an implicit step's: the contact anticipates s cycles of its own wear, so the
        wear (h_m, h_s) + s·rates is the one its pressure belongs to.
        """
        try:
            return self.model.solve(self.h_m if h_m is None else h_m, self.h_s if h_s is None else h_s, self.solves,
                                    guess, step=implicit, memory=self.memory, cycle=cycle,
                                    detail=detail or cycle in self.s.snapshots or (
                                        TRACTIONS if self._fatigue_due(cycle) else False))
        except CycleError as exc:
            raise NumericalFailure(f"{exc} at cycle {cycle}", self.n) from None

    def next_stop(self) -> int:
        return next(t for t in self.stops if t > self.n)

    def emit(self, cyc: Cycle, jump: int, error_pressure: float = 0.0) -> Optional[Step]:
        """Record the current state with its cycle, check it, land on a wear limit, hand it to the observers; None
        where the step was rolled back to land on a limit's crossing."""
        s = self.s
        self.cyc = cyc
        self.p, self.r_m, self.r_s, self.memory = cyc.pressure, cyc.rate_moving, cyc.rate_stationary, cyc.memory
        self.rate_work = cyc.work
        self.rate_energy = self.energy_rate(cyc)
        step = _record(s, self.n, self.h_m, self.h_s, cyc, self.work, self.t0 - self.elapsed)
        step.energy = self.dissipated()
        step.jump, step.rejected = jump, self.rejected
        step.error_depth = self.depth_error()
        step.error_pressure = error_pressure
        self.rejected = 0
        checks.check_invariant(step.archard_error, self.model.invariant, self.n)
        checks.check_bounds(self.model, cyc, self.work, self.n, blocks.work_bound(self))
        if self.n > 0 and self.watch.update(step.checkerboard) and s.watch_growth:
            raise checks.growth_failure(self.n, step.checkerboard, s.stepper.growth_cause(s, self.model),
                                        checks.grows_on_grid(self.model, s.stepper.implicit))
        step.block = self.block
        verdict = self.landing.check(self, step) if s.wear_limits and self.n > 0 else None
        if verdict == "retake":
            return None
        if verdict == "reached":
            step.is_snapshot = True  # the state at the limit is what the engineer looks at
            step.limit = self.reached = self.landing.reached()
        crack = fatigue.count(self, step) if self.miners else None
        if crack is not None and (verdict != "reached" or crack[0] < step.limit[1]):  # (the first crossing names it)
            verdict = "reached"  # limits.crack_initiation: the run ends at the state where the damage reached 1
            step.is_snapshot = True
            step.limit = self.reached = ("crack_initiation", crack[0], self.n - crack[0], 1.0)
        step.state = checkpoint.state(self)
        self.last_state = step.state
        for obs in self.observers:
            obs.on_step(s, step)
        if self.progress is not None and jump:
            self.progress(jump)
        if verdict == "reached":
            raise Reached(step)
        checks.check_body(s.limits, s.grid, self.h_m, self.p, self.n)
        if self.coarsen is not None and 0 < self.n < s.cycles:
            why = self.coarsen(s, step)
            if why:
                raise Coarsen(step, why)
        return step

    def _fatigue_due(self, cycle: int) -> bool:
        return fatigue.due(self, cycle)

    def fatigue_restart(self, cyc: Cycle) -> None:
        """A block's start: the new block's cycle at the same wear restarts Miner's sums (loop.blocks)."""
        fatigue.restart(self, cyc)

    def restored_cycle(self) -> Cycle:
        """The cycle at the restored state: rebuilt from its pressure where the rates are linear in it, else solved
        again from it."""
        if self.model.linear:
            return self.model.restore(self.p)
        return self.cycle_at(self.n, self.p)

    def current_step(self) -> Step:
        """The current state as a step record, without stepping (a resumed run at its end)."""
        self.cyc = self.cyc or self.restored_cycle()
        step = _record(self.s, self.n, self.h_m, self.h_s, self.cyc, self.work, self.t0 - self.elapsed)
        step.energy = self.dissipated()
        step.error_depth = self.depth_error()
        step.block, step.limit, step.is_snapshot = self.block, self.reached, step.is_snapshot or bool(self.reached)
        step.state = checkpoint.state(self)
        return step

    def depth_error(self) -> float:
        """The stepping's estimate of the reported depths' relative error: each body's accumulated local errors
        (absolute, at the element where they are largest, or the deepest one's under implicit steps) over its
        deepest wear.  (Over the L2 norm of the whole depth field, as before, it was √(elements in contact) times
        too small: McColl 185 N 3D, 100 cycles, estimated 3.2e-5 against an error of 7.8e-4 from the run cycle
        by cycle.)"""
        return max(relative_to_deepest(self.err_abs_m, self.h_m), relative_to_deepest(self.err_abs_s, self.h_s))

    def energy_rate(self, cyc: Cycle) -> float:
        """The cycle's dissipated energy as the rate the loop accumulates (N·mm); 0 for a cycle that knows none,
        which clears ``energy_known``."""
        if np.isfinite(cyc.energy):
            return float(cyc.energy)
        self.energy_known = 0
        return 0.0

    def dissipated(self) -> float:
        """The energy dissipated from cycle 0 to the current state (N·mm; NaN once a cycle knew none)."""
        return self.energy if self.energy_known else float("nan")

    def advance(self, dh_m, dh_s, d_n: int, d_work: float, d_energy: float) -> None:
        if (dh_m < 0).any() or (dh_s < 0).any():
            raise NumericalFailure(f"negative wear increment at cycle {self.n + d_n}", self.n)
        self.h_m = self.h_m + dh_m
        self.h_s = self.h_s + dh_s
        self.work = self.work + d_work
        self.energy = self.energy + d_energy
        self.n += d_n

    def explicit_step(self, d_n) -> tuple[Cycle, float]:
        """Forward Euler over ``d_n`` cycles with the current rates (the paper's update), then the cycle there;
        with the pressure lag it leaves."""
        r_m, r_s = self.r_m, self.r_s
        p_old = self.p
        self.advance(r_m * d_n, r_s * d_n, d_n, self.rate_work * d_n, self.rate_energy * d_n)
        # predictor: extrapolate the pressure history so the warm start begins closer to the answer
        guess = p_old if self.p_prev is None else np.clip(p_old + (p_old - self.p_prev) * (d_n / self.d_prev), 0, None)
        cyc = self.cycle_at(self.n, guess)
        self.p_prev, self.d_prev = p_old, d_n
        # forward Euler with ΔN against the per-cycle update: local error ≈ ½(ΔN − 1)·ΔN·ṙ
        r2_m, r2_s = cyc.rate_moving, cyc.rate_stationary
        # (at each body's deepest element in contact before and after, as the implicit schemes hold it: the
        #  reported depth's; elements the contact front crossed carry the pressure lag's error instead)
        inner = (p_old > 0) & (cyc.pressure > 0)
        self.err_abs_m += 0.5 * (d_n - 1) * at_deepest((r2_m - r_m)[inner], self.h_m[inner])
        self.err_abs_s += 0.5 * (d_n - 1) * at_deepest((r2_s - r_s)[inner], self.h_s[inner])
        return cyc, 0.5 * relative_change(cyc.pressure - p_old, cyc.pressure)

    def run(self, resume: Optional[dict] = None) -> Step:
        s = self.s
        step = None
        if resume is None:
            cyc = self.cycle_at(0, None)
            checks.check_resolution(cyc.contact, s.solve_grid, s.y_edges_free)
            c = 0.5 if s.per_cycle else 0.0
            self.history = [(0, c * cyc.rate_moving, c * cyc.rate_stationary, cyc.pressure, c * cyc.work,
                             c * self.energy_rate(cyc))]  # φ = h + ½r
            step = self.emit(cyc, 0)
        else:
            self.restore(resume)
            if self.n >= s.cycles or self.reached is not None:  # killed as it finished: the state is the last step
                return self.current_step()
        if s.cycles == 0 or self.n >= s.cycles:
            return step
        try:
            return s.stepper.run(self) or step
        except Reached as reached:
            return reached.step


def _record(setup: Setup, cycle: int, h_m, h_s, cyc: Cycle, work: float, t0) -> Step:
    area = setup.grid.area * setup.volume_factor
    v_m = float(h_m.sum()) * area
    v_s = float(h_s.sum()) * area
    err = 0.0
    if cycle > 0:
        expect_m, expect_s = blocks.expected_volumes(setup, cycle, work)
        err = max(abs(v_m / expect_m - 1) if expect_m else abs(v_m),
                  abs(v_s / expect_s - 1) if expect_s else abs(v_s))
    res = cyc.contact
    return Step(cycle=cycle, wear_moving=h_m, wear_stationary=h_s, pressure=cyc.pressure,
                pressure_average=cyc.pressure_stationary, cycle_result=cyc, iterations=cyc.iterations,
                wall_time=time.perf_counter() - t0, approach=res.approach, is_snapshot=cycle in setup.snapshots,
                volume_moving=v_m, volume_stationary=v_s, archard_error=err, work=work,
                # on the grid the contact is solved on: with refinement the fine pressure is smooth by construction
                checkerboard=checkerboard_signed(res.pressure, stick=cyc.stick))


def summarize(setup: Setup, step: Step, solves: int, wall_time: float, max_errors: tuple = (0.0, 0.0)) -> dict:
    """The /summary figures (names are a contract; see README)."""
    return {
        "cycles": int(step.cycle),
        "contact_solves": int(solves),
        "wall_time_s": float(wall_time),
        **wear_summary(step, setup.grid.x),
        "archard_volume_error": float(step.archard_error),
        "max_pressure_MPa": float(step.pressure.max()),
        "error_estimate_depth": float(max(step.error_depth, max_errors[0])),
        "error_estimate_pressure": float(max(step.error_pressure, max_errors[1])),
        "linear_jump": int(setup.linear_jump),
        "stability_limit_linear": float(setup.stability_limit),
        "element_size_x_um": setup.grid.dx * 1e3,
        "element_size_y_um": setup.grid.dy * 1e3 if not setup.grid.plane_strain else float("nan"),
        "elements_x": int(setup.grid.shape[1]),
        "elements_y": int(setup.grid.shape[0]),
        # friction: the regime and the loop of the final state (the uniform model assumes gross slip)
        "regime": step.cycle_result.regime,
        "tangential_force_amplitude_N": float(step.cycle_result.force_amplitude),
        "dissipated_energy_per_cycle_J": float(step.cycle_result.energy) * 1e-3,
        "stick_half_width_x_mm": float(step.cycle_result.stick_half_width_x),
        "gross_slip_stroke_um": float(setup.gross_slip_stroke) * 1e3,
        # wear limits: the first reached ("" if none) and the interpolated cycle (NaN if none was reached)
        "limit_reached": step.limit[0] if step.limit else "",
        "cycles_to_limit": float(step.limit[1]) if step.limit else float("nan"),
        "time_to_limit_h": (float(step.limit[1]) / setup.frequency / 3600.0 if step.limit and setup.frequency
                            else float("nan")),
        **(fatigue_summary(setup.fatigue_specs, step.state, step.limit) if setup.fatigue_specs else {}),
    }
