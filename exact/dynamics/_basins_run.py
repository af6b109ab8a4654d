"""The starts of :func:`exact.basins` as they run: one start's outcome as plain data (:func:`run_start`, the
function shipped to the workers), and all of them in grid order on an executor under the call's wall-clock
deadline (:func:`run_all`).

The deadline is a time of the system clock (``time.time()``, seconds since the epoch), the one clock a worker
process or a dask worker on another host shares with the caller (to the hosts' clock skew): a start that begins
after it is not run, a start that is running gets what is left of it as its run's ``max_wall``, and the caller
cancels the starts not begun once it has passed.  Either way the start's outcome is a failure with the text
``"failure:max_wall"`` (:data:`WALL_TEXT`), like any other failure an outcome, not an exception.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Executor
from typing import Any

import numpy as np

from peelapprox import ModelBreakdown, PeelParams, SolverBudgetExceeded, SolverFailure, periodicity, return_map
from peelapprox.io import ProgressLine
from peelapprox.parallel import AUTO, DEADLINE_TEXT, map_points

from .._initial import initial_state
from .._simulate import simulate

__all__ = ["APERIODIC", "BREAKDOWN", "FAILURE", "INVALID", "UNDETERMINED", "WALL_TEXT", "msg", "reporter", "run_all",
           "run_start"]

#: Label codes of the starts that reach no periodic attractor (``BasinResult.labels``).
INVALID, APERIODIC, BREAKDOWN, UNDETERMINED, FAILURE = -1, -2, -3, -4, -5
#: The outcome text of a start the call's ``max_wall`` left out or cut (code :data:`FAILURE`).
WALL_TEXT = "failure:max_wall"


def _wall_outcome(message: str) -> dict[str, Any]:
    return {"code": FAILURE, "text": WALL_TEXT, "n": None, "cycle": (), "n_returns": 0, "message": message}


def run_start(params: PeelParams, t_transient: float, window: float, rtol: float, max_period: int,
              alpha0: float, axis: str, value: float, solver: str | None = None,
              deadline: float | None = None) -> dict[str, Any]:
    """Outcome of one start as plain data (runs in a worker process; never raises for a model outcome).

    ``deadline``: the call's, a ``time.time()`` (module docstring; None: unbounded).  Returns ``{"code": INVALID |
    APERIODIC | BREAKDOWN | UNDETERMINED | FAILURE | 0 (periodic), "text", "n", "cycle" (sorted, the window's last
    n returns), "n_returns", "message"}``.
    """
    kw: dict[str, Any] = {"alpha0": alpha0, axis: value}
    out: dict[str, Any] = {"code": FAILURE, "text": "failure", "n": None, "cycle": (), "n_returns": 0, "message": ""}
    left = None if deadline is None else deadline - time.time()
    if left is not None and left <= 0:
        return _wall_outcome("not run: the call's max_wall was spent before this start began")
    try:
        initial_state(params, **kw)
    except ValueError as exc:  # no root of CONSTR (or a degenerate geometry) at this start
        return {**out, "code": INVALID, "text": "invalid start", "message": msg(exc)}
    try:
        tr = simulate(params, t_transient + window, rtol=rtol, save="jumps", t_transient=t_transient, solver=solver,
                      max_wall=left, **kw)
    except ModelBreakdown as exc:
        return {**out, "code": BREAKDOWN, "text": f"breakdown:{exc.reason}", "message": msg(exc)}
    except SolverBudgetExceeded as exc:
        if exc.budget == "max_wall":  # the only max_wall of the run is what was left of the call's
            return _wall_outcome(f"cut: the call's max_wall was spent during this start's run ({msg(exc)})")
        return {**out, "text": f"failure:{type(exc).__name__}", "message": msg(exc)}
    except (SolverFailure, ValueError, ArithmeticError) as exc:
        return {**out, "text": f"failure:{type(exc).__name__}", "message": msg(exc)}
    x = return_map(tr)
    out["n_returns"] = int(x.size)
    if x.size < 2:
        return {**out, "code": UNDETERMINED, "text": "undetermined:no stick-slip",
                "message": f"{x.size} AB->CD jumps in the window"}
    per = periodicity(x, max_period=max_period)
    if per.period is not None:
        n = int(per.period)
        return {**out, "code": 0, "text": f"period-{n}", "n": n, "cycle": tuple(float(c) for c in np.sort(x[-n:]))}
    if per.kind == "aperiodic":
        return {**out, "code": APERIODIC, "text": "aperiodic"}
    return {**out, "code": UNDETERMINED, "text": f"undetermined:{per.kind}",
            "message": f"{x.size} returns cannot rule out periods up to max_period={max_period}: lengthen window"}


def msg(exc: BaseException) -> str:
    """An exception's message on one line, at most 300 characters (an outcome's ``message``)."""
    return " ".join(str(exc).split())[:300]


def reporter(progress: Any, total: int) -> Callable[[int, dict], None]:
    """``progress=True``: a line on stderr for the first start, the last, every ~5 % and every start that failed
    (with its message); one updating line in Jupyter (:class:`peelapprox.io.ProgressLine`)."""
    if callable(progress):
        return lambda done, rec: progress(done, total, rec)
    if not progress:
        return lambda done, rec: None
    line = ProgressLine("basins", total)

    def report(done: int, rec: dict) -> None:
        failed = f"{rec['text']}: {rec.get('message', '')}"[:200] if rec["code"] == FAILURE else None
        line.update(done, failed=failed)

    return report


def run_all(tasks: list[tuple], executor: str | Executor | None, max_workers: int | None,
            report: Callable[[int, dict], None], deadline: float | None = None) -> list[dict]:
    """Outcomes of ``run_start(*task, deadline)`` in task order, whatever order they finish in, on
    :func:`peelapprox.parallel.map_points` (``executor`` its ``pool``; None: ``"auto"``); once ``deadline`` (a
    ``time.time()``) has passed, the starts not begun are cancelled (:data:`WALL_TEXT`), and a start the pool
    lost (its worker died) is a failure naming the pool's error."""
    results: list[dict | None] = [None] * len(tasks)
    done = 0

    def put(k: int, res: dict) -> None:
        nonlocal done
        results[k] = res
        done += 1
        report(done, res)

    lost = map_points(run_start, [(k, (*t, deadline)) for k, t in enumerate(tasks)], put,
                      pool=AUTO if executor is None else executor, max_workers=max_workers, deadline=deadline)
    for k, text in sorted(lost, key=lambda kt: kt[0]):
        if text == DEADLINE_TEXT:
            put(k, _wall_outcome("not run: the call's max_wall was spent before this start began"))
        else:  # "error: <Type>: <message>" (peelapprox.parallel.error_text)
            kind = text.split(":")[1].strip() if text.startswith("error:") else "lost"
            put(k, {"code": FAILURE, "text": f"failure:{kind}", "n": None, "cycle": (), "n_returns": 0,
                    "message": f"the executor lost this start: {text[:300]}"})
    return results  # type: ignore[return-value]
