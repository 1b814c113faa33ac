"""Zero-padded real FFTs with as little per-call overhead as the installed scipy allows.

The contact solver applies small convolutions thousands of times per run (a window of a few dozen elements
around the contact), where scipy.fft's Python layer (argument checks, padding, backend dispatch) costs two to
three times the transform itself.  scipy's own pocketfft binding, called directly, skips that layer.  It is a
private module: at the first transform the direct path is checked against numpy's FFT on small transforms and
used only if it exists and agrees; otherwise numpy's functions are used.  Both give the same numbers.

The binding is loaded at the first transform, not with this module (`fretsim check` and `summary` need none), and
from its file, not through ``import scipy.fft``, whose package costs 0.2-0.3 s to import (scipy.special, the
array-API layer) and gives nothing the solver uses.  numpy's FFT (pocketfft as well) checks it and stands in for it.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=512)  # every window of every operator asks again: the search cost a tenth of a resolved run
def next_fast_len(n: int, real: bool) -> int:
    """scipy.fft.next_fast_len for its pocketfft backend, without importing it: the smallest m ≥ n whose prime
    factors are 2, 3 and 5 (real transforms) or 2, 3, 5, 7 and 11 (complex ones)."""
    if n <= 6:
        return max(n, 1)
    best = 2 ** (n - 1).bit_length()  # a power of two ≥ n
    primes = (3, 5) if real else (3, 5, 7, 11)

    def search(m: int, i: int) -> None:
        nonlocal best
        for j in range(i, len(primes)):
            k = m * primes[j]
            while k < best:
                search(k, j + 1)
                p2 = k
                while p2 < n:
                    p2 *= 2
                best = min(best, p2)
                k *= primes[j]

    search(1, 0)
    return best


def _public_forward(p: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    ly, lx = shape
    ph = np.fft.rfft(p, n=lx, axis=-1)
    return np.fft.fft(ph, n=ly, axis=-2) if ly > 1 else ph


def _public_backward(ph: np.ndarray, shape: tuple[int, int], out_shape: tuple[int, int]) -> np.ndarray:
    ny, nx = out_shape
    ly, lx = shape
    if ly > 1:
        ph = np.fft.ifft(ph, axis=-2)[..., :ny, :]
    return np.fft.irfft(ph, n=lx, axis=-1)[..., :nx]


def _binding():
    """scipy's pocketfft binding (:func:`fretsim.native.load`: not through ``import scipy.fft``); where the file is
    not where scipy keeps it, the package's own module."""
    from fretsim.native import load
    module = load("fft/_pocketfft/pypocketfft", "scipy.fft._pocketfft.pypocketfft")
    if module is not None:
        return module
    from scipy.fft._pocketfft import pypocketfft  # private: verified below before use
    return pypocketfft


