"""Count how hostile inputs end on the surfaces issues #20 and #31 name, for a before/after table.

For each surface, N random examples (the same ones for every tree: a seeded generator), each judged as
    ok        a sound result (accepted and consistent) or a refusal with a one-paragraph message (exit 2)
    traceback anything else raised (exit 1 from the CLI)
    wrong     accepted, but not what was asked for (a roller profile read other than as written)
    hung      still running after HANG seconds
Surfaces: CSV roller profiles (`fretsim check`), sweep files (`load_sweep`), --dask addresses (the connection
step, against addresses where nothing listens or nothing is valid); issue #31's: friction keys, load histories
and wear limits (`fretsim check`), sampled sweep files (`load_sweep`) and measured CSVs (`fit.read_measured`),
drawn by tests/hostile.py (the examples the tests draw, from the same seeds).

    python scripts/fuzz_surfaces.py [-n 200] [--tree DIR] [--only 31]   # --tree: another checkout's fretsim

Prints one line per surface.
"""
from __future__ import annotations

import argparse
import os
import random
import sys
import tempfile
import threading
from pathlib import Path

NUMBERS = ["0", "1", "-5", "5", "4.5", "2", "60", "nan", "inf", "-inf", "1e999", "", " ", "x", "5 mm", "1,5", "-0",
           "1e308", "0.0001"]
HEADERS = ["y [mm], drop [um]", "y [um], drop [nm]", "y, drop", "y [mm]", "y [kg], drop [um]",
           "\ufeffy [mm], drop [um]", "y [mm], drop [um], extra [mm]", ""]
KEYS = ["loading.stroke", "loading.normal_load", "loading.cycles", "materials.moving.wear_coefficient",
        "model.dimension", "jumping.linear", "loading.strok", "loading", "", "a.b.c"]
VALUES = ["10 um", "25 um", "185 N", "2e-8 1/MPa", "2d", "-5 um", "0 N", "1e308 N", "nan um", "10 kg", "abc", "",
          "[1, 2]", "{a: 1}", None, True, 5, -1, 1e308, float("nan")]
ADDRESSES = ["garbage", "http://127.0.0.1:1", "tcp://:", "inproc://x", "tcp://127.0.0.1:9", "127.0.0.1:9",
             "tcp://[::1]:9", "tls://127.0.0.1:9", "tcp://127.0.0.1:99999", "tcp://a b:1", "ws://x:1", "", ":", "x:y",
             "tcp://127.0.0.1", "tcp://127.0.0.1:0", "tcp:/127.0.0.1:9", "localhost:9"]


HANG = 40.0  # s: an attempt still running after this counts as hung


def profile_example(rng: random.Random) -> tuple[str, bool]:
    """(the CSV text, whether it is a well-formed asymmetric profile whose y < 0 half must be read)."""
    if rng.random() < 0.3:
        return "y [mm], drop [um]\n-5, 60\n0, 0\n5, 0\n", True
    rows = [[rng.choice(NUMBERS) for _ in range(rng.randint(0, 3))] for _ in range(rng.randint(0, 6))]
    return rng.choice(HEADERS) + "\n" + "\n".join(", ".join(r) for r in rows) + "\n", False


