"""The command line: run / summary / plot, exit codes, and bad input that leaves files alone."""
import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from conftest import VOLUME_ROUND_OFF, check_archard_results
from fretsim.cli import main
from fretsim.results import read_results

CASES = Path(__file__).resolve().parent.parent / "cases"
SHORT = ["--set", "loading.cycles=600", "--set", "output.snapshots=[0, 300, 600]"]


@pytest.fixture
def cli(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return CliRunner()


def test_run_summary_plot_round_trip_3d(cli, tmp_path):
    r = cli.invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), *SHORT])
    assert r.exit_code == 0, r.output
    assert "Results: mccoll_185N.h5" in r.output and (tmp_path / "mccoll_185N.h5").exists()
    r = cli.invoke(main, ["summary", "mccoll_185N.h5", "--json"])
    data = json.loads(r.output)
    assert data["status"] == "complete" and data["cycles"] == 600
    # Archard's volumes as the summary reports them, against k·P·4δ·N from the case file's numbers (k_m 2e-8 and
    # k_s 3e-8 1/MPa, 185 N, δ 25 µm, 600 cycles); and summed from the written wear fields (round-off: conftest)
    for body, k in (("moving", 2e-8), ("stationary", 3e-8)):
        assert data[f"wear_volume_{body}_mm3"] == pytest.approx(k * 185 * 4 * 0.025 * 600, rel=VOLUME_ROUND_OFF)
    check_archard_results(read_results(tmp_path / "mccoll_185N.h5"))
    r = cli.invoke(main, ["plot", "mccoll_185N.h5", "-o", "plots"])
    assert r.exit_code == 0, r.output
    pngs = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert pngs == ["mccoll_185N_history.png", "mccoll_185N_maps.png", "mccoll_185N_pressure_profiles.png",
                    "mccoll_185N_wear_profiles.png"]


def _write(tmp_path, text):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("edit, key", [
    (("radius: 6 mm, ", ""), "geometry.radius"),  # a missing key
    (("stroke:", "strok:"), "loading.strok"),  # an unknown key
    (("185 N", "185 kg"), "loading.normal_load"),  # a wrong unit
    (("185 N", "-185 N"), "loading.normal_load"),  # a negative load
    (("grid:      {}", "grid: {domain: [0.4 mm, 10 mm], elements: [61, 27]}"), "loading.stroke"),  # stroke > domain
])
def test_bad_case_exits_2_names_the_key_and_writes_nothing(cli, tmp_path, edit, key):
    text = (CASES / "mccoll_185N.yaml").read_text()
    if key == "loading.stroke":
        text = text.replace("stroke: 25 um", "stroke: 250 um")
    bad = _write(tmp_path, text.replace(*edit))
    r = cli.invoke(main, ["run", str(bad), "-o", "out.h5"])
    assert r.exit_code == 2
    assert key in r.output and "Traceback" not in r.output
    assert not (tmp_path / "out.h5").exists()


def test_existing_results_are_not_overwritten(cli, tmp_path):
    (tmp_path / "out.h5").write_bytes(b"precious")
    r = cli.invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", "out.h5", *SHORT])
    assert r.exit_code == 2 and "--overwrite" in r.output
    assert (tmp_path / "out.h5").read_bytes() == b"precious"


def test_failed_run_exits_3_and_marks_the_file(cli, tmp_path):
    r = cli.invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", "f.h5", "--set", "model.dimension=2d",
                          "--set", "grid.domain=[0.35 mm]", "--set", "grid.elements=[57]"])
    assert r.exit_code == 3 and "edge of the grid" in r.output
    assert json.loads(cli.invoke(main, ["summary", "f.h5", "--json"]).output)["status"] == "failed"


def test_debug_shows_the_traceback(cli, tmp_path):
    bad = _write(tmp_path, "name: x\n")
    assert "Traceback" not in cli.invoke(main, ["run", str(bad)]).output
    assert "Traceback" in cli.invoke(main, ["run", str(bad), "--debug"]).output


def test_summary_of_a_non_results_file_is_a_clear_error(cli, tmp_path):
    (tmp_path / "junk.h5").write_text("not hdf5")
    r = cli.invoke(main, ["summary", "junk.h5"])
    assert r.exit_code == 2 and "not a readable fretsim results file" in r.output


def test_linear_jump_beyond_the_limit_exits_2_with_the_limit(cli, tmp_path):
    r = cli.invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", "u.h5", "--set", "jumping.linear=80"])
    assert r.exit_code == 2 and "stability limit" in r.output and not (tmp_path / "u.h5").exists()


