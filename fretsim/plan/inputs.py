"""The planner's first stage: is the input plausible, and is it in the elastic model's range?

Implausible input (a stroke a thousand contact widths long, a contact wider than the body) is refused as a
:class:`~fretsim.case.CaseError` with every problem at once; input that runs but stretches the model (a peak
pressure past yield, a contact a sizeable share of the radius) is run with a warning.  Also here: the memory a
grid needs, checked once the grid is known.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from fretsim.case import Case, CaseError
from fretsim.plan.choices import Choice, Plan
from fretsim.reference import effective_modulus
from fretsim.solvers import DENSE_SOLVERS

MAX_STROKE_OVER_CONTACT = 50.0  # δ/a beyond this is sliding, not fretting, or a unit slip (µm → mm)
MEMORY_SHARE = 0.5  # refuse a grid that would take more than this share of the machine's memory
ELASTIC_P0 = 0.04  # p0/E* beyond which no metal stays elastic (bearing steel: ~4 GPa over E* = 115 GPa, 3.5 %)
# the Hertz peak pressure at first yield (von Mises, ν = 0.3, below the surface): Johnson, Contact Mechanics §6.2
YIELD_ONSET = {"point": 1.60, "line": 1.79}
SMALL_CONTACT = 0.1  # a/R beyond which the half-space (small-strain) contact model is said to be stretched
PRESSURE_TOLERANCE = 0.1  # model.pressure_accuracy: the stepping tolerance at most this share of it


@dataclass(frozen=True)
class Contact:
    """The unworn contact under the loading's largest load, and the wear coefficients of gross slip."""

    e_star: float  # MPa
    hertz: object  # fretsim.reference's Hertz solution
    k_moving: float  # coefficient of p·|ds| where every point slides (Archard's k, α·μ for the energy law)
    k_stationary: float


def tighten_for_pressure(case: Case, plan: Plan) -> Case:
    """model.pressure_accuracy asks for a stepping tolerance of at most PRESSURE_TOLERANCE of it."""
    if case.pressure_accuracy is None or case.step_tolerance <= case.pressure_accuracy * PRESSURE_TOLERANCE:
        return case
    # a worn, conforming contact's pressure is sensitive to the wear profile: at the pressure-accuracy grids the
    # stepping's part of the pressure error grows past its estimate (McColl 185 N at 1769 elements: 2.2 %
    # between tolerance 1e-2 and 1e-4, estimated 0.8 %); scripts/study_grid_error.py --pressure
    tightened = float(f"{case.pressure_accuracy * PRESSURE_TOLERANCE:.6g}")
    plan.add(Choice("jumping.tolerance", tightened, f"model.pressure_accuracy {case.pressure_accuracy:.2g}: the "
                                                    f"stepping tolerance at most {PRESSURE_TOLERANCE:g} of it "
                                                    f"(was {case.step_tolerance:g})"))
    return case.with_choices(step_tolerance=tightened)


def contact(case: Case, plan: Plan) -> Contact:
    """The unworn contact; implausible input refused, a stretched model warned of."""
    g, loading = case.geometry, case.loading
    e_star = effective_modulus(case.moving.youngs_modulus, case.moving.poissons_ratio,
                               case.stationary.youngs_modulus, case.stationary.poissons_ratio)
    hertz = g.hertz(loading.peak_load, e_star)
    problems: list = []
    if loading.peak_stroke > MAX_STROKE_OVER_CONTACT * hertz.half_width_x:
        problems.append(("loading.stroke", f"the stroke amplitude {loading.peak_stroke:.4g} mm is "
                                           f"{loading.peak_stroke / hertz.half_width_x:.0f} times the Hertz contact "
                                           f"half-width ({hertz.half_width_x:.3g} mm); fretting is a small "
                                           f"oscillation (up to {MAX_STROKE_OVER_CONTACT:g} a here): check its unit"))
    reach = g.limits.reach_x
    if hertz.half_width_x >= reach:
        problems.append(("loading.normal_load", f"the unworn contact alone (Hertz half-width {hertz.half_width_x:.4g} "
                                                f"mm and peak pressure p0 = {hertz.peak_pressure:.4g} MPa under "
                                                f"{loading.peak_load:.4g} N) reaches beyond {reach:.4g} mm, "
                                                f"half the body's radius, where its paraboloid (Eqs. 9–10) stops "
                                                f"describing it: no elastic contact model holds; check the load "
                                                f"and the radius and their units"))
    if problems:
        raise CaseError(case.source, problems)
    _warn_range(case, plan, hertz, e_star, reach)
    return Contact(e_star, hertz, *case.wear_coefficients())


def _warn_range(case: Case, plan: Plan, hertz, e_star: float, reach: float) -> None:
    """Where the elastic half-space model is stretched: past yield, past small contacts."""
    p0_ratio = hertz.peak_pressure / e_star
    if p0_ratio > ELASTIC_P0:
        plan.warnings.append(f"the Hertz peak pressure p0 = {hertz.peak_pressure:.4g} MPa is {p0_ratio:.1%} of the "
                             f"contact modulus E* = {e_star:.4g} MPa: well beyond the yield of the softer body for "
                             f"any metal (hardened bearing steel stays elastic to about 4 GPa, 3.5 % of its E*); the "
                             f"elastic model is out of its range, check the load and the moduli")
    onset = YIELD_ONSET["line" if hertz.line else "point"]
    for body, m in (("moving", case.moving), ("stationary", case.stationary)):
        if m.yield_strength is not None and hertz.peak_pressure > onset * m.yield_strength:
            plan.warnings.append(f"the Hertz peak pressure p0 = {hertz.peak_pressure:.4g} MPa passes the onset of "
                                 f"yield in the {body} body ({onset:g} × its yield strength {m.yield_strength:.4g} MPa "
                                 f"= {onset * m.yield_strength:.4g} MPa for a {'line' if hertz.line else 'point'} "
                                 f"contact): it yields below the surface, where the elastic model does not follow it")
    if hertz.half_width_x > SMALL_CONTACT * reach * 2:
        plan.warnings.append(f"the Hertz half-width a = {hertz.half_width_x:.4g} mm is {hertz.half_width_x / (2 * reach):.0%}"
                             f" of the radius: the half-space model assumes a ≪ R (beyond about "
                             f"{SMALL_CONTACT:.0%} its pressures are off by more than a few per cent)")


def available_memory() -> int:
    """Physical memory of this machine in bytes."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 8 * 2**30


def memory_estimate(elements: int, snapshots: int, solver: str, coarse_elements: int = 0) -> float:
    """Bytes a run needs: ~40 work arrays, FFT buffers (4x, complex), 4 fields per snapshot, the implicit
    schemes' history (3 arrays × 8 points), a dense matrix for the dense solvers (on the grid solved on)."""
    solved = coarse_elements or elements
    need = 8.0 * elements * (40 + 24 + 4 * snapshots) + 8.0 * solved * 4 * 2 * 4
    if solver in DENSE_SOLVERS:
        need += 3 * 8.0 * solved**2  # the matrix, its gathered copy, the basis factors
    return need
