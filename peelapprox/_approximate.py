"""The stick-slip attractor predicted from the paper's reduced branch-wise equations alone (no DAE solve).

:func:`approximate_attractor` chains the reduced segments of :mod:`peelapprox._segment` (Sec. V of the paper:
an α model coupled to the velocity equation approxvdot or fullvdot) into a return map and iterates it to its
attractor:

1. **AB**: from the landing velocity ``v_land_ab`` the α model and the v equation are integrated until v reaches
   the fold ``v_max`` (CONSTR linearised, ``F(1 + α) = f(v)``, reaches ``f_max``).  With an oscillating α that
   happens at a crest of the oscillation, before the quasi-static force reaches ``f_max``: the exit is the
   transversal event ``ln v = ln v_max`` of the desingularised field (``dt/ds = v f'``), met on the way up
   whatever drives v there; a crest that stays below ``f_max`` turns v back and the segment goes on.
2. **AB→CD jump**: F and α continuous (the fast fibre of the ε → 0 limit), v to the landing ``v_land_cd``, and
   the roller's angular velocity ``ω = α̇ + v/R`` continuous (FLOW1; the hybrid solver's jump), so
   ``α̇ → α̇ - (v_land_cd - v_max)/R``.
3. **CD**: the CD α model and v equation from ``v_land_cd`` until v falls to ``v_min``.
4. **CD→AB jump**: likewise, ``α̇ → α̇ + (v_min - v_land_ab)/R``.

The map starts where the exact solver does, and again at rest on the relaxation cycle's foot where that start
finds no periodic attractor (:func:`approximate_attractor`).  The force at each jump and the jump times
make the same jump record an exact trajectory has, and the observables are read off it by
:func:`peelapprox._observables.jump_statistics`, the one definition both sides use.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from ._observables import StickSlipObservables, jump_statistics
from ._params import PeelParams
from ._ranges import F0_FACTOR
from ._regime import regime
from ._segment import SegmentPlan, run_segment, segment_plan, segment_status
from ._segment_kernel import ALPHA_MODELS, AM_EXP, AM_HARM, AM_SIN, AM_STATIC, V_EQUATIONS, alpha_at
from ._status import DONE, F_NONPOSITIVE, LAW_DOMAIN, MAX_STEPS, NONFINITE, STATUS, STEP_FAIL, T_MAX, V_CEILING, V_FLOOR
from .io import fmt_number
from .law import fixed_point
from .law._compiled import compiled_law
from .validate import choice, integer, optional, positive
from .validate import params as _params
from .validate import rtol as _rtol

__all__ = ["APPROX_DEFAULTS", "EARLY_RETURNS", "PERIOD_RTOL", "SEGMENT_MAX_STEPS", "STARTS", "approximate_attractor",
           "default_models"]

#: The default reductions per inertia label of :func:`peelapprox.estimate` (:data:`peelapprox.INERTIA_RULE`):
#: ``{inertia: ((AB α model, AB v equation), (CD α model, CD v equation))}``; the table and its reasons are in
#: the docstring of :func:`approximate_attractor`.
APPROX_DEFAULTS: dict[str, tuple[tuple[str, str], tuple[str, str]]] = {
    "low": (("airy1", "approxvdot"), ("airy1", "approxvdot")),
    "intermediate": (("airy1", "approxvdot"), ("airy1", "approxvdot")),
    "high": (("airy1", "approxvdot"), ("airy1", "approxvdot")),
}

#: Where the map starts (``start=``): ``"solver"``, the exact solver's default start; ``"rest"``, the foot of the
#: relaxation cycle at rest (AB landing, F = f_min, α = α̇ = 0); ``"auto"``, the solver's start and, where that
#: reaches no periodic attractor, the rest start (:func:`approximate_attractor`).
STARTS = ("auto", "solver", "rest")

#: The map stops early once its last ``max(EARLY_RETURNS, 3 n)`` returns repeat with a period n <= 12 to the
#: period tolerance (:data:`PERIOD_RTOL`) and their mismatch is not growing: a periodic attractor has then been
#: reached, and further returns would only repeat it.  An escape slower than that from an unstable small orbit
#: is not told apart (V = 4.31, I = 7.2e-4: the map's returns stay within 303 to 306 N for 500 returns, spread to
#: 298 to 311 N after 2000; docs/theory.md, "The approximate attractor").
EARLY_RETURNS = 12
#: The tolerance of the returns' period, ``max(PERIOD_RTOL, 100 rtol)`` relative to the largest return.  Some
#: reduced maps approach their periodic orbit slowly: after 60 transient returns ``max|x_{k+n} - x_k|/max|x|`` is
#: 5e-6 to 8e-5 at six low-inertia points (V = 0.89 to 4.3 m/s, I = 1e-6 and 5e-6), the same at rtol 1e-6, 1e-8
#: and 1e-10 (convergence, not integration error).  1e-4 calls them periodic; their means are then within ~1e-4
#: of the limit's, far inside the reductions' errors, and an aperiodic map's returns differ by 1e-3 or more.
PERIOD_RTOL = 1e-4
#: Step budget of one segment: the most step-hungry stays (I = 1e-6, V = 0.5, ~190 α oscillations on AB) take
#: ~2000 steps at rtol 1e-6.
SEGMENT_MAX_STEPS = 200_000


def default_models(params: PeelParams) -> tuple[tuple[str, str], tuple[str, str]]:
    """The regime's ``((AB α model, AB v equation), (CD α model, CD v equation))`` (:data:`APPROX_DEFAULTS`); the
    low-inertia pair where the law has no folds at V (nothing runs there)."""
    inertia, _ = regime(params)
    return APPROX_DEFAULTS.get(inertia, APPROX_DEFAULTS["low"])


def approximate_attractor(
    params: PeelParams,
    *,
    alpha_model: str | None = None,
    v_equation: str | None = None,
    cd_alpha_model: str | None = None,
    cd_v_equation: str | None = None,
    start: str = "auto",
    n_transient: int = 40,
    n_returns: int = 60,
    rtol: float = 1e-6,
    max_wall: float | None = 10.0,
) -> StickSlipObservables:
    """The stick-slip attractor predicted by the paper's reduced branch-wise equations, without the DAE.

    Iterates the reduced return map (module docstring: AB segment to the fold, jump, CD segment to the fold,
    jump) and reads the observables off its jumps with the definitions of :class:`StickSlipObservables` (slip
    interval, force drop, slip and stick times, F at the jumps, the return map's period).

    The map starts where :func:`exact.simulate` does (:func:`exact.initial_state`); that start's kick
    ``α̇ = (V - v)/R`` can hold the map on a small mode around the unstable fixed point which the exact run
    leaves only after thousands of slips, so where it reaches no periodic attractor the map starts again at rest
    on the relaxation cycle's foot.  The default reductions, Airy1 + approxvdot on both branches,
    keep FLOW1's kinematic term ``-v̇/R``, large near the folds, and measured best on a
    40 x 40 grid of the paper's law (94 % of the low-inertia, low-V points within 10 % of the exact slip
    interval and force drop, against 77 % for the paper's Case I).  docs/theory.md, "The approximate
    attractor", has the measurements of both choices.

    Parameters
    ----------
    params : PeelParams
        The paper's model (no tape mass or load: the reduced equations are the massless DAE's), any law with a
        compiled kernel.  The reduced equations are linear in α whatever ``params.geometry``.
    alpha_model, v_equation, cd_alpha_model, cd_v_equation : str, optional
        AB's and CD's α model (:data:`peelapprox.ALPHA_MODELS`) and v equation (:data:`peelapprox.V_EQUATIONS`),
        any combination; each None is the default (:data:`APPROX_DEFAULTS`).
    start : {"auto", "solver", "rest"}
        Where the map starts (:data:`STARTS`): ``"auto"`` the solver's, then at rest if need be (above).
    n_transient : int
        Returns (AB→CD jumps) discarded before the sample, an integer in [0, 10**6] (40).
    n_returns : int
        Returns in the sample, in [3, 10**6] (60); fewer once they repeat with a period n <= 12 over the last
        ``max(12, 3n)`` (:data:`EARLY_RETURNS`): an attractor reached.
    rtol : float
        Relative tolerance of each segment (1e-6: the observables agree with rtol 1e-10 to 1e-4, far inside the
        reductions' own errors); the returns' period tolerance is :data:`PERIOD_RTOL`.
    max_wall : float or None
        Wall-clock budget [s] (10; None: unbounded), checked between segments, each with a step budget.

    Returns
    -------
    StickSlipObservables
        ``method`` names the chain, the start and the sample, ``t_start``/``t_end`` are on the map's own clock.
        ``status``: ``"stick-slip"``; ``"steady"`` (no folds at V, or a segment settles on the stable fixed
        point); ``"no attractor"`` (a budget spent first) or ``"breakdown"`` (of a reduced segment), with the
        reason.  Every mean is None for the last three, never NaN.

    Raises
    ------
    ValueError
        An unknown model, a value out of range, a model variant or a law without a compiled kernel (named).
    peelapprox.validate.ArgumentTypeError
        (also a TypeError) An argument of the wrong kind.
    """
    t_wall = time.perf_counter()
    params = _params("params", params, variants=False)
    chosen = (optional(choice, "alpha_model", alpha_model, ALPHA_MODELS),
              optional(choice, "v_equation", v_equation, V_EQUATIONS),
              optional(choice, "cd_alpha_model", cd_alpha_model, ALPHA_MODELS),
              optional(choice, "cd_v_equation", cd_v_equation, V_EQUATIONS))
    n_transient = integer("n_transient", n_transient, lo=0, hi=10**6)
    n_returns = integer("n_returns", n_returns, lo=3, hi=10**6)
    start = choice("start", start, STARTS)
    rtol = _rtol("rtol", rtol)
    max_wall = optional(positive, "max_wall", max_wall)
    law = compiled_law(params.force, params.V)  # ValueError naming params.force for a law without a kernel
    bs = law.structure
    common: dict[str, Any] = dict(V=float(params.V), I=float(params.I), t_start=None, t_end=None)
    if not bs.has_folds:
        return StickSlipObservables._no_slip(
            status="steady", method="approximate: no folds, nothing to chain", **common,
            reason=f"the law has no folds at V = {fmt_number(params.V, 4)} m/s (f increases in v): steady peeling "
                   "at the stable fixed point v = V")
    (ab_am, ab_ve), (cd_am, cd_ve) = default_models(params)
    ab_am, ab_ve = chosen[0] or ab_am, chosen[1] or ab_ve
    cd_am, cd_ve = chosen[2] or cd_am, chosen[3] or cd_ve
    chain = f"approximate: AB {ab_am}/{ab_ve}, CD {cd_am}/{cd_ve}"
    if bs.v_land_ab is None or bs.v_land_cd is None:
        which = "AB (f_min <= f(0+, V))" if bs.v_land_ab is None else "CD (the law's domain ends below f_max)"
        return StickSlipObservables._no_slip(status="breakdown", method=chain, **common,
                                             reason=f"a jump has no landing on {which}: no return map")
    assert bs.v_max is not None and bs.v_min is not None  # has_folds
    models = ((ab_am, ab_ve), (cd_am, cd_ve))
    if start == "rest":
        return _iterate(params, law, models, _rest(law), n_transient, n_returns, rtol, max_wall, t_wall,
                        f"{chain}, rest start", common)[0]
    first, periodic = _iterate(params, law, models, _solver_start(params, law), n_transient, n_returns, rtol,
                               max_wall, t_wall, f"{chain}, solver's start", common)
    if start == "solver" or first.status != "stick-slip" or periodic:
        return first
    second, _ = _iterate(params, law, models, _rest(law), n_transient, n_returns, rtol, max_wall, t_wall,
                         f"{chain}, rest start (the solver's: no periodic attractor in {n_transient + n_returns} "
                         "returns)", common)
    return second if second.status == "stick-slip" else first


def _plan(params: PeelParams, law: Any, branch: str, v_in: float, models: tuple[str, str], rtol: float
          ) -> SegmentPlan:
    bs = law.structure
    return segment_plan(params, law, branch, v_in=v_in, v_f=bs.v_max if branch == "AB" else bs.v_min,
                        alpha_model=models[0], v_equation=models[1], F_rate=None, rtol=rtol, t_max=None,
                        max_steps=SEGMENT_MAX_STEPS)


#: A start of the map: ``(branch code (0 AB, 1 CD), F, v, α, α̇)``.
Start = tuple[int, float, float, float, float]


def _rest(law: Any) -> Start:
    """The foot of the relaxation cycle at rest: the AB landing ``v_land_ab`` with ``F = f_min``, ``α = α̇ = 0``."""
    bs = law.structure
    return 0, float(bs.f_min), float(bs.v_land_ab), 0.0, 0.0


def _solver_start(params: PeelParams, law: Any) -> Start:
    """The exact solver's default start (:func:`exact.initial_state`, α = 0, ω = V/R so α̇ = (V - v)/R): F = F0_FACTOR
    f(V, V) on the branch with the lowest root; the AB landing with F = f_min where f(V) is outside the law's
    domain or the level has no root."""
    bs = law.structure
    lo, hi = law.domain
    kick = lambda v: (params.V - v) / params.R  # noqa: E731
    if lo <= params.V <= hi:
        F = F0_FACTOR * law.f(params.V)
        for code, branch in enumerate(("AB", "CD")):
            if bs.has_root(F, branch):
                try:
                    v = law.branch_root(F, branch)
                except ValueError:  # the CD root beyond a table's range
                    break
                lo_b, hi_b = bs.branch_range(branch)
                if lo_b < v < hi_b:
                    return code, F, v, 0.0, kick(v)
                break
    return 0, float(bs.f_min), float(bs.v_land_ab), 0.0, kick(float(bs.v_land_ab))


def _iterate(params: PeelParams, law: Any, models: tuple[tuple[str, str], tuple[str, str]], start: Start,
             n_transient: int, n_returns: int, rtol: float, max_wall: float | None, t_wall: float, chain: str,
             common: dict[str, Any]) -> tuple[StickSlipObservables, bool]:
    """Iterate the map (module docstring) from ``start``: its sample's observables, and whether it stopped early
    on a periodic attractor."""
    ab, cd = models
    bs = law.structure
    R = params.R
    plans = (_plan(params, law, "AB", bs.v_land_ab, ab, rtol), _plan(params, law, "CD", bs.v_land_cd, cd, rtol))
    # the jump of ω-continuity: α̇ after = α̇ before + (v before - v after)/R
    kick = ((bs.v_max - bs.v_land_cd) / R, (bs.v_min - bs.v_land_ab) / R)
    closed = {AM_SIN, AM_HARM, AM_EXP, AM_STATIC}
    branch, F, v0, a, ad = start
    t = 0.0
    first: SegmentPlan | None = None
    if v0 != plans[branch].v_in:
        first = _plan(params, law, ("AB", "CD")[branch], v0, (ab, cd)[branch], rtol)
    jt: list[float] = []
    jF: list[float] = []
    jb: list[int] = []
    returns: list[float] = []  # F at the AB→CD jumps
    ret_at: list[int] = []  # their indices in the jump record
    total = n_transient + n_returns
    ptol = max(PERIOD_RTOL, 100.0 * rtol)
    sample_from: int | None = None
    early = (0, 0)  # (period, returns) when the map stopped early
    while len(returns) < total:
        plan = first if first is not None else plans[branch]
        first = None
        run = run_segment(plan, F, a, ad)
        if run.code != DONE:
            return _failed(params, plan, run, len(returns), t, chain, common), False
        y = run.y
        t += float(y[0])
        F = float(y[2])
        a, ad = alpha_at(y, run.q) if plan.alpha_model in closed else (float(y[3]), float(y[4]))
        jt.append(t)
        jF.append(F)
        jb.append(branch)
        ad += kick[branch]
        if branch == 0:
            returns.append(F)
            ret_at.append(len(jt) - 1)
            n = _repeats(returns, ptol)
            if n is not None:
                sample_from, early = ret_at[-max(EARLY_RETURNS, 3 * n)], (n, len(returns))
                break
        branch = 1 - branch
        if max_wall is not None and time.perf_counter() - t_wall > max_wall:
            return StickSlipObservables._no_slip(
                status="no attractor", method=chain, **common,
                reason=f"max_wall = {fmt_number(max_wall, 3)} s spent after {len(returns)} of the {total} returns "
                       f"(n_transient + n_returns)"), False
    if sample_from is None:
        sample_from = ret_at[n_transient]
        how = f"{n_returns} returns after {n_transient}"
    else:
        how = f"period-{early[0]} reached after {early[1]} returns"
    T, FF, B = (np.asarray(x[sample_from:]) for x in (jt, jF, jb))
    n_ret = int(np.count_nonzero(B == 0))
    stats, cycles = jump_statistics(T, FF, B, period_rtol=ptol, max_period=max(1, min(32, n_ret // 3)))
    method = f"{chain}, {how}, rtol {fmt_number(rtol, 3)}"
    common = {**common, "t_start": float(T[0]), "t_end": float(T[-1])}
    reason = (f"{stats['n_slips']} slips of the reduced return map ({how}), return map {stats['period_label']}"
              + (f"; means over the last {cycles} whole cycles" if cycles is not None else ""))
    return StickSlipObservables(status="stick-slip", reason=reason, method=method, **stats, **common), early[0] > 0


def _repeats(x: list[float], tol: float) -> int | None:
    """The period n <= 12 with which the last ``max(EARLY_RETURNS, 3 n)`` returns repeat to ``tol`` (relative to
    their largest) without their mismatch ``|x_{k+n} - x_k|`` growing from the first half of them to the second
    (beyond a 1e-9 noise floor), or None; a scalar test of the newest return first, numpy only for a candidate."""
    r = len(x)
    if r < EARLY_RETURNS:
        return None
    last = x[-1]
    scale = abs(last)
    for n in range(1, 13):
        m = max(EARLY_RETURNS, 3 * n)
        if m > r:
            return None
        if abs(last - x[-1 - n]) <= tol * scale:
            tail = np.asarray(x[-m:])
            d = np.abs(tail[n:] - tail[:-n])
            h = d.size // 2
            top = float(np.max(np.abs(tail)))
            # within tol, and not growing: a slow escape from an unstable orbit (returns drifting away from the
            # unstable fixed point by less than tol per return at first) is not an attractor reached
            if float(d.max()) <= tol * top and float(d[h:].max()) <= max(float(d[:h].max()), 1e-9 * top):
                return n
    return None


def _failed(params: PeelParams, plan: SegmentPlan, run: Any, n_returns: int, t: float, chain: str,
            common: dict[str, Any]) -> StickSlipObservables:
    """The observables of a map stopped by a segment that did not reach its fold: steady, no attractor or
    breakdown (:func:`approximate_attractor`'s statuses)."""
    code = segment_status(plan, run.code)
    y = run.y
    v, F = math.exp(float(y[1])), float(y[2])
    where = (f"the {plan.branch} segment entered at t = {fmt_number(t, 6)} s on the map's clock (after {n_returns} "
             f"returns) stopped at v = {fmt_number(v, 4)} m/s, F = {fmt_number(F, 5)} N, {fmt_number(float(y[0]), 4)} "
             "s after its entry")
    if code == T_MAX:
        fp = fixed_point(params.V, params.R, force=params.force)
        if fp.stable:
            return StickSlipObservables._no_slip(
                status="steady", method=chain, **common,
                reason=f"{where}: it did not reach its fold within its horizon ({fmt_number(run.t_max, 3)} s) and "
                       f"the fixed point v = V is stable (f'(V, V) = {fmt_number(fp.fprime, 4)} N s/m): steady "
                       "peeling")
        return StickSlipObservables._no_slip(
            status="no attractor", method=chain, **common,
            reason=f"{where}: it did not reach its fold within its horizon ({fmt_number(run.t_max, 3)} s), "
                   "though the fixed point is unstable")
    if code == MAX_STEPS:
        return StickSlipObservables._no_slip(status="no attractor", method=chain, **common,
                                             reason=f"{where}: its step budget ({SEGMENT_MAX_STEPS}) was spent")
    why = _BREAKDOWNS.get(code, "the segment's solver stopped")
    return StickSlipObservables._no_slip(status="breakdown", method=chain, **common,
                                         reason=f"{where}: {why} (status {STATUS[code].reason})")


#: Why a segment that broke down stopped (the reduced segment's statuses, :mod:`peelapprox._status`).
_BREAKDOWNS = {
    V_FLOOR: "v fell by a factor e^60 below its entry on AB: v -> 0",
    V_CEILING: "v ran away on CD (above 1000 times its entry)",
    F_NONPOSITIVE: "the pull force reached 0",
    NONFINITE: "the state became non-finite",
    LAW_DOMAIN: "v left the peel-force law's domain",
    STEP_FAIL: "the step size collapsed",
}
