"""The loop's units and the branches the families turned from strings into attributes: landing on a wear limit
across an interruption, the cold start only the implicit schemes fall back to, the per-cycle update's own
instability, and what the run's paragraph says of the regime."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import fretsim.simulate
from fretsim.api import load_case, resume, run
from fretsim.cli import main
from fretsim.plan import prepare
from fretsim.results import read_results
from fretsim.simulate import NumericalFailure

CASES = Path(__file__).resolve().parent.parent / "cases"
MCCOLL = str(CASES / "mccoll_185N.yaml")
LIMITED = ["model.dimension=2d", "loading.cycles=20000", "grid.error_estimate=none",
           "limits={max_wear_depth_stationary: 1.5 um}"]


class _StopAtTheLimit:
    """Ctrl-C right after the results file has recorded the state at the wear limit."""

    def on_step(self, setup, step):
        if step.limit is not None:
            raise KeyboardInterrupt


def test_a_run_interrupted_at_its_wear_limit_resumes_to_the_limit_not_past_it(tmp_path):
    # the checkpoint written with the state at the limit did not say the limit was reached: a resume stepped on
    # past it (a deeper scar, a later cycle) and still reported the limit's cycle
    whole = run(load_case(MCCOLL, LIMITED))
    assert whole.summary["limit_reached"] == "max_wear_depth_stationary"
    out = tmp_path / "r.h5"
    with pytest.raises(KeyboardInterrupt):
        run(load_case(MCCOLL, LIMITED), out, observers=(_StopAtTheLimit(),))
    assert read_results(out).status == "interrupted"
    resumed = resume(out)
    assert resumed.status == "complete"
    for key in ("cycles", "limit_reached", "cycles_to_limit", "max_wear_depth_stationary_um",
                "max_wear_depth_moving_um", "max_pressure_MPa"):
        assert resumed.summary[key] == whole.summary[key], key
    assert read_results(out).history["cycle"][-1] == whole.summary["cycles"]


def test_a_stalled_warm_start_is_retried_cold_by_the_implicit_schemes_and_fails_the_explicit_ones(monkeypatch):
    real = fretsim.simulate.solve

    def stalling(op, gap, load, method="cg", p0=None, tol=1e-5, **kw):
        res = real(op, gap, load, method=method, p0=p0, tol=tol, **kw)
        return res if p0 is None else type(res)(res.pressure, res.approach, res.contact, res.iterations, False,
                                                 "stalled (a test's)")

    monkeypatch.setattr(fretsim.simulate, "solve", stalling)
    case = ["model.dimension=2d", "loading.cycles=300", "grid.error_estimate=none"]
    out = run(load_case(MCCOLL, case + ["jumping.scheme=bdf2"]))
    assert out.status == "complete", out.message
    monkeypatch.setattr(fretsim.simulate, "solve", real)
    reference = run(load_case(MCCOLL, case + ["jumping.scheme=bdf2"]))
    # cold starts converge to the same contact within the solver's tolerance (1e-5 relative in the pressure)
    assert out.summary["max_wear_depth_stationary_um"] == pytest.approx(
        reference.summary["max_wear_depth_stationary_um"], rel=1e-4)
    monkeypatch.setattr(fretsim.simulate, "solve", stalling)
    failed = run(load_case(MCCOLL, case + ["jumping.scheme=linear"]))
    assert failed.status == "failed" and "did not converge" in failed.message and "stalled" in failed.message


def test_implicit_steps_warn_where_the_per_cycle_update_itself_is_unstable_and_linear_jumps_are_refused():
    fast = ["model.dimension=2d", "loading.cycles=100", "materials.moving.wear_coefficient=2e-5 1/MPa",
            "materials.stationary.wear_coefficient=3e-5 1/MPa"]
    setup, _, plan = prepare(load_case(MCCOLL, fast))
    assert setup.stability_limit < 1 and not setup.per_cycle
    assert any("per-cycle update is itself unstable" in w for w in plan.warnings)
    setup, _, plan = prepare(load_case(MCCOLL, fast[:2]))  # the case's own coefficients: stable per cycle
    assert setup.per_cycle and not any("per-cycle update is itself unstable" in w for w in plan.warnings)
    from fretsim.case import CaseError
    with pytest.raises(CaseError, match="below one cycle even an update per cycle is unstable"):
        prepare(load_case(MCCOLL, fast + ["jumping.scheme=linear", "jumping.linear=1"]))


@pytest.mark.parametrize("slip, words", [
    ("uniform", "Gross slip assumed (the stroke is"),
    ("coulomb", "Gross slip (the whole contact slides): tangential force amplitude"),
])
def test_the_runs_paragraph_says_whether_the_regime_was_assumed_or_measured(tmp_path, slip, words):
    r = CliRunner().invoke(main, ["run", MCCOLL, "-o", str(tmp_path / "r.h5"), "--quiet", "--set",
                                  "model.dimension=2d", "--set", "loading.cycles=200", "--set",
                                  "loading.friction_coefficient=0.9", "--set", f"model.slip={slip}", "--set",
                                  "grid.error_estimate=none"])
    assert r.exit_code == 0, r.output
    assert words in r.output, r.output
    measured = float(r.output.split("tangential force amplitude ")[1].split(" N")[0]) if slip == "coulomb" else None
    if measured is not None:  # gross slip: Q* = μP to the solver's tolerance
        assert measured == pytest.approx(0.9 * 185.0, rel=1e-6)
    assert np.isfinite(read_results(tmp_path / "r.h5").summary["gross_slip_stroke_um"])
