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
        """:meth:`life` at every entry of an array, by Newton's method on u = log 2N: log SWT(u) is a log-sum-exp
        of two lines falling in u, convex, so Newton from the left of the root (the larger of the two terms'
        own inversions, each below it) climbs to it monotonically, quadratically once near (a few steps to a part
        in 10¹⁴, where bisection took 64)."""
        swt = np.asarray(swt, dtype=float)
        floor = max(self.swt(longest), self.endurance_limit if self.endurance_limit is not None else 0.0)
        out = np.full(swt.shape, np.inf)
        live = swt > floor
        out[live & (swt >= self.swt(0.25))] = 0.25  # (above the curve's top, inf too: no root to find)
        live &= swt < self.swt(0.25)
        if not live.any():
            return out
        target = swt[live]
        f, b, c = self.strength_coefficient, self.strength_exponent, self.ductility_exponent
        ka, kb = math.log(f * f / self.youngs_modulus), math.log(f * self.ductility_coefficient)  # log of each term
        ea, eb = 2.0 * b, b + c  # ... its slope in u
        goal = np.log(target)
        u = np.maximum((goal - ka) / ea, (goal - kb) / eb)  # where each term alone reaches the target: left of the root
        for _ in range(60):
            ta, tb = np.exp(ka + ea * u), np.exp(kb + eb * u)
            step = (np.log(ta + tb) - goal) * (ta + tb) / (ea * ta + eb * tb)
            u -= step
            if not (np.abs(step) > 1e-15 * np.maximum(1.0, np.abs(u))).any():
                break
        lives = np.minimum(0.5 * np.exp(u), longest)
        out[live] = np.maximum(lives, 0.25)
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
FINE_HALF = 4  # ... then every degree within ±4° of each point's two best: the 1° optimum of a π-periodic function
#               whose peaks the 5° pass has bracketed (tests/test_fatigue_loop.py: equal to the full search)
CHUNK_2D = 60_000  # planes × history entries × points per matrix product: the work arrays stay in the cache


