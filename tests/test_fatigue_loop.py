"""Fretting fatigue in the loop (issue 34): the flat's stresses from a cycle's tractions, the fast critical plane,
Miner's sum over the wear history, the crack limit, the results file and resume, and the case's errors."""
from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner

from fretsim.api import load_case, run
from fretsim.case import CaseError
from fretsim.cli import main
from fretsim.fatigue import history
from fretsim.fatigue.damage import FatigueSpec, FatigueState, Miner, damage_parameter, fatigue_states, slides
from fretsim.fatigue.stresses import strip_stresses
from fretsim.fatigue.swt import FINE_SHARE, Basquin, swt_2d, swt_search
from fretsim.results import read_results

from conftest import interrupted_and_resumed

CASES = Path(__file__).resolve().parent.parent / "cases"
TI = str(CASES / "ti_fretting_fatigue.yaml")
SHORT = ["loading.cycles=30000", "grid.error_estimate=none"]
TI_CURVE = Basquin(2030.0, -0.104, 0.841, -0.688, 115000.0)


def _hertz_line(n=301, a=0.2, extent=2.0):
    dx = 2 * extent * a / n
    x = (np.arange(n) - (n - 1) / 2) * dx
    return x, dx, np.sqrt(np.clip(1 - (x / a) ** 2, 0, None))


def test_the_flats_stresses_by_fft_equal_the_strips_dense_sums():
    """The convolution by FFT against strip_stresses' direct sums, several states with different tractions: the
    same closed forms summed two ways, so equal to round-off (1e-12 of the peak)."""
    x, dx, p = _hertz_line()
    rng = np.random.default_rng(3)
    ps = p[None] * rng.uniform(0.5, 1.5, (4, 1))
    qs = 0.4 * ps * rng.uniform(-1, 1, (4, 1))
    z = history.depths(dx, 0.6)
    fast = history.stresses(ps, qs, dx, z)
    for k in range(4):
        ref = strip_stresses(x, dx, ps[k], qs[k], x, z)
        for a, b in ((fast.sxx[k], ref.sxx), (fast.szz[k], ref.szz), (fast.sxz[k], ref.sxz)):
            assert np.abs(a - b).max() < 1e-12 * np.abs(b).max()


def test_laying_tractions_on_the_flat_keeps_the_load_and_moves_it_with_the_travel():
    """Linear weights: each state's total load kept to round-off, and its centroid moved by the travel exactly
    (a uniform travel of 2.3 elements)."""
    x, dx, p = _hertz_line()
    travel = np.full((1, x.size), 2.3 * dx)
    laid = history.on_flat(p[None], travel, x, dx)
    assert laid.sum() == pytest.approx(p.sum(), rel=1e-13)
    assert (laid[0] * x).sum() / laid.sum() == pytest.approx((p * x).sum() / p.sum() + 2.3 * dx, abs=1e-12)


def _sliding_history():
    """A sliding cylinder's stresses (q = ±μp) at both ends of a ±5-element stroke, and every position between."""
    x, dx, p = _hertz_line(n=201, a=0.2, extent=1.5)
    z = history.depths(dx, 0.3, layers=10)
    states, travels, fine = [], [], []
    for sign, (u0, u1) in ((+1, (-5, 5)), (-1, (5, -5))):
        for u in (u0, u1):
            states.append((p, sign * 0.5 * p))
            travels.append(np.full(x.size, u * dx))
        for u in range(u0, u1 + sign, sign):
            fine.append(history.on_flat(np.array([p, sign * 0.5 * p]), np.full((2, x.size), u * dx), x, dx))
    ps = np.array([history.on_flat(s[0][None], t[None], x, dx)[0] for s, t in zip(states, travels)])
    qs = np.array([history.on_flat(s[1][None], t[None], x, dx)[0] for s, t in zip(states, travels)])
    return x, dx, z, ps, qs, np.array(travels), fine


