"""The schemes' arithmetic: BDF2 coefficients and error estimate, Taylor jumps, step control."""
import numpy as np
import pytest

from fretsim.jumping import (bdf2_coefficients, bdf2_local_error, next_step, taylor_extrapolate, taylor_jump)


@pytest.mark.parametrize("step, span", [(1.0, 1.0), (2.0, 1.0), (0.3, 1.0), (5.0, 17.0)])
def test_bdf2_reproduces_quadratics_exactly_and_keeps_linear_invariants(step, span):
    # y = a + b t + c t²: BDF2 is exact (second order); Σ over a linear invariant: b·span + γ·step = step
    tn, tk = 3.0, 3.0 - span
    y = lambda t: 1.0 + 2.0 * t + 0.7 * t * t  # noqa: E731
    dy = lambda t: 2.0 + 1.4 * t  # noqa: E731
    b, g = bdf2_coefficients(step, span)
    assert y(tn) + b * (y(tn) - y(tk)) + g * step * dy(tn + step) == pytest.approx(y(tn + step), rel=1e-13)
    assert b * span + g * step == pytest.approx(step, rel=1e-14)


def test_bdf2_local_error_estimate_is_exact_for_a_cubic_at_variable_steps():
    y = lambda t: t**3  # noqa: E731  (y''' = 6: the leading error term is the whole error)
    t0, tk, tn, d = 0.2, 0.7, 1.5, 0.9
    b, g = bdf2_coefficients(d, tn - tk)
    actual = y(tn) + b * (y(tn) - y(tk)) + g * d * 3 * (tn + d) ** 2 - y(tn + d)
    estimate = bdf2_local_error((t0, tk, tn, tn + d), (y(t0), y(tk), y(tn), y(tn + d) + actual))
    assert estimate == pytest.approx(actual, rel=1e-9)
    # constant steps: a step whose result carries the classical error 2/9·ΔN³·y''' is estimated at that error
    assert bdf2_local_error((0.0, 1.0, 2.0, 3.0), (0.0, 1.0, 8.0, 27.0 + 2 / 9 * 6)) == pytest.approx(2 / 9 * 6)


def test_step_controller_scales_by_the_error_power_of_the_order_within_bounds():
    assert next_step(100, 0.0, 0.01, 2) == 200
    assert next_step(100, 0.01 / 8, 0.01, 2) == pytest.approx(180)  # 0.9·8^(1/3) = 1.8
    assert next_step(100, 1e9, 0.01, 2) == 20  # never below a fifth


def test_taylor_extrapolation_keeps_archards_volume():
    rng = np.random.default_rng(0)
    h2 = rng.random(50)
    h1 = h2 + 0.1 * rng.random(50) / 10 * 10
    h1 *= (h2.sum() + 1.0) / h1.sum()
    h0 = h1 * ((h1.sum() + 1.0) / h1.sum())  # each linear step adds volume 1
    jumped = taylor_extrapolate(h2, h1, h0, 10, 70)
    assert jumped.sum() == pytest.approx(h0.sum() + 7.0, rel=1e-12)


def test_taylor_jump_ignores_unworn_and_barely_worn_elements():
    h1 = np.array([0.0, 1e-9, 1.0, 2.0])
    h0 = np.array([0.0, 2e-9, 1.5, 2.25])  # element 1 doubles (would force a tiny jump) but is 1e-9 of the maximum
    assert taylor_jump([(h1, h1, h0)], 8, 0.5, 10_000) == 12  # element 2 limits: η|h|/|ḣ| = 0.5·1.5/(0.5/8)