def swt_search(history: tuple, youngs: float, poisson: float, slides: Optional[dict] = None,
               skip: float = 0.0, worth=None) -> CriticalPlane:
    """:func:`swt_2d`'s critical plane to the same degree in a fraction of the work: a 5° pass, then each point's
    two best planes' neighbourhoods degree by degree.  On a plane of normal angle φ the normal stress is
    a + b·cos 2φ + c·sin 2φ (a, b, c the mean, half-difference and shear of the in-plane stresses), and in plane
    strain the normal strain is k·((1 − 2ν)·a + b·cos 2φ + c·sin 2φ), k = (1 + ν)/E: both, for many planes at
    many points, are one matrix product (BLAS) of the planes' weights with the points' (a, b, c).  The second
    pass is made where the first found at least FINE_SHARE of the field's peak; elsewhere the 5° value stands
    (its damage rate, ∝ SWT^(−1/2b) ≈ SWT^5, is 10⁻¹⁰ of the peak's).

    ``slides`` {state k: m}: the states reached by sliding rigidly, with their tractions as they are, over m
    elements of the last axis (signed) since the state before — so that on the way the field at a point was state
    k's m' elements further on, for every m' between 0 and m: each such state counts as the extremes over that
    window, exactly, however few states the cycle was cut into.

    ``skip`` > 0: points whose bound max σ₁·(max ε₁ − min ε₃)/2 (no plane's SWT exceeds it) is below ``skip`` of
    the field's largest bound are not searched (0 there): for the damage alone, where they count nothing.

    ``worth``: for the damage alone, a function of the first pass's field (the points' shape) that gives the points
    where the second pass is worth making (besides FINE_SHARE); elsewhere the 5° value stands."""
    sxx, szz, sxz = (np.asarray(a, dtype=float) for a in history)
    shape = sxx.shape[1:]
    nx = shape[-1]
    abc = np.stack([0.5 * (sxx + szz), 0.5 * (sxx - szz), sxz]).reshape(3, sxx.shape[0], -1, nx)  # (3, state, row, x)
    slides = {k: m for k, m in (slides or {}).items() if m}
    windows = {t: _reach(m) for t, m in slides.items()}  # (the positions each slide passed, as _window counts them)
    rows, cols = slice(None), slice(None)
    if skip > 0:  # the bounding box of the points worth searching (with the windows' reach along x)
        bound = _bound(abc, windows, youngs, poisson)
        on = bound >= skip * bound.max() if bound.size and bound.max() > 0 else np.zeros(bound.shape, bool)
        if not on.any():
            return CriticalPlane(np.zeros(shape), np.zeros(shape))
        r, c = np.flatnonzero(on.any(axis=1)), np.flatnonzero(on.any(axis=0))
        reach = max((abs(m) for m in slides.values()), default=0)
        rows = slice(int(r[0]), int(r[-1]) + 1)
        cols = slice(max(0, int(c[0]) - reach), int(c[-1]) + reach + 1)
    part = np.ascontiguousarray(abc[:, :, rows, cols])
    coarse = _coarse_field(part, windows, _weights(np.arange(COARSE_ANGLES) * (180 // COARSE_ANGLES), youngs, poisson))
    weights = lambda degrees: _weights(degrees, youngs, poisson)  # noqa: E731
    mask = None
    if worth is not None:
        first = np.zeros(abc.shape[2:])
        first[rows, cols] = coarse.max(axis=1).reshape(part.shape[2:])
        mask = np.asarray(worth(first.reshape(shape))).reshape(abc.shape[2:])[rows, cols].ravel()
    best, where = _refine(coarse, lambda ref, degrees, sel: _values_at(part, windows, ref, degrees, sel, weights),
                          mask)
    out, angle = np.zeros(abc.shape[2:]), np.zeros(abc.shape[2:])
    out[rows, cols], angle[rows, cols] = best.reshape(part.shape[2:]), where.reshape(part.shape[2:])
    return CriticalPlane(out.reshape(shape), angle.reshape(shape))


def _weights(degrees, youngs: float, poisson: float) -> np.ndarray:
    """(2 × planes, 3): the rows (1, cos 2φ, sin 2φ) that give each plane's normal stress from a point's (a, b, c),
    then k·(1 − 2ν, cos 2φ, sin 2φ), its normal strain (plane strain: the strains' mean is k(1 − 2ν) times the
    stresses', their half-difference and shear k times)."""
    phi = np.asarray(degrees, dtype=float) * (np.pi / ANGLES)
    one, c2, s2 = np.ones(phi.size), np.cos(2.0 * phi), np.sin(2.0 * phi)
    k = (1.0 + poisson) / youngs
    return np.concatenate([np.stack([one, c2, s2], axis=1), k * np.stack([(1.0 - 2.0 * poisson) * one, c2, s2],
                                                                        axis=1)])


def _bound(abc: np.ndarray, windows: dict, youngs: float, poisson: float) -> np.ndarray:
    """max σ₁·(max ε₁ − min ε₃)/2 over the history at each point (row, x): no plane's SWT exceeds it."""
    r = np.hypot(abc[1], abc[2])
    k, mean = (1.0 + poisson) / youngs, (1.0 - 2.0 * poisson) * abc[0]
    parts = [(abc[0] + r, np.maximum), (k * (mean + r), np.maximum), (k * (mean - r), np.minimum)]
    out = []
    for v, pick in parts:
        for t, m in windows.items():
            v[t] = _window(v[t], m, pick)
        out.append(v.max(axis=0) if pick is np.maximum else v.min(axis=0))
    return np.maximum(out[0], 0.0) * 0.5 * (out[1] - out[2])


def _reach(m: int) -> int:
    """A 2D slide of m elements passes m + 1 positions (0 … m): :func:`_window`'s count, signed."""
    return m + (1 if m > 0 else -1)


def _coarse_field(abc: np.ndarray, windows: dict, weights: np.ndarray) -> np.ndarray:
    """SWT on each plane of ``weights`` (:func:`_weights`) at every point: (point, plane), the points (row, x) in
    order.  A few rows at a time, each state's normal stresses and strains on every plane are a matrix product laid
    (x, row, plane), and a sliding state's window is a running extreme of them along x (:func:`_run_along`, over
    whole contiguous slabs), all in arrays made once: fresh ones, mapped and faulted in at every step, made the
    windows 5x as slow."""
    _, states, nrows, nx = abc.shape
    planes = weights.shape[0] // 2
    w_s, w_e = np.ascontiguousarray(weights[:planes].T), np.ascontiguousarray(weights[planes:].T)  # (3, planes)
    group = min(nrows, max(1, CHUNK_2D // (2 * planes * nx)))
    out = np.empty((nrows, nx, planes))
    buffers: dict = {}
    for lo in range(0, nrows, group):
        g = min(nrows - lo, group)
        if g not in buffers:  # (at most two sizes: the groups and the last)
            buffers[g] = [np.empty((nx, g, planes), dtype=abc.dtype) for _ in range(10)]
        top = _planes_pass(lambda t: np.ascontiguousarray(abc[:, t, lo:lo + g].transpose(2, 1, 0)).reshape(-1, 3),
                           states, windows, w_s, w_e, buffers[g])  # (each state's (x·row, 3))
        out[lo:lo + g] = top.transpose(1, 0, 2)
    return out.reshape(nrows * nx, planes)


def _planes_pass(block_of, states: int, windows: dict, w_s: np.ndarray, w_e: np.ndarray, bufs: list) -> np.ndarray:
    """SWT on every plane of the weights at a group of points laid (x, row, plane), from each state's stress
    components ``block_of(t)`` (x·row, components): the state's normal stresses and strains are two products into
    ``bufs`` (ten arrays of the group's shape), a slid state's (``windows`` {t: :func:`_window`'s count}) taken over
    its window (:func:`_run_along`), and their extremes kept in place.  Returns one of ``bufs``, overwritten by the
    next call."""
    sn, en, s_top, e_high, e_low, top, high, low, *work = bufs
    k = sn.shape[-1]
    for t in range(states):
        block = block_of(t)
        np.matmul(block, w_s, out=sn.reshape(-1, k))
        np.matmul(block, w_e, out=en.reshape(-1, k))
        if t in windows:
            m = windows[t]
            s_hi = _run_along(sn, m, np.maximum, s_top, work)
            e_hi, e_lo = _run_along(en, m, np.maximum, e_high, work), _run_along(en, m, np.minimum, e_low, work)
        else:
            s_hi, e_hi, e_lo = sn, en, en
        if t == 0:
            np.copyto(top, s_hi), np.copyto(high, e_hi), np.copyto(low, e_lo)
        else:
            np.maximum(top, s_hi, out=top)
            np.maximum(high, e_hi, out=high)
            np.minimum(low, e_lo, out=low)
    np.maximum(top, 0.0, out=top)
    high -= low
    high *= 0.5
    top *= high
    return top


def _run_along(src: np.ndarray, m: int, pick, out: np.ndarray, work: list) -> np.ndarray:
    """:func:`_window` along the first axis, into ``out``, with ``work`` two arrays of ``src``'s shape to build its
    sparse table in."""
    width = abs(m)
    if width <= 1:
        np.copyto(out, src)
        return out
    a, o = (src[::-1], out[::-1]) if m < 0 else (src, out)
    n = a.shape[0]
    run, span, length, k = a, 1, n, 0  # run[i]: the extreme of a[i : i + span], for i < length
    # (a window longer than the axis needs no table: every position is in the tail below — and a span past the
    # table's length would pair slices of different lengths)
    while 2 * span <= min(width, n):
        dst = work[k][::-1] if m < 0 else work[k]
        pick(run[:length - span], run[span:length], out=dst[:length - span])
        run, span, length, k = dst, 2 * span, length - span, 1 - k
    body = max(0, n - width + 1)
    if body:
        pick(run[:body], run[width - span:width - span + body], out=o[:body])
    if body < n:  # the last width − 1: each the extreme of what is left
        o[body:] = pick.accumulate(a[body:][::-1], axis=0)[::-1]
    return out


def _values_at(abc: np.ndarray, windows: dict, ref: np.ndarray, degrees: np.ndarray, points: np.ndarray,
               weights) -> np.ndarray:
    """SWT at the flat indices ``points`` (row, x) on the planes ``ref``·5° + ``degrees``·1° (each point its own
    ``ref``: its (b, c) turned by 2·ref·5° so that the planes' weights are the same for all): (degrees, points)."""
    hist = _gathered(abc, windows, points)  # (3, history, point)
    phi = ref * (2.0 * np.pi / COARSE_ANGLES)  # 2φ of each point's reference plane
    c, s = np.cos(phi), np.sin(phi)
    turned = np.stack([hist[0], hist[1] * c + hist[2] * s, hist[2] * c - hist[1] * s])
    w = weights(degrees)
    planes, length = len(degrees), turned.shape[1]
    out = np.empty((planes, len(points)))
    size = max(1, CHUNK_2D // (2 * planes * length))
    for lo in range(0, len(points), size):
        block = turned[:, :, lo:lo + size]
        v = (w @ block.reshape(3, -1)).reshape(2 * planes, length, block.shape[2])
        out[:, lo:lo + size] = np.maximum(v[:planes].max(axis=1), 0.0) * 0.5 * (
            v[planes:].max(axis=1) - v[planes:].min(axis=1))
    return out


def _refine(coarse: np.ndarray, value, mask: Optional[np.ndarray] = None) -> tuple:
    """From the 5° pass's values (point, angle): each point's two best planes' neighbourhoods degree by degree,
    where the 5° value is at least FINE_SHARE of the peak (a fretting cycle's mirror-image planes often tie to
    round-off, and the pass about the wrong one of two near-equal peaks can miss the best by 10 % or more).
    ``value(ref, degrees, selection)`` → the SWT at the selected points on the planes ref·5° + degrees·1°
    (degrees, selection).  ``mask`` (point): where the second pass may be made at all."""
    step = np.pi / COARSE_ANGLES
    per = ANGLES // COARSE_ANGLES
    top = np.argmax(coarse, axis=1)
    best, where = coarse[np.arange(len(coarse)), top], top * step
    sel = np.flatnonzero((best >= FINE_SHARE * best.max()) & (True if mask is None else mask)) if (
        best.size and best.max() > 0) else np.zeros(0, int)
    top, rest = top[sel], coarse[sel]
    rest[np.arange(sel.size), top] = -np.inf
    second = np.argmax(rest, axis=1)
    ks = np.array([k for k in range(-FINE_HALF, FINE_HALF + 1) if k])
    # the two best are next to each other at almost every point: their neighbourhoods share four planes, each
    # evaluated once (in degrees from the lower of the two, the same twelve at every such point)
    adjacent = (second - top) % COARSE_ANGLES == 1
    pair = adjacent | ((top - second) % COARSE_ANGLES == 1)
    low = np.where(adjacent, top, second)
    shared = np.union1d(ks, ks + per)
    b, w = best[sel], where[sel]
    for mask, ref, degrees in ((pair, low, shared), (~pair, top, ks), (~pair, second, ks)):
        if not mask.any():
            continue
        got = value(ref[mask], degrees, sel[mask])  # (degrees, points)
        k = np.argmax(got, axis=0)  # (ties: the 5° best, then the first plane listed)
        v = got[k, np.arange(k.size)]
        better = v > b[mask]
        at = np.flatnonzero(mask)[better]
        b[at], w[at] = v[better], np.mod(ref[at] * step + degrees[k[better]] * (np.pi / ANGLES), np.pi)
    best[sel], where[sel] = b, w
    return best, where


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
        pilot = np.argpartition(bound, -PILOT_POINTS)[-PILOT_POINTS:] if bound.size > PILOT_POINTS else np.arange(bound.size)
        peak = float(_best_over(_gathered(rows, slides, pilot), coarse_normals, youngs, poisson, CHUNK)[0].max(
            initial=0.0))
        search = np.flatnonzero(bound >= skip * peak) if peak > 0 else np.zeros(0, int)
    if search.size:
        best[search], normal[search] = _coarse_rows(rows, slides, search, coarse_normals, youngs, poisson)
        found = best[search]
        fine = search[found >= (FINE_SHARE if full else REFINE_SHARE_3D) * found.max()]
        size = CHUNK // max(c * c for _, c in CONES)
        for lo in range(0, fine.size, size):  # each chunk's histories gathered once for both cones
            part = fine[lo:lo + size]
            history = _gathered(rows, slides, part)
            for half, count in CONES:
                best[part], normal[part] = _cone(history, normal[part], youngs, poisson, half, count)
    return CriticalPlane3D(best.reshape(shape), normal.reshape(shape + (3,)))


def _window(a: np.ndarray, m: int, pick) -> np.ndarray:
    """``pick`` (np.maximum or np.minimum) of ``a`` over the |m| positions 0 … |m| − 1 elements on along the last
    axis (towards +x for m > 0, −x for m < 0; positions beyond the array left out): log₂ |m| comparisons, each into
    a fresh array (a sparse table: the extreme over 2s positions from two over s), the last two spans overlapping
    (an extreme is exact in any grouping: the same values as one by one)."""
    width = abs(m)
    if width <= 1:
        return np.array(a, copy=True)
    src = a[..., ::-1] if m < 0 else a
    n = src.shape[-1]
    run, span = src, 1  # run[..., i]: the extreme of src[..., i : i + span]
    while 2 * span <= min(width, n):  # (as _run_along's: no table where no window lies wholly inside)
        run, span = pick(run[..., :-span], run[..., span:]), 2 * span
    out = np.empty(src.shape, dtype=np.result_type(src))
    body = max(0, n - width + 1)  # the positions whose whole window lies inside
    if body:
        pick(run[..., :body], run[..., width - span:width - span + body], out=out[..., :body])
    if body < n:  # the last width − 1: each the extreme of what is left of the row
        out[..., body:] = pick.accumulate(src[..., body:][..., ::-1], axis=-1)[..., ::-1]
    return out[..., ::-1] if m < 0 else out


def _slid_bound(rows: np.ndarray, slides: dict, youngs: float, poisson: float) -> np.ndarray:
    """:func:`bound_3d` over the states and every position their slides passed (rows (6, time, row, x)): a state at
    a time, in arrays made once (a state's field stays in the cache; the whole history's temporaries did not)."""
    shape = rows.shape[2:]
    top, high, low = np.full(shape, -np.inf), np.full(shape, -np.inf), np.full(shape, np.inf)
    axy, axz, ayz, reach, upper, lower, trace, tmp = (np.empty(shape) for _ in range(8))
    for t in range(rows.shape[1]):
        s = rows[:, t]
        np.abs(s[3], out=axy), np.abs(s[4], out=axz), np.abs(s[5], out=ayz)
        for i, (p, q) in enumerate(((axy, axz), (axy, ayz), (axz, ayz))):  # Gershgorin's radius of each row
            np.add(p, q, out=reach)
            if i == 0:
                np.add(s[0], reach, out=upper), np.subtract(s[0], reach, out=lower)
            else:
                np.maximum(upper, np.add(s[i], reach, out=tmp), out=upper)
                np.minimum(lower, np.subtract(s[i], reach, out=tmp), out=lower)
        np.add(s[0], s[1], out=trace)
        trace += s[2]
        trace *= poisson
        upper_e = np.subtract((1.0 + poisson) * upper, trace, out=tmp)
        lower_e = np.subtract(np.multiply(lower, 1.0 + poisson, out=lower), trace, out=lower)
        s_hi = upper
        if t in slides:
            m = slides[t]
            s_hi, upper_e, lower_e = (_window(upper, m, np.maximum), _window(upper_e, m, np.maximum),
                                      _window(lower_e, m, np.minimum))
        np.maximum(top, s_hi, out=top)
        np.maximum(high, upper_e, out=high)
        np.minimum(low, lower_e, out=low)
    np.maximum(top, 0.0, out=top)
    return top * 0.5 * (high - low) / youngs


def _gathered(rows: np.ndarray, slides: dict, points: np.ndarray) -> np.ndarray:
    """The histories (components, time, point) of the flat indices ``points`` (rows (components, time, row, x): 3D's
    six stresses, 2D's (a, b, c)): the states, then each slide's positions on the way, 1 … |m| − 1 (:func:`_window`'s
    count; a position beyond the row repeats the last one inside: an extreme over a set is not changed by a
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
    strain per state (two matrix products, laid (x, row, plane): ε_n = ((1 + ν)σ_n − ν·tr σ)/E has weights of its
    own), a slid state's over its window (:func:`_run_along`, in arrays made once), their extremes over the
    history."""
    n, weights = _plane_weights(normals)
    k = len(n)
    nx = rows.shape[-1]
    wanted = np.unique(search // nx)
    group = max(1, COARSE_CHUNK // (nx * k))
    value_at, where_at = np.zeros(rows.shape[2] * nx), np.zeros(rows.shape[2] * nx, dtype=int)
    # in single precision: where a point's value stands (below the cones' share) it is within ~1e-7 of the peak of
    # double's, against its plane's few degrees from the optimum; every point the cones refine is evaluated again in
    # double (12 % off the gross-slip ball's whole run, paired)
    w_s = weights.astype(np.float32)  # (6, k)
    w_e = ((1.0 + poisson) / youngs * weights - poisson / youngs * np.array([1.0, 1, 1, 0, 0, 0])[:, None]).astype(
        np.float32)
    buffers: dict = {}
    for lo in range(0, wanted.size, group):
        r = wanted[lo:lo + group]
        g = r.size
        if g not in buffers:  # (at most two sizes: the groups and the last)
            buffers[g] = [np.empty((nx, g, k), dtype=np.float32) for _ in range(10)]
        top = _planes_pass(lambda t: np.ascontiguousarray(rows[:, t][:, r].transpose(2, 1, 0), np.float32).reshape(-1, 6),
                           rows.shape[1], slides, w_s, w_e, buffers[g])  # (each state's (x·row, 6))
        value = top.transpose(1, 0, 2).reshape(-1, k)  # (row, x) in order
        flat = (r[:, None] * nx + np.arange(nx)[None, :]).ravel()
        where_at[flat] = np.argmax(value, axis=1)
        value_at[flat] = value[np.arange(value.shape[0]), where_at[flat]]
    return value_at[search], n[where_at[search]]


COARSE_CHUNK = 160_000  # the 3D first pass's points × normals a group of rows (float32: 0.6 MB a work array; at
#                        40 000 a group was two rows of the ball's window and numpy's cost per call dominated: 12 %
#                        of its replayed states)
CHUNK = 40_000  # points × normals at a time: the work arrays stay in the cache (a quarter of the time of 4·10⁶)


PRUNE_FROM = 32  # a cone's histories this long or longer (long slides) are pruned (_may_hold_extreme) first: the seat
#                 on a rail's 89 entries in 0.5-0.6 of the time; below about 24 the pruning costs more than it saves


def _cone(s: np.ndarray, centre: np.ndarray, youngs: float, poisson: float, half: float, count: int) -> tuple:
    """Each point's best over a count × count grid of normals within ``half`` radians of its own ``centre`` (the
    centre itself among them, so a point never gets worse).  Each point's stresses are turned into its own frame
    (t₁, t₂, centre) first (a 6 × 6 product per point): the grid's normals are then the same (a, b, 1)/|…| in every
    frame, and all points' normal stresses and strains are two shared matrix products (BLAS) — not a 6 × count²
    product per point."""
    helper = np.where(np.abs(centre[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    t1 = np.cross(centre, helper)
    t1 /= np.sqrt((t1 * t1).sum(axis=1, keepdims=True))
    t2 = np.cross(centre, t1)
    frame = np.stack([t1, t2, centre], axis=1)  # (point, 3, 3): rows t₁, t₂, centre
    local = np.matmul(np.ascontiguousarray(s.transpose(2, 1, 0)), _turning(frame))  # (point, time, 6)
    a, b = np.meshgrid(np.linspace(-half, half, count), np.linspace(-half, half, count))
    own = np.stack([a.ravel(), b.ravel(), np.ones(a.size)], axis=1)  # (k, 3) in each point's frame
    own, w = _plane_weights(own)
    w_e = (1.0 + poisson) / youngs * w - poisson / youngs * np.array([1.0, 1, 1, 0, 0, 0])[:, None]  # (tr σ kept)
    points, times = local.shape[:2]
    if times < PRUNE_FROM or not np.isfinite(local).all():  # (laid time first: the extremes over it are whole-array maxima, 4x a middle axis's)
        flat = np.ascontiguousarray(local.transpose(1, 0, 2)).reshape(-1, 6)
        sn, en = (flat @ w).reshape(times, points, -1), (flat @ w_e).reshape(times, points, -1)
        value = np.maximum(sn.max(axis=0), 0.0) * 0.5 * (en.max(axis=0) - en.min(axis=0))
    else:  # only the entries that may hold an extreme somewhere in the cone, each point's in turn
        keep = _may_hold_extreme(local, math.atan(half * math.sqrt(2.0)), youngs, poisson)  # (point, time)
        flat = local[keep]  # (entry, 6)
        starts = np.concatenate([[0], np.cumsum(keep.sum(axis=1))[:-1]])
        sn, en = w.T @ flat.T, w_e.T @ flat.T  # (plane, entry): each point's entries contiguous for the reductions
        value = (np.maximum(np.maximum.reduceat(sn, starts, axis=1), 0.0) * 0.5 * (
            np.maximum.reduceat(en, starts, axis=1) - np.minimum.reduceat(en, starts, axis=1))).T
    value[:, (count * count) // 2] *= 1.0 + 1e-15  # (ties go to the centre: a flat optimum keeps its normal)
    k = np.argmax(value, axis=1)
    rows = np.arange(value.shape[0])
    n = own[k, 0:1] * t1 + own[k, 1:2] * t2 + own[k, 2:3] * centre  # back in (x, y, z)
    return value[rows, k], n / np.sqrt((n * n).sum(axis=1, keepdims=True))


def _may_hold_extreme(local: np.ndarray, theta: float, youngs: float, poisson: float) -> np.ndarray:
    """(point, time): the entries of each point's history, in its own frame (point, time, 6: the centre's normal
    stress is σ'_zz), that can be the largest normal stress, or the largest or smallest normal strain, on some plane
    within ``theta`` of the centre.  Turned by θ from n₀ towards t, a normal stress moves over the circle of the
    2 × 2 block of σ in (n₀, t): by at most (μ₁ − μ₂)·sin θ, μ₁ − μ₂ ≤ λ_max − λ_min ≤ √2·|dev σ| (the strain by
    (1 + ν)/E times that: its trace part is the same on every plane).  So an entry whose value at n₀ plus that
    margin is below the largest value less its margin is the largest on no plane of the cone: exact, and a long
    slide's history (the seat on a rail: 89 entries) keeps about a quarter in the fine cone."""
    sn = local[..., 2]
    trace = local @ np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    # |dev σ|² from the normal stresses' differences, not Σσ² − (tr σ)²/3: that cancels where the mean stress is far
    # larger than the deviator and could make the margin too small
    d = local[..., [0, 1, 2]] - local[..., [1, 2, 0]]
    dev2 = (d * d) @ np.full(3, 1.0 / 3.0) + (local[..., 3:] * local[..., 3:]) @ np.full(3, 2.0)
    # (widened by a part in 10⁹ of the stresses' scale: the bound's own round-off never drops an extreme)
    scale = max(float(trace.max(initial=0.0)), -float(trace.min(initial=0.0)), float(dev2.max(initial=0.0)) ** 0.5)
    ms = np.sqrt(2.0 * dev2)
    ms *= math.sin(theta) * (1 + 1e-9)
    ms += 1e-9 * scale
    k = (1.0 + poisson) / youngs
    en, me = k * sn - (poisson / youngs) * trace, k * ms
    return ((sn + ms >= (sn - ms).max(axis=1, keepdims=True)) | (en + me >= (en - me).max(axis=1, keepdims=True))
            | (en - me <= (en + me).min(axis=1, keepdims=True)))


_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))  # the six components' indices, in _components' order
_PAIR_INDEX = np.array(_PAIRS)


def _turning(frame: np.ndarray) -> np.ndarray:
    """(point, 6, 6): the weights that turn a point's six stress components into those in its ``frame`` (rows: the
    new axes in x, y, z), σ' = σ @ W — σ'_ab = Σ R_ak·R_bl·σ_kl, each shear counted both ways."""
    a, b = _PAIR_INDEX[:, 0][None, :], _PAIR_INDEX[:, 1][None, :]  # (1, 6): the new component j's axes
    k, l = _PAIR_INDEX[:, 0][:, None], _PAIR_INDEX[:, 1][:, None]  # (6, 1): the old component i's
    out = frame[:, a, k] * frame[:, b, l]  # (point, i, j)
    out[:, 3:] += frame[:, a, l[3:]] * frame[:, b, k[3:]]  # (a shear's other half: k ≠ l)
    return out
