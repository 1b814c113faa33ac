"""The results file's writer: an observer of the loop that keeps the run in memory and the file complete on disk.

At every flush it builds the whole file as an in-memory HDF5 image, writes it with plain file I/O to a temporary
file beside the target, fsyncs it and renames it over the target (atomic on POSIX), so a full disk or an I/O
error is an ordinary OSError at a known point and the last good file stays intact.
"""
from __future__ import annotations

import errno
import io
import json
import math
import os
import time
from pathlib import Path
from typing import Optional

import h5py
import numpy as np

from fretsim import __version__
from fretsim.results.layout import FIELDS, FORMAT_VERSION, SUBSURFACE_3D, SUBSURFACE_BODIES, SUBSURFACE_TABLES, HISTORY, INTEGER_HISTORY, SUMMARY_UNITS, summary_long_name
from fretsim.results.seal import USERBLOCK, _SealingWriter, checkpoint_digest, seal_image
from fretsim.results.reader import Results

FLUSH_SECONDS = 0.5
FLUSH_COST_FACTOR = 20.0  # flushes no more often than this many times their own cost (≤ ~5 % of the run)


class ResultsIOError(OSError):
    """Writing the results failed (disk full, I/O error, directory gone); the last good file is intact."""



class ResultsWriter:
    """Observer that records each accepted step and keeps the results file complete on disk.

    ``previous`` (a :class:`Results` read back from an interrupted run) seeds the history and fields, so a
    resumed run appends to what was there.  ``replace`` allows replacing an existing file (overwrite, resume).
    """

    def __init__(self, path: str | Path, case_yaml: str, case_name: str, grid, notes=(), overwrite: bool = False,
                 previous: Optional["Results"] = None, choices=(), inputs: Optional[dict] = None,
                 input_sha256: str = "", regrids=(), coarsenings=()):
        self.path = Path(path)
        self.replace = overwrite or previous is not None
        if self.path.exists() and not self.replace:
            raise FileExistsError(f"{self.path} exists")
        self.case_yaml, self.case_name, self.grid, self.notes = case_yaml, case_name, grid, tuple(notes)
        # what the case asked for before the plan filled it (Case.fingerprint); a resumed run keeps its original
        self.input_sha256 = str(previous.attrs.get("input_sha256", "")) if previous is not None else input_sha256
        self.choices = tuple(choices)
        self.inputs = inputs or {}
        if previous is not None:
            self.rows = [list(r) for r in zip(*(previous.history.get(k, np.zeros(len(previous.history["cycle"])))
                                                for k in HISTORY))] if len(previous.history.get("cycle", [])) else []
            self.fields = {k: list(previous.fields[k]) for k in FIELDS}
            self.field_cycles = list(previous.fields["cycle"])
            self.loops = [tuple(pair) for pair in zip(previous.fretting_loop["displacement"],
                                                      previous.fretting_loop["tangential_force"])]
        else:
            self.rows, self.fields, self.field_cycles = [], {k: [] for k in FIELDS}, []
            self.loops = []  # (applied displacement um, tangential force N) at each snapshot
        self.regrids = list(regrids)  # the automatic grid's widenings (fretsim.regrid.Regrid)
        # ... and its coarsenings (fretsim.regrid.Coarsening): the run's element is ``factor`` output elements
        self.coarsenings = list(coarsenings)
        # fretting fatigue's fields below the flat at each snapshot, each (layers, y, x), and the layers' depths
        self.depths = previous.subsurface.get("z") if previous is not None else None
        self.subsurface = ({k: [a if a.ndim == 3 else a[:, None, :] for a in v]
                            for k, v in previous.subsurface.items() if k != "z"} if previous is not None else {})
        self.status, self.message, self.summary = "running", "", {}
        self.state: Optional[dict] = None
        self._flushed = -math.inf
        self._started: Optional[float] = None
        self._flush_cost = 0.0  # seconds the last flush took
        self._placed = self.path.exists() and self.replace

    def on_step(self, setup, step) -> None:
        self.rows.append([get(step) for _, _, get in HISTORY.values()])
        if step.is_snapshot and (not self.field_cycles or self.field_cycles[-1] != step.cycle):
            self.field_cycles.append(step.cycle)
            for name, (_, _, get) in FIELDS.items():
                self.fields[name].append(self._on_output(np.array(get(step))))
            if setup.fatigue_specs:
                _add_subsurface(self, setup, step)
            loop = step.cycle_result.loop
            self.loops.append((loop[0] * 1e3, loop[1]) if loop is not None else (np.zeros(0), np.zeros(0)))
        self.state = step.state
        # at most every FLUSH_SECONDS, the first FLUSH_SECONDS into the run: each flush rewrites the whole file,
        # a kill costs at most the steps since the last one (which --resume recomputes), and a run shorter than
        # that writes its file once, at the end
        now = time.monotonic()
        if self._started is None:
            self._started = self._flushed = now
        # a flush rebuilds the whole file (tens of ms): never let flushing take more than ~5 % of a long run
        if now - self._flushed > max(FLUSH_SECONDS, FLUSH_COST_FACTOR * self._flush_cost):
            self.flush()

    @property
    def factor(self) -> int:
        """The run's element along x in output elements (1 until the grid coarsens)."""
        return self.coarsenings[-1].factor if self.coarsenings else 1

    def _on_output(self, value):
        """An array (or a list of them, or a state) on the run's grid written on the output grid: each coarse value
        repeated over its output elements (:mod:`fretsim.regrid`)."""
        from fretsim.regrid import prolong
        f = self.factor
        shape = (self.grid.shape[0], self.grid.shape[1] // f)
        if isinstance(value, dict):
            return {k: prolong(v, shape, f) for k, v in value.items()}
        return prolong(value, shape, f)

    def coarsen(self, c) -> None:
        """The run goes on on a grid coarsened by :mod:`fretsim.regrid` (``c``): its next states are prolonged."""
        self.coarsenings.append(c)

    def regrid(self, r, grid, case_yaml: str, choices, notes) -> None:
        """The run moved onto a widened grid (:mod:`fretsim.regrid`): the snapshots so far are padded onto it (the
        new elements were unworn and unloaded), the case and choices are the ones it now runs (a resume plans this
        grid), and the widening is recorded."""
        from fretsim.regrid import pad  # (the results package does not depend on the loop's modules otherwise)
        self.fields = {k: [pad(a, r) for a in v] for k, v in self.fields.items()}
        self.subsurface = {k: [pad(a, r) for a in v] for k, v in self.subsurface.items()}
        self.grid, self.case_yaml, self.choices, self.notes = grid, case_yaml, tuple(choices), tuple(notes)
        self.regrids.append(r)

    def finish(self, status: str, message: str = "", summary: Optional[dict] = None) -> None:
        self.status, self.message = status, message
        self.summary = summary or {}
        self.flush()

    def image(self) -> bytes:
        """The whole results file as bytes (an in-memory HDF5 image)."""
        buf = io.BytesIO()
        with h5py.File(buf, "w", userblock_size=USERBLOCK) as f:
            self._write(f)
        return seal_image(buf.getvalue())

    def flush(self) -> None:
        """Write the whole file beside the target and move it over the target (atomic); ResultsIOError if the
        disk refuses, with the last good file left as it was and no temporary left behind."""
        started = time.monotonic()
        data = self.image()
        tmp = self.path.with_name(f".fretsim-{os.getpid()}-{os.urandom(4).hex()}.tmp")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
            try:
                view = memoryview(data)
                while view:
                    view = view[os.write(fd, view):]
                os.fsync(fd)
            finally:
                os.close(fd)
            if self._placed:
                os.replace(tmp, self.path)
            else:
                try:
                    os.link(tmp, self.path)  # fails if the name appeared meanwhile: never clobber
                except FileExistsError:
                    if not self.replace:
                        raise ResultsIOError(errno.EEXIST, f"{self.path} appeared while this run started; nothing "
                                                           f"of it was replaced") from None
                    os.replace(tmp, self.path)
                self._placed = True
            _fsync_dir(self.path.parent)
        except ResultsIOError:
            raise
        except OSError as exc:
            what = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is exceeded",
                    errno.EIO: "an I/O error", errno.ENOENT: "its directory has gone",
                    errno.EROFS: "the file system is read-only", errno.EACCES: "permission denied"}.get(
                exc.errno, exc.strerror or str(exc))
            raise ResultsIOError(exc.errno, f"cannot write {self.path}: {what}") from None
        finally:
            try:
                tmp.unlink()
            except OSError:
                pass
        self._flushed = time.monotonic()
        self._flush_cost = self._flushed - started

    def _write(self, f: h5py.File) -> None:
        grid = self.grid
        text = h5py.string_dtype()
        w = _SealingWriter(f)
        w.attrs(f, format_version=FORMAT_VERSION, fretsim_version=__version__, status=self.status,
                status_message=self.message, case_name=self.case_name, notes="\n".join(self.notes),
                input_sha256=self.input_sha256)
        w.dataset(f, "case", self.case_yaml, text,
                  long_name="the validated case with every default and automatic choice filled (YAML)")
        self._write_inputs(w, f)
        ch = w.group(f, "choices")
        w.dataset(ch, "key", [c.key for c in self.choices], text)
        w.dataset(ch, "value", [_valuetext(c.value) for c in self.choices], text)
        w.dataset(ch, "reason", [c.reason for c in self.choices], text)
        w.dataset(ch, "given", np.array([c.given for c in self.choices], dtype=np.int8))
        # the model difference auto accepted with each choice (part of the reported error estimates): a resumed
        # run, which plans again from the filled case where every choice reads as given, takes it from here
        w.dataset(ch, "error", np.array([c.error for c in self.choices], dtype=np.float64))
        g = w.group(f, "grid")
        for name, values in (("x", grid.x), ("y", grid.y)):
            w.dataset(g, name, values, units="mm",
                      long_name=f"element centre, {'sliding direction' if name == 'x' else 'across it'}")
        w.attrs(g, dx_mm=grid.dx, dy_mm=grid.dy, plane_strain=np.int8(grid.plane_strain))
        h = w.group(f, "history")
        n = len(self.rows)
        rows = np.array(self.rows, dtype=float).reshape(n, len(HISTORY))
        step = w.dataset(h, "step", np.arange(n, dtype="i8"), units="1", long_name="accepted step")
        step.make_scale("step")
        for j, (name, (units, long_name, _)) in enumerate(HISTORY.items()):
            data = rows[:, j].astype("i8") if name in INTEGER_HISTORY else rows[:, j]
            extra = {} if name == "cycle" else {"coordinates": "cycle"}
            ds = w.dataset(h, name, data, units=units, long_name=long_name, **extra)
            ds.dims[0].attach_scale(step)
        fl = w.group(f, "fields")
        ny, nx = grid.shape
        cyc = w.dataset(fl, "cycle", np.array(self.field_cycles, dtype="i8"), units="cycles",
                        long_name="cycle number of the snapshot")
        cyc.make_scale("cycle")
        scales = [cyc]
        for name, values in (("y", grid.y), ("x", grid.x)):
            ds = w.dataset(fl, name, values, units="mm",
                           long_name=f"element centre, {'sliding direction' if name == 'x' else 'across it'}")
            ds.make_scale(name)
            scales.append(ds)
        for name, (units, long_name, _) in FIELDS.items():
            data = np.array(self.fields[name]).reshape(len(self.fields[name]), ny, nx)
            ds = w.dataset(fl, name, data, units=units, long_name=long_name)
            for axis, scale in enumerate(scales):
                ds.dims[axis].attach_scale(scale)
        if self.subsurface:
            _write_subsurface(self, w, fl, scales)
        self._write_loops(w, f)
        if self.regrids:
            _write_regrids(self, w, f)
        s = w.group(f, "summary")
        for key, value in self.summary.items():
            w.dataset(s, key, value, units=SUMMARY_UNITS.get(key, "1"), long_name=summary_long_name(key))
        w.attrs(s, **self.summary)
        if self.summary:
            w.attrs(s, units=", ".join(f"{k}: {SUMMARY_UNITS.get(k, '1')}" for k in self.summary))
        if self.coarsenings:
            _write_coarsenings(self, w, f)
        if self.state is not None:  # not sealed: it carries its own digest (but the root names it)
            c = w.unsealed_group(f, "checkpoint")
            state = self._on_output(self.state)  # on the output grid: a resume takes each coarse element's middle
            for key, value in state.items():
                if isinstance(value, np.ndarray):
                    c.create_dataset(key, data=value)
                elif isinstance(value, list):  # a list of arrays (the schemes' memory)
                    c.create_dataset(key, data=np.array(value)) if value else c.attrs.__setitem__(key + "_empty", 1)
                elif value is not None:
                    c.attrs[key] = value
            c.attrs["sha256"] = checkpoint_digest(state)
        w.seal()

    def _write_loops(self, w: "_SealingWriter", f: h5py.File) -> None:
        lp = w.group(f, "fretting_loop")
        w.attrs(lp, long_name="the fretting loop at each snapshot: the rig's displacement and the tangential "
                              "force round one cycle (−δ → +δ → −δ); no points for uniform slip")
        lcyc = w.dataset(lp, "cycle", np.array(self.field_cycles, dtype="i8"), units="cycles",
                         long_name="cycle number of the snapshot")
        lcyc.make_scale("cycle")
        points = max((len(u) for u, _ in self.loops), default=0)
        for name, k, units, long_name in (("displacement", 0, "um", "the rig's tangential displacement"),
                                          ("tangential_force", 1, "N", "the tangential force Q (total)")):
            data = np.full((len(self.loops), points), np.nan)
            for i, pair in enumerate(self.loops):
                data[i, :len(pair[k])] = pair[k]
            ds = w.dataset(lp, name, data, units=units, long_name=long_name)
            ds.dims[0].attach_scale(lcyc)

    def _write_inputs(self, w: "_SealingWriter", f: h5py.File) -> None:
        g = w.group(f, "inputs")
        for key, (value, units, long_name) in self.inputs.get("values", {}).items():
            w.dataset(g, key, value, h5py.string_dtype() if isinstance(value, str) else None, units=units,
                      long_name=long_name)
        w.attrs(g, overrides=json.dumps(list(self.inputs.get("overrides", []))),
                case_file=str(self.inputs.get("case_file", "")))


