"""The symbolic source of truth: peel force, closures, equations of motion.

Everything numerical in peelapprox that encodes the *model* (the peel force
fvV and its derivatives, the closures of ``cos θ``, the equations of motion
FLOW1, FLOW2, flow3, the constraint CONSTR and its time derivative vdot, and the
Jacobian of the paper's ε-regularised system XDAE) is written once here, in
sympy, and rendered into :mod:`peelapprox._generated` by :func:`render_module`.
A test asserts that the committed generated file equals a fresh rendering, so
the two never drift apart.  Regenerate with::

    python -m peelapprox._symbolic

The module also carries the derivation of the equations of motion from the
Lagrangian (LAGRAN) and the dissipation function (DISSPN) via the Lagrange
equations MOTION1 and MOTION2 (:func:`lagrange_equations`); the tests check
that it reduces to FLOW2 and CONSTR.

sympy is imported only here and only by code that derives or generates;
importing :mod:`peelapprox` does not import sympy.
"""

from __future__ import annotations

import sympy as sp

# --------------------------------------------------------------------------
# symbols (SI units): state, parameters
# --------------------------------------------------------------------------
alpha, omega, F, v, u = sp.symbols("alpha omega F v u", real=True)
V, I, k, R, l, eps = sp.symbols("V I k R l eps", positive=True)
t = sp.Symbol("t", real=True)
w = sp.Symbol("w", real=True)  # w = ln v, used to share powers of v in code
c_, dc_ = sp.symbols("c dc", real=True)  # c = -cos(theta) and dc/dalpha
b_, A_ = sp.symbols("b A", real=True)  # V-dependent coefficients of f(v, V)

#: Exponents and prefactors of fvV, exact rationals.
_POWER_TERMS = ((400, sp.Rational(35, 100)), (110, sp.Rational(15, 100)))


def peel_force_coefficients_expr(V_=V):
    """V-dependent coefficients of fvV: ``b(V) = -2 V^1.5`` and
    ``A(V) = 415 - 45 V^0.4 - 0.35 V^2.15`` (the prefactor of ``-v^0.5``)."""
    b = -2 * V_ ** sp.Rational(3, 2)
    A = 415 - 45 * V_ ** sp.Rational(2, 5) - sp.Rational(35, 100) * V_ ** sp.Rational(215, 100)
    return b, A


def peel_force_expr(v_=v, V_=V):
    """Eq. (fvV) of the paper:

    f(v,V) = 400 v^0.35 + 110 v^0.15 + 130 e^(v/11) - 2 V^1.5
             - (415 - 45 V^0.4 - 0.35 V^2.15) v^0.5
    """
    b, A = peel_force_coefficients_expr(V_)
    return (
        sum(c * v_**p for c, p in _POWER_TERMS)
        + 130 * sp.exp(v_ / 11)
        + b
        - A * v_ ** sp.Rational(1, 2)
    )


def _peel_force_in_w():
    """fvV with ``v = e^w`` and the V-dependence in symbols ``b``, ``A``.

    Differentiating in ``w = ln v`` and mapping back (``f' = f_w / v``,
    ``f'' = (f_ww - f_w) / v²``) writes every derivative in the same powers
    ``v^0.15, v^0.35, v^0.5`` as f itself, so common-subexpression elimination
    shares them: two ``pow``, one ``sqrt`` and one ``exp`` for f, f' and f''.
    """
    vv = sp.exp(w)
    return (
        sum(c * sp.exp(p * w) for c, p in _POWER_TERMS)
        + 130 * sp.exp(vv / 11)
        + b_
        - A_ * sp.exp(w / 2)
    )


def cos_theta_expr(geometry: str, alpha_=alpha):
    """``cos θ`` as a function of α.

    ``"paper"``: ``cos θ = -sin α`` (the paper's numerics, below CONSTR).
    ``"exact"``: ``L cos θ = -l sin α`` with ``L² = l² + R² - 2 l R cos α``.
    """
    if geometry == "paper":
        return -sp.sin(alpha_)
    if geometry == "exact":
        L = sp.sqrt(l**2 + R**2 - 2 * l * R * sp.cos(alpha_))
        return -l * sp.sin(alpha_) / L
    raise ValueError(f"geometry must be 'paper' or 'exact', got {geometry!r}")


