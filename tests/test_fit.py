"""`fretsim fit` refuses what it cannot fit, each with its reason, and never hangs, overwrites its inputs or loses
the settings it fitted under (issue 31, part three)."""
import csv
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from fretsim.api import load_case, run
from fretsim.cli import main
from fretsim.export import export_csv
from fretsim.fit import fit, read_measured
from fretsim.results import read_results

CASES = Path(__file__).resolve().parent.parent / "cases"
CASE = CASES / "mccoll_185N.yaml"
TWO_D = "model.dimension=2d"
K_MOVING, K_STATIONARY = 3e-8, 1.2e-8  # the truth the synthetic measurements come from
# run with the model the fit's runs use (the stroke-averaged gap: fretsim.fit._Grid), so that the fit can recover
# it: against the case's own mid-stroke gap the coefficients differ by 0.3 %, outside the intervals of noiseless data
TRUTH = [TWO_D, "model.gap=stroke_average", f"materials.moving.wear_coefficient={K_MOVING} 1/MPa",
         f"materials.stationary.wear_coefficient={K_STATIONARY} 1/MPa", "output.snapshots=[3000, 9000, 18000]",
         "grid.error_estimate=none", "jumping.tolerance=1e-3"]
DEPTHS = "cycle [cycles],max_wear_depth_moving [um],max_wear_depth_stationary [um]"


@pytest.fixture(scope="session")  # per worker, once
def truth(tmp_path_factory):
    """A 2D run with known coefficients, its depths at three cycles (measured.csv) and its exported CSVs."""
    tmp = tmp_path_factory.mktemp("fit_truth")
    run(load_case(CASE, TRUTH), tmp / "truth.h5")
    res = read_results(tmp / "truth.h5")
    lines = [DEPTHS]
    for i, c in enumerate(res.fields["cycle"]):
        if c:
            lines.append(f"{c},{res.fields['wear_depth_moving'][i].max():.5g},"
                         f"{res.fields['wear_depth_stationary'][i].max():.5g}")
    (tmp / "measured.csv").write_text("\n".join(lines) + "\n")
    export_csv(res, tmp / "export")
    return tmp


