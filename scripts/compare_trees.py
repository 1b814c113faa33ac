"""Prove that two source trees of fretsim write the same results: every number, bit for bit.

Runs a fixed list of cases (CASES below) with each tree, through the command line as a user would, and
compares the two results files of every case entry by entry.  Meant for refactors: the old tree is the one
before, the new tree the one after, and NO number in any results file may change.

    python scripts/compare_trees.py --old OLD_TREE --new NEW_TREE [--jobs 2] [--out DIR]
                                    [--only NAME ...] [--reuse-old] [--strict] [--timeout SECONDS]

    # once, the baseline of the tree before the refactor (both sides the same tree: a self-check):
    python scripts/compare_trees.py --old /tmp/base --new /tmp/base --out /tmp/compare
    # then, after each change, only the new tree is run again:
    python scripts/compare_trees.py --old /tmp/base --new /work/main --out /tmp/compare --reuse-old

How each case runs.  From the tree's root, in a fresh process with PYTHONPATH=<tree> (and nothing else on it):
``python -m fretsim run CASE.yaml -o DIR/<side>/<name>.h5 --quiet [--set key=value ...]``, with the case file
named relative to the tree's root (cases/...), so the paths recorded in the file are the same for both trees.
The process is started as ``python -c BOOT TREE run ...``, where BOOT (below) imports fretsim, refuses to go on
unless ``fretsim.__file__`` lies inside TREE (fretsim is also pip-installed editable from /work/main: a wrong
import would compare a tree with itself), then runs the package's ``__main__`` exactly as ``-m`` does
(``runpy.run_module``), and at exit checks that every fretsim module loaded came from TREE.  A wrong tree stops
the whole comparison with exit code 2.  Each side writes DIR/<side>/<name>.h5, <name>.log (its stdout and
stderr) and <name>.json (exit code, seconds, the fretsim it imported).  BLAS/OpenMP are pinned to one thread in
every run, whatever --jobs is, so neither the machine's load nor --jobs can change a result; byte-code is not
written into the trees.  The sides run one after the other (all of old, then all of new), --jobs cases at a time,
and the time each side took is reported (the whole list: about 2 to 2.5 minutes a side on 2 cores, --jobs 2).

What "identical" means. Both runs exited with the same code, both wrote a results file or neither did (then what
they printed, an error message, is compared as text), and the two files hold the same objects: the same groups,
datasets and attributes, by name, everywhere (/, /case, /inputs, /choices, /grid, /history, /fields,
/fretting_loop, /summary, /checkpoint), each dataset with the same dtype, shape and value bytes, each attribute the
same value (dimension-scale references compared by the names they point to, not by file address). Numbers are
compared with np.array_equal (NaNs equal), and then also byte for byte, so a signed zero or a different NaN is
still reported. Where numbers differ, the largest relative difference |a-b|/max(|a|,|b|) is reported (inf where a
NaN or an infinity is on one side only).

Excluded, and only these, because they measure time or are not results:
  * /history/wall_time, /summary/wall_time_s, /summary/grid_error_wall_time_s (datasets) and the /summary
    attributes of the same names: wall-clock seconds;
  * the /checkpoint attribute ``elapsed``: the loop's wall-clock seconds (for --resume);
  * every checksum attribute (``sha256`` of each dataset and of /case and /checkpoint, ``attrs_sha256`` of each
    group and dataset): the values they cover are compared directly here instead.  Several of them cover a wall
    time and so change from run to run: /history/wall_time's and /summary/wall_time_s's sha256, /summary's
    attrs_sha256 (its wall_time_s attributes), /checkpoint's sha256 (it covers ``elapsed``).  The root's
    ``input_sha256`` is not a checksum of the file but the fingerprint of the case asked for: it is compared;
  * the root attribute ``fretsim_version``: the package's version string, not a result.
Checked on the pre-refactor tree against itself (every case, each run with its own random hash seed): with
nothing excluded, two runs differ in exactly the time entries and checksums above, in every file, and nowhere else.
Nothing is excluded for being "close": a difference below 1e-12 relative is listed in its own section as
near-identical (exit 0 then, unless --strict), never passed silently.

The generated cases (GENERATED) are written to DIR/cases/ and named there by an absolute path, which the
results record (/inputs case_file): compare a new tree against a baseline in the same DIR (--reuse-old does).

Exit code: 0 every case bit-identical (or only near-identical ones, listed; with --strict those fail too),
1 some case differs or a run timed out, 2 the comparison itself failed (wrong tree imported, bad arguments).
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import h5py
import numpy as np

# --- the cases ------------------------------------------------------------------------------------------------------
# (name, case file, overrides).  The case file is relative to the tree's root (cases/ is a symlink to
# fretsim/cases) or, for a case this script writes itself, "{out}/cases/<file>" (see GENERATED).  The shipped
# Table 4 files (mccoll_*, kirk_*, s132_*) are 3D cases (model.dimension: 3d in the file), so their shipped
# entries are the Table 4 cases' 3D runs, and only the 2D runs are listed again.  Every shipped case runs as
# shipped: single-threaded (see THREAD_VARS) none takes more than ~25 s on 2 cores with --jobs 2, so none is
# shortened.  The one short run is the resolved stroke's (2000 cycles, as asked: the slowest cycle model).
MU = ["loading.friction_coefficient=0.9"]
COULOMB = MU + ["model.slip=coulomb", "model.stroke=mid_stroke"]  # auto resolves McColl's stroke now
D2, D3 = ["model.dimension=2d"], ["model.dimension=3d"]
CASES: list[tuple[str, str, list[str]]] = [
    # -- every shipped case, as shipped (the Table 4 ones are their 3D runs)
    ("ball_partial_slip", "cases/ball_partial_slip.yaml", []),  # Coulomb partial slip, 3D ball
    ("kirk_450N_20Hz", "cases/kirk_450N_20Hz.yaml", []),
    ("kirk_450N_100Hz", "cases/kirk_450N_100Hz.yaml", []),
    ("kirk_450N_200Hz", "cases/kirk_450N_200Hz.yaml", []),
    ("mccoll_185N", "cases/mccoll_185N.yaml", []),
    ("mccoll_185N_free_faces", "cases/mccoll_185N_free_faces.yaml", []),  # model.corrections free_faces (auto)
    ("mccoll_500N", "cases/mccoll_500N.yaml", []),
    ("mccoll_500N_10um", "cases/mccoll_500N_10um.yaml", []),
    ("mccoll_1670N", "cases/mccoll_1670N.yaml", []),
    ("roller_edge_rounded", "cases/roller_edge_rounded.yaml", []),  # dimension auto: 2D and 3D proxy runs
    ("s132_250N_100um", "cases/s132_250N_100um.yaml", []),
    ("seat_rail", "cases/seat_rail.yaml", []),
    ("table1_case1", "cases/table1_case1.yaml", []),  # contact only (0 cycles)
    ("table1_case2", "cases/table1_case2.yaml", []),
    ("table1_case3", "cases/table1_case3.yaml", []),
    ("table1_case4", "cases/table1_case4.yaml", []),
    ("tube_90C", "cases/tube_90C.yaml", []),  # dimension auto, ring bending
    ("tube_RT", "cases/tube_RT.yaml", []),
    ("tube_service_90C", "cases/tube_service_90C.yaml", []),  # load blocks, a wall_loss limit
    ("tube_service_RT", "cases/tube_service_RT.yaml", []),
    ("wire_rope", "cases/wire_rope.yaml", []),  # crossed cylinders
    # -- the Table 4 cases in 2D (their 3D runs are the shipped ones above)
    ("mccoll_185N_2d", "cases/mccoll_185N.yaml", D2),
    ("mccoll_500N_2d", "cases/mccoll_500N.yaml", D2),
    ("mccoll_1670N_2d", "cases/mccoll_1670N.yaml", D2),
    ("mccoll_500N_10um_2d", "cases/mccoll_500N_10um.yaml", D2),
    ("kirk_450N_20Hz_2d", "cases/kirk_450N_20Hz.yaml", D2),
    ("kirk_450N_100Hz_2d", "cases/kirk_450N_100Hz.yaml", D2),
    ("kirk_450N_200Hz_2d", "cases/kirk_450N_200Hz.yaml", D2),
    ("s132_250N_100um_2d", "cases/s132_250N_100um.yaml", D2),
    # -- Coulomb friction and the energy wear law (ball_partial_slip above: partial slip as shipped)
    ("mccoll_185N_coulomb_2d", "cases/mccoll_185N.yaml", COULOMB + D2),
    ("mccoll_185N_coulomb_3d", "cases/mccoll_185N.yaml", COULOMB + D3),
    # the resolved stroke solves the contact at every increment of every cycle: a short run
    ("mccoll_185N_coulomb_resolved_2d", "cases/mccoll_185N.yaml",
     COULOMB + D2 + ["model.stroke=resolved", "loading.cycles=2000", "output.snapshots=[0, 1000, 2000]"]),
    # α = k/μ: about the Archard case's wear (k 2e-8 and 3e-8 1/MPa = 2e-5 and 3e-5 mm3/J)
    ("mccoll_185N_energy_2d", "cases/mccoll_185N.yaml",
     MU + D2 + ["model.wear_law=energy", "materials.moving.energy_wear_coefficient=2.2e-5 mm3/J",
                "materials.stationary.energy_wear_coefficient=3.3e-5 mm3/J"]),
    # -- every stepping scheme (bdf2 is the default, given explicitly here)
    ("mccoll_185N_linear_2d", "cases/mccoll_185N.yaml", D2 + ["jumping.scheme=linear"]),
    ("mccoll_185N_adaptive_2d", "cases/mccoll_185N.yaml", D2 + ["jumping.scheme=adaptive"]),
    ("mccoll_185N_implicit_2d", "cases/mccoll_185N.yaml", D2 + ["jumping.scheme=implicit"]),
    ("mccoll_185N_bdf2_2d", "cases/mccoll_185N.yaml", D2 + ["jumping.scheme=bdf2"]),
    ("mccoll_185N_preset_paper_2d", "cases/mccoll_185N.yaml", D2 + ["jumping.preset=paper"]),
    # -- load histories and wear limits (tube_service_* above): two blocks, a limit reached in the second
    ("blocks_mccoll_2d", "{out}/cases/blocks_mccoll_2d.yaml", []),
    # -- the grid
    ("mccoll_185N_coarse_element_2d", "cases/mccoll_185N.yaml", D2 + ["grid.coarse_element=[15.75 um]"]),
    ("mccoll_185N_grid_rule_paper_2d", "cases/mccoll_185N.yaml", D2 + ["grid.rule=paper"]),
    ("mccoll_185N_no_error_estimate_2d", "cases/mccoll_185N.yaml", D2 + ["grid.error_estimate=none"]),
    # -- beyond the brief's list, cheap: the other solvers, gap model, rig stiffness, pressure-driven grid,
    #    stepping limits, a spectrum, a run stopped at a physical limit (exit 4) and a refused case (exit 2, no file)
    ("mccoll_185N_msm_2d", "cases/mccoll_185N.yaml", D2 + ["solver.method=msm"]),
    ("mccoll_185N_active_set_2d", "cases/mccoll_185N.yaml", D2 + ["solver.method=active_set"]),
    ("mccoll_185N_stroke_average_2d", "cases/mccoll_185N.yaml", D2 + ["model.gap=stroke_average"]),
    ("mccoll_185N_rig_stiffness_2d", "cases/mccoll_185N.yaml", COULOMB + D2 + ["loading.tangential_stiffness=50 N/um"]),
    ("mccoll_185N_pressure_accuracy_2d", "cases/mccoll_185N.yaml", D2 + ["model.pressure_accuracy=5 %"]),
    ("mccoll_185N_jump_max_2d", "cases/mccoll_185N.yaml", D2 + ["jumping.max=500", "jumping.tolerance=0.1 %"]),
    ("spectrum_mccoll_2d", "{out}/cases/spectrum_mccoll_2d.yaml", []),
    ("mccoll_185N_stopped_2d", "cases/mccoll_185N.yaml",  # the scar reaches half the radius: status stopped
     D2 + ["materials.moving.wear_coefficient=1e-5 1/MPa", "materials.stationary.wear_coefficient=1e-5 1/MPa",
           "loading.cycles=1e6", "output.snapshots=[0, 1000]"]),
    ("mccoll_185N_refused", "cases/mccoll_185N.yaml", ["loading.cycles=-1"]),  # an input error: exit 2
]

# Cases this script writes into DIR/cases/ (file name: YAML text).
GENERATED = {
    "blocks_mccoll_2d.yaml": """\
