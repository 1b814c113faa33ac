"""Sweeps: one case over many values, in long-lived workers (local or an existing Dask cluster), one table.

A sweep file (YAML, read as strictly as a case):

    base: mccoll_185N.yaml          # a case file (relative to the sweep file), or a case mapping inline
    set: [model.dimension=2d]       # overrides every point shares (optional)
    mode: product                   # product (every combination) | zip (the i-th values together) | points
    axes:                           # dotted case keys, each with a list of values (units as in a case)
      loading.normal_load: [150 N, 185 N, 250 N]
      loading.stroke: [10 um, 25 um]
    points:                         # mode: points — an explicit list, e.g. a design of experiments
      - {jumping.eta: 0.1, jumping.max: 100}

Every point is named from its values (the same values, the same name) and writes the ordinary results file
DIR/points/NAME.h5, whose /inputs record the point's overrides.  DIR/table.csv and DIR/table.h5 hold one row
per point: its swept values, status, message and summary.  table.h5 is readable by xarray (engine
"h5netcdf"): a product sweep's outputs are arrays over its axes, with the axis values as coordinates (numbers
in mm, N, MPa, 1/MPa, with units); other sweeps run over a ``point`` dimension.

Re-running a sweep skips complete points and resumes interrupted ones (their results files say which) — only
those whose file was written for the case the sweep would run now (``Case.fingerprint``); the others run again and
their rows say why.  A point
that fails or is refused is recorded with its status and message and does not stop the others.
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import signal
from dataclasses import dataclass, field
from itertools import product
from pathlib import Path
from typing import Callable, Optional

from fretsim.case import CaseError, parse_case
from fretsim.units import UNITS, UnitError, parse_quantity
from fretsim.yamlread import YamlProblem, excerpt, loads, read_text

MODES = ("product", "zip", "points", "sample")
MAX_POINTS = 100_000
DASK_CONNECT_TIMEOUT = "10s"  # a scheduler that does not answer within this is reported, not waited on
KEYS = {"base", "set", "mode", "axes", "points", "sample"}


@dataclass(frozen=True)
class Point:
    name: str
    overrides: tuple  # ("key=value", ...) the point's own, after the shared ones
    values: dict  # key → value as written
    fingerprint: str = ""  # Case.fingerprint of the case this point runs: its results file must have been made for it


@dataclass
class Sweep:
    source: str
    base_text: str
    base_source: str
    shared: tuple
    mode: str
    axes: dict  # key → list of values (product, zip)
    points: list = field(default_factory=list)
    sample: Optional[dict] = None  # mode sample: {n, seed}; the distributed axes are in ``axes`` as mappings

    @property
    def groups(self) -> list:
        """Mode sample: the listed (not distributed) axes, whose values group the percentiles."""
        return [k for k, v in self.axes.items() if isinstance(v, list)] if self.mode == "sample" else []

    def spec(self) -> dict:
        """What defines the sweep (stored beside its results: a changed sweep gets its own new points)."""
        return {"base": self.base_source, "set": list(self.shared), "mode": self.mode,
                "axes": {k: ([str(v) for v in vs] if isinstance(vs, list) else vs) for k, vs in self.axes.items()},
                "points": [p.name for p in self.points], **({"sample": self.sample} if self.sample else {})}


def _text(v) -> str:
    return v if isinstance(v, str) else json.dumps(v)


def point_name(values: dict) -> str:
    """A file-system-safe name from a point's values, unique by a hash of all of them."""
    canonical = json.dumps([[k, _text(v)] for k, v in sorted(values.items())])
    digest = hashlib.sha1(canonical.encode()).hexdigest()[:8]
    parts = [f"{k.split('.')[-1]}={_text(v)}" for k, v in values.items()]
    slug = re.sub(r"[^A-Za-z0-9.=_-]+", "", "_".join(parts))[:80]
    return f"{slug}-{digest}" if slug else digest


