"""The fretting map every fretting paper draws: normal load × stroke, coloured by regime and wear.

Runs the sweep ``cases/sweeps/fretting_map.yaml`` (McColl's cylinder in 2D, μ = 0.9, 10 000 cycles; local
workers, or ``--dask tcp://HOST:PORT``) with ``model.slip: auto`` — which resolves every point below or near the
transition with Coulomb friction — and draws

* the map: stroke (log) against load, each point marked by its regime (open: partial slip, filled: gross slip)
  and coloured by the flat's wear volume, with the transition stroke δ_t(P) of the unworn contact as a line;
* the dissipated energy per cycle against stroke, one line per load: the cubic rise of partial slip (Mindlin),
  the knee at δ_t, the linear 4μP(δ − δ_e) of gross slip.

    python scripts/study_fretting_map.py [--jobs N] [--dask ADDRESS]

Writes scripts/out/fretting_map/ (the sweep) and scripts/out/fretting_map.{png,txt}.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report  # noqa: E402

from fretsim.api import sweep  # noqa: E402

OUT = ROOT / "scripts" / "out"


def main(jobs: int = 0, dask=None) -> None:
    table = sweep(ROOT / "cases" / "sweeps" / "fretting_map.yaml", OUT / "fretting_map", jobs=jobs, dask=dask)
    say = Report()
    rows = [r for r in table.rows if r["status"] == "complete"]
    say(f"{len(table.rows)} points, {len(rows)} complete")
    load = np.array([float(str(r["loading.normal_load"]).split()[0]) for r in rows])
    stroke = np.array([float(str(r["loading.stroke"]).split()[0]) for r in rows])
    volume = np.array([float(r["wear_volume_stationary_mm3"]) for r in rows])
    energy = np.array([float(r["dissipated_energy_per_cycle_J"]) for r in rows]) * 1e3
    limit = np.array([float(r["gross_slip_stroke_um"]) for r in rows])
    regime = np.array([r["regime"] for r in rows])
    say(f"{'load N':>8}{'stroke µm':>11}{'δ_t µm':>9}  {'regime':<13}{'volume mm³':>12}{'energy mJ':>11}")
    for i in np.lexsort((stroke, load)):
        say(f"{load[i]:>8.0f}{stroke[i]:>11.3g}{limit[i]:>9.3f}  {regime[i]:<13}{volume[i]:>12.3e}{energy[i]:>11.4g}")
    # every point's regime against its own δ_t: partial below, gross above
    agree = np.mean((regime == "gross_slip") == (stroke > limit))
    say(f"regime of the worn contact against the unworn δ_t: {agree:.0%} of points agree")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    fig, axes = plt.subplots(1, 2, figsize=(13, 5))
    ax = axes[0]
    norm = LogNorm(vmin=max(volume[volume > 0].min(), 1e-12), vmax=volume.max())
    for name, marker, face in (("partial_slip", "o", False), ("gross_slip", "s", True)):
        sel = regime == name
        sc = ax.scatter(stroke[sel], load[sel], c=np.clip(volume[sel], norm.vmin, None), norm=norm, cmap="viridis",
                        marker=marker, s=90, edgecolors="k" if face else None, linewidths=0.6,
                        label=name.replace("_", " "))
        if not face:
            sc.set_facecolor("none")
            sc.set_edgecolor(sc.get_cmap()(norm(np.clip(volume[sel], norm.vmin, None))))
            sc.set_linewidth(2.0)
    loads = np.unique(load)
    ax.plot([limit[load == p][0] for p in loads], loads, "k--", lw=1.2, label="δ_t(P), the unworn contact")
    ax.set_xscale("log")
    ax.set_xlabel("stroke δ (µm)")
    ax.set_ylabel("normal load P (N)")
    ax.set_title("fretting map: regime and the flat's wear volume (colour, mm³)")
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, label="wear volume, flat (mm³)")
    ax.legend(fontsize=8, loc="upper left")
    ax = axes[1]
    for p in loads:
        sel = np.argsort(stroke[load == p])
        ax.plot(stroke[load == p][sel], energy[load == p][sel], "o-", ms=4, label=f"P = {p:g} N")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("stroke δ (µm)")
    ax.set_ylabel("energy dissipated per cycle (mJ)")
    ax.set_title("partial slip ∝ δ³ (Mindlin), gross slip ≈ 4μPδ")
    ax.legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3, which="both")
    fig.suptitle("McColl's cylinder, 2D, μ = 0.9, 10 000 cycles (cases/sweeps/fretting_map.yaml)", fontsize=10)
    fig.tight_layout()
    fig.savefig(OUT / "fretting_map.png", dpi=130)
    say.write(OUT / "fretting_map.txt")
    print(f"wrote {OUT / 'fretting_map.png'} and .txt")


if __name__ == "__main__":
    args = sys.argv[1:]
    main(int(args[args.index("--jobs") + 1]) if "--jobs" in args else 0,
         args[args.index("--dask") + 1] if "--dask" in args else None)
