"""Modified Archard wear of both bodies (paper Eqs. 14–17) and the stroke-averaged pressure (section 2.2.1).

The moving body (cylinder, ball) carries the same pressure field through the
cycle.  A point of the stationary flat sees that field slide past it by
u ∈ [−δ, δ], so it wears with the average p_av(x) = (1/2δ)∫ p(x − u) du.  For
element-wise constant p this is an exact box average: each element
contributes its pressure times the length of its overlap with the window.

How the flat's wear enters the gap (``gap_model``):

* ``mid_stroke`` (the paper, Eq. 18): the contact is solved at mid-stroke with
  the gap ε + h_m + h_s.  Per Fourier mode of the wear the update has the
  growth factor 1 − ΔN·4δ(k_m + k_s b)/c, with b the symbol of the stroke
  average (b ≥ −0.22): when the moving body wears less than ~0.22 of the flat
  (k_m < −k_s·min b) modes shorter than the stroke grow — in the model itself,
  even cycle by cycle, not only in a solver — and the pressure breaks into
  spikes one stroke-average lobe apart.
* ``stroke_average``: the moving body sees the flat's wear averaged over the
  stroke, gap ε + h_m + B h_s.  To first order in the gap's variation over a
  stroke it is the same average pressure, and its modes decay for any
  coefficients (factor 1 − ΔN·4δ(k_m + k_s b²)/c).  It differs from the paper
  only for wear features shorter than the stroke.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.ndimage import convolve1d

from fretsim.compliance import Convolution
from fretsim.grid import Grid

GAP_MODELS = ("mid_stroke", "stroke_average")


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


def stroke_reach(dx: float, stroke: float) -> int:
    """Elements the stroke average reaches on each side."""
    return (stroke_weights(dx, stroke).size - 1) // 2


def stroke_average(pressure: np.ndarray, dx: float, stroke: float) -> np.ndarray:
    """p_av of the stationary body along x (axis 1); exact for element-wise constant pressure."""
    return convolve1d(pressure, stroke_weights(dx, stroke), axis=1, mode="constant", cval=0.0)


def stroke_symbol(dx: float, stroke: float, theta: np.ndarray) -> np.ndarray:
    """b(θ) = Σ w_k cos kθ: how the stroke average scales a wear mode of phase θ per element."""
    w = stroke_weights(dx, stroke)
    reach = (w.size - 1) // 2
    return np.cos(np.multiply.outer(theta, np.arange(-reach, reach + 1))) @ w


def archard_depth(wear_coefficient: float, pressure: np.ndarray, cycles: float, stroke: float) -> np.ndarray:
    """Wear depth dh = k·ΔN·p·4δ (Eqs. 15–16): sliding distance 4δ per cycle, k in 1/MPa, p in MPa → mm."""
    return wear_coefficient * cycles * 4.0 * stroke * pressure


def archard_volume(wear_coefficient: float, load: float, cycles: float, stroke: float) -> float:
    """Archard's law V = k·P·s with s = 4δN (Eq. 13): the invariant every run is checked against."""
    return wear_coefficient * load * 4.0 * stroke * cycles


def wear_rates(pressure: np.ndarray, dx: float, stroke: float, k_moving: float, k_stationary: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """Wear per cycle of the moving body (its own pressure) and of the flat (the stroke average), Eqs. 15–16."""
    return (archard_depth(k_moving, pressure, 1.0, stroke),
            archard_depth(k_stationary, stroke_average(pressure, dx, stroke), 1.0, stroke))


def gap_wear(h_moving: np.ndarray, h_stationary: np.ndarray, dx: float, stroke: float, gap_model: str) -> np.ndarray:
    """The wear the contact solve sees: h_m + h_s (mid_stroke, Eq. 18) or h_m + B h_s (stroke_average)."""
    if gap_model == "mid_stroke":
        return h_moving + h_stationary
    return h_moving + stroke_average(h_stationary, dx, stroke)


def wear_operator(grid: Grid, stroke: float, k_moving: float, k_stationary: float, gap_model: str) -> Convolution:
    """W: the growth of the gap per cycle per unit pressure, 4δ(k_m I + k_s B) or 4δ(k_m I + k_s B²).

    An implicit wear step of ΔN cycles solves the contact with C + ΔN·W; the explicit update's stability is
    set by the spectrum of the pencil (W, C).
    """
    ny, nx = grid.shape
    w = stroke_weights(grid.dx, stroke)
    if gap_model == "stroke_average":
        w = np.convolve(w, w)
    elif gap_model != "mid_stroke":
        raise ValueError(f"unknown gap model {gap_model!r}; expected one of {', '.join(GAP_MODELS)}")
    reach = (w.size - 1) // 2
    kernel = np.zeros((2 * ny - 1, 2 * nx - 1))
    row = kernel[ny - 1]
    lo, hi = max(0, nx - 1 - reach), min(2 * nx - 1, nx + reach)
    row[lo:hi] += k_stationary * w[lo - (nx - 1 - reach):hi - (nx - 1 - reach)]
    row[nx - 1] += k_moving
    return Convolution(grid, 4.0 * stroke * kernel)