def fit_cli(*args, timeout=None):
    """The command in a subprocess (a hang is a failure after ``timeout`` s, not a stuck suite)."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parent.parent)}
    return subprocess.run([sys.executable, "-m", "fretsim", "fit", *map(str, args)], capture_output=True,
                          text=True, timeout=timeout, env=env)


def refused(r, *words):
    out = r.output if hasattr(r, "output") else r.stdout + r.stderr
    code = r.exit_code if hasattr(r, "exit_code") else r.returncode
    assert code == 2, out
    assert "Traceback" not in out, out
    for w in words:
        assert w in out, (w, out)
    return out


# --- 1. -o never names an input ------------------------------------------------------------------------------------

def test_fit_refuses_an_output_that_is_its_measured_file_and_leaves_the_measurements(truth, tmp_path):
    measured = tmp_path / "m.csv"
    measured.write_bytes((truth / "measured.csv").read_bytes())
    before = measured.read_bytes()
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(measured), "--set", TWO_D, "-o",
                                  str(measured)])
    refused(r, "measured file")
    assert measured.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]


def test_fit_refuses_an_output_that_is_its_case_file_under_another_name(truth, tmp_path):
    """A hard link is the same file by another name: the same inode is refused, not only the same path."""
    case = tmp_path / "case.yaml"
    case.write_bytes(CASE.read_bytes())
    os.link(case, tmp_path / "alias.yaml")
    r = CliRunner().invoke(main, ["fit", str(case), "--measured", str(truth / "measured.csv"), "--set", TWO_D,
                                  "-o", str(tmp_path / "alias.yaml")])
    refused(r, "case file")
    assert case.read_bytes() == CASE.read_bytes()


# --- 2. a cycle that is no whole number ----------------------------------------------------------------------------

@pytest.mark.parametrize("cycle", ["inf", "-inf", "nan", "1e400", "2.5", "0.5"])
def test_a_measured_cycle_that_is_not_a_whole_number_above_0_is_refused_naming_its_row(tmp_path, cycle):
    path = tmp_path / "m.csv"
    path.write_text(f"cycle [cycles],max_wear_depth_stationary [um]\n1000,0.1\n{cycle},1\n")
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(path)])
    refused(r, str(path), "row 3", "cycle", "whole number")


# --- 3. a measured file is a small regular file --------------------------------------------------------------------

def _fifo(tmp_path):
    path = tmp_path / "fifo.csv"
    os.mkfifo(path)
    return path, "regular"


def _zero(tmp_path):
    return Path("/dev/zero"), "regular"


def _huge(tmp_path):
    path = tmp_path / "huge.csv"
    with open(path, "wb") as fh:  # sparse: 50 MB on paper, nothing on disk
        fh.write(b"cycle [cycles],max_wear_depth_stationary [um]\n")
        fh.truncate(50_000_000)
    return path, "50.0 MB"


def _long(tmp_path):
    path = tmp_path / "long.csv"
    path.write_text("cycle [cycles],max_wear_depth_stationary [um]\n" + "".join(f"{n},0.5\n" for n in
                                                                                range(1, 20_002)))
    return path, "rows"


@pytest.mark.parametrize("make", [_fifo, _zero, _huge, _long], ids=["fifo", "dev_zero", "50MB", "20000_rows"])
def test_a_measured_file_that_is_not_a_small_regular_file_is_refused_at_once(tmp_path, make):
    path, reason = make(tmp_path)
    r = fit_cli(CASE, "--measured", path, timeout=30)
    refused(r, str(path), reason)


@pytest.mark.parametrize("make", [_fifo, lambda tmp: (tmp / "none.yaml", "does not exist")], ids=["fifo", "missing"])
def test_a_case_file_that_cannot_be_read_is_bad_input_to_fit(truth, tmp_path, make):
    path, reason = make(tmp_path)
    r = fit_cli(path, "--measured", truth / "measured.csv", timeout=30)
    refused(r, str(path), reason)


# --- 4. the fit's runs hold the contact within its bounds; columns the geometry has not are refused -----------------

def test_a_fit_started_three_times_below_the_truth_holds_the_contact_and_finds_it(truth):
    """A normal first guess, both coefficients 3× low: the searches beyond them once ran off the grid (exit 3)."""
    low = [TWO_D, f"materials.moving.wear_coefficient={K_MOVING / 3} 1/MPa",
           f"materials.stationary.wear_coefficient={K_STATIONARY / 3} 1/MPa"]
    res = fit(CASE.read_text(), str(CASE), read_measured(truth / "measured.csv"), overrides=low)
    assert res.converged, res.message
    for true, lo, hi in zip((K_MOVING, K_STATIONARY), res.low, res.high):
        assert lo <= true <= hi, (true, lo, hi)


def test_a_fit_to_one_measured_depth_holds_the_contact(tmp_path, truth):
    """One datum for both coefficients, both started 3× low: nothing pins the pair, and the search wanders to
    wear the grid planned at the starting values did not hold (a stop at the x edge, exit 3)."""
    last = (truth / "measured.csv").read_text().splitlines()[-1].split(",")
    path = tmp_path / "one.csv"
    path.write_text(f"cycle [cycles],max_wear_depth_stationary [um]\n{last[0]},{last[2]}\n")
    low = [TWO_D, f"materials.moving.wear_coefficient={K_MOVING / 3} 1/MPa",
           f"materials.stationary.wear_coefficient={K_STATIONARY / 3} 1/MPa"]
    res = fit(CASE.read_text(), str(CASE), read_measured(path), overrides=low)
    assert res.dof == -1 and abs(res.residuals[0]) < 1e-3
    # a combination of the two is fitted, neither alone: not determined (the CLI exits 3 and writes no case)
    assert res.undetermined == res.keys and not res.determined


def test_a_wall_loss_column_on_a_cylinder_is_refused_by_name(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("cycle [cycles],wall_loss [%]\n18000,20\n")
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(path), "--set", TWO_D])
    refused(r, "wall_loss", "cylinder_on_flat", "wall")


# --- 5. the fitted case is the case the fit ran ---------------------------------------------------------------------

def test_the_fitted_case_keeps_the_set_overrides_and_reruns_to_the_fitted_depth(truth, tmp_path):
    out = tmp_path / "fitted.yaml"
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(truth / "measured.csv"), "--set", TWO_D,
                                  "--set", f"materials.moving.wear_coefficient={K_MOVING} 1/MPa",
                                  "--fit", "materials.stationary.wear_coefficient", "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert "\r" not in r.output and re.search(r"^\d+ runs, ", r.output, re.M)  # off a terminal: the total only
    fitted = load_case(out)
    assert fitted.dimension == "2d"
    assert fitted.moving.wear_coefficient == K_MOVING
    printed = float(re.search(r"materials.stationary.wear_coefficient = (\S+)", r.output).group(1))
    assert fitted.stationary.wear_coefficient == pytest.approx(printed, rel=1e-3)
    model = float(re.search(r"18,000  max_wear_depth_stationary: measured \S+ µm, model (\S+) µm", r.output)
                  .group(1))
    again = run(fitted, tmp_path / "again.h5")
    assert again.summary["max_wear_depth_stationary_um"] == pytest.approx(model, rel=0.01)


# --- 6. the history `fretsim export` writes -------------------------------------------------------------------------

def test_fit_reads_the_history_export_writes_and_names_the_columns_it_ignores(truth):
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(truth / "export" / "history.csv"),
                                  "--set", TWO_D, "--set", f"materials.moving.wear_coefficient={K_MOVING} 1/MPa",
                                  "--fit", "materials.stationary.wear_coefficient"])
    assert r.exit_code == 0, r.output
    note = next(line for line in r.output.splitlines() if line.startswith("note:") and "max_pressure" in line)
    assert "max_wear_depth_total" in note and "wear_volume_stationary" not in note
    value = float(re.search(r"materials.stationary.wear_coefficient = (\S+)", r.output).group(1))
    assert value == pytest.approx(K_STATIONARY, rel=0.03)


def test_a_file_whose_every_column_is_one_fit_cannot_use_is_refused_naming_them(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("cycle [cycles],max_pressure [MPa],solver_iterations\n100,300,4\n")
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(path)])
    refused(r, "max_pressure", "solver_iterations", "no column")


# --- 7. a unit slip ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("header, row, column", [
    ("cycle [cycles],max_wear_depth_stationary [mm]", "18000,1.28", "max_wear_depth_stationary [mm]"),
    ("cycle [cycles],scar_width_stationary [um]", "18000,0.51", "scar_width_stationary [um]"),
    ("cycle [cycles],scar_width_stationary [um]", "18000,510000", "scar_width_stationary [um]"),
])
def test_measured_values_a_unit_slip_away_from_the_case_are_refused_naming_the_column_and_unit(tmp_path, header,
                                                                                             row, column):
    path = tmp_path / "m.csv"
    path.write_text(f"{header}\n{row}\n")
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(path), "--set", TWO_D])
    refused(r, str(path), column, "unit")


def test_the_fits_grid_is_widened_only_when_a_trial_outgrows_it(truth):
    """Sizing the grid for the top of the search (1000×) up front made every 3D fit dearer by its elements' ratio
    (2.6× a run on McColl 3D, ~28× on a ball).  Started at the truth, a fit runs on the grid its starting values
    plan; started 30× below both, its trials outgrow that grid, the grid is widened (with a note) and the fit
    still finds the truth within its intervals."""
    measured = read_measured(truth / "measured.csv")
    for factor, widened in ((1, False), (30, True)):
        notes = []
        start = [TWO_D, f"materials.moving.wear_coefficient={K_MOVING / factor} 1/MPa",
                 f"materials.stationary.wear_coefficient={K_STATIONARY / factor} 1/MPa"]
        res = fit(CASE.read_text(), str(CASE), measured, overrides=start, note=notes.append)
        assert res.converged and bool(notes) == widened, (factor, notes, res.message)
        for true, lo, hi in zip((K_MOVING, K_STATIONARY), res.low, res.high):
            assert lo <= true <= hi, (factor, true, lo, hi)


def test_a_start_whose_top_of_the_search_is_beyond_the_plausible_range_is_searched_not_refused(truth):
    """A starting coefficient of 2e-7 1/MPa puts the top of the search (1000×) beyond the case reader's plausible
    1e-4: the unit-slip check built that case and refused the fit before any run, naming a value the user never
    gave.  The bound is capped at the plausible top, and the fit runs (here down to the truth's 1.2e-8)."""
    measured = read_measured(truth / "measured.csv")
    start = [TWO_D, f"materials.moving.wear_coefficient={K_MOVING} 1/MPa",
             "materials.stationary.wear_coefficient=2e-7 1/MPa"]
    res = fit(CASE.read_text(), str(CASE), measured, keys=("materials.stationary.wear_coefficient",), overrides=start)
    assert res.low[0] <= K_STATIONARY <= res.high[0], (res.values, res.low, res.high, res.message)


# --- 7. the energy law's α ------------------------------------------------------------------------------------------

ENERGY = [TWO_D, "loading.friction_coefficient=0.9", "model.slip=coulomb", "model.stroke=mid_stroke",
          "model.wear_law=energy", "materials.moving.energy_wear_coefficient=2e-5 mm3/J", "grid.error_estimate=none",
          "loading.cycles=3000", "output.snapshots=[1000, 2000, 3000]"]
ALPHA_STATIONARY = 3e-5  # mm³/J: the truth


def test_fit_recovers_the_energy_laws_alpha_from_the_history_an_energy_run_exports(tmp_path):
    """`--fit materials.stationary.energy_wear_coefficient` under `model.wear_law: energy`, started 2× high, finds
    the α the measurements were made with from the run's exported history.csv at its recorded states (its
    cumulative dissipated energy, not a wear quantity, noted and left out) within its interval."""
    run(load_case(CASE, [*ENERGY, f"materials.stationary.energy_wear_coefficient={ALPHA_STATIONARY} mm3/J"]),
        tmp_path / "truth.h5")
    export_csv(read_results(tmp_path / "truth.h5"), tmp_path / "export")
    header, *rows = (tmp_path / "export" / "history.csv").read_text().splitlines()
    measured = tmp_path / "measured.csv"  # every step's row would be a snapshot of every trial run
    measured.write_text("\n".join([header, *(r for r in rows if r.split(",")[0] in ("1000", "2000", "3000"))]) + "\n")
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(measured),
                                  *[a for s in ENERGY for a in ("--set", s)], "--set",
                                  f"materials.stationary.energy_wear_coefficient={2 * ALPHA_STATIONARY} mm3/J",
                                  "--fit", "materials.stationary.energy_wear_coefficient"])
    assert r.exit_code == 0, r.output
    note = next(line for line in r.output.splitlines() if line.startswith("note:") and "max_pressure" in line)
    assert "cumulative_dissipated_energy_J" in note
    found = re.search(r"materials.stationary.energy_wear_coefficient = (\S+) mm3/\(N\*mm\)  \(95 % CI \[(\S+) "
                      r"mm3/\(N\*mm\), (\S+) mm3/\(N\*mm\)\]", r.output)
    value, low, high = (float(v) * 1e3 for v in found.groups())  # mm³/(N·mm) → mm³/J
    assert value == pytest.approx(ALPHA_STATIONARY, rel=0.01) and low <= ALPHA_STATIONARY <= high, r.output


