"""Figures from a results file (the only module importing matplotlib; Agg backend, no display).

After the paper: wear profiles across the contact (Fig. 17) and, in 3D, along it; pressure profiles (Fig. 16)
with the initial Hertz solution; wear maps of both bodies, each on its own round colour scale (Figs. 24–25), and the pressure
map (the finite cylinder's end peaks, Fig. 5); maximum depth and wear volume against cycles (Figs. 14, 28)
with Archard's line and a marker at every contact solve, and against time where the case gives a frequency, with
the load blocks, the wear limits and where the run stopped at one; with friction, Fouvry's wear volume against
the cumulative dissipated energy with the fitted energy wear coefficient α.  They read only the results file:
:func:`figures` returns the matplotlib figures (tests check what is drawn), :func:`plot_all` saves them.
"""
from __future__ import annotations

import math
import os
import re
import textwrap
import threading
from pathlib import Path
from typing import Optional

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter, MaxNLocator  # noqa: E402

from fretsim.measures import centre_line, column_quantiles, quantiles, through_origin  # noqa: E402
from fretsim.quantities import SUMMARY, shown_unit  # noqa: E402
from fretsim.results import Results, ResultsFileError, SweepTable  # noqa: E402

STYLES = ["-", "--", "-.", ":", (0, (5, 1)), (0, (3, 1, 1, 1))]


def _input(res: Results, key: str, default=None):
    return res.inputs.get(key, (default, ""))[0]


def _float(res: Results, key: str) -> float | None:
    """An input as a finite number, or None where the file lacks it or holds something else: a damaged or
    foreign file still plots its data, without what it could not read (a "?" in the title, no reference line)."""
    try:
        value = float(_input(res, key))
    except (TypeError, ValueError):
        return None
    return value if np.isfinite(value) else None


def _number(res: Results, key: str, spec: str) -> str:
    value = _float(res, key)
    return "?" if value is None else format(value, spec)


def title_block(res: Results) -> str:
    """Case, load, stroke, wear coefficients, model and the --set overrides, for every figure."""
    name = res.attrs.get("case_name", "")
    status = "" if res.status == "complete" else f" [{res.status}]"
    parts = [f"{name}{status}"]
    blocks = res.history.get("block")
    nblocks = int(np.max(blocks)) + 1 if blocks is not None and len(blocks) else 1
    stop = _stop_line(res)
    # at a wear limit loading.cycles is only an upper bound: the stop's own line says how long the run was
    length = "" if stop else f"N = {_number(res, 'cycles', '.0f')}{_time_of(res, _float(res, 'cycles'), short=True)}, "
    if res.inputs and nblocks > 1:
        parts += textwrap.wrap(f"{_load_history(res, nblocks)}, {length}{_coefficients(res)}; "
                               f"{str(_input(res, 'dimension', '')).upper()} {_input(res, 'geometry', '')}, "
                               f"{_input(res, 'scheme', '')}", TITLE_WIDTH, break_long_words=False)
    elif res.inputs:
        parts.append(f"P = {_number(res, 'normal_load', '.4g')} N, δ = ±{_number(res, 'stroke', '.4g')} µm, "
                     f"{length}{_coefficients(res)}; "
                     f"{str(_input(res, 'dimension', '')).upper()} {_input(res, 'geometry', '')}, "
                     + ("stroke resolved" if _input(res, "stroke_model") == "resolved" else  # the gap model unused
                        f"gap {_input(res, 'gap_model', '')}") + f", {_input(res, 'scheme', '')}")
    if stop:
        parts.append(stop)
    if res.overrides:  # wrapped: a long --set line ran off the figure's top
        parts += textwrap.wrap("--set " + " ".join(res.overrides), TITLE_WIDTH, break_long_words=False)
    est = [(label, res.summary.get(f"estimated_error_{key}")) for label, key in
           (("depth", "depth"), ("width", "width"), ("pressure", "pressure"), ("peak pressure", "max_pressure"))]
    if all(isinstance(v, float) and math.isfinite(v) for _, v in est):
        parts.append("estimated error (stepping + grid + model): "
                     + ", ".join(f"{label} ±{_percent(v)}" for label, v in est))
    return "\n".join(parts)


def _load_history(res: Results, applied: int) -> str:
    """A load history's loads and strokes as ranges over its blocks: "load history of 3 blocks (13 applied): P from
    5 to 15 N, δ from ±20 to ±80 µm".  A single P (the peak of all blocks, /inputs' normal_load) read as the load
    the run was under; where the file's case cannot say its blocks, the peaks are said to be bounds."""
    given = res.load_blocks()
    if not given:
        return (f"load history of {applied} blocks: P ≤ {_number(res, 'normal_load', '.4g')} N, "
                f"δ ≤ ±{_number(res, 'stroke', '.4g')} µm")
    loads = sorted({p for p, _ in given})
    strokes = sorted({d * 1e3 for _, d in given})
    count = f"{len(given)} blocks" + (f" ({applied} applied)" if applied != len(given) else "")
    load = f"P = {loads[0]:.4g} N" if len(loads) == 1 else f"P from {loads[0]:.4g} to {loads[-1]:.4g} N"
    stroke = (f"δ = ±{strokes[0]:.4g} µm" if len(strokes) == 1 else
              f"δ from ±{strokes[0]:.4g} to ±{strokes[-1]:.4g} µm")
    return f"load history of {count}: {load}, {stroke}"


def _stop_line(res: Results) -> str:
    """Where a run stopped at a wear limit, in cycles and (with loading.frequency) time; "" for any other run."""
    key = res.summary.get("limit_reached")
    if not key:
        return ""
    n = float(res.summary["cycles_to_limit"])
    cycles = f"{n:,.0f}".replace(",", " ")
    return f"stopped at {cycles} cycles (limit {key} reached){_time_of(res, n)}"


def _time_of(res: Results, n: Optional[float], short: bool = False) -> str:
    """", 1 710 h of continuous fretting at 30 Hz" (short: " (1 710 h at 30 Hz)") for ``n`` cycles where the case
    gives a frequency, else ""."""
    time = _run_time(res)
    if time is None or n is None:
        return ""
    duration = _duration(n / time[2], time[1])
    return f" ({duration} at {time[0]:g} Hz)" if short else f", {duration} of continuous fretting at {time[0]:g} Hz"


TITLE_WIDTH = 150  # characters of a title line at fontsize 9 across the narrowest figure (11 in)


def _coefficients(res: Results) -> str:
    """The wear law's coefficients: Archard's k (1/MPa), or the energy law's α (mm³/J), which is what it runs on."""
    if _input(res, "wear_law", "archard") == "energy" and _float(res, "moving_energy_wear_coefficient") is not None:
        return (f"α_m = {_number(res, 'moving_energy_wear_coefficient', '.3g')}, α_s = "
                f"{_number(res, 'stationary_energy_wear_coefficient', '.3g')} mm³/J")
    return (f"k_m = {_number(res, 'moving_wear_coefficient', '.3g')}, k_s = "
            f"{_number(res, 'stationary_wear_coefficient', '.3g')} 1/MPa")


def _percent(v: float) -> str:
    """A relative error as a percentage with two significant figures (0.031 %, not 0.0 %)."""
    return f"{v * 100:.2g} %"


def _shown(unit: str) -> str:
    """A unit as the files write it (um, mm^3, mm3) as a figure shows it (µm, mm³)."""
    return shown_unit(unit)


def _unit(res: Results, key: str) -> str:
    return _shown(res.units.get(key, ""))


MAX_PROFILES = 6  # labelled profiles a panel draws at most: beyond, the legend and the colours stop reading


def shown_states(count: int, most: int = MAX_PROFILES) -> np.ndarray:
    """Which of ``count`` recorded states a profile panel draws: all of them up to ``most``, else ``most`` spread
    evenly over the record, the first and the last among them (snapshots at 0, 10, 100, 1000 … keep their
    spacing, which the user chose)."""
    if count <= most:
        return np.arange(count)
    return np.unique(np.round(np.linspace(0, count - 1, most)).astype(int))


def state_colours(count: int) -> list:
    """A sequential order: the first state light, the last dark (viridis, perceptually ordered, and ordered in
    grey when printed so); its palest yellow left out, which vanished on white."""
    cmap = plt.get_cmap("viridis")
    return [cmap(v) for v in (np.linspace(0.85, 0.05, count) if count > 1 else [0.05])]


def _snapshot_lines(ax, x, curves, labels, sign=1.0) -> int:
    """One line per shown recorded state (at most MAX_PROFILES, coloured in order); returns how many are shown."""
    shown = shown_states(len(curves))
    for k, colour in zip(shown, state_colours(len(shown))):
        ax.plot(x, sign * curves[k], color=colour, lw=1.4, label=labels[k])
    return len(shown)


def _profile_figure(three_d: bool):
    """Two panels a row (one row in 2D, two in 3D) and, right of them, a column for the legend of the recorded
    states: inside a panel of nested profiles it lay over them."""
    rows = 2 if three_d else 1
    fig = plt.figure(figsize=(12.5, 7.5 if three_d else 4.2))
    gs = fig.add_gridspec(rows, 3, width_ratios=[1, 1, 0.5])
    axes = np.array([[fig.add_subplot(gs[r, c]) for c in range(2)] for r in range(rows)])
    key = fig.add_subplot(gs[:, 2])
    key.set_axis_off()
    return fig, axes, key


def _state_legend(key, ax, shown: int, recorded: int) -> None:
    """The legend of ``ax``'s lines in the legend column, saying how many of the recorded states it shows."""
    title = "recorded states" + (f" ({shown} of {recorded} shown)" if shown < recorded else "")
    key.legend(*ax.get_legend_handles_labels(), loc="upper left", fontsize=8, title=title, title_fontsize=8)


_SUPERSCRIPT = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")


def cycles_tick(v: float) -> str:
    """A cycle count on an axis as it reads: 20 000 up to 10⁵, then 2.5×10⁸ and 10⁹ (a service life's
    1000000000 was a row of zeros to count)."""
    if abs(v) < 1e5:
        return f"{v:,.0f}".replace(",", " ")
    exponent = int(math.floor(math.log10(abs(v))))
    mantissa = round(v / 10 ** exponent, 2)
    if abs(mantissa) >= 10:
        mantissa, exponent = mantissa / 10, exponent + 1
    power = "10" + str(exponent).translate(_SUPERSCRIPT)
    return power if mantissa == 1 else f"{mantissa:g}×{power}"


def _cycles_label(n: int) -> str:
    return f"N = {n:,}".replace(",", " ")


HOURS_PER_YEAR = 8766.0  # a Julian year, as `run`'s summary and the sweep's histogram count years


def time_unit(cycles: float, frequency: float) -> tuple[str, float]:
    """The unit a run of ``cycles`` at ``frequency`` (Hz) reads best in, and the cycles in one of it: minutes
    below an hour of continuous fretting, hours below a year, years from one (a wall limit at 1.09 years reads
    1.09 years, one at 0.195 years 1 710 h)."""
    per_hour = frequency * 3600.0
    if cycles < per_hour:
        return "min", frequency * 60.0
    if cycles < per_hour * HOURS_PER_YEAR:
        return "h", per_hour
    return "years", per_hour * HOURS_PER_YEAR


def _run_time(res: Results) -> Optional[tuple[float, str, float]]:
    """(frequency Hz, unit, cycles per unit) for the run's time axis and labels, or None without a frequency;
    the unit chosen once for the run's length, so every figure of a run reads time alike."""
    f = res.frequency()
    if f is None:
        return None
    last = max([float(c[-1]) for c in (res.history.get("cycle"), res.fields.get("cycle")) if c is not None and
                len(c)] + [0.0])
    unit, per = time_unit(last, f)
    return f, unit, per


def _duration(value: float, unit: str) -> str:
    """A time in its unit as it reads: 1 710 h, 0.195 years, 12.5 min."""
    number = f"{value:,.0f}".replace(",", " ") if abs(value) >= 100 else f"{value:.3g}"
    return f"{number} {unit}"


