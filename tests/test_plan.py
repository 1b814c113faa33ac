"""The planner's stages, each on its own: what it decides, what it refuses, what it warns of.  No run is made here
except where a stage's own proxies are the point (the side runs' keeping)."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from fretsim.api import run
from fretsim.case import CaseError, load_case
from fretsim.plan import SideRuns, cost, cycle, grid, inputs, model, prepare, stepping
from fretsim.plan.choices import Plan

CASES = Path(__file__).resolve().parent.parent / "cases"
MCCOLL = CASES / "mccoll_185N.yaml"
TWO_D = ["model.dimension=2d", "model.corrections=none"]


def _case(*overrides, path=MCCOLL):
    return load_case(path, [*TWO_D, *overrides])


# --- inputs -------------------------------------------------------------------------------------------------------

def test_inputs_refuse_a_stroke_of_sixty_contact_widths_and_a_contact_past_half_the_radius():
    # a stroke in mm where µm were meant; a load in MN where N were
    with pytest.raises(CaseError) as err:
        inputs.contact(_case("loading.stroke=5 mm"), Plan())
    a = math.sqrt(4 * 185.0 * 6.0 / (math.pi * 2.0e5 / (2 * (1 - 0.3**2)) * 10.0))  # Hertz line contact, 0.0359 mm
    assert err.value.problems[0][0] == "loading.stroke" and f"{5 / a:.0f} times the Hertz contact" in str(err.value)
    with pytest.raises(CaseError) as err:
        inputs.contact(_case("loading.normal_load=2 MN"), Plan())
    assert err.value.problems[0][0] == "loading.normal_load" and "half the body's radius" in str(err.value)


def test_inputs_warn_past_the_onset_of_yield_and_tighten_the_stepping_for_a_pressure_target():
    plan = Plan()
    c = inputs.contact(_case("materials.moving.yield_strength=150 MPa"), plan)
    # the McColl 185 N line contact: p0 = 2P/(πaL) = 328 MPa, past the onset of yield at 1.79 σ_y = 269 MPa
    assert c.hertz.peak_pressure == pytest.approx(2 * 185.0 / (math.pi * c.hertz.half_width_x * 10.0), rel=1e-12)
    assert [w for w in plan.warnings if "onset of yield in the moving body" in w]
    plan = Plan()
    tightened = inputs.tighten_for_pressure(_case("model.pressure_accuracy=5 %"), plan)
    assert tightened.step_tolerance == pytest.approx(0.005) and plan.choices[0].key == "jumping.tolerance"
    assert inputs.tighten_for_pressure(_case(), Plan()).step_tolerance == 0.01  # no target: unchanged


# --- grid ---------------------------------------------------------------------------------------------------------

def test_grid_holds_the_scar_and_the_stroke_at_the_accuracy_rule_and_records_the_states():
    case = _case("loading.cycles=1000", "output.snapshots=auto")
    plan = Plan()
    c = inputs.contact(case, plan)
    g = grid.build(case, plan, c, "2d", 1000, 1.0)
    a = c.hertz.half_width_x
    assert g.grid.dx <= 7 * a / 40 * (1 + 1e-12)  # never coarser than the paper's rule
    assert g.domain[0] / 2 > g.sizing.scar_half_width + case.loading.peak_stroke  # the scar and the stroke fit
    assert g.snapshots == (0, 250, 500, 750, 1000)
    assert [ch.key for ch in plan.choices] == ["grid.domain", "grid.elements", "output.snapshots"]


def test_a_limited_runs_automatic_states_are_quarters_of_its_predicted_stop_else_decades_and_always_n():
    """With wear limits loading.cycles is an upper bound: the states go on the way to the pilot's stop (N kept,
    should the run get there); to N where the pilot reached no limit; at the decades where nothing predicts it."""
    limited = _case("loading.cycles=1000000", "output.snapshots=auto", "limits.max_wear_depth_stationary=1 um")
    to_stop = grid.choose_snapshots(limited, 12_345.4)
    assert to_stop.value == (0, 3086, 6172, 9258, 1_000_000)
    assert "S = 12,345 cycles" in to_stop.reason and "pilot" in to_stop.reason
    assert grid.choose_snapshots(limited, math.inf).value == (0, 250_000, 500_000, 750_000, 1_000_000)
    unknown = grid.choose_snapshots(limited, None)
    assert unknown.value == (0, 10, 100, 1000, 10_000, 100_000, 1_000_000) and "decades" in unknown.reason
    no_limit = _case("loading.cycles=1000", "output.snapshots=auto")
    assert grid.choose_snapshots(no_limit, 200.0).value == (0, 250, 500, 750, 1000)  # a prediction needs a limit


def test_grid_keeps_the_automatic_element_over_a_given_domain_and_refuses_a_domain_shorter_than_the_stroke():
    case = _case("loading.cycles=1000")
    c = inputs.contact(case, Plan())
    auto = grid.build(case, Plan(), c, "2d", 1000, 1.0)
    given = grid.build(_case("loading.cycles=1000", f"grid.domain=[{2 * auto.domain[0]} mm]"), Plan(), c, "2d",
                       1000, 1.0)
    assert given.grid.dx == pytest.approx(auto.grid.dx, rel=0.01)  # the same element, odd counts rounded
    with pytest.raises(CaseError, match="no room for the stroke"):
        grid.build(_case("grid.domain=[0.06 mm]", "grid.elements=[7]"), Plan(), c, "2d", 1000, 1.0)


def test_partial_slip_refinement_resolves_the_stick_zone_and_the_annulus_by_mindlins_radius():
    case = _case("loading.friction_coefficient=0.9", "loading.stroke=0.5 um")
    a, dx, transition = 0.1, 0.1 * 7 / 40, 1e-3
    refine = grid.partial_slip_refinement(case, "coulomb", transition, a, dx)
    c_over_a = math.sqrt(1 - 0.5e-3 / transition)  # c/a = √(1 − δ/δ_t)
    narrowest = min(c_over_a, 1 - c_over_a) * a
    assert refine == pytest.approx(grid.PARTIAL_SLIP_ELEMENTS * dx / narrowest, rel=1e-12)
    assert grid.partial_slip_refinement(case, "uniform", transition, a, dx) == 1.0  # the paper's member: no stick
    assert grid.partial_slip_refinement(case, "coulomb", 1e-4, a, dx) == 1.0  # far above δ_t: gross slip


# --- model --------------------------------------------------------------------------------------------------------

def test_gap_model_is_the_papers_where_stable_and_the_stroke_average_where_the_moving_body_does_not_wear():
    case = _case()
    g = grid.build(case, Plan(), inputs.contact(case, Plan()), "2d", case.loading.cycles, 1.0).grid
    assert model.choose_gap_model(case, g).value == "mid_stroke"
    still = _case("materials.moving.wear_coefficient=0 1/MPa")
    choice = model.choose_gap_model(still, g)
    assert choice.value == "stroke_average" and "unstable" in choice.reason


def test_a_correction_that_does_not_apply_is_refused_with_what_does():
    case = load_case(CASES / "tube_RT.yaml", ["model.dimension=2d", "model.corrections=[free_faces]"])
    with pytest.raises(CaseError) as err:
        model.choose_corrections(case, True, SideRuns(), prepare)
    assert "free_faces does not apply" in str(err.value) and "available: ring_bending" in str(err.value)


# --- cycle --------------------------------------------------------------------------------------------------------

def test_the_regime_picks_coulomb_in_partial_slip_refuses_uniform_there_and_keeps_uniform_far_above():
    partial = _case("loading.friction_coefficient=0.9", "loading.stroke=0.3 um")
    block = partial.loading.blocks[0]
    assert cycle.choose_slip(partial, block, 0.6e-3).value == "coulomb"
    with pytest.raises(CaseError, match="uniform slip is refused here"):
        cycle.choose_slip(_case("loading.friction_coefficient=0.9", "loading.stroke=0.3 um", "model.slip=uniform"),
                          block, 0.6e-3)
    far = _case("loading.friction_coefficient=0.9")
    choice = cycle.choose_slip(far, far.loading.blocks[0], 0.1e-3)  # δ_t/δ = 0.4 %: within model.accuracy 1 %
    assert choice.value == "uniform" and choice.error == pytest.approx(0.1e-3 / 0.025)
    near = cycle.choose_slip(far, far.loading.blocks[0], 0.5e-3)  # 2 %: more than model.accuracy
    assert near.value == "coulomb" and near.error == 0.0


def test_a_history_is_judged_on_its_block_nearest_partial_slip():
    case = _case("loading.friction_coefficient=0.9", "loading.cycles=null",
                 "loading.blocks=[{normal_load: 185 N, stroke: 25 um, cycles: 10}, "
                 "{normal_load: 185 N, stroke: 2 um, cycles: 10}]", "loading.normal_load=null", "loading.stroke=null")
    g = grid.build(case, Plan(), inputs.contact(case, Plan()), "2d", 20, 1.0)
    operators = model.build(case, Plan(), g, inputs.contact(case, Plan()).e_star, case, SideRuns(), prepare)
    regime = cycle.regime(case, g.grid, operators.compliance)
    assert regime.block.stroke == pytest.approx(0.002) and regime.transition > 0


# --- stepping -----------------------------------------------------------------------------------------------------

def test_a_short_run_steps_one_cycle_at_a_time_and_an_explicit_jump_past_the_limit_is_refused():
    setup, filled, plan = prepare(_case("loading.cycles=6"))
    assert (filled.scheme, filled.linear_jump) == ("linear", 1)
    setup, _, _ = prepare(_case("jumping.scheme=linear"))
    with pytest.raises(CaseError, match="exceeds the explicit stability limit"):
        prepare(_case("jumping.scheme=linear", f"jumping.linear={int(setup.stability_limit) + 1}"))


def test_the_adaptive_schemes_largest_jump_is_capped_at_the_stability_limit():
    setup, filled, plan = prepare(_case("jumping.scheme=adaptive"))
    limit = setup.stability_limit
    assert filled.max_jump == max(filled.linear_jump, int(limit)) < 600
    assert "600 capped at the explicit stability limit" in dict((c.key, c.reason) for c in plan.choices)["jumping.max"]


def test_a_historys_stability_limit_is_its_most_restrictive_blocks():
    blocks = ("loading.blocks=[{normal_load: 185 N, stroke: 10 um, cycles: 100}, "
              "{normal_load: 185 N, stroke: 25 um, cycles: 100}]")
    history, _, _ = prepare(_case(blocks, "loading.cycles=null", "loading.normal_load=null", "loading.stroke=null",
                                  "grid.domain=[1.2 mm]", "grid.elements=[241]"))
    single = {s: prepare(_case(f"loading.stroke={s} um", "loading.cycles=200", "grid.domain=[1.2 mm]",
                               "grid.elements=[241]"))[0].stability_limit for s in (10, 25)}
    assert single[25] < single[10]  # the longer stroke wears faster per cycle: the lower limit
    assert history.stability_limit == single[25]


# --- cost ---------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("scheme", [
    "bdf2", "implicit", "linear",
    pytest.param("adaptive", marks=pytest.mark.xfail(strict=True, reason="measured 7-9× more solves than estimated on "
                                                                         "the accuracy grid (ΔN_L 5): the estimate "
                                                                         "assumes the paper's coarser grid")),
])
def test_the_solves_estimate_is_within_a_factor_two_of_the_run(scheme):
    # what `check` and the progress bar promise: measured 0.61-0.74 (BDF2), 1.4-1.5 (backward Euler), 1.0 (linear)
    for cycles in (2000, 18000):
        out = run(load_case(MCCOLL, [*TWO_D, f"loading.cycles={cycles}", "grid.error_estimate=none",
                                     f"jumping.scheme={scheme}"]))
        ratio = out.summary["contact_solves"] / cost.estimate_solves(out.setup)
        assert 0.5 <= ratio <= 2.0, (cycles, ratio)
    assert cost.estimate_solves(prepare(_case("loading.cycles=0"))[0]) == 1  # the contact alone: one solve


# --- the runs planning makes besides the run ----------------------------------------------------------------------

def test_proxies_are_kept_by_whoever_passes_the_side_runs_and_by_nobody_else():
    case = load_case(MCCOLL, ["loading.cycles=300", "model.dimension=auto", "grid.error_estimate=none"])
    said: list = []
    runs = SideRuns(announce=said.append)
    prepare(case, runs=runs)
    first = len(said)
    assert first == 2 and all(s.startswith("model.dimension auto") for s in said), said  # a 2D and a 3D proxy
    prepare(case, runs=runs)
    assert len(said) == first  # kept: not run again
    again: list = []
    prepare(case, runs=SideRuns(announce=again.append))
    assert len(again) == first  # a new keeping runs them again: nothing was left behind at module level


def test_increments_auto_takes_five_for_a_resolved_gross_slip_stroke_and_nine_elsewhere():
    """model.increments auto: 5 where the stroke is resolved and every elastic side fits in one of them (McColl
    185 N: δ 25 µm, 37 δ_t; the measured table in scripts/results/resolved_increments_auto.txt); 9 for a resolved
    stroke near or in partial slip (δ 1 µm on the same contact), 9 at mid-stroke, a given number as given; the
    filled case carries the choice, so that the run resumes with it."""
    mu = ["loading.friction_coefficient=0.9", "model.slip=coulomb", "model.dimension=2d"]

    def chosen(*sets):
        _, filled, plan = prepare(_case(*mu, *sets))
        choice = next(c for c in plan.choices if c.key == "model.increments")
        assert filled.increments == choice.value
        return choice.value

    assert chosen("model.stroke=resolved") == 5
    assert chosen("model.stroke=resolved", "loading.stroke=3 um") == 9  # (δ_t 0.67 µm: 4.5 δ_t)
    assert chosen("model.stroke=resolved", "loading.stroke=3.5 um") == 5  # (5.2 δ_t)
    assert chosen("model.stroke=mid_stroke") == 9
    assert chosen("model.stroke=resolved", "model.increments=7") == 7
    # fatigue samples its stress history at the increments: 9 in gross slip too (the Ti-6Al-4V case at 40 µm had
    # its Miner's sum 32 % low at 5 against 27, 2.6 % at 9)
    _, filled, _ = prepare(load_case(CASES / "ti_fretting_fatigue.yaml", ["model.stroke=resolved",
                                                                          "loading.stroke=40 um"]))
    assert filled.increments == 9
