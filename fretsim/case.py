"""A YAML case → one validated, frozen :class:`Case` (all problems reported together, each with its YAML path).

The layout is a contract users write against (see README): sections ``name``, ``geometry``, ``materials``,
``loading``, ``model``, ``solver``, ``jumping``, ``grid``, ``output``.  Every dimensional value carries its
unit; values are stored in the internal mm–N–MPa system (see :mod:`fretsim.units`).
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Optional

import yaml

from fretsim.units import UnitError, format_quantity, parse_quantity

GEOMETRIES = ("cylinder_on_flat", "ball_on_flat")
SCHEMES = ("implicit", "linear", "adaptive")
# the paper's DOE optimum (section 3.1): η = 0.55, ΔN_max = 600, ΔN_L = 55
PRESETS = {"paper": {"scheme": "adaptive", "eta": 0.55, "max": 600, "linear": 55}}
DIMENSIONS = ("2d", "3d")
SECTIONS = {
    "name": None,
    "geometry": {"type", "radius", "length"},
    "materials": {"moving", "stationary"},
    "loading": {"normal_load", "stroke", "cycles"},
    "model": {"dimension"},
    "solver": {"method", "tolerance"},
    "jumping": {"scheme", "linear", "eta", "max", "tolerance", "preset"},
    "grid": {"domain", "elements", "coarse_element"},
    "output": {"snapshots"},
}
MATERIAL_KEYS = {"youngs_modulus", "poissons_ratio", "wear_coefficient"}
MAX_CYCLES = 10**10
LENGTH_RANGE = (1e-3, 1e4, "1 µm to 10 m")


class CaseError(Exception):
    """A case that cannot be run: every problem with its YAML path."""

    def __init__(self, source: str, problems: list[tuple[str, str]]):
        self.source = source
        self.problems = problems
        super().__init__(str(self))

    def __str__(self) -> str:
        head = f"{self.source}: the case has {len(self.problems)} problem{'s' if len(self.problems) > 1 else ''}"
        return head + ":\n" + "\n".join(f"  - {path}: {msg}" if path else f"  - {msg}" for path, msg in self.problems)


@dataclass(frozen=True)
class Material:
    youngs_modulus: float  # MPa
    poissons_ratio: float
    wear_coefficient: float  # 1/MPa


@dataclass(frozen=True)
class Case:
    name: str
    geometry: str
    radius: float  # mm
    length: Optional[float]  # mm (cylinder only)
    moving: Material
    stationary: Material
    normal_load: float  # N (total)
    stroke: float  # mm, the amplitude δ (sliding distance per cycle 4δ)
    cycles: int
    dimension: str
    solver: str = "cg"
    tolerance: float = 1e-6  # contact solver; tighter changes depths by ~1e-10 (measured), costs ~30 % more
    linear_jump: Optional[int] = None  # None: chosen from the stability limit
    scheme: str = "implicit"  # implicit (controlled backward Euler) | linear | adaptive (paper Eqs. 19-21)
    eta: float = 0.55  # adaptive: accuracy parameter η
    max_jump: Optional[int] = None  # adaptive: ΔN_max; implicit: the largest step (None: unbounded)
    step_tolerance: float = 1e-2  # implicit: local error per step relative to the current maximum depth
    coarse_element: Optional[tuple[float, ...]] = None  # mm: solve the contact on this coarser grid (Eqs. 11-12)
    domain: Optional[tuple[float, ...]] = None  # mm, (x, y) extents
    elements: Optional[tuple[int, ...]] = None
    snapshots: Optional[tuple[int, ...]] = None
    source: str = field(default="<case>", compare=False)

    @property
    def plane_strain(self) -> bool:
        return self.dimension == "2d"

    def with_choices(self, **kw: Any) -> "Case":
        return replace(self, **kw)

    def to_dict(self) -> dict:
        """The case with defaults filled, in the file layout, every dimensional value with its unit."""
        geometry = {"type": self.geometry, "radius": format_quantity(self.radius, "length")}
        if self.length is not None:
            geometry["length"] = format_quantity(self.length, "length")

        def mat(m: Material) -> dict:
            return {"youngs_modulus": format_quantity(m.youngs_modulus, "pressure"),
                    "poissons_ratio": m.poissons_ratio,
                    "wear_coefficient": format_quantity(m.wear_coefficient, "wear_coefficient")}

        grid: dict = {}
        if self.domain is not None:
            grid["domain"] = [format_quantity(d, "length") for d in self.domain]
        if self.elements is not None:
            grid["elements"] = list(self.elements)
        if self.coarse_element is not None:
            grid["coarse_element"] = [format_quantity(d, "length") for d in self.coarse_element]
        return {
            "name": self.name,
            "geometry": geometry,
            "materials": {"moving": mat(self.moving), "stationary": mat(self.stationary)},
            "loading": {"normal_load": format_quantity(self.normal_load, "force"),
                        "stroke": format_quantity(self.stroke, "length"), "cycles": self.cycles},
            "model": {"dimension": self.dimension},
            "solver": {"method": self.solver, "tolerance": self.tolerance},
            "jumping": {"scheme": self.scheme,
                        "linear": self.linear_jump if self.linear_jump is not None else "auto",
                        "eta": self.eta, "max": self.max_jump if self.max_jump is not None else "auto",
                        "tolerance": self.step_tolerance},
            "grid": grid,
            "output": {"snapshots": list(self.snapshots) if self.snapshots is not None else "auto"},
        }

    def to_yaml(self) -> str:
        return yaml.safe_dump(self.to_dict(), sort_keys=False, allow_unicode=True)


def load_case(path: str | Path, overrides: Optional[list[str]] = None) -> Case:
    """Read, override (``key.path=value``) and validate a YAML case file."""
    path = Path(path)
    source = str(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise CaseError(source, [("", "the file does not exist")]) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseError(source, [("", f"cannot read the file: {exc}")]) from None
    return parse_case(text, source=source, overrides=overrides, default_name=path.stem)


def parse_case(text: str, source: str = "<case>", overrides: Optional[list[str]] = None,
               default_name: str = "case") -> Case:
    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise CaseError(source, [("", f"YAML syntax error at {where}{problem}")]) from None
    if raw is None:
        raise CaseError(source, [("", "the file is empty; expected a YAML mapping with the sections "
                                      + ", ".join(SECTIONS))])
    if not isinstance(raw, dict):
        raise CaseError(source, [("", f"expected a YAML mapping of sections at the top level, got a "
                                      f"{type(raw).__name__}")])
    problems: list[tuple[str, str]] = []
    for item in overrides or []:
        _apply_override(raw, item, problems)
    case = _validate(raw, problems, source, default_name)
    if problems:
        raise CaseError(source, problems)
    return case


def _apply_override(raw: dict, item: str, problems: list) -> None:
    key, sep, value = item.partition("=")
    if not sep or not key.strip():
        problems.append((f"--set {item}", "expected key.path=value, e.g. loading.cycles=1000"))
        return
    parts = key.strip().split(".")
    node = raw
    for part in parts[:-1]:
        if not isinstance(node.get(part), dict):
            node[part] = {}
        node = node[part]
    try:
        node[parts[-1]] = yaml.safe_load(value) if value.strip() else None
    except yaml.YAMLError:
        node[parts[-1]] = value


def _plain_number(v: Any) -> Any:
    """YAML 1.1 reads 1e-8 (no dot) as text; accept such numerals as the numbers they are."""
    if isinstance(v, str):
        try:
            return float(v.strip()) if v.strip().lower() not in ("nan", "inf", "-inf", "+inf", "infinity") else v
        except ValueError:
            return v
    return v


class _Reader:
    """Collects problems while reading typed values out of the raw mapping."""

    def __init__(self, problems: list):
        self.problems = problems

    def fail(self, path: str, msg: str) -> None:
        self.problems.append((path, msg))

    def section(self, raw: dict, name: str, keys: set, required: bool = True) -> Optional[dict]:
        """The section's mapping ({} if optional and absent); None, with the problem recorded, if unusable."""
        value = raw.get(name)
        if value is None:
            if required:
                self.fail(name, f"missing section; expected a mapping with keys {', '.join(sorted(keys))}")
                return None
            return {}
        if not isinstance(value, dict):
            self.fail(name, f"expected a mapping with keys {', '.join(sorted(keys))}, got a {type(value).__name__}")
            return None if required else {}
        self.unknown(value, keys, name)
        return value

    def unknown(self, mapping: dict, keys: set, prefix: str) -> None:
        for k in mapping:
            if k not in keys:
                hint = difflib.get_close_matches(str(k), keys, n=1, cutoff=0.6)
                self.fail(f"{prefix}.{k}" if prefix else str(k), "unknown key" + (
                    f" (did you mean '{hint[0]}'?)" if hint else f"; allowed: {', '.join(sorted(keys))}"))

    def quantity(self, mapping: dict, key: str, prefix: str, dimension: str, required: bool = True,
                 positive: bool = True, plausible: Optional[tuple[float, float, str]] = None) -> Optional[float]:
        path = f"{prefix}.{key}"
        if key not in mapping or mapping[key] is None:
            if required:
                self.fail(path, f"missing; expected a {dimension.replace('_', ' ')} with its unit")
            return None
        try:
            v = parse_quantity(mapping[key], dimension)
        except UnitError as exc:
            self.fail(path, str(exc))
            return None
        if positive and not v > 0:
            self.fail(path, f"must be positive, got {mapping[key]!r}")
            return None
        if plausible is not None and not plausible[0] <= v <= plausible[1]:
            self.fail(path, f"{mapping[key]!r} is outside the plausible range {plausible[2]} for a fretting contact: "
                            f"check the value and its unit")
            return None
        return v

    def number(self, mapping: dict, key: str, path: str, lo: float, hi: float, required: bool = True,
               default: Optional[float] = None, open_hi: bool = False) -> Optional[float]:
        if key not in mapping or mapping[key] is None:
            if required:
                self.fail(path, f"missing; expected a number in [{lo}, {hi}{')' if open_hi else ']'}")
            return default
        v = _plain_number(mapping[key])
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            self.fail(path, f"expected a plain number, got {v!r}")
            return None
        if not (lo <= v <= hi) or (open_hi and v >= hi):
            self.fail(path, f"{v!r} is out of range; expected a number in [{lo}, {hi}{')' if open_hi else ']'}")
            return None
        return float(v)

    def integer(self, value: Any, path: str, lo: int, hi: int) -> Optional[int]:
        value = _plain_number(value)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or (
                isinstance(value, float) and not (math.isfinite(value) and value.is_integer())):
            self.fail(path, f"expected a whole number, got {value!r}")
            return None
        if not lo <= value <= hi:
            self.fail(path, f"{value!r} is out of range; expected a whole number from {lo} to {hi}")
            return None
        return int(value)

    def vector(self, mapping: dict, key: str, want: int, item, expected: str) -> Optional[tuple]:
        """A list of one (2d) or two (3d) items, each read by ``item(value, path)``; None if absent or bad."""
        path = f"grid.{key}"
        value = mapping.get(key) if mapping else None
        if value is None:
            return None
        if not isinstance(value, list) or not 1 <= len(value) <= 2:
            self.fail(path, f"expected a list {expected}")
            return None
        vals = [item(v, f"{path}[{i}]") for i, v in enumerate(value)]
        if len(value) < want:
            self.fail(path, f"a 3d case needs two entries: {expected}")
            return None
        return None if None in vals else tuple(vals[:want])

    def choice(self, mapping: dict, key: str, path: str, options: tuple, default: Optional[str] = None):
        v = mapping.get(key, default)
        if v is None:
            self.fail(path, f"missing; expected one of {', '.join(options)}")
            return None
        if v not in options:
            hint = difflib.get_close_matches(str(v), options, n=1)
            self.fail(path, f"unknown value {v!r}" + (f" (did you mean '{hint[0]}'?)" if hint else "")
                      + f"; expected one of {', '.join(options)}")
            return None
        return v


