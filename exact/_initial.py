"""The consistent initial state of a run (:func:`initial_state`): ``α, ω, F`` and v the root of CONSTR on a branch."""

from __future__ import annotations

import math

from peelapprox import (
    BRANCHES,
    F0_FACTOR,
    STATE_RANGES,
    TIME_MAX,
    BranchStructure,
    PeelParams,
    branch_inverse,
    branch_structure,
    peel_force,
)
from peelapprox.kernels import CompiledLaw, compiled_law
from peelapprox.validate import choice, in_range, interval, optional, shown, state
from peelapprox.validate import params as _params

from ._trajectory import State

__all__ = ["initial_state", "law_for"]


def law_for(params: PeelParams) -> CompiledLaw:
    """The peel-force law of ``params`` compiled at ``params.V`` (:func:`peelapprox.kernels.compiled_law`);
    ValueError naming ``params.force`` if its AB→CD jumps could not land (a table that stops below ``f_max`` on
    CD), or as ``compiled_law`` raises."""
    law = compiled_law(params.force, params.V)
    bs = law.structure
    if bs.has_folds and bs.v_land_cd is None:
        raise ValueError(f"params.force: {params.force!r} at V={params.V!r} m/s never reaches f_max={bs.f_max!r} N "
                         f"on its fast branch within its domain up to {law.domain[1]!r} m/s: an AB->CD jump could not "
                         "land (extend the table to higher v)")
    return law


def initial_state(
    params: PeelParams,
    *,
    alpha0: float = 0.0,
    omega0: float | None = None,
    F0: float | None = None,
    branch0: str | None = None,
    t0: float = 0.0,
) -> State:
    """The consistent initial state used by :func:`simulate`.

    Defaults (documented behaviour): ``α = 0``, ``ω = V/R``,
    ``F = 1.01 f(V, V)`` and v the lowest-velocity stable root of CONSTR,
    ``f(v, V) = F (1 - cos θ)``: on AB if the level lies in AB's range
    ``(f(0+), f_max]``, otherwise on CD.  f is the law ``params.force`` (the paper's fvV, or a cubic, whose
    folds are :func:`peelapprox.kernels.cubic_v_structure`'s and whose root is found in ln v by Brent's method).

    Parameters
    ----------
    params : PeelParams
        The model's parameters (V, I, k, R, l, geometry).
    alpha0 : float
        Peel angle α [rad], in ``STATE_RANGES["alpha"]``.
    omega0 : float, optional
        Roller angular velocity ω [rad/s]; None: ``V/R`` (the roller turning with the pull).
    F0 : float, optional
        Pull force F [N]; None: ``1.01 f(V, V)``, just above steady sliding.
    branch0 : {"AB", "CD"}, optional
        The branch v is taken on; None: AB when the level has a root there, else CD.
    t0 : float
        Initial time [s], in ``[0, TIME_MAX]``.

    Returns
    -------
    State
        ``t, alpha, omega, F, v, branch`` with v solving CONSTR on the branch (consistent: the DAE starts on
        its constraint manifold).

    Raises
    ------
    ValueError
        Naming the argument and its valid range, if the level
        ``F0 (1 - cos θ(α0))`` has no root on the requested branch (or on
        any branch), or if ``1 - cos θ(α0) <= 0``; or, when F0 is not given,
        if the default ``1.01 f(V, V)`` is outside ``STATE_RANGES["F"]`` (a
        law in other units than newtons, or with coefficients like 1e300).
        A message about a value the caller did not pass says that the
        default was used.
    """
    _params("params", params)
    a0 = state("alpha0", alpha0, "alpha")
    w0 = params.V / params.R if omega0 is None else state("omega0", omega0, "omega")
    law = None if params.force.kind == "paper" else law_for(params)  # another law: its compiled form
    F, f0 = _start_force(params, law, F0)
    t0 = in_range("t0", t0, 0.0, TIME_MAX)
    branch0 = optional(choice, "branch0", branch0, BRANCHES)
    at = f"alpha0={a0!r}" + (" (the default)" if a0 == 0.0 else "")
    c = float(params.closure(a0)[0])
    if not (1.0 + c > 0.0):
        raise ValueError(f"alpha0={a0!r} makes 1 - cos(theta) = {1 + c} <= 0: alpha0 must keep 1 + sin(alpha0) > 0")
    G = F * (1.0 + c)
    bs = branch_structure(params.V) if law is None else law.structure
    branch0 = _start_branch(bs, G, branch0, f0, at, c)
    if law is None:
        v = branch_inverse(G, params.V, branch0)
    else:
        try:
            v = law.branch_root(G, branch0)
        except ValueError as exc:  # the root beyond the law's domain: say which F0 asked for it
            raise ValueError(f"{f0} at {at} gives the level F0*(1 - cos theta)={G} on branch0={branch0!r} of "
                             f"params.force={shown(params.force)}, but {exc}: give an F0 whose level has its root in "
                             "the law's v range, or a law whose v range holds it") from None
    return State(float(t0), a0, w0, F, float(v), branch0)