def _add_subsurface(writer: "ResultsWriter", setup, step) -> None:
    """Each body's fields below its surface at a snapshot (NaN where the state had no fatigue evaluated)."""
    writer.depths = setup.fatigue_specs[0].depths  # (the bodies share them)
    for spec in setup.fatigue_specs:
        swt, stresses, attribute = SUBSURFACE_BODIES[spec.body]
        state = getattr(step, attribute)
        across = SUBSURFACE_3D if setup.grid.shape[0] > 1 and spec.body == "stationary" else {}  # (3D: the flat)
        for name, (_, _, get) in {**swt, **across, **(stresses if spec.keep_stresses else {})}.items():
            shape = (len(writer.depths),) + setup.grid.shape
            value = np.asarray(get(state)) if state is not None else np.full(shape, np.nan)
            writer.subsurface.setdefault(name, []).append(value.reshape(shape))


def _write_subsurface(writer: "ResultsWriter", w: "_SealingWriter", fl, scales: list) -> None:
    """/fields/z and the fatigue fields over (cycle, z, x): a line contact's y (one row) dropped; over (cycle, z, y,
    x) in 3D."""
    z = w.dataset(fl, "z", np.asarray(writer.depths, dtype=float), units="mm",
                  long_name="depth below the stationary body's surface" if "swt" in writer.subsurface else
                  "depth below the moving body's surface")
    z.make_scale("z")
    for name, values in writer.subsurface.items():
        units, long_name, _ = SUBSURFACE_TABLES[name]
        data = np.array(values, dtype=float)
        rows = data.shape[2]
        data = data.reshape(len(values), len(writer.depths), -1) if rows == 1 else data
        ds = w.dataset(fl, name, data, units=units, long_name=long_name)
        for axis, scale in enumerate((scales[0], z, scales[-1]) if rows == 1 else (scales[0], z, *scales[1:])):
            ds.dims[axis].attach_scale(scale)



