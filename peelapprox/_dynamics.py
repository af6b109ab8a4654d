"""Dynamics of the exact solution: periodicity, force drops, transients, attractors, Lyapunov exponents.

Everything here reads the *jump sequence* of an exact (hybrid, ε → 0) trajectory, the natural Poincaré
section of stick-slip: the pull force at the AB→CD jumps, ``x_k = F(t_k)``, is the return map whose
periods the paper reports ("period 4 at V = 2, I = 1e-5", "period 8 at V = 1, I = 1e-2", ...).

* :func:`return_map` — ``x_k``, the F values at AB→CD jumps.
* :func:`periodicity` — period-n (n <= 32) of ``x_k`` to a stated tolerance, or aperiodic.
* :func:`force_drops` — ``ΔF_k = F(AB→CD jump k) − F(next CD→AB jump)``, the slip's force drop (Fig. 6).
* :func:`settle_time` — when a periodic orbit is reached (the transient's end).
* :func:`attractors` — sample initial states and group the attractors they reach.
* :func:`benettin` — the largest Lyapunov exponent of any flow by the two-trajectory renormalisation
  method (Benettin et al. 1980), tested on systems with known exponents; :func:`lyapunov` applies it to
  the peeling model in bits/s.  :func:`lyapunov_tangent` (variational equations with saltation matrices at
  the jumps, :mod:`exact._tangent`) and :func:`lyapunov_return_map` (tangent map of the jump-to-jump map)
  are the cross-checks.

Exact solutions come from :func:`exact.simulate` (imported lazily: ``exact`` depends on this package).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ._errors import WallBudget
from ._params import LYAPUNOV_TAU, RTOL_RANGE, T_TRANSIENT, PeelParams
from ._peelforce import BRANCHES, branch_structure
from ._validate import ArgumentTypeError, duration, function, in_range, integer, optional, positive, reals, state
from ._validate import params as _params

#: Default wall-clock budget [s] of the calls made of many solver runs (lyapunov, lyapunov_return_map,
#: attractors): their work grows with counts (n, n_returns, starts) that no step budget bounds.
DEFAULT_MAX_WALL = 3600.0

__all__ = [
    "DEFAULT_MAX_WALL",
    "return_map",
    "Periodicity",
    "periodicity",
    "force_drops",
    "settle_time",
    "window_run",
    "classify",
    "Attractor",
    "attractors",
    "BenettinResult",
    "benettin",
    "LyapunovResult",
    "lyapunov",
]

_AB = BRANCHES.index("AB")
#: Valid initial perturbation ``d0`` of :func:`lyapunov` (scaled units): below 1e-12 the perturbation of F,
#: ``d0 f_max``, nears the rounding of F itself (``2e-16 F``) and the two orbits can start at distance 0;
#: above 1 it is not a perturbation.
D0_RANGE = (1e-12, 1.0)


def _rtol(name: str, x) -> float:
    return in_range(name, x, *RTOL_RANGE)


def _trajectory(name: str, x):
    """x if it looks like an :class:`exact.Trajectory` (has ``jumps`` with ``t``, ``F``, ``from_branch``)."""
    J = getattr(x, "jumps", None)
    if not all(hasattr(J, a) for a in ("t", "F", "from_branch")):
        raise ArgumentTypeError(f"{name} must be an exact.Trajectory (with jumps), got {type(x).__name__}")
    return x


def return_map(trajectory, *, with_times: bool = False):
    """``x_k``: the pull force [N] at the AB→CD jumps of an exact trajectory (its stored window).

    With ``with_times=True``, the pair ``(t_k, x_k)`` of jump times and forces.
    """
    J = _trajectory("trajectory", trajectory).jumps
    m = np.asarray(J.from_branch) == _AB
    x = np.asarray(J.F)[m]
    return (np.asarray(J.t)[m], x) if with_times else x


@dataclass(frozen=True)
class Periodicity:
    """Period of the return map ``x_k`` (see :func:`periodicity`).

    ``kind`` is ``"periodic"`` (``period`` = the smallest n that repeats), ``"aperiodic"`` (no n <=
    ``max_period`` repeats; ``period`` None) or ``"too short"`` (fewer than
    ``(min_repeats + 1) · max_period`` returns were given — 96 with the defaults — so not every n could be
    tried, *and* no shorter period repeated).  ``mismatch`` = ``max_k |x_{k+n} − x_k| / max|x|`` for
    the period found, or the smallest over all n tried (``inf`` when too few returns to try any n; NaN only
    for "no stick-slip" from :func:`classify`); ``n_returns`` = ``len(x)``.
    """

    kind: str
    period: int | None
    mismatch: float
    n_returns: int
    rtol: float

    @property
    def label(self) -> str:
        return f"period-{self.period}" if self.kind == "periodic" else self.kind


def periodicity(x, *, rtol: float = 1e-6, max_period: int = 32, min_repeats: int = 2) -> Periodicity:
    """Classify the return map as period-n or aperiodic.

    Parameters
    ----------
    x : array_like or exact.Trajectory
        The F values at AB→CD jumps (or a trajectory, through :func:`return_map`), after the transient.
    rtol : float
        Tolerance: period n is accepted when ``max_k |x_{k+n} − x_k| <= rtol · max|x|`` over every k.  The
        hybrid solver at rtol 1e-10 reproduces a periodic orbit's jump forces to ~1e-12, so 1e-6 separates
        periodic orbits from chaotic ones, whose returns do not come within 1e-6 for n <= 32.
    max_period : int
        Largest n tried (the issue asks n <= 32).
    min_repeats : int
        A period n needs at least ``min_repeats · n`` pairs ``(x_k, x_{k+n})``.

    Returns
    -------
    Periodicity
    """
    if hasattr(x, "jumps"):
        x = return_map(x)
    x = reals("x", x)
    rtol = positive("rtol", rtol)
    max_period, min_repeats = integer("max_period", max_period), integer("min_repeats", min_repeats)
    if x.ndim != 1 or x.size < 2:
        raise ValueError(f"x must be a 1-D finite sequence of at least 2 returns, got shape {x.shape}")
    scale = float(np.max(np.abs(x)))
    # differences of x / max|x| (in [-1, 1]): no overflow for |x| near the float maximum, and all-zero
    # returns (scale 0) are the constant sequence, mismatch 0
    xs = x / scale if scale > 0 else x
    best = math.inf
    for n in range(1, int(max_period) + 1):
        if x.size - n < int(min_repeats) * n:
            break
        mis = float(np.max(np.abs(xs[n:] - xs[:-n])))
        if mis <= rtol:
            return Periodicity("periodic", n, mis, x.size, rtol)
        best = min(best, mis)
    enough = x.size - int(max_period) >= int(min_repeats) * int(max_period)
    return Periodicity("aperiodic" if enough else "too short", None, best, x.size, rtol)


def force_drops(trajectory) -> np.ndarray:
    """Force drop of each slip [N]: ``F`` at an AB→CD jump minus ``F`` at the next CD→AB jump.

    One value per completed slip in the stored window.
    The paper's Fig. 6 plots their mean against V.
    """
    J = _trajectory("trajectory", trajectory).jumps
    fb = np.asarray(J.from_branch)
    F = np.asarray(J.F)
    idx = np.flatnonzero(fb[:-1] == _AB)  # AB→CD followed by CD→AB (jumps alternate)
    if np.any(fb[idx + 1] == _AB):
        raise ValueError("force_drops: the jumps do not alternate AB→CD→AB (not an exact trajectory's jumps)")
    return F[idx] - F[idx + 1]


def settle_time(trajectory, *, rtol: float = 1e-6, max_period: int = 32) -> float | None:
    """The time from which the return map is periodic to the end of the stored window, or None.

    The orbit's period n is found on the last half of the returns (:func:`periodicity`); the settle time is
    that of the earliest AB→CD jump from which ``|x_{k+n} − x_k| <= rtol·max|x|`` holds for every later k.
    None means no period was found in the last half (aperiodic, or still in the transient).
    """
    rtol = positive("rtol", rtol)
    max_period = integer("max_period", max_period)
    t, x = return_map(trajectory, with_times=True)
    if x.size < 4:
        return None
    per = periodicity(x[x.size // 2:], rtol=rtol, max_period=max_period)
    if per.kind != "periodic":
        return None
    n = per.period
    assert n is not None  # kind "periodic" comes with its period
    bad = np.abs(x[n:] - x[:-n]) > rtol * float(np.max(np.abs(x)))
    k = int(np.flatnonzero(bad)[-1]) + 1 if bad.any() else 0
    return float(t[k])


# ---------------------------------------------------------------------------------------------- windows
WINDOW_DEFAULTS = dict(t_transient=T_TRANSIENT, window=20.0, rtol=1e-10, alpha0=0.0)


def window_run(params: PeelParams, *, t_transient: float = T_TRANSIENT, window: float = 20.0, rtol: float = 1e-10,
               alpha0: float = 0.0, max_wall: float | None = None):
    """The jumps of the exact solution over ``[t_transient, t_transient + window]`` (``save="jumps"``).

    The one windowed run behind :func:`attractors`, the sweep measures ``period`` and
    ``jumps`` and ``peelapprox dynamics`` (the same defaults everywhere).  The last call is cached, so
    measures of one sweep point share it.  Raises ``ModelBreakdown`` and ``SolverBudgetExceeded`` (also
    for ``max_wall`` seconds of wall time) as :func:`exact.simulate` does.
    """
    return _window_run(_params("params", params), duration("t_transient", t_transient, zero=True),
                       duration("window", window), _rtol("rtol", rtol), state("alpha0", alpha0, "alpha"),
                       optional(positive, "max_wall", max_wall))


@functools.lru_cache(maxsize=2)
def _window_run(params, t_transient, window, rtol, alpha0, max_wall=None):
    from exact import simulate

    return simulate(params, t_transient + window, alpha0=alpha0, rtol=rtol, t_transient=t_transient, save="jumps",
                    max_wall=max_wall)


def classify(trajectory, *, period_rtol: float = 1e-6, max_period: int = 32) -> Periodicity:
    """:func:`periodicity` of a window's return map, with ``kind = "no stick-slip"`` below 2 returns."""
    x = return_map(trajectory)
    if x.size < 2:
        return Periodicity("no stick-slip", None, math.nan, int(x.size), period_rtol)
    return periodicity(x, rtol=period_rtol, max_period=max_period)


