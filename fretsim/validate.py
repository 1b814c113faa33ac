"""`fretsim validate`: every published case of the paper, run, and one report against experiment, FEA and the paper.

The expected values live in each case file's ``expected:`` section (kept by the parser, never run):

    expected:
      source: "[18] McColl et al. 2004, as tabulated by Kong, Bennett & Hyde, Table 4"
      experiment: {centre_wear_depth_stationary: 2.9 um, scar_width_stationary: 0.54 mm}
      fea: {...}
      paper: {...}                           # the paper's own model ("current method")
      paper_ratio: {of: tube_90C, max_wear_depth_moving: 1.76}   # the paper's ratio of case `of` to this one

Quantities (with units; the report's unit in brackets): centre_wear_depth_stationary [µm] (the flat's maximum
depth along y = 0, the paper's Table 4 "wear depth"), scar_width_stationary [mm] and scar_width_moving [mm]
(worn width along y = 0 where the depth exceeds 0.1 % of its maximum, interpolated between elements, so it
moves continuously with the grid), max_wear_depth_moving [µm], contact_half_width [mm] (of the unworn pressure
along y = 0, interpolated at its edges), element_size_x [µm].  MAPE against experiment is computed as the paper
does: the mean of |model − experiment| / experiment over the Table 4 cases that have both.
"""
from __future__ import annotations

import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import numpy as np

from fretsim.case import CaseError, load_case
from fretsim.quantities import WEAR, shown_unit
from fretsim.units import UnitError, parse_quantity

CASES = Path(__file__).resolve().parent / "cases"
# expected key: (summary key or None, unit in the report, scale from mm): the wear quantities published values are
# given for (fretsim.quantities), the unworn contact's half-width and the element
QUANTITIES = {**{key: (WEAR[key].summary_key, shown_unit(WEAR[key].unit), WEAR[key].factor)
                 for key in ("centre_wear_depth_stationary", "max_wear_depth_stationary", "max_wear_depth_moving",
                             "scar_width_stationary", "scar_width_moving")},
              "contact_half_width": (None, "mm", 1.0),
              "element_size_x": ("element_size_x_um", "µm", 1e3)}
GROUPS = ("experiment", "fea", "paper")
# Kong et al. Table 3: simulation times of the paper's method (the FEA and BEM beside it)
TABLE3 = [("2D cylinder on flat, 18 000 cycles", "mccoll_185N", ["model.dimension=2d"], "36 s (FEA [18]: 1 day, "
           "BEM [30]: 30 min)"),
          ("3D cylinder on flat, 1 000 cycles", "mccoll_185N", ["loading.cycles=1000"], "44 s (BEM [30]: 10 h)"),
          ("3D ball on flat, 1 000 cycles", "table1_case4", ["loading.cycles=1000"], "44 s (BEM [30]: 10 h)")]
# McColl's finite-element model (the FEA column of Table 4): μ = 0.9, plane strain, the flat a 12 mm wide × 6 mm
# high block whose base carries the stroke, the half-cylinder held at its flat top 6 mm above the contact
FE_MODEL = ["loading.friction_coefficient=0.9", "geometry.flat_width=12 mm", "geometry.flat_thickness=6 mm",
            "geometry.moving_height=6 mm"]
# `validate --friction`: McColl's cases under the FE model's friction and bodies, each model of the cycle beside
# the paper's (label → overrides); the uniform model has no bodies (every point slides the whole stroke)
FRICTION_MODELS = {"uniform (the paper's)": ["model.slip=uniform"],
                   "coulomb, mid-stroke": ["model.slip=coulomb", "model.stroke=mid_stroke"],
                   "coulomb, resolved": ["model.slip=coulomb", "model.stroke=resolved"]}


@dataclass
class Expected:
    source: str
    values: dict  # group → {quantity: value in the report's unit}
    ratios: dict = field(default_factory=dict)  # companion case → {quantity: ratio}