# the 1° pass, over each point's gathered history, and the 5° pass alone (its running extremes along x): nothing is
# refined where the share asked is above the peak
@pytest.mark.parametrize("fine_share", [FINE_SHARE, 2.0])
def test_a_rigidly_sliding_state_counts_every_position_on_its_way(fine_share, monkeypatch):
    """Four states (each end of each half-stroke) with the slides marked give the SWT of all 22 positions
    computed one by one: the sliding maximum is exact on the grid (1e-12)."""
    import fretsim.fatigue.swt as swt
    monkeypatch.setattr(swt, "FINE_SHARE", fine_share)
    x, dx, z, ps, qs, travels, fine = _sliding_history()
    slid = slides(np.ones_like(ps), travels, dx)
    assert slid == {1: 10, 3: -10}
    st = history.stresses(ps, qs, dx, z)
    few = swt_search((st.sxx, st.szz, st.sxz), 115000.0, 0.3, slid)
    every = history.stresses(np.array([f[0] for f in fine]), np.array([f[1] for f in fine]), dx, z)
    ref = swt_search((every.sxx, every.szz, every.sxz), 115000.0, 0.3)
    # (the window holds the field at the grid's ends: compared ten elements of travel from them; and where the
    # value matters, a tenth of the peak and more: below, two planes can tie to round-off and the search's second
    # pass refine about either)
    inner = (slice(None), slice(12, -12))
    big = ref.swt[inner] > 0.1 * ref.swt.max()
    assert big.sum() > 50 and np.abs(few.swt - ref.swt)[inner][big].max() < 1e-12 * ref.swt.max()
    without = swt_search((st.sxx, st.szz, st.sxz), 115000.0, 0.3)  # the ends alone miss the edge passing by
    assert np.abs(without.swt - ref.swt).max() > 0.05 * ref.swt.max()


def test_the_fast_critical_plane_search_finds_the_full_searchs_plane_on_a_fretting_history():
    """swt_search (5°, then 1° about the two best) against swt_2d's every degree on a sliding cylinder's history:
    the same value (to 1e-9 of the peak: the same 1° planes) wherever it is 1.5 FINE_SHARE of the peak or more
    (there the second pass is made); below, the 5° pass's value, never above the true one (a lower bound whose
    damage is 10⁻¹⁰ of the peak's)."""
    x, dx, z, ps, qs, travels, fine = _sliding_history()
    every = history.stresses(np.array([f[0] for f in fine]), np.array([f[1] for f in fine]), dx, z)
    fast = swt_search((every.sxx, every.szz, every.sxz), 115000.0, 0.3)
    full = swt_2d((every.sxx, every.szz, every.sxz), 115000.0, 0.3)
    big = full.swt >= 1.5 * FINE_SHARE * full.swt.max()  # (the 5° pass, a few % low, decides where to refine)
    assert big.sum() > 100 and np.abs(fast.swt - full.swt)[big].max() < 1e-9 * full.swt.max()
    small = ~big & (full.swt > 0)
    assert (fast.swt[small] <= full.swt[small] + 1e-20).all()


def test_where_the_second_pass_is_not_worth_making_the_first_passs_value_stands_and_elsewhere_nothing_changes():
    """``worth`` (the damage-only states' columns that count): where it says so, the search is the full one's to
    round-off; elsewhere the 5° value, never above the 1° one and within 5 % of it on this history (the 5° planes
    are every fifth 1° plane: 2.5° from the optimum at worst)."""
    x, dx, z, ps, qs, travels, fine = _sliding_history()
    every = history.stresses(np.array([f[0] for f in fine]), np.array([f[1] for f in fine]), dx, z)
    hist = (every.sxx, every.szz, every.sxz)
    full = swt_search(hist, 115000.0, 0.3)
    column = lambda first: np.broadcast_to(first.max(axis=0) >= 0.5 * first.max(), first.shape)  # noqa: E731
    part = swt_search(hist, 115000.0, 0.3, worth=column)
    worth = column(part.swt) & (full.swt >= FINE_SHARE * full.swt.max())
    assert worth.sum() > 100 and (~worth & (full.swt > 0.1 * full.swt.max())).sum() > 100
    assert np.abs(part.swt - full.swt)[worth].max() < 1e-12 * full.swt.max()
    rest = ~worth & (full.swt > 0)
    assert (part.swt[rest] <= full.swt[rest] * (1 + 1e-12)).all()
    assert (part.swt[rest] >= 0.95 * full.swt[rest]).all() and (part.swt[rest] < full.swt[rest]).any()


def test_between_recorded_states_the_second_pass_where_the_damage_counts_leaves_the_crack_where_it_was(monkeypatch):
    """REFINE_SHARE (the 1° pass between recorded states only in the columns whose damage parameter is at least a
    quarter of the largest) against the 1° pass everywhere: the crack cycle and the largest damage within 1e-4
    (measured: the same crack cycle to every digit printed on the Ti case at 4, 5, 10 and 25 µm, the damage
    within 7e-5)."""
    import fretsim.fatigue.damage as dmg
    shipped = dmg.REFINE_SHARE
    assert shipped > 0
    out = {}
    for share in (shipped, 0.0):
        monkeypatch.setattr(dmg, "REFINE_SHARE", share)
        out[share] = run(load_case(TI, SHORT)).summary
    a, b = out[shipped], out[0.0]
    assert math.isfinite(b["cycles_to_crack_initiation"])
    assert a["cycles_to_crack_initiation"] == pytest.approx(b["cycles_to_crack_initiation"], rel=1e-4)
    assert a["fatigue_damage"] == pytest.approx(b["fatigue_damage"], rel=1e-4)


