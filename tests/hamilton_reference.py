"""An independent reference for the sliding sphere: Hamilton's explicit stresses (G. M. Hamilton, "Explicit equations
for the stresses beneath a sliding spherical contact", Proc. IMechE C 197 (1983) 53–59), for the tractions

    p = p₀√(1 − r²/a²)  and  q_x = μp  on r ≤ a,   z > 0 into the body, tension positive, σzz = −p, σxz = −q_x at z = 0,

the conventions of :mod:`fretsim.fatigue.stresses3d` (q_x is the traction acting ON the half-space along +x, so the
counterface slides along +x over it and the contact's trailing edge is x = −a).  Nothing here uses the rectangles or
the FFT of stresses3d; the derivation is written out below.

1. Love's potentials (Johnson, Contact Mechanics §3.2).  With Ω = z·ln(ρ + z) − ρ (harmonic), the loads enter through
   H₁ = (1/2π)∫∫p·Ω dA and F₁ = (1/2π)∫∫q_x·Ω dA.  For q_x = μp both are the same function: F₁ = μH₁ = μΦ.
   Displacements (2G·u) from Johnson's (3.7)–(3.9), worked through by hand for each load (∇²Φ = 0 used to drop the
   horizontal Laplacian), give the stresses

     pressure, with χ = ∂Φ/∂z:          σxx = 2νχ_zz − (1 − 2ν)χ_xx − zχ_xxz     σxy = −(1 − 2ν)χ_xy − zχ_xyz
                                         σyy = 2νχ_zz − (1 − 2ν)χ_yy − zχ_yyz     σxz = −zχ_xzz
                                         σzz = χ_zz − zχ_zzz                      σyz = −zχ_yzz
     shear q_x, from Φ itself:           σxx = 2(1 + ν)Φ_xzz + 2νΦ_xxx − zΦ_xxxz   σxy = Φ_yzz + 2νΦ_xxy − zΦ_xxyz
                                         σyy = 2νΦ_xzz + 2νΦ_xyy − zΦ_xyyz         σxz = Φ_zzz − zΦ_xxzz
                                         σzz = −zΦ_xzzz                            σyz = −zΦ_xyzz

   (with Φ = Ω/2π, a unit point force, these are Boussinesq's and Cerruti's stresses: checked in the tests).
2. The Hertz pressure as a line of complex sources (Hamilton & Goodman 1966; Hamilton 1983 §2): for a function h
   harmonic in z > 0 and real for real arguments,
        ∫∫ p₀√(1 − r'²/a²) h(x − ξ, y − η, z) dA = (2πp₀/a)·Im ∫₀ᵃ t·k(x, y, z + it) dt,   ∂k/∂z = h,
   (each complex source z → z + it is Appell's disc of radius t; the weight t stacks the discs into the hemisphere;
   the constant is the total load (2/3)πa²p₀ in the far field).  Integrating by parts twice along ζ = z + it,
        Φ = (p₀/a)·Im W(q, z₁),   W = −ia·P₃ + P₄,   z₁ = z + ia,   q = x² + y²,
   with P₂, P₃, P₄ the successive ζ-primitives of Ω (found by polynomial ansatz, checked by differentiation):
        P₂ = (ζ²/2 − q/4)L − (3/4)ζR
        P₃ = (ζ³/6 − qζ/4)L + (q/9 − 11ζ²/36)R
        P₄ = (ζ⁴/24 − qζ²/8 + q²/64)L + (55qζ/576 − 25ζ³/288)R,      R = √(q + ζ²), L = ln(R + ζ)
   (the primitives' free functions of x, y drop out: they enter W as −ia·g + (z + ia)·g, whose Im is 0).
   At ζ = z₁ these are Hamilton's quantities: R = M + iN with M, N = √((S ± A)/2), A = r² + z² − a²,
   S = √(A² + 4a²z²), and Im ln(R + z₁) = atan((a + N)/(z + M)).  ∂W/∂ζ lowers the primitive by one
   (W_z = −iaP₂ + P₃, …, W_zzzz = −ia/R + L), and the horizontal derivatives go through q:
   ∂x f = 2x f_q, ∂xx f = 2f_q + 4x²f_qq, ∂xxx f = 12x f_qq + 8x³f_qqq, ∂xyy f = 4x f_qq + 8xy²f_qqq, etc.
   The q-derivatives are taken exactly by truncated Taylor series in q (``_Jet``), not by differences.
3. Hamilton's printed equations for the normal load (his eq. for σx, σy, σz, τxy, τyz, τzx in M, N, S, A, G, H, φ;
   recoded from the published form in ``hamilton_normal``) are the same numbers: a check on step 2's normalisation
   and branches.  His printed tangential equations were not available to this work; the tangential stresses here
   are step 2's closed form, checked (tests) against quadratures of Cerruti's point force and the trailing edge's
   p₀[(1 − 2ν)/3 + (4 + ν)πμ/8].

Singular only on the contact's rim at z = 0 (R = 0); on the axis everything is regular (no 1/r factors).
"""
from __future__ import annotations

