"""The reduced return map on the exact model's section, its periodic orbits by Newton and their multipliers.

The map (:func:`peelapprox.approximate_attractor`, module docstring of :mod:`peelapprox._reduced._approximate`) chains a
reduced AB segment to the fold ``v_max``, the AB→CD jump, a reduced CD segment to ``v_min`` and the CD→AB jump.
Here its state is the section of the exact model: the point on AB just before the AB→CD jump, where CONSTR,
``F (1 - c(α)) = f_max`` (``1 - c = 1 + sin α`` for the paper's geometry), ties F to α, so the map is a map of
the plane ``x = (α, α̇)``.  At each fold F is put back on CONSTR (``F = f_fold/(1 - c(α))``) instead of carried
over from the reduced segment, whose linearised constraint drifts under approxvdot (measured: the residual of
``F(1 + α) = f(v)`` changes at rate ``Ḟα``, -88…+83 N over 50 s); the map then lives on the exact section and its
fixed points are comparable with :func:`exact.periodic_orbit`'s.

A period-n orbit is a zero of ``P^n(x) - x``, found by Newton with a finite-difference Jacobian (central
differences, step :data:`FD_STEP` of the orbit's scale, at :data:`NEWTON_RTOL`); its multipliers are the
eigenvalues of that Jacobian.  :func:`envelope` measures a section point's deviation from an unstable orbit in that
Jacobian's dominant eigen-coordinates (the amplitude of its escape law).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .._params import PeelParams
from .._status import DONE
from . import _reducedmap_kernel as RK
from . import _segment_kernel as K
from ._segment_kernel import AM_EXP, AM_HARM, AM_SIN, AM_STATIC, alpha_at
from ._segment_plan import SegmentPlan, SegmentRun, run_segment, segment_plan

__all__: list[str] = []

#: Step budget of one segment: the most step-hungry stays (I = 1e-6, V = 0.5, ~190 α oscillations on AB) take
#: ~2000 steps at rtol 1e-6.
SEGMENT_MAX_STEPS = 200_000
#: Segment tolerance of the Newton iterations and the Jacobian: the map is then smooth to ~1e-9 of its scale,
#: so differences of step :data:`FD_STEP` carry ~3e-5 of noise (the reduction's own multiplier error is ~0.06).
NEWTON_RTOL = 1e-9
#: The finite-difference step, relative to the orbit's scale in each coordinate.
FD_STEP = 3e-5
#: Newton converged when the scaled step is below this.
NEWTON_TOL = 1e-8
#: Newton iterations at most.
NEWTON_MAX_IT = 8
#: Integration steps of one compiled call of returns (:meth:`ReturnMap.run`) at most: the wall-clock deadline is
#: checked between calls (~10-30 ms of work each).
STEP_CAP = 20_000
#: Runs a map keeps (:attr:`ReturnMap.memo`) before it forgets them all: Newton's evaluations of one orbit.
MEMO_SIZE = 32
_CLOSED = {AM_SIN, AM_HARM, AM_EXP, AM_STATIC}
_NO_T = np.empty(0)


class MapStop(Exception):
    """A segment of the map did not reach its fold (its plan, its run and where the map was), or the wall-clock
    deadline passed (``timeout``)."""

    def __init__(self, plan: SegmentPlan | None, run: Any, returns: int, timeout: bool = False) -> None:
        super().__init__("timeout" if timeout else getattr(plan, "branch", ""))
        self.plan, self.run, self.returns, self.timeout = plan, run, returns, timeout


class ReturnMap:
    """The reduced return map of one chain at one segment tolerance (module docstring)."""

    def __init__(self, params: PeelParams, law: Any, models: tuple[tuple[str, str], tuple[str, str]],
                 rtol: float, deadline: float = math.inf, book: dict | None = None) -> None:
        bs = law.structure
        self.params, self.law, self.models, self.rtol = params, law, models, rtol
        #: The plans built so far by (branch, v_in), shared by the maps of one call (``book``): a plan of another
        #: chain or tolerance is the same plan with its model fields changed, not built again (~0.5 ms each).
        self.book: dict = {} if book is None else book
        self.plans: tuple[SegmentPlan, ...] = ()
        self.plans = (self.plan("AB", bs.v_land_ab), self.plan("CD", bs.v_land_cd))
        R = params.R
        # the jump of ω-continuity: α̇ after = α̇ before + (v before - v after)/R
        self.kick = ((bs.v_max - bs.v_land_cd) / R, (bs.v_min - bs.v_land_ab) / R)
        self.fold = (float(bs.f_max), float(bs.f_min))
        self.paper = params.geometry == "paper"
        self.omega = math.sqrt(self.fold[0] * R / params.I)
        self.returns = 0
        self.deadline = deadline
        #: Runs kept by their section point's bytes and count (:meth:`run`), None: none kept.
        self.memo: dict | None = None
        # run_segment's default horizon, its entry-independent part: 20 quasi-static passages of the fold gap
        self.horizon = 20.0 * (self.fold[0] - self.fold[1]) / (params.k * params.V)
        self.compiled = self.paper and not any(pl.alpha_model in _CLOSED for pl in self.plans)
        if self.compiled:  # the branch rows of the compiled returns (peelapprox._reduced._reducedmap_kernel)
            self.rows = np.array([[pl.v_in, pl.fp_in, pl.F_rate, pl.x_f, pl.x_lo, pl.x_hi,
                                   -1.0 if pl.t_max is None else pl.t_max, pl.max_steps, fold, kick, up]
                                  for pl, fold, kick, up in ((self.plans[0], self.fold[1], self.kick[1], 1.0),
                                                             (self.plans[1], self.fold[0], self.kick[0], 0.0))])
            self.loop = RK.returns(not law.inlined)

    def at(self, rtol: float) -> ReturnMap:
        """This map with its segments at the tolerance ``rtol`` (the same plans otherwise, not built again)."""
        other = copy.copy(self)
        other.rtol, other.returns, other.memo = rtol, 0, {}
        other.plans = tuple(dataclasses.replace(pl, rtol=rtol) for pl in self.plans)
        return other

    def plan(self, branch: str, v_in: float) -> SegmentPlan:
        bs = self.law.structure
        code = 0 if branch == "AB" else 1
        if self.plans and v_in == self.plans[code].v_in:
            return self.plans[code]
        am, ve = self.models[code]
        pl = self.book.get((branch, v_in))
        if pl is None:
            pl = self.book[(branch, v_in)] = segment_plan(
                self.params, self.law, branch, v_in=v_in, v_f=bs.v_max if code == 0 else bs.v_min, alpha_model=am,
                v_equation=ve, F_rate=None, rtol=self.rtol, t_max=None, max_steps=SEGMENT_MAX_STEPS)
            return pl
        a, e = K.ALPHA_MODELS.index(am), K.V_EQUATIONS.index(ve)
        if (pl.alpha_model, pl.v_equation, pl.rtol) == (a, e, self.rtol):
            return pl
        q = pl.q.copy()  # segment_plan's q depends on the chain through these two fields only
        q[K.Q_AM], q[K.Q_VE] = a, e
        return dataclasses.replace(pl, alpha_model=a, v_equation=e, q=q, rtol=self.rtol)

    def force(self, branch: int, a: float) -> float:
        """F on CONSTR at the fold of ``branch`` (0 AB: f_max, 1 CD: f_min) with the angle ``a``."""
        one_minus_c = 1.0 + math.sin(a) if self.paper else 1.0 - float(self.params.closure(a)[0])
        return self.fold[branch] / one_minus_c

    def segment(self, plan: SegmentPlan, F: float, a: float, ad: float) -> tuple[float, float, float]:
        """One stay: ``(duration, α, α̇)`` at its fold; :class:`MapStop` if it does not get there."""
        if time.perf_counter() > self.deadline:
            raise MapStop(None, None, self.returns, timeout=True)
        if plan.alpha_model in _CLOSED:
            run = run_segment(plan, F, a, ad)
            if run.code != DONE:
                raise MapStop(plan, run, self.returns)
            a, ad = alpha_at(run.y, run.q)
            return float(run.y[0]), a, ad
        y = self.lean(plan, F, a, ad)
        return float(y[0]), float(y[3]), float(y[4])

    def lean(self, plan: SegmentPlan, F: float, a: float, ad: float) -> np.ndarray:
        """:func:`peelapprox._reduced._segment.run_segment`'s arithmetic for an integrated α model (no closed form),
        without
        its per-call set-up: the same parameter vector, atol, horizon and driver call, so the same numbers bitwise;
        the final state ``(t, ln v, F, α, α̇)``."""
        p = self.params
        q = plan.q.copy()
        q[K.Q_FIN], q[K.Q_VIN], q[K.Q_FPIN], q[K.Q_S] = F, plan.v_in, plan.fp_in, plan.F_rate
        q[K.Q_AIN], q[K.Q_ADIN], q[K.Q_TAU] = a, ad, p.R * plan.fp_in / F
        q[K.Q_AMP] = q[K.Q_PH] = 0.0
        Om = float(np.sqrt(p.R * F / p.I))
        a_scale = max(abs(a), abs(ad) / Om, 1e-8)
        atol = plan.rtol * np.array([1e-3, 1.0, F, a_scale, Om * a_scale])
        t_max = plan.t_max if plan.t_max is not None else self.horizon + 20.0 * 2.0 * math.pi / Om
        y = np.array([0.0, math.log(plan.v_in), F, a, ad])
        cnt = np.zeros(5, dtype=np.int64)
        code = plan.drive(y, q, plan.law_arg, plan.law.coef, plan.rtol, atol, plan.x_f, plan.x_lo, plan.x_hi,
                          plan.branch == "AB", t_max, plan.max_steps, K.SAVE_NONE, _NO_T, np.empty((1, 5)), cnt)
        if code != DONE:
            raise MapStop(plan, SegmentRun(int(code), y, np.empty((0, 5)), cnt, q, a, ad, atol, float(t_max)),
                          self.returns)
        return y

    def run(self, x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``n`` returns from ``x``: the last section point and the returns' records (:meth:`ret`'s, one row each,
        shape ``(n, 6)``), compiled where the chain allows (:mod:`peelapprox._reduced._reducedmap_kernel`: the
        same numbers), else by :meth:`ret`.  With :attr:`memo` set, the returns from a section point and count
        already run are not run again (the same numbers: a return depends on its section point alone)."""
        memo = self.memo
        if memo is None:
            return self._run(x, n)
        key = (np.asarray(x, dtype=float).tobytes(), n)
        if key in memo:
            y, recs = memo[key]
            self.returns += n
            return y.copy(), recs
        y, recs = self._run(x, n)
        if len(memo) >= MEMO_SIZE:
            memo.clear()
        memo[key] = (y.copy(), recs)
        return y, recs

    def _run(self, x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        if not self.compiled:
            recs = []
            for _ in range(n):
                x, r = self.ret(x)
                recs.append(r)
            return x, np.array(recs, dtype=float).reshape(n, 6)
        x = np.array(x, dtype=float)
        rows = np.empty((n, 6))
        info = np.zeros(4, dtype=np.int64)
        stop = np.empty(6)
        pl = self.plans
        got = 0
        while got < n:
            if time.perf_counter() > self.deadline:
                raise MapStop(None, None, self.returns, timeout=True)
            self.loop(x, n - got, pl[0].q, pl[1].q, self.rows, pl[0].law_arg, pl[0].law.coef, self.rtol,
                      self.horizon, STEP_CAP, rows[got:], info, stop)
            done = int(info[RK.I_DONE])
            self.returns += done
            got += done
            if info[RK.I_CODE] != DONE:
                plan = pl[int(info[RK.I_BRANCH])]
                raise MapStop(plan, SegmentRun(int(info[RK.I_CODE]), stop[:5].copy(), np.empty((0, 5)),
                                               np.zeros(5, dtype=np.int64), plan.q, 0.0, 0.0, np.zeros(5),
                                               float(stop[5])), self.returns)
        return x, rows

    def ret(self, x: np.ndarray | tuple[float, float]) -> tuple[np.ndarray, tuple[float, ...]]:
        """One return from the section point ``x = (α, α̇)``: the next one, and ``(F at the AB→CD jump, F at the
        CD→AB jump, the CD stay, the AB stay, α at the two jumps)``."""
        a0, ad = float(x[0]), float(x[1])
        F = self.force(0, a0)
        t_cd, a, ad = self.segment(self.plans[1], F, a0, ad + self.kick[0])
        G = self.force(1, a)
        t_ab, a1, ad = self.segment(self.plans[0], G, a, ad + self.kick[1])
        self.returns += 1
        return np.array([a1, ad]), (F, G, t_cd, t_ab, a0, a)

    def power(self, x: np.ndarray, n: int) -> np.ndarray:
        return self.run(x, n)[0]

    def enter(self, start: tuple[int, float, float, float, float]) -> np.ndarray:
        """The first section point from a start ``(branch code, F, v, α, α̇)`` anywhere on a branch."""
        branch, F, v, a, ad = start
        if branch == 1:
            dt, a, ad = self.segment(self.plan("CD", v), F, a, ad)
            F, v, ad = self.force(1, a), self.law.structure.v_land_ab, ad + self.kick[1]
        dt, a, ad = self.segment(self.plan("AB", v), F, a, ad)
        return np.array([a, ad])

    def scale(self, x: np.ndarray) -> np.ndarray:
        """The coordinates' scales at ``x``: ``(A, A Ω)``, ``A = max(|α|, |α̇|/Ω, 1e-4)``."""
        A = max(abs(float(x[0])), abs(float(x[1])) / self.omega, 1e-4)
        return np.array([A, A * self.omega])



def jacobian(power: Callable[[np.ndarray, int], np.ndarray], x: np.ndarray, n: int, s: np.ndarray,
             fx: np.ndarray | None = None) -> np.ndarray:
    """``D P^n`` at ``x`` by central differences of step ``FD_STEP s``, or forward ones from ``fx = P^n(x)`` when
    given."""
    J = np.empty((x.size, x.size))
    for j in range(x.size):
        h = np.zeros(x.size)
        h[j] = FD_STEP * s[j]
        J[:, j] = (power(x + h, n) - power(x - h, n)) / (2.0 * h[j]) if fx is None else (power(x + h, n) - fx) / h[j]
    return J


def _scaled(d: np.ndarray, s: np.ndarray) -> float:
    """``max |d / s|`` of finite vectors, in Python floats (numpy's quotients and maximum, without its per-call
    cost)."""
    return max(abs(a / b) for a, b in zip(d.tolist(), s.tolist()))


def newton(m: Any, x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The period-n orbit's point near ``x`` and ``D P^n`` there (multipliers: its eigenvalues), or None when the
    chord iteration (a forward-difference Jacobian at ``x``, renewed once after three steps) does not converge to
    :data:`NEWTON_TOL` (the step relative to ``m.scale(x)``) in :data:`NEWTON_MAX_IT` steps, diverges (a step over
    half the scale) or a segment stops.

    ``m`` is any map of the plane with ``power(x, n)`` (``P^n(x)``) and ``scale(x)`` (:class:`ReturnMap`)."""
    s = m.scale(x)
    eye = np.eye(x.size)
    try:
        fx = m.power(x, n)
        J = jacobian(m.power, x, n, s, fx)
        for it in range(NEWTON_MAX_IT):
            r = fx - x
            if _scaled(r, s) < NEWTON_TOL:  # on the orbit already (a neutral direction need not be solved)
                return x, jacobian(m.power, x, n, s)
            try:
                dx = np.linalg.solve(J - eye, -r)
            except np.linalg.LinAlgError:
                return None
            if not all(math.isfinite(d) for d in dx.tolist()) or (step := _scaled(dx, s)) > 0.5:
                return None
            x = x + dx
            if step < NEWTON_TOL:
                return x, jacobian(m.power, x, n, s)
            fx = m.power(x, n)
            if it == 2:
                J = jacobian(m.power, x, n, s, fx)  # a fresh Jacobian once, near the orbit
    except MapStop:
        return None
    return None


def envelope(m: ReturnMap, J: np.ndarray, x: np.ndarray, xs: np.ndarray) -> float:
    """The envelope of the AB→CD force's deviation from the orbit through ``xs`` of the section point ``x``: its
    amplitude in the dominant eigen-coordinates of ``J = D P^n`` (a complex pair's plane, where the deviation turns
    by arg μ per period, or a real μ's left eigenvector) times the force's gradient along them.  One return's force
    deviation samples one phase of a turning deviation and may be far below the envelope that reaches the escape:
    with it 3 of the escape benchmark's 10 predictions were within 20 % of the exact escape, with the envelope 6,
    and 10 with the envelope and the exact orbit's |μ| (``python -m comparisons.benchmark.approx_targets --seed 1
    --points 100 --escapes 10``)."""
    mu, W = np.linalg.eig(J)
    i = int(np.argmax(np.abs(mu)))
    h = 1e-7
    g = np.array([(m.force(0, float(xs[0]) + h) - m.force(0, float(xs[0]) - h)) / (2.0 * h), 0.0])
    d = np.asarray(x, dtype=float) - xs
    if abs(mu[i].imag) > 1e-12 * abs(mu[i]):
        B = np.column_stack([W[:, i].real, W[:, i].imag])
        return float(np.linalg.norm(g @ B) * np.linalg.norm(np.linalg.solve(B, d)))
    left = np.linalg.inv(W.real)[i]
    return float(abs(g @ W.real[:, i]) * abs(left @ d))