def load_sweep(path: str | Path, progress: Optional[Callable[[int, int], None]] = None) -> Sweep:
    """Read and check a sweep file: every problem with its YAML path, and every point's case validated.

    Parameters
    ----------
    path : the sweep file (YAML).
    progress : ``progress(done, total)`` is called every 1 000 points (10⁵ points take about 15 s).

    Returns
    -------
    Sweep : its points named and fingerprinted.  A ``CaseError`` lists every problem at once (the first 50).
    """
    path = Path(path)
    source = str(path)
    raw = _read_sweep(path, source)
    problems = []
    for k in raw:
        if k not in KEYS:
            problems.append((str(k)[:40], f"unknown key; allowed: {', '.join(sorted(KEYS))}"))
    base_text, base_source = _base(raw.get("base"), path, source, problems)
    shared = raw.get("set", [])
    if not isinstance(shared, list) or not all(isinstance(s, str) and "=" in s for s in shared):
        problems.append(("set", "expected a list of key.path=value overrides, e.g. [model.dimension=2d]"))
        shared = []
    mode = raw.get("mode", "sample" if "sample" in raw else "points" if "points" in raw and "axes" not in raw
                   else "product")
    if "sample" in raw and mode != "sample":
        problems.append(("mode", f"{excerpt(mode)} with sample:; a sampled sweep is mode sample (or leave mode out)"))
    if mode not in MODES:
        problems.append(("mode", f"unknown value {excerpt(mode)}; expected one of {', '.join(MODES)}"))
    axes = raw.get("axes", {}) if mode != "points" else {}
    points: list[dict] = []
    if mode in ("product", "zip"):
        axes, points = _grid_points(mode, axes, problems)
    elif mode == "sample":
        axes, points = _sampled_points(raw.get("sample"), axes, problems)
    elif mode == "points":
        points = _listed_points(raw.get("points"), problems)
    sweep = Sweep(source, base_text, base_source, tuple(shared), mode, axes if isinstance(axes, dict) else {},
                  sample=raw.get("sample") if mode == "sample" else None)
    _add_points(sweep, points, progress, problems)
    if problems:
        raise CaseError(source, problems[:50] + ([("", f"… and {len(problems) - 50} more")] if len(problems) > 50
                                                 else []), "sweep file")
    return sweep


def _read_sweep(path: Path, source: str) -> dict:
    """The sweep file's mapping; a file that cannot be read or is no mapping stops the reading here."""
    try:
        raw = loads(read_text(path, "sweep file"))
    except (OSError, ValueError) as exc:
        where = exc.path if isinstance(exc, YamlProblem) else ""
        raise CaseError(source, [(where, getattr(exc, "message", str(exc)))], "sweep file") from None
    if not isinstance(raw, dict):
        raise CaseError(source, [("", "expected a mapping with base, axes (or points), and optionally set and mode")],
                        "sweep file")
    return raw


def _base(base, path: Path, source: str, problems: list) -> tuple[str, str]:
    """The base case's text and source: a file beside the sweep file, or an inline mapping; ("", "") otherwise."""
    named = path.parent / base if isinstance(base, str) else path
    try:
        str(named).encode("utf-8")  # the base's source: every point's results file records it as UTF-8 text
    except UnicodeEncodeError:
        problems.append(("base", f"{excerpt(str(named), 80)}: the {'base case' if named != path else 'sweep'} "
                                 f"file's name is not UTF-8 text, which the points' results files record; rename it"))
        return "", ""
    if isinstance(base, str):
        base_path = path.parent / base
        try:
            return read_text(base_path, "base case file"), str(base_path)
        except (OSError, ValueError) as exc:
            problems.append(("base", f"{base_path}: {exc}"))
    elif isinstance(base, dict):
        import yaml
        return yaml.safe_dump(base, sort_keys=False, allow_unicode=True), f"{source}:base"
    else:
        problems.append(("base", ("missing" if base is None else f"got {excerpt(base)}")
                         + "; expected a case file name or an inline case mapping"))
    return "", ""


def _grid_points(mode: str, axes, problems: list) -> tuple[dict, list[dict]]:
    """Modes product and zip: the checked axes and their points (none while anything in the file is wrong)."""
    if not isinstance(axes, dict) or not axes:
        problems.append(("axes", "expected a mapping of case keys to lists of values"))
        axes = {}
    for k, vs in axes.items():
        if not isinstance(k, str) or "." not in k:
            problems.append((f"axes.{str(k)[:40]}", "expected a dotted case key, e.g. loading.normal_load"))
        if not isinstance(vs, list) or not vs:
            problems.append((f"axes.{k}", "expected a non-empty list of values"))
    good = {k: vs for k, vs in axes.items() if isinstance(vs, list) and vs}
    if mode == "zip" and len({len(vs) for vs in good.values()}) > 1:
        lengths = ", ".join(f"{k}: {len(v)}" for k, v in good.items())
        problems.append(("axes", f"zip needs lists of one length; got {lengths}"))
    count = 1
    for vs in good.values():
        count *= len(vs)
    if mode == "product" and count > MAX_POINTS:
        problems.append(("axes", f"{count} points; at most {MAX_POINTS}"))
    elif not problems:
        keys = list(good)
        combos = product(*good.values()) if mode == "product" else zip(*good.values())
        return axes, [dict(zip(keys, c)) for c in combos]
    return axes, []


