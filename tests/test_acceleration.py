"""Fewer solves without losing the state: BDF2 and backward Euler against the exact per-cycle model, stability
where the paper's methods fail, the paper's adaptive jumping, refinement."""
import functools
from pathlib import Path

import numpy as np
import pytest

from conftest import check_archard, cylinder_problem
from fretsim.api import run
from fretsim.case import CaseError, load_case
from fretsim.plan import prepare
from fretsim.refine import coarsen, mape, refine_pressure
from fretsim.simulate import simulate
from fretsim.solvers import solve
from fretsim.stability import wear_spectrum
from fretsim.wear import wear_operator

CASES = Path(__file__).resolve().parent.parent / "cases"
# the shipped cases that wear (the Table 1 cases are contact-only checks, cycles: 0)
SHIPPED = sorted(p.stem for p in CASES.glob("*.yaml") if load_case(p).loading.cycles > 0)
# point contacts have no 2D model, so they get short 3D runs
POINT = {name for name in SHIPPED if not load_case(CASES / f"{name}.yaml").geometry.has_2d}
# service cases stop at a wear limit, their loading.cycles only an upper bound (10⁹-10¹⁰): where a test takes a
# body's wear away the limit is never reached, so these tests take their first LIMITED_CYCLES cycles.  (Without
# the tube's wear the flat's groove fits the tube ever closer and cg slows: 2·10⁷ cycles took 668 solves and 170 s;
# tests/test_service_life.py covers the blocks and the limits.)
LIMITED = {name for name in SHIPPED if load_case(CASES / f"{name}.yaml").limits}
LIMITED_CYCLES = 2_000_000


def quick(name: str, cycles: int) -> list[str]:
    """A fast version of a shipped case: 2D for line contacts, a short 3D run for point contacts."""
    # on the paper's grid, without the grid's companion run: these tests are about the stepping on a given grid
    paper = ["grid.rule=paper", "grid.error_estimate=none"]
    if name in POINT:
        return [f"loading.cycles={min(cycles, 300)}", "output.snapshots=auto", *paper]
    return ["model.dimension=2d", f"loading.cycles={cycles}", "output.snapshots=auto", *paper]
# one shipped case of each kind, for the tests that take every shipped case through quick(): a line contact (in 2D),
# the partial-slip ball, a ball in gross slip, crossed cylinders, the tube, and the service tube whose explicit
# limit is below a cycle.  The others take these paths with other numbers (roller_edge_rounded and
# mccoll_185N_free_faces are mccoll_185N in 2D; the service tubes' first cycles lie in their first block): they run
# in `pytest -m slow`
KINDS = {"mccoll_185N", "ball_partial_slip", "seat_rail", "wire_rope", "tube_RT", "tube_service_90C"}
# issue #9's targets at the defaults, at every recorded state, against the exact model on the same grid
DEPTH, PRESSURE, P0 = 1e-3, 2e-2, 5e-3
STEPPED_DEPTHS = ("max_wear_depth_moving_um", "max_wear_depth_stationary_um", "centre_wear_depth_stationary_um")


class States:
    def __init__(self):
        self.states = {}

    def on_step(self, setup, step):
        if step.is_snapshot:
            self.states[step.cycle] = (step.wear_moving.copy(), step.wear_stationary.copy(), step.pressure.copy())


@functools.lru_cache(maxsize=None)
def states_of(name: str, *overrides: str):
    setup, _, _ = prepare(load_case(CASES / f"{name}.yaml", list(overrides)))
    obs = States()
    simulate(setup, (obs,))
    return obs.states


def worst_errors(name: str, *overrides: str, reference=("jumping.scheme=linear", "jumping.linear=1")):
    ref, got = states_of(name, *overrides, *reference), states_of(name, *overrides)
    depth = pressure = p0 = 0.0
    for c, (hm_r, hs_r, p_r) in ref.items():
        if c == 0:
            continue
        hm, hs, p = got[c]
        depth = max(depth, abs(hm.max() / hm_r.max() - 1), abs(hs.max() / hs_r.max() - 1))
        pressure = max(pressure, float(np.linalg.norm(p - p_r) / np.linalg.norm(p_r)))
        row, col = p_r.shape[0] // 2, p_r.shape[1] // 2
        p0 = max(p0, abs(p[row, col] / p_r[row, col] - 1))
    return depth, pressure, p0


