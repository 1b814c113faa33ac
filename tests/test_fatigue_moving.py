"""The moving body's fretting fatigue (issue 34): its own half-space under the pressure p and the opposite shear
traction −q at its own points.  Smith & Liu's surface stress at the right edge, the mirror relation between the
bodies, the crack limit in either body, resume, a case with the moving body's constants only, the results file,
and the refusals."""
from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fretsim.api import load_case, run
from fretsim.case import CaseError
from fretsim.fatigue.damage import FatigueSpec, evaluate
from fretsim.fatigue.history import depths
from fretsim.fatigue.swt import Basquin
from fretsim.results import read_results

from conftest import interrupted_and_resumed, same

CASES = Path(__file__).resolve().parent.parent / "cases"
TI = str(CASES / "ti_fretting_fatigue.yaml")
SHORT = ["loading.cycles=30000", "grid.error_estimate=none"]
MOVING = ("materials.moving.fatigue={strength_coefficient: 2464 MPa, strength_exponent: -0.1715, "
          "ductility_coefficient: 0.0711, ductility_exponent: -0.6098, critical_distance: 25 um}")
ONLY_MOVING = [MOVING, "materials.stationary.fatigue=null"]
CURVE = Basquin(2464.0, -0.1715, 0.0711, -0.6098, 116000.0)
A, P0, MU = 0.1, 600.0, 0.5


def _cycle(p, q, n):
    """A detailed cycle's stand-in: the states' (pressure, shear on the flat, travel), each (states, 1, nx)."""
    states = lambda v: np.asarray(v, dtype=float)[:, None, :]  # noqa: E731
    return SimpleNamespace(tractions=(states(p), states(q), np.zeros((len(p), 1, n))),
                           slip_stationary=np.zeros((1, n)), slip_moving=np.zeros((1, n)))


def _hertz(n=801):
    dx = 4 * A / n
    x = (np.arange(n) - (n - 1) / 2) * dx
    return x, dx, P0 * np.sqrt(np.clip(1 - (x / A) ** 2, 0, None))


def _field(body, x, dx, cyc, keep=True):
    spec = FatigueSpec(CURVE, 0.31, depths(dx, 4 * A), None, (0,), keep_stresses=keep, body=body)
    return evaluate(spec, x, dx, CURVE.youngs_modulus, cyc)


def test_the_cycle_drags_the_flat_along_the_moving_bodys_travel():
    """The convention the moving body's −q rests on: while the moving body travels along +x the shear traction
    the cycle records is +μp (it drags the flat along +x), in both cycle models' gross slip."""
    from fretsim.cycle.result import TRACTIONS
    from fretsim.plan import prepare
    from fretsim.simulate import _Loop
    for model in ("uniform", "coulomb"):
        setup = prepare(load_case(TI, ["loading.cycles=0", "grid.error_estimate=none", "loading.stroke=25 um",
                                       f"model.slip={model}"]))[0]
        p, q, s = (np.asarray(a)[:, 0, :] for a in _Loop(setup, (), None).cycle_at(0, None, detail=TRACTIONS)
                   .tractions)
        on = p[0] > 0
        moved = [k for k in range(1, len(s)) if (s[k] - s[k - 1])[on].mean() > 0.5 * 0.025]  # a slide along +x
        assert moved, model
        for k in moved:
            assert q[k][on] == pytest.approx(0.8 * p[k][on], rel=1e-6), model


def test_in_full_sliding_each_bodys_surface_tension_is_smith_and_lius_2_mu_p0_at_its_own_edge():
    """Full sliding with the moving body travelling along +x: the flat carries q = +μp, the moving body −μp.
    Smith & Liu (Johnson §7.1), derived for a half-space under p₀√(1 − t²) and a shear ±μp along +x: the surface
    σx = −p₀(√(1 − t²) ± 2μt) under the contact, ∓2μp₀(t − sign t·√(t² − 1)) outside (the semi-ellipse's Hilbert
    transform), t = x/a.  The flat's tension +2μp₀ is at x = −a, the trailing edge of the moving body's travel;
    the moving body's at x = +a: its leading edge, the edge its friction traction (−x) points away from, where
    the flat's surface leaves it.  Away from the edges within 1 % of p₀; at each edge the nearest element within
    10 % of 2μp₀ (the semi-ellipse's √ is resolved as √dx) and the other edge in compression."""
    x, dx, p = _hertz()
    cyc = _cycle([p, p], [MU * p, MU * p], x.size)
    t = x / A
    away = (np.abs(np.abs(t) - 1) > 0.1) & (np.abs(t) < 1.9)
    for body, sign, edge in (("stationary", 1, -A), ("moving", -1, A)):
        sx = _field(body, x, dx, cyc).stresses[0][0]  # the largest σx over the cycle, at the surface layer
        exact = np.where(np.abs(t) <= 1, -P0 * (np.sqrt(np.clip(1 - t * t, 0, None)) + sign * 2 * MU * t),
                         -sign * 2 * MU * P0 * (t - np.sign(t) * np.sqrt(np.clip(t * t - 1, 0, None))))
        assert np.abs(sx - exact)[away].max() < 0.01 * P0, body
        k = int(np.argmax(sx))
        assert abs(x[k] - edge) < 2 * dx, body
        assert sx[k] == pytest.approx(2 * MU * P0, rel=0.1), body
        assert sx[np.argmin(np.abs(x + edge))] < -P0 * 0.5, body


