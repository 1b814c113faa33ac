"""Tangential influence operators: the surface slip-direction displacement due to element shear tractions.

3D: Cerruti's point-force solution integrated over a rectangle of uniform shear q along x (Johnson eq. 3.86a at
z = 0): u_x = q(1 + ν)/(πE)·∬ [(1 − ν)/r + ν x²/r³] dA.  Both integrals are closed: ∬ dA/r is Love's (the
normal kernel's, :mod:`.halfspace`) and ∬ x²/r³ dA = Σ corners Y·asinh(X/|Y|).  Both bodies add, each with its
own E and ν; since Σ(1 − ν²)/E = 1/E*, the combined operator is the normal one plus Σ ν(1 + ν)/(πE)·∬x²/r³.
Only the x-component is kept (the slip direction): the y-displacement that q_x also causes (∝ νxy/r³, odd in
both x and y) is neglected, as in Mindlin's solution.

2D (plane strain): a shear strip moves the surface like a pressure strip moves it normally, u_x =
−(2(1 − ν²)/πE)·[(x + a)ln|x + a| − (x − a)ln|x − a|] + C (Johnson eq. 2.19b integrated).  A half-plane's
displacement is defined only up to that constant, which the normal problem hides in the approach but the
tangential one cannot: it sets how much of the stroke the bodies take up elastically.  fretsim measures it
from a datum at distance d = 2L·exp(ν/(1 − ν) − 1) from the load, L the contact's length: there the 2D
displacement equals the mean displacement of the 3D half-space under a uniform line load of length L (the
3D kernel integrated along the line and averaged over it: (2(1 − ν²)/πE)·[ln(2L/|x|) − 1 + ν/(1 − ν)]), so that
the 2D model of a line contact takes up the stroke as its 3D model does (tests compare them on a long cylinder).

The rig's own tangential compliance 1/k (a test machine, a support) takes Q/k of the stroke: with Q = Σ q·A it
is a constant kernel A/k between every pair of elements, added like the datum's constant.

All operators are :class:`~fretsim.compliance.operator.Convolution` s on the normal grid; lengths in mm,
tractions in MPa, displacements in mm.
"""
from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from fretsim.compliance.halfspace import love_rectangle, strip_plane_strain
from fretsim.compliance.operator import Convolution
from fretsim.grid import Grid


def cerruti_xx_integral(x: np.ndarray, y: np.ndarray, a: float, b: float) -> np.ndarray:
    """∬ (x − ξ)²/r³ dξdη over the rectangle |ξ| ≤ a, |η| ≤ b, at the surface point (x, y) (mm).

    The corner function Y·asinh(X/|Y|) has ∂²/∂X∂Y = X²/r³; asinh keeps it accurate far from the rectangle.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)

    def corner(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(Y == 0.0, 0.0, Y * np.arcsinh(X / np.abs(Y)))

    return corner(x + a, y + b) - corner(x + a, y - b) - corner(x - a, y + b) + corner(x - a, y - b)


def cerruti_rectangle(x: np.ndarray, y: np.ndarray, a: float, b: float, youngs_modulus: float,
                      poissons_ratio: float) -> np.ndarray:
    """u_x at (x, y) of one half-space (E, ν) under unit shear along x on the rectangle |x| ≤ a, |y| ≤ b."""
    nu = poissons_ratio
    # love_rectangle(…, e_star) is ∬dA/r divided by π·e_star: pass e_star = 1 to get the integral times 1/π
    ones = love_rectangle(x, y, a, b, 1.0) * math.pi
    return (1.0 + nu) / (math.pi * youngs_modulus) * ((1.0 - nu) * ones + nu * cerruti_xx_integral(x, y, a, b))


def datum_distance(length: float, poissons_ratio: float) -> float:
    """The distance (mm) of the 2D datum at which a line contact of length L takes up the stroke as in 3D."""
    nu = poissons_ratio
    return 2.0 * length * math.exp(nu / (1.0 - nu) - 1.0)


def tangential_kernel(grid: Grid, bodies: Sequence[tuple[float, float]], line_length: Optional[float] = None,
                      rig_compliance: float = 0.0, log_datums: Optional[Sequence[Optional[float]]] = None) -> np.ndarray:
    """Kernel (shape (2My − 1, 2Mx − 1)) of u_x per unit shear traction on one element, both bodies.

    ``bodies``: (E, ν) of each body (MPa).  2D needs ``line_length`` (the datum's L).  ``rig_compliance``: the
    displacement per unit traction on one element that the rig adds (A/k in 3D, L·dx/k in 2D), mm/MPa.
    ``log_datums``: per body, ln of the datum distance (mm) of a finite body held at a face (:mod:`.bodies`), or
    None for the half-space's; in 3D (a line contact of length L) a finite body's datum d adds (2/πE'L)·ln(d/d_L)
    per unit force, d_L the half-space's 2D datum, times the element's area.
    """
    ny, nx = grid.shape
    ox = (np.arange(2 * nx - 1) - (nx - 1)) * grid.dx
    log_datums = tuple(log_datums) if log_datums is not None else (None,) * len(bodies)
    if grid.plane_strain:
        if line_length is None:
            raise ValueError("a 2D tangential operator needs the contact length for its datum")
        kernel = np.zeros((1, 2 * nx - 1))
        for (e, nu), log_d in zip(bodies, log_datums):
            e_body = e / (1.0 - nu * nu)  # this body's share of 1/E*
            log_d = log_d if log_d is not None else math.log(datum_distance(line_length, nu))
            # the strip kernel is referred to ln(1 mm) = 0; far away it is −(2/πE)·dx·(ln|x| + 1): refer it to d
            kernel += strip_plane_strain(ox, grid.dx / 2.0, e_body)[None, :]
            kernel += 2.0 / (math.pi * e_body) * grid.dx * (log_d + 1.0)
    else:
        oy = (np.arange(2 * ny - 1) - (ny - 1)) * grid.dy
        X, Y = np.meshgrid(ox, oy)
        kernel = sum(cerruti_rectangle(X, Y, grid.dx / 2.0, grid.dy / 2.0, e, nu) for e, nu in bodies)
        for (e, nu), log_d in zip(bodies, log_datums):
            if log_d is not None:
                if line_length is None:
                    raise ValueError("a finite body's datum in 3D needs a line contact's length")
                e_body = e / (1.0 - nu * nu)
                kernel = kernel + grid.area * 2.0 / (math.pi * e_body * line_length) * (
                    log_d - math.log(datum_distance(line_length, nu)))
    return kernel + rig_compliance


class Tangential(Convolution):
    """Both bodies' tangential compliance (and the rig's) on the normal grid: u_x = K q."""

    def __init__(self, grid: Grid, bodies: Sequence[tuple[float, float]], line_length: Optional[float] = None,
                 rig_compliance: float = 0.0, _kernel: Optional[np.ndarray] = None,
                 log_datums: Optional[Sequence[Optional[float]]] = None):
        self.bodies = tuple((float(e), float(nu)) for e, nu in bodies)
        self.line_length = line_length
        self.rig_compliance = float(rig_compliance)
        self.log_datums = tuple(log_datums) if log_datums is not None else (None,) * len(self.bodies)
        super().__init__(grid, tangential_kernel(grid, self.bodies, line_length, rig_compliance, self.log_datums)
                         if _kernel is None else _kernel)

    def _like(self, grid: Grid, kernel: np.ndarray) -> "Tangential":
        return Tangential(grid, self.bodies, self.line_length, self.rig_compliance, kernel, self.log_datums)
