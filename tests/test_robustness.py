"""Long runs and hostile input: fuzzed cases, interrupt and resume, kills, injected failures, physical limits."""
import copy
import dataclasses
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings, strategies as st

import fretsim.simulate as simulate_module
from fretsim.api import load_case, resume, run
from fretsim.cli import main
from fretsim.results import FIELDS, read_results

CASES = Path(__file__).resolve().parent.parent / "cases"
BASE = yaml.safe_load((CASES / "mccoll_185N.yaml").read_text())

# --- fuzzed cases: every mutation below makes the case invalid, so every example must end in exit code 2 -------

INVALID = {
    ("geometry", "type"): ["cube", 3, ["cylinder_on_flat"], "Cylinder_On_Flat"],
    ("geometry", "radius"): [6, "6", "6 kg", "-6 mm", "0 mm", "nan mm", "inf mm", "1 km", None, [6], {"r": 6}, True,
                             "1e400 mm", "6mm mm"],
    ("geometry", "length"): [10, "10 N", "-1 mm", None, "20 m", "0.5 nm"],
    ("materials", "moving", "youngs_modulus"): [200, "200", "200 mm", "-200 GPa", "0 GPa", "nan GPa", None, "1e9 GPa"],
    ("materials", "stationary", "poissons_ratio"): [0.5, 0.7, -1, -3, "abc", None, float("nan"), float("inf"),
                                                     [0.3], True],
    ("materials", "moving", "wear_coefficient"): [2e-8, "2e-8", "-2e-8 1/MPa", "2e-8 MPa", "nan 1/MPa", None,
                                                  "1 1/MPa"],
    ("materials", "stationary", "wear_coefficient"): ["3e-8 1/m", "3e-8 N", -3e-8, "inf 1/MPa"],
    ("loading", "normal_load"): [185, "185", "185 kg", "-185 N", "0 N", "nan N", "inf N", None, "1e12 N"],
    ("loading", "stroke"): [25, "25", "25 N", "-25 um", "0 um", "25 mm", "25 cm", None],
    ("loading", "cycles"): [-1, 1.5, "many", None, float("nan"), 1e20, True, [18000], "1e20", -0.0001],
    ("model", "dimension"): ["4d", 2, "3 d", ["3d"]],  # "3D" is accepted (issue #11)
    ("solver", "method"): ["foo", "CG", 3, [1], "msn"],
    ("solver", "tolerance"): [0, -1, 1.0, "tight", float("nan")],
    ("jumping", "linear"): [0, -5, 1.5, "fast", 10**12, 80],
    ("jumping", "scheme"): ["explicit", 3, "Implicit"],
    ("jumping", "eta"): [0, -1, 100, "x"],
    ("grid", "domain"): ["1 mm", [0.5], ["1 mm"], ["-1 mm", "10 mm"], [1, 10], ["1 kg", "10 mm"]],
    ("grid", "elements"): [[0, 27], [1.5, 27], "many", [27], [10**6, 10**6]],
    ("output", "snapshots"): ["all", [-1], [1.5], ["x"], 5],
}
REQUIRED = [("geometry", "type"), ("geometry", "radius"), ("geometry", "length"), ("materials", "moving"),
            ("materials", "stationary", "wear_coefficient"), ("loading", "normal_load"), ("loading", "stroke"),
            ("loading", "cycles"), ("geometry",), ("materials",), ("loading",)]
SECTIONS = ["geometry", "materials", "loading", "model", "solver", "jumping", "grid", "output"]
BROKEN_TEXT = ["geometry: {type: ball_on_flat, radius: [6 mm\n", "a: [1, 2\nb: 3\n", "\t- tab\n:", "key: 'open\n",
               "{{{", "- 1\n- 2\n", "just text", "", "   \n", "name: x\ngeometry: *anchor\n", "? [a\n"]


def _set(tree, path, value):
    node = tree
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value


def _delete(tree, path):
    node = tree
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]


@st.composite
def hostile_case(draw):
    """(yaml text, the sections that were made invalid, or None for a broken file)."""
    if draw(st.integers(0, 9)) == 0:
        text = draw(st.sampled_from(BROKEN_TEXT)) if draw(st.booleans()) else draw(st.text(max_size=40)) + ": ["
        return text, None
    tree = copy.deepcopy(BASE)
    kinds = draw(st.lists(st.sampled_from(["value", "delete", "unknown", "section"]), min_size=1, max_size=3))
    touched = []
    for kind in kinds:
        if kind == "value":
            path = draw(st.sampled_from(sorted(INVALID)))
            try:
                _set(tree, path, draw(st.sampled_from(INVALID[path])))
            except (KeyError, TypeError):  # an earlier mutation removed or replaced the section
                continue
        elif kind == "delete":
            path = draw(st.sampled_from(REQUIRED))
            try:
                _delete(tree, path)
            except (KeyError, TypeError):
                continue
        elif kind == "unknown":
            section = draw(st.sampled_from(SECTIONS))
            if not isinstance(tree.get(section), dict):
                continue
            path = (section, draw(st.sampled_from(["radus", "lenght", "colour", "x", "Stroke", "cycle"])))
            _set(tree, path, "1 mm")
        else:
            path = (draw(st.sampled_from(SECTIONS)),)
            _set(tree, path, draw(st.sampled_from([[1, 2], "text", 5, ["a", {"b": 1}]])))
        touched.append(path[0])
    if not touched:
        _delete(tree, ("loading",))
        touched.append("loading")
    return yaml.safe_dump(tree, allow_unicode=True), tuple(touched)


