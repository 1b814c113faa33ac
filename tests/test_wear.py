"""Archard increments and the flat's stroke-averaged pressure."""
import numpy as np
import pytest

from fretsim.wear import archard_depth, archard_volume, stroke_average, stroke_weights

ROUND_OFF = 1e-12


@pytest.mark.parametrize("dx, stroke", [(0.00625, 0.025), (0.0103, 0.010), (0.01, 0.0049), (0.02, 0.1)])
def test_stroke_weights_sum_to_one(dx, stroke):
    assert stroke_weights(dx, stroke).sum() == pytest.approx(1.0, abs=ROUND_OFF)


def test_stroke_average_is_the_exact_box_average_of_piecewise_constant_pressure():
    rng = np.random.default_rng(1)
    dx, stroke = 0.01, 0.023  # a window that cuts elements partially
    p = np.zeros((1, 60))
    p[0, 15:45] = rng.random(30)
    avg = stroke_average(p, dx, stroke)
    x = (np.arange(60) - 29.5) * dx
    # brute force: sample the window finely; piecewise-constant p evaluated by element lookup
    u = np.linspace(-stroke, stroke, 200001)
    for i in (20, 31, 44):
        idx = np.floor((x[i] - u - x[0]) / dx + 0.5).astype(int)
        brute = np.trapezoid(p[0, np.clip(idx, 0, 59)], u) / (2 * stroke)
        assert avg[0, i] == pytest.approx(brute, abs=2e-5)  # quadrature of the brute-force sum, not ours


def test_stroke_average_conserves_the_load_and_widens_the_contact():
    p = np.zeros((3, 80))
    p[:, 30:50] = 1.0
    avg = stroke_average(p, 0.005, 0.025)
    assert avg.sum() == pytest.approx(p.sum(), rel=ROUND_OFF)
    assert (avg > 0).sum(axis=1)[0] == 20 + 2 * 5  # widened by δ/dx = 5 elements each side
    assert avg.max() == pytest.approx(1.0)


def test_archard_depth_and_volume_follow_eqs_15_16():
    # k = 3e-8 1/MPa, p = 100 MPa, 1000 cycles of 4·25 µm: 3e-8 · 1000 · 0.1 mm · 100 = 3e-4 mm
    assert archard_depth(3e-8, np.array([100.0]), 1000, 0.025)[0] == pytest.approx(3e-4, rel=ROUND_OFF)
    assert archard_volume(3e-8, 185.0, 18000, 0.025) == pytest.approx(3e-8 * 185 * 0.1 * 18000, rel=ROUND_OFF)
