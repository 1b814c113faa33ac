"""Fretting fatigue's building blocks (issue 34): the stresses under the contact against closed forms derived
independently of the strip integrals, and the SWT critical plane and its life against their definitions."""
import math

import numpy as np
import pytest
from scipy import integrate

from fretsim.fatigue.stresses import strip_stresses
from fretsim.fatigue.swt import Basquin, ruiz, swt_2d

A, P0 = 1.0, 1.0  # the Hertz half-width and peak pressure: the results scale with them
N = 2001  # elements over the contact: the discretisation error of a semi-ellipse is ~1/N^1.5 at the centre


def _hertz(n: int = N, extent: float = 1.0):
    dx = 2 * extent * A / n
    x = (np.arange(n) - (n - 1) / 2) * dx
    return x, dx, P0 * np.sqrt(np.clip(1 - (x / A) ** 2, 0, None))


def test_hertz_line_contact_has_its_largest_shear_0_300_p0_at_0_786_a_and_minus_p0_at_the_surface():
    """Johnson, Contact Mechanics §4.2 (frictionless cylinder): the principal shear stress below the centre peaks at
    0.300 p₀ at z = 0.786 a; at the surface σx = σz = −p₀ (tolerances: the table's three digits)."""
    x, dx, p = _hertz()
    z = np.linspace(0.6, 1.0, 401) * A
    s = strip_stresses(x, dx, p, np.zeros_like(p), np.array([0.0]), z)
    shear = s.max_shear()[:, 0]
    k = int(np.argmax(shear))
    assert shear[k] == pytest.approx(0.300 * P0, abs=0.0006)
    assert z[k] == pytest.approx(0.786 * A, abs=0.002)
    top = strip_stresses(x, dx, p, np.zeros_like(p), np.array([0.0]), np.array([1e-5 * A]))
    assert top.szz[0, 0] == pytest.approx(-P0, rel=1e-3) and top.sxx[0, 0] == pytest.approx(-P0, rel=1e-3)


def test_a_sliding_cylinder_pulls_the_surface_to_2_mu_p0_at_its_trailing_edge():
    """Smith & Liu (1953), Johnson §7.1: full sliding, q = μp along +x.  The surface σx is −p₀(√(1 − x²/a²) + 2μx/a)
    under the contact and −2μp₀(x/a ∓ √(x²/a² − 1)) outside it (the Hilbert transform of the semi-ellipse): the
    largest tension, +2μp₀, at the trailing edge x = −a.  Away from the edges, where the semi-ellipse's √ slope
    is resolved, within 0.2 % of p₀."""
    mu = 0.3
    x, dx, p = _hertz(extent=1.5)
    points = np.array([-1.4, -1.1, -0.9, -0.5, 0.0, 0.5, 0.9, 1.1, 1.4]) * A
    s = strip_stresses(x, dx, p, mu * p, points, np.array([1e-6 * A]))
    t = points / A
    inside = np.abs(t) <= 1
    exact = np.where(inside, -P0 * (np.sqrt(np.clip(1 - t * t, 0, None)) + 2 * mu * t),
                     -2 * mu * P0 * (t - np.sign(t) * np.sqrt(np.clip(t * t - 1, 0, None))))
    np.testing.assert_allclose(s.sxx[0], exact, atol=2e-3 * P0)
    # at the edge itself the semi-ellipse's √ is resolved as √dx: the gap to 2μp₀ halves for elements 4× smaller
    gaps = []
    for n in (1001, 4001):
        x, dx, p = _hertz(n, extent=1.5)
        gaps.append(2 * mu * P0 - strip_stresses(x, dx, p, mu * p, np.array([-A]), np.array([1e-7 * A])).sxx[0, 0])
    assert 0 < gaps[0] < 0.02 * 2 * mu * P0 and gaps[0] / gaps[1] == pytest.approx(2.0, rel=0.05)


