"""Modified Archard wear of both bodies (paper Eqs. 14–17) and the stroke-averaged pressure (section 2.2.1).

The moving body (cylinder, ball) carries the same pressure field through the
cycle.  A point of the stationary flat sees that field slide past it by
u ∈ [−δ, δ], so it wears with the average p_av(x) = (1/2δ)∫ p(x − u) du.  For
element-wise constant p this is an exact box average: each element
contributes its pressure times the length of its overlap with the window.

How the flat's wear enters the gap (``gap_model``):

* ``mid_stroke`` (the paper, Eq. 18): the contact is solved at mid-stroke with
  the gap ε + h_m + h_s.  Per Fourier mode of the wear the update has the
  growth factor 1 − ΔN·4δ(k_m + k_s b)/c, with b the symbol of the stroke
  average (b ≥ −0.22): when the moving body wears less than ~0.22 of the flat
  (k_m < −k_s·min b) modes shorter than the stroke grow — in the model itself,
  even cycle by cycle, not only in a solver — and the pressure breaks into
  spikes one stroke-average lobe apart.
* ``stroke_average``: the moving body sees the flat's wear averaged over the
  stroke, gap ε + h_m + B h_s.  To first order in the gap's variation over a
  stroke it is the same average pressure, and its modes decay for any
  coefficients (factor 1 − ΔN·4δ(k_m + k_s b²)/c).  It differs from the paper
  only for wear features shorter than the stroke.
"""
from __future__ import annotations

from functools import lru_cache

from typing import Optional

import numpy as np

from fretsim.compliance import Convolution
from fretsim.grid import Grid
from fretsim.native import scatter_add

GAP_MODELS = ("mid_stroke", "stroke_average", "resolved")


@lru_cache(maxsize=64)
def stroke_weights(dx: float, stroke: float) -> np.ndarray:
    """Weights w_k (k = −K..K) with p_av,i = Σ w_k p_{i−k}; they sum to 1.  Cached: treat as read-only."""
    if not (dx > 0 and stroke > 0):
        raise ValueError(f"element size and stroke must be positive, got {dx}, {stroke}")
    reach = int(np.ceil(stroke / dx + 0.5))
    centres = np.arange(-reach, reach + 1) * dx
    overlap = np.clip(np.minimum(centres + dx / 2, stroke) - np.maximum(centres - dx / 2, -stroke), 0.0, None)
    weights = overlap / (2.0 * stroke)
    weights.flags.writeable = False
    return weights


def stroke_reach(dx: float, stroke: float) -> int:
    """Elements the stroke average reaches on each side."""
    return (stroke_weights(dx, stroke).size - 1) // 2


def stroke_average(pressure: np.ndarray, dx: float, stroke: float) -> np.ndarray:
    """p_av of the stationary body along x (the last axis); exact for element-wise constant pressure.  The weights
    are one value over the elements the stroke covers whole (a box: a difference of running sums) and a partial
    weight at each end; an element beyond the reach of every loaded one gets exactly 0 (its running sums are the
    same number).  Not scipy.ndimage's convolve1d: importing it cost 0.2 s of every run's start, and a box is two
    array passes whatever the stroke (the tube's 143 weights, for one)."""
    w = stroke_weights(dx, stroke)
    reach = (w.size - 1) // 2
    full = w[reach]  # the weight of an element the stroke covers whole (the centre's)
    inner = 0  # elements each side at that weight, to round-off
    while inner < reach and abs(w[reach + inner + 1] - full) <= 1e-12 * full and \
            abs(w[reach - inner - 1] - full) <= 1e-12 * full:
        inner += 1
    p = np.asarray(pressure, dtype=float)
    if not np.isfinite(p).all():  # (running sums would carry a NaN or inf along the row: term by term, where it is)
        out = w[reach] * p
        for k in range(1, reach + 1):
            for weight, src, dst in ((w[reach + k], np.s_[..., :-k], np.s_[..., k:]),
                                     (w[reach - k], np.s_[..., k:], np.s_[..., :-k])):
                if weight:
                    out[dst] += weight * p[src]
        return out
    n = p.shape[-1]
    padded = np.zeros(p.shape[:-1] + (n + 2 * reach + 1,))
    padded[..., reach + 1:reach + 1 + n] = p  # padded[j + reach + 1] = p[j]; one zero more in front for the sums
    sums = np.cumsum(padded, axis=-1)
    # Σ_{|k| ≤ inner} p[i − k] = sums[i + inner + reach + 1] − sums[i − inner + reach]
    out = full * (sums[..., reach + inner + 1:reach + inner + 1 + n] - sums[..., reach - inner:reach - inner + n])
    for k in range(inner + 1, reach + 1):  # the partial ends (and the zero weights beyond)
        for weight, offset in ((w[reach - k], -k), (w[reach + k], k)):  # w[reach + k] multiplies p[i − k]
            if weight:
                out += weight * padded[..., reach + 1 - offset:reach + 1 - offset + n]
    return out


