"""Fretting fatigue over the wear history: each body's SWT field at each fatigue state, its crack-initiation life,
and Miner's sum of the damage over the cycles as the wear changes the contact.

Either body may be given constants (``materials.<body>.fatigue``).  The flat carries the moving body's tractions
where the moving body is (ξ + s, :func:`history.on_flat`).  The moving body (a cylinder of radius R ≫ the contact
half-width) is taken as a half-space of its own: it carries the pressure p and the opposite shear traction, −q,
at its own points (no travel: the grid moves with it).  Mirrored through the contact plane (its depth pointing
into it, x kept) its problem is the flat's with the shear's sign turned — the stress components in (x, depth)
are those of :func:`history.stresses` under (p, −q), the critical plane's angle measured towards its own depth.

At a fatigue state (a cycle the loop details: :data:`Setup.fatigue`'s ``states``) the cycle's tractions give the
flat's stresses over the cycle (:mod:`.history`), the SWT parameter on each point's critical plane
(:func:`fretsim.fatigue.swt.swt_search`) and the life N_i it would have if the contact stayed as it is now
(:meth:`fretsim.fatigue.swt.Basquin.lives`).  With a critical distance L the parameter is averaged over the
depth L below each surface point first (the line method) and the damage is counted per surface point.

Between two fatigue states the damage rate 1/N_i of each point is taken linear in the cycles (the trapezoid
rule): D += ½(1/N_i,before + 1/N_i,after)·ΔN.  A crack starts where D first reaches 1; the crossing within an
interval is the root of that quadratic.  Wear that removes the surface layer and relieves the edge shows as a
falling rate: the damage counted is the contact's as it was at each state, not the unworn one's.  How many
states keep the answer within model.accuracy is measured in scripts/study_fatigue.py.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from fretsim.fatigue import history
from fretsim.fatigue.swt import Basquin, swt_search
from fretsim.quantities import keyed

STATES_PER_DECADE = 6  # fatigue states on the way up (geometric): the damage rate changes fastest early
LINEAR_STATES = 16  # ... and evenly over the run, where the contact evolves slowly


@dataclass(frozen=True)
class FatigueSpec:
    """What the loop needs for one body's fatigue: its curve and elastic constants, the depths, the states."""

    curve: Basquin
    poisson: float
    depths: np.ndarray  # mm, the layers below the surface (history.depths)
    critical_distance: Optional[float]  # mm (line method); None: each point's own SWT
    states: tuple  # cycles at which the fatigue is evaluated (and the loop details the cycle)
    crack_limit: bool = False  # stop where the damage reaches 1
    keep_stresses: bool = False  # output.stresses
    body: str = "stationary"  # whose: the flat's (the tractions at ξ + s) or the moving body's (−q at its points)

    def line_layers(self) -> int:
        """The layers a state between recorded states computes: every layer without a critical distance, else
        those :func:`damage_parameter` reads (the surface layer standing for z = 0, the field interpolated at L)."""
        if self.critical_distance is None:
            return len(self.depths)
        z = np.concatenate([[0.0], self.depths[1:]])
        return min(len(z), int(np.searchsorted(z, self.critical_distance)) + 1)


def fatigue_states(last: int, snapshots: tuple) -> tuple:
    """0, the recorded states, STATES_PER_DECADE per decade up to ``last`` and LINEAR_STATES evenly over it."""
    out = {0, int(last)} | {int(s) for s in snapshots if s <= last}
    if last > 0:
        k = 0
        while True:
            n = int(round(last * 10.0 ** (-k / STATES_PER_DECADE)))
            if n < 1:
                break
            out.add(n)
            k += 1
        out |= {int(round(last * j / LINEAR_STATES)) for j in range(1, LINEAR_STATES)}
    return tuple(sorted(out))


