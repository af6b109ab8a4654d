"""The symbolic model source (peelapprox._compiled._symbolic) and the code generated from it.

Checks that (a) the committed generated module is a fresh rendering, (b) the
Lagrangian derivation (LAGRAN, DISSPN, MOTION1, MOTION2) reproduces FLOW2,
CONSTR and flow3, (c) the paper's closure cos θ = -sin α against the exact
geometry, (d) the generated peel-force kernels against 30-digit sympy/mpmath
and (e) the generated Jacobian of the ε-regularised system (XDAE) against
finite differences of the generated right-hand side.
"""

import pathlib

import mpmath
import numpy as np
import pytest
import sympy as sp

from peelapprox import branch_structure
from peelapprox._compiled import _generated as g
from peelapprox._compiled import _symbolic as S

# ---------------------------------------------------------------- (a)


def test_generated_module_is_fresh():
    """Hypothesis: peelapprox/_compiled/_generated.py is exactly what render_module() produces now.

    Tolerance: none (exact string equality).  Any edit of the sympy source that
    is not followed by ``python -m peelapprox.law.codegen`` fails here.  (The
    rendering depends on the sympy version's printer and CSE; a sympy upgrade
    that changes the text is also reported, which is intended: regenerate and
    review the diff.)
    """
    committed = pathlib.Path(g.__file__).read_text()
    assert S.render_module() == committed


# ---------------------------------------------------------------- (b)


@pytest.fixture(scope="module")
def lagrange():
    m1, m2, wdot, fsym, cth, uu = S.lagrange_equations()
    C = sp.Symbol("C", real=True)  # cos θ, kept general (any closure)
    # F = k u: the tape tension is the elastic force
    m1 = m1.subs(cth, C).subs(uu, S.F / S.k)
    m2 = m2.subs(cth, C).subs(uu, S.F / S.k)
    return m1, m2, wdot, fsym, C


def _constraint_residual(C, fsym):
    """CONSTR residual F (1 - cos θ) - f from equations_of_motion, with f(v,V) -> symbol f."""
    g_ = S.equations_of_motion(-C)[3]
    return sp.expand(g_ + S.peel_force_expr(S.v, S.V) - fsym)


def test_lagrange_dalpha_terms_cancel():
    """Hypothesis: in MOTION1 the ∂L/∂α term cancels the cos θ'(α) α̇ part of d/dt ∂L/∂α̇.

    With ω = (1 - cos θ) α̇ + (V - u̇)/R one has ∂L/∂α̇ = I ω (1 - cos θ) and
    ∂L/∂α = -I ω cos θ'(α) α̇, so MOTION1 = I ω̇ (1 - cos θ) - R f cos θ contains
    no velocity and no derivative of the closure.  Exact symbolic check: the
    returned expressions contain no Derivative at all (after ω̇ -> symbol).
    """
    m1, m2, wdot, fsym, cth, uu = S.lagrange_equations()
    assert not m1.atoms(sp.Derivative) and not m2.atoms(sp.Derivative)
    assert sp.simplify(m1 - (S.I * wdot * (1 - cth) - S.R * fsym * cth)) == 0
    assert sp.simplify(m2 - (-S.I * wdot / S.R - fsym + S.k * uu)) == 0


def test_lagrange_gives_flow2_and_constr(lagrange):
    """Hypothesis: MOTION1 and MOTION2 (with F = k u) are equivalent to FLOW2 and CONSTR.

    MOTION2 alone gives I ω̇ = R (F - f): this is FLOW2 (I ω̇ = F R cos θ)
    only on the constraint, since R (F - f) - F R cos θ = R [F (1 - cos θ) - f].
    Eliminating ω̇ between MOTION1 and MOTION2 gives
    MOTION1 + R (1 - cos θ) MOTION2 = R [F (1 - cos θ) - f] (R times the CONSTR
    residual).  Equivalently the two equations, linear in (ω̇, f) with
    determinant -I ≠ 0, have the unique solution ω̇ = F R cos θ / I (FLOW2),
    f = F (1 - cos θ) (CONSTR).  Tolerance: exact (sympy simplify to 0).
    """
    m1, m2, wdot, fsym, C = lagrange
    resid = _constraint_residual(C, fsym)
    flow2 = S.equations_of_motion(-C)[1]  # ω̇ = F R cos θ / I

    # MOTION2 solved for I ω̇
    (wd2,) = sp.solve(m2, wdot)
    assert sp.simplify(S.I * wd2 - S.R * (S.F - fsym)) == 0
    # ... which equals FLOW2 up to R x CONSTR residual
    assert sp.simplify(S.I * wd2 - S.I * flow2 - S.R * resid) == 0

    # elimination of ω̇: proportional to the CONSTR residual
    elim = sp.expand(m1 + S.R * (1 - C) * m2)
    assert wdot not in elim.free_symbols
    assert sp.simplify(elim - S.R * resid) == 0
    assert sp.simplify(m1.subs(wdot, wd2) - S.R * resid) == 0

    # unique joint solution = (FLOW2, CONSTR)
    sol = sp.solve([m1, m2], [wdot, fsym], dict=True)
    assert len(sol) == 1
    assert sp.simplify(sol[0][wdot] - flow2) == 0
    assert sp.simplify(sol[0][fsym] - S.F * (1 - C)) == 0


