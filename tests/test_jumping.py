"""Linear jumping: schedule, the explicit stability limit, and the checkerboard detector."""
import numpy as np
import pytest

from conftest import E_STAR
from fretsim.compliance import Compliance
from fretsim.grid import Grid
from fretsim.jumping import (checkerboard_amplitude, compliance_symbol_x, default_linear_jump,
                             explicit_stability_limit, is_checkerboard)


def _min_eigenvalue_zero_sum(dense):
    n = dense.shape[0]
    q = np.linalg.qr(np.column_stack([np.ones(n), np.eye(n)[:, :n - 1]]))[0][:, 1:]
    return np.linalg.eigvalsh(q.T @ dense @ q).min()


@pytest.mark.parametrize("grid", [Grid.centred(161, 1, 0.00625, 1.0, plane_strain=True),
                                  Grid.centred(61, 9, 0.00625, 10 / 9)], ids=["2d", "3d"])
def test_symbol_at_nyquist_matches_smallest_eigenvalue_of_the_dense_operator(grid):
    # the symbol bounds the spectrum of every finite section from below and is approached by it
    lam = _min_eigenvalue_zero_sum(Compliance(grid, E_STAR).dense())
    f = compliance_symbol_x(grid, E_STAR, np.array([np.pi]))[0]
    assert f <= lam * (1 + 1e-6)
    assert f == pytest.approx(lam, rel=0.02)  # finite section of 61-161 elements: within 2 %


def test_stability_limit_of_the_2d_185N_case_lies_between_25_and_50():
    # issue #3: measured on the 185 N case in 2D with 6.25 µm elements: between ΔN 25 and 50
    limit = explicit_stability_limit(Grid.centred(161, 1, 0.00625, 1.0, True), E_STAR, 0.025, 2e-8, 3e-8)
    assert 25 < limit < 50


def test_stability_limit_scales_with_element_size_and_wear_rate():
    g = Grid.centred(161, 1, 0.00625, 1.0, True)
    g2 = Grid.centred(161, 1, 0.0125, 1.0, True)
    base = explicit_stability_limit(g, E_STAR, 0.025, 2e-8, 3e-8)
    assert explicit_stability_limit(g2, E_STAR, 0.025, 2e-8, 3e-8) > 1.5 * base  # coarser → larger
    assert explicit_stability_limit(g, E_STAR, 0.025, 4e-8, 6e-8) == pytest.approx(base / 2, rel=1e-9)


def test_default_jump_is_half_the_limit_and_within_the_run():
    assert default_linear_jump(42.7, 18000) == 21
    assert default_linear_jump(1e9, 500) == 500
    assert default_linear_jump(0.5, 100) == 1


def test_detector_flags_a_checkerboard_and_not_hertz_or_edge_peaks():
    x = np.linspace(-1, 1, 41)
    hertz = np.sqrt(np.clip(1 - x**2, 0, None))[None, :] * 100
    edge_peaked = np.where(np.abs(x) < 0.95, 40 + 15 * np.exp(-((np.abs(x) - 0.9) / 0.03) ** 2), 0)[None, :]
    chequered = hertz * (1 + 0.03 * (-1.0) ** np.arange(41))
    assert not is_checkerboard(hertz) and not is_checkerboard(edge_peaked)
    assert is_checkerboard(chequered)
    assert checkerboard_amplitude(chequered) == pytest.approx(0.03, rel=0.2)


def test_detector_flags_a_strong_checkerboard_whose_troughs_touch_zero():
    # an unstable run's pressure swings between ~0 and twice its mean: the troughs must not hide the contact
    x = np.linspace(-1, 1, 41)
    smooth = np.where(np.abs(x) < 0.9, 200.0, 0.0)
    strong = smooth * (1 + 0.98 * (-1.0) ** np.arange(41))
    assert is_checkerboard(strong[None, :])
