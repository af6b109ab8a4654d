"""Continuation of a periodic orbit in a parameter, with its bifurcations located (issue 16).

:func:`continue_orbit` follows a :class:`exact.PeriodicOrbit` in V, I, k or a coefficient of a family law
(``"force.c"``) by **natural continuation**: at each step the parameter moves by ``h``, the section state is
predicted by the secant through the last two points (the first step keeps it), and Newton (:func:`exact.
solve_orbit`, n fixed) corrects it.  Step control: a correction in at most 3 Newton iterations grows ``h`` by
1.5 (up to ``max_step``); a failed one, or one whose corrector moves the state farther than ``max_correction``
from the prediction (a jump to another, coexisting orbit), halves it, down to ``min_step``, where the branch
stops.

Between two accepted points the nontrivial Floquet multipliers are compared, and a crossing of the unit circle
is a bifurcation, located by bisection in the parameter (to ``locate_tol`` relative) on the quantity that
changes sign:

* **fold** (a real multiplier through +1: ``μ - 1``): the branch turns back; natural continuation cannot pass it
  and stops there (the step falls to ``min_step``);
* **period doubling** (a real multiplier through -1: ``μ + 1``);
* **Neimark-Sacker** (a complex pair through the unit circle: ``|μ| - 1``).

The non-smooth ends of a branch are reported as the reason it stopped: ``"grazing"`` (the orbit meets a fold
of f tangentially: the rate ``Ġ`` at which its level reaches the fold falls below ``graze_tol k V``; beyond it
the branch stay no longer ends in a jump there, the itinerary changes, and the multipliers diverge on the way
in), ``"breakdown"`` (a return breaks down, e.g. a landing no longer exists), ``"no_convergence"`` (Newton fails
at ``min_step``: the branch folds, or another non-smooth event), ``"stop"`` (the parameter reached ``stop``),
``"max_points"``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from peelapprox import PeelForce, PeelParams
from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure
from peelapprox.validate import function, in_range, integer, optional, real

from ._orbits import PeriodicOrbit, solve_orbit

__all__ = ["PARAMETERS", "Bifurcation", "BranchPoint", "OrbitBranch", "continue_orbit", "parameter_value",
           "with_parameter"]

#: The parameters of :func:`continue_orbit` besides a family law's coefficients (``"force.<name>"``).
PARAMETERS = ("V", "I", "k")


def _coefficient(params: PeelParams, parameter: str) -> str | None:
    """The family coefficient named by ``parameter`` (None for V, I, k); ValueError naming the valid ones."""
    if parameter in PARAMETERS:
        return None
    law = params.force
    name = parameter.removeprefix("force.")
    coefs = dict(law.coefficients)
    if not parameter.startswith("force.") or law.kind != "family" or name not in coefs:
        have = ", ".join(f"force.{c}" for c in coefs) if law.kind == "family" else "none (not a family law)"
        raise ValueError(f"parameter must be one of {', '.join(PARAMETERS)} or a coefficient of the family law "
                         f"params.force ({have}), got {parameter!r}")
    return name


def with_parameter(params: PeelParams, parameter: str, value: float) -> PeelParams:
    """``params`` with ``parameter`` (V, I, k or ``"force.<coefficient>"`` of a family law) set to ``value``."""
    name = _coefficient(params, parameter)
    if name is None:
        return params.replace(**{parameter: value})
    law = params.force
    return params.replace(force=PeelForce.family(str(law.name), **{**dict(law.coefficients), name: value}))


def parameter_value(params: PeelParams, parameter: str) -> float:
    """The value of ``parameter`` in ``params`` (:func:`with_parameter`)."""
    name = _coefficient(params, parameter)
    return float(getattr(params, parameter) if name is None else dict(params.force.coefficients)[name])


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
    """A bifurcation located on a branch: ``kind`` ("fold", "period_doubling", "neimark_sacker"), the
    parameter's ``value`` (bisection to ``locate_tol``) and the orbit there."""

    kind: str
    value: float
    orbit: PeriodicOrbit


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
        Why the branch ended: "stop", "max_points", "grazing", "breakdown", "no_convergence".
    message : str
        The detail (the exception's message for "breakdown"/"no_convergence").
    wall_time : float
    """

    parameter: str
    points: tuple[BranchPoint, ...]
    bifurcations: tuple[Bifurcation, ...]
    stopped: str
    message: str
    wall_time: float

    def rows(self) -> list[dict]:
        """Every point as a row (:meth:`BranchPoint.row`), for ``peelapprox.io.write_rows`` (CSV/JSON)."""
        return [p.row(self.parameter) for p in self.points]


def _crossing(a: PeriodicOrbit, b: PeriodicOrbit) -> str | None:
    """The bifurcation between two orbits of a branch, by their multipliers (module docstring), or None."""
    ma, mb = a.multipliers, b.multipliers
    real_a, real_b = np.all(np.abs(ma.imag) < 1e-12), np.all(np.abs(mb.imag) < 1e-12)
    if not real_a and not real_b:
        return "neimark_sacker" if (abs(ma[0]) - 1.0) * (abs(mb[0]) - 1.0) < 0 else None
    if real_a and real_b:
        for kind, level in (("fold", 1.0), ("period_doubling", -1.0)):
            sa, sb = np.sort(ma.real - level), np.sort(mb.real - level)
            if np.any(np.sign(sa) != np.sign(sb)):
                return kind
    return None


def _gauge(kind: str, o: PeriodicOrbit) -> float:
    """The quantity whose sign change marks ``kind`` (module docstring)."""
    mu = o.multipliers
    if kind == "neimark_sacker":
        return float(abs(mu[0]) - 1.0)
    level = 1.0 if kind == "fold" else -1.0
    return float(min(mu.real - level, key=abs))


def continue_orbit(orbit: PeriodicOrbit, parameter: str = "V", *, stop: float, step: float | None = None,
                   min_step: float | None = None, max_step: float | None = None, max_points: int = 200,
                   tol: float = 1e-10, rtol: float = 1e-12, locate_tol: float = 1e-8, max_correction: float = 0.02,
                   graze_tol: float = 1e-3,
                   progress: Callable[[int, float], None] | None = None) -> OrbitBranch:
    """Follow ``orbit`` in ``parameter`` up to ``stop``, locating its bifurcations (module docstring).

    Parameters
    ----------
    orbit : PeriodicOrbit
        The start (``exact.periodic_orbit``).
    parameter : {"V", "I", "k"} or "force.<coefficient>"
    stop : float
        The parameter value to continue to (either side of the start).
    step, min_step, max_step : float, optional
        Initial, smallest and largest step in the parameter (defaults: 1/50, 1/1e5 and 1/10 of
        ``|stop - start|``).
    max_points : int
        Most orbits on the branch, in [2, 100000].
    tol, rtol : float
        Newton's closing tolerance and the integration's (:func:`exact.periodic_orbit`).
    locate_tol : float
        Relative accuracy of a bifurcation's parameter value.
    max_correction : float
        Largest move of Newton's corrector from the secant prediction, relative to the section state in
        ``z = (α, ω R/V)``; a larger one is a jump to another orbit: the step is halved instead.
    graze_tol : float
        The branch stops with "grazing" when the rate ``Ġ`` at which the orbit meets one of its folds
        (``PeriodicOrbit.fold_rates``) falls below ``graze_tol * k V``.
    progress : callable, optional
        ``progress(points, value)`` after every accepted point.

    Returns
    -------
    OrbitBranch

    Raises
    ------
    ValueError, TypeError
        Bad arguments (named).
    """
    wall0 = time.perf_counter()
    if not isinstance(orbit, PeriodicOrbit):
        raise TypeError(f"orbit must be an exact.PeriodicOrbit, got {type(orbit).__name__}")
    lam0 = parameter_value(orbit.params, parameter)
    stop = real("stop", stop)
    span = abs(stop - lam0)
    if not span > 0:
        raise ValueError(f"stop must differ from the start's {parameter}={lam0}, got {stop}")
    sign = 1.0 if stop > lam0 else -1.0
    h = in_range("step", step, 0.0, span, lo_open=True) if step is not None else span / 50
    hmin = in_range("min_step", min_step, 0.0, span, lo_open=True) if min_step is not None else span * 1e-5
    hmax = in_range("max_step", max_step, 0.0, span, lo_open=True) if max_step is not None else span / 10
    max_points = integer("max_points", max_points, 2, 100_000)
    max_correction = in_range("max_correction", max_correction, 0.0, 1.0, lo_open=True)
    graze_tol = in_range("graze_tol", graze_tol, 0.0, 1.0)
    progress = optional(function, "progress", progress)

    scale = np.array([1.0, orbit.params.V / orbit.params.R])  # z = (α, ω R/V)
    points = [BranchPoint(lam0, orbit)]
    bifs: list[Bifurcation] = []
    stopped, message = "stop", ""
    n = orbit.n

    def solve(value: float, x0: np.ndarray) -> PeriodicOrbit:
        return solve_orbit(with_parameter(orbit.params, parameter, value), x0, n, tol=tol, rtol=rtol, max_iter=8)

    while len(points) < max_points:
        last = points[-1]
        if (stop - last.value) * sign <= 0:
            break
        hv = min(h, abs(stop - last.value))
        value = last.value + sign * hv
        x0 = last.orbit.section_states[0]
        if len(points) >= 2:  # secant predictor
            prev = points[-2]
            slope = (x0 - prev.orbit.section_states[0]) / (last.value - prev.value)
            x0 = x0 + slope * (value - last.value)
        try:
            o = solve(value, x0)
            jump = float(np.linalg.norm((o.section_states[0] - x0) / scale))
            if jump > max_correction * max(1.0, float(np.linalg.norm(x0 / scale))):
                raise ValueError(f"the corrector moved the section state by {jump:.3g} (scaled) from the "
                                 f"prediction: a jump to another orbit, refused (max_correction={max_correction})")
        except (ValueError, ModelBreakdown, SolverFailure, SolverBudgetExceeded) as exc:
            if h / 2 < hmin:
                stopped = "breakdown" if isinstance(exc, ModelBreakdown) else "no_convergence"
                message = str(exc)
                break
            h /= 2
            continue
        if np.min(np.abs(o.fold_rates)) < graze_tol * o.params.k * o.params.V:
            i = int(np.argmin(np.abs(o.fold_rates)))
            points.append(BranchPoint(value, o))
            stopped = "grazing"
            message = (f"the orbit meets the {'AB' if i % 2 else 'CD'} fold (fold {i + 1} of the period) almost "
                       f"tangentially at {parameter}={value:.10g}: dG/dt = {o.fold_rates[i]:.3g} N/s there (below "
                       f"graze_tol * k V); the period-{n} branch ends in a grazing bifurcation, where its "
                       "multipliers diverge")
            break
        kind = _crossing(last.orbit, o)
        if kind is not None:
            bifs.append(_locate(kind, last, BranchPoint(value, o), solve, locate_tol))
        points.append(BranchPoint(value, o))
        if progress:
            progress(len(points), value)
        h = min(hmax, h * 1.5) if len(o.newton) <= 3 else h
    else:
        stopped = "max_points"
    return OrbitBranch(parameter, tuple(points), tuple(bifs), stopped, message, time.perf_counter() - wall0)


def _locate(kind: str, a: BranchPoint, b: BranchPoint, solve: Callable[[float, np.ndarray], PeriodicOrbit],
            locate_tol: float) -> Bifurcation:
    """Bisection in the parameter between ``a`` and ``b`` on :func:`_gauge` (module docstring)."""
    ga = _gauge(kind, a.orbit)
    lo, hi, o_best = a, b, b.orbit
    for _ in range(60):
        if abs(hi.value - lo.value) <= locate_tol * max(abs(lo.value), abs(hi.value), 1e-300):
            break
        mid = 0.5 * (lo.value + hi.value)
        try:
            om = solve(mid, 0.5 * (lo.orbit.section_states[0] + hi.orbit.section_states[0]))
        except (ValueError, ModelBreakdown, SolverFailure, SolverBudgetExceeded):
            break
        gm = _gauge(kind, om)
        if gm == 0 or math.copysign(1.0, gm) != math.copysign(1.0, ga):
            hi, o_best = BranchPoint(mid, om), om
        else:
            lo, ga = BranchPoint(mid, om), gm
    value = 0.5 * (lo.value + hi.value)
    return Bifurcation(kind, value, o_best)

