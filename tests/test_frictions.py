"""What a new user trips on, fixed: each test is one friction a first session met."""

from __future__ import annotations

import numpy as np
import pytest

import exact
from peelapprox import PeelParams


@pytest.fixture(scope="module")
def run():
    return exact.simulate(PeelParams(V=1.0, I=1e-5), 1.0)


def test_jumps_slice_and_mask_give_jumps(run):
    """``tr.jumps[:5]`` and ``tr.jumps[mask]`` are ``Jumps`` holding exactly numpy's selection of every field;
    ``jumps[k]`` stays one ``Jump``; a wrong-length mask and a string index are named errors."""
    j = run.jumps
    head = j[:5]
    assert isinstance(head, exact.Jumps) and len(head) == 5
    assert np.array_equal(head.t, j.t[:5]) and np.array_equal(head.F, j.F[:5])
    up = j[j.from_branch == 0]
    assert np.array_equal(up.t, j.t[j.from_branch == 0]) and set(up.from_branch.tolist()) == {0}
    assert isinstance(j[0], exact.Jump) and j[0].t == float(j.t[0])
    assert np.array_equal(j[[0, 2]].F, j.F[[0, 2]])
    with pytest.raises(IndexError, match="boolean mask"):
        j[np.array([True, False])]
    with pytest.raises(TypeError, match="Jumps indices"):
        j["t"]


def test_unreported_rejections_are_none_not_minus_one():
    """scipy's solvers do not report rejected steps: ``n_rejected`` is None (unknown), not -1; the hybrid
    solver reports its count (an int >= 0)."""
    reg = exact.simulate(PeelParams(V=1.0, I=1e-5), 0.05, method="regularized")
    assert reg.stats.n_rejected is None
    hyb = exact.simulate(PeelParams(V=1.0, I=1e-5), 0.05)
    assert isinstance(hyb.stats.n_rejected, int) and hyb.stats.n_rejected >= 0


def test_no_period_found_says_raise_max_period():
    """A period-3 orbit searched with max_period=2: the message says no period was found up to 2 and to raise
    max_period, not that the map is aperiodic."""
    with pytest.raises(ValueError, match=r"no period up to max_period=2 found.*raise max_period"):
        exact.periodic_orbit(PeelParams(V=1.0, I=1e-5), max_period=2)


def test_compare_rows_repr_is_a_short_summary(run):
    """``compare(run)`` in a REPL shows a summary of a few hundred characters (it printed a 129,504-character
    list): the row count, statuses, reductions and median errors; the rows are still the list's."""
    from comparisons import compare

    rows = compare(run)
    text = repr(rows)
    assert len(text) < 600 and f"{len(rows)} ComparisonRow" in text and "median |dt_rel_error|" in text
    assert isinstance(rows, list) and rows[0].segment == 0 and "<table>" in rows._repr_html_()


def test_periodic_orbit_reports_its_smallest_fold_rate_and_warns_near_a_grazing():
    """The period-8 orbit at V = 1, I = 1e-2 reports its smallest |Gdot| at a fold (1215 N/s, far from grazing:
    no warning); fold rates whose smallest is 2e-7 of their median (as the period-49 orbit at V = 4, I = 1e-2
    passes a fold at ~2e-5 N/s) warn."""
    import warnings

    from exact.orbits._periodic import grazing_warning

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        o = exact.periodic_orbit(PeelParams(V=1.0, I=1e-2))
    assert o.min_fold_rate == pytest.approx(1215.45, rel=1e-3)
    with pytest.warns(RuntimeWarning, match="near a grazing"):
        grazing_warning(np.array([120.0, 2e-5, 300.0, 95.0]), 2)
