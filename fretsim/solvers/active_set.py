"""Dense active-set method (Kalker's scheme): guess the contact set, solve its equalities, correct.

On a contact set S the separations vanish and the load balances:

    [C_SS  −e] [p_S]   [−ε_S]
    [eᵀ     0] [ α ] = [ W/A ]

Elements with negative pressure leave S, penetrating ones join (at most
doubling S per sweep), until neither happens.  Exact to round-off in a handful of dense solves, so it is
the independent check on the iterative solvers for small grids.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.solvers.result import ContactResult, complementarity_residual


def solve_active_set(compliance, gap: np.ndarray, load: float, p0: Optional[np.ndarray] = None,
                     tol: float = 1e-10, max_iter: Optional[int] = None) -> ContactResult:
    """Normal contact by a dense active-set method (Kalker): an independent, exact check on small grids.

    Parameters
    ----------
    compliance : an operator with ``dense()`` (at most ``DENSE_LIMIT`` elements).
    gap : the initial separation ε (mm); +inf where no contact is possible.
    load : Σ p·A (N; N/mm in 2D).
    p0 : a warm start: its contact set is the first guess of the active set.
    tol : the penetration allowed outside the contact set, relative to the spread of the displacement.
    max_iter : sweeps of the active set allowed (default 200).

    Returns
    -------
    ContactResult : with ``success`` False and a message if the set kept changing or a system was singular.
    """
    shape = gap.shape
    idx = np.flatnonzero(np.isfinite(gap).ravel())
    try:
        C = compliance.dense()[np.ix_(idx, idx)]
    except ValueError as exc:
        return ContactResult(np.zeros(shape), 0.0, np.zeros(shape, bool), 0, False, f"active_set: {exc}")
    eps = gap.ravel()[idx]
    total = load / compliance.grid.area
    max_iter = max_iter or 200
    if p0 is not None and (p0.ravel()[idx] > 0).any():
        active = p0.ravel()[idx] > 0
    else:
        active = eps <= eps.min()
    p = np.zeros(idx.size)
    alpha = 0.0
    success = False
    message = ""
    import scipy.linalg as sla
    for it in range(1, max_iter + 1):
        s = np.flatnonzero(active)
        k = s.size
        kkt = np.empty((k + 1, k + 1))
        kkt[:k, :k] = C[np.ix_(s, s)]
        kkt[:k, k] = -1.0
        kkt[k, :k] = 1.0
        kkt[k, k] = 0.0
        rhs = np.concatenate([-eps[s], [total]])
        try:
            sol = sla.solve(kkt, rhs, check_finite=False)
        except (sla.LinAlgError, ValueError) as exc:
            message = f"active_set: singular contact system at sweep {it}: {exc}"
            break
        ps, alpha = sol[:k], float(sol[k])
        if (ps < 0).any():
            if (ps >= 0).any():
                active[s[ps < 0]] = False
            else:
                active[:] = False
                active[s[np.argmax(ps)]] = True
            continue
        p[:] = 0.0
        p[s] = ps
        u = ps @ C[s]  # C is symmetric: a contiguous row gather
        y = eps + u - alpha
        scale = float(u.max() - u.min()) or 1.0
        penetrating = ~active & (y < -tol * scale)
        if not penetrating.any():
            success = True
            message = f"active_set converged in {it} sweeps ({k} elements in contact)"
            break
        # grow by at most the current size, most penetrating first: adding every penetrating element
        # after a poor guess overshoots to a huge dense system
        cand = np.flatnonzero(penetrating)
        active[cand[np.argsort(y[cand])[:max(k, 1)]]] = True
    else:
        message = f"active_set: contact set still changing after {max_iter} sweeps"
    full = np.zeros(gap.size)
    full[idx] = p
    pressure = full.reshape(shape)
    residual = complementarity_residual(compliance(pressure), gap, pressure, alpha) if success else float("nan")
    return ContactResult(pressure, alpha, pressure > 0, it, success, message, residual)
