"""How a worn state is measured: the centre line, the maximum depth and the scar width, computed here once.

The summary, the results file's history, the wear limits, `fit` and the validation report all read a state
through these functions (by way of :mod:`fretsim.quantities`), so a depth or a width means the same thing
wherever it is reported.  Arrays are (My, Mx) fields on the grid, in mm.
"""
from __future__ import annotations

import math

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

    Sub-element: each edge's crossing of the threshold lies between the last element centre above it (depth b)
    and the first at or below it (depth a).  It is read as the later of
    - the logarithm's linear interpolation between b and a (a tail that decays geometrically: the worn flat's,
      whose stroke-averaged wear fades over several elements), none where a = 0;
    - the secant through the last two centres above the threshold, continued (a profile that ends inside the
      element: the moving body's, whose depth falls about linearly to the edge of its largest contact), but not
      past the chord from b to a.
    Both lie between the centres and vary continuously with a.  The chord alone (linear interpolation of the
    depths), used before, put the edge up to a whole element outside it: 1.2-2.2 element widths of error in the
    width against runs 4× finer, where this reading is within 0.3-1.0 (``scripts/study_width_error.py``).
    """
    peak = float(profile.max())
    if peak <= 0:
        return 0.0
    level = fraction * peak
    above = np.flatnonzero(profile > level)
    return _crossing(profile, x, level, above[-1], 1) - _crossing(profile, x, level, above[0], -1)


def _crossing(profile: np.ndarray, x: np.ndarray, level: float, i_in: int, step: int) -> float:
    """Where the depth falls through ``level`` between element ``i_in`` (above it) and its neighbour ``step`` on."""
    i_out, i_prev = i_in + step, i_in - step
    if i_out < 0 or i_out >= profile.size:
        return float(x[i_in])
    a, b = float(profile[i_out]), float(profile[i_in])
    c = float(profile[i_prev]) if 0 <= i_prev < profile.size else b
    chord = (b - level) / (b - a)
    secant = (b - level) / (c - b) if c > b else chord
    geometric = math.log(b / level) / math.log(b / a) if a > 0 else 0.0
    t = min(max(geometric, min(secant, chord)), 1.0)
    return float(x[i_in] + (x[i_out] - x[i_in]) * t)


PERCENTILES = (10, 50, 90)  # what a sampled sweep reports of each value (percentiles.csv, the uncertainty figure)


def quantiles(values) -> np.ndarray:
    """P10, P50 and P90 of ``values`` (numbers, inf for a limit not reached), each sample at the middle of its share of
    the probability (Hazen's (i + ½)/n, the middle of its Latin-hypercube stratum: fretsim.uncertainty) and
    interpolated between them; where the upper of the two is inf (beyond the run) the lower, which the percentile is
    at least (a time to a limit read short, not long), and inf where both are.  ``percentiles.csv`` and the time-to-
    limit figure both take them from here, so they agree.  numpy's default plotting position i/(n − 1) puts the
    extreme samples at 0 and 1 where their strata's middles are ½/n and 1 − ½/n: at n = 10 it read P10 and P90 of a
    lognormal (factor 2) 14 % and 10 % towards the median, a band too narrow and a time-to-limit P10 too long (a
    review's 300 seeds).  A percentile on a stratum's edge is now interpolated between the two samples that bracket
    it, and errs outwards by the quantile function's curvature over one stratum (that P90 7 % high at n = 10, under
    2 % at n = 60): a band a little too wide."""
    values = np.sort(np.asarray(values, dtype=float))
    n = values.size
    out = []
    for q in PERCENTILES:
        pos = min(max(q / 100 * n - 0.5, 0.0), n - 1.0)
        lo = int(math.floor(pos))
        hi, w = min(lo + 1, n - 1), pos - lo
        a, b = values[lo], values[hi]
        out.append(a if w == 0 or a == b or not np.isfinite(b) else a + w * (b - a))
    return np.array(out, dtype=float)


def column_quantiles(values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P10, P50 and P90 of each column of ``values`` (samples, points) as :func:`quantiles` reads them, its NaNs
    (a sample that has stopped) left out; NaN where a column has none.  The uncertainty figure's depth band, so that
    it reads its samples as ``percentiles.csv`` does."""
    values = np.asarray(values, dtype=float)
    out = np.full((len(PERCENTILES), values.shape[1]), np.nan)
    for j in range(values.shape[1]):
        column = values[:, j][~np.isnan(values[:, j])]
        if column.size:
            out[:, j] = quantiles(column)
    return out[0], out[1], out[2]


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
