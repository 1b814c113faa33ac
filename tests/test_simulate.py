"""The contact–wear loop: the paper's Table 4, conservation, convergence, stability, and the results contract."""
import functools
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import check_archard_results
from fretsim.api import run
from fretsim.case import CaseError, load_case
from fretsim.results import FIELDS, HISTORY, read_results
from fretsim.measures import centre_line

CASES = Path(__file__).resolve().parent.parent / "cases"
# Kong et al. Table 4, "current method": stationary centre-line depth (µm) and scar width (mm)
TABLE4 = {"mccoll_185N": (3.0, 0.55), "mccoll_500N": (9.0, 0.87), "mccoll_1670N": (13.4, 1.08),
          "mccoll_500N_10um": (4.5, 0.62)}
DEPTH_TOL = 0.05  # issue #3: Table 4 depths within 5 %
WIDTH_TOL = 0.10  # and scar widths within 10 % (the paper's grid is coarser: widths move by elements)
CONVERGED = 0.01  # halving the jump and the element size moves the depth by < 1 %
# issue #9's target for the depths of the default steps against the exact per-cycle model; explicit jumps below the
# stability limit meet it on the paper's grid too (measured 7e-6 for jumps of 38 and 42 cycles)
STEPPING = 1e-3


# under pytest-xdist the module runs on one worker: its tests share the runs results_of keeps
pytestmark = pytest.mark.xdist_group("test_simulate")


@pytest.fixture(scope="session")  # per worker, once: xdist interleaves modules, a module fixture is rebuilt
def results_of(tmp_path_factory):
    """Runs a shipped case into this module's temporary directory once per process; its results as read back."""
    out_dir = tmp_path_factory.mktemp("simulate")

    @functools.lru_cache(maxsize=None)
    def results_of(name: str, dimension: str, *overrides: str):
        case = load_case(CASES / f"{name}.yaml", [f"model.dimension={dimension}", *overrides])
        path = out_dir / f"{name}-{dimension}-{abs(hash(overrides))}.h5"
        out = run(case, path, overwrite=True)
        assert out.status == "complete", out.message
        return read_results(path)

    return results_of


@pytest.fixture(scope="session")  # per worker, once: xdist interleaves modules, a module fixture is rebuilt
def summary_of(results_of):
    return lambda name, dimension, *overrides: results_of(name, dimension, *overrides).summary


@pytest.mark.parametrize("name", sorted(TABLE4))
def test_table4_depth_and_scar_width_in_3d(name, results_of):
    depth, width = TABLE4[name]
    res = results_of(name, "3d")
    s = res.summary
    assert s["centre_wear_depth_stationary_um"] == pytest.approx(depth, rel=DEPTH_TOL)
    assert s["scar_width_stationary_mm"] == pytest.approx(width, rel=WIDTH_TOL)
    check_archard_results(res)  # the worn volumes, summed from the written fields, are k·P·4δ·N


@pytest.mark.parametrize("name", sorted(TABLE4))
def test_2d_centre_line_agrees_with_3d_within_the_end_load_share(name, results_of):
    # A finite cylinder's end peaks take part of the load off its centre line, most at the start (Fig. 5).
    # Wear depth follows the load, so the 3D/2D centre-line depth ratio must lie between the smallest and the
    # largest share of P/L the 3D centre line carries during the run (0.94-0.998 for these cases).
    r2, r3 = results_of(name, "2d"), results_of(name, "3d")
    load_per_length = float(name.split("_")[1].rstrip("N")) / 10.0
    shares = [centre_line(p).sum() * (r3.x[1] - r3.x[0]) / load_per_length for p in r3.fields["pressure"]]
    for body in ("stationary", "moving"):
        key = f"centre_wear_depth_{body}_um"
        ratio = r3.summary[key] / r2.summary[key]
        assert min(shares) <= ratio <= max(shares), (ratio, shares)
    check_archard_results(r2)  # per unit length in 2D: the volume needs the line length


def test_halving_the_jump_and_the_element_size_changes_the_depth_by_under_1pct(summary_of):
    base = summary_of("mccoll_185N", "2d", "jumping.scheme=linear")
    nx = base["elements_x"]
    domain = nx * base["element_size_x_um"] * 1e-3
    fine = summary_of("mccoll_185N", "2d", "jumping.scheme=linear", f"jumping.linear={base['linear_jump'] // 2}",
                      f"grid.domain=[{domain!r} mm]", f"grid.elements=[{2 * nx}]")
    assert fine["element_size_x_um"] == pytest.approx(base["element_size_x_um"] / 2)
    assert fine["centre_wear_depth_stationary_um"] == pytest.approx(base["centre_wear_depth_stationary_um"],
                                                                    rel=CONVERGED)


def test_3d_wear_exceeds_the_centre_line_near_the_cylinder_ends(summary_of):
    s = summary_of("mccoll_185N", "3d")
    assert s["max_wear_depth_stationary_um"] > s["centre_wear_depth_stationary_um"]  # end effect (Fig. 5)


