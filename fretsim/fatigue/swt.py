"""Multiaxial fatigue on the critical plane: the Smith–Watson–Topper parameter, its life from the
Basquin–Coffin–Manson curve, and Ruiz's fretting damage parameter.

SWT on a plane of normal n over a cycle is σ_n,max·Δε_n/2: the largest normal stress on the plane times half the
range of its normal strain.  The critical plane is the one where it is largest; in plane strain (2D) the normals
are searched over angles in the (x, z) plane.  The life N_i (cycles to crack initiation) solves

    SWT = (σ'_f²/E)·(2N)^(2b) + σ'_f·ε'_f·(2N)^(b+c),

monotone in N for b, c < 0, by bisection on log N.  Ruiz's parameter σ_t·τ·δ (the surface's largest tensile
stress, its shear traction and its slip, MPa·MPa·mm) is the cheap companion fretting designers quote beside it.

Pure functions over arrays: stresses in MPa, strains dimensionless, moduli in MPa.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

ANGLES = 180  # plane normals searched in 2D: every degree (the parameter is π-periodic in the angle)


@dataclass(frozen=True)
class Basquin:
    """The strain-life curve's constants (``materials.<body>.fatigue``)."""

    strength_coefficient: float  # σ'_f, MPa
    strength_exponent: float  # b (< 0)
    ductility_coefficient: float  # ε'_f
    ductility_exponent: float  # c (< 0)
    youngs_modulus: float  # E, MPa
    endurance_limit: Optional[float] = None  # an SWT below it never cracks (MPa); None: the curve alone

    def swt(self, cycles: float) -> float:
        """The SWT value (MPa) that cracks in ``cycles``."""
        two_n = 2.0 * cycles
        f, b = self.strength_coefficient, self.strength_exponent
        return f * f / self.youngs_modulus * two_n ** (2 * b) + f * self.ductility_coefficient * two_n ** (
            b + self.ductility_exponent)

    def life(self, swt: float, longest: float = 1e30) -> float:
        """Cycles to crack initiation at ``swt`` (MPa); inf below the endurance limit or beyond ``longest``."""
        if not swt > 0 or (self.endurance_limit is not None and swt <= self.endurance_limit):
            return math.inf
        if swt <= self.swt(longest):
            return math.inf
        lo, hi = 0.25, longest  # swt(lo) is above any SWT that matters (a quarter of a reversal)
        if swt >= self.swt(lo):
            return lo
        for _ in range(200):
            mid = math.sqrt(lo * hi)
            if self.swt(mid) > swt:
                lo = mid
            else:
                hi = mid
            if hi / lo < 1 + 1e-12:
                break
        return math.sqrt(lo * hi)


    def lives(self, swt: np.ndarray, longest: float = 1e30) -> np.ndarray:
        """:meth:`life` at every entry of an array (bisection on log N, all entries at once)."""
        swt = np.asarray(swt, dtype=float)
        floor = max(self.swt(longest), self.endurance_limit if self.endurance_limit is not None else 0.0)
        out = np.full(swt.shape, np.inf)
        live = swt > floor
        if not live.any():
            return out
        target = swt[live]
        lo, hi = np.full(target.shape, math.log(0.25)), np.full(target.shape, math.log(longest))
        for _ in range(64):  # 2⁻⁶⁴ of the 32 decades: below a part in 10¹² of N
            mid = 0.5 * (lo + hi)
            above = self._swt_array(np.exp(mid)) > target
            lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
        out[live] = np.where(target >= self.swt(0.25), 0.25, np.exp(0.5 * (lo + hi)))
        return out

    def _swt_array(self, cycles: np.ndarray) -> np.ndarray:
        two_n = 2.0 * cycles
        f, b = self.strength_coefficient, self.strength_exponent
        return f * f / self.youngs_modulus * two_n ** (2 * b) + f * self.ductility_coefficient * two_n ** (
            b + self.ductility_exponent)


def plane_strain_strains(sxx, szz, sxz, youngs: float, poisson: float) -> tuple:
    """(ε_x, ε_z, γ_xz) of plane strain (ε_y = 0) from the in-plane stresses."""
    k = (1.0 + poisson) / youngs
    return (k * ((1.0 - poisson) * sxx - poisson * szz), k * ((1.0 - poisson) * szz - poisson * sxx),
            2.0 * k * sxz)


@dataclass(frozen=True)
class CriticalPlane:
    """The SWT parameter at each point on its critical plane: value (MPa) and the plane's normal angle from x
    (radians, in [0, π))."""

    swt: np.ndarray
    angle: np.ndarray