# --- 7. what a review found (2026-11-28): limits, undetermined values, unit slips, the Jacobian's step -------------

def test_a_fit_of_a_case_with_a_wear_limit_runs_every_trial_to_the_last_measured_cycle(truth):
    """A trial that wears faster than the measurements stopped at the case's limit before the last measured cycle,
    and the fit crashed (KeyError, a traceback): its runs now go without the limits, and find the truth."""
    depths = (truth / "measured.csv").read_text().splitlines()
    last = float(depths[-1].split(",")[2])
    sets = [TWO_D, f"limits.max_wear_depth_stationary={last * 1.05} um",
            f"materials.moving.wear_coefficient={K_MOVING * 1.5} 1/MPa",
            f"materials.stationary.wear_coefficient={K_STATIONARY * 1.5} 1/MPa"]
    res = fit(CASE.read_text(), str(CASE), read_measured(truth / "measured.csv"), overrides=sets)
    assert res.converged and res.determined, res.message
    assert res.values == pytest.approx([K_MOVING, K_STATIONARY], rel=0.01)


def test_values_the_data_do_not_determine_fail_the_fit_and_write_no_case(truth, tmp_path):
    """The flat's worn volume alone is k_s·P·4δ·N: it says nothing of k_m.  The fit printed k_m as if fitted (no
    interval, the reason unsaid) and exited 0 with the fitted case written; now it names the value it cannot
    determine and exits 3, writing nothing."""
    rows = list(csv.DictReader((truth / "export" / "history.csv").open()))
    volume = next(k for k in rows[0] if k.startswith("wear_volume_stationary"))
    path = tmp_path / "v.csv"
    path.write_text("cycle [cycles],wear_volume_stationary [mm3]\n" + "".join(
        f"{r['cycle [cycles]']},{r[volume]}\n" for r in rows[1:] if float(r[volume]) > 0))
    out = tmp_path / "fitted.yaml"
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(path), "--set", TWO_D, "-o", str(out)])
    assert r.exit_code == 3, r.output
    assert "do not determine materials.moving.wear_coefficient" in r.output and "not written" in r.output
    assert "Traceback" not in r.output and not out.exists()


