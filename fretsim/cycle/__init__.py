"""The fretting-cycle family: one representative cycle of the loaded contact, given both bodies' wear.

Every member answers one question for the loop — *what does one fretting cycle do at this wear state?* — and
returns a :class:`Cycle`: the pressure on the moving body (at mid-stroke), what the flat sees over the stroke,
each body's slip distance per cycle at each point, the shear traction, the dissipated energy and the wear per
cycle of both bodies.  The loop (:mod:`fretsim.simulate`) only steps the wear with these rates; the stepping
schemes never see the physics of the cycle.

Members (chosen by ``model.slip``):

* ``uniform`` (:mod:`.uniform`): the paper's model — pressure solved once at mid-stroke, every point slides 4δ,
  the flat wears with the stroke-averaged pressure (Eqs. 15–16).  Its rates are linear in the pressure, so the
  implicit steps fold them into the compliance exactly.  Invariant: wear volume k·P·4δ·N.
* ``coulomb`` (:mod:`.coulomb`): Coulomb friction resolved through the cycle in increments (partial and gross
  slip, Mindlin–Deresiewicz history), with the pressure at mid-stroke or resolved at each increment.  Its rates
  depend on the slip, which depends on the pressure: the implicit steps use a linear operator that bounds its
  stiffness and report the mismatch (``Cycle.defect``).  Invariant: wear volume k·Σ p·|ds|·A per cycle.

Every member has the same small interface (:class:`FrettingCycle`); the registry :data:`CYCLES` maps names to
builders, and tests loop over it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional, Protocol

import numpy as np

from fretsim.solvers.result import ContactResult

REGIMES = ("partial_slip", "gross_slip")


class CycleError(Exception):
    """A cycle that could not be solved (a tangential solve that did not converge); the loop reports it as a
    numerical failure at the cycle it was asked for."""


@dataclass
class Cycle:
    """What one representative fretting cycle does at a given wear state.  Arrays on the fine grid."""

    pressure: np.ndarray  # MPa, on the moving body at mid-stroke
    pressure_stationary: np.ndarray  # MPa, on the flat averaged over the stroke's travel
    rate_moving: np.ndarray  # mm of wear per cycle
    rate_stationary: np.ndarray
    slip_moving: np.ndarray  # mm of slip per cycle at each point of the moving body
    slip_stationary: np.ndarray  # ... and of the flat
    shear: np.ndarray  # MPa, amplitude of the shear traction on the moving body over the cycle (NaN: not modelled)
    energy: float  # N·mm dissipated per cycle (NaN where no friction coefficient is known)
    work: float  # the invariant per cycle whose k-multiple is each body's wear volume per cycle (N·mm)
    force_amplitude: float  # N, the largest |Q| over the cycle (NaN: not modelled)
    regime: str  # partial_slip | gross_slip
    stick_half_width_x: float  # mm, of the stick zone along y = 0 at the stroke's end (0 in gross slip)
    contact: ContactResult  # the mid-stroke normal solve, on the grid it was solved on
    iterations: int = 0  # solver iterations over the whole cycle
    loop: Optional[tuple] = None  # (applied displacement mm, tangential force N) round the fretting loop
    memory: dict = field(default_factory=dict)  # what the member carries to its next cycle (checkpointed)
    stick: Optional[np.ndarray] = None  # elements that stuck through the end of the up-stroke (partial slip)
    mismatch: Optional[np.ndarray] = None  # implicit steps of a non-linear member: the gap growth found − anticipated
    defect: float = 0.0  # implicit steps: |wear the solve anticipated − wear found| at the deepest element (mm)


Normal = Callable[..., tuple]  # normal(seen_wear, guess, extra=None, load=None, cycle=0) -> (pressure, ContactResult)


class FrettingCycle(Protocol):
    """The interface of a member.  ``solve`` may be asked for an implicit cycle: with ``step`` = s > 0 each normal
    solve anticipates s cycles of the wear it produces (compliance C + s·W), so that the loop's update
    h + s·rates is what the contact saw."""

    name: str
    linear: bool  # wear rates linear in the mid-stroke pressure: implicit steps are exact
    invariant: str  # the conserved quantity, for messages

    def solve(self, wear_moving: np.ndarray, wear_stationary: np.ndarray, normal: Normal,
              guess: Optional[np.ndarray], step: float = 0.0, memory: Optional[dict] = None,
              cycle: int = 0, detail: bool = True) -> Cycle:
        """``detail``: the state will be recorded, so draw what is only drawn (the loop's shape) in full."""

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

    # a linear member also rebuilds the cycle of a checkpoint's pressure without solving: restore(pressure)


def stick_half_width(stick_row: np.ndarray, x: np.ndarray, dx: float) -> float:
    """Half the length along x of the stick zone in one row (0 if none): the stuck elements' extent, centre to
    centre plus one element, halved."""
    idx = np.flatnonzero(stick_row)
    if not idx.size:
        return 0.0
    return 0.5 * (float(x[idx[-1]] - x[idx[0]]) + dx)



from fretsim.cycle.coulomb import CoulombCycle  # noqa: E402 - the members need Cycle above
from fretsim.cycle.uniform import UniformCycle  # noqa: E402

CYCLES: dict[str, type] = {"uniform": UniformCycle, "coulomb": CoulombCycle}
