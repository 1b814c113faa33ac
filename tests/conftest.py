import numpy as np
import pytest

from fretsim.compliance import HalfSpace
from fretsim.grid import Grid
from fretsim.reference import effective_modulus

# The paper's steel pair: E = 200 GPa, ν = 0.3 on both bodies (internal units: MPa).
E_STAR = effective_modulus(2.0e5, 0.3, 2.0e5, 0.3)


def ball_problem(n: int, radius=6.0, half_width=None, a_hertz=0.19637):
    """Ball on flat on an n × n grid spanning ±1.5 a (a = Hertz radius of the 185 N, R = 6 mm ball)."""
    half_width = half_width or 1.5 * a_hertz
    grid = Grid.centred(n, n, 2 * half_width / n, 2 * half_width / n)
    X, Y = grid.mesh()
    return HalfSpace(grid, E_STAR), (X**2 + Y**2) / (2 * radius)


def cylinder_problem(nx: int, ny: int, radius=6.0, length=10.0, half_width=0.126):
    """Finite cylinder on flat: the grid spans the cylinder's length and ±half_width along x."""
    grid = Grid.centred(nx, ny, 2 * half_width / nx, length / ny)
    X, _ = grid.mesh()
    return HalfSpace(grid, E_STAR), X**2 / (2 * radius)


def line_problem(nx: int, radius=6.0, half_width=0.126):
    grid = Grid.centred(nx, 1, 2 * half_width / nx, 1.0, plane_strain=True)
    return HalfSpace(grid, E_STAR), (grid.x**2 / (2 * radius))[None, :]


@pytest.fixture
def e_star():
    return E_STAR
