"""Periodic orbits of the hybrid DAE as objects: fixed points of the section map ``P^n``
(:mod:`exact.orbits._section`) by Newton, and their Floquet multipliers.

**Newton** on ``G(z) = P^n(z) - z`` in the scaled coordinates ``z = (α, ω R/V)`` with ``DG = DP^n - 1``;
a step that does not reduce ``|G|`` is halved (at most 8 times).  Converged when the closing residual
``|P^n(z) - z| / max(1, |z|)`` is at most ``tol``.  The **nontrivial Floquet multipliers** are the two
eigenvalues of ``DP^n`` at the orbit (the flow direction and the constraint are removed by the section);
the orbit is stable if both lie inside the unit circle.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from peelapprox import T_TRANSIENT, PeelParams
from peelapprox.errors import SolverBudgetExceeded, WallBudget
from peelapprox.io import fmt_number, html_table
from peelapprox.validate import duration, in_range, integer, optional, positive
from peelapprox.validate import params as _params

from .._shared import DEFAULT_MAX_WALL, paper_model_only
from .._tangent import TangentSystem
from ._section import Composed, compose, section_F, section_return_n, system_of
from ._start import check_start, seed

__all__ = ["NEAR_GRAZING", "SAME_STATE", "PeriodicOrbit", "grazing_warning", "check_wall", "make_orbit",
           "minimal_period", "periodic_orbit", "solve_orbit"]

@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic stick-slip orbit: a fixed point of ``P^n`` on the AB→CD section (:func:`periodic_orbit`).

    Attributes
    ----------
    params : PeelParams
    n : int
        AB→CD jumps per period.
    period : float
        Period [s].
    section_states : ndarray, shape (n, 2)
        ``(α, ω)`` at the n AB→CD jumps of one period, in order.
    return_map_values : ndarray, shape (n,)
        F [N] at those jumps (``f_max / (1 + c(α))``): the return-map values of ``peelapprox.return_map``.
    itinerary : tuple of str
        The branch stays of one period, in order (``("CD", "AB") * n`` in this model).
    multipliers : ndarray of complex, shape (2,)
        The nontrivial Floquet multipliers (eigenvalues of ``DP^n``), by decreasing modulus.
    stable : bool
        Both multipliers inside the unit circle.
    residual : float
        The closing residual ``|P^n(z) - z| / max(1, |z|)`` in the scaled coordinates ``z = (α, ω R/V)``.
    newton : tuple of float
        The residual at each Newton iterate (the last is ``residual``).
    monodromy : ndarray, shape (2, 2)
        ``DP^n`` at the orbit, in ``(α, ω)``.
    fold_rates : ndarray, shape (2 n,)
        ``Ġ`` [N/s] on arrival at each fold of one period (CD, AB, CD, AB, ...): near 0 the orbit grazes a fold
        (a non-smooth bifurcation: the multipliers diverge).  :attr:`min_fold_rate` is the smallest; below
        :data:`NEAR_GRAZING` of their median the orbit warns (its precision is limited: a fold passed at
        ``Ġ ≈ 2e-5`` N/s once per period, as the period-49 orbit at V = 4, I = 1e-2 does, closes only to ~1e-8).
    steps, wall_time : int, float
        Accepted integration steps and seconds spent (all Newton iterations).
    """

    params: PeelParams
    n: int
    period: float
    section_states: np.ndarray
    return_map_values: np.ndarray
    itinerary: tuple[str, ...]
    multipliers: np.ndarray
    stable: bool
    residual: float
    newton: tuple[float, ...]
    monodromy: np.ndarray
    fold_rates: np.ndarray = field(default_factory=lambda: np.zeros(0))
    steps: int = 0
    wall_time: float = 0.0

    def trajectory(self, *, rtol: float = 1e-12, save: str = "steps", t_eval: Any = None) -> Any:
        """One period of the orbit by ``exact.simulate``, from the first AB→CD jump (just after it, on CD);
        ``t_eval`` (times in [0, period]) samples it there instead of at the steps (``save``)."""
        from .._simulate import simulate

        a, w = self.section_states[0]
        return simulate(self.params, self.period, alpha0=float(a), omega0=float(w),
                        F0=float(self.return_map_values[0]), branch0="CD", rtol=rtol, save=save, t_eval=t_eval)

    @property
    def min_fold_rate(self) -> float | None:
        """The smallest ``|Ġ|`` [N/s] on arrival at a fold (None without fold rates)."""
        return float(np.min(np.abs(self.fold_rates))) if self.fold_rates.size else None

    def _summary(self) -> dict:
        F = self.return_map_values
        return {"n": self.n, "period [s]": self.period, "stable": self.stable, "min |Ġ| at a fold [N/s]":
                self.min_fold_rate,
                "|μ|": ", ".join(fmt_number(abs(m), 4) for m in self.multipliers),
                "F at the AB→CD jumps [N]": ", ".join(fmt_number(x, 7) for x in F[:4]) + (" …" if F.size > 4 else ""),
                "residual": self.residual, "V [m/s]": self.params.V, "I [kg m²]": self.params.I}

    def __repr__(self) -> str:
        d = self._summary()
        return (f"PeriodicOrbit(period-{self.n}, T={fmt_number(self.period, 6)} s, "
                f"{'stable' if self.stable else 'unstable'}, |mu|=[{d['|μ|']}], F=[{d['F at the AB→CD jumps [N]']}] N, "
                f"residual={fmt_number(self.residual, 2)}, V={self.params.V:g}, I={self.params.I:g})")

    def _repr_html_(self) -> str:
        return html_table(f"PeriodicOrbit (period-{self.n})", self._summary())


