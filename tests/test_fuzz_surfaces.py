"""Fuzzing the surfaces issue #20 names: CSV profiles, sweep files, --dask addresses, and sweeps edited or killed
between runs.  Every example ends in a sound result or a one-paragraph refusal (exit 2): never a traceback, a
hang, or a table that holds numbers of other inputs.  A sample runs by default; `pytest -m slow` runs 1 000 of
each (the sweep kills: 30, each a real sweep)."""
from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings, strategies as st

from fretsim.case import CaseError, load_case
from fretsim.cli import main
from fretsim.sweep import check_dask_address, load_sweep, run_sweep

CASES = Path(__file__).resolve().parent.parent / "cases"
ROLLER = (CASES / "roller_edge_rounded.yaml").read_text().replace("edge_radius: 20 mm, flat_length: 9 mm",
                                                                   "profile: profile.csv")
FAST = dict(deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


# --- CSV profiles -------------------------------------------------------------------------------------------------

NUMBER = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=32).map(repr),
                   st.integers(-10**6, 10**6).map(str), st.sampled_from(["", " ", "x", "1e999", "-0", "5 mm", "1,5"]))
HEADER = st.sampled_from(["y [mm], drop [um]", "y [um], drop [nm]", "y, drop", "y [mm]", "y [kg], drop [um]",
                          "\ufeffy [mm], drop [um]", "y [mm], drop [um], extra [mm]", "# a comment", ""])


@st.composite
def profile_csv(draw):
    rows = draw(st.lists(st.lists(NUMBER, min_size=0, max_size=3), max_size=8))
    if draw(st.booleans()):  # a plausible profile, perturbed
        ys = sorted(draw(st.lists(st.floats(-6, 6), min_size=2, max_size=6, unique=True)))
        rows = [[repr(y), repr(draw(st.floats(0, 50)))] for y in ys] + rows[: draw(st.integers(0, 2))]
    return draw(HEADER) + "\n" + "\n".join(", ".join(r) for r in rows) + "\n"


def _judge_profile(tmp_path, text):
    (tmp_path / "profile.csv").write_text(text, encoding="utf-8", errors="surrogatepass")
    (tmp_path / "r.yaml").write_text(ROLLER)
    r = CliRunner().invoke(main, ["check", str(tmp_path / "r.yaml"), "--set", "model.dimension=3d"])
    assert r.exit_code in (0, 2) and "Traceback" not in r.output, (text, r.output)
    if r.exit_code == 2:
        assert "geometry.profile" in r.output, (text, r.output)
    else:  # accepted: a drop defined and finite over the whole roller
        case = load_case(tmp_path / "r.yaml", ["model.dimension=3d"])
        d = case.geometry.drop(np.linspace(-5.0, 5.0, 41))
        assert np.isfinite(d).all(), text


@settings(max_examples=60, **FAST)
@given(profile_csv())
def test_fuzzed_profiles(tmp_path, text):
    _judge_profile(tmp_path, text)


@pytest.mark.slow
@settings(max_examples=1000, **FAST)
@given(profile_csv())
def test_fuzzed_profiles_1000(tmp_path, text):
    _judge_profile(tmp_path, text)


# --- sweep files --------------------------------------------------------------------------------------------------

KEYS = ["loading.stroke", "loading.normal_load", "loading.cycles", "materials.moving.wear_coefficient",
        "model.dimension", "jumping.linear", "geometry.radius", "loading.strok", "loading", "", "a.b.c.d.e"]
VALUES = st.one_of(st.sampled_from(["10 um", "25 um", "185 N", "2e-8 1/MPa", "2d", "3d", "-5 um", "0 N", "1e308 N",
                                    "nan um", "10 kg", "abc", "", "[1, 2]", "{a: 1}", None, True]),
                   st.integers(-5, 10**9), st.floats(allow_nan=True, allow_infinity=True))


@st.composite
def sweep_text(draw):
    import yaml
    raw = {}
    if draw(st.integers(0, 5)):
        raw["base"] = draw(st.sampled_from([str(CASES / "mccoll_185N.yaml"), "missing.yaml", 5, None, [1],
                                            {"name": "x"}, str(CASES)]))
    if draw(st.booleans()):
        raw["set"] = draw(st.sampled_from([["model.dimension=2d"], "model.dimension=2d", [5], ["x"], [],
                                           ["loading.cycles=10"], ["loading.cycles=-1"]]))
    raw["mode"] = draw(st.sampled_from(["product", "zip", "points", "zap", None]))
    if raw["mode"] == "points" and draw(st.booleans()):
        raw["points"] = draw(st.lists(st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=2), max_size=4))
    else:
        raw["axes"] = draw(st.one_of(st.dictionaries(st.sampled_from(KEYS), st.lists(VALUES, max_size=4), max_size=3),
                                     st.sampled_from([None, 5, "x", [1, 2]])))
    if draw(st.integers(0, 9)) == 0:
        raw[draw(st.sampled_from(["extra", "axis", "Base"]))] = 1
    return yaml.safe_dump(raw, allow_unicode=True)


