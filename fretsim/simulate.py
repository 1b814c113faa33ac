"""The contact–wear loop (paper Fig. 8, Eqs. 15–18).  Knows nothing of files or plots: observers get each step.

Per step: one representative fretting cycle at the current wear (a member of :mod:`fretsim.cycle`: the
pressure, each body's slip and wear per cycle) → the stepping scheme advances the wear → the next cycle.  The
loop never looks inside the cycle: it steps the wear with the rates the cycle returns and checks the member's
invariant.  Each recorded step holds the wear at its cycle and the cycle that wear produces, so histories and
snapshots are consistent.  The loop takes a :class:`Setup` — arrays, numbers, operators, the loading and the
cycle model, built from a case by :func:`fretsim.plan.prepare`.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Optional, Protocol

import numpy as np

from fretsim.compliance import add
from fretsim.cycle import Cycle, CycleError
from fretsim.geometry import Limits
from fretsim.grid import Grid
from fretsim.jumping import (OMEGA_MAX, Q_LINEAR, THETA_LANDING, bdf2_coefficients, bdf2_local_error, next_step,
                             taylor_extrapolate, taylor_jump)
from fretsim.loading import Loading
from fretsim.quantities import wear_summary
from fretsim.refine import coarsen, refine_pressure
from fretsim.solvers import solve
from fretsim.stability import NOISE_FLOOR, GrowthWatch, checkerboard_signed

ARCHARD_ROUND_OFF = 1e-9  # the volume is the invariant's (k·P·4δ·N, k·Σp|ds|A) by construction; more is a bug
LOAD_BALANCE = 1e-8  # every solver enforces Σp·A = P exactly; a larger error is a solver fault
MAX_RETRIES = 8  # a failed solve is retried with a smaller step this many times (implicit, adaptive)
HISTORY_POINTS = 8  # states kept for BDF2 (partner, error estimate) and the predictor
EXACT_CYCLES = 2  # implicit schemes start with this many of the model's own per-cycle steps
PREDICTOR_POINTS = 2  # pressure states the warm start extrapolates from (2: linear, 3: quadratic)
# The maximum depths are held to this share of jumping.tolerance (the pressure field to all of it): depths are
# what designers extrapolate and compare with a wall, and an error made early in a short run is not damped
# before it is reported (scripts/calibrate_stepping.py measures both against the exact model).
DEPTH_SHARE = 0.07


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


class ResolutionError(SimulationError):
    """The grid cannot resolve the contact (too few elements across it): an input problem, found at the start."""

    exit_code = 2


class PhysicalLimit(SimulationError):
    """The wear went through the body: the geometry means nothing beyond this cycle."""

    exit_code = 4


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
    notes: tuple[str, ...] = ()
    block_cycles: tuple = ()  # a load history: the cycle model of each block of ``loading`` (empty: ``cycle``)
    wear_limits: dict = field(default_factory=dict)  # fretsim.limits: key -> limit (internal units)
    wall: Optional[float] = None  # mm, a tube's wall thickness (the wall_loss limit)
    limit_tolerance: float = 1e-3  # relative: the crossing cycle of a limit is found to this
    frequency: Optional[float] = None  # Hz: the time to a limit

    @property
    def solve_grid(self) -> Grid:
        return self.coarse if self.coarse is not None else self.grid

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
    block: int = 0  # the loading's block whose cycles led to this state (0 at the start)
    limit: Optional[tuple] = None  # (key, crossing cycle, its interpolation spread): the wear limit reached here
    state: dict = field(default_factory=dict)  # the loop's checkpoint after this step (for resuming)


class Observer(Protocol):
    def on_step(self, setup: Setup, step: Step) -> None: ...


def simulate(setup: Setup, observers: tuple = (), progress: Optional[Callable[[int], None]] = None,
             resume: Optional[dict] = None) -> Step:
    """Run the loop to ``setup.cycles``; returns the last step.  Raises :class:`SimulationError` on failure.

    ``resume`` is a checkpoint (``Step.state`` of an earlier run of the same setup): the loop continues from
    it and produces the same steps as the uninterrupted run.
    """
    return _Loop(setup, observers, progress).run(resume)


def _rel(v: np.ndarray, ref: np.ndarray) -> float:
    n = float(np.linalg.norm(ref))
    return float(np.linalg.norm(v)) / n if n > 0 else 0.0


BLOCK_RESTART = 1 / 4  # a block's first step, as a share of the step before its start
MAX_RETAKES = 6  # steps taken again to land on a wear limit's crossing (each lands closer: one or two suffice)


class _Reached(Exception):
    """A wear limit was reached at ``step``: the loop ends there."""

    def __init__(self, step):
        super().__init__("wear limit reached")
        self.step = step


class _Loop:
    """The loop's only mutable state: wear of both bodies, the current cycle's pressure and rates, cycle, and the
    stepping scheme's memory.

    All of it is in the attributes listed in ``STATE``, which every emitted step carries as a checkpoint.  Besides
    the wear, the loop carries ``work``: the member's invariant (volume = k·work) advanced by the same formulas as
    the wear, so a broken spatial update shows as a volume off its invariant.
    """

    STATE = ("n", "h_m", "h_s", "p", "r_m", "r_s", "rate_work", "work", "jump", "rejected", "elapsed", "lag", "err_abs_m",
             "err_abs_s", "p_prev", "d_prev", "block", "block_start", "work_bound", "retakes")

    def __init__(self, setup: Setup, observers, progress):
        self.s = setup
        self.model = setup.cycle
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
        if setup.block_cycles:
            self.model = setup.block_cycles[0]
        self.track: list = []  # wear limits: (cycle, {key: value}) of the last accepted steps
        self.retakes = 0  # steps taken again to land on a limit's crossing
        self.last_state: Optional[dict] = None
        self.h_m = np.zeros(setup.grid.shape)
        self.h_s = np.zeros(setup.grid.shape)
        self.p = self.p_prev = None
        self.r_m = self.r_s = None  # wear per cycle at the current state (the current cycle's)
        self.work = self.rate_work = 0.0  # accumulated invariant, and its rate per cycle at the current state
        self.memory: dict = {}  # the cycle model's own memory (its lagged slips)
        self.cyc: Optional[Cycle] = None
        self.d_prev = 1
        self.jump = 1.0
        self.lag = 0.0  # pressure lag per cycle of step (the last step's estimate / its length)
        self.err_abs_m = self.err_abs_s = 0.0  # accumulated local depth errors (mm, L2)
        self.history: list = []  # implicit schemes: (N, φ_m, φ_s, p, φ_work)
        self.batch: list = []  # adaptive scheme: (wear m, wear s, work) at the last linear steps
        self.watch = GrowthWatch(ceiling=not getattr(self.model, "singular_pressure", False))

    # -- checkpoint -------------------------------------------------------------------------------------------
    def state(self) -> dict:
        st = {k: getattr(self, k) for k in self.STATE}
        st["elapsed"] = self.elapsed + time.perf_counter() - self.t0
        st["batch"] = [a for b in self.batch for a in b[:2]]  # flat list of arrays: m0, s0, m1, s1, ...
        st["batch_work"] = np.array([b[2] for b in self.batch], dtype=float)
        st["history_n"] = np.array([h[0] for h in self.history], dtype=np.int64)
        st["history"] = [a for h in self.history for a in h[1:4]]  # φ_m, φ_s, p per point
        st["history_work"] = np.array([h[4] for h in self.history], dtype=float)
        st["watch"] = np.array(self.watch.history, dtype=float)
        st["scheme"] = self.s.scheme
        if self.s.wear_limits:
            st["limit_stops"] = np.array(sorted(set(self.stops) - set(self.base_stops)), dtype=np.int64)
            st["track_n"] = np.array([t[0] for t in self.track], dtype=float)
            for key in self.s.wear_limits:
                st["track_" + key] = np.array([t[1][key] for t in self.track], dtype=float)
        for k, v in self.memory.items():
            st["memory_" + k] = v
        return st

    def restore(self, st: dict) -> None:
        if st.get("scheme") != self.s.scheme:
            raise ValueError(f"the checkpoint is of scheme {st.get('scheme')!r}, the case of {self.s.scheme!r}")
        for k in self.STATE:
            if k in st:
                setattr(self, k, st[k])
        self.n, self.rejected, self.d_prev = int(self.n), int(self.rejected), int(self.d_prev)
        self.jump, self.elapsed, self.lag = float(self.jump), float(self.elapsed), float(self.lag)
        self.err_abs_m, self.err_abs_s = float(self.err_abs_m), float(self.err_abs_s)
        self.work, self.rate_work = float(self.work), float(self.rate_work)
        self.memory = {k[len("memory_"):]: v for k, v in st.items() if k.startswith("memory_")}
        self.block, self.block_start = int(self.block), int(self.block_start)
        self.work_bound = float(self.work_bound)
        if self.s.block_cycles:
            self.model = self.s.block_cycles[self.block]
        self.retakes = int(self.retakes)
        self.last_state = st  # a checkpoint is the state of the step written last: a retake goes back to it
        if self.s.wear_limits and "limit_stops" in st:
            self.stops = sorted(set(self.base_stops) | {int(v) for v in np.atleast_1d(st["limit_stops"])})
        if self.s.wear_limits and "track_n" in st:
            ns = list(np.atleast_1d(st["track_n"]))
            self.track = [(float(n), {key: float(np.atleast_1d(st["track_" + key])[i]) for key in self.s.wear_limits})
                          for i, n in enumerate(ns)]
        flat = list(st.get("batch", []))
        works = list(np.atleast_1d(st.get("batch_work", np.zeros(len(flat) // 2))))
        self.batch = [(flat[i], flat[i + 1], float(works[i // 2])) for i in range(0, len(flat), 2)]
        ns = [int(v) for v in np.atleast_1d(st.get("history_n", []))]
        arrays = list(st.get("history", []))
        hw = list(np.atleast_1d(st.get("history_work", np.zeros(len(ns)))))
        self.history = [(ns[i], arrays[3 * i], arrays[3 * i + 1], arrays[3 * i + 2], float(hw[i]))
                        for i in range(len(ns))]
        self.watch = GrowthWatch(np.atleast_1d(st.get("watch", [])), self.watch.ceiling)
        self.cyc = None  # rebuilt only if needed (a run resumed at its end)
        if "r_m" not in st:  # a checkpoint of format 1.2, which only had uniform slip: the rates follow from p
            cyc = self._restored_cycle()
            self.r_m, self.r_s, self.rate_work = cyc.rate_moving, cyc.rate_stationary, cyc.work
        self.t0 = time.perf_counter()

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
        if extra is not None:
            op = add(op, extra)
        res = solve(op, gap, load, method=s.method, p0=guess, tol=s.tolerance)
        if not res.success and guess is not None and s.scheme in ("bdf2", "implicit"):
            # (not for the explicit schemes: an adaptive jump's failed solve is its rejection, retried shorter)
            # a warm start can stall cg on a worn, conforming contact where a cold one converges (seen on the
            # tube in service: 7247 elements, a 400 µm scar): the cold start is the fallback, not the failure
            res = solve(op, gap, load, method=s.method, p0=None, tol=s.tolerance)
        if not res.success:
            hint = ("; the resolved stroke's worn profiles have kinks its pressure cannot follow (README): use "
                    "model.stroke: mid_stroke" if getattr(self.model, "singular_pressure", False) else "")
            raise NumericalFailure(f"the contact solve did not converge at cycle {cycle}: {res.message}{hint}",
                                   self.n)
        if not np.isfinite(res.pressure).all():
            raise NumericalFailure(f"non-finite pressure from the {s.method} solver at cycle {cycle}", self.n)
        if (res.pressure < 0).any():
            raise NumericalFailure(f"negative pressure from the {s.method} solver at cycle {cycle}", self.n)
        imbalance = float(res.pressure.sum()) * op.grid.area / load - 1.0
        if abs(imbalance) > LOAD_BALANCE:
            raise NumericalFailure(f"the {s.method} solution at cycle {cycle} violates the load balance by "
                                   f"{imbalance:.1e} (relative): the Archard invariant would break", self.n)
        p = res.pressure if s.coarse is None else refine_pressure(res.pressure, s.coarse, s.grid)
        _check_edges(p, s.band, s.grid, cycle, s)
        return p, res

    def cycle_at(self, cycle: int, guess, h_m=None, h_s=None, implicit: float = 0.0) -> Cycle:
        """One representative cycle at the wear (h_m, h_s) (default: the current state).

        With ``implicit`` = s > 0 it is an implicit step's: the contact anticipates s cycles of its own wear, so the
        wear (h_m, h_s) + s·rates is the one its pressure belongs to.
        """
        try:
            return self.model.solve(self.h_m if h_m is None else h_m, self.h_s if h_s is None else h_s, self.normal,
                                    guess, step=implicit, memory=self.memory, cycle=cycle,
                                    detail=cycle in self.s.snapshots)
        except CycleError as exc:
            raise NumericalFailure(f"{exc} at cycle {cycle}", self.n) from None

    def next_stop(self) -> int:
        return next(t for t in self.stops if t > self.n)

    def enter_block(self) -> None:
        """At a block's start, the next block's cycle model takes over: its cycle at the current wear gives the
        rates, and the stepping restarts as at the run's start (BDF2's history, the adaptive batch, the
        predictor, the growth watch), since the new load or stroke changes the wear's course at once."""
        s = self.s
        if not s.block_cycles:
            return
        i = s.loading.index_at(self.n)
        if i == self.block:
            return
        w_max = self.model.bounds[0]
        self.work_bound += w_max * (self.n - self.block_start)
        self.block, self.block_start, self.model = i, self.n, s.block_cycles[i]
        self.memory = {}
        # a cold start: the last block's pressure scaled to the new load made cg diverge on a worn, conforming
        # tube contact (7247 elements, load 15 N → 5 N), where the cold start converges
        cyc = self.cycle_at(self.n, None)
        self.cyc = cyc
        self.p, self.r_m, self.r_s, self.memory = cyc.pressure, cyc.rate_moving, cyc.rate_stationary, cyc.memory
        self.rate_work = cyc.work
        c = 0.5 if s.per_cycle else 0.0
        self.history = [(self.n, self.h_m + c * cyc.rate_moving, self.h_s + c * cyc.rate_stationary, cyc.pressure,
                         self.work + c * cyc.work)]
        self.batch = [(self.h_m, self.h_s, self.work)]
        # the wear state carries over smoothly, only its rate jumps: the steps restart well below the last one
        # (BLOCK_RESTART of it), not at one cycle; the error control shrinks them if the new rates change fast
        self.p_prev, self.d_prev, self.jump, self.lag = None, 1, max(1.0, self.jump * BLOCK_RESTART), 0.0
        self.watch.reset()

    def _growth_exponent(self) -> float:
        """d ln q / d ln N of the limited quantity over the last two tracked states (1 when unknown): a relative
        error ε in q is one of ε/exponent in the cycle at which q reaches its limit."""
        key = self.crossing.key
        pts = [(n, v[key]) for n, v in self.track if n > 0 and v[key] > 0]
        if len(pts) < 2 or pts[-1][0] == pts[-2][0] or pts[-1][1] == pts[-2][1]:
            return 1.0
        (n0, q0), (n1, q1) = pts[-2:]
        return float(np.log(q1 / q0) / np.log(n1 / n0))

    def _limit_check(self, step: Step) -> Optional[str]:
        """Wear limits at a new step: None to go on; "retake" when a limit was passed within a step too long to
        place the crossing (the state is rolled back to the previous step, with a stop at the estimated
        crossing); "reached" when the crossing is placed (``self.crossing``)."""
        from fretsim import limits
        s = self.s
        values = {k: limits.value(k, step, s.grid, s.wall) for k in s.wear_limits}
        points = self.track + [(float(self.n), values)]
        found = limits.first(s.wear_limits, {k: [(n, v[k]) for n, v in points] for k in s.wear_limits})
        if found is None:
            self.track = points[-3:]
            return None
        before = points[-2][0] if len(points) > 1 else 0.0
        tolerance = max(1.0, s.limit_tolerance * found.cycle)
        # half the tolerance past the estimated crossing: the landing then passes it for certain (an estimate a
        # few cycles short would leave the landing just below the limit, and the next step far past it again)
        target = int(np.ceil(found.cycle + 0.5 * (tolerance - 1.0)))
        # taken again unless it ends at the crossing (within the tolerance): the state at the limit is the one
        # reported, and a crossing placed from a step that ends there is interpolated over the least
        if (self.n - found.cycle > tolerance and self.n - before > 1 and self.retakes < MAX_RETAKES and
                self.last_state is not None and before < target < self.n):
            retakes = self.retakes + 1
            self.restore(self.last_state)
            self.retakes = retakes  # after the restore, which would count it back
            self.stops = sorted(set(self.stops) | {target})
            return "retake"
        self.crossing = found
        return "reached"

    def emit(self, cyc: Cycle, jump: int, error_pressure: float = 0.0) -> Step:
        s = self.s
        self.cyc = cyc
        self.p, self.r_m, self.r_s, self.memory = cyc.pressure, cyc.rate_moving, cyc.rate_stationary, cyc.memory
        self.rate_work = cyc.work
        step = _record(s, self.n, self.h_m, self.h_s, cyc, self.work, self.t0 - self.elapsed)
        step.jump, step.rejected = jump, self.rejected
        step.error_depth = max(_rel_scalar(self.err_abs_m, self.h_m), _rel_scalar(self.err_abs_s, self.h_s))
        step.error_pressure = error_pressure
        self.rejected = 0
        if step.archard_error > ARCHARD_ROUND_OFF:
            raise NumericalFailure(f"the wear invariant is broken at cycle {self.n}: the wear volume differs from "
                                   f"{self.model.invariant} by {step.archard_error:.2e} (relative)", self.n)
        _check_bounds(self.model, cyc, self.work, self.n,
                      self.work_bound + self.model.bounds[0] * (self.n - self.block_start))
        if self.n > 0 and self.watch.update(step.checkerboard) and s.watch_growth:
            if s.scheme in ("linear", "adaptive"):
                cause = (f"the {'linear jump ' + str(s.linear_jump) + ' cycles' if s.scheme == 'linear' else 'adaptive jumps'}"
                         f" are unstable on this grid (explicit stability limit {s.stability_limit:.4g} cycles). Use "
                         f"jumping.scheme: bdf2 (no stability limit), or a smaller jumping.linear")
            elif not getattr(self.model, "linear", True):
                cause = (f"the implicit steps have no stability limit, so the {self.model.name} cycle itself grew it: "
                         f"where the contact partly sticks, more pressure means less slip and less wear, and on a "
                         f"coarse grid that feedback grows at the stick zone's edge (the per-cycle run does it too). "
                         f"Refine the grid (grid.elements) so that the contact's half-width spans more elements")
            else:
                cause = (f"the implicit steps have no stability limit, so the model itself is unstable here (explicit "
                         f"limit {s.stability_limit:.4g} cycles, gap model {getattr(self.model, 'gap_model', '–')}): "
                         f"check the wear coefficients and their units")
            raise NumericalFailure(
                f"the pressure checkerboards at cycle {self.n}: an odd-even pattern grew over the last steps "
                f"(amplitude {abs(step.checkerboard):.1%} of the mean pressure); {cause}", self.n)
        step.block = self.block
        verdict = self._limit_check(step) if s.wear_limits and self.n > 0 else None
        if verdict == "retake":
            return None
        if verdict == "reached":
            step.is_snapshot = True  # the state at the limit is what the engineer looks at
            step.limit = (self.crossing.key, self.crossing.cycle, self.crossing.spread, self._growth_exponent())
        step.state = self.state()
        self.last_state = step.state
        for obs in self.observers:
            obs.on_step(s, step)
        if self.progress is not None and jump:
            self.progress(jump)
        if verdict == "reached":
            raise _Reached(step)
        self._check_body(self.p)
        return step

    def _restored_cycle(self) -> Cycle:
        """The cycle at the restored state: rebuilt from its pressure where the rates are linear in it, else solved
        again from it."""
        if self.model.linear:
            return self.model.restore(self.p)
        return self.cycle_at(self.n, self.p)

    def current_step(self) -> Step:
        """The current state as a step record, without stepping (a resumed run at its end)."""
        self.cyc = self.cyc or self._restored_cycle()
        step = _record(self.s, self.n, self.h_m, self.h_s, self.cyc, self.work, self.t0 - self.elapsed)
        step.error_depth = max(_rel_scalar(self.err_abs_m, self.h_m), _rel_scalar(self.err_abs_s, self.h_s))
        step.state = self.state()
        return step

    def _check_body(self, p) -> None:
        """Stop where the geometry stops meaning anything: worn through, or a scar past the limits of Eqs. 9-10."""
        s = self.s
        lim = s.limits
        if lim is None:
            return
        depth = float(self.h_m.max())
        if depth >= lim.wear_depth:
            raise PhysicalLimit(f"the moving body's wear depth {depth:.4g} mm reached {lim.wear_what} at cycle "
                                f"{self.n}: the body is worn through", self.n)
        X, Y = s.grid.mesh()
        on = p > 0
        reach_x = float(np.abs(X[on]).max()) + s.grid.dx / 2
        reach_y = float(np.abs(Y[on]).max()) + s.grid.dy / 2 if lim.reach_y is not None else 0.0
        if reach_x >= lim.reach_x or (lim.reach_y is not None and reach_y >= lim.reach_y):
            r = max(lim.reach_x, lim.reach_y or 0)
            raise PhysicalLimit(f"the contact reached {max(reach_x, reach_y):.4g} mm from the centre at cycle "
                                f"{self.n} (wear depth {depth * 1e3:.4g} µm), half of the radius of {2 * r:.4g} mm: beyond "
                                f"it the body's worn shape is no longer the paraboloid this model assumes", self.n)

    def advance(self, dh_m, dh_s, d_n: int, d_work: float) -> None:
        if (dh_m < 0).any() or (dh_s < 0).any():
            raise NumericalFailure(f"negative wear increment at cycle {self.n + d_n}", self.n)
        self.h_m = self.h_m + dh_m
        self.h_s = self.h_s + dh_s
        self.work = self.work + d_work
        self.n += d_n

    def run(self, resume: Optional[dict] = None) -> Step:
        s = self.s
        step = None
        if resume is None:
            cyc = self.cycle_at(0, None)
            _check_resolution(cyc.contact, s)
            c = 0.5 if s.per_cycle else 0.0
            self.history = [(0, c * cyc.rate_moving, c * cyc.rate_stationary, cyc.pressure, c * cyc.work)]  # φ = h + ½r
            step = self.emit(cyc, 0)
        else:
            self.restore(resume)
            if self.n >= s.cycles:  # killed as it finished: the state is the last step
                return self.current_step()
        if s.cycles == 0 or self.n >= s.cycles:
            return step
        try:
            if s.scheme in ("bdf2", "implicit"):
                return self._implicit(2 if s.scheme == "bdf2" else 1) or step
            return {"linear": self._linear, "adaptive": self._adaptive}[s.scheme]() or step
        except _Reached as reached:
            return reached.step

    # -- explicit schemes (the paper's) ---------------------------------------------------------------------
    def _explicit_step(self, d_n) -> tuple[Cycle, float]:
        r_m, r_s = self.r_m, self.r_s
        p_old = self.p
        self.advance(r_m * d_n, r_s * d_n, d_n, self.rate_work * d_n)
        # predictor: extrapolate the pressure history so the warm start begins closer to the answer
        guess = p_old if self.p_prev is None else np.clip(p_old + (p_old - self.p_prev) * (d_n / self.d_prev), 0, None)
        cyc = self.cycle_at(self.n, guess)
        self.p_prev, self.d_prev = p_old, d_n
        # forward Euler with ΔN against the per-cycle update: local error ≈ ½(ΔN − 1)·ΔN·ṙ
        r2_m, r2_s = cyc.rate_moving, cyc.rate_stationary
        self.err_abs_m += 0.5 * (d_n - 1) * float(np.linalg.norm(r2_m - r_m))
        self.err_abs_s += 0.5 * (d_n - 1) * float(np.linalg.norm(r2_s - r_s))
        return cyc, 0.5 * _rel(cyc.pressure - p_old, cyc.pressure)

    def _linear(self) -> Step:
        step = None
        while self.n < self.s.cycles:
            self.enter_block()
            d_n = min(self.s.linear_jump, self.next_stop() - self.n)
            cyc, e_p = self._explicit_step(d_n)
            step = self.emit(cyc, d_n, e_p) or step
        return step

    def _adaptive(self) -> Step:
        """Batches of Q_LINEAR linear steps, then a Taylor jump (paper Eqs. 19-21, Fig. 8), under control.

        The jump extrapolates with the current wear rates, so a jump well past the explicit stability limit
        can excite the odd-even pressure mode.  A jump after which that mode is visible (above the noise floor
        and more than twice what it was) or whose solve fails is undone and retried at half the length
        (counted as rejected); below the linear jump it becomes a linear step.  The linear steps that follow
        damp what remains.  Jumps never end on a snapshot or the last cycle: those are reached by linear
        steps, so recorded states are stabilised.  The invariant's work is extrapolated with the wear.
        """
        s = self.s
        lin = s.linear_jump
        step = None
        if not self.batch:
            self.batch = [(self.h_m, self.h_s, self.work)]
        while self.n < s.cycles:
            self.enter_block()
            room = self.next_stop() - self.n
            if len(self.batch) > Q_LINEAR and room > (Q_LINEAR + 1) * lin:
                (m2, s2, w2), (m1, s1, w1), (m0, s0, w0) = self.batch[-3:]
                jump = min(taylor_jump([(m2, m1, m0), (s2, s1, s0)], lin, s.eta, s.max_jump or 600),
                           room - Q_LINEAR * lin)
                before = abs(self.watch.history[-1]) if self.watch.history else 0.0
                while jump > lin:
                    new_m = taylor_extrapolate(m2, m1, m0, lin, jump)
                    new_s = taylor_extrapolate(s2, s1, s0, lin, jump)
                    if not ((new_m >= m0).all() and (new_s >= s0).all()):
                        jump //= 2  # the quadratic term must not make an increment negative
                        continue
                    saved = (self.h_m, self.h_s, self.n, self.work)
                    self.advance(new_m - m0, new_s - s0, jump, taylor_extrapolate(w2, w1, w0, lin, jump) - w0)
                    try:
                        cyc = self.cycle_at(self.n, self.p)
                        amp = abs(checkerboard_signed(cyc.contact.pressure))
                        unstable = amp > max(NOISE_FLOOR, 2.0 * before)
                    except NumericalFailure:
                        unstable = True
                    if unstable:
                        self.h_m, self.h_s, self.n, self.work = saved
                        self.rejected += 1
                        jump //= 2
                        continue
                    self.p_prev = None
                    self.batch = [(self.h_m, self.h_s, self.work)]
                    self.watch.reset()  # a jump is not a step of the linear sequence whose growth is watched
                    step = self.emit(cyc, jump, 0.5 * _rel(cyc.pressure - self.p, cyc.pressure)) or step
                    break
                else:
                    self.batch = [(self.h_m, self.h_s, self.work)]
                if jump > lin:
                    continue
            d_n = min(lin, room)
            cyc, e_p = self._explicit_step(d_n)
            # a shortened step breaks the equal spacing the differences need: restart the batch
            here = (self.h_m, self.h_s, self.work)
            self.batch = self.batch + [here] if d_n == lin else [here]
            step = self.emit(cyc, d_n, e_p) or step
        return step

    # -- implicit schemes: backward Euler (order 1) and variable-step BDF2 (order 2) --------------------------
    def _predict(self, cycle: int) -> np.ndarray:
        """Warm start: the pressure history extrapolated to ``cycle`` (quadratic through the last three states,
        linear through two), clipped at zero."""
        pts = self.history[-PREDICTOR_POINTS:]
        if len(pts) == 1:
            return pts[0][3]
        ns = [float(q[0]) for q in pts]
        weights = [np.prod([(cycle - ns[j]) / (ns[i] - ns[j]) for j in range(len(ns)) if j != i])
                   for i in range(len(ns))]
        return np.clip(sum(w * q[3] for w, q in zip(weights, pts)), 0.0, None)

    def _step_size(self, order: int) -> tuple[int, bool]:
        """The next step: the controller's, bounded by the stop, the caps and BDF2's step ratio, and tapered
        towards the stop so the pressure recorded there carries no lag.  Returns (ΔN, constrained)."""
        s = self.s
        rem = self.next_stop() - self.n
        d = min(self.jump, s.max_jump or np.inf, s.implicit_cap + 0.5)
        if order == 2 and len(self.history) > 1:
            d = min(d, OMEGA_MAX * (self.n - self.history[0][0]))
        # a step ending at (or near) a recorded state leaves a pressure lag ≈ lag·ΔN that the steps after it
        # relax: within the landing zone cover at most THETA_LANDING of the rest, unless the rest is cheap
        small = self.s.step_tolerance / self.lag if self.lag > 0 else np.inf
        d_land = max(np.ceil(THETA_LANDING * rem), np.floor(small))
        if self.next_stop() in self.boundaries:  # a block's end is not a recorded state: no pressure to land
            d_land = rem
        free = int(max(1, min(d, rem)))
        d = int(max(1, min(d, rem, d_land)))
        return d, d < free or d < self.jump

    def _exact_cycle(self) -> Step:
        """One cycle of the model itself (the per-cycle update, explicit and stable at one cycle).  The first
        cycles change the pressure by ~0.5 % each, too fast for the modified equation the implicit schemes
        integrate; taken one by one they are exact and cost what steps of one cycle would."""
        cyc, e_p = self._explicit_step(1)
        r_m, r_s = cyc.rate_moving, cyc.rate_stationary
        self.jump, self.lag = 2.0, e_p
        self.history = (self.history + [(self.n, self.h_m + 0.5 * r_m, self.h_s + 0.5 * r_s, cyc.pressure,
                                          self.work + 0.5 * cyc.work)])[-HISTORY_POINTS:]
        return self.emit(cyc, 1, e_p)

    def _implicit(self, order: int) -> Step:
        """Implicit steps of φ = h + ½r (see :mod:`fretsim.jumping`), one contact solve each, under control.

        Depth: the local error estimate (BDF2: from the third divided difference; backward Euler:
        ½ΔN·Δr), root-mean-square over the body relative to its depth, must stay below the tolerance, else
        the step is redone smaller.  (A maximum norm would be ruled by the few elements entering contact at
        the scar's edge, whose share of the depth error is small.)  Pressure: a step leaves a lag of about
        half the pressure change over it; near a recorded state the steps shrink until that lag is within the
        tolerance.  A solve that fails is retried with a quarter step.
        """
        s = self.s
        step = None
        retries = 0
        tol = s.step_tolerance
        while self.n < s.cycles:
            self.enter_block()
            if self.n < EXACT_CYCLES and s.stability_limit > 2.0:
                step = self._exact_cycle() or step
                continue
            d, constrained = self._step_size(order)
            n_now, phi_m, phi_s, p_now, phi_w = self.history[-1]
            partner = None
            if order == 2:
                for k in range(len(self.history) - 2, -1, -1):
                    if n_now - self.history[k][0] >= d / OMEGA_MAX:
                        partner = k
                        break
            if partner is None:
                b, g = 0.0, 1.0
                base_m, base_s, base_w = phi_m, phi_s, phi_w
            else:
                n_k, k_m, k_s, _, k_w = self.history[partner]
                b, g = bdf2_coefficients(d, n_now - n_k)
                base_m, base_s = phi_m + b * (phi_m - k_m), phi_s + b * (phi_s - k_s)
                base_w = phi_w + b * (phi_w - k_w)
            half = 0.5 if s.per_cycle else 0.0
            coef = g * d - half
            guess = self._predict(self.n + d)
            try:
                cyc = self.cycle_at(self.n + d, guess, base_m, base_s, implicit=coef)
            except NumericalFailure:
                if d == 1 or retries >= MAX_RETRIES:
                    raise
                retries += 1
                self.rejected += 1
                self.jump = max(1.0, d / 4)
                continue
            p_new, r_m, r_s = cyc.pressure, cyc.rate_moving, cyc.rate_stationary
            new_phi_m, new_phi_s = base_m + g * d * r_m, base_s + g * d * r_s
            new_phi_w = base_w + g * d * cyc.work
            h_m, h_s = new_phi_m - half * r_m, new_phi_s - half * r_s
            # local error estimates (absolute, L2) of each body
            # depth: the local error of each body's deepest element (the reported depth), held to DEPTH_SHARE of
            # the tolerance.  Over the elements in contact throughout the step only: those the contact front
            # crossed are not smooth in time, their estimate is meaningless, and their error is the pressure
            # lag's, which landing handles.
            if partner is not None and partner > 0:
                pts = (self.history[partner - 1], self.history[partner], self.history[-1])
                inner = (pts[0][3] > 0) & (pts[1][3] > 0) & (pts[2][3] > 0) & (p_new > 0)
                times = tuple(float(q[0]) for q in pts) + (float(self.n + d),)
                e_m = bdf2_local_error(times, tuple(q[1][inner] for q in pts) + (new_phi_m[inner],))
                e_s = bdf2_local_error(times, tuple(q[2][inner] for q in pts) + (new_phi_s[inner],))
                k_order = 2
            else:
                inner = (p_now > 0) & (p_new > 0)
                r0_m, r0_s = self.r_m, self.r_s  # the rates at the current state, history[-1]
                e_m, e_s, k_order = 0.5 * d * (r_m - r0_m)[inner], 0.5 * d * (r_s - r0_s)[inner], 1
            err_m, err_s = _at_deepest(e_m, h_m[inner]), _at_deepest(e_s, h_s[inner])
            # a non-linear cycle: what its linearised implicit solve got wrong, counted in both bodies' errors; it
            # limits the step only where the model's own solution is smooth (a resolved stroke's kinks are not)
            smooth = not getattr(self.model, "singular_pressure", False)
            err_m, err_s = err_m + cyc.defect, err_s + cyc.defect
            error = max(_rel_scalar(err_m if smooth else err_m - cyc.defect, _amax(h_m)),
                        _rel_scalar(err_s if smooth else err_s - cyc.defect, _amax(h_s))) / DEPTH_SHARE
            if error > 1.5 * tol and d > 1:
                self.rejected += 1
                self.jump = next_step(d, error, tol, k_order)
                continue
            e_p = 0.5 * _rel(p_new - p_now, p_new)
            if self.n + d == self.next_stop() and e_p > tol and d > 1 and self.n + d not in self.boundaries:
                # landing on a recorded state with a pressure lag beyond the tolerance: taper instead
                self.rejected += 1
                self.lag = max(self.lag, e_p / d)
                continue
            retries = 0
            self.err_abs_m += err_m
            self.err_abs_s += err_s
            self.lag = e_p / d
            self.advance(h_m - self.h_m, h_s - self.h_s, d, new_phi_w - half * cyc.work - self.work)
            self.history = (self.history + [(self.n, new_phi_m, new_phi_s, p_new, new_phi_w)])[-HISTORY_POINTS:]
            proposal = next_step(d, error, tol, k_order)
            self.jump = max(self.jump, proposal) if constrained else proposal
            step = self.emit(cyc, d, e_p) or step
        return step


