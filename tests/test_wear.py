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


@pytest.mark.parametrize("dx, stroke", [(10.0, 25.0), (10.0, 27.0), (1.128e-3, 0.08), (3.0, 1.0), (0.7, 0.35),
                                        (0.0016, 0.025)])
def test_stroke_average_by_running_sums_is_the_weighted_sum_and_exactly_zero_beyond_the_reach(dx, stroke):
    """The box of whole-covered elements by a difference of running sums, the partial ends added: the weighted sum
    Σ w_k p_(i−k) taken term by term to 1e-13 of the peak (the running sums' round-off over a few hundred
    elements), on one row and on 27; an element the stroke cannot reach from any loaded one exactly 0 (the contact's
    extent, and the scar's, are read from where the averages are 0)."""
    rng = np.random.default_rng(5)
    w = stroke_weights(dx, stroke)
    reach = (w.size - 1) // 2
    for rows in (1, 27):
        p = np.clip(rng.normal(size=(rows, 400)), 0.0, None)
        p[:, :150] = 0.0
        p[:, -150:] = 0.0
        want = np.zeros_like(p)
        for k in range(-reach, reach + 1):  # want[i] += w_k · p[i − k]
            shifted = np.zeros_like(p)
            if k >= 0:
                shifted[:, k:] = p[:, :p.shape[1] - k]
            else:
                shifted[:, :k] = p[:, -k:]
            want += w[reach + k] * shifted
        got = stroke_average(p, dx, stroke)
        assert np.abs(got - want).max() <= 1e-13 * want.max()
        assert np.array_equal(got == 0.0, want == 0.0)
    p = np.zeros((1, 60))
    p[0, 10], p[0, 40] = np.nan, 1.0  # a NaN stays where its weights reach (running sums would carry it on)
    got = stroke_average(p, dx, stroke)
    offsets = np.arange(60) - 10
    reached = (np.abs(offsets) <= reach) & (w[np.clip(reach + offsets, 0, 2 * reach)] != 0)
    assert np.array_equal(np.isnan(got[0]), reached)


def test_archard_depth_and_volume_follow_eqs_15_16():
    # k = 3e-8 1/MPa, p = 100 MPa, 1000 cycles of 4·25 µm: 3e-8 · 1000 · 0.1 mm · 100 = 3e-4 mm
    assert archard_depth(3e-8, np.array([100.0]), 1000, 0.025)[0] == pytest.approx(3e-4, rel=ROUND_OFF)
    assert archard_volume(3e-8, 185.0, 18000, 0.025) == pytest.approx(3e-8 * 185 * 0.1 * 18000, rel=ROUND_OFF)


@pytest.mark.parametrize("reach", [3.0, 40.0])
def test_the_hat_sweep_by_running_sums_reads_and_deposits_as_the_shares_do(reach, monkeypatch):
    """Long travels' hat sweeps read and deposit by running sums, not the shares (whose cost grows with the
    travel's span): the same operators, so on random fields, amounts and travels — up and down, points that stay
    put, travels of a thousandth of an element, travels that run off the grid's ends — the read and the deposit
    agree with the shares' to 1e-10 of the largest value (measured 4e-12 and 2e-12: the running sums' round-off,
    ~1e-16 of a row's integral, divided by the shortest travel, 1e-3 elements), the deposit is exactly zero where
    the shares' is (nothing landed: the round-off there is removed) and never negative, and it is the read's
    adjoint to round-off."""
    from fretsim import wear
    from fretsim.wear import HatSums, Sweep
    monkeypatch.setattr(wear, "SUMS_TRAVEL", 1e9)  # (the reference: the shares whatever the travel)
    rng = np.random.default_rng(11)
    rows, nx, dx = 7, 120, 2e-3
    field = np.zeros((rows, nx))
    field[:, 20:100] = rng.random((rows, 80))
    amount = np.zeros((rows, nx))
    amount[:, 40:70] = rng.random((rows, 30))
    a = rng.uniform(-reach, reach, (rows, nx)) * dx
    b = a + rng.uniform(-reach, reach, (rows, nx)) * dx
    b[0, :] = a[0, :]  # points that do not travel
    b[1, 40:46] = a[1, 40:46] + 1e-3 * dx  # and travels of a thousandth of an element
    a[2, :50], b[2, :50] = -1.5 * reach * dx, -0.5 * reach * dx  # off the left end
    shares = Sweep(a, b, dx, "hat")
    sums = HatSums(a / dx, b / dx)
    assert np.abs(sums.read(field) - shares.read(field)).max() <= 1e-10 * field.max()
    expected, got = shares.deposit(amount), sums.deposit(amount)
    assert np.abs(got - expected).max() <= 1e-10 * expected.max()
    assert ((got == 0.0) == (expected == 0.0)).all() and (got >= 0.0).all()
    assert abs((got * field).sum() - (amount * sums.read(field)).sum()) <= 1e-12 * (got * field).sum()
    monkeypatch.undo()  # beyond SUMS_TRAVEL elements a Sweep goes by the sums
    assert Sweep(a, b, dx, "hat").sums == (reach > wear.SUMS_TRAVEL)