@dataclass
class FatigueState:
    """The flat's fatigue at one state: fields on (depth, x) over the whole grid (0 where not computed: beyond
    :func:`history.window` of the contact) and the figures the summary reports."""

    swt: np.ndarray  # MPa, on the critical plane
    angle: np.ndarray  # rad, the critical plane's normal from x
    life: np.ndarray  # cycles to initiation if the contact stayed as now (per damage point)
    max_shear: float  # MPa, the largest in-plane principal shear over the cycle and the field
    max_shear_depth: float  # mm
    max_tension: float  # MPa, the largest surface σx over the cycle
    swt_max: float
    swt_x: float  # mm
    swt_depth: float  # mm
    ruiz_max: float  # MPa²·mm
    stresses: Optional[tuple] = None  # σx, σz, τxz each as its largest and smallest over the cycle, fields (depth, x)
    full: bool = True  # a recorded state: every layer, and the figures above (else the damage's layers only)
    # 3D (fields (depth, y, x)): where the peak is across the stroke, and the critical plane's normal out of the
    # x–z plane (``angle`` is then its angle from x towards z in that plane: fretsim.fatigue.field3d.plane_angles)
    swt_y: float = math.nan  # mm
    azimuth: Optional[np.ndarray] = None  # rad


def evaluate(spec: FatigueSpec, x: np.ndarray, dx: float, youngs: float, cyc, full: bool = True,
             y: Optional[np.ndarray] = None, dy: float = math.nan) -> FatigueState:
    """The flat's fatigue at a state from its cycle's tractions (``cyc.tractions``: pressure, shear, travel, each
    (states, ny, nx)).  ``full``: a recorded state, whose fields are written and whose figures the summary takes;
    otherwise (a fatigue state between them, for the damage only) with a critical distance only the layers the
    line method averages over are computed.  A 3D grid (``y``, ``dy``, more than one row): the fields by
    :func:`fretsim.fatigue.field3d.fields_3d`, over (depth, y, x)."""
    if np.asarray(cyc.tractions[0]).shape[1] > 1:
        from fretsim.fatigue.field3d import fields_3d
        p, q, travel = (np.asarray(a, dtype=float) for a in cyc.tractions)
        slid = slides(p, travel, dx)
        keep = _thinned(q, slid, fixed=bool((p == p[:1]).all()))
        slid = {keep.index(k): m for k, m in slid.items()}
        f = fields_3d(spec, x, dx, dy, youngs, (p[keep], q[keep], travel[keep]), slid, cyc.slip_stationary, full, SKIP)
        return _state(spec, spec.depths, x, f.swt, f.angle, f.extremes, f.shear_max, f.shear_depth, f.tension, f.ruiz,
                      full, y=y, azimuth=f.azimuth)
    p, q, travel = (np.asarray(a)[:, 0, :] for a in cyc.tractions)
    slid = slides(p, travel, dx)
    keep = _thinned(q, slid, fixed=bool((p == p[:1]).all()))
    p, q, travel = p[keep], q[keep], travel[keep]
    slid = {keep.index(k): m for k, m in slid.items()}  # (every sliding state is kept, and the one before it)
    if spec.body == "moving":  # its own points: a rigid slide moves nothing on it; the flat pulls it by −q
        p_on, q_on, slid = p, -q, {}
        slip = cyc.slip_moving
    else:
        p_on, q_on = history.on_flat(p, travel, x, dx), history.on_flat(q, travel, x, dx)
        slip = cyc.slip_stationary
    p_on, q_on, slid = _distinct(p_on, q_on, slid)
    cols = history.window(p_on)
    z = spec.depths
    nz, nx = len(z), len(x)
    layers = nz if full else spec.line_layers()
    swt, angle = np.zeros((nz, nx)), np.zeros((nz, nx))
    if cols.stop <= cols.start:
        return _state(spec, z, x, swt, angle, None, 0.0 if full else math.nan, 0.0, 0.0, 0.0, full)
    st = history.stresses(p_on[:, cols], q_on[:, cols], dx, z[:layers])
    plane = swt_search((st.sxx, st.szz, st.sxz), youngs, spec.poisson, slid, skip=0.0 if full else SKIP,
                       worth=None if full else lambda first: _worth(spec, first, nz))
    swt[:layers, cols], angle[:layers, cols] = plane.swt, plane.angle
    tension = float(st.sxx[:, 0, :].max())  # (the surface layer: computed at every state)
    slip_amplitude = 0.25 * np.asarray(slip)[0, cols]  # mm: a quarter of the cycle's slip
    ruiz = np.maximum(st.sxx[:, 0, :].max(axis=0), 0.0) * np.abs(q_on[:, cols]).max(axis=0) * slip_amplitude
    shear_max, shear_depth, extremes = math.nan, math.nan, None
    if full:  # every layer: the largest shear (often deeper than the critical distance) and the stresses' range
        shear = np.hypot(0.5 * (st.sxx - st.szz), st.sxz).max(axis=0)  # (depth, x) over the cycle
        k = np.unravel_index(np.argmax(shear), shear.shape)
        shear_max, shear_depth = float(shear[k]), float(z[k[0]])
        if spec.keep_stresses:
            extremes = tuple(_widen(pick(a, axis=0), cols, nx) for a in (st.sxx, st.szz, st.sxz)
                             for pick in (np.max, np.min))
    return _state(spec, z, x, swt, angle, extremes, shear_max, shear_depth, tension, float(ruiz.max(initial=0.0)),
                  full)