def _check_rejected(tmp_path, text, sections):
    case = tmp_path / "case.yaml"
    case.write_text(text)
    out = tmp_path / "out.h5"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out)])
    assert r.exit_code == 2, (text, r.output)
    assert r.output.startswith("fretsim: ") and "Traceback" not in r.output, r.output
    assert str(case) in r.output or "line" in r.output  # names the file
    if sections is not None:  # names the YAML path of (at least) one of the problems
        named = [f"- {s}" for s in sections + ("grid",)] + [f": {s}" for s in sections + ("grid",)]
        assert any(n in r.output for n in named), r.output
    assert not out.exists()


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(hostile_case())
def test_fuzzed_hostile_cases_exit_2_with_a_message_and_write_nothing(tmp_path, example):
    _check_rejected(tmp_path, *example)


@pytest.mark.slow
@settings(max_examples=1000, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(hostile_case())
def test_fuzzed_hostile_cases_1000(tmp_path, example):
    _check_rejected(tmp_path, *example)


# --- interrupt and resume ------------------------------------------------------------------------------------------

def _same_arrays(a, b):
    for name in list(FIELDS) + ["cycle"]:
        assert np.array_equal(a.fields[name], b.fields[name], equal_nan=True), name
    for name in a.history:
        if name != "wall_time":
            assert np.array_equal(a.history[name], b.history[name], equal_nan=True), name


class _StopAt:
    def __init__(self, k):
        self.k, self.n = k, 0

    def on_step(self, setup, step):
        self.n += 1
        if self.n == self.k:
            raise KeyboardInterrupt


@pytest.mark.parametrize("overrides, stops", [
    (["model.dimension=2d"], (3, 20, 45)),
    (["model.dimension=2d", "jumping.scheme=linear", "loading.cycles=3000"], (2, 60)),
    (["model.dimension=2d", "jumping.preset=paper", "grid.coarse_element=[15.75 um]"], (9, 100)),
    (["loading.cycles=3000"], (10,)),
    (["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=mid_stroke",
      "loading.cycles=4000"], (2, 15, 30)),
    # the resolved stroke (auto's choice here) carries its corrections' memory: once, short (a resolved run is ~15×)
    (["model.dimension=2d", "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=resolved",
      "loading.cycles=1000", "grid.error_estimate=none"], (12,)),
    (["model.dimension=2d", "loading.friction_coefficient=0.9", "loading.stroke=0.4 um", "loading.cycles=4000",
      "jumping.scheme=adaptive"], (4, 12)),
], ids=["implicit-2d", "linear-2d", "adaptive-refined-2d", "implicit-3d", "coulomb-2d", "coulomb-resolved-2d",
        "coulomb-partial-adaptive"])
def test_interrupted_runs_resume_to_identical_arrays(tmp_path, overrides, stops):
    run(load_case(CASES / "mccoll_185N.yaml", overrides), tmp_path / "full.h5")
    full = read_results(tmp_path / "full.h5")
    for k in stops:
        part = tmp_path / f"part{k}.h5"
        with pytest.raises(KeyboardInterrupt):
            run(load_case(CASES / "mccoll_185N.yaml", overrides), part, observers=(_StopAt(k),))
        assert read_results(part).status == "interrupted"
        assert resume(part).status == "complete"
        _same_arrays(full, read_results(part))


# about 1900 linear steps: long enough to be killed mid-run at any of the row counts below
LONG = ["--set", "model.dimension=2d", "--set", "jumping.scheme=linear", "--set", "loading.cycles=80000",
        "--set", "output.snapshots=[0, 40000, 80000]"]


def _kill_at(tmp_path, sig, rows, name):
    out = tmp_path / f"{name}.h5"
    # (SIGINT restored to its default in the child: a background job, and an xdist worker, ignore it, and Python
    #  keeps an inherited SIG_IGN, so the run never saw the Ctrl-C and completed: exit 0 in `pytest -m slow -n 2`
    #  started in the background)
    proc = subprocess.Popen([sys.executable, "-m", "fretsim.cli", "run", str(CASES / "mccoll_185N.yaml"), "-o",
                             str(out), *LONG], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            if out.exists() and read_results(out).history["cycle"].size >= rows:
                break
        except ValueError:
            pass  # never expected: the file is replaced atomically; retried anyway
        time.sleep(0.02)
    proc.send_signal(sig)
    code = proc.wait(timeout=60)
    return out, code


@pytest.fixture(scope="session")  # per worker, once: xdist interleaves modules, a module fixture is rebuilt
def long_reference(tmp_path_factory):
    path = tmp_path_factory.mktemp("ref") / "ref.h5"
    sets = [LONG[i + 1] for i in range(0, len(LONG), 2)]
    run(load_case(CASES / "mccoll_185N.yaml", sets), path)
    return read_results(path)


# each signal costs a whole long run (the kill at 200 rows, then its resume): SIGKILL by default, the hardest (the
# process writes nothing more; its last flush must stand); Ctrl-C's and SIGTERM's handler in `pytest -m slow` (a real
# Ctrl-C's file: test_reliability.py; an API interrupt's resume: test_interrupted_runs_resume_to_identical_arrays)
@pytest.mark.parametrize("sig, code, status", [
    pytest.param(signal.SIGINT, 130, "interrupted", marks=pytest.mark.slow),
    pytest.param(signal.SIGTERM, 130, "interrupted", marks=pytest.mark.slow),
    (signal.SIGKILL, -9, "running")])
def test_signalled_run_keeps_its_steps_and_resumes_identically(tmp_path, long_reference, sig, code, status):
    out, got = _kill_at(tmp_path, sig, 200, sig.name)
    assert got == code
    before = read_results(out)
    assert before.status == status and before.history["cycle"].size >= 200
    r = CliRunner().invoke(main, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    _same_arrays(long_reference, read_results(out))


@pytest.mark.slow
@pytest.mark.parametrize("rows", [5, 400, 1200, 1800])
def test_kill_9_at_many_points_always_resumes_identically(tmp_path, long_reference, rows):
    out, got = _kill_at(tmp_path, signal.SIGKILL, rows, f"k{rows}")
    assert got == -9
    assert resume(out).status == "complete"
    _same_arrays(long_reference, read_results(out))


def test_resume_refuses_complete_runs_and_extra_arguments(tmp_path):
    run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=500"]), tmp_path / "c.h5")
    r = CliRunner().invoke(main, ["run", "--resume", str(tmp_path / "c.h5")])
    assert r.exit_code == 2 and "'complete'" in r.output
    r = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "--resume", str(tmp_path / "c.h5")])
    assert r.exit_code == 2 and "alone" in r.output


# --- numerical failure, injected -------------------------------------------------------------------------------------

def _inject(monkeypatch, calls, mode):
    real = simulate_module.solve
    count = {"n": 0}

    def fake(op, gap, load, **kw):
        count["n"] += 1
        res = real(op, gap, load, **kw)
        if count["n"] in calls:
            p = res.pressure.copy()
            if mode == "unconverged":
                return dataclasses.replace(res, success=False, message="injected failure")
            if mode == "nan":
                p.flat[np.argmax(p)] = np.nan
            elif mode == "load":
                p *= 1.01
            elif mode == "negative":
                p.flat[np.argmax(p)] = -1.0
            return dataclasses.replace(res, pressure=p)
        return res

    monkeypatch.setattr(simulate_module, "solve", fake)


@pytest.mark.parametrize("mode, words", [("unconverged", "did not converge at cycle"), ("nan", "non-finite"),
                                         ("load", "violates the load balance"),
                                         ("negative", "negative pressure")])
def test_injected_failure_stops_the_run_with_exit_3_and_keeps_only_good_steps(tmp_path, monkeypatch, mode, words):
    _inject(monkeypatch, set(range(6, 10**6)), mode)
    out = tmp_path / "f.h5"
    r = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", str(out), "--set",
                                  "model.dimension=2d", "--set", "jumping.scheme=linear"])
    assert r.exit_code == 3 and words in r.output, r.output
    res = read_results(out)
    assert res.status == "failed" and words in res.attrs["status_message"]
    assert res.history["cycle"].size == 5  # the 5 good solves; nothing from the failed one
    assert np.isfinite(res.fields["pressure"]).all() and (res.fields["pressure"] >= 0).all()


