"""Where the rectangle's corner functions in :mod:`fretsim.fatigue.stresses3d` come from, redone with sympy (an
optional tool, never a dependency of fretsim).

1. The point loads: Johnson's potentials (Contact Mechanics §3.2) with H₁ = Ω (a normal force pressing in) and
   F₁ = Ω (a tangential force along +x), Ω = z·ln(ρ + z) − ρ, give the displacements; Hooke's law the stresses.
   Checked: equilibrium, a free surface away from the force, and the resultant on a plane below it.
2. Each stress is Σ c·z^m·∂X^i ∂Y^j ∂z^k Ω.  A rectangle's is Σ_corners ±F with ∂X∂Y F = the kernel: for i, j ≥ 1
   F is a lower derivative of Ω; otherwise ∇²Ω = 0 trades ∂X² for −∂Y² − ∂z² until one of a few base primitives
   is reached (ln(Y + ρ), atan forms).  The script prints each component's point-load combination.
3. The module's coded corner functions, summed over a rectangle's corners, against the same sums of the sympy
   expressions at random points (they agree to round-off).

    python scripts/derive_stresses3d.py
"""
from __future__ import annotations

import sys
from collections import defaultdict

from _study import have_comparator

import numpy as np  # noqa: E402

NU_VALUE = 0.3


def _fields(sp):
    """Displacements of the two point loads as {(m, i, j, k): coefficient} of z^m·∂X^i ∂Y^j ∂z^k Ω."""
    nu = sp.Symbol("nu")

    def d(f, axis):
        out = defaultdict(lambda: 0)
        for (m, i, j, k), c in f.items():
            key = {"x": (m, i + 1, j, k), "y": (m, i, j + 1, k), "z": (m, i, j, k + 1)}[axis]
            out[key] += c
            if axis == "z" and m:
                out[(m - 1, i, j, k)] += m * c
        return dict(out)

    def add(*terms):
        out = defaultdict(lambda: 0)
        for s, f in terms:
            for key, c in f.items():
                out[key] += s * c
        return {k: sp.simplify(v) for k, v in out.items() if sp.simplify(v) != 0}

    def times_z(f):
        return {(m + 1, i, j, k): c for (m, i, j, k), c in f.items()}

    omega, c = {(0, 0, 0, 0): 1}, 1 / (4 * sp.pi)  # shear modulus 1
    psi1 = d(omega, "z")
    v1 = d(psi1, "z")
    normal = [add((-c * (1 - 2 * nu), d(psi1, a)), (-c, times_z(d(v1, a)))) for a in "xy"]
    normal.append(add((2 * c * (1 - nu), v1), (-c, times_z(d(v1, "z")))))
    f, ps1 = d(omega, "z"), d(omega, "x")
    ps = d(ps1, "z")
    shear = [add((2 * c, d(f, "z")), (2 * nu * c, d(ps1, "x")), (-c, times_z(d(ps, "x")))),
             add((2 * nu * c, d(ps1, "y")), (-c, times_z(d(ps, "y")))),
             add((c * (1 - 2 * nu), ps), (-c, times_z(d(ps, "z"))))]
    return nu, d, add, normal, shear


def _stresses(sp, nu, d, add, u):
    pairs = {"sxx": (0, 0), "syy": (1, 1), "szz": (2, 2), "sxy": (0, 1), "sxz": (0, 2), "syz": (1, 2)}
    strain = [[add((sp.Rational(1, 2), d(u[i], "xyz"[j])), (sp.Rational(1, 2), d(u[j], "xyz"[i])))
               for j in range(3)] for i in range(3)]
    trace = add((1, strain[0][0]), (1, strain[1][1]), (1, strain[2][2]))
    lam = 2 * nu / (1 - 2 * nu)
    return {name: add((lam if i == j else 0, trace), (2, strain[i][j])) for name, (i, j) in pairs.items()}


