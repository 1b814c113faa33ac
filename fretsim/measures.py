"""How a worn state is measured: the centre line, the maximum depth and the scar width, computed here once.

The summary, the results file's history, the wear limits, `fit` and the validation report all read a state
through these functions (by way of :mod:`fretsim.quantities`), so a depth or a width means the same thing
wherever it is reported.  Arrays are (My, Mx) fields on the grid, in mm.
"""
from __future__ import annotations

import numpy as np


def centre_line(field_2d: np.ndarray) -> np.ndarray:
    """Values along y = 0: the middle row, or the mean of the two middle rows when My is even."""
    ny = field_2d.shape[0]
    return field_2d[ny // 2] if ny % 2 else 0.5 * (field_2d[ny // 2 - 1] + field_2d[ny // 2])


def max_depth(depth: np.ndarray) -> float:
    """The deepest wear of a body (mm)."""
    return float(depth.max())


def centre_depth(depth: np.ndarray) -> float:
    """The deepest wear along y = 0 (mm): what a profilometer's trace across the scar's middle reads."""
    return float(centre_line(depth).max())


def centre_width(depth: np.ndarray, x: np.ndarray) -> float:
    """The scar width (mm) along y = 0 (:func:`scar_width` of the centre line)."""
    return scar_width(centre_line(depth), x)


def scar_width(profile: np.ndarray, x: np.ndarray, fraction: float = 1e-3) -> float:
    """Width (mm) of the worn zone of a profile: where the depth exceeds ``fraction`` of its maximum.

    Sub-element: the two crossings of the threshold are interpolated linearly between element centres, so
    the width moves continuously with the grid instead of by whole elements.
    """
    peak = float(profile.max())
    if peak <= 0:
        return 0.0
    level = fraction * peak
    above = np.flatnonzero(profile > level)
    i0, i1 = above[0], above[-1]

    def crossing(i_in: int, i_out: int) -> float:
        if i_out < 0 or i_out >= profile.size:
            return float(x[i_in])
        a, b = profile[i_out], profile[i_in]
        return float(x[i_out] + (x[i_in] - x[i_out]) * (level - a) / (b - a))

    return crossing(i1, i1 + 1) - crossing(i0, i0 - 1)


PERCENTILES = (10, 50, 90)  # what a sampled sweep reports of each value (percentiles.csv, the uncertainty figure)


def quantiles(values) -> np.ndarray:
    """P10, P50 and P90 of ``values`` (numbers, inf for a limit not reached): interpolated between the samples
    where all are finite, else the sample at or above each fraction (an inf takes no part in an interpolation).
    ``percentiles.csv`` and the time-to-limit figure both take them from here, so they agree."""
    values = np.sort(np.asarray(values, dtype=float))
    if np.isfinite(values).all():
        return np.percentile(values, PERCENTILES, method="linear")
    return np.array([np.quantile(values, q / 100, method="inverted_cdf") for q in PERCENTILES])


def through_origin(x, y) -> tuple[float, float]:
    """The slope of ``y`` against ``x`` by least squares through the origin, Σxy/Σx², and its scatter: the root
    mean square of y/(slope·x) − 1 over the points with x > 0 (0 for points exactly on the line).  Fouvry's
    energy wear coefficient α is the slope of the worn volume against the cumulative dissipated energy (Fouvry,
    Kapsa & Vincent, Wear 1996); the scatter says how well one straight line holds.  (NaN, NaN) without a point
    off x = 0; non-finite points take no part."""
    x, y = np.asarray(x, dtype=float).ravel(), np.asarray(y, dtype=float).ravel()
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    sxx = float((x * x).sum())
    if sxx <= 0:
        return float("nan"), float("nan")
    slope = float((x * y).sum()) / sxx
    on = x > 0
    if slope == 0:
        return 0.0, 0.0 if not y[on].any() else float("nan")
    return slope, float(np.sqrt(np.mean((y[on] / (slope * x[on]) - 1.0) ** 2)))
