"""A YAML case → one validated, frozen :class:`Case` (all problems reported together, each with its YAML path).

The layout is a contract users write against (see README): sections ``name``, ``geometry``, ``materials``,
``loading``, ``model``, ``solver``, ``jumping``, ``grid``, ``output`` and ``expected`` (published values kept
beside the inputs, never run).  Every key is declared once in :data:`SCHEMA` — its kind, unit, default,
range and meaning — and read from there; ``fretsim case-reference`` prints the same table, so the reference
cannot drift from the parser.  Values are stored in the internal mm–N–MPa system (see :mod:`fretsim.units`).
"""
from __future__ import annotations

import difflib
import functools
import hashlib
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Optional

import numpy as np

from fretsim.cycle import CYCLES, STROKES, friction_needed
from fretsim.errors import InputError
from fretsim.geometry import GEOMETRIES, Geometry
from fretsim.loading import Block, Loading, expand
from fretsim.quantities import WEAR
from fretsim.stepping import DEFAULT_SCHEME, SCHEMES
from fretsim.units import UNITS, UnitError, format_quantity, parse_quantity
from fretsim.wear_laws import WEAR_LAWS, gross_slip_coefficients
from fretsim.yamlread import YamlProblem, excerpt, loads, read_text


class Names:
    """The names a case may give for a family's members: a live view of its registry (so a member registered
    later, a test's say, is accepted), after the words that are not members (``auto``)."""

    def __init__(self, registry, extra: tuple = ()):
        self.registry, self.extra = registry, tuple(extra)

    def __iter__(self):
        yield from self.extra
        yield from self.registry

    def __contains__(self, name) -> bool:
        return name in self.extra or name in self.registry

    def __len__(self) -> int:
        return len(self.extra) + len(self.registry)

    def __getitem__(self, i):
        return tuple(self)[i]


# the paper's DOE optimum (section 3.1): η = 0.55, ΔN_max = 600, ΔN_L = 55
PRESETS = {"paper": {"scheme": "adaptive", "eta": 0.55, "max": 600}}
PRESET_LINEAR = {"paper": 55}  # a preset's ΔN_L: not filled into the case, the planner scales it to the grid
DIMENSIONS = ("2d", "3d", "auto")
GAP_MODELS = ("auto", "mid_stroke", "stroke_average")
SLIP_MODELS = Names(CYCLES, ("auto",))
GRID_RULES = ("accuracy", "paper")
GRID_ERRORS = ("companion", "none")
STROKE_MODELS = Names(STROKES, ("auto",))
CORRECTIONS = ("ring_bending", "free_faces")
MAX_CYCLES = 10**10
LENGTH_RANGE = (1e-3, 1e4, "1 µm to 10 m")
REQUIRED = object()


@dataclass(frozen=True)
class Key:
    """One case key: its kind (a unit dimension, or number, integer, choice, text, …), default and meaning."""

    kind: str
    help: str
    default: Any = None  # REQUIRED, None (optional, absent), or the value used when absent
    lo: float = -math.inf
    hi: float = math.inf
    plausible: Optional[tuple] = None  # (lo, hi, text) in internal units: outside is refused as implausible
    choices: tuple = ()
    positive: bool = True  # quantities: must be > 0 (else ≥ 0)
    example: str = ""  # a value for templates (`fretsim init`) where there is no default
    any_case: bool = False  # choices: also accepted in capitals (2D/3D, as the paper and the summaries print them)

    def unit(self) -> str:
        from fretsim.units import INTERNAL
        return INTERNAL.get(self.kind, {"fraction": "% or fraction"}.get(self.kind, "–"))


GEOMETRY_KEYS: dict[str, dict[str, Key]] = {
    "cylinder_on_flat": {
        "radius": Key("length", "cylinder radius R (Eq. 9)", REQUIRED, plausible=LENGTH_RANGE, example="6 mm"),
        "length": Key("length", "cylinder length L along y (the line contact's length)", REQUIRED,
                      plausible=LENGTH_RANGE, example="10 mm"),
        "block_length": Key("length", "the flat's length along y when it ends in free faces, centred on the "
                                      "cylinder (McColl's flat: as long as the cylinder; at least L); omitted: the "
                                      "flat runs on well beyond the contact", None, plausible=LENGTH_RANGE),
        "flat_width": Key("length", "the flat as a block: its width along x, centred on the contact; its far face "
                                    "(flat_thickness below the contact) carries the stroke, and the block's tangential "
                                    "compliance, from a one-off plane-strain solve, replaces the half-space's datum "
                                    "(give both; omitted: a half-space)", None, plausible=LENGTH_RANGE,
                          example="12 mm"),
        "flat_thickness": Key("length", "the flat block's height, from the contact to the face that carries the "
                                        "stroke (with flat_width)", None, plausible=LENGTH_RANGE, example="6 mm"),
        "moving_height": Key("length", "where the cylinder is held, measured from the contact (at most R: the "
                                       "half-cylinder held at its flat face is R); its tangential compliance replaces "
                                       "the half-space's datum; omitted: a half-space", None, plausible=LENGTH_RANGE,
                             example="6 mm")},
    "ball_on_flat": {
        "radius": Key("length", "ball radius R (Eq. 10)", REQUIRED, plausible=LENGTH_RANGE, example="6 mm")},
    "crossed_cylinders": {
        "radius": Key("length", "radius R₁ of the moving cylinder", REQUIRED, plausible=LENGTH_RANGE,
                      example="0.225 mm"),
        "radius_stationary": Key("length", "radius R₂ of the stationary cylinder (default: R₁)", None,
                                 plausible=LENGTH_RANGE),
        "sliding": Key("choice", "the moving cylinder slides across its axis or along it", "across",
                       choices=("across", "along"))},
    "tube_on_flat": {
        "outer_radius": Key("length", "outer radius R_o of the tube (the contact's radius)", REQUIRED,
                            plausible=LENGTH_RANGE, example="8.75 mm"),
        "inner_radius": Key("length", "inner radius R_i of the tube (the wall is R_o − R_i)", REQUIRED,
                            plausible=LENGTH_RANGE, example="7.75 mm"),
        "length": Key("length", "contact length along the tube's axis (the flat's length)", REQUIRED,
                      plausible=LENGTH_RANGE, example="12 mm")},
    "roller_on_flat": {
        "radius": Key("length", "roller radius R", REQUIRED, plausible=LENGTH_RANGE, example="6 mm"),
        "length": Key("length", "roller length L along y", REQUIRED, plausible=LENGTH_RANGE, example="10 mm"),
        "crown_radius": Key("length", "crowning: the axial profile drops by y²/2R_c", None, plausible=LENGTH_RANGE,
                            example="500 mm"),
        "edge_radius": Key("length", "edge rounding: beyond flat_length/2 the profile drops by (|y| − l/2)²/2r_e",
                           None, plausible=LENGTH_RANGE),
        "flat_length": Key("length", "the straight middle of an edge-rounded roller", None, plausible=LENGTH_RANGE),
        "block_length": Key("length", "the flat's length along y when it ends in free faces, centred on the "
                                      "roller (at least L); omitted: the flat runs on well beyond the contact", None,
                            plausible=LENGTH_RANGE),
        "profile": Key("profile_file", "a CSV of the axial profile drop: a header `y [unit], drop [unit]`, then rows "
                               "(relative to the case file; read as given, so an asymmetric profile stays asymmetric; mirrored if "
                               "given for y ≥ 0 only; it must cover the roller's length; 3D only)", None),
        "profile_table": Key("table", "the same profile inline: {y: [lengths], drop: [lengths]} (the filled case "
                                      "carries it, so a results file reruns without the CSV)", None)},
}

