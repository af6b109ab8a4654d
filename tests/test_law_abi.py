"""The peel-force law as a function argument of the hybrid driver (any law compiled once, passed to the loop).

The paper's law through the ABI must be *the same arithmetic* as the inlined law (bitwise), and a second law
must run through the one compiled law driver without compiling it again, with the physics of that law: its jumps
leave the slow branch at its own fold levels, found here independently with numpy's polynomial roots.
"""

from __future__ import annotations

import numpy as np
import pytest

import exact._hybrid as H
import exact._hybrid_driver as HL
from exact import Budget, Hybrid, SaveAt, State
from peelapprox import PeelForce, PeelParams, branch_structure
from peelapprox.kernels import (
    LAW_FP,
    LAW_FPP,
    LAW_LNV,
    family_kernel,
    paper_coefficients,
    paper_law,
    peel_force_fp_jit,
    peel_force_fpp_jit,
    peel_force_lnv_jit,
)

#: f = 150 + 300 v - 300 v^2 + 80 v^3 [N]: folds at v = (5 -+ sqrt 5)/4 (0.691, 1.809 m/s), f_max 240.45 N,
#: f_min 184.55 N, f(0+) = 150 N: the paper's range of forces, with an N shape of the paper's kind.
COEF = np.array([150.0, 300.0, 300.0, 80.0])


def _poly(coef):
    """numpy's coefficients (highest power first) of a + b v - c v^2 + d v^3."""
    a, b, c, d = coef
    return np.array([d, -c, b, a])


def _give_paper_as_law(monkeypatch) -> None:
    """Route runs of the paper's law through the law driver (``inlined=False``: the law as an argument) by
    substituting ``exact._hybrid_driver.law_for``."""
    from peelapprox.kernels import CompiledLaw, compiled_law

    def law_for(params):
        cl = compiled_law(params.force, params.V)
        return CompiledLaw(cl.force, cl.V, cl.fn, cl.coef, cl.structure, cl.domain, False)

    monkeypatch.setattr(HL, "law_for", law_for)


def test_paper_law_is_the_inlined_law_bitwise():
    """Hypothesis: ``paper_law`` evaluates the generated fvV code unchanged, so every form equals the inlined
    kernels exactly (tolerance 0: the same operations in the same order), at V in {0.3, 1, 4} and v from 1e-60
    to 30 m/s; the pull force and the field through the law equal the inlined ones exactly too."""
    vs = np.concatenate([np.logspace(-60, 1.5, 40), [0.1, 0.5, 2.0]])
    for V in (0.3, 1.0, 4.0):
        c = paper_coefficients(V)
        b, A = c
        for v in vs:
            u = float(np.log(v))
            assert paper_law(u, c, LAW_LNV) == peel_force_lnv_jit(u, b, A)
            f, fp, nan = paper_law(v, c, LAW_FP)
            assert (f, fp) == peel_force_fp_jit(v, b, A) and np.isnan(nan)
            assert paper_law(v, c, LAW_FPP) == peel_force_fpp_jit(v, b, A)
        p = HL.param_vector(PeelParams(V=V, I=1e-5))
        for a, v in ((0.0, 0.1), (0.3, 1e-20), (-0.5, 3.0)):
            assert HL.pull_force_law(a, v, p, paper_law, c) == H.pull_force(a, v, p)
            y = np.array([0.0, a, 10.0, np.log(v)])
            g0, g1 = np.empty(4), np.empty(4)
            H._rhs(y, p, g0)
            HL._rhs_law(y, (p, paper_law, c), g1)
            assert np.array_equal(g0, g1)