# ---------------------------------------------------------------------------------------------- attractors
@dataclass(frozen=True)
class Attractor:
    """One attractor reached from sampled initial states (see :func:`attractors`).

    ``signature`` is the sorted cycle of return-map values (periodic) or the (min, max, mean) of the
    returns (aperiodic), rounded; ``starts`` the initial α0 values that reach it.
    """

    label: str
    period: int | None
    signature: tuple[float, ...]
    F_range: tuple[float, float]
    starts: tuple[float, ...]
    settle_times: tuple[float | None, ...]


def attractors(
    params: PeelParams,
    alpha0s: Sequence[float] = (-0.3, -0.15, 0.0, 0.15, 0.3),
    *,
    t_transient: float = T_TRANSIENT,
    window: float = 20.0,
    rtol: float = 1e-10,
    period_rtol: float = 1e-6,
    match_rtol: float = 1e-4,
    progress: Callable[[str], None] | None = None,
    max_wall: float | None = DEFAULT_MAX_WALL,
) -> list[Attractor]:
    """Sample initial peel angles and group the attractors they reach.

    ``max_wall`` [s] bounds the wall time of all starts together (``SolverBudgetExceeded``, ``budget="max_wall"``;
    None: unbounded).

    Each start (α0, the rest :func:`exact.initial_state`'s default) is integrated for ``t_transient`` s
    (discarded) and ``window`` s (stored jumps) by :func:`window_run`.  Two periodic orbits are the same
    attractor when their
    periods agree and their sorted return-map cycles agree to ``match_rtol`` relative (a cycle is the same
    set of jump forces whatever its phase); aperiodic windows are grouped by their return range.  A start
    that breaks down (``ModelBreakdown``) or is infeasible (``ValueError``) is reported as its own entry.
    More than one entry means coexisting attractors — or a transient longer than ``t_transient``: the
    entries' settle times tell which.
    """
    from exact import ModelBreakdown, SolverBudgetExceeded, initial_state

    # validate everything up front: inside the loop a ValueError can then only be an infeasible start
    params = _params("params", params)
    kw = dict(t_transient=duration("t_transient", t_transient, zero=True), window=duration("window", window),
              rtol=_rtol("rtol", rtol))
    period_rtol = positive("period_rtol", period_rtol)
    match_rtol = positive("match_rtol", match_rtol)
    alpha0s = [float(a) for a in np.atleast_1d(states_alpha("alpha0s", alpha0s))]
    say = optional(function, "progress", progress) or (lambda msg: None)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    groups: list[dict] = []
    for a0 in alpha0s:
        say(f"attractors V={params.V:g} I={params.I:g}: alpha0={a0:g}")
        try:
            s0 = initial_state(params, alpha0=a0)
            tr = window_run(params, alpha0=a0, max_wall=wall.left(0.0, s0.__dict__, kw["t_transient"] + kw["window"]),
                            **kw)
        except SolverBudgetExceeded as exc:
            raise wall.reraise(exc) from None
        except (ModelBreakdown, ValueError) as exc:
            groups.append(dict(label=f"{type(exc).__name__}: {str(exc)[:80]}", period=None, signature=(),
                               F_range=(math.nan, math.nan), starts=[a0], settle=[None]))
            continue
        per = classify(tr, period_rtol=period_rtol)
        x = return_map(tr)
        if per.kind == "no stick-slip":
            groups.append(dict(label=per.kind, period=None, signature=(), F_range=(math.nan, math.nan),
                               starts=[a0], settle=[None]))
            continue
        if per.kind == "periodic":
            sig = tuple(float(v) for v in np.sort(x[: per.period]))
        else:
            sig = (float(x.min()), float(x.max()), float(x.mean()))
        st = settle_time(tr, rtol=period_rtol)
        for g in groups:
            if g["period"] == per.period and g["label"] == per.label and len(g["signature"]) == len(sig) and \
                    np.allclose(g["signature"], sig, rtol=match_rtol, atol=0.0):
                g["starts"].append(a0)
                g["settle"].append(st)
                break
        else:
            groups.append(dict(label=per.label, period=per.period, signature=sig,
                               F_range=(float(x.min()), float(x.max())), starts=[a0], settle=[st]))
    return [Attractor(g["label"], g["period"], tuple(round(s, 6) for s in g["signature"]), g["F_range"],
                      tuple(float(a) for a in g["starts"]), tuple(g["settle"])) for g in groups]