def test_for_symmetric_tractions_without_travel_the_moving_bodys_field_is_the_flats_mirrored():
    """Even pressure, even shear on the flat (a Mindlin-like loading one way, no rigid slide, no travel):
    the moving body's problem, (p, −q), is the flat's reflected through x = 0 — its SWT at x the flat's at −x and
    its plane the flat's mirrored, φ ↦ π − φ.  To round-off (the search's angles are symmetric about 90°)."""
    x, dx, p = _hertz(n=401)
    stick = 0.6 * A
    q_full = MU * p
    q_stick = MU * P0 * (stick / A) * np.sqrt(np.clip(1 - (x / stick) ** 2, 0, None))
    shear = [s * (q_full - 2 * q_stick) for s in (0.0, 1.0, 0.3, 0.8)]  # one way only: the flat not symmetric
    cyc = _cycle([p] * len(shear), shear, x.size)
    flat, moving = _field("stationary", x, dx, cyc, keep=False), _field("moving", x, dx, cyc, keep=False)
    top = flat.swt.max()
    assert top > 0 and np.abs(flat.swt - flat.swt[:, ::-1]).max() > 0.1 * top  # (else the test could not fail)
    np.testing.assert_allclose(moving.swt, flat.swt[:, ::-1], atol=1e-9 * top)
    strong = flat.swt[:, ::-1] > 0.05 * top
    turned = np.mod(np.pi - flat.angle[:, ::-1], np.pi)
    gap = np.abs(np.angle(np.exp(2j * (moving.angle - turned))))  # (π-periodic planes)
    assert np.median(gap[strong]) < 1e-9


def test_identical_bodies_in_the_loop_see_nearly_the_same_swt_mirrored(tmp_path):
    """The Ti case's identical bodies, unworn: the flat's tractions move ±5 µm with the travel on a 240 µm
    contact, the moving body's do not, so the two bodies' SWT peaks agree within a few per cent, at mirrored x,
    and their surface tension to 1 %.  The loop is symmetric (q ↦ −q over x ↦ −x), so each body's field is
    symmetric in x to round-off and its peak stands at both edges: which one the summary names is round-off's
    choice (it changed with the tangential solves' rounding), so the fields' symmetry is checked and the
    location compared in magnitude."""
    from fretsim.api import read_results
    s = run(load_case(TI, ["loading.cycles=0", "grid.error_estimate=none", MOVING]), tmp_path / "r.h5").summary
    assert s["swt_max_moving_MPa"] == pytest.approx(s["swt_max_MPa"], rel=0.03)
    fields = read_results(tmp_path / "r.h5").subsurface
    for key in ("swt", "swt_moving"):
        f = np.asarray(fields[key])[-1]
        assert np.abs(f - f[:, ::-1]).max() < 1e-9 * f.max()  # (so the peak at −x is the peak at +x)
    assert abs(s["swt_location_x_moving_mm"]) == pytest.approx(abs(s["swt_location_x_mm"]), abs=0.01)
    assert s["max_surface_tensile_stress_moving_MPa"] == pytest.approx(s["max_surface_tensile_stress_MPa"],
                                                                       rel=0.01)


@pytest.fixture(scope="module")
def moving_only(tmp_path_factory):
    out = tmp_path_factory.mktemp("moving") / "m.h5"
    return run(load_case(TI, SHORT + ONLY_MOVING + ["limits.crack_initiation=true", "output.stresses=true"]),
               out), out


def test_a_case_with_the_moving_bodys_constants_only_cracks_it_and_stops_there(moving_only):
    outcome, path = moving_only
    s = outcome.summary
    assert outcome.setup.fatigue is None and outcome.setup.fatigue_moving is not None
    assert "swt_max_MPa" not in s and "cycles_to_crack_initiation" not in s  # (the flat has no constants)
    assert s["limit_reached"] == "crack_initiation" and s["crack_body"] == "moving"
    assert s["damage_mode"] == "cracking"
    assert s["cycles_to_limit"] == s["cycles_to_crack_initiation_moving"] < s["cycles"]
    assert s["fatigue_damage_moving"] >= 1.0
    assert abs(s["crack_location_x_moving_mm"]) <= 0.2
    states = outcome.setup.fatigue_moving.states
    assert s["cycles"] >= min(n for n in states if n >= s["cycles_to_crack_initiation_moving"])


