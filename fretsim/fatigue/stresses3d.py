"""Stresses under a 3D contact: the elastic half-space under piecewise-constant pressure and shear tractions.

Why: fretting fatigue (issue 34) needs the stress history below a 3D contact, not only at the surface, and a
point contact's cracks start where plane strain (:mod:`.stresses`) cannot look — off the axis of sliding.

Method (a) of the issue: closed-form influence coefficients of one uniformly loaded rectangle, convolved over
the grid by zero-padded FFT (DC-FFT: the kernel is computed in space on the 2n − 1 offsets and padded, so there
is no periodic wrap-around) one depth layer at a time.

Each element (a rectangle |ξ − x_k| ≤ dx/2, |η − y_l| ≤ dy/2) carries a uniform pressure p (compressive, ≥ 0)
and uniform shear tractions q_x, q_y acting on this body.  z > 0 points into the body and tension is positive,
so at the surface σzz = −p, σxz = −q_x, σyz = −q_y.

The closed forms are derived here, from the Boussinesq–Cerruti potentials of Johnson's Contact Mechanics §3.2
(Love 1929 gave the pressure's rectangle; Liu & Wang 2002 tabulate both — neither was consulted for the code).
With Ω = z·ln(ρ + z) − ρ, ρ² = X² + Y² + z², the point-load fields are derivatives of Ω (the potentials with
H₁ = Ω for the pressure, F₁ = Ω for q_x).  A rectangle's field is Σ_corners s·F(X, Y, z)
where ∂X∂Y F is the point kernel, X = x − ξ_c, Y = y − η_c, and s = +1 at (x + a, y + b) and (x − a, y − b),
−1 at the other two corners.  Where a kernel has no ∂X (or ∂Y) to absorb the primitive, ∇²Ω = 0 trades ∂X² for
−∂Y² − ∂z²; functions of X alone or Y alone drop out of the corner sum.  The corner functions are

    K = −atan(XY/(zρ)),   B_Y = atan(XY(ρ − z)/(X²ρ + Y²z)),   B_X = atan(XY(ρ − z)/(Y²ρ + X²z)),
    L_Y = ln(Y + ρ),      L_X = ln(X + ρ),     and the derivatives of Ω and of L below,

and 2π times the stress per unit traction is, for the pressure

    σxx: 2νK − (1 − 2ν)B_Y − zX/(ρ(Y + ρ))        σxy: −(1 − 2ν)ln(ρ + z) − z/ρ
    σyy: 2νK − (1 − 2ν)B_X − zY/(ρ(X + ρ))        σxz: −z²/(ρ(Y + ρ))
    σzz: K + zX/(ρ(Y + ρ)) + zY/(ρ(X + ρ))        σyz: −z²/(ρ(X + ρ))

and for the shear q_x (q_y: the same with x and y exchanged)

    σxx: 2L_Y + 2νY/(ρ + z) + zY/(ρ(ρ + z)) + z²/(ρ(Y + ρ))     σxy: L_X − 2νX/(ρ + z) − zX/(ρ(ρ + z))
    σyy: 2νL_Y − 2νY/(ρ + z) − zY/(ρ(ρ + z))                     σxz: K − zX/(ρ(Y + ρ))
    σzz: −z²/(ρ(Y + ρ))                                           σyz: −z/ρ

They were derived with sympy (displacements from the potentials, Hooke's law, then the primitives:
``python scripts/derive_stresses3d.py`` redoes it); the point-load fields satisfy equilibrium, a free surface
away from the load and the force's resultant, and equal Boussinesq's and Cerruti's stresses (Johnson ch. 3).
tests/test_fatigue_3d.py checks the rectangle against a quadrature of those point loads, the FFT against a
direct sum, Hertz (Johnson §3.4) and the sliding sphere against quadratures over Hamilton's tractions.
Y + ρ and ρ − z are evaluated in forms free of cancellation: (ρ − Y)/(X² + z²) for 1/(Y + ρ) when Y < 0,
(X² + Y²)/(ρ + z) for ρ − z.

Cost, seconds per depth layer (the kernels, their FFTs, the products and the six inverse FFTs; the tractions'
FFTs are paid once per call), one thread, numpy 2.4 / scipy 1.17 on a shared 2-core machine, minimum of 9
(``python scripts/bench_stresses3d.py``, which writes scripts/results/stresses3d_cost.txt)::

    grid nx × ny   padded FFT   loaded        s/layer
    427 × 27       864 × 54     p, q_x        0.025
    427 × 27       864 × 54     p, q_x, q_y   0.032
    128 × 128      256 × 256    p, q_x        0.032
    128 × 128      256 × 256    p, q_x, q_y   0.061

so 40 depths on the 427 × 27 grid cost about a second per stress state; the kernels (transcendental functions on
the 2n × 2n edges) are about half of it.

All lengths in mm, tractions and stresses in MPa; the grid's arrays are shaped (ny, nx) as in
:mod:`fretsim.compliance`.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

COMPONENTS = ("sxx", "syy", "szz", "sxy", "sxz", "syz")
# the q_y problem is the q_x one with x and y exchanged: its component k is the q_x component SWAP[k]
SWAP = (1, 0, 2, 3, 5, 4)


@dataclass(frozen=True)
class Stress3D:
    """The six stress components (MPa), arrays of one shape (depth, y, x)."""

    sxx: np.ndarray
    syy: np.ndarray
    szz: np.ndarray
    sxy: np.ndarray
    sxz: np.ndarray
    syz: np.ndarray

    def tensor(self) -> np.ndarray:
        """The stress tensors, shape (..., 3, 3)."""
        rows = ((self.sxx, self.sxy, self.sxz), (self.sxy, self.syy, self.syz), (self.sxz, self.syz, self.szz))
        return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)

    def principal(self) -> np.ndarray:
        """The principal stresses, ascending, shape (..., 3)."""
        return np.linalg.eigvalsh(self.tensor())

    def max_shear(self) -> np.ndarray:
        """The largest principal shear stress (σ₁ − σ₃)/2 (Tresca's)."""
        s = self.principal()
        return 0.5 * (s[..., 2] - s[..., 0])

    def von_mises(self) -> np.ndarray:
        d = (self.sxx - self.syy) ** 2 + (self.syy - self.szz) ** 2 + (self.szz - self.sxx) ** 2
        return np.sqrt(0.5 * d + 3.0 * (self.sxy ** 2 + self.sxz ** 2 + self.syz ** 2))


def _corner_functions(X: np.ndarray, Y: np.ndarray, z: float, nu: float) -> np.ndarray:
    """2π × the corner functions of the pressure and of q_x at corner offsets (X, Y): shape (2, 6, *X.shape)."""
    X, Y = np.broadcast_arrays(np.asarray(X, float), np.asarray(Y, float))
    x2, y2, z2 = X * X, Y * Y, z * z
    rho = np.sqrt(x2 + y2 + z2)
    rz = rho + z
    rmz = (x2 + y2) / rz  # ρ − z without cancellation when z ≫ |X|, |Y|
    # 1/(Y + ρ) and ln(Y + ρ): for Y < 0 through ρ − Y, since (Y + ρ)(ρ − Y) = X² + z²
    with np.errstate(divide="ignore"):  # np.where evaluates the branch it then discards
        inv_y = np.where(Y >= 0, 1.0 / (Y + rho), (rho - Y) / (x2 + z2))
        inv_x = np.where(X >= 0, 1.0 / (X + rho), (rho - X) / (y2 + z2))
        log_y = np.where(Y >= 0, np.log(Y + rho), np.log(x2 + z2) - np.log(rho - Y))
        log_x = np.where(X >= 0, np.log(X + rho), np.log(y2 + z2) - np.log(rho - X))
    k = -np.arctan2(X * Y, z * rho)
    # arctan2 with a denominator ≥ 0 is atan of the ratio, and 0 (the limit) on a corner's own vertical
    b_y = np.arctan2(X * Y * rmz, x2 * rho + y2 * z)
    b_x = np.arctan2(X * Y * rmz, y2 * rho + x2 * z)
    lx10, ly10 = Y * inv_x / rho, X * inv_y / rho
    lx01, ly01 = z * inv_x / rho, z * inv_y / rho
    c = 1.0 - 2.0 * nu
    pressure = (2 * nu * k - c * b_y - z * ly10, 2 * nu * k - c * b_x - z * lx10, k + z * (ly10 + lx10),
                -c * np.log(rz) - z / rho, -z * ly01, -z * lx01)
    shear = (2 * log_y + 2 * nu * Y / rz + z * Y / (rho * rz) + z * ly01,
             2 * nu * log_y - 2 * nu * Y / rz - z * Y / (rho * rz),
             -z * ly01,
             log_x - 2 * nu * X / rz - z * X / (rho * rz),
             k - z * ly10,
             -z / rho)
    return np.array([pressure, shear])


def _corner_sum(f: np.ndarray) -> np.ndarray:
    """Σ s·F over the four corners of every rectangle, for F on a grid of edges (rows: y edges, columns: x)."""
    return f[..., 1:, 1:] - f[..., :-1, 1:] - f[..., 1:, :-1] + f[..., :-1, :-1]


def _three_loads(corners_xy: np.ndarray, corners_yx: np.ndarray) -> np.ndarray:
    """(pressure, q_x, q_y) × six components from the corner functions at (X, Y) and at (Y, X) (÷ 2π)."""
    qy = np.stack([corners_yx[1, k] for k in SWAP])  # q_y: the q_x problem mirrored in the plane x = y
    return np.concatenate([corners_xy, qy[None]], axis=0) / (2.0 * np.pi)


def rectangle_stresses(x, y, z: float, a: float, b: float, poisson: float) -> np.ndarray:
    """The stresses at points (x, y, z) (mm, relative to the rectangle's centre) under unit traction on the
    rectangle |ξ| ≤ a, |η| ≤ b: shape (3, 6, *shape) — loads (pressure, q_x, q_y) × components (σxx, σyy, σzz,
    σxy, σxz, σyz).  Four corner evaluations per point; the convolution builds the same numbers on a grid of
    edges instead."""
    if not z > 0:
        raise ValueError(f"the depth must be positive (below the surface), got {z}")
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    out = 0.0
    for sx, sy, sign in ((a, b, 1.0), (a, -b, -1.0), (-a, b, -1.0), (-a, -b, 1.0)):
        X, Y = x + sx, y + sy
        out = out + sign * _three_loads(_corner_functions(X, Y, z, poisson), _corner_functions(Y, X, z, poisson))
    return out


def influence_kernels(nx: int, ny: int, dx: float, dy: float, z: float, poisson: float,
                      loads=(True, True, True)) -> np.ndarray:
    """The rectangle's stresses at every offset between two elements, shape (3, 6, 2ny − 1, 2nx − 1): element
    offset (j − (ny − 1))·dy, (i − (nx − 1))·dx at [.., j, i] (the layout of :class:`~fretsim.compliance.operator
    .Convolution`).  The corner functions are evaluated once on the 2n edges each way and differenced.  Loads
    flagged False get zeros (not computed)."""
    if not z > 0:
        raise ValueError(f"the depth must be positive (below the surface), got {z}")
    ex = (np.arange(2 * nx) - nx + 0.5) * dx  # offsets of the element edges from a field point's centre
    ey = (np.arange(2 * ny) - ny + 0.5) * dy
    X, Y = np.meshgrid(ex, ey)
    out = np.zeros((3, 6, 2 * ny - 1, 2 * nx - 1))
    if loads[0] or loads[1]:
        out[:2] = _corner_sum(_corner_functions(X, Y, z, poisson)) / (2.0 * np.pi)
    if loads[2]:
        swapped = _corner_sum(_corner_functions(Y, X, z, poisson)[1]) / (2.0 * np.pi)
        out[2] = swapped[list(SWAP)]
    return out


def _wrapped_transform(kernels: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """The kernels (..., 2ny − 1, 2nx − 1) placed on the padded grid with offset 0 at [0, 0], transformed."""
    from fretsim.compliance import fft
    ly, lx = shape
    ny, nx = (kernels.shape[-2] + 1) // 2, (kernels.shape[-1] + 1) // 2
    wrapped = np.zeros(kernels.shape[:-2] + shape)
    iy = (np.arange(2 * ny - 1) - (ny - 1)) % ly
    ix = (np.arange(2 * nx - 1) - (nx - 1)) % lx
    wrapped[..., iy[:, None], ix[None, :]] = kernels
    return fft.forward(wrapped, shape)  # (rfft along x, then fft along y: rfft2's)


def half_space_stresses(x: np.ndarray, y: np.ndarray, dx: float, dy: float, pressure: np.ndarray,
                        shear_x: np.ndarray, shear_y: np.ndarray, depths: np.ndarray, poisson: float) -> Stress3D:
    """The stresses (MPa) at the element centres (x, y) at each depth: each component shaped (len(depths), ny,
    nx), under the elements' uniform pressure and shear tractions (MPa, arrays (ny, nx)).  ``x`` and ``y`` are
    the element centres (mm; uniform steps dx, dy); ``depths`` must be positive — for the surface itself take a
    depth small against the elements (the fields are continuous there away from the element edges)."""
    from fretsim.compliance import fft
    x, y = np.asarray(x, float), np.asarray(y, float)
    ny, nx = y.size, x.size
    tractions = [np.zeros((ny, nx)) if t is None else np.asarray(t, float) for t in (pressure, shear_x, shear_y)]
    _check(x, y, dx, dy, tractions, depths)
    depths = np.atleast_1d(np.asarray(depths, float))
    loads = tuple(bool(np.any(t != 0)) for t in tractions)
    # linear (non-periodic) convolution needs at least 2n − 1 points per axis
    shape = (fft.next_fast_len(2 * ny - 1, real=False), fft.next_fast_len(2 * nx - 1, real=True))
    hats = [fft.forward(t, shape) if on else None for t, on in zip(tractions, loads)]
    out = np.zeros((6, depths.size, ny, nx))
    if not any(loads):
        return Stress3D(*out)
    on = [m for m in range(3) if loads[m]]
    for d, z in enumerate(depths):
        kernel_hat = _wrapped_transform(influence_kernels(nx, ny, dx, dy, z, poisson, loads)[on], shape)
        for k in range(6):
            # the loads add in Fourier space: one inverse transform per component
            total = sum(kernel_hat[i, k] * hats[m] for i, m in enumerate(on))
            out[k, d] = fft.backward(total, shape, (ny, nx))
    return Stress3D(*out)


def _check(x, y, dx, dy, tractions, depths) -> None:
    ny, nx = y.size, x.size
    for t in tractions:
        if t.shape != (ny, nx):
            raise ValueError(f"tractions must be shaped (ny, nx) = {(ny, nx)}, got {t.shape}")
    if not (dx > 0 and dy > 0):
        raise ValueError(f"element sizes must be positive, got {dx} x {dy}")
    for centres, step in ((x, dx), (y, dy)):
        if centres.size > 1 and not np.allclose(np.diff(centres), step, rtol=1e-9, atol=0):
            raise ValueError("the element centres must be uniformly spaced by dx (x) and dy (y)")
    if (np.asarray(depths) <= 0).any():
        raise ValueError("the depths must be positive (below the surface); for the surface take a small depth")
    if (np.asarray(tractions[0]) < 0).any():
        raise ValueError("the pressure must be non-negative (compressive)")


@lru_cache(maxsize=64)
def _layer_hats(nx: int, ny: int, dx: float, dy: float, z: float, poisson: float, shape: tuple) -> np.ndarray:
    """The pressure's and q_x's kernels at one depth, transformed on the padded ``shape``: (2, 6, ly, lx // 2 + 1).
    Cached: a run's fatigue states mostly share a window's size, and the kernels are half a layer's cost."""
    return _wrapped_transform(influence_kernels(nx, ny, dx, dy, z, poisson, (True, True, False))[:2], shape)


def stress_history(pressure: np.ndarray, shear_x: np.ndarray, dx: float, dy: float, depths: np.ndarray,
                   poisson: float, single: bool = False) -> np.ndarray:
    """The six stresses at every (state, depth, y, x) under each state's pressure and shear along x (arrays (state,
    ny, nx) on a uniform grid): shape (6, state, depth, ny, nx) in :data:`COMPONENTS`' order.  The cycle's states
    at once: each depth's kernels are made (or found) once for all of them — a fatigue state's dozen states would
    otherwise pay the kernels a dozen times.  ``single``: the transforms and the result in single precision (a
    fatigue state between recorded ones, whose search's first pass is single anyway)."""
    from fretsim.compliance import fft
    pressure, shear_x = np.asarray(pressure, float), np.asarray(shear_x, float)
    states, ny, nx = pressure.shape
    depths = np.atleast_1d(np.asarray(depths, float))
    if (depths <= 0).any():
        raise ValueError("the depths must be positive (below the surface); for the surface take a small depth")
    shape = (fft.next_fast_len(2 * ny - 1, real=False), fft.next_fast_len(2 * nx - 1, real=True))
    # (the solver's transforms: x on the loaded rows only, and back y first, then x on the rows kept — irfft2 did x
    # on every padded row and cropped after, 2.5x the time)
    real = np.float32 if single else np.float64
    p_hat = fft.forward(pressure.astype(real), shape)[:, None]  # (state, 1, ly, lx')
    q_hat = fft.forward(shear_x.astype(real), shape)[:, None]
    out = np.empty((6, states, depths.size, ny, nx), dtype=real)
    for d, z in enumerate(depths):
        k = _layer_hats(nx, ny, float(dx), float(dy), float(z), float(poisson), shape)
        if single:
            k = k.astype(np.complex64)
        field = fft.backward(p_hat * k[0][None] + q_hat * k[1][None], shape, (ny, nx))  # (state, 6, ny, nx)
        out[:, :, d] = np.moveaxis(field, 1, 0)
    return out
