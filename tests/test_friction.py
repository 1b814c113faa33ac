"""Coulomb friction through the fretting cycle against Mindlin's closed forms, the invariants, and the models it
reduces to.

Tolerances, with their reasons:
* SOLVER (1e-8): two routes to one discrete solution (the tangential solver against a dense QP).
* FORCE (1e-3 at 32 elements across, shrinking with the grid): Q(δ) of a discretised Hertz contact; its error
  is the pressure's (second order in the element size).
* ENERGY (3e-2 at 32 across, 1e-3 at 64 for the ball; 3e-3 at 128–256 for the cylinder): the loop's dissipated
  energy; small loops are a difference of nearly equal terms (W ∝ Q*³), so their error is amplified at coarse
  grids.
* STICK: the stick zone is resolved to an element (its edge falls between element centres): |c − c_exact| ≤ dx.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from conftest import check_archard
from fretsim.compliance import HalfSpace, add
from fretsim.compliance.tangential import Tangential, cerruti_rectangle, datum_distance
from fretsim.cycle import CoulombCycle, UniformCycle
from fretsim.wear_laws import WEAR_LAWS
from fretsim.grid import Grid
from fretsim.reference import effective_modulus, mindlin as M
from fretsim.solvers import solve
from fretsim.solvers.tangential import solve_tangential
from fretsim.wear import wear_operator

E, NU = 200e3, 0.3
BODIES = [(E, NU), (E, NU)]
E_STAR = effective_modulus(E, NU, E, NU)


def ball_contact(n: int, load=185.0, radius=6.0, extent=3.0):
    """A ball's unworn contact on an n × n grid spanning ``extent`` Hertz radii: grid, operators, a ``normal``."""
    a = (3 * load * radius / (4 * E_STAR)) ** (1 / 3)
    dx = extent * a / n
    grid = Grid.centred(n, n, dx, dx)
    c = HalfSpace(grid, E_STAR)
    x, y = grid.mesh()
    gap = (x**2 + y**2) / (2 * radius)

    def normal(seen, guess, extra=None, load=load, cycle=0):
        res = solve(c if extra is None else add(c, extra), gap + seen, load, p0=guess, tol=1e-12)
        return res.pressure, res

    return grid, c, Tangential(grid, BODIES), normal, a


def cylinder_contact(n: int, load_per_length=18.5, radius=6.0, length=10.0, extent=3.0):
    a = math.sqrt(4 * load_per_length * radius / (math.pi * E_STAR))
    dx = extent * a / n
    grid = Grid.centred(n, 1, dx, 1.0, plane_strain=True)
    c = HalfSpace(grid, E_STAR)
    gap = grid.x[None, :] ** 2 / (2 * radius)

    def normal(seen, guess, extra=None, load=load_per_length, cycle=0):
        res = solve(c, gap + seen, load, p0=guess, tol=1e-12)
        return res.pressure, res

    return grid, c, Tangential(grid, BODIES, line_length=length), normal, a


def fretting_cycle(grid, c, k, stroke, load, mu, volume_factor=1.0, **kw):
    return CoulombCycle(grid, c, k, stroke, load, load * volume_factor, mu, 2e-8, 3e-8,
                        volume_factor=volume_factor, **kw)


# under pytest-xdist the module runs on one worker: its tests share the per-cycle runs of its module fixtures (the
# partial-slip one is 3000 Coulomb cycles), which each worker would otherwise run again
pytestmark = pytest.mark.xdist_group("test_friction")


# --- the tangential operator and solver -------------------------------------------------------------------------

def test_cerruti_rectangle_matches_a_quadrature_of_the_point_force_solution():
    """Outside the rectangle a plain double quadrature; inside, polar coordinates about the point, where the
    integrand times r is (1 + ν)/(πE)·[(1 − ν) + ν cos²θ] and only the distance to the edge R(θ) remains."""
    from scipy.integrate import dblquad, quad
    a, b = 0.5, 0.8
    for x, y in ((1.7, 0.4), (-4.0, 6.0), (0.6, 0.0)):
        def f(eta, xi):
            r = math.hypot(x - xi, y - eta)
            return (1 + NU) / (math.pi * E) * ((1 - NU) / r + NU * (x - xi) ** 2 / r**3)
        ref, _ = dblquad(f, -a, a, -b, b, epsabs=1e-14, epsrel=1e-10)
        assert cerruti_rectangle(x, y, a, b, E, NU) == pytest.approx(ref, rel=1e-7)
    for x, y in ((0.0, 0.0), (0.3, -0.2), (-0.45, 0.7)):
        def edge(t):  # distance from (x, y) to the rectangle's boundary along the direction t
            c, s_ = math.cos(t), math.sin(t)
            return min((a - x) / c if c > 0 else (-a - x) / c if c < 0 else math.inf,
                       (b - y) / s_ if s_ > 0 else (-b - y) / s_ if s_ < 0 else math.inf)
        corners = sorted(math.atan2(cy - y, cx - x) % (2 * math.pi) for cx in (-a, a) for cy in (-b, b))
        ref = quad(lambda t: (1 + NU) / (math.pi * E) * ((1 - NU) + NU * math.cos(t) ** 2) * edge(t), 0, 2 * math.pi,
                   points=corners, epsabs=1e-15, epsrel=1e-11, limit=200)[0]
        assert cerruti_rectangle(x, y, a, b, E, NU) == pytest.approx(ref, rel=1e-8)


def test_the_2d_datum_makes_a_line_load_move_as_the_3d_half_space_on_average():
    """The 2D datum (d = 2L·e^{ν/(1−ν)−1}) is derived from the 3D kernel averaged along the line; check that
    derivation numerically: the mean over y of the 3D displacement of a uniform line load of length L."""
    from scipy.integrate import quad
    length, x0 = 10.0, 0.02

    def u3(y):  # the 3D displacement at (x0, y) of a unit line load along [−L/2, L/2], one body
        f = lambda eta: (1 + NU) / (math.pi * E) * ((1 - NU) / math.hypot(x0, y - eta)  # noqa: E731
                                                    + NU * x0**2 / math.hypot(x0, y - eta) ** 3)
        return quad(f, -length / 2, length / 2, points=[y], limit=200)[0]

    mean3 = quad(u3, -length / 2, length / 2, limit=200)[0] / length
    u2 = 2 * (1 - NU**2) / (math.pi * E) * math.log(datum_distance(length, NU) / x0)
    assert mean3 == pytest.approx(u2, rel=2e-3)  # the closed form drops O(x0/L) terms: 2e-3 at x0/L = 2e-3


def test_tangential_solver_agrees_with_a_dense_bounded_least_squares_solution():
    grid, c, k, normal, a = ball_contact(20)
    p, _ = normal(np.zeros(grid.shape), None)
    rng = np.random.default_rng(1)
    q0 = np.clip(rng.normal(0, 20, grid.shape), -0.5 * p, 0.5 * p)
    rhs = k(q0) + 3e-4
    res = solve_tangential(k, rhs, 0.5 * p, q0, tol=1e-13)
    on = (p > 0).ravel()
    kd = k.dense()[np.ix_(on, on)]
    chol = np.linalg.cholesky(kd)  # ½qᵀKq − bᵀq = ½‖Lᵀq − L⁻¹b‖² + const
    ref = lsq_linear(chol.T, np.linalg.solve(chol, rhs.ravel()[on]), bounds=(-0.5 * p.ravel()[on], 0.5 * p.ravel()[on]),
                     tol=1e-14, lsmr_tol="auto", max_iter=10000)
    assert res.success, res.message
    assert np.abs(res.traction.ravel()[on] - ref.x).max() < 1e-6 * 0.5 * p.max()
    # the slip it reports is the increment's: zero where it sticks, along the traction where it slips
    slipping = ~res.stick & (p > 0)
    assert np.all(res.slip[res.stick] == 0)
    assert np.all(res.slip[slipping] * res.traction[slipping] >= 0)


