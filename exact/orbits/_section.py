"""The return map of the AB→CD section and its Jacobian from the saltation tangent.

**The section** is the AB→CD jump.  There the state lies on the AB fold, ``v = v_max``, so CONSTR fixes
``F = f_max / (1 + c(α))`` and the section is two-dimensional: ``x = (α, ω)``.  The return map ``P`` takes
the state at one AB→CD jump to the state at the next: the jump to ``v_land_cd`` on CD, CD to its fold
``v_min``, the jump to ``v_land_ab``, AB to its fold ``v_max``.  A period-n orbit is a fixed point of ``P^n``
(:mod:`exact.orbits._periodic`).

**The Jacobian** ``DP`` comes from the tangent dynamics of the hybrid solver's desingularised field in the
parameter s (:mod:`exact._tangent`: state ``(t, α, ω, u = ln v)`` and one tangent, integrated together by the
package's DOP853, with the field's analytic Jacobian, :mod:`exact._jacobian`), with the saltation matrix at the CD→AB
jump.  A perturbation ``(δα, δω)`` of the section state starts as ``δy = (0, δα, δω, 0)`` after the AB→CD
jump (the jump keeps (α, ω) and sets v, so δu = 0); at the next AB fold the field is ``(0, 0, 0, Ġ)`` (dt/ds,
dα/ds, dω/ds vanish with f'), so the projection of the tangent onto the section along the flow only drops δu:
``(δα, δω)`` there is the column of ``DP``, and δt the change of the return time.  Two tangent runs give the
two columns.  Finite differences of ``P`` are the cross-check (:func:`monodromy_fd`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from peelapprox import BREAKDOWN_LEVEL, PeelParams
from peelapprox.errors import SolverFailure
from peelapprox.kernels import M_R
from peelapprox.kernels import status as _st

from .._tangent import TangentSystem, tangent_system

__all__ = ["Composed", "Iterated", "SectionReturn", "TangentReturn", "compose", "monodromy_fd", "section_return",
           "section_return_n", "section_F", "system_of"]

#: Relative tolerance of the tangent runs, whatever the state's ``rtol``: the tangent's directional difference
#: quotient carries ~1e-9 relative noise, which a tighter error control would chase with ever smaller steps.
TANGENT_RTOL = 1e-10
#: Absolute tolerance of the tangent components (unit vectors of the scaled section coordinates
#: ``(α, ω R/V)`` at the start of a return).
TANGENT_ATOL = 1e-10
#: Accepted steps allowed for one leg (one branch stay) of a return.
LEG_STEPS = 10_000_000
#: Longest stay on one branch [s] before a return is given up.
LEG_TIME = 1e4


@dataclass(frozen=True)
class SectionReturn:
    """One application of the return map ``P`` (module docstring).

    Attributes
    ----------
    x : ndarray, shape (2,)
        ``(α, ω)`` at the next AB→CD jump.
    jacobian : ndarray, shape (2, 2) or None
        ``∂x/∂x0`` (None when the tangent was not integrated).
    time : float
        The return time [s].
    dtime : ndarray, shape (2,) or None
        ``∂(return time)/∂x0``.
    steps : int
        Accepted steps (all tangent runs).
    fold_rates : (float, float)
        ``Ġ = d(F (1 + c))/dt`` on arrival at the CD fold and at the AB fold [N/s]: how transversally the orbit
        meets the folds (0: it grazes a fold, where the return map's derivative diverges).
    """

    x: np.ndarray
    jacobian: np.ndarray | None
    time: float
    dtime: np.ndarray | None
    steps: int
    fold_rates: tuple[float, float] = (math.nan, math.nan)


class TangentReturn(NamedTuple):
    """One return ``P(x)`` with one tangent ``(δα, δω)`` carried along (:func:`_one_return`)."""

    x: np.ndarray
    """``(α, ω)`` at the next AB→CD jump."""
    dx: np.ndarray
    """The tangent's ``(δα, δω)`` there."""
    dtime: float
    """The tangent's change of the return time."""
    time: float
    """The return time [s]."""
    steps: int
    fold_rates: tuple[float, float]
    """``Ġ`` on arrival at the CD fold and at the AB fold [N/s]."""


class Composed(NamedTuple):
    """``P^n`` at a section state with its Jacobian (:func:`compose`)."""

    x: np.ndarray
    """``P^n(x)``."""
    jacobian: np.ndarray
    """``DP^n`` in ``(α, ω)``."""
    period: float
    """The time of the n returns [s]."""
    states: np.ndarray
    """The n section states visited, the start first, shape (n, 2)."""
    steps: int
    fold_rates: np.ndarray
    """The 2n fold rates ``Ġ`` [N/s] (CD, AB, CD, ...)."""


class Iterated(NamedTuple):
    """``P^n`` at a section state without the tangent (:func:`section_return_n`)."""

    x: np.ndarray
    steps: int


def _leg(ts: TangentSystem, y: np.ndarray, br: int, rtol: float, atol: np.ndarray, t0: float) -> int:
    """Integrate ``y`` (state and tangent) on branch ``br`` to its fold; raise the status's exception else."""
    law = ts.law
    y0 = y.copy()
    try:
        status, n = ts.run(y, ts.p, law.arg, law.coef, br, rtol, atol, LEG_TIME, LEG_STEPS)
    except (ZeroDivisionError, OverflowError) as exc:  # a state the field's Jacobian cannot take (e.g. a wild
        v0 = math.exp(y0[3])                            # Newton iterate): the return does not exist there
        raise SolverFailure(f"section return: the tangent integration failed ({type(exc).__name__}: {exc}) "
                            f"from alpha={y0[1]:.6g} rad, omega={y0[2]:.6g} rad/s on {'AB' if br == 0 else 'CD'}",
                            t=t0, state=dict(t=t0, alpha=float(y0[1]), omega=float(y0[2]),
                                             F=float(ts.pull(y0[1], v0)), v=v0)) from None
    if status != _st.FOLD:
        v = math.exp(y[3])
        state = dict(t=t0 + y[0], alpha=float(y[1]), omega=float(y[2]), F=float(ts.pull(y[1], v)), v=v,
                     branch="AB" if br == 0 else "CD")
        if status == _st.DONE:
            raise SolverFailure(f"section return: no fold reached on {state['branch']} within {LEG_TIME:g} s",
                                t=state["t"], state=state)
        raise _st.status_error(status, t=state["t"], state=state, prefix="section return: ", limit=LEG_STEPS,
                               f_zero=law.structure.f_zero, level=BREAKDOWN_LEVEL, v=v, lo=law.domain[0],
                               hi=law.domain[1],
                               law=repr(law.force), v_ceiling=math.inf, what="v left the law's domain")
    return int(n)


def _one_return(ts: TangentSystem, x: np.ndarray, d: np.ndarray, rtol: float, atol: np.ndarray) -> TangentReturn:
    """``P(x)`` with the tangent ``d = (δα, δω)`` carried along."""
    y = np.array([0.0, x[0], x[1], math.log(ts.landing(0)), 0.0, d[0], d[1], 0.0])
    steps = _leg(ts, y, 1, rtol, atol, 0.0)
    t_cd = float(y[0])
    rate_cd = ts.jump(y, 1)  # Ġ on arrival at the CD fold (< 0: the level falls to f_min)
    if rate_cd is None:
        v = math.exp(y[3])
        raise _st.status_error(_st.NO_LANDING, t=t_cd, state=dict(t=t_cd, alpha=float(y[1]), omega=float(y[2]),
                               F=float(ts.pull(y[1], v)), v=v, branch="CD"), prefix="section return: ",
                               f_min=ts.law.structure.f_min, f_zero=ts.law.structure.f_zero)
    steps += _leg(ts, y, 0, rtol, atol, t_cd)
    gm = np.empty(4)
    ts.field(y[:4], gm)
    return TangentReturn(y[1:3].copy(), y[5:7].copy(), float(y[4]), t_cd + float(y[0]), steps,
                         (rate_cd, float(gm[3])))


def section_return(params: PeelParams, x: Any, *, rtol: float = 1e-12, tangent: bool = True,
                   system: TangentSystem | None = None) -> SectionReturn:
    """The return map ``P`` of the AB→CD section at ``x = (α, ω)`` (module docstring).

    Parameters
    ----------
    params : PeelParams
        Any law with folds at ``params.V``.
    x : sequence of 2 floats
        ``(α [rad], ω [rad/s])`` at an AB→CD jump.
    rtol : float
        Relative tolerance of the state's integration (its absolute tolerances scale with it as in
        ``exact.simulate``); the tangent runs use ``max(rtol, TANGENT_RTOL)`` and :data:`TANGENT_ATOL`.
    tangent : bool
        Also integrate the two tangent columns (``jacobian``, ``dtime``).

    Returns
    -------
    SectionReturn

    Raises
    ------
    ValueError
        Bad arguments, or a law without folds at V (no section).
    ModelBreakdown, SolverBudgetExceeded, SolverFailure
        The orbit breaks down or does not return.
    """
    from .._methods import ATOL_SCALE

    ts = system or system_of(params)
    x0 = np.asarray(x, dtype=float).reshape(2)
    scale = np.asarray(ATOL_SCALE["hybrid"])
    atol = np.concatenate([rtol * scale, np.ones(4)])  # the tangent stays 0: its weights do not matter
    r = _one_return(ts, x0, np.zeros(2), rtol, atol)  # the state alone, at rtol
    if not tangent:
        return SectionReturn(r.x, None, r.time, None, r.steps, r.fold_rates)
    jrt = max(rtol, TANGENT_RTOL)
    atol_t = np.concatenate([jrt * scale, np.full(4, TANGENT_ATOL)])
    cols, dts, steps = [], [], r.steps
    s = np.array([1.0, ts.law.V / float(ts.p[M_R])])  # unit vectors of z = (α, ω R/V): balanced columns
    for i in range(2):
        d = np.zeros(2)
        d[i] = s[i]
        t = _one_return(ts, x0, d, jrt, atol_t)
        cols.append(t.dx / s[i])
        dts.append(t.dtime / s[i])
        steps += t.steps
    return SectionReturn(r.x, np.column_stack(cols), r.time, np.array(dts), steps, r.fold_rates)


def system_of(params: PeelParams) -> TangentSystem:
    ts = tangent_system(params)
    if not ts.law.structure.has_folds:
        raise ValueError(f"params: f(v, V={params.V}) has no folds (no stick-slip): there is no AB->CD section")
    return ts


def section_F(params: PeelParams, ts: TangentSystem, alpha: np.ndarray) -> np.ndarray:
    """F at the AB→CD jump: ``f_max / (1 + c(α))`` (CONSTR on the fold)."""
    return float(ts.law.structure.f_max) / (1.0 + np.asarray(params.closure(np.asarray(alpha))[0]))


def compose(params: PeelParams, ts: TangentSystem, x: np.ndarray, n: int, rtol: float) -> Composed:
    """``P^n(x)`` with ``DP^n``, the period, the n section states, the steps and the 2n fold rates."""
    J = np.eye(2)
    T, steps, states = 0.0, 0, [x.copy()]
    rates: list[float] = []
    for _ in range(n):
        r = section_return(params, x, rtol=rtol, system=ts)
        assert r.jacobian is not None
        J = r.jacobian @ J
        T += r.time
        steps += r.steps
        x = r.x
        states.append(x.copy())
        rates.extend(r.fold_rates)
    return Composed(x, J, T, np.array(states[:-1]), steps, np.array(rates))


def section_return_n(params: PeelParams, ts: TangentSystem, x: np.ndarray, n: int, rtol: float) -> Iterated:
    """``P^n(x)`` and the steps taken, without the tangent."""
    steps = 0
    for _ in range(n):
        r = section_return(params, x, rtol=rtol, tangent=False, system=ts)
        x, steps = r.x, steps + r.steps
    return Iterated(x, steps)


def monodromy_fd(params: PeelParams, x: Any, n: int, *, h: float = 1e-5, rtol: float = 1e-12) -> np.ndarray:
    """``DP^n`` at ``x = (α, ω)`` by fourth-order central differences of the return map (the cross-check of the
    tangent's Jacobian): steps ``h`` in α and ``h V/R`` in ω, ``(-P(2e) + 8 P(e) - 8 P(-e) + P(-2e)) / 12e``."""
    ts = system_of(params)
    x = np.asarray(x, dtype=float).reshape(2)
    s = np.array([1.0, params.V / params.R])
    cols = []
    for i in range(2):
        e = np.zeros(2)
        e[i] = h * s[i]
        Pn = [section_return_n(params, ts, x + k * e, n, rtol).x for k in (2, 1, -1, -2)]
        cols.append((-Pn[0] + 8 * Pn[1] - 8 * Pn[2] + Pn[3]) / (12 * e[i]))
    return np.column_stack(cols)
