"""The case file: contract layout, units, and clear errors that name the YAML path."""
from pathlib import Path

import pytest

from fretsim.case import CaseError, load_case, parse_case

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]

CONTRACT = """
name: mccoll-185N
geometry:  {type: cylinder_on_flat, radius: 6 mm, length: 10 mm}
materials:
  moving:     {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 2.0e-8 1/MPa}
  stationary: {youngs_modulus: 200 GPa, poissons_ratio: 0.3, wear_coefficient: 3.0e-8 1/MPa}
loading:   {normal_load: 185 N, stroke: 25 um, cycles: 18000}   # stroke = amplitude δ
model:     {dimension: 3d}
solver:    {method: cg}
jumping:   {linear: 55}
grid:      {}
output:    {snapshots: [1000, 5000, 10000, 18000]}
"""


def problems_of(text, overrides=None):
    with pytest.raises(CaseError) as info:
        parse_case(text, overrides=overrides)
    return dict(info.value.problems), str(info.value)


def test_the_issue_example_case_parses_into_internal_units():
    c = parse_case(CONTRACT)
    assert (c.geometry.radius, c.geometry.length, c.loading.peak_load, c.loading.peak_stroke, c.loading.cycles) == (6.0, 10.0, 185.0, 0.025, 18000)
    assert c.moving.youngs_modulus == 2.0e5 and c.stationary.wear_coefficient == 3.0e-8
    assert (c.dimension, c.solver, c.linear_jump, c.snapshots) == ("3d", "cg", 55, (1000, 5000, 10000, 18000))


def test_filled_case_round_trips():
    c = parse_case(CONTRACT)
    again = parse_case(c.to_yaml())
    assert again == c


def test_missing_key_is_named():
    probs, _ = problems_of(CONTRACT.replace("radius: 6 mm, ", ""))
    assert "geometry.radius" in probs and "missing" in probs["geometry.radius"]


def test_unknown_key_gets_did_you_mean():
    probs, _ = problems_of(CONTRACT.replace("stroke:", "strok:"))
    assert "did you mean 'stroke'" in probs["loading.strok"]


def test_wrong_unit_dimension_is_caught():
    probs, _ = problems_of(CONTRACT.replace("normal_load: 185 N", "normal_load: 185 mm"))
    assert "is a length, not a force" in probs["loading.normal_load"]


def test_bare_number_for_a_length_is_an_error():
    probs, _ = problems_of(CONTRACT.replace("stroke: 25 um", "stroke: 25"))
    assert "without a unit" in probs["loading.stroke"]


def test_negative_load_is_rejected():
    probs, _ = problems_of(CONTRACT.replace("185 N", "-185 N"))
    assert "positive" in probs["loading.normal_load"]


def test_stroke_larger_than_the_domain_is_rejected():
    probs, _ = problems_of(CONTRACT.replace("grid:      {}", "grid: {domain: [0.5 mm, 10 mm], elements: [81, 27]}")
                           .replace("25 um", "300 um"))
    assert "larger than half the grid" in probs["loading.stroke"]


def test_absurd_magnitudes_are_caught_with_their_unit_named():
    probs, _ = problems_of(CONTRACT, overrides=["geometry.radius=1 km", "loading.stroke=25 mm"])
    assert "plausible range" in probs["geometry.radius"] and "plausible range" in probs["loading.stroke"]


def test_all_problems_are_reported_together():
    probs, text = problems_of(CONTRACT, overrides=["loading.cycles=-1", "model.dimension=4d",
                                                   "solver.method=msn", "materials.moving.poissons_ratio=0.7"])
    assert {"loading.cycles", "model.dimension", "solver.method", "materials.moving.poissons_ratio"} <= set(probs)
    assert "did you mean 'msm'" in probs["solver.method"]
    assert text.count("\n  - ") == len(probs)


def test_yaml_syntax_error_reports_line_and_column():
    _, text = problems_of("name: x\ngeometry: {type: ball_on_flat, radius: [6 mm\n")
    assert "line 3" in text or "line 2" in text
    assert "column" in text


@pytest.mark.parametrize("text, expect", [("", "empty"), ("- a\n- b\n", "mapping"),
                                          ("geometry: [1, 2]\n", "geometry")])
def test_structurally_wrong_files_are_explained(text, expect):
    _, msg = problems_of(text)
    assert expect in msg


def test_ball_in_2d_is_refused():
    text = CONTRACT.replace("type: cylinder_on_flat, radius: 6 mm, length: 10 mm", "type: ball_on_flat, radius: 6 mm")
    probs, _ = problems_of(text.replace("3d", "2d"))
    assert "model.dimension" in probs


def test_numbers_written_without_a_dot_are_accepted():
    assert parse_case(CONTRACT, overrides=["solver.tolerance=1e-6"]).tolerance == 1e-6


def test_missing_file_is_a_case_error(tmp_path):
    with pytest.raises(CaseError, match="does not exist"):
        load_case(tmp_path / "nope.yaml")


