"""The results file's layout: its format versions, and what each step and snapshot writes, with units."""
from __future__ import annotations

import numpy as np

from fretsim.quantities import SUMMARY, WEAR

FORMAT_VERSION = "1.5"
READABLE_FORMATS = ("1.1", "1.2", "1.3", "1.4", "1.5")
STATUSES = ("running", "complete", "interrupted", "failed", "stopped")
MAX_DATASET_BYTES = 2**32  # 4 GiB: no results file of this tool holds a larger array
MAX_NAME = 200  # bytes of the output's base name we accept (temporaries use fixed-length names)

# name: (units, long name, how to get the value from a Step)
HISTORY = {
    "cycle": ("cycles", "cycle number", lambda s: s.cycle),
    **{key: (WEAR[key].unit, WEAR[key].long_name, lambda s, q=WEAR[key]: q.measure(s, None, None) * q.factor)
       for key in ("max_wear_depth_moving", "max_wear_depth_stationary")},
    "max_wear_depth_total": ("um", "maximum total wear depth", lambda s: (s.wear_moving + s.wear_stationary).max() * 1e3),
    **{key: ("mm^3", WEAR[key].long_name, lambda s, q=WEAR[key]: q.measure(s, None, None))
       for key in ("wear_volume_moving", "wear_volume_stationary")},
    "max_pressure": ("MPa", "maximum contact pressure", lambda s: s.pressure.max()),
    "solver_iterations": ("1", "contact solver iterations", lambda s: s.iterations),
    "wall_time": ("s", "wall time since the start of the run", lambda s: s.wall_time),
    "approach": ("um", "rigid-body approach", lambda s: s.approach * 1e3),
    "archard_volume_error": ("1", "relative difference of the wear volume from k·P·4δ·N", lambda s: s.archard_error),
    "checkerboard_amplitude": ("1", "odd-even pressure amplitude relative to the mean", lambda s: abs(s.checkerboard)),
    "cycle_jump": ("cycles", "cycles since the previous step", lambda s: s.jump),
    "rejected_steps": ("1", "steps rejected since the previous accepted one", lambda s: s.rejected),
    "error_estimate_depth": ("1", "the stepping's part of the relative error of the maximum depths (the run's "
                                  "estimate against the exact per-cycle model on its grid)", lambda s: s.error_depth),
    "error_estimate_pressure": ("1", "the stepping's part of the relative error of the pressure field (L2)",
                                lambda s: s.error_pressure),
    "dissipated_energy_J": ("J", "energy dissipated per cycle by friction at this state (NaN: no friction "
                                 "coefficient)", lambda s: s.cycle_result.energy * 1e-3),
    "wear_work": ("N*mm", "the wear invariant's work accumulated: Σp·|ds|·A (Archard) or Σ|q|·|ds|·A (energy "
                          "law) over the cycles; each body's wear volume is its coefficient times it",
                  lambda s: s.work),
    "block": ("1", "the loading's block (from 0, in the order applied) whose cycles led to this state",
              lambda s: s.block),
    "cumulative_dissipated_energy_J": ("J", "energy dissipated by friction from cycle 0 to this state: the per-cycle "
                                            "energy summed over the cycles as the wear is, jumps included (NaN: no "
                                            "friction coefficient)", lambda s: s.energy * 1e-3),
}
INTEGER_HISTORY = {"cycle", "solver_iterations", "cycle_jump", "rejected_steps", "block"}
NAN_HISTORY = {"dissipated_energy_J", "cumulative_dissipated_energy_J"}  # NaN without a friction coefficient
HISTORY_V14 = [k for k in HISTORY if k != "cumulative_dissipated_energy_J"]
HISTORY_V13 = [k for k in HISTORY_V14 if k != "block"]
HISTORY_V12 = [k for k in HISTORY_V13 if k not in ("dissipated_energy_J", "wear_work")]
HISTORY_V11 = [k for k in HISTORY_V12 if not k.startswith("error_estimate")]
FIELDS = {
    "wear_depth_moving": ("um", "wear depth of the moving body", lambda s: s.wear_moving * 1e3),
    "wear_depth_stationary": ("um", "wear depth of the stationary body", lambda s: s.wear_stationary * 1e3),
    "pressure": ("MPa", "contact pressure on the moving body at mid-stroke", lambda s: s.pressure),
    "pressure_stationary_average": ("MPa", "stroke-averaged pressure on the stationary body",
                                    lambda s: s.pressure_average),
    "slip_distance_moving": ("um", "slip distance per cycle at each point of the moving body",
                             lambda s: s.cycle_result.slip_moving * 1e3),
    "slip_distance_stationary": ("um", "slip distance per cycle at each point of the stationary body",
                                 lambda s: s.cycle_result.slip_stationary * 1e3),
    "shear_traction": ("MPa", "amplitude of the shear traction on the moving body over the cycle (NaN: not "
                              "modelled)", lambda s: s.cycle_result.shear),
}
# fretting fatigue (materials.stationary.fatigue): the flat's fields below its surface at the recorded states, over
# (cycle, z, x) with /fields/z the depths; the stresses only with output.stresses.  Absent without fatigue.
SUBSURFACE = {
    "swt": ("MPa", "Smith-Watson-Topper parameter on the critical plane below the stationary body's surface",
            lambda f: f.swt),
    "swt_plane_angle": ("deg", "the critical plane's normal, from the sliding direction x towards the depth z",
                        lambda f: np.degrees(f.angle)),
}
# 3D (fields over (cycle, z, y, x)): the critical plane's normal out of the x–z plane, with swt_plane_angle its angle
# from x towards z in that plane: n = ±(cos β cos θ, sin β, cos β sin θ)
SUBSURFACE_3D = {
    "swt_plane_azimuth": ("deg", "the critical plane's normal, out of the x-z plane towards y (3D; with "
                                 "swt_plane_angle its angle from x towards z in that plane)",
                          lambda f: np.degrees(f.azimuth)),
}
STRESSES = {
    f"stress_{c}_{end}": ("MPa", f"the stationary body's stress σ_{c} below its surface: its {end}imum over the cycle",
                          lambda f, i=2 * i + j: f.stresses[i])
    for i, c in enumerate(("xx", "zz", "xz")) for j, end in enumerate(("max", "min"))}