import numpy as np

ORDER = 4  # Taylor coefficients in q kept: f, f_q, f_qq/2, f_qqq/6


class _Jet:
    """A truncated Taylor series in q (coefficients c[k] of δq^k, k < ORDER), complex arrays."""

    def __init__(self, c):
        self.c = list(c)

    @staticmethod
    def of(value, slope=0.0):
        v = np.asarray(value, complex)
        return _Jet([v, np.broadcast_to(np.asarray(slope, complex), v.shape)] + [np.zeros_like(v)] * (ORDER - 2))

    def __add__(self, o):
        o = o if isinstance(o, _Jet) else _Jet.of(o)
        return _Jet([a + b for a, b in zip(self.c, o.c)])

    __radd__ = __add__

    def __neg__(self):
        return _Jet([-a for a in self.c])

    def __sub__(self, o):
        return self + (-(o if isinstance(o, _Jet) else _Jet.of(o)))

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if not isinstance(o, _Jet):
            return _Jet([a * o for a in self.c])
        return _Jet([sum(self.c[i] * o.c[k - i] for i in range(k + 1)) for k in range(ORDER)])

    __rmul__ = __mul__

    def _compose(self, derivs):
        """f(self) from f's derivatives at c[0] (Faà di Bruno, truncated): Σ f⁽ⁿ⁾(c₀)·uⁿ/n!, u = self − c₀."""
        u = _Jet([np.zeros_like(self.c[0])] + self.c[1:])
        out, power, fact = _Jet.of(derivs[0]), _Jet.of(1.0 + 0 * self.c[0]), 1.0
        for n in range(1, ORDER):
            power, fact = power * u, fact * n
            out = out + power * (derivs[n] / fact)
        return out

    def sqrt(self):
        v = np.sqrt(self.c[0])
        return self._compose([v, 0.5 / v, -0.25 / v ** 3, 0.375 / v ** 5])

    def log(self):
        v = self.c[0]
        return self._compose([np.log(v), 1 / v, -1 / v ** 2, 2 / v ** 3])

    def inv(self):
        v = self.c[0]
        return self._compose([1 / v, -1 / v ** 2, 2 / v ** 3, -6 / v ** 4])

    def d(self, n):
        """The n-th q-derivative."""
        return self.c[n] * float(np.prod(range(1, n + 1)))


def _potentials(q, z, a):
    """W and its z-derivatives W_z … W_zzzz at z₁ = z + ia, as jets in q (step 2 of the module docstring)."""
    s = _Jet.of(z + 1j * a)
    qj = _Jet.of(q, 1.0)
    R = (qj + s * s).sqrt()  # principal branch: Re R = M ≥ 0, Im R = N ≥ 0 for z > 0
    L = (R + s).log()
    omega = s * L - R
    p2 = (s * s * 0.5 - qj * 0.25) * L - s * R * 0.75
    p3 = (s * s * s * (1 / 6) - qj * s * 0.25) * L + (qj * (1 / 9) - s * s * (11 / 36)) * R
    p4 = ((s * s * s * s) * (1 / 24) - qj * s * s * 0.125 + qj * qj * (1 / 64)) * L \
        + (qj * s * (55 / 576) - s * s * s * (25 / 288)) * R
    ia = 1j * a
    return [p4 - p3 * ia, p3 - p2 * ia, p2 - omega * ia, omega - L * ia, L - R.inv() * ia]