def _state_label(n: float, time: Optional[tuple]) -> str:
    """A recorded state: its cycle as the axes read it (N = 20 000, N = 1.5×10⁸), and its time where the run has
    one (``time``: :func:`_run_time`)."""
    label = f"N = {cycles_tick(n)}"
    return label if time is None else f"{label}, {_duration(n / time[2], time[1])}"


def _builders(res: Results, log_cycles: bool) -> dict:
    """name → a function drawing that figure, for what the file holds (a contact-only run has no wear figures)."""
    if res.fields.get("cycle") is None or res.fields["cycle"].size == 0:
        raise ResultsFileError(f"{res.path} has no snapshot fields to plot (status {res.status})")
    out = {"pressure_profiles": lambda: _pressure(res)}
    if (res.fields["cycle"] > 0).any():
        out["wear_profiles"] = lambda: _profiles(res)
    if (res.history["cycle"] > 0).any():  # every accepted step is in the history, recorded states or not
        out["history"] = lambda: _history(res, log_cycles)
    if res.y.size > 1:
        out["maps"] = lambda: _maps(res)
    if res.fretting_loop.get("displacement") is not None and res.fretting_loop["displacement"].size:
        out["fretting"] = lambda: _fretting(res)
    if _dissipates(res.history):  # a run with a friction coefficient (format 1.5 on)
        out["energy_wear"] = lambda: _energy_wear(res)
    for body, name in (("stationary", "fatigue"), ("moving", "fatigue_moving")):  # each body's, where it has one
        if res.fatigue(body).get("swt") is not None and res.fatigue(body)["swt"].size:
            out[name] = lambda body=body: _fatigue(res, body)
    return out


def skipped(res: Results) -> list[str]:
    """What the file cannot draw, and why (for the CLI to say, not to leave out silently)."""
    out = []
    if not (res.fields["cycle"] > 0).any():
        last = int(res.history["cycle"][-1]) if res.history["cycle"].size else 0
        out.append(f"no wear profiles: the file's only recorded state is cycle 0 (status {res.status}, its last "
                   f"step cycle {last}); recorded states are the case's output.snapshots and the last cycle")
    if res.y.size == 1:
        out.append("no maps: a 2D run has one row")
    return out


def figures(res: Results, log_cycles: bool = False, names=None) -> dict:
    """name → matplotlib Figure (all, or those in ``names``), for what the file holds."""
    out = {name: build() for name, build in _builders(res, log_cycles).items() if names is None or name in names}
    title = title_block(res)
    for name, fig in out.items():
        fig.suptitle(title, fontsize=9)
        # fixed margins: a layout engine redraws every figure several times (twice the time, measured)
        # the panels' rows (a colorbar's own axes is not a row: counted as one, it took the bottom margin of two
        # rows and the 3D fretting figure's x labels fell off the canvas)
        specs = [ax.get_subplotspec() for ax in fig.axes if ax.get_subplotspec()]
        rows = specs[0].get_gridspec().nrows if specs else 1
        # a cycles axis on top (the history's, under a time axis) takes its tick labels and label there
        above = 0.5 if any(ax.xaxis.get_label_position() == "top" for ax in fig.axes) else 0.0
        top = 1 - (0.45 + above + 0.18 * (1 + title.count("\n"))) / fig.get_figheight()
        fig.subplots_adjust(left=0.07 if name != "maps" else 0.05, right=0.97 if name != "maps" else 0.95,
                            bottom=0.09 if rows > 1 else 0.14, top=top, hspace=0.42,
                            wspace=0.22 if name != "maps" else 0.08)
    return out


def _savefig(fig, path, dpi: int, fmt: Optional[str] = None) -> None:
    """fig.savefig; a PNG with zlib's fastest level: a third of a figure's time was the default level's
    compression, for files 8 % smaller (measured on a 3D run's four figures)."""
    fmt = fmt or Path(path).suffix.lstrip(".") or "png"
    fig.savefig(path, dpi=dpi, format=fmt, **({"pil_kwargs": {"compress_level": 1}} if fmt == "png" else {}))


# figures drawn by the forked helper: together about as long to render as the others (measured on a 3D file)
_FORKED = ("wear_profiles", "maps", "fretting")


def plot_all(res: Results, outdir: str | Path, fmt: str = "png", dpi: int = 150, log_cycles: bool = False,
             jobs: int = 2) -> list[Path]:
    """Save every figure; with ``jobs`` > 1, half of them in a forked process (rendering is most of the time).

    A helper that fails (or a platform without fork) leaves its figures to this process, so an error surfaces
    here with its own message and type.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    stem = Path(res.path).stem
    names = list(_builders(res, log_cycles))
    paths = {name: outdir / f"{stem}_{name}.{fmt}" for name in names}

    def save(subset):
        for name in subset:
            fig = figures(res, log_cycles, (name,))[name]
            # a figure appears whole or not at all: a full disk never leaves a truncated one over a good one
            tmp = outdir / f".{paths[name].name}.{os.getpid()}.tmp"
            try:
                _savefig(fig, tmp, dpi, fmt)
                os.replace(tmp, paths[name])
            finally:
                plt.close(fig)
                tmp.unlink(missing_ok=True)

    # fork only a single-threaded process: a lock held by another thread would stay locked in the child
    helper = [n for n in names if n in _FORKED] if jobs > 1 and hasattr(os, "fork") \
        and threading.active_count() == 1 else []
    if not helper or len(helper) == len(names):
        save(names)
        return [paths[n] for n in names]
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            save(helper)
            code = 0
        finally:
            os._exit(code)  # the helper never returns into the caller's code
    try:
        save([n for n in names if n not in helper])
    finally:
        _, status = os.waitpid(pid, 0)
    if status != 0:
        save(helper)
    return [paths[n] for n in names]


EXPECTED_MARKERS = {"experiment": "o", "fea": "s", "paper": "^"}


def run_status(res: Results) -> str:
    """How far a run that did not complete got ("interrupted at cycle 1 200 of 500 000"), "" for a complete one:
    an overlay draws every file alike, and a run cut short looks like one with less wear."""
    if res.status == "complete":
        return ""
    cycles = res.history.get("cycle")
    reached = int(cycles[-1]) if cycles is not None and len(cycles) else 0
    asked = _float(res, "cycles")
    where = f"at cycle {reached:,}".replace(",", " ") + (f" of {asked:,.0f}".replace(",", " ") if asked else "")
    said = {"interrupted": "interrupted", "failed": "failed", "stopped": "stopped at a physical limit",
            "running": "unfinished (status running: still running, or killed)"}
    return f"{said.get(res.status, f'status {res.status!r}')} {where}"


LABEL_WIDTH = 48  # characters of a legend line at fontsize 7 that keep a legend within an overlay's panel
LABEL_KEYS = 3  # differing values a label names; the rest are counted ("+2 more")
VALUE_WIDTH = 24  # characters of a value in a label (a load history's blocks are a long list)


def run_labels(results: list) -> list[str]:
    """A legend label per run, saying what tells it apart from the others (a file name alone said nothing):
    the ``--set`` values that differ (as written where every run set the key, else each run's value from its
    filled case); else the case's own values that differ (another case file or an edited one; the automatic
    choices they lead to are left out); else the automatic choices that differ.  The case's name where the cases
    differ or nothing else does, the file's name in brackets, and how far a run that did not complete got
    (:func:`run_status`); at most LABEL_KEYS values, in lines of at most LABEL_WIDTH characters."""
    return [_fill(chunks) for chunks in _label_chunks(results)]


def _label_chunks(results: list) -> list[list]:
    """Each run's label as (separator, text) pieces, for :func:`_fill` to break into lines between them."""
    cases = [_case_values(r) for r in results]
    asked = [_asked(r) for r in results]
    names = [str(r.attrs.get("case_name", "")) for r in results]
    automatic = {str(k) for r in results for k, _, why in r.choices if not str(why).startswith("given")}

    def canonical(i, k):  # the filled case's value (one spelling: 25 um and 0.025 mm are the same stroke)
        return cases[i].get(k, asked[i].get(k))

    keys = list(dict.fromkeys([k for a in asked for k in a] + [k for c in cases for k in c]))
    differ = [k for k in keys if len({canonical(i, k) for i in range(len(results))}) > 1]
    given = [k for k in differ if any(k in a for a in asked)]
    own = [k for k in differ if k not in given and k not in automatic]
    named = len(set(names)) > 1
    shown = given if named else (given + own or [k for k in differ if k not in given])
    short = _short_keys(shown)
    # as written where every run set it; else each run's filled value, in one spelling (not 10 um beside 0.025 mm)
    written = {k: all(k in a for a in asked) for k in shown}
    out = []
    for i, res in enumerate(results):
        chunks = [(", ", names[i])] if named or not shown else []
        for k in shown[:LABEL_KEYS]:
            value = asked[i][k] if written[k] else canonical(i, k) or "–"
            chunks.append((", ", f"{short[k]}={_excerpt(value, VALUE_WIDTH)}"))
        if len(shown) > LABEL_KEYS:
            chunks.append((", ", f"+{len(shown) - LABEL_KEYS} more"))
        status = run_status(res)
        stem = _excerpt(Path(res.path).stem, VALUE_WIDTH)
        chunks += [(" ", f"({stem}" + ("," if status else ")"))] + ([(" ", f"{status})")] if status else [])
        out.append(chunks)
    return out


def _fill(chunks: list, width: int = LABEL_WIDTH) -> str:
    """Join (separator, text) pieces into lines of at most ``width`` characters, breaking only between pieces (a
    value, a number and its unit, a run's status stay whole: a piece longer than ``width`` makes a line of its
    own)."""
    lines: list = []
    for i, (sep, text) in enumerate(chunks):
        length = len(lines[-1]) + len(sep) + len(text) if lines else 0
        after = chunks[i + 1] if i + 1 < len(chunks) else ("", "")
        ends = "," in after[0] and length + len(after[0]) + len(after[1]) > width  # the line would end ", "
        if lines and length + ends <= width:
            lines[-1] += sep + text
        else:
            if lines:
                lines[-1] += sep.rstrip()  # a comma stays at the end of its line
            lines.append(text)
    return "\n".join(lines)


def _case_values(res: Results) -> dict:
    """The filled case stored in the file as dotted key → value as text (its name and published values aside)."""
    return {k: _as_text(v) for k, v in res.case_values().items()}


def _asked(res: Results) -> dict:
    """The run's --set overrides, key → value as written (the last of a key wins, as when the run read them)."""
    out = {}
    for item in res.overrides:
        key, sep, value = str(item).partition("=")
        if sep:
            out[key.strip()] = value.strip()
    return out


def _as_text(value) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_as_text(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_as_text(v) for v in value) + "]"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return f"{value:g}"
    return _tidy(str(value))


def _tidy(text: str) -> str:
    """A number as it reads: 185.0 N as 185 N, 1.0e-05 as 1e-05."""
    number, sep, unit = text.partition(" ")
    try:
        return f"{float(number):g}{sep}{unit}" if number.strip() else text
    except ValueError:
        return text


def _excerpt(text: str, width: int) -> str:
    return text if len(text) <= width else text[:width - 1] + "…"


def _short_keys(keys: list) -> dict:
    """Each dotted key by its shortest tail that no other of ``keys`` ends with (normal_load;
    moving.wear_coefficient beside stationary.wear_coefficient; loading.stroke beside model.stroke)."""
    out = {}
    for k in keys:
        parts = k.split(".")
        for n in range(1, len(parts) + 1):
            tail = ".".join(parts[-n:])
            if not any(o != k and (o == tail or o.endswith("." + tail)) for o in keys):
                break
        out[k] = tail
    return out


