"""The HDF5 results file: layout, crash-safe exclusive writer, and a reader that verifies what it reads.

    /                  attrs format_version, fretsim_version, status, status_message, case_name, notes,
                       input_sha256 (the case as asked for, before the plan filled it: Case.fingerprint)
    /case              the validated case with defaults and automatic choices filled (YAML text; attr sha256)
    /inputs            the resolved inputs as scalar datasets with units; attrs overrides (the --set items), case_file
    /choices           every automatic choice: key, value, reason, given (one entry each)
    /grid/x, /grid/y   element centres (mm)
    /history/<name>    one entry per accepted step over the dimension ``step``, ``cycle`` its coordinate
    /fields/<name>     at the snapshot cycles: (cycle, y, x), with ``cycle``, ``y``, ``x`` as dimension scales
    /summary           attrs: the run's headline figures (same names as `fretsim summary`), and the same values
                       as scalar datasets each with its ``units``
    /fretting_loop     at the snapshot cycles: the applied displacement and the tangential force round the loop,
                       (cycle, point); no points for the uniform-slip model, which has no loop
    /checkpoint        the loop's state at the last written step, for `fretsim run --resume` (attr sha256)

Format 1.3 seals the rest too: every dataset carries ``sha256`` of its values, every group (and the root)
``attrs_sha256`` of its attributes and member names; readers refuse a file that differs, naming where.

The layout is a contract (README): names are only ever added.  Every dataset has ``units`` and ``long_name``,
and the dimension scales make ``xarray.open_dataset(path, engine="h5netcdf", group="fields")`` come out
labelled.  Format 1.2 adds /inputs, /choices, the dimension scales, the summary datasets and the checksums to
1.1; format 1.3 adds friction: the slip-distance and shear-traction fields, the dissipated energy and the
invariant's work in the history, /fretting_loop, and the regime in the summary; format 1.4 adds load histories
and wear limits: the block of every step in the history, and the summary's limit_reached, cycles_to_limit and
time_to_limit_h.  1.1, 1.2 and 1.3 files are still read.

Writing.  The writer keeps the run in memory and at every flush builds the whole file as an in-memory HDF5
image, writes it with plain file I/O to a temporary file beside the target, fsyncs it and renames it over the
target (atomic on POSIX).  HDF5 therefore never writes to a disk that can fail: a full disk or an I/O error is
an ordinary OSError at a known point, after which the temporary is removed and the last good file is intact
(:class:`ResultsIOError`).  The first placement uses a hard link, which fails if the name appeared meanwhile,
so a results file is never replaced without overwrite.  Flushes happen at most every FLUSH_SECONDS (the first
FLUSH_SECONDS into the run), or 20 times the last flush's cost if longer, and at the end: a run shorter than
that writes its file once.

Claiming.  A run holds an exclusive ``flock`` on a lock file beside its output for as long as it may write it
(:class:`OutputClaim`), so two runs never share one output, with or without overwrite; the kernel releases the
lock if the process dies, so a killed run leaves no stale claim.

Reading.  :func:`read_results` checks structure, types, shapes against the grid, sizes before allocating,
finiteness and the checksums, and refuses a damaged file with the path of what is wrong.
"""
from __future__ import annotations

import errno
import fcntl
import hashlib
import io
import json
import math
import os
import stat
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import h5py
import numpy as np

from fretsim import __version__
from fretsim.errors import ResultsFileError
from fretsim.quantities import SUMMARY, WEAR

FORMAT_VERSION = "1.4"
READABLE_FORMATS = ("1.1", "1.2", "1.3", "1.4")
FLUSH_SECONDS = 0.5
FLUSH_COST_FACTOR = 20.0  # flushes no more often than this many times their own cost (≤ ~5 % of the run)
STATUSES = ("running", "complete", "interrupted", "failed", "stopped")
MAX_DATASET_BYTES = 2**32  # 4 GiB: no results file of this tool holds a larger array
MAX_NAME = 200  # bytes of the output's base name we accept (temporaries use fixed-length names)