def _direct():
    pp = _binding()

    def forward(p: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
        ly, lx = shape
        *lead, ny, nx = p.shape
        buf = np.zeros((*lead, ny, lx), dtype=p.dtype if p.dtype == np.float32 else float)
        buf[..., :nx] = p
        ph = pp.r2c(buf, (buf.ndim - 1,), True, 0, None, 1)
        if ly > 1:  # the padding rows are zero: x first on the My rows, then y on the padded length
            full = np.zeros((*lead, ly, ph.shape[-1]), dtype=ph.dtype)
            full[..., :ny, :] = ph
            ph = pp.c2c(full, (full.ndim - 2,), True, 0, full, 1)
        return ph

    def backward(ph: np.ndarray, shape: tuple[int, int], out_shape: tuple[int, int]) -> np.ndarray:
        ny, nx = out_shape
        ly, lx = shape
        if ly > 1:
            ph = pp.c2c(ph, (ph.ndim - 2,), False, 2, None, 1)[..., :ny, :]
        return pp.c2r(ph, (ph.ndim - 1,), lx, False, 2, None, 1)[..., :nx]

    def along(a: np.ndarray, n: int, axis: int, kind: str) -> np.ndarray:
        a = np.asarray(a)
        axis = axis % a.ndim
        if kind == "irfft":  # (the first n // 2 + 1 coefficients, zero-padded where fewer: numpy's irfft)
            half = n // 2 + 1
            spec = np.zeros(a.shape[:axis] + (half,) + a.shape[axis + 1:], dtype=complex)
            keep = (slice(None),) * axis + (slice(0, min(half, a.shape[axis])),)
            spec[keep] = a[keep]
            return pp.c2r(spec, (axis,), n, False, 2, None, 1)
        if kind == "rfft" and np.iscomplexobj(a):
            raise TypeError("rfft of complex input")
        size = a.shape[axis]
        buf = np.zeros(a.shape[:axis] + (n,) + a.shape[axis + 1:], dtype=float if kind == "rfft" else complex)
        buf[(slice(None),) * axis + (slice(0, min(n, size)),)] = a[(slice(None),) * axis + (slice(0, n),)]
        return pp.r2c(buf, (axis,), True, 0, None, 1) if kind == "rfft" else pp.c2c(buf, (axis,), True, 0, buf, 1)

    rng = np.random.default_rng(0)  # against numpy's own FFT (pocketfft too) before use
    for shape, p in (((10, 16), rng.random((4, 7))), ((1, 12), rng.random((1, 5))), ((10, 16), rng.random((3, 4, 7)))):
        a, b = forward(p, shape), _public_forward(p, shape)
        if a.shape != b.shape or not np.allclose(a, b, rtol=1e-12, atol=1e-12):
            raise RuntimeError("pocketfft binding disagrees")
        if not np.allclose(backward(a, shape, p.shape[-2:]), _public_backward(b, shape, p.shape[-2:]), rtol=1e-12,
                           atol=1e-12):
            raise RuntimeError("pocketfft binding disagrees")
    q = rng.random((3, 5))
    for kind, ref in (("rfft", np.fft.rfft), ("fft", np.fft.fft)):
        if not np.allclose(along(q, 8, 0, kind), ref(q, 8, axis=0), rtol=1e-12, atol=1e-12):
            raise RuntimeError("pocketfft binding disagrees")
    if not np.allclose(along(np.fft.rfft(q, 8, axis=1), 8, 1, "irfft"), np.fft.irfft(np.fft.rfft(q, 8, axis=1), 8,
                                                                                       axis=1), rtol=1e-12, atol=1e-12):
        raise RuntimeError("pocketfft binding disagrees")
    return forward, backward, along


def _public_along(a: np.ndarray, n: int, axis: int, kind: str) -> np.ndarray:
    return {"rfft": np.fft.rfft, "fft": np.fft.fft, "irfft": np.fft.irfft}[kind](a, n, axis=axis)


def _choose() -> tuple:
    global forward, backward, _along, DIRECT
    try:
        forward, backward, _along = _direct()
        DIRECT = True
    except Exception:  # noqa: BLE001 - any problem with the private binding means: numpy's FFT (the same pocketfft)
        forward, backward, _along = _public_forward, _public_backward, _public_along
        DIRECT = False
    return forward, backward, _along


def forward(p: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """p (My, Mx) zero-padded to ``shape`` and transformed: rfft along x, then fft along y.  A stack (…, My, Mx)
    is transformed layer by layer in one call (the resolved stroke's positions)."""
    return _choose()[0](p, shape)  # the first call replaces this module's forward and backward


def backward(ph: np.ndarray, shape: tuple[int, int], out_shape: tuple[int, int]) -> np.ndarray:
    """Inverse of :func:`forward`, cropped to ``out_shape``."""
    return _choose()[1](ph, shape, out_shape)


def _along(a: np.ndarray, n: int, axis: int, kind: str) -> np.ndarray:
    return _choose()[2](a, n, axis, kind)


def rfft(a: np.ndarray, n: int, axis: int = -1) -> np.ndarray:
    """numpy.fft.rfft(a, n, axis) (zero-padded or cut to n) by the same binding as :func:`forward`."""
    return _along(a, n, axis, "rfft")


def fft(a: np.ndarray, n: int, axis: int = -1) -> np.ndarray:
    """numpy.fft.fft(a, n, axis)."""
    return _along(a, n, axis, "fft")


def irfft(a: np.ndarray, n: int, axis: int = -1) -> np.ndarray:
    """numpy.fft.irfft(a, n, axis)."""
    return _along(a, n, axis, "irfft")


DIRECT: bool | None = None  # known after the first transform