@pytest.mark.parametrize("x, z", [(0.3, 0.2), (-0.7, 0.05), (1.5, 0.8), (0.0, 2.0)])
def test_the_strip_closed_forms_equal_a_quadrature_of_the_line_loads(x, z):
    """One strip [−0.5, 0.4] with p = 1 and q = 0.7: the closed forms against scipy's quadrature of Flamant's normal
    and Cerruti's shear line loads (σx, σz, τxz = −(2/π)·(u²z, z³, uz²)/r⁴·p and −(2/π)·(u³, uz², u²z)/r⁴·q)."""
    lo, hi, p, q = -0.5, 0.4, 1.0, 0.7

    def quad(f):
        return integrate.quad(lambda xi: f(x - xi), lo, hi, epsabs=1e-13, epsrel=1e-12, limit=200)[0]

    r4 = lambda u: (u * u + z * z) ** 2  # noqa: E731
    k = -2 / math.pi
    sxx = k * (p * quad(lambda u: u * u * z / r4(u)) + q * quad(lambda u: u ** 3 / r4(u)))
    szz = k * (p * quad(lambda u: z ** 3 / r4(u)) + q * quad(lambda u: u * z * z / r4(u)))
    sxz = k * (p * quad(lambda u: u * z * z / r4(u)) + q * quad(lambda u: u * u * z / r4(u)))
    s = strip_stresses(np.array([(lo + hi) / 2]), hi - lo, np.array([p]), np.array([q]), np.array([x]),
                       np.array([z]))
    np.testing.assert_allclose([s.sxx[0, 0], s.szz[0, 0], s.sxz[0, 0]], [sxx, szz, sxz], rtol=1e-9, atol=1e-12)


def test_swt_of_a_uniaxial_cycle_is_the_uniaxial_formula_on_the_plane_normal_to_the_load():
    """σx alternating ±σa alone: SWT = σ_max·ε_a on the plane normal to x.  In plane strain ε_x = (1 − ν²)σx/E;
    with ν = 0 that is the uniaxial σa²/E."""
    sa, e = 300.0, 200e3
    cycle = (np.array([[sa], [-sa]]), np.zeros((2, 1)), np.zeros((2, 1)))
    for nu in (0.0, 0.3):
        plane = swt_2d(cycle, e, nu)
        assert plane.swt[0] == pytest.approx(sa * sa * (1 - nu * nu) / e, rel=1e-12)
        assert plane.angle[0] == pytest.approx(0.0)


def test_the_critical_plane_of_pure_shear_is_at_45_degrees():
    """τxz alternating ±τa: the normal stress peaks at τa on the planes at ±45°, where ε_n = γ/2 = (1 + ν)τ/E."""
    ta, e, nu = 200.0, 200e3, 0.3
    plane = swt_2d((np.zeros((2, 1)), np.zeros((2, 1)), np.array([[ta], [-ta]])), e, nu)
    assert plane.swt[0] == pytest.approx(ta * ta * (1 + nu) / e, rel=1e-12)
    assert min(abs(plane.angle[0] - math.pi / 4), abs(plane.angle[0] - 3 * math.pi / 4)) < 1e-12


def test_the_life_inverts_the_basquin_coffin_manson_curve_and_is_infinite_below_the_endurance_limit():
    steel = Basquin(strength_coefficient=1817.0, strength_exponent=-0.103, ductility_coefficient=0.77,
                    ductility_exponent=-0.58, youngs_modulus=200e3, endurance_limit=0.05)  # a 4340-like steel
    for cycles in (10.0, 1e3, 1e5, 1e7, 1e9):
        assert steel.life(steel.swt(cycles)) == pytest.approx(cycles, rel=1e-9)
    assert steel.life(0.04) == math.inf and steel.life(0.0) == math.inf
    assert steel.life(2 * steel.swt(1e4)) < 1e4  # more damage, shorter life


def test_ruiz_counts_only_tension():
    assert ruiz(np.array([200.0, -100.0]), np.array([-50.0, 50.0]), np.array([0.01, 0.01])).tolist() == [100.0, 0.0]
