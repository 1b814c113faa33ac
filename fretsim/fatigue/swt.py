"""Multiaxial fatigue on the critical plane: the Smith–Watson–Topper parameter, its life from the
Basquin–Coffin–Manson curve, and Ruiz's fretting damage parameter.

SWT on a plane of normal n over a cycle is σ_n,max·Δε_n/2: the largest normal stress on the plane times half the
range of its normal strain.  The critical plane is the one where it is largest; in plane strain (2D) the normals
are searched over angles in the (x, z) plane.  The life N_i (cycles to crack initiation) solves

    SWT = (σ'_f²/E)·(2N)^(2b) + σ'_f·ε'_f·(2N)^(b+c),

monotone in N for b, c < 0, by bisection on log N.  Ruiz's parameter σ_t·τ·δ (the surface's largest tensile
stress, its shear traction and its slip, MPa·MPa·mm) is the cheap companion fretting designers quote beside it.

Pure functions over arrays: stresses in MPa, strains dimensionless, moduli in MPa.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

ANGLES = 180  # plane normals searched in 2D: every degree (the parameter is π-periodic in the angle)


@dataclass(frozen=True)
class Basquin:
    """The strain-life curve's constants (``materials.<body>.fatigue``)."""

    strength_coefficient: float  # σ'_f, MPa
    strength_exponent: float  # b (< 0)
    ductility_coefficient: float  # ε'_f
    ductility_exponent: float  # c (< 0)
    youngs_modulus: float  # E, MPa
    endurance_limit: Optional[float] = None  # an SWT below it never cracks (MPa); None: the curve alone

    def swt(self, cycles: float) -> float:
        """The SWT value (MPa) that cracks in ``cycles``."""
        two_n = 2.0 * cycles
        f, b = self.strength_coefficient, self.strength_exponent
        return f * f / self.youngs_modulus * two_n ** (2 * b) + f * self.ductility_coefficient * two_n ** (
            b + self.ductility_exponent)

    def life(self, swt: float, longest: float = 1e30) -> float:
        """Cycles to crack initiation at ``swt`` (MPa); inf below the endurance limit or beyond ``longest``."""
        if not swt > 0 or (self.endurance_limit is not None and swt <= self.endurance_limit):
            return math.inf
        if swt <= self.swt(longest):
            return math.inf
        lo, hi = 0.25, longest  # swt(lo) is above any SWT that matters (a quarter of a reversal)
        if swt >= self.swt(lo):
            return lo
        for _ in range(200):
            mid = math.sqrt(lo * hi)
            if self.swt(mid) > swt:
                lo = mid
            else:
                hi = mid
            if hi / lo < 1 + 1e-12:
                break
        return math.sqrt(lo * hi)


def plane_strain_strains(sxx, szz, sxz, youngs: float, poisson: float) -> tuple:
    """(ε_x, ε_z, γ_xz) of plane strain (ε_y = 0) from the in-plane stresses."""
    k = (1.0 + poisson) / youngs
    return (k * ((1.0 - poisson) * sxx - poisson * szz), k * ((1.0 - poisson) * szz - poisson * sxx),
            2.0 * k * sxz)


@dataclass(frozen=True)
class CriticalPlane:
    """The SWT parameter at each point on its critical plane: value (MPa) and the plane's normal angle from x
    (radians, in [0, π))."""

    swt: np.ndarray
    angle: np.ndarray


def swt_2d(history: tuple, youngs: float, poisson: float, angles: int = ANGLES) -> CriticalPlane:
    """SWT on the critical plane at each point from the stresses over a cycle: ``history`` = (σx, σz, τxz), each
    an array (time, ...) of the cycle's states.  Plane strain."""
    sxx, szz, sxz = (np.asarray(a, dtype=float) for a in history)
    exx, ezz, gxz = plane_strain_strains(sxx, szz, sxz, youngs, poisson)
    best = np.full(sxx.shape[1:], -np.inf)
    where = np.zeros(sxx.shape[1:])
    for phi in np.arange(angles) * (np.pi / angles):
        c, s = math.cos(phi), math.sin(phi)
        sn = sxx * c * c + szz * s * s + 2.0 * sxz * s * c
        en = exx * c * c + ezz * s * s + gxz * s * c
        value = np.maximum(sn.max(axis=0), 0.0) * 0.5 * (en.max(axis=0) - en.min(axis=0))
        better = value > best
        best = np.where(better, value, best)
        where = np.where(better, phi, where)
    return CriticalPlane(best, where)


def ruiz(tensile: np.ndarray, shear: np.ndarray, slip: np.ndarray) -> np.ndarray:
    """Ruiz's fretting damage parameter σ_t·τ·δ at each surface point (MPa²·mm): the largest tensile surface
    stress over the cycle (compression counts 0), the shear traction's amplitude and the slip amplitude."""
    return np.maximum(tensile, 0.0) * np.abs(shear) * np.abs(slip)