# written by scripts/compare_trees.py: McColl's cylinder in 2D under a two-block load history, 185 N then
# 100 N at 25 um, with a wear limit on the flat's depth that is reached in the second block
name: blocks_mccoll_2d
geometry:  {type: cylinder_on_flat, radius: 6 mm, length: 10 mm}
materials:
  moving:     {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 2.0e-8 1/MPa}
  stationary: {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 3.0e-8 1/MPa}
loading:
  blocks:
    - {normal_load: 185 N, stroke: 25 um, cycles: 4000}
    - {normal_load: 100 N, stroke: 25 um, cycles: 4000}
limits:    {max_wear_depth_stationary: 1.3 um}   # reached near cycle 6100 (1.09 um at the blocks' change)
model:     {dimension: 2d}
""",
    "spectrum_mccoll_2d.yaml": """\
# written by scripts/compare_trees.py: McColl's cylinder in 2D under a load spectrum in three passes, Coulomb
# friction with a block's own friction coefficient, and a frequency
name: spectrum_mccoll_2d
geometry:  {type: cylinder_on_flat, radius: 6 mm, length: 10 mm}
materials:
  moving:     {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 2.0e-8 1/MPa}
  stationary: {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 3.0e-8 1/MPa}
loading:
  cycles: 12000
  frequency: 20 Hz
  repeat: 3
  friction_coefficient: 0.8
  spectrum:
    - {normal_load: 185 N, stroke: 25 um, fraction: 0.7}
    - {normal_load: 100 N, stroke: 40 um, fraction: 0.3, friction_coefficient: 0.6}
