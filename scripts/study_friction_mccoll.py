"""McColl's tests with the friction of McColl's FE (μ = 0.9): uniform slip against Coulomb friction, 2D and 3D.

The paper (§3.2) puts its disagreement with McColl's finite-element wear down to friction: the FE slip varies
over the contact and evolves with wear, its own model assumes uniform slip.  This runs each of McColl's four
Table 4 cases with μ = 0.9 under

* ``uniform``: the paper's model (gross slip, 4δ everywhere, mid-stroke pressure);
* ``coulomb``: Coulomb friction through the cycle, the normal contact at mid-stroke (fretsim's default with μ);
* ``coulomb, resolved``: the normal contact solved at each increment too (which wears kinks at the contact's
  turning edges, README) — reported where it completes;

and sets them beside the paper's FEA and model values (Table 4).  Report, do not tune: the wear coefficients are
the paper's.  Prints a table; writes ``scripts/out/friction_mccoll.{csv,txt,png}`` (profiles of the 185 N case).

    python scripts/study_friction_mccoll.py [--quick] [--bodies]

``--bodies`` adds the Coulomb runs with McColl's FE bodies (geometry.flat_width/flat_thickness/moving_height), whose
elastic share of the stroke the half-spaces underestimate, and the MAPE of each model against the FEA.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report, write_csv  # noqa: E402

from fretsim.api import load_case, run  # noqa: E402
from fretsim.measures import centre_line  # noqa: E402

OUT = ROOT / "scripts" / "out"
CASES = ("mccoll_185N", "mccoll_500N", "mccoll_1670N", "mccoll_500N_10um")
MODELS = {"uniform": ["model.slip=uniform"], "coulomb": ["model.slip=coulomb", "model.stroke=mid_stroke"],
          "coulomb, resolved": ["model.slip=coulomb", "model.stroke=resolved"]}
# McColl's FE bodies: the flat a 12 × 6 mm block with the stroke at its base, the cylinder held 6 mm above the contact
BODIES = ["geometry.flat_width=12 mm", "geometry.flat_thickness=6 mm", "geometry.moving_height=6 mm"]
WITH_BODIES = {"coulomb, FE bodies": ["model.slip=coulomb", "model.stroke=mid_stroke", *BODIES],
               "resolved, FE bodies": ["model.slip=coulomb", "model.stroke=resolved", *BODIES]}


def number(text) -> float:
    return float(str(text).split()[0])


def main(quick: bool = False, bodies: bool = False) -> None:
    models = {**MODELS, **(WITH_BODIES if bodies else {})}
    say = Report()
    rows, profiles = [], {}
    dims = ("2d",) if quick else ("2d", "3d")
    say("McColl's cases with μ = 0.9 (McColl's FE): flat's centre-line depth (µm) and scar width (mm)")
    say(f"{'case':<18}{'dim':<5}{'model':<20}{'status':<10}{'depth':>8}{'width':>8}{'cyl. depth':>11}"
        f"{'loop s':>8}{'FEA depth':>10}{'FEA width':>10}{'paper':>12}")
    for name in CASES[:1] if quick else CASES:
        expected = load_case(ROOT / "cases" / f"{name}.yaml").expected
        fea, paper = expected.get("fea", {}), expected.get("paper", {})
        for dim in dims:
            for label, model in models.items():
                t = time.perf_counter()
                out = run(load_case(ROOT / "cases" / f"{name}.yaml", [f"model.dimension={dim}",
                                                                      "loading.friction_coefficient=0.9", *model]))
                s = out.summary
                row = {"case": name, "dimension": dim, "model": label, "status": out.status,
                       "depth_um": s.get("centre_wear_depth_stationary_um", np.nan),
                       "width_mm": s.get("scar_width_stationary_mm", np.nan),
                       "cylinder_depth_um": s.get("centre_wear_depth_moving_um", np.nan),
                       "loop_s": s.get("wall_time_s", np.nan), "wall_s": time.perf_counter() - t,
                       "regime": s.get("regime", ""), "fea_depth_um": number(fea.get("centre_wear_depth_stationary", "nan")),
                       "fea_width_mm": number(fea.get("scar_width_stationary", "nan")),
                       "paper_depth_um": number(paper.get("centre_wear_depth_stationary", "nan")),
                       "paper_width_mm": number(paper.get("scar_width_stationary", "nan")),
                       "message": out.message[:120]}
                rows.append(row)
                say(f"{name:<18}{dim:<5}{label:<20}{out.status:<10}{row['depth_um']:>8.3f}{row['width_mm']:>8.3f}"
                    f"{row['cylinder_depth_um']:>11.3f}{row['loop_s']:>8.2f}{row['fea_depth_um']:>10.2f}"
                    f"{row['fea_width_mm']:>10.2f}{row['paper_depth_um']:>6.1f}/{row['paper_width_mm']:.2f}")
                if name == "mccoll_185N" and out.last is not None:
                    profiles[(dim, label)] = (out.setup.grid.x, centre_line(out.last.wear_stationary) * 1e3,
                                              centre_line(out.last.wear_moving) * 1e3)
    say("")
    say("FEA: McColl et al. (2D, μ = 0.9), as tabulated by Kong, Bennett & Hyde, Table 4; paper: its own model.")
    say("")
    say("MAPE against the FEA (cases where the run completed), depth and width:")
    for dim in dims:
        for label in models:
            done = [r for r in rows if r["dimension"] == dim and r["model"] == label and r["status"] == "complete"]
            if done:
                md = np.mean([abs(r["depth_um"] / r["fea_depth_um"] - 1) for r in done])
                mw = np.mean([abs(r["width_mm"] / r["fea_width_mm"] - 1) for r in done])
                say(f"  {dim} {label:<22} depth {md:6.1%}  width {mw:6.1%}  ({len(done)} of {len(CASES[:1] if quick else CASES)})")
    OUT.mkdir(parents=True, exist_ok=True)
    stem = "friction_mccoll_bodies" if bodies else "friction_mccoll"
    write_csv(rows, OUT / f"{stem}.csv")
    say.write(OUT / f"{stem}.txt")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    for (dim, label), (x, flat, cyl) in profiles.items():
        ls = "-" if dim == "3d" else "--"
        axes[0].plot(x, -flat, ls=ls, label=f"{label}, {dim.upper()}")
        axes[1].plot(x, -cyl, ls=ls, label=f"{label}, {dim.upper()}")
    for ax, body in zip(axes, ("flat (stationary)", "cylinder (moving)")):
        ax.set_xlabel("x, sliding direction (mm)")
        ax.set_ylabel("worn profile, −depth (µm)")
        ax.set_title(f"McColl 185 N, μ = 0.9, 18 000 cycles: {body}, y = 0")
        ax.grid(alpha=0.3)
        ax.set_xlim(-0.35, 0.35)
    axes[0].axhline(-3.0, color="k", lw=0.8, ls=":", label="FEA depth 3.0 µm (Table 4)")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / f"{stem}.png", dpi=130)
    print(f"wrote {OUT / stem}.txt, .csv, .png")


if __name__ == "__main__":
    main("--quick" in sys.argv, "--bodies" in sys.argv)