def swt_2d(history: tuple, youngs: float, poisson: float, angles: int = ANGLES) -> CriticalPlane:
    """SWT on the critical plane at each point from the stresses over a cycle: ``history`` = (σx, σz, τxz), each
    an array (time, ...) of the cycle's states.  Plane strain."""
    sxx, szz, sxz = (np.asarray(a, dtype=float) for a in history)
    exx, ezz, gxz = plane_strain_strains(sxx, szz, sxz, youngs, poisson)
    best = np.full(sxx.shape[1:], -np.inf)
    where = np.zeros(sxx.shape[1:])
    for phi in np.arange(angles) * (np.pi / angles):
        c, s = math.cos(phi), math.sin(phi)
        sn = sxx * c * c + szz * s * s + 2.0 * sxz * s * c
        en = exx * c * c + ezz * s * s + gxz * s * c
        value = np.maximum(sn.max(axis=0), 0.0) * 0.5 * (en.max(axis=0) - en.min(axis=0))
        better = value > best
        best = np.where(better, value, best)
        where = np.where(better, phi, where)
    return CriticalPlane(best, where)


COARSE_ANGLES = 36  # the fast search's first pass: every 5°
FINE_SHARE = 0.01  # ... refined where it found at least this share of the field's peak
GATHER = 2  # windows' positions, per state, up to which the 5° pass gathers each point's whole history (beyond,
#             running filters per plane were faster: McColl-size fields, measured)
FINE_HALF = 4  # ... then every degree within ±4° of each point's two best: the 1° optimum of a π-periodic function
#               whose peaks the 5° pass has bracketed (tests/test_fatigue_loop.py: equal to the full search)


def swt_search(history: tuple, youngs: float, poisson: float, slides: Optional[dict] = None,
               skip: float = 0.0) -> CriticalPlane:
    """:func:`swt_2d`'s critical plane to the same degree in a fraction of the work: a 5° pass, then each point's
    two best planes' neighbourhoods degree by degree.  On a plane of normal angle φ the normal stress is
    a + b·cos 2φ + c·sin 2φ (a, b, c the mean, half-difference and shear of the in-plane stresses), and so is the
    normal strain.  The second pass is made where the first found at least FINE_SHARE of the field's peak;
    elsewhere the 5° value stands (its damage rate, ∝ SWT^(−1/2b) ≈ SWT^5, is 10⁻¹⁰ of the peak's).

    ``slides`` {state k: m}: the states reached by sliding rigidly, with their tractions as they are, over m
    elements of the last axis (signed) since the state before — so that on the way the field at a point was state
    k's m' elements further on, for every m' between 0 and m: each such state counts as the extremes over that
    window, exactly, however few states the cycle was cut into.

    ``skip`` > 0: points whose bound max σ₁·(max ε₁ − min ε₃)/2 (no plane's SWT exceeds it) is below ``skip`` of
    the field's largest bound are not searched (0 there): for the damage alone, where they count nothing."""
    sxx, szz, sxz = (np.asarray(a, dtype=float) for a in history)
    exx, ezz, gxz = plane_strain_strains(sxx, szz, sxz, youngs, poisson)
    shape = sxx.shape[1:]
    flat = lambda a: a.reshape(a.shape[0], -1, a.shape[-1])  # noqa: E731  (state, leading points, x)
    s_abc = tuple(flat(a) for a in (0.5 * (sxx + szz), 0.5 * (sxx - szz), sxz))
    e_abc = tuple(flat(a) for a in (0.5 * (exx + ezz), 0.5 * (exx - ezz), 0.5 * gxz))
    slides = {k: m for k, m in (slides or {}).items() if m}
    rows, cols = slice(None), slice(None)
    if skip > 0:  # the bounding box of the points worth searching (with the windows' reach along x)
        bound = _bound(s_abc, e_abc, slides)
        on = bound >= skip * bound.max() if bound.size and bound.max() > 0 else np.zeros(bound.shape, bool)
        if not on.any():
            return CriticalPlane(np.zeros(shape), np.zeros(shape))
        r, c = np.flatnonzero(on.any(axis=1)), np.flatnonzero(on.any(axis=0))
        reach = max((abs(m) for m in slides.values()), default=0)
        rows = slice(int(r[0]), int(r[-1]) + 1)
        cols = slice(max(0, int(c[0]) - reach), int(c[-1]) + reach + 1)
    plane = _search_field(tuple(a[:, rows, cols] for a in s_abc), tuple(a[:, rows, cols] for a in e_abc), slides)
    best, where = np.zeros(s_abc[0].shape[1:]), np.zeros(s_abc[0].shape[1:])
    best[rows, cols], where[rows, cols] = plane
    return CriticalPlane(best.reshape(shape), where.reshape(shape))