def test_a_profiles_x_in_micrometres_headed_mm_is_refused_naming_the_column(tmp_path):
    """x written in µm under `x [mm]` put the profile ±300 mm wide on a 0.75 mm grid: each point beyond the grid
    was compared with its edge and the fit ran (a review).  Refused, as the other unit slips are."""
    path = tmp_path / "p.csv"
    path.write_text("cycle [cycles],x [mm],wear_depth_stationary [um]\n" + "".join(
        f"18000,{x},{max(0.0, 3 - abs(x) / 100)}\n" for x in range(-300, 301, 50)))
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(path), "--set", TWO_D])
    refused(r, "column x [mm]", "unit")


def test_the_jacobian_steps_five_percent_in_each_value_not_five_percent_of_its_logarithm():
    """scipy's diff_step is relative to x, here ln k ≈ −17.7: its 5 % was a step of 0.89 in ln k (a factor of 2.4)
    and the intervals came out 1.4× too wide (a review's central differences).  The step is now ln 1.05, backward
    at the top of the search; the derivative of exp(x) there is exp(x) within the step's first-order error."""
    import math

    import numpy as np

    from fretsim.fit import DIFF_STEP, _jacobian
    seen = []

    def evaluate(x):
        seen.append(np.array(x))
        return np.exp(x)

    x = np.log([2e-8, 3e-8])
    jac = _jacobian(evaluate, x, (x - 5, np.array([x[0] + 5, x[1] + 0.01])))
    steps = sorted({round(float(s[j] - x[j]), 12) for s in seen for j in range(2) if s[j] != x[j]})
    assert steps == [round(-math.log1p(DIFF_STEP), 12), round(math.log1p(DIFF_STEP), 12)]
    assert np.diag(jac) == pytest.approx(np.exp(x), rel=DIFF_STEP)