def periodic_orbit(params: PeelParams, *, start: Any = None, n: int | None = None, t_transient: float = T_TRANSIENT,
                   window: float = 20.0, tol: float = 1e-10, rtol: float = 1e-12, max_iter: int = 30,
                   max_period: int = 32, max_wall: float | None = DEFAULT_MAX_WALL) -> PeriodicOrbit:
    """A periodic orbit of the hybrid DAE with ``n`` AB→CD jumps per period, by Newton on the section map.

    Parameters
    ----------
    params : PeelParams
        Any law with folds at V.
    start : None, exact.Trajectory or exact.State
        Where to look: None runs ``exact.simulate`` from the default start for ``t_transient + window`` s; a
        State runs from it; a Trajectory is used as it is (its jumps after its own ``t_transient``).  Newton
        starts from the AB→CD jump whose state comes back nearest after n returns (exact on a periodic
        attractor; a near-recurrence of a chaotic run seeds an unstable orbit).  A State's fields must lie in
        their ranges (``t`` in [0, 1e6], ``alpha``, ``omega``, ``F``, ``v`` in ``STATE_RANGES``, ``branch`` "AB"
        or "CD", ``Vp`` None under velocity control); a Trajectory must be a run of ``params`` (same parameters
        and peel-force law).
    n : int, optional
        AB→CD jumps per period (default: the period of the run's return map, ``peelapprox.periodicity``).  When
        Newton closes an orbit whose own period is a divisor d of n (a run read as period 2d before it settled),
        the orbit is returned with n = d.
    t_transient, window : float
        Transient and window of the run that seeds Newton [s].
    tol : float
        Closing tolerance of the scaled residual (module docstring), in [1e-14, 1e-3].
    rtol : float
        Relative tolerance of the integrations, in [1e-14, 1e-6].
    max_iter : int
        Newton iterations, in [1, 200].
    max_period : int
        Largest period looked for when ``n`` is None.
    max_wall : float or None
        Wall-clock budget [s] of the whole call, the seed run's and every Newton iteration's (checked before
        each); None: unbounded.  Default :data:`exact.DEFAULT_MAX_WALL` (3600 s).

    Returns
    -------
    PeriodicOrbit

    Raises
    ------
    ValueError
        Bad arguments (``start.<field>`` for a bad start); no stick-slip or no period found in the run (give
        n); Newton did not converge within ``max_iter`` (the message gives the residual history).
    ModelBreakdown, SolverBudgetExceeded, SolverFailure
        A return breaks down or never comes; ``SolverBudgetExceeded`` with ``budget="max_wall"`` when
        ``max_wall`` is spent.
    """
    wall0 = time.perf_counter()
    params = _params("params", params)
    paper_model_only(params, "periodic_orbit (Newton on the hybrid AB->CD section map with saltation matrices)",
                     "use exact.orbit_diagram or exact.attractors for the variant's periods")
    n = optional(integer, "n", n, 1, 10_000)
    t_transient = duration("t_transient", t_transient, zero=True)
    window = duration("window", window)
    tol = in_range("tol", tol, 1e-14, 1e-3)
    rtol = in_range("rtol", rtol, 1e-14, 1e-6)
    max_iter = integer("max_iter", max_iter, 1, 200)
    max_period = integer("max_period", max_period, 1, 1000)
    check_start(params, start)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    ts = system_of(params)  # no folds: no section (before the seed run)
    try:
        x, n = seed(params, start, n, t_transient, window, max_period, min(1e-10, 100 * rtol),
                    wall.left(0.0, {"t": 0.0}, t_transient + window))
    except SolverBudgetExceeded as exc:
        raise wall.reraise(exc) from None
    o = solve_orbit(params, x, n, tol=tol, rtol=rtol, max_iter=max_iter, system=ts, wall=wall)
    d = minimal_period(o)
    if d < n:  # e.g. a slowly settling run read as period 2d: the orbit itself has the smaller period
        o = solve_orbit(params, o.section_states[0], d, tol=tol, rtol=rtol, max_iter=max_iter, system=ts, wall=wall)
    return dataclasses.replace(o, wall_time=time.perf_counter() - wall0)


