"""scipy's compiled kernels, called without importing their packages.

The solver's inner loops use two of scipy's extension modules: pocketfft (the transforms,
:mod:`fretsim.compliance.fft`) and sparsetools (the resolved stroke's sparse read and deposit,
:func:`row_matrix`); planning a free-faces case uses LAPACK's banded Cholesky and generalised symmetric eigenvalues
(:func:`banded_cholesky_solve`, :func:`generalized_eigenvalues`, from scipy's ``_flapack``; ``import scipy.linalg``
is 0.13 s).  Their packages cost far more to import than the kernels do to load: ``import scipy.fft``
0.2-0.3 s (scipy.special, the array-API layer), ``import scipy.sparse`` 0.13-0.2 s (the array-API layer and
numpy.f2py) — a fifth of a 2D resolved run, paid again by every process of a sweep.  The extension modules load
in under a millisecond and need neither.  Each is loaded from its file where scipy keeps it and checked against
numpy before use; numpy's own functions stand in where it is missing or disagrees (the same numbers).
"""
from __future__ import annotations

from typing import Optional

import numpy as np


def load(relative: str, name: str):
    """scipy's extension module ``name`` (e.g. ``scipy.sparse._sparsetools``) from its file ``relative`` to the
    scipy package (``sparse/_sparsetools``), without running any package's ``__init__``; None where not found."""
    import importlib.machinery
    import importlib.util
    from pathlib import Path
    spec = importlib.util.find_spec("scipy")  # (finds the package without running it)
    for base in (spec.submodule_search_locations or []) if spec is not None else []:
        for suffix in importlib.machinery.EXTENSION_SUFFIXES:
            path = Path(base) / f"{relative}{suffix}"
            if path.is_file():
                loader = importlib.machinery.ExtensionFileLoader(name, str(path))
                module = importlib.util.module_from_spec(importlib.util.spec_from_file_location(name, path,
                                                                                                loader=loader))
                loader.exec_module(module)
                return module
    return None


class RowMatrix:
    """A sparse matrix stored by rows (CSR) from its entries (``rows`` ascending, ``cols``), whose values are given
    with each product: one structure serves several matrices with the same entries (the resolved stroke's read,
    and its deposit, which is the read's transpose with other weights).  Duplicate entries add."""

    def __init__(self, rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int]):
        if rows.size and (np.diff(rows) < 0).any():
            raise ValueError("a RowMatrix's rows must be ascending")
        if max(shape) >= 2 ** 31 or rows.size >= 2 ** 31:
            raise ValueError("a RowMatrix this large needs 64-bit indices")
        if rows.size and (rows[0] < 0 or rows[-1] >= shape[0] or cols.min() < 0 or cols.max() >= shape[1]):
            raise ValueError("a RowMatrix's entries must lie in its shape")  # (the kernel does not check: it would
            #                                                                   read and write past the arrays)
        self.shape = shape
        self.rows, self.indices = rows.astype(np.int32), cols.astype(np.int32)
        self.indptr = np.zeros(shape[0] + 1, np.int32)
        np.cumsum(np.bincount(rows, minlength=shape[0]), out=self.indptr[1:])

    def dot(self, values: np.ndarray, x: np.ndarray) -> np.ndarray:
        """A·x, A the matrix with these entries' ``values``."""
        return _kernels()[0](self, np.ascontiguousarray(values, float), np.ascontiguousarray(x, float))

    def dot_transposed(self, values: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Aᵀ·x."""
        return _kernels()[1](self, np.ascontiguousarray(values, float), np.ascontiguousarray(x, float))


def scatter_add(rows: np.ndarray, cols: np.ndarray, values: np.ndarray, x: np.ndarray, size: int) -> np.ndarray:
    """y (``size``) with y[rows[k]] += values[k]·x[cols[k]] over the entries in order: a sparse matrix's product
    from its entries, unsorted (numpy's bincount of the products: the same sums in the same order, where
    sparsetools' coo_matvec saves the products' array and is 1.7x faster)."""
    if rows.size and (rows.min() < 0 or rows.max() >= size or cols.min() < 0 or cols.max() >= x.size):
        raise ValueError("scatter_add's entries must lie in y and x")  # (the kernel does not check)
    return _kernels()[2](rows, cols, np.ascontiguousarray(values, float), np.ascontiguousarray(x, float), size)


def _numpy_scatter_add(rows, cols, values, x, size):
    return np.bincount(rows, weights=x[cols] * values, minlength=size)


def _numpy_dot(a: RowMatrix, values, x):
    return np.bincount(a.rows, weights=values * x[a.indices], minlength=a.shape[0])


def _numpy_dot_transposed(a: RowMatrix, values, x):
    return np.bincount(a.indices, weights=values * x[a.rows], minlength=a.shape[1])


_KERNELS: Optional[tuple] = None


def _kernels() -> tuple:
    """sparsetools' products (its CSR and, read as the transpose's CSC, the same arrays), checked against numpy's
    on a small random matrix; numpy's where they are missing or disagree."""
    global _KERNELS
    if _KERNELS is None:
        _KERNELS = (_numpy_dot, _numpy_dot_transposed, _numpy_scatter_add)
        try:
            tools = load("sparse/_sparsetools", "scipy.sparse._sparsetools")
            if tools is not None:
                def dot(a, values, x):
                    y = np.zeros(a.shape[0])
                    tools.csr_matvec(a.shape[0], a.shape[1], a.indptr, a.indices, values, x, y)
                    return y

                def dot_transposed(a, values, x):
                    y = np.zeros(a.shape[1])
                    tools.csc_matvec(a.shape[1], a.shape[0], a.indptr, a.indices, values, x, y)
                    return y
                def scatter(rows, cols, values, x, size):
                    y = np.zeros(size)
                    if cols.dtype != rows.dtype:
                        cols = cols.astype(rows.dtype)
                    tools.coo_matvec(rows.size, rows, cols, values, x, y)
                    return y
                if _agrees(dot, dot_transposed, scatter):
                    _KERNELS = (dot, dot_transposed, scatter)
        except Exception:  # noqa: BLE001 - any problem with the private module means: numpy's products
            pass
    return _KERNELS