SKIP = 0.01  # between recorded states, points whose SWT bound is below this share of the field's largest are not
#              searched: their damage rate, ∝ SWT^3 to SWT^5 here, is below 10⁻⁶ of the peak's
REFINE_SHARE = 0.25  # between recorded states the 1° pass is made only where the damage counts: the columns (with a
#                      critical distance; else the points) whose 5° damage parameter is at least this share of the
#                      largest.  Elsewhere the damage rate, ∝ SWT^2.5 to ^5 for fatigue lives well beyond the curve's
#                      transition, is under 3 % of the peak's, and the 5° value a few % low.


def _worth(spec: FatigueSpec, first: np.ndarray, layers: int) -> np.ndarray:
    """The points (depth, x) of ``first`` (the search's 5° field over the layers computed) worth its 1° pass."""
    field = np.zeros((layers,) + first.shape[1:])
    field[:len(first)] = first
    value = damage_parameter(spec, field)
    return np.broadcast_to(value >= REFINE_SHARE * value.max(), field.shape)[:len(first)]


SLIDE_SPREAD = 0.1  # of an element: an increment whose points all travelled alike within this slid rigidly


def slides(pressure: np.ndarray, travel: np.ndarray, dx: float) -> dict:
    """{state k: elements} for the states the contact reached by sliding as a whole from the state before (every
    loaded point's travel the same within SLIDE_SPREAD of an element), by at least one element: gross slip's
    sliding between the elastic sides, which a detailed cycle takes in one increment (the tractions fixed, the
    mid-stroke models) or a few (the resolved stroke: its tractions within an increment are taken as its end's).
    The flat saw the tractions at every position on the way (:func:`fretsim.fatigue.swt.swt_search`)."""
    out = {}
    for k in range(1, len(travel)):
        on = pressure[k] > 0
        if not on.any():
            continue
        moved = (travel[k] - travel[k - 1])[on]
        m = int(round(float(moved.mean()) / dx))
        if m and float(moved.max() - moved.min()) < SLIDE_SPREAD * dx:
            out[k] = m
    return out


TIME_STATES = 12  # the cycle's states the stresses are computed at, at most, besides the sliding ones: a recorded
#                  state's elastic sides are cut in 12 for the loop's shape, the stresses need their ends