# name: (units, long name, how to get the value from a Step)
HISTORY = {
    "cycle": ("cycles", "cycle number", lambda s: s.cycle),
    **{key: (WEAR[key].unit, WEAR[key].long_name, lambda s, q=WEAR[key]: q.measure(s, None, None) * q.factor)
       for key in ("max_wear_depth_moving", "max_wear_depth_stationary")},
    "max_wear_depth_total": ("um", "maximum total wear depth", lambda s: (s.wear_moving + s.wear_stationary).max() * 1e3),
    **{key: ("mm^3", WEAR[key].long_name, lambda s, q=WEAR[key]: q.measure(s, None, None))
       for key in ("wear_volume_moving", "wear_volume_stationary")},
    "max_pressure": ("MPa", "maximum contact pressure", lambda s: s.pressure.max()),
    "solver_iterations": ("1", "contact solver iterations", lambda s: s.iterations),
    "wall_time": ("s", "wall time since the start of the run", lambda s: s.wall_time),
    "approach": ("um", "rigid-body approach", lambda s: s.approach * 1e3),
    "archard_volume_error": ("1", "relative difference of the wear volume from k·P·4δ·N", lambda s: s.archard_error),
    "checkerboard_amplitude": ("1", "odd-even pressure amplitude relative to the mean", lambda s: abs(s.checkerboard)),
    "cycle_jump": ("cycles", "cycles since the previous step", lambda s: s.jump),
    "rejected_steps": ("1", "steps rejected since the previous accepted one", lambda s: s.rejected),
    "error_estimate_depth": ("1", "the stepping's part of the relative error of the maximum depths (the run's "
                                  "estimate against the exact per-cycle model on its grid)", lambda s: s.error_depth),
    "error_estimate_pressure": ("1", "the stepping's part of the relative error of the pressure field (L2)",
                                lambda s: s.error_pressure),
    "dissipated_energy_J": ("J", "energy dissipated per cycle by friction at this state (NaN: no friction "
                                 "coefficient)", lambda s: s.cycle_result.energy * 1e-3),
    "wear_work": ("N*mm", "the wear invariant's work accumulated: Σp·|ds|·A (Archard) or Σ|q|·|ds|·A (energy "
                          "law) over the cycles; each body's wear volume is its coefficient times it",
                  lambda s: s.work),
    "block": ("1", "the loading's block (from 0, in the order applied) whose cycles led to this state",
              lambda s: s.block),
}
INTEGER_HISTORY = {"cycle", "solver_iterations", "cycle_jump", "rejected_steps", "block"}
HISTORY_V11 = [k for k in HISTORY if not k.startswith("error_estimate") and k not in ("dissipated_energy_J",
                                                                                        "wear_work", "block")]
HISTORY_V12 = [k for k in HISTORY if k not in ("dissipated_energy_J", "wear_work", "block")]
HISTORY_V13 = [k for k in HISTORY if k != "block"]
FIELDS = {
    "wear_depth_moving": ("um", "wear depth of the moving body", lambda s: s.wear_moving * 1e3),
    "wear_depth_stationary": ("um", "wear depth of the stationary body", lambda s: s.wear_stationary * 1e3),
    "pressure": ("MPa", "contact pressure on the moving body at mid-stroke", lambda s: s.pressure),
    "pressure_stationary_average": ("MPa", "stroke-averaged pressure on the stationary body",
                                    lambda s: s.pressure_average),
    "slip_distance_moving": ("um", "slip distance per cycle at each point of the moving body",
                             lambda s: s.cycle_result.slip_moving * 1e3),
    "slip_distance_stationary": ("um", "slip distance per cycle at each point of the stationary body",
                                 lambda s: s.cycle_result.slip_stationary * 1e3),
    "shear_traction": ("MPa", "amplitude of the shear traction on the moving body over the cycle (NaN: not "
                              "modelled)", lambda s: s.cycle_result.shear),
}
FIELDS_V12 = [k for k in FIELDS if not k.startswith(("slip_distance", "shear"))]
NAN_FIELDS = {"shear_traction"}  # the uniform model without a friction coefficient does not know it
SUMMARY_UNITS = {key: figure.unit for key, figure in SUMMARY.items()}
NAN_SUMMARY = {key for key, figure in SUMMARY.items() if figure.nan}


class ResultsIOError(OSError):
    """Writing the results failed (disk full, I/O error, directory gone); the last good file is intact."""


class OutputBusy(Exception):
    """Another live run holds the output."""


def _lock_path(path: Path) -> Path:
    digest = hashlib.sha1(path.name.encode()).hexdigest()[:16]
    return path.with_name(f".fretsim-{digest}.lock")


