"""``bdf2`` and ``implicit``: implicit steps of φ = h + ½r (variable-step BDF2, order 2, or backward Euler, order
1; :mod:`fretsim.jumping`), one contact solve each with the compliance C + s·W, under error control.

Depth: the local error estimate (BDF2: from the third divided difference; backward Euler: ½ΔN·Δr) of each
body's deepest element (the reported depth), held to DEPTH_SHARE of the tolerance, else the step is redone
smaller.  (Over the elements in contact throughout the step only: those the contact front crossed are not smooth
in time, their estimate is meaningless, and their error is the pressure lag's, which landing handles.)
Pressure: a step leaves a lag of about half the pressure change over it; near a recorded state the steps shrink
until that lag is within the tolerance.  A solve that fails is retried with a quarter step.

Partial slip (a Coulomb cycle with a stick zone): forward-Euler steps under error control instead, of at most
half the explicit stability limit of the cycle's own wear stiffness, which its largest slip bounds
(:func:`_partial_slip_step`).  The implicit step solves the contact with the wear every point would have
sliding as far as the furthest (``slip_lin``), then corrects its gap once for the wear the cycle really found; in
the stick zone, which does not wear, that iteration barely contracts once the step exceeds a few tens of cycles.
Its residue is invisible to the deepest element's error estimate, yet it moves the stick zone's edge, where the
pressure peaks, and the run follows another path: Ti-6Al-4V at 5 µm stroke (cases/ti_fretting_fatigue.yaml,
10⁵ cycles) ended 21-27 % deep against the run cycle by cycle, with a stepping estimate of 2 %; 2 and 3 µm
ended 35 % and 26 % deep.  Forward Euler uses the cycle's own rates, with nothing to converge: within 0.02 % of
explicit jumps of 50 cycles, at 3.5-5× the solves of the implicit steps and 1.3-1.6× their time
(scripts/study_partial_slip_stepping.py).
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

from fretsim.errors import NumericalFailure
from fretsim.jumping import OMEGA_MAX, THETA_LANDING, bdf2_coefficients, bdf2_local_error, next_step
from fretsim.loop.checks import model_growth_cause
from fretsim.stepping.linear import relative_change
from fretsim.wear import AVERAGED

MAX_RETRIES = 8  # a failed solve is retried with a smaller step this many times
HISTORY_POINTS = 8  # states kept for BDF2 (partner, error estimate) and the predictor
EXACT_CYCLES = 2  # implicit schemes start with this many of the model's own per-cycle steps
PREDICTOR_POINTS = 2  # pressure states the warm start extrapolates from (2: linear, 3: quadratic)
# The maximum depths are held to this share of jumping.tolerance (the pressure field to all of it): depths are
# what designers extrapolate and compare with a wall, and an error made early in a short run is not damped
# before it is reported (scripts/calibrate_stepping.py measures both against the exact model).
DEPTH_SHARE = 0.07
PARTIAL_SLIP_EXPLICIT = True  # forward-Euler steps while the cycle has a stick zone (module docstring)
# ... their local depth error held to this share of the tolerance: first order, their errors add up where BDF2's
# largely cancel (at DEPTH_SHARE McColl's cylinder at 0.4 µm ended 2.9e-3 off the run cycle by cycle after 3 000
# cycles, at a quarter of it 1.5e-3)
EXPLICIT_SHARE = DEPTH_SHARE / 4
# the wear stiffness k·(s + p·∂s/∂p) against k·s_max: the slip answers the pressure too (more pressure, less slip
# in the annulus).  Measured with error control off (Ti-6Al-4V, 8.2 µm, μ 1.2, 10⁵ cycles): steps of 4δ/(2·s_max)
# times half the planned limit were stable at 1.5 times that and built a 22 % checkerboard at 2 (a review found
# 4δ/s_max unstable there): the stiffness is about 2.3·k·s_max (1.7 at 5.5 µm, μ 0.8), and 3 keeps the steps
# within half the limit it allows, where every mode decays without changing sign
SLIP_STIFFNESS = 3.0
SPREAD_EXPLICIT = 0.2  # near_transition: the slip's spread there 0.25-0.4, in gross slip well above δ_t under 0.14


class Implicit:
    implicit = True
    per_cycle_short_runs = False

    def __init__(self, name: str, order: int):
        self.name, self.order = name, order

    def reason(self, case) -> str:
        if self.order == 2:
            return (f"second-order implicit steps under error control (tolerance {case.step_tolerance:g}): no "
                    f"stability limit, recorded states landed on with shrinking steps")
        return "backward-Euler steps (first order) under error control"

    def describe(self, case, summary: dict) -> str:
        what = "BDF2" if self.order == 2 else "backward-Euler"
        return f"{what} steps (tolerance {case.step_tolerance:g})"

    def estimate_solves(self, setup) -> int:
        # ~25 solves per decade of cycles after the first, ~7 per recorded state landed on (measured)
        n = setup.cycles
        steps = 10 + 12 * math.log10(max(n, 10)) + 7 * len(setup.snapshots)
        stick = _stick_cycles(setup)
        if stick:  # forward-Euler steps of up to half the stability limit, partial slip's
            # (the slip's headroom guessed from δ/δ_t: its largest slip is about 0.4·δ/δ_t of 4δ, measured
            # 0.09-0.15 at 0.36 δ_t and 0.16-0.35 at 0.91 δ_t on cases/ti_fretting_fatigue.yaml; a history's from
            # the block nearest partial slip)
            stroke = (setup.regime_block or setup.cycle).stroke
            headroom = max(1.0, 1.0 / (SLIP_STIFFNESS * 0.4 * stroke / setup.gross_slip_stroke))
            steps += stick / (setup.stability_limit / 2.0 * headroom)
        elif _expects_near_transition(setup):  # the same steps in gross slip (near_transition): every point slides
            steps += n / (setup.stability_limit / 2.0 * 4.0 / SLIP_STIFFNESS)  # nearly 4δ, the headroom 4/3
        return min(n + 1, int(steps))

    def max_jump(self, case, jump: int, limit: float, allow_unstable: bool) -> tuple[Optional[int], list]:
        return case.max_jump, []

    def growth_cause(self, setup, model) -> str:
        return model_growth_cause(model, setup)

    def run(self, loop):
        s = loop.s
        step = None
        retries = 0
        while loop.n < s.cycles:
            loop.enter_block()
            if loop.n < EXACT_CYCLES and s.stability_limit > 2.0:
                step = _exact_cycle(loop) or step
                continue
            if explicit_in_partial_slip(loop):
                step = _partial_slip_step(loop) or step
                continue
            d, constrained = _step_size(loop, self.order)
            partner = _partner(loop.history, d) if self.order == 2 else None
            base, g = _base(loop.history, partner, d)
            half = 0.5 if s.per_cycle else 0.0
            try:
                cyc = loop.cycle_at(loop.n + d, _predict(loop.history, loop.n + d), base[0], base[1],
                                    implicit=g * d - half)
            except NumericalFailure:
                if d == 1 or retries >= MAX_RETRIES:
                    raise
                retries += 1
                loop.rejected += 1
                loop.jump = max(1.0, d / 4)
                continue
            accepted = _accept(loop, cyc, d, partner, base, g, half)
            if accepted is None:
                continue
            retries = 0
            error, k_order, e_p = accepted
            proposal = next_step(d, error, s.step_tolerance, k_order)
            loop.jump = max(loop.jump, proposal) if constrained else proposal
            step = loop.emit(cyc, d, e_p) or step
        return step


def _partner(history: list, d: int) -> Optional[int]:
    """BDF2's second point: the latest state at least d/OMEGA_MAX cycles back (None: a backward-Euler step)."""
    n_now = history[-1][0]
    for k in range(len(history) - 2, -1, -1):
        if n_now - history[k][0] >= d / OMEGA_MAX:
            return k
    return None