@pytest.mark.parametrize("contact", ["ball", "cylinder"])
@pytest.mark.parametrize("factor", [0.4, 0.9, 1.5, 8.0])  # of the gross-slip stroke: partial slip to gross slip
def test_a_cycle_at_fixed_pressure_from_its_first_loading_is_the_cycle_solved_increment_by_increment(contact, factor):
    """masing() builds every increment of a cycle at fixed pressure from the first loading alone (Masing's rule):
    q_turn ∓ 2·q₀(o/2).  Against the tangential solver driven increment by increment round the same path (the
    recorded loop's, sides finely cut; and the unrecorded one, a half-stroke per increment): the same traction,
    travel and stick set after every increment, to the solver's tolerance.  A rule without the factor 2, or a
    half-stroke that did not start from its turning point's state, is off by the traction itself."""
    from fretsim.cycle.coulomb import gross_slip_stroke, increment_path, masing
    from fretsim.cycle.loop import elastic_side, loop_path
    grid, c, k, normal, a = ball_contact(24) if contact == "ball" else cylinder_contact(60)
    mu = 0.6
    p, _ = normal(np.zeros(grid.shape), None)
    stroke = factor * gross_slip_stroke(k, p, mu)
    member = fretting_cycle(grid, c, k, stroke, 185.0, mu)
    for path in (loop_path(stroke, elastic_side(k, mu, p), 12), increment_path(stroke, 1)):
        built = masing(member, p, path)
        q = np.zeros(grid.shape)
        for (u0, u1, _), (q_b, ds_b, stuck_b, _) in zip(path, built):
            q, ds, stuck, _ = member._tangential(q, p, u1 - u0)
            assert np.abs(q_b - q).max() < 1e-7 * mu * p.max()
            assert np.abs(ds_b - ds).max() < 1e-7 * stroke
            on = p > 0
            # the same stick set, but for ties: an element at the bound |q| = μp that moves by nothing (round-off)
            # both sticks and slides; the solver calls it stuck
            tie = (np.abs(np.abs(q) - mu * p) < 1e-9 * mu * p.max()) & (np.abs(ds) < 1e-12 * stroke)
            assert np.array_equal((stuck_b & on) | tie, (stuck & on) | tie)
        if factor < 1.0:  # partial slip: something stuck at the end of each half-stroke
            assert built[-1][2][p > 0].any()


def test_a_frictionless_cycle_at_fixed_pressure_slides_four_strokes_recorded_or_not():
    """μ = 0 (a block may set it under coulomb slip): the elastic side is of no width, so the recorded loop's side
    increments have none.  Each must move nothing: the recorded cycle slides every point 4δ and wears as the cycle
    taken a half-stroke at a time (k·p·4δ), with no energy.  (An increment of no width read as the other
    half-stroke's slid 6δ.)"""
    grid, c, k, normal, a = cylinder_contact(80)
    stroke = 0.025
    member = fretting_cycle(grid, c, k, stroke, 18.5, 0.0)
    zero = np.zeros(grid.shape)
    recorded, plain = (member.solve(zero, zero, normal, None, detail=d) for d in (True, False))
    p, on = recorded.pressure, recorded.pressure > 0
    np.testing.assert_allclose(recorded.slip_moving[on], 4 * stroke, rtol=1e-12)
    np.testing.assert_allclose(recorded.rate_moving, member.k_moving * 4 * stroke * p, rtol=1e-12, atol=0)
    for key in ("rate_moving", "rate_stationary", "slip_moving"):
        np.testing.assert_allclose(getattr(recorded, key), getattr(plain, key), rtol=1e-12, atol=0)
    assert recorded.energy == 0.0 and recorded.work == pytest.approx(plain.work, rel=1e-12)


@pytest.mark.parametrize("factor", [0.5, 1.2, 3.0])  # of 2δ_t after a reversal: partly stuck, just past, far past
def test_an_increment_that_slides_the_whole_contact_is_taken_without_a_solve_and_is_the_solvers_answer(factor):
    """_tangential takes q = ±μp without the solver where that leaves no point slipping against its traction (the
    minimum is unique, so it is the increment's solution).  Against the solver on the same increment, from the
    traction at the turning point: the same traction and travel where it slides; where part of the contact must
    stick (below 2δ_t) the candidate must be refused and the solver's stick zone returned."""
    grid, c, k, normal, a = ball_contact(24)
    mu = 0.6
    member = fretting_cycle(grid, c, k, 1e-3, 185.0, mu)
    p, _ = normal(np.zeros(grid.shape), None)
    q_turn = -mu * p  # the whole contact slid the other way up to the reversal
    du = factor * 2.0 * M.ball_gross_slip_displacement(mu, 185.0, a, BODIES)
    q, ds, stuck, its = member._tangential(q_turn, p, du)
    on = p > 0
    ref = solve_tangential(k, k(q_turn) + du, mu * p, q_turn, tol=1e-13)
    assert ref.success, ref.message
    assert np.abs(q - ref.traction).max() < 1e-8 * mu * p.max()
    assert np.abs(ds[on] - np.where(ref.stick, 0.0, ref.slip)[on]).max() < 1e-8 * du
    if factor < 1.0:
        assert ref.stick.any() and stuck.any() and its > 0
    elif not ref.stick.any():  # (just past 2δ_t the grid's last points may still hold: then the solver decides)
        assert its == 0 and not stuck.any() and np.array_equal(q, mu * p)
    if factor > 2.0:
        assert its == 0


# --- Mindlin: the ball (3D) -------------------------------------------------------------------------------------

@pytest.mark.parametrize("fraction", [0.3, 0.7])
def test_ball_partial_slip_loop_matches_mindlin_deresiewicz_and_converges(fraction):
    errors = []
    for n in (32, 64):
        grid, c, k, normal, a = ball_contact(n)
        mu = 0.6
        stroke = fraction * M.ball_gross_slip_displacement(mu, 185.0, a, BODIES)
        cyc = fretting_cycle(grid, c, k, stroke, 185.0, mu).solve(np.zeros(grid.shape), np.zeros(grid.shape),
                                                                  normal, None)
        q_star = M.ball_force(stroke, mu, 185.0, a, BODIES)
        assert cyc.regime == "partial_slip"
        assert abs(cyc.stick_half_width_x - M.ball_stick_radius(q_star, mu, 185.0) * a) <= grid.dx
        errors.append((abs(cyc.force_amplitude / q_star - 1),
                       abs(cyc.energy / M.ball_loop_energy(q_star, mu, 185.0, a, BODIES) - 1)))
        # the traction at the stroke's end: Cattaneo–Mindlin, to the pressure's discretisation
        r = np.hypot(*grid.mesh())
        assert np.abs(cyc.shear - M.ball_traction(r, q_star, mu, 185.0, a)).max() < 0.06 * mu * cyc.pressure.max()
    (f32, w32), (f64, w64) = errors
    assert f32 < 1e-3 and w32 < 3e-2
    assert f64 < 0.5 * f32 and w64 < 1e-3  # converging with the element size


def test_gross_slip_begins_at_mindlins_displacement():
    grid, c, k, normal, a = ball_contact(64)
    from fretsim.cycle.coulomb import gross_slip_stroke
    p, _ = normal(np.zeros(grid.shape), None)
    assert gross_slip_stroke(k, p, 0.6) == pytest.approx(M.ball_gross_slip_displacement(0.6, 185.0, a, BODIES),
                                                         rel=3e-3)  # the centre's displacement: the pressure's error


