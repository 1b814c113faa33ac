"""The scar width's reading between element centres: exact where the profile's shape near its edge is the one the
reading assumes, continuous as the last element's depth goes to zero, and never outside the chord's crossing."""
import math

import numpy as np
import pytest

from conftest import chord_width as _chord
from fretsim.measures import scar_width

X = (np.arange(201) - 100) * 0.01  # mm, element centres 10 µm apart


@pytest.mark.parametrize("edge", [0.3, 0.3033, 0.3071, 0.3099])
def test_a_profile_that_falls_linearly_to_its_edge_is_read_at_its_threshold_crossing(edge):
    """The moving body's scar: depth falling linearly to the edge of support, which lies anywhere within an
    element.  The secant of the last two centres finds the crossing of 0.1 % of the peak exactly (to round-off);
    the chord put it up to an element outside."""
    profile = np.maximum(edge - np.abs(X), 0.0)
    exact = 2 * (edge - 1e-3 * edge)
    assert scar_width(profile, X) == pytest.approx(exact, rel=1e-12)
    # the chord: the crossing read between the last centre above (depth b) and the first at zero, x_out
    x_out = X[np.flatnonzero((profile == 0) & (X > 0))[0]]
    b = profile[np.flatnonzero(X == x_out)[0] - 1]
    chord_edge = x_out - 0.01 * 1e-3 * edge / b
    assert _chord(profile, X) == pytest.approx(2 * chord_edge, rel=1e-12)
    assert 2 * chord_edge - exact >= -1e-12  # never inside; outside by most of an element unless the edge is at a
    if 0.001 < edge - 0.3 < 0.008:           # centre (0.3) or next to one (0.3099)
        assert 2 * chord_edge - exact > 0.2 * 0.01


@pytest.mark.parametrize("scale", [0.013, 0.021, 0.034])
def test_a_geometrically_decaying_tail_is_read_at_its_threshold_crossing(scale):
    """The worn flat's tail, fading over several elements: for a depth exp(-|x|/s) the interpolation of the
    logarithm is exact; the chord overshoots (the tail is convex)."""
    profile = np.exp(-np.abs(X) / scale)
    exact = 2 * scale * math.log(1e3)
    assert scar_width(profile, X) == pytest.approx(exact, rel=1e-12)
    assert _chord(profile, X) > exact * (1 + 1e-4)


def test_the_reading_is_continuous_as_the_first_element_below_the_threshold_goes_to_zero():
    """Between a residue and exact zero in the first element outside, the width moves by no more than the residue
    says: no jump between the two formulas."""
    base = np.maximum(0.3033 - np.abs(X), 0.0)
    outside = np.flatnonzero(base == 0)[0] + 0  # the first element past the right edge
    widths = []
    for residue in (0.0, 1e-12, 1e-9, 1e-7, 1e-5, 1e-4, 2e-4):
        p = base.copy()
        p[outside] = residue
        widths.append(scar_width(p, X))
    steps = np.abs(np.diff(widths))
    assert steps.max() < 0.2 * 0.01  # each step of the residue moves the edge by < 0.2 element
    assert widths[1] == pytest.approx(widths[0], abs=1e-9)


def test_the_reading_lies_between_the_last_centre_above_the_threshold_and_the_chords_crossing():
    """On arbitrary decreasing edges (random concave, convex and kinked tails) each crossing stays within that
    interval: the reading never moves a width by more than the chord's own element."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        half = rng.uniform(0.2, 0.6)
        power = rng.uniform(0.3, 3.0)
        profile = np.maximum(half - np.abs(X), 0.0) ** power * (1 + 0.2 * rng.random(X.size))
        profile[np.abs(X) > half] = rng.choice([0.0, 1e-9])
        level = 1e-3 * profile.max()
        above = np.flatnonzero(profile > level)
        inner = X[above[-1]] - X[above[0]]
        w = scar_width(profile, X)
        assert inner - 1e-12 <= w <= _chord(profile, X) + 1e-12