def _base(history: list, partner: Optional[int], d: int) -> tuple[tuple, float]:
    """The step's known part of φ (moving, stationary, work, energy) and γ: φ_{n+1} = base + γ·ΔN·r_{n+1}."""
    _, phi_m, phi_s, _, phi_w, phi_e = history[-1]
    if partner is None:
        return (phi_m, phi_s, phi_w, phi_e), 1.0
    n_k, k_m, k_s, _, k_w, k_e = history[partner]
    b, g = bdf2_coefficients(d, history[-1][0] - n_k)
    return (phi_m + b * (phi_m - k_m), phi_s + b * (phi_s - k_s), phi_w + b * (phi_w - k_w),
            phi_e + b * (phi_e - k_e)), g


def _accept(loop, cyc, d: int, partner: Optional[int], base: tuple, g: float, half: float) -> Optional[tuple]:
    """Accept the step (advance the loop) or reject it (None, with the next step proposed): (the error relative
    to the tolerance's depth share, the estimate's order, the pressure lag) of an accepted one."""
    s = loop.s
    tol = s.step_tolerance
    p_now = loop.history[-1][3]
    p_new, r_m, r_s = cyc.pressure, cyc.rate_moving, cyc.rate_stationary
    new_phi_m, new_phi_s = base[0] + g * d * r_m, base[1] + g * d * r_s
    new_phi_w = base[2] + g * d * cyc.work
    rate_e = loop.energy_rate(cyc)
    new_phi_e = base[3] + g * d * rate_e
    h_m, h_s = new_phi_m - half * r_m, new_phi_s - half * r_s
    err_m, err_s, k_order = _local_errors(loop, partner, d, p_now, p_new, r_m, r_s, new_phi_m, new_phi_s, h_m, h_s)
    # a non-linear cycle: what its linearised implicit solve got wrong, counted in both bodies' errors
    err_m, err_s = err_m + cyc.defect, err_s + cyc.defect
    error = max(relative_to_deepest(err_m, h_m), relative_to_deepest(err_s, h_s)) / DEPTH_SHARE
    if error > 1.5 * tol and d > 1:
        loop.rejected += 1
        loop.jump = next_step(d, error, tol, k_order)
        return None
    e_p = 0.5 * relative_change(p_new - p_now, p_new)
    if loop.n + d == loop.next_stop() and e_p > tol and d > 1 and loop.n + d not in loop.boundaries:
        # landing on a recorded state with a pressure lag beyond the tolerance: taper instead
        loop.rejected += 1
        loop.lag = max(loop.lag, e_p / d)
        return None
    loop.err_abs_m += err_m + cyc.bias
    loop.err_abs_s += err_s + cyc.bias
    loop.lag = e_p / d
    loop.advance(h_m - loop.h_m, h_s - loop.h_s, d, new_phi_w - half * cyc.work - loop.work,
                 new_phi_e - half * rate_e - loop.energy)
    loop.history = (loop.history + [(loop.n, new_phi_m, new_phi_s, p_new, new_phi_w, new_phi_e)])[-HISTORY_POINTS:]
    return error, k_order, e_p