def test_the_moving_bodys_fields_are_in_the_file_the_reader_the_figure_and_the_export(moving_only, tmp_path):
    from fretsim.export import export_csv
    from fretsim.plotting import figures
    outcome, path = moving_only
    res = read_results(path)
    n, nx = res.fields["cycle"].size, res.x.size
    nz = res.subsurface["z"].size
    for key in ("swt_moving", "swt_plane_angle_moving", "stress_xx_max_moving", "stress_xz_min_moving"):
        assert res.subsurface[key].shape == (n, nz, nx), key
    assert "swt" not in res.subsurface and res.fatigue("stationary") == {}
    mine = res.fatigue("moving")
    assert np.array_equal(mine["swt"], res.subsurface["swt_moving"]) and res.units["fields/swt_moving"] == "MPa"
    assert np.array_equal(mine["swt"][-1], outcome.last.fatigue_moving.swt)
    assert np.nanmax(mine["swt"]) <= res.summary["swt_max_moving_MPa"]
    assert res.to_xarray()["swt_moving"].dims == ("cycle", "z", "x")
    built = figures(res, names=["fatigue_moving"])
    assert "fatigue_moving" in built and "fatigue" not in figures(res)
    marks = {line.get_label(): line.get_xdata()[0] for line in built["fatigue_moving"].axes[0].get_lines()}
    crack = next(v for k, v in marks.items() if k.startswith("crack"))
    assert crack == pytest.approx(res.summary["crack_location_x_moving_mm"] * 1e3)
    export_csv(res, tmp_path)
    header = (tmp_path / "subsurface.csv").read_text().splitlines()[0]
    assert header.startswith("cycle,z [mm],x [mm],swt_moving [MPa]")


@pytest.mark.parametrize("weaker, body", [("moving", "moving"), ("stationary", "stationary")])
def test_with_both_bodies_the_crack_limit_stops_at_the_first_crack_and_names_its_body(weaker, body):
    """Both bodies with constants; the one given a lower σ'_f cracks first and stops the run; the other's damage
    is below 1 and its crack cycle NaN."""
    other = "stationary" if weaker == "moving" else "moving"
    s = run(load_case(TI, SHORT + [MOVING, "limits.crack_initiation=true",
                                   f"materials.{other}.fatigue.strength_coefficient=3500 MPa"])).summary
    suffix = "_moving" if body == "moving" else ""
    assert s["crack_body"] == body and s["limit_reached"] == "crack_initiation"
    assert s["cycles_to_limit"] == s[f"cycles_to_crack_initiation{suffix}"]
    other_suffix = "" if suffix else "_moving"
    assert math.isnan(s[f"cycles_to_crack_initiation{other_suffix}"])
    assert s[f"fatigue_damage{other_suffix}"] < 1.0


def test_a_run_with_both_bodies_interrupted_resumes_to_the_same_damage_of_each(tmp_path):
    keys = ("cycles_to_crack_initiation", "fatigue_damage", "swt_max_MPa", "cycles_to_crack_initiation_moving",
            "fatigue_damage_moving", "swt_max_moving_MPa", "crack_location_x_moving_mm", "crack_body")
    whole = run(load_case(TI, SHORT + [MOVING])).summary

    resumed = interrupted_and_resumed(TI, SHORT + [MOVING], 2000, tmp_path / "r.h5").summary
    for key in keys:
        assert same(resumed[key], whole[key]), key
    assert whole["fatigue_damage_moving"] > 0.1  # (a resume that lost the moving body's sum would show)


def test_a_moving_body_that_is_not_a_half_space_is_refused_and_one_that_is_runs():
    """a = √(4PR/πE*): 21.8 µm on R = 0.2 mm (a/R = 0.11, refused), 34.5 µm on R = 0.5 mm (0.069, runs)."""
    from fretsim.plan import prepare
    base = ["loading.cycles=0", "grid.error_estimate=none", MOVING]
    with pytest.raises(CaseError) as exc:
        prepare(load_case(TI, base + ["geometry.radius=0.2 mm"]))
    assert "materials.moving.fatigue" in str(exc.value) and "half-space" in str(exc.value)
    assert prepare(load_case(TI, base + ["geometry.radius=0.5 mm"]))[0].fatigue_moving is not None


def test_a_tubes_moving_body_fatigue_is_refused():
    """A tube's wall bends as a ring under the contact: not a half-space."""
    from fretsim.plan import prepare
    with pytest.raises(CaseError) as exc:
        prepare(load_case(str(CASES / "tube_RT.yaml"), ["loading.cycles=0", "grid.error_estimate=none",
                                                        "model.dimension=2d", "loading.friction_coefficient=0.5",
                                                        MOVING]))
    assert "materials.moving.fatigue" in str(exc.value) and "ring" in str(exc.value)
