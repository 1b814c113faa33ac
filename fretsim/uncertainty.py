"""Uncertainty: sweep axes that are distributions, sampled by Latin hypercube, and the percentiles of what the
points report.

A sweep file with ``sample: {n: 200, seed: 1}`` may give an axis as a distribution instead of a list, in the
axis's own unit:

    materials.moving.wear_coefficient: {distribution: lognormal, median: 2e-8 1/MPa, factor: 2}
    loading.normal_load: {distribution: normal, mean: 40 N, sd: 4 N}
    loading.friction_coefficient: {distribution: uniform, low: 0.6, high: 0.9}

``factor`` is the geometric standard deviation (ln of it is the σ of ln x: two thirds of the values lie within
median/factor … median·factor).  The n samples of all distributed axes are one Latin hypercube (scipy's
``stats.qmc``): each axis's range is cut into n equally likely strata and each stratum is sampled once, which
estimates percentiles with a fraction of plain Monte Carlo's scatter.  Axes given as lists are crossed with the
samples: every listed value gets the same n samples (paired, so that a difference between groups is not sampling
noise).
"""
from __future__ import annotations

import math
from typing import Optional

DISTRIBUTIONS = {"normal": ("mean", "sd"), "lognormal": ("median", "factor"), "uniform": ("low", "high")}


def _split(value) -> tuple[float, str]:
    """A value as written ('2e-8 1/MPa', 40, '0.6') → (number, unit text, '' for none)."""
    from fretsim.units import _QUANTITY
    if isinstance(value, bool):
        raise ValueError(f"expected a number, got {value!r}")
    if isinstance(value, (int, float)):
        return float(value), ""
    m = _QUANTITY.match(str(value))
    if not m:
        try:
            return float(str(value)), ""
        except ValueError:
            raise ValueError(f"could not read {value!r}; expected a number with the axis's unit") from None
    return float(m.group(1)), m.group(2)


def check(spec) -> Optional[str]:
    """What is wrong with a distribution's mapping (None if nothing)."""
    if not isinstance(spec, dict) or "distribution" not in spec:
        return "expected a list of values or a mapping with distribution (normal, lognormal or uniform)"
    kind = spec["distribution"]
    if kind not in DISTRIBUTIONS:
        return f"unknown distribution {kind!r}; expected one of {', '.join(DISTRIBUTIONS)}"
    need = DISTRIBUTIONS[kind]
    extra = set(spec) - {"distribution", *need}
    if extra or any(k not in spec for k in need):
        return f"a {kind} distribution takes {' and '.join(need)} (in the axis's unit); got {', '.join(map(str, spec))}"
    try:
        (a, ua), (b, ub) = (_split(spec[k]) for k in need)
    except ValueError as exc:
        return str(exc)
    if kind == "lognormal":
        if ub:
            return "factor is a plain number (the geometric standard deviation, e.g. 2)"
        if not (a > 0 and b > 1):
            return "lognormal needs median > 0 and factor > 1"
    elif ua != ub and not (kind == "normal" and ub == "" and b == 0):
        return f"{need[0]} and {need[1]} must be in one unit ({ua or 'none'} and {ub or 'none'})"
    elif kind == "normal" and not b > 0:
        return "normal needs sd > 0"
    elif kind == "uniform" and not b > a:
        return "uniform needs high > low"
    return None


def sample(specs: dict, n: int, seed: int) -> list[dict]:
    """n points of the distributed axes (key → value as written, in the axis's unit), one Latin hypercube."""
    import numpy as np
    from scipy.stats import norm, qmc
    keys = list(specs)
    u = qmc.LatinHypercube(d=len(keys), seed=seed).random(n)
    columns = {}
    for j, k in enumerate(keys):
        spec = specs[k]
        kind = spec["distribution"]
        a, unit = _split(spec[DISTRIBUTIONS[kind][0]])
        b, _ = _split(spec[DISTRIBUTIONS[kind][1]])
        if kind == "normal":
            x = a + b * norm.ppf(u[:, j])
        elif kind == "lognormal":
            x = a * np.exp(math.log(b) * norm.ppf(u[:, j]))
        else:
            x = a + (b - a) * u[:, j]
        columns[k] = [f"{v:.6g} {unit}" if unit else float(f"{v:.6g}") for v in x]
    return [{k: columns[k][i] for k in keys} for i in range(n)]


def percentiles(rows: list, group_keys: list, units: dict) -> list[dict]:
    """One row per (group, summary value): key, p10, p50, p90, its unit, the points it is over, those where it
    is missing and the group's points that did not complete (stopped at a physical limit, failed: not counted,
    which biases the percentiles if they are many).  A limit never reached (cycles_to_limit NaN) counts as beyond every reached one: its percentile is
    then inf ('not reached within loading.cycles')."""
    from fretsim.measures import PERCENTILES, quantiles
    import numpy as np
    done = [r for r in rows if r.get("status") == "complete"]
    groups: dict = {}
    for r in done:
        groups.setdefault(tuple(r.get(k) for k in group_keys), []).append(r)
    others: dict = {}  # the points that did not complete (stopped at a physical limit, failed): not in the numbers
    for r in rows:
        if r.get("status") != "complete":
            key = tuple(r.get(k) for k in group_keys)
            others[key] = others.get(key, 0) + 1
    out = []
    censored = {"cycles_to_limit", "time_to_limit_h"}
    for group, members in groups.items():
        for key, unit in units.items():
            vals = [r.get(key) for r in members]
            if not vals or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
                continue
            arr = np.array(vals, dtype=float)
            if key in censored and any(r.get("limit_reached") for r in members):
                arr = np.where(np.isnan(arr), np.inf, arr)
            finite = arr[~np.isnan(arr)]
            if not finite.size:
                continue
            p = quantiles(finite)
            out.append({**dict(zip(group_keys, group)), "key": key, **{f"p{q}": float(v) for q, v in
                                                                        zip(PERCENTILES, p)},
                        "unit": unit, "points": int(finite.size), "missing": int(arr.size - finite.size),
                        "not_complete": others.get(group, 0)})
    return out