def test_lives_of_an_array_equal_the_scalar_bisection_and_the_endurance_limit_counts_none():
    curve = Basquin(2030.0, -0.104, 0.841, -0.688, 115000.0, endurance_limit=0.5)
    swt = np.array([0.1, 0.5, 0.6, 1.0, 3.0, 10.0, 100.0, 1e4])
    lives = curve.lives(swt)
    for s, n in zip(swt, lives):
        assert (n == curve.life(s)) if math.isinf(n) else n == pytest.approx(curve.life(s), rel=1e-10)
    assert math.isinf(lives[1]) and curve.swt(lives[3]) == pytest.approx(1.0, rel=1e-10)


def _state(life: float) -> FatigueState:
    one = np.full((1, 1), life)
    return FatigueState(swt=one, angle=one, life=one, max_shear=0, max_shear_depth=0, max_tension=0, swt_max=0,
                        swt_x=0, swt_depth=0, ruiz_max=0)


def test_miners_sum_crosses_one_at_the_life_for_a_steady_contact_and_at_the_quadratics_root_for_a_changing_one():
    """A constant life N: D = n/N, the crack at N exactly.  A life whose rate 1/N grows linearly from r0 to r1
    over the interval: D(t) = r0·t + (r1 − r0)t²/2Δ, crossing 1 at its root (derived by hand in the docstring of
    fretsim.fatigue.damage)."""
    m = Miner()
    for n in (0, 400, 1000, 1500):
        m.add(n, _state(1000.0))
    assert m.crack[0] == pytest.approx(1000.0, rel=1e-12)
    m = Miner()
    m.add(0, _state(1 / 1e-4))
    m.add(10000, _state(1 / 3e-4))  # D(t) = 1e-4 t + 1e-8 t² : 1 at t = (−1e-4 + √(1e-8 + 4e-8))/2e-8
    assert m.crack[0] == pytest.approx((-1e-4 + math.sqrt(5e-8)) / 2e-8, rel=1e-10)


def test_the_line_method_averages_the_parameter_over_the_critical_distance():
    """A parameter linear in depth, 10 − 2z (z in µm): its mean over 0…L is 10 − L, whatever the layers."""
    z = history.depths(0.001, 0.2)
    swt = (10.0 - 2.0 * z * 1e3)[:, None] * np.ones((1, 3))
    spec = FatigueSpec(curve=TI_CURVE, poisson=0.3, depths=z, critical_distance=0.004, states=())
    swt[0] = 10.0  # the surface layer stands for z = 0
    assert damage_parameter(spec, swt) == pytest.approx(np.full((1, 3), 10.0 - 4.0), rel=1e-12)


@pytest.mark.parametrize("elements", [0.01, 0.05, 0.3, 0.5, 0.7, 3.0, 40.0, 1e4])
def test_the_layers_computed_between_recorded_states_are_all_the_line_method_reads(elements):
    """A critical distance of ``elements`` element sizes (from well inside the surface layer's depth, 0.05 of an
    element, to beyond the deepest layer): the layers past ``line_layers`` set to NaN change nothing.  Counted from
    the layers' own depths, a distance at or inside the surface layer's computed one layer while the mean read two
    (the second then 0: the parameter up to 5 % low, its damage rate ~25 %)."""
    dx = 0.001
    z = history.depths(dx, 0.2)
    spec = FatigueSpec(curve=TI_CURVE, poisson=0.3, depths=z, critical_distance=elements * dx, states=())
    field = (10.0 - z * 1e3)[:, None] * np.ones((1, 3))
    cut = field.copy()
    cut[spec.line_layers():] = np.nan
    assert np.array_equal(damage_parameter(spec, cut), damage_parameter(spec, field))


def test_fatigue_states_thin_out_geometrically_and_hold_every_recorded_state():
    states = fatigue_states(100000, (0, 25000, 100000))
    assert {0, 25000, 100000} <= set(states) and states == tuple(sorted(set(states)))
    ratios = np.diff(np.log10([s for s in states if 0 < s < 10000]))
    assert ratios.max() < 0.55  # at least two per decade below the linear ones


