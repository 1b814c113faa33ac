"""Tangential contact with Coulomb friction: one load increment, as a bound-constrained quadratic program.

Over an increment the rigid tangential displacement of the moving body changes by ΔU and the shear traction
from q₀ to q; the slip increment of each element is s = ΔU − K(q − q₀) (K the tangential compliance, both
bodies and the rig).  Coulomb's law: where |q| < μp the element sticks (s = 0); where it slips, q = μp·sign(s).
These are the optimality conditions of

    minimise ½ qᵀKq − qᵀb   subject to  −μp ≤ q ≤ μp,     b = K q₀ + ΔU·1,

whose gradient g = Kq − b is −s: zero in the stick zone, pointing out of the box where an element slips (the
incremental form of Kalker's variational principle).  K is symmetric positive definite, so the minimum is
unique; a monotone increment from a converged state (stick zones only shrinking) reaches the same state
whatever the path inside it, so a partial-slip loop is exact with one increment per half-stroke when the
pressure does not change (Mindlin–Deresiewicz).

The solver is Polonsky & Keer's constrained conjugate gradient carried over to a box, in the manner of Dostál's
MPRGP: conjugate directions on the stick set, preconditioned by the inverse of the compliance's Fourier symbol
(as the normal solver); an element that overshoots its bound is clipped to it (it starts to slip); elements at a
bound whose gradient points inwards (their slip has reversed, as at the stroke's end) are released together by
an exact line search along their gradient, and conjugacy restarts.  Converged when the traction
changed by less than ``tol`` (relative to the largest traction allowed) in the last iteration and the
conditions hold to PENETRATION of the displacement scale.  It never raises: ``success`` False and a message.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from fretsim.solvers.cg import _preconditioner

SLIP_TOLERANCE = 1e-8  # a stuck element's |gradient| (its slip), relative to the displacement scale
RECOMPUTE_EVERY = 20  # the updated displacement is recomputed this often (round-off)


@dataclass(frozen=True)
class TangentialResult:
    traction: np.ndarray  # shear traction q along x (MPa)
    slip: np.ndarray  # slip increment s = ΔU − K(q − q₀) (mm); 0 where the element sticks
    stick: np.ndarray  # boolean: elements in contact that stuck over the increment
    iterations: int
    success: bool
    message: str
    residual: float = float("nan")  # the worst violation of the conditions, relative to the displacement scale


def solve_tangential(compliance, rhs: np.ndarray, bound: np.ndarray, q0: Optional[np.ndarray] = None,
                     tol: float = 1e-10, max_iter: Optional[int] = None) -> TangentialResult:
    """Minimise ½ qᵀKq − qᵀ·rhs over |q| ≤ bound (elementwise; bound 0 outside the contact).

    Parameters
    ----------
    compliance : the tangential operator K (mm per MPa), e.g. :class:`fretsim.compliance.tangential.Tangential`.
    rhs : b = K q₀ + ΔU (mm) on the grid.
    bound : μ·p (MPa), ≥ 0.
    q0 : a warm start (the traction before the increment); clipped to the box.
    tol : relative change of the traction (L1, against Σ bound) in the last iteration below which it stops.
    max_iter : iterations allowed (default from the grid size).

    Returns
    -------
    TangentialResult : traction, slip increment, stick set, iterations, success, message.
    """
    bound = np.clip(bound, 0.0, None)
    lo, hi = -bound, bound
    allowed = bound > 0
    scale_q = float(bound.sum())
    max_iter = max_iter or max(1000, 5 * int(np.sqrt(rhs.size)) + 200)
    if scale_q <= 0:
        zero = np.zeros_like(rhs)
        return TangentialResult(zero, np.zeros_like(rhs), np.zeros(rhs.shape, bool), 0, True, "no contact")
    q = np.zeros_like(rhs) if q0 is None else np.clip(np.where(allowed, q0, 0.0), lo, hi)
    return _iterate(compliance, rhs, lo, hi, allowed, scale_q, q, tol, max_iter)


def _iterate(compliance, rhs: np.ndarray, lo: np.ndarray, hi: np.ndarray, allowed: np.ndarray, scale_q: float,
             q: np.ndarray, tol: float, max_iter: int) -> TangentialResult:
    """Constrained CG from the start ``q``: proportioning where a slip reversed, conjugate steps on the stuck set."""
    precond = _preconditioner(compliance)
    u = compliance(q)
    disp_scale = max(float(np.abs(rhs[allowed]).max()), float(np.abs(u[allowed]).max()), 1e-300)
    t = np.zeros_like(q)
    gz_old, delta, err = 1.0, 0.0, np.inf
    it = 0
    for it in range(1, max_iter + 1):
        g = u - rhs
        at_lo, at_hi = allowed & (q <= lo), allowed & (q >= hi)
        free = allowed & ~at_lo & ~at_hi
        release = (at_lo & (g < 0)) | (at_hi & (g > 0))  # a slipping element whose slip has reversed
        q_old = q
        if release.any():
            q, curvature = _release(compliance, q, g, release, lo, hi)
            if q is None:
                return _result(q_old, u, rhs, allowed, lo, hi, disp_scale, it, False, _not_definite(curvature))
            u, delta = compliance(q), 0.0
            err = float(np.abs(q - q_old).sum()) / scale_q
            continue
        if not free.any():  # every element slips the way its gradient says: optimal
            return _finish(compliance, q, rhs, allowed, lo, hi, disp_scale, it, True, 0.0, tol)
        t, gz = _direction(g, free, precond, t, delta, gz_old)
        gz_old = gz
        r = compliance(t)
        denom = float((r * t).sum())
        if denom <= 0.0:
            if gz != 0.0:
                return _result(q, u, rhs, allowed, lo, hi, disp_scale, it, False, _not_definite(denom))
            err = 0.0  # the stuck set is already exact
        else:
            q, tau, clipped = _step(q, t, g, denom, free, lo, hi)
            delta = 0.0 if clipped else 1.0
            u = compliance(q) if clipped or it % RECOMPUTE_EVERY == 0 else u - tau * r
            err = float(np.abs(q - q_old).sum()) / scale_q
        if not np.isfinite(err):
            return _result(q_old, compliance(q_old), rhs, allowed, lo, hi, disp_scale, it, False,
                           f"tangential: non-finite traction at iteration {it}")
        if err < tol and _kkt(q, u - rhs, allowed, lo, hi) <= SLIP_TOLERANCE * disp_scale:
            return _finish(compliance, q, rhs, allowed, lo, hi, disp_scale, it, True, err, tol)
    return _finish(compliance, q, rhs, allowed, lo, hi, disp_scale, it, False, err, tol)


def _finish(compliance, q, rhs, allowed, lo, hi, disp_scale, it, ok, err, tol) -> TangentialResult:
    """The record of the last iterate, its slip from an exact K q, and the stopping rule's verdict."""
    u = compliance(q)
    msg = (f"tangential converged in {it} iterations" if ok else
           f"tangential did not converge in {it} iterations: relative traction change {err:.1e} (tolerance "
           f"{tol:.0e}), optimality residual {_kkt(q, u - rhs, allowed, lo, hi) / disp_scale:.1e}")
    return _result(q, u, rhs, allowed, lo, hi, disp_scale, it, ok, msg)


