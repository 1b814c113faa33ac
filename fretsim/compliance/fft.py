"""Zero-padded real FFTs with as little per-call overhead as the installed scipy allows.

The contact solver applies small convolutions thousands of times per run (a window of a few dozen elements
around the contact), where scipy.fft's Python layer (argument checks, padding, backend dispatch) costs two to
three times the transform itself.  scipy's own pocketfft binding, called directly, skips that layer.  It is a
private module: at import the direct path is checked against the public API on a small transform and used
only if it exists and agrees; otherwise the public functions are used.  Both give the same numbers.
"""
from __future__ import annotations

import numpy as np
import scipy.fft as sfft


def _public_forward(p: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    ly, lx = shape
    ph = sfft.rfft(p, n=lx, axis=1, workers=1)
    return sfft.fft(ph, n=ly, axis=0, workers=1) if ly > 1 else ph


def _public_backward(ph: np.ndarray, shape: tuple[int, int], out_shape: tuple[int, int]) -> np.ndarray:
    ny, nx = out_shape
    ly, lx = shape
    if ly > 1:
        ph = sfft.ifft(ph, axis=0, workers=1)[:ny]
    return sfft.irfft(ph, n=lx, axis=1, workers=1)[:, :nx]


def _direct():
    from scipy.fft._pocketfft import pypocketfft as pp  # private: verified below before use

    def forward(p: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        ly, lx = shape
        ny, nx = p.shape
        buf = np.zeros((ny, lx))
        buf[:, :nx] = p
        ph = pp.r2c(buf, (1,), True, 0, None, 1)
        if ly > 1:  # the padding rows are zero: x first on the My rows, then y on the padded length
            full = np.zeros((ly, ph.shape[1]), dtype=complex)
            full[:ny] = ph
            ph = pp.c2c(full, (0,), True, 0, full, 1)
        return ph

    def backward(ph: np.ndarray, shape: tuple[int, int], out_shape: tuple[int, int]) -> np.ndarray:
        ny, nx = out_shape
        ly, lx = shape
        if ly > 1:
            ph = pp.c2c(ph, (0,), False, 2, None, 1)[:ny]
        return pp.c2r(ph, (1,), lx, False, 2, None, 1)[:, :nx]

    rng = np.random.default_rng(0)
    for shape, p in (((10, 16), rng.random((4, 7))), ((1, 12), rng.random((1, 5)))):
        a, b = forward(p, shape), _public_forward(p, shape)
        if a.shape != b.shape or not np.allclose(a, b, rtol=1e-12, atol=1e-12):
            raise RuntimeError("pocketfft binding disagrees")
        if not np.allclose(backward(a, shape, p.shape), _public_backward(b, shape, p.shape), rtol=1e-12, atol=1e-12):
            raise RuntimeError("pocketfft binding disagrees")
    return forward, backward


try:
    forward, backward = _direct()
    DIRECT = True
except Exception:  # noqa: BLE001 - any problem with the private binding means: use the public API
    forward, backward = _public_forward, _public_backward
    DIRECT = False
