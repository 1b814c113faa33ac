"""Partial slip (issue 34): the Cattaneo–Mindlin cylinder's stresses from ``strip_stresses`` against a closed form of
the surface stress and against a quadrature of the line loads, both derived here and not from the strip integrals.

The closed form.  A normal load P and a tangential force Q < μP on a Hertz line contact of half-width a and peak
pressure p₀ (P = πap₀/2).  Mindlin's traction on the half-space, along +x (the sign ``strip_stresses`` takes), is
the full-sliding μp minus a corrective over the stick zone |x| < c:

    q(x) = (μp₀/a)·√(a² − x²) − (μp₀/a)·√(c² − x²)·[|x| < c],   ∫q = μP(1 − c²/a²) = Q,  so  c = a·√(1 − Q/μP).

A unit line load along +x at ξ (Cerruti, 2D) is a radial field σr = −(2/π)·cos φ/r, φ measured from +x: ahead of
it the surface is compressed, σx(x, 0) = −(2/π)/(x − ξ).  So the surface σx of a shear traction q is
−(2/π)·PV∫ q(ξ)/(x − ξ) dξ, and with PV∫_{−b}^{b} √(b² − ξ²)/(x − ξ) dξ = π·(x − sgn(x)·√(x² − b²)·[|x| > b]),

    σx,shear(x) = −2μp₀·h(x, a) + 2μp₀·h(x, c),   h(x, b) = (x − sgn(x)·√(x² − b²)·[|x| > b]) / a.

The normal pressure adds σx = −p(x) at the surface (a Flamant load's σx is a delta of the same weight there).  The
linear parts x/a cancel between the two shear terms, which leaves

    stick zone  |x| ≤ c:      σx/p₀ = −√(1 − x²/a²)
    slip zones  c < |x| ≤ a:  σx/p₀ = −√(1 − x²/a²) − 2μ·sgn(x)·√(x² − c²)/a
    outside     |x| > a:      σx/p₀ = −2μ·sgn(x)·(√(x² − c²) − √(x² − a²))/a

(Hills & Nowell 1994, Johnson §7.2 in other words).  At c = 0 it is Smith & Liu's sliding cylinder; the stick zone
carries no shear-induced σx at all.  The largest tension is at the trailing edge x = −a (the slip zone's term grows
to it, the outside term falls from it): σx = 2μp₀·√(1 − c²/a²) = 2μp₀·√(Q/μP).  At the leading edge +a it is the
same in compression.  Reversing Q reverses the shear part: the peak moves to +a.
"""
import math

import numpy as np
import pytest
from scipy import integrate

from fretsim.fatigue.stresses import strip_stresses

A, P0 = 0.4, 700.0  # a half-width (mm) and a peak pressure (MPa) of a cylinder-on-flat test: the results scale
MU, LOAD_RATIO = 0.6, 0.6  # μ and Q/μP: a stick zone c = 0.632 a, slip zones 0.37 a wide, room between the edges
C = A * math.sqrt(1 - LOAD_RATIO)
PER_A = 1500  # elements per half-width: a, c's neighbours and the test points fall on element centres
EXTENT = 1.5  # the grid spans ±1.5 a: 4501 elements, the tractions nonzero on the middle two thirds


def _grid(per_a: int = PER_A, direction: float = 1.0):
    """Element centres k·dx (so ±a and the test points are centres), the Hertz pressure and Mindlin's shear at
    them; ``direction`` −1 reverses Q."""
    dx = A / per_a
    k = round(EXTENT * per_a)
    x = np.arange(-k, k + 1) * dx
    p = P0 * np.sqrt(np.clip(1 - (x / A) ** 2, 0, None))
    q = direction * MU * P0 / A * (np.sqrt(np.clip(A * A - x * x, 0, None)) - np.sqrt(np.clip(C * C - x * x, 0, None)))
    return x, dx, p, q


