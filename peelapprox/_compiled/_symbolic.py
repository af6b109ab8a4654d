"""The symbolic source of truth: peel force, closures, equations of motion.

Everything numerical in peelapprox that encodes the *model* (the peel force
fvV and its derivatives, the closures of ``cos θ``, the equations of motion
FLOW1, FLOW2, flow3, the constraint CONSTR and its time derivative vdot, and the
Jacobian of the paper's ε-regularised system XDAE) is written once here, in
sympy, and rendered into :mod:`peelapprox._compiled._generated` by :func:`render_module`
(through the one renderer, :mod:`peelapprox._compiled._render`, which renders the laws too).
A test asserts that the committed generated file equals a fresh rendering, so
the two never drift apart.  Regenerate both generated modules with::

    python -m peelapprox.law.codegen

The module also carries the derivation of the equations of motion from the
Lagrangian (LAGRAN) and the dissipation function (DISSPN) via the Lagrange
equations MOTION1 and MOTION2 (:func:`lagrange_equations`); the tests check
that it reduces to FLOW2 and CONSTR.

sympy is imported only here and only by code that derives or generates;
importing :mod:`peelapprox` does not import sympy.
"""

from __future__ import annotations

import sympy as sp

from . import _render

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


# --------------------------------------------------------------------------
# model variants (docs/tape-mass.md, docs/constant-load.md): the tape's mass, the constant load
# --------------------------------------------------------------------------
#: Tape (ribbon) mass m [kg], loading-device mass M [kg], load F_L [N], the pull speed as a state V_p [m/s].
m_tape, M_load, F_load = sp.symbols("m M F_L", positive=True)
Vp = sp.Symbol("Vp", real=True)
Vp_dot = sp.Symbol("Vp_dot", real=True)  # its rate: 0 under velocity control, (F_L - F)/M under a load


def tape_mass_lagrange_equations(load: bool = False):
    """Equations of motion of the tape-mass model from LAGRAN plus the ribbon's kinetic energy.

    Generalised coordinates ``(α, u)`` and, under a load, the position ``x_p`` of the pulled end (O') with
    ``ẋ_p = V_p``.  The kinematics are the paper's Eq. (v) with ``V → ẋ_p``: ``v = ẋ_p - R cos θ α̇ - u̇``,
    ``ω = α̇ + v/R``.  The Lagrangian is LAGRAN plus the translational kinetic energy of the peeled ribbon
    (mass ``m``), whose material moves along PO' with the velocity ``ẋ_p - u̇ = v - L̇`` of its end at the
    spring (the paper lumps the tape's elasticity in ``u`` at O'):

        L = I ω²/2 + m (ẋ_p - u̇)²/2 - k u²/2   [+ M ẋ_p²/2 + F_L x_p under a load]

    with the dissipation function DISSPN, ``∂ℛ/∂q̇ = f(v, V) ∂v/∂q̇``.  Under velocity control ``x_p = V t`` is
    prescribed (not a coordinate).  Returns the accelerations solved from MOTION1, MOTION2 (and the ``x_p``
    equation) as a dict ``{"omega_dot", "u_ddot"[, "Vp_dot"]}`` of expressions in ``α(t), u(t)`` and their
    first derivatives, ``f`` (the symbol ``f``) and ``V_p`` (the symbol; ``V`` under velocity control), with
    ``c(α) = -cos θ`` an undefined function.
    """
    a = sp.Function("alpha")(t)
    uu = sp.Function("u")(t)
    ad, ud = sp.diff(a, t), sp.diff(uu, t)
    cfun = sp.Function("c")(a)
    coords = [a, uu]
    if load:
        xp = sp.Function("x_p")(t)
        xpd = sp.diff(xp, t)
        coords.append(xp)
    else:
        xpd = V
    vel = xpd + R * cfun * ad - ud  # Eq. (v), cos θ = -c
    om = ad + vel / R
    Lag = I / 2 * om**2 + m_tape / 2 * (xpd - ud) ** 2 - k / 2 * uu**2  # LAGRAN + the ribbon
    if load:
        Lag += M_load / 2 * xpd**2 + F_load * xp  # the loading mass and the load's potential -F_L x_p
    fsym = sp.Symbol("f")
    eqs = []
    for q in coords:
        qd = sp.diff(q, t)
        eqs.append(sp.diff(sp.diff(Lag, qd), t) - sp.diff(Lag, q) + fsym * sp.diff(vel, qd))  # MOTION1, MOTION2
    acc = [sp.diff(q, t, 2) for q in coords]
    accs = sp.symbols(f"acc0:{len(coords)}")
    sol = sp.solve([e.subs(dict(zip(acc, accs))) for e in eqs], accs, dict=True)[0]
    omega_dot = sp.diff(om, t).subs(dict(zip(acc, accs))).subs(sol)
    out = {"omega_dot": omega_dot, "u_ddot": sol[accs[1]], "v": vel}
    if load:
        out["Vp_dot"] = sol[accs[2]]
        out = {kk: e.subs(xpd, Vp) for kk, e in out.items()}
    return out


