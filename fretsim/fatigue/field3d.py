"""The flat's fatigue below a 3D contact at one fatigue state: the 2D state's method (:func:`.damage.evaluate`)
with the half-space's six stresses and the critical plane searched over normals.

The cycle's tractions (pressure and the shear along the stroke, x) are laid on the flat where the moving body's
points are, row by row (:func:`.history.on_flat`); the stresses below the loaded window follow from the uniform
rectangles' closed forms by FFT, each depth's kernels made once for all the cycle's states
(:func:`.stresses3d.stress_history`); the SWT parameter is searched over 400 normals and refined about each
point's best where it matters (:func:`.swt.swt_search_3d`).

A state the contact reached by sliding rigidly over m elements passed every position between: those positions'
stresses are the slid state's shifted by 1 … m − 1 elements along x (the same tractions on a uniform grid), which
the plane search takes as sliding windows (:func:`.swt.swt_search_3d`) — exact, like the 2D search's, and no
stress computed twice.

In 3D the search skips points whose bound (:func:`.swt.bound_3d`) is below SKIP_3D of the field's peak at every
state, the recorded ones too: the window's deep, far layers are most of its points and carry nothing; the
written field is 0 there, and the bound says by how little that can be wrong (at most SKIP_3D of the peak).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from fretsim.fatigue import history
from fretsim.fatigue.stresses3d import stress_history
from fretsim.fatigue.swt import swt_search_3d

SKIP_3D = 1e-3  # of the peak: below it a point's SWT is written as 0 (recorded states; SKIP between them)
MARGIN_Y = 0.5  # the window's widening across the stroke, times the loaded width (as history.window along x)


@dataclass(frozen=True)
class Fields3D:
    """A 3D state's fields (depth, y, x) and figures, for :func:`.damage.evaluate` to make its state of."""

    swt: np.ndarray
    angle: np.ndarray  # rad: the critical plane's normal from x towards z in the x–z plane
    azimuth: np.ndarray  # rad: ... out of that plane towards y
    extremes: Optional[tuple]  # σxx, σzz, σxz each as its largest and smallest over the cycle (output.stresses)
    shear_max: float
    shear_depth: float
    tension: float
    ruiz: float


def fields_3d(spec, x: np.ndarray, dx: float, dy: float, youngs: float, tractions: tuple, slid: dict,
              slip_stationary: np.ndarray, full: bool, skip_between: float) -> Fields3D:
    """The flat's fields below a 3D contact from the cycle's kept states' tractions (pressure, shear, travel, each
    (state, ny, nx)) and its rigid slides {state: elements} (:func:`.damage.slides`)."""
    p, q, travel = tractions
    states, ny, nx = p.shape
    flat = lambda v: history.on_flat(v.reshape(-1, nx), travel.reshape(-1, nx), x, dx).reshape(v.shape)  # noqa
    p_flat, q_flat = flat(p), flat(q)
    z = spec.depths
    nz = len(z)
    layers = nz if full else spec.line_layers()
    swt, angle, azimuth = np.zeros((nz, ny, nx)), np.zeros((nz, ny, nx)), np.zeros((nz, ny, nx))
    rows, cols = _window(p_flat)
    if cols.stop <= cols.start:
        return Fields3D(swt, angle, azimuth, None, 0.0 if full else math.nan, 0.0, 0.0, 0.0)
    st = stress_history(p_flat[:, rows, cols], q_flat[:, rows, cols], dx, dy, z[:layers], spec.poisson, single=not full)
    plane = swt_search_3d(st, youngs, spec.poisson, skip=SKIP_3D if full else skip_between, full=full, slides=slid)
    swt[:layers, rows, cols] = plane.swt
    angle[:layers, rows, cols], azimuth[:layers, rows, cols] = plane_angles(plane.normal)
    sxx_surface = st[0, :, 0]  # (state, y, x): the surface layer, computed at every state
    slip_amplitude = 0.25 * np.asarray(slip_stationary)[rows, cols]  # mm: a quarter of the cycle's slip
    ruiz = np.maximum(sxx_surface.max(axis=0), 0.0) * np.abs(q_flat[:, rows, cols]).max(axis=0) * slip_amplitude
    shear_max, shear_depth, extremes = math.nan, math.nan, None
    if full:  # every layer: the largest principal shear (Tresca's), often deeper than the critical distance
        shear_max, layer = _largest_shear(st)
        shear_depth = float(z[layer])
        if spec.keep_stresses:
            extremes = tuple(_widen(pick(st[c], axis=0), rows, cols, (nz, ny, nx)) for c in (0, 2, 4)
                             for pick in (np.max, np.min))
    return Fields3D(swt, angle, azimuth, extremes, shear_max, shear_depth, float(sxx_surface.max()),
                    float(ruiz.max(initial=0.0)))


