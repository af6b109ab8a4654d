"""The model variants' equations from their symbolic source: the tape-mass model and the load.

Hypotheses: (1) the compact rates of :func:`tape_mass_rates` are exactly what the Lagrange equations give for
LAGRAN plus the ribbon's kinetic energy (sympy simplifies the difference to 0: no tolerance); (2) with m = 0
the tape-mass model is the paper's DAE (FLOW2 and CONSTR, exactly); (3) under a load the pulled end obeys
M V̇_p = F_L - F (exactly); (4) the compiled fields and Jacobians equal the sympy expressions evaluated in
double precision (to 1e-12 relative: a few roundings of the CSE'd code) and the Jacobian equals central
differences of the field (to 1e-5 relative: the differencing error at h = 1e-7 relative).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import peelapprox._compiled._symbolic as S
from peelapprox import PeelParams
from peelapprox.kernels import compiled_law, variant_field, variant_parameters


def _in_state(e, load):
    """A Lagrange-equation expression in the state (α, ω, F, v[, V_p])."""
    a = sp.Function("alpha")(S.t)
    uu = sp.Function("u")(S.t)
    cf = sp.Function("c")(a)
    ad, ud = a.diff(S.t), uu.diff(S.t)
    vp = S.Vp if load else S.V
    e = e.subs(sp.Derivative(cf, a), S.dc_).subs(cf, S.c_)
    e = e.subs(ud, vp + S.R * S.c_ * ad - S.v).subs(ad, S.omega - S.v / S.R).subs(uu, S.F / S.k)
    return e


@pytest.mark.parametrize("load", [False, True])
def test_compact_rates_are_the_lagrange_equations(load):
    """ω̇ and v̇ of tape_mass_rates equal the Lagrange equations' (sympy: difference simplifies to 0)."""
    d = S.tape_mass_lagrange_equations(load)
    a = sp.Function("alpha")(S.t)
    cf = sp.Function("c")(a)
    ad = a.diff(S.t)
    vd = sp.Symbol("vd")
    Vpd = d["Vp_dot"] if load else 0
    # v = V_p + R c α̇ - u̇ differentiated, with α̈ = ω̇ - v̇/R
    vsol = sp.solve(vd - (Vpd + S.R * sp.Derivative(cf, a) * ad**2 + S.R * cf * (d["omega_dot"] - vd / S.R)
                          - d["u_ddot"]), vd)[0]
    _, wr, _, vr = S.tape_mass_rates()
    vr = vr.subs(S.Vp_dot, 0) if not load else vr
    if not load:
        vr = vr.subs(S.Vp, S.V)
    assert sp.simplify(_in_state(d["omega_dot"], load) - wr) == 0
    assert sp.simplify(_in_state(vsol, load) - vr) == 0
    if load:
        assert sp.simplify(_in_state(d["Vp_dot"], load) - (S.F_load - S.F) / S.M_load) == 0


def test_zero_mass_is_the_paper_dae():
    """m (1 + c)² v̇ at m = 0 is CONSTR's residual F (1 + c) - f, and ω̇ on CONSTR (f = F (1 + c)) is FLOW2."""
    f = sp.Symbol("f")
    _, wr, Fr, vr = S.tape_mass_rates()
    lead = sp.limit(sp.expand(S.m_tape * (1 + S.c_) ** 2 * vr), S.m_tape, 0)
    assert sp.simplify(lead - (S.F * (1 + S.c_) - f)) == 0
    _, wd, Fd, _ = S.equations_of_motion(S.c_)
    assert sp.simplify(wr.subs(f, S.F * (1 + S.c_)) - wd) == 0
    assert sp.simplify(Fr.subs(S.Vp, S.V) - Fd) == 0  # flow3 unchanged


@pytest.mark.parametrize("model", ["tape", "tape_load", "eps_load"])
def test_compiled_fields_equal_sympy(model):
    """The compiled field equals the sympy right-hand side (1e-12 relative) at a state off the slow manifold; its
    Jacobian equals central differences (1e-5 relative)."""
    p = PeelParams(V=1.0, I=1e-5, geometry="exact")
    cl = compiled_law(p.force, p.V)
    mass = 1e-7 if model == "eps_load" else 1e-3
    q = variant_parameters(p, mass, 20.0, 250.0)
    n = 4 if model == "tape" else 5
    y = np.array([0.05, 8.0, 240.0, 0.5, 1.1][:n])
    fun, jac = variant_field(model)
    got = fun(y, q, cl.fn, cl.coef)
    rhs, _ = S.variant_system(model)
    c_expr = -S.cos_theta_expr("exact", S.alpha)
    f, fp = cl.fn(y[3], cl.coef, 1)[:2]
    subs = {S.alpha: y[0], S.omega: y[1], S.F: y[2], S.v: y[3], S.c_: c_expr, S.dc_: sp.diff(c_expr, S.alpha),
            sp.Symbol("f"): f, sp.Symbol("fp"): fp, S.V: p.V, S.I: p.I, S.k: p.k, S.R: p.R, S.l: p.l,
            S.m_tape: mass, S.eps: mass, S.M_load: 20.0, S.F_load: 250.0}
    if n == 5:
        subs[S.Vp] = y[4]
    want = np.array([float(sp.N(e.subs(S.c_, c_expr).subs(S.dc_, sp.diff(c_expr, S.alpha)).subs(subs), 30))
                     for e in rhs])
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.max(np.abs(want)))
    J = jac(y, q, cl.fn, cl.coef)
    Jfd = np.empty((n, n))
    for j in range(n):
        h = 1e-7 * max(1.0, abs(y[j]))
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        Jfd[:, j] = (fun(yp, q, cl.fn, cl.coef) - fun(ym, q, cl.fn, cl.coef)) / (2 * h)
    np.testing.assert_allclose(J, Jfd, rtol=1e-5, atol=1e-5 * np.max(np.abs(Jfd)))