# ---------------------------------------------------------------------------------------------- Lyapunov
def states_alpha(name: str, x) -> np.ndarray:
    """A non-empty 1-D array of initial peel angles, each in ``STATE_RANGES["alpha"]``."""
    from ._validate import states

    a = states(name, x, "alpha")
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence of initial peel angles, got shape {a.shape}")
    return a


def natural_scales(params: PeelParams) -> np.ndarray:
    """The natural sizes ``(1 rad, V/R, f_max)`` of ``(α, ω, F)``: every Lyapunov estimate measures
    perturbations in ``(δα, δω, δF)`` divided by these (``f_max`` is 1 N when f has no folds)."""
    bs = branch_structure(params.V)
    return np.array([1.0, params.V / params.R, bs.f_max if bs.has_folds else 1.0])


@dataclass
class BenettinResult:
    """Largest Lyapunov exponent by two-trajectory renormalisation.

    ``exponent`` [1/time unit, natural log] = ``Σ log(d_k/d0) / T`` over the kept intervals; ``running``
    the running estimate after each interval; ``local`` the per-interval rates ``log(d_k/d0)/Δt_k``;
    ``stderr`` the standard error of the mean local rate (intervals treated as independent; a rough
    convergence indicator); ``time`` the total kept time.
    """

    exponent: float
    running: np.ndarray
    local: np.ndarray
    stderr: float
    time: float
    n: int
    d0: float
    wall_time: float

    @classmethod
    def from_logs(cls, logs, dts, d0: float, wall_time: float) -> BenettinResult:
        """The record of per-interval log growths ``logs`` over durations ``dts`` (the one place the
        exponent, running estimate, local rates and standard error are computed from them)."""
        logs, dts = np.asarray(logs, float), np.asarray(dts, float)
        T = float(dts.sum())
        local = logs / dts
        stderr = float(np.std(local, ddof=1) / math.sqrt(local.size)) if local.size > 1 else math.nan
        return cls(float(logs.sum() / T), np.cumsum(logs) / np.cumsum(dts), local, stderr, T, int(logs.size),
                   float(d0), float(wall_time))


