"""``linear``: the paper's explicit linear jumps, h ← h + ΔN_L·r(h), stable below the explicit limit
(:mod:`fretsim.stability`); ΔN_L = 1 is the per-cycle model itself."""
from __future__ import annotations

from typing import Optional

import numpy as np


class Linear:
    name = "linear"
    implicit = False
    per_cycle_short_runs = True

    def reason(self, case) -> str:
        return "the paper's explicit linear jumps"

    def describe(self, case, summary: dict) -> str:
        return (f"linear jump {summary['linear_jump']} cycles (stability limit "
                f"{summary['stability_limit_linear']:.3g})")

    def estimate_solves(self, setup) -> int:
        return setup.cycles // setup.linear_jump + len(setup.snapshots) + 1

    def max_jump(self, case, jump: int, limit: float, allow_unstable: bool) -> tuple[Optional[int], list]:
        return case.max_jump, []

    def growth_cause(self, setup, model) -> str:
        return explicit_growth_cause(setup, f"linear jump {setup.linear_jump} cycles")

    def run(self, loop):
        step = None
        while loop.n < loop.s.cycles:
            loop.enter_block()
            d_n = min(loop.s.linear_jump, loop.next_stop() - loop.n)
            cyc, e_p = loop.explicit_step(d_n)
            step = loop.emit(cyc, d_n, e_p) or step
        return step


def explicit_growth_cause(setup, what: str) -> str:
    """An explicit scheme's checkerboard: its jumps beyond the stability limit."""
    return (f"the {what} are unstable on this grid (explicit stability limit {setup.stability_limit:.4g} cycles). Use "
            f"jumping.scheme: bdf2 (no stability limit), or a smaller jumping.linear")


def relative_change(v: np.ndarray, ref: np.ndarray) -> float:
    """‖v‖/‖ref‖ (0 for a zero reference).  (Not np.linalg.norm: its BLAS dot woke a multithreaded BLAS's sleeping
    threads once a step, 4 ms a call on two cores, 0.4 s of a 3D resolved run's 9 s.)"""
    n = float(np.sqrt(np.square(ref).sum()))
    return float(np.sqrt(np.square(v).sum())) / n if n > 0 else 0.0
