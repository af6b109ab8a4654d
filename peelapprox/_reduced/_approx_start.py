"""What the reduced return map reaches from one start (:func:`peelapprox.approximate_attractor`'s search).

From a start the map runs its transient returns; the returns' near-repetition proposes a period n <=
:data:`MAX_PERIOD`, and Newton on ``P^n(x) = x`` (:func:`peelapprox._reduced._reducedmap.newton`) finds the orbit
and its multipliers.  A stable orbit is the answer (its observables over whole cycles of the orbit itself); an
unstable one is recorded with its escape return (:mod:`peelapprox._reduced._escape`) and left along the map's own
deviation (at most :data:`MAX_ESCAPES` times); where no period is found the map samples its returns.  A segment
that stops before its fold ends the search with a steady, no-attractor or breakdown answer (:func:`_failed`).
The ranking of the starts' answers, their confidence and the starts themselves are
:mod:`peelapprox._reduced._approximate`'s.
"""

from __future__ import annotations

import dataclasses
import math
import operator
from typing import Any

import numpy as np

from .._observables import StickSlipObservables, jump_statistics
from .._params import PeelParams
from .._status import F_NONPOSITIVE, LAW_DOMAIN, MAX_STEPS, NONFINITE, STATUS, STEP_FAIL, T_MAX, V_CEILING, V_FLOOR
from ..io import fmt_number
from ..law import fixed_point
from ._approx_result import MULTIPLIER_ERROR, ApproximateAttractor
from ._escape import escape_return
from ._reducedmap import SEGMENT_MAX_STEPS, MapStop, ReturnMap, newton
from ._segment_plan import SegmentPlan, segment_status

__all__ = ["CANDIDATE_RTOL", "EARLY_RETURNS", "EARLY_RTOL", "ESCAPE_FRACTION", "ESCAPE_PUSH", "FULL_CHAIN", "Found",
           "MAX_CANDIDATES", "MAX_ESCAPES", "MAX_PERIOD", "NEUTRAL", "PERIOD_RTOL", "Start", "from_start", "promote"]

#: A periodic orbit is looked for with periods up to this (Newton on ``P^n``); longer ones are sampled.
MAX_PERIOD = 12
#: The returns' period tolerance of an aperiodic sample, ``max(PERIOD_RTOL, 100 rtol)`` relative to the largest
#: return (long periods of a sample: :func:`peelapprox.periodicity`).
PERIOD_RTOL = 1e-4
#: A period n is tried by Newton when the last returns repeat after n to this fraction of ``f_max - f_min``.
CANDIDATE_RTOL = 0.2
#: After this many transient returns, periods that repeat to :data:`EARLY_RTOL` are tried at once, and a clearly
#: stable orbit (every multiplier inside 1 - the multiplier error) ends the transient.
EARLY_RETURNS = 18
EARLY_RTOL = 0.01
#: Periods tried by Newton at most, best repeating first.
MAX_CANDIDATES = 2
#: An unstable orbit is left (:attr:`ApproximateAttractor.escape_returns`) when the deviation of the force at
#: the AB→CD jumps from the orbit's reaches this fraction of the orbit's force drop: the deviation is then as
#: large as the orbit itself, and the run goes over to another attractor.
ESCAPE_FRACTION = 1.0
#: The map leaves an unstable orbit from a force deviation of this fraction of its force drop (along its own
#: deviation), where the orbit's linearisation no longer holds the map near it.
ESCAPE_PUSH = 1.0
#: The full branch dynamics linearised in α: the chain whose breakdown the default chain is checked against.
FULL_CHAIN = (("genalpha", "fullvdot"), ("genalpha", "fullvdot"))
#: A multiplier within this of the unit circle is neutral (a family of orbits, as with α held fixed by the
#: ``"static"`` model): the orbit is the answer, not left.
NEUTRAL = 1e-7
#: Unstable orbits left in turn from one start before the map samples what it reaches.
MAX_ESCAPES = 3


