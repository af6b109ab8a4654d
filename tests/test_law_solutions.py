"""Solutions of the full DAE with a peel-force law given as data: the evidence that a tape's own law is solved right.

Hypotheses: a tabulated curve sampled from an analytic law reproduces that law's jump times within the
interpolation error and converges as the table is refined; a run that leaves a table stops with a
ModelBreakdown naming the law's domain (never an extrapolated answer).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import exact
from peelapprox import ModelBreakdown, PeelForce, PeelParams

CUBIC = PeelForce.cubic()  # f = 150 + 300 v - 300 v^2 + 80 v^3: folds at 0.691 and 1.809 m/s
P = PeelParams(V=1.2, I=1e-3)


def _table(n: int, lo: float = 0.02, hi: float = 10.0) -> PeelForce:
    v = np.exp(np.linspace(math.log(lo), math.log(hi), n))
    return PeelForce.tabulated(v, CUBIC.f(v, 1.0))


def test_tabulated_jump_times_converge_to_the_sampled_law():
    """Hypothesis: the hybrid solution of a table sampled from the cubic (n points log-spaced over
    [0.02, 10] m/s, PCHIP in ln v) has the cubic's 10 jumps in 0.5 s, and the largest jump-time error falls as
    the table is refined.  PCHIP puts the folds on data points (fold position error first order in the spacing,
    fold force second order), so the order is between 1 and 2: measured 1.1e-2, 2.0e-3, 7.6e-4, 2.8e-4 s at
    n = 20, 40, 80, 160 (order 1.4 from 40 to 160).  Tolerances: the error at n = 160 below 5e-4 s (measured
    2.8e-4) and the observed order from 40 to 160 at least 1.0 (measured 1.4); a fold misplaced by a wrong
    interpolant would not converge at all."""
    ref = exact.simulate(P.replace(force=CUBIC), 0.5, rtol=1e-10)
    assert ref.jumps.t.size == 10
    err = {}
    for n in (40, 160):
        tr = exact.simulate(P.replace(force=_table(n)), 0.5, rtol=1e-10)
        assert tr.jumps.t.size == ref.jumps.t.size
        err[n] = float(np.abs(tr.jumps.t - ref.jumps.t).max())
    order = math.log(err[40] / err[160]) / math.log(4.0)
    assert err[160] < 5e-4 and order >= 1.0, (err, order)


def test_a_run_landing_below_a_table_stops_with_law_domain():
    """Hypothesis: a table starting at v = 0.2 m/s, above the cubic's CD→AB landing (0.132 m/s), cannot hold
    that landing: the run stops at the first CD fold (one period in, t ≈ 0.086 s) with ModelBreakdown
    ``reason="law_domain"``, a finite time and state, and a message naming the law's range, never a landing
    extrapolated below the table."""
    with pytest.raises(ModelBreakdown) as e:
        exact.simulate(P.replace(force=_table(80, lo=0.2, hi=5.0)), 0.5)
    err = e.value
    assert err.reason == "law_domain" and 0.0 < err.t < 0.5 and math.isfinite(err.state["v"])
    assert "defined on [0.2, 5] m/s only" in str(err)


def test_a_table_ending_below_the_landing_is_refused_up_front():
    """Hypothesis: a table ending at 2.2 m/s never reaches f_max on its fast branch (the cubic lands at
    2.37 m/s), so no AB→CD jump could land: the run is refused before it starts with a ValueError naming
    params.force and what to do."""
    with pytest.raises(ValueError, match=r"params.force.*never reaches f_max.*extend the table"):
        exact.simulate(P.replace(force=_table(80, hi=2.2)), 0.5)


FVV_TEXT = "400*v**0.35 + 110*v**0.15 + 130*exp(v/11) - 2*V**1.5 - (415 - 45*V**0.4 - 0.35*V**2.15)*v**0.5"


@pytest.mark.parametrize("law", [PeelForce.expression(FVV_TEXT), PeelForce.paper_family()], ids=repr)
def test_fvV_as_a_user_law_reproduces_the_built_in_solution(law):
    """Hypothesis: fvV typed as an expression (compiled from its own generated module) or as the paper family
    (its 14 numbers as data) is the built-in law to rounding, so the hybrid solution at V = 1 m/s, I = 1e-5
    over 0.5 s has the same 12 jumps: jump times to 1e-12 s and F at the jumps to 1e-11 relative (measured
    8e-15 s and 2.6e-13: the law's value differs by a few ulp, which the fold passage amplifies by ~100; a
    wrong coefficient or a missing term moves jumps by > 1e-4 s)."""
    P1 = PeelParams(V=1.0, I=1e-5)
    ref = exact.simulate(P1, 0.5, rtol=1e-10)
    tr = exact.simulate(P1.replace(force=law), 0.5, rtol=1e-10)
    assert ref.jumps.t.size == tr.jumps.t.size == 12
    np.testing.assert_allclose(tr.jumps.t, ref.jumps.t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tr.jumps.F, ref.jumps.F, rtol=1e-11)


@pytest.mark.parametrize("peer", ["diffsol", "cvode", "ida"])
def test_peers_solve_the_same_eps_system_for_a_family_law(peer):
    """Hypothesis: the solver peers integrate the ε-system of the law itself (diffsol: DiffSL printed from the
    cubic's sympy form; SUNDIALS: the compiled field with the law as an argument), so at ε = 1e-6, rtol 1e-9
    their three inflection crossings in 0.15 s equal the package's regularised scheme's to 1e-7 s (measured:
    agreement to the 8 digits printed; independent BDF/Radau error control at rtol 1e-9 on a ~0.05 s period)."""
    pytest.importorskip("pydiffsol" if peer == "diffsol" else "sksundae")
    from comparisons.benchmark.peers import run_peer

    p = P.replace(force=CUBIC)
    ref = exact.simulate(p, 0.15, method="regularized", eps=1e-6, rtol=1e-9)
    res = run_peer(peer, p, 0.15, eps=1e-6, rtol=1e-9)
    assert res.status == "ok" and ref.jumps.t.size == res.jump_t.size == 3
    np.testing.assert_allclose(res.jump_t, ref.jumps.t, rtol=0, atol=1e-7)


def test_a_table_runs_on_sundials_and_is_refused_by_diffsol():
    """Hypothesis: a tabulated law has no closed form, so the diffsol peer (DiffSL source) refuses it with a
    ValueError naming params.force and saying which solvers run tables, while CVODE runs it through the compiled
    field with its three crossings within 5e-4 s of the cubic's (the table's interpolation error at 80 points,
    as in the convergence test above)."""
    pytest.importorskip("sksundae")
    from comparisons.benchmark.peers import run_peer

    p = P.replace(force=_table(80))
    res = run_peer("cvode", p, 0.15, eps=1e-6, rtol=1e-9)
    ref = run_peer("cvode", P.replace(force=CUBIC), 0.15, eps=1e-6, rtol=1e-9)
    np.testing.assert_allclose(res.jump_t, ref.jump_t, rtol=0, atol=5e-4)
    pytest.importorskip("pydiffsol")
    with pytest.raises(ValueError, match=r"params.force.*tabulated.*cannot be written in DiffSL"):
        run_peer("diffsol", p, 0.15, eps=1e-6, rtol=1e-9)
