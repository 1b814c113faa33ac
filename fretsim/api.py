"""The Python API the CLI wraps: load a case, check it, run it (or resume it), read the results, sweep.

    >>> from fretsim.api import load_case, run, read_results
    >>> outcome = run(load_case("cases/mccoll_185N.yaml"), "out.h5")
    >>> outcome.summary["centre_wear_depth_stationary_um"]
    >>> table = sweep("cases/sweeps/mccoll_load_stroke.yaml", "load_stroke")   # every point, one table
    >>> table.rows[0]["centre_wear_depth_stationary_um"], table.to_xarray()

A façade: running one case is :mod:`fretsim.runner`, sweeps are :mod:`fretsim.sweep` (which runs its points
through the runner, not through this module).
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Optional

from fretsim.case import Case, CaseError, load_case, parse_case
from fretsim.plan import SideRuns
from fretsim.results import Results, read_results
from fretsim.runner import Outcome, check, inputs_of, resume, run
from fretsim.simulate import SimulationError

__all__ = ["Case", "CaseError", "Outcome", "Results", "SideRuns", "SimulationError", "check", "load_case",
           "parse_case", "read_results", "run", "resume", "inputs_of", "sweep"]


def sweep(sweep_file: str | Path, outdir: str | Path, *, jobs: int = 0, dask: Optional[str] = None,
          overwrite: bool = False, progress: Optional[Callable[[dict], None]] = None):
    """Run every point of a sweep file into ``outdir`` (see :mod:`fretsim.sweep`) and return its table
    (:class:`fretsim.sweep.SweepOutcome`: ``rows``, ``counts``, ``to_pandas()``, ``to_xarray()``)."""
    from fretsim.sweep import load_sweep, run_sweep
    return run_sweep(load_sweep(sweep_file), outdir, jobs=jobs, dask=dask, overwrite=overwrite, progress=progress)
