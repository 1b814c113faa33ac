"""What one fretting cycle returns (:class:`Cycle`), what a member is built from (:class:`CycleSpec`), and the
failure of a cycle that could not be solved: the records the fretting-cycle family shares."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from fretsim.grid import Grid
from fretsim.loading import Block
from fretsim.solvers.result import ContactResult

REGIMES = ("partial_slip", "gross_slip")
TRACTIONS = "tractions"  # ``detail`` of a state detailed for its tractions only (fatigue), not recorded


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
    # a detailed cycle (a recorded or fatigue state): the moving body's pressure, shear traction (MPa) and each
    # point's travel over the flat (mm) at the loop's start and the end of each increment, arrays (state, ny, nx)
    tractions: Optional[tuple] = None
    turns: Optional[tuple] = None  # the resolved stroke: (traction, pressure) at −δ and +δ, the recorded loop's start
    positions: Optional[tuple] = None  # the resolved stroke solved as a stack: (pressures, starts, travels) (m, nx)
    bias: float = 0.0  # implicit steps: what the step's corrections, stopped early, may leave there (mm): counted in
    #                    the error estimate, not in the step's control (the corrections' own tolerance holds it)


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
