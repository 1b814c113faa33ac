"""Coarse ↔ fine grid transfer: the paper's refinement methodology (section 2.1.2, Eqs. 11–12).

The contact is solved on a coarse grid; its forces are redistributed onto the
fine grid one direction at a time: in each coarse row the forces are turned
into weights (force × number of columns / row total, so they average 1),
the weights are interpolated to the fine columns with Akima's spline (which
does not overshoot near the flat zero tails), and the row total is shared out
in proportion; then the same across y.  Totals are preserved exactly, so the
load is.  Wear goes the other way by conservative averaging (overlap-weighted),
which preserves the wear volume exactly.
"""
from __future__ import annotations

import numpy as np

from fretsim.grid import Grid


def _edges(centres: np.ndarray, size: float) -> np.ndarray:
    return np.concatenate([centres - size / 2, [centres[-1] + size / 2]])


def averaging_matrix(src_centres: np.ndarray, src_size: float, dst_centres: np.ndarray, dst_size: float) -> np.ndarray:
    """R[i, j] = overlap(dst_i, src_j) / dst_size: dst values as overlap-weighted averages of src values."""
    se, de = _edges(src_centres, src_size), _edges(dst_centres, dst_size)
    lo = np.maximum(de[:-1, None], se[None, :-1])
    hi = np.minimum(de[1:, None], se[None, 1:])
    return np.clip(hi - lo, 0.0, None) / dst_size


def coarsen(field: np.ndarray, fine: Grid, coarse: Grid) -> np.ndarray:
    """Average a fine field (e.g. wear depth) onto the coarse grid; Σ h·A is preserved when both span one domain."""
    rx = averaging_matrix(fine.x, fine.dx, coarse.x, coarse.dx)
    out = field @ rx.T
    if not fine.plane_strain:
        out = averaging_matrix(fine.y, fine.dy, coarse.y, coarse.dy) @ out
    return out


def _redistribute(forces: np.ndarray, src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Share each row's total over the dst positions with Akima-interpolated weights (rows: axis 0).

    All rows are interpolated in one vector-valued spline; rows carrying no force stay zero.
    """
    totals = forces.sum(axis=1)
    loaded = totals > 0
    out = np.zeros((forces.shape[0], dst.size))
    if not loaded.any():
        return out
    weights = forces[loaded] * (forces.shape[1] / totals[loaded, None])  # Eq. 11: weights average 1 per row
    if src.size < 3:
        fine = np.array([np.interp(dst, src, w) for w in weights])
    else:
        from scipy.interpolate import Akima1DInterpolator  # only refined runs need it (~0.2 s to import)
        fine = Akima1DInterpolator(src, weights, axis=1, extrapolate=True)(dst)
    fine = np.clip(np.nan_to_num(fine), 0.0, None)
    sums = fine.sum(axis=1, keepdims=True)
    out[loaded] = np.where(sums > 0, fine * (totals[loaded, None] / np.where(sums > 0, sums, 1.0)), 0.0)  # Eq. 12
    return out


def refine_pressure(pressure: np.ndarray, coarse: Grid, fine: Grid) -> np.ndarray:
    """Coarse element pressures → fine element pressures with the same total force (along x, then along y)."""
    forces = pressure * coarse.area
    along_x = _redistribute(forces, coarse.x, fine.x)  # (My_c, Mx_f)
    if fine.plane_strain:
        return along_x / fine.area
    both = _redistribute(along_x.T, coarse.y, fine.y).T  # (My_f, Mx_f)
    return both / fine.area


def mape(reference: np.ndarray, approx: np.ndarray) -> float:
    """Mean absolute percentage error over the elements the reference has in contact (paper Fig. 9)."""
    on = reference > 0
    return float(100.0 * np.mean(np.abs(approx[on] - reference[on]) / reference[on]))
