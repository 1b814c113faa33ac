"""Is the resolved stroke stable under every stepping scheme?  Every shipped case with μ = 0.9 (its own μ where it
gives one), model.stroke: resolved, under each scheme of the registry (linear at 0.9 of its stability limit),
in 2D where the scene has a 2D model and in 3D otherwise; the status of each run and, for a failure, the first
line of its message (issue 30's baseline: a failure must say its reason and what to change).

Cases longer than 5 000 cycles run their first 5 000 (a service case's 10⁹ would be hours resolved, and the
explicit schemes take minutes for 20 000 on the Kirk cases); the table is rewritten after each case, so a
stopped study keeps what it ran.  Report, do not tune.

    python scripts/study_resolved_stability.py [--quick] [--from CASE] [--schemes bdf2,implicit]

Prints a table; writes scripts/out/resolved_stability.{txt,csv} (``--from CASE``: the cases from CASE on,
alphabetically, into scripts/out/resolved_stability_from_CASE.{txt,csv}, so that a study stopped part-way is
continued without running again what it ran).  ``--schemes``: only these (the implicit ones, say, after a change to
the implicit step), into scripts/out/resolved_stability_SCHEMES.{txt,csv}.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _study import ROOT, Report, write_csv  # noqa: E402

from fretsim.api import load_case, run  # noqa: E402
from fretsim.case import CaseError  # noqa: E402
from fretsim.plan import prepare  # noqa: E402
from fretsim.stepping import SCHEMES  # noqa: E402

OUT = ROOT / "scripts" / "out"
MAX_CYCLES = 5_000


def overrides(path: Path) -> list[str]:
    case = load_case(path)
    sets = ["model.slip=coulomb", "model.stroke=resolved", "grid.error_estimate=none"]
    if case.loading.friction_coefficient is None:
        sets.append("loading.friction_coefficient=0.9")
    if case.geometry.has_2d:
        sets.append("model.dimension=2d")
    if case.loading.cycles > MAX_CYCLES and not case.loading.history:
        sets.append(f"loading.cycles={MAX_CYCLES}")
    return sets


def main(quick: bool = False, start: str = "", schemes: tuple = ()) -> None:
    say = Report()
    rows = []
    paths = [p for p in sorted((ROOT / "cases").glob("*.yaml")) if p.stem >= start][: 3 if quick else None]
    name = f"resolved_stability_from_{start}" if start else "resolved_stability"
    name += "_" + "_".join(schemes) if schemes else ""
    say(f"{'case':<24}{'scheme':<10}{'status':<12}{'s':>7}  message")
    for path in paths:
        try:
            base = overrides(path)
        except CaseError as exc:
            say(f"{path.stem:<24}{'-':<10}{'refused':<12}{0:>7.1f}  {str(exc).splitlines()[0][:110]}")
            continue
        for scheme in schemes or SCHEMES:
            sets = [*base, f"jumping.scheme={scheme}"]
            t = time.perf_counter()
            try:
                if scheme == "linear":
                    limit = prepare(load_case(path, sets), allow_unstable=True)[0].stability_limit
                    sets.append(f"jumping.linear={max(1, int(0.9 * limit))}")
                out = run(load_case(path, sets))
                status, message = out.status, out.message
            except CaseError as exc:
                status, message = "refused", str(exc)
            except Exception as exc:  # a traceback is itself a finding
                status, message = "error", f"{type(exc).__name__}: {exc}"
            seconds = time.perf_counter() - t
            first = " ".join(message.split())[:110]
            rows.append({"case": path.stem, "scheme": scheme, "status": status, "seconds": seconds,
                         "message": " ".join(message.split())})
            say(f"{path.stem:<24}{scheme:<10}{status:<12}{seconds:>7.1f}  {first}")
        OUT.mkdir(parents=True, exist_ok=True)
        say.write(OUT / f"{name}.txt")
    counts = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    say("")
    say("runs by status: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    OUT.mkdir(parents=True, exist_ok=True)
    write_csv(rows, OUT / f"{name}.csv")
    say.write(OUT / f"{name}.txt")


if __name__ == "__main__":
    args = sys.argv[1:]
    main("--quick" in args, args[args.index("--from") + 1] if "--from" in args else "",
         tuple(args[args.index("--schemes") + 1].split(",")) if "--schemes" in args else ())