# the moving body's (materials.moving.fatigue), on its own grid (the grid moves with it) and the same depths,
# below its surface: its depth points into it, x as the flat's.  Absent without its constants.
SUBSURFACE_MOVING = {
    "swt_moving": ("MPa", "Smith-Watson-Topper parameter on the critical plane below the moving body's surface "
                          "(its half-space, at its own points)", lambda f: f.swt),
    "swt_plane_angle_moving": ("deg", "the moving body's critical plane's normal, from the sliding direction x "
                                      "towards its depth", lambda f: np.degrees(f.angle)),
}
STRESSES_MOVING = {
    f"stress_{c}_{end}_moving": ("MPa", f"the moving body's stress σ_{c} below its surface (x, its depth): its "
                                        f"{end}imum over the cycle", lambda f, i=2 * i + j: f.stresses[i])
    for i, c in enumerate(("xx", "zz", "xz")) for j, end in enumerate(("max", "min"))}
# each body's subsurface tables: (SWT fields, stresses), and the Step's attribute holding its fatigue state
SUBSURFACE_BODIES = {"stationary": (SUBSURFACE, STRESSES, "fatigue"),
                     "moving": (SUBSURFACE_MOVING, STRESSES_MOVING, "fatigue_moving")}
SUBSURFACE_TABLES = {**SUBSURFACE, **SUBSURFACE_3D, **STRESSES, **SUBSURFACE_MOVING, **STRESSES_MOVING}
FIELDS_V12 = [k for k in FIELDS if not k.startswith(("slip_distance", "shear"))]
NAN_FIELDS = {"shear_traction"}  # the uniform model without a friction coefficient does not know it
SUMMARY_UNITS = {key: figure.unit for key, figure in SUMMARY.items()}
_SUMMARY_ORDER = {key: i for i, key in enumerate(SUMMARY)}


def in_summary_order(summary: dict) -> dict:
    """A summary in the registry's order (keys it does not know after, by name): a run's and a file's read back
    list the same keys in the same order, so a sweep's table has the same columns whether its points ran now or
    were read from their files."""
    return dict(sorted(summary.items(), key=lambda kv: (_SUMMARY_ORDER.get(kv[0], len(_SUMMARY_ORDER)), kv[0])))
NAN_SUMMARY = {key for key, figure in SUMMARY.items() if figure.nan}




def summary_long_name(key: str) -> str:
    return key.replace("_", " ")