def test_above_the_transition_the_contact_slides_as_a_whole_and_dissipates_four_mu_p_delta_less_the_elastic_part():
    grid, c, k, normal, a = ball_contact(48)
    mu = 0.6
    d_t = M.ball_gross_slip_displacement(mu, 185.0, a, BODIES)
    for factor in (2.0, 20.0):
        cyc = fretting_cycle(grid, c, k, factor * d_t, 185.0, mu).solve(np.zeros(grid.shape), np.zeros(grid.shape),
                                                                         normal, None)
        assert cyc.regime == "gross_slip" and cyc.stick_half_width_x == 0
        assert cyc.force_amplitude == pytest.approx(mu * 185.0, rel=1e-9)
        # W = 4μP(δ − δ_e): each point slides 4(δ − its elastic displacement under μp); δ_e lies within (0, δ_t)
        elastic = factor * d_t - cyc.energy / (4 * mu * 185.0)
        assert 0.0 < elastic < d_t
    # and as the stroke grows the local-slip wear approaches the uniform model's within model.accuracy
    wide = fretting_cycle(grid, c, k, 100 * d_t, 185.0, mu).solve(np.zeros(grid.shape), np.zeros(grid.shape),
                                                                   normal, None)
    uniform = 4 * 100 * d_t * 2e-8 * wide.pressure
    assert np.abs(wide.rate_moving - uniform).max() <= 0.01 * uniform.max()


def test_partial_slip_wears_an_annulus_and_nothing_where_it_sticks():
    grid, c, k, normal, a = ball_contact(64)
    mu = 0.6
    stroke = 0.5 * M.ball_gross_slip_displacement(mu, 185.0, a, BODIES)
    cyc = fretting_cycle(grid, c, k, stroke, 185.0, mu).solve(np.zeros(grid.shape), np.zeros(grid.shape), normal, None)
    q_star = M.ball_force(stroke, mu, 185.0, a, BODIES)
    c_exact = M.ball_stick_radius(q_star, mu, 185.0) * a
    r = np.hypot(*grid.mesh())
    inside, annulus = r < c_exact - grid.dx, (r > c_exact + grid.dx) & (cyc.pressure > 0)
    assert cyc.rate_moving[inside].max() == 0.0 and cyc.slip_moving[inside].max() == 0.0
    assert (cyc.rate_moving[annulus] > 0).mean() > 0.95


# --- Cattaneo: the cylinder (2D) ------------------------------------------------------------------------------

@pytest.mark.parametrize("fraction", [0.4, 0.8])
def test_cylinder_partial_slip_matches_cattaneo_and_its_loop_energy_ignores_the_datum(fraction):
    """The datum of a 2D displacement is arbitrary: it sets how much stroke the bodies take up (δ_t), but the loop
    an amplitude Q* makes, and so its energy, are Cattaneo's whatever it is."""
    from fretsim.cycle.coulomb import gross_slip_stroke
    mu = 0.6
    for n in (128, 256):
        grid, c, k, normal, a = cylinder_contact(n)
        p, _ = normal(np.zeros(grid.shape), None)
        transitions = []
        for length in (10.0, 100.0):  # the same contact with its datum ten times as far
            kk = Tangential(grid, BODIES, line_length=length)
            transitions.append(gross_slip_stroke(kk, p, mu))
            cyc = fretting_cycle(grid, c, kk, fraction * transitions[-1], 18.5, mu).solve(
                np.zeros(grid.shape), np.zeros(grid.shape), normal, None)
            q_star = cyc.force_amplitude  # per unit length: the grid is per unit length, volume factor 1
            assert cyc.regime == "partial_slip"
            assert abs(cyc.stick_half_width_x - M.cylinder_stick_half_width(q_star, mu, 18.5) * a) <= grid.dx
            # a small loop's energy (∝ Q*³) is a difference of near-equal terms: where the stick edge falls within
            # an element moves it by up to ~1e-3 here (2.5e-2 at 64 elements, 4e-5 at 512, measured)
            assert cyc.energy == pytest.approx(M.cylinder_loop_energy(q_star, mu, 18.5, E_STAR), rel=3e-3)
        # the farther datum takes up more stroke: (2/πE*)·μP′·ln 10 more, exactly (the kernels differ by a constant)
        extra = 2 / (math.pi * E_STAR) * mu * 18.5 * math.log(10.0)
        assert transitions[1] - transitions[0] == pytest.approx(extra, rel=1e-9)


def test_cylinder_tangential_force_against_displacement_matches_cattaneo_with_the_datum():
    """Q′(δ) of a cylinder against the closed form with fretsim's datum: the datum's constant is implemented as
    derived (to the solver's tolerance: the displacement is exact for the discrete pressure up to O(dx²))."""
    from fretsim.compliance.tangential import datum_distance
    mu = 0.6
    grid, c, k, normal, a = cylinder_contact(256)
    for t in (0.3, 0.6, 0.9):
        stroke = M.cylinder_displacement(t * mu * 18.5, mu, 18.5, a, E_STAR, datum_distance(10.0, NU))
        cyc = fretting_cycle(grid, c, k, stroke, 18.5, mu).solve(np.zeros(grid.shape), np.zeros(grid.shape), normal,
                                                                  None)
        assert cyc.force_amplitude == pytest.approx(t * mu * 18.5, rel=1e-4)  # measured 8e-6 at 256 elements


def test_a_long_cylinder_takes_up_the_stroke_in_2d_as_in_3d():
    """The 2D datum is chosen so that the 2D model of a line contact shares the stroke with its bodies as the 3D
    half-space model does: the displacement at which gross slip begins, 2D against 3D on a long cylinder."""
    from fretsim.cycle.coulomb import gross_slip_stroke
    radius, length, load = 6.0, 10.0, 185.0
    a = math.sqrt(4 * load / length * radius / (math.pi * E_STAR))
    dx = 7 * a / 40
    g2 = Grid.centred(61, 1, dx, 1.0, plane_strain=True)
    out = []
    for g, lf in ((g2, load / length), (Grid.centred(61, 21, dx, length / 21), load),
                  (Grid.centred(61, 81, dx, length / 81), load)):
        x, y = g.mesh()
        gap = x**2 / (2 * radius) if g.plane_strain else np.where(np.abs(y) <= length / 2, x**2 / (2 * radius), np.inf)
        p = solve(HalfSpace(g, E_STAR), gap, lf, tol=1e-12).pressure
        k = Tangential(g, BODIES, line_length=length if g.plane_strain else None)
        out.append(gross_slip_stroke(k, p, 0.9))
    # δ_t is read on the centre section, which the 2D model is of: measured 0.7 % (21 rows) and 1.1 % (81 rows)
    # below 2D; 2 % leaves room for the 3D value's slow drift with the rows, and a datum off by a factor e (one
    # unit in its logarithm) would move 2D by 14 %
    assert out[0] == pytest.approx(out[2], rel=0.02)
    # and it is a property of the contact, not of the grid: 21 against 81 rows, measured 0.4 % (the ends' maximum,
    # which the end effects rule, moves 1.7 %)
    assert out[1] == pytest.approx(out[2], rel=0.01)


# --- the models it reduces to, and the invariants ----------------------------------------------------------------

