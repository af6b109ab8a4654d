"""Continuation of a periodic orbit in a parameter, with its bifurcations located.

:func:`continue_orbit` follows a :class:`exact.PeriodicOrbit` in V, I, k or a coefficient of a family law
(``"force.c"``) by **pseudo-arclength continuation** in ``w = (α, ω R/V, λ/Λ)`` (the first section state,
scaled, and the parameter λ over the span ``Λ = |stop - start|``): the predictor steps ``h`` along the secant
through the last two points (from the start, along the branch's tangent, the null vector of ``[DP^n - 1,
∂P^n/∂λ]``, oriented towards ``stop``), and the corrector (:func:`exact.orbits._corrector.bordered_newton`, n fixed)
solves the closing condition ``P^n(x; λ) = x`` together with ``τ · (w - w_pred) = 0`` (the step orthogonal to
the secant).  Steps from an orbit with a real multiplier within ``FOLD_NEAR`` (0.25) of +1 are
pseudo-arclength steps, so the branch passes **folds**, where λ turns back; the others (and the last one onto
``stop``) are natural (λ fixed: Newton at fixed λ, no ``∂P/∂λ``): near a grazing the branch steepens like a
square root, which a pseudo-arclength step would follow around the corner where the orbit ceases to exist.
Step control: a correction in at most 3 Newton iterations grows ``h`` by 1.5 (up to ``max_step``);
a failed one, or one whose corrector moves the point farther than ``max_correction`` from the prediction (a
jump to another, coexisting orbit), halves it, down to ``min_step``, where the branch stops.  Steps are
arclengths measured in units of the parameter (``Λ`` times the arclength in ``w``).

Between two accepted points the nontrivial Floquet multipliers are compared, and a crossing of the unit circle
is a bifurcation, located by bisection along the arclength between the two points (to ``locate_tol`` relative
in λ and ``GAUGE_TOL`` in the gauge, or 40 halvings) on the quantity that changes sign:

* **fold** (a real multiplier through +1: ``μ - 1``): the branch turns back in λ (the located λ lies beyond
  both neighbouring points; where it lies between them, λ does not turn and the crossing is reported as a
  ``"branch_point"``);
* **period doubling** (a real multiplier through -1: ``μ + 1``); :func:`switch_branch` starts the doubled
  (period-2n) branch there (:mod:`exact.orbits._switch`);
* **Neimark-Sacker** (a complex pair through the unit circle: ``|μ| - 1``).

The non-smooth ends of a branch are reported as the reason it stopped (``OrbitBranch.stopped``, with the
parameter value of the event in ``end_value``, the linear extrapolation of the quantity that vanishes there
when it lies within two steps (or 1e-3 of the span) of the last point, else the last point):

* ``"grazing"``: the orbit meets a fold of f tangentially: the rate ``Ġ`` at which its level reaches the fold
  falls below ``graze_tol k V``; the multipliers diverge on the way in;
* ``"crest"``: an interior crest of ``F (1 + c(α))`` on AB reaches f_max (or a trough on CD reaches f_min):
  beyond it the solution jumps one oscillation earlier, the itinerary changes and this orbit no longer exists
  (:mod:`exact.orbits._crest`).  Detected when the crest margin of an accepted point falls below ``crest_tol``, or,
  when Newton fails at ``min_step``, when the last two points' margins extrapolate linearly to 0 within two
  steps or 1e-3 of the span; ``end_value`` is that extrapolation (likewise for a grazing, from ``Ġ²``, and a
  breakdown, from the lowest level on AB above f(0+));
* ``"breakdown"``: a return breaks down (e.g. CONSTR loses its root: a landing no longer exists);
* ``"no_convergence"``: Newton fails at ``min_step`` for another reason;
* ``"stop"`` (λ reached ``stop``), ``"range"`` (the branch turned back at a fold and left the range
  ``[start, stop]`` at the start's side), ``"max_points"``, ``"max_wall"`` (the call's wall-clock budget was
  spent: the branch holds the points accepted so far, and every bifurcation on it is located to ``locate_tol``;
  the budget is checked before each Newton iteration of the corrector, the returns of one iteration being
  compiled runs bounded by their step budget).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure, WallBudget

from .._shared import DEFAULT_MAX_WALL
from ._branch_end import NO_CREST, event_message, events_ahead, failure_end, near
from ._continuation_options import _checked_options, _Options
from ._corrector import (
    PARAMETERS,
    bordered_newton,
    branch_tangent,
    parameter_value,
    with_parameter,
)
from ._crest import crest_margin
from ._kinds import ENDS, KINDS, crossing, gauge, marker
from ._periodic import PeriodicOrbit, minimal_period

__all__ = ["FAILURES", "PARAMETERS", "Bifurcation", "BranchPoint", "OrbitBranch", "Stepper", "continue_orbit",
           "parameter_value", "with_parameter"]

@dataclass(frozen=True)
class BranchPoint:
    """One orbit of a branch: the parameter's value and the orbit (:class:`exact.PeriodicOrbit`)."""

    value: float
    orbit: PeriodicOrbit

    def row(self, parameter: str) -> dict:
        """A flat row (CSV/JSON): parameter, period, stability, multipliers (modulus, real, imaginary), return-map
        values."""
        o = self.orbit
        row: dict = {parameter: self.value, "n": o.n, "period": o.period, "stable": o.stable, "residual": o.residual}
        for i, mu in enumerate(o.multipliers):
            row.update({f"mu{i + 1}_abs": float(abs(mu)), f"mu{i + 1}_re": float(mu.real),
                        f"mu{i + 1}_im": float(mu.imag)})
        row.update({f"F{i + 1}": float(x) for i, x in enumerate(o.return_map_values)})
        return row


