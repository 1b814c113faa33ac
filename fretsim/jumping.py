"""Linear cycle jumping: the step schedule, its stability limit, and detection of the instability.

Explicit (forward-Euler) wear updates h ← h + ΔN·4δ·(k_m p + k_s B p), with p
the contact pressure for the current gap.  Linearised about a settled
contact, a wear perturbation changes the pressure by δp = −C⁻¹δh, so each
Fourier mode ξ of the wear is multiplied per step by

    g(ξ) = 1 − ΔN · 4δ · (k_m + k_s b(ξ)) / c(ξ)

with c the symbol of the compliance (displacement per unit pressure) and b
that of the stroke average.  c is smallest for the shortest wavelength the
grid holds (c ∝ element size / E*), so the limit ΔN < 2c/(4δ(k_m + k_s b))
shrinks with the element size, the wear coefficients and the stroke, and grows
with the compliance 1/E*.  Past it the pressure checkerboards; below half of
it every mode decays without changing sign.
"""
from __future__ import annotations

import numpy as np

from fretsim.compliance import love_rectangle, strip_plane_strain
from fretsim.grid import Grid
from fretsim.wear import stroke_weights

SAFETY = 0.5  # default jump as a fraction of the limit: monotone decay of every mode


def compliance_symbol_x(grid: Grid, e_star: float, theta: np.ndarray, lags: int = 4096) -> np.ndarray:
    """Symbol f(θ) = Σ_k K(k·dx) e^{ikθ} of the compliance along x, for modes constant or alternating in y.

    The 2D (log) kernel has an additive constant and the sums converge slowly,
    so f is computed from the second difference Δ²K (∝ 1/k², absolutely
    convergent, blind to constants): f(θ) = Σ Δ²K(k) cos kθ / (2 cos θ − 2).
    Returns the smaller of the two y-modes at each θ (shape of ``theta``).
    """
    k = np.arange(-lags - 1, lags + 2)
    if grid.plane_strain:
        kernels = [strip_plane_strain(k * grid.dx, grid.dx / 2, e_star)]
    else:
        ny = grid.shape[0]
        half = (ny - 1) // 2
        rows = np.arange(-half, half + 1)
        X, Y = np.meshgrid(k * grid.dx, rows * grid.dy)
        K = love_rectangle(X, Y, grid.dx / 2, grid.dy / 2, e_star)
        kernels = [K.sum(axis=0), (K * ((-1.0) ** np.abs(rows))[:, None]).sum(axis=0)] if ny > 1 else [K[0]]
    out = np.full(np.shape(theta), np.inf)
    for ker in kernels:
        d2 = ker[2:] - 2 * ker[1:-1] + ker[:-2]
        kk = k[1:-1]
        s = np.cos(np.multiply.outer(theta, kk)) @ d2
        out = np.minimum(out, s / (2 * np.cos(theta) - 2))
    return out


def explicit_stability_limit(grid: Grid, e_star: float, stroke: float, k_moving: float, k_stationary: float) -> float:
    """Largest stable linear jump ΔN_L (cycles) of the explicit update: min over modes of 2f/(4δ(k_m + k_s b)).

    Checked against the smallest eigenvalue of the dense operator (tests).
    """
    theta = np.linspace(0.25 * np.pi, np.pi, 181)
    f = compliance_symbol_x(grid, e_star, theta)
    w = stroke_weights(grid.dx, stroke)
    reach = (w.size - 1) // 2
    b = np.cos(np.multiply.outer(theta, np.arange(-reach, reach + 1))) @ w
    rate = 4.0 * stroke * (k_moving + k_stationary * b)
    ok = (f > 0) & (rate > 0)
    if not ok.any():
        return float("inf")
    return float((2.0 * f[ok] / rate[ok]).min())


def default_linear_jump(limit: float, cycles: int) -> int:
    """The default ΔN_L: half the stability limit, at least 1 and at most the run."""
    if not np.isfinite(limit):
        return max(cycles, 1)
    return int(max(1, min(cycles if cycles > 0 else 1, np.floor(SAFETY * limit))))


def linear_schedule(cycles: int, jump: int, stops: tuple[int, ...] = ()) -> list[int]:
    """Step sizes of at most ``jump`` cycles that land exactly on every stop and on ``cycles``."""
    targets = sorted({s for s in stops if 0 < s < cycles} | {cycles}) if cycles > 0 else []
    steps, n = [], 0
    for target in targets:
        while n < target:
            d = min(jump, target - n)
            steps.append(d)
            n += d
    return steps


CHECKERBOARD_LIMIT = 0.01  # odd-even amplitude relative to the mean interior pressure


def checkerboard_amplitude(pressure: np.ndarray, edge: int = 3) -> float:
    """Amplitude of the odd-even (checkerboard) component of the pressure along x, relative to its mean.

    For p_i = P_i + A(−1)^i with P smooth, r_i = (−1)^i (p_{i−1} − 2p_i + p_{i+1})/4 ≈ −A at every element,
    while the smooth part and isolated features such as edge peaks give r of no consistent sign, which
    averages out.  Elements within ``edge`` of a contact edge are left out (the pressure is not smooth there).
    Returns the worst row.
    """
    worst = 0.0
    for row in np.atleast_2d(pressure):
        on = np.flatnonzero(row > 0)
        if on.size < 2 * edge + 6:
            continue
        seg = row[on[0] + edge:on[-1] + 1 - edge]
        d2 = seg[:-2] - 2 * seg[1:-1] + seg[2:]
        r = d2 * (1.0 - 2.0 * (np.arange(d2.size) % 2)) / 4.0
        mean = float(seg.mean())
        if mean > 0:
            worst = max(worst, abs(float(r.mean())) / mean)
    return worst


def is_checkerboard(pressure: np.ndarray) -> bool:
    """True when the pressure oscillates from element to element along x (an unstable explicit update)."""
    return checkerboard_amplitude(pressure) > CHECKERBOARD_LIMIT