FATIGUE_SCHEMA: dict[str, Key] = {  # materials.<body>.fatigue: the Basquin–Coffin–Manson curve and its options
    "strength_coefficient": Key("pressure", "fatigue strength coefficient σ'_f", REQUIRED,
                                plausible=(10.0, 1e5, "10 MPa to 100 GPa"), example="2030 MPa"),
    "strength_exponent": Key("number", "fatigue strength exponent b (negative)", REQUIRED, lo=-1.0, hi=-1e-6,
                             example="-0.104"),
    "ductility_coefficient": Key("number", "fatigue ductility coefficient ε'_f", REQUIRED, lo=1e-6, hi=10.0,
                                 example="0.841"),
    "ductility_exponent": Key("number", "fatigue ductility exponent c (negative)", REQUIRED, lo=-3.0, hi=-1e-6,
                              example="-0.688"),
    "critical_distance": Key("length", "the SWT parameter averaged over this depth below each surface point "
                                       "(the line method: the stress gradient's size effect); omitted: the value "
                                       "at each point", None, plausible=(1e-6, 10.0, "1 nm to 10 mm"),
                             example="50 um"),
    "endurance_limit": Key("pressure", "the fully reversed stress amplitude below which no crack starts: SWT "
                                       "values below σ_e²/E count no damage; omitted: the curve alone", None,
                           plausible=(1.0, 1e5, "1 MPa to 100 GPa"), example="300 MPa"),
}
FATIGUE_KEYS_TEXT = tuple(FATIGUE_SCHEMA)

SCHEMA: dict[str, dict[str, Key]] = {
    "geometry": {"type": Key("choice", "the contact geometry", REQUIRED, choices=tuple(GEOMETRY_KEYS))},
    "material": {  # each of materials.moving and materials.stationary
        "youngs_modulus": Key("pressure", "Young's modulus E", REQUIRED, plausible=(1.0, 1e7, "1 MPa to 10 TPa"),
                              example="200 GPa"),
        "poissons_ratio": Key("number", "Poisson's ratio ν", REQUIRED, lo=-1.0, hi=0.5, example="0.3"),
        "wear_coefficient": Key("wear_coefficient", "Archard wear coefficient k (Eqs. 14–16; includes hardness); "
                                                    "required with model.wear_law archard", None,
                                # 1e-4 1/MPa is 0.1 mm³/(N·m): a hundred times the fastest-wearing polymers; beyond,
                                # the wear of one cycle outruns the elastic contact (k_s 1e-3 stopped a 2D run at
                                # cycle 1 and crawled in 3D)
                                plausible=(0.0, 1e-4, "0 to 1e-4 1/MPa (0.1 mm3/(N·m))"), positive=False,
                                example="2.0e-8 1/MPa"),
        "energy_wear_coefficient": Key("energy_wear_coefficient", "energy wear coefficient α (Fouvry): worn volume "
                                                                  "per dissipated energy, dh = α·|q|·|ds|; "
                                                                  "required with model.wear_law energy", None,
                                       plausible=(0.0, 1.0, "0 to 1000 mm3/J"), positive=False),
        "yield_strength": Key("pressure", "tensile yield strength σ_y, optional: `check` and `run` warn where the "
                                          "unworn Hertz peak pressure passes the onset of yield below the surface "
                                          "(p0 = 1.60 σ_y for a point contact, 1.79 σ_y for a line contact; von "
                                          "Mises, ν = 0.3, Johnson §6.2)", None,
                              plausible=(1.0, 1e5, "1 MPa to 100 GPa"), example="250 MPa"),
        "fatigue": Key("fatigue", "opt-in fretting fatigue of this body (the flat; the moving body as a half-space "
                                  "of its own, a cylinder whose contact half-width is at most a tenth of its "
                                  "radius): the strain-life curve's constants, a mapping of "
                                  + ", ".join(FATIGUE_KEYS_TEXT) + "; with it the run reports the body's SWT "
                                  "parameter under the contact, its crack-initiation life over the wear history "
                                  "and the damage mode (the flat's in 2D and 3D, the moving body's in 2D; README); "
                                  "omitted: none", None)},
    "loading": {
        "normal_load": Key("force", "normal load P (total, both in 2D and 3D)", REQUIRED,
                           plausible=(1e-6, 1e7, "1 µN to 10 MN"), example="185 N"),
        "stroke": Key("length", "slip amplitude δ (sliding distance 4δ per cycle)", REQUIRED,
                      plausible=(1e-6, 10.0, "1 nm to 10 mm"), example="25 um"),
        "cycles": Key("integer", "fretting cycles N (0 solves the contact alone)", REQUIRED, lo=0, hi=MAX_CYCLES,
                      example="18000"),
        "friction_coefficient": Key("number", "friction coefficient μ (Coulomb): the shear traction |q| ≤ μp of "
                                              "model.slip coulomb, the regime (partial or gross slip) and, for "
                                              "the uniform model, the energy law and the reported energy. μ = 0 "
                                              "is frictionless: no shear traction, nothing sticks (δ_t = 0, gross "
                                              "slip), every point slides the whole stroke, no energy is dissipated; "
                                              "auto takes the uniform model, which is exact then, and model.slip "
                                              "coulomb, model.stroke resolved and the energy law, which have nothing "
                                              "to work with, are refused", None,
                                    lo=0.0, hi=10.0),
        "blocks": Key("blocks", "a load history instead of one load: a list of blocks, each with normal_load, "
                                "stroke, cycles (and friction_coefficient where it differs), applied in order; with "
                                "`repeat` the list is applied that many times, with `cycles` it is repeated up to "
                                "that many cycles (the last pass cut short)", None),
        "spectrum": Key("blocks", "a load spectrum: a list of blocks with normal_load, stroke and fraction (of "
                                  "loading.cycles), applied in order, in `repeat` passes (each block's cycles "
                                  "split evenly among them)", None),
        "repeat": Key("integer", "how many times loading.blocks is applied (or the passes a spectrum is split "
                                 "into)", None, lo=1, hi=100_000),
        "frequency": Key("frequency", "the fretting frequency: with it, the time to a wear limit is reported "
                                      "too; omitted: cycles only", None, plausible=(1e-6, 1e6, "1 µHz to 1 MHz"),
                         example="30 Hz"),
        "tangential_stiffness": Key("stiffness", "the rig's tangential stiffness: it takes Q/k of the stroke, the "
                                                 "contact the rest (as in fretting rigs and FE models of them); "
                                                 "omitted: a rigid rig", None,
                                    plausible=(1e-3, 1e12, "1 N/m to 1e12 N/mm"))},
    "model": {
        "dimension": Key("choice", "2d (line contact per unit length), 3d, or auto: the cheapest within "
                                   "model.accuracy", "auto", choices=DIMENSIONS, any_case=True),
        "gap": Key("choice", "how the flat's wear enters the gap: mid_stroke (the paper, Eq. 18), stroke_average "
                             "(stable for any wear coefficients) or auto", "auto", choices=GAP_MODELS),
        "corrections": Key("corrections", "compliance added to the half-spaces: `auto` (each where its effect "
                                          "exceeds model.accuracy), `none`, or a list of ring_bending "
                                          "(tubes, Eq. 23) and free_faces (3d: bodies that end across the "
                                          "contact, paper §2.1)", "auto"),
        "accuracy": Key("fraction", "the depths' and scar widths' target: the largest difference from the full "
                                    "model accepted when `auto` simplifies it, and (grid.rule accuracy) what the "
                                    "grid is sized for", 0.01, lo=1e-4, hi=0.5),
        "pressure_accuracy": Key("fraction", "opt-in: the pressure field's target (L2, relative), for which the grid "
                                             "is refined (a 1 % field costs many times the elements: README); "
                                             "omitted: the pressures are reported with their estimate only", None,
                                 lo=1e-3, hi=0.5, example="5 %"),
        "slip": Key("choice", "the fretting cycle: uniform (the paper's gross slip, 4δ everywhere), coulomb "
                              "(Coulomb friction through the cycle: partial and gross slip, the local slip in the "
                              "wear law), or auto: coulomb where uniform slip is not within model.accuracy of it",
                    "auto", choices=SLIP_MODELS),
        "stroke": Key("choice", "the normal contact at mid-stroke only (mid_stroke, the paper) or at each increment "
                                "of the cycle with the moving body where it is over the worn flat (resolved); "
                                "auto: with model.slip coulomb on a line contact, resolved where 2D proxy runs "
                                "show the mid-stroke depths or widths more than model.accuracy/3 away (its loop costs "
                                "about 2.5× the mid-stroke run's in 2D, 3× in 3D: README), else mid_stroke (uniform slip, partial slip, "
                                "point contacts: said why); resolved needs loading.friction_coefficient",
                      "auto",
                      choices=STROKE_MODELS),
        "wear_law": Key("choice", "archard (dh = k·p·|ds|) or energy (dh = α·|q|·|ds|, Fouvry; needs "
                                  "materials.*.energy_wear_coefficient and loading.friction_coefficient)",
                        "archard", choices=Names(WEAR_LAWS)),
        "increments": Key("integer", "increments per half-stroke of the cycle (coulomb; odd: one is centred on "
                                     "mid-stroke), or auto: 5 with the stroke resolved in gross slip, δ ≥ 5δ_t, without fatigue "
                                     "(McColl's cases within 0.1 % in depth of 27 increments, 2D and 3D), else 9 (at "
                                     "mid-stroke they only draw the loop and sample a fatigue state's cycle)", None, lo=1,
                          hi=1001)},
    "solver": {
        "method": Key("choice", "contact solver: cg (FFT, Polonsky–Keer), msm (the paper's simplex, dense), "
                                "active_set (dense)", "cg", choices=("cg", "msm", "active_set")),
        "tolerance": Key("number", "contact solver tolerance: relative change of the pressure in an iteration "
                                   "(and the gap complementary)", 1e-5, lo=1e-14, hi=1e-2)},
    "jumping": {
        "scheme": Key("choice", "bdf2 (second-order implicit, default), implicit (backward Euler), linear "
                                "(the paper's explicit ΔN_L) or adaptive (Eqs. 19–21)", None, choices=Names(SCHEMES)),
        "tolerance": Key("fraction", "implicit schemes: target relative error of the recorded depths and "
                                     "pressures", 0.01, lo=1e-6, hi=0.5),
        "linear": Key("integer", "ΔN_L, cycles per explicit step (auto: half the stability limit)", None, lo=1,
                      hi=MAX_CYCLES),
        "eta": Key("number", "adaptive: accuracy parameter η (Eq. 21)", 0.55, lo=1e-6, hi=10.0),
        "max": Key("integer", "adaptive: ΔN_max; implicit schemes: the largest step (auto: unbounded)", None, lo=1,
                   hi=MAX_CYCLES),
        "preset": Key("choice", "paper: the DOE optimum η 0.55, ΔN_max 600, ΔN_L 55 (scaled to the grid's "
                                "stability limit if needed)", None, choices=tuple(PRESETS))},
    "grid": {
        "domain": Key("lengths", "[x, y] extents (one entry in 2D); automatic from the final scar if absent (and then widened "
                                   "during the run if the contact outgrows it)", None),
        "elements": Key("counts", "[Mx, My] elements; automatic (7a/40) if absent (and then coarsened along x as "
                                  "the scar grows, in 2D and for a line contact)", None, lo=1, hi=100_000),
        "coarse_element": Key("lengths", "[dx, dy] of a coarse grid to solve the contact on (refinement, "
                                         "Eqs. 11–12)", None),
        "rule": Key("choice", "how the automatic grid is sized: accuracy (the element along x small enough for "
                              "the scar widths to meet model.accuracy, never coarser than the paper's) or paper "
                              "(the paper's convergence rule, dx = 7a/40)", "accuracy", choices=GRID_RULES),
        "error_estimate": Key("choice", "the grid's part of the reported error estimates: companion (a second "
                                        "run on a grid twice as coarse; it adds about a third to the run's "
                                        "time) or none (the estimates then cover the stepping only, and say so)",
                              "companion", choices=GRID_ERRORS)},
    "output": {
        "snapshots": Key("cycle_list", "cycles at which fields are written (+ the last); auto: 0, N/4, N/2, "
                                       "3N/4, N; with limits, quarters of the pilot's predicted stop (else the "
                                       "decades below N) and N", None),
        "stresses": Key("flag", "with fatigue: also write the stress components under the contact at the recorded "
                                "states (/fields/stress_*, the moving body's /fields/stress_*_moving); omitted: "
                                "the SWT field only",
                        False)},
}
SECTIONS = ("name", "geometry", "materials", "loading", "model", "solver", "jumping", "grid", "output", "limits",
            "expected")