def test_a_fit_with_no_degrees_of_freedom_that_leaves_residuals_says_the_model_cannot_match_them(truth, tmp_path):
    """As many values as data, yet residuals remain (the flat's depth at 18 000 cycles 1.5× what grows from its depth
    at 9 000 under any coefficients): the fit said only 'no CI' (a review, on the tube's ±5 %); it now warns that
    the model cannot reproduce the data."""
    rows = (truth / "measured.csv").read_text().splitlines()[2:]
    (n1, _, d1), (n2, _, d2) = (r.split(",") for r in rows)
    path = tmp_path / "m.csv"
    path.write_text(f"cycle [cycles],max_wear_depth_stationary [um]\n{n1},{d1}\n{n2},{float(d2) * 1.5}\n")
    r = CliRunner().invoke(main, ["fit", str(CASE), "--measured", str(path), "--set", TWO_D])
    assert "no degrees of freedom" in r.output and "model cannot reproduce these data" in r.output, r.output


def test_the_search_stays_within_a_values_own_range():
    """A friction coefficient searched to 1000× its start ran 6 minutes and stopped at μ = 18.3, out of the key's
    range [0, 10] (a review): the bounds are the key's range where it is narrower."""
    import math

    import numpy as np

    from fretsim.fit import RANGE, _bounds, _spec
    spec = _spec("loading.friction_coefficient")
    lo, hi = _bounds(np.log([0.9]), [spec])
    assert hi[0] <= math.log(spec.hi) + 1e-12 and lo[0] == pytest.approx(math.log(0.9 / RANGE))
    k = _spec("materials.moving.wear_coefficient")
    lo, hi = _bounds(np.log([2e-8]), [k])
    assert hi[0] <= math.log(2e-8 * RANGE) + 1e-12 and lo[0] >= math.log(2e-8 / RANGE) - 1e-12
