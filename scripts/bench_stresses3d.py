"""What the 3D subsurface stresses cost per depth layer (issue 34): seconds to build one layer's rectangle
influence kernels, to transform them, and the whole layer (kernels, their FFTs, the products and the six inverse
FFTs) as :func:`fretsim.fatigue.stresses3d.half_space_stresses` does it, on a 427 × 27 grid (the issue's size)
and on a square 128 × 128.  Loaded: pressure and q_x (a fretting cycle's state), then all three.

The tractions' own FFTs are paid once per call, not per layer; a layer's time does not depend on its depth.
Median (and minimum) of the repeats over ten layers each; one thread (``_study`` pins BLAS before numpy loads).

    python scripts/bench_stresses3d.py [--repeats 5]     # table on stdout; scripts/results/stresses3d_cost.txt
"""
from __future__ import annotations

import argparse
import statistics
import time

from _study import ROOT, Report  # first: it pins the BLAS threads before numpy loads

import numpy as np  # noqa: E402

from fretsim.compliance.fft import next_fast_len  # noqa: E402
from fretsim.fatigue import stresses3d as s3  # noqa: E402

GRIDS = ((427, 27), (128, 128))
LAYERS = 10


def _times(fn, repeats: int) -> list:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return times


def _median(fn, repeats: int) -> float:
    return statistics.median(_times(fn, repeats))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    say = Report()
    say(f"{'grid nx × ny':<14}{'padded FFT':>12}{'loads':>13}{'kernels s':>11}{'kernel FFT s':>14}"
        f"{'layer s':>10}{'layer s, min':>14}")
    rng = np.random.default_rng(0)
    depths = np.geomspace(0.001, 0.5, LAYERS)
    for nx, ny in GRIDS:
        dx, dy = 0.005, 0.02
        x, y = np.arange(nx) * dx, np.arange(ny) * dy
        p = rng.random((ny, nx))
        shape = (next_fast_len(2 * ny - 1, real=False), next_fast_len(2 * nx - 1, real=True))
        for label, loads, (qx, qy) in (("p, q_x", (True, True, False), (0.3 * p, None)),
                                       ("p, q_x, q_y", (True, True, True), (0.3 * p, 0.1 * p))):
            kernels = _median(lambda: s3.influence_kernels(nx, ny, dx, dy, 0.01, 0.3, loads), args.repeats)
            k = s3.influence_kernels(nx, ny, dx, dy, 0.01, 0.3, loads)[[m for m in range(3) if loads[m]]]
            hat = _median(lambda: s3._wrapped_transform(k, shape), args.repeats)
            runs = np.array(_times(lambda: s3.half_space_stresses(x, y, dx, dy, p, qx, qy, depths, 0.3),
                                   args.repeats)) / LAYERS
            say(f"{f'{nx} × {ny}':<14}{f'{shape[1]} × {shape[0]}':>12}{label:>13}{kernels:>11.4f}{hat:>14.4f}"
                f"{np.median(runs):>10.4f}{runs.min():>14.4f}")
    say(f"(median of {args.repeats} unless min; layer: half_space_stresses over {LAYERS} depths ÷ {LAYERS}; "
        f"kernel FFT: the 12 (or 18) kernels of one layer; numpy {np.__version__}, one thread; a shared machine: "
        f"the minimum is the steadier figure)")
    say.write(ROOT / "scripts" / "results" / "stresses3d_cost.txt")


if __name__ == "__main__":
    main()
