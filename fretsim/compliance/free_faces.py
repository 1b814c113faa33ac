"""Free faces of a body that ends across the contact: the compliance they add to the half-space's (paper §2.1).

A cylinder pressed on a flat block as long as itself (McColl's test, the paper's Fig. 2) loads the block right
up to its faces at y = ±B/2, where a half-space would have material beyond; so are the cylinder's own ends.
The faces carry no traction, so the body is softer there and its ends carry less of the load.  The paper
approximates this with overlapping half-spaces (the shear on the overlaps neglected); solved exactly, that
approximation captures about a fifth of the faces' effect (scripts/study_free_faces_fe.py), so fretsim solves
the block itself instead.

The block is prismatic: infinite along x (sliding), its cross-section B wide and D deep (bottom fixed).  A
surface pressure q(y)·cos(kx) gives displacements (U sin kx, V cos kx, W cos kx) with U, V, W functions of
(y, z): one small 2D elastic problem per wavenumber k, whose stiffness is K0 + k K1 + k² K2 (bilinear
quadrilaterals, assembled once).  The faces' effect is the block's settlement minus that of the same block
three times wider (a half-space along y to the accuracy needed): the difference is smooth, so nine
wavenumbers resolve it, and the common errors of mesh, finite depth and fixed bottom cancel to first order.
Back in x by the Fourier integral, it is a convolution along x between every pair of rows, applied per
Fourier mode as a small dense matrix across the rows: O(n log n + M_y² M_x) per application, or in a basis of
the few row patterns the faces excite when there are many rows (:func:`compressed`).

Verified in the tests against the half-space's exact 2(1 − ν²)/(E k) and against an independent finite-
element solution (scikit-fem, quadratic elements) stored in tests/data; on the McColl case in
scripts/study_free_faces_fe.py.
"""
from __future__ import annotations

import numpy as np

from fretsim.compliance import fft
from fretsim.compliance.operator import _check_dense, window_grid
from fretsim.grid import Grid
from fretsim.native import banded_cholesky_solve

WIDE = 3.0  # the control block is this many times wider than the flat
DEPTH = 2.0  # the block's depth, in lengths B (0.5B to 2B moves McColl's maximum depth by 0.14 points: the study)
# finite elements across one grid row (even: a node at each row's centre).  4 instead of 2 moves McColl's
# maximum depth by 0.03 points of its 1.4 % change, at 2.2x the cost; the block's depth alone moves it 0.14.
SPLIT = 2
K_SAMPLES = (0.0, 2.5, 4.6, 8.5, 15.6, 28.7, 52.8, 97.1, 178.6)  # k·B; beyond, |ΔG| < 2e-4 of its value at k = 0
RANK_TOL = 1e-4  # the compressed operator's singular values, relative to the largest (see compressed)
K_POINTS = 2001  # quadrature points of the Fourier integral back to x (at least; more for grids long against B)


def _graded(h0: float, growth: float, cap: float, length: float) -> np.ndarray:
    """Steps from h0 growing geometrically (at most ``cap``) that add up to ``length``."""
    steps, total, h = [], 0.0, h0
    while total + h < length:
        steps.append(h)
        total += h
        h = min(h * growth, cap)
    if not steps:
        return np.array([length])
    steps[-1] += length - total
    return np.array(steps)


def _elasticity(youngs: float, poisson: float) -> np.ndarray:
    """D for strains ordered (εxx, εyy, εzz, γyz, γxy, γxz)."""
    lam = youngs * poisson / ((1 + poisson) * (1 - 2 * poisson))
    mu = youngs / (2 * (1 + poisson))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[np.arange(3), np.arange(3)] += 2 * mu
    d[np.arange(3, 6), np.arange(3, 6)] = mu
    return d