def _local_errors(loop, partner, d, p_now, p_new, r_m, r_s, new_phi_m, new_phi_s, h_m, h_s) -> tuple:
    """Each body's local depth error at its deepest element (absolute), over the elements in contact throughout
    the step, and the order of the estimate."""
    if partner is not None and partner > 0:
        pts = (loop.history[partner - 1], loop.history[partner], loop.history[-1])
        inner = (pts[0][3] > 0) & (pts[1][3] > 0) & (pts[2][3] > 0) & (p_new > 0)
        times = tuple(float(q[0]) for q in pts) + (float(loop.n + d),)
        e_m = bdf2_local_error(times, tuple(q[1][inner] for q in pts) + (new_phi_m[inner],))
        e_s = bdf2_local_error(times, tuple(q[2][inner] for q in pts) + (new_phi_s[inner],))
        k_order = 2
    else:
        inner = (p_now > 0) & (p_new > 0)
        r0_m, r0_s = loop.r_m, loop.r_s  # the rates at the current state, history[-1]
        e_m, e_s, k_order = 0.5 * d * (r_m - r0_m)[inner], 0.5 * d * (r_s - r0_s)[inner], 1
    return at_deepest(e_m, h_m[inner]), at_deepest(e_s, h_s[inner]), k_order


def _predict(history: list, cycle: int) -> np.ndarray:
    """Warm start: the pressure history extrapolated to ``cycle`` (quadratic through the last three states,
    linear through two), clipped at zero."""
    pts = history[-PREDICTOR_POINTS:]
    if len(pts) == 1:
        return pts[0][3]
    ns = [float(q[0]) for q in pts]
    weights = [np.prod([(cycle - ns[j]) / (ns[i] - ns[j]) for j in range(len(ns)) if j != i])
               for i in range(len(ns))]
    return np.clip(sum(w * q[3] for w, q in zip(weights, pts)), 0.0, None)


