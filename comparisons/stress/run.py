"""One stress point in this process: run it and classify how it ended.

:func:`run_point` runs a :class:`~comparisons.stress.points.StressPoint`, inspects the trajectory (complete or
partial) and returns a record; :func:`is_allowed` and :func:`is_bug` classify records.  Every run must end in a
:class:`~exact.Trajectory` or a documented exception, never in a non-finite value or a hang; the record's
``outcome`` says which:

* allowed: ``ok`` (reached ``t_end``); ``breakdown:<reason>`` (:class:`~exact.ModelBreakdown`: ``no_root``,
  ``no_landing``, ``geometry``, ``v_ceiling``, ...); ``budget:<which>`` (:class:`~exact.SolverBudgetExceeded`
  for ``max_steps``, ``max_jumps`` or ``max_points``); ``solver_failure`` (:class:`~exact.SolverFailure`);
  ``invalid_initial_state`` (:func:`exact.initial_state`'s ValueError: no root of CONSTR at that α0 and F0);
* bugs: ``nan`` (a non-finite value in the returned or partial arrays); ``timeout`` (no answer within the
  wall-clock timeout: a hang); ``crash`` (the worker died); ``unexpected:<ExceptionType>`` (any other
  exception, also a ValueError from ``simulate`` after the initial state was accepted).

Independently, ``t_monotone`` is False, a bug, if stored or jump times ever decrease or leave ``[0, t_end]``.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from peelapprox.io import jsonable

from .._worker import message
from .points import StressPoint

__all__ = ["ALLOWED_PREFIXES", "BUG_CLASSES", "DRIFT_FRACTION", "run_point", "is_allowed", "is_bug"]

#: Outcome classes (or prefixes) that are documented, legitimate endings.
ALLOWED_PREFIXES: tuple[str, ...] = ("ok", "breakdown:", "budget:", "solver_failure", "invalid_initial_state")
#: Outcome classes (or prefixes) that are bugs.
BUG_CLASSES: tuple[str, ...] = ("nan", "timeout", "crash", "unexpected:")

#: Fraction of the stored points / jumps counted as "early" and "late" in the drift check.
DRIFT_FRACTION = 0.1


def _nonfinite(*arrays: Any) -> bool:
    return any(np.size(a) and not np.all(np.isfinite(np.asarray(a, dtype=float))) for a in arrays)


def _maxabs(x: np.ndarray) -> float:
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return float("nan")
    return float(np.max(np.abs(x)))


def _early_late(x: np.ndarray) -> tuple[float, float]:
    n = len(x)
    if n == 0:
        return float("nan"), float("nan")
    m = max(1, int(math.ceil(DRIFT_FRACTION * n)))
    return _maxabs(x[:m]), _maxabs(x[-m:])


def _jump_residuals(tr: Any) -> np.ndarray:
    """Relative CONSTR residual at each jump, before and after, worst of the two [-]."""
    from peelapprox import peel_force

    J = tr.jumps
    if len(J) == 0:
        return np.zeros(0)
    G = J.F * (1.0 + np.asarray(tr.params.closure(J.alpha)[0], dtype=float))
    with np.errstate(all="ignore"):
        fb = peel_force(np.maximum(J.v_before, 1e-300), tr.params.V)
        fa = peel_force(np.maximum(J.v_after, 1e-300), tr.params.V)
        return np.maximum(np.abs((G - fb) / fb), np.abs((G - fa) / fa))


def _inspect(tr: Any, t_end: float, rec: dict, keep_jump_times: bool) -> None:
    """Fill the trajectory-derived fields of ``rec`` from a Trajectory (complete or partial)."""
    J = tr.jumps
    rec["n_points"] = int(len(tr.t))
    rec["n_jumps"] = int(tr.stats.n_jumps)
    rec["n_steps"] = int(tr.stats.n_steps)
    rec["nonfinite"] = bool(  # a non-finite value, or a stored v <= 0 (outside the model's domain)
        _nonfinite(tr.t, tr.alpha, tr.omega, tr.F, tr.v, J.t, J.alpha, J.omega, J.F, J.v_before, J.v_after)
        or np.any(np.asarray(tr.v) <= 0.0)
    )
    ok_t = True
    for ts in (tr.t, J.t):
        ts = np.asarray(ts, dtype=float)
        if ts.size:
            ok_t &= bool(np.all(np.diff(ts) >= 0)) and bool(ts[0] >= 0.0) and bool(ts[-1] <= t_end)
    rec["t_monotone"] = bool(ok_t)
    with np.errstate(all="ignore"):
        r = tr.constraint_residual(relative=True) if len(tr.t) else np.zeros(0)
    rec["res_max"] = _maxabs(r)
    rec["res_median"] = float(np.median(np.abs(r))) if r.size else float("nan")
    rec["res_early"], rec["res_late"] = _early_late(r)
    jr = _jump_residuals(tr)
    rec["jres_max"] = _maxabs(jr)
    rec["jres_early"], rec["jres_late"] = _early_late(jr)
    if keep_jump_times:
        rec["_jump_t"] = [float(x) for x in J.t]


def _empty_record(point: StressPoint) -> dict:
    rec = point.as_dict()
    rec.update(
        outcome="", exception="", reason="", message="", t_reached=float("nan"), wall=float("nan"),
        n_steps=0, n_jumps=0, n_points=0, res_max=float("nan"), res_median=float("nan"), res_early=float("nan"),
        res_late=float("nan"),
        jres_max=float("nan"), jres_early=float("nan"), jres_late=float("nan"), t_monotone=True, nonfinite=False,
        expect_met=True,
    )
    return rec


def run_point(point: StressPoint, keep_jump_times: bool = False) -> dict:
    """Run one point in this process and classify how it ended.

    Parameters
    ----------
    point : StressPoint
    keep_jump_times : bool
        Also return the jump times under the private key ``"_jump_t"`` (used
        by the tolerance sweep; not written to CSV/JSON).

    Returns
    -------
    dict
        The point's fields plus ``outcome`` (see the module docstring),
        ``exception`` (type name or ""), ``reason``, ``message``,
        ``t_reached`` [s], ``wall`` [s] (initial state + integration,
        excluding kernel compilation), ``n_steps``, ``n_jumps``, ``n_points``,
        ``res_max``/``res_early``/``res_late`` (max relative CONSTR residual
        over all / the first / the last 10 % of stored points; NaN when no
        point is stored), ``res_median``, ``jres_*`` (the same at the jumps, before and after
        the jump), ``t_monotone``, ``nonfinite`` and ``expect_met``.  For
        exceptions carrying a partial trajectory the trajectory fields are
        taken from it.

    Raises
    ------
    ValueError
        If ``point`` is not a :class:`StressPoint`.
    """
    if not isinstance(point, StressPoint):
        raise ValueError(f"point must be a StressPoint, got {type(point).__name__}")
    import exact
    from peelapprox import PeelParams

    rec = _empty_record(point)
    if point.method == "hybrid":
        exact.compile_kernels(calls=("simulate",))
    params = PeelParams(V=point.V, I=point.I, k=point.k, geometry=point.geometry)
    t0 = time.perf_counter()
    try:
        exact.initial_state(params, alpha0=point.alpha0)
    except ValueError as e:
        rec.update(outcome="invalid_initial_state", exception="ValueError", message=message(e), t_reached=0.0,
                   wall=time.perf_counter() - t0)
        return _finish(point, rec)
    kw: dict[str, Any] = dict(alpha0=point.alpha0, method=point.method, rtol=point.rtol, atol=point.atol,
                              max_steps=point.max_steps, max_jumps=point.max_jumps, max_points=point.max_points)
    if point.n_eval:
        kw["t_eval"] = np.linspace(0.0, point.t_end, point.n_eval)
    else:
        kw["save"] = point.save
    tr, exc = _simulate(params, point, kw, rec)
    rec["wall"] = time.perf_counter() - t0
    _check_end(point, rec, tr, exc, keep_jump_times)
    return _finish(point, rec)


def _simulate(params: Any, point: StressPoint, kw: dict, rec: dict) -> tuple[Any, Any]:
    """Run ``exact.simulate`` and classify how it ended into ``rec`` (outcome, exception, reason, message,
    t_reached); returns the trajectory (the partial one of an exception, None after an unexpected one) and the
    model's or solver's exception (None when it finished or raised something else)."""
    import exact
    from exact import ModelBreakdown, SolverBudgetExceeded, SolverFailure

    tr = None
    exc: Any = None
    try:
        tr = exact.simulate(params, point.t_end, **kw)
        rec.update(outcome="ok", t_reached=float(tr.final_state.t))
    except ModelBreakdown as e:
        rec.update(outcome=f"breakdown:{e.reason}", exception="ModelBreakdown", reason=str(e.reason), t_reached=e.t)
        tr, exc = e.partial, e
        rec["message"] = message(e)
    except SolverBudgetExceeded as e:
        rec.update(outcome=f"budget:{e.budget}", exception="SolverBudgetExceeded", reason=str(e.budget), t_reached=e.t)
        tr, exc = e.partial, e
        rec["message"] = message(e)
    except SolverFailure as e:
        rec.update(outcome="solver_failure", exception="SolverFailure", t_reached=e.t, message=message(e))
        tr, exc = e.partial, e
    except Exception as e:  # noqa: BLE001 - anything else is a finding, not a crash of the suite
        rec.update(outcome=f"unexpected:{type(e).__name__}", exception=type(e).__name__, message=message(e))
        tr = None
    return tr, exc


def _check_end(point: StressPoint, rec: dict, tr: Any, exc: Any, keep_jump_times: bool) -> None:
    """The checks of a run's end into ``rec``: the trajectory's (:func:`_inspect`), a finished run's final state
    and end time, an exception's finite time and state with v > 0; ``nan`` as the outcome where one fails."""
    if tr is not None:
        _inspect(tr, point.t_end, rec, keep_jump_times)
        if rec["outcome"] == "ok":
            fs = tr.final_state
            rec["nonfinite"] |= _nonfinite([fs.t, fs.alpha, fs.omega, fs.F, fs.v]) or not fs.v > 0
            rec["t_monotone"] &= bool(abs(fs.t - point.t_end) <= 1e-12 * max(1.0, point.t_end))
    if exc is not None:  # an exception reports a finite time and state with v > 0
        sd = exc.state
        rec["nonfinite"] |= _nonfinite([exc.t, sd["alpha"], sd["omega"], sd["F"], sd["v"]]) or not sd["v"] > 0
    if tr is not None or exc is not None:
        if rec["nonfinite"]:
            rec["outcome"] = "nan"
    if isinstance(rec["t_reached"], float) and not math.isfinite(rec["t_reached"]) and rec["outcome"] != "nan":
        rec["t_reached"] = float("nan")


def _finish(point: StressPoint, rec: dict) -> dict:
    rec["expect_met"] = (rec["outcome"] == point.expect) if point.expect else is_allowed(rec["outcome"])
    for key, val in list(rec.items()):
        if isinstance(val, (np.floating, np.integer, np.bool_)):
            rec[key] = jsonable(val, keep_nonfinite=True, scalar=True)
    return rec


def is_allowed(outcome: str) -> bool:
    """True for the documented, legitimate outcome classes (:data:`ALLOWED_PREFIXES`)."""
    return any(outcome == p or (p.endswith(":") and outcome.startswith(p)) for p in ALLOWED_PREFIXES)


def is_bug(record: dict) -> bool:
    """True if a record shows a bug: a bug outcome class or non-monotone time."""
    return (not is_allowed(record["outcome"])) or not record.get("t_monotone", True)
