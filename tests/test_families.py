"""The families are the path: every fretting-cycle member × wear law × stepping scheme that combine runs through
the registries, and each run is held to an invariant, a bound and the per-cycle model; a member registered by a
test alone runs end to end.

The case: McColl's 185 N cylinder in 2D at μ = 0.9 on the paper's grid, a few hundred cycles — gross slip, where
every member has something exact to be checked against:
* a member that assumes gross slip (``uniform``, at mid-stroke or resolved with rigid bodies) wears each body by
  k·P·4δ·N exactly, k the law's coefficient of p·|ds| where every point slides (Archard's k, α·μ);
* the incremental cycle conserves k·W, W = Σ amount·A its own work, which no point can make larger than the rig's
  travel allows: W ≤ P·4δ·N (Archard) or μ·P·4δ·N (energy);
* every scheme follows the per-cycle model (jumping.linear 1) of the same member and law.
The volumes are recomputed here from the depth fields the run returns, not read from the loop's own check.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Optional

import numpy as np
import pytest

from fretsim.api import CaseError, load_case, run
from fretsim.cycle import CYCLES, STROKES
from fretsim.stepping import SCHEMES
from fretsim.wear_laws import WEAR_LAWS

CASE = Path(__file__).resolve().parent.parent / "cases" / "mccoll_185N.yaml"
MU, LOAD, STROKE, LENGTH = 0.9, 185.0, 0.025, 10.0  # the case's μ (set below), N, mm, mm
K = {"moving": 2e-8, "stationary": 3e-8}  # mccoll_185N's Archard coefficients, 1/MPa
ALPHA = {"moving": 2.2e-8, "stationary": 3.3e-8}  # energy coefficients for the energy law, mm³/(N·mm)
LAWS = {"archard": [],
        "energy": ["model.wear_law=energy", "materials.moving.energy_wear_coefficient=2.2e-5 mm3/J",
                   "materials.stationary.energy_wear_coefficient=3.3e-5 mm3/J"]}
ROUND_OFF = 1e-9  # the worn volume against its invariant: both are sums of the same increments
# the schemes against the per-cycle model, depths.  The implicit schemes hold their own estimate of the depth error
# to DEPTH_SHARE (7 %) of jumping.tolerance (1 %), but on a run this short it under-covers: measured 0.08-0.28 %
# here (BDF2, backward Euler), so 0.5 %; the explicit ones at half the stability limit were measured within 0.8 %
# (their error is ½(ΔN − 1)·ΔN·ṙ, not controlled), so 1 %.  A resolved stroke's depths move with the step by a
# few per cent (its kinks: README, "the resolved stroke"; measured up to 1.6 % at 200 cycles), so 3 %.
TO_PER_CYCLE = {(False, True): 0.005, (False, False): 0.01, (True, True): 0.03, (True, False): 0.03}


def _base(cycles: int) -> list:
    return ["model.dimension=2d", f"loading.cycles={cycles}", "grid.rule=paper", "grid.error_estimate=none",
            f"loading.friction_coefficient={MU}", f"output.snapshots=[{cycles}]"]


@lru_cache(maxsize=None)
def _run(slip: str, stroke: str, law: str, scheme: Optional[str], cycles: int):
    """One run of the combination (scheme None: the per-cycle model, jumping.linear 1)."""
    stepping = ["jumping.scheme=linear", "jumping.linear=1"] if scheme is None else [f"jumping.scheme={scheme}"]
    out = run(load_case(CASE, _base(cycles) + LAWS[law] + [f"model.slip={slip}", f"model.stroke={stroke}"] + stepping))
    assert out.status == "complete", out.message
    return out


def _volumes(out) -> dict:
    """Each body's worn volume from its depth field (mm³): Σh·dx·L."""
    g = out.setup.grid
    return {"moving": float(out.last.wear_moving.sum()) * g.dx * LENGTH,
            "stationary": float(out.last.wear_stationary.sum()) * g.dx * LENGTH}


def _coefficient(law: str, body: str, gross_slip: bool) -> float:
    """The law's coefficient for a body: of p·|ds| where every point slides (gross_slip), else of its amount."""
    if law == "archard":
        return K[body]
    return ALPHA[body] * MU if gross_slip else ALPHA[body]


@dataclass(frozen=True)
class Combo:
    slip: str
    stroke: str
    law: str
    scheme: str

    @property
    def id(self) -> str:
        return f"{self.slip}-{self.stroke}-{self.law}-{self.scheme}"


COMBOS = [Combo(*c) for c in itertools.product(CYCLES, STROKES, WEAR_LAWS, SCHEMES)]
# the resolved stroke solves the contact at every increment: its per-cycle references take seconds each, so its
# combinations run in the slow suite, one of them (the incremental cycle, BDF2) in the default one
DEFAULT = {c.id for c in COMBOS if not STROKES[c.stroke]} | {"coulomb-resolved-archard-bdf2"}
PARAMS = [pytest.param(c, id=c.id, marks=() if c.id in DEFAULT else pytest.mark.slow) for c in COMBOS]


def test_every_registered_member_is_in_the_matrix():
    # the matrix is built from the registries: a member added to any of them is tested the moment it is added
    assert {c.slip for c in COMBOS} == set(CYCLES) and {c.law for c in COMBOS} == set(WEAR_LAWS)
    assert {c.scheme for c in COMBOS} == set(SCHEMES) and {c.stroke for c in COMBOS} == set(STROKES)
    assert len(COMBOS) == len(CYCLES) * len(STROKES) * len(WEAR_LAWS) * len(SCHEMES)