def promote(o: StickSlipObservables, **extra: Any) -> ApproximateAttractor:
    """``o`` as an :class:`ApproximateAttractor` with ``extra`` fields."""
    fields = {f: getattr(o, f) for f in StickSlipObservables.__dataclass_fields__}
    return ApproximateAttractor(**{**fields, **extra})


#: A start of the map: ``(branch code (0 AB, 1 CD), F, v, α, α̇)``.
Start = tuple[int, float, float, float, float]


class Found:
    """What one start reached: the attractor's observables (None where the start was not followed past an orbit
    it left: :func:`from_start`'s ``outranked``), the unstable orbits left on the way, and the sample's largest
    |α| at a jump (the confidence rules' inputs)."""

    def __init__(self, obs: ApproximateAttractor | None, left: list[ApproximateAttractor],
                 alpha_max: float | None) -> None:
        self.obs, self.left, self.alpha_max = obs, left, alpha_max


def _observe(recs: np.ndarray, F_next: float, *, period_rtol: float, max_period: int, how: str, chain: str,
             common: dict[str, Any], t0: float, **extra: Any) -> ApproximateAttractor:
    """The observables of the returns ``recs`` (:meth:`ReturnMap.run`'s records) and the next AB→CD force; the
    jump times are the stays summed in order from ``t0`` (``np.cumsum`` adds one after the other)."""
    m = len(recs)
    t = np.empty(2 * m + 1)
    t[0], t[1::2], t[2::2] = t0, recs[:, 2], recs[:, 3]
    t = np.cumsum(t)
    F = np.empty(2 * m + 1)
    F[0:-1:2], F[1::2], F[-1] = recs[:, 0], recs[:, 1], F_next
    fb = np.zeros(2 * m + 1, dtype=int)
    fb[1::2] = 1
    stats, cycles = jump_statistics(t, F, fb, period_rtol=period_rtol, max_period=max_period)
    reason = (f"{stats['n_slips']} slips of the reduced return map ({how}), return map {stats['period_label']}"
              + (f"; means over the last {cycles} whole cycles" if cycles is not None else ""))
    return ApproximateAttractor(status="stick-slip", reason=reason, method=f"{chain}, {how}", **stats,
                                **{**common, "t_start": float(t[0]), "t_end": float(t[-1])}, **extra)


def _candidates(F: np.ndarray, scale: float, rtol: float = CANDIDATE_RTOL) -> list[int]:
    """Periods n <= :data:`MAX_PERIOD` after which the last returns repeat to :data:`CANDIDATE_RTOL` of
    ``scale``, best repeating first, at most :data:`MAX_CANDIDATES`; a divisor of n that repeats nearly as well
    (within 4 times n's mismatch, or 1e-3) stands for n (a period-2 orbit also repeats after 4).  The largest
    ``|F_k - F_(k-n)|`` over the last ``max(2n, 6)`` returns, in Python floats on the last 3 :data:`MAX_PERIOD`
    returns (the same differences as numpy's, and the same maximum, without numpy's per-call cost)."""
    size = len(F)
    x = F[-3 * MAX_PERIOD:].tolist()
    k = len(x)
    mismatch: dict[int, float] = {}
    for n in range(1, MAX_PERIOD + 1):
        m = max(2 * n, 6)
        if size < m + n:
            break
        mismatch[n] = max(map(abs, map(operator.sub, x[k - m:], x[k - m - n:k - n]))) / scale
    out: list[int] = []
    for n, r in sorted(mismatch.items(), key=lambda item: item[1]):
        if r >= rtol:
            break
        n = min(d for d in mismatch if n % d == 0 and mismatch[d] <= max(4.0 * r, 1e-3))
        if n not in out:
            out.append(n)
    return out[:MAX_CANDIDATES]


def _multipliers(J: np.ndarray) -> tuple[complex, ...]:
    """The eigenvalues of ``J = D P^n``: the orbit's multipliers."""
    return tuple(complex(m) for m in np.linalg.eigvals(J))