def test_rigid_slip_through_the_cycle_is_the_papers_stroke_average_to_round_off():
    """With every point sliding with the rig (slip: uniform) the incremental cycle's flat wear, summed over the
    increments of the travel, is exactly the paper's stroke-averaged pressure times 4δ."""
    grid, c, k, normal, a = cylinder_contact(96)
    rng = np.random.default_rng(3)
    h_m = np.clip(rng.normal(1e-4, 3e-5, grid.shape), 0, None) * (np.abs(grid.x) < 2 * a)
    h_s = np.clip(rng.normal(1e-4, 3e-5, grid.shape), 0, None) * (np.abs(grid.x) < 2 * a)
    stroke = 0.4 * a
    w = wear_operator(grid, stroke, 2e-8, 3e-8, "mid_stroke")
    paper = UniformCycle(grid, w, stroke, 18.5, 185.0, 2e-8, 3e-8, "mid_stroke")
    ours = fretting_cycle(grid, c, k, stroke, 18.5, 0.6, volume_factor=10.0, rigid=True)
    a_cyc = paper.solve(h_m, h_s, normal, None)
    b_cyc = ours.solve(h_m, h_s, normal, None)
    scale = a_cyc.rate_stationary.max()
    assert np.abs(a_cyc.rate_stationary - b_cyc.rate_stationary).max() < 1e-12 * scale
    assert np.abs(a_cyc.rate_moving - b_cyc.rate_moving).max() < 1e-12 * scale
    assert np.abs(a_cyc.pressure_stationary - b_cyc.pressure_stationary).max() < 1e-12 * a_cyc.pressure.max()
    assert b_cyc.work == pytest.approx(a_cyc.work, rel=1e-12)


def test_the_energy_law_is_archard_with_k_equal_alpha_mu_and_conserves_alpha_times_the_energy():
    grid, c, k, normal, a = ball_contact(40)
    mu, stroke = 0.6, 0.4 * M.ball_gross_slip_displacement(0.6, 185.0, a, BODIES)
    archard = CoulombCycle(grid, c, k, stroke, 185.0, 185.0, mu, 2e-8 * mu, 3e-8 * mu)
    energy = CoulombCycle(grid, c, k, stroke, 185.0, 185.0, mu, 2e-8, 3e-8, law=WEAR_LAWS["energy"])
    zero = np.zeros(grid.shape)
    x, y = archard.solve(zero, zero, normal, None), energy.solve(zero, zero, normal, None)
    assert np.abs(x.rate_moving - y.rate_moving).max() <= 1e-9 * x.rate_moving.max()
    assert y.work == pytest.approx(y.energy, rel=1e-12)  # the energy law's invariant is ΣW
    area = grid.area
    assert y.rate_moving.sum() * area == pytest.approx(2e-8 * y.energy, rel=1e-12)
    assert y.rate_stationary.sum() * area == pytest.approx(3e-8 * y.energy, rel=1e-9)  # deposited in the grid


def test_the_loops_area_is_the_dissipated_energy():
    grid, c, k, normal, a = ball_contact(40)
    stroke = 0.6 * M.ball_gross_slip_displacement(0.6, 185.0, a, BODIES)
    cyc = fretting_cycle(grid, c, k, stroke, 185.0, 0.6, increments=101).solve(np.zeros(grid.shape),
                                                                               np.zeros(grid.shape), normal, None)
    u, q = cyc.loop
    area = abs(float(np.sum(0.5 * (q[1:] + q[:-1]) * np.diff(u))))
    assert u[0] == pytest.approx(-stroke) and u[-1] == pytest.approx(-stroke) and q[0] == pytest.approx(q[-1])
    assert area == pytest.approx(cyc.energy, rel=2e-3)  # the trapezoid rule on 202 points of a smooth loop


def _side_um(u, q):
    """The rig travel from the loop's top turning point (+Q*) to where the force first reaches −Q* again."""
    ok = np.isfinite(u)
    u, q = u[ok], q[ok]
    top = int(np.argmax(u))
    reach = next(i for i in range(top, u.size) if q[i] <= -abs(q[top]) * (1 - 1e-6))
    return u[top] - u[reach]


@pytest.mark.parametrize("factor", [1.5, 40.0])
def test_the_recorded_loops_elastic_side_spans_what_a_finely_stepped_loop_does(factor):
    """Evenly spaced increments (2δ/9) slid the whole contact in the first increment after reversal, so the loop's
    side spanned 2δ/9, several times 2δ_t, and a tangential stiffness read off it was that many times too
    compliant.  The recorded loop must span the side as a loop stepped 400 times per half-stroke does, within 10 %,
    just above the transition and far above it; and be the same loop (the force at each recorded displacement)."""
    grid, c, k, normal, a = ball_contact(40)
    mu = 0.6
    stroke = factor * M.ball_gross_slip_displacement(mu, 185.0, a, BODIES)
    member = fretting_cycle(grid, c, k, stroke, 185.0, mu)
    cyc = member.solve(np.zeros(grid.shape), np.zeros(grid.shape), normal, None)
    assert cyc.regime == "gross_slip"
    # the reference: the same tangential solver driven in 2δ/400 increments round the loop, the pressure fixed
    p, q = cyc.pressure, np.zeros(grid.shape)
    q, _, _, _ = member._tangential(q, p, -stroke)
    us, qs, n = [-stroke], [float(q.sum()) * grid.area], 400
    for u0, u1 in [(-stroke + 2 * stroke * j / n, -stroke + 2 * stroke * (j + 1) / n) for j in range(n)] + \
                  [(stroke - 2 * stroke * j / n, stroke - 2 * stroke * (j + 1) / n) for j in range(n)]:
        q, _, _, _ = member._tangential(q, p, u1 - u0)
        us.append(u1)
        qs.append(float(q.sum()) * grid.area)
    fine = _side_um(np.array(us), np.array(qs))
    recorded = _side_um(*cyc.loop)
    assert recorded == pytest.approx(fine, rel=0.10)
    if factor > 10:  # McColl's 185 N at 25 µm is 37× δ_t: the old loop's first increment, 2δ/9, slid it all
        assert 2 * stroke / 9 > 4 * fine
    # and its points lie on the fine loop: the down-stroke's force at each recorded displacement
    u, f = cyc.loop
    top = int(np.argmax(u))
    down_fine = slice(n, 2 * n + 1)  # from the top turning point (+δ) down
    at = np.interp(-u[top:], -np.array(us)[down_fine], np.array(qs)[down_fine])
    assert np.abs(f[top:] - at).max() < 0.02 * mu * 185.0  # the fine loop's own interpolation error, side curvature


@pytest.mark.parametrize("factor", [1.5, 6.0])
def test_a_resolved_strokes_recorded_loop_spans_its_side_as_a_finely_stepped_resolved_loop_does(factor):
    """The resolved stroke's wear increments are a quadrature along the stroke (9 evenly spaced by default): the
    loop they drew had sides an increment wide.  Its recorded loop is drawn from each turning point on the
    pressure there, the side finely cut; it must span the side as the loop of 201 increments per half-stroke
    (the pressure solved at every one) does, within 10 %."""
    grid, c, k, normal, a = ball_contact(32)
    mu = 0.6
    stroke = factor * M.ball_gross_slip_displacement(mu, 185.0, a, BODIES)
    zero = np.zeros(grid.shape)
    recorded = fretting_cycle(grid, c, k, stroke, 185.0, mu, resolved=True).solve(zero, zero, normal, None)
    fine = fretting_cycle(grid, c, k, stroke, 185.0, mu, resolved=True, increments=201).solve(
        zero, zero, normal, None, detail=False)  # not a recorded state: the loop of its own increments
    assert recorded.regime == fine.regime == "gross_slip"
    assert _side_um(*recorded.loop) == pytest.approx(_side_um(*fine.loop), rel=0.10)
    if factor > 5:  # the loop of the 9 wear increments themselves (what was recorded before): far off here
        evenly = fretting_cycle(grid, c, k, stroke, 185.0, mu, resolved=True).solve(zero, zero, normal, None,
                                                                                   detail=False)
        assert abs(_side_um(*evenly.loop) / _side_um(*fine.loop) - 1) > 0.2


# --- whole runs ---------------------------------------------------------------------------------------------------

CASES = __import__("pathlib").Path(__file__).resolve().parents[1] / "cases"
# the paper's grid: these runs compare stepping schemes, the explicit ones among them, on one grid
COULOMB_2D = ["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=mid_stroke",
              "grid.rule=paper"]