def _write_regrids(writer: "ResultsWriter", w: "_SealingWriter", f: h5py.File) -> None:
    g = w.group(f, "regrids")
    w.attrs(g, long_name="each widening of the automatic grid: the earlier snapshots are padded onto the last "
                         "grid with zeros (the new elements were unworn and unloaded)")
    rs = writer.regrids
    w.dataset(g, "cycle", np.array([r.cycle for r in rs], dtype="i8"), units="cycles",
              long_name="the state the run went back to and continued from on the wider grid")
    for i, axis in enumerate("xy"):
        for when in ("old", "new"):
            w.dataset(g, f"{when}_elements_{axis}", np.array([getattr(r, f"{when}_elements")[i] for r in rs],
                                                             dtype="i8"), units="1",
                      long_name=f"elements along {axis} {'before' if when == 'old' else 'after'}")
            w.dataset(g, f"{when}_domain_{axis}", np.array([getattr(r, f"{when}_domain")[i] for r in rs],
                                                           dtype=float), units="mm",
                      long_name=f"extent along {axis} {'before' if when == 'old' else 'after'}"
                                f"{' (1 in 2D: the plane-strain row)' if axis == 'y' else ''}")
    w.dataset(g, "reason", [r.reason for r in rs], h5py.string_dtype())



def _write_coarsenings(writer: "ResultsWriter", w: "_SealingWriter", f: h5py.File) -> None:
    g = w.group(f, "coarsenings")
    w.attrs(g, long_name="each coarsening of the automatic grid as the contact grew: from its cycle on, the run's "
                         "element along x is `factor` elements of /grid, and the snapshots are written with each of "
                         "its values repeated over them (piecewise constant, the same worn volume)")
    cs = writer.coarsenings
    w.dataset(g, "cycle", np.array([c.cycle for c in cs], dtype="i8"), units="cycles",
              long_name="the accepted state the run coarsened at and went on from")
    w.dataset(g, "factor", np.array([c.factor for c in cs], dtype="i8"), units="1",
              long_name="the run's element along x after it, in elements of /grid")
    w.dataset(g, "elements_x", np.array([c.elements[0] for c in cs], dtype="i8"), units="1",
              long_name="the run's elements along x after it")
    w.dataset(g, "reason", [c.reason for c in cs], h5py.string_dtype())


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory if str(directory) else ".", os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _valuetext(value) -> str:
    if isinstance(value, tuple):
        return "[" + ", ".join(repr(v) for v in value) + "]"
    return str(value)


