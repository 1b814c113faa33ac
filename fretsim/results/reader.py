"""Reading a results file back: structure, types, shapes against the grid, sizes before allocating, finiteness
and the checksums verified, and a damaged file refused with the path of what is wrong."""
from __future__ import annotations

import hashlib
import json
import math
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import h5py
import numpy as np

from fretsim.errors import ResultsFileError
from fretsim.results.layout import (FIELDS, FIELDS_V12, FORMAT_VERSION, HISTORY, HISTORY_V11, HISTORY_V12, HISTORY_V13,
                                    HISTORY_V14, MAX_DATASET_BYTES, NAN_FIELDS, NAN_HISTORY, NAN_SUMMARY,
                                    READABLE_FORMATS, STATUSES, SUBSURFACE_TABLES,
                                    in_summary_order)
from fretsim.results.seal import (SEALED_FROM, _SCALE_ATTRS, _Damaged, _verify_attrs_seal, _verify_seal,
                                  checkpoint_digest, plain, text, verify_image)


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
    fretting_loop: dict = field(default_factory=dict)  # cycle, displacement (um), tangential_force (N)
    choices: list = field(default_factory=list)  # (key, value, reason) of every automatic choice
    provenance: list = field(default_factory=list)  # (key, value, reason, given, error) of each, as first planned
    inputs: dict = field(default_factory=dict)  # name: (value, units)
    overrides: list = field(default_factory=list)
    regrids: list = field(default_factory=list)  # the automatic grid's widenings (fretsim.regrid.Regrid), in order
    coarsenings: list = field(default_factory=list)  # ... and its coarsenings (fretsim.regrid.Coarsening)
    subsurface: dict = field(default_factory=dict)  # fretting fatigue: z (mm) and fields (cycle, z, [y,] x) below
    #                                                  the flat (swt, …) and the moving body (swt_moving, …): see fatigue()

    def fatigue(self, body: str = "stationary") -> dict:
        """One body's fields below its surface, by their plain names (z, swt, swt_plane_angle, stress_…), or {}
        where the run had no fatigue constants for it: ``body`` "stationary" (the flat) or "moving"."""
        from fretsim.results.layout import SUBSURFACE_3D, SUBSURFACE_BODIES
        swt, stresses, _ = SUBSURFACE_BODIES[body]
        suffix = "_moving" if body == "moving" else ""
        names = (*swt, *stresses, *(SUBSURFACE_3D if body == "stationary" else ()))
        out = {k[:len(k) - len(suffix)]: self.subsurface[k] for k in names if k in self.subsurface}
        return {"z": self.subsurface["z"], **out} if out else {}

    @property
    def status(self) -> str:
        return self.attrs.get("status", "")

    def case_values(self) -> dict:
        """The filled case stored in the file as dotted key → value (its name and published values aside; {} where
        it cannot be read)."""
        from fretsim.yamlread import YamlProblem, loads
        try:
            case = loads(self.case_yaml) or {}
        except YamlProblem:
            return {}
        out: dict = {}

        def walk(node, prefix):
            for k, v in node.items():
                if isinstance(v, dict):
                    walk(v, f"{prefix}{k}.")
                else:
                    out[f"{prefix}{k}"] = v
        if isinstance(case, dict):
            walk({k: v for k, v in case.items() if k not in ("name", "expected")}, "")
        return out

    def _case_section(self, name: str) -> dict:
        """A top-level mapping of the stored case ({} where absent or not a mapping)."""
        from fretsim.yamlread import YamlProblem, loads
        try:
            section = (loads(self.case_yaml) or {}).get(name) or {}
        except (YamlProblem, AttributeError):
            return {}
        return section if isinstance(section, dict) else {}

    def wear_limits(self) -> dict:
        """The case's wear limits (key → (value in internal units: mm, mm³ or a fraction, as written)), those the
        file's case states readably; what the history figure draws beside its quantities."""
        from fretsim.quantities import WEAR
        from fretsim.units import UnitError, parse_quantity
        out = {}
        for key, written in self._case_section("limits").items():
            wear = WEAR.get(str(key))
            if wear is None:
                continue
            try:
                value = float(written) if wear.kind == "fraction" else parse_quantity(written, wear.kind)
            except (TypeError, ValueError, UnitError):
                continue
            if math.isfinite(value):
                out[wear.key] = (value, f"{value:.3g}" if wear.kind == "fraction" else str(written))
        return out

    def frequency(self) -> Optional[float]:
        """The case's ``loading.frequency`` (Hz), or None where it gives none (or the file's case cannot say)."""
        from fretsim.units import UnitError, parse_quantity
        written = self._case_section("loading").get("frequency")
        if written is None:
            return None
        try:
            hz = parse_quantity(written, "frequency")
        except UnitError:
            return None
        return hz if math.isfinite(hz) and hz > 0 else None

    def load_blocks(self) -> list:
        """A load history's blocks as the case gives them, one pass (``loading.blocks`` or ``loading.spectrum``):
        [(normal load N, stroke mm), ...]; [] for one load, or where the file's case cannot say (what a title
        quotes beside the peak values of /inputs)."""
        from fretsim.units import UnitError, parse_quantity
        loading = self._case_section("loading")
        given = loading.get("blocks", loading.get("spectrum"))
        if not isinstance(given, list):
            return []
        out = []
        for block in given:
            try:
                load, stroke = (parse_quantity(block[k], kind) for k, kind in (("normal_load", "force"),
                                                                              ("stroke", "length")))
            except (TypeError, KeyError, UnitError):
                return []
            if not (math.isfinite(load) and math.isfinite(stroke)):
                return []
            out.append((load, stroke))
        return out

    def published(self) -> dict:
        """source (experiment, fea, paper) → (the flat's centre-line depth µm, its scar width mm) from the case's
        `expected:` data (None where absent): what figures compare with."""
        from fretsim.units import UnitError, parse_quantity
        out = {}
        for source, values in self._case_section("expected").items():
            if not isinstance(values, dict):
                continue
            got = []
            for key in ("centre_wear_depth_stationary", "scar_width_stationary"):
                try:
                    got.append(parse_quantity(values[key], "length") if key in values else None)
                except UnitError:
                    got.append(None)
            if any(v is not None for v in got):
                out[source] = (got[0] * 1e3 if got[0] is not None else None, got[1])
        return out

    def to_xarray(self):
        """The run as one xarray Dataset: the fields over (cycle, y, x) at the recorded states, the history over
        ``step`` (every accepted step, with its cycle as the coordinate ``step_cycle``), units on every variable,
        and the summary as attributes.  Needs xarray (``pip install xarray``)."""
        import xarray as xr
        coords = {"cycle": ("cycle", self.fields["cycle"], {"units": "cycles", "long_name": "recorded state"}),
                  "y": ("y", self.y, {"units": "mm"}), "x": ("x", self.x, {"units": "mm"}),
                  "step": ("step", np.arange(len(self.history["cycle"])), {"long_name": "accepted step"}),
                  "step_cycle": ("step", self.history["cycle"], {"units": "cycles",
                                                                 "long_name": "cycle of the accepted step"})}
        data = {k: (("cycle", "y", "x"), v, {"units": self.units.get(f"fields/{k}", "")})
                for k, v in self.fields.items() if k != "cycle"}
        if self.subsurface:  # fretting fatigue: each body's fields below its surface (the moving body's …_moving)
            said = {frozenset({"swt"}): "the flat's", frozenset({"swt_moving"}): "the moving body's"}.get(
                frozenset({"swt", "swt_moving"} & set(self.subsurface)), "each body's")
            coords["z"] = ("z", self.subsurface["z"], {"units": "mm", "long_name": f"depth below {said} surface"})
            data.update({k: (("cycle", "z", "x") if v.ndim == 3 else ("cycle", "z", "y", "x"), v,
                             {"units": self.units.get(f"fields/{k}", "")})
                         for k, v in self.subsurface.items() if k != "z"})
        data.update({k: ("step", v, {"units": self.units.get(f"history/{k}", "")})
                     for k, v in self.history.items() if k not in ("cycle", "step")})
        attrs = {"case_name": self.attrs.get("case_name", ""), "status": self.status}
        attrs.update({k: v for k, v in self.summary.items() if isinstance(v, (int, float, str))})
        return xr.Dataset(data, coords=coords, attrs=attrs)