def _bound(s_abc, e_abc, slides: dict) -> np.ndarray:
    """max σ₁·(max ε₁ − min ε₃)/2 over the history at each point: no plane's SWT exceeds it."""
    def extreme(abc, sign, pick):
        v = abc[0] + sign * np.hypot(abc[1], abc[2])
        out = v.max(axis=0) if pick is np.maximum else v.min(axis=0)
        for k, m in slides.items():
            out = pick(out, _sliding(v[k].T, m, pick).T)
        return out
    return (np.maximum(extreme(s_abc, 1, np.maximum), 0.0) * 0.5 *
            (extreme(e_abc, 1, np.maximum) - extreme(e_abc, -1, np.minimum)))


def _refine(coarse: np.ndarray, value) -> tuple:
    """From the 5° pass's values (point, angle): each point's two best planes' neighbourhoods degree by degree,
    where the 5° value is at least FINE_SHARE of the peak (a fretting cycle's mirror-image planes often tie to
    round-off, and the pass about the wrong one of two near-equal peaks can miss the best by 10 % or more).
    ``value(phi, selection)`` → the SWT at the selected points on their planes φ, phi (planes, selection)."""
    step = np.pi / COARSE_ANGLES
    order = np.argsort(coarse, axis=1)  # (each point's angles in a row: the sort reads them contiguous)
    best = np.take_along_axis(coarse, order[:, -1:], 1)[:, 0]
    where = order[:, -1] * step
    sel = np.flatnonzero(best >= FINE_SHARE * best.max()) if best.max() > 0 else np.zeros(0, int)
    top, second = order[sel, -1], order[sel, -2]
    ks = np.array([k for k in range(-FINE_HALF, FINE_HALF + 1) if k])
    centres = np.concatenate([np.repeat(top[None], ks.size, 0), np.repeat(second[None], ks.size, 0)])
    offsets = np.concatenate([ks, ks])[:, None] * np.ones(sel.size, int)  # (16, sel): the planes in degrees
    # the two best are next to each other at almost every point: their neighbourhoods share four planes, each
    # evaluated once (the planes, in degrees from the lower of the two, are then the same twelve at every point)
    low = np.where((second - top) % COARSE_ANGLES == 1, top, second)
    pair = ((second - top) % COARSE_ANGLES == 1) | ((top - second) % COARSE_ANGLES == 1)
    degrees = (centres - low) % COARSE_ANGLES * (ANGLES // COARSE_ANGLES) + offsets  # (16, sel), from `low`
    shared = np.unique(degrees[:, pair], axis=None) if pair.any() else np.zeros(0, int)
    values = np.empty(degrees.shape)
    if pair.any():
        phi = np.mod(low[pair] * step + shared[:, None] * (np.pi / ANGLES), np.pi)
        got = value(phi, sel[pair])
        values[:, pair] = got[np.searchsorted(shared, degrees[:, pair]), np.arange(pair.sum())]
    if (~pair).any():
        values[:, ~pair] = value(np.mod(centres[:, ~pair] * step + offsets[:, ~pair] * (np.pi / ANGLES), np.pi),
                                 sel[~pair])
    b, w = best[sel], where[sel]
    for v, d in zip(values, np.mod(centres * step + offsets * (np.pi / ANGLES), np.pi)):  # in the search's order
        better = v > b
        b, w = np.where(better, v, b), np.where(better, d, w)
    best[sel], where[sel] = b, w
    return best, where


def _value_pts(s_pts: tuple, e_pts: tuple, phi, work: Optional[tuple] = None) -> np.ndarray:
    """SWT on the plane(s) φ at points whose whole history (states and windows) is gathered: (history, points).
    ``work``: two arrays of the histories' shape to sum in (a search's planes reuse them)."""
    c2, s2 = np.cos(2.0 * phi), np.sin(2.0 * phi)
    work = work if work is not None else _work(s_pts[0])
    sn = _project(s_pts, c2, s2, work)
    s_hi = sn.max(axis=0)
    en = _project(e_pts, c2, s2, work)  # (over sn, done with)
    return np.maximum(s_hi, 0.0) * 0.5 * (en.max(axis=0) - en.min(axis=0))


def _work(like: np.ndarray) -> tuple:
    """Two arrays to sum in: fresh arrays above glibc's mmap threshold (128 kB) are mapped and faulted in anew at
    every allocation, which made a plane's sums 3x slower than in arrays reused (9 x 3010 points, measured)."""
    return np.empty_like(like), np.empty_like(like)


def _project(abc: tuple, c2, s2, work: Optional[tuple] = None) -> np.ndarray:
    """a + b·cos 2φ + c·sin 2φ, summed in that order (into ``work[0]``, with ``work[1]`` for the third term)."""
    out, tmp = work if work is not None else (None, None)
    out = np.multiply(abc[1], c2, out=out)
    out += abc[0]  # (a + b·c2 as b·c2 + a: the same rounding)
    out += np.multiply(abc[2], s2, out=tmp)
    return out


def _search_field(s_abc, e_abc, slides: dict) -> tuple:
    """The search over a (state, leading, x) field: the 5° pass over the field plane by plane
    (:func:`_coarse_field`), or with every point's history gathered (the states and each window's positions: one
    array operation per plane) where GATHER says; the second pass at the points that need it, their windows
    gathered."""
    step = np.pi / COARSE_ANGLES
    shape = s_abc[0].shape[1:]
    if sum(abs(m) for m in slides.values()) < GATHER * s_abc[0].shape[0]:
        rows, cols = (a.ravel() for a in np.indices(shape))
        s_all, e_all = _at_points(s_abc, slides, rows, cols), _at_points(e_abc, slides, rows, cols)
        work = _work(s_all[0])
        coarse = np.array([_value_pts(s_all, e_all, phi, work) for phi in np.arange(COARSE_ANGLES) * step]).T
    else:
        coarse = _coarse_field(s_abc, e_abc, slides, np.arange(COARSE_ANGLES) * step)
    nx = shape[-1]

    def value(phi, sel):
        rows, cols = np.divmod(sel, nx)
        pts = (_at_points(s_abc, slides, rows, cols), _at_points(e_abc, slides, rows, cols))
        work = _work(pts[0][0])
        return np.array([_value_pts(*pts, row, work) for row in phi])

    best, where = _refine(np.ascontiguousarray(coarse), value)
    return best.reshape(shape), where.reshape(shape)


def _coarse_field(s_abc, e_abc, slides: dict, phis: np.ndarray) -> np.ndarray:
    """SWT on each plane φ at every point: (point, angle), the points (leading, x) in order.  A state's normal
    stress and strain are projected once per plane over the field, and a sliding state's window is a running
    extreme of that projection along x: each position of the window costs one comparison, not (gathered) a
    projection."""
    # (the cosines as the gathered pass takes them, one by one: the same planes to the last bit)
    c2 = np.array([np.cos(2.0 * phi) for phi in phis])[:, None, None]
    s2 = np.array([np.sin(2.0 * phi) for phi in phis])[:, None, None]

    def extremes(abc, low: bool):
        hi = lo = None
        for t in range(abc[0].shape[0]):
            # laid (angle, x, leading): the planes' sums run over whole contiguous fields, a window's shift too
            values = _project(tuple(np.ascontiguousarray(a[t].T) for a in abc), c2, s2)
            for pick in (np.maximum, np.minimum)[:1 + low]:
                own = [values] + ([_sliding(values.transpose(1, 0, 2), slides[t], pick).transpose(1, 0, 2)]
                                  if t in slides else [])
                kept = hi if pick is np.maximum else lo
                for v in own:
                    kept = v.copy() if kept is None else pick(kept, v, out=kept)
                hi, lo = (kept, lo) if pick is np.maximum else (hi, kept)
        return hi, lo

    s_hi, _ = extremes(s_abc, False)
    e_hi, e_lo = extremes(e_abc, True)
    out = np.maximum(s_hi, 0.0) * 0.5 * (e_hi - e_lo)  # (angle, x, leading)
    return out.transpose(2, 1, 0).reshape(-1, len(phis))


def _at_points(abc: tuple, slides: dict, rows: np.ndarray, cols: np.ndarray) -> tuple:
    """(a, b, c) at the points (rows, cols) over the states and, for each sliding state, every position of its
    window (the state's values m' elements further on, held at the grid's ends): arrays (history, points), so that
    each point's own planes are evaluated in one pass."""
    nx = abc[0].shape[-1]
    out = []
    for arr in abc:
        parts = [arr[:, rows, cols]]
        for k, m in slides.items():
            at = np.clip(cols[None, :] + np.sign(m) * np.arange(1, abs(m) + 1)[:, None], 0, nx - 1)
            parts.append(arr[k][rows[None, :], at])
        # C order: a fancy index over the states leaves them the fast axis, and the reductions over that short
        # axis ran 25x slower (55 µs instead of 2 for 3 states x 1400 points)
        out.append(np.ascontiguousarray(np.concatenate(parts, axis=0)))
    return tuple(out)


def _sliding(values: np.ndarray, m: int, pick) -> np.ndarray:
    """pick (np.maximum or np.minimum) over the window x + 1 … x + m along the first axis (x − |m| … x − 1 for
    m < 0), the field held at its edges.  By doubling spans: log₂|m| + 1 comparisons a point whatever the window
    (an extreme is exact in any grouping: the same values as one by one)."""
    n, w = values.shape[0], abs(m)
    held = np.repeat(values[-1:] if m > 0 else values[:1], w, axis=0)
    padded = np.concatenate([values, held] if m > 0 else [held, values], axis=0)
    run, span = padded, 1  # run[i]: the extreme of padded[i : i + span]
    while 2 * span <= w:
        run, span = pick(run[:-span], run[span:]), 2 * span
    if span < w:
        run = pick(run[:span - w], run[w - span:])
    start = 1 if m > 0 else 0  # (padded's entry x + 1 is the field's x + 1; for m < 0 its entry x is x − |m|)
    return run[start:start + n]


def ruiz(tensile: np.ndarray, shear: np.ndarray, slip: np.ndarray) -> np.ndarray:
    """Ruiz's fretting damage parameter σ_t·τ·δ at each surface point (MPa²·mm): the largest tensile surface
    stress over the cycle (compression counts 0), the shear traction's amplitude and the slip amplitude."""
    return np.maximum(tensile, 0.0) * np.abs(shear) * np.abs(slip)


NORMALS = 400  # plane normals searched in 3D: a Fibonacci hemisphere, ~6° apart (the parameter is even in n)


def hemisphere_normals(count: int = NORMALS) -> np.ndarray:
    """``count`` unit normals (count, 3) spread near-uniformly over the hemisphere n_z ≥ 0 (a Fibonacci lattice:
    equal-area bands in n_z, the golden angle in azimuth) — deterministic, so a run's critical planes repeat."""
    i = np.arange(count) + 0.5
    nz = i / count
    azimuth = i * (np.pi * (3.0 - math.sqrt(5.0)))
    s = np.sqrt(1.0 - nz * nz)
    return np.stack([s * np.cos(azimuth), s * np.sin(azimuth), nz], axis=1)


@dataclass(frozen=True)
class CriticalPlane3D:
    """The SWT parameter at each point on its critical plane: value (MPa) and the plane's unit normal (..., 3)
    in (x, y, z)."""

    swt: np.ndarray
    normal: np.ndarray


def _components(history) -> np.ndarray:
    """The history as one array (6, time, ...): from six arrays (σxx, σyy, σzz, σxy, σxz, σyz) or anything with
    those as attributes (a :class:`~fretsim.fatigue.stresses3d.Stress3D` with time first)."""
    names = ("sxx", "syy", "szz", "sxy", "sxz", "syz")
    parts = [getattr(history, n) for n in names] if hasattr(history, "sxx") else list(history)
    if len(parts) != 6:
        raise ValueError(f"a 3D stress history has six components, got {len(parts)}")
    return np.stack(np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in parts)))


