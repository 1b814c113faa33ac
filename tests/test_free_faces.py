"""The free faces of bodies that end across the contact (paper §2.1): the finite block behind the correction,
against the half-space's exact response and an independent finite-element solution, and on McColl's case."""
from pathlib import Path

import numpy as np
import pytest

from fretsim.api import load_case, run
from fretsim.case import CaseError
from fretsim.compliance.free_faces import (Block, RowConvolution, _graded, face_settlement, free_faces,
                                           kernel_along_x)
from fretsim.grid import Grid
from fretsim.plan import prepare

HERE = Path(__file__).resolve().parent
CASES = HERE.parent / "cases"


def test_the_block_settles_like_the_half_space_under_a_load_across_its_whole_width():
    # cos(kx) over the whole top of a block deep against 1/k: mid-width settlement 2(1 − ν²)/(E k) exactly.
    # Bilinear elements on a graded mesh (growth 1.3) are 0.58 % stiff at every k (the grading is self-similar);
    # 1 % bounds that.  The correction is a difference of two blocks with the same mesh, where this cancels.
    youngs, nu = 200e3, 0.3
    for k in (20.0, 100.0, 400.0):
        z = np.concatenate([[0.0], np.cumsum(_graded(0.1 / k, 1.3, 3 / 8, 3.0))])
        block = Block(np.linspace(-2, 2, 81), z, youngs, nu)
        w = block.settlement(k, block.loads(np.array([-2.0, 2.0])), np.array([40]))[0, 0]
        assert abs(w / (2 * (1 - nu**2) / (youngs * k)) - 1) < 0.01


def test_the_face_correction_matches_an_independent_finite_element_solution():
    # tests/data: scikit-fem, quadratic quadrilaterals, its own mesh and control block (scripts/
    # study_free_faces_fe.py, face_correction at depth 20 mm), at McColl's 27 rows and fretsim's wavenumbers.
    # Bilinear elements, two across a row, against quadratic ones, four: 2.4 % of the largest entry measured (at
    # k = 0, the end row on itself, whose weight in the operator is nil), 0.5 % at k > 0; 3 % and 1.5 % allowed.
    ref = np.load(HERE / "data" / "free_faces_skfem_mccoll.npz")
    mine = face_settlement(ref["rows"], float(ref["dy"]), float(ref["length"]), float(ref["youngs"]),
                           float(ref["poisson"]), ref["ks"])
    scale = np.abs(ref["delta"]).max()
    assert np.abs(mine - ref["delta"]).max() < 0.03 * scale
    assert np.abs(mine - ref["delta"])[1:].max() < 0.015 * scale
    # and what it says: the faces soften the end rows most, the centre rows least
    assert mine[0, -1, -1] > 0 and mine[0, -1, -1] > 5 * abs(mine[0, 13, 13])


def test_faces_far_from_the_contact_change_nothing():
    # the operator (integrated over k): faces at the grid's ends, on the end element, against a flat 40 mm long
    # (faces 17.75 mm beyond the grid), on the centre element
    grid = Grid.centred(21, 9, 0.02, 0.5)
    near = free_faces(grid, [(4.5, 200e3, 0.3)]).kernel
    far = free_faces(grid, [(40.0, 200e3, 0.3)]).kernel
    assert near[-1, -1, 20] > 0 and abs(far[4, 4, 20]) < 0.05 * near[-1, -1, 20]


def test_the_row_convolution_applies_its_dense_matrix_and_its_windows_are_sub_blocks():
    grid = Grid.centred(15, 6, 0.01, 0.3)
    rng = np.random.default_rng(1)
    ks = np.array([0.0, 1.0, 3.0, 9.0])
    delta = rng.random((4, 6, 6)) * np.array([1.0, 0.6, 0.2, 0.01])[:, None, None]
    op = RowConvolution(grid, kernel_along_x(delta, ks, grid.dx, 15))
    dense = op.dense()
    p = rng.random(grid.shape)
    assert np.allclose(op(p).ravel(), dense @ p.ravel(), rtol=1e-12, atol=1e-12 * np.abs(dense).max())
    rows, cols = slice(1, 5), slice(3, 12)
    idx = np.arange(grid.size).reshape(grid.shape)[rows, cols].ravel()
    assert np.allclose(op.window(rows, cols).dense(), dense[np.ix_(idx, idx)])


