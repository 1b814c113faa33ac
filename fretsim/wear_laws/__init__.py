"""The wear-law family: how much each point of a body wears for what it carries and how far it slides.

A member answers, for the fretting-cycle members (:mod:`fretsim.cycle`), what a body's coefficient multiplies
at each point in one increment of the cycle (its *amount*: Archard's p·|ds|, Fouvry's dissipated energy
|q|·|ds|, ...), which material key holds that coefficient, what the amount is where every point slides
(gross slip, |q| = μp: a factor times p·|ds|, which the paper's uniform cycle and the stability limit use), and
the invariant it conserves (each body's worn volume is its coefficient times the amount summed over the cycles
and the contact area; the loop checks it at every step).

Every member has the interface of :class:`WearLaw`; :data:`WEAR_LAWS` maps the names a case may give in
``model.wear_law`` to them, the case reader validates the name against it and the planner asks it.  A new law
is one module here and one line in the registry; the tests loop over the registry.
"""
from __future__ import annotations

from typing import Optional, Protocol

import numpy as np


class WearLaw(Protocol):
    name: str
    coefficient_key: str  # the materials.<body> key holding its coefficient
    needs_friction: bool  # its amount needs μ: the case reader asks for loading.friction_coefficient
    invariant: str  # each body's worn volume is its coefficient times this, for messages
    symbol: str  # the coefficient's symbol, for messages and figures
    formula: str  # the law itself, for messages

    def amount(self, pressure: np.ndarray, shear: np.ndarray, slip: np.ndarray) -> np.ndarray:
        """What the coefficient multiplies at each point over an increment (N/mm: MPa × mm): from the pressure p,
        the shear traction q at the increment's end and the slip |ds| over it."""

    def gross_slip_factor(self, friction_coefficient: Optional[float]) -> float:
        """The amount where every point slides (|q| = μp), as a factor of p·|ds| — and its physical bound: since
        |q| ≤ μp and no point slides further than the rig travels, a cycle's amount summed over the contact never
        exceeds this factor times P·4δ (the loop checks every cycle against it)."""


from fretsim.wear_laws.archard import Archard  # noqa: E402 - the members need the interface above
from fretsim.wear_laws.energy import Energy  # noqa: E402

WEAR_LAWS: dict[str, WearLaw] = {"archard": Archard(), "energy": Energy()}


def coefficients(law: WearLaw, moving, stationary) -> tuple[float, float]:
    """(moving, stationary) coefficients of the law's amount, read from the two bodies' materials."""
    return getattr(moving, law.coefficient_key), getattr(stationary, law.coefficient_key)


def gross_slip_coefficients(law: WearLaw, moving, stationary, friction_coefficient: Optional[float]
                            ) -> tuple[float, float]:
    """(moving, stationary) coefficients of p·|ds| where every point slides: what the paper's uniform cycle, the
    grid's sizing and the explicit stability limit take as Archard's k."""
    k_m, k_s = coefficients(law, moving, stationary)
    factor = law.gross_slip_factor(friction_coefficient)
    return k_m * factor, k_s * factor