model:     {dimension: 2d}
""",
}

# --- what is not compared (see the docstring) ------------------------------------------------------------------------
TIME_DATASETS = {"/history/wall_time", "/summary/wall_time_s", "/summary/grid_error_wall_time_s"}
TIME_ATTRS = {("/summary", "wall_time_s"), ("/summary", "grid_error_wall_time_s"), ("/checkpoint", "elapsed")}
OTHER_ATTRS = {("/", "fretsim_version")}
CHECKSUM_ATTRS = {"sha256", "attrs_sha256"}  # anywhere: digests of values compared directly
NEAR = 1e-12  # relative differences below this are "near-identical": listed separately, never passed silently
# Every run is single-threaded in BLAS/OpenMP, for both trees.  The results depend on the thread count (measured on
# mccoll_185N_free_faces: 2 OpenBLAS threads against 1 move the fields by up to 3e-5 relative and an estimated
# error by 2 %), so a comparison must fix it; and on this 2-core machine the default (a thread per core) made
# the same run 8x slower (53 s against 6 s), two runs at a time worse still.
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

# Runs in the child: check the import, run `python -m fretsim` as -m does, check every fretsim module loaded.
BOOT = r"""
import os, sys, runpy
tree = os.path.realpath(sys.argv.pop(1))
def _inside(f):
    return f is not None and os.path.realpath(f).startswith(tree + os.sep)