def _rel_scalar(err: float, h) -> float:
    n = float(np.linalg.norm(h)) if isinstance(h, np.ndarray) else float(h)
    return err / n if n > 0 else 0.0


def _amax(a: np.ndarray) -> float:
    return float(np.abs(a).max()) if a.size else 0.0


def _at_deepest(error: np.ndarray, depth: np.ndarray) -> float:
    """|error| at the deepest element (0 when there is none)."""
    return float(abs(error.ravel()[np.argmax(depth.ravel())])) if error.size else 0.0


MIN_ELEMENTS_ACROSS_CONTACT = 4


def _check_resolution(res, setup: Setup) -> None:
    """The unworn contact must span a few elements each way the grid resolves (Hertz is then within ~1 %)."""
    across_x = int(res.contact.sum(axis=1).max())
    across_y = int(res.contact.sum(axis=0).max())
    g = setup.solve_grid
    line = setup.y_edges_free
    if across_x < MIN_ELEMENTS_ACROSS_CONTACT or (not g.plane_strain and not line and
                                                   across_y < MIN_ELEMENTS_ACROSS_CONTACT):
        raise ResolutionError(f"the grid is too coarse to resolve the contact: the initial contact spans "
                              f"{across_x} element(s) of {g.dx * 1e3:.3g} µm along x"
                              + ("" if g.plane_strain or line else f" and {across_y} of {g.dy * 1e3:.3g} µm along y")
                              + f"; at least {MIN_ELEMENTS_ACROSS_CONTACT} are needed", 0)