class OutputClaim:
    """An exclusive claim on an output name, held for the life of a run (flock on a lock file beside it)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.lock = _lock_path(self.path)
        self.fd: Optional[int] = None

    def acquire(self) -> "OutputClaim":
        while True:
            fd = os.open(self.lock, os.O_CREAT | os.O_RDWR, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise OutputBusy(f"{self.path}: another fretsim run is writing this file; wait for it, or "
                                     f"choose another -o") from None
                raise
            # the lock file may have been unlinked by its previous holder after we opened it: then retry
            try:
                if os.fstat(fd).st_ino == os.stat(self.lock).st_ino:
                    self.fd = fd
                    os.ftruncate(fd, 0)
                    os.write(fd, f"{os.getpid()}\n".encode())
                    _clean_stale_locks(self.lock)
                    return self
            except FileNotFoundError:
                pass
            os.close(fd)

    def release(self) -> None:
        if self.fd is None:
            return
        try:
            os.unlink(self.lock)
        except OSError:
            pass
        os.close(self.fd)
        self.fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


def _clean_stale_locks(mine: Path) -> None:
    """Remove the lock files beside ``mine`` that nobody holds (left by a kill -9: the kernel drops the lock, the
    file stays).  One a live run holds cannot be locked here and stays; one a run is just claiming it re-checks
    (the inode test in acquire) and claims again."""
    try:
        names = [p for p in mine.parent.glob(".fretsim-*.lock") if p != mine]
    except OSError:
        return
    for p in names[:100]:
        try:
            fd = os.open(p, os.O_RDWR)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            os.unlink(p)
        except OSError:
            pass
        finally:
            os.close(fd)


def check_output_path(path: str | Path, protect: tuple = ()) -> Path:
    """An output name that can be a results file: not a directory, not one of ``protect`` (the case file), in an
    existing directory, of a sane length.  Raises ValueError with the reason."""
    text = str(path)
    p = Path(path)
    if text in ("", "-"):
        raise ValueError(f"{text!r} is not a file name; results go to an HDF5 file, e.g. -o out.h5")
    if text.endswith(os.sep) or p.is_dir():
        what = "is a directory" if p.is_dir() else "ends in a '/', so it names a directory"
        raise ValueError(f"{text} {what}; give a file name, e.g. -o {os.path.join(text, 'out.h5')}")
    if p.is_symlink():
        # the writer replaces the file by renaming over it, which would replace the link, not write through it
        target = os.readlink(p)
        raise ValueError(f"{text} is a symbolic link (to {target}{'' if p.exists() else ', which does not exist'}); "
                         f"give the file's own name, or a new name")
    if len(p.name.encode()) > MAX_NAME:
        raise ValueError(f"the output name is {len(p.name.encode())} bytes long; at most {MAX_NAME}")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise ValueError(f"the directory {parent} does not exist; create it first")
    for other in protect:
        if other is not None and Path(other).exists() and p.exists() and os.path.samefile(p, other):
            raise ValueError(f"{text} is the case file itself; choose another output name")
        if other is not None and os.path.abspath(p) == os.path.abspath(other):
            raise ValueError(f"{text} is the case file itself; choose another output name")
    if p.exists() and not stat.S_ISREG(os.stat(p).st_mode):
        raise ValueError(f"{text} exists and is not a regular file")
    return p


def _checkpoint_digest(state: dict) -> str:
    h = hashlib.sha256()
    for key in sorted(state):
        value = state[key]
        if value is None:  # not written, so not hashed
            continue
        h.update(key.encode())
        if isinstance(value, list):
            for a in value:
                a = np.ascontiguousarray(a)
                h.update(f"{a.dtype.str}{a.shape}".encode())
                h.update(a.tobytes())
        elif isinstance(value, np.ndarray):
            a = np.ascontiguousarray(value)
            h.update(f"{a.dtype.str}{a.shape}".encode())
            h.update(a.tobytes())
        else:
            h.update(repr(_plain(value)).encode())
    return h.hexdigest()


def _long_name(key: str) -> str:
    return key.replace("_", " ")


class ResultsWriter:
    """Observer that records each accepted step and keeps the results file complete on disk.

    ``previous`` (a :class:`Results` read back from an interrupted run) seeds the history and fields, so a
    resumed run appends to what was there.  ``replace`` allows replacing an existing file (overwrite, resume).
    """

    def __init__(self, path: str | Path, case_yaml: str, case_name: str, grid, notes=(), overwrite: bool = False,
                 previous: Optional["Results"] = None, choices=(), inputs: Optional[dict] = None,
                 input_sha256: str = ""):
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
                self.fields[name].append(np.array(get(step)))
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

    def finish(self, status: str, message: str = "", summary: Optional[dict] = None) -> None:
        self.status, self.message = status, message
        self.summary = summary or {}
        self.flush()

    def image(self) -> bytes:
        """The whole results file as bytes (an in-memory HDF5 image)."""
        buf = io.BytesIO()
        with h5py.File(buf, "w") as f:
            self._write(f)
        return buf.getvalue()

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
        w.dataset(ch, "value", [_value_text(c.value) for c in self.choices], text)
        w.dataset(ch, "reason", [c.reason for c in self.choices], text)
        w.dataset(ch, "given", np.array([c.given for c in self.choices], dtype=np.int8))
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
        s = w.group(f, "summary")
        for key, value in self.summary.items():
            w.dataset(s, key, value, units=SUMMARY_UNITS.get(key, "1"), long_name=_long_name(key))
        w.attrs(s, **self.summary)
        if self.summary:
            w.attrs(s, units=", ".join(f"{k}: {SUMMARY_UNITS.get(k, '1')}" for k in self.summary))
        if self.state is not None:  # not sealed: it carries its own digest (but the root names it)
            c = w.unsealed_group(f, "checkpoint")
            for key, value in self.state.items():
                if isinstance(value, np.ndarray):
                    c.create_dataset(key, data=value)
                elif isinstance(value, list):  # a list of arrays (the schemes' memory)
                    c.create_dataset(key, data=np.array(value)) if value else c.attrs.__setitem__(key + "_empty", 1)
                elif value is not None:
                    c.attrs[key] = value
            c.attrs["sha256"] = _checkpoint_digest(self.state)
        w.seal()

    def _write_inputs(self, w: "_SealingWriter", f: h5py.File) -> None:
        g = w.group(f, "inputs")
        for key, (value, units, long_name) in self.inputs.get("values", {}).items():
            w.dataset(g, key, value, h5py.string_dtype() if isinstance(value, str) else None, units=units,
                      long_name=long_name)
        w.attrs(g, overrides=json.dumps(list(self.inputs.get("overrides", []))),
                case_file=str(self.inputs.get("case_file", "")))


# --- checksums: every dataset and every group's attributes carry a sha256 of what was written ----------------------
SEALED_FROM = "1.3"  # files of this format on carry (and must carry) the checksums
_SCALE_ATTRS = {"DIMENSION_LIST", "REFERENCE_LIST", "CLASS", "NAME", "sha256", "attrs_sha256"}  # HDF5's own, ours


def _value_digest(value) -> str:
    """sha256 of a dataset's value as read back: a text by its UTF-8 bytes (so /case's is the sha256 of its YAML,
    as it always was), an array by its type, shape and bytes."""
    if isinstance(value, bytes):
        return hashlib.sha256(value).hexdigest()
    if isinstance(value, str):
        return hashlib.sha256(value.encode()).hexdigest()
    a = np.asarray(value)
    h = hashlib.sha256(f"{a.dtype.str}{a.shape}".encode())
    if a.dtype.kind == "O":
        for v in a.ravel():
            h.update(v if isinstance(v, bytes) else str(v).encode())
            h.update(b"\0")
    else:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _attrs_digest(obj) -> str:
    """sha256 of an object's attributes and, for a group, of the names it holds (so a deleted or added dataset
    shows)."""
    h = hashlib.sha256()
    if isinstance(obj, h5py.Group):
        h.update(("members:" + "\0".join(sorted(obj.keys())) + "\0").encode())
    for k in sorted(k for k in obj.attrs.keys() if k not in _SCALE_ATTRS):
        v = obj.attrs[k]
        h.update(k.encode() + b"=")
        h.update(v if isinstance(v, bytes) else _value_digest(v).encode() if isinstance(v, np.ndarray) else
                 repr(v).encode())
        h.update(b"\0")
    return h.hexdigest()


def _sealed_objects(f):
    """Every group (the root included) and dataset the readers trust; /checkpoint carries its own digest."""
    out = [("", f)]
    f.visititems(lambda name, obj: None if name == "checkpoint" or name.startswith("checkpoint/") else
                 out.append((name, obj)))
    return out


def _seal(f) -> None:
    for name, obj in _sealed_objects(f):
        if isinstance(obj, h5py.Dataset):
            obj.attrs["sha256"] = _value_digest(obj[()])
        obj.attrs["attrs_sha256"] = _attrs_digest(obj)


def _verify_seal(f) -> None:
    """Refuse a file whose datasets or attributes differ from what was written, naming the first that does."""
    for name, obj in _sealed_objects(f):
        where = f"/{name}"
        if isinstance(obj, h5py.Dataset):
            if "sha256" not in obj.attrs:
                raise _Damaged(f"{where}: its checksum is missing (every dataset of this format carries one)")
            if obj.size * max(obj.dtype.itemsize, 1) > MAX_DATASET_BYTES:
                raise _Damaged(f"{where}: declares {obj.size:.3g} values, more than any results file holds")
            if _value_digest(obj[()]) != _text(obj.attrs["sha256"]):
                raise _Damaged(f"{where}: its values do not match their checksum (changed since it was written)")
        if "attrs_sha256" not in obj.attrs:
            raise _Damaged(f"{where or '/'}: the checksum of its attributes is missing")
        if _attrs_digest(obj) != _text(obj.attrs["attrs_sha256"]):
            raise _Damaged(f"{where or '/'}: its attributes{'' if isinstance(obj, h5py.Dataset) else ' or the names it holds'}"
                           f" do not match their checksum (changed since it was written)")


class _SealingWriter:
    """Creates the sealed groups and datasets of a file and seals them from the values it was given, without
    reading the file back (which cost most of a flush).  Each value is taken in the form HDF5 gives it back (a
    Python float as numpy.float64, a text list as bytes), so the seal is the one :func:`_seal` would compute and
    :func:`_verify_seal` checks; an object created past this writer is left unsealed and the reader refuses it."""

    def __init__(self, f: h5py.File):
        self._objects = {"/": f}
        self._attrs = {"/": {}}
        self._members = {"/": []}
        self._digests = {}

    def group(self, parent, name: str, **attrs):
        g = parent.create_group(name)
        self._enter(parent, g, name)
        self.attrs(g, **attrs)
        return g

    def dataset(self, parent, name: str, data, dtype=None, **attrs):
        ds = _new_dataset(parent, name, data, dtype)
        self._enter(parent, ds, name)
        try:
            self._digests[ds.name] = _given_digest(data, dtype)
        except TypeError:  # a value of another kind: sealed as it reads back
            self._digests[ds.name] = _value_digest(ds[()])
        self.attrs(ds, **attrs)
        return ds

    def attrs(self, obj, **attrs) -> None:
        given = self._attrs[obj.name]
        for key, value in attrs.items():
            if given is not None and key in given or given is None and key in obj.attrs:
                del obj.attrs[key]
            _new_attr(obj, key, value)
            if given is not None:
                try:
                    given[key] = _as_read(value)
                except TypeError:  # a value of another kind: this object's attributes are sealed as they read back
                    self._attrs[obj.name] = given = None

    def unsealed_group(self, parent, name: str):
        self._members[parent.name].append(name)
        return parent.create_group(name)

    def seal(self) -> None:
        for name, obj in self._objects.items():
            if name in self._digests:
                _new_attr(obj, "sha256", self._digests[name])
            given = self._attrs[name]
            _new_attr(obj, "attrs_sha256", _attrs_digest(obj) if given is None else
                      _digest_of_attrs(given, self._members.get(name)))

    def _enter(self, parent, obj, name: str) -> None:
        self._objects[obj.name] = obj
        self._attrs[obj.name] = {}
        self._members[parent.name].append(name)
        if isinstance(obj, h5py.Group):
            self._members[obj.name] = []


_TEXT = h5py.string_dtype()
_HTYPES: dict = {}


def _types(key) -> tuple:
    """The HDF5 file and memory types h5py makes for a numpy dtype (or "text": variable-length UTF-8), made once."""
    if key not in _HTYPES:
        dtype = _TEXT if key == "text" else key
        _HTYPES[key] = (h5py.h5t.py_create(dtype, logical=True), h5py.h5t.py_create(dtype))
    return _HTYPES[key]


def _space(shape: tuple):
    if shape:
        return h5py.h5s.create_simple(shape)
    if "scalar" not in _HTYPES:
        _HTYPES["scalar"] = h5py.h5s.create(h5py.h5s.SCALAR)
    return _HTYPES["scalar"]


def _new_attr(obj, name: str, value) -> None:
    """obj.attrs[name] = value for a name not yet there, by HDF5's own calls: the same attribute h5py writes
    (a text as variable-length UTF-8, a number or numeric array by its numpy type) at a third of the cost."""
    if isinstance(value, str):
        data, key = np.array(value, dtype=_TEXT), "text"
    else:
        data = np.asarray(value)
        key = data.dtype
        if data.dtype.kind not in "biuf":
            obj.attrs[name] = value
            return
    logical, memory = _types(key)
    attr = h5py.h5a.create(obj.id, name.encode(), logical, _space(data.shape))
    try:
        attr.write(data, mtype=memory)
    finally:
        attr.close()


def _new_dataset(parent, name: str, data, dtype=None):
    """parent.create_dataset(name, data=data, dtype=dtype) by HDF5's own calls for the contiguous text and
    numeric datasets of this layout (h5py's general path cost half a flush); anything else goes through h5py."""
    if isinstance(data, str) or (dtype is not None and h5py.check_string_dtype(dtype) is not None):
        array, key = np.array(data, dtype=_TEXT), "text"
    else:
        array = np.asarray(data, dtype=dtype)
        key = array.dtype
        if array.dtype.kind not in "biuf":
            return parent.create_dataset(name, data=data, dtype=dtype)
    logical, memory = _types(key)
    space = _space(array.shape)
    if "dcpl" not in _HTYPES:  # as h5py's: no creation and modification times, so equal runs write equal bytes
        _HTYPES["dcpl"] = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
        _HTYPES["dcpl"].set_obj_track_times(False)
    dset = h5py.h5d.create(parent.id, name.encode(), logical, space, dcpl=_HTYPES["dcpl"])
    if array.size:
        dset.write(h5py.h5s.ALL, h5py.h5s.ALL, np.ascontiguousarray(array), mtype=memory)
    return h5py.Dataset(dset)


def _as_read(value):
    """An attribute's value as h5py reads it back."""
    if isinstance(value, str):
        return str(value)
    if isinstance(value, (bool, np.bool_)):
        return np.bool_(value)
    if isinstance(value, int):
        return np.int64(value)
    if isinstance(value, float):
        return np.float64(value)
    if isinstance(value, np.ndarray):
        return value[()] if value.ndim == 0 else value  # h5py gives a 0-d array back as its scalar
    if isinstance(value, np.number):
        return value
    raise TypeError(f"an attribute of type {type(value).__name__} is not sealed by value")


def _given_digest(data, dtype) -> str:
    """_value_digest of a dataset's value as read back, from the value it was created with."""
    if isinstance(data, str):
        return _value_digest(data)
    if dtype is not None and h5py.check_string_dtype(dtype) is not None:
        return _value_digest(np.array([v.encode() for v in data], dtype=object).reshape(len(data)))
    a = np.asarray(data, dtype=dtype)
    if a.dtype.kind in "OUS":
        raise TypeError("text datasets are written with a string dtype")
    return _value_digest(a)


def _digest_of_attrs(attrs: dict, members: Optional[list]) -> str:
    """_attrs_digest of an object from the attributes given to it (as read back) and, for a group, its members."""
    h = hashlib.sha256()
    if members is not None:
        h.update(("members:" + "\0".join(sorted(members)) + "\0").encode())
    for k in sorted(k for k in attrs if k not in _SCALE_ATTRS):
        v = attrs[k]
        h.update(k.encode() + b"=")
        h.update(v if isinstance(v, bytes) else _value_digest(v).encode() if isinstance(v, np.ndarray) else
                 repr(v).encode())
        h.update(b"\0")
    return h.hexdigest()


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
    fretting_loop: dict = field(default_factory=dict)  # cycle, displacement (um), tangential_force (N)
    choices: list = field(default_factory=list)  # (key, value, reason) of every automatic choice
    inputs: dict = field(default_factory=dict)  # name: (value, units)
    overrides: list = field(default_factory=list)

    @property
    def status(self) -> str:
        return self.attrs.get("status", "")

    def _case_section(self, name: str) -> dict:
        """A top-level mapping of the stored case ({} where absent or not a mapping)."""
        from fretsim.yamlread import YamlProblem, loads
        try:
            section = (loads(self.case_yaml) or {}).get(name) or {}
        except (YamlProblem, AttributeError):
            return {}
        return section if isinstance(section, dict) else {}

    def depth_limits(self) -> dict:
        """The case's wear limits on depths (key → (µm, as written)): what the history figure draws."""
        from fretsim.units import UnitError, parse_quantity
        out = {}
        for key, text in self._case_section("limits").items():
            if "wear_depth" in str(key):
                try:
                    out[key] = (parse_quantity(text, "length") * 1e3, str(text))
                except UnitError:
                    continue
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
        data.update({k: ("step", v, {"units": self.units.get(f"history/{k}", "")})
                     for k, v in self.history.items() if k not in ("cycle", "step")})
        attrs = {"case_name": self.attrs.get("case_name", ""), "status": self.status}
        attrs.update({k: v for k, v in self.summary.items() if isinstance(v, (int, float, str))})
        return xr.Dataset(data, coords=coords, attrs=attrs)


class _Damaged(ResultsFileError):
    pass


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


def _text(value) -> str:
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray) and value.shape == ():
        return _text(value[()])
    return str(value)


