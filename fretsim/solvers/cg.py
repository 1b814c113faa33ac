"""Constrained conjugate gradient of Polonsky & Keer (Wear 231, 1999), preconditioned, with FFT convolution.

Minimises the complementary energy ½pᵀCp + pᵀg over p ≥ 0 with Σp·A = W.  Each iteration costs one
application of C while the contact set is unchanged (the displacement is updated, not recomputed), and one
of the preconditioner.

Preconditioner: the inverse of the translation-invariant part's Fourier symbol on the padded grid (the
operator's ``convolution``), applied to the residual on the contact set and projected back onto zero-mean
changes.  It approximates C⁻¹ inside the contact, whatever the element aspect ratio (a finite cylinder's
elements are ~60 times longer than wide), and includes an implicit step's wear term exactly.  It halves the
iterations and makes each ~4 times more accurate (measured, scripts/bench_contact.py); a Polonsky–Keer step
is the unpreconditioned special case.

Convergence needs both: the pressure changed by less than ``tol`` (relative, L1) in the last iteration, and
the gap is complementary — no element outside the contact set penetrates by more than PENETRATION of the
displacement scale.  A start on one element, whose residual is zero, is therefore never "converged" while
its neighbours penetrate.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.solvers.result import ContactResult, complementarity_residual

PENETRATION = 1e-6  # allowed penetration outside the contact set, relative to the displacement scale
RECOMPUTE_EVERY = 20  # the incrementally updated displacement is recomputed this often (round-off)
# In 3D, the search directions' images and the preconditioner in single precision until the pressure changes by
# less than SINGLE_UNTIL in an iteration, then double (single's round-off held a line's change above 1e-10):
# 3D solves 1.3-1.5x faster on 400 × 27 and 128 × 128 grids, the pressures within 1e-10 of the peak
SINGLE_PRECONDITIONER = True
SINGLE_UNTIL = 1e-5


def _preconditioner(compliance, single: bool = False):
    """The preconditioner (None without a convolution part); ``single``: in single precision (float32 out)."""
    conv = getattr(compliance, "convolution", None)
    if conv is None:
        return None
    hat = conv.hat.real if np.iscomplexobj(conv.hat) else conv.hat
    inv = 1.0 / np.maximum(hat, 1e-3 * float(hat.max()))
    if single:
        inv32 = inv.astype(np.float32)
        return lambda v: conv.backward(conv.forward(v.astype(np.float32)) * inv32)
    return lambda v: conv.backward(conv.forward(v) * inv)


def solve_cg(compliance, gap: np.ndarray, load: float, p0: Optional[np.ndarray] = None,
             tol: float = 1e-10, max_iter: Optional[int] = None, precondition: bool = True) -> ContactResult:
    """Normal contact by preconditioned constrained conjugate gradient (Polonsky & Keer 1999), FFT-applied.

    Parameters
    ----------
    compliance : an operator of :mod:`fretsim.compliance` (u = C p, mm per MPa); its ``convolution`` part, if
        any, preconditions the iteration.
    gap : the initial separation ε (mm), shape of the grid; +inf where no contact is possible.
    load : Σ p·A to reach (N; N/mm in 2D).
    p0 : a warm start (MPa), clipped to p ≥ 0 and rescaled to the load; None starts near the closest points.
    tol : the relative (L1) pressure change of an iteration below which it stops, the gap then complementary.
    max_iter : iterations allowed (default from the grid size).
    precondition : False gives the plain Polonsky–Keer step (for comparisons).

    Returns
    -------
    ContactResult : pressure, approach α, contact set, iterations, ``success`` and a message; never raises on
        non-convergence (the caller decides).
    """
    total = load / compliance.grid.area  # required Σp
    allowed = np.isfinite(gap)
    h = np.where(allowed, gap, 0.0)
    max_iter = max_iter or max(1000, 5 * int(np.sqrt(gap.size)) + 200)
    # (3D only: a 2D line's transforms are too short to gain, and 2D results keep their round-off symmetries)
    single = hasattr(compliance, "single") and gap.shape[0] > 1 and SINGLE_UNTIL > 0
    precond = _preconditioner(compliance, single and SINGLE_PRECONDITIONER) if precondition else None
    p = _start(p0, h, allowed, total)
    t = np.zeros_like(p)
    gz_old, delta, err = 1.0, 0.0, np.inf
    u = compliance(p)
    # the search directions' images in single precision (a 3D transform in double costs several times single's):
    # the displacement they update drifts by about 1e-7 of each step's change, so it is recomputed in double every
    # RECOMPUTE_EVERY iterations and before convergence is judged (PENETRATION is 1e-6), as in cg_coupled
    fast, complementary = compliance.single() if single else compliance, False
    for it in range(1, max_iter + 1):
        on, m, count, g = _gradient(u, h, p)
        t, gz = _direction(g, m, count, precond, t, delta, gz_old)
        gz_old = gz
        r_raw = fast(t)
        denom = _curvature(r_raw, t, m, count)
        penetrating = (~on) & allowed & (g < 0.0)
        if denom <= 0.0 or gz == 0.0:
            # nothing left to do on this set: converged if nothing outside it penetrates (judged in double)
            if fast is not compliance:
                u = compliance(p)
                on, m, count, g = _gradient(u, h, p)
                penetrating = (~on) & allowed & (g < 0.0)
            if not penetrating.any():
                err, complementary = 0.0, True
                break
            p = _admit(p, g, penetrating, total)
            u, delta = compliance(p), 0.0
            continue
        p_old = p
        p, tau, clipped, scale = _step(p_old, float((g * t).sum()) / denom, t, g, penetrating, total)
        delta = 0.0 if penetrating.any() else 1.0
        # Without clipping or added elements p is linear in t, and so is u: one FFT per iteration instead of
        # two.  Otherwise (an element may be clipped and re-added in one step, leaving the set unchanged but p
        # not linear in t), and every RECOMPUTE_EVERY-th step against round-off, u is recomputed exactly.
        if clipped or delta == 0.0 or it % RECOMPUTE_EVERY == 0:
            u = compliance(p)
        else:
            u = scale * (u - tau * r_raw)
        err = float(np.abs(p - p_old).sum()) / total
        if not np.isfinite(err):
            return ContactResult(p_old, 0.0, p_old > 0, it, False, f"cg: non-finite pressure at iteration {it}")
        if err < SINGLE_UNTIL and single:  # the last iterations in double: single's round-off held a 60-element
            single, fast, u = False, compliance, compliance(p)  # line's change at 1.6e-10 > tol
            precond = _preconditioner(compliance) if precondition else None
        # (not in a step that admitted penetrating elements: it puts only a small pressure on them, so its change
        #  is small whatever is left to do — a window grown round a contact that moved stopped there with its gap
        #  off by a fifth of the displacement spread over the contact)
        if err < tol and delta:
            if fast is not compliance:
                u = compliance(p)
            complementary = _complementary(u, h, p, allowed)
            if complementary:
                break
    return _result(compliance, p, h, gap, allowed, it, err, tol, complementary)


def _start(p0: Optional[np.ndarray], h: np.ndarray, allowed: np.ndarray, total: float) -> np.ndarray:
    """The first pressure, Σp = total: the warm start clipped to p ≥ 0, or uniform near the closest points."""
    if p0 is not None and (p0[allowed] > 0).any():
        p = np.where(allowed, np.clip(p0, 0.0, None), 0.0)
    else:
        # a uniform start on the region nearest to contact keeps the first steps physical
        hmin = h[allowed].min()
        near = allowed & (h <= hmin + 0.5 * (np.percentile(h[allowed], 10) - hmin) + 1e-300)
        p = near.astype(float)
    p *= total / p.sum()
    return p


def _gradient(u: np.ndarray, h: np.ndarray, p: np.ndarray):
    """The contact set (mask, 0/1 weights, size) and the gap u + h less its mean over that set.

    The mean is the approach α of the current pressure, so g is the separation the step drives to zero.
    """
    on = p > 0
    m = on.astype(float)
    count = float(m.sum())
    g = u + h
    g -= float((g * m).sum()) / count
    return on, m, count, g


def _direction(g: np.ndarray, m: np.ndarray, count: float, precond, t: np.ndarray, delta: float,
               gz_old: float) -> tuple[np.ndarray, float]:
    """The next search direction on the contact set, conjugate to the last unless ``delta`` is 0, and ⟨g, z⟩.

    The preconditioned residual is projected onto zero-mean changes, so a step keeps Σp (the load).
    """
    if precond is not None:
        z = precond(g * m) * m
        z -= m * (float(z.sum()) / count)
    else:
        z = g * m
    gz = float((g * z).sum())
    t = z + (delta * gz / gz_old) * t if delta else z
    t *= m
    return t, gz


def _curvature(r_raw: np.ndarray, t: np.ndarray, m: np.ndarray, count: float) -> float:
    """tᵀ(C t − mean over the contact set): the energy's curvature along t at fixed load."""
    r_mean = float((r_raw * m).sum()) / count
    return float((r_raw * t).sum()) - r_mean * float(t.sum())


