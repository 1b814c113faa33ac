"""A results file as CSV files for spreadsheets: units in the column names, one row per step or element."""
from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np

from fretsim.results import SUMMARY_UNITS, Results


def _col(name: str, units: str) -> str:
    return f"{name} [{units}]" if units and units != "1" else name


def export_csv(res: Results, outdir: str | Path) -> list[Path]:
    """Write history.csv, summary.csv, inputs.csv, fields.csv (long format: cycle, x, y, fields), with fatigue
    subsurface.csv (cycle, z, x — and y in 3D — the SWT and its plane) and, for a
    cycle with friction, fretting_loop.csv (cycle, displacement, force round each recorded loop) to outdir."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    paths = []

    def write(name: str, header: list, rows) -> None:
        # whole or not at all: beside the target, then renamed over it (a full disk leaves the old file, or none)
        path = outdir / name
        tmp = outdir / f".{name}.{os.getpid()}.part"
        try:
            with open(tmp, "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(header)
                w.writerows(rows)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, path)
        finally:
            if tmp.exists():
                tmp.unlink()
        paths.append(path)

    keys = [k for k in res.history if k != "step"]
    write("history.csv", [_col(k, res.units.get(f"history/{k}", "")) for k in keys],
          zip(*(res.history[k].tolist() for k in keys)))
    write("summary.csv", ["quantity", "value", "units"],
          [(k, v, SUMMARY_UNITS.get(k, "1")) for k, v in res.summary.items()])
    write("inputs.csv", ["input", "value", "units"],
          [(k, v, u) for k, (v, u) in res.inputs.items()] + [("overrides", " ".join(res.overrides), "")])
    names = [k for k in res.fields if k != "cycle"]
    X, Y = np.meshgrid(res.x, res.y)
    rows = []
    for s, cycle in enumerate(res.fields["cycle"]):
        cols = [np.full(X.size, cycle), X.ravel(), Y.ravel()] + [res.fields[k][s].ravel() for k in names]
        rows.extend(zip(*(c.tolist() for c in cols)))
    write("fields.csv", ["cycle", "x [mm]", "y [mm]"] + [_col(k, res.units.get(f"fields/{k}", "")) for k in names],
          rows)
    sub = res.subsurface
    if sub:  # fretting fatigue: the flat's fields below its surface, long format (cycle, z, x), and y in 3D
        names = [k for k in sub if k != "z"]
        three = sub[names[0]].ndim == 4
        if three:
            Z, Y, X = np.meshgrid(sub["z"], res.y, res.x, indexing="ij")
            where = [Z.ravel(), X.ravel(), Y.ravel()]
        else:
            Z, X = np.meshgrid(sub["z"], res.x, indexing="ij")
            where = [Z.ravel(), X.ravel()]
        rows = []
        for s, cycle in enumerate(res.fields["cycle"]):
            cols = [np.full(Z.size, cycle), *where] + [sub[k][s].ravel() for k in names]
            rows.extend(zip(*(c.tolist() for c in cols)))
        write("subsurface.csv", ["cycle", "z [mm]", "x [mm]"] + (["y [mm]"] if three else [])
              + [_col(k, res.units.get(f"fields/{k}", "")) for k in names], rows)
    loop = res.fretting_loop
    if loop.get("displacement") is not None and loop["displacement"].size:
        rows = [(int(c), float(u), float(q)) for c, us, qs in zip(loop["cycle"], loop["displacement"],
                                                                   loop["tangential_force"])
                for u, q in zip(us, qs) if np.isfinite(u) and np.isfinite(q)]
        write("fretting_loop.csv", ["cycle", _col("displacement", res.units.get("fretting_loop/displacement", "um")),
                                    _col("tangential_force", res.units.get("fretting_loop/tangential_force", "N"))],
              rows)
    return paths