import fretsim
sys.stderr.write("compare_trees: fretsim imported from %s\n" % os.path.realpath(fretsim.__file__))
sys.stderr.flush()
if not _inside(fretsim.__file__):
    sys.stderr.write("compare_trees: WRONG TREE: fretsim is not from %s\n" % tree)
    sys.exit(86)
try:
    runpy.run_module("fretsim", run_name="__main__", alter_sys=True)
finally:
    wrong = sorted(n for n, m in list(sys.modules.items())
                   if (n == "fretsim" or n.startswith("fretsim.")) and getattr(m, "__file__", None)
                   and not _inside(m.__file__))
    if wrong:
        sys.stderr.write("compare_trees: WRONG TREE: modules not from %s: %s\n" % (tree, ", ".join(wrong)))
        sys.stderr.flush()
        os._exit(86)
"""
IMPORTED = "compare_trees: fretsim imported from "
WRONG = "compare_trees: WRONG TREE"


class HarnessError(Exception):
    """The comparison itself cannot be trusted (exit 2)."""


# --- running --------------------------------------------------------------------------------------------------------
_RUNNING: set = set()
_LOCK = threading.Lock()


def case_path(case: str, out: Path) -> str:
    return case.replace("{out}", str(out))


def spec_of(name: str, case: str, overrides: list, out: Path) -> dict:
    spec = {"name": name, "case": case_path(case, out), "overrides": list(overrides)}
    gen = Path(case).name if case.startswith("{out}") else None
    if gen is not None:
        spec["case_text"] = GENERATED[gen]
    return spec


def write_generated(out: Path) -> None:
    (out / "cases").mkdir(parents=True, exist_ok=True)
    for fname, text in GENERATED.items():
        path = out / "cases" / fname
        if not path.exists() or path.read_text() != text:
            path.write_text(text)


def child_env(tree: Path) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    for var in THREAD_VARS:
        env[var] = "1"
    return env


def probe(tree: Path) -> str:
    """Where fretsim comes from in a child run for ``tree``; HarnessError unless inside it."""
    code = "import os, fretsim; print(os.path.realpath(fretsim.__file__))"
    p = subprocess.run([sys.executable, "-c", code], cwd=tree, env=child_env(tree), capture_output=True, text=True)
    where = p.stdout.strip()
    if p.returncode != 0 or not where.startswith(str(tree) + os.sep):
        raise HarnessError(f"{tree}: a child process imports fretsim from {where or '?'} ({p.stderr.strip()[-300:]}); "
                           f"not from this tree")
    return where


def run_one(tree: Path, side: str, spec: dict, out: Path, timeout: float) -> dict:
    """Run one case with one tree; returns the record also written to DIR/<side>/<name>.json."""
    d = out / side
    h5, log, rec_path = d / f"{spec['name']}.h5", d / f"{spec['name']}.log", d / f"{spec['name']}.json"
    for p in (h5, log, rec_path):
        p.unlink(missing_ok=True)
    args = ["run", spec["case"], "-o", str(h5), "--quiet"]
    for item in spec["overrides"]:
        args += ["--set", item]
    cmd = [sys.executable, "-c", BOOT, str(tree)] + args
    started = time.monotonic()
    timed_out = False
    with open(log, "wb") as fh:
        proc = subprocess.Popen(cmd, cwd=tree, env=child_env(tree), stdout=fh, stderr=subprocess.STDOUT,
                                start_new_session=True)
        with _LOCK:
            _RUNNING.add(proc)
        try:
            rc = proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            os.killpg(proc.pid, signal.SIGKILL)
            rc = proc.wait()
        finally:
            with _LOCK:
                _RUNNING.discard(proc)
    seconds = time.monotonic() - started
    text = log.read_text(errors="replace")
    imported = next((line[len(IMPORTED):].strip() for line in text.splitlines() if line.startswith(IMPORTED)), None)
    rec = dict(spec, side=side, tree=str(tree), rc=None if timed_out else rc, timed_out=timed_out,
               seconds=round(seconds, 2), fretsim_file=imported, h5=h5.exists(),
               command="python -m fretsim " + " ".join(_quote(a) for a in args))
    rec_path.write_text(json.dumps(rec, indent=1) + "\n")
    if WRONG in text or imported is None or not imported.startswith(str(tree) + os.sep):
        raise HarnessError(f"{spec['name']} ({side}): fretsim was not imported from {tree} (see {log}): "
                           f"{imported or 'no import recorded'}")
    return rec


def _quote(a: str) -> str:
    return repr(a) if (" " in a or "[" in a) else a


def reusable(spec: dict, out: Path, tree: Path) -> dict | None:
    """The old side's earlier record of this case, if it ran the same command and its file is there."""
    rec_path, h5 = out / "old" / f"{spec['name']}.json", out / "old" / f"{spec['name']}.h5"
    if not rec_path.exists():
        return None
    rec = json.loads(rec_path.read_text())
    if any(rec.get(k) != v for k, v in spec.items()) or rec.get("timed_out") or rec.get("h5") != h5.exists():
        print(f"  {spec['name']}: the baseline in {out / 'old'} is of another command or incomplete: run again",
              file=sys.stderr)
        return None
    if rec.get("tree") != str(tree):
        print(f"  {spec['name']}: note: the baseline was run with {rec.get('tree')}, not {tree}", file=sys.stderr)
    return dict(rec, reused=True)