def _run(*overrides, case="mccoll_185N.yaml", output=None):
    from fretsim.api import load_case, run
    return run(load_case(CASES / case, list(overrides)), output)


@pytest.fixture(scope="session")  # per worker, once: xdist interleaves modules, a module fixture is rebuilt
def exact_per_cycle():
    """The exact model: one representative cycle per cycle (600 cycles, 2D)."""
    return _run(*COULOMB_2D, "loading.cycles=600", "output.snapshots=[0, 200, 600]", "jumping.scheme=linear",
                "jumping.linear=1")


@pytest.mark.parametrize("scheme, tolerance", [("bdf2", 1e-3), ("implicit", 3e-3), ("linear", 3e-3),
                                               ("adaptive", 3e-3)])
def test_every_stepping_scheme_runs_the_coulomb_cycle_and_meets_the_exact_per_cycle_run(exact_per_cycle, scheme,
                                                                                        tolerance):
    """bdf2 at its default tolerance keeps depths within τ/10 (measured 3e-4); the first-order schemes within
    their own error (backward Euler 1.3e-3, linear 1.0e-3 measured); every one keeps the invariant and reports an
    error estimate that covers what it got wrong."""
    out = _run(*COULOMB_2D, "loading.cycles=600", "output.snapshots=[0, 200, 600]", f"jumping.scheme={scheme}")
    assert out.status == "complete", out.message
    s, ref = out.summary, exact_per_cycle.summary
    check_archard(out)  # from the fields: k·P·4(δ − δ_t)·N ≤ each volume ≤ k·P·4δ·N in gross slip
    worst = max(abs(s[k] / ref[k] - 1) for k in ("centre_wear_depth_stationary_um", "max_wear_depth_moving_um"))
    assert worst < tolerance
    assert s["error_estimate_depth"] >= 0.5 * worst  # the estimate is of the right size (an estimate, not a bound)
    assert s["contact_solves"] < 0.2 * ref["contact_solves"]


PARTIAL_2D = ["model.dimension=2d", "loading.friction_coefficient=0.9", "loading.stroke=0.4 um", "loading.cycles=3000",
              "output.snapshots=[0, 1000, 3000]"]


@pytest.fixture(scope="session")  # per worker, once: xdist interleaves modules, a module fixture is rebuilt
def exact_partial_slip():
    """The exact model in partial slip (McColl's cylinder at 0.4 µm, well below δ_t): a cycle per cycle."""
    return _run(*PARTIAL_2D, "jumping.scheme=linear", "jumping.linear=1")


@pytest.mark.parametrize("scheme, tolerance", [("bdf2", 3e-3), ("implicit", 3e-3), ("adaptive", 1e-2)])
def test_partial_slip_stepping_meets_the_exact_per_cycle_run(exact_partial_slip, scheme, tolerance):
    """The rates of a partly stuck contact are not linear in the pressure and change where the stick edge moves.
    Measured against the per-cycle run: the implicit schemes, which take forward-Euler steps under error control
    while the cycle has a stick zone (fretsim.stepping.implicit), 1.5e-3 with an estimate of 1.8e-3 (their BDF2
    steps were 2.6e-4 off over these 3 000 cycles, but 21-35 % off over 10⁵: the next test); the paper's adaptive
    jumps 4.5e-3 (estimate 8.5e-3).  First order: bounds about 2× the measured error."""
    out = _run(*PARTIAL_2D, f"jumping.scheme={scheme}")
    assert out.status == "complete", out.message
    s, ref = out.summary, exact_partial_slip.summary
    assert s["regime"] == ref["regime"] == "partial_slip"
    worst = max(abs(s[k] / ref[k] - 1) for k in ("max_wear_depth_stationary_um", "max_wear_depth_moving_um",
                                                    "centre_wear_depth_stationary_um"))
    assert worst < tolerance
    assert s["error_estimate_depth"] >= 0.5 * worst
    assert s["contact_solves"] < 0.02 * ref["contact_solves"]


def test_a_long_partial_slip_run_keeps_to_short_explicit_steps_and_its_estimate_covers_the_difference():
    """Ti-6Al-4V at 5 µm stroke, 10⁵ cycles (cases/ti_fretting_fatigue.yaml, its fatigue off): BDF2's linearised
    steps, which corrected the stick zone's wear once, ended 21 % deep (0.710 against 0.586 µm) with a stepping
    estimate of 1.7 %.  Against the paper's explicit jumps of 50 cycles (within 8.5e-5 of the run cycle by cycle,
    measured: 0.58574 against 0.58569 µm) the default now stays within 1e-3 (measured 1.2e-4), and its estimate
    covers the difference (measured 2.2e-3)."""
    base = ("materials.stationary.fatigue=null", "grid.error_estimate=none")
    ref = _run(*base, "jumping.scheme=linear", "jumping.linear=50", case="ti_fretting_fatigue.yaml").summary
    out = _run(*base, case="ti_fretting_fatigue.yaml")
    s = out.summary
    assert out.status == "complete", out.message
    assert s["regime"] == ref["regime"] == "partial_slip"
    worst = max(abs(s[k] / ref[k] - 1) for k in ("max_wear_depth_stationary_um", "max_wear_depth_moving_um",
                                                    "centre_wear_depth_stationary_um", "scar_width_stationary_mm"))
    assert worst < 1e-3
    assert s["error_estimate_depth"] >= worst
    assert s["contact_solves"] < 0.6 * ref["contact_solves"]


def test_partial_slip_steps_near_the_transition_build_no_checkerboard_the_small_explicit_jumps_do_not(tmp_path):
    """The forward-Euler steps of partial slip are capped at half the stability limit of the cycle's own wear
    stiffness.  Taken as k·s_max (4δ over the largest slip times half the planned limit), the cap was too long near
    the transition at high friction: Ti-6Al-4V at 8.2 µm, μ 1.2 built an odd-even pressure pattern of 21 % of the
    mean from cycle 11 800 to 21 600 (found by a review), where explicit jumps of a quarter of the planned limit
    stay at 0.24 %; the slip's own response to the pressure raises the stiffness (SLIP_STIFFNESS).  Now the pattern
    is the reference's (measured 0.243 % against 0.241 %) and the state at 19 600 cycles, inside that window, has
    its pressure within 1 % of the reference's peak (measured 0.32 %)."""
    import h5py
    base = ("materials.stationary.fatigue=null", "grid.error_estimate=none", "loading.stroke=8.2 um",
            "loading.friction_coefficient=1.2", "loading.cycles=25000", "output.snapshots=[0, 19600, 25000]")
    found = {}
    for name, over in (("default", ()), ("reference", ("jumping.scheme=linear", "jumping.linear=42"))):
        out = _run(*base, *over, case="ti_fretting_fatigue.yaml", output=tmp_path / f"{name}.h5")
        assert out.summary["regime"] == "partial_slip"
        with h5py.File(tmp_path / f"{name}.h5", "r") as f:
            found[name] = (f["history/checkerboard_amplitude"][:].max(), f["fields/pressure"][1])
    (board, p), (board_ref, p_ref) = found["default"], found["reference"]
    assert board < 1.5 * board_ref + 1e-3
    assert np.abs(p - p_ref).max() < 0.01 * p_ref.max()


