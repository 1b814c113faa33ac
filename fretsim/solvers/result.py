"""The one result record every contact solver returns."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ContactResult:
    pressure: np.ndarray  # element pressures (MPa), shape (My, Mx)
    approach: float  # rigid-body approach α (mm); in 2D relative to the kernel's constant
    contact: np.ndarray  # boolean mask of elements carrying pressure
    iterations: int  # solver iterations (CG steps, simplex pivots, active-set sweeps)
    success: bool
    message: str
    residual: float = float("nan")  # complementarity violation relative to the displacement spread

    def separation(self, compliance, gap: np.ndarray) -> np.ndarray:
        """Y = gap + C p − α (mm)."""
        return gap + compliance(self.pressure) - self.approach


def complementarity_residual(u: np.ndarray, gap: np.ndarray, p: np.ndarray, approach: float) -> float:
    """max(|Y| where p > 0, −Y where p = 0) over the spread of u: 0 for an exact solution."""
    finite = np.isfinite(gap)
    y = np.where(finite, gap + u - approach, np.inf)
    on = p > 0
    worst = max(float(np.abs(y[on]).max()) if on.any() else 0.0,
                float(np.clip(-y[~on & finite], 0, None).max()) if (~on & finite).any() else 0.0)
    spread = float(u.max() - u.min()) or 1.0
    return worst / spread