def equations_of_motion(c=c_):
    """FLOW1, FLOW2, flow3 and CONSTR with ``cos θ = -c``.

    Returns ``(alpha_dot, omega_dot, F_dot, constraint)`` where the constraint
    is the residual ``F (1 - cos θ) - f(v, V)`` that must vanish (CONSTR).
    """
    cos_theta = -c
    alpha_dot = omega - v / R  # FLOW1
    omega_dot = F * R * cos_theta / I  # FLOW2: I ω̇ = F R cos θ = -F R sin α
    F_dot = k * (V - v) - k * cos_theta * (omega * R - v)  # flow3
    constraint = F * (1 - cos_theta) - peel_force_expr(v, V)  # CONSTR
    return alpha_dot, omega_dot, F_dot, constraint


def lagrange_equations():
    """Derive the equations of motion from LAGRAN and DISSPN.

    Generalised coordinates ``(α, u)``; kinematics from Eq. (v):
    ``v = V - R cos θ α̇ - u̇`` and ``ω = α̇ + v/R``.  With the Lagrangian
    ``L = I ω²/2 - k u²/2`` and the dissipation function ``ℛ = Φ(v)`` with
    ``∂Φ/∂v = f(v, V)``, the Lagrange equations MOTION1 (for α) and MOTION2 (for
    u) are returned as expressions equal to zero, with ``ω̇`` left symbolic.

    Returns
    -------
    (motion1, motion2, omega_dot_symbol, fsym, cos_theta_fn, u_fn)
        ``fsym`` stands for ``f(v, V)``, ``omega_dot_symbol`` for ``ω̇``,
        ``cos_theta_fn`` is the undefined function ``cos_theta(alpha(t))`` and
        ``u_fn`` is ``u(t)``.
    """
    a = sp.Function("alpha")(t)
    uu = sp.Function("u")(t)
    ad, ud = sp.diff(a, t), sp.diff(uu, t)
    cth = sp.Function("cos_theta")(a)  # keep the closure general
    vel = V - R * cth * ad - ud  # Eq. (v)
    om = ad + vel / R  # ω = α̇ + v/R
    Lag = I / 2 * om**2 - k / 2 * uu**2  # LAGRAN
    fsym = sp.Symbol("f")
    # DISSPN: ℛ = Φ(v);  ∂ℛ/∂q̇ = f(v) ∂v/∂q̇ (chain rule, f = dΦ/dv)
    dR_dad = fsym * sp.diff(vel, ad)
    dR_dud = fsym * sp.diff(vel, ud)
    m1 = sp.diff(sp.diff(Lag, ad), t) - sp.diff(Lag, a) + dR_dad  # MOTION1
    m2 = sp.diff(sp.diff(Lag, ud), t) - sp.diff(Lag, uu) + dR_dud  # MOTION2
    # express in ω and ω̇: replace d/dt of the ω expression by a symbol
    wdot = sp.Symbol("omega_dot")
    om_dot_expr = sp.diff(om, t)
    m1 = sp.expand(m1.subs(om_dot_expr, wdot))
    m2 = sp.expand(m2.subs(om_dot_expr, wdot))
    return m1, m2, wdot, fsym, cth, uu


def regularized_system():
    """Right-hand side and Jacobian of the ε-regularised XDAE (both closures).

    ``M Ẋ = φ(X)`` with ``X = (α, ω, F, v)`` and ``M = diag(1, 1, 1, ε)``;
    dividing the last row by ε gives an ODE with ``v̇ = [F(1 - cos θ) - f]/ε``.
    The Jacobian is written in terms of ``c``, ``dc = dc/dα`` and ``f'`` symbols
    so that the same code serves both closures.
    """
    cfun = sp.Function("c")(alpha)
    ad, wd, Fd, g = equations_of_motion(cfun)
    rhs = sp.Matrix([ad, wd, Fd, g / eps])
    X = sp.Matrix([alpha, omega, F, v])
    J = rhs.jacobian(X)
    fp = sp.Symbol("fp")
    J = J.subs(sp.Derivative(cfun, alpha), dc_).subs(cfun, c_)
    J = J.subs(sp.diff(peel_force_expr(v, V), v), fp)
    return rhs.subs(cfun, c_), J, fp


