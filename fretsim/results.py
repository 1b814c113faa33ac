"""The HDF5 results file: layout, crash-safe writer and reader.  The layout is a contract (see README).

    /                  attrs format_version, fretsim_version, status, status_message, case_name, notes
    /case              the validated case with defaults and automatic choices filled (YAML text)
    /grid/x, /grid/y   element centres (mm)
    /history/<name>    one entry per accepted step (cycle, wear depths, volumes, pressure, iterations, time…)
    /fields/<name>     at the snapshot cycles: wear depths, pressure, stroke-averaged pressure (S, My, Mx)
    /summary           attrs: the run's headline figures (same names as `fretsim summary`)
    /checkpoint        the loop's state at the last written step, for `fretsim run --resume`

Crash safety: the writer keeps the run in memory and, at every flush, writes the whole file to a temporary
file beside it and renames it over the results file (an atomic replacement on POSIX).  The file on disk is
therefore always a complete, valid HDF5 file — after Ctrl-C, SIGTERM or kill -9 alike — holding every step
up to the last flush (at most FLUSH_SECONDS old) together with the state to resume from.  Flushes happen
at the first step, then at most every FLUSH_SECONDS, and at the end.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import h5py
import numpy as np

from fretsim import __version__

FORMAT_VERSION = "1.1"
FLUSH_SECONDS = 0.5

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
    "checkerboard_amplitude": ("1", lambda s: abs(s.checkerboard)),
    "cycle_jump": ("cycles", lambda s: s.jump),
    "rejected_steps": ("1", lambda s: s.rejected),
    "error_estimate_depth": ("1", lambda s: s.error_depth),
    "error_estimate_pressure": ("1", lambda s: s.error_pressure),
}
INTEGER_HISTORY = {"cycle", "solver_iterations", "cycle_jump", "rejected_steps"}
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
    "element_size_y_um": "um", "elements_x": "1", "elements_y": "1", "scar_width_moving_mm": "mm",
    "error_estimate_depth": "1", "error_estimate_pressure": "1",
}


class ResultsWriter:
    """Observer that records each accepted step and keeps the results file complete on disk.

    ``previous`` (a :class:`Results` read back from an interrupted run) seeds the history and fields, so a
    resumed run appends to what was there.
    """

    def __init__(self, path: str | Path, case_yaml: str, case_name: str, grid, notes=(), overwrite: bool = False,
                 previous: Optional["Results"] = None, choices=()):
        self.path = Path(path)
        if self.path.exists() and not overwrite and previous is None:
            raise FileExistsError(f"{self.path} exists")
        self.case_yaml, self.case_name, self.grid, self.notes = case_yaml, case_name, grid, tuple(notes)
        self.choices = tuple(choices)
        if previous is not None:
            self.rows = [list(r) for r in zip(*(previous.history[k] for k in HISTORY))] if len(
                previous.history.get("cycle", [])) else []
            self.fields = {k: list(previous.fields[k]) for k in FIELDS}
            self.field_cycles = list(previous.fields["cycle"])
        else:
            self.rows, self.fields, self.field_cycles = [], {k: [] for k in FIELDS}, []
        self.status, self.message, self.summary = "running", "", {}
        self.state: Optional[dict] = None
        self._flushed = -math.inf

    def on_step(self, setup, step) -> None:
        self.rows.append([get(step) for _, get in HISTORY.values()])
        if step.is_snapshot and (not self.field_cycles or self.field_cycles[-1] != step.cycle):
            self.field_cycles.append(step.cycle)
            for name, (_, get) in FIELDS.items():
                self.fields[name].append(np.array(get(step)))
        self.state = step.state
        # the first step (so the file exists at once), then at most every FLUSH_SECONDS: each flush rewrites the
        # whole file, and a kill costs at most the steps since the last one, which --resume recomputes
        if len(self.rows) == 1 or time.monotonic() - self._flushed > FLUSH_SECONDS:
            self.flush()

    def finish(self, status: str, message: str = "", summary: Optional[dict] = None) -> None:
        self.status, self.message = status, message
        self.summary = summary or {}
        self.flush()

    def flush(self) -> None:
        """Write the whole file beside the target and rename it over the target (atomic)."""
        tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
        try:
            with h5py.File(tmp, "w") as f:
                self._write(f)
            os.replace(tmp, self.path)
        finally:
            if tmp.exists():
                tmp.unlink()
        self._flushed = time.monotonic()

    def _write(self, f: h5py.File) -> None:
        grid = self.grid
        f.attrs.update(format_version=FORMAT_VERSION, fretsim_version=__version__, status=self.status,
                       status_message=self.message, case_name=self.case_name, notes="\n".join(self.notes))
        f.create_dataset("case", data=self.case_yaml, dtype=h5py.string_dtype())
        g = f.create_group("grid")
        for name, values in (("x", grid.x), ("y", grid.y)):
            g.create_dataset(name, data=values).attrs["units"] = "mm"
        g.attrs.update(dx_mm=grid.dx, dy_mm=grid.dy, plane_strain=grid.plane_strain)
        h = f.create_group("history")
        rows = np.array(self.rows, dtype=float).reshape(len(self.rows), len(HISTORY))
        for j, (name, (units, _)) in enumerate(HISTORY.items()):
            data = rows[:, j].astype("i8") if name in INTEGER_HISTORY else rows[:, j]
            h.create_dataset(name, data=data).attrs["units"] = units
        fl = f.create_group("fields")
        ny, nx = grid.shape
        fl.create_dataset("cycle", data=np.array(self.field_cycles, dtype="i8")).attrs["units"] = "cycles"
        for name, (units, _) in FIELDS.items():
            data = np.array(self.fields[name]).reshape(len(self.fields[name]), ny, nx)
            fl.create_dataset(name, data=data).attrs["units"] = units
        ch = f.create_group("choices")
        text = h5py.string_dtype()
        ch.create_dataset("key", data=[c.key for c in self.choices], dtype=text)
        ch.create_dataset("value", data=[_value_text(c.value) for c in self.choices], dtype=text)
        ch.create_dataset("reason", data=[c.reason for c in self.choices], dtype=text)
        ch.create_dataset("given", data=np.array([c.given for c in self.choices], dtype=np.int8))
        s = f.create_group("summary")
        for key, value in self.summary.items():
            s.attrs[key] = value
        if self.summary:
            s.attrs["units"] = ", ".join(f"{k}: {SUMMARY_UNITS.get(k, '1')}" for k in self.summary)
        if self.state is not None:
            c = f.create_group("checkpoint")
            for key, value in self.state.items():
                if isinstance(value, np.ndarray):
                    c.create_dataset(key, data=value)
                elif isinstance(value, list):  # a list of arrays (the adaptive scheme's batch)
                    c.create_dataset(key, data=np.array(value)) if value else c.attrs.__setitem__(key + "_empty", 1)
                elif value is not None:
                    c.attrs[key] = value


def _value_text(value) -> str:
    if isinstance(value, tuple):
        return "[" + ", ".join(repr(v) for v in value) + "]"
    return str(value)


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
    checkpoint: Optional[dict] = None
    choices: list = None  # (key, value, reason) of every automatic choice

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
            checkpoint = None
            if "checkpoint" in f:
                c = f["checkpoint"]
                checkpoint = {k: ds[()] for k, ds in c.items()}
                for k, v in c.attrs.items():
                    if k.endswith("_empty"):
                        checkpoint[k[:-6]] = []
                    else:
                        checkpoint[k] = _plain(v)
            choices = []
            if "choices" in f:
                c = f["choices"]
                choices = list(zip(*(( [v.decode() if isinstance(v, bytes) else str(v) for v in c[k][()]])
                                     for k in ("key", "value", "reason"))))
            case = f["case"][()]
            return Results(path=str(path), attrs={k: _plain(v) for k, v in f.attrs.items()},
                           case_yaml=case.decode() if isinstance(case, bytes) else str(case),
                           x=f["grid/x"][()], y=f["grid/y"][()], history=history, fields=fields,
                           summary={k: _plain(v) for k, v in f["summary"].attrs.items() if k != "units"},
                           units=units, checkpoint=checkpoint, choices=choices)
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
