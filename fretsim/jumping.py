"""Cycle jumping: the paper's Taylor jumps (Eqs. 19–21), implicit steps (backward Euler, BDF2) and their control.

The model is the paper's per-cycle update (Eqs. 15–17 with ΔN_L = 1): h_{N+1} = h_N + r(h_N), r the wear per
cycle of the pressure that the gap h gives.  Taking it a cycle at a time costs a contact solve per cycle.  The
schemes here take large steps instead:

* linear (the paper): h ← h + ΔN_L·r(h), explicit, stable below a limit (:mod:`fretsim.stability`);
* adaptive (the paper): batches of linear steps, then a Taylor jump (Eqs. 19–21);
* implicit: backward Euler (order 1) or variable-step BDF2 (order 2), each step one contact solve with the
  compliance C + s·W (W the gap's growth per cycle per unit pressure), stable for any step.

The per-cycle update is forward Euler with a step of one cycle, so it is not the ODE h' = r(h): its solution
differs by about ½(r(N) − r(0)), which matters in short runs (−1 % at 100 cycles).  Summing h_{N+1} − h_N =
r_N = ½(r_N + r_{N+1}) − ½(r_{N+1} − r_N) shows that φ = h + ½r(h) follows φ' = r(h) up to O(r''), so the
implicit schemes integrate φ; each step solves for h_{n+1} = base + (γΔN − ½)·r_{n+1}, i.e. with compliance
C + (γΔN − ½)·W — the per-cycle model is reproduced at the cost of a coefficient.  Σφ and Σh stay exactly
Archard's k·P·4δ·(N + ½) and k·P·4δ·N.
"""
from __future__ import annotations

import numpy as np

# --- adaptive cycle jumping (paper section 2.2.3, Eqs. 19–21) ---------------------------------------------------

Q_LINEAR = 5  # linear iterations per batch: 3 to stabilise, the last 2 give the derivatives
WORN_FRACTION = 1e-2  # elements worn less than this fraction of the body's maximum do not limit the jump


def taylor_jump(histories: list[tuple[np.ndarray, np.ndarray, np.ndarray]], linear: int, eta: float,
                max_jump: int) -> int:
    """ΔN = min over elements of η|h|/|ḣ| (Eq. 21), bounded by ΔN_max, for every body's (h_{N−2L}, h_{N−L}, h_N).

    Elements with no wear yet (h = 0) would force ΔN = 0, and those at the
    scar's edge, worn a tiny fraction of the maximum, would force tiny jumps
    whose error is negligible in absolute terms; both are left out of the
    minimum (below WORN_FRACTION of the body's maximum depth).
    """
    best = float(max_jump)
    for _, h1, h0 in histories:
        rate = (h0 - h1) / linear
        worn = (h0 > WORN_FRACTION * h0.max()) & (rate != 0) if h0.max() > 0 else np.zeros(h0.shape, bool)
        if worn.any():
            best = min(best, float((eta * np.abs(h0[worn]) / np.abs(rate[worn])).min()))
    return max(1, int(best))


def taylor_extrapolate(h2: np.ndarray, h1: np.ndarray, h0: np.ndarray, linear: int, jump: int) -> np.ndarray:
    """h_{N+ΔN} = h_N + ḣΔN + ḧΔN²/2 with backward differences (Eqs. 19–20).

    Each linear step adds exactly k·P·4δ·ΔN_L of volume, so Σḣ is that rate and
    Σḧ = 0: the extrapolation keeps Archard's volume to round-off.
    """
    rate = (h0 - h1) / linear
    curvature = (h0 - 2.0 * h1 + h2) / linear**2
    return h0 + rate * jump + 0.5 * curvature * jump**2


# --- implicit steps ------------------------------------------------------------------------------------------------

OMEGA_MAX = 2.0  # BDF2 step ratio: zero-stable below 1 + √2
THETA_LANDING = 0.5  # near a recorded state a step covers at most this share of the remaining cycles


def bdf2_coefficients(step: float, span: float) -> tuple[float, float]:
    """(b, γ) of variable-step BDF2: y_{n+1} = y_n + b(y_n − y_k) + γ·ΔN·f_{n+1}, ω = ΔN/(N_n − N_k).

    From the quadratic through (N_k, y_k), (N_n, y_n), (N_{n+1}, y_{n+1}) whose slope at N_{n+1} is f_{n+1}:
    b = ω²/(1 + 2ω), γ = (1 + ω)/(1 + 2ω); b·(N_n − N_k) + γ·ΔN = ΔN, so linear invariants (Archard's
    volume) are kept exactly.
    """
    w = step / span
    return w * w / (1 + 2 * w), (1 + w) / (1 + 2 * w)


def bdf2_local_error(times: tuple[float, float, float, float], values: tuple) -> np.ndarray:
    """Local error of the BDF2 step to t₃ from (t₀, t₁, t₂, t₃) with partner t₁ (t₀ < t₁ < t₂ < t₃); ``values``
    are the solution at those times, the last the step's own result.

    The step's defect is q'(t₃) − y'(t₃) = y'''/6·(t₃ − t₁)(t₃ − t₂) for the interpolating quadratic q; divided by
    ∂q'(t₃)/∂y₃ = 1/(t₃ − t₂) + 1/(t₃ − t₁) it is an error e = F·y'''/6 in y₃, F = (t₃−t₂)²(t₃−t₁)²/(2t₃−t₂−t₁)
    (2/9·ΔN³y''' at constant steps).  y'''/6 is the third divided difference D of the four values; computed
    with the step's own y₃ it is D + e/P, P = (t₃−t₀)(t₃−t₁)(t₃−t₂), so e = F·D/(1 + F/P) (Milne's device).
    """
    t0, t1, t2, t3 = times
    y0, y1, y2, y3 = values
    d01, d12, d23 = (y1 - y0) / (t1 - t0), (y2 - y1) / (t2 - t1), (y3 - y2) / (t3 - t2)
    d012, d123 = (d12 - d01) / (t2 - t0), (d23 - d12) / (t3 - t1)
    third = (d123 - d012) / (t3 - t0)
    f = (t3 - t2) ** 2 * (t3 - t1) ** 2 / (2 * t3 - t2 - t1)
    return third * f / (1.0 + f / ((t3 - t0) * (t3 - t1) * (t3 - t2)))


def next_step(step: float, error: float, tolerance: float, order: int) -> float:
    """Step-size controller: error ∝ ΔN^(order+1), so scale by (tol/err)^(1/(order+1)), within [0.2, 2]."""
    if error <= 0:
        return 2.0 * step
    return step * min(2.0, max(0.2, 0.9 * (tolerance / error) ** (1.0 / (order + 1))))