def test_mccolls_cylinder_ends_reproduce_the_finite_element_study():
    # scripts/study_free_faces_fe.py (scikit-fem, depth 20 mm) measured what one body's free faces at the
    # contact's ends change on this case: the flat's centre-line depth +0.40 %, its maximum depth −1.42 %.  The
    # cylinder's ends, of the same steel and length, are the same correction.  0.1 point allowed: the two FE
    # corrections differ by 1.6 % of an effect of 1.4 %, and the study samples other wavenumbers.
    case = CASES / "mccoll_185N.yaml"
    half = run(load_case(case, ["model.corrections=none"])).summary
    faces = run(load_case(case, ["model.corrections=[free_faces]"])).summary
    centre = faces["centre_wear_depth_stationary_um"] / half["centre_wear_depth_stationary_um"] - 1
    deepest = faces["max_wear_depth_stationary_um"] / half["max_wear_depth_stationary_um"] - 1
    assert abs(centre - 0.0040) < 0.001 and abs(deepest + 0.0142) < 0.001
    assert abs(faces["wear_volume_stationary_mm3"] / half["wear_volume_stationary_mm3"] - 1) < 1e-3


def test_auto_includes_the_faces_where_they_change_what_is_reported_and_says_why():
    _, filled, plan = prepare(load_case(CASES / "mccoll_185N_free_faces.yaml"))
    choice = next(c for c in plan.choices if c.key == "model.corrections")
    assert filled.corrections == ("free_faces",) and "more than model.accuracy" in choice.reason
    assert "cylinder's ends" in choice.reason and "flat's ends" in choice.reason
    # the shipped Table 4 case keeps the paper's half-spaces by saying so; under auto its cylinder's ends count
    _, filled, plan = prepare(load_case(CASES / "mccoll_185N.yaml", ["model.corrections=auto"]))
    choice = next(c for c in plan.choices if c.key == "model.corrections")
    assert filled.corrections == ("free_faces",) and "the cylinder's ends" in choice.reason


def test_a_flat_shorter_than_the_cylinder_is_refused():
    with pytest.raises(CaseError, match="block_length"):
        load_case(CASES / "mccoll_185N.yaml", ["geometry.block_length=8 mm"])


def test_free_faces_in_a_2d_model_are_refused_with_advice():
    with pytest.raises(CaseError, match="dimension: 3d"):
        prepare(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "model.corrections=[free_faces]"]))


def test_a_flat_longer_than_the_cylinder_softens_the_ends_less():
    # faces 1 mm beyond the cylinder's ends: the flat's part of the end rows' extra settlement is smaller
    grid = Grid.centred(31, 27, 0.00628, 10 / 27)
    at_ends = free_faces(grid, [(10.0, 200e3, 0.3)]).kernel[-1, -1, 30]
    beyond = free_faces(grid, [(12.0, 200e3, 0.3)]).kernel[-1, -1, 30]
    assert 0 < beyond < 0.5 * at_ends


def test_faces_that_cut_through_a_row_are_refused_naming_the_grid():
    with pytest.raises(CaseError, match="grid.domain"):
        prepare(load_case(CASES / "mccoll_185N.yaml", ["model.corrections=[free_faces]",
                                                       "grid.domain=[0.7343 mm, 11 mm]"]))


KEYS = ("max_wear_depth_moving_um", "max_wear_depth_stationary_um", "centre_wear_depth_stationary_um",
        "scar_width_moving_mm", "scar_width_stationary_mm")


def _worst(a: dict, b: dict) -> float:
    return max(abs(a[k] / b[k] - 1) for k in KEYS)


# 1670 N by default: it checks the corrections auto picks and the cheaper 2D's miss too; 185 N (measured three
# times the time) in `pytest -m slow`
@pytest.mark.parametrize("name, picked", [pytest.param("mccoll_185N", "3d", marks=pytest.mark.slow),
                                          ("mccoll_1670N", "3d")])