def _check_edges(p: np.ndarray, band: int, grid: Grid, cycle: int, setup: Setup) -> None:
    """Pressure within the stroke's reach of the x edges (or on the y edges of a point contact) is truncated."""
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


BOUND_ROUND_OFF = 1e-6  # the tangential solve's slip is exact to ~1e-10 of the stroke; a cycle beyond its physical
#                         bound by more than this is a fault, not round-off


def _check_bounds(model, cyc: Cycle, work: float, cycle: int, work_max: Optional[float] = None) -> None:
    """The cycle's work and energy, and the work accumulated to ``cycle`` (at most ``work_max``: the blocks' bounds
    times their cycles so far), within what the physics allows."""
    w_max, e_max = model.bounds
    top = 1.0 + BOUND_ROUND_OFF
    what = None
    if not (0.0 <= cyc.work <= w_max * top):
        what = f"the cycle's wear work {cyc.work:.6g} N·mm lies outside [0, {w_max:.6g}] (no point slides further " \
               f"than the rig travels, 4δ)"
    elif np.isfinite(cyc.energy) and not (0.0 <= cyc.energy <= e_max * top):
        what = f"the dissipated energy per cycle {cyc.energy:.6g} N·mm lies outside [0, μ·P·4δ = {e_max:.6g}]"
    elif not (0.0 <= work <= (w_max * max(cycle, 1) if work_max is None else max(work_max, w_max)) * top):
        bound = w_max * cycle if work_max is None else work_max
        what = f"the accumulated wear work {work:.6g} N·mm lies outside [0, {bound:.6g}] ({cycle} cycles)"
    if what:
        raise NumericalFailure(f"a physical bound is broken at cycle {cycle}: {what}", cycle)


def _expected_volumes(setup: Setup, cycle: int, work: float) -> tuple[float, float]:
    """The invariant's volumes after ``cycle`` cycles: a closed-form member's summed over the blocks so far
    (Σ kᵢ·Pᵢ·4δᵢ·Nᵢ), any other's from the accumulated work."""
    if not setup.block_cycles or not getattr(setup.cycle, "closed_form", False):
        return setup.cycle.expected_volumes(cycle, work)
    moving = stationary = 0.0
    start = 0
    for block, model in zip(setup.loading.blocks, setup.block_cycles):
        n = min(max(cycle - start, 0), block.cycles)
        start += block.cycles
        if n:
            v_m, v_s = model.expected_volumes(n, 0.0)
            moving, stationary = moving + v_m, stationary + v_s
        if start >= cycle:
            break
    return moving, stationary


def _record(setup: Setup, cycle: int, h_m, h_s, cyc: Cycle, work: float, t0) -> Step:
    area = setup.grid.area * setup.volume_factor
    v_m = float(h_m.sum()) * area
    v_s = float(h_s.sum()) * area
    err = 0.0
    if cycle > 0:
        expect_m, expect_s = _expected_volumes(setup, cycle, work)
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
    }
