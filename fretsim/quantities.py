"""The reported quantities, declared once: name, unit, long name and how each is measured.

Two tables.  :data:`WEAR` lists the quantities of a worn state that a wear limit may name (``limits:`` in a
case), that `fit` reads from measurements and that the summary and the history report: each with the unit
kind the case writes it in, the unit it is reported in, and the function (:mod:`fretsim.measures`) that reads
it off a state in internal units.  :data:`SUMMARY` lists every figure of a run's summary (``/summary`` in the
results file, `fretsim summary`, its JSON and CSV, the sweep tables) in the order they are reported, with
their units and whether NaN is a legitimate value (not applicable, or not estimated).

The names are a contract users' scripts depend on (README): they are only ever added to.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

from fretsim.measures import centre_depth, centre_width, max_depth


@dataclass(frozen=True)
class Wear:
    """A quantity of a worn state, measured from both bodies' depth fields and worn volumes."""

    key: str  # the limits' name, e.g. max_wear_depth_stationary
    kind: str  # the unit kind a case writes it in (fretsim.units): length, volume, fraction
    unit: str  # the unit it is reported in (the summary key's suffix): um, mm, mm3, 1
    factor: float  # internal units (mm, mm³) → ``unit``
    long_name: str
    measure: Callable  # (step, x, wall) → the value in internal units

    @property
    def summary_key(self) -> str:
        return f"{self.key}_{self.unit}"


def _body(step, key: str):
    return step.wear_moving if key.endswith("moving") else step.wear_stationary


WEAR: dict[str, Wear] = {q.key: q for q in (
    Wear("max_wear_depth_moving", "length", "um", 1e3, "maximum wear depth of the moving body",
         lambda s, x, wall: max_depth(s.wear_moving)),
    Wear("max_wear_depth_stationary", "length", "um", 1e3, "maximum wear depth of the stationary body",
         lambda s, x, wall: max_depth(s.wear_stationary)),
    Wear("centre_wear_depth_moving", "length", "um", 1e3, "maximum wear depth of the moving body along y = 0",
         lambda s, x, wall: centre_depth(s.wear_moving)),
    Wear("centre_wear_depth_stationary", "length", "um", 1e3,
         "maximum wear depth of the stationary body along y = 0", lambda s, x, wall: centre_depth(s.wear_stationary)),
    Wear("scar_width_moving", "length", "mm", 1.0, "scar width of the moving body along y = 0",
         lambda s, x, wall: centre_width(s.wear_moving, x)),
    Wear("scar_width_stationary", "length", "mm", 1.0, "scar width of the stationary body along y = 0",
         lambda s, x, wall: centre_width(s.wear_stationary, x)),
    Wear("wear_volume_moving", "volume", "mm3", 1.0, "wear volume of the moving body",
         lambda s, x, wall: s.volume_moving),
    Wear("wear_volume_stationary", "volume", "mm3", 1.0, "wear volume of the stationary body",
         lambda s, x, wall: s.volume_stationary),
    Wear("wall_loss", "fraction", "1", 1.0, "a tube's maximum wear depth over its wall thickness (tube_on_flat)",
         lambda s, x, wall: max_depth(s.wear_moving) / wall),
)}


def wear_value(key: str, step, x, wall: Optional[float] = None) -> float:
    """The wear quantity ``key`` of a state (anything with wear_moving, wear_stationary, volume_moving and
    volume_stationary), in internal units; ``x`` the grid's element centres, ``wall`` a tube's wall (mm)."""
    return WEAR[key].measure(step, x, wall)


@dataclass(frozen=True)
class Figure:
    """One figure of a run's summary."""

    unit: str  # as written in the results file: um, mm, mm^3, N, J, s, h, cycles, 1; "" for a text
    nan: bool = False  # NaN is a legitimate value: not applicable (2D, no friction), not estimated, not reached


