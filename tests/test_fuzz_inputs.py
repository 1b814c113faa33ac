"""Fuzzing the surfaces issue 31 names: friction keys, load histories, wear limits, sampled sweep files and the
measured CSVs of `fit`.  Every example ends in a sound result or a one-paragraph refusal (exit 2): never a
traceback or a hang.  A sample runs by default; `pytest -m slow` runs 1 000 of each.  The examples are drawn by
tests/hostile.py, which `scripts/fuzz_surfaces.py` shares for its before/after table."""
from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings, strategies as st

import hostile
from fretsim.case import CaseError
from fretsim.cli import main

CASES = Path(__file__).resolve().parent.parent / "cases"
CASE = str(CASES / "mccoll_185N.yaml")
FAST = dict(deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
RNG = st.randoms(use_true_random=False)
BASE = """name: fuzz
geometry:  {type: cylinder_on_flat, radius: 6 mm, length: 10 mm}
materials:
  moving:     {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 2.0e-8 1/MPa}
  stationary: {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 3.0e-8 1/MPa}
model: {dimension: 2d}
grid: {error_estimate: none}
"""


def _check(args: list) -> str:
    r = CliRunner().invoke(main, ["check", *args])
    verdict = hostile.judge_cli(r)
    assert verdict == "ok", (args, r.exit_code, r.output[-2000:])
    return verdict


def _friction(tmp_path, rng):
    sets = hostile.friction_example(rng)
    _check([CASE, *[a for s in sets for a in ("--set", s)]])


def _history(tmp_path, rng):
    (tmp_path / "h.yaml").write_text(BASE + hostile.history_example(rng))
    _check([str(tmp_path / "h.yaml")])


def _limits(tmp_path, rng):
    sets = hostile.limits_example(rng)
    _check([CASE, *[a for s in sets for a in ("--set", s)]])


def _sampled(tmp_path, rng):
    from fretsim.sweep import load_sweep
    (tmp_path / "s.yaml").write_text(hostile.sampled_sweep_example(rng, CASE))
    try:
        load_sweep(tmp_path / "s.yaml")
    except CaseError:
        pass


def _measured(tmp_path, rng):
    from fretsim.fit import read_measured
    (tmp_path / "m.csv").write_text(hostile.measured_example(rng), encoding="utf-8")
    try:
        read_measured(tmp_path / "m.csv")
    except CaseError:
        pass


def _fuzzed(surface, examples: int):
    """A test of ``examples`` examples of one surface (drawn from hypothesis' seeded randoms)."""
    @settings(max_examples=examples, **FAST)
    @given(RNG)
    def test(tmp_path, rng):
        surface(tmp_path, rng)
    return test


# a sample by default (a few seconds in all), 1 000 of each in the slow suite
test_fuzzed_friction_keys = _fuzzed(_friction, 15)
test_fuzzed_load_histories = _fuzzed(_history, 15)
test_fuzzed_wear_limits = _fuzzed(_limits, 10)
test_fuzzed_sampled_sweeps = _fuzzed(_sampled, 40)
test_fuzzed_measured_files = _fuzzed(_measured, 60)
test_fuzzed_friction_keys_1000 = pytest.mark.slow(_fuzzed(_friction, 1000))
test_fuzzed_load_histories_1000 = pytest.mark.slow(_fuzzed(_history, 1000))
test_fuzzed_wear_limits_1000 = pytest.mark.slow(_fuzzed(_limits, 1000))
test_fuzzed_sampled_sweeps_1000 = pytest.mark.slow(_fuzzed(_sampled, 1000))
test_fuzzed_measured_files_1000 = pytest.mark.slow(_fuzzed(_measured, 1000))