def _sampled_points(spec, axes, problems: list) -> tuple[dict, list[dict]]:
    """Mode sample: ``spec`` {n, seed} draws of the distributed axes for each combination of the listed ones
    (none while anything in the file is wrong)."""
    from fretsim import uncertainty
    n, seed = _sample_spec(spec, problems)
    if not isinstance(axes, dict) or not axes:
        problems.append(("axes", "expected a mapping of case keys to distributions (or lists of values)"))
        axes = {}
    dists, lists = {}, {}
    for k, v in axes.items():
        if isinstance(v, list) and v:
            lists[k] = v
            continue
        why = uncertainty.check(v)
        if why:
            problems.append((f"axes.{k}", why))
        else:
            dists[k] = v
    if not dists and not problems:
        problems.append(("axes", "a sampled sweep needs at least one axis that is a distribution"))
    count = n
    for vs in lists.values():
        count *= len(vs)
    if count > MAX_POINTS:
        problems.append(("sample", f"{count} points; at most {MAX_POINTS}"))
    elif not problems:
        draws = uncertainty.sample(dists, n, seed)
        return axes, [{**dict(zip(lists, combo)), **d} for combo in product(*lists.values()) for d in draws]
    return axes, []


def _whole(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)  # YAML's true is an int to Python, not a count


def _sample_spec(spec, problems: list) -> tuple[int, int]:
    """(n, seed) of ``sample:``, each key's problem under its own path; (0, 0) while anything is wrong."""
    if not isinstance(spec, dict):
        problems.append(("sample", f"expected {{n: number of samples (1 to {MAX_POINTS}), seed: a whole number "
                                   f"≥ 0}}, got {excerpt(spec)}"))
        return 0, 0
    before = len(problems)
    for k in spec:
        if k not in ("n", "seed"):
            problems.append((f"sample.{str(k)[:40]}", "unknown key; allowed: n, seed"))
    n, seed = spec.get("n"), spec.get("seed", 1)
    if not _whole(n) or not 1 <= n <= MAX_POINTS:
        problems.append(("sample.n", f"{'missing' if 'n' not in spec else f'got {excerpt(n)}'}; expected the number "
                                     f"of samples, a whole number from 1 to {MAX_POINTS}"))
    # numpy seeds from non-negative integers only: a negative one is refused here, not by its traceback
    if not _whole(seed) or seed < 0:
        problems.append(("sample.seed", f"got {excerpt(seed)}; expected a whole number ≥ 0 (the same seed draws "
                                        f"the same samples)"))
    return (n, seed) if len(problems) == before else (0, 0)


def _listed_points(listed, problems: list) -> list[dict]:
    """Mode points: the file's own list of points."""
    if not isinstance(listed, list) or not listed or not all(isinstance(p, dict) and p for p in listed):
        problems.append(("points", "expected a list of mappings of case keys to values"))
    elif len(listed) > MAX_POINTS:
        problems.append(("points", f"{len(listed)} points; at most {MAX_POINTS}"))
    else:
        return listed
    return []


def _add_points(sweep: Sweep, points: list[dict], progress, problems: list) -> None:
    """Each point's case validated, named and fingerprinted into ``sweep.points``; its problems under its label."""
    names = set()
    for i, values in enumerate(points):
        if progress is not None and i % 1000 == 0 and len(points) > 1000:
            progress(i, len(points))
        overrides = tuple(f"{k}={_text(v)}" for k, v in values.items())
        try:
            case = parse_case(sweep.base_text, source=sweep.base_source, overrides=[*sweep.shared, *overrides])
        except CaseError as exc:
            label = (f"points[{i}]" if sweep.mode == "points" else
                     f"point {', '.join(f'{k}={_text(v)}' for k, v in values.items())}")
            problems += [(f"{label}: {p}" if p else label, m) for p, m in exc.problems]
            continue
        name = point_name(values)
        if name in names:
            problems.append((f"points[{i}]", f"the same values as an earlier point ({name})"))
        names.add(name)
        sweep.points.append(Point(name, overrides, dict(values), case.fingerprint()))