def test_flow1_and_flow3_from_kinematics():
    """Hypothesis: FLOW1 is ω = α̇ + v/R and flow3 follows from F = k u and Eq. (v).

    Ḟ = k u̇, u̇ = V - v - R cos θ α̇ (Eq. v) and R α̇ = ω R - v (FLOW1) give
    Ḟ = k (V - v) - k cos θ (ω R - v), which must equal equations_of_motion's
    F_dot with c = -cos θ.  Tolerance: exact (sympy simplify to 0).
    """
    C = sp.Symbol("C", real=True)
    ad, wd, Fd, _ = S.equations_of_motion(-C)
    assert sp.simplify(ad - (S.omega - S.v / S.R)) == 0  # FLOW1
    alpha_dot = S.omega - S.v / S.R
    u_dot = S.V - S.v - S.R * C * alpha_dot  # Eq. (v) solved for u̇
    assert sp.simplify(S.k * u_dot - Fd) == 0
    assert sp.simplify(Fd - (S.k * (S.V - S.v) - S.k * C * (S.omega * S.R - S.v))) == 0


# ---------------------------------------------------------------- (c)


def test_paper_closure_constraint_and_flow3_small_angle():
    """Hypothesis: with cos θ = -sin α, CONSTR is F (1 + sin α) - f and flow3 ≈ FLOW3.

    flow3 with cos θ = -sin α is k (V - v) + k sin α · R α̇, whose first order
    in α is the paper's FLOW3 k [V - v + R α α̇] (difference O(α³)).
    Tolerance: exact symbolic identities.
    """
    c = sp.sin(S.alpha)
    assert sp.simplify(-S.cos_theta_expr("paper") - c) == 0
    _, wd, Fd, g_ = S.equations_of_motion(c)
    f = S.peel_force_expr(S.v, S.V)
    assert sp.expand(g_ - (S.F * (1 + sp.sin(S.alpha)) - f)) == 0
    assert sp.simplify(wd + S.F * S.R * sp.sin(S.alpha) / S.I) == 0  # FLOW2
    alpha_dot = S.omega - S.v / S.R
    flow3_small = S.k * (S.V - S.v + S.R * S.alpha * alpha_dot)  # FLOW3
    diff = sp.series((Fd - flow3_small).subs(S.omega, S.v / S.R + sp.Symbol("ad")), S.alpha, 0, 3)
    assert sp.expand(diff.removeO()) == 0


def test_exact_closure_slope_at_zero_is_l_over_l_minus_R():
    """Hypothesis: c(α) = l sin α / L(α) = [l/(l-R)] α + O(α³), so the paper's
    closure sin α matches the exact geometry at first order only up to the
    factor l/(l - R) (1.111 for the defaults R = 0.1 m, l = 1 m; → 1 as l/R → ∞).

    Found: c'(0) = l/(l-R) exactly (L(0) = l - R, L is even in α so there is no
    α² term).  Tolerances: symbolic checks exact; generated closure_exact at
    α = 0 within 1e-15 relative (one division); c(α)/sin α at α = 1e-4 within
    1e-7 relative (the O(α²) correction is ~ 1e-9 here).
    """
    d = sp.Symbol("d", positive=True)  # l = R + d > R
    c = (-S.cos_theta_expr("exact")).subs(S.l, S.R + d)
    ser = sp.series(c, S.alpha, 0, 3).removeO()
    assert sp.simplify(ser - (S.R + d) / d * S.alpha) == 0  # no α² term
    assert sp.simplify(sp.diff(c, S.alpha).subs(S.alpha, 0) - (S.R + d) / d) == 0

    R, l = 0.1, 1.0
    c0, dc0 = g.closure_exact(0.0, R, l)
    assert c0 == 0.0
    assert dc0 == pytest.approx(l / (l - R), rel=1e-15)
    assert dc0 == pytest.approx(1.1111111111111112, rel=1e-15)
    a = 1e-4
    ca, _ = g.closure_exact(a, R, l)
    assert ca / np.sin(a) == pytest.approx(l / (l - R), rel=1e-7)
    # the paper's closure has slope 1
    cp, dcp = g.closure_paper(0.0, R, l)
    assert (cp, dcp) == (0.0, 1.0)
    # the paper's closure is the l/R -> ∞ limit of the exact one
    assert sp.limit(-S.cos_theta_expr("exact"), S.l, sp.oo) == sp.sin(S.alpha)


# ---------------------------------------------------------------- (d)


@pytest.fixture(scope="module")
def peel_force_mp():
    """30-digit f, f', f'' and the largest |term| of each, by sympy diff + mpmath."""
    f = S.peel_force_expr(S.v, S.V)
    terms = sp.Add.make_args(sp.expand(f))
    fns = []
    for n in range(3):
        full = sp.diff(f, S.v, n)
        parts = [sp.diff(t, S.v, n) for t in terms]
        fns.append(
            (
                sp.lambdify((S.v, S.V), full, modules="mpmath"),
                [sp.lambdify((S.v, S.V), p, modules="mpmath") for p in parts],
            )
        )
    return fns


