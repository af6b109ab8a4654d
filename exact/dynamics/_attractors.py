"""Windowed runs of the exact solution and the attractors they reach.

* :func:`window_run` — the jumps of one run over ``[t_transient, t_transient + window]``, the one windowed
  run behind :func:`attractors`, the sweep measures ``period`` and ``jumps`` and ``peelapprox dynamics``.
* :func:`attractors` — sample initial peel angles and group the attractors they reach, by the return-map
  analysis of :mod:`peelapprox` (:func:`peelapprox.classify`, :func:`peelapprox.settle_time`).
* :func:`attractor_observables` — the observables of the attractor one window reaches
  (:class:`peelapprox.StickSlipObservables`, read off :func:`window_run`'s jumps).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np

from peelapprox import (
    TIME_MAX,
    WINDOW_DEFAULTS,
    ModelBreakdown,
    PeelParams,
    SolverBudgetExceeded,
    StickSlipObservables,
    classify,
    return_map,
    settle_time,
)
from peelapprox.errors import WallBudget
from peelapprox.io import fmt_number
from peelapprox.parallel import AUTO, DEADLINE_TEXT, POOL_KINDS, map_points
from peelapprox.validate import duration, function, integer, optional, positive, state, states
from peelapprox.validate import params as _params
from peelapprox.validate import rtol as _rtol

from .._initial import initial_state
from .._method_contract import method_option
from .._shared import DEFAULT_MAX_WALL
from .._simulate import simulate
from .._trajectory import Trajectory

__all__ = ["window_run", "states_alpha", "Attractor", "attractors", "attractor_observables"]


def states_alpha(name: str, x) -> np.ndarray:
    """A non-empty 1-D array of initial peel angles, each in ``STATE_RANGES["alpha"]``."""
    a = states(name, x, "alpha")
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence of initial peel angles, got shape {a.shape}")
    return a


# ---------------------------------------------------------------------------------------------- windows
def window_run(
    params: PeelParams,
    *,
    t_transient: float = WINDOW_DEFAULTS["t_transient"],
    window: float = WINDOW_DEFAULTS["window"],
    rtol: float = WINDOW_DEFAULTS["rtol"],
    alpha0: float = WINDOW_DEFAULTS["alpha0"],
    max_wall: float | None = None,
    method: str | None = None,
    solver: str | None = None,
) -> Trajectory:
    """The jumps of the exact solution over ``[t_transient, t_transient + window]`` (``save="jumps"``).

    The one windowed run behind :func:`attractors`, the sweep measures ``period`` and ``jumps`` and
    ``peelapprox dynamics``; its defaults are :data:`peelapprox.WINDOW_DEFAULTS`, the same everywhere.  The
    last call is cached, so measures of one sweep point share it.

    Parameters
    ----------
    params : PeelParams
        With any law ``params.force`` the hybrid solver runs (:func:`exact.simulate`); a model variant (a tape
        mass, a constant load: ``params.variant``) runs its own method (``"smooth"``, ``"regularized"``), whose
        jumps are the crossings of the inflection velocity (docs/tape-mass-dynamics.md).
    t_transient : float
        Seconds integrated from the initial state before the window, discarded, in [0, 1e6] (30).
    window : float
        Seconds whose jumps are stored, in (0, 1e6] (20).
    rtol : float
        Relative tolerance of the run, in :data:`peelapprox.RTOL_RANGE` (1e-10).
    alpha0 : float
        Initial peel angle; the rest of the initial state is :func:`exact.initial_state`'s (0).
    max_wall : float, optional
        Wall-clock budget [s] of the run; None: unbounded.
    method, solver : str, optional
        :func:`exact.simulate`'s (None: the model's method and the method's solver; a method or solver the
        model cannot use is simulate's ValueError).

    Returns
    -------
    Trajectory
        :func:`exact.simulate`'s with ``save="jumps"`` and ``t_transient``: the jumps in the window, no
        stored points.

    Raises
    ------
    ValueError
        A bad argument (named, with its range).
    peelapprox.ModelBreakdown, peelapprox.SolverBudgetExceeded
        As :func:`exact.simulate` (also for ``max_wall`` seconds of wall time).
    """
    return _window_run(_params("params", params), duration("t_transient", t_transient, zero=True),
                       duration("window", window), _rtol("rtol", rtol), state("alpha0", alpha0, "alpha"),
                       optional(positive, "max_wall", max_wall), method, solver)


def attractor_observables(
    params: PeelParams,
    *,
    t_transient: float = WINDOW_DEFAULTS["t_transient"],
    t_window: float = WINDOW_DEFAULTS["window"],
    rtol: float = WINDOW_DEFAULTS["rtol"],
    alpha0: float = WINDOW_DEFAULTS["alpha0"],
    period_rtol: float = 1e-6,
    max_period: int = 32,
    max_wall: float | None = None,
    method: str | None = None,
    solver: str | None = None,
) -> StickSlipObservables:
    """The observables of the exact attractor reached from ``alpha0``: slip interval, force drop, slip and
    stick times, the F range at the jumps and the return map's period (docs/dynamics.md, "Attractor
    observables").

    One :func:`window_run` (cached: a sweep point's other window measures share it) read by
    :meth:`peelapprox.StickSlipObservables.from_trajectory`.  Steady peeling (no folds at V, a stable fixed
    point: no jump in the window) is ``status="steady"`` with every mean None, not an error.

    Parameters
    ----------
    params : PeelParams
        Any law ``params.force``; a model variant (a tape mass, a constant load) runs its own method, whose
        jumps are the crossings of the inflection velocity of f (docs/tape-mass-dynamics.md).
    t_transient : float
        Seconds integrated and discarded before the window, in [0, 1e6] (30).
    t_window : float
        Seconds whose jumps are read, in (0, 1e6] (20); ``t_transient + t_window`` at most 1e6.
    rtol : float
        Relative tolerance of the run, in :data:`peelapprox.RTOL_RANGE` (1e-10).
    alpha0 : float
        Initial peel angle [rad]; the rest of the initial state is :func:`exact.initial_state`'s (0).
    period_rtol, max_period
        Of the period detection (:func:`peelapprox.periodicity`): 1e-6 and 32.
    max_wall : float, optional
        Wall-clock budget [s] of the run; None: unbounded.
    method, solver : str, optional
        :func:`exact.simulate`'s (None: the model's method and the method's solver).

    Returns
    -------
    peelapprox.StickSlipObservables
        With ``method`` e.g. ``"exact: hybrid (DOP853), rtol 1e-10, alpha0 0, window [30, 50] s,
        period_rtol 1e-06"``.

    Raises
    ------
    ValueError
        A bad argument (named, with its range), before the run.
    peelapprox.ModelBreakdown
        When the model breaks down in the run (its time and state; the sweeps record it as a status).
    peelapprox.SolverBudgetExceeded
        When a step budget or ``max_wall`` is spent.
    """
    params = _params("params", params)
    t_transient = duration("t_transient", t_transient, zero=True)
    t_window = duration("t_window", t_window)
    if t_transient + t_window > TIME_MAX:
        raise ValueError(f"t_transient + t_window must be at most {TIME_MAX:g} s (simulate's t_end), got "
                         f"{t_transient:g} + {t_window:g}")
    rtol, alpha0 = _rtol("rtol", rtol), state("alpha0", alpha0, "alpha")
    period_rtol, max_period = positive("period_rtol", period_rtol), integer("max_period", max_period)
    method_option(method, solver=solver, eps=None, rtol=rtol, atol=None, v_floor=None, params=params)
    tr = window_run(params, t_transient=t_transient, window=t_window, rtol=rtol, alpha0=alpha0, max_wall=max_wall,
                    method=method, solver=solver)
    how = (f"exact: {tr.method} ({tr.solver}), rtol {fmt_number(rtol, 3)}, alpha0 {fmt_number(alpha0, 6)}, window "
           f"[{fmt_number(t_transient, 6)}, {fmt_number(t_transient + t_window, 6)}] s, period_rtol "
           f"{fmt_number(period_rtol, 3)}")
    return StickSlipObservables.from_trajectory(tr, t_transient, period_rtol=period_rtol, max_period=max_period,
                                                method=how)


@functools.lru_cache(maxsize=2)
def _window_run(params, t_transient, window, rtol, alpha0, max_wall=None, method=None, solver=None):
    return simulate(params, t_transient + window, alpha0=alpha0, rtol=rtol, t_transient=t_transient, save="jumps",
                    max_wall=max_wall, method=method, solver=solver)


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


def _start_outcome(params: PeelParams, a0: float, kw: dict, method: str | None, solver: str | None,
                   period_rtol: float, deadline: float | None) -> dict:
    """One start of :func:`attractors` as plain data (a pool's task; never raises for the run's outcome):
    ``{"budget", "limit", "t", "message"}`` (a budget spent: the caller raises), ``{"error"}`` (a breakdown or an
    infeasible start), or ``{"kind", "period", "label", "x", "settle"}``.  ``deadline``: the call's, a
    ``time.time()``; a start that begins after it is not run, a running one gets what is left as its
    ``max_wall``."""
    left = None if deadline is None else deadline - time.time()
    if left is not None and left <= 0:
        return {"budget": "max_wall", "limit": None, "t": 0.0, "message": "spent before this start began",
                "state": _start_state(params, a0)}
    try:
        initial_state(params, alpha0=a0)
        tr = window_run(params, alpha0=a0, max_wall=left, method=method, solver=solver, **kw)
    except SolverBudgetExceeded as exc:  # as data: the exception's keyword-only fields do not pickle
        return {"budget": exc.budget, "limit": exc.limit, "t": exc.t, "message": str(exc),
                "state": dict(exc.state)}
    except (ModelBreakdown, ValueError) as exc:
        return {"error": f"{type(exc).__name__}: {str(exc)[:80]}"}
    per = classify(tr, period_rtol=period_rtol)
    if per.kind == "no stick-slip":
        return {"kind": per.kind}
    return {"kind": per.kind, "period": per.period, "label": per.label, "x": return_map(tr),
            "settle": settle_time(tr, rtol=period_rtol)}


def _start_state(params: PeelParams, a0: float) -> dict | None:
    """The consistent start at ``alpha0 = a0`` as a state dict (that of a start the budget left unbegun), or None
    where the start is infeasible."""
    try:
        return initial_state(params, alpha0=a0).as_dict()
    except (ModelBreakdown, ValueError):
        return None


def _budget_error(out: dict, wall: WallBudget, t_end: float) -> SolverBudgetExceeded:
    """The exception of a start whose budget was spent: the call's ``max_wall`` named as such, else the run's;
    its state is where that start's run stopped (its start, if it never began)."""
    state = out.get("state") or {"t": out["t"]}
    if out["budget"] == "max_wall" and wall.limit is not None:
        return SolverBudgetExceeded(f"more than {wall.limit:g} s of wall time (max_wall) at t={out['t']:.6g}; pass "
                                    "a larger max_wall, or None", budget="max_wall", limit=wall.limit, t=out["t"],
                                    state=state, partial=None)
    return SolverBudgetExceeded(out["message"], budget=out["budget"], limit=out["limit"], t=out["t"],
                                state=state, partial=None)


def attractors(params: PeelParams, alpha0s: Sequence[float] = (-0.3, -0.15, 0.0, 0.15, 0.3), *,
               t_transient: float = WINDOW_DEFAULTS["t_transient"], window: float = WINDOW_DEFAULTS["window"],
               rtol: float = WINDOW_DEFAULTS["rtol"], period_rtol: float = 1e-6, match_rtol: float = 1e-4,
               progress: Callable[[str], None] | None = None, max_wall: float | None = DEFAULT_MAX_WALL,
               method: str | None = None, solver: str | None = None, executor: str | Executor | None = None,
               max_workers: int | None = None) -> list[Attractor]:
    """Sample initial peel angles and group the attractors they reach.

    Each start (α0, the rest :func:`exact.initial_state`'s default) is integrated for ``t_transient`` s
    (discarded) and ``window`` s (stored jumps) by :func:`window_run`.  Two periodic orbits are the same
    attractor when their periods agree and their sorted return-map cycles agree to ``match_rtol`` relative (a
    cycle is the same set of jump forces whatever its phase); aperiodic windows are grouped by their return
    range.  A start that breaks down (``ModelBreakdown``) or is infeasible (``ValueError``) is reported as its
    own entry.  More than one entry means coexisting attractors — or a transient longer than ``t_transient``:
    the entries' settle times tell which.

    Parameters
    ----------
    params : PeelParams
        With any law ``params.force`` the hybrid solver runs (:func:`exact.simulate`); a model variant, its own
        method (:func:`window_run`).
    alpha0s : sequence of float
        Initial peel angles [rad], each in ``STATE_RANGES["alpha"]``, at least one.
    t_transient, window, rtol : float
        Of each start's :func:`window_run` (defaults :data:`peelapprox.WINDOW_DEFAULTS`: 30 s, 20 s, 1e-10).
    period_rtol : float
        Relative tolerance of the period detection (:func:`peelapprox.classify`) and the settle time, > 0.
    match_rtol : float
        Relative tolerance within which two periodic cycles are the same attractor, > 0.
    progress : callable, optional
        Called as ``progress(message)`` as each start finishes (in this process).
    max_wall : float or None
        Wall-clock budget [s] of all starts together (``SolverBudgetExceeded``, ``budget="max_wall"``; None:
        unbounded).
    method, solver : str, optional
        Of each start's :func:`window_run` (None: the model's method and its solver).
    executor : {"auto", "threads", "processes", "serial"} or concurrent.futures.Executor, optional
        Where the starts run: a local pool of :mod:`peelapprox.parallel` (None: ``"auto"``, processes on more
        than two CPUs, threads on one or two), or any executor, used as is.  The starts are grouped in their
        order whatever order they finish in: the result is the same, bit for bit, wherever they ran.
    max_workers : int, optional
        Of a local pool (default: the CPUs, at most one per start; 0: in this process).

    Returns
    -------
    list of Attractor
        One entry per attractor (or per failed start), in the order first reached; ``starts`` lists the α0
        values that reach it, ``settle_times`` their settle times.

    Raises
    ------
    ValueError
        A bad argument (named, with its range).
    peelapprox.SolverBudgetExceeded
        When ``max_wall`` is spent.
    """
    # validate everything up front: inside the loop a ValueError can then only be an infeasible start
    params = _params("params", params)
    kw = dict(t_transient=duration("t_transient", t_transient, zero=True), window=duration("window", window),
              rtol=_rtol("rtol", rtol))
    method_option(method, solver=solver, eps=None, rtol=kw["rtol"], atol=None, v_floor=None, params=params)
    period_rtol = positive("period_rtol", period_rtol)
    match_rtol = positive("match_rtol", match_rtol)
    alpha0s = [float(a) for a in np.atleast_1d(states_alpha("alpha0s", alpha0s))]
    say = optional(function, "progress", progress) or (lambda msg: None)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    max_workers = optional(integer, "max_workers", max_workers, 0)
    if not (executor is None or executor in POOL_KINDS or callable(getattr(executor, "submit", None))):
        raise ValueError(f"executor must be None, one of {POOL_KINDS} or a concurrent.futures.Executor, got "
                         f"{executor!r}")
    found = _run_starts(params, alpha0s, kw, method, solver, period_rtol, wall, say, executor, max_workers)
    return _grouped(alpha0s, found, wall, kw["t_transient"] + kw["window"], match_rtol)


def _run_starts(params: PeelParams, alpha0s: list[float], kw: dict, method: str | None, solver: str | None,
                period_rtol: float, wall: WallBudget, say: Callable[[str], None], executor: str | Executor | None,
                max_workers: int | None) -> dict[int, dict]:
    """Each start's outcome (:func:`_start_outcome`; a start the pool lost: its budget or error), by its index."""
    deadline = None if wall.limit is None else time.time() + wall.limit - (time.perf_counter() - wall.t0)
    tasks = [(k, (params, a0, kw, method, solver, period_rtol, deadline)) for k, a0 in enumerate(alpha0s)]
    found: dict[int, dict] = {}

    def put(k: int, out: dict) -> None:
        say(f"attractors V={params.V:g} I={params.I:g}: alpha0={alpha0s[k]:g} done")
        found[k] = out

    lost = map_points(_start_outcome, tasks, put, pool=AUTO if executor is None else executor,
                      max_workers=max_workers, deadline=deadline)
    for k, text in lost:
        found[k] = {"budget": "max_wall", "limit": wall.limit, "t": 0.0, "message": text,
                    "state": _start_state(params, alpha0s[k])} if text == DEADLINE_TEXT else {"error": text[:100]}
    return found


def _grouped(alpha0s: list[float], found: dict[int, dict], wall: WallBudget, t_end: float,
             match_rtol: float) -> list[Attractor]:
    """The starts' outcomes grouped into attractors, in the order of the starts (wherever they ran); the first
    spent budget raised."""
    groups: list[dict] = []
    for k, a0 in enumerate(alpha0s):
        out = found[k]
        if "budget" in out:
            raise _budget_error(out, wall, t_end)
        if "error" in out or out["kind"] == "no stick-slip":
            groups.append(dict(label=out.get("error", "no stick-slip"), period=None, signature=(),
                               F_range=(math.nan, math.nan), starts=[a0], settle=[None]))
            continue
        x, st = out["x"], out["settle"]
        if out["kind"] == "periodic":
            sig = tuple(float(v) for v in np.sort(x[: out["period"]]))
        else:
            sig = (float(x.min()), float(x.max()), float(x.mean()))
        for g in groups:
            if g["period"] == out["period"] and g["label"] == out["label"] and len(g["signature"]) == len(sig) and \
                    np.allclose(g["signature"], sig, rtol=match_rtol, atol=0.0):
                g["starts"].append(a0)
                g["settle"].append(st)
                break
        else:
            groups.append(dict(label=out["label"], period=out["period"], signature=sig,
                               F_range=(float(x.min()), float(x.max())), starts=[a0], settle=[st]))
    return [Attractor(g["label"], g["period"], tuple(round(s, 6) for s in g["signature"]), g["F_range"],
                      tuple(float(a) for a in g["starts"]), tuple(g["settle"])) for g in groups]