def benettin(
    advance: Callable,
    x_ref,
    x_pert,
    distance: Callable,
    rescale: Callable,
    n: int,
    *,
    n_discard: int = 0,
) -> BenettinResult:
    """The largest Lyapunov exponent of a flow by the two-trajectory (Benettin) method.

    Parameters
    ----------
    advance : callable
        ``advance(x_ref, x_pert) -> (x_ref, x_pert, dt)``: both states advanced by the same time ``dt``
        (the caller chooses the renormalisation interval; it may vary, e.g. to avoid renormalising across
        a switching surface).
    x_ref, x_pert : state
        The reference state and a perturbed one at distance ``d0 = distance(x_ref, x_pert)`` (small).
    distance : callable
        ``distance(a, b) -> float``, any norm (the exponent does not depend on it).
    rescale : callable
        ``rescale(x_ref, x_pert, factor) -> x_pert`` putting the perturbation back to ``factor`` times its
        size along its current direction (or shorter: the next interval's growth is measured from the
        distance it returns).
    n : int
        Number of renormalisation intervals kept.
    n_discard : int
        Intervals run first and not counted (the perturbation aligning with the most unstable direction).

    Returns
    -------
    BenettinResult
    """
    advance, distance, rescale = (function(nm, f) for nm, f in
                                  (("advance", advance), ("distance", distance), ("rescale", rescale)))
    n, n_discard = integer("n", n, lo=2), integer("n_discard", n_discard, lo=0)
    d0 = float(distance(x_ref, x_pert))
    if not (d0 > 0.0 and math.isfinite(d0)):
        raise ValueError(f"the initial perturbation must have a finite positive size, got {d0}")
    wall0 = time.perf_counter()
    logs, dts = [], []
    d_start = d0
    for k in range(int(n_discard) + int(n)):
        x_ref, x_pert, dt = advance(x_ref, x_pert)
        d = float(distance(x_ref, x_pert))
        if not (d > 0.0 and math.isfinite(d)):
            raise ValueError(f"the perturbation collapsed or diverged at interval {k} (distance {d}); choose a "
                             f"different d0 or interval")
        if k >= n_discard:
            logs.append(math.log(d / d_start))
            dts.append(dt)
        x_pert = rescale(x_ref, x_pert, d0 / d)
        # the growth of the next interval is measured from the size rescale actually gave (it may shorten
        # the perturbation further, e.g. to keep a state feasible)
        d_start = float(distance(x_ref, x_pert))
    return BenettinResult.from_logs(logs, dts, d0, time.perf_counter() - wall0)