def _release(compliance, q: np.ndarray, g: np.ndarray, release: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Proportioning: the released elements move inwards along their gradient by the exact line search of the
    quadratic, then stick or reach the other bound (conjugacy restarts after).

    Returns the new traction (None where the curvature along the gradient is not positive) and that curvature.
    """
    d = np.where(release, g, 0.0)
    r = compliance(d)
    curvature = float((d * r).sum())
    if curvature <= 0.0:
        return None, curvature
    return np.clip(q - float((d * g).sum()) / curvature * d, lo, hi), curvature


def _direction(g: np.ndarray, free: np.ndarray, precond, t: np.ndarray, delta: float,
               gz_old: float) -> tuple[np.ndarray, float]:
    """The preconditioned direction on the stuck set, conjugate to the last unless ``delta`` is 0, and ⟨g, z⟩."""
    m = free.astype(float)
    z = precond(g * m) * m if precond is not None else g * m
    gz = float((g * z).sum())
    return (z + (delta * gz / gz_old) * t if delta and gz_old else z) * m, gz


def _step(q: np.ndarray, t: np.ndarray, g: np.ndarray, denom: float, free: np.ndarray, lo: np.ndarray,
          hi: np.ndarray) -> tuple[np.ndarray, float, bool]:
    """The exact line-search step along t, clipped to the box: (traction, step length, whether a stuck element
    overshot its bound)."""
    tau = float((g * t).sum()) / denom
    trial = q - tau * t
    clipped = bool(((trial < lo) | (trial > hi))[free].any())
    return np.clip(trial, lo, hi), tau, clipped  # an element that overshoots its bound starts to slip


def _not_definite(curvature: float) -> str:
    return f"tangential: the compliance is not positive definite here (curvature {curvature:.2e})"


def _kkt(q, g, allowed, lo, hi) -> float:
    """The worst violation (mm) of the optimality conditions: |g| where stuck, g of the wrong sign at a bound."""
    free = allowed & (q > lo) & (q < hi)
    worst = float(np.abs(g[free]).max()) if free.any() else 0.0
    at_lo, at_hi = allowed & (q <= lo), allowed & (q >= hi)
    if at_lo.any():
        worst = max(worst, float(np.clip(-g[at_lo], 0, None).max()))
    if at_hi.any():
        worst = max(worst, float(np.clip(g[at_hi], 0, None).max()))
    return worst


def _result(q, u, rhs, allowed, lo, hi, scale, it, ok, msg) -> TangentialResult:
    g = u - rhs
    stick = allowed & (q > lo) & (q < hi)
    slip = np.where(allowed & ~stick, -g, 0.0)
    return TangentialResult(q, slip, stick, it, ok, msg, _kkt(q, g, allowed, lo, hi) / scale)
