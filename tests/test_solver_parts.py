"""The pieces of the contact solvers (and of the measurements' reader), each against the property it is there for."""
import numpy as np
import pytest

from conftest import ball_problem
from fretsim.compliance.tangential import Tangential
from fretsim.fit import _cell
from fretsim.solvers import solve
from fretsim.solvers.cg import _admit, _direction, _gradient, _preconditioner, _step
from fretsim.solvers.tangential import _release

ROUND_OFF = 1e-12  # sums of O(1) terms over a few hundred elements, relative


def _iterate_state(n=24):
    """A contact set part-way through a solve: a warm start from a lighter load, its gap and operator."""
    op, gap = ball_problem(n)
    p = solve(op, gap, 60.0, method="cg").pressure
    p *= 185.0 / op.grid.area / p.sum()
    return op, gap, p


def test_the_preconditioned_direction_keeps_the_load_and_lives_on_the_contact_set():
    op, gap, p = _iterate_state()
    on, m, count, g = _gradient(op(p), gap, p)
    t, gz = _direction(g, m, count, _preconditioner(op), np.zeros_like(p), 0.0, 1.0)
    assert np.all(t[~on] == 0)
    assert abs(t.sum()) < ROUND_OFF * np.abs(t).sum()  # a step along t leaves Σp, the load, unchanged
    assert gz > 0  # a descent direction: the energy falls along −t


def test_a_step_that_would_lift_every_element_off_is_shortened_until_some_pressure_remains():
    p_old = np.array([[1.0, 2.0, 3.0]])
    t = np.array([[1.0, 1.0, 1.0]])
    none = np.zeros_like(p_old, bool)
    p, tau, clipped, scale = _step(p_old, 100.0, t, np.zeros_like(p_old), none, 6.0)
    assert tau == 100.0 / 2**6  # 1.5625: the first halving below the largest pressure, 3
    assert clipped and p.sum() == pytest.approx(6.0, rel=ROUND_OFF)
    assert p[0, 0] == 0.0 and (p[0, 1:] > 0).all()


def test_penetrating_elements_are_admitted_in_proportion_to_their_penetration_at_the_same_load():
    p = np.array([[2.0, 0.0, 0.0, 1.0]])
    g = np.array([[0.0, -1.0, -3.0, 0.0]])
    penetrating = g < 0
    q = _admit(p, g, penetrating, 3.0)
    assert q.sum() == pytest.approx(3.0, rel=ROUND_OFF)
    assert q[0, 2] / q[0, 1] == pytest.approx(3.0, rel=ROUND_OFF)
    assert p.tolist() == [[2.0, 0.0, 0.0, 1.0]]  # the caller's pressure is left as it was


def test_a_released_slip_moves_to_the_minimum_of_the_quadratic_along_its_gradient():
    op, gap, p = _iterate_state(16)
    k = Tangential(op.grid, [(2.0e5, 0.3), (2.0e5, 0.3)])
    bound = 0.5 * p
    q = bound.copy()  # everything slipping one way; the increment reverses it
    rhs = k(q) - 1e-7
    g = k(q) - rhs
    release = (bound > 0) & (g > 0)
    q_new, curvature = _release(k, q, g, release, -bound, bound)
    assert curvature > 0
    d = np.where(release, g, 0.0)
    assert release.any() and (np.abs(q_new[release]) < bound[release]).all()  # a small reversal: all stick again
    assert abs(float((d * (k(q_new) - rhs)).sum())) < 1e-9 * float((d * g).sum())  # exact line search


@pytest.mark.parametrize("text, unit, value", [("15%", "%", 0.15), ("12", "%", 0.12), ("0.3%", "", 0.003),
                                               ("0.2", "", 0.2)])
def test_a_wall_loss_cell_reads_as_a_fraction_or_a_percentage(text, unit, value):
    assert _cell(text, "fraction", unit) == pytest.approx(value, rel=ROUND_OFF)


def test_a_depth_cell_reads_in_its_columns_unit():
    assert _cell(" 2.5 ", "length", "um") == pytest.approx(2.5e-3, rel=ROUND_OFF)
