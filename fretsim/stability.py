"""Stability of the explicit wear update, for the operator actually used, and a detector that measures growth.

Explicit (forward-Euler) wear updates h ← h + ΔN·W p, with p the contact
pressure for the current gap.  Linearised about a settled contact, a wear
perturbation changes the pressure by δp = −C⁻¹δh (the load fixes its mean), so
each eigenmode of the pencil (W, C) is multiplied per step by 1 − ΔN·μ.  The
update is stable for ΔN < 2/μ_max; μ is largest for the shortest wave the grid
holds, where the compliance c is smallest (c ∝ element size / E*), so the
limit shrinks with the element size, the wear coefficients and the stroke and
grows with 1/E*.  Below half the limit every mode decays without changing sign.
A negative μ means the *model* is unstable (see :mod:`fretsim.wear`).

Two ways to get μ: the closed form over the Fourier symbols (a plain half-space
and a translation-invariant W, the fast path) and, for any operator, the
generalised eigenvalues of (W, C) on a window of the grid around its centre
(the finite section approaches the lattice from inside; tests check both agree).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Optional

import numpy as np

from fretsim.compliance import HalfSpace

SAFETY = 0.5  # default jump as a fraction of the limit: monotone decay of every mode
WINDOW = (9, 48)  # rows, columns of the window for the general method


@dataclass(frozen=True)
class Spectrum:
    """Extreme eigenvalues μ (per cycle) of the explicit wear update's pencil (W, C)."""

    mu_min: float
    mu_max: float
    method: str  # "symbol" (closed form) or "window" (dense generalised eigenvalues)

    @property
    def limit(self) -> float:
        """Largest stable explicit jump ΔN (cycles)."""
        return float("inf") if self.mu_max <= 0 else 2.0 / self.mu_max

    @property
    def growth_rate(self) -> float:
        """Per-cycle growth of the fastest growing wear mode of the model itself (0 if none grows)."""
        return max(0.0, -self.mu_min)


@lru_cache(maxsize=32)
def _halfspace_symbol(plane_strain: bool, dx: float, dy: float, ny: int, e_star: float, theta: tuple) -> np.ndarray:
    from fretsim.grid import Grid
    grid = Grid.centred(3, ny, dx, dy, plane_strain=plane_strain)
    # the 2D log kernel's sums converge as 1/lags, the 3D ones as 1/lags²
    return HalfSpace(grid, e_star).symbol_x(np.array(theta), lags=4096 if plane_strain else 512)


THETA = tuple(np.linspace(0.01 * np.pi, np.pi, 160))