# a wear limit per summary quantity (fretsim.limits): the run stops where the first is reached
LIMITS_SCHEMA = {key: Key(q.kind, q.long_name, None, **({"lo": 1e-6, "hi": 1.0} if q.kind == "fraction" else {}))
                 for key, q in WEAR.items()}
MIN_FRICTION = 1e-9  # below it a friction coefficient is 0 in all but name: μ·p underflows the tangential solve
CRACK_LIMIT = "crack_initiation"  # limits.crack_initiation: true — the fatigue damage's limit, not a wear quantity
BLOCK_KEYS = ("normal_load", "stroke", "cycles", "friction_coefficient")
MAX_BLOCKS = 10_000  # blocks after repeats: each restarts the stepping (a few solves)


# what users call a key by another name: the key's full path (materials.<key>: a body's material key)
_ALIASES = {"mu": "loading.friction_coefficient", "cof": "loading.friction_coefficient",
            "friction": "loading.friction_coefficient", "coefficient_of_friction": "loading.friction_coefficient",
            "k": "materials.wear_coefficient", "archard": "materials.wear_coefficient"}


@functools.lru_cache(maxsize=1)
def _key_homes() -> dict:
    """Each key name of the schema's sections → its section ("" for a body's material)."""
    homes: dict = {}
    for section, keys in SCHEMA.items():
        for key in keys:
            homes.setdefault(key, "" if section == "material" else section)
    return homes


def _elsewhere(key: str, prefix: str) -> Optional[str]:
    """Where a key given in the wrong section (``model.friction_coefficient``) or by another name (``mu``) lives,
    as the hint to print; None if it is not one."""
    name = key.strip().lower()
    home = _ALIASES.get(name) or (f"{_key_homes()[name]}.{name}" if name in _key_homes() else None)
    if home is None:
        return None
    section, _, leaf = home.rpartition(".")
    if section in ("", "materials"):  # a body's material key
        return leaf if prefix.startswith("materials.") else f"materials.moving.{leaf}' or 'materials.stationary.{leaf}"
    return None if section == prefix else home


class CaseError(InputError):
    """A case (or a sweep file, an option, an output) that cannot be run: every problem with its YAML path."""

    def __init__(self, source: str, problems: list[tuple[str, str]], what: str = "case"):
        self.source = source
        self.problems = problems
        self.what = what
        super().__init__(str(self))

    def __str__(self) -> str:
        n = len(self.problems)
        if n == 1:
            path, msg = self.problems[0]
            return f"{self.source}: {path + ': ' if path else ''}{msg}"
        verb = "have" if self.what.endswith("s") else "has"  # "the measurements have", "the case has"
        head = f"{self.source}: the {self.what} {verb} {n} problems"
        return head + ":\n" + "\n".join(f"  - {path}: {msg}" if path else f"  - {msg}" for path, msg in self.problems)


@dataclass(frozen=True)
class Material:
    youngs_modulus: float  # MPa
    poissons_ratio: float
    wear_coefficient: Optional[float]  # 1/MPa (Archard's k)
    energy_wear_coefficient: Optional[float] = None  # mm³/(N·mm) = 1/MPa (α)
    yield_strength: Optional[float] = None  # MPa (σ_y, for the elastic model's range only)
    fatigue: Optional["Fatigue"] = None  # the strain-life curve (fretting fatigue, opt-in)


@dataclass(frozen=True)
class Fatigue:
    """``materials.<body>.fatigue``: the Basquin–Coffin–Manson constants and the options of the SWT life."""

    strength_coefficient: float  # σ'_f, MPa
    strength_exponent: float  # b
    ductility_coefficient: float  # ε'_f
    ductility_exponent: float  # c
    critical_distance: Optional[float] = None  # mm: the line method's averaging depth
    endurance_limit: Optional[float] = None  # MPa, a stress amplitude