@pytest.mark.parametrize("mode", ["unconverged", "nan"])
def test_a_transient_failure_is_retried_with_a_smaller_step(tmp_path, monkeypatch, mode):
    _inject(monkeypatch, {8}, mode)
    out = run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d"]), tmp_path / "t.h5")
    assert out.status == "complete"
    assert read_results(tmp_path / "t.h5").history["rejected_steps"].sum() >= 1


# --- physical limits and determinism ----------------------------------------------------------------------------------

def test_wearing_through_the_geometry_stops_with_exit_4(tmp_path):
    r = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", str(tmp_path / "p.h5"), "--set",
                                  "model.dimension=2d", "--set", "loading.cycles=10000000000", "--set",
                                  "materials.moving.wear_coefficient=1e-4 1/MPa"])
    assert r.exit_code == 4 and "half of the radius" in r.output
    res = read_results(tmp_path / "p.h5")
    assert res.status == "stopped" and res.history["cycle"][-1] < 10**10


def test_default_3d_runs_are_bit_identical(tmp_path):
    for k in (1, 2):
        run(load_case(CASES / "mccoll_185N.yaml", ["loading.cycles=4000"]), tmp_path / f"{k}.h5")
    a, b = read_results(tmp_path / "1.h5"), read_results(tmp_path / "2.h5")
    _same_arrays(a, b)
