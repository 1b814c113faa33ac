"""Constrained conjugate gradient of Polonsky & Keer (Wear 231, 1999) with FFT convolution.

Minimises the complementary energy ½pᵀCp + pᵀg over p ≥ 0 with Σp·A = W.
Each iteration costs one FFT convolution while the contact set is unchanged, two when it changes.  A warm start (the previous
pressure) cuts the iterations when the gap changes a little between solves,
as it does between wear steps.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.compliance import Compliance
from fretsim.solvers.result import ContactResult, complementarity_residual


def solve_cg(compliance: Compliance, gap: np.ndarray, load: float, p0: Optional[np.ndarray] = None,
             tol: float = 1e-10, max_iter: Optional[int] = None) -> ContactResult:
    area = compliance.grid.area
    total = load / area  # required Σp
    allowed = np.isfinite(gap)
    h = np.where(allowed, gap, 0.0)
    max_iter = max_iter or max(1000, 5 * int(np.sqrt(gap.size)) + 200)

    if p0 is not None and (p0[allowed] > 0).any():
        p = np.where(allowed, np.clip(p0, 0.0, None), 0.0)
    else:
        # a uniform start on the region nearest to contact keeps the first steps physical
        hmin = h[allowed].min()
        near = allowed & (h <= hmin + 0.5 * (np.percentile(h[allowed], 10) - hmin) + 1e-300)
        p = near.astype(float)
    p *= total / p.sum()

    t = np.zeros_like(p)
    g_norm_old = 1.0
    delta = 0.0
    err = np.inf
    u = compliance(p)
    for it in range(1, max_iter + 1):
        g = u + h
        on = p > 0
        g -= g[on].mean()
        g_norm = float(np.dot(g[on], g[on]))
        t = np.where(on, g + delta * (g_norm / g_norm_old) * t, 0.0)
        g_norm_old = g_norm
        r_raw = compliance(t)
        r = r_raw - r_raw[on].mean()
        denom = float(np.dot(r[on], t[on]))
        if denom == 0.0 or g_norm == 0.0:
            err = 0.0
            break
        tau = float(np.dot(g[on], t[on])) / denom
        p_old = p
        trial = p - tau * t
        clipped = bool((trial < 0.0).any())
        p = np.clip(trial, 0.0, None)
        overlap = (p == 0.0) & (g < 0.0) & allowed
        if overlap.any():
            delta = 0.0
            p[overlap] -= tau * g[overlap]
        else:
            delta = 1.0
        scale = total / p.sum()
        p *= scale
        # Without clipping or added elements p is linear in t, and so is u: one FFT per iteration instead of
        # two.  Otherwise (an element may be clipped and re-added in one step, leaving the set unchanged but p
        # not linear in t), and every 20th step against round-off, u is recomputed exactly.
        if clipped or delta == 0.0 or it % 20 == 0:
            u = compliance(p)
        else:
            u = scale * (u - tau * r_raw)
        err = float(np.abs(p - p_old).sum()) / total
        if not np.isfinite(err):
            return ContactResult(p_old, 0.0, p_old > 0, it, False, f"cg: non-finite pressure at iteration {it}")
        if err < tol:
            break
    u = compliance(p)
    on = p > 0
    approach = float((u + h)[on].mean())
    contact = on
    residual = complementarity_residual(u, np.where(allowed, gap, np.inf), p, approach)
    success = err < tol
    msg = (f"cg converged in {it} iterations (relative pressure change {err:.1e} < {tol:.0e})" if success else
           f"cg did not converge in {it} iterations: relative pressure change {err:.1e} > tolerance {tol:.0e}")
    return ContactResult(p, approach, contact, it, success, msg, residual)