class Block:
    """A prismatic block, infinite along x: cross-section y_nodes × z_nodes (z down from the loaded top, bottom
    fixed, sides free), bilinear elements.  ``settlement(k)``: the top's downward displacement amplitude at the
    given nodes under unit pressure cos(kx) on each load row."""

    def __init__(self, y_nodes: np.ndarray, z_nodes: np.ndarray, youngs: float, poisson: float):
        y, z = np.asarray(y_nodes, float), np.asarray(z_nodes, float)
        ny, nz = y.size, z.size
        self.y = y
        node = np.arange(ny * nz).reshape(ny, nz).T  # node (iz, iy), numbered down each column: a narrow band
        corners = np.stack([node[:-1, :-1], node[:-1, 1:], node[1:, 1:], node[1:, :-1]], axis=-1).reshape(-1, 4)
        hy = np.broadcast_to(np.diff(y)[None, :], (nz - 1, ny - 1)).ravel()
        hz = np.broadcast_to(np.diff(z)[:, None], (nz - 1, ny - 1)).ravel()
        xi_a, eta_a = np.array([-1, 1, 1, -1.0]), np.array([-1, -1, 1, 1.0])
        g = 1 / np.sqrt(3.0)
        d = _elasticity(youngs, poisson)
        k0 = k1 = k2 = 0.0
        for xi, eta in ((-g, -g), (g, -g), (g, g), (-g, g)):
            n = (1 + xi * xi_a) * (1 + eta * eta_a) / 4  # (4,)
            ny_ = (xi_a * (1 + eta * eta_a) / 4)[None, :] * (2 / hy)[:, None]  # ∂N/∂y per element, (E, 4)
            nz_ = ((1 + xi * xi_a) * eta_a / 4)[None, :] * (2 / hz)[:, None]
            e = hy.size
            b0 = np.zeros((e, 6, 12))
            b1 = np.zeros((e, 6, 12))
            u, v, w = slice(0, 12, 3), slice(1, 12, 3), slice(2, 12, 3)
            b0[:, 1, v] = ny_
            b0[:, 2, w] = nz_
            b0[:, 3, v] = nz_
            b0[:, 3, w] = ny_
            b0[:, 4, u] = ny_
            b0[:, 5, u] = nz_
            b1[:, 0, u] = n
            b1[:, 4, v] = -n
            b1[:, 5, w] = -n
            jac = (hy * hz / 4)[:, None, None]
            db0, db1 = d @ b0, d @ b1
            b0t, b1t = b0.transpose(0, 2, 1), b1.transpose(0, 2, 1)
            cross = b0t @ db1
            k0 = k0 + jac * (b0t @ db0)
            k1 = k1 + jac * (cross + cross.transpose(0, 2, 1))
            k2 = k2 + jac * (b1t @ db1)
        dofs = (3 * corners[:, :, None] + np.arange(3)[None, None, :]).reshape(-1, 12)
        rows = np.broadcast_to(dofs[:, :, None], (dofs.shape[0], 12, 12)).ravel()
        cols = np.broadcast_to(dofs[:, None, :], (dofs.shape[0], 12, 12)).ravel()
        # keep the upper band of K0, K1, K2 over the free dofs (the bottom row of nodes is fixed): LAPACK's
        # banded Cholesky then solves each k in O(n·band²), 4x faster than a general sparse LU here
        fixed = np.zeros(3 * ny * nz, bool)
        fixed[(3 * node[-1][:, None] + np.arange(3)).ravel()] = True
        number = np.cumsum(~fixed) - 1
        keep = ~fixed[dofs]
        self.band = 3 * (nz + 1) + 2
        self.n = int((~fixed).sum())
        self.k = []
        for m in (k0, k1, k2):
            i = np.broadcast_to(dofs[:, :, None], m.shape)
            j = np.broadcast_to(dofs[:, None, :], m.shape)
            ok = keep[:, :, None] & keep[:, None, :]
            i, j, val = number[i[ok]], number[j[ok]], m[ok]
            upper = i <= j
            ab = np.zeros((self.band + 1, self.n))
            np.add.at(ab, (self.band + i[upper] - j[upper], j[upper]), val[upper])
            self.k.append(ab)
        self.top_w = number[3 * node[0] + 2]  # the top's vertical dofs, along y

    def loads(self, edges: np.ndarray) -> np.ndarray:
        """One column per load row [edges[j], edges[j+1]]: unit pressure on it as consistent nodal forces."""
        y = self.y
        out = np.zeros((self.n, edges.size - 1))
        for j in range(edges.size - 1):
            inside = np.flatnonzero((y[:-1] >= edges[j] - 1e-9) & (y[1:] <= edges[j + 1] + 1e-9))
            h = y[inside + 1] - y[inside]
            np.add.at(out[:, j], self.top_w[inside], h / 2)
            np.add.at(out[:, j], self.top_w[inside + 1], h / 2)
        return out

    def settlement(self, k: float, loads: np.ndarray, at: np.ndarray) -> np.ndarray:
        """Downward displacement of the top nodes ``at`` (indices along y) per load column, under cos(kx)."""
        ab = self.k[0] + k * self.k[1] + (k * k) * self.k[2]
        return banded_cholesky_solve(ab, loads)[self.top_w[at]]