def test_autos_pick_is_within_model_accuracy_of_the_full_model_and_the_cheaper_one_is_not(name, picked):
    # the full model of a cylinder on a flat: 3D with the cylinder's free ends.  auto must land within
    # model.accuracy (1 %) of it; where 2D is farther than that it must pick 3D
    # (scripts/results/model_hierarchy.txt: 0.63 % for 2D at 185 N; 1.28 % for 2D at 1670 N).  At 185 N the
    # proxy's 0.6 % is within 1 % but not within 1 %/3, the margin a proxy's own uncertainty asks: 3D
    case = CASES / f"{name}.yaml"
    auto = run(load_case(case, ["model.dimension=auto", "model.corrections=auto"]))
    full = run(load_case(case, ["model.dimension=3d", "model.corrections=[free_faces]"])).summary
    assert auto.case.dimension == picked
    assert _worst(auto.summary, full) < 0.01
    if name == "mccoll_1670N":
        assert auto.case.corrections == ("free_faces",)
        assert _worst(run(load_case(case, ["model.dimension=2d"])).summary, full) > 0.01


def test_the_fourier_integrals_monotone_cubic_is_scipys_pchip_and_keeps_the_datas_shape():
    """The faces' settlement is interpolated between its nine wavenumbers by a monotone cubic written here (scipy's
    interpolate costs 0.2 s to import): against scipy's PchipInterpolator on random, flat-stretched and monotone
    samples (the wavenumbers' own spacing and random ones; vector values) to 1e-13, and monotone data stays
    monotone between the samples (no overshoot: what a plain cubic spline would not keep)."""
    from scipy.interpolate import PchipInterpolator

    from fretsim.compliance.free_faces import K_SAMPLES, pchip
    rng = np.random.default_rng(3)
    for trial in range(120):
        n = int(rng.integers(2, 12))
        xs = np.unique(np.sort(rng.random(n)) * 10) if trial % 2 else np.array(K_SAMPLES[:min(n, 9)])
        if len(xs) < 2:
            continue
        ys = rng.normal(size=(len(xs), 3, 4))
        if trial % 3 == 0 and len(xs) > 4:
            ys[2:4] = ys[2]
        if trial % 5 == 0:
            ys = np.cumsum(np.abs(ys), axis=0)
        x = np.concatenate([np.linspace(xs[0], xs[-1], 257), xs])
        want = PchipInterpolator(xs, ys, axis=0)(x)
        assert np.abs(pchip(xs, ys, x) - want).max() <= 1e-13 * np.abs(want).max()
        if trial % 5 == 0:
            assert (np.diff(pchip(xs, ys, np.linspace(xs[0], xs[-1], 257)), axis=0) >= -1e-12).all()


@pytest.mark.parametrize("rows, mirrored", [(27, True), (26, True), (5, False), (1, True)])
def test_the_kernel_along_x_from_half_the_rows_and_the_positive_lags_is_the_whole_sum(rows, mirrored):
    """kernel_along_x computes the lags ≥ 0 and, where the rows are placed symmetrically (ΔG_ij = ΔG_(n−1−i)(n−1−j)),
    the first half of the rows, and fills in the rest (a quarter of the work): the same as the whole sum written
    out, ΔK_ij(s) = (1/π) Σ_k w_k ΔG_ij(k) B(k) cos(k s), at every lag of either sign and every pair of rows, to
    round-off.  A sample that is not mirrored (5 rows, random) takes every row."""
    from fretsim.compliance.free_faces import K_POINTS, pchip
    rng = np.random.default_rng(rows)
    ks = np.array([0.0, 0.1, 0.3, 1.0, 3.0, 10.0])
    delta = rng.normal(size=(ks.size, rows, rows))
    if mirrored:
        delta = 0.5 * (delta + delta[:, ::-1, ::-1])
    nx, dx = 59, 0.01
    s = (np.arange(2 * nx - 1) - (nx - 1)) * dx
    k = np.linspace(0.0, ks[-1], max(K_POINTS, int(ks[-1] * s[-1] / 0.05) + 1))
    weights = np.full(k.size, k[1] - k[0])
    weights[[0, -1]] *= 0.5
    box = np.where(k > 0, 2 * np.sin(k * dx / 2) / np.where(k > 0, k, 1.0), dx)
    whole = np.einsum("kij,k,ks->ijs", pchip(ks, delta, k), weights * box, np.cos(np.outer(k, s))) / np.pi
    got = kernel_along_x(delta, ks, dx, nx)
    assert got.shape == whole.shape
    assert np.abs(got - whole).max() <= 1e-12 * np.abs(whole).max()