def test_linear_jumps_just_below_the_limit_are_not_false_alarms(results_of):
    # issue #9: jumps of 38-42 cycles (limit 42.7) used to stop with a checkerboard alarm; their modes decay, so the
    # whole run lands where the default steps do on the same grid, and keeps Archard's volume
    implicit = results_of("mccoll_185N", "2d", "grid.rule=paper").summary
    for jump in (38, 42):  # on the paper's grid, where that limit is
        res = results_of("mccoll_185N", "2d", f"jumping.linear={jump}", "grid.rule=paper")
        s = res.summary
        assert s["cycles"] == 18000 and s["linear_jump"] == jump and s["stability_limit_linear"] > jump
        for key in ("centre_wear_depth_stationary_um", "max_wear_depth_stationary_um", "max_wear_depth_moving_um"):
            assert s[key] == pytest.approx(implicit[key], rel=STEPPING), key
        check_archard_results(res)


def test_contact_outgrowing_the_grid_stops_with_an_edge_error():
    case = load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "grid.domain=[0.35 mm]",
                                                    "grid.elements=[57]"])
    out = run(case)
    assert out.status == "failed" and "edge of the grid" in out.message


def test_contact_only_run_writes_the_initial_pressure(tmp_path):
    case = load_case(CASES / "mccoll_185N.yaml", ["loading.cycles=0", "model.dimension=2d"])
    out = run(case, tmp_path / "c0.h5")
    res = read_results(tmp_path / "c0.h5")
    assert out.status == "complete" and list(res.fields["cycle"]) == [0]
    assert res.summary["contact_solves"] == 1 and res.summary["max_wear_depth_stationary_um"] == 0.0
    p = res.fields["pressure"][0, 0]
    assert p.sum() * (res.x[1] - res.x[0]) == pytest.approx(18.5, rel=1e-10)  # N/mm over the strip


def test_grid_too_coarse_is_a_case_error_and_writes_nothing(tmp_path):
    case = load_case(CASES / "mccoll_185N.yaml", ["model.dimension=2d", "grid.domain=[1 mm]", "grid.elements=[31]"])
    with pytest.raises(CaseError, match="too coarse"):
        run(case, tmp_path / "x.h5")
    assert not (tmp_path / "x.h5").exists()


def test_results_file_follows_the_contract(tmp_path):
    case = load_case(CASES / "mccoll_185N.yaml", ["loading.cycles=400", "output.snapshots=[100, 400]"])
    run(case, tmp_path / "r.h5")
    with h5py.File(tmp_path / "r.h5", "r") as f:
        assert {"format_version", "fretsim_version", "status"} <= set(f.attrs) and f.attrs["status"] == "complete"
        assert "jumping" in f["case"][()].decode()
        assert f["grid/x"].shape == (f["fields/pressure"].shape[2],) and f["grid/y"].shape == (27,)
        for name in HISTORY:
            assert f[f"history/{name}"].attrs["units"] and f[f"history/{name}"].shape[0] >= 2
        for name in list(FIELDS) + ["cycle"]:
            assert f[f"fields/{name}"].attrs["units"] and f[f"fields/{name}"].shape[0] == 2
        assert list(f["fields/cycle"][()]) == [100, 400] and f["history/cycle"][-1] == 400
        required = {"cycles", "contact_solves", "wall_time_s", "max_wear_depth_moving_um",
                    "max_wear_depth_stationary_um", "centre_wear_depth_moving_um", "centre_wear_depth_stationary_um",
                    "scar_width_stationary_mm", "wear_volume_moving_mm3", "wear_volume_stationary_mm3",
                    "archard_volume_error"}
        assert required <= set(f["summary"].attrs)
    again = load_case(CASES / "mccoll_185N.yaml")
    stored = read_results(tmp_path / "r.h5").case_yaml
    assert "linear: " in stored and "elements:" in stored and again.name in stored


def test_runs_are_deterministic(tmp_path):
    for k in (1, 2):
        run(load_case(CASES / "mccoll_500N_10um.yaml", ["model.dimension=2d", "loading.cycles=2000"]),
            tmp_path / f"{k}.h5")
    a, b = read_results(tmp_path / "1.h5"), read_results(tmp_path / "2.h5")
    for name in FIELDS:
        assert np.array_equal(a.fields[name], b.fields[name], equal_nan=True)


def test_wear_loop_with_the_papers_msm_matches_cg(results_of):
    # two independent solvers in the full loop: every step's pressure agrees to solver tolerance, so must the wear
    a = results_of("mccoll_185N", "2d", "loading.cycles=2000", "solver.method=msm")
    b = results_of("mccoll_185N", "2d", "loading.cycles=2000", "solver.method=cg", "solver.tolerance=1e-12")
    for name in ("wear_depth_stationary", "wear_depth_moving", "pressure"):
        assert np.abs(a.fields[name] - b.fields[name]).max() <= 1e-6 * np.abs(b.fields[name]).max()


@pytest.mark.slow
def test_3d_halving_the_jump_and_the_element_size_changes_the_depth_by_under_1pct(summary_of):
    base = summary_of("mccoll_185N", "3d", "jumping.scheme=linear")
    nx, ny = base["elements_x"], base["elements_y"]
    domain = nx * base["element_size_x_um"] * 1e-3
    fine = summary_of("mccoll_185N", "3d", "jumping.scheme=linear", f"jumping.linear={base['linear_jump'] // 2}",
                      f"grid.domain=[{domain!r} mm, 10 mm]", f"grid.elements=[{2 * nx}, {ny}]")
    assert fine["centre_wear_depth_stationary_um"] == pytest.approx(base["centre_wear_depth_stationary_um"],
                                                                    rel=CONVERGED)
    assert fine["scar_width_stationary_mm"] == pytest.approx(base["scar_width_stationary_mm"], rel=WIDTH_TOL)
