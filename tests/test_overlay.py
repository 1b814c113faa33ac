"""Overlays (`fretsim plot A.h5 B.h5`): each run labelled by what differs between the runs, and a run that did not
complete marked as such where it is drawn."""
from pathlib import Path

import matplotlib.pyplot as plt
import pytest
from click.testing import CliRunner

from fretsim.api import load_case, run
from fretsim.cli import main
from fretsim.plotting import overlay
from fretsim.results import read_results

CASE = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"


class _StopAfter:
    """Ctrl-C, as the loop sees it, at the first step past ``cycle``."""

    def __init__(self, cycle: int):
        self.cycle = cycle

    def on_step(self, setup, step):
        if step.cycle > self.cycle:
            raise KeyboardInterrupt


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    """A complete 2D run and the same case interrupted part-way."""
    tmp = tmp_path_factory.mktemp("overlay")
    overrides = ["model.dimension=2d", "loading.cycles=2000", "output.snapshots=[0, 100, 2000]",
                 "grid.error_estimate=none"]
    run(load_case(CASE, overrides), tmp / "A.h5")
    with pytest.raises(KeyboardInterrupt):
        run(load_case(CASE, overrides), tmp / "B.h5", observers=(_StopAfter(100),))
    return read_results(tmp / "A.h5"), read_results(tmp / "B.h5")


def _legend_texts(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]


def test_an_overlaid_interrupted_run_says_so_and_how_far_it_got_in_every_legend(two_runs):
    complete, interrupted = two_runs
    assert interrupted.status == "interrupted"
    reached = int(interrupted.history["cycle"][-1])
    assert 100 < reached < 2000
    fig = overlay([complete, interrupted])
    try:
        texts = _legend_texts(fig)
    finally:
        plt.close(fig)
    mark = f"interrupted at cycle {reached:,} of 2,000".replace(",", " ")
    of_b = [t for t in texts if "(B" in t]
    assert len(of_b) == 4 and all(mark in t for t in of_b), texts  # profiles and histories, both bodies
    assert all("interrupted" not in t for t in texts if "(A" in t), texts


def test_plotting_an_overlay_with_a_run_that_did_not_complete_notes_it(two_runs, tmp_path):
    complete, interrupted = two_runs
    r = CliRunner().invoke(main, ["plot", complete.path, interrupted.path, "-o", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert f"note: {interrupted.path}: interrupted at cycle" in r.output, r.output
    assert f"note: {complete.path}" not in r.output, r.output


@pytest.fixture(scope="module")
def other_runs(two_runs):
    """The same case at 150 N (C), and with five values changed (D): the load, the stroke, both wear coefficients
    and the step tolerance."""
    tmp = Path(two_runs[0].path).parent
    base = ["model.dimension=2d", "loading.cycles=2000", "output.snapshots=[0, 100, 2000]", "grid.error_estimate=none"]
    run(load_case(CASE, base + ["loading.normal_load=150 N"]), tmp / "C.h5")
    changed = ["loading.normal_load=150 N", "loading.stroke=10 um", "materials.moving.wear_coefficient=3e-8 1/MPa",
               "materials.stationary.wear_coefficient=1e-8 1/MPa", "jumping.tolerance=0.005"]
    run(load_case(CASE, base + changed), tmp / "D.h5")
    return read_results(tmp / "C.h5"), read_results(tmp / "D.h5")


def test_overlaid_runs_are_labelled_by_the_set_value_that_differs_and_a_cut_short_one_by_its_status(two_runs,
                                                                                                   other_runs):
    """Each run was labelled by its case's name and file name: mccoll_185N (A), mccoll_185N (C)."""
    complete, interrupted = two_runs
    at_150, _ = other_runs
    reached = int(interrupted.history["cycle"][-1])
    fig = overlay([complete, interrupted, at_150])
    try:
        history = [t.get_text() for t in fig.axes[3].get_legend().get_texts()]
        profiles = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
        title = fig.texts[0].get_text()
    finally:
        plt.close(fig)
    # the value that differs, from each filled case (A and B did not set it); the shared --set values not named
    assert history == ["normal_load=185 N (A)",
                       f"normal_load=185 N (B,\ninterrupted at cycle {reached} of 2 000)",
                       "normal_load=150 N (C)"], history
    assert profiles == ["normal_load=185 N (A), N = 2 000",  # and the last recorded state
                        f"normal_load=185 N (B,\ninterrupted at cycle {reached} of 2 000), N = 100",
                        "normal_load=150 N (C), N = 2 000"], profiles
    assert title == "3 runs of mccoll_185N overlaid", title


def test_a_label_names_three_differences_counts_the_rest_and_keeps_the_overlay_on_its_canvas(two_runs, other_runs):
    """Five values differ: a label names the first three (each run's, in one spelling: A set none of them),
    the wear coefficients by as much of their key as tells them apart, says how many more, breaks into lines of at
    most LABEL_WIDTH characters between values, and every legend stays on the figure.  C and D share their load:
    between them it is not named."""
    from conftest import outside_canvas
    from fretsim import plotting
    complete, interrupted = two_runs
    at_150, changed = other_runs
    reached = int(interrupted.history["cycle"][-1])
    fig = overlay([complete, interrupted, at_150, changed], expected=True)
    try:
        history = [t.get_text() for t in fig.axes[3].get_legend().get_texts()]
        runs = [t.get_text() for ax in fig.axes for t in ax.get_legend().get_texts() if not t.get_text().startswith(
            ("experiment", "fea", "paper"))]
        outside = outside_canvas(fig)
    finally:
        plt.close(fig)
    assert history == [
        "normal_load=185 N, stroke=0.025 mm,\nmoving.wear_coefficient=2e-08 1/MPa, +2 more (A)",
        f"normal_load=185 N, stroke=0.025 mm,\nmoving.wear_coefficient=2e-08 1/MPa, +2 more (B,\ninterrupted at "
        f"cycle {reached} of 2 000)",
        "normal_load=150 N, stroke=0.025 mm,\nmoving.wear_coefficient=2e-08 1/MPa, +2 more (C)",
        "normal_load=150 N, stroke=0.01 mm,\nmoving.wear_coefficient=3e-08 1/MPa, +2 more (D)"], history
    assert len(runs) == 16 and all(len(line) <= plotting.LABEL_WIDTH for t in runs for line in t.splitlines()), runs
    assert outside is None, outside
    assert plotting.run_labels([at_150, changed]) == [
        "stroke=0.025 mm,\nmoving.wear_coefficient=2e-08 1/MPa,\nstationary.wear_coefficient=3e-08 1/MPa, +1 more\n(C)",
        "stroke=0.01 mm,\nmoving.wear_coefficient=3e-08 1/MPa,\nstationary.wear_coefficient=1e-08 1/MPa, +1 more\n(D)"]
