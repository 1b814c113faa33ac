"""What a planned run will cost: the solves its stepping scheme takes, and seconds from one timed solve."""
from __future__ import annotations

import time

import numpy as np

from fretsim.compliance import add
from fretsim.compliance import fft
from fretsim.solvers import solve

# a step's solve, warm-started on the contact's window, against the cold solve timed (loop time per solve over one
# cold solve, measured on McColl 185 N 2D/3D with BDF2 and linear jumps, Kirk 20 Hz, the 3D tube, the partial-slip
# ball: 0.22-0.56, the 2D runs' per-step overhead the rest; was 0.5, and 1 for friction cycles, which estimated
# those 1.9-3.6x too long)
WARM_SOLVE = 0.35


def estimate_solves(setup) -> int:
    """Solves a run is expected to take (measured on the shipped cases; for progress and `check`)."""
    if setup.cycles == 0:
        return 1
    return setup.stepper.estimate_solves(setup)


def estimate_cost(setup) -> tuple[int, float]:
    """(solves, seconds) before a run: solves from the scheme, seconds from one timed contact solve."""
    fft.forward(np.zeros((1, 3)), (1, 6))  # the FFT's import and choice, once a process: not a solve's cost
    solves = estimate_solves(setup)
    op = setup.coarse_compliance or setup.compliance
    if op.convolution is not None:
        op.convolution.hat  # its transform, made once a run: not a solve's cost
    gap = setup.coarse_gap if setup.coarse_gap is not None else setup.gap
    if setup.cycle.linear:  # a cycle is one normal solve
        t = time.perf_counter()
        solve(op, gap, setup.cycle.load, method=setup.method, tol=setup.tolerance)
        cold = time.perf_counter() - t
        return solves, solves * cold * WARM_SOLVE

    def normal(seen, guess, extra=None, load=None, cycle=0):
        res = solve(op if extra is None else add(op, extra), gap + seen, load, method=setup.method, p0=guess,
                    tol=setup.tolerance)
        return res.pressure, res

    zero = np.zeros(setup.grid.shape)
    t = time.perf_counter()
    setup.cycle.solve(zero, zero, normal, None)
    return solves, solves * (time.perf_counter() - t) * WARM_SOLVE
