"""Stresses under the contact: the plane-strain half-space under piecewise-constant normal and shear tractions.

Each element of the surface grid carries a uniform pressure p (compressive, ≥ 0) and a uniform shear traction q
(acting on this body along +x) over its strip [x_j − dx/2, x_j + dx/2].  The stresses at a point (x, z) below
the surface (z > 0 into the body, tension positive) are the integrals of Flamant's line-load solution over the
strips, which have closed forms.  With u = x − ξ and r² = u² + z², a unit normal line load at ξ gives

    σx = −(2/π)·u²z/r⁴,   σz = −(2/π)·z³/r⁴,   τxz = −(2/π)·u z²/r⁴,

and a unit shear line load along +x (Cerruti's 2D problem; ahead of it, u > 0, the surface is compressed)

    σx = −(2/π)·u³/r⁴,    σz = −(2/π)·u z²/r⁴,  τxz = −(2/π)·u²z/r⁴;

their antiderivatives in u (z fixed) are

    ∫u²z/r⁴ = ½·atan(u/z) − zu/(2r²),   ∫z³/r⁴ = ½·atan(u/z) + zu/(2r²),   ∫u z²/r⁴ = −z²/(2r²),
    ∫u³/r⁴ = ½·ln r² + z²/(2r²),

so a strip's stress is −(2/π)·(traction)·[F(x − ξ₁) − F(x − ξ₂)].  Plane strain adds σy = ν(σx + σz).  The
closed forms are checked against Hertz (the maximum shear 0.300 p₀ at 0.786 a), Smith & Liu's sliding cylinder
(+2μp₀ at the trailing edge) and a numerical quadrature of the line loads (tests/test_fatigue.py).

All functions take arrays and numbers: the element centres and size (mm), the tractions (MPa) and the points.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PlaneStress:
    """The in-plane stresses (MPa) at points (z, x): arrays of one shape."""

    sxx: np.ndarray
    szz: np.ndarray
    sxz: np.ndarray

    def syy(self, poisson: float) -> np.ndarray:
        """The out-of-plane stress of plane strain."""
        return poisson * (self.sxx + self.szz)

    def max_shear(self) -> np.ndarray:
        """The largest in-plane shear stress (the principal shear of the (x, z) plane)."""
        return np.hypot(0.5 * (self.sxx - self.szz), self.sxz)


def _normal_terms(u: np.ndarray, z: np.ndarray) -> tuple:
    """The antiderivatives of the normal line load's kernels (σx, σz, τxz) at u for depth z > 0."""
    r2 = u * u + z * z
    half_angle = 0.5 * np.arctan2(u, z)
    zu = z * u / (2.0 * r2)
    return half_angle - zu, half_angle + zu, -z * z / (2.0 * r2)


def _shear_terms(u: np.ndarray, z: np.ndarray) -> tuple:
    """The antiderivatives of the shear line load's kernels (σx, σz, τxz) at u for depth z > 0."""
    r2 = u * u + z * z
    z2 = z * z / (2.0 * r2)
    return 0.5 * np.log(r2) + z2, -z2, 0.5 * np.arctan2(u, z) - z * u / (2.0 * r2)


def strip_stresses(centres: np.ndarray, dx: float, pressure: np.ndarray, shear: np.ndarray, x: np.ndarray,
                   depths: np.ndarray) -> PlaneStress:
    """The stresses at every (depth, x) — arrays (len(depths), len(x)) — under the elements' uniform pressure and
    shear traction.  ``depths`` must be positive (the surface itself: a depth small against dx)."""
    depths = np.asarray(depths, dtype=float)
    if (depths <= 0).any():
        raise ValueError("the depths must be positive (below the surface); for the surface take a small depth")
    on = (np.asarray(pressure) != 0) | (np.asarray(shear) != 0)
    c, p, q = np.asarray(centres, float)[on], np.asarray(pressure, float)[on], np.asarray(shear, float)[on]
    u_lo = np.asarray(x, float)[:, None] - (c - 0.5 * dx)[None, :]  # x − ξ₁ (the strip's left edge)
    u_hi = u_lo - dx  # x − ξ₂
    out = [np.zeros((depths.size, np.size(x))) for _ in range(3)]
    for i, z in enumerate(depths):
        for terms, traction in ((_normal_terms, p), (_shear_terms, q)):
            lo, hi = terms(u_lo, z), terms(u_hi, z)
            for k in range(3):
                out[k][i] += (lo[k] - hi[k]) @ traction
    scale = -2.0 / np.pi
    return PlaneStress(scale * out[0], scale * out[1], scale * out[2])


def depth_grid(half_width: float, deepest: float, near: int = 12, total: int = 40) -> np.ndarray:
    """Depths (mm) from near the surface to ``deepest``, geometric so that the steep gradients under the contact's
    edges get most of them: ``total`` depths, the first at half_width/(10·near)."""
    first = half_width / (10.0 * near)
    return np.geomspace(first, max(deepest, 2 * first), total)