@dataclass(frozen=True)
class Bifurcation:
    """A bifurcation located on a branch: ``kind`` ("fold", "period_doubling", "neimark_sacker",
    "branch_point"), the parameter's ``value`` (bisection to ``locate_tol``), the orbit there and the
    ``parameter``'s name."""

    kind: str
    value: float
    orbit: PeriodicOrbit
    parameter: str = "V"

    @property
    def marker(self) -> tuple[str, str]:
        """The matplotlib marker and colour of its kind (:data:`exact.orbits._kinds.BIFURCATIONS`)."""
        return marker(self.kind)

    @property
    def doubles(self) -> bool:
        """A period doubling: :func:`exact.switch_branch` starts the doubled branch here."""
        return self.kind == "period_doubling"


@dataclass(frozen=True)
class OrbitBranch:
    """A continued branch of periodic orbits (:func:`continue_orbit`).

    Attributes
    ----------
    parameter : str
    points : tuple of BranchPoint
        In the order continued (the start first).
    bifurcations : tuple of Bifurcation
    stopped : str
        Why the branch ended: "stop", "range", "max_points", "max_wall", "grazing", "crest", "breakdown",
        "no_convergence" (module docstring).
    message : str
        The detail (the exception's message for "breakdown"/"no_convergence").
    wall_time : float
    end_value : float
        The parameter's value at the end: the extrapolated event for "crest", else the last point's.
    """

    parameter: str
    points: tuple[BranchPoint, ...]
    bifurcations: tuple[Bifurcation, ...]
    stopped: str
    message: str
    wall_time: float
    end_value: float = math.nan

    @property
    def end_marker(self) -> str | None:
        """The matplotlib marker of its non-smooth end (:data:`exact.orbits._kinds.ENDS`), None for another stop."""
        return KINDS[self.stopped].marker if self.stopped in {k.name for k in ENDS} else None

    def rows(self) -> list[dict]:
        """Every point as a row (:meth:`BranchPoint.row`), for ``peelapprox.io.write_rows`` (CSV/JSON)."""
        return [p.row(self.parameter) for p in self.points]

    def to_dataframe(self) -> object:
        """:meth:`rows` as a :class:`pandas.DataFrame`, one row per point in the order continued; ``df.attrs``:
        ``units`` (per column), ``parameter``, ``stopped``, ``end_value``, ``message``, ``bifurcations``
        (``[{"kind", "value"}]``) and ``params`` (the start's).  ImportError without pandas."""
        from ._branch_out import branch_dataframe

        return branch_dataframe(self)

    def __repr__(self) -> str:
        from ._branch_out import branch_summary

        return branch_summary(self, short=True)

    def _repr_html_(self) -> str:
        from ._branch_out import branch_summary

        return branch_summary(self, short=False)