def expected_of(case) -> Optional[Expected]:
    """The ``expected`` section of a case, with its units checked (CaseError naming the path otherwise)."""
    raw = case.expected
    if not raw:
        return None
    problems, values, ratios = [], {}, {}
    for key, group in raw.items():
        if key == "source":
            continue
        path = f"expected.{key}"
        if not isinstance(group, dict):
            problems.append((path, "expected a mapping of quantities"))
            continue
        if key == "paper_ratio":
            companion = group.get("of")
            if not isinstance(companion, str):
                problems.append((f"{path}.of", "expected the name of the case the ratio is of"))
                continue
            for q, v in group.items():
                if q == "of":
                    continue
                if q not in QUANTITIES or isinstance(v, bool) or not isinstance(v, (int, float)):
                    problems.append((f"{path}.{q}", f"expected a plain ratio of one of {', '.join(QUANTITIES)}"))
                else:
                    ratios.setdefault(companion, {})[q] = float(v)
            continue
        if key not in GROUPS:
            problems.append((path, f"unknown group; expected source, {', '.join(GROUPS)} or paper_ratio"))
            continue
        for q, v in group.items():
            if q not in QUANTITIES:
                problems.append((f"{path}.{q}", f"unknown quantity; expected one of {', '.join(QUANTITIES)}"))
                continue
            try:
                values.setdefault(key, {})[q] = parse_quantity(v, "length") * QUANTITIES[q][2]
            except UnitError as exc:
                problems.append((f"{path}.{q}", str(exc)))
    if problems:
        raise CaseError(case.source, problems)
    return Expected(str(raw.get("source", "")), values, ratios)


def shipped_with_expected() -> list[str]:
    return sorted(p.stem for p in CASES.glob("*.yaml") if "expected:" in p.read_text())


def _contact_half_width(grid, p: np.ndarray, line: bool) -> float:
    """The contact half-width along x from the pressure's second moment, free of the grid's pixelation: for
    Hertz ∫x²p/∫p is a²/4 along a line contact and a²/5 over an elliptical one."""
    X, _ = grid.mesh()
    m2 = float((X**2 * p).sum() / p.sum())
    return float(np.sqrt((4.0 if line else 5.0) * m2))