def test_the_readmes_case_and_sweep_examples_are_valid_as_printed(tmp_path):
    import re
    from fretsim.case import parse_case
    from fretsim.sweep import load_sweep
    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    blocks = re.findall(r"```yaml\n(.*?)```", readme, flags=re.S)
    case_blocks = [b for b in blocks if "geometry:" in b]
    sweep_blocks = [b for b in blocks if "axes:" in b]
    assert case_blocks and sweep_blocks
    for text in case_blocks:
        assert parse_case(text, source="README").loading.cycles > 0
    cases = Path(__file__).resolve().parent.parent / "cases"
    (tmp_path / "mccoll_185N.yaml").write_text((cases / "mccoll_185N.yaml").read_text())
    for text in sweep_blocks:  # its base is relative to cases/sweeps/, where the README says it lives
        sweep = tmp_path / "sweeps" / "s.yaml"
        sweep.parent.mkdir(exist_ok=True)
        sweep.write_text(text)
        assert len(load_sweep(sweep).points) == 20


def test_a_run_that_will_take_long_by_request_says_so_before_it_starts():
    """ΔN_L = 1 over 10⁹ cycles used to start without a word; a default run says nothing extra."""
    from fretsim.api import load_case
    from fretsim.cli import long_run_note
    from fretsim.plan import prepare
    case = load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=1000000000",
                                                  "jumping.scheme=linear", "jumping.linear=1",
                                                  "output.snapshots=[1000000000]"])
    note = long_run_note(prepare(case)[0])
    assert note is not None and "estimate: about 1,000,000,00" in note and ("years" in note or "days" in note)
    assert long_run_note(prepare(load_case(CASES / "mccoll_185N.yaml", []))[0]) is None


def test_an_override_that_is_not_utf8_is_refused_not_a_traceback(tmp_path):
    """A command line's undecodable bytes reach Python as lone surrogates, which h5py cannot store."""
    r = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "--set", "name=a\udc80b", "-o",
                                  str(tmp_path / "r.h5")])
    assert r.exit_code == 2 and "not valid UTF-8" in r.output and not (tmp_path / "r.h5").exists(), r.output


@pytest.mark.parametrize("kind", ["cylinder_on_flat", "ball_on_flat", "crossed_cylinders", "tube_on_flat",
                                  "roller_on_flat"])
def test_every_commented_line_of_a_template_parses_when_uncommented(kind):
    """The templates commented `scheme: auto` and `preset: auto`, which the parser refuses."""
    from fretsim.case import parse_case
    from fretsim.templates import template_text
    lines = template_text(kind).splitlines()
    for i, line in enumerate(lines):
        if line.startswith("  # ") and ":" in line:
            text = "\n".join(lines[:i] + [line.replace("# ", "", 1)] + lines[i + 1:])
            if "profile:" in line:  # names a CSV file the template does not ship
                continue
            parse_case(text)


def test_summary_refuses_two_formats_at_once(tmp_path):
    from fretsim.api import load_case, run
    run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=10"]), tmp_path / "r.h5")
    r = CliRunner().invoke(main, ["summary", str(tmp_path / "r.h5"), "--json", "--csv"])
    assert r.exit_code == 2 and "choose one" in r.output, r.output


def test_check_shows_hertz_and_refuses_or_warns_where_the_elastic_model_cannot_hold():
    """5 MN on a 5 mm ball (a half-width beyond the ball) and 1.7 GPa on aluminium used to pass `check` silently."""
    r = CliRunner().invoke(main, ["check", str(CASES / "ball_partial_slip.yaml"), "--set", "loading.normal_load=5 MN",
                                  "--set", "geometry.radius=5 mm"])
    assert r.exit_code == 2 and "loading.normal_load" in r.output and "half the body's radius" in r.output, r.output
    r = CliRunner().invoke(main, ["check", str(CASES / "ball_partial_slip.yaml"), "--set",
                                  "loading.normal_load=3000 N", "--set", "materials.moving.youngs_modulus=70 GPa",
                                  "--set", "materials.stationary.youngs_modulus=70 GPa"])
    assert r.exit_code == 0 and "peak pressure p0 = 1746 MPa" in r.output and "out of its range" in r.output
    r = CliRunner().invoke(main, ["check", str(CASES / "mccoll_185N.yaml")])
    assert "unworn contact (Hertz)" in r.output and "out of its range" not in r.output