def face_settlement(rows_y: np.ndarray, dy: float, length: float, youngs: float, poisson: float,
                    ks: np.ndarray, depth: float | None = None) -> np.ndarray:
    """ΔG[m, i, j] (mm/MPa): the settlement at row i's centre per unit pressure cos(k_m x) on row j that a flat of
    ``length`` B (faces at ±B/2, rows centred at ``rows_y``, each ``dy`` wide) adds to a half-space's; the
    blocks are ``depth`` deep (default DEPTH·B)."""
    half = length / 2
    rows_y = np.asarray(rows_y, float)
    edges = np.concatenate([rows_y - dy / 2, [rows_y[-1] + dy / 2]])
    if edges[0] < -half - 1e-9 * length or edges[-1] > half + 1e-9 * length:
        raise ValueError(f"the grid's rows ({edges[0]:.4g} … {edges[-1]:.4g} mm) reach beyond the flat's faces "
                         f"at ±{half:.4g} mm")
    h = dy / SPLIT
    inner = np.linspace(edges[0], edges[-1], rows_y.size * SPLIT + 1)
    # the grid is centred: from its last row to the face (if the flat is longer), then beyond for the wide block
    gap = half - edges[-1]
    to_face = edges[-1] + np.cumsum(_graded(h, 1.25, length / 8, gap)) if gap > 1e-9 * length else np.zeros(0)
    flat_y = np.concatenate([-to_face[::-1], inner, to_face])
    beyond = half + np.cumsum(_graded(h, 1.25, length / 4, (WIDE - 1) * half))
    wide_y = np.concatenate([-beyond[::-1], flat_y, beyond])
    depth = DEPTH * length if depth is None else depth
    z = np.concatenate([[0.0], np.cumsum(_graded(min(h, dy) / 8, 1.3, depth / 8, depth))])
    out = np.empty((ks.size, rows_y.size, rows_y.size))
    blocks = [Block(flat_y, z, youngs, poisson), Block(wide_y, z, youngs, poisson)]
    at = [np.searchsorted(b.y, rows_y - 1e-9 * length) for b in blocks]
    for b, a in zip(blocks, at):
        if np.abs(b.y[a] - rows_y).max() > 1e-9 * length:
            raise AssertionError("row centres must be mesh nodes")
    # the blocks are symmetric about y = 0 when the rows are: G[i, j] = G[−i, −j], so half the loads suffice
    symmetric = np.allclose(rows_y, -rows_y[::-1], rtol=0, atol=1e-9 * length)
    half_rows = (rows_y.size + 1) // 2 if symmetric else rows_y.size
    loads = [b.loads(edges)[:, :half_rows] for b in blocks]
    for m, k in enumerate(ks):
        faces, wide = (b.settlement(k, ld, a) for b, ld, a in zip(blocks, loads, at))
        out[m, :, :half_rows] = faces - wide
        if symmetric:
            out[m, :, half_rows:] = out[m, ::-1, :rows_y.size - half_rows][:, ::-1]
    return out