def test_paper_law_through_the_law_driver_is_the_default_run_bitwise(monkeypatch):
    """Hypothesis: the paper's law given as a law (``params.force`` of kind "paper": the law driver, an indirect
    call per field evaluation) gives the default run (the driver with the law inlined) bit for bit: every stored
    point, jump and counter of a 0.3 s run at V = 1, I = 1e-5 with 8 jumps, and of a ``t_eval`` run at V = 4,
    I = 1e-2 (tolerance 0: the same operations in the same order)."""
    from exact import simulate

    for V, I, kw in ((1.0, 1e-5, dict(save="steps")), (4.0, 1e-2, dict(t_eval=np.linspace(0.0, 0.05, 101)))):
        a = simulate(PeelParams(V=V, I=I), kw.get("t_eval", [0.3])[-1], **kw)
        with monkeypatch.context() as m:
            _give_paper_as_law(m)
            b = simulate(PeelParams(V=V, I=I), kw.get("t_eval", [0.3])[-1], **kw)
        for name in ("t", "alpha", "omega", "F", "v", "branch"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
        for name in ("t", "F", "alpha", "omega", "v_before", "v_after"):
            assert np.array_equal(getattr(a.jumps, name), getattr(b.jumps, name)), name
        assert (a.stats.n_steps, a.stats.n_rhs, a.stats.n_rejected) == (b.stats.n_steps, b.stats.n_rhs,
                                                                        b.stats.n_rejected)
        assert a.final_state == b.final_state
    assert len(a.jumps.t) >= 1


def test_cubic_law_against_numpy_polynomials():
    """Hypothesis: the three forms of the cubic family's compiled law (generated from its sympy form) are the
    cubic, its derivatives and ``v f'`` as numpy's ``polyval``/``polyder`` give them (an independent evaluation:
    Horner in another arrangement), to 1e-13 relative of the largest term (a few roundings of terms of size
    ~d v^3)."""
    cubic_v_law, pack = family_kernel("cubic")
    coef = pack(1.2, tuple(COEF))
    P = _poly(COEF)
    for v in (1e-6, 0.1, 0.6909, 1.25, 2.0, 7.0):
        scale = np.polyval(np.abs(P), v)
        f, fp, fpp = cubic_v_law(v, coef, LAW_FPP)
        assert abs(f - np.polyval(P, v)) <= 1e-13 * scale
        assert abs(fp - np.polyval(np.polyder(P), v)) <= 1e-13 * scale / min(v, 1.0)
        assert abs(fpp - np.polyval(np.polyder(P, 2), v)) <= 1e-13 * scale / min(v, 1.0) ** 2
        vv, f2, g = cubic_v_law(np.log(v), coef, LAW_LNV)
        assert abs(vv - v) <= 1e-15 * v
        assert abs(f2 - f) <= 1e-13 * scale and abs(g - v * fp) <= 1e-13 * scale
        assert cubic_v_law(v, coef, LAW_FP)[:2] == (f, fp)


def _numpy_folds(coef):
    P = _poly(coef)
    v_max, v_min = np.sort(np.roots(np.polyder(P)).real)
    f_max, f_min = np.polyval(P, v_max), np.polyval(P, v_min)
    land_cd = max(np.roots(P - [0, 0, 0, f_max]).real)
    land_ab = min(r.real for r in np.roots(P - [0, 0, 0, f_min]) if r.real > 0)
    return v_max, f_max, v_min, f_min, land_cd, land_ab


def test_cubic_structure_is_the_numpy_roots():
    """Hypothesis: the branch structure the solvers use for a cubic (folds by Brent's method on f', landings on
    f, breakdown velocity) has the roots numpy finds (the companion-matrix eigenvalues): folds to 1e-13 relative
    (Brent to ~4 ulp in ln v, numpy's simple roots of f' to ~1e-15), landings to 1e-7 (``np.roots`` of the double
    root ``v_max`` of ``f - f_max`` is only sqrt(eps)-accurate), levels to 1e-13 (stationary at the folds); a
    cubic with c² < 3 b d has no fold (f' > 0 throughout)."""
    bs = branch_structure(1.2, force=PeelForce.cubic(*COEF))
    v_max, f_max, v_min, f_min, land_cd, land_ab = _numpy_folds(COEF)
    assert bs.has_folds and bs.f_zero == 150.0
    assert bs.v_max == pytest.approx(v_max, rel=1e-13) and bs.v_min == pytest.approx(v_min, rel=1e-13)
    assert bs.f_max == pytest.approx(f_max, rel=1e-13) and bs.f_min == pytest.approx(f_min, rel=1e-13)
    assert bs.v_land_cd == pytest.approx(land_cd, rel=1e-7) and bs.v_land_ab == pytest.approx(land_ab, rel=1e-7)
    assert 0 < bs.v_breakdown < 1e-9
    assert not branch_structure(1.0, force=PeelForce.cubic(150.0, 300.0, 10.0, 80.0)).has_folds


def test_second_law_runs_in_the_compiled_driver_with_its_own_folds():
    """Hypothesis: a second law goes through the one compiled law driver (its signature list stays one entry and
    it cannot compile: ``driver(True)`` is compiled for ``RUN_SIG`` only), and gives that law's physics: every
    AB→CD jump leaves at the level ``G = F(1 + sin α) = f_max`` and every CD→AB jump at ``f_min`` of the cubic,
    with v at its fold before and at its landing root after, the folds found independently by numpy.  Tolerances: levels
    1e-12 relative (the jump is taken at v = v_fold exactly and F = f(v_fold)/(1 + c), so G is f at the fold to a
    few roundings; f is stationary there, so the closed-form vs numpy v_max differences of ~1e-15 do not show),
    velocities 1e-7 (numpy's root of the double root, as above)."""
    params = PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic(*COEF))
    v0 = 0.5
    s0 = State(0.0, 0.0, 1.2 / 0.1, float(np.polyval(_poly(COEF), v0)), v0, "AB")
    run = HL.driver(True)
    assert len(run.signatures) == 1
    tr = HL.run_hybrid(params, 2.0, s0, Hybrid(rtol=1e-10), SaveAt(jumps_only=True),
                       Budget(max_points=10, max_steps=10**7, max_jumps=10**5), None)
    assert len(run.signatures) == 1
    assert len(tr.jumps.t) >= 20  # stick-slip: ~17 cycles per second at these parameters
    assert_jumps_at_cubic_folds(tr.jumps, COEF)


