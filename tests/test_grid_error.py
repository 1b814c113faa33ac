"""The reported error estimates cover the grid: honest against runs on much finer grids, sized to model.accuracy."""
import functools
import math
from pathlib import Path

import numpy as np
import pytest

from fretsim.api import load_case, run
from fretsim.grid_error import companion_case
from fretsim.sizing import MAX_ACCURACY_REFINEMENT

CASES = Path(__file__).resolve().parents[1] / "cases"
DEPTHS = ("max_wear_depth_moving_um", "max_wear_depth_stationary_um")
WIDTHS = ("scar_width_moving_mm", "scar_width_stationary_mm")


def _on(p, x, xf):
    return np.stack([np.interp(xf, x, row) for row in np.atleast_2d(p)])


def _finer(name, out, factor, extra=()):
    """The same case on the same domain with ``factor`` times the elements along x, stepping tightened 10×."""
    f = out.case
    elements = [int(f.elements[0] * factor) | 1] + list(f.elements[1:])
    ov = ["model.dimension=2d", f"jumping.tolerance={f.step_tolerance / 10}",
          f"grid.domain=[{', '.join(f'{d!r} mm' for d in f.domain)}]",
          f"grid.elements=[{', '.join(map(str, elements))}]", *extra]
    return run(load_case(CASES / f"{name}.yaml", ov))


# under pytest-xdist the module runs on one worker: the depth and the pressure tests share each case's runs
pytestmark = pytest.mark.xdist_group("test_grid_error")


@functools.lru_cache(maxsize=None)
def _default_and_reference(name):
    out = run(load_case(CASES / f"{name}.yaml", ["model.dimension=2d"]))
    return out, _finer(name, out, 4)


@pytest.mark.parametrize("name", ["mccoll_185N", "mccoll_500N_10um", "mccoll_1670N", "kirk_450N_20Hz"])
def test_default_depths_and_widths_meet_the_accuracy_and_their_estimates_cover_their_errors(name):
    """Against the same case on a grid 4× finer (and 10× tighter stepping): the depths and widths within
    model.accuracy (1 %), and each estimate at least the error it estimates.  The reference has errors of its
    own, about a quarter to a sixteenth of the default's (widths and depths converge as h to h²; the study
    script's runs 32× finer say the same), which is why the bound is the estimate itself and not a fraction."""
    out, ref = _default_and_reference(name)
    s, r = out.summary, ref.summary
    depth = max(abs(s[k] / r[k] - 1) for k in DEPTHS)
    width = max(abs(s[k] / r[k] - 1) for k in WIDTHS)
    assert depth <= out.case.accuracy and width <= out.case.accuracy, (depth, width)
    assert depth <= s["estimated_error_depth"], (depth, s["estimated_error_depth"])
    assert width <= s["estimated_error_width"], (width, s["estimated_error_width"])
    assert s["estimated_error_depth"] >= s["error_estimate_depth"]  # the totals include the stepping's part


@pytest.mark.parametrize("name", ["mccoll_185N", "mccoll_500N_10um", "mccoll_1670N", "kirk_450N_20Hz"])
def test_the_pressure_fields_and_peaks_estimates_cover_their_errors(name):
    out, ref = _default_and_reference(name)
    s, r = out.summary, ref.summary
    pr = _on(ref.last.pressure, ref.setup.grid.x, out.setup.grid.x)
    pressure = float(np.linalg.norm(out.last.pressure - pr) / np.linalg.norm(pr))
    peak = abs(s["max_pressure_MPa"] / r["max_pressure_MPa"] - 1)
    assert pressure <= s["estimated_error_pressure"], (pressure, s["estimated_error_pressure"])
    assert peak <= s["estimated_error_max_pressure"], (peak, s["estimated_error_max_pressure"])
    assert s["estimated_error_pressure"] >= s["error_estimate_pressure"]


