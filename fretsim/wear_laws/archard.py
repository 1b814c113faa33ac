"""``archard``: the worn depth is k·p·|ds| (Archard; the paper's Eqs. 13–16, k including the hardness)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np


@dataclass(frozen=True)
class Archard:
    name: str = "archard"
    coefficient_key: str = "wear_coefficient"
    needs_friction: bool = False
    invariant: str = "k·Σp·|ds|·A"
    formula: str = "dh = k·p·|ds|"
    symbol: str = "k"

    def amount(self, pressure: np.ndarray, shear: np.ndarray, slip: np.ndarray) -> np.ndarray:
        return pressure * np.abs(slip)

    def gross_slip_factor(self, friction_coefficient: Optional[float]) -> float:
        return 1.0