def test_the_loops_hertz_contact_has_its_largest_shear_0_300_p0_at_0_786_a():
    """A contact-only run (0 cycles, μ tiny) through the whole pipeline (tractions, laying on the flat, the depth
    layers, the summary): Johnson §4.2's 0.300 p₀ at 0.786 a, within 1 % (the layers are 30 % apart near 0.786 a;
    the maximum is flat there) and the depth within the layer spacing."""
    out = run(load_case(TI, ["loading.cycles=0", "grid.error_estimate=none", "loading.friction_coefficient=0.001"]))
    s, hz = out.summary, out.setup
    case = out.case
    e_star = case.moving.youngs_modulus / (2 * (1 - case.moving.poissons_ratio ** 2))  # equal bodies
    load = case.loading.peak_load / case.geometry.length  # N/mm
    a = math.sqrt(4 * load * case.geometry.radius / (math.pi * e_star))  # Johnson (4.43), (4.45)
    p0 = 2 * load / (math.pi * a)
    assert s["max_shear_stress_MPa"] == pytest.approx(0.300 * p0, rel=0.01)
    assert s["max_shear_stress_depth_um"] * 1e-3 == pytest.approx(0.786 * a, rel=0.2)
    assert hz.fatigue is not None


@pytest.fixture(scope="module")
def cracked(tmp_path_factory):
    out = tmp_path_factory.mktemp("fatigue") / "ti.h5"
    return run(load_case(TI, SHORT + ["limits.crack_initiation=true", "output.stresses=true"]), out), out


def test_a_run_with_the_crack_limit_stops_at_the_state_after_the_crack_and_reports_its_cycle(cracked):
    outcome, path = cracked
    s = outcome.summary
    assert s["limit_reached"] == "crack_initiation" and s["damage_mode"] == "cracking"
    assert s["cycles_to_limit"] == s["cycles_to_crack_initiation"] < s["cycles"]
    # the fatigue is evaluated at the first step at or past each fatigue state: the run stops at the first one past
    # the crack
    assert s["cycles"] >= min(n for n in outcome.setup.fatigue.states if n >= s["cycles_to_crack_initiation"])
    steps = read_results(path).history["cycle"]
    assert steps[-2] < min(n for n in outcome.setup.fatigue.states if n >= s["cycles_to_crack_initiation"])
    assert s["fatigue_damage"] >= 1.0
    assert abs(s["crack_location_x_mm"]) <= 0.2  # at the contact (half-width 0.12 mm unworn, 0.16 mm worn)


def test_the_results_file_holds_the_swt_field_over_cycle_depth_x_and_the_stresses_asked_for(cracked):
    outcome, path = cracked
    res = read_results(path)
    sub = res.subsurface
    n, nz, nx = res.fields["cycle"].size, sub["z"].size, res.x.size
    for key in ("swt", "swt_plane_angle", *(f"stress_{c}_{e}" for c in ("xx", "zz", "xz") for e in ("max", "min"))):
        assert sub[key].shape == (n, nz, nx), key
    assert res.units["fields/swt"] == "MPa" and res.units["fields/z"] == "mm"
    last = outcome.last.fatigue  # the state the run ended at, evaluated in full: what the file's last row holds
    assert np.array_equal(sub["swt"][-1], last.swt) and np.array_equal(sub["stress_xx_max"][-1], last.stresses[0])
    assert np.nanmax(sub["swt"]) <= res.summary["swt_max_MPa"]  # (the peak over every fatigue state)
    # the surface's largest tension over the cycle is the one the summary reports at the state it peaked
    assert (sub["stress_xx_max"][:, 0, :] <= res.summary["max_surface_tensile_stress_MPa"] + 1e-9).all()
    ds = res.to_xarray()
    assert ds["swt"].dims == ("cycle", "z", "x")


def test_a_run_interrupted_with_fatigue_resumes_to_the_same_damage_and_crack(tmp_path):
    whole = run(load_case(TI, SHORT))

    resumed = interrupted_and_resumed(TI, SHORT, 2000, tmp_path / "r.h5")
    for key in ("cycles_to_crack_initiation", "fatigue_damage", "swt_max_MPa", "crack_location_x_mm"):
        assert resumed.summary[key] == whole.summary[key], key