def overlay(results: list, expected: bool = False):
    """Several runs on one figure, as the paper compares RT with 90 °C and runs with and without jumping: the
    final worn profiles of both bodies across the contact, and each body's maximum depth against cycles; with
    ``expected``, each case's published values (experiment, FEA, the paper) as markers."""
    fig, axes = plt.subplots(2, 2, figsize=(12, 8), squeeze=False)
    shown = set()  # published values are the case's: drawn once per case, in black
    for k, (res, chunks) in enumerate(zip(results, _label_chunks(results))):
        label = _fill(chunks)
        colour = f"C{k % 10}"
        last = len(res.fields["cycle"]) - 1
        at = _fill(chunks + [(", ", _cycles_label(res.fields["cycle"][last]))])
        for col, body in enumerate(("stationary", "moving")):
            row = centre_line(res.fields[f"wear_depth_{body}"][last])
            axes[0, col].plot(res.x, -row, color=colour, label=at)
            axes[1, col].plot(res.history["cycle"], res.history[f"max_wear_depth_{body}"], color=colour,
                              marker=".", ms=3, label=label)
        name = res.attrs.get("case_name", "")
        if expected and name not in shown:
            shown.add(name)
            for source, (depth, width) in res.published().items():
                m = EXPECTED_MARKERS.get(source, "x")
                text = f"{source}, {name}: " + ", ".join(
                    t for t in (f"{depth:.3g} µm deep" if depth is not None else "",
                                f"scar {width:.3g} mm" if width is not None else "") if t)
                if depth is not None:
                    axes[0, 0].plot([0.0], [-depth], m, color="k", mfc="none", ms=8, label=text)
                    axes[1, 0].plot([res.fields["cycle"][last]], [depth], m, color="k", mfc="none", ms=8, label=text)
                if width is not None:  # the scar's edges, at the surface
                    axes[0, 0].plot([-width / 2, width / 2], [0.0, 0.0], m, color="k", mfc="none", ms=8,
                                    label=None if depth is not None else text)
    units = _unit(results[0], "fields/wear_depth_stationary")
    for col, body in enumerate(("stationary", "moving")):
        axes[0, col].set_xlabel("x, sliding direction (mm)")
        axes[0, col].set_ylabel(f"worn profile at y = 0, −depth ({units})")
        axes[0, col].set_title(f"{body} body, last recorded state")
        axes[1, col].set_xlabel("cycles")
        axes[1, col].set_ylabel(f"maximum depth ({units})")
        axes[1, col].set_title(f"{body} body, every accepted step")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    names = {str(r.attrs.get("case_name", "")) for r in results}
    of = f" of {names.pop()}" if len(names) == 1 else ""  # one case: its name here, what differs in the legends
    fig.suptitle(f"{len(results)} run{'s' if len(results) > 1 else ''}{of} overlaid"
                 + ("; markers: published values (case `expected:`)" if expected else ""), fontsize=9)
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.07, top=0.93, hspace=0.32, wspace=0.22)
    return fig