def _validate(raw: dict, problems: list, source: str, default_name: str) -> Optional[Case]:
    from fretsim.solvers import SOLVERS  # the registry decides which names are valid

    r = _Reader(problems)
    r.unknown(raw, set(SECTIONS), "")
    name = raw.get("name", default_name)
    if not isinstance(name, (str, int, float)) or isinstance(name, bool):
        r.fail("name", f"expected a text, got a {type(name).__name__}")
        name = default_name
    name = str(name)

    geo = r.section(raw, "geometry", SECTIONS["geometry"])
    gtype = r.choice(geo, "type", "geometry.type", GEOMETRIES) if geo is not None else None
    radius = r.quantity(geo, "radius", "geometry", "length", plausible=LENGTH_RANGE) if geo is not None else None
    length = None
    if gtype == "cylinder_on_flat":
        length = r.quantity(geo, "length", "geometry", "length", plausible=LENGTH_RANGE)
    elif gtype == "ball_on_flat" and geo.get("length") is not None:
        r.fail("geometry.length", "a ball has no axial length; remove this key")

    mats = r.section(raw, "materials", SECTIONS["materials"])
    materials = {}
    for body in ("moving", "stationary"):
        if mats is None:
            break
        m = mats.get(body)
        path = f"materials.{body}"
        if not isinstance(m, dict):
            r.fail(path, "missing; expected a mapping with youngs_modulus, poissons_ratio, wear_coefficient"
                   if m is None else f"expected a mapping, got a {type(m).__name__}")
            continue
        r.unknown(m, MATERIAL_KEYS, path)
        e = r.quantity(m, "youngs_modulus", path, "pressure", plausible=(1.0, 1e7, "1 MPa to 10 TPa"))
        nu = r.number(m, "poissons_ratio", f"{path}.poissons_ratio", -1.0, 0.5, open_hi=True)
        if nu is not None and nu <= -1.0:
            r.fail(f"{path}.poissons_ratio", "must be greater than -1")
            nu = None
        k = r.quantity(m, "wear_coefficient", path, "wear_coefficient", positive=False,
                       plausible=(0.0, 1e-3, "0 to 1e-3 1/MPa"))
        if k is not None and k < 0:
            r.fail(f"{path}.wear_coefficient", f"must not be negative, got {m['wear_coefficient']!r}")
            k = None
        if None not in (e, nu, k):
            materials[body] = Material(e, nu, k)

    load = r.section(raw, "loading", SECTIONS["loading"])
    normal_load = r.quantity(load, "normal_load", "loading", "force", plausible=(1e-6, 1e7, "1 µN to 10 MN")) \
        if load is not None else None
    stroke = r.quantity(load, "stroke", "loading", "length", plausible=(1e-6, 10.0, "1 nm to 10 mm")) \
        if load is not None else None
    cycles = None
    if load is not None:
        if "cycles" not in load:
            r.fail("loading.cycles", "missing; expected a whole number of cycles (0 solves the contact alone)")
        else:
            cycles = r.integer(load["cycles"], "loading.cycles", 0, MAX_CYCLES)

    model = r.section(raw, "model", SECTIONS["model"], required=False)
    dimension = r.choice(model, "dimension", "model.dimension", DIMENSIONS, default="3d")
    if dimension == "2d" and gtype == "ball_on_flat":
        r.fail("model.dimension", "a ball on a flat is a point contact: it needs 3d (2d is a line contact)")

    solver = r.section(raw, "solver", SECTIONS["solver"], required=False)
    method = r.choice(solver, "method", "solver.method", tuple(SOLVERS), default="cg")
    tolerance = r.number(solver, "tolerance", "solver.tolerance", 1e-14, 1e-2, required=False, default=1e-6)

    jumping = dict(r.section(raw, "jumping", SECTIONS["jumping"], required=False))
    if "preset" in jumping:
        preset = r.choice(jumping, "preset", "jumping.preset", tuple(PRESETS))
        jumping = {**PRESETS.get(preset, {}), **{k: v for k, v in jumping.items() if k != "preset"}}
    # a block giving only `linear` keeps its original meaning: explicit linear jumping
    default_scheme = "linear" if "linear" in jumping and jumping["linear"] not in ("auto", None) else "implicit"
    scheme = r.choice(jumping, "scheme", "jumping.scheme", SCHEMES, default=default_scheme)
    linear = jumping.get("linear", "auto")
    linear_jump = None
    if linear not in ("auto", None):
        linear_jump = r.integer(linear, "jumping.linear", 1, MAX_CYCLES)
    eta = r.number(jumping, "eta", "jumping.eta", 1e-6, 10.0, required=False, default=0.55)
    max_jump = None
    if jumping.get("max", "auto") not in ("auto", None):
        max_jump = r.integer(jumping["max"], "jumping.max", 1, MAX_CYCLES)
    step_tolerance = r.number(jumping, "tolerance", "jumping.tolerance", 1e-8, 0.5, required=False, default=1e-2)

    grid = r.section(raw, "grid", SECTIONS["grid"], required=False)
    want = 1 if dimension == "2d" else 2

    def length_item(v, path):
        return r.quantity({"v": v}, "v", path, "length")

    def count_item(v, path):
        return r.integer(v, path, 1, 100_000)

    domain = r.vector(grid, "domain", want, length_item, "[x extent, y extent] of lengths, e.g. [1 mm, 10 mm]")
    elements = r.vector(grid, "elements", want, count_item, "[Mx, My] of whole numbers, e.g. [101, 27]")
    coarse = r.vector(grid, "coarse_element", want, length_item,
                      "[dx, dy] of lengths, e.g. [15.75 um, 1000 um]")

    output = r.section(raw, "output", SECTIONS["output"], required=False)
    snaps = output.get("snapshots", "auto")
    snapshots = None
    if snaps not in ("auto", None):
        if not isinstance(snaps, list):
            r.fail("output.snapshots", "expected a list of cycle numbers, e.g. [1000, 5000, 18000]")
        else:
            vals = [r.integer(v, f"output.snapshots[{i}]", 0, MAX_CYCLES) for i, v in enumerate(snaps)]
            if None not in vals:
                snapshots = tuple(sorted(set(vals)))

    if domain is not None and stroke is not None and stroke >= domain[0] / 2:
        r.fail("loading.stroke", f"the stroke amplitude {load['stroke']!r} is larger than half the grid's "
                                 f"x extent ({domain[0]:.4g} mm): check its unit")
    if problems:
        return None
    return Case(name=name, geometry=gtype, radius=radius, length=length, moving=materials["moving"],
                stationary=materials["stationary"], normal_load=normal_load, stroke=stroke, cycles=cycles,
                dimension=dimension, solver=method, tolerance=tolerance, linear_jump=linear_jump, scheme=scheme,
                eta=eta, max_jump=max_jump, step_tolerance=step_tolerance, coarse_element=coarse, domain=domain,
                elements=elements, snapshots=snapshots, source=source)