def _orbit(maps: tuple[ReturnMap, ReturnMap], x: np.ndarray, n: int, mu: tuple[complex, ...], returns: int,
           name: str, chain: str, common: dict[str, Any]) -> tuple[ApproximateAttractor, np.ndarray, float]:
    """A periodic orbit's observables over whole cycles of the orbit itself (at Newton's tolerance), its records
    and its mean force drop.  The first cycle is Newton's last ``P^n(x)`` where it ran it (the map's memo)."""
    hi = maps[1]
    cycles = 3  # the orbit itself: one cycle gives its means, three its period label (peelapprox.periodicity)
    y, first = hi.run(x, n)
    y, rest = hi.run(y, (cycles - 1) * n)
    recs = np.concatenate((first, rest))
    rho = max(abs(m) for m in mu)
    kind = "stable" if rho < 1.0 else ("neutral" if rho <= 1.0 + NEUTRAL else "unstable")
    how = (f"{name} start, Newton on P^{n} after {returns} returns, {kind} "
           f"(|mu| {'/'.join(fmt_number(abs(m), 6) for m in mu)})")
    obs = _observe(recs, hi.force(0, float(y[0])), period_rtol=1e-6, max_period=n, how=how, chain=chain,
                   common=common, t0=0.0, multipliers=mu, start=name)
    return obs, recs, float(np.mean(recs[:, 0] - recs[:, 1]))


def _alpha_max(recs: np.ndarray) -> float:
    """The largest |α| at a jump of the returns ``recs``."""
    return float(np.max(np.abs(recs[:, 4:6])))


def _deviation(recs: np.ndarray, orbit: np.ndarray, n: int) -> float:
    """The largest deviation of the last n returns' AB→CD forces from the orbit's at the same phase."""
    return float(max(abs(recs[-i, 0] - orbit[(n - i) % n, 0]) for i in range(1, n + 1)))


def _periodic(maps: tuple[ReturnMap, ReturnMap], x: np.ndarray, recs: np.ndarray, rtol: float
              ) -> tuple[np.ndarray, np.ndarray, int] | None:
    """The periodic orbit Newton finds from ``x`` for a period n the returns ``recs`` propose (best first, those
    repeating to ``rtol``): its section point, ``D P^n`` there and n; None if none converges."""
    bs = maps[0].law.structure
    for n in _candidates(recs[:, 0], float(bs.f_max - bs.f_min), rtol):
        res = newton(maps[1], x.copy(), n)
        if res is not None:
            return res[0], res[1], n
    return None


def _settle(maps: tuple[ReturnMap, ReturnMap], x: np.ndarray, recs: np.ndarray, name: str, chain: str,
            common: dict[str, Any], rtol: float = CANDIDATE_RTOL
            ) -> tuple[ApproximateAttractor, np.ndarray, float, tuple[np.ndarray, np.ndarray], int] | None:
    """The periodic orbit of :func:`_periodic`: its observables, records, mean force drop, section point and
    ``D P^n`` there, and n; None if none converges."""
    got = _periodic(maps, x, recs, rtol)
    if got is None:
        return None
    xs, J, n = got
    obs, orbit, drop = _orbit(maps, xs, n, _multipliers(J), maps[0].returns, name, chain, common)
    return obs, orbit, drop, (xs, J), n