def _step_size(loop, order: int) -> tuple[int, bool]:
    """The next step: the controller's, bounded by the stop, the caps and BDF2's step ratio, and tapered
    towards the stop so the pressure recorded there carries no lag.  Returns (ΔN, constrained)."""
    s = loop.s
    rem = loop.next_stop() - loop.n
    d = min(loop.jump, s.max_jump or np.inf, s.implicit_cap + 0.5)
    if order == 2 and len(loop.history) > 1:
        d = min(d, OMEGA_MAX * (loop.n - loop.history[0][0]))
    # a step ending at (or near) a recorded state leaves a pressure lag ≈ lag·ΔN that the steps after it
    # relax: within the landing zone cover at most THETA_LANDING of the rest, unless the rest is cheap
    small = s.step_tolerance / loop.lag if loop.lag > 0 else np.inf
    d_land = max(np.ceil(THETA_LANDING * rem), np.floor(small))
    if loop.next_stop() in loop.boundaries:  # a block's end is not a recorded state: no pressure to land
        d_land = rem
    free = int(max(1, min(d, rem)))
    d = int(max(1, min(d, rem, d_land)))
    return d, d < free or d < loop.jump


def _exact_cycle(loop):
    """One cycle of the model itself (the per-cycle update, explicit and stable at one cycle).  The first
    cycles change the pressure by ~0.5 % each, too fast for the modified equation the implicit schemes
    integrate; taken one by one they are exact and cost what steps of one cycle would."""
    cyc, e_p = loop.explicit_step(1)
    loop.jump, loop.lag = 2.0, e_p
    _remember(loop, cyc)
    return loop.emit(cyc, 1, e_p)


def _remember(loop, cyc) -> None:
    """An explicit step's state in the BDF2 history (φ = h + ½r of the per-cycle update), so that implicit steps
    can follow it."""
    r_m, r_s = cyc.rate_moving, cyc.rate_stationary
    loop.history = (loop.history + [(loop.n, loop.h_m + 0.5 * r_m, loop.h_s + 0.5 * r_s, cyc.pressure,
                                     loop.work + 0.5 * cyc.work,
                                     loop.energy + 0.5 * loop.energy_rate(cyc))])[-HISTORY_POINTS:]


def explicit_in_partial_slip(loop) -> bool:
    """Whether the next step is a forward-Euler one: the last cycle had a stick zone (a Coulomb cycle in partial
    slip; its memory says so, a checkpoint with it), or slid very unevenly with the flat's wear seen through the
    stroke average (:func:`near_transition`), and an explicit step of two cycles is stable on this grid."""
    m = loop.memory
    return (m.get("stuck", 0.0) > 0 or near_transition(loop.model, m)) and _explicit_allowed(loop.s)


def near_transition(model, memory: dict) -> bool:
    """A gross-slip Coulomb cycle near the transition (its slip's spread, 1 − mean/max, over SPREAD_EXPLICIT) with the
    stroke-averaged gap (a moving body wearing under 0.307 of the flat): there the implicit step's correction barely
    converges and its defect, read at the deepest element, does not see what is left.  Ti-6Al-4V with k_m = k_s/10,
    μ 1.0, 8 µm, 989 elements, 4·10⁴ cycles (a review's case): BDF2 ended 9.7 % short of the run cycle by cycle
    (0.428 against 0.474 µm) with an estimate of 1.8 % (3 and 6 corrections: 0.391, 0.440), forward Euler 1.9 %
    short (and 0.3 % at steps of 20 cycles), its estimate 0.2 %: better, still no bound, which the plan's warning
    says.  With the paper's mid-stroke gap and equal wear the implicit steps held there (the same review)."""
    return memory.get("slip_spread", 0.0) > SPREAD_EXPLICIT and _averaged(model)


def _averaged(member) -> bool:
    """Whether a cycle member's contact sees the flat's wear averaged over the stroke (fretsim.wear.AVERAGED)."""
    return AVERAGED.get(getattr(member, "gap_model", ""), False)


def _explicit_allowed(setup) -> bool:
    """Partial slip's forward-Euler steps are on, and one of two cycles is stable on this grid."""
    return PARTIAL_SLIP_EXPLICIT and setup.per_cycle and setup.stability_limit > 4.0


