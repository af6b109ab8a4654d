"""Stick-slip orbits as objects: the AB→CD section, its return map with the Jacobian from the saltation tangent,
periodic orbits by Newton, and their Floquet multipliers (issue 16).

**The section** is the AB→CD jump.  There the state lies on the AB fold, ``v = v_max``, so CONSTR fixes
``F = f_max / (1 + c(α))`` and the section is two-dimensional: ``x = (α, ω)``.  The return map ``P`` takes
the state at one AB→CD jump to the state at the next: the jump to ``v_land_cd`` on CD, CD to its fold
``v_min``, the jump to ``v_land_ab``, AB to its fold ``v_max``.  A period-n orbit is a fixed point of ``P^n``.

**The Jacobian** ``DP`` comes from the tangent dynamics of the hybrid solver's desingularised field in the
parameter s (:mod:`exact._tangent`: state ``(t, α, ω, u = ln v)`` and one tangent, integrated together by the
package's DOP853, with the field's analytic Jacobian, :mod:`exact._jacobian`), with the saltation matrix at the CD→AB
jump.  A perturbation ``(δα, δω)`` of the section state starts as ``δy = (0, δα, δω, 0)`` after the AB→CD
jump (the jump keeps (α, ω) and sets v, so δu = 0); at the next AB fold the field is ``(0, 0, 0, Ġ)`` (dt/ds,
dα/ds, dω/ds vanish with f'), so the projection of the tangent onto the section along the flow only drops δu:
``(δα, δω)`` there is the column of ``DP``, and δt the change of the return time.  Two tangent runs give the
two columns.  Finite differences of ``P`` are the cross-check (:func:`monodromy_fd`).

**Newton** on ``G(z) = P^n(z) - z`` in the scaled coordinates ``z = (α, ω R/V)`` with ``DG = DP^n - 1``;
a step that does not reduce ``|G|`` is halved (at most 8 times).  Converged when the closing residual
``|P^n(z) - z| / max(1, |z|)`` is at most ``tol``.  The **nontrivial Floquet multipliers** are the two
eigenvalues of ``DP^n`` at the orbit (the flow direction and the constraint are removed by the section);
the orbit is stable if both lie inside the unit circle.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from peelapprox import BREAKDOWN_LEVEL, T_TRANSIENT, PeelParams
from peelapprox.errors import SolverBudgetExceeded, SolverFailure, WallBudget
from peelapprox.io import fmt_number, html_table
from peelapprox.kernels import M_R
from peelapprox.kernels import status as _st
from peelapprox.validate import duration, in_range, integer, optional, positive
from peelapprox.validate import params as _params

from ._orbit_start import check_start, seed
from ._shared import DEFAULT_MAX_WALL, paper_model_only
from ._tangent import TangentSystem, tangent_system

__all__ = ["PeriodicOrbit", "SectionReturn", "check_wall", "monodromy_fd", "periodic_orbit", "section_return",
           "solve_orbit"]

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


def _one_return(ts: TangentSystem, x: np.ndarray, d: np.ndarray, rtol: float, atol: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, float, float, int, tuple[float, float]]:
    """``P(x)`` with the tangent ``d = (δα, δω)`` carried along: ``(x', (δα', δω'), δT, T, steps, (Ġ at the CD
    fold, Ġ at the AB fold))``."""
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
    return y[1:3].copy(), y[5:7].copy(), float(y[4]), t_cd + float(y[0]), steps, (rate_cd, float(gm[3]))


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
    from ._methods import ATOL_SCALE

    ts = system or system_of(params)
    x0 = np.asarray(x, dtype=float).reshape(2)
    scale = np.asarray(ATOL_SCALE["hybrid"])
    atol = np.concatenate([rtol * scale, np.ones(4)])  # the tangent stays 0: its weights do not matter
    xn, _, _, T, steps, rates = _one_return(ts, x0, np.zeros(2), rtol, atol)  # the state alone, at rtol
    if not tangent:
        return SectionReturn(xn, None, T, None, steps, rates)
    jrt = max(rtol, TANGENT_RTOL)
    atol_t = np.concatenate([jrt * scale, np.full(4, TANGENT_ATOL)])
    cols, dts = [], []
    s = np.array([1.0, ts.law.V / float(ts.p[M_R])])  # unit vectors of z = (α, ω R/V): balanced columns
    for i in range(2):
        d = np.zeros(2)
        d[i] = s[i]
        _, dx, dT, _, n, _ = _one_return(ts, x0, d, jrt, atol_t)
        cols.append(dx / s[i])
        dts.append(dT / s[i])
        steps += n
    return SectionReturn(xn, np.column_stack(cols), T, np.array(dts), steps, rates)


def system_of(params: PeelParams) -> TangentSystem:
    ts = tangent_system(params)
    if not ts.law.structure.has_folds:
        raise ValueError(f"params: f(v, V={params.V}) has no folds (no stick-slip): there is no AB->CD section")
    return ts


def _section_F(params: PeelParams, ts: TangentSystem, alpha: np.ndarray) -> np.ndarray:
    """F at the AB→CD jump: ``f_max / (1 + c(α))`` (CONSTR on the fold)."""
    return float(ts.law.structure.f_max) / (1.0 + np.asarray(params.closure(np.asarray(alpha))[0]))


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
        (a non-smooth bifurcation: the multipliers diverge).
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

    def trajectory(self, *, rtol: float = 1e-12, save: str = "steps") -> Any:
        """One period of the orbit by ``exact.simulate``, from the first AB→CD jump (just after it, on CD)."""
        from ._simulate import simulate

        a, w = self.section_states[0]
        return simulate(self.params, self.period, alpha0=float(a), omega0=float(w),
                        F0=float(self.return_map_values[0]), branch0="CD", rtol=rtol, save=save)

    def _summary(self) -> dict:
        F = self.return_map_values
        return {"n": self.n, "period [s]": self.period, "stable": self.stable,
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


def compose(params: PeelParams, ts: TangentSystem, x: np.ndarray, n: int, rtol: float
             ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray, int, np.ndarray]:
    """``(P^n(x), DP^n, period, the n section states, steps, the 2n fold rates)``."""
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
    return x, J, T, np.array(states[:-1]), steps, np.array(rates)


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
        xn, J, T, states, k, rates = compose(params, ts, x, n, rtol)
        steps += k
        z, g = x / s, (xn - x) / s
        res = float(np.linalg.norm(g) / max(1.0, np.linalg.norm(z)))
        history.append(res)
        if res <= tol:
            break
        Js = J * s[None, :] / s[:, None]  # DP^n in z
        dz = np.linalg.solve(Js - np.eye(2), -g)
        lam = 1.0
        for _ in range(9):  # halve a step that does not reduce the residual
            x_try = (z + lam * dz) * s
            xt = section_return_n(params, ts, x_try, n, rtol)
            steps += xt[1]
            r_try = float(np.linalg.norm((xt[0] - x_try) / s) / max(1.0, np.linalg.norm(x_try / s)))
            if r_try < res:
                break
            lam *= 0.5
        x = x_try
    else:
        raise ValueError(f"periodic_orbit: Newton did not close the period-{n} orbit to tol={tol} in "
                         f"max_iter={max_iter} iterations; residuals {', '.join(f'{r:.3g}' for r in history)}")
    return make_orbit(params, ts, J, T, states, rates, history, steps, wall0)


def make_orbit(params: PeelParams, ts: TangentSystem, J: np.ndarray, T: float, states: np.ndarray,
               rates: np.ndarray, history: list[float], steps: int, wall0: float) -> PeriodicOrbit:
    """The :class:`PeriodicOrbit` of a closed Newton iteration (``compose``'s output at the orbit)."""
    n = len(states)
    mu = np.linalg.eigvals(J)
    mu = mu[np.argsort(-np.abs(mu))]
    return PeriodicOrbit(params=params, n=n, period=T, section_states=states,
                         return_map_values=_section_F(params, ts, states[:, 0]), itinerary=("CD", "AB") * n,
                         multipliers=mu, stable=bool(np.all(np.abs(mu) < 1.0)), residual=history[-1],
                         newton=tuple(history), monodromy=J, fold_rates=rates, steps=steps,
                         wall_time=time.perf_counter() - wall0)


def section_return_n(params: PeelParams, ts: TangentSystem, x: np.ndarray, n: int, rtol: float
                     ) -> tuple[np.ndarray, int]:
    """``(P^n(x), steps)`` without the tangent."""
    steps = 0
    for _ in range(n):
        r = section_return(params, x, rtol=rtol, tangent=False, system=ts)
        x, steps = r.x, steps + r.steps
    return x, steps


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
        Pn = [section_return_n(params, ts, x + k * e, n, rtol)[0] for k in (2, 1, -1, -2)]
        cols.append((-Pn[0] + 8 * Pn[1] - 8 * Pn[2] + Pn[3]) / (12 * e[i]))
    return np.column_stack(cols)
