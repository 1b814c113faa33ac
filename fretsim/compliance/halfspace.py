"""The elastic half-space: Love's rectangle (3D, paper Eq. 6) and the plane-strain strip (2D).

The displacement under uniform pressure on one element depends only on the
offset between elements, so the operator is a convolution.  Both bodies are
lumped into the contact modulus E* (1/E* = Σ (1-ν²)/E), which is exactly
C = C¹ + C² of the paper's Eq. (5) for two half-spaces.
"""
from __future__ import annotations

import numpy as np

from fretsim.compliance.operator import Convolution
from fretsim.grid import Grid


def love_rectangle(x: np.ndarray, y: np.ndarray, a: float, b: float, e_star: float) -> np.ndarray:
    """Displacement at (x, y) due to unit pressure on the rectangle |x|≤a, |y|≤b (Love 1929; paper Eq. 6).

    Written with asinh instead of the paper's logarithms: the ln|X| parts of
    the four corner terms cancel exactly, and asinh keeps full precision far
    from the loaded element where the logarithms' arguments cancel.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)

    def corner(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = np.where(X == 0.0, 0.0, X * np.arcsinh(Y / np.abs(X)))
            t2 = np.where(Y == 0.0, 0.0, Y * np.arcsinh(X / np.abs(Y)))
        return t1 + t2

    s = corner(x + a, y + b) - corner(x + a, y - b) - corner(x - a, y + b) + corner(x - a, y - b)
    return s / (np.pi * e_star)


def strip_plane_strain(x: np.ndarray, a: float, e_star: float) -> np.ndarray:
    """Displacement at x due to unit pressure on the strip |x|≤a in plane strain (Johnson eq. 2.25b).

    Defined up to an additive constant, which the rigid-body approach absorbs;
    we take the form -(2/πE*)[(x+a)ln|x+a| - (x-a)ln|x-a|] with lengths in mm.
    """
    x = np.asarray(x, dtype=float)

    def xlogx(t: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(t == 0.0, 0.0, t * np.log(np.abs(t)))

    return -(2.0 / (np.pi * e_star)) * (xlogx(x + a) - xlogx(x - a))


def influence_kernel(grid: Grid, e_star: float) -> np.ndarray:
    """Kernel K[j, i] for offsets (j-(My-1))·dy, (i-(Mx-1))·dx, shape (2My-1, 2Mx-1)."""
    ny, nx = grid.shape
    ox = (np.arange(2 * nx - 1) - (nx - 1)) * grid.dx
    if grid.plane_strain:
        return strip_plane_strain(ox, grid.dx / 2.0, e_star)[None, :]
    oy = (np.arange(2 * ny - 1) - (ny - 1)) * grid.dy
    X, Y = np.meshgrid(ox, oy)
    return love_rectangle(X, Y, grid.dx / 2.0, grid.dy / 2.0, e_star)


class HalfSpace(Convolution):
    """Both bodies as elastic half-spaces (plane strain in 2D): u = C p with C = C¹ + C² (paper Eq. 5).

    Parameters
    ----------
    grid : the surface grid
    e_star : contact modulus E* (MPa), 1/E* = Σ (1 − ν²)/E
    """

    def __init__(self, grid: Grid, e_star: float, _kernel: np.ndarray | None = None):
        if not (e_star > 0 and np.isfinite(e_star)):
            raise ValueError(f"contact modulus must be positive and finite, got {e_star}")
        self.e_star = float(e_star)
        super().__init__(grid, influence_kernel(grid, e_star) if _kernel is None else _kernel)

    def _like(self, grid: Grid, kernel: np.ndarray) -> "HalfSpace":
        return HalfSpace(grid, self.e_star, kernel)

    def symbol_x(self, theta: np.ndarray, lags: int = 4096) -> np.ndarray:
        """Symbol f(θ) = Σ_k K(k·dx) e^{ikθ} along x on the unbounded lattice, for modes constant or
        alternating in y; the smaller of the two at each θ (the fast path of the stability limit).

        The 2D (log) kernel has an additive constant and the sums converge slowly, so f is computed from the
        second difference Δ²K (∝ 1/k², absolutely convergent, blind to constants):
        f(θ) = Σ Δ²K(k) cos kθ / (2 cos θ − 2).
        """
        grid = self.grid
        k = np.arange(-lags - 1, lags + 2)
        if grid.plane_strain:
            kernels = [strip_plane_strain(k * grid.dx, grid.dx / 2, self.e_star)]
        else:
            ny = grid.shape[0]
            half = (ny - 1) // 2
            rows = np.arange(-half, half + 1)
            X, Y = np.meshgrid(k * grid.dx, rows * grid.dy)
            K = love_rectangle(X, Y, grid.dx / 2, grid.dy / 2, self.e_star)
            kernels = [K.sum(axis=0), (K * ((-1.0) ** np.abs(rows))[:, None]).sum(axis=0)] if ny > 1 else [K[0]]
        out = np.full(np.shape(theta), np.inf)
        for ker in kernels:
            d2 = ker[2:] - 2 * ker[1:-1] + ker[:-2]
            s = np.cos(np.multiply.outer(theta, k[1:-1])) @ d2
            out = np.minimum(out, s / (2 * np.cos(theta) - 2))
        return out
