"""The reduced return map's compiled returns (peelapprox/_reduced/_reducedmap_kernel.py) against the Python map they
replace
(:meth:`ReturnMap.ret`, one segment driver call per stay): the same numbers bitwise, the same stops."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from peelapprox import PeelForce, PeelParams
from peelapprox._reduced import _reducedmap as RM
from peelapprox._reduced._approximate import APPROX_DEFAULTS, FULL_CHAIN, _rest, _solver_start
from peelapprox.law._compiled import compiled_law

RNG = np.random.default_rng(2035)
POINTS = [(float(V), float(math.exp(lnI))) for V, lnI in
          zip(RNG.uniform(0.5, 4.5, 6), RNG.uniform(math.log(1e-5), math.log(5e-2), 6))]
POINTS.append((0.903, 1.08e-4))  # genalpha + fullvdot breaks down on AB here (v -> 0): the stops compared


def _python(m: RM.ReturnMap, x: np.ndarray, n: int) -> tuple[np.ndarray, list]:
    recs = []
    for _ in range(n):
        x, r = m.ret(x)
        recs.append(r)
    return x, recs


@pytest.mark.parametrize("V, I", POINTS)
@pytest.mark.parametrize("models", [APPROX_DEFAULTS["high"], FULL_CHAIN])
def test_compiled_returns_equal_the_python_map(V, I, models):
    """Hypothesis: from the rest start and the solver's start at seeded random points, 25 returns of the compiled
    loop equal 25 returns of the Python map (section points and every record) bitwise, for the default chain and
    genalpha + fullvdot: the kernel repeats ReturnMap.lean's arithmetic in the same order.  Exact equality: any
    difference would be a different computation; and a step cap of 50 steps per call (many calls) changes
    nothing."""
    p = PeelParams(V=V, I=I)
    law = compiled_law(p.force, p.V)
    m = RM.ReturnMap(p, law, models, 1e-6)
    assert m.compiled
    for start in (_rest(law), _solver_start(p, law)):
        try:
            x0 = m.enter(start)
        except RM.MapStop:
            continue  # the entry segment itself breaks down: nothing of the loop to compare
        m.returns = 0
        try:
            xp, rp = _python(m, x0.copy(), 25)
        except RM.MapStop as stop:  # a breakdown: the compiled loop stops at the same return, branch and state
            m.returns = 0
            with pytest.raises(RM.MapStop) as got:
                m.run(x0.copy(), 25)
            assert (got.value.returns, got.value.plan.branch, int(got.value.run.code), got.value.run.t_max) == \
                (stop.returns, stop.plan.branch, int(stop.run.code), stop.run.t_max)
            assert np.array_equal(got.value.run.y, stop.run.y)
            continue
        xc, rc = m.run(x0.copy(), 25)
        assert np.array_equal(xp, xc) and np.array_equal(np.array(rp), rc)
        cap = RM.STEP_CAP
        try:
            RM.STEP_CAP = 50
            xs, rs = m.run(x0.copy(), 25)
        finally:
            RM.STEP_CAP = cap
        assert np.array_equal(xs, xc) and np.array_equal(rs, rc)


def test_a_spent_deadline_stops_the_compiled_loop():
    """Hypothesis: a deadline already past stops the compiled loop before its first call (MapStop with timeout),
    as it stops the Python map before its first segment."""
    p = PeelParams(V=1.0, I=1e-2)
    law = compiled_law(p.force, p.V)
    m = RM.ReturnMap(p, law, APPROX_DEFAULTS["high"], 1e-6, deadline=time.perf_counter() - 1.0)
    with pytest.raises(RM.MapStop) as got:
        m.run(np.array([0.05, 0.0]), 3)
    assert got.value.timeout


def test_a_law_argument_runs_the_second_copy():
    """Hypothesis: a law that is not the inlined fvV (a cubic family) runs the copy taking the law as an argument,
    with the same numbers as its Python map (bitwise, 10 returns from rest)."""
    p = PeelParams(V=1.0, I=1e-3, force=PeelForce.cubic())
    law = compiled_law(p.force, p.V)
    assert not law.inlined
    m = RM.ReturnMap(p, law, APPROX_DEFAULTS["low"], 1e-6)
    x0 = m.enter(_rest(law))
    xp, rp = _python(m, x0.copy(), 10)
    xc, rc = m.run(x0.copy(), 10)
    assert np.array_equal(xp, xc) and np.array_equal(np.array(rp), rc)


@pytest.mark.parametrize("V, I", POINTS[:3])
def test_memo_and_split_runs_equal_one_run(V, I):
    """Hypothesis: the Newton map's memo (ReturnMap.at) returns what a run would compute, and an orbit's cycles
    read as n returns then 2n more (approximate_attractor's _orbit, the first n from the memo) equal 3n returns
    in one call: a return depends on its section point alone.  Exact equality (the same computation), and the
    memo's copy of the section point is not the caller's (changing one leaves the other)."""
    p = PeelParams(V=V, I=I)
    law = compiled_law(p.force, p.V)
    hi = RM.ReturnMap(p, law, APPROX_DEFAULTS["high"], 1e-6).at(RM.NEWTON_RTOL)
    fresh = RM.ReturnMap(p, law, APPROX_DEFAULTS["high"], RM.NEWTON_RTOL)
    x0 = fresh.enter(_rest(law))
    y_all, r_all = fresh.run(x0.copy(), 9)
    y1, r1 = hi.run(x0.copy(), 3)
    y1[0] += 1.0  # the caller's copy
    y1b, r1b = hi.run(x0.copy(), 3)  # from the memo
    assert len(hi.memo) == 1 and hi.returns == 6
    y2, r2 = hi.run(y1b, 6)
    assert np.array_equal(y2, y_all) and np.array_equal(np.concatenate((r1b, r2)), r_all)
    assert np.array_equal(r1, r1b) and y1[0] == y1b[0] + 1.0
