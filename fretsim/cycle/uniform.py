"""``uniform``: the paper's fretting cycle — gross slip everywhere, the pressure solved once at mid-stroke.

Every point in contact slides the full stroke, 4δ per cycle (the bodies are rigid tangentially); the moving
body wears with its own pressure and the flat with the stroke-averaged one (Eqs. 15–16, :mod:`fretsim.wear`).
How the flat's wear enters the mid-stroke gap is ``gap_model`` (Eq. 18, or its stroke average).  The rates are
linear in the pressure: W = 4δ(k_m I + k_s B), so an implicit step solves the contact with C + s·W and is exact.
Invariant: each body's wear volume is k·P·4δ·N.  With a friction coefficient the cycle also reports what gross
slip implies (shear traction μp, tangential force μP, energy 4μPδ per cycle); without one those are NaN.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from fretsim.compliance import scaled
from fretsim.cycle.result import Cycle, CycleSpec
from fretsim.grid import Grid
from fretsim.solvers.result import ContactResult
from fretsim.wear import archard_volume, gap_wear, stroke_average, wear_operator, wear_rates
from fretsim.wear_laws import gross_slip_coefficients


SAMPLES = 1  # increments per half-stroke of a detailed cycle's tractions: the contact slides rigidly with them
#             fixed, which the fatigue counts over every position on the way (fretsim.fatigue.damage.slides)


@dataclass(frozen=True)
class UniformCycle:
    """The paper's cycle.  ``k_moving``/``k_stationary`` are the coefficients of p·ds in the wear law (Archard's k,
    or α·μ for the energy law, which equals it in gross slip)."""

    grid: Grid  # the fine grid (wear, rates)
    wear_op: object  # W on the grid the contact is solved on (fretsim.wear.wear_operator)
    stroke: float  # mm
    load: float  # on the grid: N (3D) or N/mm (2D)
    total_load: float  # N
    k_moving: float
    k_stationary: float
    gap_model: str
    friction_coefficient: Optional[float] = None
    name: str = "uniform"
    linear: bool = True
    invariant: str = "k·P·4δ·N"
    closed_form = True  # its invariant is k·P·4δ·N itself (summed over a load history's blocks)
    needs_friction = False
    assumes_gross_slip = True

    @classmethod
    def build(cls, spec: CycleSpec):
        """The paper's cycle for one block; with the stroke resolved, the incremental cycle with bodies rigid
        tangentially (every point slides with the rig), which is uniform slip at each position."""
        if spec.resolved:
            from fretsim.cycle.coulomb import CoulombCycle
            return CoulombCycle.build(spec, rigid=True)
        block = spec.block
        mu = block.friction_coefficient
        k_m, k_s = gross_slip_coefficients(spec.law, spec.moving, spec.stationary, mu)
        return cls(grid=spec.grid, wear_op=wear_operator(spec.solve_grid, block.stroke, k_m, k_s, spec.gap_model),
                   stroke=block.stroke, load=spec.load, total_load=block.normal_load, k_moving=k_m, k_stationary=k_s,
                   gap_model=spec.gap_model, friction_coefficient=mu)

    def rates(self, pressure: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Wear per cycle of the moving and the stationary body for the mid-stroke pressure (Eqs. 15–16)."""
        return wear_rates(pressure, self.grid.dx, self.stroke, self.k_moving, self.k_stationary)

    def stiffness(self):
        return self.wear_op

    def passes(self, implicit: bool) -> int:
        return 1

    def describe(self) -> str:
        return f"gap model {self.gap_model}"

    def solve(self, wear_moving, wear_stationary, normal, guess, step: float = 0.0, memory=None,
              cycle: int = 0, detail: bool = True) -> Cycle:
        seen = gap_wear(wear_moving, wear_stationary, self.grid.dx, self.stroke, self.gap_model)
        p, res = normal(seen, guess, scaled(self.wear_op, step) if step else None, load=self.load, cycle=cycle)
        cyc = self._cycle(p, res)
        if detail and self.friction_coefficient:
            cyc.tractions = self.tractions(p)
        return cyc

    def tractions(self, p: np.ndarray) -> tuple:
        """The loop's tractions (Cycle.tractions): the mid-stroke pressure carried rigidly along the stroke, the
        shear μp along the motion, reversed at each end (gross slip everywhere), at SAMPLES positions per half."""
        d, mu = self.stroke, self.friction_coefficient
        up = np.linspace(-d, d, SAMPLES + 1)
        travel = np.concatenate([up, up[::-1]])
        sign = np.concatenate([np.ones(SAMPLES + 1), -np.ones(SAMPLES + 1)])
        n = travel.size
        return (np.broadcast_to(p, (n,) + p.shape).copy(), sign[:, None, None] * (mu * p)[None],
                np.broadcast_to(travel[:, None, None], (n,) + p.shape).copy())

    def restore(self, pressure: np.ndarray) -> Cycle:
        """The cycle of a mid-stroke pressure read back from a checkpoint (no solve: everything follows from p)."""
        return self._cycle(pressure, ContactResult(pressure, float("nan"), pressure > 0, 0, True,
                                                   "restored from the checkpoint"))

    def _cycle(self, p: np.ndarray, res: ContactResult) -> Cycle:
        r_m, r_s = self.rates(p)
        p_av = stroke_average(p, self.grid.dx, self.stroke)
        travel = 4.0 * self.stroke
        mu = self.friction_coefficient
        nan = float("nan")
        return Cycle(
            pressure=p, pressure_stationary=p_av, rate_moving=r_m, rate_stationary=r_s,
            slip_moving=np.where(p > 0, travel, 0.0), slip_stationary=travel * stroke_average((p > 0).astype(float), self.grid.dx, self.stroke),
            shear=mu * p if mu is not None else np.full(p.shape, nan),
            energy=mu * self.total_load * travel if mu is not None else nan,
            work=self.total_load * travel,
            force_amplitude=mu * self.total_load if mu is not None else nan,
            regime="gross_slip", stick_half_width_x=0.0, contact=res, iterations=res.iterations)

    @property
    def bounds(self) -> tuple[float, float]:
        """(work, energy) per cycle that no cycle may exceed: here they are reached exactly (N·mm)."""
        mu = self.friction_coefficient
        return self.total_load * 4.0 * self.stroke, (mu * self.total_load * 4.0 * self.stroke if mu is not None
                                                      else float("inf"))

    def expected_volumes(self, cycles: int, work: float) -> tuple[float, float]:
        # closed form, not the accumulated work: the paper's invariant exactly
        return (archard_volume(self.k_moving, self.total_load, cycles, self.stroke),
                archard_volume(self.k_stationary, self.total_load, cycles, self.stroke))

