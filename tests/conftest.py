import contextlib
import os
import shutil
import sys
import tempfile

if os.environ.get("PYTEST_XDIST_WORKER"):
    # A parallel worker has a core of its own: OpenBLAS's threads (one per core by default) would spin against the
    # other worker's, which made the banded solves of tests/test_free_faces.py five times slower.  Before numpy
    # is first imported, or it is too late (a plugin that imports it first leaves the threads as they are: slower).
    if "numpy" in sys.modules:
        import warnings
        warnings.warn("numpy was imported before tests/conftest.py: its BLAS threads are not limited to 1 per worker")
    for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

from fretsim.compliance import HalfSpace  # noqa: E402
from fretsim.cycle import CYCLES, STROKES  # noqa: E402
from fretsim.grid import Grid  # noqa: E402
from fretsim.reference import effective_modulus  # noqa: E402

# No example database: it would be written to the current directory (.hypothesis/), shared by the parallel workers,
# and make a run depend on the runs before it.  A failing example is still printed in full.
settings.register_profile("fretsim", database=None)
settings.load_profile("fretsim")
_HYPOTHESIS_HOME: list = []


def pytest_configure(config):
    """Hypothesis also keeps caches in .hypothesis/ of the current directory (the constants it finds in the code
    under test, gathered while the tests are collected): each process, each parallel worker, keeps them in a
    temporary directory of its own instead, removed at its end."""
    from hypothesis.configuration import set_hypothesis_home_dir
    _HYPOTHESIS_HOME.append(tempfile.mkdtemp(prefix="fretsim-hypothesis-"))
    set_hypothesis_home_dir(_HYPOTHESIS_HOME[-1])


def pytest_unconfigure(config):
    from hypothesis.configuration import set_hypothesis_home_dir
    set_hypothesis_home_dir(None)
    while _HYPOTHESIS_HOME:
        shutil.rmtree(_HYPOTHESIS_HOME.pop(), ignore_errors=True)


# The paper's steel pair: E = 200 GPa, ν = 0.3 on both bodies (internal units: MPa).
E_STAR = effective_modulus(2.0e5, 0.3, 2.0e5, 0.3)


def ball_problem(n: int, radius=6.0, half_width=None, a_hertz=0.19637):
    """Ball on flat on an n × n grid spanning ±1.5 a (a = Hertz radius of the 185 N, R = 6 mm ball)."""
    half_width = half_width or 1.5 * a_hertz
    grid = Grid.centred(n, n, 2 * half_width / n, 2 * half_width / n)
    X, Y = grid.mesh()
    return HalfSpace(grid, E_STAR), (X**2 + Y**2) / (2 * radius)


def cylinder_problem(nx: int, ny: int, radius=6.0, length=10.0, half_width=0.126):
    """Finite cylinder on flat: the grid spans the cylinder's length and ±half_width along x."""
    grid = Grid.centred(nx, ny, 2 * half_width / nx, length / ny)
    X, _ = grid.mesh()
    return HalfSpace(grid, E_STAR), X**2 / (2 * radius)


def line_problem(nx: int, radius=6.0, half_width=0.126):
    grid = Grid.centred(nx, 1, 2 * half_width / nx, 1.0, plane_strain=True)
    return HalfSpace(grid, E_STAR), (grid.x**2 / (2 * radius))[None, :]


@pytest.fixture
def e_star():
    return E_STAR


# --- independent checks of a finished run --------------------------------------------------------------------------
# The loop checks its running volume against its own invariant (and raises at 1e-9), so a test that reads its
# `archard_volume_error` back cannot fail.  These recompute both sides from what a user sees instead: the final wear
# fields, the element size, the contact length of a 2D model and the case's loading, so a wrong element area, line
# length, block bookkeeping, unit or field written fails here.
# Tolerance: the volume is Archard's by construction; what remains is the round-off of summing the depths of up to
# ~10⁵ elements and of the loop's running sums (measured ≤ 6e-15 on every shipped case); 1e-9 is the loop's own
# threshold (fretsim.loop.checks.ARCHARD_ROUND_OFF), and a wrong area, length or load is off by far more.
VOLUME_ROUND_OFF = 1e-9


def archard_travel(case, cycles: int) -> float:
    """Σ Pᵢ·4δᵢ·nᵢ (N·mm) over the loading's blocks up to ``cycles``: the load times the rig's travel."""
    total, start = 0.0, 0
    for block in case.loading.blocks:
        n = min(max(cycles - start, 0), block.cycles)
        total += block.normal_load * 4.0 * block.stroke * n
        start += block.cycles
    return total


def _check_volumes(case, cycles: int, volumes, regime: str = "", gross_slip_stroke: float = float("nan")) -> None:
    """Archard's law on worn volumes (mm³) after ``cycles`` of ``case`` (a filled case: its slip and stroke known).

    The paper's cycle (slip uniform at mid-stroke): each body's volume is k·Σ Pᵢ·4δᵢ·Nᵢ, to round-off.  A cycle
    that resolves friction or the stroke: no point slides further than the rig travels, so each volume lies in
    (0, k·Σ Pᵢ·4δᵢ·Nᵢ] (0 for a body with k = 0); in gross slip under one constant loading each point slides at least
    4(δ − δ_t) a cycle (its elastic take-up under μp is at most the centre's at the onset of gross slip, δ_t), so
    the volume is at least k·P·4(δ − δ_t)·N."""
    travel = archard_travel(case, cycles)
    closed_form = CYCLES[case.slip].assumes_gross_slip and not STROKES[case.stroke_model]  # the paper's cycle
    for k, volume in zip(case.wear_coefficients(), volumes):
        if closed_form:
            assert volume == pytest.approx(k * travel, rel=VOLUME_ROUND_OFF, abs=0.0), (volume, k * travel)
        elif k == 0 or cycles == 0:
            assert volume == 0.0
        else:
            assert 0.0 < volume <= k * travel * (1 + VOLUME_ROUND_OFF), (volume, k * travel)
            if regime == "gross_slip" and len(case.loading.blocks) == 1:
                block = case.loading.blocks[0]
                least = k * block.normal_load * 4.0 * (block.stroke - gross_slip_stroke) * cycles
                assert volume >= least * (1 - VOLUME_ROUND_OFF), (volume, least)