# --- running the points ------------------------------------------------------------------------------------------

_IN_POINT = False  # a worker is inside a point's run (its SIGTERM then ends the run cleanly)


_PARENT = 0  # the sweep process a worker serves (0: not in a worker)
_STOPPING = False  # a worker was told to stop: it starts no further point (some may be queued already)


def _on_terminate(signum, frame) -> None:
    global _STOPPING
    _STOPPING = True
    if not _IN_POINT:
        os._exit(0)  # idle: nothing to save


class _StopWhenTold:
    """Ends a point's run at its next step once the worker was told to stop: the run then writes its file with
    status interrupted.  Raised here, not in the signal handler: an exception raised by a handler can land in a
    weakref callback or a __del__, where Python prints it and carries on (seen in CI)."""

    def on_step(self, setup, step) -> None:
        if _STOPPING:
            raise KeyboardInterrupt


def _init_worker(parent: int = 0) -> None:
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent stops the sweep; workers are ended by SIGTERM
    signal.signal(signal.SIGTERM, _on_terminate)
    if hasattr(signal, "pthread_sigmask"):  # (forked with both held, _submit_held: a SIGTERM that came while the
        #                                     worker still had the parent's handler waited for this one)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    global _PARENT
    _PARENT = parent or os.getppid()
    _die_with(_PARENT)


def _die_with(parent: int) -> None:
    """A worker whose sweep process dies (SIGKILL included) gets SIGTERM, as if told to stop: a running point
    writes itself as interrupted, an idle worker leaves.  Linux says so at once (PR_SET_PDEATHSIG); elsewhere a
    thread notices within a second that the worker was handed to another parent."""
    try:
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(1, int(signal.SIGTERM), 0, 0, 0) == 0:  # PR_SET_PDEATHSIG
            if os.getppid() != parent:  # it died before the request took effect
                os.kill(os.getpid(), signal.SIGTERM)
            return
    except (OSError, AttributeError):
        pass
    import threading
    import time

    def watch():
        while os.getppid() == parent:
            time.sleep(1.0)
        os.kill(os.getpid(), signal.SIGTERM)
    threading.Thread(target=watch, daemon=True).start()


_RUNS = []  # this worker process's side runs: the points it runs share auto's proxies and the pilots


def _worker_runs():
    """The side runs of the points this process runs (one keeping per worker, silent: a sweep reports points)."""
    if not _RUNS:
        from fretsim.plan import SideRuns
        _RUNS.append(SideRuns())
    return _RUNS[0]


def run_point(task: tuple) -> dict:
    """Run (or resume) one point, writing its results file; returns the point's status.  In a worker process."""
    global _IN_POINT
    name, base_text, base_source, overrides, output, mode = task
    if _STOPPING:
        return {"name": name, "status": "not run", "message": "the sweep was stopped first"}
    from fretsim.runner import resume, run
    try:
        _IN_POINT = True
        if mode == "resume":
            outcome = resume(output, observers=(_StopWhenTold(),), runs=_worker_runs())
        else:
            case = parse_case(base_text, source=base_source, overrides=list(overrides))
            outcome = run(case, output, overwrite=True, observers=(_StopWhenTold(),), runs=_worker_runs())
        return {"name": name, "status": outcome.status, "message": outcome.message, "summary": outcome.summary}
    except KeyboardInterrupt:
        return {"name": name, "status": "interrupted", "message": "the sweep was stopped; re-run it to resume"}
    except CaseError as exc:
        return {"name": name, "status": "refused", "message": str(exc)}
    except Exception as exc:  # noqa: BLE001 - a point's failure is recorded, the sweep goes on
        return {"name": name, "status": "failed", "message": f"{type(exc).__name__}: {exc}"}
    finally:
        _IN_POINT = False
        if _STOPPING and _PARENT and os.getppid() != _PARENT:
            os._exit(0)  # the sweep is gone: its point is written (interrupted); nobody will send another


def run_point_remote(task: tuple) -> dict:
    """As :func:`run_point` on a Dask worker that may not share DIR: writes to a temporary file, returns bytes."""
    import tempfile
    name, base_text, base_source, overrides, _, mode = task
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / f"{name}.h5"
        row = run_point((name, base_text, base_source, overrides, out, "run"))
        row["data"] = out.read_bytes() if out.exists() else None
    return row


