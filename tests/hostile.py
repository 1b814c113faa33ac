"""Hostile inputs for the surfaces issue 31 names (friction keys, load histories, wear limits, sampled sweeps,
measured CSVs for `fit`), each drawn from a ``random.Random`` so that the default tests, the slow suite's 1 000
and ``scripts/fuzz_surfaces.py`` (a before/after table on two trees) draw the same examples from the same seed.

Each ``*_example(rng)`` returns what the surface reads; :func:`judge_cli` says how a command ended:
``ok`` (exit 0, or exit 2 with a short paragraph and no traceback) or ``traceback`` (anything else)."""
from __future__ import annotations

import random

UNITLESS = ["0", "0.9", "1", "10", "11", "-0.1", "nan", "inf", "1e308", "abc", "", "0.0", "1e-300", "[0.5]", "true"]
LENGTHS = ["12 mm", "6 mm", "0 mm", "-1 mm", "1e9 mm", "1 um", "nan mm", "inf mm", "6", "6 N", "", "0.6 mm", "100 mm"]
STIFFNESS = ["1e5 N/mm", "0 N/mm", "-1 N/mm", "inf N/mm", "1e-300 N/mm", "5 N", "nan N/mm", "1e5"]
LOADS = ["185 N", "100 N", "0 N", "-5 N", "1e9 N", "nan N", "5 um", "", "1e-9 N", "185"]
STROKES = ["25 um", "10 um", "0 um", "-5 um", "1 m", "nan um", "25 N", "", "1e-9 um", "25"]
CYCLES = ["5", "1", "0", "-1", "1.5", "1e9", "1e12", "nan", "", "abc", "1000"]
FRACTIONS = ["0.5", "0.25", "0", "-0.5", "1", "1.5", "nan", "", "1e-12"]


def friction_example(rng: random.Random) -> list[str]:
    """--set items over the friction keys, the cycle's models and the bodies' shapes (McColl 185 N, 2D)."""
    sets = ["model.dimension=" + rng.choice(["2d", "2d", "3d"]), "loading.cycles=" + rng.choice(["1000", "0", "10"])]
    choices = [
        ("loading.friction_coefficient", UNITLESS),
        ("loading.tangential_stiffness", STIFFNESS),
        ("model.slip", ["auto", "uniform", "coulomb", "partial", "", "COULOMB"]),
        ("model.stroke", ["auto", "mid_stroke", "resolved", "end", ""]),
        ("model.increments", ["9", "3", "1", "8", "0", "-3", "1e9", "x", "10001"]),
        ("model.wear_law", ["archard", "energy", "", "x"]),
        ("materials.moving.energy_wear_coefficient", ["2.5e-5 mm3/J", "0 mm3/J", "-1 mm3/J", "1 1/MPa", "nan mm3/J"]),
        ("materials.stationary.energy_wear_coefficient", ["2.5e-5 mm3/J", "0 mm3/J", "1e300 mm3/J"]),
        ("geometry.flat_width", LENGTHS), ("geometry.flat_thickness", LENGTHS), ("geometry.moving_height", LENGTHS),
        ("loading.stroke", STROKES),
    ]
    for key, values in rng.sample(choices, rng.randint(1, 5)):
        valid = values[:VALID.get(key, 1)]  # each list starts with values the key accepts: most examples run far
        sets.append(f"{key}={rng.choice(valid if rng.random() < 0.7 else values)}")
    return sets


# how many values at the head of each friction list a key accepts
VALID = {"loading.friction_coefficient": 4, "loading.tangential_stiffness": 1, "model.slip": 3, "model.stroke": 3,
         "model.increments": 3, "model.wear_law": 2, "materials.moving.energy_wear_coefficient": 1,
         "materials.stationary.energy_wear_coefficient": 1, "geometry.flat_width": 2, "geometry.flat_thickness": 2,
         "geometry.moving_height": 2, "loading.stroke": 2}