def run_side(tree: Path, side: str, specs: list, out: Path, jobs: int, timeout: float, reuse: bool) -> tuple:
    """Run the cases with one tree, ``jobs`` at a time; (records by name, wall seconds of this side)."""
    (out / side).mkdir(parents=True, exist_ok=True)
    records, todo = {}, []
    for spec in specs:
        rec = reusable(spec, out, tree) if reuse else None
        if rec is not None:
            records[spec["name"]] = rec
        else:
            todo.append(spec)
    if reuse:
        print(f"{side}: reusing {len(records)} baseline run(s) from {out / side}, running {len(todo)}", flush=True)
    # longest first where an earlier run of the case is known (better packing on the workers)
    known = {}
    for spec in todo:
        for s in ("old", "new"):
            p = out / s / f"{spec['name']}.json"
            if p.exists():
                try:
                    known[spec["name"]] = max(known.get(spec["name"], 0.0), json.loads(p.read_text())["seconds"])
                except (ValueError, KeyError):
                    pass
    todo.sort(key=lambda s: -known.get(s["name"], float("inf")))
    started = time.monotonic()
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = {pool.submit(run_one, tree, side, spec, out, timeout): spec for spec in todo}
        try:
            for fut in futures:
                rec = fut.result()
                records[rec["name"]] = rec
                print(f"  {side} {rec['name']:<34} rc {rec['rc']!s:>4}  {rec['seconds']:7.1f} s"
                      + ("  TIMED OUT" if rec["timed_out"] else ""), flush=True)
        except BaseException:
            for f in futures:
                f.cancel()
            with _LOCK:
                for proc in list(_RUNNING):
                    try:
                        os.killpg(proc.pid, signal.SIGKILL)
                    except ProcessLookupError:
                        pass
            raise
    return records, time.monotonic() - started


