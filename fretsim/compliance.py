"""Influence operators: the normal surface displacement of both bodies due to element pressures.

The displacement of an elastic half-space under uniform pressure on one
element depends only on the offset between elements, so the operator is a
(non-periodic) convolution.  It is applied by zero-padded FFT in O(n log n);
dense matrices are formed only on request, for the small-grid solvers.

Both bodies are lumped into the contact modulus E* (1/E* = Σ (1-ν²)/E), which
is exactly C = C¹ + C² of the paper's Eq. (5) for two half-spaces.
"""
from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from fretsim.grid import Grid

DENSE_LIMIT = 8000  # elements; a dense n×n matrix beyond this costs > 0.5 GB


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


class Compliance:
    """u = C p on a grid, applied by zero-padded FFT; ``dense()`` for small grids.

    Parameters
    ----------
    grid : the surface grid
    e_star : contact modulus (MPa)
    """

    def __init__(self, grid: Grid, e_star: float):
        if not (e_star > 0 and np.isfinite(e_star)):
            raise ValueError(f"contact modulus must be positive and finite, got {e_star}")
        self.grid = grid
        self.e_star = float(e_star)
        self.kernel = influence_kernel(grid, e_star)
        ny, nx = grid.shape
        # Linear (non-periodic) convolution needs at least 2M-1 points per axis.
        self._fft_shape = (1 if ny == 1 else sfft.next_fast_len(2 * ny - 1, real=True),
                           sfft.next_fast_len(2 * nx - 1, real=True))
        wrapped = np.zeros(self._fft_shape)
        ly, lx = self._fft_shape
        iy = (np.arange(2 * ny - 1) - (ny - 1)) % ly
        ix = (np.arange(2 * nx - 1) - (nx - 1)) % lx
        wrapped[np.ix_(iy, ix)] = self.kernel
        self._kernel_hat = sfft.rfft2(wrapped)
        self.n_applications = 0

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    def __call__(self, p: np.ndarray) -> np.ndarray:
        """Displacement (mm) of both surfaces together for element pressures p (MPa), shape (My, Mx)."""
        self.n_applications += 1
        ny, nx = self.grid.shape
        ph = sfft.rfft2(p, s=self._fft_shape, workers=1)
        ph *= self._kernel_hat
        return sfft.irfft2(ph, s=self._fft_shape, workers=1)[:ny, :nx]

    def dense(self) -> np.ndarray:
        """The n × n matrix C (displacement per unit pressure), row-major element order."""
        ny, nx = self.grid.shape
        n = nx * ny
        if n > DENSE_LIMIT:
            raise ValueError(f"a dense compliance matrix for {n} elements would take {n * n * 8 / 1e9:.1f} GB; "
                             f"use an FFT-based solver (limit {DENSE_LIMIT} elements)")
        # C[(jy,ix),(ky,kx)] = K[jy-ky+ny-1, ix-kx+nx-1]: windows of the flipped kernel, one strided copy
        windows = np.lib.stride_tricks.sliding_window_view(self.kernel[::-1, ::-1], (ny, nx))
        return np.ascontiguousarray(windows[::-1, ::-1]).reshape(n, n)