def _pick(rng: random.Random, values: list, valid: int) -> str:
    """One of ``values``, mostly from the first ``valid`` (which the key accepts), so most examples reach the plan."""
    return rng.choice(values[:valid] if rng.random() < 0.8 else values)


def _block(rng: random.Random, spectrum: bool) -> str:
    items = [f"normal_load: {_pick(rng, LOADS, 2)}", f"stroke: {_pick(rng, STROKES, 2)}",
             f"fraction: {_pick(rng, FRACTIONS, 2)}" if spectrum else f"cycles: {_pick(rng, CYCLES, 3)}"]
    if rng.random() < 0.3:
        items.append(f"friction_coefficient: {_pick(rng, UNITLESS, 4)}")
    if rng.random() < 0.1:
        items.append(rng.choice(["extra: 1", "cycles: 5", "fraction: 0.5", "stroke: 10 um"]))
    rng.shuffle(items)
    return "{" + ", ".join(items[: len(items) - (rng.random() < 0.1)]) + "}"


def history_example(rng: random.Random) -> str:
    """A `loading:` section with blocks or a spectrum, repeat, cycles, friction and frequency, some of them
    hostile (zero, negative, huge, missing, mixed)."""
    spectrum = rng.random() < 0.35
    lines = ["loading:"]
    if spectrum or rng.random() < 0.3:
        lines.append(f"  cycles: {_pick(rng, CYCLES, 3)}")
    if rng.random() < 0.3:
        lines.append(f"  repeat: {_pick(rng, CYCLES, 2)}")
    if rng.random() < 0.3:
        lines.append(f"  friction_coefficient: {_pick(rng, UNITLESS, 4)}")
    if rng.random() < 0.2:
        lines.append(f"  frequency: {rng.choice(['20 Hz', '0 Hz', '-1 Hz', 'nan Hz', '20'])}")
    if rng.random() < 0.1:
        lines.append(f"  normal_load: {rng.choice(LOADS)}")
    n = rng.choice([0, 1, 2, 2, 3, 5])
    key = "spectrum" if spectrum else "blocks"
    lines.append(f"  {key}: [" + ", ".join(_block(rng, spectrum) for _ in range(n)) + "]")
    return "\n".join(lines) + "\n"


LIMIT_KEYS = ["max_wear_depth_moving", "max_wear_depth_stationary", "centre_wear_depth_stationary",
              "scar_width_stationary", "wear_volume_stationary", "wall_loss", "max_pressure", "x"]
LIMIT_VALUES = ["1 um", "0.5 um", "0 um", "-1 um", "1e9 mm", "nan um", "50 %", "0.5", "2", "0.01 mm3", "1 N", "",
                "1e-30 um", "inf um"]


def limits_example(rng: random.Random) -> list[str]:
    """--set items: one to three wear limits, and sometimes the cycles and frequency that bound them."""
    sets = ["model.dimension=2d", "loading.cycles=" + rng.choice(["2000", "0", "1", "100000"])]
    for key in rng.sample(LIMIT_KEYS, rng.randint(1, 3)):
        sets.append(f"limits.{key}={_pick(rng, LIMIT_VALUES, 2)}")
    if rng.random() < 0.3:
        sets.append("loading.frequency=" + rng.choice(["20 Hz", "0 Hz", "1e-30 Hz"]))
    return sets


DISTRIBUTIONS = [
    "{distribution: lognormal, median: 2e-8 1/MPa, factor: 2}", "{distribution: lognormal, median: 2e-8 1/MPa, factor: 1}",
    "{distribution: lognormal, median: 2e-8 1/MPa, factor: 0.5}", "{distribution: lognormal, median: -1 1/MPa, factor: 2}",
    "{distribution: normal, mean: 2e-8 1/MPa, std: 1e-9 1/MPa}", "{distribution: normal, mean: 2e-8 1/MPa, std: -1 1/MPa}",
    "{distribution: uniform, low: 1e-8 1/MPa, high: 3e-8 1/MPa}", "{distribution: uniform, low: 3e-8 1/MPa, high: 1e-8 1/MPa}",
    "{distribution: weibull}", "{distribution: lognormal}", "{median: 2e-8 1/MPa}", "{}", "[1e-8 1/MPa, 2e-8 1/MPa]",
    "{distribution: uniform, low: 10 um, high: 20 um}", "{distribution: normal, mean: nan 1/MPa, std: 1 1/MPa}"]