@pytest.mark.parametrize("V", [0.4, 1.0, 4.0])
def test_generated_peel_force_matches_30_digit_sympy(V, peel_force_mp):
    """Hypothesis: peel_force_fpp (generated, double precision) equals d^n f/dv^n
    of peel_force_expr (fvV), n = 0, 1, 2, for v in [1e-6, 50] (plus the folds).

    Reference: sympy's own derivatives of fvV evaluated by mpmath at 30 digits.
    Tolerance: |double - ref| <= 1e-12 x (largest |term| of that derivative).
    The generated code sums a handful of terms, each carrying a few ulp of
    pow/exp/sqrt rounding, so its absolute error is ~1e-15 of the largest
    term; a relative-to-result test is meaningless near the folds, where f' is
    a cancellation of terms of size ~100 to 0.  The margin (~1000 ulp) absorbs
    libm differences while any wrong coefficient or exponent (>= 1e-3 of a
    term) fails by orders of magnitude.
    """
    vs = list(np.geomspace(1e-6, 50.0, 20))
    bs = branch_structure(V)
    if bs.has_folds:
        vs += [bs.v_max, bs.v_min, bs.v_inflection]
    b, A = g.peel_force_coefficients(V)
    with mpmath.workdps(30):
        for vv in vs:
            got = g.peel_force_fpp(vv, b, A)
            for n in range(3):
                full, parts = peel_force_mp[n]
                ref = full(mpmath.mpf(vv), mpmath.mpf(V))
                scale = max(abs(p(mpmath.mpf(vv), mpmath.mpf(V))) for p in parts)
                err = abs(mpmath.mpf(got[n]) - ref)
                assert err <= 1e-12 * scale, (V, vv, n, float(err), float(scale))


# ---------------------------------------------------------------- (e)

_CLOSURES = {"paper": g.closure_paper, "exact": g.closure_exact}
_PAR = dict(eps=1e-7, V=1.0, I=1e-5, k=1000.0, R=0.1, l=1.0)


def _rhs(X, geometry):
    alpha, omega, F, v = X
    p = _PAR
    c, _ = _CLOSURES[geometry](alpha, p["R"], p["l"])
    b, A = g.peel_force_coefficients(p["V"])
    f, _ = g.peel_force_fp(v, b, A)
    return np.array(g.regularized_rhs(alpha, omega, F, v, c, f, p["eps"], p["V"], p["I"], p["k"], p["R"]))


def _jac(X, geometry):
    alpha, omega, F, v = X
    p = _PAR
    c, dc = _CLOSURES[geometry](alpha, p["R"], p["l"])
    b, A = g.peel_force_coefficients(p["V"])
    _, fp = g.peel_force_fp(v, b, A)
    j = g.regularized_jacobian(alpha, omega, F, v, c, dc, fp, p["eps"], p["V"], p["I"], p["k"], p["R"])
    return np.array(j, dtype=float).reshape(4, 4)


# (alpha, omega, F, v): on AB, in the unstable middle, on CD; small and large alpha
_STATES = [
    (0.02, 10.3, 250.0, 0.05),
    (-0.3, 4.0, 230.0, 2.0),
    (0.5, 60.0, 280.0, 12.0),
    (-0.05, 9.0, 205.0, 0.3),
]


@pytest.mark.parametrize("geometry", ["paper", "exact"])
@pytest.mark.parametrize("X", _STATES)
def test_regularized_jacobian_matches_finite_differences(X, geometry):
    """Hypothesis: regularized_jacobian is the Jacobian of regularized_rhs with
    respect to X = (α, ω, F, v), when c, dc come from the closure and f, f' from
    peel_force_fp (XDAE, both geometries).

    Central differences with step h_j = 1e-6 |X_j|: truncation error
    O(h²) ~ 1e-12 relative; rounding error ~ u |φ| / h ~ 1e-10 relative, larger
    in the v-row where φ_4 = [F(1+c) - f]/ε is a difference of ~300 N terms.
    Tolerance: 1e-6 relative to the entry plus 1e-6 of the largest entry of its
    row, which leaves ~1e4 of margin for this amplification while any missing
    term or wrong sign (O(1) error) fails.  Entries whose variable does not
    appear are exactly 0 in both.
    """
    X = np.array(X, dtype=float)
    J = _jac(X, geometry)
    Jfd = np.empty((4, 4))
    for j in range(4):
        h = 1e-6 * abs(X[j])
        Xp, Xm = X.copy(), X.copy()
        Xp[j] += h
        Xm[j] -= h
        Jfd[:, j] = (_rhs(Xp, geometry) - _rhs(Xm, geometry)) / (Xp[j] - Xm[j])
    for i in range(4):
        np.testing.assert_allclose(Jfd[i], J[i], rtol=1e-6, atol=1e-6 * np.max(np.abs(J[i])), err_msg=f"row {i}")
    # structural zeros are exact
    assert J[0, 0] == J[0, 2] == J[1, 1] == J[1, 3] == J[2, 2] == J[3, 1] == 0.0