def test_the_uniform_and_the_coulomb_cycle_give_the_same_swt_in_gross_slip():
    """Two descriptions of one gross-slip cycle: uniform's rigid slides of μp against coulomb's increments with
    their elastic sides.  They differ by the sides (2δ_t of the 4δ: 11 % of the stroke here), so within 5 % at
    the SWT peak; the damage, ∝ SWT^4.8, within 25 %."""
    runs = [run(load_case(TI, SHORT + ["loading.stroke=25 um", f"model.slip={m}"])).summary
            for m in ("uniform", "coulomb")]
    assert runs[0]["swt_max_MPa"] == pytest.approx(runs[1]["swt_max_MPa"], rel=0.05)
    assert runs[0]["fatigue_damage"] == pytest.approx(runs[1]["fatigue_damage"], rel=0.25)


@pytest.mark.parametrize("override, where", [
    ("loading.friction_coefficient=null", "materials.stationary.fatigue"),
    ("materials.stationary.fatigue.strength_exponent=0.1", "materials.stationary.fatigue.strength_exponent"),
    ("materials.stationary.fatigue.critical_distance=25", "materials.stationary.fatigue.critical_distance"),
])
def test_what_fatigue_cannot_use_is_refused_with_its_key(override, where):
    with pytest.raises(CaseError) as exc:
        load_case(TI, [override])
    assert where in str(exc.value)


MOVING = ("materials.moving.fatigue={strength_coefficient: 2464 MPa, strength_exponent: -0.1715, "
          "ductility_coefficient: 0.0711, ductility_exponent: -0.6098, critical_distance: 25 um}")


@pytest.mark.parametrize("overrides", [
    ["model.dimension=3d"],  # with the flat's constants: both refused by the first key
    ["model.dimension=3d", "materials.stationary.fatigue=null"],  # the moving body's alone: refused by its own
    ["loading.friction_coefficient=null", "materials.stationary.fatigue=null"],
    ["materials.moving.fatigue.strength_exponent=0.1"],
])
def test_what_the_moving_bodys_fatigue_cannot_use_is_refused_with_its_key(overrides):
    with pytest.raises(CaseError) as exc:
        load_case(TI, [MOVING] + overrides)
    text = str(exc.value)
    assert ("materials.moving.fatigue" in text if "materials.stationary.fatigue=null" in overrides or
            "strength_exponent" in overrides[0] else "materials.stationary.fatigue" in text), text


def test_the_crack_limit_and_the_stresses_need_the_constants_and_the_cli_says_so_in_a_paragraph(tmp_path):
    mccoll = str(CASES / "mccoll_185N.yaml")
    result = CliRunner().invoke(main, ["run", mccoll, "-o", str(tmp_path / "m.h5"), "--set",
                                       "limits.crack_initiation=true"])
    assert result.exit_code != 0 and "Traceback" not in result.output
    assert "limits.crack_initiation" in result.output and "materials.stationary.fatigue" in result.output
    assert not (tmp_path / "m.h5").exists()


def test_the_fatigue_figure_marks_the_runs_swt_peak_and_the_crack_and_export_writes_the_field(cracked, tmp_path):
    from fretsim.export import export_csv
    from fretsim.plotting import figures
    outcome, path = cracked
    res = read_results(path)
    fig = figures(res, names=["fatigue"])["fatigue"]
    field_ax = fig.axes[0]
    marks = {line.get_label(): (line.get_xdata()[0], line.get_ydata()[0]) for line in field_ax.get_lines()
             if line.get_label().startswith(("peak", "crack"))}
    peak = next(v for k, v in marks.items() if k.startswith("peak"))
    assert peak == pytest.approx((res.summary["swt_location_x_mm"] * 1e3, res.summary["swt_depth_um"]))
    crack = next(v for k, v in marks.items() if k.startswith("crack"))
    assert crack[0] == pytest.approx(res.summary["crack_location_x_mm"] * 1e3)
    paths = export_csv(res, tmp_path)
    sub = tmp_path / "subsurface.csv"
    assert sub in paths
    lines = sub.read_text().splitlines()
    assert lines[0].startswith("cycle,z [mm],x [mm],swt [MPa]")
    assert len(lines) - 1 == res.fields["cycle"].size * res.subsurface["z"].size * res.x.size