@dataclass
class LyapunovResult:
    """The peeling model's largest Lyapunov exponent (see :func:`lyapunov`).

    ``bits_per_s`` = ``per_s / ln 2`` (the paper's unit); ``benettin`` holds the running estimate and the
    local rates; ``n_jumps`` the jumps the reference orbit made while measured."""

    per_s: float
    bits_per_s: float
    stderr_bits: float
    benettin: BenettinResult
    params: PeelParams
    tau: float
    n_jumps: int
    method: str = "hybrid two-trajectory (Benettin)"
    notes: list[str] = field(default_factory=list)


def lyapunov(
    params: PeelParams,
    *,
    t_transient: float = T_TRANSIENT,
    tau: float = LYAPUNOV_TAU,
    n: int = 10000,
    n_discard: int = 200,
    d0: float = 1e-7,
    alpha0: float = 0.0,
    rtol: float = 1e-12,
    max_wall: float | None = DEFAULT_MAX_WALL,
) -> LyapunovResult:
    """Largest Lyapunov exponent of the exact (hybrid) peeling dynamics, in bits/s.

    With the defaults, 50 s are measured after 30 s of transient (3-4 s of wall time).  ``max_wall`` [s]
    bounds the wall time of the whole computation (``SolverBudgetExceeded`` with
    ``budget="max_wall"``; None: unbounded).

    Method: :func:`benettin` on the hybrid solver.  The state is ``(α, ω, F, branch)`` — v follows from
    CONSTR — and the distance is measured in the continuous variables scaled by their natural sizes,
    ``(Δα/1 rad, Δω/(V/R), ΔF/f_max)``; α, ω and F are continuous across jumps, so two neighbouring orbits
    stay close in this norm while they jump at slightly different times (the jump is a state-dependent
    switching).  Renormalisation happens every ``tau`` seconds, postponed in steps of ``tau/8`` while the
    two orbits are on different branches (a renormalised state must lie on its branch).  The exponent is
    ``Σ log(d_k/d0)/T`` over ``n`` intervals after ``n_discard``.

    **d0 against rtol.**  Each interval restarts both orbits, so the solver's local errors enter as fresh
    perturbations every ``tau``, and the jumps amplify them.  Unless ``d0/rtol >= 1e5`` this noise inflates
    the exponent: at V = 2, I = 1e-4 we measured 9.5-13.5 bits/s with d0/rtol = 10-100, and 4.06-4.15 bits/s
    for every d0/rtol >= 1e5 (d0 from 1e-8 to 1e-6, rtol 1e-12 or 1e-13, tau = 0.005; docs/dynamics.md).
    Hence the defaults d0 = 1e-7, rtol = 1e-12.  ``d0`` must lie in :data:`D0_RANGE` = [1e-12, 1].

    The running estimate and ``stderr_bits`` show the convergence.  Cross-checks: :func:`lyapunov_tangent`
    (variational equations with saltation matrices at the jumps) and :func:`lyapunov_return_map`.
    """
    from exact import SolverBudgetExceeded, initial_state, simulate

    params = _params("params", params)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    tau = duration("tau", tau)
    d0 = in_range("d0", d0, *D0_RANGE)
    t_transient = duration("t_transient", t_transient, zero=True)
    n, n_discard = integer("n", n, lo=2), integer("n_discard", n_discard, lo=0)
    alpha0 = state("alpha0", alpha0, "alpha")
    rtol = _rtol("rtol", rtol)
    bs = branch_structure(params.V)
    scale = natural_scales(params)
    jumps = [0]
    t_total = t_transient + (n + n_discard) * tau

    def run(state, dt):
        a, w, F, br = state
        try:
            tr = simulate(params, dt, alpha0=a, omega0=w, F0=F, branch0=br, rtol=rtol, save="jumps",
                          max_wall=wall.left(0.0, lambda: initial_state(params, alpha0=a, omega0=w, F0=F,
                                                                        branch0=br).__dict__, t_total))
        except SolverBudgetExceeded as exc:
            raise wall.reraise(exc) from None
        s = tr.final_state
        return (s.alpha, s.omega, s.F, s.branch), len(tr.jumps)

    def vec(s):
        return np.array(s[:3]) / scale

    def distance(a, b):
        return float(np.linalg.norm(vec(a) - vec(b)))

    def rescale(ref, pert, factor):
        # a state near a fold may leave its branch's level range when moved: halve the step until it does not
        for _ in range(60):
            x = (vec(ref) + factor * (vec(pert) - vec(ref))) * scale
            G = x[2] * (1.0 + float(params.closure(x[0])[0]))
            if bs.has_root(G, ref[3]):
                return (float(x[0]), float(x[1]), float(x[2]), ref[3])
            factor *= 0.5
        return ref  # unreachable in practice: the reference itself lies on its branch

    max_postpones = 64

    def advance(ref, pert):
        ref, nj = run(ref, tau)
        pert, _ = run(pert, tau)
        dt = tau
        for _ in range(max_postpones):
            if ref[3] == pert[3]:
                break
            ref, nj2 = run(ref, tau / 8)
            pert, _ = run(pert, tau / 8)
            dt += tau / 8
            nj += nj2
        else:
            raise RuntimeError(f"lyapunov: the two orbits stayed on different branches for {max_postpones} "
                               f"postponements of tau/8 = {tau / 8:g} s: d0 = {d0:g} is too large for this orbit")
        jumps[0] += nj
        return ref, pert, dt

    s0 = initial_state(params, alpha0=alpha0)
    ref = (s0.alpha, s0.omega, s0.F, s0.branch)
    if t_transient > 0:
        ref, _ = run(ref, t_transient)
    # the perturbation: along F (the variable the constraint and the jumps act on), size d0
    pert = rescale(ref, (ref[0], ref[1], ref[2] + d0 * scale[2], ref[3]), 1.0)
    res = benettin(advance, ref, pert, distance, rescale, n, n_discard=n_discard)
    ln2 = math.log(2.0)
    return LyapunovResult(res.exponent, res.exponent / ln2, res.stderr / ln2, res, params, tau, jumps[0])


