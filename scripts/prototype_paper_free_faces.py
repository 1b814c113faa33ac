"""PROTOTYPE, NOT VERIFIED, NOT USED BY FRETSIM: the paper's finite-space model of the flat (section 2.1,
Fig. 2; Zhang et al. and Stan et al.), kept for the next step of issue #8.

Run as a script it builds the correction on the McColl 185 N grid and runs the case with it beside the plain
half-space, for comparison with ``study_free_faces_fe.py``.  Measured (2026-11-22), as changes of the flat's
centre-line depth, the maximum depths and the end/centre pressure at N = 0 (1.192 on a half-space):

    this prototype (normal stress on the faces only)          +0.03 %   −0.02 %   1.187
    the paper's approximation solved by FE (shear-only plane)  +0.08 %   −0.28 %   1.158
    free faces, FE                                             +0.39 %   −1.4 %    1.053

The prototype changes the end element's own compliance by 0.9 %; its correction is 20 % asymmetric before it
is symmetrised (the neglected shear breaks reciprocity).  It and the FE solution of the same approximation
disagree by a factor of about 5 on a small effect, and both leave out most of the faces' effect: on the face
plane the half-space's vertical shear τ_yz, which the method neglects, exceeds the normal stress σ_yy it
corrects (−0.28 p against −0.21 p at the first face row, with these kernels).  The kernels follow
Boussinesq's point-load formulas (Johnson, Contact Mechanics, 3.20–3.21), but nothing here checks them
independently: verify before building on it.

A flat of finite width: the extra compliance of its free side faces (paper §2.1, Fig. 2).

The flat occupies |y| ≤ W/2, z ≥ 0 (z into the body), unbounded along x.  A half-space model leaves normal
stress σ_yy on the planes y = ±W/2, which are free faces of the real body.  Following the overlapping
half-spaces of Hetényi, as Zhang et al. and Stan et al. use it (shear on the overlaps neglected), the body is
the intersection of three half-spaces: H0 below the top surface and H± behind each face.  Fictitious normal
loads s on the top and q± on the faces make the normal tractions right:

    top:    s − G q = p          (G: σ_zz on the top from loads on the faces)
    faces:  q − A s − Q q = 0    (A: σ_yy on a face from loads on the top; Q: from the other face)

and the top's normal displacement is u = U s + V q (U: the flat's own half-space, Love's rectangle; V: the
displacement along z of a face load, tangential to that face).  Eliminating s and q,

    u = U p + ΔC p,    ΔC = (U G + V)(I − A G − Q)⁻¹ A,

so the flat of finite width is the half-space plus the correction ΔC, which this module builds.  Every
block is translation-invariant along x, so the blocks are arrays over the x offset and the solve is one small
dense system per Fourier mode along x (periodic over a padded length that holds the faces' reach).

All kernels come from Boussinesq's point load on a half-space (Johnson, Contact Mechanics, Eqs. 3.20–3.21),
integrated over each loaded element with Gauss rules, sinh-mapped where the point is close to the element.
Stresses are tension-positive, pressures compressive-positive, lengths in mm, moduli in MPa.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import scipy.fft as sfft

from fretsim.compliance.halfspace import love_rectangle
from fretsim.compliance.operator import _check_dense, window_grid
from fretsim.grid import Grid

GAUSS_FAR = np.polynomial.legendre.leggauss(3)  # per direction, for a point far from the element
GAUSS_NEAR = np.polynomial.legendre.leggauss(16)  # per piece of a sinh-mapped direction
NEAR = 1.5  # a direction is resolved with the sinh map when the element is longer than NEAR × the distance


# --- Boussinesq's point load P = 1 at the origin of a half-space; field point (ξ, η) along its surface, ζ deep ---

def sigma_tangential(xi, eta, zeta, nu):
    """σ_ηη: the normal stress along η (parallel to the surface) at (ξ, η, ζ)."""
    rho2 = xi * xi + eta * eta
    r = np.sqrt(rho2 + zeta * zeta)
    t = (1 - 2 * nu) / (r * (r + zeta))  # (1 − 2ν)(1 − ζ/R)/ρ², without the cancellation
    s_r = (t - 3 * zeta * rho2 / r**5) / (2 * np.pi)
    s_t = -(t - (1 - 2 * nu) * zeta / r**3) / (2 * np.pi)
    with np.errstate(invalid="ignore", divide="ignore"):
        sin2 = np.where(rho2 > 0, eta * eta / np.where(rho2 > 0, rho2, 1.0), 0.5)
    return s_t + (s_r - s_t) * sin2


def sigma_normal(xi, eta, zeta):
    """σ_ζζ: the normal stress across the planes parallel to the surface at (ξ, η, ζ)."""
    r2 = xi * xi + eta * eta + zeta * zeta
    return -1.5 / np.pi * zeta**3 / r2**2.5


def u_tangential(xi, eta, zeta, nu, youngs):
    """The displacement along η at (ξ, η, ζ) (positive along +η, away from the load for η > 0)."""
    r = np.sqrt(xi * xi + eta * eta + zeta * zeta)
    return (1 + nu) / (2 * np.pi * youngs) * eta * (zeta / r**3 - (1 - 2 * nu) / (r * (r + zeta)))


# --- quadrature over loaded rectangles --------------------------------------------------------------------------

def _rule_1d(lo, hi, x, delta, near):
    """Nodes and weights (arrays (..., n)) for ∫_lo^hi f(s) ds with the point at x and transverse distance δ.

    Far: 3-point Gauss.  Near: the interval is split at the point's projection and each piece mapped by
    s = x ± δ sinh(u), which spreads the nodes geometrically away from the point (Johnston & Elliott)."""
    if not near:
        g, w = GAUSS_FAR
        half = (hi - lo)[..., None] / 2
        return (lo + hi)[..., None] / 2 + half * g, half * w
    g, w = GAUSS_NEAR
    c = np.clip(x, lo, hi)
    d = np.maximum(delta, 1e-12 * np.maximum(hi - lo, 1e-300))
    nodes, weights = [], []
    for a, b, sign in ((c, hi, 1.0), (c, lo, -1.0)):  # from the projection outwards, each way
        ua = np.arcsinh(sign * (a - x) / d)
        ub = np.arcsinh(sign * (b - x) / d)
        half = (ub - ua)[..., None] / 2
        u = (ua + ub)[..., None] / 2 + half * g
        nodes.append(x[..., None] + sign * d[..., None] * np.sinh(u))
        weights.append(np.abs(half * w) * d[..., None] * np.cosh(u))
    return np.concatenate(nodes, axis=-1), np.concatenate(weights, axis=-1)


def rect_integral(f, x, y, zeta, xlo, xhi, ylo, yhi):
    """∫∫ f(x − x', y − y', ζ) dx' dy' over [xlo, xhi] × [ylo, yhi], for arrays of points and rectangles
    (broadcast together).  ``f(ξ, η, ζ)`` is a point-load kernel."""
    x, y, zeta, xlo, xhi, ylo, yhi = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in
                                                            (x, y, zeta, xlo, xhi, ylo, yhi)))
    gx = np.maximum(0.0, np.maximum(xlo - x, x - xhi))
    gy = np.maximum(0.0, np.maximum(ylo - y, y - yhi))
    dist = np.sqrt(gx * gx + gy * gy + zeta * zeta)
    near_x = (xhi - xlo) > NEAR * dist
    near_y = (yhi - ylo) > NEAR * dist
    out = np.zeros(x.shape)
    for nx_ in (False, True):
        for ny_ in (False, True):
            sel = (near_x == nx_) & (near_y == ny_)
            if not sel.any():
                continue
            px, py, pz = x[sel], y[sel], zeta[sel]
            sx, wx = _rule_1d(xlo[sel], xhi[sel], px, np.sqrt(pz * pz + gy[sel] ** 2), nx_)
            sy, wy = _rule_1d(ylo[sel], yhi[sel], py, np.sqrt(pz * pz + gx[sel] ** 2), ny_)
            vals = f(px[:, None, None] - sx[:, :, None], py[:, None, None] - sy[:, None, :], pz[:, None, None])
            out[sel] = np.einsum("kij,ki,kj->k", vals, wx, wy)
    return out


# --- the operator -------------------------------------------------------------------------------------------------

def face_depths(first: float, depth: float, ratio: float = 1.25) -> np.ndarray:
    """Edges 0 = z₀ < z₁ < … ≥ depth of the face elements, growing geometrically from ``first``."""
    edges = [0.0]
    h = first
    while edges[-1] < depth:
        edges.append(edges[-1] + h)
        h *= ratio
    return np.array(edges)


class FreeFaces:
    """ΔC of a flat of width W (free faces at y = ±W/2) on a 3D grid: apply, dense, restrict (the interface
    of :mod:`fretsim.compliance.operator`).

    Parameters: the grid (its rows must lie within the flat: |y| ≤ W/2), W, the flat's E and ν.  The faces are
    discretised with the grid's dx along x and elements growing from dx/2 at the top edge to ``depth`` (default:
    4 row pitches or 4 grid widths along x, whichever is larger, and at most W) into the body; ``reach`` is
    how far along x beyond the grid the faces are kept (default: the depth)."""

    convolution = None

    def __init__(self, grid: Grid, width: float, youngs_modulus: float, poissons_ratio: float,
                 depth: Optional[float] = None, reach: Optional[float] = None, _hat=None, _fft_len=None):
        if grid.plane_strain:
            raise ValueError("free faces need a 3D grid: a 2D line contact has no faces along y")
        self.grid, self.width = grid, float(width)
        self.youngs, self.nu = float(youngs_modulus), float(poissons_ratio)
        if _hat is not None:
            self.hat, self.fft_len = _hat, _fft_len
            return
        ny, nx = grid.shape
        half = self.width / 2
        if np.abs(grid.y).max() + grid.dy / 2 > half * (1 + 1e-9):
            raise ValueError(f"the grid reaches |y| = {np.abs(grid.y).max() + grid.dy / 2:.4g} mm, beyond the "
                             f"flat's faces at ±{half:.4g} mm")
        span_x = nx * grid.dx
        depth = min(self.width, 4 * max(grid.dy, span_x)) if depth is None else float(depth)
        reach = depth if reach is None else float(reach)
        self.depth, self.reach = depth, reach
        self.fft_len = sfft.next_fast_len(nx + 2 * int(np.ceil(reach / grid.dx)), real=True)
        self.hat = self._build(depth)

    # top rows: the grid's, then strips out to each face where the grid stops short of it
    def _top_rows(self) -> tuple[np.ndarray, np.ndarray, int]:
        g = self.grid
        lo = list(g.y - g.dy / 2)
        hi = list(g.y + g.dy / 2)
        half = self.width / 2
        top, bottom = hi[-1], lo[0]
        while top < half * (1 - 1e-9):
            lo.append(top)
            top = min(top + g.dy, half)
            hi.append(top)
        while bottom > -half * (1 - 1e-9):
            hi.insert(0, bottom)
            bottom = max(bottom - g.dy, -half)
            lo.insert(0, bottom)
        first = int(np.searchsorted(np.array(lo), g.y[0] - g.dy / 2 - 1e-12 * g.dy))
        return np.array(lo), np.array(hi), first

    def _build(self, depth: float) -> np.ndarray:
        g, nu, E = self.grid, self.nu, self.youngs
        ny = g.shape[0]
        L, half = self.fft_len, self.width / 2
        m = np.arange(L)
        ox = np.where(m <= L // 2, m, m - L) * g.dx  # periodic x offsets of a point from a loaded element
        ylo, yhi, first = self._top_rows()
        yc = (ylo + yhi) / 2
        zedges = face_depths(g.dx / 2, depth)
        zlo, zhi = zedges[:-1], zedges[1:]
        zc = (zlo + zhi) / 2
        nt, nz = yc.size, zc.size
        hx = g.dx / 2
        X = ox[:, None, None]

        # A: σ_yy at face points (x offset, depth z_f) from unit pressure on top elements (H0's frame)
        A = []
        for face in (1.0, -1.0):
            eta = face * half  # the face's y: the stress component along y is σ_ηη
            A.append(rect_integral(lambda xi, et, ze: sigma_tangential(xi, et, ze, nu),
                                   X, eta, zc[None, :, None], -hx, hx, ylo[None, None, :], yhi[None, None, :]))
        A = np.concatenate(A, axis=1)  # (L, 2nz, nt)
        # G, V: σ_zz and the displacement along z at top points from unit pressure on face elements, in the
        # frame of the face's half-space: depth = distance of the point from the face, η along z (into H0)
        G, V = [], []
        for face in (1.0, -1.0):
            dist = half - face * yc  # ≥ 0
            G.append(rect_integral(lambda xi, et, ze: sigma_tangential(xi, et, ze, nu),
                                   X, 0.0, dist[None, :, None], -hx, hx, zlo[None, None, :], zhi[None, None, :]))
            V.append(rect_integral(lambda xi, et, ze: u_tangential(xi, et, ze, nu, E),
                                   X, 0.0, dist[None, :, None], -hx, hx, zlo[None, None, :], zhi[None, None, :]))
        G = np.concatenate(G, axis=2)  # (L, nt, 2nz)
        V = np.concatenate(V, axis=2)
        # Q: σ_yy on one face from unit pressure on the other, W away (normal stress across planes parallel to
        # the loaded face)
        Qx = rect_integral(sigma_normal, X, zc[None, :, None], self.width, -hx, hx, zlo[None, None, :],
                           zhi[None, None, :])  # (L, nz, nz)
        Q = np.zeros((L, 2 * nz, 2 * nz))
        Q[:, :nz, nz:] = Qx
        Q[:, nz:, :nz] = Qx
        # U: the flat alone as a half-space (Love's rectangle, E/(1 − ν²)) between top rows of any width
        e1 = E / (1 - nu * nu)
        U = np.empty((L, nt, nt))
        for j in range(nt):
            b = (yhi[j] - ylo[j]) / 2
            U[:, :, j] = love_rectangle(X[:, :, 0], (yc - (ylo[j] + b))[None, :], hx, b, e1)
        Ah, Gh, Vh, Qh, Uh = (np.fft.rfft(a, axis=0) for a in (A, G, V, Q, U))
        eye = np.eye(2 * nz)
        # the faces' loads for a unit top pressure, then the top displacement they cause
        solve = np.linalg.solve(eye[None] - Ah @ Gh - Qh, Ah)  # (modes, 2nz, nt)
        full = (Uh @ Gh + Vh) @ solve  # (modes, nt, nt)
        rows = slice(first, first + ny)
        hat = full[:, rows, rows]
        # reciprocity: the finite body's compliance is symmetric; neglecting shear on the overlaps breaks that
        # slightly, so keep the symmetric part (the asymmetry is measured in the tests)
        self.asymmetry = float(np.abs(hat - np.conj(np.transpose(hat, (0, 2, 1)))).max() / np.abs(hat).max())
        return 0.5 * (hat + np.conj(np.transpose(hat, (0, 2, 1))))

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    def __call__(self, p: np.ndarray) -> np.ndarray:
        ny, nx = self.grid.shape
        ph = np.fft.rfft(np.reshape(p, (ny, nx)), n=self.fft_len, axis=1)  # (ny, modes)
        uh = np.einsum("kij,jk->ik", self.hat, ph)
        return np.fft.irfft(uh, n=self.fft_len, axis=1)[:, :nx]

    def kernel(self) -> np.ndarray:
        """K[m, i, j]: displacement of row i at x offset m·dx (periodic index) for unit pressure on row j."""
        return np.fft.irfft(self.hat, n=self.fft_len, axis=0)

    def dense(self) -> np.ndarray:
        ny, nx = self.grid.shape
        _check_dense(ny * nx)
        k = self.kernel()
        idx = (np.arange(nx)[:, None] - np.arange(nx)[None, :]) % self.fft_len  # (x, x')
        blocks = k[idx]  # (nx, nx, ny, ny)
        return np.transpose(blocks, (2, 0, 3, 1)).reshape(ny * nx, ny * nx)

    def restrict(self, rows: slice, cols: slice) -> "FreeFaces":
        sub = window_grid(self.grid, rows, cols)
        r = np.arange(self.grid.shape[0])[rows]
        return FreeFaces(sub, self.width, self.youngs, self.nu, _hat=self.hat[:, r][:, :, r],
                         _fft_len=self.fft_len)


def main() -> None:
    import time

    from study_free_faces_fe import CASE, SHORT, run_mccoll

    from fretsim.case import load_case
    from fretsim.plan import prepare

    case = load_case(CASE)
    grid = prepare(case)[0].grid
    ny, nx = grid.shape
    t = time.perf_counter()
    faces = FreeFaces(grid, ny * grid.dy, case.stationary.youngs_modulus, case.stationary.poissons_ratio)
    print(f"built in {time.perf_counter() - t:.1f} s (asymmetry before symmetrising {faces.asymmetry:.1e})")
    base = run_mccoll(None, grid.shape)
    for label, (_, steps, summ) in (("half-space flat", base),
                                     ("paper's free faces (prototype)", run_mccoll(faces.dense(), grid.shape))):
        p0 = steps[0].pressure[:, nx // 2]
        print(f"{label:<32}" + ", ".join(f"{SHORT[k]} {summ[k] / base[2][k] - 1:+.2%}" for k in SHORT)
              + f"; end/centre pressure at N = 0 {p0[-1] / p0[ny // 2]:.3f}")


if __name__ == "__main__":
    main()