def test_a_sweep_over_stroke_draws_the_life_with_wear_and_without(tmp_path):
    """Two strokes, each with wear and without: the figure's two curves hold the points' crack cycles (or, where
    none started, their last cycle as a lower bound)."""
    from fretsim.plotting import fatigue_life_sweep
    from fretsim.results import read_sweep_table
    from fretsim.sweep import load_sweep, run_sweep
    sweep_file = tmp_path / "s.yaml"
    sweep_file.write_text(f"base: {TI}\nset: [loading.cycles=20000, grid.error_estimate=none]\nmode: points\npoints:\n"
                          "  - {loading.stroke: 5 um}\n  - {loading.stroke: 10 um}\n"
                          "  - {loading.stroke: 5 um, materials.moving.wear_coefficient: 0 1/MPa, "
                          "materials.stationary.wear_coefficient: 0 1/MPa}\n"
                          "  - {loading.stroke: 10 um, materials.moving.wear_coefficient: 0 1/MPa, "
                          "materials.stationary.wear_coefficient: 0 1/MPa}\n")
    run_sweep(load_sweep(sweep_file), tmp_path / "out")
    table = read_sweep_table(tmp_path / "out")
    fig = fatigue_life_sweep(table)
    drawn = {line.get_label(): list(zip(line.get_xdata(), line.get_ydata())) for line in fig.axes[0].get_lines()}
    for row in table.rows:
        life = float(row["cycles_to_crack_initiation"])
        worn = not row.get("materials.stationary.wear_coefficient")
        label = ("with wear" if worn else "without wear (k = 0)") + ("" if math.isfinite(life) else
                                                                     ": no crack by the run's end")
        stroke = float(row["loading.stroke"].split()[0])
        assert (stroke, life if math.isfinite(life) else float(row["cycles"])) in drawn[label]


def test_the_states_error_is_nil_for_a_rate_the_trapezoid_integrates_exactly_and_not_for_one_it_does_not():
    """A damage rate linear in the cycles: Miner's trapezoid is exact over any states, so leaving every other one
    out changes nothing (1e-12).  A rate growing as N²: the sums differ, and the error said is their difference."""
    linear, square = Miner(), Miner()
    for n in range(0, 5001, 500):
        linear.add(n, _state(1.0 / (1e-5 + 1e-8 * n)))
        square.add(n, _state(1.0 / (1e-5 + 1e-11 * n * n)))
    assert linear.crack is None and linear.states_error() < 1e-12
    assert square.states_error() > 1e-3


def test_fatigue_changes_no_wear_result():
    """The fatigue states are not stops and a detailed mid-stroke cycle wears as an undetailed one: the wear, the
    steps and the solves are those of the run without fatigue, to round-off."""
    with_f = run(load_case(TI, SHORT)).summary
    without = run(load_case(TI, SHORT + ["materials.stationary.fatigue=null"])).summary
    assert with_f["contact_solves"] == without["contact_solves"]
    for key in ("max_wear_depth_stationary_um", "wear_volume_stationary_mm3", "scar_width_stationary_mm"):
        assert with_f[key] == pytest.approx(without[key], rel=1e-10), key


@pytest.mark.parametrize("yield_strength, said", [("300 MPa", True), ("3000 MPa", False)])
def test_a_fatigue_run_says_where_the_flats_shear_passes_trescas_yield(yield_strength, said):
    """The unworn contact's largest shear (about 0.3 p₀ = 190 MPa below the surface, more at it with μ = 0.8)
    against σ_y/2: 150 MPa is passed, 1500 MPa is not."""
    out = run(load_case(TI, ["loading.cycles=0", "grid.error_estimate=none",
                             f"materials.stationary.yield_strength={yield_strength}"]))
    assert any("Tresca" in n for n in out.notes) == said


def test_the_resolved_stroke_and_mid_stroke_see_the_same_unworn_swt():
    """Unworn, the pressure is the same at every position of a ±5 µm stroke on a 240 µm contact: the two cycle
    models' stresses differ only by how the cycle is cut, which must keep its turning points (an even stride once
    dropped the resolved up-stroke's end and put its life 37 % long).  Within 1 %."""
    swt = [run(load_case(TI, ["loading.cycles=0", "grid.error_estimate=none", f"model.stroke={m}"])).summary
           ["swt_max_MPa"] for m in ("mid_stroke", "resolved")]
    assert swt[1] == pytest.approx(swt[0], rel=0.01)


BLOCKS = ["loading.normal_load=null", "loading.stroke=null", "loading.cycles=null", "grid.error_estimate=none"]


def test_a_heavy_block_between_fatigue_states_counts_its_damage():
    """47 000 light cycles, 2 500 heavy, 50 500 light: the heavy block's damage (its SWT five times the light
    blocks') is counted though no fatigue state of the run's spacing falls in it — each block's end and start are
    evaluated, and the sum restarts at each — so it is many times the all-light history's."""
    heavy = ("[{normal_load: 300 N, stroke: 2 um, cycles: 47000}, {normal_load: 1200 N, stroke: 5 um, cycles: "
             "2500}, {normal_load: 300 N, stroke: 2 um, cycles: 50500}]")
    light = "[{normal_load: 300 N, stroke: 2 um, cycles: 100000}]"
    with_heavy = run(load_case(TI, BLOCKS + [f"loading.blocks={heavy}"])).summary
    all_light = run(load_case(TI, BLOCKS + [f"loading.blocks={light}"])).summary
    assert with_heavy["fatigue_damage"] > 20 * all_light["fatigue_damage"]
    assert with_heavy["swt_max_MPa"] > 3 * all_light["swt_max_MPa"]