def test_a_peak_that_is_not_converging_is_seen_on_three_grids_and_said():
    """McColl 1670 N in 2D: its peak is 233, 209, 217 MPa on grids 4×, 2× and 1× the default element and ~265 MPa
    converged; two grids alone read 10 % against the 22 % it is off.  The third grid sees the differences change
    sign, the estimate takes the larger, and a note says it is a scale."""
    out = run(load_case(CASES / "mccoll_1670N.yaml", ["model.dimension=2d"]))
    assert any("not yet converging" in n for n in out.notes)
    assert out.summary["estimated_error_max_pressure"] > 0.2


def test_a_converging_peak_is_read_from_the_nearer_difference_and_a_wandering_one_from_the_larger():
    from fretsim.grid_error import SQRT_H, peak_estimate
    est, ok = peak_estimate(100.0, 104.0, 110.0)  # differences 4 then 6: one sign, shrinking by 1.5 ≥ √2
    assert ok and est == pytest.approx(SQRT_H * 0.04)
    est, ok = peak_estimate(100.0, 96.0, 110.0)  # the sign changes
    assert not ok and est == pytest.approx(SQRT_H * 0.14)
    est, ok = peak_estimate(100.0, 104.0, 109.0)  # one sign, but shrinking by only 1.25: not yet asymptotic
    assert not ok and est == pytest.approx(SQRT_H * 0.05)


def test_the_papers_grid_reads_its_widths_within_an_element_and_its_estimate_covers_them():
    """McColl 1670 N in 2D at the paper's 7a/40 (dx/W ≈ 1.8 %), against 8× finer: the chord reading of the
    crossing was 1.8 % off, the sub-element reading is within an element (measured 0.68 %) and closer than the
    chord on both bodies; the estimate covers the error and, being over model.accuracy, is said."""
    from conftest import chord_width as _chord_width
    from fretsim.measures import centre_line
    out = run(load_case(CASES / "mccoll_1670N.yaml", ["model.dimension=2d", "grid.rule=paper"]))
    ref = _finer("mccoll_1670N", out, 8)
    x, xr = out.setup.grid.x, ref.setup.grid.x
    for body, key in (("wear_stationary", "scar_width_stationary_mm"), ("wear_moving", "scar_width_moving_mm")):
        width, ref_width = out.summary[key], ref.summary[key]
        element = out.setup.grid.dx / width
        error = abs(width / ref_width - 1)
        chord = abs(_chord_width(centre_line(getattr(out.last, body)), x)
                    / _chord_width(centre_line(getattr(ref.last, body)), xr) - 1)
        assert error < element and error < chord, (body, error, element, chord)
        assert error <= out.summary["estimated_error_width"]
    assert out.summary["estimated_error_width"] > out.case.accuracy
    assert any("the scar widths" in n and "exceeds model.accuracy" in n for n in out.notes)


def test_the_accuracy_rule_sizes_the_element_by_the_scar_and_the_paper_rule_by_the_contact():
    acc = run_check("mccoll_185N", ["model.dimension=2d"])
    paper = run_check("mccoll_185N", ["model.dimension=2d", "grid.rule=paper"])
    dx_paper = paper[0].grid.dx
    assert acc[0].grid.dx < dx_paper / 2 and acc[0].grid.dx >= dx_paper / MAX_ACCURACY_REFINEMENT * (1 - 1e-9)
    reason = next(c.reason for c in acc[2].choices if c.key == "grid.elements")
    assert "grid.rule accuracy" in reason and "scar width" in reason
    loose = run_check("mccoll_185N", ["model.dimension=2d", "model.accuracy=0.2"])
    assert loose[0].grid.dx == pytest.approx(dx_paper)  # the paper's element is already a fine enough share


def run_check(name, ov):
    from fretsim.api import check
    return check(load_case(CASES / f"{name}.yaml", ov))


def test_the_companion_halves_the_elements_along_x_and_keeps_a_line_contacts_rows():
    line = run_check("mccoll_185N", ["model.dimension=3d"])[1]
    c = companion_case(line, True)
    assert c.elements[1] == line.elements[1] and abs(c.elements[0] - line.elements[0] / 2) <= 1.5
    ball = run_check("wire_rope", [])[1]
    c = companion_case(ball, False)
    assert all(abs(a - b / 2) <= 1.5 for a, b in zip(c.elements, ball.elements)) and c.grid_error == "none"