@pytest.mark.parametrize("cycles", [10, 100, 2000])
def test_default_steps_match_the_exact_per_cycle_model_at_every_recorded_state(cycles):
    depth, pressure, p0 = worst_errors("mccoll_185N", "model.dimension=2d", f"loading.cycles={cycles}",
                                       "output.snapshots=auto")
    assert depth <= DEPTH and pressure <= PRESSURE and p0 <= P0, (depth, pressure, p0)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["mccoll_185N", "mccoll_500N_10um"])
def test_default_steps_match_the_exact_model_over_a_whole_case(name):
    depth, pressure, p0 = worst_errors(name, "model.dimension=2d")
    assert depth <= DEPTH and pressure <= PRESSURE and p0 <= P0, (depth, pressure, p0)


def test_bdf2_is_more_accurate_than_backward_euler_at_a_third_of_the_tolerance_with_half_the_solves():
    # BDF2's order is verified on polynomials in test_jumping.py; in the loop, the contact front's
    # non-smoothness and the landing on recorded states blur a fixed-step order study, so the claim that
    # matters is compared directly: accuracy per solve against the exact model (measured: 47 vs 163 solves)
    base = ("model.dimension=2d", "loading.cycles=2000", "output.snapshots=auto")
    solves = {}
    errors = {}
    for scheme, tol in (("bdf2", 0.01), ("implicit", 0.01 / 3)):
        overrides = (*base, f"jumping.scheme={scheme}", f"jumping.tolerance={tol}")
        solves[scheme] = run(load_case(CASES / "mccoll_185N.yaml", list(overrides))).summary["contact_solves"]
        errors[scheme] = worst_errors("mccoll_185N", *overrides)
    assert all(b <= e for b, e in zip(errors["bdf2"], errors["implicit"])), errors
    assert solves["bdf2"] < 0.5 * solves["implicit"], solves


@pytest.mark.parametrize("body", ["moving", "stationary"])
@pytest.mark.parametrize("name", [n if n in KINDS else pytest.param(n, marks=pytest.mark.slow) for n in SHIPPED])
def test_either_body_with_a_zero_wear_coefficient_completes_with_the_default_scheme(name, body):
    cycles = load_case(CASES / f"{name}.yaml").loading.cycles
    cycles = min(cycles, LIMITED_CYCLES) if name in LIMITED else cycles
    out = run(load_case(CASES / f"{name}.yaml", [*quick(name, cycles), f"materials.{body}.wear_coefficient=0 1/MPa"]))
    assert out.status == "complete", out.message
    check_archard(out)  # the body without wear has none at all; the other its k·P·4δ·N (or within its bounds)
    # the paper's gap model is kept wherever it is stable on the grid, and replaced (with the reason) where not:
    # without wear of the moving body it is unstable whenever the stroke average has negative modes on the grid
    model = out.setup.cycle
    paper = wear_spectrum(out.setup.compliance, wear_operator(out.setup.grid, model.stroke, model.k_moving,
                                                              model.k_stationary, "mid_stroke"))
    assert model.gap_model == ("stroke_average" if paper.growth_rate > 0 else "mid_stroke")
    if body == "moving" and model.stroke > 1.5 * out.setup.grid.dx:
        assert model.gap_model == "stroke_average"


def test_the_papers_gap_model_forced_where_it_is_unstable_is_refused_with_advice_that_runs():
    overrides = ["model.dimension=2d", "materials.moving.wear_coefficient=0 1/MPa", "model.gap=mid_stroke"]
    with pytest.raises(CaseError, match="model.gap: auto") as info:
        prepare(load_case(CASES / "mccoll_185N.yaml", overrides))
    assert "unstable" in str(info.value)
    advice = [o for o in overrides if not o.startswith("model.gap")] + ["model.gap=auto"]
    assert run(load_case(CASES / "mccoll_185N.yaml", advice)).status == "complete"


# explicit jumps are first order: their depths against the exact per-cycle run measured ≤ 6.5e-4 on the line
# contacts (kirk_450N_200Hz at 0.99 of its limit) and 1.5e-3 on the partial-slip ball, whose 300 cycles are a
# single jump; a jump that let a mode grow, or a wrong update, is off by far more.  The partial-slip cylinder of
# ti_fretting_fatigue, whose worn stick edge changes fast, is off by 9.8e-6 per cycle of jump (2.0e-3 at 0.99 of its
# limit, linear in the jump from 26 to 208): beyond the bound a case must show that first order (half the jump,
# half the error), which an instability, growing with the steps taken, does not
LINEAR_DEPTH = 2e-3