def test_with_a_wear_limit_and_the_crack_limit_the_first_crossing_is_the_limit_reached():
    """The crack starts at about 8 500 cycles; a wear limit the flat reaches later: the run reports the crack."""
    out = run(load_case(TI, SHORT + ["limits={crack_initiation: true, max_wear_depth_stationary: 0.16 um}"])).summary
    assert out["limit_reached"] == "crack_initiation" and out["damage_mode"] == "cracking"
    assert out["cycles_to_limit"] == out["cycles_to_crack_initiation"]


@pytest.mark.parametrize("nx", [1, 5, 6, 11, 20, 40])
@pytest.mark.parametrize("width", [2, 7, 8, 9, 16, 33, 64, 70])
@pytest.mark.parametrize("sign", [1, -1])
def test_the_running_extremes_along_x_equal_a_loop_for_windows_longer_than_the_grid(nx, width, sign):
    """_run_along (the 5° pass's windows, laid (x, row, plane)) against the extremes taken one by one, the positions
    beyond the grid left out: also where the window is longer than the grid (a long slide on a short field)."""
    import fretsim.fatigue.swt as swt
    rng = np.random.default_rng(nx * 100 + width)
    src = rng.normal(size=(nx, 3, 4))
    for pick in (np.maximum, np.minimum):
        out, work = np.full_like(src, np.nan), [np.full_like(src, np.nan), np.full_like(src, np.nan)]
        got = swt._run_along(src, sign * width, pick, out, work)
        want = np.array([pick.reduce(src[[j for j in range(x, x + sign * width, sign) if 0 <= j < nx]], axis=0)
                         for x in range(nx)])
        assert np.array_equal(got, want)


def test_a_slide_longer_than_the_grid_counts_as_one_to_the_grids_end():
    """A slide over more elements than the field has columns (2D: m ≥ nx − 1; 3D: |m| ≥ nx) passes every position
    to the grid's end, held there: the same critical planes as the slide cut to the grid (it raised in the 5° pass's
    running extremes instead)."""
    from fretsim.fatigue.swt import swt_search_3d
    rng = np.random.default_rng(4)
    hist = tuple(rng.normal(scale=100.0, size=(4, 3, 6)) for _ in range(3))
    for m in (8, 15, 40):
        for sign in (1, -1):
            long = swt_search(hist, 115000.0, 0.3, {1: sign * m, 3: -sign * m})
            cut = swt_search(hist, 115000.0, 0.3, {1: sign * 5, 3: -sign * 5})
            assert np.allclose(long.swt, cut.swt, rtol=1e-12, atol=0) and np.array_equal(long.angle, cut.angle)
    s = rng.normal(scale=100.0, size=(6, 3, 2, 9))
    for m in (16, 25):
        long = swt_search_3d(s, 200000.0, 0.3, slides={1: m, 2: -m})
        cut = swt_search_3d(s, 200000.0, 0.3, slides={1: 9, 2: -9})
        assert np.allclose(long.swt, cut.swt, rtol=1e-12, atol=0) and np.allclose(long.normal, cut.normal, atol=1e-12)


