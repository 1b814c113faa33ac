"""The surface grid: Mx × My rectangular elements of size dx × dy (= 2a × 2b), values at element centres.

A 2D (plane-strain, line-contact) problem is a grid with one row of strips;
its loads and volumes are per unit length.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Grid:
    x: np.ndarray  # element centres along the sliding direction (mm), length Mx
    y: np.ndarray  # element centres across it (mm), length My; [0.] in 2D
    dx: float  # element length along x (mm) = 2a
    dy: float  # element width along y (mm) = 2b; 1 in 2D (per unit length)
    plane_strain: bool = False  # True: 2D line contact, one row of strips

    @classmethod
    def centred(cls, nx: int, ny: int, dx: float, dy: float, plane_strain: bool = False) -> "Grid":
        """A grid symmetric about x = 0 and y = 0."""
        if nx < 1 or ny < 1:
            raise ValueError(f"a grid needs at least one element each way, got {nx} x {ny}")
        if plane_strain and ny != 1:
            raise ValueError("a plane-strain (2D) grid has exactly one row")
        if not (dx > 0 and dy > 0):
            raise ValueError(f"element sizes must be positive, got {dx} x {dy}")
        x = (np.arange(nx) - (nx - 1) / 2.0) * dx
        y = np.zeros(1) if plane_strain else (np.arange(ny) - (ny - 1) / 2.0) * dy
        return cls(x=x, y=y, dx=float(dx), dy=float(1.0 if plane_strain else dy), plane_strain=plane_strain)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.y.size, self.x.size)

    @property
    def size(self) -> int:
        return self.x.size * self.y.size

    @property
    def area(self) -> float:
        """Area of one element (mm²); in 2D the length of one strip (mm), per unit length."""
        return self.dx * self.dy

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        return np.meshgrid(self.x, self.y)