def _agrees(dot, dot_transposed, scatter) -> bool:
    rng = np.random.default_rng(0)
    rows = np.sort(rng.integers(0, 7, 40))
    a = RowMatrix(rows, rng.integers(0, 11, 40), (9, 11))  # (rows 7, 8 empty; duplicates)
    values, x, z = rng.random(40), rng.random(11), rng.random(9)
    shuffled = rng.permutation(40)
    return bool(np.allclose(dot(a, values, x), _numpy_dot(a, values, x), rtol=1e-13, atol=1e-14) and
                np.allclose(dot_transposed(a, values, z), _numpy_dot_transposed(a, values, z), rtol=1e-13,
                            atol=1e-14) and
                np.array_equal(scatter(rows[shuffled], a.indices[shuffled].astype(np.int64), values[shuffled], x, 9),
                               _numpy_scatter_add(rows[shuffled], a.indices[shuffled], values[shuffled], x, 9)))


# --- LAPACK (scipy.linalg's own wrappers, loaded from their file) ------------------------------------------------

_LAPACK: Optional[object] = None


def _lapack():
    """scipy's ``_flapack`` from its file, or scipy.linalg.lapack itself where that cannot be loaded (the same
    routines; only the import costs more)."""
    global _LAPACK
    if _LAPACK is None:
        try:
            _LAPACK = load("linalg/_flapack", "scipy.linalg._flapack")
        except Exception:  # noqa: BLE001 - any problem with the private module means: the public one
            _LAPACK = None
        if _LAPACK is None or not all(hasattr(_LAPACK, f) for f in ("dpbtrf", "dpbtrs", "dsygvd")):
            import scipy.linalg.lapack as _LAPACK_PUBLIC
            _LAPACK = _LAPACK_PUBLIC
    return _LAPACK


def banded_cholesky_solve(ab: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with A x = b for A symmetric positive definite in LAPACK's upper band storage ``ab`` (band + 1, n), as
    scipy.linalg's cholesky_banded and cho_solve_banded compute it (dpbtrf, dpbtrs); ``ab`` is overwritten.
    numpy.linalg.LinAlgError where A is not positive definite."""
    if b.shape[0] != ab.shape[1]:
        raise ValueError(f"the right-hand side has {b.shape[0]} rows for a matrix of order {ab.shape[1]}")
    lapack = _lapack()
    c, info = lapack.dpbtrf(ab, lower=0, overwrite_ab=1)
    if info > 0:
        raise np.linalg.LinAlgError(f"the {info}-th leading minor of a banded matrix is not positive definite")
    if info < 0:
        raise ValueError(f"dpbtrf: illegal value in argument {-info}")
    x, info = lapack.dpbtrs(c, b, lower=0)
    if info != 0:
        raise ValueError(f"dpbtrs: illegal value in argument {-info}")
    return x


def generalized_eigenvalues(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The eigenvalues, ascending, of a v = λ b v for a symmetric and b symmetric positive definite (their lower
    triangles read), as scipy.linalg.eigh(a, b, eigvals_only=True) computes them (dsygvd).  numpy.linalg.LinAlgError
    where b is not positive definite or the iteration fails."""
    w, _, info = _lapack().dsygvd(a, b, itype=1, jobz="N", uplo="L")
    if info != 0:
        raise np.linalg.LinAlgError(f"dsygvd failed (info {info}): "
                                    + ("b is not positive definite" if info > a.shape[0] else "no convergence"))
    return w