def _closed_form(x: np.ndarray, direction: float = 1.0) -> np.ndarray:
    """The surface σx of the module docstring, zone by zone (normal part plus ``direction`` × shear part)."""
    x = np.asarray(x, float)
    ax, s = np.abs(x), np.sign(x)
    normal = -P0 * np.sqrt(np.clip(1 - (x / A) ** 2, 0, None))
    root_c, root_a = np.sqrt(np.clip(x * x - C * C, 0, None)), np.sqrt(np.clip(x * x - A * A, 0, None))
    slip = -2 * MU * P0 * s * root_c / A
    outside = -2 * MU * P0 * s * (root_c - root_a) / A
    shear = np.where(ax <= C, 0.0, np.where(ax <= A, slip, outside))
    return normal + direction * shear


def test_the_mindlin_traction_carries_q_and_sticks_where_it_is_below_mu_p():
    """The premise of the closed form: the traction integrates to Q = μP(1 − c²/a²) (P = πap₀/2), is below μp in
    the stick zone and equals μp in the slip zones.  Tolerance 1e-4 of Q: the midpoint rule on the √ edges
    (error ~ (dx/a)^1.5 = 2e-5 here)."""
    x, dx, p, q = _grid()
    load = math.pi * A * P0 / 2
    assert q.sum() * dx == pytest.approx(MU * load * LOAD_RATIO, rel=1e-4)
    stick, slip = np.abs(x) < C, (np.abs(x) > C) & (np.abs(x) <= A)
    assert (q[stick] < MU * p[stick]).all()
    np.testing.assert_allclose(q[slip], MU * p[slip], rtol=1e-12)


def test_the_surface_tractions_come_back_as_minus_sigma_zz_and_minus_tau_xz():
    """The sign the closed form rests on: with q along +x on this body and the outward normal −z, the surface
    carries σz = −p and τxz = −q.  At element centres, at a depth 1e-5 of an element, the strips return their own
    tractions to 1e-4 of p₀ (the neighbours' share ~ depth/dx)."""
    x, dx, p, q = _grid()
    pts = np.array([-0.9, -0.5, 0.0, 0.3, 0.8]) * A
    s = strip_stresses(x, dx, p, q, pts, np.array([1e-5 * dx]))
    exact_p = P0 * np.sqrt(1 - (pts / A) ** 2)
    exact_q = MU * P0 / A * (np.sqrt(A * A - pts ** 2) - np.sqrt(np.clip(C * C - pts ** 2, 0, None)))
    np.testing.assert_allclose(s.szz[0], -exact_p, atol=1e-4 * P0)
    np.testing.assert_allclose(s.sxz[0], -exact_q, atol=1e-4 * P0)


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_the_surface_stress_of_partial_slip_is_the_closed_form_in_stick_slip_and_outside(direction):
    """Points in the stick zone, both slip zones and outside on both sides, each at least 0.05 a from the √ edges
    (±c, ±a) where a piecewise-constant traction resolves the √ only as √dx.  Within 1e-3 of p₀: the staircase
    of shear traction is first order in dx at the surface (its own element adds ~(2/π)·q'·dx, ≤ 8e-4 p₀ at 0.05 a
    from the edges with dx = a/1500; measured ≤ 5e-4 p₀, halving with dx); reversing the shear part moves σx by
    up to 1.7 p₀ at these points."""
    x, dx, p, q = _grid(direction=direction)
    stick = np.array([-0.55, -0.3, 0.0, 0.2, 0.55])
    slip = np.array([-0.95, -0.8, -0.7, 0.7, 0.85, 0.95])
    outside = np.array([-2.0, -1.3, -1.05, 1.05, 1.2, 1.45])
    pts = np.concatenate([stick, slip, outside]) * A
    # 1e-7 dx deep: the surface, for the strips' atan/log forms (they need z > 0)
    s = strip_stresses(x, dx, p, q, pts, np.array([1e-7 * dx]))
    np.testing.assert_allclose(s.sxx[0], _closed_form(pts, direction), atol=1e-3 * P0)


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_the_peak_tension_is_2_mu_p0_root_q_over_mu_p_at_the_trailing_edge(direction):
    """The closed form peaks at the trailing edge (−a for Q along +x) at 2μp₀√(Q/μP).  The discretised surface σx,
    sampled at every element centre, peaks at that edge; its value there converges as √dx (the semi-ellipse's √
    edge in one element), so the gap halves for elements 4× smaller and the Richardson value 2·s(dx/4) − s(dx)
    is the limit to 1e-3 of the peak (the next term of the expansion, ~dx)."""
    peak = 2 * MU * P0 * math.sqrt(LOAD_RATIO)
    trailing = -direction * A
    dense = np.union1d(np.linspace(-3 * A, 3 * A, 600001), [-A, A])  # the edges themselves
    exact = _closed_form(dense, direction)
    assert exact.max() == pytest.approx(peak, rel=1e-12)
    assert dense[np.argmax(exact)] == pytest.approx(trailing, abs=1e-5 * A)
    values = []
    for per_a in (500, 2000):
        x, dx, p, q = _grid(per_a, direction)
        if per_a == 500:  # every centre on the coarser grid (the finer one would cost a 6001² matrix)
            sxx = strip_stresses(x, dx, p, q, x, np.array([1e-7 * dx])).sxx[0]
            assert x[np.argmax(sxx)] == pytest.approx(trailing, abs=1.5 * dx)
        values.append(strip_stresses(x, dx, p, q, np.array([trailing]), np.array([1e-7 * dx])).sxx[0, 0])
    assert 0 < peak - values[0] < 0.05 * peak and (peak - values[0]) / (peak - values[1]) == pytest.approx(2, rel=0.05)
    assert 2 * values[1] - values[0] == pytest.approx(peak, rel=1e-3)


