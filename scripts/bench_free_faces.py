"""What the free faces cost: building the correction, and the loop with it against the half-spaces, side by side.

For McColl's 185 N case on its automatic grid (27 rows) and on a fine grid (301 × 101, 2 000 cycles): the time
to build the correction (the finite-element blocks, the Fourier integral, the row basis), and the loop's time
with `model.corrections: [free_faces]` and with `none`, run in turn so that each pair sees the same machine.
Quote the median ratio; absolute times on a shared machine drift.

    python scripts/bench_free_faces.py [--repeats 7]     # table on stdout; scripts/out/bench_free_faces.txt
"""
from __future__ import annotations

import argparse
import statistics
import time

from _study import ROOT, Report  # first: it pins the BLAS threads before numpy loads

from fretsim.case import load_case  # noqa: E402
from fretsim.compliance import free_faces as ff  # noqa: E402
from fretsim.plan import prepare  # noqa: E402
from fretsim.simulate import simulate  # noqa: E402

CASE = ROOT / "cases" / "mccoll_185N.yaml"
GRIDS = {"automatic (27 rows)": [], "301 × 101, 2 000 cycles": ["grid.elements=[301,101]", "loading.cycles=2000",
                                                                "output.snapshots=auto"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    say = Report()
    say(f"{'grid':<26}{'build s':>9}{'rank':>6}{'loop, none s':>14}{'loop, faces s':>15}{'ratio (median)':>16}"
        f"{'ratio min-max':>16}")
    for label, extra in GRIDS.items():
        half = prepare(load_case(CASE, [*extra, "model.corrections=none"]))[0]
        ff._CACHE.clear()
        t = time.perf_counter()
        faces = prepare(load_case(CASE, [*extra, "model.corrections=[free_faces]"]))[0]
        build = time.perf_counter() - t
        op = next(o for o in faces.compliance.terms if isinstance(o, ff.RowConvolution))
        rank = op.basis.shape[1] if op.basis is not None else faces.grid.shape[0]
        loops = {"none": [], "faces": []}
        ratios = []
        for _ in range(args.repeats):
            for key, setup in (("none", half), ("faces", faces)):
                t = time.perf_counter()
                simulate(setup)
                loops[key].append(time.perf_counter() - t)
            ratios.append(loops["faces"][-1] / loops["none"][-1])
        say(f"{label:<26}{build:>9.2f}{rank:>6}{statistics.median(loops['none']):>14.3f}"
            f"{statistics.median(loops['faces']):>15.3f}{statistics.median(ratios):>16.2f}"
            f"{min(ratios):>9.2f}-{max(ratios):.2f}")
    say("(build: prepare with the faces from an empty cache; rank: rows of the operator's basis, or all rows)")
    say.write(ROOT / "scripts" / "out" / "bench_free_faces.txt")


if __name__ == "__main__":
    main()
