"""Normal-contact solvers behind one signature, chosen by name.

Every solver is a function ``solver(compliance, gap, load, p0, tol, max_iter) -> ContactResult``
that finds element pressures p ≥ 0 and an approach α with

    separation Y = gap + C p − α ≥ 0,  p·Y = 0,  Σ p·A = load        (paper Eqs. 1–4)

``gap`` may be +inf where no contact is possible (beyond a cylinder's end).
Solvers never raise on non-convergence: they return ``success=False`` and a
message, and the caller decides.  Bad input raises ``ValueError`` in
:func:`solve` before any solver runs.
"""
from __future__ import annotations

from typing import Callable, Optional

import numpy as np

from fretsim.solvers.result import ContactResult, complementarity_residual
from fretsim.solvers.cg import solve_cg
from fretsim.solvers.msm import solve_msm
from fretsim.solvers.active_set import solve_active_set

Solver = Callable[..., ContactResult]

SOLVERS: dict[str, Solver] = {
    "cg": solve_cg,  # Polonsky–Keer constrained conjugate gradient, FFT: the workhorse
    "msm": solve_msm,  # the paper's Modified Simplex Method (dense, small grids)
    "active_set": solve_active_set,  # dense active-set Newton (small grids): an independent check
}
DENSE_SOLVERS = frozenset({"msm", "active_set"})
DEFAULT_TOL = 1e-10
MIN_ELEMENTS_ACROSS_CONTACT = 4

__all__ = ["ContactResult", "SOLVERS", "DENSE_SOLVERS", "solve", "check_resolution", "DEFAULT_TOL"]


def solve(compliance, gap: np.ndarray, load: float, *, method: str = "cg",
          p0: Optional[np.ndarray] = None, tol: float = DEFAULT_TOL, max_iter: Optional[int] = None) -> ContactResult:
    """Solve the normal contact on ``compliance.grid`` for ``gap`` (mm) and ``load`` (N; N/mm in 2D).

    Raises ``ValueError`` for bad input: unknown method, non-positive or
    non-finite load, a gap of the wrong shape, with NaN, or allowing no contact.
    """
    if method not in SOLVERS:
        import difflib
        hint = difflib.get_close_matches(method, SOLVERS, n=1)
        raise ValueError(f"unknown contact solver {method!r}" + (f" (did you mean {hint[0]!r}?)" if hint else "")
                         + f"; registered solvers: {', '.join(sorted(SOLVERS))}")
    if not (np.isfinite(load) and load > 0):
        raise ValueError(f"the normal load must be positive and finite, got {load}")
    gap = np.asarray(gap, dtype=float)
    if gap.shape != compliance.shape:
        raise ValueError(f"gap has shape {gap.shape}, the grid {compliance.shape}")
    if np.isnan(gap).any() or np.isneginf(gap).any():
        raise ValueError("the gap contains NaN or -inf")
    if not np.isfinite(gap).any():
        raise ValueError("the gap allows no contact anywhere on the grid (it is infinite everywhere)")
    if p0 is not None:
        p0 = np.asarray(p0, dtype=float)
        if p0.shape != gap.shape or not np.isfinite(p0).all() or not (p0 > 0).any():
            p0 = None  # an unusable warm start is dropped, not an error
    if method in DENSE_SOLVERS or p0 is None or not hasattr(compliance, "window"):
        return SOLVERS[method](compliance, gap, float(load), p0, float(tol), max_iter)
    return _solve_windowed(SOLVERS[method], compliance, gap, float(load), p0, float(tol), max_iter)


WINDOW_MARGIN = (6, 0.25)  # elements added round the warm start's contact: at least 6, or a quarter of its width
PENETRATION = 1e-6  # as the solvers' own complementarity test, relative to the displacement scale


def _span(mask_1d: np.ndarray, n: int, extra: Optional[np.ndarray] = None) -> slice:
    idx = np.flatnonzero(mask_1d if extra is None else (mask_1d | extra))
    width = idx[-1] - idx[0] + 1
    margin = max(WINDOW_MARGIN[0], int(WINDOW_MARGIN[1] * width))
    return slice(max(0, idx[0] - margin), min(n, idx[-1] + margin + 1))


def _solve_windowed(solver, compliance, gap, load, p0, tol, max_iter) -> ContactResult:
    """Solve on the neighbourhood of the warm start's contact, then verify complementarity on the whole grid.

    Pressure is zero outside the window, so the displacement inside it is exact; outside, one full
    application checks that nothing penetrates.  If something does (the contact outgrew the window), the
    window grows to include it and the solve continues from where it was.  Far cheaper while the contact is
    small against a grid sized for the final wear scar.
    """
    ny, nx = gap.shape
    finite = np.isfinite(gap)
    on = p0 > 0
    extra_rows = extra_cols = None
    p_start = p0
    for _ in range(4):
        rows = _span(on.any(axis=1), ny, extra_rows)
        cols = _span(on.any(axis=0), nx, extra_cols)
        if rows.stop - rows.start == ny and cols.stop - cols.start == nx:
            return solver(compliance, gap, load, p_start, tol, max_iter)
        res = solver(compliance.window(rows, cols), gap[rows, cols], load, p_start[rows, cols], tol, max_iter)
        p = np.zeros_like(gap)
        p[rows, cols] = res.pressure
        if not res.success:
            return _embed(res, p)
        u = compliance(p)
        g = np.where(finite, u + gap - res.approach, np.inf)
        scale = max(float(np.abs(u[p > 0]).max()), 1e-300)
        inside = np.zeros(gap.shape, bool)
        inside[rows, cols] = True
        bad = ~inside & (g < -PENETRATION * scale)
        if not bad.any():
            return _embed(res, p, complementarity_residual(u, gap, p, res.approach))
        extra_rows, extra_cols = bad.any(axis=1), bad.any(axis=0)
        on, p_start = p > 0, p
    return solver(compliance, gap, load, p_start, tol, max_iter)


def _embed(res: ContactResult, p: np.ndarray, residual: float = float("nan")) -> ContactResult:
    from dataclasses import replace
    return replace(res, pressure=p, contact=p > 0, residual=residual)


def check_resolution(result: ContactResult, plane_strain: bool) -> None:
    """Raise ``ValueError`` if the contact spans too few elements to be resolved."""
    if not result.success:
        return
    across_x = int(result.contact.sum(axis=1).max())
    across_y = int(result.contact.sum(axis=0).max())
    too_coarse = across_x < MIN_ELEMENTS_ACROSS_CONTACT or (
        not plane_strain and result.contact.shape[0] > 1 and across_y < MIN_ELEMENTS_ACROSS_CONTACT)
    if too_coarse:
        raise ValueError(f"the grid is too coarse to resolve the contact: it spans {across_x} element(s) along x"
                         + ("" if plane_strain else f" and {across_y} along y")
                         + f"; at least {MIN_ELEMENTS_ACROSS_CONTACT} are needed (refine the grid)")