def _thinned(shear: np.ndarray, slid: dict, fixed: bool = False) -> list:
    """The states kept: the first and last, the loop's turning points (where the tangential force Σq is largest,
    smallest, or turns back: a resolved cycle's up-stroke ends at an odd index, which an even stride dropped, and
    its life came out 37 % long), every sliding one and the one it slid from, and evenly among the rest up to
    TIME_STATES — but for a cycle at ``fixed`` pressure, whose elastic sides are Masing's branches between the
    states kept (:func:`fretsim.cycle.coulomb.masing`): a recorded state then takes the states its fatigue states
    take (FATIGUE_SIDE_INCREMENTS), and its fields agree with theirs.  (The side's inner states moved the SWT field
    by at most 1.3e-5 of its peak on the Ti case at 4–25 µm and 1.9e-5 on the partial-slip ball, the lives not at
    all, and cost a recorded state 1.4× its time in 2D, 2.4× in 3D.)"""
    states = len(shear)
    force = shear.reshape(states, -1).sum(axis=1)
    step = np.diff(force)
    turns = {k for k in range(1, states - 1) if step[k - 1] * step[k] < 0}
    stride = states if fixed else max(1, int(np.ceil(states / TIME_STATES)))
    keep = ({0, states - 1, int(np.argmax(force)), int(np.argmin(force))} | turns | set(slid)
            | {k - 1 for k in slid} | set(range(0, states, stride)))
    return sorted(keep)


def _distinct(p_flat: np.ndarray, q_flat: np.ndarray, slid: dict) -> tuple:
    """The states without those whose tractions on the flat another state repeats exactly (a closed loop's start
    is its end: a fifth of gross slip's stresses and searches): the extremes over the cycle are the same."""
    states = len(p_flat)
    same = lambda j, k: np.array_equal(p_flat[j], p_flat[k]) and np.array_equal(q_flat[j], q_flat[k])  # noqa: E731
    # (kept: a sliding state, whose window counts, or the last of equal ones)
    drop = [j for j in range(states) if j not in slid and any(same(j, k) for k in range(j + 1, states))]
    if not drop:
        return p_flat, q_flat, slid
    keep = [k for k in range(states) if k not in drop]
    return p_flat[keep], q_flat[keep], {keep.index(k): m for k, m in slid.items()}


def _widen(a: np.ndarray, cols: slice, nx: int) -> np.ndarray:
    out = np.zeros(a.shape[:-1] + (nx,))
    out[..., cols] = a
    return out


def _state(spec, z, x, swt, angle, amplitudes, max_shear, shear_depth, tension, ruiz, full, y=None,
           azimuth=None) -> FatigueState:
    k = np.unravel_index(np.argmax(swt), swt.shape)
    return FatigueState(swt=swt, angle=angle, life=spec.curve.lives(damage_parameter(spec, swt)),
                        max_shear=max_shear, max_shear_depth=shear_depth, max_tension=tension,
                        swt_max=float(swt[k]), swt_x=float(x[k[-1]]), swt_depth=float(z[k[0]]), ruiz_max=ruiz,
                        stresses=amplitudes, full=full, swt_y=float(y[k[1]]) if swt.ndim == 3 else math.nan,
                        azimuth=azimuth)


def damage_parameter(spec: FatigueSpec, swt: np.ndarray) -> np.ndarray:
    """The SWT the damage is counted with: each point's (depth, x), or with a critical distance L its mean over
    the depths 0 to L below each surface point (x) — the line method, trapezoidal over the layers, the surface
    layer standing for z = 0 and the field interpolated at L."""
    L = spec.critical_distance
    if L is None:
        return swt
    z = np.concatenate([[0.0], spec.depths[1:]])  # the surface layer is at the surface
    inside = z < L
    zs = np.concatenate([z[inside], [L]])
    columns = swt.reshape(len(z), -1)  # (depth, surface point): a 3D field's (y, x) flattened
    k = int(np.searchsorted(z, L))  # L lies in [z[k − 1], z[k]) (or beyond the deepest layer: the last value)
    if L >= z[-1]:
        at_l = columns[-1]
    else:
        slope = (columns[k] - columns[k - 1]) / (z[k] - z[k - 1])  # (np.interp's own arithmetic, to the bit)
        at_l = slope * (L - z[k - 1]) + columns[k - 1]
    values = np.concatenate([columns[inside], at_l[None, :]], axis=0)
    return (np.trapezoid(values, zs, axis=0) / L).reshape((1,) + swt.shape[1:])