def swt_3d(history, youngs: float, poisson: float, normals: Optional[np.ndarray] = None,
           chunk: int = 4_000_000) -> CriticalPlane3D:
    """SWT = σ_n,max·Δε_n/2 on the critical plane at each point, the largest over ``normals`` (k, 3) (default:
    :func:`hemisphere_normals`), from the stresses over a cycle: ``history`` = (σxx, σyy, σzz, σxy, σxz, σyz),
    each (time, ...), or a Stress3D with time first.  Isotropic linear elasticity: ε_n = ((1 + ν)σ_n − ν·tr σ)/E.
    ``chunk`` bounds the work arrays (points × normals) so that a grid's whole volume fits in memory."""
    s = _components(history)
    shape = s.shape[2:]
    best, normal = _best_over(s.reshape(6, s.shape[1], -1), normals, youngs, poisson, chunk)
    return CriticalPlane3D(best.reshape(shape), normal.reshape(shape + (3,)))


def _plane_weights(normals) -> tuple:
    """The unit normals (k, 3) and their weights (6, k): σ_n = nᵀσn as one product of the six components against
    (nx², ny², nz², 2nxny, 2nxnz, 2nynz)."""
    n = np.asarray(normals, dtype=float)
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    return n, np.stack([n[:, 0] ** 2, n[:, 1] ** 2, n[:, 2] ** 2, 2 * n[:, 0] * n[:, 1], 2 * n[:, 0] * n[:, 2],
                        2 * n[:, 1] * n[:, 2]])


