"""The evidence behind `auto`: each scene at each fidelity, cost against the difference from the full model.

Fidelities: 2D line contact (where the geometry has one), 3D half-spaces, 3D + the tube wall's ring bending
(Eq. 23; tubes only), 3D + the free faces of bodies that end across the contact (paper §2.1: the cylinder's or
roller's ends, the flat's where the case gives geometry.block_length, a tube's support).  For each, the wall
time of the loop and the difference of the reported quantities (maximum depth of each body, the flat's
centre-line depth, the scar width of each body) from the fullest model, and what `model.dimension: auto` /
`model.corrections: auto` choose for the scene (set to auto here even where the shipped case fixes its model),
with the reason.

    python scripts/study_model_hierarchy.py [--quick] [--out scripts/out]

Prints a table and writes model_hierarchy.csv and model_hierarchy.png.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from _study import ROOT, run_case, write_csv

from fretsim.case import load_case
from fretsim.plan import prepare

SCENES = {
    "mccoll_185N": [("2D", ["model.dimension=2d"]), ("3D", ["model.dimension=3d", "model.corrections=none"]),
                    ("3D + free faces (cylinder)", ["model.dimension=3d", "model.corrections=[free_faces]"])],
    "mccoll_185N_free_faces": [("2D", ["model.dimension=2d", "model.corrections=none"]),
                               ("3D", ["model.dimension=3d", "model.corrections=none"]),
                               ("3D + free faces (both)", ["model.dimension=3d", "model.corrections=[free_faces]"])],
    "mccoll_1670N": [("2D", ["model.dimension=2d"]), ("3D", ["model.dimension=3d", "model.corrections=none"]),
                     ("3D + free faces (cylinder)", ["model.dimension=3d", "model.corrections=[free_faces]"])],
    "kirk_450N_20Hz": [("2D", ["model.dimension=2d"]), ("3D", ["model.dimension=3d", "model.corrections=none"]),
                       ("3D + free faces (cylinder)", ["model.dimension=3d", "model.corrections=[free_faces]"])],
    "roller_edge_rounded": [("2D", ["model.dimension=2d"]), ("3D", ["model.dimension=3d", "model.corrections=none"]),
                            ("3D + free faces (roller)", ["model.dimension=3d", "model.corrections=[free_faces]"])],
    "tube_RT": [("2D", ["model.dimension=2d", "model.corrections=none"]),
                ("2D + ring bending", ["model.dimension=2d", "model.corrections=[ring_bending]"]),
                ("3D", ["model.dimension=3d", "model.corrections=none"]),
                ("3D + ring bending", ["model.dimension=3d", "model.corrections=[ring_bending]"]),
                ("3D + bending + free faces", ["model.dimension=3d", "model.corrections=[ring_bending, free_faces]"])],
    "tube_90C": [("2D", ["model.dimension=2d", "model.corrections=none"]),
                 ("3D", ["model.dimension=3d", "model.corrections=none"]),
                 ("3D + ring bending", ["model.dimension=3d", "model.corrections=[ring_bending]"])],
    "seat_rail": [("3D", [])],
    "wire_rope": [("3D", [])],
}
KEYS = {"max_wear_depth_moving_um": "depth, moving", "max_wear_depth_stationary_um": "depth, flat",
        "centre_wear_depth_stationary_um": "centre depth, flat", "scar_width_moving_mm": "width, moving",
        "scar_width_stationary_mm": "width, flat"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the cylinders only, 2000 cycles")
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out")
    args = ap.parse_args()
    rows = []
    for scene, levels in SCENES.items():
        if args.quick and scene not in ("mccoll_185N", "mccoll_185N_free_faces", "roller_edge_rounded"):
            continue
        extra = ["loading.cycles=2000", "output.snapshots=auto"] if args.quick else []
        # what auto would choose, even where the shipped case fixes its model (McColl's cases say 3d, as the paper)
        _, _, plan = prepare(load_case(ROOT / "cases" / f"{scene}.yaml",
                                       [*extra, "model.dimension=auto", "model.corrections=auto"]))
        auto = "; ".join(f"{c.key} = {c.value}: {c.reason}" for c in plan.choices
                         if c.key in ("model.dimension", "model.corrections"))
        runs = [(label, run_case(f"cases/{scene}.yaml", [*ov, *extra])) for label, ov in levels]
        full = runs[-1][1]
        for label, r in runs:
            diff = {v: abs(r.summary[k] / full.summary[k] - 1) if full.summary.get(k) else 0.0 for k, v in KEYS.items()}
            rows.append({"scene": scene, "model": label, "seconds": round(r.seconds, 3), "solves": r.solves,
                         **{k: float(f"{v:.3g}") for k, v in diff.items()}, "worst": float(f"{max(diff.values()):.3g}"),
                         "auto": auto})
            print(f"{scene:22s} {label:28s} {r.seconds:7.2f} s {r.solves:4d} solves  worst difference from "
                  f"{levels[-1][0]}: {max(diff.values()):.2%}  ({', '.join(f'{k} {v:.2%}' for k, v in diff.items())})",
                  flush=True)
        print(f"  auto: {auto}")
    write_csv(rows, args.out / "model_hierarchy.csv")
    chart(rows, args.out / "model_hierarchy.png")
    print(f"wrote {args.out / 'model_hierarchy.csv'} and {args.out / 'model_hierarchy.png'}")


def chart(rows: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    markers = {"2D": "o", "2D + ring bending": "P", "3D": "s", "3D + ring bending": "D", "3D + free faces": "^",
               "3D + bending + free faces": "X"}

    def marker(label: str) -> str:  # "3D + free faces (roller)" → the free faces' marker
        return markers.get(label, markers.get(label.split(" (")[0], "v"))

    for scene in dict.fromkeys(r["scene"] for r in rows):
        pts = [r for r in rows if r["scene"] == scene]
        line, = ax.plot([r["seconds"] for r in pts], [max(r["worst"], 1e-5) for r in pts], "-", alpha=0.4)
        for r in pts:
            ax.plot(r["seconds"], max(r["worst"], 1e-5), marker(r["model"]), color=line.get_color())
        ax.annotate(scene, (pts[0]["seconds"], max(pts[0]["worst"], 1e-5)), fontsize=8, xytext=(4, 4),
                    textcoords="offset points")
    ax.axhline(0.01, color="grey", ls=":", lw=1)
    ax.text(ax.get_xlim()[0], 0.0105, " model.accuracy 1 %", fontsize=8, color="grey")
    for label, m in markers.items():
        ax.plot([], [], m, color="k", label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("loop wall time (s)")
    ax.set_ylabel("worst relative difference from the fullest model (–)")
    ax.set_title("model hierarchy: cost against the difference in depth and width")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)


if __name__ == "__main__":
    main()