def from_start(params: PeelParams, maps: tuple[ReturnMap, ReturnMap], s: Start, name: str, n_transient: int,
                n_returns: int, rtol: float, chain: str, common: dict[str, Any], outranked: bool = False) -> Found:
    """The attractor the map reaches from ``s`` (module docstring), with the unstable orbits it left.

    With ``outranked`` (another start's answer ranks first whatever this start reaches once
    it has left an orbit of undecided stability: :func:`peelapprox._reduced._approximate._assemble`) the start is
    not followed past such an orbit: its answer is then None, with the orbits it left."""
    lo, hi = maps
    lo.returns = 0
    left: list[ApproximateAttractor] = []
    k_in = 0  # the return at which the map set out towards the orbit it reaches next (the start, or the last push)
    try:
        x, recs = lo.run(lo.enter(s), min(n_transient, EARLY_RETURNS))
        if EARLY_RETURNS < n_transient:  # nearly repeating already: a clearly stable orbit ends the transient
            early = _periodic(maps, x, recs, EARLY_RTOL)
            mu = _multipliers(early[1]) if early is not None else (1.0,)
            if early is not None and max(abs(m) for m in mu) < 1.0 - MULTIPLIER_ERROR:  # its observables only now
                obs, orbit, _ = _orbit(maps, early[0], early[2], mu, lo.returns, name, chain, common)
                return Found(obs, left, _alpha_max(orbit))
            x, more = lo.run(x, n_transient - EARLY_RETURNS)
            recs = np.concatenate((recs, more))
        for _ in range(MAX_ESCAPES + 1):
            got = _settle(maps, x, recs, name, chain, common)
            if got is None:
                break  # no period found: a sample
            obs, orbit, drop, (xs, J), n = got
            rho, thr = max(abs(m) for m in obs.multipliers or ()), ESCAPE_FRACTION * drop
            if obs.stable or rho <= 1.0 + NEUTRAL:  # the escape of an orbit the full chain finds weakly unstable
                k_esc, mu_esc = escape_return(lo, J, x, xs, n, rho, thr, FULL_CHAIN, lo.returns - k_in) \
                    if rho < 1.0 - NEUTRAL else (None, None)
                return Found(dataclasses.replace(obs, escape_returns=k_esc, escape_multiplier=mu_esc), left,
                              _alpha_max(orbit))
            dev = _deviation(recs, orbit, n)
            k_esc, mu_esc = escape_return(lo, J, x, xs, n, rho, thr, FULL_CHAIN, lo.returns - k_in)
            left.append(dataclasses.replace(obs, escape_returns=k_esc, escape_multiplier=mu_esc))
            if outranked and abs(rho - 1.0) < MULTIPLIER_ERROR:  # ranked after the other start's whatever follows
                return Found(None, left, None)
            if 0.0 < dev < ESCAPE_PUSH * drop:  # past the escape along the map's own deviation, on from there
                x = xs + (x - xs) * (ESCAPE_PUSH * drop / dev)
            k_in = lo.returns
            x, recs = lo.run(x, max(n_transient, 3 * MAX_PERIOD))
        x, recs = lo.run(x, n_returns)  # the sample: n_returns after the transient
        got = _settle(maps, x, recs, name, chain, common)  # a periodic orbit reached late, after the transient
        if got is not None and max(abs(m) for m in got[0].multipliers or (2.0,)) <= 1.0 + NEUTRAL:
            return Found(got[0], left, _alpha_max(got[1]))
        sample = recs[-n_returns:]
        how = f"{name} start, {n_returns} returns sampled after {lo.returns - n_returns}, rtol {fmt_number(rtol, 3)}"
        obs = _observe(sample, lo.force(0, float(x[0])), period_rtol=max(PERIOD_RTOL, 100.0 * rtol), max_period=32,
                       how=how, chain=chain, common=common, t0=0.0, start=name)
        return Found(obs, left, _alpha_max(sample))
    except MapStop as stop:
        if stop.timeout or stop.plan is None:
            return Found(promote(StickSlipObservables._no_slip(
                status="no attractor", method=f"{chain}, {name} start", **common,
                reason=f"max_wall spent after {lo.returns + hi.returns} returns"), start=name), left, None)
        return Found(promote(_failed(params, stop.plan, stop.run, stop.returns, f"{chain}, {name} start", common),
                               start=name), left, None)


def _failed(params: PeelParams, plan: SegmentPlan, run: Any, n_returns: int, chain: str,
            common: dict[str, Any]) -> StickSlipObservables:
    """The observables of a map stopped by a segment that did not reach its fold: steady, no attractor or
    breakdown (:func:`approximate_attractor`'s statuses)."""
    code = segment_status(plan, run.code)
    y = run.y
    v, F = math.exp(float(y[1])), float(y[2])
    where = (f"the {plan.branch} segment entered after {n_returns} returns stopped at v = {fmt_number(v, 4)} m/s, "
             f"F = {fmt_number(F, 5)} N, {fmt_number(float(y[0]), 4)} s after its entry")
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