def _state(path: Path, fingerprint: str) -> tuple[str, Optional[dict]]:
    """What a point's results file says: missing, complete, resumable, done (failed/stopped), unreadable, or stale
    (written for other inputs: the base case, the shared `set:` or the file were changed since); with, for a file
    that stands (complete or done), its status, message and summary for the table (read and verified once: a
    complete sweep's re-run was mostly reading every file twice)."""
    if not path.exists():
        return "missing", None
    from fretsim.results import read_results
    try:
        res = read_results(path, every_seal=False)
    except ValueError:
        return "unreadable", None
    if res.attrs.get("input_sha256") != fingerprint:
        return "stale", None
    state = {"complete": "complete", "running": "resumable", "interrupted": "resumable"}.get(res.status, "done")
    stands = state in ("complete", "done") and res.summary
    return state, ({"status": res.status, "message": res.attrs.get("status_message", ""), "summary": res.summary}
                   if stands else None)


STALE = "ran again: its results file was written for other inputs (the base case, `set:` or the file changed)"


@dataclass
class SweepOutcome:
    rows: list
    table_csv: Path
    table_h5: Path
    counts: dict

    @property
    def all_complete(self) -> bool:
        return all(r["status"] == "complete" for r in self.rows)

    def to_pandas(self):
        """The table as a pandas DataFrame (needs pandas)."""
        import pandas as pd
        return pd.DataFrame(self.rows)

    def to_xarray(self):
        """The table as an xarray Dataset (needs xarray and h5netcdf)."""
        import xarray as xr
        return xr.open_dataset(self.table_h5, engine="h5netcdf")


def run_sweep(sweep: Sweep, outdir: str | Path, jobs: int = 0, dask: Optional[str] = None,
              overwrite: bool = False, progress: Optional[Callable[[dict], None]] = None) -> SweepOutcome:
    """Run every point not yet complete; write the table.  KeyboardInterrupt stops cleanly (the table of what is
    done is written first); a re-run continues."""
    outdir = Path(outdir)
    if dask:
        check_dask_address(dask)  # a malformed address is refused before anything is written
    (outdir / "points").mkdir(parents=True, exist_ok=True)
    spec_path = outdir / "sweep.json"
    from fretsim.results import OutputBusy, OutputClaim
    try:  # the directory is this sweep's, as a results file is its run's: a second sweep is refused, not mixed in
        claim = OutputClaim(spec_path).acquire()
    except OutputBusy:
        raise CaseError(str(outdir), [("", "another fretsim sweep is writing into this directory; wait for it to "
                                           "finish, or choose another -o")], "sweep directory") from None
    try:
        return _run_claimed(sweep, outdir, spec_path, jobs, dask, overwrite, progress)
    finally:
        claim.release()


def _run_claimed(sweep: Sweep, outdir: Path, spec_path: Path, jobs: int, dask: Optional[str], overwrite: bool,
                 progress) -> SweepOutcome:
    spec_path.write_text(json.dumps(sweep.spec(), indent=1))
    statuses = {}
    tasks = []
    stale = set()
    for p in sweep.points:
        out = outdir / "points" / f"{p.name}.h5"
        state, known = ("missing", None) if overwrite else _state(out, p.fingerprint)
        if state == "complete" or state == "done":
            statuses[p.name] = known  # None: read from its file for the table
            continue
        if state == "unreadable":
            out.unlink()
        if state == "stale":
            stale.add(p.name)
        mode = "resume" if state == "resumable" else "run"
        tasks.append((p.name, sweep.base_text, sweep.base_source, (*sweep.shared, *p.overrides), out, mode))
    try:
        if dask:
            results = _run_dask(tasks, dask, progress)
        else:
            results = _run_local(tasks, jobs or os.cpu_count() or 1, progress)
        statuses.update({r["name"]: r for r in results})
    finally:
        rows = _table_rows(sweep, outdir, statuses, stale)
        csv_path, h5_path = write_table(sweep, rows, outdir)
    counts = {s: sum(1 for r in rows if r["status"] == s) for s in {r["status"] for r in rows}}
    return SweepOutcome(rows, csv_path, h5_path, counts)


