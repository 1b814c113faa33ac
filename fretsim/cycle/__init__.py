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

from dataclasses import dataclass, field
from typing import Callable, Optional, Protocol

import numpy as np

from fretsim.grid import Grid
from fretsim.loading import Block
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
    closed_form: bool  # the invariant is k·P·4δ·N itself (summed over a load history's blocks), not the work
    singular_pressure: bool  # the model's own pressure has element-scale peaks: no ceiling on the checkerboard
    gap_model: str  # how the flat's wear enters the mid-stroke gap ("–": not at mid-stroke)
    needs_friction: bool  # the member resolves the shear traction: loading.friction_coefficient is required
    assumes_gross_slip: bool  # every point slides: refused where the contact partly sticks

    @classmethod
    def build(cls, spec: "CycleSpec") -> "FrettingCycle":
        """The member for one block of the loading."""

    def solve(self, wear_moving: np.ndarray, wear_stationary: np.ndarray, normal: Normal,
              guess: Optional[np.ndarray], step: float = 0.0, memory: Optional[dict] = None,
              cycle: int = 0, detail: bool = True) -> Cycle:
        """``detail``: the state will be recorded, so draw what is only drawn (the loop's shape) in full."""

    def describe(self) -> str:
        """The cycle model in a few words, for a run's one-paragraph summary."""

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


@dataclass(frozen=True)
class CycleSpec:
    """What a member is built from: one block of the loading on the run's grids, with its operators."""

    grid: Grid  # the fine grid (wear, rates)
    solve_grid: Grid  # the grid the normal contact is solved on (coarser with refinement, Eqs. 11-12)
    compliance: object  # the normal operator C on ``grid``
    tangential: object  # both bodies' tangential compliance K on ``grid`` (None without a friction coefficient)
    block: Block  # the load, stroke and μ
    load: float  # the block's load on the grid: N (3D) or N/mm (2D)
    law: object  # the wear law (fretsim.wear_laws)
    moving: object  # the bodies' materials (their wear-law coefficients)
    stationary: object
    gap_model: str  # how the flat's wear enters the mid-stroke gap (fretsim.wear)
    resolved: bool  # the normal contact solved at each increment of the stroke (model.stroke resolved)
    increments: int  # per half-stroke
    volume_factor: float  # the line length in 2D: grid volumes and forces → totals


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
PAPER = "uniform"  # the paper's member: what auto keeps where gross slip is assumed or within model.accuracy
FRICTION = "coulomb"  # the member that resolves friction: what auto takes where the paper's is not accurate enough
# model.stroke: where the normal contact is solved — once at mid-stroke (the paper), or at each increment
STROKES: dict[str, bool] = {"mid_stroke": False, "resolved": True}
MID_STROKE = "mid_stroke"


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