def _admit(p: np.ndarray, g: np.ndarray, penetrating: np.ndarray, total: float) -> np.ndarray:
    """Pressure put on the penetrating elements, in proportion to their penetration, then back to the load."""
    p = p.copy()
    p[penetrating] = -g[penetrating] * (total / max(float(np.abs(g[penetrating]).sum()), 1e-300))
    p *= total / p.sum()
    return p


def _step(p_old: np.ndarray, tau: float, t: np.ndarray, g: np.ndarray, penetrating: np.ndarray, total: float):
    """The step p − τt clipped to p ≥ 0, penetrating elements added, rescaled to the load.

    Returns the new pressure, the step length taken (halved while the step lifted every element off), whether
    any element was clipped, and the load's rescaling factor.
    """
    for _ in range(60):
        trial = p_old - tau * t
        clipped = bool((trial < 0.0).any())
        p = np.clip(trial, 0.0, None)
        if penetrating.any():
            p[penetrating] -= tau * g[penetrating]
        if p.sum() > 0.0:
            break
        tau *= 0.5  # the step lifted every element off (a rough gap, a poor warm start): a shorter one
    scale = total / p.sum()
    p *= scale
    return p, tau, clipped, scale


def _result(compliance, p: np.ndarray, h: np.ndarray, gap: np.ndarray, allowed: np.ndarray, it: int, err: float,
            tol: float, complementary: bool) -> ContactResult:
    """The last iterate's record: approach and residual from an exact C p, and the stopping rule's verdict."""
    u = compliance(p)
    on = p > 0
    approach = float((u + h)[on].mean())
    residual = complementarity_residual(u, np.where(allowed, gap, np.inf), p, approach)
    success = err < tol and complementary
    msg = (f"cg converged in {it} iterations (relative pressure change {err:.1e} < {tol:.0e}, gap complementary)"
           if success else
           f"cg did not converge in {it} iterations: relative pressure change {err:.1e} (tolerance {tol:.0e})"
           + ("" if complementary or err >= tol else ", elements outside the contact penetrate"))
    return ContactResult(p, approach, on, it, success, msg, residual)


def _complementary(u: np.ndarray, h: np.ndarray, p: np.ndarray, allowed: np.ndarray) -> bool:
    """No element outside the contact set penetrates beyond PENETRATION of the displacement scale."""
    on = p > 0
    g = u + h
    alpha = float(g[on].mean())
    outside = (~on) & allowed
    if not outside.any():
        return True
    scale = max(float(np.abs(u[on]).max()), 1e-300)
    return bool(float((g[outside] - alpha).min()) >= -PENETRATION * scale)