def _run_local(tasks: list, jobs: int, progress) -> list:
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed
    if not tasks:
        return []
    results = []
    # fork where there is fork: the workers start with fretsim already imported (a spawned one re-imports
    # numpy, scipy and h5py, a second or two each); the CLI pins BLAS to one thread before numpy loads
    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    if ctx.get_start_method() == "fork":
        import fretsim.runner  # noqa: F401 - imported once here (scipy's FFT and interpolation, ~1.5 s), not per worker
    pool = ProcessPoolExecutor(max_workers=max(1, min(jobs, len(tasks))), mp_context=ctx, initializer=_init_worker,
                               initargs=(os.getpid(),))
    try:
        futures = _submit_held(pool, tasks)
        for f in as_completed(futures):
            r = f.result()
            results.append(r)
            if progress is not None:
                progress(r)
    except BaseException:
        workers = list((getattr(pool, "_processes", None) or {}).values())  # shutdown forgets them
        pool.shutdown(wait=False, cancel_futures=True)
        _end_workers(workers)
        raise
    pool.shutdown(wait=True)
    return results


def _end_workers(workers: list, patience: float = 60.0) -> None:
    """SIGTERM to each worker, repeated until it is gone (or `patience` seconds): a running point records itself as
    interrupted (and resumes next time), an idle worker leaves.  Repeated because one signal is not always enough:
    a worker that took it inside a point returns to the queue when the point is written, and there waits forever
    on the queue's lock if another worker was ended holding it (seen in CI as a sweep that never exited); and where
    signals cannot be held while the pool forks (:func:`_submit_held`), a worker signalled in the instant after its
    fork loses the signal (Python clears what arrived before its fork handling)."""
    import time
    deadline = time.monotonic() + patience
    alive = list(workers)
    while alive and time.monotonic() < deadline:
        for proc in alive:
            proc.terminate()
        for proc in alive:
            proc.join(timeout=0.5)  # its last write done before the table reads its file
        alive = [proc for proc in alive if proc.is_alive()]
    for proc in alive:  # one that never took SIGTERM (still starting, with it held: _submit_held) is not left
        proc.kill()     # behind: its point's file, if any, stays as last written (a resume continues from it)
        proc.join(timeout=5)


def _submit_held(pool, tasks: list) -> list:
    """The points submitted with Ctrl-C held while the pool forks its workers (at the first submit): a SIGINT that
    landed inside os.fork's at-fork hooks (logging's) was printed as "Exception ignored" with a traceback and lost —
    the sweep ran on to the end (tests/test_fuzz_surfaces.py, a Ctrl-C half a second in).  Held, it arrives once
    the forks are done, as a KeyboardInterrupt here, and the sweep stops as it does at any other moment."""
    import threading
    hold = hasattr(signal, "pthread_sigmask") and threading.current_thread() is threading.main_thread()
    # SIGTERM held too: the workers inherit the mask, and one the parent ended while it was still starting (with the
    # parent's handler, before _init_worker's) printed a KeyboardInterrupt traceback from multiprocessing's bootstrap
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM}) if hold else None
    try:
        return [pool.submit(run_point, t) for t in tasks]
    finally:
        if hold:
            signal.pthread_sigmask(signal.SIG_SETMASK, before)


def _run_dask(tasks: list, address: str, progress) -> list:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise CaseError("--dask", [("", "needs Dask's distributed: pip install 'fretsim[dask]'")]) from None
    results = []
    client = _connect(Client, address)
    try:
        futures = client.map(run_point_remote, tasks, pure=False)
        for f in as_completed(futures):
            r = f.result()
            data = r.pop("data", None)
            out = next(t[4] for t in tasks if t[0] == r["name"])
            if data is not None:
                _write_whole(out, data)
            results.append(r)
            if progress is not None:
                progress(r)
    finally:
        client.close()
    return results


DASK_WORKER_WAIT = 30.0  # s: a scheduler with no workers gets this long to be given one, then it is reported


def check_dask_address(address: str) -> tuple[str, str, int]:
    """(scheme://host:port, host, port) of a scheduler address, or a CaseError saying what is expected."""
    import re
    m = re.fullmatch(r"(?:(tcp|tls)://)?(\[[0-9a-fA-F:]+\]|[A-Za-z0-9._-]+):(\d{1,5})", address.strip())
    if not m or not 0 < int(m.group(3)) < 65536:
        raise CaseError("--dask", [("", f"{address!r} is not a scheduler address; expected tcp://HOST:PORT (or "
                                         f"HOST:PORT, or tls://HOST:PORT), e.g. tcp://127.0.0.1:8786")])
    scheme = m.group(1) or "tcp"
    return f"{scheme}://{m.group(2)}:{m.group(3)}", m.group(2).strip("[]"), int(m.group(3))