SAMPLES = ["{n: 3, seed: 1}", "{n: 3, seed: -1}", "{n: 0, seed: 1}", "{n: -2}", "{n: 1e9, seed: 1}", "{n: 3}",
           "{seed: 2}", "{n: 3, seed: 1.5}", "{n: 3, seed: true}", "{n: 3, seed: 1e30}", "{n: 3, seed: x}", "3", "{}",
           "{n: 2.5, seed: 1}", "{n: 3, seed: 1, method: lhs}", "{n: 3, seed: 99999999999999999999}"]


def sampled_sweep_example(rng: random.Random, base: str) -> str:
    """A sampled sweep file over the wear coefficients (and sometimes a listed axis) of ``base``."""
    lines = [f"base: {base}", "set: [model.dimension=2d, loading.cycles=10]"]
    if rng.random() < 0.1:
        lines.append(f"mode: {rng.choice(['sample', 'product', 'points'])}")
    lines.append(f"sample: {rng.choice(SAMPLES)}")
    lines.append("axes:")
    for key in rng.sample(["materials.moving.wear_coefficient", "materials.stationary.wear_coefficient",
                           "loading.stroke"], rng.randint(0, 3)):
        lines.append(f"  {key}: {rng.choice(DISTRIBUTIONS)}")
    if rng.random() < 0.2:
        lines.append("  loading.normal_load: [185 N, 100 N]")
    return "\n".join(lines) + "\n"


MEASURED_HEADERS = ["cycle [cycles]", "cycle", "cycle [s]", "max_wear_depth_stationary [um]", "max_wear_depth_stationary",
                    "centre_wear_depth_stationary [mm]", "scar_width_stationary [mm]", "wall_loss [%]", "x [mm]",
                    "wear_depth_stationary [um]", "max_pressure [MPa]", "wear_volume_stationary [mm3]", "", "\ufeffcycle [cycles]"]
MEASURED_CELLS = ["1000", "18000", "0", "-1", "inf", "nan", "1e308", "1e999", "2.9", "0.0029", "", " ", "x", "1,5", "3e3",
                  "1.5", "-0", "2900"]


def measured_example(rng: random.Random) -> str:
    """A measured CSV for `fit`: a header of some of the columns fit reads (and some it does not), rows of
    numbers, hostile cells among them; sometimes a comment or a plausible file perturbed."""
    if rng.random() < 0.25:
        rows = ["cycle [cycles],max_wear_depth_stationary [um]", "5000,1.1", "18000,3.0"]
    else:
        cols = rng.sample(MEASURED_HEADERS, rng.randint(0, 4))
        rows = [",".join(cols)] + [",".join(rng.choice(MEASURED_CELLS) for _ in range(max(len(cols) + rng.choice(
            [0, 0, 0, -1, 1]), 0))) for _ in range(rng.randint(0, 5))]
    if rng.random() < 0.2:
        rows.insert(rng.randint(0, len(rows)), "# a comment")
    return "\n".join(rows) + ("\n" if rng.random() < 0.8 else "")


def judge_cli(result) -> str:
    """``ok``: exit 0, or exit 2 with a one-paragraph refusal (a first line, at most a list of problems after it)
    and no traceback; ``traceback`` otherwise."""
    text = result.output
    if "Traceback" in text or (result.exception is not None and not isinstance(result.exception, SystemExit)):
        return "traceback"
    if result.exit_code == 0:
        return "ok"
    if result.exit_code == 2 and text.strip() and all(line.startswith(("fretsim:", "  -", "Usage", "Try", "Error",
                                                                           "warning:", "note:", " "))
                                                      for line in text.strip().splitlines()):
        return "ok"
    return "traceback"