def plot_overlay(results: list, outdir: str | Path, expected: bool = False, fmt: str = "png",
                 dpi: int = 150) -> list[Path]:
    """Save :func:`overlay` as OUTDIR/overlay.FMT, whole or not at all."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    path = outdir / f"overlay.{fmt}"
    tmp = outdir / f".overlay.{os.getpid()}.tmp"
    fig = overlay(results, expected)
    try:
        _savefig(fig, tmp, dpi, fmt)
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        if tmp.exists():
            tmp.unlink()
    return [path]


def published_profiles(panels: list, path: str | Path) -> Path:
    """A panel per case: a worn flat across the contact and its published depth and width as markers.
    ``panels``: (title, x mm, depth µm, {source: (depth µm, width mm)}[, the moving body's depth µm]).  For the
    validation report."""
    path = Path(path)
    cols = min(4, len(panels))
    rows = -(-len(panels) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3.2 * rows), squeeze=False)
    for ax, (title, x, depth, published, *moving) in zip(axes.ravel(), panels):
        ax.plot(x, [-v for v in depth], "C0-", label="fretsim" if not moving else "fretsim, flat")
        if moving:
            ax.plot(x, [-v for v in moving[0]], "C1--", label="fretsim, moving body")
        for source, (d, w) in published.items():
            m = EXPECTED_MARKERS.get(source, "x")
            if d is not None:
                ax.plot([0.0], [-d], m, color="k", mfc="none", label=source)
            if w is not None:
                ax.plot([-w / 2, w / 2], [0.0, 0.0], m, color="k", mfc="none", label=None if d is not None else source)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("x (mm)", fontsize=8)
        ax.set_ylabel("−depth (µm)", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    fig.tight_layout()
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        _savefig(fig, tmp, 110, "png")
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        if tmp.exists():
            tmp.unlink()
    return path


def _profiles(res: Results):
    """Wear profiles of both bodies at the worn recorded states (up to MAX_PROFILES of them, spread over the
    record, light to dark): across the contact (y = 0) and, in 3D, along it."""
    cycles = res.fields["cycle"]
    worn = np.flatnonzero(cycles > 0)
    three_d = res.y.size > 1
    fig, axes, key = _profile_figure(three_d)
    time = _run_time(res)
    labels = [_state_label(cycles[k], time) for k in worn]
    unit = _unit(res, "fields/wear_depth_moving")
    for col, body in enumerate(("moving", "stationary")):
        data = res.fields[f"wear_depth_{body}"]
        ax = axes[0, col]
        shown = _snapshot_lines(ax, res.x, [centre_line(data[k]) for k in worn], labels, sign=-1.0)
        ax.set_xlabel("x, sliding direction (mm)")
        ax.set_ylabel(f"worn profile, −depth ({unit})")
        ax.set_title(f"{body} body, across the contact (y = 0)")
        if three_d:
            ax = axes[1, col]
            last = data[worn[-1]]
            ix = int(np.argmax(centre_line(last)))
            _snapshot_lines(ax, res.y, [data[k][:, ix] for k in worn], labels, sign=-1.0)
            ax.set_xlabel("y, across the sliding direction (mm)")
            ax.set_ylabel(f"worn profile, −depth ({unit})")
            ax.set_title(f"{body} body, along the contact (x = {res.x[ix]:.3g} mm)")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    _state_legend(key, axes[0, 1], shown, len(worn))
    return fig


def hertz_profile(res: Results, x: np.ndarray) -> np.ndarray | None:
    """The initial Hertz pressure along x (y = 0), from the inputs recorded in the file."""
    a = _float(res, "hertz_half_width_x")
    p0 = _float(res, "hertz_peak_pressure")
    if a is None or p0 is None or a <= 0:
        return None
    return p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))


def _pressure(res: Results):
    """Pressure at the recorded states (up to MAX_PROFILES) along y = 0 (moving body, stroke average) and, in 3D,
    along x = 0; the N = 0 curve is overlaid by Hertz's solution.  The scale follows the worn states: an unworn
    peak far above them is cut off and labelled, instead of squashing them."""
    cycles = res.fields["cycle"]
    three_d = res.y.size > 1
    fig, axes, key = _profile_figure(three_d)
    time = _run_time(res)
    labels = [_state_label(c, time) for c in cycles]
    unit = _unit(res, "fields/pressure")
    worn = cycles > 0
    hertz = hertz_profile(res, res.x)
    for col, (name, what) in enumerate((("pressure", "moving body (mid-stroke)"),
                                        ("pressure_stationary_average", "stationary body (stroke average)"))):
        data = res.fields[name]
        ax = axes[0, col]
        rows = [centre_line(d) for d in data]
        shown = _snapshot_lines(ax, res.x, rows, labels)
        if name == "pressure" and hertz is not None and 0 in cycles and _input(res, "hertz_line_contact", 1) in (1, 0):
            ax.plot(res.x, hertz, "k:", lw=1.0, label="Hertz (N = 0)")
        if worn.any() and (~worn).any():
            top = 1.25 * max(r.max() for r, w in zip(rows, worn) if w)
            peak = max(r.max() for r, w in zip(rows, worn) if not w)
            if peak > top:
                ax.set_ylim(0, top)
                ax.annotate(f"N = 0 peak {peak:.4g} {unit} (off scale)", xy=(0.02, 0.95), xycoords="axes fraction",
                            fontsize=8, va="top")
        ax.set_xlabel("x, sliding direction (mm)")
        ax.set_ylabel(f"contact pressure ({unit})")
        ax.set_title(f"{what}, y = 0")
        if three_d:
            ax = axes[1, col]
            ix = res.x.size // 2
            along = [d[:, ix] for d in data]
            _snapshot_lines(ax, res.y, along, labels)
            if worn.any() and (~worn).any():  # clipped as across x: the unworn peak would flatten the worn curves
                top = 1.25 * max(r.max() for r, w in zip(along, worn) if w)
                peak = max(r.max() for r, w in zip(along, worn) if not w)
                if peak > top:
                    ax.set_ylim(0, top)
                    ax.annotate(f"N = 0 peak {peak:.4g} {unit} (off scale)", xy=(0.02, 0.95),
                                xycoords="axes fraction", fontsize=8, va="top")
            ax.set_xlabel("y, across the sliding direction (mm)")
            ax.set_ylabel(f"contact pressure ({unit})")
            short = what.split(" (")[0]
            ax.set_title(f"{short}, along y at x = {res.x[ix]:.3g} mm")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    _state_legend(key, axes[0, 0], shown, len(cycles))
    return fig


def _nice_levels(vmax: float) -> np.ndarray:
    """Contour levels at round values from 0 to at least ``vmax`` (ticks like 0, 0.5, 1 … not 0.462, 14.77 …)."""
    if not vmax > 0:
        return np.linspace(0.0, 1.0, 11)
    ticks = MaxNLocator(nbins=10, steps=[1, 2, 2.5, 5, 10]).tick_values(0.0, vmax)
    ticks = ticks[ticks >= 0]
    return ticks if ticks[-1] >= vmax else np.append(ticks, ticks[-1] + (ticks[1] - ticks[0]))


def _maps(res: Results):
    """Final wear of each body on its own colour scale (an aluminium ball's 98.5 µm no longer darkens a steel
    flat's 4.9 µm), and the final pressure; round contour levels; a note where x and y are drawn to different
    scales."""
    cycles = res.fields["cycle"]
    last = len(cycles) - 1
    wear = [res.fields[f"wear_depth_{b}"][last] for b in ("moving", "stationary")]
    fig = plt.figure(figsize=(16, 4.8))
    gs = fig.add_gridspec(1, 8, width_ratios=[1, 0.045, 0.3, 1, 0.045, 0.3, 1, 0.045], wspace=0.08)
    axes = [fig.add_subplot(gs[0, i]) for i in (0, 3, 6)]
    bars = [fig.add_subplot(gs[0, i]) for i in (1, 4, 7)]
    unit = _unit(res, "fields/wear_depth_moving")
    for ax, bar, body, w in zip(axes[:2], bars[:2], ("moving", "stationary"), wear):
        cs = ax.contourf(res.x, res.y, w, levels=_nice_levels(float(w.max())), cmap="viridis", extend="neither")
        ax.set_title(f"{body} body wear, {_cycles_label(cycles[last])} (max {float(w.max()):.3g} {unit})")
        fig.colorbar(cs, cax=bar, label=f"wear depth ({unit}), this body's scale")
    p = res.fields["pressure"][last]
    pc = axes[2].contourf(res.x, res.y, p, levels=_nice_levels(float(p.max())), cmap="magma")
    fig.colorbar(pc, cax=bars[2], label=f"contact pressure ({_unit(res, 'fields/pressure')})")
    axes[2].set_title(f"pressure on the moving body, {_cycles_label(cycles[last])}")
    lx = float(res.x[-1] - res.x[0]) if res.x.size > 1 else 1.0
    ly = float(res.y[-1] - res.y[0]) if res.y.size > 1 else 0.0
    for ax in axes:
        ax.set_xlabel("x, sliding direction (mm)")
        ax.xaxis.set_major_locator(MaxNLocator(5))
        ax.set_ylabel("y (mm)")
    if ly > 0 and not 0.5 < ly / lx < 2:
        fig.text(0.5, 0.005, f"x and y are drawn to different scales: the maps span {lx:.3g} mm along x and "
                             f"{ly:.3g} mm along y ({max(ly / lx, lx / ly):.0f}:1)", ha="center", fontsize=8)
    return fig


def _history(res: Results, log_cycles: bool):
    """Maximum depth and wear volume against cycles (and, with loading.frequency, time), a marker at each solve,
    Archard's volume line, the load blocks, the case's wear limits and where the run stopped at one."""
    h = res.history
    n = h["cycle"]
    time = _run_time(res)
    # a time axis below and the cycles above take half an inch more: the panels keep their height
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4 if time is None else 4.9))
    curves = {}  # history entry → its line, for the limits drawn beside them
    ax = axes[0]
    for (name, label), ls in zip((("max_wear_depth_total", "total"), ("max_wear_depth_stationary", "stationary"),
                                  ("max_wear_depth_moving", "moving")), STYLES):
        curves[name], = ax.plot(n, h[name], ls=ls, marker="o", ms=2.5, lw=1.3, label=label)
    ax.set_ylabel(f"maximum wear depth ({_unit(res, 'history/max_wear_depth_total')})")
    ax = axes[1]
    for (name, label, key), ls in zip((("wear_volume_moving", "moving", "moving_wear_coefficient"),
                                       ("wear_volume_stationary", "stationary", "stationary_wear_coefficient")),
                                      STYLES):
        line, = ax.plot(n, h[name], ls=ls, marker="o", ms=2.5, lw=1.3, label=label)
        curves[name] = line
        _archard_line(res, ax, n, line, label, key)
    ax.set_ylabel(f"wear volume ({_unit(res, 'history/wear_volume_moving')})")
    _mark_blocks(res, axes)
    _mark_limits(res, axes, curves, time)
    for ax in axes:
        ax.set_xlabel("cycles N (–)")
        if log_cycles:
            ax.set_xscale("log")
        else:
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: cycles_tick(v)))
            ax.tick_params(axis="x", labelrotation=20)
        if time is not None:
            _time_axis(ax, time)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    axes[0].set_title("maximum wear depth (a marker per contact solve)")
    axes[1].set_title("wear volume against its invariant")
    return fig


def _archard_line(res: Results, ax, n, line, label: str, key: str) -> None:
    """The volume's invariant beside the volume: Σk·P·4δ·N over a load history's blocks, k·Σp|ds|A (α·ΣW) with
    friction, or k·P·4δ·N."""
    h = res.history
    k, load, stroke = _float(res, key), _float(res, "normal_load"), _float(res, "stroke")
    energy_law = _input(res, "wear_law") == "energy"
    if energy_law:
        k = _float(res, key.replace("wear_coefficient", "energy_wear_coefficient"))
        k = None if k is None else k * 1e-3  # mm³/J → mm³/(N·mm)
    work = h.get("wear_work")
    blocks = h.get("block")
    history = blocks is not None and len(np.unique(blocks)) > 1
    if k is not None and work is not None and np.isfinite(work).all() and history and not energy_law:
        ax.plot(n, k * work, color=line.get_color(), lw=0.8, alpha=0.6, ls=(0, (1, 2)),
                label=f"Archard Σk·P·4δ·N over the blocks, {label}")
    elif k is not None and work is not None and np.isfinite(work).all() and _input(res, "slip_model") == "coulomb":
        ax.plot(n, k * work, color=line.get_color(), lw=0.8, alpha=0.6, ls=(0, (1, 2)),
                label=f"{'α·ΣW' if energy_law else 'k·Σp|ds|A'}, {label}")
    elif None not in (k, load, stroke) and not energy_law:
        archard = k * load * 4 * stroke * 1e-3 * n
        ax.plot(n, archard, color=line.get_color(), lw=0.8, alpha=0.6, ls=(0, (1, 2)),
                label=f"Archard k·P·4δ·N, {label}")


def _time_axis(ax, time: tuple) -> None:
    """Time of continuous fretting below the panel, the cycles (the data's own axis) moved above it."""
    frequency, unit, per = time
    ax.xaxis.tick_top()
    ax.xaxis.set_label_position("top")
    below = ax.secondary_xaxis("bottom", functions=(lambda c: np.asarray(c) / per, lambda t: np.asarray(t) * per))
    below.set_xlabel(f"time of continuous fretting at {frequency:g} Hz ({unit})")


MAX_BLOCK_LINES = 60  # beyond, the boundaries would be a grey wash: said in the legend instead


def _mark_blocks(res: Results, axes) -> None:
    """A load history's block boundaries (thin vertical lines)."""
    h = res.history
    blocks = h.get("block")
    if blocks is not None and len(np.unique(blocks)) > 1:
        ends = h["cycle"][:-1][np.diff(blocks) != 0]
        shown = ends if len(ends) <= MAX_BLOCK_LINES else ends[:0]
        for ax in axes:
            for i, c in enumerate(shown):
                ax.axvline(c, color="0.6", lw=0.6, ls="--", label="block boundaries" if i == 0 else None)
            if len(ends) > MAX_BLOCK_LINES:
                ax.plot([], [], " ", label=f"{len(ends) + 1} load blocks (boundaries not drawn)")


LIMIT_OFF_SCALE = 2.0  # a limit not reached is drawn up to this many times the panel's data; beyond, only named


def _limit_on_panel(res: Results, key: str, value: float) -> Optional[tuple[str, float, str]]:
    """(the history entry beside which a wear limit is drawn, the limit in that entry's unit, its legend text),
    or None for a limit no panel shows (centre-line depths, scar widths) or a tube's wall the file lacks."""
    from fretsim.quantities import WEAR
    if key == "wall_loss":
        outer, inner = _float(res, "geometry_outer_radius"), _float(res, "geometry_inner_radius")
        if outer is None or inner is None:
            return None
        depth = value * (outer - inner) * 1e3
        return ("max_wear_depth_moving", depth,
                f"limit wall_loss: {value * 100:.3g} % of the {outer - inner:.3g} mm wall ({depth:.4g} µm)")
    if key not in ("max_wear_depth_moving", "max_wear_depth_stationary", "wear_volume_moving",
                   "wear_volume_stationary"):
        return None
    shown = value * WEAR[key].factor
    return key, shown, f"limit {key}: {shown:.4g} {_unit(res, 'history/' + key)}"


def _mark_limits(res: Results, axes, curves: dict, time: Optional[tuple]) -> None:
    """Each of the case's wear limits as a horizontal line on the panel of its quantity (in that quantity's
    colour; a limit far above what the run reached only named), and where the run stopped at one: a vertical
    line through both panels, labelled with the cycle (and time), and a ring where the quantity meets its limit.
    The label is the legend's: wear grows, so the stop's neighbourhood holds the curves' ends and no room."""
    reached = res.summary.get("limit_reached") or ""
    limits = res.wear_limits()
    for key, (value, _) in limits.items():
        on_panel = _limit_on_panel(res, key, value)
        if on_panel is None:
            continue
        name, level, text = on_panel
        line = curves[name]
        ax = line.axes
        ys = [np.asarray(c.get_ydata(), float) for c in curves.values() if c.axes is ax]
        top = max((float(np.nanmax(y)) for y in ys if np.isfinite(y).any()), default=0.0)
        if key == reached or level <= LIMIT_OFF_SCALE * top:
            ax.axhline(level, color=line.get_color(), lw=1.2, ls=(0, (4, 2)), label=text)
        else:
            ax.plot([], [], " ", label=f"{text}, above the scale")
    if not reached:
        return
    n = float(res.summary["cycles_to_limit"])
    when = _cycles_label(round(n)) + (f", {_duration(n / time[2], time[1])}" if time is not None else "")
    for ax in axes:
        ax.axvline(n, color="C3", lw=1.0, label=f"{reached} limit reached: {when}")
    on_panel = _limit_on_panel(res, reached, limits[reached][0]) if reached in limits else None
    if on_panel is not None:  # a ring where the quantity meets its limit
        curves[on_panel[0]].axes.plot([n], [on_panel[1]], "o", mfc="none", mec="C3", ms=9, mew=1.5)


def _loop_facts(res: Results) -> str:
    """What an engineer reads off a fretting loop, stated: the regime, μ, Q*/μP, δ_t and the energy per cycle."""
    s, mu, load = res.summary, _float(res, "friction_coefficient"), _float(res, "normal_load")
    lines = [f"regime: {str(s.get('regime', '?')).replace('_', ' ')}" + (f", μ = {mu:.3g}" if mu is not None else "")]
    q_star = s.get("tangential_force_amplitude_N")
    if q_star is not None and mu and load:
        lines.append(f"Q*/μP = {float(q_star) / (mu * load):.3g} (Q* = {float(q_star):.4g} N)")
    d_t = s.get("gross_slip_stroke_um")
    if d_t is not None and np.isfinite(float(d_t)):
        lines.append(f"gross slip from δ_t = {float(d_t):.3g} µm (unworn)")
    energy = s.get("dissipated_energy_per_cycle_J")
    if energy is not None and np.isfinite(float(energy)):
        lines.append(f"energy {float(energy) * 1e3:.4g} mJ per cycle")
    return "\n".join(lines)


def _fretting(res: Results):
    """The fretting loop at each snapshot, the slip distance per cycle of both bodies across the contact, and
    where the contact sticks: the shear traction against μp along y = 0 (2D) or the moving body's slip map (3D)."""
    loop = res.fretting_loop
    cycles = loop["cycle"]
    three_d = res.y.size > 1
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4))
    ax = axes[0]
    for k, c in enumerate(cycles):
        u, q = loop["displacement"][k], loop["tangential_force"][k]
        ok = np.isfinite(u) & np.isfinite(q)
        ax.plot(u[ok], q[ok], ls=STYLES[k % len(STYLES)], marker=".", ms=3, lw=1.2, label=_cycles_label(c))
    ax.set_xlabel(f"applied displacement ({_unit(res, 'fretting_loop/displacement')})")
    ax.set_ylabel(f"tangential force Q ({_unit(res, 'fretting_loop/tangential_force')})")
    ax.set_title("fretting loop")
    ax.legend(fontsize=8, loc="lower right")
    ax.text(0.5, 0.5, _loop_facts(res), transform=ax.transAxes, va="center", ha="center", fontsize=8,
            bbox=dict(boxstyle="round", fc="white", ec="0.7", alpha=0.9))
    ax = axes[1]
    last = len(res.fields["cycle"]) - 1
    unit = _unit(res, "fields/slip_distance_moving")
    for body, ls in (("moving", "-"), ("stationary", "--")):
        ax.plot(res.x, centre_line(res.fields[f"slip_distance_{body}"][last]), ls=ls, lw=1.3, label=f"{body} body")
    stroke = _float(res, "stroke")
    if stroke is not None:
        ax.axhline(4 * stroke, color="k", lw=0.8, ls=":", label="4δ (uniform slip)")
    ax.set_xlabel("x, sliding direction (mm)")
    ax.set_ylabel(f"slip distance per cycle ({unit})")
    ax.set_title(f"slip, y = 0, {_cycles_label(res.fields['cycle'][last])}")
    ax.legend(fontsize=8)
    ax = axes[2]
    if three_d:
        slip = res.fields["slip_distance_moving"][last]
        # from stuck (0) to the whole stroke (4δ): scaled to the data, a gross-slip map's 0.5 % variation took the
        # full colour range and read as stick and slip
        top = max(4 * stroke if stroke is not None else 0.0, float(np.nanmax(slip)) if slip.size else 0.0)
        pc = ax.pcolormesh(res.x, res.y, np.ma.masked_where(res.fields["pressure"][last] <= 0, slip), shading="nearest",
                           cmap="viridis", vmin=0.0, vmax=top if top > 0 else None)
        fig.colorbar(pc, ax=ax, label=f"slip per cycle ({unit}); 0 = stuck")
        ax.set_ylabel("y (mm)")
        ax.set_title("stick and slip on the moving body")
    else:
        mu = _float(res, "friction_coefficient")
        ax.plot(res.x, centre_line(res.fields["shear_traction"][last]), lw=1.3, label="|q| amplitude")
        if mu is not None:
            ax.plot(res.x, mu * centre_line(res.fields["pressure"][last]), "k:", lw=1.0, label="μp (slip where reached)")
        ax.set_ylabel(f"shear traction ({_unit(res, 'fields/shear_traction')})")
        ax.set_title("stick (|q| < μp) and slip")
        ax.legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[2].set_xlabel("x, sliding direction (mm)")
    return fig


# --- fretting fatigue: the SWT field under the contact, and a sweep's life against the stroke ---------------------


def _fatigue(res: Results, body: str = "stationary"):
    """One body's SWT field below its surface at the recorded state where it peaks (the peak over the run and
    where the crack starts marked); the hot spot at true scale with the critical plane's trace at each point; and
    the field's peak at each recorded state against cycles, with the crack cycle.  The moving body's is drawn at
    its own points, depth into it."""
    from fretsim.quantities import keyed
    sub = res.fatigue(body)
    summary = {k: res.summary.get(keyed(k, body), np.nan) for k in (
        "cycles_to_crack_initiation", "crack_location_x_mm", "swt_location_x_mm", "swt_depth_um", "swt_max_MPa",
        "fatigue_damage", "crack_location_y_mm", "swt_location_y_mm")}
    summary["damage_mode"] = res.summary.get("damage_mode", "–")
    swt, angle, z = sub["swt"], sub["swt_plane_angle"], sub["z"] * 1e3  # depths in µm
    peaks = np.array([np.nanmax(f) if np.isfinite(f).any() else np.nan for f in swt])
    k = int(np.nanargmax(peaks)) if np.isfinite(peaks).any() else len(peaks) - 1
    field, plane, x = swt[k], angle[k], res.x * 1e3  # x in µm as well: the planes are drawn at their true angle
    where = ""
    if field.ndim == 3:  # 3D: the section along the stroke through the state's peak (its planes projected on it)
        row = int(np.unravel_index(np.nanargmax(np.nan_to_num(field, nan=-np.inf)), field.shape)[1])
        field, plane = field[:, row, :], plane[:, row, :]
        where = f" at y = {res.y[row] * 1e3:.0f} µm"
    top = float(np.nanmax(field)) if np.isfinite(field).any() else 0.0
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), gridspec_kw={"width_ratios": [1.8, 1.1, 1]})
    if top > 0:
        _swt_overview(axes[0], fig, field, x, z, top, summary)
        _hot_spot(axes[1], field, plane, x, z, top)
    axes[0].set_title(f"{body} body, {_cycles_label(res.fields['cycle'][k])}{where}: SWT on the critical plane",
                      **({"fontsize": 10} if where else {}))
    ax = axes[2]
    ax.plot(res.fields["cycle"], peaks, "o-", ms=4, label="SWT peak at each recorded state")
    crack = summary["cycles_to_crack_initiation"]
    if np.isfinite(crack):
        ax.axvline(crack, color="b", ls="--", lw=1.0, label="crack starts")
    ax.set_xlabel("cycles")
    ax.set_ylabel(f"SWT peak ({_unit(res, 'fields/swt' if body == 'stationary' else 'fields/swt_moving')})")
    ax.set_title(f"damage {summary['fatigue_damage']:.3g} of 1 at the end; {summary['damage_mode']}", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def _swt_overview(ax, fig, field, x, z, top: float, summary: dict) -> None:
    """The field where it reaches 1 % of its peak, depth downwards, the run's peak and the crack marked."""
    cols = np.flatnonzero((field >= 0.01 * top).any(axis=0))
    rows = np.flatnonzero((field >= 0.01 * top).any(axis=1))
    pad = max(3, (cols[-1] - cols[0]) // 6)
    xs = slice(max(0, cols[0] - pad), min(x.size, cols[-1] + pad + 1))
    zs = slice(0, min(z.size, rows[-1] + 2))
    pc = ax.pcolormesh(x[xs], z[zs], field[zs, xs], shading="nearest", cmap="magma_r", vmin=0.0, vmax=top)
    fig.colorbar(pc, ax=ax, label="SWT (MPa)")
    # (3D: the section is through one row; the peak's and the crack's own y said, as they may lie on another)
    across = lambda key: (f" at y = {summary[key] * 1e3:.0f} µm" if np.isfinite(summary.get(key, np.nan))  # noqa
                          else "")
    ax.plot(summary.get("swt_location_x_mm", np.nan) * 1e3, summary.get("swt_depth_um", np.nan), "c*", ms=12,
            label=f"peak over the run: {summary.get('swt_max_MPa', np.nan):.3g} MPa{across('swt_location_y_mm')}")
    crack = summary.get("cycles_to_crack_initiation", np.nan)
    if np.isfinite(crack):
        ax.plot(summary["crack_location_x_mm"] * 1e3, z[0], "bv", ms=9,
                label=f"crack starts: cycle {crack:,.0f}".replace(",", " ") + across("crack_location_y_mm"))
    ax.set_ylim(z[zs][-1], 0.0)
    ax.set_xlabel("x, sliding direction (µm)")
    ax.set_ylabel("depth below the surface (µm)")
    ax.legend(fontsize=8, loc="lower right")


def _hot_spot(ax, field, angle_deg, x, z, top: float) -> None:
    """Around the field's peak at equal scale: the field and the critical plane's trace (perpendicular to its
    normal, at φ from x towards the depth) at the points above a tenth of the peak."""
    i, j = np.unravel_index(np.nanargmax(field), field.shape)
    half = max(8.0 * float(x[1] - x[0]), 4.0 * float(z[min(i + 4, z.size - 1)]))
    xs = np.flatnonzero(np.abs(x - x[j]) <= half)
    zs = np.flatnonzero(z <= 1.2 * half)
    ax.pcolormesh(x[xs], z[zs], field[np.ix_(zs, xs)], shading="nearest", cmap="magma_r", vmin=0.0, vmax=top)
    length = 0.06 * half
    step = max(1, xs.size // 12)
    for r in zs[:: max(1, zs.size // 8)]:
        for c in xs[::step]:
            if field[r, c] >= 0.1 * top:
                phi = math.radians(float(angle_deg[r, c]))
                tx, tz = -math.sin(phi), math.cos(phi)
                ax.plot([x[c] - length * tx, x[c] + length * tx], [z[r] - length * tz, z[r] + length * tz],
                        color="c", lw=1.2)
    ax.set_xlim(x[xs][0], x[xs][-1])
    ax.set_ylim(z[zs][-1], 0.0)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x (µm)")
    ax.set_title("at the peak, true scale: critical planes", fontsize=10)


def fatigue_life_sweep(table: SweepTable):
    """Crack-initiation life against the stroke, with wear and without (points whose wear coefficients are 0):
    a point without a crack is drawn at its last cycle, pointing up (a lower bound); the gross-slip limit δ_t of
    the unworn contact as a vertical line.  None where the points have no fatigue."""
    rows = [r for r in table.rows if r.get("damage_mode") not in (None, "") and r.get("status") == "complete"]
    if not rows:
        return None
    fig, ax = plt.subplots(figsize=(10.5, 4.6))

    def worn(row) -> bool:  # without wear: a point that sets both bodies' wear coefficients to 0
        values = [row.get(f"materials.{body}.wear_coefficient") for body in ("moving", "stationary")]
        given = [_AS_WRITTEN.match(str(v)) or re.match(r"^\s*([-+0-9.eE]+)\s*$", str(v)) for v in values if v]
        return not (len(given) == 2 and all(m is not None and float(m.group(1)) == 0 for m in given))

    for label, colour, pick in (("with wear", "C0", True), ("without wear (k = 0)", "C3", False)):
        group = sorted((r for r in rows if worn(r) == pick), key=lambda r: _in_unit(r.get("loading.stroke"), _TO_UM))
        if not group:
            continue
        stroke = np.array([_in_unit(r.get("loading.stroke"), _TO_UM) for r in group])
        life = np.array([_row_number(r, "cycles_to_crack_initiation") for r in group])
        ran = np.array([_row_number(r, "cycles") for r in group])
        ax.plot(stroke, np.where(np.isfinite(life), life, ran), "-", color=colour, lw=1.0, alpha=0.6)
        ax.plot(stroke[np.isfinite(life)], life[np.isfinite(life)], "o", color=colour, label=label)
        ax.plot(stroke[~np.isfinite(life)], ran[~np.isfinite(life)], "^", color=colour, mfc="none",
                label=f"{label}: no crack by the run's end")
    d_t = np.array([_row_number(r, "gross_slip_stroke_um") for r in rows])
    if np.isfinite(d_t).any():
        ax.axvline(float(np.nanmedian(d_t)), color="k", ls=":", lw=1.0, label="gross-slip limit δ_t (unworn)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("stroke amplitude δ (µm)")
    ax.set_ylabel("cycles to crack initiation")
    ax.set_title(f"{Path(table.path).name}: fretting fatigue life against the stroke")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0))  # (the curve's minimum sits low centre)
    fig.subplots_adjust(left=0.09, right=0.64, bottom=0.12)
    return fig


ENERGY = "cumulative_dissipated_energy_J"
BODIES = ("moving", "stationary")


def _dissipates(history: dict) -> bool:
    """Whether a history knows the energy its run dissipated, and some was: a run with a friction coefficient."""
    energy = history.get(ENERGY)
    return energy is not None and energy.size > 0 and bool(np.isfinite(energy).all()) and energy[-1] > 0


def _scatter(v: float) -> str:
    return "scatter –" if not np.isfinite(v) else f"scatter ±{_percent(v)}" if v >= 1e-4 else "scatter < 0.01 %"


def _alpha_text(alpha: float, scatter: float) -> str:
    """A fitted energy wear coefficient (mm³/J) and its scatter, as the legends say them."""
    return f"α = {alpha:.4g} mm³/J, {_scatter(scatter)}"


def _energy_wear(res: Results):
    """Fouvry's energy approach: each body's wear volume against the energy dissipated by friction since cycle 0,
    with α fitted by least squares through the origin (the case's α beside it under the energy law), and each
    state's departure from the fitted line."""
    h = res.history
    energy = h[ENERGY]
    on = energy > 0
    law = _input(res, "wear_law") == "energy"
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for body, ls, colour in zip(BODIES, STYLES, ("C0", "C1")):
        volume = h[f"wear_volume_{body}"]
        alpha, scatter = through_origin(energy, volume)
        given = _float(res, f"{body}_energy_wear_coefficient") if law else None
        label = f"{body}: {_alpha_text(alpha, scatter)}" + (f" (the case's {given:.4g})" if given else "")
        axes[0].plot(energy, volume, ls="none", marker="o", ms=3, color=colour, label=f"{body} body")
        if np.isfinite(alpha):
            axes[0].plot([0.0, energy[-1]], [0.0, alpha * energy[-1]], ls=ls, lw=1.0, color=colour, label=label)
            if alpha > 0:
                axes[1].plot(energy[on], (volume[on] / (alpha * energy[on]) - 1) * 100, ls=ls, marker="o", ms=3,
                             color=colour, label=f"{body} body")
    axes[0].set_ylabel(f"wear volume ({_unit(res, 'history/wear_volume_moving')})")
    axes[0].ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))  # 0.00150 mm³ took the label's room
    axes[0].set_title("wear volume against dissipated energy (Fouvry)")
    axes[1].axhline(0.0, color="k", lw=0.8)
    axes[1].set_ylabel("V/(α·ΣE) − 1 (%)")
    axes[1].set_title("each state off the fitted line")
    for ax in axes:
        ax.set_xlabel(f"cumulative dissipated energy ΣE ({_unit(res, 'history/' + ENERGY)})")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return fig


def energy_wear_sweep(table: SweepTable):
    """Fouvry's figure of a sweep: each complete point's wear volume against its cumulative dissipated energy
    (its history a line, its end a marker), one panel a body, and α fitted through the origin over the points'
    ends with its scatter; all on one line where the energy law holds across loads and strokes.  None where no
    point dissipated energy (no friction coefficient, or files written before format 1.5)."""
    from fretsim.results import read_results
    rows = [r for r in table.rows if r.get("status") == "complete" and _finite(r.get("dissipated_energy_per_cycle_J"))
            and float(r["dissipated_energy_per_cycle_J"]) > 0]
    read = ((r, read_results(Path(table.path) / "points" / f"{r['point']}.h5").history) for r in rows)
    points = [(r, h) for r, h in read if _dissipates(h)]
    if not points:
        return None
    histories = [h for _, h in points]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    colours = state_colours(len(histories))
    ends = np.array([h[ENERGY][-1] for h in histories])
    named = len(points) <= MAX_PROFILES  # beyond, the legend stops reading: the points counted instead
    labels = [", ".join(f"{a.split('.')[-1]} = {r.get(a, '')}" for a in table.axes) or r["point"] if named else
              (f"each point's history ({len(points)} points)" if k == 0 else None) for k, (r, _) in enumerate(points)]
    for ax, body in zip(axes, BODIES):
        key = f"wear_volume_{body}"
        for h, colour, label in zip(histories, colours, labels):
            ax.plot(h[ENERGY], h[key], color=colour, lw=1.0, label=label)
            ax.plot([h[ENERGY][-1]], [h[key][-1]], "o", color=colour, ms=4)
        alpha, scatter = through_origin(ends, [h[key][-1] for h in histories])
        if np.isfinite(alpha):
            ax.plot([0.0, ends.max()], [0.0, alpha * ends.max()], "k--", lw=1.0,
                    label=f"{_alpha_text(alpha, scatter)}\n(through the origin, over the points' ends)")
        ax.set_xlabel("cumulative dissipated energy ΣE (J)")
        ax.set_ylabel(f"wear volume, {body} body (mm³)")
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
    fig.suptitle(f"{Path(table.path).name}: wear volume against dissipated energy (Fouvry)", fontsize=10)
    fig.tight_layout()
    return fig


SWEEP_OUTPUTS = ("centre_wear_depth_stationary_um", "max_wear_depth_moving_um", "scar_width_stationary_mm",
                 "wall_time_s")


def plot_sweep(table: SweepTable, outdir: str | Path, fmt: str = "png", dpi: int = 150) -> list[Path]:
    """Response curves: each output against each swept axis, one line per combination of the other axes; for a
    sweep over load and stroke whose points judged their regime (a friction coefficient given), the fretting
    figures (:func:`fretting_figures`) in place of the curves over those two axes; where the points dissipate
    energy, Fouvry's figure (:func:`energy_wear_sweep`); for a sampled sweep, the uncertainty figures instead
    (:func:`uncertainty_bands`)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    if table.mode == "sample":
        return uncertainty_bands(table, outdir, fmt, dpi)
    axes = list(table.axes)
    fouvry = energy_wear_sweep(table)
    life = fatigue_life_sweep(table) if any(r.get("damage_mode") for r in table.rows) else None
    if not axes and fouvry is None and life is None:
        raise ResultsFileError(f"{table.path}: the sweep has no axes (a list of points): nothing to draw curves over")
    builders = {} if life is None else {"sweep_fatigue_life": lambda: life}
    if is_fretting_sweep(table):
        builders.update(fretting_figures(table, build=False))
        axes = [a for a in axes if a not in FRETTING_AXES]
    builders.update({f"sweep_{a.replace('.', '_')}": (lambda a=a: _response_curves(table, a)) for a in axes})
    if fouvry is not None:
        builders["sweep_energy_wear"] = lambda: fouvry
    return _save_each(builders, outdir, fmt, dpi)


def _save_each(builders: dict, outdir: Path, fmt: str, dpi: int) -> list[Path]:
    """Build each figure (None: skipped), save it as OUTDIR/NAME.FMT and close it, whatever the save did."""
    paths = []
    for name, build in builders.items():
        fig = build()
        if fig is None:
            continue
        path = outdir / f"{name}.{fmt}"
        try:
            _savefig(fig, path, dpi)
        finally:
            plt.close(fig)
        paths.append(path)
    return paths


def _response_curves(table: SweepTable, axis: str):
    """Each output against ``axis``, one line per combination of the other axes."""
    axes = list(table.axes)
    fig, ax_list = plt.subplots(1, len(SWEEP_OUTPUTS), figsize=(4.2 * len(SWEEP_OUTPUTS), 3.8), squeeze=False)
    others = [a for a in axes if a != axis]
    groups: dict = {}
    for row in table.rows:
        groups.setdefault(tuple(row.get(o, "") for o in others), []).append(row)
    values = table.axes[axis]
    for k, (key, rows) in enumerate(groups.items()):
        order = {str(v): i for i, v in enumerate(_as_written(table, axis))}
        rows = sorted(rows, key=lambda r: order.get(r.get(axis, ""), 0))
        xs = [values[order[r[axis]]] if r.get(axis) in order else np.nan for r in rows]
        label = ", ".join(f"{o.split('.')[-1]} = {v}" for o, v in zip(others, key)) or None
        for ax, out in zip(ax_list[0], SWEEP_OUTPUTS):
            ys = [float(r[out]) if r.get(out) not in (None, "") and r.get("status") == "complete" else np.nan
                  for r in rows]
            ax.plot(xs, ys, ls=STYLES[k % len(STYLES)], marker="o", ms=3, label=label)
    for ax, out in zip(ax_list[0], SWEEP_OUTPUTS):
        unit = table.units.get(axis, "")
        ax.set_xlabel(f"{axis} ({_shown(unit)})" if unit and unit != "1" else axis)
        ax.set_ylabel(out.rsplit("_", 1)[0].replace("_", " ") + f" ({_shown(SUMMARY[out].unit)})")
        ax.grid(alpha=0.3)
    if groups and next(iter(groups)):
        ax_list[0][0].legend(fontsize=7)
    fig.suptitle(f"{Path(table.path).name}: response to {axis}", fontsize=10)
    fig.tight_layout()
    return fig


# --- a sweep over load and stroke: the fretting map, the energy per cycle, the loops ------------------------------
FRETTING_AXES = ("loading.normal_load", "loading.stroke")
# the units a sweep file may write a load or a stroke in (fretsim.units.UNITS' force and length, a test keeps them
# alike), to N and µm: this module reads the table's values as written and imports nothing but the results
_TO_N = {"N": 1.0, "kN": 1e3, "MN": 1e6, "mN": 1e-3, "uN": 1e-6, "µN": 1e-6, "μN": 1e-6}
_TO_UM = {"km": 1e9, "m": 1e6, "cm": 1e4, "mm": 1e3, "um": 1.0, "µm": 1.0, "μm": 1.0, "micron": 1.0, "microns": 1.0,
          "nm": 1e-3}
_AS_WRITTEN = re.compile(r"^\s*(?:±|\+/-)?\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S+)\s*$")
REGIMES = {"partial_slip": "partial slip", "gross_slip": "gross slip"}


def _in_unit(text, scale: dict) -> float:
    """A value as the sweep file wrote it ("185 N", "±0.5 um") in the unit of ``scale`` (1.0 there); NaN if not."""
    m = _AS_WRITTEN.match(str(text))
    return float(m.group(1)) * scale[m.group(2)] if m and m.group(2) in scale else math.nan


def _row_number(row: dict, key: str) -> float:
    try:
        return float(row.get(key))
    except (TypeError, ValueError):
        return math.nan


def fretting_points(rows: list) -> dict:
    """The points of a load × stroke sweep as arrays: ``load`` (N), ``stroke`` (µm), ``status``, ``regime``,
    ``assumed`` (no friction coefficient judged the regime: no δ_t), ``volume`` (the flat's wear, mm³), ``energy``
    (J per cycle), ``q_star`` (N), ``d_t`` (δ_t of the unworn contact, µm) and ``point`` (the results file's
    name), read from the table's rows."""
    def column(key, kind=float):
        return np.array([kind(r.get(key, "")) if kind is str else _row_number(r, key) for r in rows], dtype=kind)
    pts = {"load": np.array([_in_unit(r.get(FRETTING_AXES[0]), _TO_N) for r in rows], dtype=float),
           "stroke": np.array([_in_unit(r.get(FRETTING_AXES[1]), _TO_UM) for r in rows], dtype=float),
           "status": column("status", str), "regime": column("regime", str), "point": column("point", str),
           "volume": column("wear_volume_stationary_mm3"), "energy": column("dissipated_energy_per_cycle_J"),
           "q_star": column("tangential_force_amplitude_N"), "d_t": column("gross_slip_stroke_um")}
    pts["assumed"] = ~np.isfinite(pts["d_t"])
    pts["done"] = pts["status"] == "complete"
    return pts


def is_fretting_sweep(table: SweepTable) -> bool:
    """A sweep over load and stroke (both axes, every value a force and a length) whose complete points judged
    their regime (a friction coefficient given: δ_t known): drawn as a fretting map."""
    if table.mode == "sample" or not set(FRETTING_AXES) <= set(table.axes) or not table.rows:
        return False
    pts = fretting_points(table.rows)
    finite = np.isfinite(pts["load"]) & np.isfinite(pts["stroke"]) & (pts["load"] > 0) & (pts["stroke"] > 0)
    return bool(finite.all() and (pts["done"] & ~pts["assumed"]).any())


def fretting_figures(table: SweepTable, build: bool = True) -> dict:
    """A load × stroke sweep's figures, name → Figure (or, with ``build`` False, → a function drawing it, None where
    there is nothing to draw): the fretting map, the energy per cycle against stroke, the loops of chosen points;
    one set per combination of the other axes' values (named by them)."""
    others = [a for a in table.axes if a not in FRETTING_AXES]
    groups: dict = {}
    for row in table.rows:
        groups.setdefault(tuple(row.get(o, "") for o in others), []).append(row)
    out = {}
    for key, rows in groups.items():
        said = ", ".join(f"{o.split('.')[-1]} = {v}" for o, v in zip(others, key))
        suffix = "".join(f"_{o.split('.')[-1]}={v}" for o, v in zip(others, key)).replace(" ", "").replace("/", "_")
        title = Path(table.path).name + (f" ({said})" if said else "")
        pts = fretting_points(rows)
        out[f"sweep_fretting_map{suffix}"] = lambda pts=pts, title=title: _fretting_map(pts, title)
        out[f"sweep_fretting_energy{suffix}"] = lambda pts=pts, title=title: _fretting_energy(pts, title)
        out[f"sweep_fretting_loops{suffix}"] = lambda pts=pts, title=title: _fretting_loops(table, pts, title)
    if not build:
        return out
    return {name: fig for name, fig in ((n, b()) for n, b in out.items()) if fig is not None}


def gross_slip_limits(pts: dict) -> tuple[np.ndarray, np.ndarray]:
    """δ_t(P): each load's gross-slip stroke of the unworn contact (µm; the median over its complete points, which
    agree to the grid's rounding) and the loads (N), ascending; loads without one left out."""
    ok = pts["done"] & np.isfinite(pts["d_t"])
    loads = np.unique(pts["load"][ok])
    return np.array([np.median(pts["d_t"][ok & (pts["load"] == p)]) for p in loads]), loads


def _wear_norm(values: np.ndarray):
    """The map's colour scale: logarithmic over the positive wear (partial and gross slip differ by decades)."""
    from matplotlib.colors import LogNorm, Normalize
    pos = values[np.isfinite(values) & (values > 0)]
    if not pos.size:
        return Normalize(0.0, 1.0)
    lo, hi = float(pos.min()), float(pos.max())
    return LogNorm(lo / 1.1, hi * 1.1) if hi <= lo * 1.01 else LogNorm(lo, hi)


# the map's markers by regime: label, selection, marker, filled
def _map_classes(pts: dict) -> list:
    done, assumed = pts["done"], pts["assumed"]
    return [("partial slip", done & ~assumed & (pts["regime"] == "partial_slip"), "o", False),
            ("gross slip", done & ~assumed & (pts["regime"] == "gross_slip"), "s", True),
            ("gross slip, assumed (no μ)", done & assumed, "D", True),
            ("not complete", ~done, "x", None)]


def _fretting_map(pts: dict, title: str):
    """The fretting map: each point at its stroke and load (log axes), its marker the regime (open circle: partial
    slip, filled square: gross slip, diamond: gross slip assumed without μ, cross: not complete), its colour the
    flat's wear volume; the gross-slip limit δ_t(P) through each load's δ_t (straight on log axes: interpolated
    in log-log)."""
    fig, ax = plt.subplots(figsize=(7.5, 5.6))
    norm, cmap = _wear_norm(pts["volume"][pts["done"]]), plt.get_cmap("viridis")
    for label, sel, marker, filled in _map_classes(pts):
        if not sel.any():
            continue
        x, y, v = pts["stroke"][sel], pts["load"][sel], pts["volume"][sel]
        colours = cmap(norm(np.where(np.isfinite(v) & (v > 0), v, norm.vmin)))
        if filled is None:
            ax.scatter(x, y, marker=marker, s=70, c="0.5", linewidths=1.5, label=label, zorder=3)
        elif filled:
            ax.scatter(x, y, marker=marker, s=90, c=colours, edgecolors="k", linewidths=0.8, label=label, zorder=3)
        else:
            ax.scatter(x, y, marker=marker, s=90, facecolors="none", edgecolors=colours, linewidths=2.2, label=label,
                       zorder=3)
    d_t, loads = gross_slip_limits(pts)
    if loads.size:
        ax.plot(d_t, loads, "k--" if loads.size > 1 else "k|", lw=1.3, ms=16, mew=1.5,
                label="δ_t(P): gross slip beyond (unworn contact)")
    xs = np.concatenate([pts["stroke"], d_t])
    _log_axis(ax, "x", float(np.min(xs)), float(np.max(xs)), _swept(pts["stroke"]))
    _log_axis(ax, "y", float(np.min(pts["load"])), float(np.max(pts["load"])), _swept(pts["load"]))
    ax.set_xlabel("stroke δ, slip amplitude (µm)")
    ax.set_ylabel("normal load P (N)")
    ax.grid(alpha=0.3, which="both")
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="wear volume of the flat (mm³)")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, frameon=False)
    ax.set_title(f"{title}: fretting map, regime (marker) and the flat's wear (colour)", fontsize=9)
    fig.tight_layout()
    return fig


def _fretting_energy(pts: dict, title: str):
    """The energy dissipated per cycle against stroke (log-log), one line per load, δ_t marked on each: Mindlin's
    δ³ below δ_t (drawn through the smallest partial-slip stroke), the gross-slip line 4μP(δ − δ_e) above it (μP
    the gross-slip points' Q*, δ_e their mean δ − E/4μP).  None where no point dissipated energy (no μ)."""
    ok = pts["done"] & np.isfinite(pts["energy"]) & (pts["energy"] > 0)
    if not ok.any():
        return None
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    limits = dict(zip(*gross_slip_limits(pts)[::-1]))
    said: set = set()
    for i, p in enumerate(np.unique(pts["load"][ok])):
        sel = np.flatnonzero(ok & (pts["load"] == p))
        sel = sel[np.argsort(pts["stroke"][sel])]
        x, e, colour = pts["stroke"][sel], pts["energy"][sel], f"C{i % 10}"
        ax.plot(x, e, "o-", color=colour, lw=0.9, ms=6, label=f"P = {p:g} N")
        d_t = limits.get(p, math.nan)
        e_t = _energy_guides(ax, pts, sel, d_t, colour, said)  # δ_t on a guide, where the strokes do not reach it
        if x[0] <= d_t <= x[-1]:
            e_t = math.exp(np.interp(math.log(d_t), np.log(x), np.log(e)))
        if e_t is not None:
            ax.plot([d_t], [e_t], ls="none", marker="|", ms=20, mew=2.2, color=colour,
                    label=_once(said, "δ_t of each load (unworn contact)"))
    xs = np.concatenate([pts["stroke"][ok], [v for p, v in limits.items() if p in pts["load"][ok]]])
    _log_axis(ax, "x", float(xs.min()), float(xs.max()), _swept(pts["stroke"][ok]))
    ax.set_yscale("log")
    ax.set_xlabel("stroke δ, slip amplitude (µm)")
    ax.set_ylabel("energy dissipated per cycle (J)")
    ax.grid(alpha=0.3, which="both")
    handles, labels = ax.get_legend_handles_labels()  # the loads first, then what marks and guides them
    order = sorted(range(len(labels)), key=lambda k: not labels[k].startswith("P = "))
    ax.legend([handles[k] for k in order], [labels[k] for k in order], fontsize=8, loc="upper left")
    ax.set_title(f"{title}: energy per cycle, partial slip ∝ δ³ (Mindlin), gross slip 4μP(δ − δ_e)", fontsize=9)
    fig.tight_layout()
    return fig


def _once(said: set, label: str) -> str:
    """``label`` the first time (for the legend), "_nolegend_" after."""
    if label in said:
        return "_nolegend_"
    said.add(label)
    return label


def _energy_guides(ax, pts: dict, sel: np.ndarray, d_t: float, colour, said: set) -> Optional[float]:
    """One load's references (dotted, dashed): δ³ through its smallest partial-slip stroke up to δ_t, and
    4μP(δ − δ_e) from δ_t (or its smallest gross-slip stroke) to its largest stroke; returns the energy at δ_t on
    them (the gross-slip line's, else the δ³'s; None if neither reaches δ_t)."""
    at_limit = None
    partial = sel[(pts["regime"][sel] == "partial_slip") & ~pts["assumed"][sel]]
    if partial.size and np.isfinite(d_t):
        x0, e0 = pts["stroke"][partial[0]], pts["energy"][partial[0]]
        xs = np.geomspace(x0, max(d_t, x0), 100)
        ax.plot(xs, e0 * (xs / x0) ** 3, ":", color=colour, lw=1.2, label=_once(said, "∝ δ³ (Mindlin), partial slip"))
        at_limit = e0 * (d_t / x0) ** 3 if d_t >= x0 else None
    gross = sel[(pts["regime"][sel] == "gross_slip") & ~pts["assumed"][sel] & np.isfinite(pts["q_star"][sel])]
    if gross.size:
        mu_p = float(np.median(pts["q_star"][gross]))  # in gross slip Q* = μP
        x, e = pts["stroke"][gross], pts["energy"][gross]
        d_e = float(np.mean(x - e / (4.0 * mu_p * 1e-6)))  # N·µm = 1e-6 J
        start = d_t if np.isfinite(d_t) and d_e < d_t < x.min() else x.min()
        xs = np.geomspace(start, x.max(), 100)
        ax.plot(xs, 4.0 * mu_p * (xs - d_e) * 1e-6, "--", color=colour, lw=1.0,
                label=_once(said, "4μP(δ − δ_e), gross slip (μP = Q*, δ_e fitted)"))
        at_limit = 4.0 * mu_p * (d_t - d_e) * 1e-6 if start == d_t else at_limit
    return at_limit


def _loop_choice(pts: dict) -> tuple[float, list]:
    """The load whose loops are drawn (most complete points; the middle one of those) and its points' indices:
    the smallest stroke, the one nearest δ_t (in ratio), the largest."""
    done = pts["done"]
    loads, counts = np.unique(pts["load"][done], return_counts=True)
    best = loads[counts == counts.max()]
    load = float(best[len(best) // 2])
    at = np.flatnonzero(done & (pts["load"] == load))
    at = at[np.argsort(pts["stroke"][at])]
    d_t = dict(zip(*gross_slip_limits(pts)[::-1])).get(load, math.nan)
    chosen = [at[0]]
    if np.isfinite(d_t) and d_t > 0:
        chosen.append(at[np.argmin(np.abs(np.log(pts["stroke"][at] / d_t)))])
    chosen.append(at[-1])
    return load, sorted(dict.fromkeys(int(i) for i in chosen), key=lambda i: pts["stroke"][i])


def _fretting_loops(table: SweepTable, pts: dict, title: str):
    """The recorded fretting loops (the last recorded cycle) of the points :func:`_loop_choice` picks, force
    against displacement, one panel each (their strokes differ by decades), each named by its stroke and regime;
    ±μP dotted.  None where no point recorded a loop (uniform slip has none)."""
    from fretsim.results import read_results
    if not pts["done"].any():
        return None
    load, chosen = _loop_choice(pts)
    drawn = []
    for i in chosen:
        try:
            res = read_results(Path(table.path) / "points" / f"{pts['point'][i]}.h5")
        except (OSError, ResultsFileError):
            continue
        loop = res.fretting_loop
        if loop.get("displacement") is not None and loop["displacement"].size:
            drawn.append((i, res))
    if not drawn:
        return None
    fig, axes = plt.subplots(1, len(drawn), figsize=(4.4 * len(drawn), 4.6), squeeze=False)
    for ax, (i, res) in zip(axes[0], drawn):
        loop = res.fretting_loop
        u, q = loop["displacement"][-1], loop["tangential_force"][-1]
        ok = np.isfinite(u) & np.isfinite(q)
        regime = REGIMES.get(str(pts["regime"][i]), str(pts["regime"][i])) + (" (assumed)" if pts["assumed"][i] else "")
        name = f"δ = ±{pts['stroke'][i]:.3g} µm, {regime}"
        ax.plot(u[ok], q[ok], "-", marker=".", ms=3, lw=1.3, label=f"{name} ({_cycles_label(loop['cycle'][-1])})")
        mu = _float(res, "friction_coefficient")
        if mu is not None:
            for sign in (1, -1):
                ax.axhline(sign * mu * load, color="k", ls=":", lw=0.9,
                           label=f"±μP = ±{mu * load:.4g} N" if sign > 0 else "_nolegend_")
        ax.set_xlabel(f"applied displacement ({_unit(res, 'fretting_loop/displacement')})")
        ax.set_ylabel(f"tangential force Q ({_unit(res, 'fretting_loop/tangential_force')})")
        ratio = pts["stroke"][i] / pts["d_t"][i] if np.isfinite(pts["d_t"][i]) and pts["d_t"][i] > 0 else None
        ax.set_title(name + (f" ({ratio:.2g} δ_t)" if ratio else ""), fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.15), frameon=False)
    fig.suptitle(f"{title}: fretting loops at P = {load:g} N (each point's last recorded cycle)", fontsize=10)
    fig.tight_layout()
    return fig


MAX_SWEPT_TICKS = 10  # swept values an axis labels each; beyond, the 1-2-5 ticks of log_ticks


def _swept(values: np.ndarray) -> Optional[list]:
    """The distinct swept values, as an axis's ticks (185 N, 0.3 µm read off the axis), if there are few."""
    distinct = np.unique(values[np.isfinite(values) & (values > 0)])
    return [float(v) for v in distinct] if 0 < distinct.size <= MAX_SWEPT_TICKS else None


def _log_axis(ax, which: str, lo: float, hi: float, ticks: Optional[list] = None) -> None:
    """A log axis over ``lo`` to ``hi`` (a quarter wider each side) with ticks that read: ``ticks`` if given, else
    :func:`log_ticks` (1-2-5 within a decade or two, as powers of ten past 10⁵)."""
    axis = ax.xaxis if which == "x" else ax.yaxis
    getattr(ax, f"set_{which}scale")("log")
    if ticks and (lo < ticks[0] / 2 or hi > ticks[-1] * 2):  # they would leave a stretch of the axis unlabelled
        ticks = None
    ticks = ticks or log_ticks(lo / 1.25, hi * 1.25)
    getattr(ax, f"set_{which}lim")(min(lo / 1.25, ticks[0]), max(hi * 1.25, ticks[-1]))
    getattr(ax, f"set_{which}ticks")(ticks)
    axis.set_major_formatter(FuncFormatter(lambda v, _: _log_tick(v)))
    axis.set_minor_formatter(plt.NullFormatter())


BAND_POINTS = 200  # cycles at which the points' histories are read for the band


def band_data(table: SweepTable, key: str = "max_wear_depth_moving") -> dict:
    """Per group of the listed axes: the cycles and the P10, P50 and P90 of ``key`` (a history entry) over the
    complete points' histories, read at common cycles.  A point that stopped at its wear limit is held at its
    last value beyond its stop (it has reached the limit: at least that deep), so the band saturates at the
    limit as the samples reach it rather than follow only the slow ones."""
    from fretsim.results import read_results
    done = [r for r in table.rows if r.get("status") == "complete"]
    groups: dict = {}
    for r in done:
        groups.setdefault(tuple(r.get(k) for k in table.groups), []).append(r)
    out = {}
    for group, rows in groups.items():
        histories = []
        for r in rows:
            h = read_results(Path(table.path) / "points" / f"{r['point']}.h5").history
            histories.append((h["cycle"].astype(float), h[key].astype(float)))
        top = max(float(c[-1]) for c, _ in histories)
        grid = np.linspace(0.0, top, BAND_POINTS)
        stopped = [bool(r.get("limit_reached")) for r in rows]
        values = np.array([np.interp(grid, c, v, right=v[-1] if held else np.nan)
                           for (c, v), held in zip(histories, stopped)])
        p10, p50, p90 = column_quantiles(values)  # as percentiles.csv reads the samples
        out[group] = {"cycles": grid, "p10": p10, "p50": p50, "p90": p90, "points": len(histories)}
    return out


def uncertainty_figures(table: SweepTable) -> dict:
    """A sampled sweep's figures, name → matplotlib Figure (tests check what is drawn; :func:`uncertainty_bands`
    saves them): the depth band, and where samples reached a wear limit, the histogram of the time to it."""
    out = {"uncertainty_depth_band": _depth_band(table)}
    histogram = _time_to_limit(table)
    if histogram is not None:
        out["uncertainty_time_to_limit"] = histogram
    return out


def uncertainty_bands(table: SweepTable, outdir: Path, fmt: str = "png", dpi: int = 150) -> list[Path]:
    """Save :func:`uncertainty_figures` as OUTDIR/NAME.FMT."""
    return _save_each({name: (lambda fig=fig: fig) for name, fig in uncertainty_figures(table).items()}, Path(outdir),
                      fmt, dpi)


def _group_label(table: SweepTable, group: tuple) -> str:
    return ", ".join(f"{k.split('.')[-1]} = {v}" for k, v in zip(table.groups, group)) or "all samples"


def _depth_band(table: SweepTable):
    """The deepest wear against cycles: the P10–P90 band and the P50 over the samples, per group of the listed
    axes, each named by its percentiles."""
    bands = band_data(table, "max_wear_depth_moving")
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for i, (group, b) in enumerate(bands.items()):
        prefix = f"{_group_label(table, group)}: " if table.groups else ""
        line, = ax.plot(b["cycles"], b["p50"], ls=STYLES[i % len(STYLES)], label=f"{prefix}P50 (median)")
        ax.fill_between(b["cycles"], b["p10"], b["p90"], color=line.get_color(), alpha=0.25,
                        label=f"{prefix}P10–P90 of {b['points']} samples")
    ax.set_xlabel("cycles N (–)")
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: cycles_tick(v)))
    ax.set_ylabel("maximum wear depth of the moving body (µm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f"{Path(table.path).name}: depth band over the samples (a sample at its limit held there)",
                 fontsize=9)
    fig.tight_layout()
    return fig


