"""PNG figures from a results file (the only module importing matplotlib; Agg backend, no display).

Figures after the paper: wear profiles along the centre line (Fig. 17), wear
maps of both bodies (Figs. 24–25), maximum wear depth against cycles (Figs. 14,
28), pressure profiles (Fig. 16).  They read only the results file.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from fretsim.results import Results  # noqa: E402
from fretsim.simulate import centre_line  # noqa: E402


def plot_all(res: Results, outdir: str | Path) -> list[Path]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    stem = Path(res.path).stem
    if res.fields.get("cycle") is None or res.fields["cycle"].size == 0:
        raise ValueError(f"{res.path} has no snapshot fields to plot (status {res.status})")
    paths = [_profiles(res, outdir / f"{stem}_wear_profiles.png"),
             _pressure(res, outdir / f"{stem}_pressure_profiles.png"),
             _history(res, outdir / f"{stem}_max_wear_history.png")]
    if res.y.size > 1:
        paths.append(_maps(res, outdir / f"{stem}_wear_maps.png"))
    return paths


def _title(res: Results, what: str) -> str:
    return f"{res.attrs.get('case_name', '')}: {what}" + ("" if res.status == "complete" else f" [{res.status}]")


def _profiles(res: Results, path: Path) -> Path:
    return _centre_line_pair(res, path, "wear profiles", [
        ("wear_depth_moving", "moving body, centre line y = 0", "worn profile, -depth"),
        ("wear_depth_stationary", "stationary body, centre line y = 0", "worn profile, -depth")], sign=-1.0)


def _pressure(res: Results, path: Path) -> Path:
    return _centre_line_pair(res, path, "pressure profiles", [
        ("pressure", "moving body (mid-stroke), y = 0", "contact pressure"),
        ("pressure_stationary_average", "stationary body (stroke average), y = 0", "contact pressure")])


def _centre_line_pair(res: Results, path: Path, what: str, panels, sign: float = 1.0) -> Path:
    """Two panels of a field along the centre line at every snapshot."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    for ax, (name, title, quantity) in zip(axes, panels):
        for k, n in enumerate(res.fields["cycle"]):
            ax.plot(res.x, sign * centre_line(res.fields[name][k]), label=f"N = {n}")
        ax.set_xlabel("x, sliding direction (mm)")
        ax.set_ylabel(f"{quantity} ({_unit(res, 'fields/' + name)})")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    axes[1].legend(fontsize=8)
    return _save(fig, res, what, path)


def _unit(res: Results, key: str) -> str:
    return res.units[key].replace("um", "µm")


def _save(fig, res: Results, what: str, path: Path) -> Path:
    fig.suptitle(_title(res, what))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _history(res: Results, path: Path) -> Path:
    h = res.history
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for name, label in (("max_wear_depth_total", "total"), ("max_wear_depth_stationary", "stationary"),
                        ("max_wear_depth_moving", "moving")):
        ax.plot(h["cycle"], h[name], label=label, marker="." if h["cycle"].size < 60 else None)
    ax.set_xlabel("cycles (–)")
    ax.set_ylabel(f"maximum wear depth ({_unit(res, 'history/max_wear_depth_total')})")
    ax.grid(alpha=0.3)
    ax.legend()
    return _save(fig, res, "maximum wear depth", path)


def _maps(res: Results, path: Path) -> Path:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, body in zip(axes, ("moving", "stationary")):
        data = res.fields[f"wear_depth_{body}"][-1]
        cs = ax.contourf(res.x, res.y, data, levels=20, cmap="viridis")
        fig.colorbar(cs, ax=ax, label="wear depth (µm)")
        ax.set_xlabel("x, sliding direction (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_title(f"{body} body at N = {res.fields['cycle'][-1]}")
    return _save(fig, res, "wear maps", path)
