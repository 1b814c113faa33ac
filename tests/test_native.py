"""scipy's kernels loaded from their files (fretsim.native): the same products as numpy's, a stand-in where they
are missing, and a resolved run that imports none of their packages."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fretsim import native

CASES = Path(__file__).resolve().parent.parent / "cases"


def _random_matrix(rng, n_rows=30, n_cols=45, entries=400):
    rows = np.sort(rng.integers(0, n_rows - 3, entries))  # (the last rows empty; duplicate entries)
    cols = rng.integers(0, n_cols, entries)
    values = rng.normal(size=entries)
    dense = np.zeros((n_rows, n_cols))
    np.add.at(dense, (rows, cols), values)
    return native.RowMatrix(rows, cols, (n_rows, n_cols)), values, dense


def test_a_row_matrix_and_its_transpose_multiply_as_the_dense_matrix_does():
    rng = np.random.default_rng(3)
    a, values, dense = _random_matrix(rng)
    x, z = rng.normal(size=45), rng.normal(size=30)
    # (sums of at most a few dozen products of order 1: round-off a few 1e-15)
    assert np.abs(a.dot(values, x) - dense @ x).max() < 1e-13
    assert np.abs(a.dot_transposed(values, z) - dense.T @ z).max() < 1e-13
    other = rng.normal(size=values.size)  # another matrix on the same entries
    dense2 = np.zeros(dense.shape)
    np.add.at(dense2, (a.rows, a.indices), other)
    assert np.abs(a.dot(other, x) - dense2 @ x).max() < 1e-13


def test_scatter_add_is_numpys_bincount_of_the_products_bit_for_bit():
    """The sweep's deposit and read (fretsim.wear.Sweep) add each entry's product in the entries' order, as
    bincount did: the same sums, not only to round-off."""
    rng = np.random.default_rng(11)
    rows, cols = rng.integers(0, 50, 3000), rng.integers(0, 80, 3000)
    values, x = rng.normal(size=3000), rng.normal(size=80)
    assert np.array_equal(native.scatter_add(rows, cols, values, x, 60),
                          np.bincount(rows, weights=x[cols] * values, minlength=60))


def test_without_scipys_kernels_numpys_products_stand_in_with_the_same_numbers(monkeypatch):
    rng = np.random.default_rng(5)
    a, values, dense = _random_matrix(rng)
    x, z = rng.normal(size=45), rng.normal(size=30)
    want = a.dot(values, x), a.dot_transposed(values, z)
    want_scatter = native.scatter_add(a.rows, a.indices, values, x, 30)
    monkeypatch.setattr(native, "_KERNELS", None)
    monkeypatch.setattr(native, "load", lambda *args: None)
    got = a.dot(values, x), a.dot_transposed(values, z)
    assert native._KERNELS[0] is native._numpy_dot
    assert np.abs(got[0] - want[0]).max() < 1e-13 and np.abs(got[1] - want[1]).max() < 1e-13
    assert np.array_equal(native.scatter_add(a.rows, a.indices, values, x, 30), want_scatter)


def test_a_row_matrix_refuses_rows_out_of_order_and_entries_outside_its_shape():
    # (the compiled kernel does not check its indices: outside the arrays it read garbage and crashed the process)
    with pytest.raises(ValueError, match="ascending"):
        native.RowMatrix(np.array([0, 2, 1]), np.array([0, 0, 0]), (3, 1))
    with pytest.raises(ValueError, match="shape"):
        native.RowMatrix(np.array([0, 1]), np.array([0, 5]), (2, 3))
    with pytest.raises(ValueError, match="shape"):
        native.RowMatrix(np.array([0, 2]), np.array([0, 1]), (2, 3))
    with pytest.raises(ValueError, match="lie in"):
        native.scatter_add(np.array([0, 7]), np.array([0, 1]), np.ones(2), np.ones(2), 3)
    with pytest.raises(ValueError, match="lie in"):
        native.scatter_add(np.array([0, 1]), np.array([0, 2]), np.ones(2), np.ones(2), 3)


def test_a_resolved_run_imports_no_scipy_package():
    """McColl 185 N 2D with the stroke resolved in a fresh process: its coupled steps' sparse products load
    sparsetools from its file; ``import scipy.sparse`` (0.13-0.2 s: the array-API layer, numpy.f2py) was a fifth of
    the run."""
    code = ("import sys; from fretsim.api import load_case, run; "
            f"o = run(load_case({str(CASES / 'mccoll_185N.yaml')!r}, ['model.dimension=2d', 'loading.cycles=2000', "
            "'loading.friction_coefficient=0.9', 'model.slip=coulomb', 'model.stroke=resolved', "
            "'grid.error_estimate=none'])); "
            "print(o.status, 'scipy.sparse._sparsetools' in sys.modules, "
            "sorted(m for m in sys.modules if m.startswith('scipy') and not m.endswith(('_sparsetools', 'pypocketfft'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=CASES)
    status, coupled, modules = out.stdout.strip().splitlines()[-1].split(" ", 2)
    assert status == "complete" and coupled == "True"  # (the coupled steps' products ran)
    assert modules == "[]", modules


def test_lapacks_banded_cholesky_and_generalised_eigenvalues_are_scipy_linalgs_bit_for_bit():
    """Loaded from scipy's _flapack file, the free faces' banded solve and the window spectrum's eigenvalues are the
    very routines scipy.linalg calls (dpbtrf/dpbtrs, dsygvd): the same numbers bit for bit; a matrix that is not
    positive definite is refused, not solved."""
    import scipy.linalg as sla
    rng = np.random.default_rng(3)
    n, band = 120, 6
    a = np.zeros((n, n))
    for d in range(band + 1):
        v = rng.normal(size=n - d)
        a += np.diag(v, d) + (np.diag(v, -d) if d else 0.0)
    a += 3 * (2 * band + 5) * np.eye(n)
    ab = np.zeros((band + 1, n))
    for d in range(band + 1):
        ab[band - d, d:] = np.diag(a, d)
    b = rng.normal(size=(n, 4))
    ref = sla.cho_solve_banded((sla.cholesky_banded(ab.copy(), check_finite=False), False), b, check_finite=False)
    assert np.array_equal(native.banded_cholesky_solve(ab.copy(), b), ref)
    assert np.abs(a @ ref - b).max() < 1e-12
    m = rng.normal(size=(40, 40))
    c, w = m @ m.T + 40 * np.eye(40), m + m.T
    assert np.array_equal(native.generalized_eigenvalues(w, c), sla.eigh(w, c, eigvals_only=True))
    with pytest.raises(np.linalg.LinAlgError):
        native.banded_cholesky_solve(-ab.copy(), b)
    with pytest.raises(np.linalg.LinAlgError):
        native.generalized_eigenvalues(w, -c)


def test_planning_a_free_faces_case_imports_no_scipy_package():
    """`check` of McColl 185 N with the free faces (two 3D proxies, the faces' finite-element blocks, the window
    spectrum) in a fresh process: LAPACK loaded from its file; ``import scipy.linalg`` (0.13 s) was an eighth of it."""
    code = ("import sys; from fretsim.api import load_case; from fretsim.plan import prepare; "
            f"setup, filled, plan = prepare(load_case({str(CASES / 'mccoll_185N_free_faces.yaml')!r})); "
            "print('free_faces' in str(filled.to_dict()), "
            "sorted(m for m in sys.modules if m.startswith('scipy') and not m.endswith(('_flapack', 'pypocketfft'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=CASES)
    kept, modules = out.stdout.strip().splitlines()[-1].split(" ", 1)
    assert kept == "True"  # (auto kept the faces: their blocks and spectrum were computed)
    assert modules == "[]", modules