class Stepper:
    """The corrector of one branch: points ``w`` and bordered Newton at a prediction (module docstring)."""

    def __init__(self, orbit: PeriodicOrbit, parameter: str, lam_scale: float, tol: float, rtol: float,
                 wall: WallBudget | None = None):
        self.base, self.parameter, self.ls, self.tol, self.rtol = orbit.params, parameter, lam_scale, tol, rtol
        self.scale = np.array([1.0, orbit.params.V / orbit.params.R])  # z = (α, ω R/V)
        self.n = orbit.n
        self.wall = wall

    def w(self, p: BranchPoint) -> np.ndarray:
        return np.concatenate([p.orbit.section_states[0] / self.scale, [p.value / self.ls]])

    def params_at(self, value: float):
        return with_parameter(self.base, self.parameter, value)

    def correct(self, w_pred: np.ndarray, tau: np.ndarray, n: int | None = None, max_iter: int = 12,
                max_dlam: float = math.inf) -> BranchPoint:
        o, lam = bordered_newton(self.params_at, n or self.n, w_pred[:2] * self.scale, float(w_pred[2] * self.ls),
                                 tau, w_pred, self.scale, self.ls, tol=self.tol, rtol=self.rtol, max_iter=max_iter,
                                 max_dlam=max_dlam, wall=self.wall)
        return BranchPoint(lam, o)


FAILURES = (ValueError, ModelBreakdown, SolverFailure, SolverBudgetExceeded)


def _out_of_wall(exc: BaseException) -> bool:
    """Whether ``exc`` is the call's wall budget running out (the section returns have no wall clock of their own:
    a ``max_wall`` exception inside a continuation is always the call's)."""
    return isinstance(exc, SolverBudgetExceeded) and exc.budget == "max_wall"


def _spent(wall: WallBudget) -> bool:
    return wall.limit is not None and time.perf_counter() - wall.t0 >= wall.limit


