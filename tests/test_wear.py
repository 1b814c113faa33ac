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


@pytest.mark.parametrize("reach", [3.0, 40.0])
def test_the_hat_read_by_running_sums_is_the_shares_read(reach):
    """A long travel's hat read goes by the running integral of the field's interpolation, not the shares (whose
    cost grows with the travel's span): the same operator, so the two agree on random fields and travels — up and
    down, points that stay put, travels that run off the grid's ends — to 1e-10 of the field's largest value
    (measured 4e-13 and 2.3e-12: the running sums' round-off, ~1e-16 of a row's integral, ~40 here, divided by the
    shortest travel, 1e-3 elements, is 4e-12).
    ``sweep_read`` takes the sums beyond SUMS_TRAVEL elements and agrees with the shares there too."""
    from fretsim.wear import SUMS_TRAVEL, Sweep, _hat_read_by_sums, sweep_read
    rng = np.random.default_rng(11)
    rows, nx, dx = 7, 120, 2e-3
    field = np.zeros((rows, nx))
    field[:, 20:100] = rng.random((rows, 80))
    a = rng.uniform(-reach, reach, (rows, nx)) * dx
    b = a + rng.uniform(-reach, reach, (rows, nx)) * dx
    b[0, :6] = a[0, :6]  # points that do not travel
    b[1, :6] = a[1, :6] + 1e-3 * dx  # and travels of a thousandth of an element
    a[2, :10], b[2, :10] = -1.5 * reach * dx, -0.5 * reach * dx  # off the left end
    expected = Sweep(a, b, dx, "hat").read(field)
    got = _hat_read_by_sums(field, a / dx, b / dx)
    assert np.abs(got - expected).max() <= 1e-10 * field.max()
    assert (reach > SUMS_TRAVEL) == (np.abs(b - a).max() > SUMS_TRAVEL * dx)
    assert np.abs(sweep_read(field, a, b, dx, "hat") - expected).max() <= 1e-10 * field.max()