@pytest.mark.parametrize("name", [n if n in KINDS else pytest.param(n, marks=pytest.mark.slow) for n in SHIPPED])
def test_linear_jumps_below_the_computed_limit_are_stable_and_meet_the_per_cycle_run(name):
    """Jumps of 0.5, 0.9 and 0.99 of the computed limit, up to 4000 cycles (an instability shows within a few hundred
    steps; whole cases in the slow suite): each completes, keeps Archard's volume (summed from its fields), and its
    depths meet the exact per-cycle run's (linear jumps of one cycle) to a first-order scheme's error."""
    case = load_case(CASES / f"{name}.yaml", quick(name, 4000))
    limit = prepare(case)[0].stability_limit
    linear = [*quick(name, 4000), "jumping.scheme=linear"]
    if limit < 1:  # no whole cycle is below the limit (the 90 °C tube in service, 80 µm stroke): refused, said so
        with pytest.raises(CaseError, match="exceeds the explicit stability limit"):
            run(load_case(CASES / f"{name}.yaml", [*linear, "jumping.linear=1"]))
        return
    exact = run(load_case(CASES / f"{name}.yaml", [*linear, "jumping.linear=1"]))
    check_archard(exact)
    jumps = sorted({max(1, int(fraction * limit)) for fraction in (0.5, 0.9, 0.99)} - {1})  # 1: the exact run
    for jump in jumps:
        out = run(load_case(CASES / f"{name}.yaml", [*linear, f"jumping.linear={jump}"]))
        assert out.status == "complete", out.message
        assert out.setup.linear_jump == jump < limit
        check_archard(out)
        worst = max(abs(out.summary[k] / exact.summary[k] - 1) for k in STEPPED_DEPTHS)
        if worst > LINEAR_DEPTH:  # beyond the bound measured on the other cases: it must still be first order
            half = run(load_case(CASES / f"{name}.yaml", [*linear, f"jumping.linear={jump // 2}"]))
            worst_half = max(abs(half.summary[k] / exact.summary[k] - 1) for k in STEPPED_DEPTHS)
            assert 1.8 <= worst / worst_half * (jump // 2) / (jump / 2) <= 2.2, (jump, worst, worst_half)


@pytest.mark.slow
@pytest.mark.parametrize("fraction", [0.5, 0.9, 0.99])
@pytest.mark.parametrize("name", sorted(set(SHIPPED) - LIMITED))  # a service case's 10⁹ cycles in linear jumps of
#                                                                    a few hundred would be millions of solves
def test_linear_jumps_below_the_computed_limit_complete_whole_cases(name, fraction):
    dim = [] if name in POINT else ["model.dimension=2d"]
    limit = prepare(load_case(CASES / f"{name}.yaml", dim))[0].stability_limit
    linear = [*dim, "jumping.scheme=linear", f"jumping.linear={max(1, int(fraction * limit))}"]
    if limit < 1:  # no whole cycle is below the limit (the wire rope's 0.68 µm elements: 0.94 cycles): refused
        with pytest.raises(CaseError, match="exceeds the explicit stability limit"):
            run(load_case(CASES / f"{name}.yaml", linear))
        return
    out = run(load_case(CASES / f"{name}.yaml", linear))
    assert out.status == "complete", out.message


def test_a_linear_jump_above_the_limit_is_refused_and_the_advised_jump_runs():
    case = ["model.dimension=2d", "loading.cycles=3000"]
    limit = prepare(load_case(CASES / "mccoll_185N.yaml", case))[0].stability_limit
    with pytest.raises(CaseError) as info:
        prepare(load_case(CASES / "mccoll_185N.yaml", [*case, f"jumping.linear={int(1.2 * limit)}"]))
    text = str(info.value)
    assert f"stability limit {limit:.4g}" in text
    advised = int(text.split("Use at most ")[1].split()[0])
    assert run(load_case(CASES / "mccoll_185N.yaml", [*case, f"jumping.linear={advised}"])).status == "complete"


def test_an_unstable_linear_jump_forced_through_is_caught_by_its_growth():
    case = load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=20000"])
    limit = prepare(case)[0].stability_limit
    setup, _, _ = prepare(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=20000",
                                                                  "jumping.scheme=linear",
                                                                  f"jumping.linear={int(1.2 * limit)}"]),
                          allow_unstable=True)
    from fretsim.simulate import NumericalFailure
    with pytest.raises(NumericalFailure, match="checkerboards") as info:
        simulate(setup)
    assert info.value.cycle < 20000