def run_one(args: tuple) -> dict:
    """Run one case (in a worker process): its summary, a few derived figures, and the time."""
    name, overrides = args
    from fretsim.runner import run
    case = load_case(CASES / f"{name}.yaml", list(overrides))
    t = time.perf_counter()
    try:
        out = run(case)
    except CaseError as exc:
        return {"name": name, "status": "refused", "message": str(exc)}
    seconds = time.perf_counter() - t
    row = {"name": name, "status": out.status, "message": out.message, "seconds": seconds,
           "summary": dict(out.summary), "dimension": out.case.dimension, "overrides": list(overrides),
           "choices": [(c.key, str(c.value), c.reason) for c in (out.plan.choices if out.plan else []) if not c.given]}
    if out.last is not None and out.last.cycle > 0:  # the flat's final profile along y = 0, for the report's figure
        from fretsim.measures import centre_line
        row["profile_x_mm"] = out.setup.grid.x.tolist()
        row["profile_stationary_um"] = (centre_line(out.last.wear_stationary) * 1e3).tolist()
        row["profile_moving_um"] = (centre_line(out.last.wear_moving) * 1e3).tolist()
    if out.last is not None and out.last.cycle == 0:
        g = out.setup.grid
        p = out.last.pressure
        line = case.geometry.line_length is not None
        row["contact_half_width"] = _contact_half_width(g, p[p.shape[0] // 2:p.shape[0] // 2 + 1] if line and
                                                        not g.plane_strain else p, line)
    return row


def friction_tasks(cases: dict, quick: bool) -> list[tuple[str, tuple]]:
    """(key, (case name, overrides)) of `validate --friction`'s runs: each case with FEA values that takes its bodies
    under each of FRICTION_MODELS with the FE model's μ and bodies, in 2D and 3D (2D only with ``quick``)."""
    tasks = []
    for name, (case, exp) in cases.items():
        if not (exp and exp.values.get("fea")):
            continue
        try:  # the FE model's bodies are a block and a held cylinder: cases of another geometry are left out
            load_case(CASES / f"{name}.yaml", FE_MODEL)
        except CaseError:
            continue
        for dim in ("2d",) if quick else ("2d", "3d"):
            for label, sets in FRICTION_MODELS.items():
                tasks.append((f"friction:{name}:{dim}:{label}", (name, (*FE_MODEL, *sets, f"model.dimension={dim}"))))
    return tasks


def validate(names: list[str], outdir: Path, jobs: int = 0, quick: bool = False, progress=None,
             friction: bool = False) -> dict:
    """Run the cases and the Table 3 timings (and, with ``friction``, McColl's cases under the FE model's friction
    and bodies), write report.md and figures to outdir; returns the results."""
    jobs = jobs or os.cpu_count() or 1
    cases = {}
    for name in names:
        case = load_case(CASES / f"{name}.yaml")
        cases[name] = (case, expected_of(case))
    tasks = []
    for name, (case, _) in cases.items():
        overrides = []
        if quick:
            overrides = ["model.dimension=2d"] if case.geometry.has_2d else ["loading.cycles=" +
                                                                             str(min(case.loading.cycles, 500))]
        tasks.append((name, tuple(overrides)))
    timing = [] if quick else [(f"table3:{i}", (case, tuple(ov))) for i, (_, case, ov, _) in enumerate(TABLE3)]
    timing += friction_tasks(cases, quick) if friction else []
    work = tasks + [(name, ov) for _, (name, ov) in timing]
    results = {}
    with ProcessPoolExecutor(max_workers=max(1, min(jobs, len(work)))) as pool:
        for (key, _), res in zip(tasks + [(k, None) for k, _ in timing], pool.map(run_one, work)):
            results[key] = res
            if progress is not None:
                progress(1)
    outdir.mkdir(parents=True, exist_ok=True)
    report = build_report(cases, results, outdir, quick)
    tmp = outdir / f".report.md.{os.getpid()}.part"  # whole or not at all: a full disk keeps the last report
    try:
        tmp.write_text(report)
        os.replace(tmp, outdir / "report.md")
    finally:
        if tmp.exists():
            tmp.unlink()
    return {"results": results, "report": outdir / "report.md",
            "ok": all(r.get("status") == "complete" for r in results.values())}


def _value(res: dict, q: str) -> Optional[float]:
    key = QUANTITIES[q][0]
    if key is None:
        return res.get("contact_half_width")
    v = res.get("summary", {}).get(key)
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else v


def _fmt(v) -> str:
    return "–" if v is None else f"{v:.3g}"


def _mape(pairs: list[tuple[float, float]]) -> Optional[float]:
    pairs = [(m, e) for m, e in pairs if m is not None and e is not None and e != 0]
    return 100.0 * float(np.mean([abs(m - e) / e for m, e in pairs])) if pairs else None


def build_report(cases: dict, results: dict, outdir: Path, quick: bool) -> str:
    """The validation report (Markdown): a section per table of the paper the cases reproduce, then failures
    and choices.

    Parameters
    ----------
    cases : name → (case, its :class:`Expected` or None).
    results : name (or ``table3:i``) → the row :func:`run_one` returned.
    outdir : where the report's figures are written.
    quick : whether the runs were the quick ones (said in the report's first lines).

    Returns
    -------
    str : the report, one line per line, ending in a newline.
    """
    lines = ["# Validation: fretsim against the published cases of Kong, Bennett & Hyde", "",
             "Generated by `fretsim validate" + (" --quick" if quick else "") + "`.  Every number of the experiment, "
             "the FEA and the paper is read from the `expected:` section of the case file named in the first "
             "column (cases/); fretsim's columns are this run.  Differences are stated, not hidden.", ""]
    lines += _table4_section(cases, results, outdir)
    lines += _friction_section(cases, results)
    lines += _table1_section(cases, results)
    lines += _section4(cases, results, outdir)
    lines += _table3_section(results)
    failed = [k for k, r in results.items() if r.get("status") != "complete"]
    if failed:
        lines += ["## Runs that did not complete", ""] + [f"- {k}: {results[k].get('status')}: "
                                                          f"{results[k].get('message', '')}" for k in failed] + [""]
    lines += ["## Choices", "", "What each run decided for itself (`fretsim check CASE` shows the same):", ""]
    for n in cases:
        for key, value, reason in results[n].get("choices", []):
            if key in ("model.dimension", "model.gap", "model.corrections", "jumping.scheme"):
                lines.append(f"- {n}: {key} = {value}: {reason}")
    return "\n".join(lines) + "\n"


def _table4_section(cases: dict, results: dict, outdir: Path) -> list[str]:
    """Table 4: the flat's wear depth and scar width of each case against experiment, FEA and the paper, each
    model's MAPE against experiment, and the figures (written to outdir)."""
    table4 = [n for n, (_, e) in cases.items() if e and "centre_wear_depth_stationary" in
              {q for g in e.values.values() for q in g}]
    if not table4:
        return []
    lines = ["## Table 4: the flat's wear depth and scar width", "",
             "Wear depth: the flat's maximum depth along the centre line y = 0 (the paper's quantity); scar "
             "width: its worn width there, at 0.1 % of the maximum depth, interpolated.", "",
             "| case | model | depth: experiment | FEA | paper | **fretsim** | vs paper | width (mm): experiment "
             "| FEA | paper | **fretsim** | time (s) |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    pairs = {g: {"depth": [], "width": []} for g in ("paper", "fea", "fretsim")}
    for n in table4:
        lines.append(_table4_row(n, cases[n][1], results[n], pairs))
    lines += ["", "MAPE against experiment (the paper's measure, over the cases each model has):", "",
              "| model | depth | cases | width | cases |", "| --- | --- | --- | --- | --- |"]
    for g, label in (("paper", "the paper's model (it reports 13.4 % and 20.1 %)"),
                     ("fea", "the FEA (the paper reports 23.1 % and 15.4 %)"), ("fretsim", "**fretsim**")):
        md, mw = _mape(pairs[g]["depth"]), _mape(pairs[g]["width"])
        lines.append(f"| {label} | {'–' if md is None else f'{md:.1f} %'} | {len(pairs[g]['depth'])} | "
                     f"{'–' if mw is None else f'{mw:.1f} %'} | {len(pairs[g]['width'])} |")
    lines += ["", "![Table 4](table4.png)", ""]
    _table4_figure(table4, cases, results, outdir / "table4.png")
    if _profiles_figure(table4, cases, results, outdir / "profiles.png"):
        lines += ["Each case's worn flat along y = 0 (fretsim, this run) against its published depth (at the centre) "
                  "and scar width (its edges at the surface): experiment ○, FEA □, the paper △.", "",
                  "![profiles](profiles.png)", ""]
    return lines


def _table4_row(n: str, exp: Expected, res: dict, pairs: dict) -> str:
    """One case's row of Table 4; its (model, experiment) pairs are added to ``pairs`` for the MAPE."""
    ev = exp.values
    d = {g: ev.get(g, {}).get("centre_wear_depth_stationary") for g in GROUPS}
    w = {g: ev.get(g, {}).get("scar_width_stationary") for g in GROUPS}
    ours_d, ours_w = _value(res, "centre_wear_depth_stationary"), _value(res, "scar_width_stationary")
    rel = "–" if d["paper"] is None or ours_d is None else f"{100 * (ours_d / d['paper'] - 1):+.1f} %"
    for g, model_d, model_w in (("paper", d["paper"], w["paper"]), ("fea", d["fea"], w["fea"]),
                                ("fretsim", ours_d, ours_w)):
        if d["experiment"] is not None and model_d is not None:
            pairs[g]["depth"].append((model_d, d["experiment"]))
        if w["experiment"] is not None and model_w is not None:
            pairs[g]["width"].append((model_w, w["experiment"]))
    return (f"| {n} | {res.get('dimension', '?').upper()} | {_fmt(d['experiment'])} | {_fmt(d['fea'])} | "
            f"{_fmt(d['paper'])} | **{_fmt(ours_d)}** | {rel} | {_fmt(w['experiment'])} | {_fmt(w['fea'])} "
            f"| {_fmt(w['paper'])} | **{_fmt(ours_w)}** | {res.get('seconds', float('nan')):.2f} |")


def _friction_section(cases: dict, results: dict) -> list[str]:
    """McColl's cases under the FE model's friction and bodies (`validate --friction`): each model of the cycle
    against the FEA and the experiment, and each model's MAPE against both."""
    keys = [k for k in results if k.startswith("friction:")]
    if not keys:
        return []
    lines = ["## Table 4 with the FE model's friction and bodies", "",
             "McColl's finite-element model, which the FEA column is: μ = 0.9, the flat a 12 × 6 mm block with the "
             "stroke at its base, the cylinder held 6 mm above the contact (`" + " ".join(FE_MODEL) + "`).  "
             "`uniform` is the paper's model (every point slides the whole stroke: no friction, no bodies); "
             "`coulomb, mid-stroke` fretsim's default with a friction coefficient; `coulomb, resolved` the normal "
             "contact solved at each increment of the stroke, over the worn flat.", "",
             "| case | dim | model | depth (µm): experiment | FEA | **fretsim** | width (mm): experiment | FEA | "
             "**fretsim** | time (s) |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    pairs: dict = {}
    for k in keys:
        _, name, dim, label = k.split(":", 3)
        ev, res = cases[name][1].values, results[k]
        ours = {q: _value(res, q) if res.get("status") == "complete" else None
                for q in ("centre_wear_depth_stationary", "scar_width_stationary")}
        row = [name, dim.upper(), label]
        for q, unit in (("centre_wear_depth_stationary", "depth"), ("scar_width_stationary", "width")):
            exp, fea = ev.get("experiment", {}).get(q), ev.get("fea", {}).get(q)
            row += [_fmt(exp), _fmt(fea), f"**{_fmt(ours[q])}**"]
            for group, ref in (("FEA", fea), ("experiment", exp)):
                pairs.setdefault((dim, label, group, unit), []).append((ours[q], ref))
        status = "" if res.get("status") == "complete" else f" ({res.get('status')})"
        lines.append("| " + " | ".join(row) + f" | {res.get('seconds', float('nan')):.1f}{status} |")
    lines += ["", "MAPE of each model (over the cases it completed):", "",
              "| dim | model | depth vs FEA | width vs FEA | depth vs experiment | width vs experiment |",
              "| --- | --- | --- | --- | --- | --- |"]
    for dim, label in dict.fromkeys((d, lab) for d, lab, _, _ in pairs):
        cells = [_mape(pairs[(dim, label, g, u)]) for g in ("FEA", "experiment") for u in ("depth", "width")]
        lines.append(f"| {dim.upper()} | {label} | " + " | ".join("–" if c is None else f"{c:.1f} %" for c in cells)
                     + " |")
    return lines + ["", "The FEA is McColl's 2D plane-strain model; the experiment's depths carry its scatter (the "
                    "500 N test's 15 µm is nearly twice every model's).  The resolved stroke converges with the "
                    "grid and the increments and its steps are estimated like the others' "
                    "(scripts/results/resolved_convergence.txt, resolved_stepping.txt): where its depth is further "
                    "from the FEA than mid-stroke's, that is the model's difference, not its numerics.", ""]


def _table1_section(cases: dict, results: dict) -> list[str]:
    """Table 1: the unworn contact's half-width and the converged element size."""
    table1 = [n for n, (_, e) in cases.items() if e and "contact_half_width" in e.values.get("paper", {})]
    if not table1:
        return []
    lines = ["## Table 1: the unworn contact and the converged element size", "",
             "| case | half-width a (mm): paper | fretsim (solved) | element size dx (µm): paper | fretsim |",
             "| --- | --- | --- | --- | --- |"]
    for n in table1:
        ev, res = cases[n][1].values["paper"], results[n]
        lines.append(f"| {n} | {_fmt(ev['contact_half_width'])} | {_fmt(_value(res, 'contact_half_width'))} | "
                     f"{_fmt(ev['element_size_x'])} | {_fmt(_value(res, 'element_size_x'))} |")
    return lines + ["", "fretsim's half-width is the solved pressure's: √(4∫x²p/∫p) along a line contact, "
                    "√(5∫x²p/∫p) for the ball, which are a for Hertz's profiles; the paper's is Hertz's a.", ""]


def _section4(cases: dict, results: dict, outdir: Optional[Path] = None) -> list[str]:
    """Section 4, the practical applications: the paper's ratios between cases, and the cases it gives no
    numbers for."""
    ratio_cases = [(n, comp, r) for n, (_, e) in cases.items() if e for comp, r in e.ratios.items()]
    section4 = [n for n, (c, e) in cases.items() if e and not e.values and not e.ratios]
    if not (ratio_cases or section4):
        return []
    lines = ["## Section 4: practical applications", ""]
    for n, other, ratios in ratio_cases:
        lines += [f"{other} over {n}:", "", "| quantity | paper | fretsim |",
                  "| --- | --- | --- |"]
        for q, paper in ratios.items():
            ours = None
            if other in results and _value(results[other], q) and _value(results[n], q):
                ours = _value(results[other], q) / _value(results[n], q)
            lines.append(f"| {q} | {paper:.2f} | {_fmt(ours)} |")
        lines.append("")
    for n in section4:
        res = results[n]
        s = res.get("summary", {})
        lines.append(f"- {n} ({cases[n][1].source}): {res.get('dimension', '?').upper()}, moving body "
                     f"{_fmt(s.get('max_wear_depth_moving_um'))} µm deep over {_fmt(s.get('scar_width_moving_mm'))} "
                     f"mm, flat {_fmt(s.get('max_wear_depth_stationary_um'))} µm over "
                     f"{_fmt(s.get('scar_width_stationary_mm'))} mm, in {res.get('seconds', float('nan')):.2f} s")
    lines += ["", "The paper prints no numbers for the wire rope and the seat rail, only figures; "
              "`python scripts/figures_section4.py` draws fretsim's counterparts of its Figs 21-22, 24-25 and 27-28.", ""]
    scenes = [n for n in dict.fromkeys([*section4, *(m for n, o, _ in ratio_cases for m in (n, o))])
              if n in results and results[n].get("profile_moving_um")]
    if scenes and outdir is not None:
        from fretsim.plotting import published_profiles
        published_profiles([(f"{n} ({results[n].get('dimension', '?')})", results[n]["profile_x_mm"],
                             results[n]["profile_stationary_um"], {}, results[n]["profile_moving_um"])
                            for n in scenes], outdir / "section4.png")
        lines += ["Each scene's worn profiles along y = 0 at the end of its run (fretsim, this run): the flat and the "
                  "moving body (tube, rail, wire).", "", "![section 4](section4.png)", ""]
    return lines


def _table3_section(results: dict) -> list[str]:
    """Table 3: the paper's simulation times beside this machine's."""
    timings = [k for k in results if k.startswith("table3:")]
    if not timings:
        return []
    lines = ["## Table 3: simulation times", "", "| set-up | the paper's method | fretsim (this machine: wall time of "
             "the run, no file written) |", "| --- | --- | --- |"]
    for k in timings:
        label, _, _, paper = TABLE3[int(k.split(":")[1])]
        res = results[k]
        lines.append(f"| {label} | {paper} | {res.get('seconds', float('nan')):.2f} s, "
                     f"{res.get('summary', {}).get('contact_solves', '?')} contact solves |")
    return lines + [""]


def _profiles_figure(names: list[str], cases: dict, results: dict, path: Path) -> bool:
    """A panel per case: fretsim's worn flat across the contact and the published depth and width as markers."""
    drawn = [n for n in names if results[n].get("profile_stationary_um")]
    if not drawn:
        return False
    from fretsim.plotting import published_profiles
    panels = []
    for n in drawn:
        ev = cases[n][1].values
        published = {g: (ev.get(g, {}).get("centre_wear_depth_stationary"), ev.get(g, {}).get("scar_width_stationary"))
                     for g in ("experiment", "fea", "paper") if g in ev}
        panels.append((f"{n} ({results[n].get('dimension', '?')})", results[n]["profile_x_mm"],
                       results[n]["profile_stationary_um"], published))
    published_profiles(panels, path)
    return True


def _table4_figure(names: list[str], cases: dict, results: dict, path: Path) -> None:
    from fretsim.plotting import grouped_bars
    panels = {}
    for q, unit in (("centre_wear_depth_stationary", "µm"), ("scar_width_stationary", "mm")):
        series = {label: [cases[n][1].values.get(source, {}).get(q) for n in names]
                  for label, source in (("experiment", "experiment"), ("FEA", "fea"), ("paper", "paper"))}
        series["fretsim"] = [_value(results[n], q) for n in names]
        panels[f"{q.replace('_', ' ')} ({unit})"] = series
    grouped_bars([n.replace("_", "\n", 1) for n in names], panels, path,
                 "Kong, Bennett & Hyde Table 4: experiment, FEA, the paper's model and fretsim")
