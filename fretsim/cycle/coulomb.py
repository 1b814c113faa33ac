"""``coulomb``: the fretting cycle resolved in increments, with Coulomb friction (partial and gross slip).

The rig moves the moving body tangentially by U: 0 → −δ (a first loading quarter, which sets up the history),
then −δ → +δ → −δ (the loop that is recorded and wears).  At each increment:

* the normal contact — once at mid-stroke for the whole cycle (``stroke_model: mid_stroke``: Mindlin's setting,
  the pressure fixed), or at each increment with every point of the moving body over the point of the flat it
  has reached (``resolved``): the gap is ε(ξ) + h_m(ξ) + h_s(ξ + s(ξ)), s the point's accumulated slip;
* the tangential contact (:func:`fretsim.solvers.tangential.solve_tangential`): the shear traction q with
  |q| ≤ μp, sticking where |q| < μp, slipping s = ΔU − KΔq where it reaches μp (K: both bodies' tangential
  compliance, the 2D datum and the rig, :mod:`fretsim.compliance.tangential`).  The increment starts from the
  previous one's traction, so stick and slip carry their history (Mindlin–Deresiewicz): unloading re-sticks
  the contact and slip spreads in from its edges;
* the wear of both bodies from the local slip: Archard dh = k·p·|ds| or, as ``law: energy``, dh = α·|q|·|ds|
  (Fouvry's dissipated-energy law).  The moving body wears at its own points; each of its points carries its
  wear along its own travel over the flat (:func:`fretsim.wear.sweep_deposit`), which with equal travel
  everywhere is exactly the paper's stroke average.

With the pressure fixed (mid-stroke), the whole cycle follows from its first loading by Masing's rule
(:func:`masing`): one loading curve, not a solve per increment round the loop.  An increment that slides the whole
contact at ±μp is recognised as such and taken without the tangential solver (:meth:`CoulombCycle._tangential`).

The resolved stroke's increments are solved together where they can be (:mod:`fretsim.cycle.resolved`): all
positions' normal contacts as the layers of one stack, the travels of increments that slide entirely at ±μp at
once — the same discretisation to the same travel tolerance, at a quarter of the time in 2D; one by one in partial
slip, on large 3D grids (no gain there), on refinement's coarse grid, or without a warm start.

The normal and tangential problems are solved uncoupled: exact for elastically similar bodies, otherwise the
normal displacement the shear causes (∝ Dundurs' β) is neglected (the plan warns where βμ matters).  The
convected strain (a flat point's elastic displacement changes as the load slides over it, ∝ μp/E* times the
travel) is neglected too: it shifts the local slip by about μp₀/E* of the stroke (≲ 1 %).

Cycle jumping.  The rates depend on the slip, which depends on the pressure: they are not linear in it.  An
implicit step solves each normal contact with C + s·W_lin, W_lin = S_lin/(4δ)·W (W: the uniform member's
operator at 4δ; for the resolved stroke 4δ(k_m + k_s)I, which bounds every position's), S_lin from the previous
cycle's slip (``memory``): the largest, so that W_lin bounds the true stiffness W_true (no point slides further).  Treating the
difference e = W_lin − W_true ∈ [0, W_lin] explicitly, a backward-Euler step multiplies a mode by
(1 + s·e)/(1 + s·W_lin) ∈ (0, 1) for every step s (not oscillating), and for large steps BDF2's roots have
|z|² → e/W_lin < 1.  (A smaller S_lin, e.g. the mean slip, lets W_true exceed W_lin, the factor turns negative and reaches
−1 where W_true = 2·W_lin: just above δ_t the pressure then checkerboarded.)  The splitting alone is first-order in
the step, so the step's gap is corrected once (CORRECTIONS) for the wear its cycle really found, and the mismatch
left after that, passed through the step's own response s·W(C + s·W)⁻¹, is
``Cycle.defect`` — the loop adds it to the step's error estimate.  Invariant: each body's volume is k·Σp|ds|A
(α·ΣW for the energy law), accumulated cycle by cycle.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from fretsim.compliance import scaled
from fretsim.cycle.loop import LOOP_SIDE_INCREMENTS, elastic_side, loop_path, turning_loop
from fretsim.cycle.resolved import (TRAVEL_TOLERANCE, add_rows, coupled_positions, mirror_images, mismatch_rows,
                                    positions, sweep_of)
from fretsim.cycle.result import TRACTIONS, Cycle, CycleError, CycleSpec, stick_half_width
from fretsim.grid import Grid
from fretsim.solvers.tangential import solve_tangential
from fretsim.wear import Sweep, gap_wear, sweep_read, wear_operator
from fretsim.wear_laws import WEAR_LAWS, WearLaw, coefficients

CORRECTIONS = 1  # fixed-point corrections of an implicit step's gap for the wear its cycle really found: the
#                 linearised step alone is first-order in the step (its bias ∝ the step), one correction cuts the
#                 depth error 4× at a third of the solves (ball_partial_slip against the per-cycle run: README)
SPREAD_TO_CORRECT = 0.1  # ... where the slip varies by more than this share of its largest (1 − mean/max): in gross
#                         slip far above δ_t every point slides nearly alike, the linearisation is nearly exact
#                         (McColl 185 N: 1e-5 without the correction) and the correction would cost 1.5× the time
RESOLVED_CORRECTIONS = 3  # ... every step of the resolved stroke that cannot be solved coupled (COUPLED: partial
#                           slip, a solver other than cg, refinement's coarse grid), where the linear operator (a bound, the same at every
#                           position) is further from each position's real wear: each pass cuts the step's bias
#                           about 5× (McColl 185 N 2D at 1 000 cycles, BDF2 against the run cycle by cycle: +1.9 %,
#                           +0.26 %, +0.025 % after 0, 1, 3 from no correction; scripts/results/resolved_stepping.txt)
# (a resolved step that stopped correcting once a pass moved the deepest wear by less than 1 % of model.accuracy of
# its depth, with each step's corrections from none, was +0.25 % off the run cycle by cycle at 1 000 cycles against an
# estimate of 0.17 %: every step corrects RESOLVED_CORRECTIONS times, +0.025 % against 0.031 %; tests/test_friction.py)
COUPLED = True  # a resolved implicit step solves its positions coupled by the step's wear (resolved.coupled_positions),
#                a symmetric cycle under one load its up-stroke only (the down-stroke mirrored: resolved.COUPLED_MIRROR):
#                McColl 185 N 2D 1.06 s against the corrected passes' 2.2 s, 3D 32–35 s against 54–60 s, with stepping
#                estimates of 0.26 % (2D) and 0.28 % (3D) where the corrected passes' defect, from their bound, makes
#                theirs 1.6 % and 1.8 %, over model.accuracy (the tube in service: 3.0 % against 86 %).  Its odd-even
#                guard (resolved.ODD_EVEN_RUN) hands a step to the corrected passes; so do partial slip, solvers other
#                than cg and refinement's coarse grid.  Off until 2026-11-27 because its short-run estimate
#                under-stated the error: the stepping estimate's own fault (simulate._Loop.depth_error), corrected
RESOLVED_PASSES = 1 + RESOLVED_CORRECTIONS  # the cost estimate's passes per resolved implicit step, corrected
COUPLED_PASSES = 2.7  # ... and what a coupled step costs in such passes over a run (its CG takes 2–4 times a pass's
#                       iterations over the up-stroke's positions where the cycle is symmetric, the run about 0.6 times
#                       the steps the estimate counts): at 4, McColl 185 N was estimated at 1.42 s (2D) and 55 s (3D)
#                       and ran 1.04 s and 33 s (2026-11-27); across load blocks, where the step is not mirrored
#                       (resolved.COUPLED_MIRROR), about 4: the estimate is then about 1.5× low
FATIGUE_SIDE_INCREMENTS = 1  # each elastic side of a fatigue state's cycle (not recorded): the flat's stresses
#                              over the side move between its ends (the damage with 1, 2 and 12 alike to 1e-11 at
#                              4, 10 and 25 µm on cases/ti_fretting_fatigue.yaml)


@dataclass(frozen=True)
class CoulombCycle:
    grid: Grid
    compliance: object  # the normal operator C on the grid (its symbol filters the implicit step's mismatch)
    tangential: object  # K on the grid
    stroke: float  # mm, the rig's amplitude δ
    load: float  # on the grid: N (3D) or N/mm (2D)
    total_load: float  # N
    friction_coefficient: float
    k_moving: float  # the wear law's coefficients (Archard's k, or α of the energy law: 1/MPa = mm³/(N·mm))
    k_stationary: float
    law: WearLaw = WEAR_LAWS["archard"]
    rigid: bool = False  # bodies rigid tangentially: every point slides with the rig (model.slip uniform)
    resolved: bool = False  # the normal contact solved at each increment, over the worn flat (model.stroke resolved)
    gap_model: str = "mid_stroke"  # at mid-stroke: how the flat's wear enters the mid-stroke gap
    increments: int = 9  # per half-stroke; odd, so that one is centred on mid-stroke
    volume_factor: float = 1.0  # the line length in 2D: grid volumes and forces → totals
    tolerance: float = 1e-10  # the tangential solver's
    name: str = "coulomb"
    linear: bool = False
    closed_form = False
    needs_friction = True
    assumes_gross_slip = False

    @classmethod
    def build(cls, spec: CycleSpec, rigid: bool = False):
        """The incremental cycle for one block (``rigid``: uniform slip resolved along the stroke)."""
        block = spec.block
        k_m, k_s = coefficients(spec.law, spec.moving, spec.stationary)
        return cls(grid=spec.grid, compliance=spec.compliance, tangential=spec.tangential, stroke=block.stroke,
                   load=spec.load, total_load=block.normal_load, friction_coefficient=block.friction_coefficient,
                   k_moving=k_m, k_stationary=k_s, law=spec.law, rigid=rigid, resolved=spec.resolved,
                   gap_model=spec.gap_model, increments=spec.increments, volume_factor=spec.volume_factor)

    @property
    def kernel(self) -> str:
        """How the flat is read and receives wear along a point's travel (fretsim.wear.sweep_deposit)."""
        return "hat" if self.resolved else "box"

    @property
    def invariant(self) -> str:
        return self.law.invariant

    # -- the linear operator the implicit steps use, and the explicit stability limit's bound --------------------
    @cached_property
    def _w_unit(self):
        """W at a slip of 4δ everywhere, with the coefficients of p·|ds| (α·μ for the energy law)."""
        c = self.law.gross_slip_factor(self.friction_coefficient)
        return wear_operator(self.grid, self.stroke, c * self.k_moving, c * self.k_stationary,
                             "resolved" if self.resolved else self.gap_model)

    def stiffness(self):
        return self._w_unit

    def passes(self, implicit: bool) -> float:  # (mid-stroke's one correction is in the cost's calibration)
        return (COUPLED_PASSES if COUPLED else RESOLVED_PASSES) if implicit and self.resolved else 1

    def describe(self) -> str:
        return (f"{'uniform' if self.rigid else 'coulomb'} slip, stroke {'resolved' if self.resolved else 'mid-stroke'}, "
                f"{self.increments} increments per half-stroke")

    @property
    def bounds(self) -> tuple[float, float]:
        """(work, energy) per cycle that no cycle may exceed (N·mm): no point slides further than the rig travels
        (4δ; less by the bodies' and the rig's elastic displacement) and |q| ≤ μp, so Σp·|ds|·A ≤ P·4δ and the
        dissipated energy ≤ μ·P·4δ, both reached in rigid gross slip.  Unlike the invariant, which the loop
        accumulates from the cycles' own work, these are independent of the solution: a slip or traction the
        tangential solve got wrong breaks them."""
        travel = 4.0 * self.stroke * self.total_load
        mu = self.friction_coefficient
        return self.law.gross_slip_factor(mu) * travel, mu * travel

    def expected_volumes(self, cycles: int, work: float) -> tuple[float, float]:
        return self.k_moving * work, self.k_stationary * work

    # -- one cycle --------------------------------------------------------------------------------------------
    def _elastic_side(self, pressure: np.ndarray) -> float:
        return 0.0 if self.rigid else elastic_side(self.tangential, self.friction_coefficient, pressure)

    def solve(self, wear_moving, wear_stationary, normal, guess, step: float = 0.0, memory=None,
              cycle: int = 0, detail: bool = True) -> Cycle:
        """One cycle; an implicit step's (``step`` > 0) corrected for its linearisation: CORRECTIONS times at
        mid-stroke, as :func:`_resolved_step` says for the resolved stroke."""
        if self.resolved and step:
            return _resolved_step(self, wear_moving, wear_stationary, normal, guess, step, memory, cycle, detail)
        uneven = float((memory or {}).get("slip_spread", 1.0)) > SPREAD_TO_CORRECT
        passes = 1 + (CORRECTIONS if step and uneven else 0)
        cyc = None
        for k in range(passes):
            cyc = self._solve(wear_moving, wear_stationary, normal, guess if cyc is None else cyc.pressure, step,
                              memory, cycle, detail, correction=None if cyc is None else cyc.mismatch,
                              corrected=k + 1 < passes)
        return cyc

    def _solve(self, wear_moving, wear_stationary, normal, guess, step: float = 0.0, memory=None,
              cycle: int = 0, detail: bool = True, correction=None, corrected: bool = False, predicted=None,
              couple: bool = False) -> Optional[Cycle]:
        """One cycle.  With the pressure fixed (mid_stroke) a half-stroke is one monotone increment, which the
        tangential solve takes exactly whatever its length: unless ``detail`` asks for the loop's shape (a
        recorded state), each half-stroke is taken in one increment — the same wear, slips, energy and regime."""
        shape = self.grid.shape
        n = self.increments if detail or self.resolved else 1
        w_lin = scaled(self._w_unit, float((memory or {}).get("slip_lin", 4.0 * self.stroke)) / (4.0 * self.stroke)) \
            if step else None
        extra = scaled(w_lin, step) if step else None
        fixed = None
        if not self.resolved:
            seen = gap_wear(wear_moving, wear_stationary, self.grid.dx, self.stroke, self.gap_model)
            seen = seen if correction is None else seen + correction
            fixed = normal(seen, guess, extra, load=self.load, cycle=cycle)
        tally = _Tally(shape, self.grid.area * self.volume_factor)
        q, s = np.zeros(shape), np.zeros(shape)
        path = _path(self, detail, fixed, n)
        first, mid, end = _marks(path)
        pre = None
        if self.resolved:  # (None: the coupled step cannot be taken here, the step corrects pass by pass)
            found = _positions(self, wear_moving, wear_stationary, normal, path, guess, extra, cycle, step, memory,
                               correction, predicted, couple)
            if found is None:
                return None
            pre, correction = found
        steps = masing(self, fixed[0], path) if fixed is not None and not self.rigid else None
        p_prev, ds_prev, du_prev = guess, None, None
        visits = []  # an implicit resolved step's (pressure, travel) at each increment, for its mismatch
        states = [] if detail else None  # the tractions round the loop (fretting fatigue; any pass may be returned)
        for k, (u0, u1, counted) in enumerate(path):
            if k == first:
                tally.loop(u0, q)
                q_low, p_low = q, p_prev
                if states is not None:
                    states.append((p_prev if p_prev is not None else fixed[0], q, s))
            du = u1 - u0
            if pre is not None:
                p, res, q_new, ds, stuck = pre[0][k], pre[1][k], pre[2][k], pre[4][k], pre[5][k]
            elif self.resolved:
                shift = correction[k] if correction is not None else None
                p, res, q_new, ds, stuck = self._resolved_increment(wear_moving, wear_stationary, normal, q, s, du,
                                                                    p_prev, ds_prev, du_prev, extra, cycle, tally,
                                                                    shift)
                if corrected:
                    visits.append((p, s, s + ds))
            else:
                (p, res), (q_new, ds, stuck, its) = fixed, steps[k] if steps is not None else \
                    self._tangential(q, fixed[0], du)
                tally.iterations += its
            if counted and pre is None:
                tally.add(self, p, q_new, s, ds, abs(du) / (4.0 * self.stroke))
            if counted:
                tally.loop(u1, q_new)
                if states is not None:
                    states.append((p, q_new, s + ds))
            if k == mid:
                p_mid, res_mid, travel_mid = p, res, (s, s + ds)
            if k == end:
                stick_end = stuck & (p > 0)
                q_high, p_high = q_new, p
            s, q = s + ds, q_new
            p_prev, ds_prev, du_prev = p, ds, du
        stacks = _stacked(self, tally, path, pre, wear_stationary) if self.resolved else None
        if self.resolved and detail is True and not self.rigid and not corrected:  # (a corrected pass draws no loop)
            tally.loop_u, tally.loop_q = turning_loop(self.stroke, max(LOOP_SIDE_INCREMENTS, self.increments),
                                                      self._tangential, self._elastic_side, (q_low, p_low),
                                                      (q_high, p_high), tally.area,
                                                      mirror_images(self, (q_low, p_low), (q_high, p_high)))
        defect, mismatch = _step_defect(self, wear_moving, wear_stationary, step, w_lin, tally, stacks, p_mid,
                                        travel_mid, correction, mid, corrected, visits, couple) if step else (0.0, None)
        cyc = tally.cycle(self, p_mid, res_mid, stick_end, defect, mismatch)
        if states:
            cyc.tractions = tuple(np.array(a) for a in zip(*states))
        cyc.turns = ((q_low, p_low), (q_high, p_high)) if self.resolved else None
        cyc.positions = stacks  # the resolved stroke's (pressures, starts, travels): the next pass's prediction
        return cyc

    def _resolved_increment(self, wear_moving, wear_stationary, normal, q, s, du, p_prev, ds_prev, du_prev, extra,
                            cycle: int, tally: "_Tally", shift=None):
        """One increment with the normal contact solved where the moving body is: each of its points over the worn
        flat at the travel predicted from the last increment, solved again where a point went elsewhere."""
        dx = self.grid.dx
        same_way = ds_prev is not None and du * du_prev > 0 and not self.rigid
        on = p_prev > 0 if p_prev is not None else None
        if same_way and np.abs(ds_prev[on] - du_prev).max(initial=0.0) < TRAVEL_TOLERANCE * dx:
            # the last increment slid the whole contact with the rig: this one will too (gross slip far from a
            # reversal, most increments); points about to enter the contact go as their nearest neighbour in it
            ds_guess = _nearest_in_contact(ds_prev * (du / du_prev), on)
        elif p_prev is not None and not self.rigid:
            # near a reversal, or in partial slip: where each point goes if the pressure stayed as it was, from a
            # tangential solve (about a quarter of a normal one in 2D), which foresees the elastic take-up that
            # scaling the last increment's slips missed by most of an element.  With both, the travel misses by
            # 0.1 element in 2.5 % of the increments, not 63 %: the normal contact is solved about once per
            # increment, not 1.6 times (McColl 185 N 2D: 4735 → 3279 normal solves)
            _, ds_guess, _, its = self._tangential(q, p_prev, du)
            tally.iterations += its
            ds_guess = _nearest_in_contact(ds_guess, on)
        else:
            ds_guess = ds_prev * (du / du_prev) if same_way else np.full(self.grid.shape, du)
        moving = wear_moving if shift is None else wear_moving + shift
        p, res = normal(moving + sweep_read(wear_stationary, s, s + ds_guess, dx, self.kernel), p_prev, extra,
                        load=self.load, cycle=cycle)
        tally.iterations += res.iterations
        q_new, ds, stuck, its = self._tangential(q, p, du)
        tally.iterations += its
        if not self.rigid:
            off = np.abs(ds - ds_guess)[p > 0]
            if off.size and off.max() > TRAVEL_TOLERANCE * dx:  # solve again where the points really went
                p, res = normal(moving + sweep_read(wear_stationary, s, s + ds, dx, self.kernel), p, extra,
                                load=self.load, cycle=cycle)
                q_new, ds, stuck, its = self._tangential(q, p, du)
                tally.iterations += res.iterations + its
        return p, res, q_new, ds, stuck

    def _tangential(self, q, p, du):
        """One increment's traction, its travel (the slip where in contact) and stick set; rigid bodies (``slip:
        uniform``) slide with the rig.

        The travel is every point's relative tangential displacement ΔU − KΔq, in contact or not: a point outside
        the contact still moves with its body.  Taking it as 0 there (the solver's slip) left a point that lost
        contact over the flat point where it left, so it re-entered the resolved stroke's contact reading the worn
        flat up to the stroke away from where it was: the moving body's profile went rough at element scale and
        the contact rattled between its spikes, worse on every finer grid (scripts/results/resolved_convergence.txt)."""
        on = p > 0
        if self.rigid:
            return np.where(on, np.sign(du) * self.friction_coefficient * p, 0.0), np.full(p.shape, du), \
                np.zeros(p.shape, bool), 0
        rhs = self.tangential(q) + du  # on the whole grid: the old traction may reach beyond the new contact
        if du != 0.0:
            # the whole contact sliding the rig's way at μp is the increment's solution (the minimum is unique)
            # where it leaves no point slipping against its traction: one convolution, not a solve
            cand = np.sign(du) * self.friction_coefficient * np.where(on, p, 0.0)
            ds = rhs - self.tangential(cand)
            if (np.sign(du) * ds[on] >= 0.0).all():
                return cand, ds, np.zeros(p.shape, bool), 0
        rows, cols = _span(on.any(axis=1)), _span(on.any(axis=0))
        res = solve_tangential(self.tangential.window(rows, cols), rhs[rows, cols],
                               self.friction_coefficient * p[rows, cols], q[rows, cols], tol=self.tolerance)
        if not res.success:
            raise CycleError(f"the tangential contact did not converge: {res.message}")
        q_new, stuck = np.zeros(p.shape), np.zeros(p.shape, bool)
        q_new[rows, cols], stuck[rows, cols] = res.traction, res.stick
        ds = rhs - self.tangential(q_new)  # ΔU − KΔq everywhere (rhs = Kq + ΔU)
        ds[rows, cols] = np.where(on[rows, cols], res.slip, ds[rows, cols])  # in contact: the solver's, 0 where stuck
        return q_new, ds, stuck, res.iterations

