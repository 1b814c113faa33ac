"""Acceleration without losing accuracy: implicit steps, adaptive jumping, refinement, and stability guards."""
import functools
from pathlib import Path

import numpy as np
import pytest

from conftest import E_STAR, cylinder_problem
from fretsim.api import run
from fretsim.case import CaseError, load_case
from fretsim.compliance import Compliance
from fretsim.grid import Grid
from fretsim.jumping import CHECKERBOARD_LIMIT, ImplicitCompliance, implicit_jump_cap
from fretsim.refine import coarsen, mape, refine_pressure
from fretsim.simulate import prepare
from fretsim.solvers import solve

CASES = Path(__file__).resolve().parent.parent / "cases"
SHORT = ["model.dimension=2d", "loading.cycles=10000", "output.snapshots=[10000]"]


@functools.lru_cache(maxsize=None)
def last_step(*overrides: str):
    out = run(load_case(CASES / "mccoll_185N.yaml", list(overrides)))
    assert out.status == "complete", out.message
    return out


def reference(*grid):
    """No-jump stand-in: explicit steps of 5 cycles (ΔN 5 and 1 differ by < 1e-5 in depth, measured)."""
    return last_step(*SHORT, "jumping.scheme=linear", "jumping.linear=5", *grid)


def rel(a, b):
    return abs(a / b - 1)


# --- the implicit step -----------------------------------------------------------------------------------------

def test_implicit_compliance_is_positive_definite_for_any_jump_when_the_flat_does_not_wear():
    grid = Grid.centred(40, 3, 0.00628, 10 / 3)
    base = Compliance(grid, E_STAR)
    lam0 = np.linalg.eigvalsh(base.dense()).min()
    for cycles in (1e2, 1e5, 1e8):
        lam = np.linalg.eigvalsh(ImplicitCompliance(base, cycles, 0.025, 2e-8, 0.0).dense()).min()
        assert lam >= lam0 * (1 - 1e-9)  # C + s·k_m·I: the wear term only adds
    assert implicit_jump_cap(grid, E_STAR, 0.025, 2e-8, 0.0) == np.inf


def test_implicit_compliance_with_only_the_flat_wearing_is_positive_definite_up_to_the_cap_only():
    # k_m = 0: the stroke average B has negative Fourier modes, so C + s·k_s·B loses definiteness for long jumps
    grid = Grid.centred(120, 1, 0.00628, 1.0, plane_strain=True)
    base = Compliance(grid, E_STAR)
    cap = implicit_jump_cap(grid, E_STAR, 0.025, 0.0, 3e-8)
    assert np.isfinite(cap)
    n = grid.size
    q = np.linalg.qr(np.column_stack([np.ones(n), np.eye(n)[:, :n - 1]]))[0][:, 1:]  # the load fixes the mean

    def lam(cycles):
        return np.linalg.eigvalsh(q.T @ ImplicitCompliance(base, cycles, 0.025, 0.0, 3e-8).dense() @ q).min()
    assert lam(cap) > 0
    assert lam(8 * cap) < 0  # the cap is not vacuous: twice its safety margin, squared, and definiteness is gone


def test_implicit_step_is_first_order_accurate():
    ref = reference()
    errors = []
    for jump in (1000, 500, 250):  # fixed steps: no control (tolerance at its ceiling), jump bounded both ways
        out = last_step(*SHORT, "jumping.scheme=implicit", f"jumping.linear={jump}", f"jumping.max={jump}",
                        "jumping.tolerance=0.5")
        errors.append(rel(out.summary["centre_wear_depth_stationary_um"], ref.summary["centre_wear_depth_stationary_um"]))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert ((ratios > 1.6) & (ratios < 2.6)).all(), (errors, ratios)  # halving the step halves the error


def test_default_implicit_run_matches_the_reference_in_depth_and_pressure():
    ref, out = reference(), last_step(*SHORT)
    assert out.setup.scheme == "implicit"
    assert rel(out.summary["centre_wear_depth_stationary_um"], ref.summary["centre_wear_depth_stationary_um"]) < 1e-3
    assert mape(ref.last.pressure, out.last.pressure) < 3.0  # % over the contact; edges dominate it
    assert out.summary["contact_solves"] < ref.summary["contact_solves"] / 20
    assert out.summary["archard_volume_error"] < 1e-9


