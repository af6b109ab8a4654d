"""The stick-slip attractor predicted from the paper's reduced branch-wise equations alone (no DAE solve).

:func:`approximate_attractor` chains the reduced segments of :mod:`peelapprox._reduced._segment` (Sec. V of the paper:
an α model coupled to the velocity equation approxvdot or fullvdot) into a return map on the exact model's
section (:mod:`peelapprox._reduced._reducedmap`) and finds its attractors:

1. **AB**: from the landing velocity ``v_land_ab`` the α model and the v equation are integrated until v reaches
   the fold ``v_max`` (the transversal event ``ln v = ln v_max`` of the desingularised field).
2. **AB→CD jump**: F put on CONSTR, ``F = f_max/(1 + sin α)`` (the section), α continuous, v to the landing
   ``v_land_cd``, and the roller's angular velocity ``ω = α̇ + v/R`` continuous (FLOW1; the hybrid solver's
   jump), so ``α̇ → α̇ - (v_land_cd - v_max)/R``.
3. **CD**: the CD α model and v equation from ``v_land_cd`` until v falls to ``v_min``.
4. **CD→AB jump**: likewise, ``F = f_min/(1 + sin α)``, ``α̇ → α̇ + (v_min - v_land_ab)/R``.

From each start the map runs ``n_transient`` returns; the returns' near-repetition proposes a period n <= 12,
and Newton on ``P^n(x) = x`` finds the orbit and its multipliers.  A stable orbit is the answer (its
observables over whole cycles of the orbit itself); an unstable one is reported with the return at which
its amplitude law ``A_k = A_k0 |μ|^((k - k0)/n)`` reaches :data:`ESCAPE_FRACTION` of its force drop, and the
map is moved there along its own deviation and iterated on (at most :data:`MAX_ESCAPES` times); where no
period is found the map samples ``n_returns`` returns (whole cycles of a long period, or an aperiodic
sample).  The observables are read by :func:`peelapprox._observables.jump_statistics`, the one definition both
sides use.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

from .._observables import StickSlipObservables
from .._params import PeelParams
from .._ranges import F0_FACTOR
from .._status import LAW_DOMAIN, V_FLOOR
from ..io import fmt_number
from ..law import fixed_point
from ..law._compiled import compiled_law
from ..validate import choice, flag, integer, optional, positive
from ..validate import params as _params
from ..validate import rtol as _rtol
from ._approx_result import ALPHA_LINEAR, MULTIPLIER_ERROR, ApproximateAttractor, confidence, warn_low
from ._approx_start import (
    ESCAPE_FRACTION,
    FULL_CHAIN,
    MAX_ESCAPES,
    MAX_PERIOD,
    PERIOD_RTOL,
    Found,
    Start,
    from_start,
    promote,
)
from ._reducedmap import NEWTON_RTOL, MapStop, ReturnMap
from ._regime import regime
from ._segment_kernel import ALPHA_MODELS, V_EQUATIONS
from ._segment_plan import segment_status

__all__ = ["APPROX_DEFAULTS", "ESCAPE_FRACTION", "MAX_ESCAPES", "MAX_PERIOD", "PERIOD_RTOL", "START_NAMES",
           "approximate_attractor", "default_models"]


#: The default reductions per inertia label of :func:`peelapprox.estimate` (:data:`peelapprox.INERTIA_RULE`):
#: ``{inertia: ((AB α model, AB v equation), (CD α model, CD v equation))}``: the full branch dynamics linearised in
#: α, genalpha + fullvdot on both branches (:data:`FULL_CHAIN`), at every label.  Measured on the benchmark's 200
#: random points (docs/theory.md, "Which chain where"): the full chain gives the exact run's period label where
#: Airy1 + approxvdot (FLOW1's kinematic term kept, the O(α) terms dropped) gives a neighbouring one (10 → 9 slips
#: per cycle, 6 → 3), matches the exact set about as often, and, since the solver's start is not followed past a
#: weakly unstable small mode where the rest start's answer ranks first (:func:`_starts`), runs fewer returns a call
#: at high inertia (709 against 737) than Airy1 + approxvdot did as the default there.
APPROX_DEFAULTS: dict[str, tuple[tuple[str, str], tuple[str, str]]] = {
    "low": FULL_CHAIN, "intermediate": FULL_CHAIN, "high": FULL_CHAIN}
#: Where the map starts (``start=``): ``"solver"``, the exact solver's default start; ``"rest"``, the foot of the
#: relaxation cycle at rest (AB landing, F = f_min, α = α̇ = 0); ``"auto"``, both: the solver's attractor is the
#: primary prediction, the rest start's an alternative (the primary where the solver's start finds none).
START_NAMES = ("auto", "solver", "rest")
#: Returns of :data:`FULL_CHAIN` from the solver's start in which a breakdown is looked for.
PROBE_RETURNS = 5


def default_models(params: PeelParams) -> tuple[tuple[str, str], tuple[str, str]]:
    """The regime's ``((AB α model, AB v equation), (CD α model, CD v equation))`` (:data:`APPROX_DEFAULTS`); the
    low-inertia pair where the law has no folds at V (nothing runs there)."""
    inertia, _ = regime(params)
    return APPROX_DEFAULTS.get(inertia, APPROX_DEFAULTS["low"])


def approximate_attractor(params: PeelParams, *, alpha_model: str | None = None, v_equation: str | None = None,
                          cd_alpha_model: str | None = None, cd_v_equation: str | None = None, start: str = "auto",
                          n_transient: int = 40, n_returns: int = 500, rtol: float = 1e-6,
                          max_wall: float | None = 10.0, warn: bool = True) -> ApproximateAttractor:
    """The stick-slip attractor predicted by the paper's reduced branch-wise equations, without the DAE.

    Runs the reduced return map on the exact model's section (module docstring: AB segment to the fold, jump
    with F put on CONSTR, CD segment to the fold, jump) from the exact solver's start and from rest, finds its
    periodic orbits by Newton with their multipliers, leaves the unstable ones, and reads the observables of
    what it reaches with the definitions of :class:`StickSlipObservables`.  The default reductions
    (:data:`APPROX_DEFAULTS`): the full branch dynamics linearised in α (genalpha + fullvdot on both branches) at
    every inertia; Airy1 + approxvdot (FLOW1's ``-v̇/R`` kept, the O(α) terms dropped) and the others are options
    (measurements: docs/theory.md, "The approximate attractor").

    Parameters
    ----------
    params : PeelParams
        The paper's model (no tape mass or load: the reduced equations are the massless DAE's), any law with a
        compiled kernel.  The reduced equations are linear in α whatever ``params.geometry``.
    alpha_model, v_equation, cd_alpha_model, cd_v_equation : str, optional
        AB's and CD's α model (:data:`peelapprox.ALPHA_MODELS`) and v equation (:data:`peelapprox.V_EQUATIONS`),
        any combination; each None is the default (:data:`APPROX_DEFAULTS`).
    start : {"auto", "solver", "rest"}
        Where the map starts (:data:`START_NAMES`): ``"auto"`` both, the solver's attractor first.
    n_transient : int
        Returns discarded before a period is looked for, an integer in [0, 10**6] (40).
    n_returns : int
        Returns in the sample where no periodic orbit of period <= :data:`MAX_PERIOD` is found (chaotic,
        quasi-periodic or long-period), in [3, 10**6] (500).
    rtol : float
        Relative tolerance of the segments while iterating (1e-6); Newton and its Jacobian run at 1e-9.
    max_wall : float or None
        Wall-clock budget [s] of the iteration (10; None: unbounded), checked every 20,000 integration steps at
        most, from when the map's kernels are ready (compiled or loaded: an answer does not depend on that).
    warn : bool
        Warn once (:class:`peelapprox.ApproximationWarning`) if the primary prediction has low confidence (True).

    Returns
    -------
    ApproximateAttractor
        A :class:`StickSlipObservables` (``method`` names the chain, the start and how the attractor was found;
        ``t_start``/``t_end`` on the map's own clock) with ``multipliers``, ``escape_returns``, ``confidence`` and
        ``confidence_reason``, and ``alternatives``: the attractors of the other start and the unstable orbits left on
        the way (:func:`_starts`: when the solver's start is not followed). ``status``: ``"stick-slip"``; ``"steady"``
        (no folds at V, a segment settles on the stable fixed point, or no AB landing while the solver's start lies
        on that fixed point); ``"no attractor"`` (a budget spent first) or ``"breakdown"`` (of a reduced segment, or
        no return map: a jump without a landing, a fold force not positive), with the reason. Every mean is None for
        the last three, never NaN.

    Raises
    ------
    ValueError, TypeError
        An unknown model, a value out of range, a model variant or a law without a compiled kernel (named); an
        argument of the wrong kind (:class:`peelapprox.validate.ArgumentTypeError`, a TypeError).
    """
    params = _params("params", params, where="approximate_attractor", variants=False)
    chosen, n_transient, n_returns, start, rtol, max_wall, warn = _checked(
        alpha_model, v_equation, cd_alpha_model, cd_v_equation, n_transient, n_returns, start, rtol, max_wall, warn)
    law = compiled_law(params.force, params.V)  # ValueError naming params.force for a law without a kernel
    common: dict[str, Any] = dict(V=float(params.V), I=float(params.I), t_start=None, t_end=None)
    inertia, velocity, models, chain = _chain(params, law, chosen)
    names = ("solver", "rest") if start == "auto" else (start,)
    if (no_map := _no_map(params, law.structure, chain, common)) is not None:
        at_rest = _at_fixed_point(params, law, common) if "solver" in names and no_map.status == "breakdown" else None
        primary = _assemble([Found(o, [], None) for o in (at_rest, no_map) if o is not None], "n/a", None)
        if warn:  # rated as any answer: a breakdown is low confidence
            warn_low(primary)
        return primary
    lo = ReturnMap(params, law, models, rtol)  # kernels compiled or loaded: max_wall counts from here (docstring)
    lo.deadline = math.inf if max_wall is None else time.perf_counter() + max_wall
    maps = (lo, lo.at(NEWTON_RTOL))
    solver = _solver_start(params, law) if "solver" in names else None
    found = _starts(params, maps, solver, _rest(law), names, (n_transient, n_returns, rtol, chain, common))
    probe = _probe(params, law, solver, rtol, lo.deadline, lo.book) if solver is not None and models != FULL_CHAIN \
        else None
    primary = _assemble(found, "no stick-slip (stable fixed point)" if velocity == "stable"
                        else f"{inertia} inertia, {velocity} V", probe)  # the regime label of estimate()
    if warn:
        warn_low(primary)
    return primary


def _checked(alpha_model: Any, v_equation: Any, cd_alpha_model: Any, cd_v_equation: Any, n_transient: Any,
             n_returns: Any, start: Any, rtol: Any, max_wall: Any, warn: Any) -> tuple:
    """:func:`approximate_attractor`'s options checked (each error names its argument and range), in its order."""
    chosen = [optional(choice, name, value, ALPHA_MODELS if "alpha" in name else V_EQUATIONS) for name, value in (
        ("alpha_model", alpha_model), ("v_equation", v_equation), ("cd_alpha_model", cd_alpha_model),
        ("cd_v_equation", cd_v_equation))]
    return (chosen, integer("n_transient", n_transient, lo=0, hi=10**6),
            integer("n_returns", n_returns, lo=3, hi=10**6), choice("start", start, START_NAMES), _rtol("rtol", rtol),
            optional(positive, "max_wall", max_wall), flag("warn", warn))


def _chain(params: PeelParams, law: Any, chosen: list[str | None]
           ) -> tuple[str, str, tuple[tuple[str, str], tuple[str, str]], str]:
    """``estimate()``'s inertia and velocity labels of ``params`` and the chain: the models ``chosen`` (AB α, AB v,
    CD α, CD v), :data:`APPROX_DEFAULTS`' for the regime where None, and the chain's name."""
    bs = law.structure
    if not bs.has_folds:
        inertia, velocity = "n/a", "stable"
    elif _landless(bs) is not None:  # no map to label (:func:`_no_map`); the regime's periods need f_min > 0
        inertia, velocity = "n/a", "n/a"
    else:
        inertia, velocity = regime(params)
    (ab_am, ab_ve), (cd_am, cd_ve) = APPROX_DEFAULTS.get(inertia, APPROX_DEFAULTS["low"])
    models = ((chosen[0] or ab_am, chosen[1] or ab_ve), (chosen[2] or cd_am, chosen[3] or cd_ve))
    return inertia, velocity, models, f"approximate: AB {models[0][0]}/{models[0][1]}, CD {models[1][0]}/{models[1][1]}"


def _no_map(params: PeelParams, bs: Any, chain: str, common: dict[str, Any]) -> ApproximateAttractor | None:
    """The answer where there is no return map to iterate: no folds at V (steady) or a jump without a landing
    (breakdown); None where there is one."""
    if not bs.has_folds:
        return promote(StickSlipObservables._no_slip(
            status="steady", method="approximate: no folds, nothing to chain", **common,
            reason=f"the law has no folds at V = {fmt_number(params.V, 4)} m/s (f increases in v): steady peeling "
                   "at the stable fixed point v = V"))
    if (why := _landless(bs)) is not None:
        return promote(StickSlipObservables._no_slip(status="breakdown", method=chain, **common,
                                                      reason=f"{why}: no return map"))
    return None


def _at_fixed_point(params: PeelParams, law: Any, common: dict[str, Any]) -> ApproximateAttractor | None:
    """Where the map has no AB landing (f_min <= f(0+, V): no stick-slip cycle closes) and the fixed point v = V
    is stable on AB (``f'(V, V) > 0``, V below the fold v_max), the solver's start, F = F0_FACTOR f(V, V) at v = V
    on AB, relaxes to it: steady peeling (the exact solver's start does, at 30 of 30 random such points of the
    paper's law, V 0.05-0.2 m/s, I 1e-7-0.2 kg m^2, k 200-5000 N/m); None otherwise."""
    bs = law.structure
    lo, hi = law.domain
    if bs.v_land_ab is not None or not (lo <= params.V <= hi and bs.v_max is not None and params.V < bs.v_max):
        return None
    fp = fixed_point(params.V, params.R, force=params.force)
    if not fp.stable:
        return None
    return promote(StickSlipObservables._no_slip(
        status="steady", method="approximate: no AB landing, the solver's start on the stable fixed point", **common,
        reason=f"no stick-slip cycle closes (the CD->AB jump has no landing on AB: f_min <= f(0+, V)) and the "
               f"fixed point v = V = {fmt_number(params.V, 4)} m/s is stable on AB (f'(V, V) = "
               f"{fmt_number(fp.fprime, 4)} N s/m > 0): the solver's start, on AB at v = V, relaxes to it: steady "
               "peeling; a start off its basin jumps to CD and breaks down"), start="solver")


def _landless(bs: Any) -> str | None:
    """Why the law's folds at V give the map no jump to land (a fold force not positive, as a law with a negative
    dip has: the exact model's F reaches 0; a jump without a landing), or None where both jumps land."""
    if not bs.f_min > 0.0:
        return (f"the law's lower fold force f_min = {fmt_number(bs.f_min, 5)} N is not positive: F reaches 0 "
                "before the CD->AB jump (the exact model's breakdown F <= 0)")
    if bs.v_land_ab is None or bs.v_land_cd is None:
        which = "AB (f_min <= f(0+, V))" if bs.v_land_ab is None else "CD (the law's domain ends below f_max)"
        return f"a jump has no landing on {which}"
    return None


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


def _starts(params: PeelParams, maps: tuple[ReturnMap, ReturnMap], solver: Start | None, rest: Start,
            names: tuple[str, ...], run: tuple[int, int, float, str, dict[str, Any]]) -> list[Found]:
    """What each start of ``names`` reaches (:func:`from_start` with the options ``run``), in their order.

    With both starts the rest start runs first.  Where its answer ranks first whatever the solver's start reaches
    once that start has left an orbit of undecided stability (:func:`_assemble`'s ranking: the rest start's answer
    is stick-slip, inside the linearised reductions' range of α, its stability decided), the solver's start is not
    followed past such an orbit (``outranked``): its pushes and sample (500 returns) would rank after the rest
    start's answer.  The primary prediction is the same as with both followed (every field of 200 seeded calls);
    the solver start's attractor is then not among the alternatives, the orbits it left are."""
    if names != ("solver", "rest") or solver is None:
        return [from_start(params, maps, solver if name == "solver" and solver is not None else rest, name, *run)
                for name in names]
    r = from_start(params, maps, rest, "rest", *run)
    first = r.obs is not None and not any(_rank(r.obs, r))
    return [from_start(params, maps, solver, "solver", *run, outranked=first), r]


def _rank(o: ApproximateAttractor, f: Found) -> tuple[bool, bool, bool]:
    """A start's answer's place in :func:`_assemble`'s ranking (False first): not stick-slip, beyond the
    linearised reductions' range of α, of undecided stability (:func:`_marginal`); all False ranks first."""
    return o.status != "stick-slip", (f.alpha_max or 0.0) > ALPHA_LINEAR, _marginal(f)


def _marginal(f: Found) -> bool:
    """The start reached an orbit whose stability the map cannot decide (a multiplier within the reduction's
    multiplier error of 1), or left such an orbit on its way (the escape's amplitude is the map's guess, and what
    follows it may still be the transient)."""
    def undecided(o: ApproximateAttractor | None) -> bool:
        return o is not None and o.multipliers is not None and \
            abs(max(abs(m) for m in o.multipliers) - 1.0) < MULTIPLIER_ERROR
    return undecided(f.obs) or any(undecided(o) for o in f.left)


def _probe(params: PeelParams, law: Any, start: Start, rtol: float, deadline: float,
           book: dict | None = None) -> str | None:
    """Why the exact model breaks down from the solver's start (``start``) where Airy1 + approxvdot may not: the full
    branch dynamics linearised in α (:data:`FULL_CHAIN`) reaches ``F(1 + sin α) = f(0+, V)`` on AB (v -> 0) within
    :data:`PROBE_RETURNS` returns; None if it does not (a probe found, of 200 random points, 3 where the exact run
    breaks down got a stick-slip prediction; at V = 0.903, I = 1.08e-4 Airy1 + approxvdot's first CD stay lasts
    2.6 ms and lands at 247 N where the exact one lasts 11.2 ms and lands at 162 N, with α = 0.2, whose swing on
    AB then reaches f(0+, V): the O(α) terms of that chain, not the physics).  Run where the chain is not the full
    one (the default), i.e. where the caller chose another."""
    m = ReturnMap(params, law, FULL_CHAIN, rtol, deadline, book)
    try:
        m.run(m.enter(start), PROBE_RETURNS)
    except MapStop as stop:
        if stop.timeout or stop.plan is None or stop.plan.branch != "AB":
            return None
        code = segment_status(stop.plan, stop.run.code)
        if code in (V_FLOOR, LAW_DOMAIN):
            return (f"the full branch dynamics linearised in alpha (genalpha + fullvdot) breaks down from the solver's "
                    f"start after {stop.returns} returns (v -> 0 on AB: F(1 + sin alpha) reaches f(0+, V)), as the "
                    "exact model can: this chain's stick-slip may be an artefact of its O(alpha) terms")
    return None


def _same(a: ApproximateAttractor, b: ApproximateAttractor) -> bool:
    """Two predictions of one attractor: the same status and period, means within 1 %."""
    if a.status != b.status or a.period != b.period:
        return False
    return all(x is None and y is None or (x is not None and y is not None and abs(x - y) <= 0.01 * abs(y))
               for x, y in ((a.slip_interval, b.slip_interval), (a.force_drop, b.force_drop)))


def _assemble(found: list[Found], label: str, breakdown: str | None) -> ApproximateAttractor:
    """The primary prediction (the first start's stick-slip attractor, the map's orbits of undecided stability
    (:func:`_marginal`) last) with its confidence, and the others as its alternatives."""
    def rated(o: ApproximateAttractor, f: Found | None) -> ApproximateAttractor:
        if o.status == "stick-slip":
            c, why = confidence(o, label, f.alpha_max if f else None, tuple(f.left) if f else (), breakdown)
        elif o.status == "steady":
            c, why = "high", "steady peeling: no stick-slip to doubt"
        else:
            c, why = "low", f"no attractor predicted ({o.status}): {o.reason}"
        return dataclasses.replace(o, confidence=c, confidence_reason=why)

    # stick-slip first, inside the linearised reductions' range of α before outside it, an attractor whose
    # stability the map decides before one it does not, then the starts' order (a start not followed: none)
    order = sorted(((f.obs, f) for f in found if f.obs is not None), key=lambda p: _rank(*p))
    primary = rated(*order[0])
    others: list[ApproximateAttractor] = []
    for o, f in order[1:]:
        if not _same(o, primary) and not any(_same(o, x) for x in others):
            others.append(rated(o, f))
    for f in found:
        for o in f.left:
            if not any(_same(o, x) for x in others):
                others.append(rated(o, None))
    return dataclasses.replace(primary, alternatives=tuple(others))