def wear_spectrum(compliance, stiffness, general: bool = False) -> Spectrum:
    """μ_min and μ_max of the explicit update for ``compliance`` and the cycle's stiffness W (a
    :class:`fretsim.wear.WearOperator` on the same grid): closed form for a plain half-space."""
    grid = compliance.grid
    if isinstance(compliance, HalfSpace) and not general:
        theta = np.array(THETA)
        # the kernel is homogeneous (degree 1 in lengths, -1 in E*; the 2D log's constant drops out of the second
        # difference): one symbol per aspect ratio serves every dx and E* (a sweep's points, the companions)
        aspect = 1.0 if grid.plane_strain else grid.dy / grid.dx
        f = _halfspace_symbol(grid.plane_strain, 1.0, aspect, grid.shape[0], 1.0, THETA) * (grid.dx / compliance.e_star)
        mu = stiffness.rate(theta) / f
        return Spectrum(float(min(mu.min(), 0.0)), float(mu.max()), "symbol")
    ny, nx = grid.shape
    my, mx = min(ny, WINDOW[0]), min(nx, WINDOW[1])
    rows = slice((ny - my) // 2, (ny - my) // 2 + my)
    cols = slice((nx - mx) // 2, (nx - mx) // 2 + mx)
    c = compliance.restrict(rows, cols).dense()
    w = stiffness.restrict(rows, cols).dense()
    mu = window_eigenvalues(w, c, (my, mx))
    return Spectrum(float(min(mu.min(), 0.0)), float(mu.max()), "window")


def window_eigenvalues(w: np.ndarray, c: np.ndarray, shape: tuple) -> np.ndarray:
    """The eigenvalues μ of W v = μ C v over pressure changes of zero sum (the load fixes the mean pressure), for
    W and C dense on a window of ``shape`` (rows, columns; row-major elements).  Where both commute with the
    window's reflections along x and along y (even kernels, a symmetric stroke and faces: every case here), the
    problem splits into the four classes of modes even or odd along each axis, each a quarter the size (a 9 × 48
    window's whole problem, its basis by QR and eigh, 33 ms on one thread at every plan of a free-faces case and its
    proxies).  Otherwise the whole problem."""
    from fretsim.native import generalized_eigenvalues
    my, mx = shape
    # symmetric parts: a free-faces C is symmetric to ~5e-7 only, and LAPACK reads one triangle, so without this
    # the eigenvalues depended (by ~1e-8) on the basis they were computed in
    w, c = 0.5 * (w + w.T), 0.5 * (c + c.T)
    w4, c4 = w.reshape(my, mx, my, mx), c.reshape(my, mx, my, mx)
    if not (_mirrored(w4) and _mirrored(c4)):
        q = _zero_sum_basis(np.ones(w.shape[0]))
        return generalized_eigenvalues(q.T @ w @ q, q.T @ c @ q)
    out = []
    for odd_y in (False, True):
        for odd_x in (False, True):
            if (odd_y and my < 2) or (odd_x and mx < 2):
                continue
            wc, cc = _in_class(w4, odd_y, odd_x), _in_class(c4, odd_y, odd_x)
            if not (odd_y or odd_x):  # the uniform change lives here: its complement only
                ones = np.outer(_fold(np.ones(my), 0, False), _fold(np.ones(mx), 0, False)).ravel()
                q = _zero_sum_basis(ones)
                if q.shape[1] == 0:
                    continue
                wc, cc = q.T @ wc @ q, q.T @ cc @ q
            out.append(generalized_eigenvalues(wc, cc))
    return np.concatenate(out) if out else np.zeros(0)


def _mirrored(a4: np.ndarray) -> bool:
    scale = float(np.abs(a4).max()) or 1.0
    return bool(np.abs(a4 - a4[::-1, :, ::-1, :]).max() <= 1e-12 * scale
                and np.abs(a4 - a4[:, ::-1, :, ::-1]).max() <= 1e-12 * scale)


def _in_class(a4: np.ndarray, odd_y: bool, odd_x: bool) -> np.ndarray:
    """Bᵀ A B for A given as (rows, columns, rows, columns) and B the orthonormal basis of the modes even or odd
    under the reflection along y and along x: each axis folded onto its first half (:func:`_fold`)."""
    out = a4
    for axis, odd in enumerate((odd_y, odd_x, odd_y, odd_x)):
        out = _fold(out, axis, odd)
    k = out.shape[0] * out.shape[1]
    return out.reshape(k, k)


def _fold(a: np.ndarray, axis: int, odd: bool) -> np.ndarray:
    """The components of ``a`` along ``axis`` (length m) on the orthonormal basis of the vectors even (odd) under
    its reversal: (a_i ± a_(m−1−i))/√2 for i < m/2, and the middle element's own for an even one of odd m."""
    m = a.shape[axis]
    h = m // 2
    a = np.moveaxis(a, axis, 0)
    lo, hi = a[:h], a[::-1][:h]
    parts = [np.sqrt(0.5) * (lo - hi if odd else lo + hi)]
    if not odd and m % 2:
        parts.append(a[h:h + 1])
    return np.moveaxis(np.concatenate(parts), 0, axis)


def _zero_sum_basis(ones: np.ndarray) -> np.ndarray:
    """An orthonormal basis of the vectors orthogonal to ``ones``: the last columns of the Householder reflection
    that takes ``ones`` to the first axis."""
    n = ones.size
    e = ones / np.linalg.norm(ones)
    u = e.copy()
    u[0] -= 1.0
    norm = np.linalg.norm(u)
    h = np.eye(n)
    if norm > 1e-14:
        u /= norm
        h -= 2.0 * np.outer(u, u)
    return h[:, 1:]


def combined(spectra) -> Spectrum:
    """The spectrum that bounds several (a load history's blocks): the fastest decay and the fastest growth."""
    spectra = list(spectra)
    return Spectrum(min(s.mu_min for s in spectra), max(s.mu_max for s in spectra), spectra[0].method)


def default_linear_jump(limit: float, cycles: int) -> int:
    """The default ΔN_L: half the stability limit, at least 1 and at most the run."""
    if not np.isfinite(limit):
        return max(cycles, 1)
    return int(max(1, min(cycles if cycles > 0 else 1, np.floor(SAFETY * limit))))


# --- the odd-even (checkerboard) pattern of an unstable explicit update --------------------------------------

NOISE_FLOOR = 1e-2  # odd-even amplitude / mean pressure below which growth is not judged (edges crossing elements)
CEILING = 0.3  # an amplitude this large is a broken pressure field whatever its history
GROWTH_STEPS = 8  # consecutive steps of accelerating growth that make an instability
GROWTH_FACTOR = 1.5  # ... over which the amplitude grew at least this much


def checkerboard_signed(pressure: np.ndarray, edge: int = 3, stick: Optional[np.ndarray] = None) -> float:
    """Signed amplitude of the odd-even component of the pressure along x, relative to its mean.

    For p_i = P_i + A(−1)^i with P smooth, r_i = (−1)^i (p_{i−1} − 2p_i + p_{i+1})/4 ≈ −A at every element,
    while the smooth part and isolated features such as edge peaks give r of no consistent sign, which
    averages out.  The contact is taken where p exceeds 5 % of the row's peak, and elements within ``edge``
    of its edges are left out — and, given the ``stick`` zone of a partial-slip contact, of its edges too: where
    the wear stops at the stick zone's edge the pressure peaks, by the physics, over an element or two.  Returns the row of largest magnitude (at least 6 interior elements); its
    sign alternates from step to step when the mode oscillates.
    """
    p = np.atleast_2d(pressure)
    peak = p.max(axis=1, keepdims=True)
    on = p > 0.05 * peak
    # a span, not the mask: a strong checkerboard has near-zero elements inside the contact
    idx = np.arange(p.shape[1])
    first = np.argmax(on, axis=1)[:, None]
    last = (p.shape[1] - 1 - np.argmax(on[:, ::-1], axis=1))[:, None]
    interior = (idx >= first + edge + 1) & (idx <= last - edge - 1) & on.any(axis=1, keepdims=True)
    if stick is not None and stick.any():
        change = np.zeros(p.shape, bool)  # an element at the stick zone's edge along x, and its neighbours
        change[:, 1:] |= stick[:, 1:] != stick[:, :-1]
        change[:, :-1] |= stick[:, 1:] != stick[:, :-1]
        near = change.copy()
        for k in range(1, edge + 1):
            near[:, k:] |= change[:, :-k]
            near[:, :-k] |= change[:, k:]
        interior &= ~near
    d2 = np.zeros_like(p)
    d2[:, 1:-1] = p[:, :-2] - 2 * p[:, 1:-1] + p[:, 2:]
    r = d2 * (1.0 - 2.0 * (idx % 2)) / 4.0
    count = interior.sum(axis=1)
    mean_p = (p * interior).sum(axis=1) / np.maximum(count, 1)
    rows = (count >= 6) & (mean_p > 0)  # (a row with no pressure inside its span has no pattern to judge)
    if not rows.any():
        return 0.0
    mean_r = (r * interior).sum(axis=1)[rows] / count[rows]
    mean_p = mean_p[rows]
    amp = -mean_r / mean_p
    return float(amp[np.argmax(np.abs(amp))])


def odd_even_run(pressure: np.ndarray, share: float = 0.1) -> int:
    """The longest run of elements along x over which the pressure alternates element by element: its second
    difference changes sign from each element to the next, each above ``share`` of the row's mean contact pressure.
    A checkerboard, even one that lifts every other element off, runs over the contact (16–40 elements on the tube
    in service); a contact's edges, a peak at a turning edge or two patches of one position make runs of a few
    (McColl's worn positions: at most 4) — where :func:`checkerboard_signed`'s mean over the span read them as
    40 % patterns."""
    p = np.atleast_2d(pressure)
    if p.shape[1] < 4:
        return 0
    on = p > 0
    mean = (p * on).sum(axis=1) / np.maximum(on.sum(axis=1), 1)
    d2 = p[:, :-2] - 2.0 * p[:, 1:-1] + p[:, 2:]
    big = np.abs(d2) > share * mean[:, None]
    alt = big[:, :-1] & big[:, 1:] & (np.sign(d2[:, :-1]) == -np.sign(d2[:, 1:]))
    edges = np.diff(np.pad(alt.astype(np.int8), ((0, 0), (1, 1))), axis=1)
    starts, ends = np.nonzero(edges == 1), np.nonzero(edges == -1)
    return int((ends[1] - starts[1]).max()) if starts[1].size else 0


def checkerboard_amplitude(pressure: np.ndarray) -> float:
    return abs(checkerboard_signed(pressure))


class GrowthWatch:
    """Tells a growing odd-even oscillation from a decaying (or saturating) one.

    An unstable mode is multiplied by the same factor |g| > 1 every step, a_n = |g|·a_{n−1} + e_n, so its
    growth accelerates: each increment is larger than the one before.  A stable mode (|g| < 1) excited at
    every step (contact edges moving) rises towards a plateau e/(1 − |g|) with shrinking increments — which
    for |g| near 1 may take dozens of steps, so "it grew" alone is not evidence.  Unstable means: above the
    noise floor, with GROWTH_STEPS increments in a row each positive and larger than the last, or above the
    ceiling.  A contact edge crossing an element makes a transient of a few steps; eight accelerating steps
    and a 1.5-fold growth are not made that way.  The state is a short list of numbers, kept in the checkpoint.
    """

    def __init__(self, history=()):
        self.history = [float(a) for a in history][-(GROWTH_STEPS + 2):]

    def update(self, signed_amplitude: float) -> bool:
        self.history = (self.history + [float(signed_amplitude)])[-(GROWTH_STEPS + 2):]
        a = np.abs(self.history)
        if a[-1] > CEILING:
            return True
        if len(a) < GROWTH_STEPS + 2 or a[-1] < NOISE_FLOOR:
            return False
        steps = np.diff(a)
        return bool((steps > 0).all() and (np.diff(steps) > 0).all() and a[-1] >= GROWTH_FACTOR * a[0])

    def reset(self) -> None:
        self.history = []