def continue_orbit(orbit: PeriodicOrbit, parameter: str = "V", *, stop: float, step: float | None = None,
                   min_step: float | None = None, max_step: float | None = None, max_points: int = 200,
                   tol: float = 1e-10, rtol: float = 1e-12, locate_tol: float = 1e-8, max_correction: float = 0.02,
                   graze_tol: float = 1e-3, crest_tol: float = 1e-6,
                   progress: Callable[[int, float], None] | None = None,
                   max_wall: float | None = DEFAULT_MAX_WALL) -> OrbitBranch:
    """Follow ``orbit`` in ``parameter`` towards ``stop``, locating its bifurcations (module docstring).

    Parameters
    ----------
    orbit : PeriodicOrbit
        The start (``exact.periodic_orbit``).
    parameter : {"V", "I", "k"} or "force.<coefficient>"
        A coefficient of the family law ``orbit.params.force``.
    stop : float
        The parameter value to continue to (either side of the start): finite, a valid value of ``parameter``
        (``PeelParams``' range), not the start's.
    step, min_step, max_step : float, optional
        Initial, smallest and largest arclength step, in units of the parameter (defaults: 1/50, 1/1e5 and 1/10
        of ``|stop - start|``).
    max_points : int
        Most orbits on the branch, in [2, 100000].
    tol, rtol : float
        Newton's closing tolerance, in [1e-14, 1e-3], and the integration's, in [1e-14, 1e-6]
        (:func:`exact.periodic_orbit`).
    locate_tol : float
        Relative accuracy of a bifurcation's parameter value, in (0, 1).
    max_correction : float
        Largest move of the corrector from the prediction, relative to ``max(1, |w|)``; a larger one is a jump
        to another orbit: the step is halved instead.
    graze_tol : float
        The branch stops with "grazing" when the rate ``Ġ`` at which the orbit meets one of its folds
        (``PeriodicOrbit.fold_rates``) falls below ``graze_tol * k V``.
    crest_tol : float
        The branch stops with "crest" when an interior crest of the orbit comes within ``crest_tol (f_max -
        f_min)`` of its fold (:func:`exact.orbits._crest.crest_margin`, one run of a period per point); 0 checks only
        when Newton fails.
    progress : callable, optional
        ``progress(points, value)`` after every accepted point.
    max_wall : float or None
        Wall-clock budget [s] of the whole continuation (None: unbounded; default
        :data:`exact.DEFAULT_MAX_WALL`, 3600 s).  When it is spent the branch ends like any other, with
        ``stopped="max_wall"`` and the points accepted so far (a budget is a reason a branch ends, as
        ``max_points`` is, not an error); continue from ``branch.points[-1].orbit`` to go on.

    Returns
    -------
    OrbitBranch

    Raises
    ------
    ValueError, TypeError
        Bad arguments (named, with the valid values: ``parameter`` lists the parameters of ``orbit``'s law).
    """
    wall0 = time.perf_counter()
    a = _checked_options(orbit, parameter, stop, step, min_step, max_step, max_points, tol, rtol, locate_tol,
                         max_correction, graze_tol, crest_tol, progress, max_wall)
    run = _Continuation(orbit, a, Stepper(orbit, a.parameter, a.span, a.tol, a.rtol, a.wall))
    while len(run.points) < a.max_points and not run.step():
        pass
    end_value = run.points[-1].value if math.isnan(run.end_value) else run.end_value
    return OrbitBranch(a.parameter, tuple(run.points), tuple(run.bifs), run.stopped, run.message,
                       time.perf_counter() - wall0, end_value)


