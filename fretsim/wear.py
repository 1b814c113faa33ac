"""Modified Archard wear of both bodies (paper Eqs. 14–17) and the stroke-averaged pressure (section 2.2.1).

The moving body (cylinder, ball) carries the same pressure field through the
cycle.  A point of the stationary flat sees that field slide past it by
u ∈ [−δ, δ], so it wears with the average p_av(x) = (1/2δ)∫ p(x − u) du.  For
element-wise constant p this is an exact box average: each element
contributes its pressure times the length of its overlap with the window.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.ndimage import convolve1d


@lru_cache(maxsize=64)
def stroke_weights(dx: float, stroke: float) -> np.ndarray:
    """Weights w_k (k = −K..K) with p_av,i = Σ w_k p_{i−k}; they sum to 1.  Cached: treat as read-only."""
    if not (dx > 0 and stroke > 0):
        raise ValueError(f"element size and stroke must be positive, got {dx}, {stroke}")
    reach = int(np.ceil(stroke / dx + 0.5))
    centres = np.arange(-reach, reach + 1) * dx
    overlap = np.clip(np.minimum(centres + dx / 2, stroke) - np.maximum(centres - dx / 2, -stroke), 0.0, None)
    weights = overlap / (2.0 * stroke)
    weights.flags.writeable = False
    return weights


def stroke_average(pressure: np.ndarray, dx: float, stroke: float) -> np.ndarray:
    """p_av of the stationary body along x (axis 1); exact for element-wise constant pressure."""
    return convolve1d(pressure, stroke_weights(dx, stroke), axis=1, mode="constant", cval=0.0)


def archard_depth(wear_coefficient: float, pressure: np.ndarray, cycles: float, stroke: float) -> np.ndarray:
    """Wear depth dh = k·ΔN·p·4δ (Eqs. 15–16): sliding distance 4δ per cycle, k in 1/MPa, p in MPa → mm."""
    return wear_coefficient * cycles * 4.0 * stroke * pressure


def archard_volume(wear_coefficient: float, load: float, cycles: float, stroke: float) -> float:
    """Archard's law V = k·P·s with s = 4δN (Eq. 13): the invariant every run is checked against."""
    return wear_coefficient * load * 4.0 * stroke * cycles