# --- reading and comparing ------------------------------------------------------------------------------------------
def _deref(f, v):
    """An attribute value with HDF5 object references replaced by the names they point to."""
    if isinstance(v, h5py.Reference):
        return f"<ref {f[v].name}>" if v else "<null ref>"
    if isinstance(v, np.ndarray) and (v.dtype.kind == "O" or v.dtype.names):  # DIMENSION_LIST, REFERENCE_LIST
        return ("array", v.dtype.str, v.shape, [_deref(f, x) for x in (v.tolist() if v.dtype.names else v.ravel())])
    if isinstance(v, tuple):
        return tuple(_deref(f, x) for x in v)
    return v


def load(path: Path) -> dict:
    """Everything compared in a results file: {label: value}, labels '/grp' (a group: its kind), '/grp/ds' (a
    dataset's value) and '/grp/ds@attr' (an attribute), exclusions left out."""
    items: dict = {}
    with h5py.File(path, "r") as f:
        def add(name: str, obj) -> None:
            where = "/" + name if name else "/"
            if isinstance(obj, h5py.Dataset):
                if where not in TIME_DATASETS:
                    items[where] = obj[()]
            else:
                items[where] = "<group>"
            for k in obj.attrs.keys():
                if k in CHECKSUM_ATTRS or (where, k) in TIME_ATTRS or (where, k) in OTHER_ATTRS:
                    continue
                items[f"{where}@{k}"] = _deref(f, obj.attrs[k])
        add("", f)
        f.visititems(add)
    return items


def _short(v, n: int = 60) -> str:
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    s = repr(v) if not isinstance(v, str) else repr(v)
    return s if len(s) <= n else s[:n - 3] + "..."


def _text_diff(a: str, b: str) -> str:
    la, lb = a.splitlines(), b.splitlines()
    for i, (x, y) in enumerate(zip(la, lb)):
        if x != y:
            return f"text differs at line {i + 1}: {_short(x)} vs {_short(y)}"
    return f"text differs: {len(la)} vs {len(lb)} lines"