def test_without_the_companion_the_totals_are_not_given_and_the_text_says_so(tmp_path):
    from click.testing import CliRunner
    from fretsim.cli import main
    res = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", str(tmp_path / "r.h5"), "--set",
                                    "model.dimension=2d", "--set", "grid.error_estimate=none", "--quiet"])
    assert res.exit_code == 0, res.output
    assert "the grid's part not estimated" in res.output
    from fretsim.results import read_results
    s = read_results(tmp_path / "r.h5").summary
    assert math.isnan(s["estimated_error_width"]) and s["error_estimate_depth"] > 0


SHIPPED = sorted(p.stem for p in CASES.glob("*.yaml"))
# not the service cases: their fullest model (3D, ring bending, free faces, 7243 × 27 elements) over 10⁹ cycles is
# beyond this suite's budget, and at a wear limit the limited depth is pinned (the comparison would be of
# cycles_to_limit); their tube's 2D-against-3D choice is the shipped tube_RT's, which is checked here
UNLIMITED = [n for n in SHIPPED if not load_case(CASES / f"{n}.yaml").limits]


@pytest.mark.slow
@pytest.mark.parametrize("name", UNLIMITED)
def test_auto_keeps_its_promise_against_the_fullest_model_at_full_resolution(name):
    """Both keys on auto, against the fullest model (3D with every correction that applies) on the default grid:
    each reported depth and width within model.accuracy.  auto accepts a simpler model only where three times
    its proxy's difference is within the accuracy (a proxy at half the x resolution under-stated 2D's difference
    2.5× on mccoll_500N_10um), and the reported depth and width estimates carry that product."""
    from fretsim.plan import available_corrections
    # the wear without the fatigue, which changes no wear result (test_fatigue_loop) and is computed in 2D only
    wear = ["materials.stationary.fatigue=null"] if load_case(CASES / f"{name}.yaml").stationary.fatigue else []
    case = load_case(CASES / f"{name}.yaml", ["model.dimension=auto", "model.corrections=auto", *wear])
    chosen = run(case)
    full_case = load_case(CASES / f"{name}.yaml", ["model.dimension=3d", *wear])
    fullest = available_corrections(full_case, False)
    full = run(load_case(CASES / f"{name}.yaml", ["model.dimension=3d", *wear, "model.corrections="
                                                  + (f"[{', '.join(fullest)}]" if fullest else "none")]))
    if not chosen.summary["cycles"]:
        keys = ("max_pressure_MPa",)
    else:
        keys = DEPTHS + WIDTHS + ("centre_wear_depth_stationary_um",)
    diff = max(abs(chosen.summary[k] / full.summary[k] - 1) for k in keys if full.summary[k])
    assert diff <= case.accuracy, (diff, chosen.case.dimension, chosen.case.corrections)


@pytest.mark.parametrize("name", ["mccoll_185N", "mccoll_500N_10um"])
def test_pressure_accuracy_refines_the_grid_and_the_field_meets_it_with_an_honest_estimate(name):
    """model.pressure_accuracy 5 %: a grid finer than the default's, the stepping tightened to a tenth of it, and
    the final pressure field within 5 % (L2) of a run 4× finer at a tenth of the tolerance, its estimate covering
    that.  Measured (scripts/study_grid_error.py --pressure 0.05): 0.4 % actual against a 4.9-5.8 % estimate."""
    default = run(load_case(CASES / f"{name}.yaml", ["model.dimension=2d", "grid.error_estimate=none"]))
    out = run(load_case(CASES / f"{name}.yaml", ["model.dimension=2d", "model.pressure_accuracy=5 %"]))
    # 5 %/30 of the scar width against the default's 1 %/3: half the element, or less where the default is capped
    assert out.setup.grid.dx <= default.setup.grid.dx / 2 * (1 + 1e-9)
    assert out.case.step_tolerance == pytest.approx(0.005)
    ref = _finer(name, out, 4)
    pr = _on(ref.last.pressure, ref.setup.grid.x, out.setup.grid.x)
    pressure = float(np.linalg.norm(out.last.pressure - pr) / np.linalg.norm(pr))
    assert pressure <= 0.05
    assert pressure <= out.summary["estimated_error_pressure"], (pressure, out.summary["estimated_error_pressure"])


