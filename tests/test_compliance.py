"""The influence operators: closed forms, symmetry, and FFT against the dense matrix."""
import numpy as np
import pytest

from fretsim.compliance import Compliance, love_rectangle, strip_plane_strain
from fretsim.grid import Grid

ROUND_OFF = 1e-12  # FFT vs direct summation: both exact up to floating point


def test_love_centre_of_square_matches_closed_form():
    # centre of a uniformly loaded square of side 2a: w = (8/π) asinh(1) a p / E*  (Johnson §3.4)
    assert love_rectangle(0.0, 0.0, 1.0, 1.0, 1.0) == pytest.approx(8 * np.arcsinh(1) / np.pi, rel=1e-14)


def test_love_far_field_tends_to_point_load():
    # far from the element the rectangle acts as a point force 4ab·p: w = 4ab/(π E* r)
    r = 50.0
    assert love_rectangle(r, 0.0, 0.5, 0.5, 1.0) == pytest.approx(1.0 / (np.pi * r), rel=1e-4)


def test_plane_strain_strip_gradient_matches_line_load_far_away():
    # dw/dx of a line load P' is -2P'/(π E* x); a strip of width 2a carries P' = 2a·p
    x, h, a = 40.0, 1e-4, 0.5
    slope = (strip_plane_strain(x + h, a, 1.0) - strip_plane_strain(x - h, a, 1.0)) / (2 * h)
    assert slope == pytest.approx(-2 * (2 * a) / (np.pi * x), rel=1e-3)


@pytest.mark.parametrize("grid", [Grid.centred(9, 6, 0.1, 0.3), Grid.centred(11, 1, 0.1, 1.0, plane_strain=True)],
                         ids=["3d", "2d"])
def test_fft_operator_equals_dense_symmetric_matrix(grid):
    op = Compliance(grid, 1.1e5)
    dense = op.dense()
    p = np.random.default_rng(0).random(grid.shape)
    assert np.abs(dense - dense.T).max() <= ROUND_OFF * np.abs(dense).max()
    assert np.abs(op(p).ravel() - dense @ p.ravel()).max() <= ROUND_OFF * np.abs(dense @ p.ravel()).max()


def test_3d_compliance_is_positive_definite():
    dense = Compliance(Grid.centred(12, 8, 0.01, 0.4), 1.1e5).dense()
    assert np.linalg.eigvalsh(dense).min() > 0


def test_dense_refused_beyond_limit():
    with pytest.raises(ValueError, match="dense compliance"):
        Compliance(Grid.centred(100, 100, 0.01, 0.01), 1.1e5).dense()
