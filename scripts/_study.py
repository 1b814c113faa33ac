"""Shared helpers for the study scripts: run a case with overrides, time it, compare with a reference."""
from __future__ import annotations

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import csv  # noqa: E402
import dataclasses  # noqa: E402
import importlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from fretsim.case import CaseError, load_case  # noqa: E402
from fretsim.refine import mape  # noqa: E402
from fretsim.plan import prepare  # noqa: E402
from fretsim.simulate import SimulationError, simulate, summarize  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


@dataclasses.dataclass
class Run:
    label: str
    status: str
    seconds: float
    solves: int
    rejected: int
    summary: dict
    last: object  # the final Step (None if failed before any)
    message: str = ""


def run_case(case_file: str, overrides: list[str], label: str = "", allow_unstable: bool = False,
             stop_on_checkerboard: bool = True, observers: tuple = ()) -> Run:
    """Run in-process (no file I/O) and time the loop alone."""
    case = load_case(ROOT / case_file, overrides)
    try:
        setup, _, _ = prepare(case, allow_unstable=allow_unstable)
    except CaseError as exc:  # e.g. a linear jump past the stability limit: refused is a result here
        return Run(label or " ".join(overrides), "refused", float("nan"), 0, 0, {}, None,
                   str(exc).splitlines()[-1].strip())
    setup = dataclasses.replace(setup, watch_growth=stop_on_checkerboard)
    steps = []

    class Count:
        def on_step(self, s, step):
            steps.append(step.rejected)

    last = None

    class Last:
        def on_step(self, s, step):
            nonlocal last
            last = step

    t = time.perf_counter()
    try:
        simulate(setup, (Count(), Last()) + tuple(observers))
        status, msg = "complete", ""
    except SimulationError as exc:
        status, msg = "failed", str(exc)
    except Exception as exc:  # a diverged explicit run can break the solver in any way: that is the finding
        status, msg = "failed", f"{type(exc).__name__}: {exc}"
    dt = time.perf_counter() - t
    summary = summarize(setup, last, len(steps), dt) if last is not None else {}
    return Run(label or " ".join(overrides), status, dt, len(steps), int(sum(steps)), summary, last, msg)


def depth_error(run: Run, ref: Run, key: str = "centre_wear_depth_stationary_um") -> float:
    if run.status != "complete":
        return float("nan")
    return abs(run.summary[key] / ref.summary[key] - 1)


def pressure_mape(run: Run, ref: Run) -> float:
    if run.last is None or run.status != "complete":
        return float("nan")
    return mape(ref.last.pressure, run.last.pressure)


def write_csv(rows: list[dict], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(dict.fromkeys(k for r in rows for k in r)))
        w.writeheader()
        w.writerows(rows)


def pareto(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points no other point beats in both time and error (lower is better)."""
    idx = []
    for i, (t, e) in enumerate(points):
        if not np.isfinite(e):
            continue
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for j, (t2, e2) in enumerate(points)
                   if j != i and np.isfinite(e2)):
            idx.append(i)
    return idx


class Report:
    """Lines printed as they come and kept for the study's results file: ``say = Report(); say("…")``."""

    def __init__(self):
        self.lines: list[str] = []

    def __call__(self, line: str = "") -> None:
        print(line, flush=True)
        self.lines.append(line)

    def write(self, path: Path) -> None:
        path.write_text("\n".join(self.lines) + "\n")


def have_comparator(module: str, install: str) -> bool:
    """Whether an optional comparator (never a dependency of fretsim) imports; if not, say how to get it."""
    try:
        importlib.import_module(module)
        return True
    except ImportError:
        print(f"{module} is not installed ({install}): nothing to compare against", file=sys.stderr)
        return False
