"""The variants' stress grid (no NaN or hang over a stress grid in (m, V, I) and (M, I)),
comparisons.stress.variants: a fast subset in the default tier, the whole grid (144 points) under ``-m slow``.

Hypothesis: every run ends in a result, a documented ModelBreakdown or a SolverBudgetExceeded (``max_wall``
bounds the stiffest ones), with finite numbers everywhere (result, jumps, V_p, the exception's time and state).
The known findings (the solver giving up at m = 1e-12 kg, SolverFailure) are listed in
:data:`KNOWN_SOLVER_FAILURES` and docs/robustness.md; any other non-allowed ending fails."""

from __future__ import annotations

import math

import pytest

from comparisons.stress.variants import (
    LOAD_MASSES,
    TAPE_I,
    TAPE_MASSES,
    TAPE_V,
    VariantPoint,
    is_allowed,
    is_bug,
    load_levels,
    run_variant_point,
    run_variant_points,
    variant_grid,
)

#: (group, V, I, tape_mass, load_mass, where) of the grid points where the solver stops with a SolverFailure
#: instead of a breakdown or a budget (``python -m comparisons.stress.variants --out stress_variants``;
#: docs/robustness.md, "Model variants"): at m = 1e-12 kg (ε_eff ~ 1e-12) LSODA cannot resolve the fast
#: transits at V = 1 m/s; the failure's message says to use the massless model there.  (The arrests under a load
#: that the first run found are ModelBreakdown("arrest") since the driver's V_ARREST.)
KNOWN_SOLVER_FAILURES: set[tuple] = {
    ("tape", 1.0, 1e-06, 1e-12, None, ""),
    ("tape", 1.0, 0.0001, 1e-12, None, ""),
    ("tape", 1.0, 0.01, 1e-12, None, ""),
}
#: The signature of that finding (a point that hit max_wall on a loaded machine may fail on a faster one).
KNOWN_MESSAGES = ("at so small a tape mass the model is the massless one",)


def _key(r: dict) -> tuple:
    return (r["group"], r["V"], r["I"], r["tape_mass"], r["load_mass"], r["where"])


def _check(rec: dict) -> None:
    assert not is_bug(rec["outcome"]), rec
    known = rec["outcome"] == "solver_failure" and (_key(rec) in KNOWN_SOLVER_FAILURES
                                                    or any(m in rec["message"] for m in KNOWN_MESSAGES))
    assert is_allowed(rec["outcome"]) or known, rec
    assert not rec["nonfinite"]
    if rec["exception"]:
        assert math.isfinite(rec["t_reached"]) and "nan" not in rec["message"].lower().split()


def test_grid_is_the_issues_grid():
    """54 tape-mass points (m × V × I, docs/robustness.md) and 90 load points (M × I × 3 loads × 2 masses)."""
    pts = variant_grid()
    tape = [p for p in pts if p.group == "tape"]
    load = [p for p in pts if p.group == "load"]
    assert {(p.tape_mass, p.V, p.I) for p in tape} == {(m, V, I) for m in TAPE_MASSES for V in TAPE_V
                                                       for I in TAPE_I}
    assert TAPE_MASSES == (1e-12, 1e-8, 1e-5, 1e-3, 1e-1, 10.0) and TAPE_V == (0.1, 1.0, 4.0)
    assert TAPE_I == (1e-6, 1e-4, 1e-2) and LOAD_MASSES == (1e-6, 1e-3, 1.0, 1e3, 1e6)
    assert len(tape) == 54 and len(load) == 90
    assert {p.tape_mass for p in load} == {None, 1e-4} and {p.where for p in load} == {"below", "inside", "above"}


def test_load_levels_straddle_the_fold_window():
    """below < f_min < inside < f_max < above at V = 1 (f_min = 199.4, f_max = 285.7 N, the paper's folds)."""
    from peelapprox import branch_structure

    bs = branch_structure(1.0)
    lv = load_levels(1.0)
    assert lv["below"] < bs.f_min < lv["inside"] < bs.f_max < lv["above"]
    assert 199 < bs.f_min < 200 and 285 < bs.f_max < 286


@pytest.mark.parametrize("point", [
    VariantPoint("tape", 4.0, 1e-4, tape_mass=1e-12, t_end=0.05, max_wall=1.0),     # the stiffest
    VariantPoint("tape", 1.0, 1e-4, tape_mass=10.0, t_end=0.01, max_wall=5.0),      # a 10 kg ribbon
    VariantPoint("load", 1.0, 1e-4, loading="load", load_mass=1e6, load=428.5, where="above", t_end=0.005,
                 max_wall=5.0),                                                      # the heaviest, above f_max
    VariantPoint("load", 1.0, 1e-4, tape_mass=1e-4, loading="load", load_mass=1e-6, load=242.5, where="inside",
                 t_end=0.05, max_wall=1.0),                                          # the lightest, m > 0
    VariantPoint("load", 1.0, 1e-4, loading="load", load_mass=1e-6, load=99.71, where="below", t_end=0.05,
                 max_wall=2.0),                                                      # the front arrests
], ids=["m=1e-12,V=4", "m=10", "M=1e6,above", "M=1e-6,m=1e-4,inside", "M=1e-6,below"])
def test_fast_subset_ends_in_an_allowed_outcome(point):
    """The grid's corners, in this process with a small max_wall: an allowed ending (or a known finding), never
    NaN; a run that cannot finish within max_wall ends in budget:max_wall (not a hang)."""
    rec = run_variant_point(point)
    _check(rec)
    if point.tape_mass == 1e-12:  # the stiffest: LSODA reaches t_end in ~0.5 s; max_wall bounds a slow machine
        assert rec["outcome"] in ("ok", "budget:max_wall")
    if point.where == "below":  # a load below the folds: F(1 + sin α) falls to f(0+), the front stops
        assert rec["outcome"] == "breakdown:arrest"


@pytest.mark.slow
def test_whole_variant_grid_no_nan_no_hang():
    """All 144 points in the stress worker (timeout 60 s: past max_wall = 5 s, a hang): no bug, every ending
    allowed or a known solver failure (docs/robustness.md records the counts)."""
    recs = run_variant_points(variant_grid(), timeout=60.0, progress=False)
    assert len(recs) == 144
    for r in recs:
        _check(r)