def tape_mass_rates(c=c_, dc=dc_):
    """FLOW1, flow3 and the tape-mass model's ω̇ and v̇ in the state ``(α, ω, F, v)`` (and ``V_p``).

    From :func:`tape_mass_lagrange_equations` with ``F = k u`` and ``u̇ = V_p + R c α̇ - v`` (Eq. v):

        α̇ = ω - v/R                                   (FLOW1)
        I ω̇ = -R c f / (1 + c)                          (FLOW2 with the ribbon's tension f/(1 + c) at P)
        Ḟ = k (V_p - v) + k c (R ω - v)                 (flow3)
        m (1 + c)² v̇ = F (1 + c) - f + m (1 + c) [R c' α̇² - R² c² f / (I (1 + c))]

    so ``m → 0`` gives back FLOW2 and CONSTR.  The ribbon's momentum, ``m (V̇_p - ü) = F - f/(1 + c)``, gives
    ``ü``; the pull speed's rate ``V̇_p`` (the symbol ``Vp_dot``: 0 under velocity control) cancels from v̇.
    Returns ``(alpha_dot, omega_dot, F_dot, v_dot)`` in terms of ``c``, ``dc`` and the symbol ``f``.
    """
    fsym = sp.Symbol("f")
    alpha_dot = omega - v / R
    omega_dot = -R * c * fsym / (I * (1 + c))
    F_dot = k * (Vp - v) + k * c * (omega * R - v)
    s_dot = Vp_dot + (fsym / (1 + c) - F) / m_tape  # ü: the ribbon's momentum, m (d/dt)(V_p - u̇) = F - f/(1 + c)
    # v = V_p + R c α̇ - u̇  =>  (1 + c) v̇ = V̇_p + R c' α̇² + R c ω̇ - ü
    v_dot = (Vp_dot + R * dc * alpha_dot**2 + R * c * omega_dot - s_dot) / (1 + c)
    return alpha_dot, omega_dot, F_dot, v_dot