def _primitive(sp, X, Y, z, i, j, k):
    """F with ∂X∂Y F = ∂X^i ∂Y^j ∂z^k Ω, up to functions of X alone or Y alone."""
    rho = sp.sqrt(X ** 2 + Y ** 2 + z ** 2)
    omega = z * sp.log(rho + z) - rho
    if i >= 1 and j >= 1:
        return sp.diff(omega, X, i - 1, Y, j - 1, z, k) if (i - 1 or j - 1 or k) else omega
    if j == 0 and i >= 3:
        return -_primitive(sp, X, Y, z, i - 2, 2, k) - _primitive(sp, X, Y, z, i - 2, 0, k + 2)
    if i == 0 and j >= 3:
        return -_primitive(sp, X, Y, z, 2, j - 2, k) - _primitive(sp, X, Y, z, 0, j - 2, k + 2)
    if j == 0 and i in (1, 2) and k >= 2:
        return sp.diff(sp.log(Y + rho), X, i - 1, z, k - 2) if (i - 1 or k - 2) else sp.log(Y + rho)
    if i == 0 and j in (1, 2) and k >= 2:
        return sp.diff(sp.log(X + rho), Y, j - 1, z, k - 2) if (j - 1 or k - 2) else sp.log(X + rho)
    if (i, j, k) == (2, 0, 1):
        return sp.atan(X * Y * (rho - z) / (X ** 2 * rho + Y ** 2 * z))
    if (i, j, k) == (0, 2, 1):
        return sp.atan(X * Y * (rho - z) / (Y ** 2 * rho + X ** 2 * z))
    if i == 0 and j == 0 and k >= 3:
        return sp.diff(-sp.atan(X * Y / (z * rho)), z, k - 3) if k - 3 else -sp.atan(X * Y / (z * rho))
    raise ValueError(f"no primitive for {(i, j, k)}")


def _check_point_loads(sp, nu, fields) -> None:
    X, Y, z = sp.symbols("X Y z", real=True)
    rho = sp.sqrt(X ** 2 + Y ** 2 + z ** 2)
    omega = z * sp.log(rho + z) - rho
    var = (X, Y, z)
    for name, stress in fields.items():
        s = {k: sum(c * z ** m * (sp.diff(omega, X, i, Y, j, z, k_) if (i or j or k_) else omega)
                    for (m, i, j, k_), c in f.items()) for k, f in stress.items()}
        tensor = [[s["sxx"], s["sxy"], s["sxz"]], [s["sxy"], s["syy"], s["syz"]], [s["sxz"], s["syz"], s["szz"]]]
        at = {X: 0.37, Y: -0.52, z: 0.81, nu: NU_VALUE}
        div = [float(sum(sp.diff(tensor[i][j], var[j]) for j in range(3)).subs(at)) for i in range(3)]
        top = [float(tensor[2][j].subs({X: 0.37, Y: -0.52, z: 1e-9, nu: NU_VALUE})) for j in range(3)]
        print(f"{name}: div σ = {np.round(div, 14)}, surface traction off the force = {np.round(top, 8)}")


def main() -> None:
    if not have_comparator("sympy", "pip install sympy"):
        sys.exit(1)
    import sympy as sp
    nu, d, add, normal, shear = _fields(sp)
    fields = {"pressure": _stresses(sp, nu, d, add, normal), "q_x": _stresses(sp, nu, d, add, shear)}
    _check_point_loads(sp, nu, fields)
    X, Y, z = sp.symbols("X Y z", real=True)
    corner = {}
    for load, stress in fields.items():
        for comp, f in stress.items():
            corner[(load, comp)] = sum(c * z ** m * _primitive(sp, X, Y, z, i, j, k) for (m, i, j, k), c in f.items())
            terms = ", ".join(f"{sp.factor(c)}·z^{m}·∂X^{i}∂Y^{j}∂z^{k}Ω" for (m, i, j, k), c in f.items())
            print(f"{load} {comp}: {terms}")
    _compare_with_module(sp, nu, X, Y, z, corner)


def _compare_with_module(sp, nu, X, Y, z, corner) -> None:
    from fretsim.fatigue.stresses3d import COMPONENTS, rectangle_stresses
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(5):
        x, y, depth = rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(0.05, 2)
        a, b = rng.uniform(0.1, 1), rng.uniform(0.1, 1)
        coded = rectangle_stresses(np.array(x), np.array(y), depth, a, b, NU_VALUE)
        for li, load in enumerate(("pressure", "q_x")):
            for ci, comp in enumerate(COMPONENTS):
                f = sp.lambdify((X, Y, z, nu), corner[(load, comp)])
                total = sum(s * f(x + sx, y + sy, depth, NU_VALUE)
                            for sx, sy, s in ((a, b, 1), (a, -b, -1), (-a, b, -1), (-a, -b, 1)))
                worst = max(worst, abs(total - coded[li, ci]))
    print(f"largest difference, module against the derivation, over 5 random rectangles: {worst:.2e}")


if __name__ == "__main__":
    main()