def check_wall(wall: WallBudget | None, what: str, x: np.ndarray) -> None:
    """:class:`peelapprox.SolverBudgetExceeded` (``budget="max_wall"``, the section state ``x = (α, ω)`` at t = 0 of
    the return about to start) once ``wall`` is spent: the check between the returns of a Newton iteration (a
    return is one compiled run, bounded by its step budget, without a wall clock of its own)."""
    if wall is None or wall.limit is None or time.perf_counter() - wall.t0 < wall.limit:
        return
    state = {"t": 0.0, "alpha": float(x[0]), "omega": float(x[1])}
    raise SolverBudgetExceeded(f"{what}: more than {wall.limit:g} s of wall time (max_wall) at the section state "
                               f"alpha={x[0]:.6g} rad, omega={x[1]:.6g} rad/s; pass a larger max_wall, or None",
                               budget="max_wall", limit=wall.limit, t=0.0, state=state)


#: Two section states of an orbit are the same point when they agree to this (scaled, relative).
SAME_STATE = 1e-6


def minimal_period(orbit: PeriodicOrbit) -> int:
    """The smallest divisor d of ``orbit.n`` with the section state d returns on equal to the first (to
    :data:`SAME_STATE` in the scaled coordinates): the orbit's own period in AB→CD jumps."""
    z = orbit.section_states / np.array([1.0, orbit.params.V / orbit.params.R])
    for d in range(1, orbit.n):
        if orbit.n % d == 0 and np.linalg.norm(z[d] - z[0]) < SAME_STATE * max(1.0, float(np.linalg.norm(z[0]))):
            return d
    return orbit.n