@dataclass
class Miner:
    """Miner's sum over the fatigue states so far, per damage point; where and when it first reached 1."""

    damage: Optional[np.ndarray] = None
    rate: Optional[np.ndarray] = None  # 1/N_i at the last state
    cycle: float = 0.0  # of the last state
    crack: Optional[tuple] = None  # (cycle, x in mm) where D first reached 1
    peaks: dict = field(default_factory=dict)  # the largest figures over the states (and where)
    # the same sum over every other state (the 1st, 3rd, …): how far the states' spacing moves the answer
    half: Optional[np.ndarray] = None
    half_rate: Optional[np.ndarray] = None
    half_cycle: float = 0.0
    half_crack: float = math.nan
    count: int = 0  # states added

    def add(self, n: int, state: FatigueState, x: Optional[np.ndarray] = None, y: Optional[np.ndarray] = None) -> None:
        """Count the damage from the last state to this one at cycle ``n``; ``x`` (and in 3D ``y``) the grid's
        element centres (mm), where a crack is said to start (kept in mm: a later widening of the grid moves the
        columns, not the place)."""
        rate = _rate(state)
        if self.damage is None:
            self.damage, self.half, self.half_rate, self.half_cycle = np.zeros_like(rate), np.zeros_like(rate), rate, n
        else:
            span = float(n) - self.cycle
            before = self.damage
            self.damage = before + 0.5 * (self.rate + rate) * span
            if self.crack is None and (self.damage >= 1.0).any():
                cycle, index = _crossing(before, self.rate, rate, span, self.cycle)
                self.crack = (cycle, float(x[index[-1]]) if x is not None else float(index[-1]))
                if len(index) == 3:  # 3D: (layer, row, column), the row's y too
                    self.crack += (float(y[index[1]]) if y is not None else float(index[1]),)
            if self.count % 2 == 0:
                self._add_half(n, rate)
        self.rate, self.cycle = rate, float(n)
        self.count += 1
        self.peak(state)

    def restart(self, n: int, state: FatigueState) -> None:
        """A load history's block starts at cycle ``n``: the damage rate jumps there, so neither sum's trapezoid
        may bridge it.  The state the last block ended at (added before) closes both sums at ``n``; the new block's
        ``state`` at the same cycle starts them again."""
        if self.damage is None:
            self.add(n, state)
            return
        if self.half_cycle < n:
            self._add_half(n, self.rate)
        self.rate = self.half_rate = _rate(state)
        self.cycle = self.half_cycle = float(n)
        self.count += self.count % 2  # (the next state is in both sums)

    def peak(self, state: FatigueState) -> None:
        """The summary's figures: the largest over the fatigue states (a load history's short heavy block may fall
        between recorded states); the largest shear, which can lie below the layers computed between recorded
        states, over the recorded states."""
        for key, value, where in (("max_shear", state.max_shear, state.max_shear_depth),
                                  ("max_tension", state.max_tension, 0.0), ("ruiz_max", state.ruiz_max, 0.0),
                                  ("swt_max", state.swt_max, (state.swt_x, state.swt_depth)
                                   + ((state.swt_y,) if math.isfinite(state.swt_y) else ()))):
            if math.isfinite(value) and (key not in self.peaks or value > self.peaks[key][0]):
                self.peaks[key] = (value, where)

    def _add_half(self, n: float, rate: np.ndarray) -> None:
        span = float(n) - self.half_cycle
        before = self.half
        self.half = before + 0.5 * (self.half_rate + rate) * span
        if not math.isfinite(self.half_crack) and (self.half >= 1.0).any():
            self.half_crack = _crossing(before, self.half_rate, rate, span, self.half_cycle)[0]
        self.half_rate, self.half_cycle = rate, float(n)

    def states_error(self) -> float:
        """The relative change of the crack cycle (or, where either sum has none, of the largest damage) when every
        other fatigue state is left out: the spacing's part of the error, read directly (a conservative reading
        for a first-order rule; the trapezoid's is second order where the rate is smooth)."""
        if self.damage is None or self.count < 3:
            return math.nan
        half, half_crack = self.half, self.half_crack
        if self.count % 2 == 0:  # the last state is not in the half set: its last interval ends there too
            span = self.cycle - self.half_cycle
            end = half + 0.5 * (self.half_rate + self.rate) * span
            if not math.isfinite(half_crack) and (end >= 1.0).any():
                half_crack = _crossing(half, self.half_rate, self.rate, span, self.half_cycle)[0]
            half = end
        if self.crack is not None and math.isfinite(half_crack):
            return abs(self.crack[0] - half_crack) / self.crack[0]
        top = float(self.damage.max())
        return abs(top - float(half.max())) / top if top > 0 else 0.0

    def to_state(self, prefix: str = "fatigue") -> dict:
        """For the loop's checkpoint (flat arrays and numbers), its keys ``prefix``_…: one Miner per body."""
        if self.damage is None:
            return {}
        # (layers, y, x): the grid's (y, x) last, so that a widening of the grid pads them as it pads the wear (a
        # line contact's one row restored: dims 3 marks a 3D grid's)
        grid = (lambda a: a) if self.damage.ndim == 3 else (lambda a: a[:, None, :])  # noqa: E731
        out = {"damage": grid(self.damage), "rate": grid(self.rate), "cycle": self.cycle,
               "half": grid(self.half), "half_rate": grid(self.half_rate),
               "half_cycle": float(self.half_cycle), "count": int(self.count)}
        if self.damage.ndim == 3:
            out["dims"] = 3
        if math.isfinite(self.half_crack):
            out["half_crack"] = float(self.half_crack)
        if self.crack is not None:
            out["crack"] = np.array(self.crack, dtype=float)
        for key, (value, where) in self.peaks.items():
            out[f"peak_{key}"] = np.array([value, *np.atleast_1d(where)], dtype=float)
        return {f"{prefix}_{k}": v for k, v in out.items()}

    @classmethod
    def from_state(cls, st: dict, prefix: str = "fatigue") -> "Miner":
        if f"{prefix}_damage" not in st:
            return cls()
        st = {k[len(prefix) + 1:]: v for k, v in st.items() if k.startswith(prefix + "_")}
        crack = None
        if "crack" in st:
            crack = tuple(float(c) for c in np.asarray(st["crack"], dtype=float))  # (cycle, x[, y in 3D])
        peaks = {}
        for key in ("max_shear", "max_tension", "ruiz_max", "swt_max"):
            if f"peak_{key}" in st:
                v = [float(a) for a in np.atleast_1d(st[f"peak_{key}"])]
                peaks[key] = (v[0], tuple(v[1:]) if len(v) > 2 else v[1])
        grid = ((lambda a: np.asarray(a, dtype=float)) if int(st.get("dims", 2)) == 3 else
                (lambda a: np.asarray(a, dtype=float)[:, 0, :]))  # noqa: E731
        return cls(grid(st["damage"]), grid(st["rate"]), float(st["cycle"]), crack, peaks, grid(st["half"]),
                   grid(st["half_rate"]), float(st["half_cycle"]), float(st.get("half_crack", math.nan)),
                   int(st["count"]))