def test_init_help_lists_the_shipped_cases_and_templates_and_completion_offers_them():
    r = CliRunner().invoke(main, ["init", "--help"])
    assert "mccoll_185N" in r.output and "ball_partial_slip" in r.output and "roller_on_flat" in r.output
    from fretsim.cli import _complete_kind
    assert "mccoll_1670N" in _complete_kind(None, None, "mccoll_1") and _complete_kind(None, None, "zz") == []


def test_autos_proxy_runs_are_announced_and_the_estimate_counts_them():
    """With `auto`, the proxies ran silently (49 s for the tube at 10⁸ cycles) while `check` estimated 0.23 s."""
    # a command's side runs are its own (no module-level cache): whatever ran before in this process, check runs
    # the proxies it announces
    r = CliRunner().invoke(main, ["check", str(CASES / "tube_RT.yaml"), "--set", "model.dimension=auto"])
    code, output = r.exit_code, r.output
    assert code == 0, output
    assert "model.dimension auto: a 3D proxy run" in output and "jumping.tolerance 0.01" in output
    # the total counts the run, its grid-error companions and the planning, which a run repeats
    m = re.search(r"about [0-9]+ contact solves, ([0-9.]+) s for the run .*companions \(2 runs on coarser grids\) "
                  r"about ([0-9.]+) s more; planning took ([0-9.]+) s here .*: about ([0-9.]+) s in all", output)
    assert m, output
    run_s, companions_s, planning_s, total_s = map(float, m.groups())
    assert planning_s > 1.0 and companions_s > 0
    assert total_s == pytest.approx(run_s + companions_s + planning_s, rel=0.1)  # each printed to 2 digits


def test_a_given_yield_strength_warns_where_hertz_passes_the_onset_of_yield_in_check_and_run(tmp_path):
    # p0 = 683.6 MPa on the partial-slip ball: over 1.60 σ_y (point contact) for σ_y = 400 MPa, not for 450 MPa
    case = str(CASES / "ball_partial_slip.yaml")
    r = CliRunner().invoke(main, ["check", case, "--set", "materials.stationary.yield_strength=400 MPa"])
    assert r.exit_code == 0 and "warning: the Hertz peak pressure p0 = 683.6 MPa passes the onset of yield in the " \
        "stationary body (1.6 × its yield strength 400 MPa = 640 MPa" in r.output, r.output
    assert "yield_strength: 400 MPa" in r.output  # kept in the filled case
    r = CliRunner().invoke(main, ["check", case, "--set", "materials.stationary.yield_strength=450 MPa"])
    assert r.exit_code == 0 and "onset of yield" not in r.output
    r = CliRunner().invoke(main, ["check", case, "--set", "materials.stationary.yield_strength=400 N"])
    assert r.exit_code == 2 and "yield_strength" in r.output and "is a force" in r.output
    r = CliRunner().invoke(main, ["run", case, "-o", str(tmp_path / "y.h5"), "--set", "loading.cycles=10",
                                  "--set", "materials.moving.yield_strength=0.4 GPa"])
    assert r.exit_code == 0 and "warning: the Hertz peak pressure" in r.output and "moving body" in r.output


def test_checks_filled_case_shows_six_significant_digits_not_binary_noise():
    r = CliRunner().invoke(main, ["check", str(CASES / "mccoll_185N.yaml"), "--set",
                                  "materials.stationary.wear_coefficient=3e-5 mm3/(N m)"])
    filled = r.output.split("filled case")[1]
    assert "wear_coefficient: 3e-08 1/MPa" in filled and "0000000" not in filled, filled
    assert not re.search(r"\d\.\d{7,}", filled), filled


def test_a_reader_that_goes_away_ends_the_command_quietly_with_141(tmp_path):
    import subprocess
    import sys
    code = subprocess.run(f"{sys.executable} -m fretsim check {CASES / 'mccoll_185N.yaml'} --set model.dimension=2d"
                          f" | head -c 10 > /dev/null; echo ${{PIPESTATUS[0]}}", shell=True, executable="/bin/bash",
                          capture_output=True, text=True, cwd=tmp_path)
    assert code.stdout.strip() == "141" and "Broken pipe" not in code.stderr and "Traceback" not in code.stderr, \
        (code.stdout, code.stderr)


def test_every_run_besides_the_runs_own_is_announced_and_a_proxy_is_not_run_twice(tmp_path):
    r = CliRunner().invoke(main, ["run", str(CASES / "tube_RT.yaml"), "-o", str(tmp_path / "t.h5"), "--set",
                                  "loading.cycles=20000"])
    code, output = r.exit_code, r.output
    assert code == 0, output
    said = [line.split("] ", 1)[1] for line in output.splitlines() if line.startswith("[")]
    assert any("twice as coarse" in s for s in said) and any("four times as coarse" in s for s in said), said
    assert any(s.startswith("model.dimension auto") for s in said), said
    assert len(said) == len(set(said)), said  # the dimension's proxy case has its own corrections' proxies, and says
    #                                           so (its looser tolerance)
    assert "grid-error companions" in output  # their time, beside the loop's