# the unit of a time to a limit (name, as labelled, hours): the largest in which the samples' median is at least
# a tenth (0.47 years, not 171 days; 5 minutes, not 0.09 hours)
TIME_UNITS = (("years", "years", 8766.0), ("days", "days", 24.0), ("hours", "h", 1.0), ("minutes", "min", 1 / 60),
              ("seconds", "s", 1 / 3600))
PERCENTILE_STYLES = (("P10", ":", "right"), ("P50", "-", "left"), ("P90", "--", "left"))  # name, line, text side


def log_ticks(lo: float, hi: float) -> list[float]:
    """Ticks of a log axis over ``lo`` to ``hi``: powers of ten, or where fewer than three of them fall inside,
    1, 2 and 5 times them, then 1, 2, 3, 5, then every digit (a histogram within one decade had a single tick);
    a range holding fewer than two digits gets those either side of it too (the axis is widened to them)."""
    ticks: list = []
    for subs in ((1,), (1, 2, 5), (1, 2, 3, 5), tuple(range(1, 10))):
        decades = range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1)
        ticks = [float(f"{m}e{e}") for e in decades for m in subs if lo <= float(f"{m}e{e}") <= hi]
        if len(ticks) >= 3:
            return ticks
    if len(ticks) >= 2:
        return ticks
    e_lo, e_hi = math.floor(math.log10(lo)), math.floor(math.log10(hi))
    below = float(f"{math.floor(lo / 10.0 ** e_lo)}e{e_lo}")
    above = float(f"{math.ceil(hi / 10.0 ** e_hi)}e{e_hi}")
    return sorted({below, *ticks, above})