def test_a_pressure_accuracy_beyond_the_grids_cap_is_said_not_met():
    """1 % asks for an element under the cap's (16× the paper's along x): the run says which estimate is over."""
    out = run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "model.pressure_accuracy=1 %"]))
    assert out.summary["estimated_error_pressure"] > 0.01
    assert any("exceeds model.pressure_accuracy" in n for n in out.notes)
    assert any("capped at 16" in n for n in out.notes)


@pytest.mark.xfail(strict=True, reason="known gap (docs/verification.md, The scar width between element centres): "
                   "on the paper's grid, a partial-slip scar reads 1.5 elements wide on the run's grid and on its "
                   "companion's alike, so their difference does not see it")
def test_a_partial_slip_scars_width_on_the_papers_grid_is_covered_by_its_estimate():
    """Ti-6Al-4V cylinder on flat in partial slip, 100 cycles, 3 µm stroke, the paper's grid (refined 7a/40 ÷ 3 for
    the stick zone; no warning): the width is 5.7 % off against 16× the elements, estimated 3.85 %."""
    name = "ti_fretting_fatigue"
    sets = ["loading.cycles=100", "loading.stroke=3 um"]
    out = run(load_case(CASES / f"{name}.yaml", sets + ["grid.rule=paper"]))
    assert out.summary["stick_half_width_x_mm"] > 0  # partial slip
    f = out.case
    ref = run(load_case(CASES / f"{name}.yaml", sets + [
        "grid.error_estimate=none", f"grid.domain=[{f.domain[0]!r} mm]", f"grid.elements=[{int(f.elements[0] * 16) | 1}]"]))
    width = max(abs(out.summary[k] / ref.summary[k] - 1) for k in WIDTHS)
    assert width <= out.summary["estimated_error_width"], (width, out.summary["estimated_error_width"])


UNEQUAL = ("materials.moving.wear_coefficient=2.75e-9 1/MPa", "loading.friction_coefficient=1.2",
           "loading.stroke=8 um", "materials.stationary.fatigue=null", "loading.cycles=40000",
           "grid.domain=[1.292 mm]")


def test_a_run_whose_coarser_companion_breaks_down_is_estimated_from_a_finer_one_that_covers_the_converged_answer():
    """Ti-6Al-4V with the moving body wearing a tenth of the flat, μ 1.2, 8 µm (a stick zone of a few elements):
    on 494 elements the run completes, but its companion on 247 builds a checkerboard at the stick edge and stops.
    Before, the run's estimates were then NaN ("not estimated") while its depths were 34-39 % short of a grid 4-8×
    finer; now a companion twice as fine gives them.  The reference, 4× finer, is itself 3.7 % short of one 8× finer
    (moving body, measured: 0.1627 against 0.1687 µm), so the run's true error is up to 1.2× its difference to it:
    the estimate must cover that."""
    ti = CASES / "ti_fretting_fatigue.yaml"
    out = run(load_case(ti, [*UNEQUAL, "grid.elements=[494]"]))
    assert out.status == "complete"
    note = next(n for n in out.notes if "companion on a grid twice as fine" in n)
    assert "989 elements" in note and "checkerboards" in note and "exceeds model.accuracy" in note
    ref = run(load_case(ti, [*UNEQUAL, "grid.elements=[1977]", "grid.error_estimate=none"])).summary
    s = out.summary
    actual = max(abs(s[k] - ref[k]) / s[k] for k in DEPTHS)
    assert actual > 0.3  # (the run is far from converged: what makes the estimate matter)
    assert s["estimated_error_depth"] >= 1.2 * actual
    width = max(abs(s[k] - ref[k]) / s[k] for k in WIDTHS)
    assert s["estimated_error_width"] >= 1.2 * width
    assert s["estimated_error_pressure"] > 0 and math.isnan(s["estimated_error_max_pressure"])  # (partial slip)


