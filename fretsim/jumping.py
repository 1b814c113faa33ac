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
from fretsim.wear import stroke_average, stroke_weights

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


CHECKERBOARD_LIMIT = 0.01  # odd-even amplitude relative to the mean interior pressure


def checkerboard_amplitude(pressure: np.ndarray, edge: int = 3) -> float:
    """Amplitude of the odd-even (checkerboard) component of the pressure along x, relative to its mean.

    For p_i = P_i + A(−1)^i with P smooth, r_i = (−1)^i (p_{i−1} − 2p_i + p_{i+1})/4 ≈ −A at every element,
    while the smooth part and isolated features such as edge peaks give r of no consistent sign, which
    averages out.  The contact is taken where p exceeds 5 % of the row's peak (refined pressures have low
    tails), and elements within ``edge`` of its edges are left out (the pressure is not smooth there).
    Returns the worst row with at least 6 interior elements.
    """
    p = np.atleast_2d(pressure)
    peak = p.max(axis=1, keepdims=True)
    on = p > 0.05 * peak
    # interior: the span from the first to the last element in contact, less `edge` (and the stencil) at each
    # end; a span, not the mask, because a strong checkerboard has near-zero elements inside the contact
    idx = np.arange(p.shape[1])
    first = np.argmax(on, axis=1)[:, None]
    last = (p.shape[1] - 1 - np.argmax(on[:, ::-1], axis=1))[:, None]
    interior = (idx >= first + edge + 1) & (idx <= last - edge - 1) & on.any(axis=1, keepdims=True)
    d2 = np.zeros_like(p)
    d2[:, 1:-1] = p[:, :-2] - 2 * p[:, 1:-1] + p[:, 2:]
    r = d2 * (1.0 - 2.0 * (np.arange(p.shape[1]) % 2)) / 4.0
    count = interior.sum(axis=1)
    rows = count >= 6
    if not rows.any():
        return 0.0
    mean_r = (r * interior).sum(axis=1)[rows] / count[rows]
    mean_p = (p * interior).sum(axis=1)[rows] / count[rows]
    return float((np.abs(mean_r) / mean_p).max())


def is_checkerboard(pressure: np.ndarray) -> bool:
    """True when the pressure oscillates from element to element along x (an unstable explicit update)."""
    return checkerboard_amplitude(pressure) > CHECKERBOARD_LIMIT


def is_checkerboard_amplitude(amplitude: float) -> bool:
    return amplitude > CHECKERBOARD_LIMIT


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


# --- implicit (backward-Euler) wear step ------------------------------------------------------------------------

class ImplicitCompliance:
    """C' = C + ΔN·4δ·(k_m I + k_s B): a backward-Euler wear step of ΔN cycles is one contact solve with C'.

    With h_{n+1} = h_n + ΔN·4δ·(k_m p + k_s B p) and the contact condition for
    the gap ε + h_{n+1}, the unknown pressure satisfies gap ε + h_n with the
    compliance C' (B: the stroke average, symmetric).  C' is symmetric; it is
    positive definite for every ΔN when k_m + k_s·min b ≥ 0 (b the symbol of B,
    min b ≈ −0.22), in particular whenever k_s = 0; otherwise up to
    :func:`implicit_jump_cap`.
    """

    def __init__(self, base, cycles: float, stroke: float, k_moving: float, k_stationary: float):
        self.base = base
        self.grid = base.grid
        self.scale = cycles * 4.0 * stroke
        self.stroke = stroke
        self.k_moving = k_moving
        self.k_stationary = k_stationary

    @property
    def shape(self):
        return self.base.shape

    def __call__(self, p: np.ndarray) -> np.ndarray:
        out = self.base(p) + (self.scale * self.k_moving) * p
        if self.k_stationary:
            out += (self.scale * self.k_stationary) * stroke_average(p, self.grid.dx, self.stroke)
        return out

    def dense(self) -> np.ndarray:
        ny, nx = self.grid.shape
        w = stroke_weights(self.grid.dx, self.stroke)
        reach = (w.size - 1) // 2
        bx = np.zeros((nx, nx))
        for k, wk in zip(range(-reach, reach + 1), w):
            bx += wk * np.eye(nx, k=k)
        wear = self.k_moving * np.eye(nx * ny) + self.k_stationary * np.kron(np.eye(ny), bx)
        return self.base.dense() + self.scale * wear


def implicit_jump_cap(grid: Grid, e_star: float, stroke: float, k_moving: float, k_stationary: float) -> float:
    """Largest ΔN for which C' stays positive definite (inf when k_m + k_s·b ≥ 0 for every mode); half-margin."""
    theta = np.linspace(0.01 * np.pi, np.pi, 400)
    w = stroke_weights(grid.dx, stroke)
    reach = (w.size - 1) // 2
    b = np.cos(np.multiply.outer(theta, np.arange(-reach, reach + 1))) @ w
    rate = k_moving + k_stationary * b
    negative = rate < 0
    if not negative.any():
        return float("inf")
    f = compliance_symbol_x(grid, e_star, theta[negative])
    return float(0.5 * (f / (4.0 * stroke * -rate[negative])).min())


def next_implicit_jump(jump: float, error: float, tolerance: float) -> float:
    """Step-size controller for a first-order method: error ∝ ΔN², so scale by √(tol/err), within [0.2, 2]."""
    if error <= 0:
        return 2.0 * jump
    return jump * min(2.0, max(0.2, 0.9 * np.sqrt(tolerance / error)))
