"""Zero-padded real FFTs with as little per-call overhead as the installed scipy allows.

The contact solver applies small convolutions thousands of times per run (a window of a few dozen elements
around the contact), where scipy.fft's Python layer (argument checks, padding, backend dispatch) costs two to
three times the transform itself.  scipy's own pocketfft binding, called directly, skips that layer.  It is a
private module: at import the direct path is checked against the public API on a small transform and used
only if it exists and agrees; otherwise the public functions are used.  Both give the same numbers.

scipy.fft is imported at the first transform, not with this module: `fretsim check` and `summary` need none,
and the import is a third of a quick command's time.
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
    import scipy.fft as sfft
    ly, lx = shape
    ph = sfft.rfft(p, n=lx, axis=-1, workers=1)
    return sfft.fft(ph, n=ly, axis=-2, workers=1) if ly > 1 else ph


def _public_backward(ph: np.ndarray, shape: tuple[int, int], out_shape: tuple[int, int]) -> np.ndarray:
    import scipy.fft as sfft
    ny, nx = out_shape
    ly, lx = shape
    if ly > 1:
        ph = sfft.ifft(ph, axis=-2, workers=1)[..., :ny, :]
    return sfft.irfft(ph, n=lx, axis=-1, workers=1)[..., :nx]


def _direct():
    from scipy.fft._pocketfft import pypocketfft as pp  # private: verified below before use

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

    rng = np.random.default_rng(0)
    for shape, p in (((10, 16), rng.random((4, 7))), ((1, 12), rng.random((1, 5))), ((10, 16), rng.random((3, 4, 7)))):
        a, b = forward(p, shape), _public_forward(p, shape)
        if a.shape != b.shape or not np.allclose(a, b, rtol=1e-12, atol=1e-12):
            raise RuntimeError("pocketfft binding disagrees")
        if not np.allclose(backward(a, shape, p.shape[-2:]), _public_backward(b, shape, p.shape[-2:]), rtol=1e-12,
                           atol=1e-12):
            raise RuntimeError("pocketfft binding disagrees")
    return forward, backward


def _choose() -> tuple:
    global forward, backward, DIRECT
    try:
        forward, backward = _direct()
        DIRECT = True
    except Exception:  # noqa: BLE001 - any problem with the private binding means: use the public API
        forward, backward = _public_forward, _public_backward
        DIRECT = False
    return forward, backward


def forward(p: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """p (My, Mx) zero-padded to ``shape`` and transformed: rfft along x, then fft along y.  A stack (…, My, Mx)
    is transformed layer by layer in one call (the resolved stroke's positions)."""
    return _choose()[0](p, shape)  # the first call replaces this module's forward and backward


def backward(ph: np.ndarray, shape: tuple[int, int], out_shape: tuple[int, int]) -> np.ndarray:
    """Inverse of :func:`forward`, cropped to ``out_shape``."""
    return _choose()[1](ph, shape, out_shape)


DIRECT: bool | None = None  # known after the first transform