def test_in_partial_slip_the_stick_edge_peaks_have_no_estimate_and_a_warning_says_why():
    """The shipped Ti-6Al-4V case in partial slip: its peak at the worn stick zone's edge read 2163, 2582, 3204 MPa
    on its three grids and 4804, 6914, 9436 MPa on grids 2×, 4× and 8× finer: an elastic singularity.  Its estimate
    was a finite 49 % (the spread of the three grids; 54-66 % off the finer ones, and no warning).  Three grids
    cannot tell (a second review: at 4 µm they read 1050, 1796, 2277 MPa, as if converging, while grids 2-8× finer
    read 3059, 4443, 6189), so in partial slip the peak is not estimated, and a warning, shown with --quiet too,
    says why."""
    from click.testing import CliRunner
    from fretsim.cli import main
    from fretsim.grid_error import stick_edge_peaks
    assert stick_edge_peaks({"regime": "partial_slip"}) and not stick_edge_peaks({"regime": "gross_slip"})
    with CliRunner().isolated_filesystem():
        res = CliRunner().invoke(main, ["run", str(CASES / "ti_fretting_fatigue.yaml"), "-o", "ti.h5", "--quiet"])
        assert res.exit_code == 0, res.output
        assert "warning: the peak pressure is not estimated (NaN): in partial slip" in res.output
        assert "its peak not estimated (partial slip: the stick zone's edge)" in res.output
        # the fatigue's point values there too (a second review: the SWT's peak doubled with each halving of the
        # element, 64.8, 137, 283 MPa, and Miner's sum rose 165, 223, 288, while their estimates read ~50 % and
        # 36 %); the crack cycle, set early, converges (within 3 % of grids 4× finer) and keeps its estimate
        assert "warning: the SWT parameter's peak and Miner's sum at the end are not estimated (NaN)" in res.output
        from fretsim.results import read_results
        s = read_results("ti.h5").summary
        assert math.isnan(s["estimated_error_max_pressure"]) and math.isfinite(s["estimated_error_pressure"])
        assert math.isnan(s["estimated_error_swt_max"]) and math.isnan(s["estimated_error_fatigue_damage"])
        assert 0 < s["estimated_error_cycles_to_crack"] < 0.2
        # a fully reversed cycle damages both edges alike: the crack's side is said to be either (a review saw
        # crack_location_x_mm change sign under refinement, |x| within 4 µm)
        assert "the flat's crack could start at either edge" in read_results("ti.h5").attrs["notes"]