def _judge_sweep_file(tmp_path, text):
    path = tmp_path / "s.yaml"
    path.write_text(text)
    try:
        sweep = load_sweep(path)
    except CaseError as exc:
        assert str(path) in str(exc) or "sweep" in str(exc), text
        return
    assert sweep.points, text  # accepted: at least one point, each validated into a case with its fingerprint
    assert all(len(p.fingerprint) == 64 for p in sweep.points)
    assert len({p.name for p in sweep.points}) == len(sweep.points)


@settings(max_examples=80, **FAST)
@given(sweep_text())
def test_fuzzed_sweep_files(tmp_path, text):
    _judge_sweep_file(tmp_path, text)


@pytest.mark.slow
@settings(max_examples=1000, **FAST)
@given(sweep_text())
def test_fuzzed_sweep_files_1000(tmp_path, text):
    _judge_sweep_file(tmp_path, text)


# --- --dask addresses ---------------------------------------------------------------------------------------------

ADDRESS = st.one_of(st.text(max_size=30),
                    st.builds(lambda s, h, p: f"{s}{h}:{p}", st.sampled_from(["", "tcp://", "tls://", "http://",
                                                                           "inproc://", "ws://", "tcp:/"]),
                              st.sampled_from(["127.0.0.1", "localhost", "", "[::1]", "a b", "host/x", "::"]),
                              st.one_of(st.integers(-5, 70000).map(str), st.sampled_from(["", "x", "8786/"]))))


def _judge_address(address):
    try:
        url, host, port = check_dask_address(address)
    except CaseError as exc:
        assert "tcp://HOST:PORT" in str(exc)
        return
    assert url.startswith(("tcp://", "tls://")) and 0 < port < 65536 and host


@settings(max_examples=300, deadline=None)
@given(ADDRESS)
def test_fuzzed_dask_addresses(address):
    _judge_address(address)


@pytest.mark.slow
@settings(max_examples=1000, deadline=None)
@given(ADDRESS)
def test_fuzzed_dask_addresses_1000(address):
    _judge_address(address)


# --- sweeps killed at random points and edited between runs --------------------------------------------------------

SLOW_SWEEP = f"""
base: {CASES / 'mccoll_185N.yaml'}
set: [model.dimension=2d, loading.cycles=1500, "output.snapshots=[1500]", jumping.scheme=linear, jumping.linear=1]
axes:
  loading.stroke: [10 um, 25 um]
  loading.normal_load: [150 N, 185 N]
"""


def _rows(outdir):
    import csv
    with open(outdir / "table.csv", newline="") as fh:
        return {r["point"]: r for r in csv.DictReader(fh)}


@pytest.fixture(scope="session")  # per worker, once: xdist interleaves modules, a module fixture is rebuilt
def sweep_reference(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ref")
    (tmp / "s.yaml").write_text(SLOW_SWEEP)
    run_sweep(load_sweep(tmp / "s.yaml"), tmp / "out", jobs=2)
    return tmp, _rows(tmp / "out")


def _kill_and_rerun(tmp_path, reference, delay, sig, edit):
    tmp, ref = reference
    (tmp_path / "s.yaml").write_text(SLOW_SWEEP)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "fretsim", "sweep", str(tmp_path / "s.yaml"), "-o", str(out),
                             "--jobs", "2"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    time.sleep(delay)
    proc.send_signal(sig)
    output, _ = proc.communicate(timeout=120)
    assert "Traceback" not in output, output
    if edit:  # the inputs change between the runs: every row must follow them
        (tmp_path / "s.yaml").write_text(SLOW_SWEEP.replace("loading.cycles=1500", "loading.cycles=1000")
                                         .replace("[1500]", "[1000]"))
    r = CliRunner().invoke(main, ["sweep", str(tmp_path / "s.yaml"), "-o", str(out), "--jobs", "2"])
    assert r.exit_code == 0, r.output
    rows = _rows(out)
    for name, row in rows.items():
        if edit:
            assert row["cycles"] == "1000", row
        else:  # the same table as an uninterrupted sweep (resumed points bit for bit, so their depths too)
            assert row["max_wear_depth_stationary_um"] == ref[name]["max_wear_depth_stationary_um"], name


@pytest.mark.slow
@settings(max_examples=30, **FAST)
@given(st.floats(0.5, 6.0), st.sampled_from([signal.SIGINT, signal.SIGTERM, signal.SIGKILL]), st.booleans())
def test_fuzzed_sweep_kills_and_edits(tmp_path_factory, sweep_reference, delay, sig, edit):
    _kill_and_rerun(tmp_path_factory.mktemp("kill"), sweep_reference, delay, sig, edit)


def test_a_sweep_killed_then_edited_then_rerun_follows_its_inputs(tmp_path, sweep_reference):
    _kill_and_rerun(tmp_path, sweep_reference, 2.0, signal.SIGKILL, True)
