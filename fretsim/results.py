"""The HDF5 results file: layout, incremental writer and reader.  The layout is a contract (see README).

    /                  attrs format_version, fretsim_version, status, status_message, case_name
    /case              the validated case with defaults and automatic choices filled (YAML text)
    /grid/x, /grid/y   element centres (mm)
    /history/<name>    one entry per accepted step (cycle, wear depths, volumes, pressure, iterations, time…)
    /fields/<name>     at the snapshot cycles: wear depths, pressure, stroke-averaged pressure (S, My, Mx)
    /summary           attrs: the run's headline figures (same names as `fretsim summary`)

History rows are written in batches and the file flushed at least every 0.5 s and at every snapshot, so
it is readable during a run; an interrupted run keeps every step it accepted, a killed one all but the
last half second.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import h5py
import numpy as np

from fretsim import __version__

FORMAT_VERSION = "1.0"

# name: (units, how to get the value from a Step)
HISTORY = {
    "cycle": ("cycles", lambda s: s.cycle),
    "max_wear_depth_moving": ("um", lambda s: s.wear_moving.max() * 1e3),
    "max_wear_depth_stationary": ("um", lambda s: s.wear_stationary.max() * 1e3),
    "max_wear_depth_total": ("um", lambda s: (s.wear_moving + s.wear_stationary).max() * 1e3),
    "wear_volume_moving": ("mm^3", lambda s: s.volume_moving),
    "wear_volume_stationary": ("mm^3", lambda s: s.volume_stationary),
    "max_pressure": ("MPa", lambda s: s.pressure.max()),
    "solver_iterations": ("1", lambda s: s.iterations),
    "wall_time": ("s", lambda s: s.wall_time),
    "approach": ("um", lambda s: s.approach * 1e3),
    "archard_volume_error": ("1", lambda s: s.archard_error),
    "checkerboard_amplitude": ("1", lambda s: s.checkerboard),
    "cycle_jump": ("cycles", lambda s: s.jump),
    "rejected_steps": ("1", lambda s: s.rejected),
}
FIELDS = {
    "wear_depth_moving": ("um", lambda s: s.wear_moving * 1e3),
    "wear_depth_stationary": ("um", lambda s: s.wear_stationary * 1e3),
    "pressure": ("MPa", lambda s: s.pressure),
    "pressure_stationary_average": ("MPa", lambda s: s.pressure_average),
}
SUMMARY_UNITS = {
    "cycles": "cycles", "contact_solves": "1", "wall_time_s": "s", "max_wear_depth_moving_um": "um",
    "max_wear_depth_stationary_um": "um", "centre_wear_depth_moving_um": "um",
    "centre_wear_depth_stationary_um": "um", "scar_width_stationary_mm": "mm", "wear_volume_moving_mm3": "mm^3",
    "wear_volume_stationary_mm3": "mm^3", "archard_volume_error": "1", "max_pressure_MPa": "MPa",
    "linear_jump": "cycles", "stability_limit_linear": "cycles", "element_size_x_um": "um",
    "element_size_y_um": "um", "elements_x": "1", "elements_y": "1",
}


class ResultsWriter:
    """Observer that writes each accepted step; create with the filled case, grid and the output path."""

    def __init__(self, path: str | Path, case_yaml: str, case_name: str, grid, notes=(), overwrite: bool = False):
        self.path = Path(path)
        self._f = h5py.File(self.path, "w" if overwrite else "w-")
        f = self._f
        f.attrs.update(format_version=FORMAT_VERSION, fretsim_version=__version__, status="running",
                       status_message="", case_name=case_name, notes="\n".join(notes))
        f.create_dataset("case", data=case_yaml, dtype=h5py.string_dtype())
        g = f.create_group("grid")
        for name, values in (("x", grid.x), ("y", grid.y)):
            ds = g.create_dataset(name, data=values)
            ds.attrs["units"] = "mm"
        g.attrs.update(dx_mm=grid.dx, dy_mm=grid.dy, plane_strain=grid.plane_strain)
        h = f.create_group("history")
        for name, (units, _) in HISTORY.items():
            ds = h.create_dataset(name, shape=(0,), maxshape=(None,), chunks=(1024,),
                                  dtype="i8" if name in ("cycle", "solver_iterations", "cycle_jump", "rejected_steps") else "f8")
            ds.attrs["units"] = units
        fl = f.create_group("fields")
        ny, nx = grid.shape
        ds = fl.create_dataset("cycle", shape=(0,), maxshape=(None,), dtype="i8", chunks=(64,))
        ds.attrs["units"] = "cycles"
        for name, (units, _) in FIELDS.items():
            ds = fl.create_dataset(name, shape=(0, ny, nx), maxshape=(None, ny, nx), chunks=(1, ny, nx), dtype="f8")
            ds.attrs["units"] = units
        f.create_group("summary")
        f.flush()
        self._rows: list = []
        self._flushed = time.monotonic()

    FLUSH_SECONDS = 0.5  # history rows are written in batches: a kill loses at most this much of the run

    def on_step(self, setup, step) -> None:
        self._rows.append([get(step) for _, get in HISTORY.values()])
        if step.is_snapshot:
            fl = self._f["fields"]
            k = fl["cycle"].shape[0]
            fl["cycle"].resize((k + 1,))
            fl["cycle"][k] = step.cycle
            for name, (_, get) in FIELDS.items():
                fl[name].resize((k + 1,) + fl[name].shape[1:])
                fl[name][k] = get(step)
        if step.is_snapshot or time.monotonic() - self._flushed > self.FLUSH_SECONDS:
            self._write_rows()

    def _write_rows(self) -> None:
        if self._rows:
            h = self._f["history"]
            n = h["cycle"].shape[0]
            rows = np.array(self._rows, dtype=float)
            for j, name in enumerate(HISTORY):
                h[name].resize((n + len(rows),))
                h[name][n:] = rows[:, j]
            self._rows = []
        self._f.flush()
        self._flushed = time.monotonic()

    def finish(self, status: str, message: str = "", summary: Optional[dict] = None) -> None:
        self._write_rows()
        if summary:
            s = self._f["summary"]
            for key, value in summary.items():
                s.attrs[key] = value
            s.attrs["units"] = ", ".join(f"{k}: {SUMMARY_UNITS.get(k, '1')}" for k in summary)
        self._f.attrs["status"] = status
        self._f.attrs["status_message"] = message
        self._f.flush()
        self._f.close()


@dataclass
class Results:
    """A results file read back into memory (arrays in the file's units; see ``units``)."""

    path: str
    attrs: dict
    case_yaml: str
    x: np.ndarray
    y: np.ndarray
    history: dict
    fields: dict
    summary: dict
    units: dict

    @property
    def status(self) -> str:
        return self.attrs.get("status", "")


def read_results(path: str | Path) -> Results:
    """Read a results file; raises ``ValueError`` with a clear message if it is not one."""
    try:
        with h5py.File(path, "r") as f:
            if "format_version" not in f.attrs:
                raise ValueError(f"{path} is an HDF5 file but not a fretsim results file (no format_version)")
            units = {}
            history = {}
            for k, ds in f["history"].items():
                history[k] = ds[()]
                units[f"history/{k}"] = ds.attrs.get("units", "")
            fields = {}
            for k, ds in f["fields"].items():
                fields[k] = ds[()]
                units[f"fields/{k}"] = ds.attrs.get("units", "")
            case = f["case"][()]
            return Results(path=str(path), attrs={k: _plain(v) for k, v in f.attrs.items()},
                           case_yaml=case.decode() if isinstance(case, bytes) else str(case),
                           x=f["grid/x"][()], y=f["grid/y"][()], history=history, fields=fields,
                           summary={k: _plain(v) for k, v in f["summary"].attrs.items() if k != "units"},
                           units=units)
    except FileNotFoundError:
        raise ValueError(f"{path}: no such results file") from None
    except OSError as exc:
        raise ValueError(f"{path}: not a readable HDF5 results file ({exc})") from None
    except KeyError as exc:
        raise ValueError(f"{path}: not a complete fretsim results file (missing {exc})") from None


def _plain(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float) and math.isnan(v):
        return None
    return v