def test_a_run_whose_steps_built_an_odd_even_pressure_pattern_that_stopped_growing_says_so(monkeypatch):
    """The growth watcher stops a pattern that keeps growing; one that grew and then stayed ended "complete"
    without a word (the partial-slip cap at 4δ/s_max: 20 % of the mean pressure at 8.2 µm, μ 1.2, found by a
    review).  Such a cap restored here, the run says where its pattern peaked; the default's (0.24 %) says nothing."""
    import fretsim.stepping.implicit as implicit
    base = ("materials.stationary.fatigue=null", "grid.error_estimate=none", "loading.stroke=8.2 um",
            "loading.friction_coefficient=1.2", "loading.cycles=25000", "output.snapshots=[0, 25000]")
    said = lambda out: [n for n in out.notes if "odd-even pattern" in n]  # noqa: E731
    assert not said(_run(*base, case="ti_fretting_fatigue.yaml"))
    monkeypatch.setattr(implicit, "SLIP_STIFFNESS", 1.0)
    out = _run(*base, case="ti_fretting_fatigue.yaml")
    assert out.status == "complete" and len(said(out)) == 1
    assert "jumping.max" in said(out)[0] and "% of its mean at cycle" in said(out)[0]


def test_a_partial_slip_runs_forward_euler_steps_keep_to_jumping_max(tmp_path):
    """jumping.max bounds every step of the implicit schemes, the forward-Euler ones of partial slip too (they
    ignored it at first: steps of 104 cycles under a bound of 20, found by a review)."""
    import h5py
    out = _run("materials.stationary.fatigue=null", "grid.error_estimate=none", "loading.cycles=2000",
               "jumping.max=10", case="ti_fretting_fatigue.yaml", output=tmp_path / "r.h5")
    assert out.summary["regime"] == "partial_slip"
    with h5py.File(tmp_path / "r.h5", "r") as f:
        jumps = f["history/cycle_jump"][:]
    assert jumps.max() == 10 and out.summary["contact_solves"] >= 200


def test_every_cycle_keeps_within_what_the_physics_allows(exact_partial_slip):
    """Independently of the invariant (which the loop accumulates from the cycles' own work): no point slides
    further than the rig travels and |q| ≤ μp, so per cycle Σp|ds|A ≤ P·4δ and the energy ≤ μ·P·4δ; a partly
    stuck contact stays well below both (its centre does not slide)."""
    h = exact_partial_slip.summary
    p_4delta = 185.0 * 4 * 0.4e-3  # N·mm
    assert 0 < h["dissipated_energy_per_cycle_J"] * 1e3 < 0.5 * 0.9 * p_4delta
    work_per_cycle = h["wear_volume_stationary_mm3"] / 2e-8 / h["cycles"]
    assert 0 < work_per_cycle < 0.5 * p_4delta


def test_a_cycle_beyond_its_physical_bounds_stops_the_run(monkeypatch):
    """A slip or traction the tangential solve got wrong keeps the invariant (the volume follows the work the cycle
    reports) but breaks the bounds: a cycle whose points slide 1.5 times the rig's travel, or dissipate more than
    μ·P·4δ, stops the run with the reason instead of being written."""
    import dataclasses
    original = CoulombCycle.solve

    def inflated(field, factor):
        def solve(self, *a, **k):
            cyc = original(self, *a, **k)
            return dataclasses.replace(cyc, **{field: getattr(cyc, field) * factor})
        return solve

    for field in ("work", "energy"):
        monkeypatch.setattr(CoulombCycle, "solve", inflated(field, 1.5))
        out = _run(*COULOMB_2D, "loading.cycles=20", "output.snapshots=[0, 20]")
        assert out.status == "failed" and "physical bound" in out.message, (field, out.status, out.message)
    monkeypatch.setattr(CoulombCycle, "solve", inflated("work", 1.0))
    assert _run(*COULOMB_2D, "loading.cycles=20", "output.snapshots=[0, 20]").status == "complete"


def test_a_resolved_stroke_without_a_friction_coefficient_is_refused_naming_the_key():
    from fretsim.api import CaseError, load_case
    with pytest.raises(CaseError, match="loading.friction_coefficient.*model.stroke resolved"):
        load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "model.stroke=resolved"])


def test_the_rig_takes_q_over_k_of_the_stroke():
    """A rig of stiffness k in series with the contact: gross slip needs μP/k more stroke (exactly: the rig's
    compliance is a constant kernel)."""
    stiff = _run(*COULOMB_2D, "loading.cycles=0")
    soft = _run(*COULOMB_2D, "loading.cycles=0", "loading.tangential_stiffness=40 N/um")
    extra_um = 0.9 * 185.0 / 40.0  # μP/k in µm (k in N/µm)
    assert soft.summary["gross_slip_stroke_um"] - stiff.summary["gross_slip_stroke_um"] == pytest.approx(extra_um,
                                                                                                          rel=1e-9)


def test_auto_slip_chooses_from_the_regime_and_keeps_model_accuracy():
    from fretsim.api import check, load_case
    choice = lambda *ov: next(c for c in check(load_case(CASES / "mccoll_185N.yaml", list(ov)))[2].choices  # noqa
                              if c.key == "model.slip")
    assert choice("model.dimension=2d").value == "uniform"  # no μ: the paper's model, said so
    assert "no friction coefficient" in choice("model.dimension=2d").reason
    partial = choice("model.dimension=2d", "loading.friction_coefficient=0.9", "loading.stroke=0.4 um")
    assert partial.value == "coulomb" and "partial slip" in partial.reason
    gross = choice("model.dimension=2d", "loading.friction_coefficient=0.9")  # δ_t/δ = 2.7 % > 1 %
    assert gross.value == "coulomb" and "2.7%" in gross.reason
    far = choice("model.dimension=2d", "loading.friction_coefficient=0.9", "model.accuracy=4 %")
    assert far.value == "uniform" and "2.68%" in far.reason
    # ... and where it keeps uniform, uniform is within model.accuracy of coulomb
    a = _run("model.dimension=2d", "loading.friction_coefficient=0.9", "model.accuracy=4 %")
    b = _run(*COULOMB_2D)
    for key in ("centre_wear_depth_stationary_um", "max_wear_depth_moving_um", "scar_width_stationary_mm",
                "scar_width_moving_mm"):
        assert abs(a.summary[key] / b.summary[key] - 1) <= 0.04, key


def test_auto_stroke_resolves_it_where_2d_proxies_show_mid_stroke_beyond_a_third_of_the_accuracy():
    """model.stroke auto: McColl 185 N with μ 0.9 gets the resolved stroke (its 2D proxies put the mid-stroke depth
    6.75 % away, more than 1 %/3), with the number in the reason; at model.accuracy 30 % the mid-stroke model is
    kept and the difference, times the proxy margin, is the model's share of the error.  No proxy is run where the
    answer is known: partial slip, the paper's uniform member, a point contact (said why)."""
    from fretsim.api import check, load_case
    from fretsim.plan.model import PROXY_MARGIN

    def choice(*ov, case="mccoll_185N.yaml"):
        return next(c for c in check(load_case(CASES / case, ["model.dimension=2d", *ov]))[2].choices
                    if c.key == "model.stroke")
    friction = ["loading.friction_coefficient=0.9", "model.slip=coulomb"]
    tight = choice(*friction)
    assert tight.value == "resolved" and "away from the mid-stroke model" in tight.reason
    diff = float(tight.reason.split("% away")[0].split()[-1]) / 100
    assert diff > 0.01 / PROXY_MARGIN
    loose = choice(*friction, "model.accuracy=30 %")
    # (its proxies' own difference: a resolved implicit step corrects its gap to a share of model.accuracy, so
    # looser proxies differ a little, 0.7 % of the difference here)
    loose_diff = float(loose.reason.split("% of the resolved")[0].split()[-1]) / 100
    assert loose_diff == pytest.approx(diff, rel=0.05)
    assert loose.value == "mid_stroke" and loose.error == pytest.approx(loose_diff * PROXY_MARGIN, rel=1e-3)
    assert choice(*friction, "loading.stroke=0.4 um").value == "mid_stroke"  # partial slip: no proxy
    assert "partial slip" in choice(*friction, "loading.stroke=0.4 um").reason
    assert choice("loading.friction_coefficient=0.9", "model.slip=uniform").value == "mid_stroke"
    ball = next(c for c in check(load_case(CASES / "ball_partial_slip.yaml", ["loading.stroke=20 um"]))[2].choices
                if c.key == "model.stroke")
    assert ball.value == "mid_stroke" and "no 2D model" in ball.reason