@pytest.mark.parametrize("text", ["2e-5 mm3/(N*m)", "2e-5 mm³/(N·m)", "2e-5 mm^3/(N m)", "2e-8 mm3/(N*mm)",
                                  "2e-14 1/Pa", "2e-14 m2/N", "2e-5 mm3/Nm", "2e-5 mm3/N/m", "2e-5 mm3 N-1 m-1",
                                  "2e-5 mm³·N⁻¹·m⁻¹", "2e-8 mm3/N/mm"])
def test_the_specific_wear_rate_tribologists_quote_is_read_in_any_spelling(text):
    """mm³/(N·m) is volume per load and sliding distance in metres: a thousandth of 1/MPa (= mm³/(N·mm))."""
    from fretsim.units import parse_quantity
    assert parse_quantity(text, "wear_coefficient") == pytest.approx(2e-8, rel=1e-12)


@pytest.mark.parametrize("text", ["25 um", "25 µm", "25 μm", "25 micron", "25 microns", "0.025 mm"])
def test_a_micrometre_is_read_as_typed_micro_sign_greek_mu_or_microns(text):
    """µ (the micro sign) and μ (the Greek letter) look alike and keyboards give either."""
    from fretsim.units import parse_quantity
    assert parse_quantity(text, "length") == pytest.approx(0.025, rel=1e-12)


@pytest.mark.parametrize("key, hint", [("model.friction_coefficient=0.9", "loading.friction_coefficient"),
                                       ("model.mu=0.9", "loading.friction_coefficient"),
                                       ("materials.moving.friction_coefficient=0.9", "loading.friction_coefficient"),
                                       ("model.cycles=5", "loading.cycles"),
                                       ("loading.wear_coefficient=2e-8 1/MPa", "materials.moving.wear_coefficient"),
                                       ("materials.moving.k=2e-8 1/MPa", "'wear_coefficient'")])
def test_a_key_in_the_wrong_section_or_by_another_name_is_pointed_to_where_it_lives(key, hint):
    with pytest.raises(CaseError) as err:
        load_case(ROOT / "cases" / "mccoll_185N.yaml", [key])
    assert f"did you mean '{hint}" in str(err.value) or f"did you mean {hint}" in str(err.value), str(err.value)


def test_a_quoted_number_without_a_unit_is_called_that():
    from fretsim.units import UnitError, parse_quantity
    with pytest.raises(UnitError, match="bare number '25'"):
        parse_quantity("25", "length")


def test_a_stroke_written_as_the_figures_print_it_is_its_amplitude():
    from pathlib import Path
    CASES = Path(__file__).resolve().parent.parent / "cases"  # noqa: N806
    a = load_case(CASES / "mccoll_185N.yaml", ["loading.stroke=±25 um"]).loading.peak_stroke
    b = load_case(CASES / "mccoll_185N.yaml", ["loading.stroke=+/-25 um"]).loading.peak_stroke
    assert a == b == load_case(CASES / "mccoll_185N.yaml").loading.peak_stroke


def test_a_plural_subject_takes_have_in_the_problem_count():
    many = [("a", "x"), ("b", "y")]
    assert "the measurements have 2 problems" in str(CaseError("m.csv", many, "measurements"))
    assert "the case has 2 problems" in str(CaseError("c.yaml", many))


def test_a_friction_coefficient_too_small_to_carry_a_traction_is_refused_and_zero_is_not():
    """μ = 1e-300 with model.slip coulomb made `fretsim check` end in a traceback (its shear tractions underflowed
    the tangential solve; found by the slow friction fuzz): a μ between 0 and MIN_FRICTION is refused, naming the
    key; μ = 0 (frictionless) and MIN_FRICTION itself are accepted."""
    from fretsim.case import MIN_FRICTION
    path = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
    with pytest.raises(CaseError, match="loading.friction_coefficient"):
        load_case(path, ["model.dimension=2d", "loading.friction_coefficient=1e-300", "model.slip=coulomb"])
    load_case(path, ["model.dimension=2d", "loading.friction_coefficient=0"])
    load_case(path, ["model.dimension=2d", f"loading.friction_coefficient={MIN_FRICTION}", "model.slip=coulomb"])
    # ... and inside a load history, where each block may give its own (not checked at first)
    single = ("loading.normal_load=null", "loading.stroke=null")  # the blocks carry them
    blocks = ('loading.blocks=[{normal_load: 185 N, stroke: 25 um, cycles: 100, friction_coefficient: 0.9}, '
              '{normal_load: 100 N, stroke: 25 um, cycles: 100, friction_coefficient: %s}]')
    with pytest.raises(CaseError, match=r"loading.blocks\[1\].friction_coefficient"):
        load_case(path, ["model.dimension=2d", "model.slip=coulomb", *single, blocks % "1e-300"])
    load_case(path, ["model.dimension=2d", "model.slip=coulomb", *single, blocks % MIN_FRICTION])