def plane_angles(normal: np.ndarray) -> tuple:
    """A plane's normal n (…, 3) as two angles: θ ∈ [0, π) from x towards z (the 2D plane angle, for a normal in
    the x–z plane), and β ∈ [−π/2, π/2] out of that plane towards y — n = ±(cos β cos θ, sin β, cos β sin θ)."""
    n = np.where((np.arctan2(normal[..., 2], normal[..., 0]) < 0)[..., None], -normal, normal)
    theta = np.mod(np.arctan2(n[..., 2], n[..., 0]), np.pi)
    return theta, np.arcsin(np.clip(n[..., 1], -1.0, 1.0))


def _window(pressure: np.ndarray) -> tuple:
    """The rows and columns the stresses are computed over: those any state loads, widened as
    :func:`.history.window` does along x (and by MARGIN_Y of the loaded width across)."""
    cols = history.window(pressure.max(axis=1))
    loaded = np.flatnonzero((pressure > 0).any(axis=(0, 2)))
    ny = pressure.shape[1]
    if not loaded.size:
        return slice(0, 0), slice(0, 0)
    pad = max(4, int(np.ceil(MARGIN_Y * (loaded[-1] - loaded[0] + 1))))
    return slice(max(0, int(loaded[0]) - pad), min(ny, int(loaded[-1]) + pad + 1)), cols


def _largest_shear(st: np.ndarray) -> tuple:
    """The largest (σ₁ − σ₃)/2 over the history (6, state, depth, y, x) and its depth's index.  It lies between
    1.5 and √3 times r = √(J₂/3) at every point (the deviator's principal values are 2r·cos(θ − 2πk/3), θ in
    [0, π/3]), so only the points with J₂ at least 3/4 of the largest can hold it: the eigenvalues are taken there
    alone (the field's J₂ a state at a time, in arrays made once; the closed form everywhere was a third of a
    second a recorded state on the ball)."""
    shape = st.shape[2:]
    j2 = np.empty(st.shape[1:])
    mean, d, t = np.empty(shape), np.empty(shape), np.empty(shape)
    for k in range(st.shape[1]):
        s = st[:, k]
        np.add(s[0], s[1], out=mean)
        mean += s[2]
        mean /= 3.0
        out = j2[k]
        np.square(np.subtract(s[0], mean, out=d), out=out)
        out += np.square(np.subtract(s[1], mean, out=d), out=t)
        out += np.square(np.subtract(s[2], mean, out=d), out=t)
        out *= 0.5
        for c in (3, 4, 5):
            out += np.square(s[c], out=t)
    at = np.flatnonzero(j2 >= 0.74 * j2.max())  # (3/4 less a margin for the rounding)
    shear = _tresca(st.reshape(6, -1)[:, at])
    best = int(np.argmax(shear))
    return float(shear[best]), int(np.unravel_index(at[best], j2.shape)[1])


def _tresca(st: np.ndarray) -> np.ndarray:
    """(σ₁ − σ₃)/2 at every (state, depth, y, x): the symmetric 3 × 3 eigenvalues in closed form (the deviator's
    invariants and the trigonometric solution of its cubic; LAPACK one matrix at a time was a second a state)."""
    sxx, syy, szz, sxy, sxz, syz = st
    mean = (sxx + syy + szz) / 3.0
    dx, dy, dz = sxx - mean, syy - mean, szz - mean
    j2 = (dx * dx + dy * dy + dz * dz) / 2.0 + sxy * sxy + sxz * sxz + syz * syz
    j3 = dx * dy * dz + 2.0 * sxy * sxz * syz - dx * syz * syz - dy * sxz * sxz - dz * sxy * sxy
    r = np.sqrt(j2 / 3.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(r > 0, j3 / (2.0 * r ** 3), 0.0)
    lode = np.arccos(np.clip(c, -1.0, 1.0)) / 3.0  # the deviator's principal values 2r·cos(lode − 2πk/3)
    return r * (np.cos(lode) - np.cos(lode + 2.0 * np.pi / 3.0))


def _widen(a: np.ndarray, rows: slice, cols: slice, shape: tuple) -> np.ndarray:
    out = np.zeros(shape)
    out[:, rows, cols] = a
    return out