def _line_load_quadrature(x: float, z: float, direction: float = 1.0) -> tuple:
    """σx, σz, τxz at (x, z) by quadrature of the line loads, derived from the radial fields: a normal (compressive)
    unit load at ξ gives σr = −(2/π)·cos θ/r with θ from the inward normal +z, a tangential unit load along +x gives
    σr = −(2/π)·cos φ/r with φ from +x; a radial field is σij = σr·nᵢnⱼ with n = (u, z)/r, u = x − ξ."""
    def pressure(xi):
        return P0 * math.sqrt(max(1 - (xi / A) ** 2, 0.0))

    def shear(xi):
        return direction * MU * P0 / A * (math.sqrt(max(A * A - xi * xi, 0.0)) - math.sqrt(max(C * C - xi * xi, 0.0)))

    def radial(xi):
        u = x - xi
        r = math.hypot(u, z)
        nx, nz = u / r, z / r
        sr = -2 / math.pi * (pressure(xi) * nz + shear(xi) * nx) / r
        return sr * nx * nx, sr * nz * nz, sr * nx * nz

    breaks = sorted({-C, C, min(max(x, -A), A)})  # the √ edges and the point above which the kernels peak
    return tuple(integrate.quad(lambda xi, k=k: radial(xi)[k], -A, A, points=breaks, epsabs=1e-10 * P0,
                                epsrel=1e-10, limit=400)[0] for k in range(3))


@pytest.mark.parametrize("x, z", [(-1.0, 0.1), (-0.8, 0.3), (0.0, 0.5), (0.7, 0.05), (1.3, 0.4), (-0.2, 1.5)])
def test_the_subsurface_field_of_partial_slip_equals_a_quadrature_of_flamant_and_cerruti(x, z):
    """Below the trailing edge, in the slip and stick zones, outside and deep: σx, σz, τxz against the quadrature.
    Within 2e-4 of p₀: seen from a depth ≥ 0.05 a the staircase's first-order sawtooth averages out (~dx²/z) and
    the √ edges leave ~(dx/a)^1.5 = 2e-5 p₀ (measured ≤ 3.2e-5 p₀, below the trailing edge); reversing the shear
    traction moves these by 0.05 p₀ (deepest) to 0.96 p₀ (below the trailing edge)."""
    x, z = x * A, z * A
    grid_x, dx, p, q = _grid()
    s = strip_stresses(grid_x, dx, p, q, np.array([x]), np.array([z]))
    np.testing.assert_allclose([s.sxx[0, 0], s.szz[0, 0], s.sxz[0, 0]], _line_load_quadrature(x, z), atol=2e-4 * P0)