def pchip(xs: np.ndarray, ys: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The monotone piecewise-cubic Hermite interpolant (Fritsch–Carlson, as scipy's PchipInterpolator: slopes the
    weighted harmonic mean of the neighbouring secants, 0 where they change sign, the ends' one-sided three-point
    estimate kept to the data's shape) of ``ys`` (samples along axis 0 at the increasing ``xs``) at ``x`` within
    [xs[0], xs[-1]].  Here rather than scipy's: scipy.interpolate costs 0.2 s to import, a fifth of planning a
    free-faces case (the run and `check` both pay it)."""
    xs, x = np.asarray(xs, float), np.asarray(x, float)
    c0, c1, c2, c3 = pchip_coefficients(xs, ys)
    i = _interval(xs, x)
    t = (x - xs[i]).reshape((-1,) + (1,) * (c0.ndim - 1))
    return ((c3[i] * t + c2[i]) * t + c1[i]) * t + c0[i]


def pchip_coefficients(xs: np.ndarray, ys: np.ndarray) -> tuple:
    """:func:`pchip`'s cubic on each interval [xs[i], xs[i+1]] in the power basis of t = x − xs[i] (scipy's PPoly):
    (c0, c1, c2, c3), each (intervals, …) — value c0 + c1·t + c2·t² + c3·t³."""
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    if xs.ndim != 1 or len(xs) < 2 or not (np.diff(xs) > 0).all() or len(ys) != len(xs):
        raise ValueError("pchip needs at least two strictly increasing abscissae, one sample each")
    shape = (-1,) + (1,) * (ys.ndim - 1)
    h = np.diff(xs)
    m = np.diff(ys, axis=0) / h.reshape(shape)
    d = np.zeros_like(ys)
    if len(xs) == 2:
        d[0] = d[1] = m[0]
    else:
        hb, ha = h[:-1].reshape(shape), h[1:].reshape(shape)  # the secants before and after each inner point
        w1, w2 = 2 * ha + hb, ha + 2 * hb
        flat = (np.sign(m[1:]) != np.sign(m[:-1])) | (m[1:] == 0) | (m[:-1] == 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = (w1 / m[:-1] + w2 / m[1:]) / (w1 + w2)
        d[1:-1] = np.where(flat, 0.0, 1.0 / np.where(flat, 1.0, mean))
        for end, (h0, h1, m0, m1) in ((0, (h[0], h[1], m[0], m[1])), (-1, (h[-1], h[-2], m[-1], m[-2]))):
            e = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
            e = np.where(np.sign(e) != np.sign(m0), 0.0, e)
            d[end] = np.where((np.sign(m0) != np.sign(m1)) & (np.abs(e) > 3 * np.abs(m0)), 3 * m0, e)
    hh = h.reshape(shape)
    d0, d1 = d[:-1], d[1:]
    return ys[:-1], d0, (3 * m - 2 * d0 - d1) / hh, (d0 + d1 - 2 * m) / (hh * hh)


def _interval(xs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The interval of ``xs`` each of ``x`` falls in (the ends' intervals beyond them)."""
    return np.clip(np.searchsorted(xs, x, side="right") - 1, 0, len(xs) - 2)


def kernel_along_x(delta: np.ndarray, ks: np.ndarray, dx: float, nx: int) -> np.ndarray:
    """ΔK[i, j, s] at lags s = −(nx−1)…(nx−1) elements: ΔK_ij(s) = (1/π) ∫ ΔG_ij(k) B(k) cos(k s dx) dk,
    B(k) = 2 sin(k dx/2)/k the transform of one element's box.  ΔG is interpolated between the sampled k (monotone
    cubic) and taken as 0 beyond the last.

    The quadrature Σ_k w_k ΔG(k) cos(k s) is taken interval by interval of the samples, where ΔG is a cubic in
    t = k − k_i: its four coefficients times the moments Σ_k t^p w_k cos(k s), so the interpolant is never
    evaluated at the quadrature's thousands of points for every pair of rows (0.2 s of planning a 3D free-faces
    case).  The kernel is even in the lag, and where the rows are placed symmetrically about the middle (every
    grid here is centred on y = 0), ΔG_ij = ΔG_(n−1−i)(n−1−j): the first half of the rows gives the rest."""
    s = np.arange(nx) * dx  # the lags ≥ 0
    k = np.linspace(0.0, ks[-1], max(K_POINTS, int(ks[-1] * s[-1] / 0.05) + 1))  # cos(ks): 0.05 rad a step
    weights = np.full(k.size, k[1] - k[0])
    weights[[0, -1]] *= 0.5
    box = np.where(k > 0, 2 * np.sin(k * dx / 2) / np.where(k > 0, k, 1.0), dx)
    w = (weights * box)[:, None] * np.cos(np.outer(k, s)) / np.pi  # (k, s)
    ny = delta.shape[1]
    half = (ny + 1) // 2 if np.allclose(delta, delta[:, ::-1, ::-1], rtol=1e-9, atol=0.0) else ny
    coeffs = np.stack(pchip_coefficients(ks, delta[:, :half]), axis=1)  # (interval, power, i, j)
    i = _interval(np.asarray(ks, float), k)
    t = k - ks[i]
    bounds = np.searchsorted(i, np.arange(len(ks)))  # k is sorted: each interval's points are a run
    moments = np.zeros((len(ks) - 1, 4, nx))
    for j in range(len(ks) - 1):
        lo, hi = bounds[j], bounds[j + 1]
        if hi > lo:
            powers = t[lo:hi] ** np.arange(4)[:, None]  # (power, k)
            moments[j] = powers @ w[lo:hi]
    part = (coeffs.reshape(-1, half * ny).T @ moments.reshape(-1, nx)).reshape(half, ny, nx)
    out = np.empty((ny, ny, 2 * nx - 1))
    out[:half, :, nx - 1:] = part
    out[half:, :, nx - 1:] = part[:ny - half][::-1, ::-1]
    out[:, :, :nx - 1] = out[:, :, nx:][:, :, ::-1]
    return out


class RowConvolution:
    """u_i(x) = Σ_j Σ_l K_ij(x − x_l) p_j(x_l): a convolution along x between every pair of rows.

    ``kernel`` has shape (My, My, 2Mx − 1), lag 0 at index Mx − 1.  Applied by zero-padded FFT along x and a
    dense My × My product per Fourier mode.  With a ``basis`` Q (My × r, orthonormal columns) the kernel is
    given in it, (r, r, 2Mx − 1), and K = Q C Qᵀ: the product per mode costs r² (plus 2·My·r to change basis).
    """

    convolution = None

    def __init__(self, grid: Grid, kernel: np.ndarray, basis: np.ndarray | None = None):
        ny, nx = grid.shape
        r = ny if basis is None else basis.shape[1]
        if kernel.shape != (r, r, 2 * nx - 1) or (basis is not None and basis.shape[0] != ny):
            raise ValueError(f"kernel shape {kernel.shape} does not fit the grid {grid.shape}")
        self.grid = grid
        self.kernel = kernel
        self.basis = basis
        self.n_fft = fft.next_fast_len(2 * nx - 1, real=True)
        wrapped = np.zeros((r, r, self.n_fft))
        idx = (np.arange(2 * nx - 1) - (nx - 1)) % self.n_fft
        wrapped[:, :, idx] = kernel
        hat = fft.rfft(wrapped, self.n_fft, axis=2).transpose(2, 0, 1)  # (modes, r, r)
        self.real = bool(np.abs(hat.imag).max() <= 1e-12 * np.abs(hat.real).max(initial=0.0))
        self.hat = np.ascontiguousarray(hat.real if self.real else hat)  # an even kernel has a real symbol

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    def __call__(self, p: np.ndarray) -> np.ndarray:
        nx = self.grid.shape[1]
        q = p if self.basis is None else self.basis.T @ p
        ph = np.ascontiguousarray(fft.forward(q, (1, self.n_fft)).T)  # (modes, r) complex
        if self.real:  # real symbol times complex data: as two real columns
            uh = np.matmul(self.hat, ph.view(np.float64).reshape(*ph.shape, 2)).reshape(ph.shape[0], -1)
            uh = uh.view(np.complex128)
        else:
            uh = np.matmul(self.hat, ph[:, :, None])[:, :, 0]
        u = fft.backward(np.ascontiguousarray(uh.T), (1, self.n_fft), (uh.shape[1], nx))
        return u if self.basis is None else self.basis @ u

    def full_kernel(self) -> np.ndarray:
        if self.basis is None:
            return self.kernel
        return np.einsum("ia,abs,jb->ijs", self.basis, self.kernel, self.basis, optimize=True)

    def dense(self) -> np.ndarray:
        ny, nx = self.grid.shape
        _check_dense(nx * ny)
        lag = np.arange(nx)[:, None] - np.arange(nx)[None, :] + nx - 1
        return self.full_kernel()[:, :, lag].transpose(0, 2, 1, 3).reshape(nx * ny, nx * ny)

    def restrict(self, rows: slice, cols: slice) -> "RowConvolution":
        ny, nx = self.grid.shape
        grid = window_grid(self.grid, rows, cols)
        mx = grid.shape[1]
        lags = slice(nx - mx, nx + mx - 1)
        if self.basis is None:
            return RowConvolution(grid, self.kernel[rows, rows, lags])
        return RowConvolution(grid, self.kernel[:, :, lags], np.ascontiguousarray(self.basis[rows]))

    def window(self, rows: slice, cols: slice) -> "RowConvolution":
        """:meth:`restrict`, cached: the solver asks for the same few windows at every step."""
        key = (rows.indices(self.grid.shape[0]), cols.indices(self.grid.shape[1]))
        cache = self.__dict__.setdefault("_windows", {})
        if key not in cache:
            if len(cache) >= 4:  # each holds a symbol as large as the operator's own
                cache.pop(next(iter(cache)))
            cache[key] = self.restrict(rows, cols)
        return cache[key]


def compressed(grid: Grid, kernel: np.ndarray) -> RowConvolution:
    """The operator of ``kernel``, in a basis of the rows where it is of low rank.

    A few rows near the faces carry the correction, so K_ij(s) ≈ Σ Q_ia C_ab(s) Q_jb with r ≪ M_y columns of
    Q: the leading eigenvectors of Σ_s (K_s K_sᵀ + K_sᵀ K_s), kept down to RANK_TOL of the largest singular
    value (errors ~1e-4 of the correction's largest entry, ~5e-6 of the displacement).  On McColl's flat on
    101 rows r = 14: the product per mode costs 14² instead of 101²."""
    ny = kernel.shape[0]
    if ny < 32:
        return RowConvolution(grid, kernel)
    rows, cols = kernel.reshape(ny, -1), kernel.transpose(1, 0, 2).reshape(ny, -1)
    gram = rows @ rows.T + cols @ cols.T  # Σ_s K_s K_sᵀ + K_sᵀ K_s
    w, v = np.linalg.eigh(gram)
    keep = w > (RANK_TOL**2) * w.max()
    if keep.sum() >= ny // 3:
        return RowConvolution(grid, kernel)
    q = np.ascontiguousarray(v[:, keep])
    return RowConvolution(grid, np.einsum("ia,ijs,jb->abs", q, kernel, q, optimize=True), q)


_CACHE: dict = {}


def _delta(rows_y: np.ndarray, dy: float, length: float, youngs: float, poisson: float) -> tuple:
    """face_settlement at the sampled wavenumbers, cached per process (a coarse grid, proxies and a sweep's points
    share it)."""
    key = (tuple(np.round(rows_y, 12)), round(dy, 12), round(length, 12), youngs, poisson)
    if key not in _CACHE:
        if len(_CACHE) >= 8:  # a sweep over lengths or grids would otherwise keep every one
            _CACHE.pop(next(iter(_CACHE)))
        ks = np.asarray(K_SAMPLES) / length
        _CACHE[key] = ks, face_settlement(rows_y, dy, length, youngs, poisson, ks)
    return _CACHE[key]


def free_faces(grid: Grid, bodies) -> RowConvolution:
    """The compliance that free faces add to the half-spaces' on ``grid`` (3D only): ``bodies`` lists, for each
    body that ends across the contact, (length between its faces centred on the grid, E, ν).  Rows beyond a
    body's faces are not part of it (nothing touches there) and get nothing from it; a face must not cut a row
    (ValueError)."""
    if grid.plane_strain:
        raise ValueError("free faces need a 3D grid: a plane-strain model has no ends")
    ny, nx = grid.shape
    kernel = np.zeros((ny, ny, 2 * nx - 1))
    for length, youngs, poisson in bodies:
        half = length / 2
        inside = np.flatnonzero(np.abs(grid.y) < half)
        if inside.size == 0:
            continue
        if grid.y[inside[-1]] + grid.dy / 2 > half * (1 + 1e-9):
            raise ValueError(f"a body's faces at ±{half:.4g} mm cut through the grid's rows ({grid.dy:.4g} mm wide, "
                             f"centred on y = 0): choose the grid's y extent so that the faces fall on row edges "
                             f"or beyond the grid")
        ks, delta = _delta(grid.y[inside], grid.dy, length, youngs, poisson)
        kernel[np.ix_(inside, inside)] += kernel_along_x(delta, ks, grid.dx, nx)
    return compressed(grid, kernel)