def hamilton_stresses(x, y, z, mu, nu, a=1.0, p0=1.0):
    """(σxx, σyy, σzz, σxy, σxz, σyz) at (x, y, z), z > 0, under p₀√(1 − r²/a²) and q_x = μp: shape (6, *shape)."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, z)))
    w = _potentials(x * x + y * y, z, a)
    im = lambda v: np.imag(v) * (p0 / a)  # noqa: E731  Φ = (p₀/a)·Im W

    def hor(f, kind):
        """Horizontal derivatives through q: 'xx', 'yy', 'xy', 'x', 'y', 'xxx', 'xyy', 'xxy'."""
        f1, f2, f3 = f.d(1), f.d(2), f.d(3)
        return {"x": 2 * x * f1, "y": 2 * y * f1, "xx": 2 * f1 + 4 * x * x * f2, "yy": 2 * f1 + 4 * y * y * f2,
                "xy": 4 * x * y * f2, "xxx": 12 * x * f2 + 8 * x ** 3 * f3, "xyy": 4 * x * f2 + 8 * x * y * y * f3,
                "xxy": 4 * y * f2 + 8 * x * x * y * f3}[kind]

    # pressure: χ = Φ_z, so χ's z-derivatives are w[2], w[3], w[4]
    chi_zz, chi_zzz = im(w[3].c[0]), im(w[4].c[0])
    c = 1 - 2 * nu
    normal = np.array([
        2 * nu * chi_zz - c * im(hor(w[1], "xx")) - z * im(hor(w[2], "xx")),
        2 * nu * chi_zz - c * im(hor(w[1], "yy")) - z * im(hor(w[2], "yy")),
        chi_zz - z * chi_zzz,
        -c * im(hor(w[1], "xy")) - z * im(hor(w[2], "xy")),
        -z * im(hor(w[3], "x")),
        -z * im(hor(w[3], "y"))])
    phi_xzz, phi_yzz = im(hor(w[2], "x")), im(hor(w[2], "y"))
    shear = np.array([
        2 * (1 + nu) * phi_xzz + 2 * nu * im(hor(w[0], "xxx")) - z * im(hor(w[1], "xxx")),
        2 * nu * phi_xzz + 2 * nu * im(hor(w[0], "xyy")) - z * im(hor(w[1], "xyy")),
        -z * im(hor(w[3], "x")),
        phi_yzz + 2 * nu * im(hor(w[0], "xxy")) - z * im(hor(w[1], "xxy")),
        im(w[3].c[0]) - z * im(hor(w[2], "xx")),
        -z * im(hor(w[2], "xy"))])
    return normal + mu * shear


def hamilton_normal(x, y, z, nu, a=1.0, p0=1.0):
    """Hamilton's (1983) printed equations for the normal load alone, in his real variables (r > 0, z > 0):
    A = r² + z² − a², S = √(A² + 4a²z²), M = √((S + A)/2), N = √((S − A)/2), φ = atan(a/M),
    G = M² − N² + zM − aN, H = 2MN + aM + zN; the prefactor 3P/(2πa³) = p₀/a.  Same order as above."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, z)))
    r2 = x * x + y * y
    A = r2 + z * z - a * a
    S = np.sqrt(A * A + 4 * a * a * z * z)
    M, N = np.sqrt((S + A) / 2), np.sqrt((S - A) / 2)
    phi = np.arctan(a / M)
    G, H = M * M - N * N + z * M - a * N, 2 * M * N + a * M + z * N
    k = p0 / a
    # the bracket shared by σx and σy, odd in the exchange x ↔ y through (y² − x²)/r²
    common = (1 - nu) * N * z * z - (1 - 2 * nu) / 3 * (N * S + 2 * A * N + a ** 3) - nu * M * z * a
    sxx = k * ((1 + nu) * z * phi + ((y * y - x * x) / r2 * common - N * (x * x + 2 * nu * y * y)
                                      - M * x * x * z * a / S) / r2)
    syy = k * ((1 + nu) * z * phi + ((x * x - y * y) / r2 * common - N * (y * y + 2 * nu * x * x)
                                      - M * y * y * z * a / S) / r2)
    szz = k * (-N + a * z * M / S)
    sxy = k * (x * y * (1 - 2 * nu) / r2 ** 2 * (-N * r2 + 2 / 3 * N * (S + 2 * A) - z * (z * N + a * M)
                                                 + 2 / 3 * a ** 3)
               + x * y * z / r2 ** 2 * (-a * M * r2 / S - z * N + a * M))
    hg = z * H / (G * G + H * H)
    sxz = -k * z * (x * N / S - x * hg)
    syz = -k * z * (y * N / S - y * hg)
    return np.array([sxx, syy, szz, sxy, sxz, syz])