def _expects_stick(setup) -> bool:
    """Whether the run is expected to take forward-Euler steps: a Coulomb cycle (not rigid) whose stroke is below
    the unworn contact's gross-slip stroke δ_t, where an explicit step of two cycles is stable."""
    member = setup.cycle
    stroke = getattr(member, "stroke", None)
    return (_explicit_allowed(setup) and getattr(member, "needs_friction", False) and not getattr(member, "rigid", True)
            and stroke is not None and stroke < setup.gross_slip_stroke)


def _stick_cycles(setup) -> int:
    """The cycles a run is expected to take forward-Euler steps over in partial slip: all of them where its one
    block sticks (:func:`_expects_stick`), a history's blocks whose stroke is below their own δ_t (the first
    block alone was judged before: a gross-slip block then 30 000 cycles at 0.5 µm were estimated at 104 solves
    and took over 9 000 steps, a review's)."""
    if not setup.block_cycles:
        return setup.cycles if _expects_stick(setup) else 0
    member = setup.cycle
    coulomb = (_explicit_allowed(setup) and getattr(member, "needs_friction", False)
               and not getattr(member, "rigid", True))
    return min(setup.stick_cycles, setup.cycles) if coulomb else 0


def _expects_near_transition(setup) -> bool:
    """Whether a run is expected to take near_transition's forward-Euler steps: a Coulomb cycle with the
    stroke-averaged gap in gross slip below twice δ_t (the plan's warning's range)."""
    member = setup.cycle
    stroke = getattr(member, "stroke", None)
    return (_explicit_allowed(setup) and _averaged(member)
            and getattr(member, "needs_friction", False) and not getattr(member, "rigid", True) and stroke is not None
            and setup.gross_slip_stroke <= stroke < 2.0 * setup.gross_slip_stroke)


def _slip_headroom(loop) -> float:
    """How far the stability limit of the cycle's own wear stiffness lies beyond the planned one.  The limit is the
    gross-slip operator's (every point sliding 4δ); no point of this cycle slid further than its largest slip
    (``slip_lin``), but the slip answers the pressure too, which raises the stiffness above what k·s_max alone
    gives (SLIP_STIFFNESS): so 4δ/(3·s_max), never below 1."""
    stroke = getattr(loop.model, "stroke", 0.0)
    largest = float(loop.memory.get("slip_lin", 0.0))
    return max(1.0, 4.0 * stroke / (SLIP_STIFFNESS * largest)) if largest > 0 and stroke > 0 else 1.0


def _partial_slip_step(loop):
    """A forward-Euler step under error control: at most half the explicit stability limit of the cycle's wear
    stiffness (every mode decays without changing sign; :func:`_slip_headroom`), sized so its local depth error
    (½(ΔN − 1)·ΔN·ṙ at the deepest element, as the linear scheme estimates it) stays within EXPLICIT_SHARE of the
    tolerance; kept in the BDF2 history as an exact cycle is, so implicit steps resume from it should the stick
    zone vanish."""
    s = loop.s
    cap = s.stability_limit / 2.0 * _slip_headroom(loop)
    d = int(max(1, min(loop.jump, cap, s.max_jump or np.inf, loop.next_stop() - loop.n)))
    before = (loop.err_abs_m, loop.err_abs_s)
    cyc, e_p = loop.explicit_step(d)
    local = max(relative_to_deepest(loop.err_abs_m - before[0], loop.h_m),
                relative_to_deepest(loop.err_abs_s - before[1], loop.h_s))
    loop.jump, loop.lag = next_step(d, local / EXPLICIT_SHARE, s.step_tolerance, 1), e_p / d
    _remember(loop, cyc)
    return loop.emit(cyc, d, e_p)


def relative_to_deepest(err: float, h: np.ndarray) -> float:
    """An absolute depth error (mm) over the deepest of the depths ``h`` (0 where there is no wear)."""
    n = _amax(h)
    return err / n if n > 0 else 0.0


def _amax(a: np.ndarray) -> float:
    return float(np.abs(a).max()) if a.size else 0.0


def at_deepest(error: np.ndarray, depth: np.ndarray) -> float:
    """|error| at the deepest element (0 when there is none)."""
    return float(abs(error.ravel()[np.argmax(depth.ravel())])) if error.size else 0.0