def test_3d_default_is_within_1pct_of_the_reference():
    ref = last_step("loading.cycles=18000", "jumping.scheme=linear", "jumping.linear=10")
    out = last_step("loading.cycles=18000")
    assert rel(out.summary["centre_wear_depth_stationary_um"], ref.summary["centre_wear_depth_stationary_um"]) < 0.01


# --- the paper's adaptive jumping --------------------------------------------------------------------------------

def test_paper_preset_on_the_papers_coarse_grid_reproduces_the_no_jump_run():
    grid = ("grid.coarse_element=[15.75 um]",)
    ref = reference(*grid)
    out = last_step(*SHORT, "jumping.preset=paper", *grid)
    total = out.last.wear_moving + out.last.wear_stationary
    ref_total = ref.last.wear_moving + ref.last.wear_stationary
    assert mape(ref_total, total) < 1.0  # % total wear depth, the DOE's measure (scripts/study_doe.py)
    assert mape(ref.last.pressure, out.last.pressure) < 2.0
    assert out.summary["archard_volume_error"] < 1e-9  # the Taylor extrapolation conserves volume
    assert out.summary["contact_solves"] < ref.summary["contact_solves"] / 10


def test_adaptive_jumps_on_a_fine_grid_never_end_silently_unstable(tmp_path):
    out = run(load_case(CASES / "mccoll_185N.yaml", [*SHORT, "jumping.preset=paper", "jumping.linear=20"]),
              tmp_path / "a.h5")
    if out.status == "complete":
        from fretsim.results import read_results
        assert read_results(tmp_path / "a.h5").history["checkerboard_amplitude"].max() < CHECKERBOARD_LIMIT
    else:
        assert "checkerboard" in out.message and "implicit" in out.message


# --- stability guards ----------------------------------------------------------------------------------------------

def test_linear_jump_beyond_the_limit_is_refused_with_the_computed_limit():
    with pytest.raises(CaseError) as info:
        prepare(load_case(CASES / "mccoll_185N.yaml", ["jumping.linear=80"]))
    assert "stability limit 42." in str(info.value) and "jumping.linear" in str(info.value)


def test_linear_jump_near_the_limit_is_caught_when_the_pressure_checkerboards():
    out = run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "jumping.linear=42"]))
    assert out.status == "failed" and "checkerboards" in out.message


def test_solves_grow_logarithmically_with_cycles():
    counts = [last_step("model.dimension=2d", f"loading.cycles={n}", f"output.snapshots=[{n}]").summary[
        "contact_solves"] for n in (2000, 20000, 200000)]
    steps = np.diff(counts)
    assert steps[1] <= 1.3 * steps[0], counts  # the same few dozen solves per decade of cycles


# --- refinement (Eqs. 11-12) -----------------------------------------------------------------------------------------

def test_refinement_keeps_load_and_wear_volume_and_meets_the_papers_10pct_mape():
    fine_op, fine_gap = cylinder_problem(40, 27, half_width=0.126)
    coarse_op, coarse_gap = cylinder_problem(16, 10, half_width=0.126)  # 15.75 µm × 1000 µm, paper Fig. 10
    p_fine = solve(fine_op, fine_gap, 185.0).pressure
    p_ref = refine_pressure(solve(coarse_op, coarse_gap, 185.0).pressure, coarse_op.grid, fine_op.grid)
    assert p_ref.sum() * fine_op.grid.area == pytest.approx(185.0, rel=1e-12)
    assert mape(p_fine, p_ref) < 10.0  # the paper's coarse-grid criterion (Fig. 9)
    h = np.random.default_rng(3).random(fine_op.grid.shape)
    assert coarsen(h, fine_op.grid, coarse_op.grid).sum() * coarse_op.grid.area == pytest.approx(
        h.sum() * fine_op.grid.area, rel=1e-12)


def test_refined_run_agrees_with_the_fine_run():
    fine = last_step(*SHORT)
    coarse = last_step(*SHORT, "grid.coarse_element=[15.75 um]")
    assert rel(coarse.summary["centre_wear_depth_stationary_um"], fine.summary["centre_wear_depth_stationary_um"]) < 0.01
    assert abs(coarse.summary["scar_width_stationary_mm"] - fine.summary["scar_width_stationary_mm"]) < 0.03
