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