def compare_values(a, b):
    """None if a and b are bit-identical, else (description, max relative difference or None if not numeric)."""
    if isinstance(a, (bytes, str)) or isinstance(b, (bytes, str)):
        if type(a) is not type(b):
            return f"type {type(a).__name__} vs {type(b).__name__}", None
        if a == b:
            return None
        da = a.decode("utf-8", "replace") if isinstance(a, bytes) else a
        db = b.decode("utf-8", "replace") if isinstance(b, bytes) else b
        return _text_diff(da, db), None
    if isinstance(a, (list, tuple)) or isinstance(b, (list, tuple)):
        return None if a == b else (f"{_short(a)} vs {_short(b)}", None)
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype != b.dtype:
        return f"dtype {a.dtype} vs {b.dtype}", None
    if a.shape != b.shape:
        return f"shape {a.shape} vs {b.shape}", None
    if a.dtype.kind == "O" or a.dtype.names:  # text arrays (e.g. /choices/reason), compound values
        flat_a, flat_b = a.ravel().tolist(), b.ravel().tolist()
        bad = [i for i, (x, y) in enumerate(zip(flat_a, flat_b)) if not (type(x) is type(y) and x == y)]
        if not bad:
            return None
        i = bad[0]
        return (f"{len(bad)} of {len(flat_a)} entries differ, first [{i}]: {_short(flat_a[i])} vs "
                f"{_short(flat_b[i])}"), None
    if a.dtype.kind in "fc":
        equal = np.array_equal(a, b, equal_nan=True)
    else:
        equal = np.array_equal(a, b)
    if equal:
        if np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes():
            return None
        return "equal values, different bits (a signed zero or a NaN's payload)", 0.0
    if a.dtype.kind not in "biufc":
        return f"{_short(a)} vs {_short(b)}", None
    x, y = a.astype(np.complex128 if a.dtype.kind == "c" else np.float64), b.astype(
        np.complex128 if b.dtype.kind == "c" else np.float64)
    with np.errstate(all="ignore"):
        same = (x == y) | (np.isnan(x) & np.isnan(y))
        rel = np.abs(x - y) / np.maximum(np.abs(x), np.abs(y))
    rel = np.where(same, 0.0, np.where(np.isfinite(rel), rel, np.inf))
    n = int((~same).sum())
    where = np.unravel_index(int(np.argmax(rel)), rel.shape) if rel.ndim else ()
    at = f" at {list(map(int, where))}" if rel.ndim else ""
    desc = (f"{n} of {same.size} values differ, max rel {float(rel.max()):.3g}{at}" if same.size > 1 else
            f"{_short(a.item())} vs {_short(b.item())}, rel {float(rel.max()):.3g}")
    return desc, float(rel.max())


def compare_files(old: Path, new: Path) -> list:
    """[(label, description, max relative difference or None)] of every difference; [] if identical."""
    a, b = load(old), load(new)
    diffs = []
    for label in sorted(set(a) | set(b)):
        if label not in b:
            diffs.append((label, "only in old", None))
        elif label not in a:
            diffs.append((label, "only in new", None))
        else:
            d = compare_values(a[label], b[label])
            if d is not None:
                diffs.append((label, d[0], d[1]))
    return diffs


def _message(log: Path) -> str:
    """A run's output less this script's own line (a run without a results file prints no times)."""
    return "\n".join(line for line in log.read_text(errors="replace").splitlines() if not line.startswith(IMPORTED))


def judge(old: dict, new: dict, out: Path) -> tuple:
    """(verdict, differences) of one case: verdict 'identical', 'near' or 'differs'."""
    diffs = []
    if old["timed_out"] or new["timed_out"]:
        diffs.append(("run", f"timed out: old {old['timed_out']}, new {new['timed_out']}", None))
    if old["rc"] != new["rc"]:
        diffs.append(("exit code", f"{old['rc']} vs {new['rc']}", None))
    ho, hn = out / "old" / f"{old['name']}.h5", out / "new" / f"{new['name']}.h5"
    if ho.exists() != hn.exists():
        diffs.append(("results file", f"written: old {ho.exists()}, new {hn.exists()}", None))
    elif not ho.exists():  # neither wrote a file (an input refused, a crash): compare what they said instead
        lo, ln = (_message(out / side / f"{old['name']}.log") for side in ("old", "new"))
        if lo != ln:
            diffs.append(("message", _text_diff(lo, ln), None))
    else:
        try:
            diffs += compare_files(ho, hn)
        except OSError as exc:  # not an HDF5 file (a run killed while placing it): a difference, not a crash
            diffs.append(("results file", f"cannot be read: {exc}", None))
    if not diffs:
        return "identical", diffs
    if all(rel is not None and rel < NEAR for _, _, rel in diffs):
        return "near", diffs
    return "differs", diffs


def status_of(rec: dict, out: Path) -> str:
    if rec["timed_out"]:
        return "timeout"
    h5 = out / rec["side"] / f"{rec['name']}.h5" if "side" in rec else None
    status = "-"
    if h5 is not None and h5.exists():
        try:
            with h5py.File(h5, "r") as f:
                v = f.attrs.get("status", "?")
                status = v.decode() if isinstance(v, bytes) else str(v)
        except OSError:
            status = "unreadable"
    return f"{rec['rc']} {status}"