def _log_tick(v: float) -> str:
    """A tick of a log axis: as :func:`cycles_tick` from 1 up, 0.5 and 0.02 below."""
    return cycles_tick(v) if v >= 1 else f"{v:g}"


def _time_to_limit(table: SweepTable):
    """Histogram of the time (with loading.frequency) or the cycles to the wear limit over the complete samples,
    with their P10, P50 and P90 as labelled vertical lines; None where no sample reached a limit.  A sample that
    did not reach it counts as beyond every one that did, as in percentiles.csv (the same quantiles)."""
    done = [r for r in table.rows if r.get("status") == "complete"]
    reached = [r for r in done if r.get("limit_reached")]
    if not reached:
        return None
    timed = all(_finite(r.get("time_to_limit_h")) for r in reached)
    key = "time_to_limit_h" if timed else "cycles_to_limit"
    unit, short, per = "cycles", "cycles", 1.0
    if timed:
        median = float(np.median([float(r[key]) for r in reached]))
        unit, short, per = next((u for u in TIME_UNITS if median / u[2] >= 0.1), TIME_UNITS[-1])
    groups: dict = {}
    for r in done:
        groups.setdefault(tuple(r.get(k) for k in table.groups), []).append(
            float(r[key]) / per if r.get("limit_reached") else math.inf)
    finite = np.array([v for vals in groups.values() for v in vals if math.isfinite(v)])
    lo, hi = float(finite.min()), float(finite.max())
    log = lo > 0
    if log and hi <= lo * 1.05:  # one value (or nearly): a bin of ±5 % around it
        lo, hi = lo / 1.05, hi * 1.05
    elif not log and hi <= lo:
        lo, hi = lo - 0.5, hi + 0.5
    bins = int(np.clip(round(2 * math.sqrt(finite.size)), 6, 25))
    edges = np.logspace(math.log10(lo), math.log10(hi), bins + 1) if log else np.linspace(lo, hi, bins + 1)
    beyond = len(done) - len(reached)
    last = max((int(float(r["cycles"])) for r in done if not r.get("limit_reached") and _finite(r.get("cycles"))),
               default=0)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    handles, top = [], 1
    for i, (group, vals) in enumerate(groups.items()):
        colour = f"C{i % 10}"
        shown = [v for v in vals if math.isfinite(v)]
        prefix = f"{_group_label(table, group)}: " if table.groups else ""
        counts, _, bars = ax.hist(shown, bins=edges, color=colour, alpha=0.5,
                                  label=f"{prefix}{len(shown)} of {len(vals)} samples reached the limit")
        handles.append(bars.patches[0])  # the first bar carries the histogram's label
        top = max(top, int(counts.max()) if len(counts) else 0)
        ps = quantiles(vals)
        for k, ((name, ls, side), p) in enumerate(zip(PERCENTILE_STYLES, ps)):
            if k + 1 < len(ps) and ps[k + 1] == p:  # equal (a few samples): one line named by both, drawn once
                continue
            name = " = ".join(n for (n, _, _), q in zip(PERCENTILE_STYLES, ps) if q == p)
            if not math.isfinite(p):
                handles.append(ax.plot([], [], " ", label=f"{prefix}{name} beyond N = {cycles_tick(last)} "
                                                          f"(not reached)")[0])
                continue
            text = f"{name} = {_value_text(p, short)}"  # the group is the line's colour, said in the legend
            ax.axvline(p, color=colour, ls=ls, lw=1.3, label=prefix + text)
            ax.text(p, 0.98, f" {text} ", transform=ax.get_xaxis_transform(), rotation=90, va="top", ha=side,
                    fontsize=7, color=colour, bbox=dict(boxstyle="square,pad=0.1", fc="white", ec="none", alpha=0.8))
    ax.set_ylim(0, top * 1.6)  # headroom for the percentiles' labels
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # whole samples
    _limit_axis(ax, log, lo, hi)
    if timed:
        r = reached[0]
        hz = float(r["cycles_to_limit"]) / (float(r["time_to_limit_h"]) * 3600.0)
        ax.set_xlabel(f"{unit} to the wear limit (continuous fretting at {hz:.3g} Hz)")
    else:
        ax.set_xlabel("cycles to the wear limit (–)")
    ax.set_ylabel("samples (–)")
    ax.grid(alpha=0.3)
    # below the axes: inside, it lay over the percentiles' labels (which hold the top for them)
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), frameon=False)
    fig.set_figheight(4.2 + 0.17 * len(handles))
    others = len(table.rows) - len(done)
    notes = ([f"{_samples(beyond)} did not reach it by N = {cycles_tick(last)}"] if beyond else []) + (
        [f"{_samples(others)} not complete, not counted"] if others else [])
    ax.set_title(f"{Path(table.path).name}: {reached[0]['limit_reached']} limit"
                 + (f" ({'; '.join(notes)})" if notes else ""), fontsize=9)
    fig.tight_layout()
    return fig


