"""The influence operators: closed forms, symmetry, and FFT against the dense matrix."""
from pathlib import Path

import numpy as np
import pytest

from fretsim.compliance import HalfSpace, love_rectangle, strip_plane_strain
from fretsim.grid import Grid

ROUND_OFF = 1e-12  # FFT vs direct summation: both exact up to floating point
CASES = Path(__file__).resolve().parent.parent / "cases"


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
    op = HalfSpace(grid, 1.1e5)
    dense = op.dense()
    p = np.random.default_rng(0).random(grid.shape)
    assert np.abs(dense - dense.T).max() <= ROUND_OFF * np.abs(dense).max()
    assert np.abs(op(p).ravel() - dense @ p.ravel()).max() <= ROUND_OFF * np.abs(dense @ p.ravel()).max()


@pytest.mark.parametrize("shape", [(1, 300, True), (27, 121, False)])
def test_a_few_elements_by_their_columns_equal_the_transform_and_many_are_left_to_it(shape):
    """Convolution.of_few, the solver's update at a step's few clipped or admitted elements: a 9-layer stack with
    elements at the grid's corners and edges (where a column is cut by the window) against the transform to
    round-off; a stack with many is declined (None), so the caller transforms."""
    ny, nx, plane = shape
    op = HalfSpace(Grid.centred(nx, ny, 0.0016, 1.0 if plane else 0.05, plane_strain=plane), 1e5)
    rng = np.random.default_rng(3)
    p = np.zeros((9, ny, nx))
    for k, j, i in ((0, 0, 0), (3, ny - 1, nx - 1), (8, ny // 2, 0), (4, 0, nx // 3), (4, ny - 1, 7)):
        p[k, j, i] = rng.uniform(0.5, 2.0)
    got, full = op.of_few(p), op(p)
    assert got is not None
    assert np.abs(got - full).max() <= ROUND_OFF * np.abs(full).max()
    assert op.of_few(rng.random((9, ny, nx))) is None


def test_3d_compliance_is_positive_definite():
    dense = HalfSpace(Grid.centred(12, 8, 0.01, 0.4), 1.1e5).dense()
    assert np.linalg.eigvalsh(dense).min() > 0


def test_dense_refused_beyond_limit():
    with pytest.raises(ValueError, match="dense compliance"):
        HalfSpace(Grid.centred(100, 100, 0.01, 0.01), 1.1e5).dense()


# --- the operator family: one interface, sums, windows ----------------------------------------------------------

from fretsim.compliance import Convolution, Matrix, Sum, add, scaled  # noqa: E402
from fretsim.compliance import fft as fft_module  # noqa: E402
from fretsim.wear import wear_operator  # noqa: E402


def _dense_apply(op, p):
    return (op.dense() @ p.ravel()).reshape(p.shape)


@pytest.mark.parametrize("grid", [Grid.centred(13, 7, 0.01, 0.3), Grid.centred(15, 1, 0.01, 1.0, plane_strain=True)],
                         ids=["3d", "2d"])
def test_sum_of_half_space_wear_term_and_a_matrix_applies_as_the_sum_of_their_matrices(grid):
    rng = np.random.default_rng(1)
    hs = HalfSpace(grid, 1.1e5)
    w = wear_operator(grid, 0.025, 2e-8, 3e-8, "mid_stroke")
    m = Matrix(grid, np.diag(rng.random(grid.size)) * 1e-6)
    op = Sum(hs, scaled(w, 300.0), m)
    assert op.convolution is not None and len(op.others) == 1  # the two convolutions merged: one FFT pair
    p = rng.random(grid.shape)
    expected = _dense_apply(hs, p) + 300.0 * _dense_apply(w, p) + _dense_apply(m, p)
    assert np.abs(op(p) - expected).max() <= ROUND_OFF * np.abs(expected).max()
    assert np.abs(op.dense() - (hs.dense() + 300.0 * w.dense() + m.dense())).max() <= ROUND_OFF * np.abs(op.dense()).max()


def test_a_window_of_any_operator_is_the_sub_block_of_its_matrix():
    grid = Grid.centred(17, 9, 0.01, 0.2)
    rng = np.random.default_rng(2)
    ops = [HalfSpace(grid, 1.1e5), add(HalfSpace(grid, 1.1e5), scaled(wear_operator(grid, 0.02, 1e-8, 2e-8,
                                                                                     "stroke_average"), 50.0)),
           Sum(HalfSpace(grid, 1.1e5), Matrix(grid, rng.random((grid.size, grid.size)) * 1e-7))]
    rows, cols = slice(2, 7), slice(3, 12)
    idx = np.arange(grid.size).reshape(grid.shape)[rows, cols].ravel()
    for op in ops:
        sub = op.window(rows, cols)
        assert sub.grid.shape == (5, 9) and np.allclose(sub.grid.x, grid.x[cols]) and np.allclose(sub.grid.y, grid.y[rows])
        full = op.dense()[np.ix_(idx, idx)]
        assert np.abs(sub.dense() - full).max() <= ROUND_OFF * np.abs(full).max()
        p = rng.random(sub.grid.shape)
        assert np.abs(sub(p).ravel() - full @ p.ravel()).max() <= 1e-12 * np.abs(full @ p.ravel()).max()


def test_windows_of_one_shape_share_one_symbol_wherever_they_lie():
    op = HalfSpace(Grid.centred(40, 5, 0.01, 0.2), 1.1e5)
    a, b = op.window(slice(0, 5), slice(0, 10)), op.window(slice(0, 5), slice(25, 35))
    assert a.hat is b.hat  # translation invariance: the window's operator depends on its size only


def test_direct_fft_path_equals_the_public_scipy_api():
    """The binding loaded from its file (not through scipy.fft) against scipy.fft's public functions: the padded 2D
    transforms both ways and the axis helpers the kernels' symbols and the fatigue stresses use."""
    import scipy.fft as sfft
    fft_module.forward(np.zeros((1, 3)), (1, 6))
    assert fft_module.DIRECT
    rng = np.random.default_rng(3)
    for shape, p in (((14, 40), rng.random((7, 19))), ((1, 64), rng.random((1, 30)))):
        direct = fft_module.forward(p, shape)
        ly, lx = shape
        public = sfft.fft(sfft.rfft(p, lx, axis=-1), ly, axis=-2) if ly > 1 else sfft.rfft(p, lx, axis=-1)
        assert np.abs(direct - public).max() <= ROUND_OFF * np.abs(public).max()
        back = fft_module.backward(direct, shape, p.shape)
        assert np.abs(back - p).max() <= ROUND_OFF
    q = rng.random((5, 6, 7))
    for axis in (0, 1, -1):
        assert np.abs(fft_module.rfft(q, 12, axis) - sfft.rfft(q, 12, axis=axis)).max() <= ROUND_OFF * 10
        assert np.abs(fft_module.fft(q, 9, axis) - sfft.fft(q, 9, axis=axis)).max() <= ROUND_OFF * 10
        h = sfft.rfft(q, 12, axis=axis)
        assert np.abs(fft_module.irfft(h, 12, axis) - sfft.irfft(h, 12, axis=axis)).max() <= ROUND_OFF


def test_without_the_binding_numpys_fft_stands_in_with_the_same_numbers(monkeypatch):
    """Where scipy's binding cannot be loaded (moved, another scipy), numpy's FFT (pocketfft too) is used: the same
    convolutions to round-off, and nothing fails."""
    rng = np.random.default_rng(8)
    p, shape = rng.random((3, 7, 19)), (14, 40)
    want = fft_module.backward(fft_module.forward(p, shape) * 2.0, shape, (7, 19))
    keep = (fft_module.forward, fft_module.backward, fft_module._along, fft_module.DIRECT)

    def broken():
        raise ImportError("no binding here")
    try:
        monkeypatch.setattr(fft_module, "_binding", broken)
        fft_module._choose()
        assert fft_module.DIRECT is False
        got = fft_module.backward(fft_module.forward(p, shape) * 2.0, shape, (7, 19))
        assert np.abs(got - want).max() <= ROUND_OFF
        assert np.abs(fft_module.rfft(p, 24, 1) - np.fft.rfft(p, 24, axis=1)).max() == 0.0
    finally:
        fft_module.forward, fft_module.backward, fft_module._along, fft_module.DIRECT = keep


def test_a_run_imports_neither_scipys_fft_nor_ndimage_nor_interpolate(tmp_path):
    """A 3D run of the 185 N case in a fresh process: scipy.fft (with scipy.special and the array-API layer),
    scipy.ndimage and scipy.interpolate cost 0.2-0.3 s of every start and are not imported (the FFT binding is
    loaded from its file; the stroke average and the monotone cubic are written here)."""
    import subprocess
    import sys
    code = ("import sys; from fretsim.api import load_case, run; "
            f"run(load_case({str(CASES / 'mccoll_185N.yaml')!r}, ['loading.cycles=100', 'grid.error_estimate=none'])); "
            "print(sorted(m for m in ('scipy.fft', 'scipy.ndimage', 'scipy.interpolate', 'scipy.special') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_fft_sizes_are_scipys_next_fast_len_without_importing_scipy():
    # the padded lengths decide every convolution's round-off: they must be exactly the ones scipy would choose
    import scipy.fft as sfft
    rng = np.random.default_rng(4)
    for n in [*range(1, 3000), *rng.integers(3000, 5_000_000, 400).tolist()]:
        for real in (True, False):
            assert fft_module.next_fast_len(n, real) == sfft.next_fast_len(n, real=real), (n, real)


def test_planning_imports_no_fft_and_the_first_transform_does():
    # `fretsim check` and `summary` start without scipy's FFT (a third of their time); an operator built while
    # planning is transformed at its first use, to the same symbol as an eager transform
    import subprocess
    import sys
    code = ("import sys; from fretsim.api import check, load_case; "
            "check(load_case(sys.argv[1], ['model.dimension=2d'])); "
            "print('scipy.fft' in sys.modules, 'scipy.linalg' in sys.modules, 'scipy.ndimage' in sys.modules)")
    case = str(Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml")
    out = subprocess.run([sys.executable, "-c", code, case], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False", "False"], out
    grid = Grid.centred(15, 7, 0.01, 0.2)
    lazy = HalfSpace(grid, 1.1e5)
    eager = Convolution(grid, lazy.kernel, lazy._transform(lazy.kernel))
    assert np.array_equal(lazy.hat, eager.hat)
    s = lazy.plus(wear_operator(grid, 0.025, 2e-8, 3e-8, "mid_stroke"), 300.0)
    assert np.array_equal(s.hat, lazy.hat + 300.0 * wear_operator(grid, 0.025, 2e-8, 3e-8, "mid_stroke").hat)


def test_the_operator_in_single_precision_is_the_double_one_to_six_digits():
    """Convolution.single (a solver's search directions, fretsim.solvers.rows.cg_coupled): float32 transforms and
    symbol, about seven digits; the convolution of a random stack within 1e-6 of its largest value (float32's
    epsilon 6e-8 times the transforms' log-length growth), and float32 out."""
    grid = Grid.centred(40, 27, 0.01, 0.2)
    op = HalfSpace(grid, 1.1e5)
    p = np.random.default_rng(2).random((3,) + grid.shape)
    got, want = op.single()(p), op(p)
    assert got.dtype == np.float32
    assert np.abs(got - want).max() < 1e-6 * np.abs(want).max()
    assert np.abs(got - want).max() > 0.0  # (it is single precision)