class _Continuation:
    """One continuation under way: the points, their crest margins, the bifurcations, the step ``h`` and, once
    it ended, why (``stopped``, ``message``, ``end_value``; NaN: the last point's)."""

    def __init__(self, orbit: PeriodicOrbit, a: _Options, st: Stepper):
        self.orbit, self.a, self.st, self.h = orbit, a, st, a.h
        self.points = [BranchPoint(a.lam0, orbit)]
        self.crests = [crest_margin(orbit) if a.crest_tol > 0 else NO_CREST]
        self.bifs: list[Bifurcation] = []
        self.stopped, self.message, self.end_value = "max_points", "", math.nan

    def end(self, stopped: str, message: str = "", end_value: float = math.nan) -> bool:
        self.stopped, self.message, self.end_value = stopped, message, end_value
        return True

    def out_of_wall(self) -> bool:
        return self.end("max_wall", _wall_message(self.a.wall, self.points, self.a.parameter))

    def step(self) -> bool:
        """One predictor-corrector step (the step halved on a failure); True when the branch ended."""
        a, st = self.a, self.st
        if _spent(a.wall):
            return self.out_of_wall()
        last = self.points[-1]
        w_pred, tau_c, final = self.predict(last)
        try:
            if self.h < a.hmin:
                raise ValueError(f"the step fell below min_step={a.hmin:.3g} before an extrapolated event")
            pt = st.correct(w_pred, tau_c)
            _check_correction(st, pt, w_pred, a.max_correction)
        except FAILURES as exc:
            if _out_of_wall(exc):
                return self.out_of_wall()
            if self.h / 2 >= a.hmin:
                self.h /= 2
                return False
            return self.end(*failure_end(exc, self.points, self.crests, a.parameter, a.span))
        return self.accept(last, pt, final)

    def predict(self, last: BranchPoint) -> tuple[np.ndarray, np.ndarray, bool]:
        """The prediction from ``last``, the corrector's direction (pseudo-arclength near a fold, else λ fixed)
        and whether it is the last step (natural, onto ``stop``); shortens ``h`` before an extrapolated event."""
        a, st, e_lam = self.a, self.st, np.array([0.0, 0.0, 1.0])
        wl = st.w(last)
        if len(self.points) == 1:  # the branch's tangent, towards stop
            tau = branch_tangent(st.params_at, self.orbit, a.lam0, st.scale, a.span, a.rtol)
            tau = tau if tau[2] * a.sign >= 0 else -tau
        else:
            tau = st.w(last) - st.w(self.points[-2])
            tau = tau / np.linalg.norm(tau)
        ahead = [v for e, v in events_ahead(self.points, self.crests).items() if e != "grazing"]
        if ahead and abs(tau[2]) > 0:  # approach an extrapolated crest or breakdown geometrically, never step over
            self.h = min(self.h, 0.5 * min(abs(v - last.value) for v in ahead) / abs(tau[2]))
        w_pred, tau_c, final = wl + (self.h / a.span) * tau, (tau if _near_fold(last.orbit) else e_lam), False
        if (w_pred[2] * a.span - a.stop) * a.sign >= 0 and tau[2] * a.sign > 0:  # the last step: natural, onto stop
            w_pred = wl + tau * ((a.stop / a.span - wl[2]) / tau[2])
            tau_c, final = e_lam, True
        return w_pred, tau_c, final

    def accept(self, last: BranchPoint, pt: BranchPoint, final: bool) -> bool:
        """Add the corrected point ``pt`` (a bifurcation since ``last`` located); True when the branch ends there."""
        a, o = self.a, pt.orbit
        if np.min(np.abs(o.fold_rates)) < a.graze_tol * o.params.k * o.params.V:
            return self.grazing(last, pt)
        kind = crossing(last.orbit.multipliers, o.multipliers)
        if kind is not None:
            try:
                self.bifs.append(_locate(kind, last, pt, self.st, a.locate_tol))
            except SolverBudgetExceeded:  # the wall budget, mid-bisection: end before the unlocated crossing
                return self.out_of_wall()
        self.points.append(pt)
        self.crests.append(crest_margin(o) if a.crest_tol > 0 else NO_CREST)
        if a.progress:
            a.progress(len(self.points), pt.value)
        c = self.crests[-1]
        if min(c.margin, c.floor) < a.crest_tol:
            event = "crest" if c.margin <= c.floor else "breakdown"
            ev = events_ahead(self.points, self.crests).get(event, pt.value)
            end_value = near(ev, pt.value, last.value, a.span)
            return self.end(event, event_message(event, c, end_value, a.parameter), end_value)
        if final:
            return self.end("stop")
        lo_end, hi_end = min(a.lam0, a.stop), max(a.lam0, a.stop)
        if not lo_end - 0.01 * a.span <= pt.value <= hi_end + 0.01 * a.span:
            return self.end("range", f"the branch turned back at a fold and left [{lo_end:.10g}, {hi_end:.10g}] at "
                                     f"{pt.value:.10g}")
        self.h = min(a.hmax, self.h * 1.5) if len(o.newton) <= 3 else self.h
        return False

    def grazing(self, last: BranchPoint, pt: BranchPoint) -> bool:
        """End at ``pt``, where the orbit meets a fold almost tangentially."""
        o = pt.orbit
        i = int(np.argmin(np.abs(o.fold_rates)))
        self.points.append(pt)
        self.crests.append(NO_CREST)
        ev = events_ahead(self.points, self.crests).get("grazing", pt.value)
        return self.end("grazing", f"the orbit meets the {'AB' if i % 2 else 'CD'} fold (fold {i + 1} of the period) "
                                   f"almost tangentially at {self.a.parameter}={pt.value:.10g}: dG/dt = "
                                   f"{o.fold_rates[i]:.3g} N/s there (below graze_tol * k V); the period-{self.st.n} "
                                   "branch ends in a grazing bifurcation, where its multipliers diverge",
                        near(ev, pt.value, last.value, self.a.span))