# --- main -----------------------------------------------------------------------------------------------------------
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--old", type=Path, help="the tree before (its root: fretsim/, cases/)")
    ap.add_argument("--new", type=Path, help="the tree after")
    ap.add_argument("--jobs", type=int, default=2, help="cases run at a time (default 2)")
    ap.add_argument("--out", type=Path, default=Path("compare_out"), help="DIR for results (default ./compare_out)")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="only these cases (names from CASES)")
    ap.add_argument("--reuse-old", action="store_true",
                    help="do not run the old tree again where DIR/old/<name>.h5 (and its record) is there")
    ap.add_argument("--strict", action="store_true", help="near-identical (< 1e-12 relative) fails too")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds a run may take (default 1800)")
    ap.add_argument("--list", action="store_true", help="print the cases and exit")
    args = ap.parse_args(argv)

    names = [c[0] for c in CASES]
    assert len(names) == len(set(names)), "duplicate case names"
    if args.list:
        for name, case, overrides in CASES:
            print(f"{name:<34} {case:<40} {' '.join(overrides)}")
        return 0
    if args.old is None or args.new is None:
        ap.error("--old and --new are required")
    if args.only:
        unknown = [n for n in args.only if n not in names]
        if unknown:
            print(f"unknown case(s): {', '.join(unknown)}; see --list", file=sys.stderr)
            return 2
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    specs = [spec_of(n, c, o, out) for n, c, o in CASES if not args.only or n in args.only]
    try:
        trees = {}
        for side, tree in (("old", args.old), ("new", args.new)):
            tree = tree.resolve()
            if not (tree / "fretsim" / "__init__.py").is_file():
                raise HarnessError(f"{tree}: not a fretsim tree (no fretsim/__init__.py)")
            print(f"{side}: {tree} (fretsim from {probe(tree)})", flush=True)
            trees[side] = tree
        write_generated(out)
        records, took = {}, {}
        for side in ("old", "new"):
            records[side], took[side] = run_side(trees[side], side, specs, out, args.jobs, args.timeout,
                                                 args.reuse_old and side == "old")
    except HarnessError as exc:
        print(f"\nCOMPARISON FAILED: {exc}", file=sys.stderr)
        return 2

    verdicts = {}
    for spec in specs:
        n = spec["name"]
        verdicts[n] = judge(records["old"][n], records["new"][n], out)

    width = max(len(s["name"]) for s in specs)
    print(f"\n{'case':<{width}}  {'old':<12} {'new':<12} {'old s':>7} {'new s':>7}  result")
    for spec in specs:
        n = spec["name"]
        ro, rn = records["old"][n], records["new"][n]
        verdict, diffs = verdicts[n]
        result = {"identical": "identical", "near": f"NEAR-IDENTICAL ({len(diffs)} < {NEAR:g} rel)",
                  "differs": f"DIFFERS ({len(diffs)})"}[verdict]
        t_old = f"{ro['seconds']:.1f}" + ("*" if ro.get("reused") else "")
        print(f"{n:<{width}}  {status_of(ro, out):<12} {status_of(rn, out):<12} {t_old:>7} {rn['seconds']:7.1f}  "
              f"{result}")
    if any(records["old"][s["name"]].get("reused") for s in specs):
        print("(* the old side's time of the reused baseline run)")

    for kind, title in (("differs", "DIFFERENCES"),
                        ("near", f"NEAR-IDENTICAL: differences below {NEAR:g} relative (NOT bit-identical)")):
        bad = [s["name"] for s in specs if verdicts[s["name"]][0] == kind]
        if not bad:
            continue
        print(f"\n{title}")
        for n in bad:
            print(f"  {n}:")
            for label, desc, rel in verdicts[n][1]:
                print(f"    {label:<48} {desc}")

    ran_old = [r for r in records["old"].values() if not r.get("reused")]
    print(f"\nold tree {trees['old']}: {len(ran_old)} run(s) in {took['old']:.0f} s wall "
          f"(sum of runs {sum(r['seconds'] for r in ran_old):.0f} s)"
          + (f", {len(specs) - len(ran_old)} reused" if len(ran_old) < len(specs) else ""))
    print(f"new tree {trees['new']}: {len(specs)} run(s) in {took['new']:.0f} s wall "
          f"(sum of runs {sum(r['seconds'] for r in records['new'].values()):.0f} s), --jobs {args.jobs}")
    counts = {k: sum(v[0] == k for v in verdicts.values()) for k in ("identical", "near", "differs")}
    print(f"{counts['identical']} identical, {counts['near']} near-identical, {counts['differs']} differ "
          f"(of {len(specs)}); results in {out}")
    if counts["differs"] or (args.strict and counts["near"]):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