def _best_over(flat: np.ndarray, normals: Optional[np.ndarray], youngs: float, poisson: float, chunk: int) -> tuple:
    """Each point's best plane among ``normals`` from the history (6, time, points): (SWT, normal (points, 3))."""
    n, weights = _plane_weights(hemisphere_normals() if normals is None else normals)
    points = flat.shape[2]
    best = np.empty(points)
    where = np.empty(points, dtype=int)
    size = max(1, chunk // max(1, len(n)))
    for lo in range(0, points, size):
        value = _plane_values(flat[:, :, lo:lo + size], weights, youngs, poisson)
        where[lo:lo + size] = np.argmax(value, axis=1)
        best[lo:lo + size] = value[np.arange(value.shape[0]), where[lo:lo + size]]
    return best, n[where]


def _plane_values(s: np.ndarray, weights: np.ndarray, youngs: float, poisson: float) -> np.ndarray:
    """SWT on each plane (points, k) from the history (6, time, points): a matrix product per state (BLAS) and
    running extremes — the normal stress's largest, the normal strain's largest and smallest, ε_n = (1 + ν)σ_n/E −
    ν·tr σ/E, whose trace part is the same on every plane."""
    a, b = (1.0 + poisson) / youngs, poisson / youngs
    top = low = high = None
    for t in range(s.shape[1]):
        sn = s[:, t].T @ weights  # (points, k)
        en = a * sn - (b * (s[0, t] + s[1, t] + s[2, t]))[:, None]
        if top is None:
            top, high, low = sn, en, en.copy()
        else:
            np.maximum(top, sn, out=top)
            np.maximum(high, en, out=high)
            np.minimum(low, en, out=low)
    return np.maximum(top, 0.0) * 0.5 * (high - low)


PILOT_POINTS = 256  # a 3D search's first points, those of the largest bound: the peak they give sets what to skip
COARSE_NORMALS = 100  # the 3D search's first pass: ~14° apart, each point's best bracketed for the cones below
CONES = ((0.20, 7), (0.04, 5))  # then normals on a grid about each point's best, half-width (rad) × count a side:
#                                 3.8° then 1.1° apart (the optimum within 0.6°: ~10⁻⁴ of the value, measured)
REFINE_SHARE_3D = 0.25  # ... where the first pass found at least this share of the peak (between recorded states:
#                         below it the damage rate, ∝ SWT^2.9 to ^5.6 for the shipped curves, is under 2 % of the
#                         peak's, its first pass within about a tenth); a recorded state refines down to
#                         FINE_SHARE, as its field is written


def bound_3d(history, youngs: float, poisson: float) -> np.ndarray:
    """An upper bound of every plane's SWT at each point: max σ₁ · (max ε₁ − min ε₃)/2 over the history, with the
    principal values bounded by Gershgorin's discs (a few array operations, not an eigen-solve per point and
    state).  ``history`` (6, time, ...)."""
    s = history if isinstance(history, np.ndarray) and history.shape[0] == 6 else _components(history)
    shape = s.shape[2:]
    return _slid_bound(s.reshape(6, s.shape[1], 1, -1), {}, youngs, poisson).reshape(shape)


def swt_search_3d(history, youngs: float, poisson: float, skip: float = 0.0, full: bool = True,
                  slides: Optional[dict] = None) -> CriticalPlane3D:
    """:func:`swt_3d` to a fraction of a degree at a fraction of a dense search's cost: COARSE_NORMALS, then, where
    they found at least REFINE_SHARE_3D of the peak (FINE_SHARE where ``full``: a recorded state's field), grids of
    normals about each point's best (CONES).  With ``skip`` > 0, points whose :func:`bound_3d` is below ``skip``
    of the peak are not searched (0 there): the peak is taken first over the PILOT_POINTS of the largest bound,
    which no skipped point can then exceed.

    ``slides`` {state k: m}: states reached by sliding rigidly over m elements of the last axis since the state
    before, so that on the way the field at a point was state k's at 0 … |m| − 1 elements further on: the first
    pass takes each plane's extremes over that window (log₂ m comparisons), the cones and the pilot the points'
    gathered histories — exact, however long the slide, for about the cost of the states themselves."""
    s = history if isinstance(history, np.ndarray) and history.shape[0] == 6 else _components(history)
    shape = s.shape[2:]
    nx = shape[-1] if shape else 1
    rows = s.reshape(6, s.shape[1], -1, nx)  # (6, time, row, x): the slides run along x
    slides = {k: m for k, m in (slides or {}).items() if abs(m) > 1}
    points = rows.shape[2] * nx
    best, normal = np.zeros(points), np.tile([0.0, 0.0, 1.0], (points, 1))
    search = np.arange(points)
    coarse_normals = hemisphere_normals(COARSE_NORMALS)
    if skip > 0 and points:
        bound = _slid_bound(rows, slides, youngs, poisson).ravel()
        pilot = np.argsort(bound)[::-1][:PILOT_POINTS]
        peak = float(_best_over(_gathered(rows, slides, pilot), coarse_normals, youngs, poisson, CHUNK)[0].max(
            initial=0.0))
        search = np.flatnonzero(bound >= skip * peak) if peak > 0 else np.zeros(0, int)
    if search.size:
        best[search], normal[search] = _coarse_rows(rows, slides, search, coarse_normals, youngs, poisson)
        found = best[search]
        fine = search[found >= (FINE_SHARE if full else REFINE_SHARE_3D) * found.max()]
        for half, count in CONES:
            for lo in range(0, fine.size, CHUNK // (count * count)):
                part = fine[lo:lo + CHUNK // (count * count)]
                best[part], normal[part] = _cone(_gathered(rows, slides, part), normal[part], youngs, poisson, half,
                                                 count)
    return CriticalPlane3D(best.reshape(shape), normal.reshape(shape + (3,)))


def _window(a: np.ndarray, m: int, pick) -> np.ndarray:
    """``pick`` (np.maximum or np.minimum) of ``a`` over the |m| positions 0 … |m| − 1 elements on along the last
    axis (towards +x for m > 0, −x for m < 0; positions beyond the array left out): log₂ |m| comparisons."""
    out = np.array(a[..., ::-1] if m < 0 else a, copy=True)
    span, width = 1, abs(m)
    while span < width:
        step = min(span, width - span)
        pick(out[..., :-step], out[..., step:].copy(), out=out[..., :-step])
        span += step
    return out[..., ::-1] if m < 0 else out


def _slid_bound(rows: np.ndarray, slides: dict, youngs: float, poisson: float) -> np.ndarray:
    """:func:`bound_3d` over the states and every position their slides passed (rows (6, time, row, x))."""
    sxx, syy, szz = rows[0], rows[1], rows[2]
    axy, axz, ayz = np.abs(rows[3]), np.abs(rows[4]), np.abs(rows[5])
    rx, ry, rz = axy + axz, axy + ayz, axz + ayz
    upper = np.maximum(np.maximum(sxx + rx, syy + ry), szz + rz)
    lower = np.minimum(np.minimum(sxx - rx, syy - ry), szz - rz)
    trace = sxx + syy + szz
    e_hi, e_lo = (1.0 + poisson) * upper - poisson * trace, (1.0 + poisson) * lower - poisson * trace
    for k, m in slides.items():
        upper[k], e_hi[k] = _window(upper[k], m, np.maximum), _window(e_hi[k], m, np.maximum)
        e_lo[k] = _window(e_lo[k], m, np.minimum)
    return np.maximum(upper.max(axis=0), 0.0) * 0.5 * (e_hi.max(axis=0) - e_lo.min(axis=0)) / youngs


def _gathered(rows: np.ndarray, slides: dict, points: np.ndarray) -> np.ndarray:
    """The histories (6, time, point) of the flat indices ``points``: the states, then each slide's positions on
    the way (a position beyond the row repeats the last one inside: an extreme over a set is not changed by a
    repeat)."""
    nx = rows.shape[-1]
    r, x = np.divmod(points, nx)
    parts = [rows[:, :, r, x]]
    for k, m in slides.items():
        j = np.arange(1, abs(m)) * (1 if m > 0 else -1)
        at = np.clip(x[None, :] + j[:, None], 0, nx - 1)  # (position, point)
        parts.append(rows[:, k][:, r[None, :], at])
    return np.ascontiguousarray(np.concatenate(parts, axis=1))


def _coarse_rows(rows: np.ndarray, slides: dict, search: np.ndarray, normals: np.ndarray, youngs: float,
                 poisson: float) -> tuple:
    """The first pass over the rows holding searched points, a few rows at a time: each plane's normal stress and
    strain per state, a slid state's over its window (:func:`_window`), their extremes over the history."""
    n, weights = _plane_weights(normals)
    nx = rows.shape[-1]
    wanted = np.unique(search // nx)
    group = max(1, CHUNK // (nx * len(n)))
    value_at, where_at = np.zeros(rows.shape[2] * nx), np.zeros(rows.shape[2] * nx, dtype=int)
    a, b = (1.0 + poisson) / youngs, poisson / youngs
    for lo in range(0, wanted.size, group):
        r = wanted[lo:lo + group]
        top = high = low = None
        for t in range(rows.shape[1]):
            block = rows[:, t][:, r]  # (6, rows, x)
            sn = (block.reshape(6, -1).T @ weights).reshape(r.size, nx, len(n))
            en = a * sn - (b * (block[0] + block[1] + block[2]))[..., None]
            s_top, e_high, e_low = sn, en, en
            if t in slides:  # the window along x: move it to the last axis and back
                m = slides[t]
                s_top = np.moveaxis(_window(np.moveaxis(sn, 1, -1), m, np.maximum), -1, 1)
                e_high = np.moveaxis(_window(np.moveaxis(en, 1, -1), m, np.maximum), -1, 1)
                e_low = np.moveaxis(_window(np.moveaxis(en, 1, -1), m, np.minimum), -1, 1)
            if top is None:
                top, high, low = s_top.copy(), e_high.copy(), e_low.copy()
            else:
                np.maximum(top, s_top, out=top)
                np.maximum(high, e_high, out=high)
                np.minimum(low, e_low, out=low)
        value = (np.maximum(top, 0.0) * 0.5 * (high - low)).reshape(-1, len(n))
        flat = (r[:, None] * nx + np.arange(nx)[None, :]).ravel()
        where_at[flat] = np.argmax(value, axis=1)
        value_at[flat] = value[np.arange(value.shape[0]), where_at[flat]]
    return value_at[search], n[where_at[search]]


CHUNK = 40_000  # points × normals at a time: the work arrays stay in the cache (a quarter of the time of 4·10⁶)


def _cone(s: np.ndarray, centre: np.ndarray, youngs: float, poisson: float, half: float, count: int) -> tuple:
    """Each point's best over a count × count grid of normals within ``half`` radians of its own ``centre`` (the
    centre itself among them, so a point never gets worse)."""
    helper = np.where(np.abs(centre[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    t1 = np.cross(centre, helper)
    t1 /= np.sqrt((t1 * t1).sum(axis=1, keepdims=True))
    t2 = np.cross(centre, t1)
    a, b = np.meshgrid(np.linspace(-half, half, count), np.linspace(-half, half, count))
    n = centre[:, None, :] + a.reshape(1, -1, 1) * t1[:, None, :] + b.reshape(1, -1, 1) * t2[:, None, :]
    n /= np.sqrt((n * n).sum(axis=2, keepdims=True))  # (point, k, 3)
    w = np.empty((n.shape[0], 6, n.shape[1]))  # (point, 6, k): σ_n = Σ_c σ_c·w_c, batched products per point
    w[:, 0], w[:, 1], w[:, 2] = n[..., 0] ** 2, n[..., 1] ** 2, n[..., 2] ** 2
    w[:, 3], w[:, 4], w[:, 5] = 2 * n[..., 0] * n[..., 1], 2 * n[..., 0] * n[..., 2], 2 * n[..., 1] * n[..., 2]
    sn = np.matmul(np.ascontiguousarray(s.transpose(2, 1, 0)), w)  # (point, time, k)
    trace = (s[0] + s[1] + s[2]).T[:, :, None]  # (point, time, 1)
    en = ((1.0 + poisson) / youngs) * sn - (poisson / youngs) * trace
    value = np.maximum(sn.max(axis=1), 0.0) * 0.5 * (en.max(axis=1) - en.min(axis=1))
    value[:, (count * count) // 2] *= 1.0 + 1e-15  # (ties go to the centre: a flat optimum keeps its normal)
    k = np.argmax(value, axis=1)
    rows = np.arange(value.shape[0])
    return value[rows, k], n[rows, k]