def sweep_example(rng: random.Random, cases: Path) -> str:
    import yaml
    raw = {}
    if rng.random() < 0.8:
        raw["base"] = rng.choice([str(cases / "mccoll_185N.yaml"), "missing.yaml", 5, None, [1], str(cases)])
    if rng.random() < 0.5:
        raw["set"] = rng.choice([["model.dimension=2d"], "model.dimension=2d", [5], ["x"], []])
    raw["mode"] = rng.choice(["product", "zip", "points", "zap", None])
    if raw["mode"] == "points":
        raw["points"] = [{rng.choice(KEYS): rng.choice(VALUES)} for _ in range(rng.randint(0, 3))]
    else:
        raw["axes"] = {rng.choice(KEYS): [rng.choice(VALUES) for _ in range(rng.randint(0, 3))]
                       for _ in range(rng.randint(0, 2))}
    return yaml.safe_dump(raw, allow_unicode=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=200)
    ap.add_argument("--dask-n", type=int, default=None, help="examples for --dask (default: -n; an old tree hangs "
                                                                 "on many, each counted after 40 s)")
    ap.add_argument("--tree", default=None, help="a checkout whose fretsim/ to test (default: this one)")
    ap.add_argument("--only", choices=["20", "31"], default=None, help="one issue's surfaces")
    args = ap.parse_args()
    tree = Path(args.tree or Path(__file__).resolve().parent.parent)
    sys.path.insert(0, str(tree))
    if args.only != "20":
        issue_31(args.n, tree)
    if args.only == "31":
        return
    from click.testing import CliRunner

    from fretsim.case import CaseError
    from fretsim.cli import main as cli
    import fretsim.sweep as sweep_module
    cases = tree / "cases"
    roller = (cases / "roller_edge_rounded.yaml").read_text().replace("edge_radius: 20 mm, flat_length: 9 mm",
                                                                       "profile: profile.csv")
    counts = {s: {"ok": 0, "traceback": 0, "wrong": 0, "hang": 0} for s in ("profiles", "sweep files",
                                                                             "dask addresses")}
    rng = random.Random(1)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "r.yaml").write_text(roller)
        for _ in range(args.n):
            text, asymmetric = profile_example(rng)
            (tmp / "profile.csv").write_text(text)
            r = CliRunner().invoke(cli, ["check", str(tmp / "r.yaml"), "--set", "model.dimension=3d"])
            if r.exit_code not in (0, 2) or "Traceback" in r.output:
                counts["profiles"]["traceback"] += 1
            elif r.exit_code == 0 and asymmetric:
                from fretsim.case import load_case
                g = load_case(tmp / "r.yaml").geometry
                import numpy as np
                ok = abs(float(g.drop(np.array([-5.0]))[0]) - 0.06) < 1e-9
                counts["profiles"]["ok" if ok else "wrong"] += 1
            else:
                counts["profiles"]["ok"] += 1
        for _ in range(args.n):
            (tmp / "s.yaml").write_text(sweep_example(rng, cases))
            try:
                sweep_module.load_sweep(tmp / "s.yaml")
                counts["sweep files"]["ok"] += 1
            except CaseError:
                counts["sweep files"]["ok"] += 1
            except Exception:  # noqa: BLE001 - counted
                counts["sweep files"]["traceback"] += 1
        (tmp / "small.yaml").write_text(f"base: {cases / 'mccoll_185N.yaml'}\nset: [model.dimension=2d, "
                                        f"loading.cycles=10]\naxes:\n  loading.stroke: [10 um]\n")
        if hasattr(sweep_module, "DASK_CONNECT_TIMEOUT"):
            sweep_module.DASK_CONNECT_TIMEOUT = "1s"
        n_dask = args.n if args.dask_n is None else args.dask_n
        for k in range(n_dask):
            address = ADDRESSES[k % len(ADDRESSES)] if k < len(ADDRESSES) else rng.choice(ADDRESSES) + rng.choice(
                ["", "/", "x", ":1"])
            box = {}

            def attempt():
                box["r"] = CliRunner().invoke(cli, ["sweep", str(tmp / "small.yaml"), "-o", str(tmp / f"o{k}"),
                                                    "--dask", address])
            t = threading.Thread(target=attempt, daemon=True)
            t.start()
            t.join(HANG)
            if "r" not in box:
                counts["dask addresses"]["hang"] += 1
                continue
            r = box["r"]
            bad = r.exit_code not in (0, 2) or "Traceback" in r.output or (r.exception is not None and
                                                                           not isinstance(r.exception, SystemExit))
            counts["dask addresses"]["traceback" if bad else "ok"] += 1
    for surface, c in counts.items():
        n = n_dask if surface == "dask addresses" else args.n
        print(f"{surface:15s} {n} examples: {c['ok']} ok, {c['traceback']} tracebacks, {c['wrong']} wrong, "
              f"{c['hang']} hung (> {HANG:g} s)", flush=True)


def _attempt(call, counts: dict) -> None:
    """Run ``call`` (returning "ok" or "traceback") in a thread; counted as hung after HANG seconds."""
    box = {}

    def attempt():
        try:
            box["v"] = call()
        except Exception:  # noqa: BLE001 - counted
            box["v"] = "traceback"
    t = threading.Thread(target=attempt, daemon=True)
    t.start()
    t.join(HANG)
    counts[box.get("v", "hang")] += 1


def issue_31(n: int, tree: Path) -> None:
    """Issue #31's surfaces, each n examples from its own seed (tests/hostile.py draws them)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    import hostile
    from click.testing import CliRunner

    from fretsim.case import CaseError
    from fretsim.cli import main as cli
    case = str(tree / "cases" / "mccoll_185N.yaml")

    def check(args):
        return hostile.judge_cli(CliRunner().invoke(cli, ["check", *args]))

    def sets(items):
        return [a for s in items for a in ("--set", s)]

    def refused_or_read(reader, path):
        def call():
            try:
                reader(path)
            except CaseError:
                pass
            return "ok"
        return call

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        from fretsim.fit import read_measured
        from fretsim.sweep import load_sweep
        base = (Path(__file__).resolve().parent.parent / "tests" / "test_fuzz_inputs.py").read_text()
        base = base.split('BASE = """', 1)[1].split('"""', 1)[0]
        surfaces = {
            "friction keys": lambda rng: (lambda: check([case, *sets(hostile.friction_example(rng))])),
            "load histories": lambda rng: ((tmp / "h.yaml").write_text(base + hostile.history_example(rng)),
                                           lambda: check([str(tmp / "h.yaml")]))[1],
            "wear limits": lambda rng: (lambda: check([case, *sets(hostile.limits_example(rng))])),
            "sampled sweeps": lambda rng: ((tmp / "s.yaml").write_text(hostile.sampled_sweep_example(rng, case)),
                                           refused_or_read(load_sweep, tmp / "s.yaml"))[1],
            "measured CSVs": lambda rng: ((tmp / "m.csv").write_text(hostile.measured_example(rng)),
                                          refused_or_read(read_measured, tmp / "m.csv"))[1],
        }
        for seed, (surface, example) in enumerate(surfaces.items()):
            rng, counts = random.Random(seed), {"ok": 0, "traceback": 0, "hang": 0}
            for _ in range(n):
                _attempt(example(rng), counts)
            print(f"{surface:15s} {n} examples: {counts['ok']} ok, {counts['traceback']} tracebacks, {counts['hang']} "
                  f"hung (> {HANG:g} s)", flush=True)


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
