"""A third solver of the full DAE, independent of the two of ``exact``: the benchmark reference's cross-check.

On a stable branch the DAE (FLOW1, FLOW2, flow3, CONSTR) is an ODE in ``(α, ω, F)`` with v from the branch
inverse of the peel-force law (fvV, or any ``params.force`` evaluated by :meth:`peelapprox.PeelForce.f` -- numpy
and scipy, not the compiled law kernels the solvers of ``exact`` call); scipy's DOP853 integrates it and the
folds are terminal events (:func:`branchwise_reference`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import cast

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from exact import SolverFailure, initial_state
from peelapprox import BranchStructure, PeelParams, branch_structure
from peelapprox.kernels import branch_inverse_at, closure_paper, peel_force_coefficients, slow_rates
from peelapprox.validate import params as _params

# the generated model functions themselves, in plain Python: the reference uses no compiled kernel
_closure_paper, _slow_rates = closure_paper.py_func, slow_rates.py_func

__all__ = ["branchwise_reference"]


def branchwise_reference(params: PeelParams, t_end: float, *, alpha0: float = 0.0, rtol: float = 1e-13):
    """The jump sequence by a second, independent method (the reference's cross-check).

    Formulation: on a stable branch the DAE (FLOW1, FLOW2, flow3, CONSTR) is an ODE in ``(α, ω, F)`` with
    ``v = v_branch(F (1 + c(α)))``, the branch inverse of fvV (solved by brentq at every field evaluation;
    the level is clipped at the fold value so that trial stages past the fold stay defined).  scipy's DOP853
    integrates it in t; the fold is the terminal event ``G = f_max`` (AB) or ``G = f_min`` (CD), located by
    scipy's event finder on the dense output, and the orbit restarts on the other branch with (α, ω, F)
    continuous.  Nothing is shared with the hybrid solver except the generated model functions: no
    desingularisation, no compiled kernel, no v state.  Near a fold ``v(G)`` has a square-root singularity,
    so this is slow and loses a few digits; it is a check, not a solver.

    The law is ``params.force``: fvV through the generated model functions, any other law through
    :meth:`peelapprox.PeelForce.f` (its numpy/scipy evaluator, independent of the compiled law kernels), its folds
    from :func:`peelapprox.branch_structure` with ``force=``, and its branch inverse by Brent's method in ln v
    over the law's range (:attr:`peelapprox.PeelForce.v_range`); a level whose root would lie outside that range
    (a table's end) raises a ValueError naming ``params.force``.

    Parameters
    ----------
    params : PeelParams
    t_end : float
        Horizon [s].
    alpha0 : float
        Initial peel angle (the rest of the initial state as :func:`exact.initial_state`).
    rtol : float
        scipy's rtol (atol = rtol times the state scale).

    Returns
    -------
    (t, F) : tuple of ndarray
        Jump times and F at the jumps.
    """
    _params("params", params)
    if params.geometry != "paper":
        raise ValueError("branchwise_reference supports geometry='paper' only")
    s0 = initial_state(params, alpha0=alpha0)
    bs = branch_structure(params.V, force=params.force)
    if not bs.has_folds:
        raise ValueError(f"params: the law {params.force!r} has no folds at V={params.V}: no jumps to reproduce")
    inverse = _paper_inverse(params, bs) if params.force.kind == "paper" else _law_inverse(params, bs)

    t, y, br = s0.t, np.array([s0.alpha, s0.omega, s0.F]), s0.branch
    # the benchmark scenes are stick-slip orbits: the folds exist and f_max is a float (BranchStructure)
    scale = np.array([1.0, params.V / params.R, float(cast(float, bs.f_max))])
    jt, jF = [], []
    while t < t_end:
        rhs, fold = _branch_system(params, bs, inverse, br)
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=rtol * scale, events=fold)
        if sol.status < 0:
            raise SolverFailure(f"branchwise reference failed at t={sol.t[-1]}: {sol.message}", t=float(sol.t[-1]),
                                state=dict(alpha=sol.y[0, -1], omega=sol.y[1, -1], F=sol.y[2, -1]))
        if sol.status == 1:
            t, y = float(sol.t_events[0][0]), sol.y_events[0][0]
            jt.append(t)
            jF.append(y[2])
            br = "CD" if br == "AB" else "AB"
        else:
            break
    return np.array(jt), np.array(jF)


def _branch_system(params: PeelParams, bs: BranchStructure, inverse: Callable[[float, str], float], branch: str):
    """On ``branch``: the field of ``(α, ω, F)`` (v from the branch inverse of ``G = F (1 + c(α))``, the level
    clipped at the fold value) and its fold, the terminal event ``G = f_max`` (AB, rising) or ``G = f_min`` (CD,
    falling)."""
    V, I, k, R, L = params.V, params.I, params.k, params.R, params.l

    def v_of(y, branch):
        c, _ = _closure_paper(y[0], R, L)
        G = y[2] * (1.0 + c)
        if branch == "AB":
            return inverse(min(G, bs.f_max), "AB"), c
        return inverse(max(G, bs.f_min), "CD"), c

    def rhs(t, y):
        v, c = v_of(y, branch)
        return list(_slow_rates(y[0], y[1], y[2], v, c, V, I, k, R))

    level = bs.f_max if branch == "AB" else bs.f_min

    def fold(t, y):
        c, _ = _closure_paper(y[0], R, L)
        return y[2] * (1.0 + c) - level

    fold.terminal = True  # type: ignore[attr-defined]
    fold.direction = 1.0 if branch == "AB" else -1.0  # type: ignore[attr-defined]
    return rhs, fold


def _paper_inverse(params: PeelParams, bs: BranchStructure) -> Callable[[float, str], float]:
    """``(G, branch) -> v`` of fvV: the package's branch inverse (Brent in ln v on AB)."""
    b, A = peel_force_coefficients(params.V)
    return lambda G, branch: branch_inverse_at(G, bs, branch, b, A)


def _law_inverse(params: PeelParams, bs: BranchStructure) -> Callable[[float, str], float]:
    """``(G, branch) -> v`` of ``params.force`` by Brent's method in ln v on :meth:`PeelForce.f`: AB in
    ``(lo, v_max]``, CD in ``[v_min, hi)`` of the law's range ``(lo, hi)``; exactly the fold at its level."""
    force, V = params.force, params.V
    lo, hi = force.v_range
    v_max, v_min = float(cast(float, bs.v_max)), float(cast(float, bs.v_min))
    w_lo, w_hi = math.log(max(lo, 1e-300)) + (1e-12 if lo > 0 else 0.0), math.log(hi) - 1e-12

    def f(w: float) -> float:
        return float(force.f(math.exp(w), V))

    def inverse(G: float, branch: str) -> float:
        if branch == "AB" and G == bs.f_max:
            return v_max
        if branch == "CD" and G == bs.f_min:
            return v_min
        a, b = (w_lo, math.log(v_max)) if branch == "AB" else (math.log(v_min), w_hi)
        fa, fb = f(a) - G, f(b) - G
        if not fa <= 0.0 <= fb:
            raise ValueError(f"params.force: the level G={G!r} N has no {branch} root of the law {force!r} at V={V} "
                             f"within its range [{lo!r}, {hi!r}] m/s (f from {fa + G!r} to {fb + G!r} N there)")
        return math.exp(brentq(lambda w: f(w) - G, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps))

    return inverse