@dataclass(frozen=True)
class Case:
    name: str
    geometry: Geometry
    moving: Material
    stationary: Material
    loading: Loading  # loads, strokes, cycles and μ: one block or a load history (fretsim.loading)
    limits: tuple = ()  # ((key, value in internal units), ...): fretsim.limits
    dimension: str = "auto"
    gap_model: str = "auto"
    corrections: object = "auto"  # "auto", "none" or a tuple of CORRECTIONS
    accuracy: float = 0.01
    pressure_accuracy: Optional[float] = None
    slip: str = "auto"
    stroke_model: str = "auto"
    wear_law: str = "archard"
    increments: Optional[int] = None  # per half-stroke; None: auto (fretsim.plan.cycle.choose_increments)
    solver: str = "cg"
    tolerance: float = 1e-5  # contact solver
    scheme: str = "bdf2"
    step_tolerance: float = 1e-2  # implicit schemes: target relative error at recorded states
    linear_jump: Optional[int] = None  # None: chosen from the stability limit
    eta: float = 0.55
    max_jump: Optional[int] = None
    preset: Optional[str] = None
    coarse_element: Optional[tuple[float, ...]] = None  # mm
    grid_rule: str = "accuracy"
    grid_error: str = "companion"
    domain: Optional[tuple[float, ...]] = None  # mm
    elements: Optional[tuple[int, ...]] = None
    snapshots: Optional[tuple[int, ...]] = None
    crack_limit: bool = False  # limits.crack_initiation: stop where the fatigue damage reaches 1
    output_stresses: bool = False  # output.stresses
    expected: dict = field(default_factory=dict, compare=False, hash=False)
    overrides: tuple[str, ...] = field(default=(), compare=False)  # --set items as given
    source: str = field(default="<case>", compare=False)

    @property
    def plane_strain(self) -> bool:
        return self.dimension == "2d"

    @property
    def law(self):
        """The wear law (a member of fretsim.wear_laws)."""
        return WEAR_LAWS[self.wear_law]

    def wear_coefficients(self) -> tuple[float, float]:
        """(moving, stationary) coefficients of p·|ds| where every point slides: Archard's k, or what the wear law
        makes of its own (α·μ for the energy law, with the loading's μ)."""
        return gross_slip_coefficients(self.law, self.moving, self.stationary, self.loading.friction_coefficient)

    def fingerprint(self) -> str:
        """sha256 of what the case asks for, as given (automatic choices unfilled; the `expected` data left out,
        since they change no result): two cases with the same fingerprint run the same.  A sweep compares it with
        the one a point's results file was written for, so a changed base case or `set:` runs the point again."""
        asked = {k: v for k, v in self.to_dict().items() if k != "expected"}
        return hashlib.sha256(json.dumps(asked, sort_keys=True, default=str).encode()).hexdigest()

    def with_choices(self, **kw: Any) -> "Case":
        return replace(self, **kw)

    def to_dict(self) -> dict:
        """The case with defaults filled, in the file layout, every dimensional value with its unit."""
        g = self.geometry
        geometry: dict = {"type": g.kind}
        for key, spec in GEOMETRY_KEYS[g.kind].items():
            if key == "profile_table":
                continue
            if key == "profile":
                if getattr(g, "profile_y", None) is not None:  # the table itself: the filled case needs no file
                    geometry["profile_table"] = {"y": [format_quantity(v, "length") for v in g.profile_y],
                                                 "drop": [format_quantity(v, "length") for v in g.profile_drop]}
                continue
            value = getattr(g, key)
            if value is None:
                continue
            geometry[key] = format_quantity(value, spec.kind) if spec.kind in ("length",) else value

        def mat(m: Material) -> dict:
            out = {"youngs_modulus": format_quantity(m.youngs_modulus, "pressure"), "poissons_ratio": m.poissons_ratio}
            if m.wear_coefficient is not None:
                out["wear_coefficient"] = format_quantity(m.wear_coefficient, "wear_coefficient")
            if m.energy_wear_coefficient is not None:
                out["energy_wear_coefficient"] = format_quantity(m.energy_wear_coefficient, "energy_wear_coefficient")
            if m.yield_strength is not None:
                out["yield_strength"] = format_quantity(m.yield_strength, "pressure")
            if m.fatigue is not None:
                out["fatigue"] = {k: (format_quantity(v, FATIGUE_SCHEMA[k].kind) if FATIGUE_SCHEMA[k].kind in
                                      ("pressure", "length") else v)
                                  for k, v in vars(m.fatigue).items() if v is not None}
            return out

        grid: dict = {}
        if self.domain is not None:
            grid["domain"] = [format_quantity(d, "length") for d in self.domain]
        if self.elements is not None:
            grid["elements"] = list(self.elements)
        if self.coarse_element is not None:
            grid["coarse_element"] = [format_quantity(d, "length") for d in self.coarse_element]
        grid["rule"], grid["error_estimate"] = self.grid_rule, self.grid_error
        loading = _loading_dict(self.loading)
        jumping = {"scheme": self.scheme, "tolerance": self.step_tolerance,
                   "linear": self.linear_jump if self.linear_jump is not None else "auto",
                   "eta": self.eta, "max": self.max_jump if self.max_jump is not None else "auto"}
        if self.preset is not None:
            jumping["preset"] = self.preset
        out = {
            "name": self.name,
            "geometry": geometry,
            "materials": {"moving": mat(self.moving), "stationary": mat(self.stationary)},
            "loading": loading,
            "model": {"dimension": self.dimension, "gap": self.gap_model,
                      "corrections": list(self.corrections) if isinstance(self.corrections, tuple) else self.corrections,
                      "accuracy": self.accuracy, **({} if self.pressure_accuracy is None else
                                                    {"pressure_accuracy": self.pressure_accuracy}),
                      "slip": self.slip, "stroke": self.stroke_model,
                      "wear_law": self.wear_law,
                      "increments": self.increments if self.increments is not None else "auto"},
            "solver": {"method": self.solver, "tolerance": self.tolerance},
            "jumping": jumping,
            "grid": grid,
            "output": {"snapshots": list(self.snapshots) if self.snapshots is not None else "auto",
                       **({"stresses": True} if self.output_stresses else {})},
            **({"limits": {**{k: (float(v) if LIMITS_SCHEMA[k].kind == "fraction" else  # a number: '0.4' is refused
                                  format_quantity(v, LIMITS_SCHEMA[k].kind)) for k, v in self.limits},
                           **({"crack_initiation": True} if self.crack_limit else {})}}
               if self.limits or self.crack_limit else {}),
        }
        if self.expected:
            out["expected"] = self.expected
        return out

    def to_yaml(self) -> str:
        import yaml
        return yaml.safe_dump(self.to_dict(), sort_keys=False, allow_unicode=True)


def _loading_dict(ld: Loading) -> dict:
    """The loading section of the file layout, every dimensional value with its unit."""
    if not ld.history:
        b = ld.given[0]
        loading = {"normal_load": format_quantity(b.normal_load, "force"), "stroke": format_quantity(b.stroke, "length"),
                   "cycles": ld.cycles}
    else:
        def block(b) -> dict:
            out = {"normal_load": format_quantity(b.normal_load, "force"), "stroke": format_quantity(b.stroke, "length")}
            out.update({"fraction": b.fraction} if ld.spectrum else {"cycles": b.cycles})
            if b.friction_coefficient is not None and b.friction_coefficient != ld.friction_coefficient:
                out["friction_coefficient"] = b.friction_coefficient
            return out
        loading = {"spectrum" if ld.spectrum else "blocks": [block(b) for b in ld.given]}
        if ld.spectrum:
            loading.update(cycles=ld.cycles, repeat=ld.repeat)
        elif sum(b.cycles for b in ld.given) * ld.repeat == ld.cycles:
            loading["repeat"] = ld.repeat
        else:  # repeated up to a number of cycles, the last pass cut short
            loading["cycles"] = ld.cycles
    if ld.frequency is not None:
        loading["frequency"] = f"{ld.frequency!r} Hz"
    if ld.friction_coefficient is not None:
        loading["friction_coefficient"] = ld.friction_coefficient
    if ld.tangential_stiffness is not None:
        loading["tangential_stiffness"] = format_quantity(ld.tangential_stiffness, "stiffness")
    return loading