def _connect(client_class, address: str):
    """A connected Client, or a CaseError within a bounded time: nothing listening, something that is not a
    Dask scheduler (it may never answer, or send what Dask reads as a 3 EiB message), or a scheduler without
    workers."""
    import socket
    import threading
    from dask.utils import parse_timedelta
    url, host, port = check_dask_address(address)
    limit = float(parse_timedelta(DASK_CONNECT_TIMEOUT))
    try:
        socket.create_connection((host, port), timeout=limit).close()
    except OSError as exc:
        raise CaseError("--dask", [("", f"cannot reach the scheduler at {url}: {exc.strerror or exc}")]) from None
    box: dict = {}

    def connect():
        try:
            box["client"] = client_class(url, timeout=DASK_CONNECT_TIMEOUT)
        except BaseException as exc:  # noqa: BLE001 - whatever a foreign service makes Dask raise is reported
            box["error"] = exc
    t = threading.Thread(target=connect, daemon=True)
    t.start()
    t.join(limit + 5.0)
    if "client" not in box:
        why = (f"{type(box['error']).__name__}: {str(box['error'])[:200]}" if "error" in box else
               f"no answer within {limit + 5:g} s")
        raise CaseError("--dask", [("", f"something listens at {url}, but no Dask scheduler answered ({why}); "
                                         f"check the address and the port")])
    client = box["client"]
    try:
        client.wait_for_workers(1, timeout=DASK_WORKER_WAIT)
    except Exception:  # noqa: BLE001 - dask raises TimeoutError (of its own, or asyncio's)
        client.close()
        raise CaseError("--dask", [("", f"the scheduler at {url} has no workers (waited {DASK_WORKER_WAIT:g} s); "
                                         f"start some, e.g. `dask worker {url}`")]) from None
    return client


def _table_rows(sweep: Sweep, outdir: Path, statuses: dict, stale: frozenset = frozenset()) -> list:
    from fretsim.results import read_results
    rows = []
    for p in sweep.points:
        out = outdir / "points" / f"{p.name}.h5"
        row = {"point": p.name, **{k: _text(v) for k, v in p.values.items()}}
        known = statuses.get(p.name)
        if p.name in stale and not (known and (known.get("summary") or known.get("status") == "refused")):
            # its file is another case's: never show its numbers
            row.update(status=(known or {}).get("status", "not run"),
                       message="its results file was written for other inputs and it has not run again yet; "
                               "re-run the sweep")
            rows.append(row)
            continue
        if known and (known.get("summary") or known.get("status") == "refused"):  # this run's: no need to read
            row.update(status=known["status"], message=known.get("message", ""))
            row.update(known.get("summary") or {})
        else:
            try:
                res = read_results(out)
                row.update(status=res.status, message=res.attrs.get("status_message", ""))
                row.update(res.summary)
            except ValueError:
                row.update(status=(known or {}).get("status", "not run"), message=(known or {}).get("message", ""))
        if p.name in stale:
            row["message"] = STALE + (f"; {row['message']}" if row.get("message") else "")
        rows.append(row)
    return rows


def _numeric_axis(values: list):
    """Axis values as numbers in the unit they were written in (the first value's, where they mix units), with
    that unit, when they are one kind of quantity: a stroke of [10 um, 25 um] is 10 and 25 µm, not 0.01 mm."""
    from fretsim.units import _QUANTITY
    for dim in UNITS:
        try:
            internal = [parse_quantity(v, dim) for v in values]
        except UnitError:
            continue
        unit = _QUANTITY.match(str(values[0])).group(2)
        scale = parse_quantity(f"1 {unit}", dim)
        return [v / scale for v in internal], unit
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return [float(v) for v in values], "1"
    return None, None