def assert_jumps_at_cubic_folds(j, coef) -> None:
    """Every AB→CD jump of ``j`` at the level ``F(1 + sin α) = f_max`` of the cubic ``coef`` (1e-12 relative),
    every CD→AB jump at ``f_min``, v at numpy's fold before and landing root after (1e-7 relative); both kinds
    present.  (Shared with tests/test_law_runs.py.)"""
    v_max, f_max, v_min, f_min, land_cd, land_ab = _numpy_folds(coef)
    G = j.F * (1.0 + np.sin(j.alpha))
    up = j.from_branch == 0
    assert up.any() and (~up).any()
    np.testing.assert_allclose(G[up], f_max, rtol=1e-12)
    np.testing.assert_allclose(G[~up], f_min, rtol=1e-12)
    np.testing.assert_allclose(j.v_before[up], v_max, rtol=1e-7)
    np.testing.assert_allclose(j.v_after[up], land_cd, rtol=1e-7)
    np.testing.assert_allclose(j.v_before[~up], v_min, rtol=1e-7)
    np.testing.assert_allclose(j.v_after[~up], land_ab, rtol=1e-7)


def test_a_monotone_cubic_runs_without_jumps():
    """Hypothesis: a cubic with ``c² < 3 b d`` increases in v throughout (no folds: no stick-slip), so the
    hybrid solver runs it on the one branch AB with no jump, and every stored point satisfies CONSTR,
    ``F (1 - cos θ) = f(v)``, to 1e-9 relative (the solver solves CONSTR to ~1e-12; the stored F is computed
    from it)."""
    from exact import simulate
    from peelapprox import PeelForce

    law = PeelForce.cubic(c=10.0)
    tr = simulate(PeelParams(V=1.2, I=1e-3, force=law), 0.2)
    assert tr.jumps.t.size == 0 and set(np.unique(tr.branch)) == {0}
    G = tr.F * (1.0 + PeelParams(V=1.2, I=1e-3).closure(tr.alpha)[0])
    np.testing.assert_allclose(G, law.f(tr.v, 1.2), rtol=1e-9)