SUMMARY: dict[str, Figure] = {
    "cycles": Figure("cycles"),
    "contact_solves": Figure("1"),
    "wall_time_s": Figure("s"),
    "max_wear_depth_moving_um": Figure("um"),
    "max_wear_depth_stationary_um": Figure("um"),
    "centre_wear_depth_moving_um": Figure("um"),
    "centre_wear_depth_stationary_um": Figure("um"),
    "scar_width_stationary_mm": Figure("mm"),
    "scar_width_moving_mm": Figure("mm"),
    "wear_volume_moving_mm3": Figure("mm^3"),
    "wear_volume_stationary_mm3": Figure("mm^3"),
    "archard_volume_error": Figure("1"),
    "max_pressure_MPa": Figure("MPa"),
    "linear_jump": Figure("cycles"),
    "stability_limit_linear": Figure("cycles", nan=True),  # infinite when nothing wears
    "element_size_x_um": Figure("um"),
    "element_size_y_um": Figure("um", nan=True),  # NaN in 2D
    "elements_x": Figure("1"),
    "elements_y": Figure("1"),
    "error_estimate_depth": Figure("1"),
    "error_estimate_pressure": Figure("1"),
    "regime": Figure(""),
    "tangential_force_amplitude_N": Figure("N", nan=True),  # unknown without a friction coefficient
    "dissipated_energy_per_cycle_J": Figure("J", nan=True),
    "stick_half_width_x_mm": Figure("mm"),
    "gross_slip_stroke_um": Figure("um", nan=True),
    # the run's error estimates (fretsim.grid_error): not estimated with grid.error_estimate none, or for a run
    # that did not complete
    "estimated_error_depth": Figure("1", nan=True),
    "estimated_error_width": Figure("1", nan=True),
    "estimated_error_pressure": Figure("1", nan=True),
    "estimated_error_max_pressure": Figure("1", nan=True),
    "limit_reached": Figure(""),
    "cycles_to_limit": Figure("cycles", nan=True),  # no limit reached
    "time_to_limit_h": Figure("h", nan=True),  # ... or no loading.frequency
    "estimated_error_cycles_to_limit": Figure("1", nan=True),
    "grid_error_wall_time_s": Figure("s"),
    # fretting fatigue of the flat (materials.stationary.fatigue; absent otherwise — damage_mode comes with either
    # body's constants): the largest over the fatigue states, the crack-initiation cycle (NaN: beyond the run) and
    # which damage comes first
    "max_shear_stress_MPa": Figure("MPa"),
    "max_shear_stress_depth_um": Figure("um"),
    "max_surface_tensile_stress_MPa": Figure("MPa"),
    "swt_max_MPa": Figure("MPa"),
    "swt_location_x_mm": Figure("mm"),
    "swt_depth_um": Figure("um"),
    "ruiz_max": Figure("MPa^2*mm"),
    "cycles_to_crack_initiation": Figure("cycles", nan=True),
    "crack_location_x_mm": Figure("mm", nan=True),
    "swt_location_y_mm": Figure("mm", nan=True),  # 3D only: across the stroke
    "crack_location_y_mm": Figure("mm", nan=True),  # 3D only
    "fatigue_damage": Figure("1"),
    "damage_mode": Figure(""),
    "fatigue_states_error": Figure("1", nan=True),  # the crack cycle's (or damage's) change with half the states
    "estimated_error_cycles_to_crack": Figure("1", nan=True),  # no crack in the run or its companion, or none run
    "estimated_error_swt_max": Figure("1", nan=True),
    # Miner's sum at the end: the companion's difference, the depths' stepping, fatigue_states_error (which is the
    # crack cycle's where the run cracked)
    "estimated_error_fatigue_damage": Figure("1", nan=True),
    # the moving body's (materials.moving.fatigue; absent otherwise): the same figures on its own half-space,
    # named as the flat's with _moving before the unit; damage_mode above counts both bodies' cracks
    "max_shear_stress_moving_MPa": Figure("MPa"),
    "max_shear_stress_depth_moving_um": Figure("um"),
    "max_surface_tensile_stress_moving_MPa": Figure("MPa"),
    "swt_max_moving_MPa": Figure("MPa"),
    "swt_location_x_moving_mm": Figure("mm"),
    "swt_depth_moving_um": Figure("um"),
    "ruiz_max_moving": Figure("MPa^2*mm"),
    "cycles_to_crack_initiation_moving": Figure("cycles", nan=True),
    "crack_location_x_moving_mm": Figure("mm", nan=True),
    "fatigue_damage_moving": Figure("1"),
    "fatigue_states_error_moving": Figure("1", nan=True),
    "crack_body": Figure(""),  # with fatigue: the body whose crack starts first, stationary or moving ("" none)
}
SUMMARY_WEAR = ("max_wear_depth_moving", "max_wear_depth_stationary", "centre_wear_depth_moving",
                "centre_wear_depth_stationary", "scar_width_stationary", "scar_width_moving", "wear_volume_moving",
                "wear_volume_stationary")  # the wear quantities of the summary, in its order


# how messages name a figure (auto's proxies compare the models on these)
SAID = {"max_wear_depth_moving_um": "the moving body's maximum depth",
        "max_wear_depth_stationary_um": "the flat's maximum depth",
        "centre_wear_depth_stationary_um": "the flat's centre-line depth",
        "scar_width_moving_mm": "the moving body's scar width", "scar_width_stationary_mm": "the flat's scar width",
        "max_pressure_MPa": "the peak pressure"}


def shown_unit(unit: str) -> str:
    """A unit as the files spell it (um, mm^3, mm3 — ASCII, what a case or a CSV header may be written in) as a
    reader reads it: µm, mm³."""
    return unit.replace("um", "µm").replace("mm^3", "mm³").replace("mm3", "mm³")


def unit_of(summary_key: str) -> str:
    """The unit of a summary figure ("1" for one fretsim does not report)."""
    figure = SUMMARY.get(summary_key)
    return figure.unit if figure is not None else "1"


def wear_summary(step, x) -> dict:
    """The summary's wear figures of a state, in their reported units."""
    return {WEAR[k].summary_key: WEAR[k].measure(step, x, None) * WEAR[k].factor for k in SUMMARY_WEAR}


def keyed(key: str, body: str) -> str:
    """A per-body fatigue summary key: the flat's as it always was, the moving body's with ``_moving`` before the
    unit (as max_wear_depth_moving_um)."""
    if body == "stationary":
        return key
    unit = next((u for u in ("_MPa", "_mm", "_um") if key.endswith(u)), "")
    return f"{key[:len(key) - len(unit)]}_moving{unit}"
