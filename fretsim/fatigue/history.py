"""The stationary flat's stresses over one fretting cycle, from the tractions of the cycle's increments.

A cycle member records, at a state the loop asks it to detail, the moving body's pressure p and shear traction q
and each of its points' travel s relative to the flat at the start of the loop and the end of every increment
(``Cycle.tractions``).  The flat carries them where the moving body is: the traction of the moving body's point
ξ acts on the flat at ξ + s(ξ), and the shear the moving body transmits drags the flat along +x where q > 0
(the loop's force Q = Σq·A follows the rig), which is :mod:`.stresses`' convention for the shear acting on the
body.  Each state's tractions are laid onto the flat's grid by linear weights (conservative: the load and the
shear force are kept; a point between two centres shares its traction between them), and the stresses below
every element centre follow from the strips' closed forms (:func:`fretsim.fatigue.stresses.strip_stresses`).

On a uniform grid a strip's stress at an element centre depends only on the offset between the two, so each
depth's field is a convolution of the tractions with one kernel per component: done by FFT over all the
cycle's states at once, it costs a few milliseconds per depth instead of the strips' dense sums (equal to
round-off: tests/test_fatigue_loop.py).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from fretsim.compliance import fft
from fretsim.fatigue.stresses import _normal_terms, _shear_terms

DEPTHS = 28  # layers below the surface: the first a twentieth of an element (the surface), then geometric
SURFACE = 0.05  # the surface layer's depth in elements: small against dx, the strips' surface values


@dataclass(frozen=True)
class StressHistory:
    """The flat's in-plane stresses (MPa) over the cycle: arrays (state, depth, x)."""

    sxx: np.ndarray
    szz: np.ndarray
    sxz: np.ndarray


def depths(dx: float, deepest: float, layers: int = DEPTHS) -> np.ndarray:
    """The depths (mm) the flat's stresses are computed at: the surface (SURFACE elements down) and a geometric
    sequence from half an element to ``deepest``, so that the steep gradients under the contact's edges, where
    fretting cracks start, get most of them."""
    return np.concatenate([[SURFACE * dx], np.geomspace(0.5 * dx, max(deepest, 2.0 * dx), layers - 1)])


def on_flat(values: np.ndarray, travel: np.ndarray, x: np.ndarray, dx: float) -> np.ndarray:
    """A moving body's field (states, nx) laid on the flat where its points are (ξ + s), by linear weights."""
    states, nx = values.shape
    where = (x[None, :] + travel - x[0]) / dx  # in elements from the first centre
    left = np.floor(where).astype(int)
    frac = where - left
    out = np.zeros((states, nx + 2))  # a margin element each side: what falls off the grid is dropped
    rows = np.broadcast_to(np.arange(states)[:, None], values.shape)
    for shift, weight in ((0, 1.0 - frac), (1, frac)):
        idx = np.clip(left + shift + 1, 0, nx + 1)
        np.add.at(out, (rows, idx), values * weight)
    return out[:, 1:-1]


WIDTH_STEP = 64  # the kernels are made for the window's width rounded up to this: a run's windows (a new width at
#                almost every fatigue state as the scar grows) share a few, not one each (23 of 39 states missed)


@lru_cache(maxsize=512)
def _kernel(nx: int, dx: float, z: float) -> tuple:
    """The strips' kernels' FFTs at one depth for ``nx`` centres: (length, normal (3, freq), shear (3, freq))."""
    length = fft.next_fast_len(2 * nx - 1, real=True)
    offsets = np.arange(-(nx - 1), nx) * dx  # x_i − ξ_j
    out = [length]
    for terms in (_normal_terms, _shear_terms):
        lo, hi = terms(offsets + 0.5 * dx, z), terms(offsets - 0.5 * dx, z)
        k = -2.0 / np.pi * (np.array(lo) - np.array(hi))  # (3, 2nx − 1), offset −(nx−1) first
        # laid out so that a linear convolution's entry nx − 1 + i is the stress at centre i
        out.append(fft.rfft(k, length, axis=-1))
    return tuple(out)


def stresses(pressure: np.ndarray, shear: np.ndarray, dx: float, z: np.ndarray) -> StressHistory:
    """The flat's stresses at every (state, depth, centre) under the states' strip tractions (states, nx) laid on
    its grid (:func:`on_flat`): pressure compressive, shear along +x."""
    states, nx = pressure.shape
    # (the tractions are zero beyond nx up to the kernels' width: the same sums, to the FFT's round-off)
    width = -(-nx // WIDTH_STEP) * WIDTH_STEP
    kernels = [_kernel(width, float(dx), float(v)) for v in z]
    length = kernels[0][0]
    p_hat = fft.rfft(pressure, length, axis=-1)[:, None, :]  # (states, 1, freq)
    q_hat = fft.rfft(shear, length, axis=-1)[:, None, :]
    out = np.empty((3, states, len(z), nx))
    for i, (_, k_n, k_s) in enumerate(kernels):  # a depth at a time: the field's spectra would be states × depths × 3
        layer = fft.irfft(p_hat * k_n[None] + q_hat * k_s[None], length, axis=-1)  # (states, 3, length)
        out[:, :, i, :] = np.moveaxis(layer[..., width - 1:width - 1 + nx], 1, 0)
    return StressHistory(out[0], out[1], out[2])


def window(pressure: np.ndarray, margin: float = 0.5, least: int = 8) -> slice:
    """The columns the flat's stresses are computed over: those any state loads, widened each side by ``margin``
    times the loaded width (at least ``least`` elements).  Beyond, a strip load's stresses fall off as 1/r: half a
    contact width from the edge they are a small share of the contact's, and the fatigue damage, as SWT^3 to ^5,
    a far smaller one."""
    loaded = np.flatnonzero((pressure > 0).any(axis=0))
    nx = pressure.shape[1]
    if not loaded.size:
        return slice(0, 0)
    pad = max(least, int(np.ceil(margin * (loaded[-1] - loaded[0] + 1))))
    return slice(max(0, int(loaded[0]) - pad), min(nx, int(loaded[-1]) + pad + 1))