def variant_system(model: str):
    """Right-hand side and Jacobian of a model variant's ODE in ``X = (α, ω, F, v[, V_p])``.

    ``model``: ``"tape"`` (tape mass, velocity control, 4 states), ``"tape_load"`` (tape mass under a load, 5
    states) or ``"eps_load"`` (the massless tape under a load in the paper's ε-regularisation XDAE, 5 states).
    Under a load ``V̇_p = (F_L - F)/M``.  Written in ``c``, ``dc``, ``ddc`` (``c = -cos θ`` and its α-derivatives)
    and ``f``, ``fp`` (the peel force and df/dv) so that one rendering serves both closures and every law.
    Returns ``(rhs, J)`` with ``f`` and ``fp`` as symbols.
    """
    if model not in ("tape", "tape_load", "eps_load"):
        raise ValueError(f"model must be 'tape', 'tape_load' or 'eps_load', got {model!r}")
    load = model != "tape"
    cfun = sp.Function("c")(alpha)
    fv = sp.Function("fv")(v)
    if model == "eps_load":
        ad, wd, Fd, g = equations_of_motion(cfun)
        rates = [ad, wd, Fd.subs(V, Vp), (g.subs(peel_force_expr(v, V), fv)) / eps]
    else:
        ad, wd, Fd, vd = tape_mass_rates(cfun, sp.diff(cfun, alpha))
        rates = [ad, wd, Fd, vd]
    X = [alpha, omega, F, v]
    vdot_load = (F_load - F) / M_load
    if load:
        rates = [e.subs(Vp_dot, vdot_load) for e in rates] + [vdot_load]
        X.append(Vp)
    else:
        rates = [e.subs({Vp_dot: 0, Vp: V}) for e in rates]
    fsym, fp = sp.symbols("f fp")
    rates = [e.subs(sp.Symbol("f"), fv) for e in rates]
    rhs = sp.Matrix(rates)
    J = rhs.jacobian(sp.Matrix(X))
    ddc = sp.Symbol("ddc")
    back = [(sp.Derivative(cfun, (alpha, 2)), ddc), (sp.Derivative(cfun, alpha), dc_), (cfun, c_),
            (sp.Derivative(fv, v), fp), (fv, fsym)]
    for old, new in back:
        rhs, J = rhs.subs(old, new), J.subs(old, new)
    return rhs, J


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
# code generation (the renderer: peelapprox/_compiled/_render.py; the command: python -m peelapprox.law.codegen)
# --------------------------------------------------------------------------
_HEADER = '''"""GENERATED by ``python -m peelapprox.law.codegen`` -- do not edit by hand.

Model kernels rendered from the sympy source in :mod:`peelapprox._compiled._symbolic`.
Every function is plain Python on scalars using ``numpy`` functions, so the
same source is compiled by numba (scalar kernels) and evaluated by numpy
(vectorised over arrays).
"""

import numpy
'''


def render_module() -> str:
    """Return the source text of :mod:`peelapprox._compiled._generated` (written by ``python -m
    peelapprox.law.codegen``)."""
    return _render.render_module(_HEADER, _render_peel_force() + _render_closures() + _render_rates()
                                 + _render_variants())


def _render_peel_force() -> list[str]:
    """fvV's coefficients, f with its v-derivatives, and f with its ln v-derivative (the hybrid solver's state)."""
    b, A = peel_force_coefficients_expr(V)
    parts = [_render.render_function(
        "peel_force_coefficients", ["V"], [b, A],
        "Coefficients (b, A) of fvV for pull speed V: b = -2 V^1.5, A = 415 - 45 V^0.4 - 0.35 V^2.15.", ["b", "A"])]
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
    for name, exprs, outs, what in (
        ("peel_force_fp", [f0, f1], ["f", "fp"], "f(v, V) (fvV) and df/dv"),
        ("peel_force_fpp", [f0, f1, f2], ["f", "fp", "fpp"], "f(v, V) (fvV), df/dv and d2f/dv2"),
    ):
        parts.append(_render.render_function(
            name, ["v", "b", "A"], exprs, f"{what} for v > 0, given (b, A) = peel_force_coefficients(V).", outs,
            [(lv, sp.log(vv))]))
    # The hybrid solver's state is ln v: f and df/d(ln v) = v f' from ln v directly (no log; v = e^(ln v)).
    g0 = fw.subs(sub).xreplace(frac)
    g1 = f_w.subs(sub).xreplace(frac)
    parts.append(_render.render_function(
        "peel_force_lnv", ["lv", "b", "A"], [g0, g1],
        "v = exp(lv), f(v, V) (fvV) and df/d(ln v) = v df/dv, given lv = ln v and (b, A).", ["f", "f_lnv"],
        [(vv, sp.exp(lv))], extra_outs=["v"]))
    return parts


def _render_closures() -> list[str]:
    """The closures c = -cos θ of both geometries with dc/dα, then with d²c/dα² too (the hybrid field's Jacobian)."""
    parts = []
    for geom in ("paper", "exact"):
        c = -cos_theta_expr(geom, alpha)
        parts.append(_render.render_function(
            f"closure_{geom}", ["alpha", "R", "l"], [c, sp.diff(c, alpha)],
            f"Closure '{geom}': c = -cos(theta) as a function of alpha, and dc/dalpha.", ["c", "dc"]))
    for geom in ("paper", "exact"):
        c = -cos_theta_expr(geom, alpha)
        parts.append(_render.render_function(
            f"closure_{geom}_d2", ["alpha", "R", "l"], [c, sp.diff(c, alpha), sp.diff(c, alpha, 2)],
            f"Closure '{geom}': c = -cos(theta), dc/dalpha and d2c/dalpha2.", ["c", "dc", "ddc"]))
    return parts


