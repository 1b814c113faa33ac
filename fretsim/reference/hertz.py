"""Hertz's solutions for a sphere and a cylinder pressed on a flat (Johnson, Contact Mechanics, ch. 4).

All inputs and outputs in the internal mm–N–MPa system.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def effective_modulus(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """Plane-strain contact modulus E* with 1/E* = (1-ν1²)/E1 + (1-ν2²)/E2."""
    for e, nu in ((e1, nu1), (e2, nu2)):
        if not e > 0:
            raise ValueError(f"Young's modulus must be positive, got {e}")
        if not -1.0 < nu < 0.5:
            raise ValueError(f"Poisson's ratio must lie in (-1, 0.5), got {nu}")
    return 1.0 / ((1 - nu1**2) / e1 + (1 - nu2**2) / e2)


@dataclass(frozen=True)
class HertzPoint:
    """Sphere of radius R on a flat under load P."""

    radius: float  # contact radius a (mm)
    peak_pressure: float  # p0 (MPa)
    approach: float  # rigid-body approach d = a²/R (mm)

    def pressure(self, r: np.ndarray) -> np.ndarray:
        r = np.asarray(r, dtype=float)
        return self.peak_pressure * np.sqrt(np.clip(1.0 - (r / self.radius) ** 2, 0.0, None))


@dataclass(frozen=True)
class HertzLine:
    """Cylinder of radius R on a flat under a load per unit length P' (plane strain).

    The approach of a 2D half-space is not defined (the displacement grows
    logarithmically with distance), so none is given.
    """

    half_width: float  # a (mm)
    peak_pressure: float  # p0 (MPa)

    def pressure(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return self.peak_pressure * np.sqrt(np.clip(1.0 - (x / self.half_width) ** 2, 0.0, None))


def hertz_point(load: float, radius: float, e_star: float) -> HertzPoint:
    """a = (3PR/4E*)^(1/3), p0 = 3P/(2πa²), d = a²/R."""
    _positive(load=load, radius=radius, e_star=e_star)
    a = (3.0 * load * radius / (4.0 * e_star)) ** (1.0 / 3.0)
    return HertzPoint(radius=a, peak_pressure=3.0 * load / (2.0 * math.pi * a * a), approach=a * a / radius)


def hertz_line(load_per_length: float, radius: float, e_star: float) -> HertzLine:
    """a = √(4P'R/πE*), p0 = 2P'/(πa)."""
    _positive(load_per_length=load_per_length, radius=radius, e_star=e_star)
    a = math.sqrt(4.0 * load_per_length * radius / (math.pi * e_star))
    return HertzLine(half_width=a, peak_pressure=2.0 * load_per_length / (math.pi * a))


def _positive(**values: float) -> None:
    for name, v in values.items():
        if not (v > 0 and math.isfinite(v)):
            raise ValueError(f"{name} must be positive and finite, got {v}")


@dataclass(frozen=True)
class HertzElliptical:
    """Two bodies of relative principal radii Rx (along x) and Ry (along y) under load P (Johnson §4.2).

    The contact is an ellipse with semi-axes ``ax`` along x and ``ay`` along y; p = p0 √(1 − x²/ax² − y²/ay²).
    """

    ax: float  # mm
    ay: float  # mm
    peak_pressure: float  # MPa
    approach: float  # mm

    def pressure(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        r2 = (np.asarray(x, float) / self.ax) ** 2 + (np.asarray(y, float) / self.ay) ** 2
        return self.peak_pressure * np.sqrt(np.clip(1.0 - r2, 0.0, None))


def hertz_elliptical(load: float, radius_x: float, radius_y: float, e_star: float) -> HertzElliptical:
    """Hertz's elliptical contact for the gap x²/(2Rx) + y²/(2Ry).

    With semi-axes a ≥ b (a along the direction of smaller curvature), e² = 1 − b²/a², and K, E the complete
    elliptic integrals of modulus e:  B/A = ((a²/b²)E − K)/(K − E) fixes e,  A = 3P(K − E)/(2πE* e² a³)
    fixes a,  P = (2/3)πab·p0 and the approach δ = p0·b·K/E*.
    """
    _positive(load=load, radius_x=radius_x, radius_y=radius_y, e_star=e_star)
    curv_x, curv_y = 1.0 / (2.0 * radius_x), 1.0 / (2.0 * radius_y)
    small, big = min(curv_x, curv_y), max(curv_x, curv_y)
    if big / small - 1.0 < 1e-9:  # a circle: the ball formulas with the mean radius
        h = hertz_point(load, 2.0 / (curv_x + curv_y) / 2.0, e_star)
        return HertzElliptical(h.radius, h.radius, h.peak_pressure, h.approach)
    from scipy.special import ellipe, ellipk

    def mismatch(m: float) -> float:  # m = e²; B/A rises from 1 (m → 0) without bound (m → 1)
        k_, e_ = ellipk(m), ellipe(m)
        return (e_ / (1.0 - m) - k_) / (k_ - e_) - big / small

    # bisection, not scipy.optimize's brentq: the root is bracketed and the function monotone, and importing
    # scipy.optimize cost a point contact's run 0.13 s of start-up (a sweep starts thousands)
    lo, hi = 1e-10, 1.0 - 1e-15
    while True:
        m = 0.5 * (lo + hi)
        if not lo < m < hi:
            break
        lo, hi = (m, hi) if mismatch(m) < 0.0 else (lo, m)
    k_, e_ = ellipk(m), ellipe(m)
    a = (3.0 * load * (k_ - e_) / (2.0 * math.pi * e_star * m * small)) ** (1.0 / 3.0)
    b = math.sqrt(1.0 - m) * a
    p0 = 3.0 * load / (2.0 * math.pi * a * b)
    approach = p0 * b * k_ / e_star
    # the major axis a lies along the direction of the smaller curvature
    ax, ay = (a, b) if curv_x <= curv_y else (b, a)
    return HertzElliptical(ax, ay, p0, approach)