def test_uniform_slip_below_the_transition_is_refused_with_the_reason():
    from fretsim.api import CaseError, check, load_case
    with pytest.raises(CaseError, match="partial-slip limit"):
        check(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.friction_coefficient=0.9",
                                                     "loading.stroke=0.4 um", "model.slip=uniform"]))


def test_a_coulomb_run_records_its_loop_slips_energy_and_regime(tmp_path):
    from fretsim.plotting import figures
    from fretsim.results import read_results
    out = _run(*COULOMB_2D, "loading.cycles=2000", "output.snapshots=[0, 2000]", output=tmp_path / "c.h5")
    res = read_results(tmp_path / "c.h5")
    s = res.summary
    assert s["regime"] == "gross_slip" and s["stick_half_width_x_mm"] == 0.0
    assert s["tangential_force_amplitude_N"] == pytest.approx(0.9 * 185.0, rel=1e-9)
    # energy per cycle: 4μP(δ − the elastic part), which lies within (0, δ_t)
    elastic_um = 25.0 - s["dissipated_energy_per_cycle_J"] * 1e3 / (4 * 0.9 * 185.0) * 1e3
    assert 0 < elastic_um < s["gross_slip_stroke_um"]
    loop = res.fretting_loop
    # the loading quarter's end, then each half-stroke: its elastic side in 12 increments and the sliding rest in one
    assert loop["displacement"].shape == loop["tangential_force"].shape == (2, 1 + 2 * (12 + 1))
    # Masing: at cycle 0 the traction reverses over 2δ_t of the unworn contact (the summary's), the side's end on an
    # increment; 1 %: the last point to slide is one element off the centre section's maximum at most
    assert _side_um(loop["displacement"][0], loop["tangential_force"][0]) == pytest.approx(
        2 * s["gross_slip_stroke_um"], rel=0.01)
    assert np.nanmax(np.abs(loop["displacement"])) == pytest.approx(25.0)
    slip = res.fields["slip_distance_moving"][-1]
    assert slip.max() < 100.0 and slip.max() > 95.0  # 4δ = 100 µm less the elastic take-up
    assert np.isfinite(res.history["dissipated_energy_J"]).all()
    volume_m = res.history["wear_volume_moving"][-1]
    assert volume_m == pytest.approx(2e-8 * res.history["wear_work"][-1], rel=1e-12)
    assert "fretting" in figures(res)
    assert out.summary["regime"] == s["regime"]
    from fretsim.export import export_csv
    names = [p.name for p in export_csv(res, tmp_path / "csv")]
    assert "fretting_loop.csv" in names
    rows = (tmp_path / "csv" / "fretting_loop.csv").read_text().splitlines()
    assert rows[0] == "cycle,displacement [um],tangential_force [N]" and len(rows) == 1 + 2 * 27


@pytest.mark.slow
def test_the_shipped_partial_slip_ball_meets_its_per_cycle_run(tmp_path):
    """ball_partial_slip (3D, 20 000 cycles) under the defaults against the exact per-cycle run on the same grid
    (about 2.5 min): measured 0.15 % in the deepest point, 0.58 % in the final pressure (L2).  The stepping
    estimate printed for it (7.5e-4) is half the depth error found: under-reported, which the error-bar issue
    addresses; the bounds here are a few times the measured errors."""
    import h5py
    from fretsim.api import load_case, run
    case = CASES / "ball_partial_slip.yaml"
    fast = run(load_case(case, []), tmp_path / "fast.h5")
    exact = run(load_case(case, ["jumping.scheme=linear", "jumping.linear=1"]), tmp_path / "exact.h5")
    assert fast.status == exact.status == "complete"
    with h5py.File(tmp_path / "fast.h5") as f, h5py.File(tmp_path / "exact.h5") as g:
        d_f, d_g = f["fields/wear_depth_stationary"][-1], g["fields/wear_depth_stationary"][-1]
        p_f, p_g = f["fields/pressure"][-1], g["fields/pressure"][-1]
    assert abs(d_f.max() / d_g.max() - 1) < 5e-3
    assert np.linalg.norm(p_f - p_g) / np.linalg.norm(p_g) < 2e-2