def _rate(state: FatigueState) -> np.ndarray:
    """The damage per cycle 1/N_i at each damage point (0 where the life is infinite)."""
    finite = np.isfinite(state.life)
    return np.where(finite, 1.0 / np.where(finite, state.life, 1.0), 0.0)


def _crossing(before: np.ndarray, r0: np.ndarray, r1: np.ndarray, span: float, start: float) -> tuple:
    """The first cycle at which D(t) = D₀ + r₀t + (r₁ − r₀)t²/(2ΔN) reaches 1 over the points that passed it in
    this interval, and that point."""
    passed = np.flatnonzero((before + 0.5 * (r0 + r1) * span >= 1.0).ravel())
    b, c = r0.ravel()[passed], before.ravel()[passed] - 1.0
    a = (r1.ravel()[passed] - r0.ravel()[passed]) / (2.0 * span)
    with np.errstate(divide="ignore", invalid="ignore"):
        # the root of a·t² + b·t + c (c < 0) in the form that does not cancel when a is small (b ≥ 0: a rate)
        t = -2.0 * c / (b + np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0)))
    t = np.clip(np.nan_to_num(t, nan=span), 0.0, span)
    k = int(np.argmin(t))
    return start + float(t[k]), tuple(int(i) for i in np.unravel_index(passed[k], before.shape))