def read_results(path: str | Path, for_resume: bool = False) -> Results:
    """Read a results file, verifying it; raises ``ValueError`` naming the file and what is wrong.

    ``for_resume`` also requires a complete, intact checkpoint that fits the grid.
    """
    _regular_file(path)
    try:
        with h5py.File(path, "r") as f:
            return _read(f, str(path), for_resume)
    except _Damaged as exc:
        raise ResultsFileError(f"{path}: damaged or not a fretsim results file: {exc}") from None
    except (OSError, RuntimeError, KeyError, TypeError, IndexError, AttributeError, UnicodeDecodeError) as exc:
        raise ResultsFileError(f"{path}: not a readable fretsim results file ({type(exc).__name__}: "
                         f"{str(exc)[:200]})") from None


def _read(f, path: str, for_resume: bool) -> Results:
    if "format_version" not in f.attrs:
        raise ResultsFileError(f"{path} is an HDF5 file but not a fretsim results file (no format_version)")
    version = _text(f.attrs["format_version"])
    if version not in READABLE_FORMATS:
        raise _Damaged(f"format_version {version!r} is not one this fretsim reads ({', '.join(READABLE_FORMATS)})")
    if version >= SEALED_FROM:
        _verify_seal(f)
    attrs = {k: _plain(v) for k, v in f.attrs.items() if k not in _SCALE_ATTRS}
    if attrs.get("status") not in STATUSES:
        raise _Damaged(f"the status {str(attrs.get('status'))[:40]!r} is not one of {', '.join(STATUSES)}")
    case_ds = f.get("case")
    if not isinstance(case_ds, h5py.Dataset) or case_ds.dtype.kind not in "OS" or case_ds.shape != ():
        raise _Damaged("/case: missing or not a text")
    case_yaml = _text(case_ds[()])
    if "sha256" in case_ds.attrs and hashlib.sha256(case_yaml.encode()).hexdigest() != _text(case_ds.attrs["sha256"]):
        raise _Damaged("/case: its text does not match its checksum")
    x = _dataset(f, "grid/x", 1)
    y = _dataset(f, "grid/y", 1)
    if not (x.size and y.size) or (x.size > 1 and not (np.diff(x) > 0).all()) or (y.size > 1 and not (np.diff(y) > 0).all()):
        raise _Damaged("/grid: x and y must be increasing element centres")
    ny, nx = y.size, x.size
    units: dict = {}
    hist_group = _group(f, "history")
    expected = (HISTORY if version >= "1.4" else HISTORY_V13 if version == "1.3" else HISTORY_V12 if version == "1.2"
                else HISTORY_V11)
    history = {}
    for k in expected:
        history[k] = _dataset(f, f"history/{k}", 1, allow_nan=k == "dissipated_energy_J")
        units[f"history/{k}"] = _text(hist_group[k].attrs.get("units", ""))
    lengths = {v.shape[0] for v in history.values()}
    if len(lengths) > 1:
        raise _Damaged(f"/history: its entries have different lengths {sorted(lengths)}")
    fl = _group(f, "fields")
    cycles = _dataset(f, "fields/cycle", 1)
    units["fields/cycle"] = "cycles"
    fields = {"cycle": cycles}
    for k in (FIELDS if version >= "1.3" else FIELDS_V12):
        fields[k] = _dataset(f, f"fields/{k}", 3, shape=(cycles.size, ny, nx), allow_nan=k in NAN_FIELDS)
        units[f"fields/{k}"] = _text(fl[k].attrs.get("units", ""))
    loop = {"cycle": cycles, "displacement": np.zeros((cycles.size, 0)), "tangential_force": np.zeros((cycles.size, 0))}
    if version >= "1.3":
        loop["cycle"] = _dataset(f, "fretting_loop/cycle", 1, shape=(cycles.size,))
        if not np.array_equal(loop["cycle"], cycles):
            raise _Damaged("/fretting_loop/cycle: not the snapshot cycles of /fields")
        for k in ("displacement", "tangential_force"):
            loop[k] = _dataset(f, f"fretting_loop/{k}", 2, allow_nan=True)
            if loop[k].shape[0] != cycles.size or loop[k].shape != loop["displacement"].shape:
                raise _Damaged(f"/fretting_loop/{k}: shape {loop[k].shape} does not fit the snapshots")
            units[f"fretting_loop/{k}"] = _text(f[f"fretting_loop/{k}"].attrs.get("units", ""))
    summary = {}
    for k, v in _group(f, "summary").attrs.items():
        k = _name(k, "/summary")
        if k == "units" or k in _SCALE_ATTRS:
            continue
        v = _plain(v)
        if isinstance(v, (list, tuple, np.ndarray)) or not isinstance(v, (int, float, str, type(None))):
            raise _Damaged(f"/summary: {k} is not a single value")
        if isinstance(v, float) and not math.isfinite(v) and k not in NAN_SUMMARY:
            raise _Damaged(f"/summary: {k} is not finite")
        summary[k] = v
    checkpoint = _read_checkpoint(f, (ny, nx)) if "checkpoint" in f else None
    if for_resume and version != FORMAT_VERSION:
        raise _Damaged(f"written in format {version}; this fretsim resumes format {FORMAT_VERSION} only (its steps "
                       f"would lack what this version records): run the case again, or resume it with the version "
                       f"that wrote it ({attrs.get('fretsim_version', '?')})")
    if for_resume and checkpoint is None:
        raise _Damaged("/checkpoint: missing; the run cannot be resumed (it was written before its first step)")
    choices = []
    if "choices" in f:
        c = _group(f, "choices")
        cols = [[_text(v) for v in _dataset(f, f"choices/{k}", 1, numeric=False)] for k in ("key", "value", "reason")]
        choices = list(zip(*cols))
        del c
    inputs, overrides = {}, []
    if "inputs" in f:
        g = _group(f, "inputs")
        for k, ds in g.items():
            k = _name(k, "/inputs")
            if isinstance(ds, h5py.Dataset) and ds.shape == ():
                value = ds[()]
                inputs[k] = (_text(value) if isinstance(value, bytes) else _plain(value), _text(ds.attrs.get("units", "")))
        try:
            overrides = [str(o) for o in json.loads(_text(g.attrs.get("overrides", "[]")))]
        except (ValueError, TypeError):
            raise _Damaged("/inputs: its overrides attribute is not a JSON list") from None
    return Results(path=path, attrs=attrs, case_yaml=case_yaml, x=x, y=y, history=history, fields=fields,
                   summary=summary, units=units, checkpoint=checkpoint, fretting_loop=loop, choices=choices,
                   inputs=inputs, overrides=overrides)


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
            digest = _text(v)
        elif k.endswith("_empty"):
            state[k[:-6]] = []
        else:
            v = _plain(v)
            if isinstance(v, float) and not math.isfinite(v):
                raise _Damaged(f"/checkpoint: {k} is not finite")
            state[k] = v
    for k in ("history", "batch"):
        if isinstance(state.get(k), np.ndarray):
            state[k] = list(state[k])
    if digest is not None:
        if _checkpoint_digest(state) != digest:
            raise _Damaged("/checkpoint: its contents do not match its checksum")
    for key in ("n", "h_m", "h_s", "p"):
        if key not in state:
            raise _Damaged(f"/checkpoint/{key}: missing")
    return state


