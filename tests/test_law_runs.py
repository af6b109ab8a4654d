"""Runs with a peel-force law other than the paper's through ``PeelParams.force``: the cubic
``PeelForce.cubic(a, b, c, d)`` in ``exact.simulate(method="hybrid")``, end to end.

The independent oracle is numpy's polynomial algebra (``np.polyval``, ``np.roots`` of f' and of ``f - level``):
the solver finds its folds in closed form (``cubic_v_structure``) and evaluates f through the compiled law.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_law_abi import _numpy_folds, _poly, assert_jumps_at_cubic_folds  # numpy's folds of a cubic

import exact
import exact._hybrid_driver as HL
from peelapprox import PeelForce, PeelParams
from peelapprox.kernels import M_A, M_B, N_M, model_block
from peelapprox.validate import params as validate_params

#: Two cubics with two folds whose CD->AB jumps land: the documented example (folds 0.691, 1.809 m/s) and another.
CUBICS = [(150.0, 300.0, 300.0, 80.0), (100.0, 250.0, 280.0, 90.0)]


@pytest.mark.parametrize("coef", CUBICS)
def test_cubic_run_jumps_at_the_cubics_folds(coef):
    """Hypothesis: ``simulate(PeelParams(force=PeelForce.cubic(...)), T)`` runs the cubic's physics: every AB→CD
    jump leaves at the level ``G = F(1 + sin α) = f_max`` and every CD→AB jump at ``f_min`` of the cubic, v at
    its fold before and at its landing root after, all found independently by numpy; and a second cubic compiles
    nothing (the law driver keeps its one signature).  Tolerances: levels 1e-12 relative (the jump is taken at
    v = v_fold with F = f(v_fold)/(1 + c): f at the fold to a few roundings, stationary there), velocities 1e-7
    (``np.roots`` of the double root v_max of f - f_max is only sqrt(eps)-accurate); the stored points satisfy
    CONSTR with f evaluated by ``PeelForce.f`` (numpy, not the compiled law) to 1e-13 relative (roundings)."""
    p = PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic(*coef))
    tr = exact.simulate(p, 1.5, rtol=1e-10)
    assert len(HL.driver(True).signatures) == 1
    assert len(tr.jumps.t) >= 10  # stick-slip at these parameters
    assert_jumps_at_cubic_folds(tr.jumps, coef)
    assert np.abs(tr.constraint_residual(relative=True)).max() <= 1e-13
    assert np.all(np.isfinite(tr.F)) and tr.final_state.F > 0


@pytest.mark.parametrize("coef", CUBICS)
@pytest.mark.parametrize("alpha0", [0.0, 0.05, -0.1])
def test_cubic_initial_state_is_on_the_cubics_ab_branch(coef, alpha0):
    """Hypothesis: the default initial state of a cubic run uses the cubic: ``F0 = 1.01 f(V, V)`` and v0 the
    root of ``f(v0) = F0 (1 + sin α0)`` on AB (below numpy's fold v_max), f by ``np.polyval``.  Tolerances: F0
    1e-14 relative (one product; f by Horner in two arrangements), the level 1e-12 relative (v0 from Brent's
    method in ln v to ~4 ulp; f' v / f <= ~1 on AB)."""
    V = 1.2
    P = _poly(coef)
    s = exact.initial_state(PeelParams(V=V, I=1e-5, force=PeelForce.cubic(*coef)), alpha0=alpha0)
    assert s.F == pytest.approx(1.01 * np.polyval(P, V), rel=1e-14)
    level = s.F * (1.0 + np.sin(alpha0))
    assert s.branch == "AB" and 0.0 < s.v < _numpy_folds(coef)[0]
    assert np.polyval(P, s.v) == pytest.approx(level, rel=1e-12)


def test_cubic_initial_state_explicit_F0_and_branch():
    """Hypothesis: an explicit F0 whose level is above the cubic's f_max has its root on CD (above numpy's
    v_min, ``f(v0) = F0`` to 1e-12 relative: Brent in ln v to ~4 ulp), and asking for AB there is a ValueError
    naming ``branch0='AB'`` with the cubic's range of F0 (not the paper's: f_max of the cubic is 240.45 N,
    of fvV at V = 1.2 about 285 N)."""
    coef = CUBICS[0]
    p = PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic(*coef))
    v_max, f_max, v_min, f_min, _, _ = _numpy_folds(coef)
    s = exact.initial_state(p, F0=260.0)
    assert s.branch == "CD" and s.v > v_min
    assert np.polyval(_poly(coef), s.v) == pytest.approx(260.0, rel=1e-12)
    with pytest.raises(ValueError, match=r"no root on branch0='AB'.*\(150\.0, 240\.45"):
        exact.initial_state(p, F0=260.0, branch0="AB")
    with pytest.raises(ValueError, match=r"below f\(0\+, V\)=150\.0"):
        exact.initial_state(p, F0=149.0)


def test_regularized_cubic_converges_to_the_hybrid_like_eps_two_thirds():
    """Hypothesis: the ε-regularised scheme runs a cubic law through the law-argument field, and its jump times
    approach the hybrid (ε → 0) solution with the fold-passage delay ~ ε^(2/3) (docs/theory.md): over the first
    two jumps at V = 1.2, I = 1e-3 (one through each fold: AB->CD at 0.038 s, CD->AB at 0.086 s) the largest gap
    falls by 10^(2/3) = 4.64 from ε = 1e-5 to 1e-6 (measured 5.6e-5 -> 1.2e-5 s; over three jumps, 0.15 s and
    half as much CPU again, 6.7e-5 -> 1.5e-5).  Tolerance: a ratio in [3.5, 6], room for the next-order ε ln ε
    terms; a field still using fvV would give gaps of order the period (0.05 s), not 1e-5."""
    p = PeelParams(V=1.2, I=1e-3, force=PeelForce.cubic())
    h = exact.simulate(p, 0.1, rtol=1e-11)
    gaps = []
    for eps in (1e-5, 1e-6):
        r = exact.simulate(p, 0.1, method="regularized", eps=eps, rtol=1e-9)
        assert r.jumps.t.size == h.jumps.t.size == 2
        gaps.append(float(np.abs(r.jumps.t - h.jumps.t).max()))
    assert gaps[0] < 2e-4 and 3.5 < gaps[0] / gaps[1] < 6.0


def test_a_cubic_whose_jumps_cannot_land_breaks_down_like_fvV():
    """Hypothesis: a cubic whose CD→AB jumps cannot land (f_min = 40 N <= f(0+) = a = 120 N) runs until the
    orbit reaches the CD fold, then stops with the same ModelBreakdown as the paper's law there ("no_landing",
    its finite time and state: the law is data, the breakdown rule is the model's); the paper-only consumers
    still refuse the cubic (``hybrid_field(law_argument=False)``: the inlined driver has only fvV)."""
    from peelapprox import ModelBreakdown

    p = PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic(a=120, b=200, c=260, d=70))
    with pytest.raises(ModelBreakdown) as e:
        exact.simulate(p, 0.1)
    assert e.value.reason == "no_landing" and 0.0 < e.value.t < 0.1 and e.value.state["branch"] == "CD"
    with pytest.raises(ValueError, match="model_block"):
        exact.hybrid_field(PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic()), law_argument=False)