def worn_volumes(out) -> tuple[float, float]:
    """Each body's worn volume (mm³) summed from its final wear field (mm): depth × element area, × the contact
    length of a 2D (per unit length) model."""
    g = out.setup.grid
    area = g.dx * g.dy * (out.case.geometry.line_length if g.plane_strain else 1.0)
    return float(np.sum(out.last.wear_moving)) * area, float(np.sum(out.last.wear_stationary)) * area


def check_archard(out) -> None:
    """Archard's law (see _check_volumes) on a finished run (an Outcome), from its final wear fields."""
    assert out.status in ("complete", "stopped"), out.message
    _check_volumes(out.case, int(out.last.cycle), worn_volumes(out), out.summary["regime"],
                   out.summary["gross_slip_stroke_um"] * 1e-3)


def check_archard_results(res) -> None:
    """The same on a results file: its last recorded wear fields (µm), its grid and the filled case it stores."""
    from fretsim.case import parse_case
    case = parse_case(res.case_yaml)
    dx = float(res.x[1] - res.x[0])
    area = dx * (float(res.y[1] - res.y[0]) if res.y.size > 1 else case.geometry.line_length)
    volumes = [float(np.sum(res.fields[f"wear_depth_{body}"][-1])) * 1e-3 * area for body in ("moving", "stationary")]
    _check_volumes(case, int(res.fields["cycle"][-1]), volumes, res.summary["regime"],
                   res.summary["gross_slip_stroke_um"] * 1e-3)


@contextlib.contextmanager
def edited(path):
    """A results file opened to be edited on purpose, its whole-file checksum (the user block's) written again
    afterwards, as a tool that edits knowingly would: what is refused then is what the per-object seals catch."""
    import h5py
    from fretsim.results import reseal_file
    with h5py.File(path, "r+") as f:
        yield f
    reseal_file(path)


# --- figures --------------------------------------------------------------------------------------------------------

def outside_canvas(fig) -> tuple | None:
    """None where everything the figure draws (labels, legends, titles, rotated text) lies on its canvas (half a
    pixel of rounding allowed), else the drawn box and the canvas, in pixels: what a saved figure would cut off."""
    if not hasattr(fig.canvas, "get_renderer"):  # closed by pyplot after saving: drawn again on Agg's canvas
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        FigureCanvasAgg(fig)
    box = fig.get_tightbbox(fig.canvas.get_renderer()).transformed(fig.dpi_scale_trans)
    inside = box.x0 >= -0.5 and box.y0 >= -0.5 and box.x1 <= fig.bbox.width + 0.5 and box.y1 <= fig.bbox.height + 0.5
    return None if inside else (box.bounds, fig.bbox.bounds)


@pytest.fixture(autouse=True)
def _close_figures():
    """Every test leaves pyplot as it found it: figures a test (or a session fixture it used) drew are closed after
    it (a closed figure can still be inspected), so one worker never holds more than matplotlib warns about."""
    yield
    import sys
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


class StopAt:
    """An observer that interrupts a run, as Ctrl-C would, at its first step at or past ``cycle``."""

    def __init__(self, cycle: int):
        self.cycle = cycle

    def on_step(self, setup, step):
        if step.cycle >= self.cycle:
            raise KeyboardInterrupt


def interrupted_and_resumed(case_path, overrides: list, cycle: int, out):
    """The case run into ``out``, interrupted at ``cycle`` (:class:`StopAt`), then resumed: the resumed outcome."""
    from fretsim.api import load_case, resume, run
    with pytest.raises(KeyboardInterrupt):
        run(load_case(case_path, overrides), out, observers=(StopAt(cycle),))
    return resume(out)


def same(a, b) -> bool:
    """Equal, or both NaN (a figure a run does not reach)."""
    return a == b or (a != a and b != b)


def underestimate(monkeypatch, factor: float):
    """The automatic grid sized for 1/``factor`` of the worn volume the run will reach (so that it is widened);
    the real sizing returned, to put back."""
    import fretsim.plan.grid as plan_grid
    real = plan_grid.auto_grid

    def small(*args, **kw):
        if kw.get("volume") is not None:
            kw["volume"] = kw["volume"] / factor
        return real(*args, **kw)

    monkeypatch.setattr(plan_grid, "auto_grid", small)
    return real


@pytest.fixture
def underestimated(monkeypatch):
    """:func:`underestimate` by 30."""
    return underestimate(monkeypatch, 30)


def chord_width(profile, x, fraction=1e-3):
    """The scar width as fretsim read it before 2026-11-28: each crossing of ``fraction`` of the peak interpolated
    linearly between the element centres around it (the chord), for the tests that compare the reading with it."""
    level = fraction * profile.max()
    above = np.flatnonzero(profile > level)
    lo, hi = above[0], above[-1]
    right = x[hi + 1] + (x[hi] - x[hi + 1]) * (level - profile[hi + 1]) / (profile[hi] - profile[hi + 1])
    left = x[lo - 1] + (x[lo] - x[lo - 1]) * (level - profile[lo - 1]) / (profile[lo] - profile[lo - 1])
    return right - left
