"""Strict parsing of quantities with units.

fretsim works internally in the consistent mm–N–MPa system: lengths in mm,
forces in N, pressures and moduli in MPa (N/mm²), wear coefficients in 1/MPa
(mm²/N, so that k·p·s is a length in mm), energy wear coefficients in mm³/(N·mm) (the same 1/MPa, so that
α·q·s is a length), tangential stiffnesses in N/mm.  Every dimensional value in a case
file carries its unit; this module converts it to the internal unit or says
exactly why it cannot.  It is deliberately tiny (a table, one regex) so that
the CLI starts quickly in sweeps that launch it thousands of times.
"""
from __future__ import annotations

import functools
import math
import re

# dimension -> {unit spelling: factor to the internal unit}
UNITS: dict[str, dict[str, float]] = {
    "length": {"km": 1e6, "m": 1e3, "mm": 1.0, "um": 1e-3, "µm": 1e-3, "micron": 1e-3, "microns": 1e-3, "nm": 1e-6,
               "cm": 10.0},
    "force": {"N": 1.0, "kN": 1e3, "MN": 1e6, "mN": 1e-3, "uN": 1e-6, "µN": 1e-6},
    "pressure": {"Pa": 1e-6, "kPa": 1e-3, "MPa": 1.0, "GPa": 1e3, "N/mm2": 1.0, "N/mm^2": 1.0},
    # Archard's k with the hardness in it: 1/MPa = mm²/N = mm³/(N·mm); tribologists quote the specific wear rate
    # in mm³/(N·m) (volume per load and sliding distance), a thousandth of it
    "wear_coefficient": {"1/MPa": 1.0, "mm3/(N*m)": 1e-3, "mm3/(N*mm)": 1.0, "1/Pa": 1e6, "m2/N": 1e6, "mm2/N": 1.0,
                         "1/GPa": 1e-3, "mm^2/N": 1.0, "m^2/N": 1e6, "mm3/Nm": 1e-3, "m3/(N*m)": 1e6},
    # worn volume per dissipated energy (Fouvry's α): 1 J = 1000 N·mm
    "energy_wear_coefficient": {"mm3/J": 1e-3, "mm^3/J": 1e-3, "um3/J": 1e-12, "µm3/J": 1e-12, "µm^3/J": 1e-12,
                                "m3/J": 1e6, "m^3/J": 1e6, "mm3/Nm": 1e-3, "mm3/(N*m)": 1e-3, "mm3/(N*mm)": 1.0},
    "frequency": {"Hz": 1.0, "kHz": 1e3, "1/s": 1.0, "1/min": 1.0 / 60, "cpm": 1.0 / 60},
    "volume": {"mm3": 1.0, "mm^3": 1.0, "um3": 1e-9, "µm3": 1e-9, "m3": 1e9, "cm3": 1e3},
    "stiffness": {"N/mm": 1.0, "N/um": 1e3, "N/µm": 1e3, "kN/mm": 1e3, "N/m": 1e-3, "kN/m": 1.0, "MN/m": 1e3},
}
INTERNAL = {"length": "mm", "force": "N", "pressure": "MPa", "wear_coefficient": "1/MPa",
            "energy_wear_coefficient": "mm3/(N*mm)", "stiffness": "N/mm", "frequency": "Hz", "volume": "mm3"}

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?inf|nan)\s*(\S.*?)\s*$", re.IGNORECASE)
_TYPESET = str.maketrans({"·": "*", "⋅": "*", "×": "*", "³": "3", "²": "2", "^": None, "μ": "µ", "⁻": "-",
                          "¹": "1"})  # (μ: the Greek letter, typed for the micro sign µ)