def lyapunov_tangent(
    params: PeelParams,
    *,
    t_transient: float = T_TRANSIENT,
    T: float = 50.0,
    rtol: float = 1e-10,
    alpha0: float = 0.0,
    max_steps: int | None = None,
) -> LyapunovResult:
    """Largest Lyapunov exponent from the tangent (variational) dynamics with saltation matrices, in bits/s.

    ``max_steps`` bounds the accepted steps (default 5e6 per simulated second;
    ~1.2e6 are used at V = 2, I = 1e-4); ``notes`` reports the steps taken.

    The variational equation of the hybrid solver's desingularised field is integrated with the state by
    the package's DOP853; the tangent crosses each jump through the saltation matrix of the fold event and
    the reset to the landing root (:mod:`exact._tangent`).  Its equal-time (α, ω, F) size is measured and
    renormalised after every jump.  Slower than :func:`lyapunov` (hundreds of steps per branch stay: the
    difference-quotient tangent is stiff near the folds), ~1 s of wall time per simulated second at
    V = 2, I = 1e-4.
    """
    from exact._tangent import lyapunov_saltation

    params = _params("params", params)
    T = duration("T", T)
    t_transient = duration("t_transient", t_transient, zero=True)
    rtol = _rtol("rtol", rtol)
    alpha0 = state("alpha0", alpha0, "alpha")
    max_steps = optional(integer, "max_steps", max_steps)
    t0 = time.perf_counter()
    lam, n_jumps, t, steps = lyapunov_saltation(params, t_transient=t_transient, T=T, rtol=rtol,
                                                alpha0=alpha0, max_steps=max_steps)
    b = BenettinResult(lam, np.array([lam]), np.array([lam]), math.nan, t, n_jumps, math.nan,
                       time.perf_counter() - t0)
    ln2 = math.log(2.0)
    return LyapunovResult(lam, lam / ln2, math.nan, b, params, math.nan, n_jumps,
                          method="tangent dynamics with saltation matrices", notes=[f"steps={steps}"])