# --------------------------------------------------------------------------
# code generation
# --------------------------------------------------------------------------
_HEADER = '''"""GENERATED by ``python -m peelapprox._symbolic`` -- do not edit by hand.

Model kernels rendered from the sympy source in :mod:`peelapprox._symbolic`.
Every function is plain Python on scalars using ``numpy`` functions, so the
same source is compiled by numba (scalar kernels) and evaluated by numpy
(vectorised over arrays).
"""

import numpy
'''


def _render_function(name, args, exprs, doc, out_names=None, prelude=(), extra_outs=()):
    from sympy.printing.numpy import NumPyPrinter

    printer = NumPyPrinter({"fully_qualified_modules": True, "inline": True})
    repl, red = sp.cse(list(exprs), symbols=sp.numbered_symbols("x"), optimizations="basic")
    lines = [f"def {name}({', '.join(args)}):", f'    """{doc}"""']
    lines += [f"    {sym} = {printer.doprint(e)}" for sym, e in prelude]
    for sym, e in repl:
        lines.append(f"    {sym} = {printer.doprint(e)}")
    outs = out_names or [f"r{i}" for i in range(len(red))]
    for o, e in zip(outs, red):
        e = sp.Float(e) if e.is_Number else e  # homogeneous float tuples for numba
        lines.append(f"    {o} = {printer.doprint(e)}")
    ret = ", ".join(list(extra_outs) + list(outs))
    lines.append(f"    return {ret}" + ("," if len(outs) + len(extra_outs) == 1 else ""))
    return "\n".join(lines) + "\n"