def stroke_symbol(dx: float, stroke: float, theta: np.ndarray) -> np.ndarray:
    """b(θ) = Σ w_k cos kθ: how the stroke average scales a wear mode of phase θ per element."""
    w = stroke_weights(dx, stroke)
    reach = (w.size - 1) // 2
    return np.cos(np.multiply.outer(theta, np.arange(-reach, reach + 1))) @ w


def archard_depth(wear_coefficient: float, pressure: np.ndarray, cycles: float, stroke: float) -> np.ndarray:
    """Wear depth dh = k·ΔN·p·4δ (Eqs. 15–16): sliding distance 4δ per cycle, k in 1/MPa, p in MPa → mm."""
    return wear_coefficient * cycles * 4.0 * stroke * pressure


def archard_volume(wear_coefficient: float, load: float, cycles: float, stroke: float) -> float:
    """Archard's law V = k·P·s with s = 4δN (Eq. 13): the invariant every run is checked against."""
    return wear_coefficient * load * 4.0 * stroke * cycles


def wear_rates(pressure: np.ndarray, dx: float, stroke: float, k_moving: float, k_stationary: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """Wear per cycle of the moving body (its own pressure) and of the flat (the stroke average), Eqs. 15–16."""
    return (archard_depth(k_moving, pressure, 1.0, stroke),
            archard_depth(k_stationary, stroke_average(pressure, dx, stroke), 1.0, stroke))


# how the flat's wear enters the gap the contact solve sees, per gap model: h_m + h_s or h_m + B h_s
_SEEN = {"mid_stroke": lambda h_s, dx, stroke: h_s, "stroke_average": stroke_average}
# how far the flat's wear reaches beyond the contact, in strokes: one, or two seen through the stroke average
GAP_REACH = {"mid_stroke": 1, "stroke_average": 2, "resolved": 1}
# whether the contact sees the flat's wear through its average over the stroke (the stepping near the transition
# needs to know: fretsim.stepping.implicit.near_transition)
AVERAGED = {"mid_stroke": False, "stroke_average": True, "resolved": False}


def gap_wear(h_moving: np.ndarray, h_stationary: np.ndarray, dx: float, stroke: float, gap_model: str) -> np.ndarray:
    """The wear the contact solve sees: h_m + h_s (mid_stroke, Eq. 18) or h_m + B h_s (stroke_average)."""
    return h_moving + _SEEN[gap_model](h_stationary, dx, stroke)


def wear_reach(dx: float, stroke: float, gap_model: str) -> int:
    """Elements beyond the contact the wear of a gap model reaches (the contact must stay this far from the
    grid's x edges)."""
    return GAP_REACH[gap_model] * stroke_reach(dx, stroke)


# the symbol of the seen wear per mode, b(θ) the stroke average's (resolved: each position sees the flat under it)
_SYMBOL = {"mid_stroke": lambda b: b, "stroke_average": lambda b: b * b, "resolved": np.ones_like}
# the kernel along x of the flat's seen wear per unit of its wear
_KERNEL = {"mid_stroke": lambda w: w, "stroke_average": lambda w: np.convolve(w, w), "resolved": lambda w: np.ones(1)}


class WearOperator(Convolution):
    """W: the growth of the gap per cycle per unit pressure, 4δ(k_m I + k_s B) or 4δ(k_m I + k_s B²); for a cycle
    resolved along the stroke (``resolved``: each position sees the flat's wear under it) the bound 4δ(k_m + k_s)I.

    An implicit wear step of ΔN cycles solves the contact with C + ΔN·W; the explicit update's stability is
    set by the spectrum of the pencil (W, C) (:mod:`fretsim.stability`), for which it knows its own symbol.
    """

    def __init__(self, grid: Grid, stroke: float, k_moving: float, k_stationary: float, gap_model: str):
        if gap_model not in _KERNEL:
            raise ValueError(f"unknown gap model {gap_model!r}; expected one of {', '.join(GAP_MODELS)}")
        ny, nx = grid.shape
        w = _KERNEL[gap_model](stroke_weights(grid.dx, stroke))
        reach = (w.size - 1) // 2
        kernel = np.zeros((2 * ny - 1, 2 * nx - 1))
        row = kernel[ny - 1]
        lo, hi = max(0, nx - 1 - reach), min(2 * nx - 1, nx + reach)
        row[lo:hi] += k_stationary * w[lo - (nx - 1 - reach):hi - (nx - 1 - reach)]
        row[nx - 1] += k_moving
        super().__init__(grid, 4.0 * stroke * kernel)
        self.stroke, self.k_moving, self.k_stationary, self.gap_model = stroke, k_moving, k_stationary, gap_model

    def rate(self, theta: np.ndarray) -> np.ndarray:
        """W's symbol along x for modes of phase θ per element: 4δ(k_m + k_s·b(θ)), b seen as the gap model says."""
        b = stroke_symbol(self.grid.dx, self.stroke, theta)
        return 4.0 * self.stroke * (self.k_moving + self.k_stationary * _SYMBOL[self.gap_model](b))


def wear_operator(grid: Grid, stroke: float, k_moving: float, k_stationary: float, gap_model: str) -> WearOperator:
    """W on ``grid`` (:class:`WearOperator`)."""
    return WearOperator(grid, stroke, k_moving, k_stationary, gap_model)


# --- the flat under a moving body whose points travel differently (the resolved cycle) -----------------------------

def _hat_integral(t: np.ndarray) -> np.ndarray:
    """∫_{−∞}^{t} of the unit hat (1 − |u|)⁺: 0, (t + 1)²/2, 1 − (1 − t)²/2, 1 — on [−1, 1] both pieces are
    ½ + t(1 − |t|/2), which takes a third of the passes over the array (a resolved cycle's sweeps are its largest
    arrays)."""
    t = np.clip(t, -1.0, 1.0)
    out = np.abs(t)
    out *= -0.5
    out += 1.0
    out *= t
    out += 0.5
    return out


def _sweep_shares(start: np.ndarray, end: np.ndarray, dx: float, kernel: str = "box", nx: int = 0, c0: int = 0):
    """For each element of the moving body, the flat elements its travel reaches and their shares: (target,
    share, inside), each (span, My, Mx) — target the flat element's column, inside whether it is on the grid and
    the share is positive.

    ``box``: a point carries its amount along its travel and leaves it in the flat element it is over (the
    paper's stroke average, a point per element).  ``hat``: the flat is read between element centres (linear
    interpolation) and receives by the same weights, so what an element sees changes smoothly as it travels —
    needed where the pressure is solved at each position, or a travel across an element boundary switches the
    whole flat by an element at once.  All the offsets at once: a resolved cycle builds thousands of these on
    small grids, where numpy's per-call cost, not the arithmetic, was the time.  ``start`` and ``end`` may be the
    columns from ``c0`` of a grid ``nx`` wide.
    """
    nx = nx or start.shape[1]
    lo = np.minimum(start, end) / dx
    hi = np.maximum(start, end) / dx
    length = hi - lo
    point = length < 1e-9
    cols = np.arange(c0, c0 + start.shape[1])[None, :]
    if kernel == "box":
        lo, hi = lo + 0.5, hi + 0.5  # in element widths from the left edge of the element's own cell
        first = np.floor(lo).astype(int)
        span = max(int(np.max(np.ceil(hi) - first)) if start.size else 1, 1)
        cell = first[None] + np.arange(span)[:, None, None]  # the flat element each piece lands in, relative
        overlap = np.clip(np.minimum(hi, cell + 1) - np.maximum(lo, cell), 0.0, None)
        share = np.where(point, (cell == first[None]), overlap / np.where(point, 1.0, length))
    else:
        first = np.floor(lo).astype(int)  # the hats that can be non-zero over [lo, hi]: first .. ceil(hi)
        span = max(int(np.max(np.ceil(hi) - first)) + 1 if start.size else 2, 2)
        cell = first[None] + np.arange(span)[:, None, None]
        share = _hat_integral(hi - cell)
        share -= _hat_integral(lo - cell)
        share /= np.where(point, 1.0, length)
        if point.any():  # (in gross slip no point stays put: the branch is skipped)
            share = np.where(point, np.clip(1.0 - np.abs(lo - cell), 0.0, None), share)
    target = cols + cell
    return target, share, (target >= 0) & (target < nx) & (share > 0)


class Sweep:
    """The shares of one travel (each element j of the moving body from x_j + start[j] to x_j + end[j], mm),
    computed once for the several fields deposited and read along it (:func:`sweep_deposit`, :func:`sweep_read`)."""

    def __init__(self, start: np.ndarray, end: np.ndarray, dx: float, kernel: str = "box", cols: slice = slice(None)):
        """``cols``: only these columns of the moving body travel anything (the rest deposit and read nothing)."""
        self.shape = start.shape
        ny, nx = self.shape
        c0, c1, _ = cols.indices(nx)
        # (long travels with the hat kernel go by running sums: the shares cost their span a point)
        self.sums = kernel == "hat" and c1 > c0 and float(np.abs(end - start).max()) > SUMS_TRAVEL * dx
        if self.sums:
            self._hat = HatSums(start / dx, end / dx)
            self._travels = np.zeros(self.shape, bool)
            self._travels[:, c0:c1] = True
            return
        target, share, inside = _sweep_shares(start[:, c0:c1], end[:, c0:c1], dx, kernel, nx, c0)
        self._flat = (np.arange(ny)[:, None] * nx + target)[inside]  # the flat elements, flattened
        self._share = share[inside]
        moving = np.arange(ny * nx).reshape(ny, nx)[:, c0:c1]
        self._from = np.broadcast_to(moving, target.shape)[inside]  # the moving body's

    def entries(self) -> Optional[tuple]:
        """(moving element, flat element, share) of every share, flattened indices: the sweep as the triplets of a
        sparse matrix (a resolved implicit step's coupling applies it so, fretsim.cycle.resolved.Coupling.window);
        None for a sweep by running sums, which has no shares."""
        return None if self.sums else (self._from, self._flat, self._share)

    def deposit(self, amount: np.ndarray) -> np.ndarray:
        if self.sums:
            return self._hat.deposit(np.where(self._travels, amount.reshape(self.shape), 0.0))
        return scatter_add(self._flat, self._from, self._share, amount.ravel(), amount.size).reshape(self.shape)

    def read(self, field: np.ndarray) -> np.ndarray:
        if self.sums:
            return np.where(self._travels, self._hat.read(field.reshape(self.shape)), 0.0)
        return scatter_add(self._from, self._flat, self._share, field.ravel(), field.size).reshape(self.shape)


def sweep_deposit(amount: np.ndarray, start: np.ndarray, end: np.ndarray, dx: float, kernel: str = "box") -> np.ndarray:
    """What the flat receives when each element j of the moving body carries ``amount[j]`` along its travel from
    x_j + start[j] to x_j + end[j] (mm, relative to its own centre), spread evenly over the travel.

    The flat's element i receives amount·|travel ∩ element i|/|travel|; a point that does not travel leaves all of
    it in the flat element under it.  Totals are kept exactly (inside the grid).  With every element travelling
    the same [−δ, δ] it is the stroke average :func:`stroke_average` times the amount — the generalisation of
    Eqs. 15–16 to slip that differs from point to point.  Rows (axis 0) are independent; arrays (My, Mx).
    """
    return Sweep(start, end, dx, kernel).deposit(amount)


def sweep_read(field: np.ndarray, start: np.ndarray, end: np.ndarray, dx: float, kernel: str = "box") -> np.ndarray:
    """The flat's ``field`` as each element j of the moving body sees it over its travel from x_j + start[j] to
    x_j + end[j]: the travel-weighted average, 0 beyond the grid (unworn).  The adjoint of :func:`sweep_deposit`
    (same shares), which keeps the resolved cycle's wear modes decaying: a read that is not the deposit's
    adjoint (interpolation at the travel's midpoint, say) lets short wear modes of the moving body grow.
    Only the columns whose travel reaches the field's non-zero part are read (the rest read 0 exactly)."""
    nx = field.shape[1]
    worn = np.flatnonzero(field.any(axis=0))
    if worn.size == 0:
        return np.zeros(field.shape)
    reach = int(np.ceil(max(np.abs(start).max(), np.abs(end).max()) / dx)) + 2
    return Sweep(start, end, dx, kernel, slice(max(worn[0] - reach, 0), min(worn[-1] + reach + 1, nx))).read(field)


SUMS_TRAVEL = 8  # elements: a hat sweep over longer travels reads and deposits by running sums (below; the shares
#                 cost their span a point, the sums the same whatever it is: a read 30× faster over 50 elements)


class HatSums:
    """A sweep with the hat kernel by running sums, for long travels (each of ``rows`` × ``nx`` elements from
    j + a to j + b, in elements): everything that depends on the travels alone is found once, as the shares are.

    The read is (F(j + b) − F(j + a))/(b − a), F the running integral of the field's linear interpolation (0 beyond
    the grid); the deposit its adjoint, element j's amount c_j/(b_j − a_j)·[H(j + b_j − i) − H(j + a_j − i)] at
    node i, H the hat's integral (1 a node or more behind the end, 0 a node or more ahead): a count of the ends
    ahead of each node by a cumulative sum, and the two nodes around each end by bincount.  The same operators as
    the shares' to round-off, in a few passes over the arrays whatever the travels' length; the shares cost their
    span a point — a resolved cycle's first quarter travels the half-stroke, and the wire rope's increments span
    29 of its 0.5 µm elements.  A point that does not travel reads and leaves its amount by the hat's weights under
    it."""

    def __init__(self, a: np.ndarray, b: np.ndarray):
        self.shape = rows, nx = a.shape
        j = np.arange(nx, dtype=float)[None, :]
        length = b - a
        self.point = np.abs(length) < 1e-9
        self.inv = np.where(self.point, 0.0, 1.0 / np.where(self.point, 1.0, length))
        base = (np.arange(rows) * (nx + 2))[:, None]  # (each row's nodes −1 … nx as slots 0 … nx + 1, flattened)
        self.ends = []  # per end: (slot of node k, slot of node k + 1, its fraction f, H(f), H(f − 1))
        for t in (j + b, j + a, j + a):  # (the last: where a point reads and leaves its amount)
            t = np.clip(t + 1.0, 0.0, nx + 1.0)  # from node −1
            k = np.minimum(np.floor(t).astype(int), nx)
            f = t - k
            self.ends.append(((base + k).ravel(), (base + np.minimum(k + 1, nx + 1)).ravel(), f.ravel(),
                              _hat_integral(f).ravel(), _hat_integral(f - 1.0).ravel()))
        lo, hi = np.minimum(j + a, j + b), np.maximum(j + a, j + b)  # a travel's nodes: ⌊lo⌋ … ⌈hi⌉
        cover = (np.arange(rows) * (nx + 3))[:, None]
        self.first = (cover + np.clip(np.floor(lo), -1, nx + 1).astype(int) + 1).ravel()
        self.last = (cover + np.clip(np.ceil(hi), -1, nx).astype(int) + 2).ravel()

    def read(self, field: np.ndarray) -> np.ndarray:
        rows, nx = self.shape
        g = np.zeros((rows, nx + 2))  # the field at nodes −1 … nx, 0 at the two beyond the grid
        g[:, 1:-1] = field
        c = np.zeros((rows, nx + 2))  # ∫ up to each node
        np.cumsum(0.5 * (g[:, :-1] + g[:, 1:]), axis=1, out=c[:, 1:])
        g, c = g.ravel(), c.ravel()
        values = []
        for k0, k1, f, _, _ in self.ends:
            g0, g1 = g[k0], g[k1]
            values.append((c[k0] + f * (g0 + 0.5 * f * (g1 - g0)), g0 + f * (g1 - g0)))
        out = (values[0][0] - values[1][0]) * self.inv.ravel()
        if self.point.any():
            out = np.where(self.point.ravel(), values[2][1], out)
        return out.reshape(self.shape)

    def deposit(self, amount: np.ndarray) -> np.ndarray:
        rows, nx = self.shape
        size = rows * (nx + 2)
        w = (amount * self.inv).ravel()
        (kb, kb1, _, hb0, hb1), (ka, ka1, _, ha0, ha1), (kp, kp1, fp, _, _) = self.ends
        # an end over node k (slot k + 1) counts for the nodes before k (H = 1 there): a count from each slot on
        ahead = np.bincount(kb, weights=w, minlength=size) - np.bincount(ka, weights=w, minlength=size)
        near = np.bincount(np.concatenate([kb, kb1, ka, ka1]),
                           weights=np.concatenate([w * hb0, w * hb1, -w * ha0, -w * ha1]), minlength=size)
        if self.point.any():
            wp = np.where(self.point, amount, 0.0).ravel()
            near += np.bincount(np.concatenate([kp, kp1]), weights=np.concatenate([wp * (1.0 - fp), wp * fp]),
                                minlength=size)
        whole = np.cumsum(ahead.reshape(rows, nx + 2)[:, ::-1], axis=1)[:, ::-1]
        out = whole[:, 2:] + near.reshape(rows, nx + 2)[:, 1:-1]
        # the sums leave round-off (±1e-16 of the row's total) where nothing lands: zero there, exactly, from an
        # integer count of the travels carrying anything over each node; no negative values from positive
        # amounts (a flat's wear that an increment made negative stops the run: simulate's check)
        live = amount.ravel() != 0.0
        count = np.bincount(self.first[live], minlength=rows * (nx + 3)) - \
            np.bincount(self.last[live], minlength=rows * (nx + 3))
        covered = np.cumsum(count.reshape(rows, nx + 3), axis=1)[:, 1:nx + 1] > 0
        out = np.where(covered, out, 0.0)
        if (amount >= 0.0).all():
            np.maximum(out, 0.0, out=out)
        return out