def _name(key, where: str) -> str:
    """A dataset or attribute name as written by this tool: a plain identifier (a damaged name is refused)."""
    if not isinstance(key, str) or not key.replace("_", "a").isalnum() or not key.isascii():
        raise _Damaged(f"{where}: an entry has a damaged name {str(key)[:40]!r}")
    return key


def _regular_file(path: str | Path) -> None:
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise ResultsFileError(f"{path}: no such results file") from None
    except OSError as exc:
        raise ResultsFileError(f"{path}: cannot read it ({exc.strerror})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ResultsFileError(f"{path}: is a directory, not a results file")
    if not stat.S_ISREG(st.st_mode):
        raise ResultsFileError(f"{path}: not a regular file (a FIFO, device or socket); expected an HDF5 results file")


def _dataset(f, path: str, ndim: Optional[int] = None, numeric: bool = True, shape: Optional[tuple] = None,
             allow_nan: bool = False):
    obj = f.get(path)
    if obj is None:
        raise _Damaged(f"/{path}: missing")
    if not isinstance(obj, h5py.Dataset):
        raise _Damaged(f"/{path}: expected a dataset, found a {type(obj).__name__.lower()}")
    if ndim is not None and obj.ndim != ndim:
        raise _Damaged(f"/{path}: expected {ndim} dimension(s), found shape {obj.shape}")
    if shape is not None and obj.shape != shape:
        raise _Damaged(f"/{path}: expected shape {shape}, found {obj.shape}")
    if numeric and obj.dtype.kind not in "iuf":
        raise _Damaged(f"/{path}: expected numbers, found data of type {obj.dtype}")
    if obj.size * max(obj.dtype.itemsize, 1) > MAX_DATASET_BYTES:
        raise _Damaged(f"/{path}: declares {obj.size:.3g} values ({obj.size * obj.dtype.itemsize / 2**30:.1f} GiB), "
                       f"more than any results file holds")
    data = obj[()]
    if numeric and data.dtype.kind == "f" and not (np.isfinite(data) | (allow_nan & np.isnan(data))).all():
        raise _Damaged(f"/{path}: holds non-finite values (NaN or infinity)")
    return data


def _group(f, path: str):
    obj = f.get(path)
    if obj is None:
        raise _Damaged(f"/{path}: missing")
    if not isinstance(obj, h5py.Group):
        raise _Damaged(f"/{path}: expected a group, found a {type(obj).__name__.lower()}")
    return obj


def read_results(path: str | Path, for_resume: bool = False, every_seal: bool = True) -> Results:
    """Read a results file, verifying it; raises ``ValueError`` naming the file and what is wrong.

    ``for_resume`` also requires a complete, intact checkpoint that fits the grid.  ``every_seal`` False trusts the
    whole-file checksum where the file has one (every byte as written) and skips the per-object seals of the
    datasets: a sweep deciding which of its points stand reads every file, and the seals were most of that.  The
    attributes of the root and of /summary (the status and the figures a sweep's table takes) are still checked
    against theirs (a few ms): a file edited and its whole-file checksum written again, which every other reader
    refuses, must not give the table its numbers.
    """
    _regular_file(path)
    try:
        whole = verify_image(path)  # before HDF5 reads a byte: it can loop for ever on some damaged files
        with h5py.File(path, "r") as f:
            return _read(f, str(path), for_resume, seals=every_seal or not whole)
    except _Damaged as exc:
        raise ResultsFileError(f"{path}: damaged or not a fretsim results file: {exc}") from None
    except (OSError, RuntimeError, KeyError, TypeError, IndexError, AttributeError, UnicodeDecodeError) as exc:
        raise ResultsFileError(f"{path}: not a readable fretsim results file ({type(exc).__name__}: "
                         f"{str(exc)[:200]})") from None


def _read(f, path: str, for_resume: bool, seals: bool = True) -> Results:
    version, attrs, case_yaml = _read_head(f, path, seals)
    x = _dataset(f, "grid/x", 1)
    y = _dataset(f, "grid/y", 1)
    if not (x.size and y.size) or (x.size > 1 and not (np.diff(x) > 0).all()) or (y.size > 1 and not (np.diff(y) > 0).all()):
        raise _Damaged("/grid: x and y must be increasing element centres")
    ny, nx = y.size, x.size
    units: dict = {}
    history = _read_history(f, version, units)
    fields = _read_fields(f, version, (ny, nx), units)
    loop = _read_loop(f, version, fields["cycle"], units)
    subsurface = _read_subsurface(f, fields["cycle"].size, (ny, nx), units) if "z" in f["fields"] else {}
    summary = _read_summary(f)
    checkpoint = _read_checkpoint(f, (ny, nx)) if "checkpoint" in f else None
    if for_resume and version != FORMAT_VERSION:
        raise _Damaged(f"written in format {version}; this fretsim resumes format {FORMAT_VERSION} only (its steps "
                       f"would lack what this version records): run the case again, or resume it with the version "
                       f"that wrote it ({attrs.get('fretsim_version', '?')})")
    if for_resume and checkpoint is None:
        raise _Damaged("/checkpoint: missing; the run cannot be resumed (it was written before its first step)")
    choices, provenance = [], []
    if "choices" in f:
        _group(f, "choices")
        cols = [[text(v) for v in _dataset(f, f"choices/{k}", 1, numeric=False)] for k in ("key", "value", "reason")]
        choices = list(zip(*cols))
        n = len(choices)
        given = (_dataset(f, "choices/given", 1).astype(bool).tolist() if "given" in f["choices"] else [None] * n)
        # absent (written before it was recorded): unknown, not 0, so a resume does not drop auto's model part
        error = (_dataset(f, "choices/error", 1, allow_nan=True).astype(float).tolist() if "error" in f["choices"]
                 else [None] * n)
        if len(given) != n or len(error) != n:
            raise _Damaged(f"/choices: {n} keys but {len(given)} given flags and {len(error)} errors")
        provenance = [(*c, g, e) for c, g, e in zip(choices, given, error)]
    inputs, overrides = _read_inputs(f)
    regrids = _read_regrids(f, (nx, ny)) if "regrids" in f else []
    coarsenings = _read_coarsenings(f, nx) if "coarsenings" in f else []
    return Results(path=path, attrs=attrs, case_yaml=case_yaml, x=x, y=y, history=history, fields=fields,
                   summary=summary, units=units, checkpoint=checkpoint, fretting_loop=loop, choices=choices,
                   provenance=provenance,
                   inputs=inputs, overrides=overrides, regrids=regrids, subsurface=subsurface,
                   coarsenings=coarsenings)


# what each format added that a file of an older one cannot hold: (test, its description)
_FORMAT_MARKS = {
    "1.5": (lambda f: isinstance(f.get("history"), h5py.Group) and "cumulative_dissipated_energy_J" in f["history"],
            "/history/cumulative_dissipated_energy_J"),
    "1.4": (lambda f: isinstance(f.get("history"), h5py.Group) and "block" in f["history"], "/history/block"),
    "1.3": (lambda f: "fretting_loop" in f or _any_checksum(f), "/fretting_loop or the checksums of every object"),
    "1.2": (lambda f: "inputs" in f, "/inputs"),  # /choices is older: 1.1 wrote it
}


def _any_checksum(f) -> bool:
    """Whether any object of the file carries the seal of format 1.3 on (1.2 had checksums on /case and
    /checkpoint only)."""
    if "attrs_sha256" in f.attrs:
        return True
    found = []
    f.visititems(lambda name, obj: found.append(name) if "attrs_sha256" in obj.attrs or (
        "sha256" in obj.attrs and name.split("/")[0] not in ("case", "checkpoint")) else None)
    return bool(found)


def _format_held(f) -> str:
    """The newest format whose additions the file holds ("1.1" for none)."""
    return next((v for v, (holds, _) in _FORMAT_MARKS.items() if holds(f)), "1.1")


def _read_head(f, path: str, seals: bool = True) -> tuple[str, dict, str]:
    """The format version (its checksums verified), the root's attributes and the case's text."""
    if "format_version" not in f.attrs:
        raise ResultsFileError(f"{path} is an HDF5 file but not a fretsim results file (no format_version)")
    version = text(f.attrs["format_version"])
    if version not in READABLE_FORMATS:
        raise _Damaged(f"format_version {version!r} is not one this fretsim reads ({', '.join(READABLE_FORMATS)})")
    held = _format_held(f)
    if held > version:
        raise _Damaged(f"format_version {version!r} is older than what the file holds (format {held}: "
                       f"{_FORMAT_MARKS[held][1]}): its version was changed since it was written")
    if version >= SEALED_FROM or held >= SEALED_FROM:  # never a version that lets them go unread
        if seals:
            _verify_seal(f)
        else:  # the whole file's bytes are as written: what the caller reports (status, summary) as sealed too,
            #    so that a file edited and its whole-file checksum written again is refused as every reader does
            _verify_attrs_seal(f, ("", "summary") if "summary" in f else ("",))
    attrs = {k: plain(v) for k, v in f.attrs.items() if k not in _SCALE_ATTRS}
    if attrs.get("status") not in STATUSES:
        raise _Damaged(f"the status {str(attrs.get('status'))[:40]!r} is not one of {', '.join(STATUSES)}")
    case_ds = f.get("case")
    if not isinstance(case_ds, h5py.Dataset) or case_ds.dtype.kind not in "OS" or case_ds.shape != ():
        raise _Damaged("/case: missing or not a text")
    case_yaml = text(case_ds[()])
    if "sha256" in case_ds.attrs and hashlib.sha256(case_yaml.encode()).hexdigest() != text(case_ds.attrs["sha256"]):
        raise _Damaged("/case: its text does not match its checksum")
    return version, attrs, case_yaml


def _read_history(f, version: str, units: dict) -> dict:
    hist_group = _group(f, "history")
    expected = {"1.1": HISTORY_V11, "1.2": HISTORY_V12, "1.3": HISTORY_V13, "1.4": HISTORY_V14}.get(version, HISTORY)
    history = {}
    for k in expected:
        history[k] = _dataset(f, f"history/{k}", 1, allow_nan=k in NAN_HISTORY)
        units[f"history/{k}"] = text(hist_group[k].attrs.get("units", ""))
    lengths = {v.shape[0] for v in history.values()}
    if len(lengths) > 1:
        raise _Damaged(f"/history: its entries have different lengths {sorted(lengths)}")
    return history


def _read_fields(f, version: str, shape: tuple, units: dict) -> dict:
    fl = _group(f, "fields")
    cycles = _dataset(f, "fields/cycle", 1)
    units["fields/cycle"] = "cycles"
    fields = {"cycle": cycles}
    for k in (FIELDS if version >= "1.3" else FIELDS_V12):
        fields[k] = _dataset(f, f"fields/{k}", 3, shape=(cycles.size,) + shape, allow_nan=k in NAN_FIELDS)
        units[f"fields/{k}"] = text(fl[k].attrs.get("units", ""))
    return fields


def _read_subsurface(f, snapshots: int, grid: tuple, units: dict) -> dict:
    """Fretting fatigue's depths and fields below each body with constants (cycle, z, x; the moving body's named
    ``…_moving``), over (cycle, z, y, x) on a 3D grid; NaN where a state had none evaluated."""
    ny, nx = grid
    z = _dataset(f, "fields/z", 1)
    if not z.size or not (z > 0).all() or (z.size > 1 and not (np.diff(z) > 0).all()):
        raise _Damaged("/fields/z: the depths must be positive and increasing")
    out = {"z": z}
    units["fields/z"] = "mm"
    across = () if ny == 1 else (ny,)
    for k in SUBSURFACE_TABLES:
        if k in f["fields"]:
            out[k] = _dataset(f, f"fields/{k}", 3 + len(across), shape=(snapshots, z.size, *across, nx),
                              allow_nan=True)
            units[f"fields/{k}"] = text(f["fields"][k].attrs.get("units", ""))
    return out


def _read_loop(f, version: str, cycles: np.ndarray, units: dict) -> dict:
    loop = {"cycle": cycles, "displacement": np.zeros((cycles.size, 0)), "tangential_force": np.zeros((cycles.size, 0))}
    if version >= "1.3":
        loop["cycle"] = _dataset(f, "fretting_loop/cycle", 1, shape=(cycles.size,))
        if not np.array_equal(loop["cycle"], cycles):
            raise _Damaged("/fretting_loop/cycle: not the snapshot cycles of /fields")
        for k in ("displacement", "tangential_force"):
            loop[k] = _dataset(f, f"fretting_loop/{k}", 2, allow_nan=True)
            if loop[k].shape[0] != cycles.size or loop[k].shape != loop["displacement"].shape:
                raise _Damaged(f"/fretting_loop/{k}: shape {loop[k].shape} does not fit the snapshots")
            units[f"fretting_loop/{k}"] = text(f[f"fretting_loop/{k}"].attrs.get("units", ""))
    return loop


def _read_summary(f) -> dict:
    summary = {}
    for k, v in _group(f, "summary").attrs.items():
        k = _name(k, "/summary")
        if k == "units" or k in _SCALE_ATTRS:
            continue
        v = plain(v)
        if isinstance(v, (list, tuple, np.ndarray)) or not isinstance(v, (int, float, str, type(None))):
            raise _Damaged(f"/summary: {k} is not a single value")
        if isinstance(v, float) and not math.isfinite(v) and k not in NAN_SUMMARY:
            raise _Damaged(f"/summary: {k} is not finite")
        summary[k] = v
    return in_summary_order(summary)  # (HDF5 gives the attributes sorted by name)


def _read_inputs(f) -> tuple[dict, list]:
    inputs, overrides = {}, []
    if "inputs" in f:
        g = _group(f, "inputs")
        for k, ds in g.items():
            k = _name(k, "/inputs")
            if isinstance(ds, h5py.Dataset) and ds.shape == ():
                value = ds[()]
                inputs[k] = (text(value) if isinstance(value, bytes) else plain(value), text(ds.attrs.get("units", "")))
        try:
            overrides = [str(o) for o in json.loads(text(g.attrs.get("overrides", "[]")))]
        except (ValueError, TypeError):
            raise _Damaged("/inputs: its overrides attribute is not a JSON list") from None
    return inputs, overrides


def _read_coarsenings(f, nx: int) -> list:
    """/coarsenings as :class:`fretsim.regrid.Coarsening` records: factors growing by 3, the last dividing the grid."""
    from fretsim.regrid import COARSEN, Coarsening
    _group(f, "coarsenings")
    cycles = _dataset(f, "coarsenings/cycle", 1)
    n = cycles.size
    factors = _dataset(f, "coarsenings/factor", 1, shape=(n,))
    elements = _dataset(f, "coarsenings/elements_x", 1, shape=(n,))
    reasons = [text(v) for v in _dataset(f, "coarsenings/reason", 1, numeric=False, shape=(n,))]
    out = [Coarsening(int(cycles[i]), int(factors[i]), (int(elements[i]), 1), reasons[i]) for i in range(n)]
    if [c.factor for c in out] != [COARSEN ** (i + 1) for i in range(n)]:
        raise _Damaged(f"/coarsenings: factors {[c.factor for c in out]}, expected powers of {COARSEN}")
    if out and nx % out[-1].factor:  # (a widening after it adds whole run elements: the count may have grown)
        raise _Damaged(f"/coarsenings: elements of {out[-1].factor} do not tile the grid's {nx}")
    return out


def _read_regrids(f, elements: tuple) -> list:
    """/regrids as :class:`fretsim.regrid.Regrid` records; the last must end on the file's grid."""
    from fretsim.regrid import Regrid
    _group(f, "regrids")
    cycles = _dataset(f, "regrids/cycle", 1)
    n = cycles.size
    cols = {k: _dataset(f, f"regrids/{k}", 1, shape=(n,)) for k in
            (f"{w}_{q}_{a}" for w in ("old", "new") for q in ("elements", "domain") for a in "xy")}
    reasons = [text(v) for v in _dataset(f, "regrids/reason", 1, numeric=False, shape=(n,))]
    out = [Regrid(int(cycles[i]), (int(cols["old_elements_x"][i]), int(cols["old_elements_y"][i])),
                  (int(cols["new_elements_x"][i]), int(cols["new_elements_y"][i])),
                  (float(cols["old_domain_x"][i]), float(cols["old_domain_y"][i])),
                  (float(cols["new_domain_x"][i]), float(cols["new_domain_y"][i])), reasons[i]) for i in range(n)]
    if out and out[-1].new_elements != elements:
        raise _Damaged(f"/regrids: the last widening ends on {out[-1].new_elements} elements, the grid has {elements}")
    return out


def _read_checkpoint(f, shape: tuple) -> dict:
    c = _group(f, "checkpoint")
    state: dict = {}
    for k, ds in c.items():
        k = _name(k, "/checkpoint")
        if not isinstance(ds, h5py.Dataset):
            raise _Damaged(f"/checkpoint/{k}: expected a dataset")
        data = _dataset(f, f"checkpoint/{k}")
        if k in ("h_m", "h_s", "p", "p_prev") and data.shape != shape:
            raise _Damaged(f"/checkpoint/{k}: shape {data.shape} does not fit the grid {shape}")
        if k in ("history", "batch") and (data.ndim != 3 or data.shape[1:] != shape):
            raise _Damaged(f"/checkpoint/{k}: shape {data.shape} does not fit the grid {shape}")
        state[k] = data
    digest = None
    for k, v in c.attrs.items():
        k = _name(k, "/checkpoint")
        if k == "sha256":
            digest = text(v)
        elif k.endswith("_empty"):
            state[k[:-6]] = []
        else:
            v = plain(v)
            if isinstance(v, float) and not math.isfinite(v):
                raise _Damaged(f"/checkpoint: {k} is not finite")
            state[k] = v
    for k in ("history", "batch"):
        if isinstance(state.get(k), np.ndarray):
            state[k] = list(state[k])
    if digest is not None:
        if checkpoint_digest(state) != digest:
            raise _Damaged("/checkpoint: its contents do not match its checksum")
    for key in ("n", "h_m", "h_s", "p"):
        if key not in state:
            raise _Damaged(f"/checkpoint/{key}: missing")
    return state


def summary_json(res: Results) -> dict:
    """The summary, the inputs and the overrides as strict JSON-able values (NaN and infinity as null)."""
    def clean(v):
        if isinstance(v, float) and not math.isfinite(v):
            return None
        return v
    data = {"status": res.status, "case_name": res.attrs.get("case_name"), "path": res.path}
    data.update({k: clean(v) for k, v in res.summary.items()})
    data["inputs"] = {k: clean(v[0]) for k, v in res.inputs.items()}
    data["input_units"] = {k: v[1] for k, v in res.inputs.items()}
    data["overrides"] = list(res.overrides)
    return data


