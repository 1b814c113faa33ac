"""Initial separation ε between the undeformed bodies at the centre of the stroke (paper Eqs. 9–10)."""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.grid import Grid


def initial_separation(kind: str, grid: Grid, radius: float, length: Optional[float] = None) -> np.ndarray:
    """ε (mm) on the grid; +inf where the bodies cannot touch (beyond a cylinder's ends)."""
    X, Y = grid.mesh()
    if kind == "cylinder_on_flat":
        gap = X**2 / (2.0 * radius)  # Eq. 9
        if not grid.plane_strain and length is not None:
            gap = np.where(np.abs(Y) <= length / 2.0 + 1e-12 * length, gap, np.inf)
        return gap
    if kind == "ball_on_flat":
        return (X**2 + Y**2) / (2.0 * radius)  # Eq. 10
    raise ValueError(f"unknown geometry {kind!r}")
