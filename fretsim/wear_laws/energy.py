"""``energy``: the worn depth is α·|q|·|ds|, the friction energy dissipated there (Fouvry's energy approach).

Where a point slides |q| = μp, so in gross slip the law is Archard's with k = α·μ; where it sticks it neither
slides nor wears.  α is ``materials.<body>.energy_wear_coefficient`` (mm³/J, internally mm³/(N·mm) = 1/MPa).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np


@dataclass(frozen=True)
class Energy:
    name: str = "energy"
    coefficient_key: str = "energy_wear_coefficient"
    needs_friction: bool = True
    invariant: str = "α·ΣW"
    formula: str = "dh = α·|q|·|ds|, |q| = μp"
    symbol: str = "α"

    def amount(self, pressure: np.ndarray, shear: np.ndarray, slip: np.ndarray) -> np.ndarray:
        return np.abs(shear) * np.abs(slip)

    def gross_slip_factor(self, friction_coefficient: Optional[float]) -> float:
        return friction_coefficient
