"""The fretting-cycle family: one representative cycle of the loaded contact, given both bodies' wear.

Every member answers one question for the loop — *what does one fretting cycle do at this wear state?* — and
returns a :class:`Cycle`: the pressure on the moving body (at mid-stroke), what the flat sees over the stroke,
each body's slip distance per cycle at each point, the shear traction, the dissipated energy and the wear per
cycle of both bodies.  The loop (:mod:`fretsim.simulate`) only steps the wear with these rates; the stepping
schemes never see the physics of the cycle.

Members (chosen by ``model.slip``; ``model.stroke`` says where the normal contact is solved):

* ``uniform`` (:mod:`.uniform`): the paper's model — pressure solved once at mid-stroke, every point slides 4δ,
  the flat wears with the stroke-averaged pressure (Eqs. 15–16).  Its rates are linear in the pressure, so the
  implicit steps fold them into the compliance exactly.  Invariant: wear volume k·P·4δ·N.
* ``coulomb`` (:mod:`.coulomb`): Coulomb friction resolved through the cycle in increments (partial and gross
  slip, Mindlin–Deresiewicz history), with the pressure at mid-stroke or resolved at each increment.  Its rates
  depend on the slip, which depends on the pressure: the implicit steps use a linear operator that bounds its
  stiffness and report the mismatch (``Cycle.defect``).  Invariant: wear volume k·Σ p·|ds|·A per cycle.

Every member has the same small interface (:class:`FrettingCycle`) and builds itself from a :class:`CycleSpec`
(one block of the loading on the run's grid, its operators and wear law); the registry :data:`CYCLES` maps the
names a case may give to the members, the case reader validates ``model.slip`` against it, the planner builds
through :func:`build`, and the tests loop over it.  A new member is one module here and one registry line.
"""
from __future__ import annotations

from typing import Callable, Optional, Protocol

import numpy as np

from fretsim.cycle.coulomb import CoulombCycle
from fretsim.cycle.result import REGIMES, Cycle, CycleError, CycleSpec, stick_half_width
from fretsim.cycle.uniform import UniformCycle

__all__ = ["CYCLES", "REGIMES", "STROKES", "CoulombCycle", "Cycle", "CycleError", "CycleSpec", "FrettingCycle",
           "UniformCycle", "build", "friction_needed", "stick_half_width"]

Normal = Callable[..., tuple]  # normal(seen_wear, guess, extra=None, load=None, cycle=0) -> (pressure, ContactResult)


class FrettingCycle(Protocol):
    """The interface of a member.  ``solve`` may be asked for an implicit cycle: with ``step`` = s > 0 each normal
    solve anticipates s cycles of the wear it produces (compliance C + s·W), so that the loop's update
    h + s·rates is what the contact saw."""

    name: str
    linear: bool  # wear rates linear in the mid-stroke pressure: implicit steps are exact
    invariant: str  # the conserved quantity, for messages
    closed_form: bool  # the invariant is k·P·4δ·N itself (summed over a load history's blocks), not the work
    gap_model: str  # how the flat's wear enters the mid-stroke gap ("–": not at mid-stroke)
    needs_friction: bool  # the member resolves the shear traction: loading.friction_coefficient is required
    assumes_gross_slip: bool  # every point slides: refused where the contact partly sticks

    @classmethod
    def build(cls, spec: "CycleSpec") -> "FrettingCycle":
        """The member for one block of the loading."""

    def solve(self, wear_moving: np.ndarray, wear_stationary: np.ndarray, normal: Normal,
              guess: Optional[np.ndarray], step: float = 0.0, memory: Optional[dict] = None,
              cycle: int = 0, detail: bool | str = True) -> Cycle:
        """``detail``: the state will be recorded, so draw what is only drawn (the loop's shape) in full, and give
        the tractions round the loop (``Cycle.tractions``); ``TRACTIONS``: the tractions only (a fatigue state)."""

    def describe(self) -> str:
        """The cycle model in a few words, for a run's one-paragraph summary."""

    def passes(self, implicit: bool) -> float:
        """Cycles solved per step (an implicit step's corrections re-solve it; a coupled step costs as many): for
        the cost estimate."""

    def stiffness(self):
        """An operator W (gap growth per cycle per unit pressure, on the solve grid) whose spectrum bounds the
        member's: it sets the explicit stability limit and is what an implicit step folds into the compliance."""

    @property
    def bounds(self) -> tuple[float, float]:
        """(work, energy) per cycle (N·mm) that the physics forbids any cycle to exceed (inf: no bound): the loop
        checks every cycle and the accumulated work against them, independently of the invariant."""

    def expected_volumes(self, cycles: int, work: float) -> tuple[float, float]:
        """(moving, stationary) wear volumes (mm³) the invariant demands after ``cycles`` with accumulated
        ``work``."""

    def restore(self, pressure: np.ndarray) -> Cycle:
        """A linear member rebuilds the cycle of a checkpoint's pressure without solving (others solve again)."""



CYCLES: dict[str, type] = {"uniform": UniformCycle, "coulomb": CoulombCycle}
PAPER = "uniform"  # the paper's member: what auto keeps where gross slip is assumed or within model.accuracy
FRICTION = "coulomb"  # the member that resolves friction: what auto takes where the paper's is not accurate enough
# model.stroke: where the normal contact is solved — once at mid-stroke (the paper), or at each increment
STROKES: dict[str, bool] = {"mid_stroke": False, "resolved": True}
MID_STROKE = "mid_stroke"
RESOLVED = "resolved"  # what auto takes where a proxy shows the stroke's positions matter


def build(slip: str, stroke: str, spec_fields: dict) -> FrettingCycle:
    """The member ``slip`` (a name in :data:`CYCLES`) for one block, the contact solved as ``stroke`` says."""
    return CYCLES[slip].build(CycleSpec(resolved=STROKES[stroke], **spec_fields))


def friction_needed(slip: str, stroke: str, law) -> Optional[str]:
    """Why a case's model needs loading.friction_coefficient (None if it does not): a member that resolves the
    shear traction, a wear law of the friction's energy, or a resolved stroke (the traction μp it reports)."""
    if slip in CYCLES and CYCLES[slip].needs_friction:
        return f"model.slip {slip}"
    if law is not None and law.needs_friction:
        return f"model.wear_law {law.name} ({law.formula})"
    if STROKES.get(stroke):
        return f"model.stroke {stroke} (the shear traction μp it reports at each increment)"
    return None