def render_module() -> str:
    """Return the source text of :mod:`peelapprox._generated`."""
    parts = [_HEADER]

    b, A = peel_force_coefficients_expr(V)
    parts.append(
        _render_function(
            "peel_force_coefficients",
            ["V"],
            [b, A],
            "Coefficients (b, A) of fvV for pull speed V: b = -2 V^1.5, A = 415 - 45 V^0.4 - 0.35 V^2.15.",
            ["b", "A"],
        )
    )

    fw = _peel_force_in_w()
    f_w = sp.diff(fw, w)
    f_ww = sp.diff(fw, w, 2)
    vv = sp.Symbol("v", positive=True)
    # d/dv = e^{-w} d/dw;  f' = f_w / v,  f'' = (f_ww - f_w) / v^2
    sub = {sp.exp(w): vv}
    f0 = fw.subs(sub)
    f1 = (f_w / sp.exp(w)).subs(sub)
    f2 = ((f_ww - f_w) / sp.exp(2 * w)).subs(sub)
    # Speed: the fractional powers v^(3/20), v^(7/20) become exp(r ln v) with ln v computed once (one log
    # and two exps instead of two pow calls: the peel force is ~2/3 of a hybrid field evaluation, and this
    # cuts it by a third).  sqrt stays native.  Accuracy is unchanged (~1e-15 relative in f).
    lv = sp.Symbol("lv")
    frac = {}
    for e in (f0, f1, f2):
        for pw in e.atoms(sp.Pow):
            if pw.base == vv and pw.exp.is_Rational and not pw.exp.is_Integer and pw.exp.q != 2:
                frac[pw] = sp.exp(pw.exp * lv)
    f0, f1, f2 = (e.xreplace(frac) for e in (f0, f1, f2))
    prelude = [(lv, sp.log(vv))]
    for name, exprs, outs, what in (
        ("peel_force_fp", [f0, f1], ["f", "fp"], "f(v, V) (fvV) and df/dv"),
        ("peel_force_fpp", [f0, f1, f2], ["f", "fp", "fpp"], "f(v, V) (fvV), df/dv and d2f/dv2"),
    ):
        parts.append(
            _render_function(
                name,
                ["v", "b", "A"],
                exprs,
                f"{what} for v > 0, given (b, A) = peel_force_coefficients(V).",
                outs,
                prelude,
            )
        )

    # The hybrid solver's state is ln v: f and df/d(ln v) = v f' from ln v directly (no log; v = e^(ln v)).
    g0 = fw.subs(sub).xreplace(frac)
    g1 = f_w.subs(sub).xreplace(frac)
    parts.append(
        _render_function(
            "peel_force_lnv",
            ["lv", "b", "A"],
            [g0, g1],
            "v = exp(lv), f(v, V) (fvV) and df/d(ln v) = v df/dv, given lv = ln v and (b, A).",
            ["f", "f_lnv"],
            [(vv, sp.exp(lv))],
            extra_outs=["v"],
        )
    )

    for geom in ("paper", "exact"):
        c = -cos_theta_expr(geom, alpha)
        parts.append(
            _render_function(
                f"closure_{geom}",
                ["alpha", "R", "l"],
                [c, sp.diff(c, alpha)],
                f"Closure '{geom}': c = -cos(theta) as a function of alpha, and dc/dalpha.",
                ["c", "dc"],
            )
        )
    for geom in ("paper", "exact"):  # with the second derivative: the Jacobian of the hybrid field (tangents)
        c = -cos_theta_expr(geom, alpha)
        parts.append(
            _render_function(
                f"closure_{geom}_d2",
                ["alpha", "R", "l"],
                [c, sp.diff(c, alpha), sp.diff(c, alpha, 2)],
                f"Closure '{geom}': c = -cos(theta), dc/dalpha and d2c/dalpha2.",
                ["c", "dc", "ddc"],
            )
        )

    ad, wd, Fd, g = equations_of_motion(c_)
    parts.append(
        _render_function(
            "slow_rates",
            ["alpha", "omega", "F", "v", "c", "V", "I", "k", "R"],
            [ad, wd, Fd],
            "FLOW1, FLOW2, flow3: (alpha_dot, omega_dot, F_dot) with c = -cos(theta).",
            ["alpha_dot", "omega_dot", "F_dot"],
        )
    )
    # d/dt of the constraint's pull side G = F (1 - cos θ) = F (1 + c(α)):
    # Ġ = Ḟ (1 + c) + F c'(α) α̇  -- the numerator of Eq. (vdot)
    Fd_s, ad_s = sp.symbols("F_dot alpha_dot", real=True)
    Gdot = Fd_s * (1 + c_) + F * dc_ * ad_s
    parts.append(
        _render_function(
            "constraint_rate",
            ["F", "F_dot", "c", "dc", "alpha_dot"],
            [Gdot],
            "dG/dt for G = F (1 + c): the numerator of Eq. (vdot), v_dot = G_dot / f'(v).",
            ["G_dot"],
        )
    )
    rhs, J, fp = regularized_system()
    fs = sp.Symbol("f")
    rhs = rhs.subs(peel_force_expr(v, V), fs)
    parts.append(
        _render_function(
            "regularized_rhs",
            ["alpha", "omega", "F", "v", "c", "f", "eps", "V", "I", "k", "R"],
            list(rhs),
            "XDAE with M = diag(1,1,1,eps), last row divided by eps: (alpha, omega, F, v) rates.",
            ["d_alpha", "d_omega", "d_F", "d_v"],
        )
    )
    names = [f"j{i}{j}" for i in range(4) for j in range(4)]
    parts.append(
        _render_function(
            "regularized_jacobian",
            ["alpha", "omega", "F", "v", "c", "dc", "fp", "eps", "V", "I", "k", "R"],
            [sp.sympify(J[i, j]) for i in range(4) for j in range(4)],
            "Jacobian of regularized_rhs, row-major 16-tuple, in terms of c, dc/dalpha and f'(v).",
            names,
        )
    )
    return "\n\n".join(parts)


def write_module(path=None) -> str:
    """Render and write :mod:`peelapprox._generated`; return the path."""
    import pathlib

    target = pathlib.Path(path) if path else pathlib.Path(__file__).with_name("_generated.py")
    target.write_text(render_module())
    return str(target)


if __name__ == "__main__":  # pragma: no cover
    print("wrote", write_module())
