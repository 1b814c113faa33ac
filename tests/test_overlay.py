"""Overlays (`fretsim plot A.h5 B.h5`): a run that did not complete is marked as such where it is drawn."""
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