def test_laws_pass_through_validate_and_model_block():
    """Hypothesis: ``validate.params(..., laws=...)`` accepts exactly the listed laws (every law by default) and
    ``model_block(..., laws)`` likewise (the paper's only by default: the drivers with fvV inlined), the refusal
    naming params.force, the consumer and the laws it runs; for a non-paper law the unused fvV slots b, A hold
    0.0 (exact: packed, not computed)."""
    cub = PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic())
    assert validate_params("params", cub, laws=("paper", "cubic")) is cub
    with pytest.raises(ValueError, match=r"params.force: here runs the laws 'paper', 'cubic' only, not "
                                         r"PeelForce.power_branches"):
        validate_params("params", cub.replace(force=PeelForce.power_branches()), laws=("paper", "cubic"),
                        where="here")
    assert validate_params("params", cub) is cub
    blk = model_block(cub, N_M, ("paper", "cubic"))
    assert blk[M_B] == 0.0 and blk[M_A] == 0.0 and blk[0] == 1.2
    with pytest.raises(ValueError, match="model_block"):
        model_block(cub)


def test_plot_of_a_cubic_run_draws_the_cubic_and_its_folds():
    """Hypothesis: ``plot_trajectory`` of a run with the cubic law draws that law's f(v) and folds, not the
    paper's (a silent wrong picture otherwise): the drawn curve equals ``law.f`` exactly (the same evaluation)
    and the fold markers sit at ``law.folds(V)`` exactly."""
    pytest.importorskip("matplotlib")
    from peelapprox.plotting import plot_trajectory

    law = PeelForce.cubic()
    tr = exact.simulate(PeelParams(V=1.2, I=1e-5, force=law), 0.3)
    fig = plot_trajectory(tr)
    phase = fig.axes[3]
    curve, folds = phase.lines[0], phase.lines[2]
    assert np.array_equal(curve.get_ydata(), law.f(curve.get_xdata(), 1.2))
    fo = law.folds(1.2)
    assert list(folds.get_xdata()) == [fo.v_max, fo.v_min] and list(folds.get_ydata()) == [fo.f_max, fo.f_min]