def test_a_run_after_check_in_one_process_does_not_repeat_autos_proxy_runs():
    # a notebook's check() then run() with one SideRuns: the planning is the same, so the proxies are reused
    from fretsim.api import check, load_case, run
    from fretsim.plan import SideRuns
    case = load_case(CASES / "tube_RT.yaml", ["loading.cycles=20000", "grid.error_estimate=none"])
    said: list = []
    runs = SideRuns(announce=said.append)
    check(case, runs)
    checked = len(said)
    out = run(case, runs=runs)
    assert checked >= 4 and len(said) == checked and out.status == "complete", said


def test_a_case_name_with_a_lone_surrogate_is_refused_naming_the_file_and_the_key(tmp_path):
    """YAML's "\\ud800" reads as a lone surrogate, which no UTF-8 file can hold: it was h5py's UnicodeEncodeError
    half-way into the run."""
    text = (CASES / "mccoll_185N.yaml").read_text().replace("name: mccoll_185N", 'name: "a\\ud800b"')
    case = _write(tmp_path, text)
    for command in (["run", str(case), "-o", str(tmp_path / "r.h5")], ["check", str(case)]):
        r = CliRunner().invoke(main, command)
        assert r.exit_code == 2 and f"{case}: name: " in r.output and "lone surrogate" in r.output, r.output
        assert "Traceback" not in r.output and not (tmp_path / "r.h5").exists(), r.output


def test_a_case_file_whose_name_is_not_utf8_is_refused_not_a_traceback(tmp_path):
    """Its name goes into the results file (/inputs case_file) as UTF-8; bytes that are not reach Python as lone
    surrogates, and h5py failed on them half-way into the run."""
    import os
    try:
        path = Path(os.fsdecode(os.fsencode(tmp_path) + b"/c\xff.yaml"))
        path.write_text((CASES / "mccoll_185N.yaml").read_text())
    except (OSError, UnicodeError):
        pytest.skip("this file system takes only UTF-8 names")
    for command in (["run", str(path), "-o", str(tmp_path / "r.h5")], ["check", str(path)]):
        r = CliRunner().invoke(main, command)
        assert r.exit_code == 2 and "name is not UTF-8" in r.output and "Traceback" not in r.output, r.output
        assert not (tmp_path / "r.h5").exists()


def _interrupted(path: Path, at_cycle: int = 0) -> Path:
    """A 2D run stopped as Ctrl-C stops it, after its first step past ``at_cycle``: its file says 'interrupted'."""
    from fretsim.api import load_case, run

    class Stop:
        def on_step(self, setup, step):
            if step.cycle > at_cycle:
                raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        run(load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "loading.cycles=500"]), path,
            observers=(Stop(),))
    return path


@pytest.mark.parametrize("command", ["run", "check", "fit"])
def test_a_results_file_given_as_a_case_is_named_for_what_it_is_with_the_commands_that_read_it(tmp_path, command):
    """It was 'the case file is not UTF-8 text (byte 0)', or for a large one 'the case file is 7.5 MB'."""
    results = _interrupted(tmp_path / "r.h5")
    measured = tmp_path / "m.csv"
    measured.write_text("cycle [cycles],max_wear_depth_stationary [um]\n18000,3.0\n")
    extra = ["--measured", str(measured)] if command == "fit" else []
    r = CliRunner().invoke(main, [command, str(results), *extra])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert f"{results} is a results file (HDF5, status 'interrupted')" in r.output, r.output
    assert f"fretsim run --resume {results}" in r.output and f"fretsim summary {results}" in r.output, r.output


def test_a_results_file_given_as_a_sweep_file_is_named_for_what_it_is(tmp_path):
    """It was 'the sweep file is not UTF-8 text'."""
    results = _interrupted(tmp_path / "r.h5")
    r = CliRunner().invoke(main, ["sweep", str(results), "-o", str(tmp_path / "out")])
    assert r.exit_code == 2 and "is an HDF5 file" in r.output and "not UTF-8" not in r.output, r.output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [["plot"], ["summary"], ["export", "--csv", "csv"], ["run", "--resume"]],
                         ids=["plot", "summary", "export", "resume"])