@pytest.mark.parametrize("combo", PARAMS)
def test_each_member_law_and_scheme_keeps_its_invariant_its_bound_and_the_per_cycle_model(combo):
    resolved = STROKES[combo.stroke]
    cycles = 60 if resolved else 200
    out = _run(combo.slip, combo.stroke, combo.law, combo.scheme, cycles)
    reference = _run(combo.slip, combo.stroke, combo.law, None, cycles)
    volumes = _volumes(out)
    work = float(out.last.work)
    travel = LOAD * 4 * STROKE * cycles  # P·4δ·N, N·mm
    rigid = CYCLES[combo.slip].assumes_gross_slip
    for body in ("moving", "stationary"):
        if rigid:  # every point in contact slides with the rig: the paper's k·P·4δ·N, in closed form
            expected = _coefficient(combo.law, body, True) * travel
        else:  # the incremental cycle's own work, with the law's coefficient of its amount
            expected = _coefficient(combo.law, body, False) * work
        assert volumes[body] == pytest.approx(expected, rel=ROUND_OFF), body
    factor = MU if combo.law == "energy" else 1.0  # the law's amount where every point slides, per p·|ds|
    if rigid:
        # every point in contact slides with the rig, Σp·|du|·A = P·4δ a cycle: the paper's cycle records that as
        # its work whatever the law (its invariant is k·P·4δ·N), the incremental one the law's own amount
        assert work == pytest.approx(travel * (factor if resolved else 1.0), rel=1e-8)
    else:
        # gross slip far above δ_t: every point slides nearly the whole travel (δ_t/δ ≈ 3 % here), and never more
        assert 0.9 * factor * travel < work <= factor * travel * (1 + 1e-6)
        cyc = out.last.cycle_result
        area = out.setup.grid.dx * LENGTH
        # the last cycle's work from what it reports: Archard's Σp·|ds|·A with the pressure held at mid-stroke (the
        # slip summed over the cycle), the energy law's the dissipated energy Σ|q|·|ds|·A
        if not resolved:
            own = cyc.energy if combo.law == "energy" else float((cyc.pressure * cyc.slip_moving).sum()) * area
            assert cyc.work == pytest.approx(own, rel=ROUND_OFF)
    for key in ("max_wear_depth_stationary_um", "max_wear_depth_moving_um"):
        tolerance = TO_PER_CYCLE[resolved, SCHEMES[combo.scheme].implicit]
        assert out.summary[key] == pytest.approx(reference.summary[key], rel=tolerance), key


# --- a member registered by a test alone ----------------------------------------------------------------------------

@dataclass(frozen=True)
class SlipPower:
    """A wear law linear in the slip power: dh = k·|q|·|ds| with Archard's coefficient key (a test's member)."""

    name: str = "slip_power"
    coefficient_key: str = "wear_coefficient"
    needs_friction: bool = True
    invariant: str = "k·Σ|q|·|ds|·A"
    formula: str = "dh = k·|q|·|ds|"
    symbol: str = "k"

    def amount(self, pressure, shear, slip):
        return np.abs(shear) * np.abs(slip)

    def gross_slip_factor(self, friction_coefficient):
        return friction_coefficient


@pytest.fixture
def slip_power(monkeypatch):
    monkeypatch.setitem(WEAR_LAWS, "slip_power", SlipPower())
    return "slip_power"


@pytest.mark.parametrize("slip", ["uniform", "coulomb"])
def test_a_wear_law_registered_by_a_test_runs_end_to_end(slip_power, slip, tmp_path):
    """One registry line: the case reader accepts the name, the planner and the members use the law, the file
    records it; uniform slip wears k·μ·P·4δ·N (not Archard's k·P·4δ·N), the incremental cycle k·W."""
    cycles = 200
    out = run(load_case(CASE, _base(cycles) + [f"model.wear_law={slip_power}", f"model.slip={slip}"]),
              tmp_path / "r.h5")
    assert out.status == "complete", out.message
    assert out.case.wear_law == slip_power and out.setup.cycle.invariant == (
        "k·P·4δ·N" if slip == "uniform" else SlipPower.invariant)
    travel = LOAD * 4 * STROKE * cycles
    work = float(out.last.work)
    for body, volume in _volumes(out).items():
        expected = K[body] * (MU * travel if slip == "uniform" else work)
        assert volume == pytest.approx(expected, rel=ROUND_OFF), body
    if slip == "coulomb":
        assert 0.9 * MU * travel < work <= MU * travel * (1 + 1e-6)  # |q| = μp where it slides
    from fretsim.results import read_results
    assert read_results(tmp_path / "r.h5").inputs["wear_law"][0] == slip_power


def test_a_name_not_in_a_registry_is_refused_with_the_nearest_member(slip_power):
    with pytest.raises(CaseError) as err:
        load_case(CASE, ["model.wear_law=slip_powr"])
    assert "did you mean 'slip_power'" in str(err.value)
    with pytest.raises(CaseError) as err:
        load_case(CASE, ["model.slip=colomb", "loading.friction_coefficient=0.9"])
    assert "did you mean 'coulomb'" in str(err.value) and "auto, uniform, coulomb" in str(err.value)
    with pytest.raises(CaseError) as err:
        load_case(CASE, ["jumping.scheme=bdf3"])
    assert "did you mean 'bdf2'" in str(err.value)
    with pytest.raises(CaseError) as err:  # the law's own needs: its coefficient and a friction coefficient
        load_case(CASE, [f"model.wear_law={slip_power}"])
    assert "loading.friction_coefficient: missing; model.wear_law slip_power (dh = k·|q|·|ds|) needs it" in str(err.value)