def _wall_message(wall: WallBudget, points: list[BranchPoint], parameter: str) -> str:
    return (f"the wall-clock budget max_wall={wall.limit:g} s was spent after {len(points)} orbit"
            f"{'s' * (len(points) != 1)}, the last at {parameter}={points[-1].value:.10g}: continue from "
            "branch.points[-1].orbit with a larger max_wall, or None")


#: A located bifurcation's orbit has its gauge (``μ ∓ 1`` or ``|μ| - 1``) within this of 0 (or 40 halvings were
#: spent): at a fold λ is stationary along the branch, so λ alone would stop the bisection with μ still far
#: from 1.
GAUGE_TOL = 1e-6
#: A real multiplier within this distance of +1 makes the next step pseudo-arclength (a fold may be ahead).
FOLD_NEAR = 0.25


def _near_fold(o: PeriodicOrbit) -> bool:
    mu = o.multipliers
    return bool(np.any((np.abs(mu.imag) < 1e-12) & (np.abs(mu.real - 1.0) < FOLD_NEAR)))


def _check_correction(st: Stepper, pt: BranchPoint, w_pred: np.ndarray, max_correction: float) -> None:
    """ValueError when the corrector jumped to another orbit: it moved too far from the prediction, or reached
    an orbit of a smaller period (a divisor of n) than the branch's."""
    move = float(np.linalg.norm(st.w(pt) - w_pred))
    if move > max_correction * max(1.0, float(np.linalg.norm(w_pred))):
        raise ValueError(f"the corrector moved the point by {move:.3g} (scaled) from the prediction: a jump to "
                         f"another orbit, refused (max_correction={max_correction})")
    d = minimal_period(pt.orbit)
    if d < st.n:
        raise ValueError(f"the corrector reached an orbit of period {d}, not {st.n}: refused")


def _locate(kind: str, a: BranchPoint, b: BranchPoint, st: Stepper, locate_tol: float) -> Bifurcation:
    """Bisection along the arclength from ``a`` to ``b`` on the kind's test value
    (:func:`exact.orbits._kinds.gauge`)."""
    wa, wb = st.w(a), st.w(b)
    tau = (wb - wa) / np.linalg.norm(wb - wa)
    ga = gauge(kind, a.orbit.multipliers)
    lo, hi, best = 0.0, 1.0, b
    pa, pb = a, b
    for _ in range(40):
        if (abs(pb.value - pa.value) <= locate_tol * max(abs(pa.value), abs(pb.value), 1e-300)
                and abs(gauge(kind, best.orbit.multipliers)) <= GAUGE_TOL):
            break
        mid = 0.5 * (lo + hi)
        try:
            pm = st.correct(wa + mid * (wb - wa), tau)
        except FAILURES as exc:
            if _out_of_wall(exc):
                raise
            break
        gm = gauge(kind, pm.orbit.multipliers)
        if gm == 0 or math.copysign(1.0, gm) != math.copysign(1.0, ga):
            hi, pb, best = mid, pm, pm
        else:
            lo, pa, ga = mid, pm, gm
    value = 0.5 * (pa.value + pb.value)
    if kind == "fold" and min(a.value, b.value) < value < max(a.value, b.value):
        kind = "branch_point"  # a multiplier through +1 where λ does not turn back: not a fold
    return Bifurcation(kind, value, best.orbit, st.parameter)