def test_a_case_given_where_a_results_file_is_expected_says_to_run_it_first(cli, tmp_path, command):
    """It was the reader's 'not a readable fretsim results file (OSError: … file signature not found)'."""
    case = _write(tmp_path, (CASES / "mccoll_185N.yaml").read_text())
    r = cli.invoke(main, [*command, str(case)])
    assert r.exit_code == 2 and "Traceback" not in r.output and "signature" not in r.output, r.output
    assert f"{case} is a case file (YAML)" in r.output and f"`fretsim run {case}`" in r.output, r.output
    assert not (tmp_path / "csv").exists()


def test_quiet_still_warns_that_an_estimated_error_exceeds_model_accuracy(tmp_path):
    """60 cycles on the automatic 2D grid estimate the scar width to about 2 %, over the case's 1 %: --quiet (no
    notes, no progress) hid that warning, which is about the results, not the run's progress."""
    args = ["run", str(CASES / "mccoll_185N.yaml"), "--set", "model.dimension=2d", "--set", "loading.cycles=60",
            "--set", "output.snapshots=[60]"]
    loud = CliRunner().invoke(main, [*args, "-o", str(tmp_path / "loud.h5")])
    quiet = CliRunner().invoke(main, [*args, "-o", str(tmp_path / "quiet.h5"), "--quiet"])
    assert loud.exit_code == 0 and quiet.exit_code == 0, (loud.output, quiet.output)
    warning = [line for line in loud.stderr.splitlines() if "exceeds model.accuracy" in line]
    assert len(warning) == 1 and warning[0].startswith("warning: the estimated error of"), loud.stderr
    assert warning[0] in quiet.stderr.splitlines(), quiet.stderr
    assert "note:" not in quiet.stderr and "note:" in loud.stderr  # the rest of what --quiet hides stays hidden
    assert quiet.stdout.startswith("mccoll_185N: 60 cycles") and "warning" not in quiet.stdout, quiet.stdout


def test_quiet_still_warns_where_the_model_is_out_of_its_range(tmp_path):
    """The plan's warnings (here: Hertz's p0 past the onset of yield) say the results may not hold: not progress."""
    r = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "--set", "model.dimension=2d", "--set",
                                  "loading.cycles=60", "--set", "output.snapshots=[60]", "--set",
                                  "materials.moving.yield_strength=100 MPa", "-o", str(tmp_path / "r.h5"), "--quiet"])
    assert r.exit_code == 0, r.output
    assert "warning: the Hertz peak pressure p0 = 328.4 MPa passes the onset of yield" in r.stderr, r.stderr


def test_a_fault_composing_the_paragraph_after_a_complete_run_never_turns_it_into_a_failure(tmp_path, monkeypatch):
    """μ = 0 once divided by δ_t = 0 in the paragraph, after the run had written a complete file: exit 1 and a
    traceback.  Whatever goes wrong in composing it, the run's exit code and file stand."""
    import fretsim.cli as cli_module

    def broken(*args):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(cli_module, "_regime", broken)
    out = tmp_path / "r.h5"
    r = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", str(out), "--set",
                                  "model.dimension=2d", "--set", "loading.cycles=100", "--set",
                                  "grid.error_estimate=none"])
    assert r.exit_code == 0 and "fretsim summary" in r.output and "Traceback" not in r.output, r.output
    assert read_results(out).status == "complete"


def test_summary_prints_a_dash_where_no_value_applies_and_marks_an_assumed_regime(tmp_path):
    """It printed Python's None for a value that does not apply (no wear limit, the y element of a 2D run) and
    'gross_slip' for a regime no friction coefficient judged; JSON keeps null and the bare regime."""
    import json
    out = tmp_path / "r.h5"
    r = CliRunner().invoke(main, ["run", str(CASES / "mccoll_185N.yaml"), "-o", str(out), "--set", "model.dimension=2d",
                                  "--set", "loading.cycles=100", "--set", "grid.error_estimate=none"])
    assert r.exit_code == 0, r.output
    text = CliRunner().invoke(main, ["summary", str(out)]).output
    assert "None" not in text
    rows = dict(line.split(None, 1) for line in text.splitlines() if line and not line.startswith(("inputs", "overrides")))
    assert rows["cycles_to_limit"] == "–" and rows["element_size_y_um"] == "–"
    assert rows["regime"] == "gross_slip (assumed)"
    data = json.loads(CliRunner().invoke(main, ["summary", str(out), "--json"]).output)
    assert data["cycles_to_limit"] is None and data["regime"] == "gross_slip"