def write_table(sweep: Sweep, rows: list, outdir: Path) -> tuple[Path, Path]:
    """DIR/table.csv and DIR/table.h5 (and a sampled sweep's percentiles.csv), each whole or not at all: a disk
    that refuses is an OSError naming the file, with no temporary left behind."""
    csv_path, h5_path = outdir / "table.csv", outdir / "table.h5"
    _write_csv(csv_path, list(dict.fromkeys(k for r in rows for k in r)), rows)
    _write_whole(h5_path, _table_image(sweep, rows))
    if sweep.mode == "sample":
        write_percentiles(sweep, rows, outdir)
    return csv_path, h5_path


def _write_whole(path: Path, data: bytes) -> None:
    """``data`` written to a temporary beside ``path`` with plain file I/O and renamed over it.  HDF5 writing to
    a full disk fails as a RuntimeError from deep in h5py, possibly at close, with its file left behind; built
    in memory first (as the results writer does), the only writes that can fail are these, as OSErrors."""
    tmp = path.with_name(f".{path.name}.part")
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
    finally:
        if tmp.is_file():
            tmp.unlink()


def _table_image(sweep: Sweep, rows: list) -> bytes:
    """table.h5 as bytes (an in-memory HDF5 image)."""
    import io

    import h5py
    import numpy as np

    from fretsim.results import SUMMARY_UNITS
    outputs = [k for k in SUMMARY_UNITS if any(k in r for r in rows)]
    buf = io.BytesIO()
    with h5py.File(buf, "w") as f:
        f.attrs["sweep"] = json.dumps(sweep.spec())
        text = h5py.string_dtype()
        if sweep.mode == "product":
            dims = []
            for k, vs in sweep.axes.items():
                nums, units = _numeric_axis(vs)
                ds = f.create_dataset(k, data=np.array(nums) if nums else np.array([str(v) for v in vs], dtype=object),
                                      dtype=None if nums else text)
                ds.make_scale(k)
                ds.attrs["units"] = units or ""
                ds.attrs["as_written"] = json.dumps([_text(v) for v in vs])
                dims.append(ds)
            shape = tuple(len(v) for v in sweep.axes.values())
        else:
            ds = f.create_dataset("point", data=np.arange(len(rows)))
            ds.make_scale("point")
            dims, shape = [ds], (len(rows),)
            f.create_dataset("point_name", data=np.array([r["point"] for r in rows], dtype=object),
                             dtype=text).dims[0].attach_scale(ds)
            for k in dict.fromkeys(k for p in sweep.points for k in p.values):
                vals = [r.get(k, "") for r in rows]
                nums, units = _numeric_axis(vals)
                c = f.create_dataset(k, data=np.array(nums) if nums else np.array(vals, dtype=object),
                                     dtype=None if nums else text)
                c.attrs["units"] = units or ""
                c.dims[0].attach_scale(ds)
        coords = " ".join(k for k in f if k not in ("point",)) if sweep.mode != "product" else ""
        texts = {"status"} | {k for k, u in SUMMARY_UNITS.items() if u == ""}  # the summary's words (unit "")
        for name, data, dtype in ([("status", [r["status"] for r in rows], text)] +
                                  [(k, [r.get(k, "" if k in texts else float("nan")) for r in rows],
                                    text if k in texts else float) for k in outputs]):
            arr = np.array(data, dtype=object if dtype is text else float).reshape(shape)
            ds = f.create_dataset(name, data=arr, dtype=text if dtype is text else None)
            for axis, scale in enumerate(dims):
                ds.dims[axis].attach_scale(scale)
            ds.attrs["units"] = SUMMARY_UNITS.get(name, "")
            if coords:
                ds.attrs["coordinates"] = coords
    return buf.getvalue()


def write_percentiles(sweep: Sweep, rows: list, outdir: Path) -> Path:
    """DIR/percentiles.csv: P10, P50 and P90 of every summary value over the complete points (per group of the
    listed axes), with its unit."""
    from fretsim.results import SUMMARY_UNITS
    from fretsim.uncertainty import percentiles
    table = percentiles(rows, sweep.groups, {k: u for k, u in SUMMARY_UNITS.items() if u != ""})
    path = outdir / "percentiles.csv"
    _write_csv(path, [*sweep.groups, "key", "p10", "p50", "p90", "unit", "points", "missing", "not_complete"], table)
    return path


def _write_csv(path: Path, fields: list, rows: list) -> None:
    """A CSV written whole or not at all (a temporary beside it, renamed over it)."""
    import csv
    import io
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fieldnames=fields)
    w.writeheader()
    w.writerows(rows)
    _write_whole(path, buf.getvalue().encode("utf-8"))