def test_the_fatigue_peaks_are_read_as_the_peak_pressure_is_and_not_at_all_where_they_diverge():
    """The SWT's peak and Miner's sum at the end read from the plain companion difference were 15-25 % short where
    they converge slowly (Ti-6Al-4V at 6 µm, gross slip: the SWT 6.29 MPa, 18 % below grids 8× finer, estimated
    15.8 %); now as the peak pressure (√h over the nearer difference, 2.4× it), and NaN where in partial slip they
    are point values at the stick zone's edge."""
    from fretsim.grid_error import SQRT_H, fatigue_unestimated, fatigue_estimates
    fine = {"swt_max_MPa": 100.0, "fatigue_damage": 2.0, "cycles_to_crack_initiation": 1000.0,
            "error_estimate_depth": 0.001, "fatigue_states_error": 0.002, "regime": "gross_slip"}
    coarse = {**fine, "swt_max_MPa": 90.0, "fatigue_damage": 1.9, "cycles_to_crack_initiation": 1050.0}
    coarsest = {**fine, "swt_max_MPa": 75.0, "fatigue_damage": 1.7, "cycles_to_crack_initiation": 1100.0}
    est = fatigue_estimates(fine, coarse, coarsest=coarsest)  # 10 then 15: converging by 1.5 ≥ √2
    assert est["estimated_error_swt_max"] == pytest.approx(SQRT_H * 0.10)
    assert est["estimated_error_fatigue_damage"] == pytest.approx(SQRT_H * 0.05 + 0.001 + 0.002)
    assert est["estimated_error_cycles_to_crack"] == pytest.approx(0.05 + 0.001 + 0.002)
    assert not fatigue_unestimated(fine, coarse, coarsest)
    rising = {**coarsest, "swt_max_MPa": 85.0}  # 5 then 10: not converging, read from the larger difference
    assert fatigue_estimates(fine, coarse, coarsest=rising)["estimated_error_swt_max"] == pytest.approx(SQRT_H * 0.1)
    partial = {**fine, "regime": "partial_slip"}  # the stick zone's edge: not estimated, whatever the grids show
    assert set(fatigue_unestimated(partial, coarse, coarsest)) == {"swt_max_MPa", "fatigue_damage"}
    est = fatigue_estimates(partial, coarse, coarsest=coarsest)
    assert math.isnan(est["estimated_error_swt_max"]) and math.isnan(est["estimated_error_fatigue_damage"])
    assert est["estimated_error_cycles_to_crack"] == pytest.approx(0.05 + 0.001 + 0.002)


def test_a_square_ended_line_contacts_end_row_depth_grows_with_the_rows_and_the_run_says_its_estimate_misses_it():
    """McColl 185 N in 3D wears deepest in the cylinder's end rows, where a square end's pressure is singular: that
    depth grows as the rows are refined (2.048, 2.061, 2.072, 2.080 µm on 13 to 109 rows at 18 000 cycles, a
    review's), the centre line does not, and the companions keep the rows.  Shown here on 2 000 cycles, where the
    end row is younger and moves more (13, 27, 55 rows: 0.487, 0.501, 0.514 µm on the moving body, its centre line
    0.4523, 0.4518, 0.4516): the end rows over 2 % deeper on twice the rows, the centre lines within 2e-3; the run
    warns of it, and neither a 2D run nor a roller with rounded edges does."""
    sets = ["model.dimension=3d", "loading.cycles=2000", "grid.error_estimate=none"]
    base = run(load_case(CASES / "mccoll_185N.yaml", sets))
    g = base.setup.grid
    domain = f"grid.domain=[{g.shape[1] * g.dx!r} mm, {g.shape[0] * g.dy!r} mm]"
    few = run(load_case(CASES / "mccoll_185N.yaml", [*sets, domain, f"grid.elements=[{g.shape[1]}, 13]"]))
    many = run(load_case(CASES / "mccoll_185N.yaml", [*sets, domain, f"grid.elements=[{g.shape[1]}, 27]"]))
    for key in ("max_wear_depth_moving_um", "max_wear_depth_stationary_um"):
        assert many.summary[key] > few.summary[key] * 1.02, key
    for key in ("centre_wear_depth_moving_um", "centre_wear_depth_stationary_um"):
        assert many.summary[key] == pytest.approx(few.summary[key], rel=2e-3), key
    said = [n for n in base.notes if "end row of the line contact" in n]
    assert len(said) == 1 and "the moving body" in said[0] and "the flat" in said[0], base.notes
    assert "not covered by its estimate" in said[0]
    # a grid wider than the line (a review): its end rows are the last worn ones, not the grid's
    wide = run(load_case(CASES / "mccoll_185N.yaml", [*sets, "grid.domain=[0.8 mm, 12 mm]", "grid.elements=[161, 33]"]))
    assert any("end row of the line contact" in n for n in wide.notes), wide.notes
    flat = run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=2000"]))
    rounded = run(load_case(CASES / "roller_edge_rounded.yaml", sets))
    for out in (flat, rounded):
        assert not any("end row" in n for n in out.notes), out.notes
