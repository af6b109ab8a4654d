"""PeelParams validation and the peel-force module (fvV, folds, branch inverses)."""

import dataclasses
import math
import re

import numpy as np
import pytest

from peelapprox import (
    PeelParams,
    branch_inverse,
    branch_structure,
    fixed_point,
    peel_force,
    peel_force_derivative,
)


@pytest.mark.parametrize("field,value", [("V", 0), ("V", -1), ("I", float("nan")), ("k", float("inf")), ("R", 0.0)])
def test_params_reject_nonpositive_or_nonfinite(field, value):
    """Every field must be finite and inside its range (PARAM_RANGES); the message names the field and the
    range."""
    from peelapprox import PARAM_RANGES
    from peelapprox.validate import interval

    kw = dict(V=1.0, I=1e-5)
    kw[field] = value
    rng = re.escape(interval(*PARAM_RANGES[field]))
    with pytest.raises(ValueError, match=rf"{field} must be finite and in {rng}"):
        PeelParams(**kw)


def test_params_l_must_exceed_R():
    """l <= R is not a geometry (the tape would start inside the roller)."""
    with pytest.raises(ValueError, match="l must be greater than R"):
        PeelParams(V=1, I=1e-5, R=0.5, l=0.5)


def test_params_are_frozen():
    p = PeelParams(V=1, I=1e-5)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.V = 2.0


def test_peel_force_matches_formula_by_hand():
    """fvV evaluated term by term in plain Python at v=0.3, V=2 (tolerance: a few ulp of ~300 N)."""
    v, V = 0.3, 2.0
    ref = (400 * v**0.35 + 110 * v**0.15 + 130 * math.exp(v / 11) - 2 * V**1.5
           - (415 - 45 * V**0.4 - 0.35 * V**2.15) * v**0.5)
    assert peel_force(v, V) == pytest.approx(ref, rel=1e-14)


def test_derivatives_match_finite_differences():
    """f' and f'' against 4th-order central differences (h=1e-4 v: truncation ~1e-12 relative)."""
    V = 1.0
    for v in (2e-3, 0.05, 0.5, 3.0, 12.0):
        h = 1e-4 * v
        fd1 = (-peel_force(v + 2 * h, V) + 8 * peel_force(v + h, V) - 8 * peel_force(v - h, V)
               + peel_force(v - 2 * h, V)) / (12 * h)
        assert peel_force_derivative(v, V, 1) == pytest.approx(fd1, rel=1e-7, abs=1e-7)
        d1 = lambda x: peel_force_derivative(x, V, 1)  # noqa: E731
        fd2 = (-d1(v + 2 * h) + 8 * d1(v + h) - 8 * d1(v - h) + d1(v - 2 * h)) / (12 * h)
        assert peel_force_derivative(v, V, 2) == pytest.approx(fd2, rel=1e-6, abs=1e-6)


def test_peel_force_rejects_bad_v():
    with pytest.raises(ValueError, match="v must be finite and in"):
        peel_force([0.1, 0.0], 1.0)


def test_folds_V1_against_independent_scan():
    """Folds for V=1 by an independent dense log-grid scan of f' (grid accuracy ~1e-5 relative),
    and the paper's reading f_max ~ 284-285.6, f_min ~ 200 (Sec. V, Case I)."""
    bs = branch_structure(1.0)
    v = np.logspace(-3, 2, 2_000_001)
    fp = peel_force_derivative(v, 1.0, 1)
    idx = np.nonzero(np.diff(np.sign(fp)))[0]
    assert len(idx) == 2
    assert bs.v_max == pytest.approx(v[idx[0]], rel=1e-5)
    assert bs.v_min == pytest.approx(v[idx[1]], rel=1e-5)
    assert peel_force_derivative(bs.v_max, 1.0, 1) == pytest.approx(0.0, abs=1e-9)
    assert peel_force_derivative(bs.v_min, 1.0, 1) == pytest.approx(0.0, abs=1e-9)
    assert bs.f_max == pytest.approx(285.6358, abs=1e-3)
    assert bs.f_min == pytest.approx(199.4276, abs=1e-3)


def test_landing_velocities_V1():
    """The jump lands on CD where f = f_max (paper: v_in = 15.54) and on AB where f = f_min
    (~1.888e-3, i.e. the paper's '0.0188' is off by a factor 10 -- docs/paper-notes.md)."""
    bs = branch_structure(1.0)
    assert bs.v_land_cd == pytest.approx(15.54, abs=0.005)
    assert bs.v_land_ab == pytest.approx(1.8884e-3, rel=1e-4)
    assert peel_force(bs.v_land_ab, 1.0) == pytest.approx(bs.f_min, rel=1e-14)


def test_no_folds_outside_window():
    """For V >= ~5.4 f is increasing: no stick-slip window; CD does not exist."""
    bs = branch_structure(6.0)
    assert not bs.has_folds
    with pytest.raises(ValueError, match="branch 'CD' does not exist"):
        branch_inverse(400.0, 6.0, "CD")


def test_fixed_point_stability_is_sign_of_fprime():
    """Hopf criterion of Sec. II: stable iff f'(V, V) > 0 (unstable at V=1, stable at V=5)."""
    assert not fixed_point(1.0).stable
    assert fixed_point(5.0).stable
    assert fixed_point(1.0).F == pytest.approx(peel_force(1.0, 1.0))


@pytest.mark.parametrize("branch,G", [("AB", 129.9), ("AB", 200.0), ("AB", 285.6), ("CD", 199.5), ("CD", 400.0)])
def test_branch_inverse_round_trip(branch, G):
    """f(branch_inverse(G)) == G to ~4 ulp, including v << 1 (G near f(0+) gives v ~ 1e-30)."""
    v = branch_inverse(G, 1.0, branch)
    assert peel_force(v, 1.0) == pytest.approx(G, rel=1e-13)
    bs = branch_structure(1.0)
    assert (v <= bs.v_max) if branch == "AB" else (v >= bs.v_min)


def test_branch_inverse_out_of_range_names_range():
    with pytest.raises(ValueError, match="no root on branch AB"):
        branch_inverse(290.0, 1.0, "AB")
    with pytest.raises(ValueError, match="no root on branch CD"):
        branch_inverse(150.0, 1.0, "CD")