def lyapunov_return_map(
    params: PeelParams,
    *,
    t_transient: float = T_TRANSIENT,
    n_returns: int = 5000,
    h: float = 1e-6,
    rtol: float = 1e-12,
    max_wall: float | None = DEFAULT_MAX_WALL,
) -> LyapunovResult:
    """Largest Lyapunov exponent from the tangent map of the jump-to-jump (Poincaré) map, in bits/s.

    ``max_wall`` [s] bounds the whole computation
    (``SolverBudgetExceeded``, ``budget="max_wall"``; None: unbounded).

    The section is the AB→CD jump; the return map P takes the state (α, ω, F) just after one such jump to
    the state at the next.  A tangent vector w is pushed through P's Jacobian by central differences,
    ``DP w ≈ [P(x + h w) − P(x − h w)] / 2h`` in the scaled variables (α, ω/(V/R), F/f_max) — the jumps'
    saltation is inside P, so nothing is linearised across them — and renormalised every return.  The
    flow's exponent is ``Σ log|DP_k w_k| / Σ T_k`` over the return times T_k.  Unlike :func:`lyapunov`
    there is no finite perturbation left to grow and no renormalisation noise; the result is independent
    of h over 1e-8 … 1e-5 (docs/dynamics.md).  On a periodic orbit it gives the (negative) transverse
    exponent, not the flow's 0.  A cross-check of :func:`lyapunov`, not a replacement: it needs a return
    map with at least two returns per second of the run.
    """
    from exact import SolverBudgetExceeded, initial_state, simulate

    params = _params("params", params)
    h = positive("h", h, hi=1.0)
    rtol = _rtol("rtol", rtol)
    t_transient = duration("t_transient", t_transient, zero=True)
    n_returns = integer("n_returns", n_returns, lo=2)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    scale = natural_scales(params)

    def ret(x, horizon):
        try:
            J = simulate(params, horizon, alpha0=x[0], omega0=x[1], F0=x[2], branch0="CD", rtol=rtol, save="jumps",
                         max_wall=wall.left(0.0, lambda: initial_state(params, alpha0=x[0], omega0=x[1], F0=x[2],
                                                                           branch0="CD").__dict__, horizon)).jumps
        except SolverBudgetExceeded as exc:
            raise wall.reraise(exc) from None
        ab = np.flatnonzero(np.asarray(J.from_branch) == _AB)
        if ab.size == 0:
            return None, None
        i = ab[0]
        return np.array([J.alpha[i], J.omega[i], J.F[i]]), float(J.t[i])

    try:
        J0 = window_run(params, t_transient=0.0, window=max(float(t_transient), 1e-3), rtol=rtol,
                        max_wall=wall.limit).jumps
    except SolverBudgetExceeded as exc:
        raise wall.reraise(exc) from None
    ab = np.flatnonzero(np.asarray(J0.from_branch) == _AB)
    if ab.size == 0:
        raise ValueError(f"no AB→CD jump within t_transient = {t_transient} s: no return map to linearise")
    k = int(ab[-1])  # start on the section, at the transient's last AB→CD jump
    x = np.array([J0.alpha[k], J0.omega[k], J0.F[k]])
    w = np.array([0.3, 0.3, 1.0]) / math.sqrt(1.18)
    wall0 = time.perf_counter()
    logs: list[float] = []
    dts: list[float] = []
    horizon, jumps = 1.0, 0
    while len(logs) < int(n_returns):
        y, dt = ret(x, horizon)
        if y is None:
            if horizon > 1e3:
                raise ValueError("the orbit stopped returning to the AB→CD section (no stick-slip)")
            horizon *= 2.0
            continue
        horizon = 3.0 * dt
        yp, _ = ret(x + h * w * scale, horizon)
        ym, _ = ret(x - h * w * scale, horizon)
        if yp is None or ym is None:
            raise ValueError("a perturbed orbit did not return within 3 return times: h is too large")
        Dw = (yp - ym) / (2.0 * h) / scale
        d = float(np.linalg.norm(Dw))
        logs.append(math.log(d))
        dts.append(dt)
        w, x = Dw / d, y
        jumps += 2
    b = BenettinResult.from_logs(logs, dts, h, time.perf_counter() - wall0)
    ln2 = math.log(2.0)
    return LyapunovResult(b.exponent, b.exponent / ln2, b.stderr / ln2, b, params, math.nan, jumps,
                          method="tangent map of the AB→CD return map (central differences)")
