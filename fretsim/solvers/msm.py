"""The Modified Simplex Method of the paper (Eqs. 7–8), after Conry & Seireg and Vijayakar et al.

Phase-1 simplex on the linear program

    −C p + α e + I Y + I Z = ε           (one row per element)
     eᵀ p               + Z_{n+1} = W/A   (equilibrium)
     p, Y, α, Z ≥ 0,   minimise Σ Z

with the restricted-basis entry rule: p_i and Y_i (the pressure and the final
separation of element i) are never basic together, which is the contact
criterion (Eq. 2).  When Σ Z reaches 0 the basis is a solution.

Implementation notes, each an exact equivalent of the textbook steps:

* The artificial Z_i of the element rows and the slacks Y_i have identical
  columns, so the n pivots that swap them are done in closed form: the start
  basis is {Y_1..Y_n, Z_{n+1}}, feasible because ε is shifted to min ε = 0.
* α is a free variable: it is pivoted in first and never leaves.
* The basis is kept as sets, not as an n × n inverse.  With the slack rows R
  (Y_i basic) and the other rows T, the basis matrix is block triangular,
      B = [[I, A_RN], [0, A_TN]],   B⁻¹ = [[I, −A_RN M⁻¹], [0, M⁻¹]],  M = A_TN,
  so a pivot only factorises M, whose size is the number of elements in
  contact (+1).  Every pivot recomputes the basic solution from scratch, so
  round-off does not accumulate.
* Pricing looks first at elements whose p and Y are both non-basic (the
  restricted rule leaves exactly one such pair), then at the others, which
  may only enter if their complement leaves in the same pivot; if no column
  improves, the complement of the variable that left last enters (a
  degenerate complementary step, as in Lemke's method).
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fretsim.solvers.result import ContactResult, complementarity_residual


def solve_msm(compliance, gap: np.ndarray, load: float, p0: Optional[np.ndarray] = None,
              tol: float = 1e-10, max_iter: Optional[int] = None) -> ContactResult:
    """Normal contact by the paper's Modified Simplex Method (Eqs. 7–8): an exact vertex of the LP, dense.

    Parameters
    ----------
    compliance : an operator with ``dense()`` (at most ``DENSE_LIMIT`` elements); its matrix is C of Eq. 5.
    gap : the initial separation ε (mm); +inf where no contact is possible (those elements are left out).
    load : Σ p·A (N; N/mm in 2D).
    p0 : ignored (the simplex starts from its own feasible basis).
    tol : ignored (the solution is exact to round-off when the artificial variables reach zero).
    max_iter : pivots allowed (default 4n + 10).

    Returns
    -------
    ContactResult : with ``success`` False and a message if the pivots ran out or the matrix was too large.
    """
    shape = gap.shape
    idx = np.flatnonzero(np.isfinite(gap).ravel())
    try:
        C = compliance.dense()[np.ix_(idx, idx)]
    except ValueError as exc:
        return ContactResult(np.zeros(shape), 0.0, np.zeros(shape, bool), 0, False, f"msm: {exc}")
    eps = gap.ravel()[idx]
    shift = float(eps.min())
    eps = eps - shift
    n = idx.size
    total = load / compliance.grid.area
    max_iter = max_iter or 4 * n + 10
    lp = _Basis(C, eps, total)
    success, message, pivots = _pivot_to_solution(lp, C, total, max_iter)
    p, approach = np.zeros(n), 0.0
    if success:
        p, approach, success, message = _solution(lp, n, shift, total, pivots)
    full = np.zeros(gap.size)
    full[idx] = p
    pressure = full.reshape(shape)
    residual = complementarity_residual(compliance(pressure), gap, pressure, approach) if success else float("nan")
    return ContactResult(pressure, approach, pressure > 0, pivots, success, message, residual)


def _pivot_to_solution(lp: "_Basis", C: np.ndarray, total: float, max_iter: int) -> tuple[bool, str, int]:
    """Pivot until Σ Z = 0 (success), no variable may enter, or ``max_iter`` pivots: (success, message, pivots)."""
    # the free variable α enters first
    lp.pivot(("alpha", -1), lp.ratio_test(lp.direction(("alpha", -1)), None))
    pivots = 1
    last_left = None
    while pivots < max_iter:
        if not lp.z_basic or lp.z_value() <= 1e-14 * total:
            return True, "", pivots  # Σ Z = 0: the basis is complementary and feasible
        entering, leaving = _entering(lp, C, last_left)
        if entering is None:
            z = lp.z_value()
            return False, f"msm: no admissible entering variable with Z = {z:.3e} > 0 after {pivots} pivots", pivots
        last_left = leaving
        lp.pivot(entering, leaving)
        pivots += 1
    return False, f"msm: no solution within {max_iter} pivots", pivots


def _entering(lp: "_Basis", C: np.ndarray, last_left):
    """The restricted-basis entry rule: (entering, leaving) variables of the next pivot, or (None, None)."""
    y_t = lp.dual()
    rc_tol = 1e-12 * (float(np.abs(y_t).max()) * float(C[0, 0]) + 1.0)
    # 1) unrestricted candidates: elements with both p and Y non-basic
    for rc, q in sorted(lp.free_pair_prices(y_t)):
        if rc >= -rc_tol:
            break
        leaving = lp.ratio_test(lp.direction(q), None)
        if leaving is not None:
            return q, leaving
    # 2) restricted candidates: only if their basic complement leaves in this pivot
    for rc, q in sorted(lp.restricted_prices(y_t))[:50]:
        if rc >= -rc_tol:
            break
        comp = _complement(q)
        leaving = lp.ratio_test(lp.direction(q), comp)
        if leaving == comp:
            return q, leaving
    # 3) degenerate complementary step
    if last_left is not None and _complement(last_left) is not None and not lp.is_basic(_complement(last_left)):
        q = _complement(last_left)
        leaving = lp.ratio_test(lp.direction(q), None)
        if leaving is not None:
            return q, leaving
    return None, None


def _solution(lp: "_Basis", n: int, shift: float, total: float, pivots: int) -> tuple[np.ndarray, float, bool, str]:
    """The pressures and approach of the final basis: (p, α, success, message); a negative pressure fails."""
    p = np.zeros(n)
    approach = 0.0
    for (kind, j), v in zip(lp.nonslack, lp.solve_basic()):
        if kind == "F":
            p[j] = v
        elif kind == "alpha":
            approach = float(v) + shift
    success, message = True, f"msm converged in {pivots} pivots"
    if (p < -1e-9 * total).any():
        success, message = False, f"msm: the final basis has negative pressure {p.min():.3e}"
    np.clip(p, 0.0, None, out=p)
    return p, approach, success, message


def _complement(var):
    kind, j = var
    return ("Y", j) if kind == "F" else (("F", j) if kind == "Y" else None)


class _Basis:
    """The simplex basis as sets: slack rows R (Y basic) and non-slack basic columns (F_j, α, Z)."""

    def __init__(self, C: np.ndarray, eps: np.ndarray, total: float):
        self.C, self.eps, self.total = C, eps, total
        n = eps.size
        self.y_basic = np.ones(n, bool)  # R
        self.f_basic = np.zeros(n, bool)
        self.nonslack: list[tuple[str, int]] = [("Z", -1)]
        self.t_rows: list[int] = [n]  # element rows not in R, then the load row n (kept last)
        self._factor()

    @property
    def z_basic(self) -> bool:
        return ("Z", -1) in self.nonslack

    def is_basic(self, var) -> bool:
        kind, j = var
        return bool(self.y_basic[j]) if kind == "Y" else (bool(self.f_basic[j]) if kind == "F" else var in self.nonslack)

    def _column_rows(self, var, rows: np.ndarray) -> np.ndarray:
        """Entries of a variable's column at constraint ``rows`` (n = load row)."""
        kind, j = var
        n = self.eps.size
        is_load = rows == n
        if kind == "F":
            out = -self.C[np.minimum(rows, n - 1), j]
            out[is_load] = 1.0
        elif kind == "alpha":
            out = np.where(is_load, 0.0, 1.0)
        elif kind == "Z":
            out = is_load.astype(float)
        else:  # Y_j
            out = (rows == j).astype(float)
        return out

    def _block(self, rows: np.ndarray) -> np.ndarray:
        """Columns of all non-slack basic variables at constraint ``rows``, vectorised."""
        n = self.eps.size
        is_load = rows == n
        out = np.empty((rows.size, len(self.nonslack)))
        f_pos = [k for k, v in enumerate(self.nonslack) if v[0] == "F"]
        if f_pos:
            f_js = [self.nonslack[k][1] for k in f_pos]
            block = -self.C[np.ix_(np.minimum(rows, n - 1), f_js)]
            block[is_load, :] = 1.0
            out[:, f_pos] = block
        for k, v in enumerate(self.nonslack):
            if v[0] != "F":
                out[:, k] = self._column_rows(v, rows)
        return out

    def _factor(self) -> None:
        import scipy.linalg as sla
        rows = np.asarray(self.t_rows)
        self._rows = rows
        self._r_rows = np.flatnonzero(self.y_basic)
        self._lu = sla.lu_factor(self._block(rows), check_finite=False)
        self._f_pos = [k for k, v in enumerate(self.nonslack) if v[0] == "F"]
        self._f_js = [self.nonslack[k][1] for k in self._f_pos]
        self._alpha_pos = self.nonslack.index(("alpha", -1)) if ("alpha", -1) in self.nonslack else None
        x_n = sla.lu_solve(self._lu, self._b_t(), check_finite=False)
        self._x_n = x_n
        self._x_r = self.eps[self._r_rows] - self._apply_rn(x_n)

    def _apply_rn(self, v: np.ndarray) -> np.ndarray:
        """A_RN v on the slack rows R; C is symmetric, so C[R, S] v_S = (v_S C[S, :])[R] (contiguous rows)."""
        full = -(v[self._f_pos] @ self.C[self._f_js]) if self._f_js else np.zeros(self.eps.size)
        if self._alpha_pos is not None:
            full = full + v[self._alpha_pos]
        return full[self._r_rows]

    def _b_t(self) -> np.ndarray:
        return np.where(self._rows == self.eps.size, self.total, self.eps[np.minimum(self._rows, self.eps.size - 1)])

    def solve_basic(self) -> np.ndarray:
        return self._x_n

    def z_value(self) -> float:
        return float(self.solve_basic()[self.nonslack.index(("Z", -1))])

    def dual(self) -> np.ndarray:
        """y on the T rows (zero on R rows): the Z row of B⁻¹."""
        import scipy.linalg as sla
        e = np.zeros(len(self.nonslack))
        e[self.nonslack.index(("Z", -1))] = 1.0
        return sla.lu_solve(self._lu, e, trans=1, check_finite=False)

    def _price(self, y_t: np.ndarray, var) -> float:
        return -float(y_t @ self._column_rows(var, self._rows))

    def free_pair_prices(self, y_t):
        free = np.flatnonzero(~self.y_basic & ~self.f_basic)
        return [(self._price(y_t, (k, int(j))), (k, int(j))) for j in free for k in ("F", "Y")]

    def restricted_prices(self, y_t):
        n = self.eps.size
        elem = self._rows[self._rows < n]
        y_elem, y_load = y_t[self._rows < n], y_t[self._rows == n].sum()
        out = []
        f_cand = np.flatnonzero(~self.f_basic & self.y_basic)
        if f_cand.size:
            rc = y_elem @ self.C[np.ix_(elem, f_cand)] - y_load
            out += [(float(r), ("F", int(j))) for r, j in zip(rc, f_cand)]
        pos = {int(r): k for k, r in enumerate(self._rows)}
        out += [(-float(y_t[pos[int(j)]]), ("Y", int(j))) for j in np.flatnonzero(~self.y_basic & self.f_basic)]
        return out

    def direction(self, var):
        """B⁻¹a for the entering column: (d on non-slack basics, d on slack rows R)."""
        import scipy.linalg as sla
        d_n = sla.lu_solve(self._lu, self._column_rows(var, self._rows), check_finite=False)
        d_r = self._column_rows(var, self._r_rows) - self._apply_rn(d_n)
        return d_n, d_r, var

    def ratio_test(self, direction, prefer):
        """The leaving basic variable by the minimum ratio; ties go to ``prefer``, then to the first found."""
        d_n, d_r, _ = direction
        x_n, x_r = self._x_n, self._x_r
        cands = []
        scale = max(float(np.abs(d_n).max(initial=0.0)), float(np.abs(d_r).max(initial=0.0)), 1e-300)
        piv = 1e-11 * scale
        for k, var in enumerate(self.nonslack):
            if var[0] != "alpha" and d_n[k] > piv:
                cands.append((max(x_n[k], 0.0) / d_n[k], var))
        mask = d_r > piv
        if mask.any():
            ratios = np.clip(x_r[mask], 0.0, None) / d_r[mask]
            cands += [(float(r), ("Y", int(j))) for r, j in zip(ratios, self._r_rows[mask])]
        if not cands:
            return None
        best = min(c[0] for c in cands)
        ties = [v for r, v in cands if r <= best * (1 + 1e-12) + 1e-300]
        return prefer if prefer in ties else ties[0]

    def pivot(self, entering, leaving) -> None:
        n = self.eps.size
        kind, j = leaving
        if kind == "Y":
            self.y_basic[j] = False
            self.t_rows.insert(len(self.t_rows) - 1, j)
        else:
            self.nonslack.remove(leaving)
            if kind == "F":
                self.f_basic[j] = False
        kind, j = entering
        if kind == "Y":
            self.y_basic[j] = True
            self.t_rows.remove(j)
        else:
            self.nonslack.append(entering)
            if kind == "F":
                self.f_basic[j] = True
        assert len(self.t_rows) == len(self.nonslack) and self.t_rows[-1] == n
        self._factor()
