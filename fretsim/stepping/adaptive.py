"""``adaptive``: the paper's adaptive cycle jumping — batches of Q_LINEAR linear steps, then a Taylor jump (Eqs.
19–21, Fig. 8), under control."""
from __future__ import annotations

from typing import Optional

from fretsim.errors import NumericalFailure
from fretsim.jumping import Q_LINEAR, taylor_extrapolate, taylor_jump
from fretsim.stability import NOISE_FLOOR, checkerboard_signed
from fretsim.stepping.linear import explicit_growth_cause, relative_change

PAPER_MAX_JUMP = 600  # the paper's ΔN_max


class Adaptive:
    name = "adaptive"
    implicit = False
    per_cycle_short_runs = False

    def reason(self, case) -> str:
        return "the paper's adaptive jumps (Eqs. 19-21)"

    def describe(self, case, summary: dict) -> str:
        return f"adaptive jumps (η {case.eta:g}, ΔN_max {case.max_jump}, ΔN_L {summary['linear_jump']})"

    def estimate_solves(self, setup) -> int:
        return int(setup.cycles / (setup.linear_jump * 6 + 300)) * 6 + len(setup.snapshots) + 10

    def max_jump(self, case, jump: int, limit: float, allow_unstable: bool) -> tuple[Optional[int], list]:
        """The paper's ΔN_max unless given, capped at the explicit stability limit; with the (value, reason) of
        each automatic choice of it, for the plan."""
        max_jump, chosen = case.max_jump, []
        if max_jump is None:
            max_jump = PAPER_MAX_JUMP
            chosen.append((max_jump, "the paper's ΔN_max"))
        if max_jump > limit and not allow_unstable:
            # an adaptive jump extrapolates the wear explicitly: a jump of ΔN multiplies the grid-scale wear modes by
            # up to |1 − 2ΔN/limit|.  The linear steps between jumps damp them again, so the run stays bounded, but a
            # state after a jump rings: McColl 1670 N 2D with the paper's 600 (limit 159) ended 8 % (L2) from the
            # per-cycle pressure, ±40 % element to element at the contact's edges; capped, 0.25 %
            capped = max(jump, int(limit))
            chosen.append((capped, f"{max_jump} capped at the explicit stability limit of this grid ({limit:.4g} "
                                   f"cycles): an adaptive jump extrapolates the wear explicitly, and one of {max_jump} "
                                   f"cycles would multiply the grid-scale wear modes "
                                   f"{abs(1 - 2 * max_jump / limit):.1f}-fold, leaving the pressure ringing at the "
                                   f"contact's edges"))
            max_jump = capped
        return max_jump, chosen

    def growth_cause(self, setup, model) -> str:
        return explicit_growth_cause(setup, "adaptive jumps")

    def run(self, loop):
        """The jump extrapolates with the current wear rates, so a jump well past the explicit stability limit
        can excite the odd-even pressure mode.  A jump after which that mode is visible (above the noise floor
        and more than twice what it was) or whose solve fails is undone and retried at half the length
        (counted as rejected); below the linear jump it becomes a linear step.  The linear steps that follow
        damp what remains.  Jumps never end on a snapshot or the last cycle: those are reached by linear
        steps, so recorded states are stabilised.  The invariant's work and the dissipated energy are
        extrapolated with the wear.
        """
        s = loop.s
        lin = s.linear_jump
        step = None
        if not loop.batch:
            loop.batch = [(loop.h_m, loop.h_s, loop.work, loop.energy)]
        while loop.n < s.cycles:
            loop.enter_block()
            room = loop.next_stop() - loop.n
            if len(loop.batch) > Q_LINEAR and room > (Q_LINEAR + 1) * lin:
                jumped, step = self._jump(loop, lin, room, step)
                if jumped:
                    continue
            d_n = min(lin, room)
            cyc, e_p = loop.explicit_step(d_n)
            # a shortened step breaks the equal spacing the differences need: restart the batch
            here = (loop.h_m, loop.h_s, loop.work, loop.energy)
            loop.batch = loop.batch + [here] if d_n == lin else [here]
            step = loop.emit(cyc, d_n, e_p) or step
        return step

    def _jump(self, loop, lin: int, room: int, step):
        """A Taylor jump from the last batch, halved until it is accepted; (whether one was taken, the last step)."""
        s = loop.s
        (m2, s2, w2, e2), (m1, s1, w1, e1), (m0, s0, w0, e0) = loop.batch[-3:]
        jump = min(taylor_jump([(m2, m1, m0), (s2, s1, s0)], lin, s.eta, s.max_jump or PAPER_MAX_JUMP),
                   room - Q_LINEAR * lin)
        before = abs(loop.watch.history[-1]) if loop.watch.history else 0.0
        while jump > lin:
            new_m = taylor_extrapolate(m2, m1, m0, lin, jump)
            new_s = taylor_extrapolate(s2, s1, s0, lin, jump)
            if not ((new_m >= m0).all() and (new_s >= s0).all()):
                jump //= 2  # the quadratic term must not make an increment negative
                continue
            saved = (loop.h_m, loop.h_s, loop.n, loop.work, loop.energy)
            loop.advance(new_m - m0, new_s - s0, jump, taylor_extrapolate(w2, w1, w0, lin, jump) - w0,
                         taylor_extrapolate(e2, e1, e0, lin, jump) - e0)
            try:
                cyc = loop.cycle_at(loop.n, loop.p)
                amp = abs(checkerboard_signed(cyc.contact.pressure))
                unstable = amp > max(NOISE_FLOOR, 2.0 * before)
            except NumericalFailure:
                unstable = True
            if unstable:
                loop.h_m, loop.h_s, loop.n, loop.work, loop.energy = saved
                loop.rejected += 1
                jump //= 2
                continue
            loop.p_prev = None
            loop.batch = [(loop.h_m, loop.h_s, loop.work, loop.energy)]
            loop.watch.reset()  # a jump is not a step of the linear sequence whose growth is watched
            step = loop.emit(cyc, jump, 0.5 * relative_change(cyc.pressure - loop.p, cyc.pressure)) or step
            return True, step
        loop.batch = [(loop.h_m, loop.h_s, loop.work, loop.energy)]
        return False, step
