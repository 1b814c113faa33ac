"""`fretsim validate`: the published cases, one report, expected values read from each case file (issue #12)."""
import shutil
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

import fretsim.validate as validate_module
from fretsim.case import CaseError, load_case
from fretsim.cli import main

CASES = Path(__file__).resolve().parent.parent / "cases"
TABLE4 = ["kirk_450N_100Hz", "kirk_450N_200Hz", "kirk_450N_20Hz", "mccoll_1670N", "mccoll_185N", "mccoll_500N",
          "mccoll_500N_10um", "s132_250N_100um"]


def test_every_published_case_ships_with_its_expected_values():
    names = validate_module.shipped_with_expected()
    assert set(TABLE4) <= set(names)  # Table 4's eight
    assert {f"table1_case{i}" for i in range(1, 5)} <= set(names)  # Table 1's four
    assert {"wire_rope", "seat_rail", "tube_RT", "tube_90C"} <= set(names)  # section 4
    for n in TABLE4:
        e = validate_module.expected_of(load_case(CASES / f"{n}.yaml"))
        assert "centre_wear_depth_stationary" in e.values["paper"] and "Table 4" in e.source


def test_a_malformed_expected_section_names_the_file_and_the_key(tmp_path):
    text = (CASES / "mccoll_185N.yaml").read_text().replace("scar_width_stationary: 0.54 mm", "scar_width: 0.54")
    (tmp_path / "c.yaml").write_text(text)
    with pytest.raises(CaseError) as info:
        validate_module.expected_of(load_case(tmp_path / "c.yaml"))
    assert "expected.experiment.scar_width" in str(info.value)


def test_quick_validation_reports_against_experiment_fea_and_paper_reading_each_case_file(tmp_path, monkeypatch):
    # a copy of the cases with one experimental value changed: the report must show the file's number
    cases = tmp_path / "cases"
    shutil.copytree(CASES, cases)
    p = cases / "mccoll_185N.yaml"
    p.write_text(p.read_text().replace("centre_wear_depth_stationary: 2.9 um", "centre_wear_depth_stationary: 2.7 um"))
    monkeypatch.setattr(validate_module, "CASES", cases)
    out = validate_module.validate(["mccoll_185N", "mccoll_500N_10um", "table1_case1"], tmp_path / "v", jobs=2,
                                   quick=True)
    assert out["ok"]
    report = out["report"].read_text()
    row = next(line for line in report.splitlines() if line.startswith("| mccoll_185N"))
    assert "| 2.7 |" in row and "| 2D |" in row
    assert "MAPE against experiment" in report and (tmp_path / "v" / "table4.png").exists()
    assert "| table1_case1 | 0.036 |" in report
    # each case's worn profile drawn against its published depth and width (the file's 2.7 µm for 185 N)
    assert "![profiles](profiles.png)" in report and (tmp_path / "v" / "profiles.png").exists()
    profile = out["results"]["mccoll_185N"]["profile_stationary_um"]
    assert max(profile) == pytest.approx(out["results"]["mccoll_185N"]["summary"]["centre_wear_depth_stationary_um"])


def test_the_report_draws_the_section_4_scenes_worn_profiles_of_both_bodies(tmp_path):
    """The paper gives the wire rope and the seat rail as figures only: the report shows fretsim's worn profiles
    of both bodies for each section-4 scene (here the wire rope, quick), the moving body's from its own run."""
    out = validate_module.validate(["wire_rope"], tmp_path / "v", jobs=1, quick=True)
    assert out["ok"]
    report = out["report"].read_text()
    assert "![section 4](section4.png)" in report and (tmp_path / "v" / "section4.png").exists()
    res = out["results"]["wire_rope"]
    assert max(res["profile_moving_um"]) == pytest.approx(res["summary"]["centre_wear_depth_moving_um"])
    assert len(res["profile_moving_um"]) == len(res["profile_x_mm"])


def test_friction_validation_runs_each_cycle_model_with_the_fe_bodies_against_the_files_fea(tmp_path, monkeypatch):
    # the FEA value changed in a copy: the section and its MAPE must be computed from the file's number
    cases = tmp_path / "cases"
    shutil.copytree(CASES, cases)
    p = cases / "mccoll_500N_10um.yaml"
    text = p.read_text()
    assert "fea: {centre_wear_depth_stationary: 4.0 um" in text
    p.write_text(text.replace("fea: {centre_wear_depth_stationary: 4.0 um", "fea: {centre_wear_depth_stationary: 4.4 um"))
    monkeypatch.setattr(validate_module, "CASES", cases)
    out = validate_module.validate(["mccoll_500N_10um", "table1_case1"], tmp_path / "v", jobs=1, quick=True,
                                   friction=True)
    assert out["ok"]
    friction = {k: r for k, r in out["results"].items() if k.startswith("friction:")}
    # one run per model of the cycle, in 2D (quick), the ball (no FEA, no block) left out
    assert sorted(friction) == sorted(f"friction:mccoll_500N_10um:2d:{m}" for m in validate_module.FRICTION_MODELS)
    for r in friction.values():
        assert set(validate_module.FE_MODEL) <= set(r["overrides"])
    report = out["report"].read_text()
    assert "## Table 4 with the FE model's friction and bodies" in report
    depth = {m: friction[f"friction:mccoll_500N_10um:2d:{m}"]["summary"]["centre_wear_depth_stationary_um"]
             for m in validate_module.FRICTION_MODELS}
    # the models differ (friction and the resolved stroke move the depth), so the rows cannot be one run repeated
    assert len({round(d, 4) for d in depth.values()}) == 3
    for m, d in depth.items():
        row = next(line for line in report.splitlines() if line.startswith(f"| 2D | {m} |"))
        assert row.split("|")[3].strip() == f"{100 * abs(d - 4.4) / 4.4:.1f} %"  # depth vs the file's FEA


def test_validate_refuses_an_unknown_case_name():
    r = CliRunner().invoke(main, ["validate", "no_such_case"])
    assert r.exit_code == 2 and "no shipped case" in r.output


@pytest.mark.slow
def test_the_whole_set_runs_in_under_five_minutes_within_1pct_of_the_papers_model_depth(tmp_path):
    t = time.perf_counter()
    out = validate_module.validate(validate_module.shipped_with_expected(), tmp_path / "v")
    assert time.perf_counter() - t < 300 and out["ok"]
    for n in TABLE4:
        paper = validate_module.expected_of(load_case(CASES / f"{n}.yaml")).values["paper"]["centre_wear_depth_stationary"]
        ours = out["results"][n]["summary"]["centre_wear_depth_stationary_um"]
        assert ours == pytest.approx(paper, rel=0.01), n