def _limit_axis(ax, log: bool, lo: float, hi: float) -> None:
    """The time-to-limit axis: log ticks that read (1-2-5, as powers of ten past 10⁵), or cycles on a linear one."""
    if log:
        _log_axis(ax, "x", lo, hi)
    else:
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: cycles_tick(v)))


def _finite(text) -> bool:
    try:
        return math.isfinite(float(text))
    except (TypeError, ValueError):
        return False


def _samples(n: int) -> str:
    return f"{n} sample{'' if n == 1 else 's'}"


def _value_text(v: float, unit: str) -> str:
    """A percentile as it is labelled: three significant figures (a dozen or a few hundred samples know no more),
    cycles as their ticks read (5 320 cycles, 1.03×10⁹ cycles)."""
    if unit == "cycles":
        return f"{cycles_tick(float(f'{v:.3g}'))} cycles"
    return f"{v:.3g} {unit}"


def _as_written(table: SweepTable, axis: str) -> list:
    """An axis's values as the sweep file wrote them (a product sweep's table.h5 keeps them with the axis); a zip
    sweep's axis is its points' values, in their order."""
    import json
    import h5py
    with h5py.File(Path(table.path) / "table.h5", "r") as f:
        if axis in f and "as_written" in f[axis].attrs:
            return json.loads(f[axis].attrs["as_written"])
    return [r.get(axis, "") for r in table.rows]


def grouped_bars(labels: list[str], panels: dict, path: str | Path, title: str, dpi: int = 130) -> Path:
    """Side-by-side panels of grouped bars: ``panels`` maps a y label to {series label: values (None = gap)}."""
    fig, axes = plt.subplots(1, len(panels), figsize=(6.5 * len(panels), 4.6), squeeze=False)
    x = np.arange(len(labels))
    for ax, (ylabel, series) in zip(axes[0], panels.items()):
        width = 0.8 / max(len(series), 1)
        for k, (name, values) in enumerate(series.items()):
            ax.bar(x + (k - (len(series) - 1) / 2) * width, [np.nan if v is None else v for v in values], width,
                   label=name)
        ax.set_xticks(x, labels, fontsize=7)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3, axis="y")
    axes[0][0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    _savefig(fig, path, dpi)
    plt.close(fig)
    return Path(path)