def _plain(v):
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, np.generic):
        v = v.item()
    return v


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
            spec = json.loads(_text(f.attrs["sweep"]))
            axes, units = {}, {}
            for k in spec.get("axes", {}):
                ds = f[k]
                axes[k] = [v.decode() if isinstance(v, bytes) else v for v in ds[()].tolist()]
                units[k] = _text(ds.attrs.get("units", ""))
                bad = [v for v in axes[k] if isinstance(v, float) and not (math.isfinite(v) and abs(v) < 1e30)]
                if bad:
                    raise ValueError(f"table.h5: the axis {k} holds {bad[0]!r}, which no sweep writes (damaged?); "
                                     f"run the sweep again to rewrite its table")
            for k, ds in f.items():
                if isinstance(ds, h5py.Dataset) and k in SUMMARY_UNITS:
                    units[k] = _text(ds.attrs.get("units", ""))
        with open(directory / "table.csv", newline="") as fh:
            rows = list(csv.DictReader(fh))
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise ResultsFileError(f"{directory}: not a sweep's directory with a readable table ({exc})") from None
    mode = spec.get("mode", "product")
    groups = tuple(k for k, v in spec.get("axes", {}).items() if isinstance(v, list)) if mode == "sample" else ()
    return SweepTable(str(directory), axes, units, rows, mode, groups)