def solve_orbit(params: PeelParams, x0: Any, n: int, *, tol: float = 1e-10, rtol: float = 1e-12,
                max_iter: int = 30, system: TangentSystem | None = None, wall: WallBudget | None = None
                ) -> PeriodicOrbit:
    """Newton on ``P^n(x) = x`` from the section state ``x0 = (α, ω)`` (module docstring); the work of
    :func:`periodic_orbit` after its start, for callers with a start of their own (continuation).  ``wall``: the
    caller's wall-clock budget, checked before each Newton iteration (:func:`check_wall`).

    Raises
    ------
    ValueError
        Newton did not close the orbit to ``tol`` within ``max_iter`` iterations (the residuals are listed).
    ModelBreakdown, SolverBudgetExceeded, SolverFailure
        A return breaks down or never comes; ``wall`` is spent (``budget="max_wall"``).
    """
    wall0 = time.perf_counter()
    ts = system or system_of(params)
    x = np.asarray(x0, dtype=float).reshape(2).copy()
    s = np.array([1.0, params.V / params.R])  # z = x / s
    history: list[float] = []
    steps = 0
    for _ in range(max_iter):
        check_wall(wall, "periodic_orbit", x)
        c = compose(params, ts, x, n, rtol)
        steps += c.steps
        z, g = x / s, (c.x - x) / s
        res = float(np.linalg.norm(g) / max(1.0, np.linalg.norm(z)))
        history.append(res)
        if res <= tol:
            break
        Js = c.jacobian * s[None, :] / s[:, None]  # DP^n in z
        dz = np.linalg.solve(Js - np.eye(2), -g)
        lam = 1.0
        for _ in range(9):  # halve a step that does not reduce the residual
            x_try = (z + lam * dz) * s
            xt = section_return_n(params, ts, x_try, n, rtol)
            steps += xt.steps
            r_try = float(np.linalg.norm((xt.x - x_try) / s) / max(1.0, np.linalg.norm(x_try / s)))
            if r_try < res:
                break
            lam *= 0.5
        x = x_try
    else:
        raise ValueError(f"periodic_orbit: Newton did not close the period-{n} orbit to tol={tol} in "
                         f"max_iter={max_iter} iterations; residuals {', '.join(f'{r:.3g}' for r in history)}")
    grazing_warning(c.fold_rates, len(c.states))  # not in make_orbit: a continuation reports a grazing as its end
    return make_orbit(params, ts, c, history, steps, wall0)


#: A fold rate below this fraction of the orbit's median fold rate is a near-grazing (:class:`PeriodicOrbit`).
NEAR_GRAZING = 1e-4


def grazing_warning(fold_rates: np.ndarray, n: int) -> None:
    """Warn (RuntimeWarning) when the smallest ``|Ġ|`` of a period-n orbit is below :data:`NEAR_GRAZING` of the
    median: a near-grazing that limits the orbit's precision and makes its multipliers sensitive."""
    g = np.abs(np.asarray(fold_rates, dtype=float))
    if g.size and float(np.median(g)) > 0 and float(g.min()) < NEAR_GRAZING * float(np.median(g)):
        warnings.warn(f"the period-{n} orbit passes a fold at |Gdot| = {fmt_number(float(g.min()), 3)} N/s, "
                      f"{fmt_number(float(g.min() / np.median(g)), 2)} of its median fold rate: near a grazing "
                      "bifurcation its precision is limited and its multipliers are sensitive (docs/orbits.md)",
                      RuntimeWarning, stacklevel=3)


def make_orbit(params: PeelParams, ts: TangentSystem, c: Composed, history: list[float], steps: int,
               wall0: float) -> PeriodicOrbit:
    """The :class:`PeriodicOrbit` of a closed Newton iteration (``c``: :func:`compose` at the orbit)."""
    n = len(c.states)
    mu = np.linalg.eigvals(c.jacobian)
    mu = mu[np.argsort(-np.abs(mu))]
    return PeriodicOrbit(params=params, n=n, period=c.period, section_states=c.states,
                         return_map_values=section_F(params, ts, c.states[:, 0]), itinerary=("CD", "AB") * n,
                         multipliers=mu, stable=bool(np.all(np.abs(mu) < 1.0)), residual=history[-1],
                         newton=tuple(history), monodromy=c.jacobian, fold_rates=c.fold_rates, steps=steps,
                         wall_time=time.perf_counter() - wall0)