def test_a_zero_friction_coefficient_is_frictionless_uniform_slip_with_no_energy(tmp_path):
    """μ = 0 (allowed by the case reference) used to divide by δ_t = 0 in `check` and, after a complete run, in the
    run's paragraph (exit 1).  Frictionless: no shear traction, nothing sticks, every point slides the whole stroke,
    so auto picks the uniform model (exact here), the regime is gross slip, no energy is dissipated; Coulomb
    friction and the energy law have nothing to work with and are refused in one paragraph."""
    from click.testing import CliRunner
    from fretsim.cli import main
    from fretsim.results import read_results
    from pathlib import Path
    case = str(Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml")
    base = ["--set", "loading.friction_coefficient=0", "--set", "model.dimension=2d", "--set", "loading.cycles=1000",
            "--set", "grid.error_estimate=none"]
    r = CliRunner().invoke(main, ["check", case, *base])
    assert r.exit_code == 0 and "frictionless (μ = 0)" in r.output, r.output
    for extra in ([], ["--set", "model.slip=uniform"]):
        out = tmp_path / f"r{len(extra)}.h5"
        r = CliRunner().invoke(main, ["run", case, *base, *extra, "-o", str(out)])
        assert r.exit_code == 0 and "frictionless (μ = 0)" in r.output, r.output
        s = read_results(out).summary
        assert s["regime"] == "gross_slip" and s["gross_slip_stroke_um"] == 0.0
        assert s["dissipated_energy_per_cycle_J"] == 0.0 and s["tangential_force_amplitude_N"] == 0.0
    for extra in (["--set", "model.slip=coulomb"], ["--set", "model.stroke=resolved"]):
        r = CliRunner().invoke(main, ["run", case, *base, *extra, "-o", str(tmp_path / "x.h5")])
        assert r.exit_code == 2 and "loading.friction_coefficient: 0 with" in r.output, r.output
        assert not (tmp_path / "x.h5").exists()


def test_the_resolved_stroke_converges_with_the_grid_and_keeps_the_moving_body_smooth():
    """Every point of the moving body travels with it, in contact or not.  When a point that left the contact kept
    its place over the flat (its slip, 0 outside the contact, taken as its travel), it re-entered reading the worn
    flat where it had left: the moving body's profile went rough at element scale, the contact rattled between
    its spikes and the depth moved with the grid (−1.35 % here from 427 to 854 elements, −2.6 % then −3.6 % at
    1 000 cycles).  Now both bodies' profiles are grid-independent: cycle by cycle (no stepping error), halving dx
    moves the flat's depth by < model.accuracy/3 (the issue's bar; measured 1e-5 relative) and the moving body's
    profile, interpolated onto the coarse grid, by < 1 % of its depth (measured 0.18 %; the rough profile
    differed by 17 %)."""
    from pathlib import Path
    from fretsim.api import load_case, run
    case = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
    base = ["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved",
            "grid.error_estimate=none", "loading.cycles=200", "grid.domain=[0.7018 mm]", "output.snapshots=[0, 200]",
            "jumping.scheme=linear", "jumping.linear=1"]
    coarse, fine = (run(load_case(case, [*base, f"grid.elements=[{n}]"])) for n in (427, 854))
    key = "centre_wear_depth_stationary_um"
    assert fine.summary[key] == pytest.approx(coarse.summary[key], rel=0.01 / 3)
    h_coarse = coarse.last.wear_moving[0]
    h_fine = np.interp(coarse.setup.grid.x, fine.setup.grid.x, fine.last.wear_moving[0])
    assert np.abs(h_fine - h_coarse).max() < 0.01 * h_coarse.max()


def test_the_resolved_strokes_implicit_steps_keep_the_worn_contacts_pressure_falling_as_the_scar_conforms(tmp_path):
    """In steady gross-slip wear of a cylinder on a flat the scar conforms and the peak pressure falls at every
    recorded state (the run cycle by cycle, 4 at a time: 116.8, 99.0, 91.1, 86.3, 81.2 MPa at 1 000, 2 000, 3 000,
    4 000 and 6 000 cycles, 72 at 18 000).  Implicit steps that started from the last step's gap corrections, scaled, carried their sharp edges to
    where the contact's edge no longer was: the peak rose again from cycle 4 000 (115 → 171 → 195 MPa) and the
    worn profile kept the spikes.  Each recorded state's peak must stay below the one before (with 1 % for the
    stepping's own scatter), and the last within 5 % of the run cycle by cycle's 81.2 MPa at 6 000 cycles (measured
    +0.3 %; the old scheme's 328 MPa, +300 %)."""
    from pathlib import Path
    from fretsim.api import load_case, run
    from fretsim.results import read_results
    case = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
    out = tmp_path / "r.h5"
    run(load_case(case, ["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb",
                         "model.stroke=resolved", "grid.error_estimate=none", "loading.cycles=6000",
                         "grid.elements=[427]", "grid.domain=[0.7018 mm]",
                         "output.snapshots=[1000, 2000, 3000, 4000, 6000]"]), out)
    res = read_results(out)
    peaks = [float(p.max()) for c, p in zip(res.fields["cycle"], res.fields["pressure"]) if c >= 1000]
    assert all(b <= 1.01 * a for a, b in zip(peaks, peaks[1:])), peaks
    assert peaks[-1] == pytest.approx(81.2, rel=0.05)


def test_the_resolved_stroke_reduces_to_the_mid_stroke_model_where_the_stroke_is_short_against_the_contact():
    """At ±4 µm against McColl 185 N's 36 µm half-width the contact hardly moves over the flat: both bodies' depths
    within 0.2 % of the mid-stroke model's (measured 0.03 % and 0.10 %; the position's effect goes as (δ/a)², here
    about 1 % of the 6.8 % it makes at ±25 µm).  The scar widths differ by 1 % (the edge's taper, read at the
    width's threshold), so they are not compared."""
    from pathlib import Path
    from fretsim.api import load_case, run
    case = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
    base = ["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb", "grid.error_estimate=none",
            "loading.stroke=4 um", "loading.cycles=2000", "output.snapshots=[0, 2000]"]
    mid, resolved = (run(load_case(case, [*base, f"model.stroke={st}"])).summary for st in ("mid_stroke", "resolved"))
    for key in ("centre_wear_depth_stationary_um", "max_wear_depth_moving_um"):
        assert resolved[key] == pytest.approx(mid[key], rel=2e-3), key


def test_a_resolved_run_reports_its_error_totals_with_the_grids_companion():
    """The resolved stroke's pressure is smooth and its implicit steps are corrected (the slow test below): its runs
    report error totals like any other, the grid's companion included."""
    import math
    from pathlib import Path
    from fretsim.api import load_case, run
    case = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
    sets = ["model.dimension=2d", "loading.friction_coefficient=0.9", "loading.cycles=200", "output.snapshots=[0, 200]",
            "model.stroke=resolved"]
    resolved = run(load_case(case, sets))
    assert math.isfinite(resolved.summary["estimated_error_depth"]) and resolved.summary["estimated_error_depth"] > 0
    assert resolved.summary["grid_error_wall_time_s"] > 0.05  # the companion ran


@pytest.mark.slow
def test_implicit_steps_of_the_resolved_stroke_stay_within_their_estimate_as_explicit_ones_do():
    """Against the run cycle by cycle, BDF2's depth at 1 000 cycles is within its own estimate for the resolved
    stroke (with RESOLVED_CORRECTIONS: +0.025 %, estimated 0.031 %; uncorrected it was +1.9 %, 60× its estimate)
    and for the mid-stroke model; explicit jumps of 4 cycles (the limit is 4.4) are within 0.5 % (measured 0.05 %).
    scripts/study_resolved_stepping.py has the table."""
    from pathlib import Path
    from fretsim.api import load_case, run
    case = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
    base = ["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb", "grid.error_estimate=none",
            "loading.cycles=1000", "grid.elements=[427]", "grid.domain=[0.7018 mm]", "output.snapshots=[0, 1000]"]
    key = "centre_wear_depth_stationary_um"
    for stroke in ("resolved", "mid_stroke"):
        exact = run(load_case(case, [*base, f"model.stroke={stroke}", "jumping.scheme=linear", "jumping.linear=1"]))
        jumped = run(load_case(case, [*base, f"model.stroke={stroke}", "jumping.scheme=bdf2"]))
        error = abs(jumped.summary[key] / exact.summary[key] - 1.0)
        assert error <= jumped.summary["error_estimate_depth"], (stroke, error)
        if stroke == "resolved":
            explicit = run(load_case(case, [*base, "model.stroke=resolved", "jumping.scheme=linear",
                                            "jumping.linear=4"]))
            assert explicit.summary[key] == pytest.approx(exact.summary[key], rel=5e-3)



def test_near_the_transition_with_the_stroke_averaged_gap_forward_euler_steps_take_over_and_the_plan_warns():
    """Ti-6Al-4V with k_m = k_s/10 (the stroke-averaged gap), μ 1.0, 8 µm (δ_t 6.9 µm), 989 elements, 4·10⁴ cycles
    (a review's case): the run cycle by cycle ends the moving body at 0.47414 µm; BDF2 ended at 0.428 (9.7 % short,
    estimated 1.8 %: its correction barely converges where the slip spreads 25-40 %); forward-Euler steps end at
    0.465 (1.9 %).  The reference here is forward Euler at steps of at most 20 cycles (0.4726: 0.3 % from the run
    cycle by cycle), the bound 3 % (measured 1.6 %; BDF2 9.4 %).  Their estimate is still no bound (0.2 %), which
    the plan says."""
    from fretsim.api import check, load_case, run
    sets = ["materials.moving.wear_coefficient=2.75e-9 1/MPa", "materials.stationary.fatigue=null",
            "loading.friction_coefficient=1.0", "loading.stroke=8 um", "loading.cycles=40000",
            "grid.domain=[1.292 mm]", "grid.elements=[989]", "grid.error_estimate=none"]
    out = run(load_case(CASES / "ti_fretting_fatigue.yaml", sets))
    ref = run(load_case(CASES / "ti_fretting_fatigue.yaml", [*sets, "jumping.max=20"]))
    key = "max_wear_depth_moving_um"
    assert abs(out.summary[key] / ref.summary[key] - 1) < 0.03
    assert any(w.startswith("near the gross-slip transition") for w in out.plan.warnings)
    # `check` counts those steps (a review: it estimated about 100 solves for a run of 188 on 303 elements)
    from fretsim.plan import estimate_solves
    assert abs(estimate_solves(out.setup) / out.summary["contact_solves"] - 1) < 0.3  # (measured 275 against 253)
    # not for the paper's mid-stroke gap (equal wear), where the implicit steps held
    equal = check(load_case(CASES / "ti_fretting_fatigue.yaml", [*sets[1:]]))[2]
    assert not any(w.startswith("near the gross-slip transition") for w in equal.warnings)