@pytest.mark.parametrize("name", ["mccoll_1670N", pytest.param("mccoll_185N", marks=pytest.mark.slow),
                                  pytest.param("kirk_450N_20Hz", marks=pytest.mark.slow)])
def test_the_papers_adaptive_jumping_on_the_default_grid_keeps_the_volume_and_meets_the_default_steps(name):
    """The paper's adaptive jumps (its defaults, its preset, and with ΔN_L = 10) on the default grid: the Taylor
    extrapolation keeps Archard's volume (summed from the fields), and the depths and the width land where the
    default BDF2 steps do, within issue #9's depth target DEPTH (measured ≤ 6e-5; BDF2 itself is within 3e-5 of
    the per-cycle run on mccoll_1670N)."""
    cycles = ["loading.cycles=30000"] if name.startswith("kirk") else []
    default = run(load_case(CASES / f"{name}.yaml", ["model.dimension=2d", *cycles])).summary
    for jumping in (["jumping.scheme=adaptive"], ["jumping.preset=paper"], ["jumping.scheme=adaptive",
                                                                            "jumping.linear=10"]):
        out = run(load_case(CASES / f"{name}.yaml", ["model.dimension=2d", *cycles, *jumping]))
        assert out.status == "complete", out.message
        assert out.case.scheme == "adaptive" and out.summary["cycles"] == default["cycles"]
        check_archard(out)  # the Taylor extrapolation conserves volume: summed from the fields, k·P·4δ·N
        for key in (*STEPPED_DEPTHS, "scar_width_stationary_mm"):
            assert out.summary[key] == pytest.approx(default[key], rel=DEPTH), (jumping, key)


def test_paper_preset_is_scaled_to_the_grids_limit_and_says_so():
    out = run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "jumping.preset=paper", "grid.rule=paper"]))
    choice = next(c for c in out.plan.choices if c.key == "jumping.linear")
    assert out.setup.linear_jump < 55 < out.setup.stability_limit * 2 and "exceeds this grid's" in choice.reason


def test_the_papers_adaptive_jumps_beyond_the_stability_limit_are_capped_and_then_meet_the_per_cycle_run():
    """McColl 1670 N in 2D with the paper's preset: ΔN_max 600 against an explicit limit of 159.  The jumps are
    explicit, so each multiplies the grid-scale wear modes 6.6-fold; the linear steps between damp them, the run
    stays bounded and its depth good (1e-4), but the pressure after a jump rings at the contact's edges
    (272/98/207/140 MPa) and the final field was 8 % (L2) from the per-cycle run, with nothing said.  The plan
    now caps ΔN_max at the limit and says why (measured 0.25 %); uncapped (a study of the instability, API only)
    it still reproduces the 8 %."""
    ov = ["model.dimension=2d", "jumping.scheme=adaptive", "jumping.preset=paper", "grid.rule=paper"]
    exact = run(load_case(CASES / "mccoll_1670N.yaml", ["model.dimension=2d", "jumping.scheme=linear",
                                                        "jumping.linear=1", "grid.rule=paper"]))
    capped = run(load_case(CASES / "mccoll_1670N.yaml", ov))
    choice = next(c for c in capped.plan.choices if c.key == "jumping.max")
    assert capped.setup.max_jump <= capped.setup.stability_limit and "capped at the explicit stability" in choice.reason
    setup, _, _ = prepare(load_case(CASES / "mccoll_1670N.yaml", ov), allow_unstable=True)
    assert setup.max_jump == 600
    last = simulate(setup)
    l2 = lambda p: float(np.linalg.norm(p - exact.last.pressure) / np.linalg.norm(exact.last.pressure))  # noqa
    assert l2(last.pressure) > 0.04  # measured 8.3 %: the ringing this test is about
    assert l2(capped.last.pressure) < 0.01  # measured 0.25 %: a stepping error, within the default tolerance


