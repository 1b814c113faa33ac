"""The paper's section-4 figures from the shipped cases: wire ropes (Figs 21-22), seat rail (Figs 24-25) and the
steam-generator tube at RT and 90 °C (Figs 27-28), with the tube's 90 °C/RT ratios beside the paper's.

    python scripts/figures_section4.py [--out scripts/out]

Runs each case as shipped (the model `auto` chooses, written in the figures' titles), writes section4_*.png and
prints a table of the ratios.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from _study import ROOT  # noqa: E402
from fretsim.api import load_case, run  # noqa: E402

PAPER = {"max_wear_depth_moving_um": 1.76, "scar_width_moving_mm": 1.59}  # §4.3: +76 % depth, +59 % width


def contour(ax, out, field, title):
    g = out.setup.grid
    data = getattr(out.last, field) * 1e3
    cs = ax.contourf(g.x, g.y, data, levels=20, cmap="viridis")
    plt.colorbar(cs, ax=ax, label="wear depth (µm)")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x, sliding direction (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_aspect("equal")


def profile(ax, out, field, title, along="x"):
    g = out.setup.grid
    data = getattr(out.last, field) * 1e3
    if along == "x":
        ax.plot(g.x, -data[data.shape[0] // 2])
        ax.set_xlabel("x (mm), y = 0")
    else:
        ax.plot(g.y, -data[:, data.shape[1] // 2])
        ax.set_xlabel("y (mm), x = 0")
    ax.set_ylabel("worn profile, −depth (µm)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    runs = {name: run(load_case(ROOT / "cases" / f"{name}.yaml"))
            for name in ("wire_rope", "seat_rail", "tube_RT", "tube_90C")}
    for name, out in runs.items():
        print(f"{name}: {out.case.dimension}, {out.summary['contact_solves']} solves, {out.summary['wall_time_s']:.2f} s;"
              f" moving max {out.summary['max_wear_depth_moving_um']:.3g} µm, flat max "
              f"{out.summary['max_wear_depth_stationary_um']:.3g} µm")

    w = runs["wire_rope"]
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    contour(axes[0, 0], w, "wear_moving", "top wire (moving): wear (cf. Fig. 21b)")
    profile(axes[0, 1], w, "wear_moving", "top wire at y = 0 (cf. Fig. 21c)")
    contour(axes[1, 0], w, "wear_stationary", "bottom wire (stroke average): wear (cf. Fig. 22b)")
    profile(axes[1, 1], w, "wear_stationary", "bottom wire at y = 0 (cf. Fig. 22c)")
    fig.suptitle(f"wire rope, Table 5: {w.summary['cycles']} cycles, 1 N, ±65 µm", fontsize=10)
    fig.tight_layout()
    fig.savefig(args.out / "section4_wire_rope.png", dpi=130)

    s = runs["seat_rail"]
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    contour(axes[0, 0], s, "wear_stationary", "SPFC 440 flat: elliptical scar (cf. Fig. 24b)")
    profile(axes[0, 1], s, "wear_stationary", "flat across the sliding direction, x = 0 (cf. Fig. 24c)", along="y")
    contour(axes[1, 0], s, "wear_moving", "SUS304 ball: circular scar (cf. Fig. 25a)")
    profile(axes[1, 1], s, "wear_moving", "ball, x = 0 (cf. Fig. 25b)", along="y")
    fig.suptitle(f"seat rail, Table 6: {s.summary['cycles']} cycles, 50 N, ±90 µm", fontsize=10)
    fig.tight_layout()
    fig.savefig(args.out / "section4_seat_rail.png", dpi=130)

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4))
    for name, style in (("tube_RT", "-"), ("tube_90C", "--")):
        out = runs[name]
        g = out.setup.grid
        axes[0].plot(g.x, -out.last.wear_moving[out.last.wear_moving.shape[0] // 2] * 1e3, style, label=name)
        axes[1].plot(g.x, -out.last.wear_stationary[out.last.wear_stationary.shape[0] // 2] * 1e3, style,
                     label=name)
    hist = {}
    for name in ("tube_RT", "tube_90C"):
        cycles, depth = [], []

        class Keep:
            def on_step(self, setup, step):
                cycles.append(step.cycle)
                depth.append(step.wear_moving.max() * 1e3)
        run(load_case(ROOT / "cases" / f"{name}.yaml"), observers=(Keep(),))
        hist[name] = (np.array(cycles), np.array(depth))
        axes[2].plot(*hist[name], "-o", ms=2, label=name)
    axes[0].set_title("tube worn profile at y = 0 (cf. Fig. 27c, d)", fontsize=9)
    axes[1].set_title("flat worn profile at y = 0", fontsize=9)
    axes[2].set_title("maximum tube depth against cycles (cf. Fig. 28)", fontsize=9)
    for ax in axes[:2]:
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("worn profile, −depth (µm)")
    axes[2].set_xlabel("cycles N (–)")
    axes[2].set_ylabel("maximum tube wear depth (µm)")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("steam-generator tube, Table 7: RT and 90 °C", fontsize=10)
    fig.tight_layout()
    fig.savefig(args.out / "section4_tube.png", dpi=130)

    print("\ntube, 90 °C over RT     fretsim   paper")
    for key, paper in PAPER.items():
        ratio = runs["tube_90C"].summary[key] / runs["tube_RT"].summary[key]
        print(f"  {key:28s} {ratio:6.2f}   {paper:5.2f}")
    print(f"wrote {', '.join(str(args.out / f'section4_{n}.png') for n in ('wire_rope', 'seat_rail', 'tube'))}")


if __name__ == "__main__":
    main()