class _Tally:
    """What a cycle's increments add up to: each body's wear and slip, the flat's pressure over the travel, the
    shear's amplitude, the energy, the invariant's work and the loop, and the solvers' iterations."""

    def __init__(self, shape: tuple, area: float):
        self.area = area
        self.rate_m, self.rate_s = np.zeros(shape), np.zeros(shape)
        self.slip_m, self.slip_s, self.p_seen, self.shear = (np.zeros(shape), np.zeros(shape), np.zeros(shape),
                                                             np.zeros(shape))
        self.energy = self.work = 0.0
        self.iterations = 0
        self.loop_u, self.loop_q = [], []

    def loop(self, u: float, q: np.ndarray) -> None:
        """A point of the fretting loop: the rig's displacement and the total tangential force."""
        self.loop_u.append(u)
        self.loop_q.append(float(q.sum()) * self.area)

    def add(self, member: "CoulombCycle", p, q_new, s, ds, share: float) -> None:
        """One counted increment, ``share`` of the cycle's rig travel: the moving body wears at its own points, the
        flat where each point travelled; the flat's pressure is averaged over the rig's travel."""
        on = np.flatnonzero((p > 0).any(axis=0))  # the columns that carry anything (p = 0 elsewhere)
        sweep = Sweep(s, s + ds, member.grid.dx, member.kernel, slice(on[0], on[-1] + 1) if on.size else slice(0, 0))
        amount = member.law.amount(p, q_new, ds)
        self.rate_m += member.k_moving * amount
        self.rate_s += member.k_stationary * sweep.deposit(amount)
        slid = np.where(p > 0, np.abs(ds), 0.0)  # slip is travel in contact
        self.slip_m += slid
        self.slip_s += sweep.deposit(slid)
        self.p_seen += share * sweep.deposit(p)
        self.energy += float((np.abs(q_new) * np.abs(ds)).sum()) * self.area
        self.work += float(amount.sum()) * self.area
        self.shear = np.maximum(self.shear, np.abs(q_new))

    def cycle(self, member: "CoulombCycle", p_mid, res_mid, stick_end, defect: float, mismatch) -> Cycle:
        """The cycle these increments make, with the memory its next cycle's implicit step needs."""
        g = member.grid
        on = p_mid > 0
        s_mean = float((p_mid * self.slip_m).sum() / p_mid.sum())
        s_max = float(self.slip_m[on].max()) if on.any() else 0.0
        return Cycle(
            pressure=p_mid, pressure_stationary=self.p_seen, rate_moving=self.rate_m, rate_stationary=self.rate_s,
            slip_moving=self.slip_m, slip_stationary=self.slip_s, shear=self.shear, energy=self.energy,
            work=self.work, force_amplitude=float(np.abs(self.loop_q).max()),
            regime="partial_slip" if stick_end.any() else "gross_slip",
            stick_half_width_x=stick_half_width(stick_end[g.shape[0] // 2], g.x, g.dx), contact=res_mid,
            iterations=self.iterations, loop=(np.array(self.loop_u), np.array(self.loop_q)),
            memory={"slip_lin": max(s_max, 1e-300), "slip_spread": 1.0 - s_mean / s_max if s_max > 0 else 1.0,
                    # a stick zone: the implicit steps take forward-Euler ones (fretsim.stepping.implicit)
                    "stuck": float(stick_end.any())},
            defect=defect, mismatch=mismatch, stick=stick_end if stick_end.any() else None)


def _path(member: CoulombCycle, detail, fixed, n: int) -> list:
    """The cycle's increments: a recorded cycle at fixed pressure with its elastic sides finely cut (the loop), else
    ``n`` even increments a half-stroke."""
    fine = max(LOOP_SIDE_INCREMENTS, member.increments)  # model.increments asks for a finer loop, never coarser
    if detail == TRACTIONS:  # a fatigue state, not recorded: the tractions need the sides' ends, not their shape
        fine = FATIGUE_SIDE_INCREMENTS
    if detail and not member.resolved and not member.rigid:
        return loop_path(member.stroke, member._elastic_side(fixed[0]), fine)
    return increment_path(member.stroke, n)


def _positions(member: CoulombCycle, wear_moving, wear_stationary, normal, path: list, guess, extra, cycle: int,
               step: float, memory, correction, predicted, couple: bool):
    """A resolved cycle's positions solved together and the gap correction each carries: coupled by an implicit
    step's wear (``couple``; None where that cannot be done here), else as a pass ((None, correction) where the
    cycle goes increment by increment)."""
    du = np.array([b - a for a, b, _ in path])
    if couple:
        return coupled_positions(member, wear_moving, wear_stationary, normal, du, np.array([c for *_, c in path]),
                                 guess, extra, cycle, step, (memory or {}).get("positions"))
    return positions(member, wear_moving, wear_stationary, normal, du, guess, extra, cycle, correction,
                     predicted), correction


def _marks(path: list) -> tuple[int, int, int]:
    """The loop's first increment (after the quarter); the increment over U = 0 going up (centred on it for the
    resolved stroke's odd count); the up-stroke's end."""
    first = next(k for k, step in enumerate(path) if step[2])
    mid = next(k for k in range(first, len(path)) if path[k][0] < 0.0 <= path[k][1])
    end = max(k for k in range(first, len(path)) if path[k][1] > path[k][0])
    return first, mid, end


def increment_path(stroke: float, n: int) -> list[tuple[float, float, bool]]:
    """(U at the start, U at the end, counted) of every increment: 0 → −δ in one (uncounted: it sets up the
    traction's history, and loading monotonically from rest it is exact at a fixed pressure; cut as the loop it
    was a fifth of a resolved cycle's solves for 0.02 % of McColl 185 N's depth), then the loop −δ → +δ → −δ."""
    d = stroke
    nq = 1
    quarter = [(-d * k / nq, -d * (k + 1) / nq, False) for k in range(nq)]
    up = [(-d + 2 * d * k / n, -d + 2 * d * (k + 1) / n, True) for k in range(n)]
    down = [(d - 2 * d * k / n, d - 2 * d * (k + 1) / n, True) for k in range(n)]
    return quarter + up + down


def masing(member: CoulombCycle, p: np.ndarray, path: list) -> list:
    """(traction, travel, stick set, iterations) after each increment of ``path`` (0 → −δ, then half-strokes from
    each turning point, as :func:`increment_path` and :func:`~fretsim.cycle.loop.loop_path` make them) under the
    fixed pressure ``p``, from the first loading alone.

    With the pressure fixed, the loop is Masing's (Mindlin–Deresiewicz; exact for the uncoupled, incremental
    problem): from a turning point q_turn, after a rig travel o the traction is q_turn ∓ 2·q₀(o/2) and the travel
    ∓2·t₀(o/2), where q₀(v), t₀(v) are the first loading's from rest to v.  (They satisfy Coulomb's conditions:
    where q₀ sticks, 2·t₀ = 0 and |q| < μp; where it slides at μp, the reversed traction is at −μp and the travel
    reversed.  The minimum being unique, it is the increment's solution.)  So one loading curve, sampled at half
    of every offset the half-strokes reach, serves the quarter and both half-strokes: the tangential solves of a
    recorded cycle's loop are halved, and a cycle in partial slip solves once, not three times."""
    ups = [(a, b) for a, b, _ in path[1:]]
    # (up and down half-strokes reach their offsets by the same floating operations, (o − δ) ± δ, so the exact
    # values are the keys: no rounding, which loses the offsets' last digits where δ_t is tiny)
    offsets = sorted({abs(b - (-member.stroke if b > a else member.stroke)) for a, b in ups if b != a}
                     | {2.0 * member.stroke})
    q, t = np.zeros(p.shape), np.zeros(p.shape)
    curve, v = {}, 0.0
    for o in offsets:  # the first loading, monotone: each value from the last (the stick zone only shrinks)
        q, ds, stuck, its = member._tangential(q, p, o / 2.0 - v)
        t, v = t + ds, o / 2.0
        curve[o] = (q, t, stuck, its)
    q_m, t_m, stuck_m, _ = curve[2.0 * member.stroke]
    out = [(-q_m, -t_m, stuck_m, sum(c[3] for c in curve.values()))]  # 0 → −δ: the first loading, the other way
    #                                                                    (the curve's solves counted once, here)
    q_turn, t_prev = -q_m, np.zeros(p.shape)
    for a, b in ups:
        if b == a:  # an increment of no width (a side of none: μ = 0): nothing moves
            out.append((out[-1][0], np.zeros(p.shape), out[-1][2], 0))
            continue
        sign = 1.0 if b > a else -1.0
        turn = -sign * member.stroke
        if a == turn:  # a half-stroke starts: from the state at its turning point
            q_turn, t_prev = (out[-1][0], np.zeros(p.shape))
        qo, to, stuck, _ = curve[abs(b - turn)]
        travel = sign * 2.0 * to
        out.append((q_turn + sign * 2.0 * qo, travel - t_prev, stuck, 0))
        t_prev = travel
    return out


def _step_defect(member: CoulombCycle, wear_moving, wear_stationary, step: float, w_lin, tally: "_Tally", stacks,
                 p_mid, travel_mid, correction, mid: int, corrected: bool, visits: list, coupled: bool = False) -> tuple:
    """An implicit pass's (defect, mismatch): the mismatch at mid-stroke, or for a resolved pass that a correction
    follows (``corrected``) each increment's own.  A ``coupled`` pass (resolved.coupled_positions) is followed by
    no correction: its mid-stroke mismatch only (every increment's, a whole-grid stack read and transformed, was
    5 % of a 3D resolved run, for the one the defect uses)."""
    if coupled:
        return _defect(member, wear_moving, wear_stationary, step, w_lin, tally, p_mid, travel_mid,
                       correction[mid] if correction is not None else None)
    ahead = mismatch_rows(tally, member, stacks[3], *stacks[:3], step, w_lin) if stacks else None
    defect, mismatch = _defect(member, wear_moving, wear_stationary, step, w_lin, tally, p_mid, travel_mid,
                               correction[mid] if member.resolved and correction is not None else correction,
                               None if ahead is None else ahead[mid])
    if member.resolved and corrected:
        mismatch = ahead or _mismatches(visits, tally, step, w_lin, member.grid.dx, member.kernel)
    return defect, mismatch


def _defect(member: CoulombCycle, wear_moving, wear_stationary, step: float, w_lin, tally: "_Tally", p_mid, travel_mid,
            correction, mismatch=None) -> tuple[float, np.ndarray]:
    """An implicit step's linearisation error: the gap growth the mid-stroke solve anticipated against what the
    cycle found for that position (``mismatch``, unless given), and its effect on the deepest element's wear
    (``defect``)."""
    dx, shape = member.grid.dx, member.grid.shape
    if mismatch is None:
        found = tally.rate_m + (sweep_read(tally.rate_s, *travel_mid, dx, member.kernel) if member.resolved else
                                gap_wear(np.zeros(shape), tally.rate_s, dx, member.stroke, member.gap_model))
        mismatch = step * (found - w_lin(p_mid))
    deepest = np.unravel_index(np.argmax(wear_moving + wear_stationary), shape)
    defect = abs(float(_response(member.compliance, step, w_lin, mismatch - (correction if correction is not None else 0))
                       [deepest]))
    return defect, mismatch


def _response(compliance, step: float, w_lin, mismatch: np.ndarray) -> np.ndarray:
    """What a gap mismatch does to the wear of an implicit step: s·W(C + s·W)⁻¹ applied by Fourier symbols (the
    contact set ignored), so a smooth mismatch, which the pressure absorbs, counts little."""
    conv = getattr(compliance, "convolution", None)
    c_hat = conv.hat if conv is not None else compliance.hat
    w_hat = step * w_lin.hat
    return w_lin.backward(w_lin.forward(mismatch) * (w_hat / (c_hat + w_hat)))


def _resolved_step(member: CoulombCycle, wear_moving, wear_stationary, normal, guess, step: float, memory,
                   cycle: int, detail: bool) -> Cycle:
    """A resolved implicit step: its positions solved coupled by the step's wear (resolved.coupled_positions), or
    where that cannot be done, its increments' gaps corrected RESOLVED_CORRECTIONS times for the wear the cycle
    really found, from no correction.

    Not from the last step's corrections scaled to this one (tried: 1.4 passes a step instead of 4): a correction
    is sharp where the contact's edge was, and the edge moves between steps, so a reused one put spikes into the
    gap that the wear then kept — McColl 185 N 2D peaked at 328 MPa at 6 000 cycles where the run cycle by cycle
    has 81 MPa, 1.4 GPa on a grid four times finer, its width 0.3 % narrow (scripts/results/bench_resolved.txt,
    fifth round)."""
    cyc = member._solve(wear_moving, wear_stationary, normal, guess, step, memory, cycle, detail, corrected=True,
                        couple=True) if COUPLED else None
    passes = 0 if cyc is not None else 1 + RESOLVED_CORRECTIONS
    correction = None
    for _ in range(passes):
        cyc = member._solve(wear_moving, wear_stationary, normal, guess if cyc is None else cyc.pressure, step,
                            memory, cycle, detail, correction=correction, corrected=True,
                            predicted=None if cyc is None else cyc.positions)
        correction = cyc.mismatch
    if COUPLED and cyc.positions:  # the next step's coupled solve starts from these (checkpointed: kept only
        cyc.memory["positions"] = cyc.positions[0]  # where a coupled solve will read them)
    if detail is True and not member.rigid:  # the recorded loop, of the pass returned only (48 ms a 2D draw)
        u, q = turning_loop(member.stroke, max(LOOP_SIDE_INCREMENTS, member.increments), member._tangential,
                            member._elastic_side, *cyc.turns, member.grid.area * member.volume_factor,
                            mirror_images(member, *cyc.turns))
        cyc.loop, cyc.force_amplitude = (np.array(u), np.array(q)), float(np.abs(q).max())
    return cyc


def _mismatches(visits: list, tally: _Tally, step: float, w_lin, dx: float, kernel: str) -> list:
    """For a resolved step's next pass, each increment's own mismatch: the gap growth its position found against
    the anticipated."""
    return [step * (tally.rate_m + sweep_read(tally.rate_s, a, b, dx, kernel) - w_lin(pk)) for pk, a, b in visits]


def _stacked(member: CoulombCycle, tally: _Tally, path: list, pre, wear_stationary) -> tuple:
    """A resolved cycle's (pressures, starts, travels, their Sweep) at every increment, stacks (m, My, Mx), where its
    increments were solved together (``pre``; the tally then adds the counted ones at once); () where one by one
    (the step's next passes then go one by one too)."""
    if pre is None:
        return ()
    p, _, q, s, ds, _, iterations = pre
    shares = np.array([abs(b - a) for a, b, _ in path]) / (4.0 * member.stroke)
    sweep = sweep_of(member, p, s, ds, wear_stationary, np.array([c for _, _, c in path]))
    add_rows(tally, member, sweep, p, q, ds, shares)
    tally.iterations += iterations
    return p, s, ds, sweep


def _nearest_in_contact(values: np.ndarray, on: np.ndarray) -> np.ndarray:
    """``values`` outside the contact ``on`` replaced, row by row, by the nearest value inside it along x (the left
    one on a tie); rows without contact kept.  All rows at once (a 3D grid's rows, one by one, were a twentieth of
    a resolved run)."""
    ny, nx = values.shape
    idx = np.broadcast_to(np.arange(nx), (ny, nx))
    big = nx
    right = np.minimum.accumulate(np.where(on, idx, big)[:, ::-1], axis=1)[:, ::-1]  # first in contact at or after
    last = np.where(on, idx, -1).max(axis=1, keepdims=True)
    right = np.where(right == big, last, right)
    before = np.maximum.accumulate(np.where(on, idx, -1), axis=1)  # last in contact at or before
    left = np.concatenate([np.full((ny, 1), -1), before[:, :-1]], axis=1)  # ... strictly before
    first = np.where(on, idx, big).min(axis=1, keepdims=True)
    left = np.where(left < 0, first, left)
    pick = np.where(idx - left <= right - idx, left, right)
    rows = on.any(axis=1)
    out = values.copy()
    out[rows] = np.take_along_axis(values, np.clip(pick, 0, nx - 1), axis=1)[rows]
    return out


def _span(mask: np.ndarray) -> slice:
    """The rows (or columns) from the first to the last in contact: shear traction lives only there."""
    idx = np.flatnonzero(mask)
    return slice(int(idx[0]), int(idx[-1]) + 1) if idx.size else slice(0, 1)


def gross_slip_stroke(tangential, pressure: np.ndarray, friction_coefficient: float) -> float:
    """δ_t (mm): the rig displacement at which the last point of a contact under ``pressure`` starts to slide.

    In full sliding every point carries q = μp, so a point has slid once the rig displacement exceeds the elastic
    displacement K·μp there; the last to go is where that is largest.  The cyclic loop reaches gross slip at the
    same amplitude (Masing: the traction reverses over 2δ_t).  It is taken on the centre section y = 0, where a
    ball's last point is anyway; a finite line contact's ends carry end effects the grid resolves only as it is
    refined (on a long cylinder the ends' value grows by 1.7 % from 21 to 81 rows, the centre's moves by 0.4 %), and the
    2D model is of the centre section.  For a Hertzian ball it is Mindlin's
    3μP/(16a)·Σ(2 − ν)/G; in 2D it depends on the datum (:mod:`fretsim.compliance.tangential`).
    """
    u = tangential(friction_coefficient * pressure)
    ny = pressure.shape[0]
    rows = slice((ny - 1) // 2, ny // 2 + 1)  # the centre section (the middle row, or the two middle rows)
    u, on = u[rows], pressure[rows] > 0
    return float(u[on].max()) if on.any() else 0.0