def _start_force(params: PeelParams, law: CompiledLaw | None, F0: float | None) -> tuple[float, str]:
    """The start's pull force ``F0`` checked, or its default ``1.01 f(V, V)`` of the law (None: the paper's), and
    how a message names it."""
    if law is None:
        fVV = float(peel_force(params.V, params.V))
    elif F0 is None and not law.domain[0] <= params.V <= law.domain[1]:
        raise ValueError(f"F0 was not given, and its default 1.01 f(V, V) needs f at v=V={params.V!r} m/s, outside "
                         f"the domain {law.domain} m/s of params.force={shown(params.force)}: give F0")
    else:
        fVV = law.f(params.V)
    if F0 is not None:
        F = state("F0", F0, "F")
        return F, f"F0={F!r}"
    F = F0_FACTOR * fVV
    f_lo, f_hi = STATE_RANGES["F"]
    if not (math.isfinite(F) and f_lo <= F <= f_hi):
        raise ValueError(f"F0 was not given, so its default 1.01 f(V, V) = {F:.6g} N was used (f of params.force="
                         f"{shown(params.force)} at V={params.V!r} m/s), outside STATE_RANGES['F'] = "
                         f"{interval(f_lo, f_hi)} N, the pull forces the solvers are built for: give F0 in that "
                         "range, or a law in newtons whose f(V, V) lies in it")
    return F, f"F0 (not given: the default 1.01 f(V, V) = {F!r} N)"


def _start_branch(bs: BranchStructure, G: float, branch0: str | None, f0: str, at: str, c: float) -> str:
    """The branch of the start: ``branch0`` checked to hold a root of the level G, or (None) the lowest that
    does (ValueError naming F0 and its valid range otherwise)."""
    if branch0 is None:
        for cand in ("AB", "CD") if bs.has_folds else ("AB",):
            if bs.has_root(G, cand):
                branch0 = cand
                break
        else:
            raise ValueError(
                f"{f0} gives F0*(1 - cos theta)={G}, below f(0+, V)={bs.f_zero}: no stable root of CONSTR; "
                f"F0 must exceed {bs.f_zero / (1 + c)} at {at}"
            )
    if branch0 not in BRANCHES:
        raise ValueError(f"branch0 must be 'AB' or 'CD' (or None for the lowest root), got {branch0!r}")
    lo, hi = bs.level_range(branch0)  # raises for CD without folds
    if not bs.has_root(G, branch0):
        raise ValueError(
            f"{f0} at {at} gives the level F0*(1 - cos theta)={G}, which has no root on branch0={branch0!r}; "
            f"valid F0 range on {branch0}: ({lo / (1 + c)}, {hi / (1 + c)})"
        )
    return branch0