def damage_mode(crack_cycle: float, wear_limit_cycle: float) -> str:
    """"cracking" where the crack starts before any wear limit is reached, "wear" where a wear limit comes first,
    "none" where neither happens within the run."""
    crack, wear = math.isfinite(crack_cycle), math.isfinite(wear_limit_cycle)
    if crack and (not wear or crack_cycle <= wear_limit_cycle):
        return "cracking"
    return "wear" if wear else "none"


PREFIX = {"stationary": "fatigue", "moving": "fatigue_moving"}  # each body's Miner in the checkpoint


def summary(specs: tuple, state: dict, limit: Optional[tuple]) -> dict:
    """The summary's fatigue figures of each body with constants (``specs``) from a step's checkpoint
    (``Step.state``) and the limit it stopped at; the damage mode and the body whose crack starts first of both."""
    out, first = {}, (math.inf, "")
    for spec in specs:
        figures = _body_summary(Miner.from_state(state, PREFIX[spec.body]))
        crack = figures["cycles_to_crack_initiation"]
        if math.isfinite(crack) and crack < first[0]:
            first = (crack, spec.body)
        out.update({keyed(k, spec.body): v for k, v in figures.items()})
    wear_limit = limit[1] if limit is not None and limit[0] != "crack_initiation" else math.nan
    out["damage_mode"] = damage_mode(first[0], wear_limit)
    out["crack_body"] = first[1]
    return out


def _body_summary(miner: Miner) -> dict:
    nan = float("nan")
    peak = lambda key: miner.peaks.get(key, (nan, nan))  # noqa: E731
    swt, where = peak("swt_max")[0], (tuple(peak("swt_max")[1]) if "swt_max" in miner.peaks else (nan, nan))
    swt_x, swt_z = where[:2]
    across = {}
    if len(where) == 3 or (miner.damage is not None and miner.damage.ndim == 3):  # 3D: where across the stroke
        across = {"swt_location_y_mm": where[2] if len(where) == 3 else nan,
                  "crack_location_y_mm": miner.crack[2] if miner.crack is not None else nan}
    return {
        "max_shear_stress_MPa": peak("max_shear")[0],
        "max_shear_stress_depth_um": peak("max_shear")[1] * 1e3,
        "max_surface_tensile_stress_MPa": peak("max_tension")[0],
        "swt_max_MPa": swt,
        "swt_location_x_mm": swt_x,
        "swt_depth_um": swt_z * 1e3,
        "ruiz_max": peak("ruiz_max")[0],
        "cycles_to_crack_initiation": miner.crack[0] if miner.crack is not None else nan,
        "crack_location_x_mm": miner.crack[1] if miner.crack is not None else nan,
        "fatigue_damage": float(miner.damage.max()) if miner.damage is not None else nan,
        "fatigue_states_error": miner.states_error(),
        **across,
    }
