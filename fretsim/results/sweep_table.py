"""A sweep's table read back (table.h5 for the axes, table.csv for the rows)."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import h5py

from fretsim.errors import ResultsFileError
from fretsim.results.layout import SUMMARY_UNITS
from fretsim.results.seal import text


@dataclass
class SweepTable:
    """A sweep's table read back: its axes (key → values as numbers in their units, or text), units, rows."""

    path: str
    axes: dict
    units: dict
    rows: list
    mode: str = "product"
    groups: tuple = ()  # mode sample: the listed axes (the percentiles' groups)


def read_sweep_table(directory: str | Path) -> SweepTable:
    """The table of a sweep directory (table.h5 for the axes, table.csv for the rows)."""
    import csv
    directory = Path(directory)
    try:
        with h5py.File(directory / "table.h5", "r") as f:
            spec = json.loads(text(f.attrs["sweep"]))
            axes, units = {}, {}
            for k in spec.get("axes", {}):
                ds = f[k]
                axes[k] = [v.decode() if isinstance(v, bytes) else v for v in ds[()].tolist()]
                units[k] = text(ds.attrs.get("units", ""))
                bad = [v for v in axes[k] if isinstance(v, float) and not (math.isfinite(v) and abs(v) < 1e30)]
                if bad:
                    raise ValueError(f"table.h5: the axis {k} holds {bad[0]!r}, which no sweep writes (damaged?); "
                                     f"run the sweep again to rewrite its table")
            for k, ds in f.items():
                if isinstance(ds, h5py.Dataset) and k in SUMMARY_UNITS:
                    units[k] = text(ds.attrs.get("units", ""))
        with open(directory / "table.csv", newline="") as fh:
            rows = list(csv.DictReader(fh))
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise ResultsFileError(f"{directory}: not a sweep's directory with a readable table ({exc})") from None
    mode = spec.get("mode", "product")
    groups = tuple(k for k, v in spec.get("axes", {}).items() if isinstance(v, list)) if mode == "sample" else ()
    return SweepTable(str(directory), axes, units, rows, mode, groups)