def _render_rates() -> list[str]:
    """FLOW1, FLOW2, flow3; the constraint's rate (Eq. vdot's numerator); the XDAE's field and Jacobian."""
    ad, wd, Fd, g = equations_of_motion(c_)
    parts = [_render.render_function(
        "slow_rates", ["alpha", "omega", "F", "v", "c", "V", "I", "k", "R"], [ad, wd, Fd],
        "FLOW1, FLOW2, flow3: (alpha_dot, omega_dot, F_dot) with c = -cos(theta).",
        ["alpha_dot", "omega_dot", "F_dot"])]
    # d/dt of the constraint's pull side G = F (1 - cos θ) = F (1 + c(α)):
    # Ġ = Ḟ (1 + c) + F c'(α) α̇  -- the numerator of Eq. (vdot)
    Fd_s, ad_s = sp.symbols("F_dot alpha_dot", real=True)
    parts.append(_render.render_function(
        "constraint_rate", ["F", "F_dot", "c", "dc", "alpha_dot"], [Fd_s * (1 + c_) + F * dc_ * ad_s],
        "dG/dt for G = F (1 + c): the numerator of Eq. (vdot), v_dot = G_dot / f'(v).", ["G_dot"]))
    rhs, J, fp = regularized_system()
    rhs = rhs.subs(peel_force_expr(v, V), sp.Symbol("f"))
    parts.append(_render.render_function(
        "regularized_rhs", ["alpha", "omega", "F", "v", "c", "f", "eps", "V", "I", "k", "R"], list(rhs),
        "XDAE with M = diag(1,1,1,eps), last row divided by eps: (alpha, omega, F, v) rates.",
        ["d_alpha", "d_omega", "d_F", "d_v"]))
    parts.append(_render.render_function(
        "regularized_jacobian", ["alpha", "omega", "F", "v", "c", "dc", "fp", "eps", "V", "I", "k", "R"],
        [J[i, j] for i in range(4) for j in range(4)],
        "Jacobian of regularized_rhs, row-major 16-tuple, in terms of c, dc/dalpha and f'(v).",
        [f"j{i}{j}" for i in range(4) for j in range(4)]))
    return parts


def _render_variants() -> list[str]:
    """The model variants' kernels: the tape-mass rates, the load's rate, the three Jacobians."""
    rhs, _ = variant_system("tape_load")
    state = ["alpha", "omega", "F", "v"]
    parts = [
        _render.render_function(
            "tape_rhs", state + ["Vp", "c", "dc", "f", "m", "I", "k", "R"], list(rhs[:4]),
            "Tape-mass model: (alpha, omega, F, v) rates with the pull speed Vp (= V under velocity control).",
            ["d_alpha", "d_omega", "d_F", "d_v"]),
        _render.render_function(
            "load_rate", ["F", "M", "F_L"], [rhs[4]], "Under a load F_L on a mass M: the pull speed's rate.",
            ["d_Vp"]),
    ]
    for model, n, extra, what in (
        ("tape", 4, ["m", "V"], "tape-mass model under velocity control"),
        ("tape_load", 5, ["Vp", "m", "M", "F_L"], "tape-mass model under a load, state (alpha, omega, F, v, Vp)"),
        ("eps_load", 5, ["Vp", "eps", "M", "F_L"], "eps-regularised massless tape under a load (XDAE)"),
    ):
        _, J = variant_system(model)
        parts.append(_render.render_function(
            f"{model}_jacobian", state + ["c", "dc", "ddc", "f", "fp"] + extra + ["I", "k", "R"],
            [J[i, j] for i in range(n) for j in range(n)],
            f"Jacobian of the {what}, row-major {n * n}-tuple, in c, its alpha-derivatives dc, ddc, f and f'.",
            [f"j{i}{j}" for i in range(n) for j in range(n)]))
    return parts
