"""The one small interface every influence operator shares, and its two building blocks.

An operator maps element pressures p (MPa, shape (My, Mx)) to normal surface
displacements u (mm) on its grid:

    op(p) -> u            apply
    op.dense()            the n × n matrix (small grids only)
    op.restrict(rows, cols)   the same physics on a window of the grid (a sub-block of the matrix)
    op.grid               the grid it lives on
    op.convolution        its translation-invariant part (a :class:`Convolution`) or None

:class:`Convolution` is the translation-invariant case (half-space kernels, the stroke average, the wear
term of an implicit step): applied by zero-padded FFT.  Convolutions on one grid add by adding kernels and
Fourier symbols, so a sum of them still costs one FFT pair.  :class:`Matrix` holds any other operator as a
dense matrix, and :class:`Sum` adds operators of either kind.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.compliance import fft
from fretsim.grid import Grid

FEW_COLUMN, FEW_SCAN, FEW_TRANSFORM = 2000, 4, 10  # Convolution.of_few's cost model
DENSE_LIMIT = 8000  # elements; a dense n×n matrix beyond this costs > 0.5 GB


def window_grid(grid: Grid, rows: slice, cols: slice) -> Grid:
    """The elements of ``grid`` in rows × cols, as a grid of their own (not centred in general)."""
    return Grid(x=grid.x[cols], y=grid.y[rows], dx=grid.dx, dy=grid.dy, plane_strain=grid.plane_strain)


def _check_dense(n: int) -> None:
    if n > DENSE_LIMIT:
        raise ValueError(f"a dense compliance matrix for {n} elements would take {n * n * 8 / 1e9:.1f} GB; "
                         f"use an FFT-based solver (limit {DENSE_LIMIT} elements)")


class Convolution:
    """u_j = Σ_k K[j − k] p_k on a grid: a (non-periodic) convolution, applied by zero-padded FFT.

    ``kernel`` has shape (2My − 1, 2Mx − 1): the displacement at offset (j − k) for unit pressure on one
    element, centred at [My − 1, Mx − 1].
    """

    def __init__(self, grid: Grid, kernel: np.ndarray, _hat=None, _parts=None):
        ny, nx = grid.shape
        if kernel.shape != (2 * ny - 1, 2 * nx - 1):
            raise ValueError(f"kernel shape {kernel.shape} does not fit the grid {grid.shape}")
        self.grid = grid
        self.kernel = kernel
        # linear (non-periodic) convolution needs at least 2M − 1 points per axis
        self.fft_shape = (1 if ny == 1 else fft.next_fast_len(2 * ny - 1, real=False),
                          fft.next_fast_len(2 * nx - 1, real=True))
        self._hat = _hat  # transformed at first use: planning (`fretsim check`) builds operators it never applies
        self.n_applications = 0
        self._parts = _parts or ((1.0, self),)  # a sum remembers its terms, whose windows are cached
        self._windows: dict = {}

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    @property
    def convolution(self) -> "Convolution":
        return self

    @property
    def hat(self) -> np.ndarray:
        """The kernel's Fourier symbol on the padded grid."""
        if self._hat is None:
            self._hat = self._transform(self.kernel)
        elif callable(self._hat):  # a sum or a scaling: of its terms' symbols, as if made at once
            self._hat = self._hat()
        return self._hat

    def _transform(self, kernel: np.ndarray) -> np.ndarray:
        ny, nx = self.grid.shape
        ly, lx = self.fft_shape
        wrapped = np.zeros(self.fft_shape)
        iy = (np.arange(2 * ny - 1) - (ny - 1)) % ly
        ix = (np.arange(2 * nx - 1) - (nx - 1)) % lx
        wrapped[np.ix_(iy, ix)] = kernel
        hat = fft.fft(fft.rfft(wrapped, lx, axis=1), ly, axis=0) if ly > 1 else fft.rfft(wrapped, lx, axis=1)
        # every kernel here is even in x and y, so its symbol is real: half the work in each product
        if np.abs(hat.imag).max() <= 1e-12 * np.abs(hat.real).max():
            hat = np.ascontiguousarray(hat.real)
        return hat

    def forward(self, p: np.ndarray) -> np.ndarray:
        """p on the padded grid in Fourier space (x first on the My rows, whose padding is zero)."""
        return fft.forward(p, self.fft_shape)

    def backward(self, ph: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`forward`, cropped to the grid."""
        return fft.backward(ph, self.fft_shape, self.grid.shape)

    def __call__(self, p: np.ndarray) -> np.ndarray:
        self.n_applications += 1
        ph = self.forward(p)
        ph *= self.hat
        return self.backward(ph)

    def single(self):
        """This operator in single precision (float32 transforms and symbol, about seven digits; returns float32):
        for a solver's search directions, whose images need no more where its displacement is recomputed in
        double before the solution is judged.  A 3D window's transforms in double cost 4-6 times single's
        (their y pass strided over complex128: memory, not arithmetic)."""
        hat = self.hat
        hat32 = hat.astype(np.complex64 if np.iscomplexobj(hat) else np.float32)

        def apply(p: np.ndarray) -> np.ndarray:
            ph = self.forward(p.astype(np.float32))
            ph *= hat32
            return self.backward(ph)
        return apply

    def of_few(self, p: np.ndarray, budget: float = 1.0) -> Optional[np.ndarray]:
        """This operator applied to a stack (…, My, Mx) with few nonzero elements, as the sum of their kernel's
        columns, where that costs less than ``budget`` times the transform (a solver's step that clipped or admitted
        a handful of elements at the contact's edges: the rest of its displacement is updated by its step); None
        where it would not."""
        ny, nx = self.grid.shape
        at = np.flatnonzero(p)
        ly, lx = self.fft_shape
        layers = p.size // (ny * nx)
        # (the costs in the time of one element's add, measured on 9-layer windows of 27 × 395, 27 × 120 and
        #  1 × 300: a column FEW_COLUMN plus its My·Mx adds, the stack's scan and zeroing FEW_SCAN an element, the
        #  transform FEW_TRANSFORM a padded point; direct sums pay up to ~270 elements in the first, ~19 in the last:
        #  scripts/bench_contact.py --few, scripts/results/bench_contact_few.txt)
        if FEW_SCAN * p.size + at.size * (FEW_COLUMN + ny * nx) > budget * FEW_TRANSFORM * layers * ly * lx:
            return None
        out = np.zeros(p.shape)
        flat_out, values = out.reshape(layers, ny, nx), p.reshape(-1)[at]
        k, rest = np.divmod(at, ny * nx)
        j, i = np.divmod(rest, nx)
        kernel = self.kernel
        for kk, jj, ii, v in zip(k.tolist(), j.tolist(), i.tolist(), values.tolist()):
            flat_out[kk] += v * kernel[ny - 1 - jj:2 * ny - 1 - jj, nx - 1 - ii:2 * nx - 1 - ii]
        return out

    def dense(self) -> np.ndarray:
        """The n × n matrix, row-major element order: C[(j,i),(k,l)] = K[j − k + My − 1, i − l + Mx − 1]."""
        ny, nx = self.grid.shape
        n = nx * ny
        _check_dense(n)
        windows = np.lib.stride_tricks.sliding_window_view(self.kernel[::-1, ::-1], (ny, nx))
        return np.ascontiguousarray(windows[::-1, ::-1]).reshape(n, n)

    def restrict(self, rows: slice, cols: slice) -> "Convolution":
        grid = window_grid(self.grid, rows, cols)
        return self._like(grid, self._crop(grid))

    def window(self, rows: slice, cols: slice) -> "Convolution":
        """:meth:`restrict`, cached by the window's shape: a convolution's window depends on its size only,
        so the solver can work on the contact's neighbourhood and pay one symbol per size."""
        grid = window_grid(self.grid, rows, cols)
        shape = grid.shape
        cached = self._windows.get(shape)
        if cached is None:
            if len(self._parts) > 1 or self._parts[0][1] is not self:
                out = None
                for scale, part in self._parts:
                    w = part.window(rows, cols)
                    out = scaled(w, scale) if out is None else out.plus(w, scale)
                cached = Convolution(grid, out.kernel, out.hat, _parts=None)
            else:
                cached = self._like(grid, self._crop(grid))
            self._windows[shape] = cached
        return Convolution(grid, cached.kernel, cached.hat) if cached.grid is not grid else cached

    def _crop(self, grid: Grid) -> np.ndarray:
        ny, nx = self.grid.shape
        my, mx = grid.shape
        return self.kernel[ny - my:ny + my - 1, nx - mx:nx + mx - 1]

    def _like(self, grid: Grid, kernel: np.ndarray) -> "Convolution":
        return Convolution(grid, kernel)

    def plus(self, other: "Convolution", scale: float = 1.0) -> "Convolution":
        """self + scale·other on the same grid: kernels and symbols add, no new transform."""
        if other.grid is not self.grid and (other.grid.shape != self.grid.shape or other.grid.dx != self.grid.dx):
            raise ValueError("convolutions on different grids cannot be added")
        parts = self._parts + tuple((scale * c, op) for c, op in other._parts)
        return Convolution(self.grid, self.kernel + scale * other.kernel, lambda: self.hat + scale * other.hat, parts)


def scaled(op: Convolution, scale: float) -> Convolution:
    """scale·op, sharing nothing but the cached windows of op's terms."""
    return Convolution(op.grid, scale * op.kernel, lambda: scale * op.hat, tuple((scale * c, o) for c, o in op._parts))


class Matrix:
    """Any operator given by its dense matrix (row-major element order)."""

    convolution = None

    def __init__(self, grid: Grid, matrix: np.ndarray):
        n = grid.size
        if matrix.shape != (n, n):
            raise ValueError(f"matrix shape {matrix.shape} does not fit the grid of {n} elements")
        self.grid = grid
        self.matrix = matrix

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return (self.matrix @ p.ravel()).reshape(self.grid.shape)

    def dense(self) -> np.ndarray:
        return self.matrix

    def restrict(self, rows: slice, cols: slice) -> "Matrix":
        idx = np.arange(self.grid.size).reshape(self.grid.shape)[rows, cols].ravel()
        return Matrix(window_grid(self.grid, rows, cols), self.matrix[np.ix_(idx, idx)])

    window = restrict


class Sum:
    """The sum of operators on one grid; its convolution parts are merged into one (one FFT pair)."""

    def __init__(self, *terms):
        terms = [t for term in terms for t in (term.terms if isinstance(term, Sum) else (term,))]
        if not terms:
            raise ValueError("a sum needs at least one operator")
        self.grid = terms[0].grid
        convs = [t for t in terms if isinstance(t, Convolution)]
        self.others = tuple(t for t in terms if not isinstance(t, Convolution))
        merged = convs[0] if convs else None
        for c in convs[1:]:
            merged = merged.plus(c)
        self.convolution = merged
        self.terms = tuple(terms)

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    def __call__(self, p: np.ndarray) -> np.ndarray:
        u = self.convolution(p) if self.convolution is not None else np.zeros(self.grid.shape)
        for op in self.others:
            u = u + op(p)
        return u

    def dense(self) -> np.ndarray:
        _check_dense(self.grid.size)
        return sum(t.dense() for t in self.terms)

    def restrict(self, rows: slice, cols: slice) -> "Sum":
        return Sum(*(t.restrict(rows, cols) for t in self.terms))

    def window(self, rows: slice, cols: slice) -> "Sum":
        return Sum(*(t.window(rows, cols) for t in self.terms))


def add(*ops):
    """op₁ + op₂ + …: a single operator stays itself, convolutions merge, anything else becomes a Sum."""
    ops = [o for o in ops if o is not None]
    if len(ops) == 1:
        return ops[0]
    if all(isinstance(o, Convolution) for o in ops):
        out = ops[0]
        for o in ops[1:]:
            out = out.plus(o)
        return out
    return Sum(*ops)