def test_lives_of_infinite_and_undefined_values_are_the_scalar_ones_without_a_warning():
    """inf (above any curve: a quarter of a reversal), nan, 0, negative: as :meth:`Basquin.life`, and no
    RuntimeWarning (Newton's step on an infinite target was inf − inf)."""
    import warnings
    curve = Basquin(2030.0, -0.104, 0.841, -0.688, 115000.0, endurance_limit=0.5)
    swt = np.array([np.inf, np.nan, -np.inf, 0.0, -3.0, 1e300, 3.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lives = curve.lives(swt)
    want = [curve.life(float(s)) for s in swt]
    assert [v for v in lives[:-1]] == want[:-1] and lives[-1] == pytest.approx(want[-1], rel=1e-10)


@pytest.mark.parametrize("stroke", ["3 um", "25 um"])  # partial slip (δ_t 5.5 µm) and gross slip
def test_a_recorded_state_at_fixed_pressure_takes_its_fatigue_states_loop_and_their_fields(stroke):
    """At fixed pressure (mid-stroke) the elastic sides are Masing's branches between their ends, and the fatigue
    states take a side in one increment (FATIGUE_SIDE_INCREMENTS).  A recorded state's cycle cuts them in 12 for
    the loop's shape; its fatigue fields must be its fatigue states' — the same SWT field from the recorded
    cycle as from the fatigue state's cycle, to the tangential solver's tolerance (the side's inner states,
    evaluated, moved it by up to 1.3e-5 of its peak, which this would catch) — and the damage points' lives the
    same."""
    from fretsim.cycle.result import TRACTIONS
    from fretsim.fatigue.damage import evaluate
    from fretsim.plan import prepare
    from fretsim.simulate import _Loop
    setup = prepare(load_case(TI, ["loading.cycles=0", "grid.error_estimate=none", f"loading.stroke={stroke}"]))[0]
    loop = _Loop(setup, (), None)
    spec, g = setup.fatigue, setup.grid
    fields = []
    for detail in (True, TRACTIONS):
        cyc = loop.cycle_at(0, None, detail=detail)
        assert np.array_equal(cyc.tractions[0][0], cyc.tractions[0][-1])  # (the pressure fixed round the loop)
        fields.append(evaluate(spec, g.x, g.dx, spec.curve.youngs_modulus, cyc, full=True))
    recorded, state = fields
    assert len(loop.cycle_at(0, None, detail=True).tractions[0]) > 2 * len(loop.cycle_at(0, None, detail=TRACTIONS)
                                                                             .tractions[0]) - 2  # (else: no test)
    assert np.abs(recorded.swt - state.swt).max() < 1e-8 * state.swt.max()
    np.testing.assert_allclose(recorded.life, state.life, rtol=1e-8)


def test_miners_sum_at_the_end_carries_an_estimate_and_a_note_where_it_exceeds_the_accuracy():
    """A run without a crack reports Miner's sum at its end (fatigue_damage): its estimated error is the companion
    grid's part (read as a peak's, √h: grid_error.fatigue_estimates) plus the depths' stepping part plus the states'
    spacing part; above model.accuracy the run says so, part by part (a gross-slip Ti run at 25 µm: 14 % from the
    states' spacing alone, which the summary showed with no word of it)."""
    from fretsim.cli import _body_fatigue
    from fretsim.grid_error import SQRT_H, fatigue_estimates, fatigue_over
    fine = {"fatigue_damage": 0.103, "fatigue_states_error": 0.142, "error_estimate_depth": 0.003,
            "cycles_to_crack_initiation": float("nan"), "swt_max_MPa": 6.19}
    coarse = {"fatigue_damage": 0.092, "cycles_to_crack_initiation": float("nan"), "swt_max_MPa": 6.0}
    est = fatigue_estimates(fine, coarse)
    assert est["estimated_error_fatigue_damage"] == pytest.approx(SQRT_H * 0.011 / 0.103 + 0.003 + 0.142, rel=1e-12)
    assert math.isnan(est["estimated_error_cycles_to_crack"])
    [note] = fatigue_over(fine, coarse, est, 0.01)
    assert "Miner's sum at the end 40.3%" in note and "spacing 14.2%" in note and "grid's 25.8%" in note
    assert fatigue_over(fine, coarse, est, 0.5) == []
    assert math.isnan(fatigue_estimates({**fine, "fatigue_damage": 0.0}, coarse)["estimated_error_fatigue_damage"])
    cracked = {**fine, "cycles_to_crack_initiation": 8412.0}
    est = fatigue_estimates(cracked, {**coarse, "cycles_to_crack_initiation": 8800.0})
    [note] = fatigue_over(cracked, {**coarse, "cycles_to_crack_initiation": 8800.0}, est, 0.01)
    assert note.startswith("the estimated error of the crack cycle")
    # a crack on the run's grid and none on the companion's: the crack cycle's error is not known, and said
    [note] = fatigue_over(cracked, coarse, fatigue_estimates(cracked, coarse), 0.01)
    assert note.startswith("the crack cycle's error was not estimated") and "no crack" in note
    assert "not measured" in fatigue_over({**fine, "fatigue_states_error": float("nan")}, coarse, {
        "estimated_error_fatigue_damage": 0.2}, 0.01)[0]
    summary = {**fine, "estimated_error_fatigue_damage": 0.252, "swt_location_x_mm": 0.095, "swt_depth_um": 0.28}
    spec = SimpleNamespace(critical_distance=0.025)
    assert "reached 0.103 of 1, ± 2.5e-01 relative" in _body_fatigue(summary, "stationary", spec, False)