def test_solves_grow_logarithmically_with_cycles():
    counts = [run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", f"loading.cycles={n}",
                                                         f"output.snapshots=[{n}]"])).summary["contact_solves"]
              for n in (2000, 20000, 200000)]
    steps = np.diff(counts)
    assert steps[1] <= 1.3 * steps[0], counts  # the same few dozen solves per decade of cycles


@pytest.fixture(scope="module")
def exact_3d_start():
    """McColl 185 N in 3D (paper grid, 33 × 27), its first 100 cycles one by one: the exact model."""
    return run(load_case(CASES / "mccoll_185N.yaml", [*START_3D, "jumping.scheme=linear", "jumping.linear=1"]))


START_3D = ("model.dimension=3d", "model.slip=uniform", "grid.rule=paper", "grid.error_estimate=none",
            "loading.cycles=100", "output.snapshots=[0, 100]")


@pytest.mark.parametrize("scheme", ["bdf2", "implicit", "linear"])
def test_the_stepping_depth_estimate_is_the_size_of_the_depth_error_in_3d(exact_3d_start, scheme):
    """The summary's error_estimate_depth is the relative error of the reported depths.  It was the accumulated
    error of the deepest element over the L2 norm of the whole depth field, √(elements in contact) too small in 3D:
    BDF2 reported 3.2e-5 for a depth 7.8e-4 off the exact run.  Measured now: BDF2 8.6e-4 against 8.6e-4, backward
    Euler 5.6e-3 against 3.5e-3, linear jumps 3.9e-2 against 2.1e-2.  Bounds: at least half the error (the
    tests' rule for an estimate of the right size: a local-error estimate is not a bound) and at most 5× (an
    estimate, not a blanket)."""
    s, ref = run(load_case(CASES / "mccoll_185N.yaml", [*START_3D, f"jumping.scheme={scheme}"])).summary, \
        exact_3d_start.summary
    error = max(abs(s[k] / ref[k] - 1) for k in ("centre_wear_depth_stationary_um", "max_wear_depth_stationary_um",
                                                 "max_wear_depth_moving_um"))
    assert 0.5 * error <= s["error_estimate_depth"] <= 5.0 * error, (error, s["error_estimate_depth"])


def test_results_carry_the_runs_error_estimates(tmp_path):
    from fretsim.results import read_results
    run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=2000"]), tmp_path / "r.h5")
    res = read_results(tmp_path / "r.h5")
    assert 0 < res.summary["error_estimate_depth"] < 0.1 and 0 < res.summary["error_estimate_pressure"] < 0.1
    assert res.history["error_estimate_pressure"].shape == res.history["cycle"].shape


# --- refinement (Eqs. 11-12) -----------------------------------------------------------------------------------------

def test_refinement_keeps_load_and_wear_volume_and_meets_the_papers_10pct_mape():
    fine_op, fine_gap = cylinder_problem(40, 27, half_width=0.126)
    coarse_op, coarse_gap = cylinder_problem(16, 10, half_width=0.126)  # 15.75 µm × 1000 µm, paper Fig. 10
    p_fine = solve(fine_op, fine_gap, 185.0).pressure
    p_ref = refine_pressure(solve(coarse_op, coarse_gap, 185.0).pressure, coarse_op.grid, fine_op.grid)
    assert p_ref.sum() * fine_op.grid.area == pytest.approx(185.0, rel=1e-12)
    assert mape(p_fine, p_ref) < 10.0  # the paper's coarse-grid criterion (Fig. 9)
    h = np.random.default_rng(3).random(fine_op.grid.shape)
    assert coarsen(h, fine_op.grid, coarse_op.grid).sum() * coarse_op.grid.area == pytest.approx(
        h.sum() * fine_op.grid.area, rel=1e-12)


def test_refined_run_agrees_with_the_fine_run():
    base = ("model.dimension=2d", "loading.cycles=10000", "output.snapshots=[10000]")
    fine = run(load_case(CASES / "mccoll_185N.yaml", list(base)))
    coarse = run(load_case(CASES / "mccoll_185N.yaml", [*base, "grid.coarse_element=[15.75 um]"]))
    assert coarse.summary["centre_wear_depth_stationary_um"] == pytest.approx(
        fine.summary["centre_wear_depth_stationary_um"], rel=0.01)
    assert abs(coarse.summary["scar_width_stationary_mm"] - fine.summary["scar_width_stationary_mm"]) < 0.03
