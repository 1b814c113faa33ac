"""The stepping-scheme family: how the loop advances the wear over many cycles per contact solve.

The model is the paper's per-cycle update, h_{N+1} = h_N + r(h_N) (:mod:`fretsim.jumping` has the numerics and
why the implicit schemes integrate φ = h + ½r).  A member drives the loop (:mod:`fretsim.simulate`) from its
current state to its last cycle: it asks the loop for a cycle at a wear state (one contact solve at least),
advances the wear with the rates that cycle returns, and hands each accepted state to the loop to record.  It
never looks inside the cycle, which is the fretting-cycle family's (:mod:`fretsim.cycle`).

Members (``jumping.scheme``): ``bdf2`` (second-order implicit steps under error control, the default),
``implicit`` (backward Euler), ``linear`` (the paper's explicit ΔN_L) and ``adaptive`` (the paper's Taylor jumps,
Eqs. 19–21).  Every member has the interface of :class:`Scheme`; :data:`SCHEMES` maps names to them, the case
reader validates the name against it, the planner and the loop ask it, and the tests loop over it.
"""
from __future__ import annotations

from typing import Optional, Protocol

from fretsim.stepping.adaptive import Adaptive
from fretsim.stepping.implicit import Implicit
from fretsim.stepping.linear import Linear, relative_change


class Scheme(Protocol):
    name: str
    implicit: bool  # each step solves with C + s·W: no explicit stability limit, a stalled warm start retried cold
    per_cycle_short_runs: bool  # a run of a few cycles takes one cycle per step unless jumping.linear is given

    def reason(self, case) -> str:
        """Why the planner chose it, as ``check`` and /choices print it."""

    def describe(self, case, summary: dict) -> str:
        """How a run stepped, for its one-paragraph summary."""

    def estimate_solves(self, setup) -> int:
        """Solves a run of ``setup`` is expected to take (for the progress bar and ``check``)."""

    def max_jump(self, case, jump: int, limit: float, allow_unstable: bool) -> tuple[Optional[int], list]:
        """The largest step (None: unbounded), and the (value, reason) of each automatic choice of it."""

    def growth_cause(self, setup, model) -> str:
        """What an odd-even pressure pattern that grows under this scheme means, and what to change."""

    def run(self, loop):
        """Step ``loop`` to its last cycle; the last accepted step (None if none was taken)."""


SCHEMES: dict[str, Scheme] = {"bdf2": Implicit("bdf2", order=2), "implicit": Implicit("implicit", order=1),
                              "linear": Linear(), "adaptive": Adaptive()}
DEFAULT_SCHEME = "bdf2"

__all__ = ["DEFAULT_SCHEME", "SCHEMES", "Adaptive", "Implicit", "Linear", "Scheme", "relative_change"]