def load_case(path: str | Path, overrides: Optional[list[str]] = None) -> Case:
    """Read, override (``key.path=value``) and validate a YAML case file."""
    path = Path(path)
    source = str(path)
    try:
        text = read_text(path, "case file")
    except (OSError, ValueError) as exc:
        raise CaseError(source, [("", str(exc) if not isinstance(exc, FileNotFoundError) or exc.args
                                  else "the file does not exist")]) from None
    return parse_case(text, source=source, overrides=overrides, default_name=path.stem)


@functools.lru_cache(maxsize=4)
def _loads_cached(text: str):
    # a sweep validates one base text once per point: parse it once per process
    return loads(text)


def _tree_copy(node):
    """A copy of a parsed YAML tree (dicts, lists, scalars): what copy.deepcopy does, 5× faster, for sweeps that
    validate 10⁵ points."""
    if isinstance(node, dict):
        return {k: _tree_copy(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_tree_copy(v) for v in node]
    return node


@functools.lru_cache(maxsize=4096)
def _override_value(value: str):
    # a sweep's axis values repeat across its points: each distinct text is parsed once
    return loads(value) if value.strip() else None


def parse_case(text: str, source: str = "<case>", overrides: Optional[list[str]] = None,
               default_name: str = "case") -> Case:
    try:
        raw = _tree_copy(_loads_cached(text))  # overrides edit the tree in place
    except YamlProblem as exc:
        raise CaseError(source, [(exc.path, exc.message)]) from None
    if raw is None:
        raise CaseError(source, [("", "the file is empty; expected a YAML mapping with the sections "
                                      + ", ".join(SECTIONS))])
    if not isinstance(raw, dict):
        raise CaseError(source, [("", f"expected a YAML mapping of sections at the top level, got a "
                                      f"{type(raw).__name__}")])
    problems: list[tuple[str, str]] = []
    for item in overrides or []:
        _apply_override(raw, item, problems)
    case = _validate(raw, problems, source, default_name, tuple(overrides or ()))
    if problems:
        raise CaseError(source, problems)
    return case


def _apply_override(raw: dict, item: str, problems: list) -> None:
    try:
        item.encode("utf-8")
    except UnicodeEncodeError:  # a command line's undecodable bytes, kept by Python as lone surrogates
        problems.append((f"--set {excerpt(item.encode('utf-8', 'backslashreplace').decode(), 60)}",
                         "not valid UTF-8 text; the results file stores the case as UTF-8"))
        return
    key, sep, value = item.partition("=")
    parts = key.strip().split(".")
    if not sep or not key.strip() or not all(parts):
        problems.append((f"--set {excerpt(item, 60)}", "expected key.path=value, e.g. loading.cycles=1000"))
        return
    node = raw
    for part in parts[:-1]:
        if not isinstance(node.get(part), dict):
            node[part] = {}
        node = node[part]
    try:
        node[parts[-1]] = _tree_copy(_override_value(value))  # a copy: the cached tree must stay as parsed
    except YamlProblem as exc:
        problems.append((f"--set {key.strip()}", exc.message))


class _Reader:
    """Collects problems while reading typed values out of the raw mapping, as the schema says."""

    def __init__(self, problems: list, source: str = "<case>"):
        self.problems = problems
        self.source = source  # the case file: relative file names in it are read from its directory

    def fail(self, path: str, msg: str) -> None:
        self.problems.append((path, msg))

    def section(self, raw: dict, name: str, keys, required: bool = True) -> Optional[dict]:
        """The section's mapping ({} if optional and absent); None, with the problem recorded, if unusable."""
        value = raw.get(name)
        if value is None:
            if required:
                self.fail(name, f"missing section; expected a mapping with keys {', '.join(sorted(keys))}")
                return None
            return {}
        if not isinstance(value, dict):
            self.fail(name, f"expected a mapping with keys {', '.join(sorted(keys))}, got {excerpt(value)}")
            return None if required else {}
        self.unknown(value, keys, name)
        return value

    def unknown(self, mapping: dict, keys, prefix: str) -> None:
        for k in mapping:
            if k not in keys:
                elsewhere = _elsewhere(str(k), prefix)
                hint = [elsewhere] if elsewhere else difflib.get_close_matches(str(k), keys, n=1, cutoff=0.6)
                name = excerpt(k) if not isinstance(k, str) else k[:40]
                self.fail(f"{prefix}.{name}" if prefix else name, "unknown key" + (
                    f" (did you mean '{hint[0]}'?)" if hint else f"; allowed: {', '.join(sorted(keys))}"))

    def key(self, mapping: Optional[dict], name: str, spec: Key, path: str) -> Any:
        """Read one key as its schema says; the default if absent; None (with a problem) if bad."""
        if mapping is None:
            return None
        value = mapping.get(name)
        if value is None or (value == "auto" and spec.kind not in ("choice", "text", "corrections")):
            if spec.default is REQUIRED:
                self.fail(path, f"missing; expected {_expected(spec)}")
            return None if spec.default is REQUIRED else spec.default
        return self.value(value, spec, path)

    def value(self, value: Any, spec: Key, path: str) -> Any:
        """A value of its schema's kind (None, with the problem recorded, if it is not one)."""
        kind = spec.kind
        if kind in UNITS:
            return self.quantity(value, spec, path)
        return getattr(self, "_" + kind)(value, spec, path)

    def _fraction(self, value: Any, spec: Key, path: str) -> Optional[float]:
        if isinstance(value, str) and value.strip().endswith("%"):
            num = value.strip()[:-1].strip()
            try:
                value = float(num) / 100.0
            except ValueError:
                self.fail(path, f"could not read {excerpt(value)}; expected e.g. '1 %' or 0.01")
                return None
        return self.number(value, spec, path)

    def _number(self, value: Any, spec: Key, path: str) -> Optional[float]:
        return self.number(value, spec, path)

    def _integer(self, value: Any, spec: Key, path: str) -> Optional[int]:
        return self.integer(value, spec, path)

    def _choice(self, value: Any, spec: Key, path: str) -> Optional[str]:
        # exact, like the keys ("Stroke" is not "stroke"); a near miss gets a hint
        if isinstance(value, str) and spec.any_case:
            value = value.lower()
        if isinstance(value, str) and value in spec.choices:
            return value
        hint = difflib.get_close_matches(str(value).lower(), spec.choices, n=1) if isinstance(value, str) else []
        self.fail(path, f"unknown value {excerpt(value)}" + (f" (did you mean '{hint[0]}'?)" if hint else "")
                  + f"; expected one of {', '.join(spec.choices)}")
        return None

    def _pair(self, value: Any, spec: Key, path: str) -> Optional[tuple]:
        lengths = spec.kind == "lengths"
        item = Key("length", "") if lengths else Key("integer", "", lo=spec.lo, hi=spec.hi)
        if not isinstance(value, list) or not 1 <= len(value) <= 2:
            self.fail(path, f"expected a list of one (2d) or two (3d) {'lengths' if lengths else 'whole numbers'}"
                            f", e.g. {'[1 mm, 10 mm]' if lengths else '[101, 27]'}")
            return None
        vals = [self.value(v, item, f"{path}[{i}]") for i, v in enumerate(value)]
        return None if None in vals else tuple(vals)

    _lengths = _counts = _pair

    def _text(self, value: Any, spec: Key, path: str) -> Optional[str]:
        if not isinstance(value, str) or not value.strip():
            self.fail(path, f"expected a text, got {excerpt(value)}")
            return None
        return value

    def _profile_file(self, value: Any, spec: Key, path: str):
        if not isinstance(value, str) or not value.strip():
            self.fail(path, f"expected the name of a CSV file, got {excerpt(value)}")
            return None
        return _read_profile(value, self.source, self, path)

    def _table(self, value: Any, spec: Key, path: str):
        ok = isinstance(value, dict) and set(value) == {"y", "drop"} and all(
            isinstance(value[k], list) and len(value[k]) >= 2 for k in ("y", "drop")) and len(value["y"]) == len(
            value["drop"])
        if not ok:
            self.fail(path, "expected {y: [lengths], drop: [lengths]} of equal length, at least two each")
            return None
        length = Key("length", "", positive=False)
        ys = [self.quantity(v, length, f"{path}.y[{i}]") for i, v in enumerate(value["y"])]
        ds = [self.quantity(v, length, f"{path}.drop[{i}]") for i, v in enumerate(value["drop"])]
        if None in ys or None in ds:
            return None
        if not (np.diff(ys) > 0).all():
            self.fail(path, "y must increase")
            return None
        return tuple(ys), tuple(ds)

    def _corrections(self, value: Any, spec: Key, path: str):
        if isinstance(value, str) and value in ("auto", "none"):
            return value
        items = value if isinstance(value, list) else None
        if items is None or not all(isinstance(v, str) and v in CORRECTIONS for v in items):
            self.fail(path, f"expected auto, none, or a list of {', '.join(CORRECTIONS)}; got {excerpt(value)}")
            return None
        return tuple(sorted(set(items)))

    def _flag(self, value: Any, spec: Key, path: str) -> Optional[bool]:
        if not isinstance(value, bool):
            self.fail(path, f"expected true or false, got {excerpt(value)}")
            return None
        return value

    def _fatigue(self, value: Any, spec: Key, path: str):
        if not isinstance(value, dict):
            self.fail(path, f"expected a mapping of {', '.join(FATIGUE_SCHEMA)}, got {excerpt(value)}")
            return None
        self.unknown(value, FATIGUE_SCHEMA, path)
        before = len(self.problems)
        vals = {k: self.key(value, k, sub, f"{path}.{k}") for k, sub in FATIGUE_SCHEMA.items()}
        return Fatigue(**vals) if len(self.problems) == before else None

    def _blocks(self, value: Any, spec: Key, path: str):
        return value  # read item by item by _read_blocks, with the loading's own key specs

    def _cycle_list(self, value: Any, spec: Key, path: str) -> Optional[tuple]:
        if not isinstance(value, list):
            self.fail(path, "expected a list of cycle numbers, e.g. [1000, 5000, 18000]")
            return None
        if len(value) > 10_000:
            self.fail(path, f"{len(value)} snapshots; at most 10000")
            return None
        vals = [self.integer(v, Key("integer", "", lo=0, hi=MAX_CYCLES), f"{path}[{i}]")
                for i, v in enumerate(value)]
        return None if None in vals else tuple(sorted(set(vals)))

    def quantity(self, value: Any, spec: Key, path: str) -> Optional[float]:
        if path == "loading.stroke" and isinstance(value, str) and value.lstrip().startswith(("±", "+/-")):
            value = value.lstrip().removeprefix("±").removeprefix("+/-")  # an amplitude, as the figures print it
        try:
            v = parse_quantity(value, spec.kind)
        except UnitError as exc:
            self.fail(path, str(exc))
            return None
        if spec.positive and not v > 0:
            self.fail(path, f"must be positive, got {excerpt(value)}")
            return None
        if not spec.positive and v < 0:
            self.fail(path, f"must not be negative, got {excerpt(value)}")
            return None
        if spec.plausible is not None and not spec.plausible[0] <= v <= spec.plausible[1]:
            self.fail(path, f"{excerpt(value)} is outside the plausible range {spec.plausible[2]} for a fretting "
                            f"contact: check the value and its unit")
            return None
        return v

    def number(self, value: Any, spec: Key, path: str) -> Optional[float]:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(path, f"expected a plain number, got {excerpt(value)}")
            return None
        try:
            v = float(value)
        except OverflowError:
            self.fail(path, f"{excerpt(value)} is out of range; expected {_expected(spec)}")
            return None
        if not math.isfinite(v):
            self.fail(path, f"expected a finite number, got {excerpt(value)}")
            return None
        hi_open = spec.kind == "number" and spec.hi == 0.5  # Poisson's ratio: (−1, 0.5)
        if not (spec.lo <= v <= spec.hi) or (hi_open and v >= spec.hi) or (spec.lo == -1.0 and v <= -1.0):
            self.fail(path, f"{excerpt(value)} is out of range; expected {_expected(spec)}")
            return None
        return v

    def integer(self, value: Any, spec: Key, path: str) -> Optional[int]:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or (
                isinstance(value, float) and not (math.isfinite(value) and value.is_integer())):
            self.fail(path, f"expected a whole number, got {excerpt(value)}")
            return None
        if not spec.lo <= value <= spec.hi:
            self.fail(path, f"{excerpt(value)} is out of range; expected a whole number from {spec.lo:.0f} to "
                            f"{spec.hi:.0f}")
            return None
        return int(value)


def _read_profile(name, source: str, r: "_Reader", key: str = "geometry.profile"):
    """(y, drop) in mm from a CSV whose header names the units: `y [mm], drop [um]`."""
    import csv
    import re
    from fretsim.units import UNITS
    path = Path(source).parent / str(name)
    try:
        text = read_text(path, "profile file")
    except (OSError, ValueError) as exc:
        r.fail(key, f"{path}: {exc}")
        return None
    text = text.removeprefix("\ufeff")  # a byte-order mark, as spreadsheets write it
    rows = [row for row in csv.reader(text.splitlines()) if row and not row[0].lstrip().startswith("#")]
    head = [h.strip() for h in rows[0]] if rows else []
    units = [re.fullmatch(r"\w+\s*\[(.+)\]", h) for h in head[:2]]
    if len(head) < 2 or not all(units) or any(u.group(1) not in UNITS["length"] for u in units):
        r.fail(key, f"{path}: the first line must name the columns with length units, e.g. "
                                   f"'y [mm], drop [um]'")
        return None
    scale = [UNITS["length"][u.group(1)] for u in units]
    short = next((i for i, row in enumerate(rows[1:], 2) if len(row) < 2), None)
    if short is not None:
        r.fail(key, f"{path}: data row {short} has one column; expected two numbers, y and drop")
        return None
    try:
        data = np.array([[float(v) for v in row[:2]] for row in rows[1:]])
    except ValueError as exc:
        r.fail(key, f"{path}: a row is not two numbers ({exc})")
        return None
    if data.ndim != 2 or len(data) < 2 or not np.isfinite(data).all() or not (np.diff(data[:, 0]) > 0).all():
        r.fail(key, f"{path}: needs at least two rows with increasing y and finite numbers")
        return None
    return tuple(data[:, 0] * scale[0]), tuple(data[:, 1] * scale[1])


def _example(kind: str) -> str:
    from fretsim.units import example
    return example(kind)


def _expected(spec: Key) -> str:
    kind = spec.kind
    if kind in UNITS:
        from fretsim.units import example
        return f"a {kind.replace('_', ' ')} with its unit, e.g. '{example(kind)}'"
    if kind == "choice":
        return "one of " + ", ".join(spec.choices)
    if kind in ("number", "fraction"):
        hi = ")" if spec.hi == 0.5 else "]"
        lo = "(" if spec.lo == -1.0 else "["
        return f"a number in {lo}{spec.lo:g}, {spec.hi:g}{hi}" + (" (or a percentage, e.g. '1 %')"
                                                                    if kind == "fraction" else "")
    if kind == "integer":
        return f"a whole number from {spec.lo:.0f} to {spec.hi:.0f}"
    return spec.help


def _read_blocks(r: "_Reader", raw_load: dict, load: dict, given: list) -> tuple[Optional[tuple], int]:
    """loading.blocks or loading.spectrum: one pass of Blocks, and the number of passes."""
    if len(given) > 1:
        r.fail("loading", "both blocks and spectrum given; a loading is one or the other")
        return None, 1
    kind = given[0]
    spectrum = kind == "spectrum"
    for k in ("normal_load", "stroke") + (() if spectrum else ("cycles",)):
        if raw_load.get(k) is not None and not (k == "cycles" and raw_load.get("repeat") is None):
            r.fail(f"loading.{k}", f"given with loading.{kind}: the blocks carry it" + (
                "; loading.cycles with blocks repeats them up to that many cycles, so it goes without "
                "loading.repeat" if k == "cycles" else ""))
    items = raw_load[kind]
    if not isinstance(items, list) or not items or len(items) > MAX_BLOCKS:
        r.fail(f"loading.{kind}", f"expected a list of 1 to {MAX_BLOCKS} mappings, each with normal_load, stroke "
                                  f"and {'fraction' if spectrum else 'cycles'}")
        return None, 1
    fields = ("normal_load", "stroke", "fraction" if spectrum else "cycles", "friction_coefficient")
    spec = dict(SCHEMA["loading"])
    spec["fraction"] = Key("fraction", "the block's share of loading.cycles", REQUIRED, lo=0.0, hi=1.0)
    spec["friction_coefficient"] = replace(spec["friction_coefficient"], default=load.get("friction_coefficient"))
    out = []
    for i, item in enumerate(items):
        path = f"loading.{kind}[{i}]"
        if not isinstance(item, dict):
            r.fail(path, f"expected a mapping with {', '.join(fields[:3])}, got {excerpt(item)}")
            continue
        r.unknown(item, fields, path)
        vals = {k: r.key(item, k, spec[k], f"{path}.{k}") for k in fields}
        if any(vals[k] is None for k in fields[:3]):
            continue
        mu = vals["friction_coefficient"]
        if "friction_coefficient" in item and mu is not None and 0 < mu < MIN_FRICTION:
            r.fail(f"{path}.friction_coefficient", _tiny_friction(mu))
            continue
        cycles = 0 if spectrum else vals["cycles"]
        out.append(Block(vals["normal_load"], vals["stroke"], cycles, vals["friction_coefficient"],
                         load.get("tangential_stiffness"), vals["fraction"] if spectrum else None))
    if len(out) != len(items):
        return None, 1
    unset = [i for i, b in enumerate(out) if b.friction_coefficient is None]
    if unset and len(unset) < len(out):  # friction is resolved for the whole history or for none of it
        r.fail(f"loading.{kind}[{unset[0]}].friction_coefficient",
               "missing where other blocks give one: give it for every block (or loading.friction_coefficient, "
               "which the blocks take unless they give their own), or for none (the paper's gross slip)")
        return None, 1
    if spectrum:
        total = sum(b.fraction for b in out)
        if abs(total - 1.0) > 1e-6:
            r.fail("loading.spectrum", f"the fractions add up to {total:.6g}; expected 1")
            return None, 1
        if load.get("cycles") is None:
            return None, 1
    elif sum(b.cycles for b in out) == 0:
        r.fail("loading.blocks", "every block has 0 cycles")
        return None, 1
    return tuple(out), load.get("repeat") or 1


def _read_limits(r: "_Reader", raw: Any) -> tuple:
    if raw is None:
        return ()
    if not isinstance(raw, dict) or not raw:
        r.fail("limits", f"expected a mapping of wear limits, e.g. {{max_wear_depth_stationary: 2 um}}, got "
                         f"{excerpt(raw)}")
        return ()
    r.unknown(raw, set(LIMITS_SCHEMA) | {CRACK_LIMIT}, "limits")
    out = []
    for k, spec in LIMITS_SCHEMA.items():
        if k in raw:
            v = r.key(raw, k, spec, f"limits.{k}")
            if v is not None:
                out.append((k, v))
    return tuple(out)


def _validate(raw: dict, problems: list, source: str, default_name: str, overrides: tuple) -> Optional[Case]:
    """The case of a parsed tree, every problem recorded in ``problems`` (None where there are any)."""
    r = _Reader(problems, source)
    r.unknown(raw, set(SECTIONS), "")
    name = _read_name(r, raw, default_name)
    geometry = _read_geometry(r, raw)
    materials = _read_materials(r, raw)
    load, blocks, repeat, spectrum = _read_loading(r, raw)
    limits = _read_limits(r, raw.get("limits"))
    raw_limits = raw.get("limits") if isinstance(raw.get("limits"), dict) else {}
    crack_limit = r.key(raw_limits, CRACK_LIMIT, Key("flag", ""), f"limits.{CRACK_LIMIT}") or False
    model, solver, jumping, grid, output = (_read_section(r, raw, section)
                                            for section in ("model", "solver", "jumping", "grid", "output"))
    expected = raw.get("expected", {})
    if not isinstance(expected, dict):
        r.fail("expected", f"expected a mapping of published values, got {excerpt(expected)}")
        expected = {}
    scheme, preset = _scheme(jumping, raw.get("jumping") if isinstance(raw.get("jumping"), dict) else {})
    mu = load.get("friction_coefficient")
    if mu is None and blocks and all(b.friction_coefficient is not None for b in blocks):
        mu = min(b.friction_coefficient for b in blocks)  # every block gives its own: the history has friction
    _check_model(r, geometry, materials, model, mu)
    _check_fatigue(r, materials, model, mu, crack_limit, output.get("stresses"))
    domain = grid.get("domain")
    stroke = load.get("stroke")
    if domain is not None and stroke is not None and stroke >= domain[0] / 2:
        r.fail("loading.stroke", f"the stroke amplitude {format_quantity(stroke, 'length')} is larger than half "
                                 f"the grid's x extent ({domain[0]:.4g} mm): check its unit")
    if problems or geometry is None:
        if not problems:
            r.fail("geometry", "incomplete")
        return None
    loading = _loading(r, load, blocks, repeat, spectrum)
    if dict(limits).get("wall_loss") is not None and geometry.kind != "tube_on_flat":
        r.fail("limits.wall_loss", f"a wall loss is a tube's (tube_on_flat); a {geometry.kind} has no wall: use "
                                   f"max_wear_depth_moving")
    if problems:
        return None
    return Case(name=name, geometry=geometry, moving=materials["moving"], stationary=materials["stationary"],
                loading=loading, limits=limits, dimension=model.get("dimension"), gap_model=model["gap"],
                corrections=model["corrections"], accuracy=model["accuracy"],
                pressure_accuracy=model.get("pressure_accuracy"), slip=model["slip"], stroke_model=model["stroke"],
                wear_law=model["wear_law"], increments=model.get("increments"), solver=solver["method"],
                tolerance=solver["tolerance"], scheme=scheme, step_tolerance=jumping["tolerance"],
                linear_jump=jumping.get("linear"), eta=jumping["eta"], max_jump=jumping.get("max"), preset=preset,
                coarse_element=grid.get("coarse_element"), grid_rule=grid["rule"], grid_error=grid["error_estimate"],
                domain=domain, elements=grid.get("elements"), snapshots=output.get("snapshots"),
                crack_limit=bool(crack_limit), output_stresses=bool(output.get("stresses")), expected=expected,
                overrides=overrides, source=source)


def _read_name(r: "_Reader", raw: dict, default_name: str) -> str:
    name = raw.get("name", default_name)
    if not isinstance(name, (str, int, float)) or isinstance(name, bool):
        r.fail("name", f"expected a text, got {excerpt(name)}")
        name = default_name
    name = str(name)
    if len(name) > 200:
        r.fail("name", f"a name of {len(name)} characters; at most 200")
    try:
        name.encode("utf-8")
    except UnicodeEncodeError as exc:  # YAML's "\ud800" (a lone surrogate) reads, but no UTF-8 file can hold it
        given = "" if "name" in raw else " (from the case file's name)"
        r.fail("name", f"{excerpt(name)}{given} holds a lone surrogate ({name[exc.start]!r} at position "
                       f"{exc.start}), which is not text and cannot be stored in the results file (UTF-8); expected "
                       f"a name of Unicode characters")
        name = "case"
    return name


def _read_geometry(r: "_Reader", raw: dict) -> Optional[Geometry]:
    """The geometry family's member for geometry.type, built from its keys (None, with the problems, if it cannot
    be)."""
    geo = r.section(raw, "geometry", {"type"} | {k for keys in GEOMETRY_KEYS.values() for k in keys})
    gtype = r.key(geo, "type", SCHEMA["geometry"]["type"], "geometry.type") if geo is not None else None
    if gtype is None:
        return None
    keys = GEOMETRY_KEYS[gtype]
    for k in geo:
        if k != "type" and k not in keys and geo[k] is not None:
            r.fail(f"geometry.{k}", f"a {gtype} has no {k}; its keys are {', '.join(keys)}")
    before = len(r.problems)
    vals = {k: r.key(geo, k, spec, f"geometry.{k}") for k, spec in keys.items()}
    if len(r.problems) != before or any(v is None for k, v in vals.items() if keys[k].default is REQUIRED):
        return None
    if "profile_table" in vals:  # a profile given inline or as a CSV file: one table either way
        table = vals.pop("profile_table")
        vals["profile"] = vals["profile"] or table
    return GEOMETRIES[gtype].from_case(vals, lambda key, msg: r.fail(f"geometry.{key}" if key else "geometry", msg))


def _read_materials(r: "_Reader", raw: dict) -> dict:
    mats = r.section(raw, "materials", {"moving", "stationary"})
    materials = {}
    for body in ("moving", "stationary"):
        if mats is None:
            break
        m = mats.get(body)
        path = f"materials.{body}"
        if not isinstance(m, dict):
            r.fail(path, "missing; expected a mapping with youngs_modulus, poissons_ratio, wear_coefficient (or "
                         "energy_wear_coefficient)" if m is None else f"expected a mapping, got {excerpt(m)}")
            continue
        r.unknown(m, SCHEMA["material"], path)
        before = len(r.problems)
        vals = [r.key(m, k, spec, f"{path}.{k}") for k, spec in SCHEMA["material"].items()]
        if len(r.problems) == before:
            materials[body] = Material(*vals)
    return materials


def _read_section(r: "_Reader", raw: dict, section: str, required: bool = False,
                  schema: Optional[dict] = None) -> dict:
    """A section's keys as its schema says ({} where the section is unusable)."""
    schema = schema or SCHEMA[section]
    mapping = r.section(raw, section, schema, required=required)
    return {k: r.key(mapping, k, spec, f"{section}.{k}") for k, spec in schema.items()} if mapping is not None else {}


def _read_loading(r: "_Reader", raw: dict) -> tuple[dict, Optional[tuple], int, bool]:
    """The loading section's keys, and a load history's blocks (one pass), passes and whether it is a spectrum."""
    raw_load = raw.get("loading") if isinstance(raw.get("loading"), dict) else {}
    given = [k for k in ("blocks", "spectrum") if raw_load.get(k) is not None]
    load_schema = SCHEMA["loading"]
    if given:  # a load history: the single load's keys are the blocks'
        relaxed = ("normal_load", "stroke") + (("cycles",) if given == ["blocks"] else ())
        load_schema = {k: (replace(v, default=None) if k in relaxed else v) for k, v in load_schema.items()}
    load = _read_section(r, raw, "loading", required=True, schema=load_schema)
    blocks, repeat = _read_blocks(r, raw_load, load, given) if given else (None, 1)
    return load, blocks, repeat, given == ["spectrum"]


def _scheme(jumping: dict, jumping_raw: dict) -> tuple[Optional[str], Optional[str]]:
    """The stepping scheme and the preset, the preset's values filled into ``jumping`` where not given."""
    preset = jumping.get("preset")
    if preset is not None:
        for k, v in PRESETS[preset].items():
            if jumping_raw.get(k) in (None, "auto"):
                jumping[k] = v
    scheme = jumping.get("scheme")
    if scheme is None:
        # a block giving only `linear` keeps its original meaning: explicit linear jumping
        scheme = "linear" if jumping.get("linear") is not None and preset is None else DEFAULT_SCHEME
    return scheme, preset


def _check_fatigue(r: "_Reader", materials: dict, model: dict, mu: Optional[float], crack_limit, stresses) -> None:
    """What fretting fatigue needs: either body's constants (the moving body's half-space is checked against the
    contact's size by the plan; in 2D only so far), a friction coefficient (the shear traction drives the cracks);
    the crack limit and the stress output need the constants."""
    if any(path.startswith(("materials.stationary.fatigue", "materials.moving.fatigue")) for path, _ in r.problems):
        return  # (already said what is wrong with them)
    given = [body for body in ("stationary", "moving") if body in materials and materials[body].fatigue is not None]
    if not given:
        for path, on in ((f"limits.{CRACK_LIMIT}", crack_limit), ("output.stresses", stresses)):
            if on:
                r.fail(path, "needs materials.stationary.fatigue or materials.moving.fatigue (the strain-life "
                             "constants)")
        return
    where = f"materials.{given[0]}.fatigue"
    if mu is None or mu == 0:
        r.fail(where, "fretting fatigue needs loading.friction_coefficient (> 0): the shear traction is what opens "
                      "the cracks")
    if model.get("dimension") != "2d" and "moving" in given:
        r.fail("materials.moving.fatigue", "the moving body's fatigue is computed in plane strain only so far (in "
                                           "3D the flat's is: give materials.stationary.fatigue); set "
                                           "model.dimension: 2d")


def _check_model(r: "_Reader", geometry, materials: dict, model: dict, mu: Optional[float]) -> None:
    """What the model's choices need of the rest of the case: a 3D point contact, the wear law's coefficients, a
    friction coefficient where the cycle or the law resolves the traction, an odd number of increments."""
    dimension = model.get("dimension")
    if geometry is not None and dimension == "2d" and not geometry.has_2d:
        r.fail("model.dimension", f"a {geometry.kind} is a point contact: it needs 3d (2d is a line contact)")
    law = WEAR_LAWS.get(model.get("wear_law"))
    if law is not None:
        for body, m in materials.items():
            if getattr(m, law.coefficient_key) is None:
                r.fail(f"materials.{body}.{law.coefficient_key}", f"missing; model.wear_law {law.name} needs it, "
                                                                   f"e.g. '{_example(law.coefficient_key)}'")
    slip = model.get("slip")
    why = friction_needed(slip, model.get("stroke"), law)
    if mu is None and why:
        r.fail("loading.friction_coefficient", f"missing; {why} needs it, e.g. 0.9")
    if model.get("increments") is not None and model["increments"] % 2 == 0:
        r.fail("model.increments", f"{model['increments']} is even; expected an odd number, so that one increment "
                                   f"is centred on mid-stroke (e.g. {model['increments'] + 1})")
    # μ = 0 is frictionless: no shear traction, every point slides the whole stroke (the uniform model, exact)
    if mu == 0 and slip in CYCLES and CYCLES[slip].needs_friction:
        r.fail("loading.friction_coefficient", f"0 with model.slip {slip}: without friction there is no shear "
                                               f"traction to resolve and every point slides the whole stroke, which "
                                               f"model.slip uniform (or auto) models exactly; give μ > 0 for "
                                               f"Coulomb friction")
    elif mu == 0 and why:
        r.fail("loading.friction_coefficient", f"0 with {why}: without friction it has nothing to work with "
                                               f"(no shear traction, no dissipated energy); give μ > 0")
    if mu is not None and 0 < mu < MIN_FRICTION:
        r.fail("loading.friction_coefficient", _tiny_friction(mu))


def _tiny_friction(mu: float) -> str:
    return (f"{mu:g}: expected 0 (frictionless) or at least {MIN_FRICTION:g}; a smaller μ is frictionless in all but "
            f"name, and its shear tractions underflow the tangential solve")


def _loading(r: "_Reader", load: dict, blocks: Optional[tuple], repeat: int, spectrum: bool) -> Loading:
    """The case's :class:`~fretsim.loading.Loading` (a problem recorded for a history of too many blocks)."""
    mu, k_t, frequency = load.get("friction_coefficient"), load.get("tangential_stiffness"), load.get("frequency")
    if blocks is None:
        return Loading.constant(load["normal_load"], load["stroke"], load["cycles"], mu, k_t, frequency)
    if load.get("cycles") == 0:  # a history cut to no cycles applies none of its blocks: no load to solve for
        r.fail("loading.cycles", f"0 with loading.{'spectrum' if spectrum else 'blocks'}: no block would be applied; "
                                 f"give the cycles the history runs for" + ("" if spectrum else
                                                                           " (or leave it out: the blocks' own)")
               + ", or a single normal_load and stroke for the unworn contact alone")
    applied = expand(blocks, repeat, load.get("cycles"), spectrum)
    if len(applied) > MAX_BLOCKS:
        r.fail("loading.repeat", f"{len(applied)} blocks in all; at most {MAX_BLOCKS} (each restarts the "
                                 f"stepping): fewer passes, or longer blocks")
    return Loading(blocks, sum(b.cycles for b in applied), repeat, spectrum, True, mu, k_t, frequency)