def _plain_unit(unit: str) -> str:
    """A unit as typed or typeset — mm³/(N·m), mm^3/(N m), mm3/N/m, mm3 N-1 m-1 — in the tables' spelling,
    mm3/(N*m): a space between two symbols is a product, any other is dropped; a chain of divisions, or
    symbols to the power −1, is one denominator."""
    unit = re.sub(r"(?<=[\w)])\s+(?=[\w(])", "*", unit.strip())
    unit = re.sub(r"\s+", "", unit).translate(_TYPESET)
    if "(" not in unit:
        parts = unit.split("*")
        below = [t[:-2] for t in parts if t.endswith("-1") and len(t) > 2]
        if below and len(below) < len(parts):
            unit = "*".join(t for t in parts if not (t.endswith("-1") and len(t) > 2)) + "/" + "*".join(below)
        num, *den = unit.split("/")
        if len(den) == 1 and "*" in den[0] or len(den) > 1:
            unit = f"{num}/({'*'.join(den)})"
    return unit


class UnitError(ValueError):
    """A value whose unit is missing, unknown or of the wrong dimension."""


@functools.lru_cache(maxsize=1)
def _plain_tables() -> dict:
    return {dim: {_plain_unit(k): v for k, v in table.items()} for dim, table in UNITS.items()}


def parse_quantity(value: object, dimension: str) -> float:
    """Return ``value`` (e.g. ``"25 um"``) in the internal unit of ``dimension``.

    Raises :class:`UnitError` with a message that says what was expected.  (Cached: a sweep reads the same few
    texts for 10⁵ points.)
    """
    if isinstance(value, str):
        return _parse_text(value, dimension)
    return _parse_quantity(value, dimension)


@functools.lru_cache(maxsize=65536)
def _parse_text(value: str, dimension: str) -> float:
    return _parse_quantity(value, dimension)


def _parse_quantity(value: object, dimension: str) -> float:
    table = UNITS[dimension]
    shown = [u for u in table if u != "km"][:5]
    expected = f"a number with a {dimension.replace('_', ' ')} unit ({', '.join(shown)}), e.g. '{example(dimension)}'"
    if isinstance(value, bool) or value is None:
        raise UnitError(f"got {_short(value)}; expected {expected}")
    if isinstance(value, (int, float)):
        raise UnitError(f"got the bare number {_short(value)} without a unit; expected {expected}")
    if not isinstance(value, str):
        raise UnitError(f"got a {type(value).__name__}; expected {expected}")
    m = _QUANTITY.match(value)
    if not m:
        raise UnitError(f"could not read {_short(value)}; expected {expected}")
    number, unit = float(m.group(1)), m.group(2)
    if re.fullmatch(r"[\d.eE+-]+", unit):  # '25' read as 2 and '5'
        raise UnitError(f"got the bare number {_short(value)} without a unit; expected {expected}")
    if unit not in table:
        plain = _plain_tables()[dimension]
        if _plain_unit(unit) in plain:
            table, unit = plain, _plain_unit(unit)
    if unit not in table:
        for dim, other in UNITS.items():
            if unit in other and dim != dimension:
                raise UnitError(f"{_short(value)} is a {dim.replace('_', ' ')}, not a {dimension.replace('_', ' ')}; expected {expected}")
        raise UnitError(f"unknown unit {unit!r} in {_short(value)}; expected {expected}")
    if not math.isfinite(number):
        raise UnitError(f"{_short(value)} is not a finite number")
    return number * table[unit]


def _short(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:35] + "…" + text[-4:]


def example(dimension: str) -> str:
    return {"length": "25 um", "force": "185 N", "pressure": "200 GPa", "wear_coefficient": "2.0e-8 1/MPa",
            "energy_wear_coefficient": "2.5e-5 mm3/J", "stiffness": "40 N/um", "frequency": "30 Hz",
            "volume": "0.01 mm3"}[dimension]


def format_quantity(value: float, dimension: str) -> str:
    """Inverse of :func:`parse_quantity` in the internal unit (used to write the filled case)."""
    return f"{float(value)!r} {INTERNAL[dimension]}"  # repr round-trips exactly: a resumed run rebuilds the same grid
