"""The starts of :func:`exact.attractor_set` and their runs: the default design (:func:`default_starts`), the check of
a given set (:func:`check_starts`), one start's windowed run as plain data (:func:`run_start`, the function shipped to
an executor) and all of them in the order of the starts under the call's deadline (:func:`run_all`).
"""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from typing import Any

import numpy as np

from peelapprox import ModelBreakdown, PeelParams, SolverBudgetExceeded, SolverFailure
from peelapprox.errors import WallBudget
from peelapprox.parallel import AUTO, worker_pool
from peelapprox.validate import real

from .._initial import initial_state
from .._model import model_of
from .._simulate import simulate
from .._trajectory import State
from ._attractor_set_result import SetStart

__all__ = ["ALPHA_SPREAD", "SECTION_SPREAD", "Deadline", "check_starts", "default_starts", "run_all", "run_start"]

#: The α0 starts of the default design (the rest :func:`exact.initial_state`'s): those of :func:`exact.attractors`.
ALPHA_SPREAD = (-0.3, -0.15, 0.15, 0.3)
#: The section starts of the default design: ``(α, α̇ R/V)`` on the AB→CD section (v at the AB fold v_max, so
#: ``ω = v_max/R + α̇``, F = f_max/(1 + c(α)), continuing on CD), spread around the quasi-static cycle's jump
#: (α = α̇ = 0) by a tenth of a radian and half the pull's angular speed.
SECTION_SPREAD = ((-0.1, 0.5), (0.1, -0.5))


class Deadline:
    """The call's wall-clock budget: a ``time.time()`` deadline the workers share (None: unbounded)."""

    def __init__(self, max_wall: float | None):
        self.limit = max_wall
        self.t0 = time.perf_counter()
        self.at = None if max_wall is None else time.time() + max_wall

    def left(self) -> float | None:
        return None if self.at is None else self.at - time.time()

    def budget(self) -> WallBudget:
        """What is left, as the :class:`peelapprox.errors.WallBudget` of a Newton solve."""
        left = self.left()
        return WallBudget(None if left is None else max(left, 1e-9))


def default_starts(params: PeelParams) -> tuple[SetStart, ...]:
    """The default design of :func:`exact.attractor_set`: the solver's start (:func:`exact.initial_state`), the
    relaxation cycle's foot at rest (α = α̇ = 0 on AB with F = f_min, v its AB root v_land_ab), α0 in
    :data:`ALPHA_SPREAD` and the section states of :data:`SECTION_SPREAD`; the last two kinds only where f has
    folds at V (8 starts then, else 5)."""
    out = [SetStart("solver")]
    try:
        bs = params.force.folds(params.V) if model_of(params).has_hybrid else None
    except ValueError:
        bs = None
    folds = bs is not None and bs.has_folds and None not in (bs.v_land_ab, bs.f_min, bs.f_max, bs.v_max)
    if folds and bs is not None and bs.v_land_ab is not None and bs.f_min is not None and math.isfinite(bs.v_land_ab):
        out.append(SetStart("rest", 0.0, bs.v_land_ab / params.R, bs.f_min, "AB"))
    out += [SetStart(f"alpha0={a:g}", a) for a in ALPHA_SPREAD]
    if folds and bs is not None and bs.f_max is not None and bs.v_max is not None:
        w = params.V / params.R
        for a, ad in SECTION_SPREAD:
            F = bs.f_max / (1.0 + float(params.closure(a)[0]))
            out.append(SetStart(f"section(alpha={a:g}, alphadot={ad:g} V/R)", a, bs.v_max / params.R + ad * w,
                                float(F), "CD"))
    return tuple(out)


def _as_start(i: int, item: Any) -> SetStart:
    if isinstance(item, SetStart):
        return item
    if isinstance(item, State):
        return SetStart(f"state[{i}]", float(item.alpha), float(item.omega), float(item.F), str(item.branch))
    if isinstance(item, Mapping):
        extra = set(item) - {"alpha0", "omega0", "F0", "branch0", "name"}
        if extra:
            raise ValueError(f"starts[{i}] has unknown keys {sorted(extra)}; allowed: alpha0, omega0, F0, branch0, "
                             "name")
        kw = {k: item[k] for k in ("alpha0", "omega0", "F0", "branch0") if item.get(k) is not None}
        alpha0 = real(f"starts[{i}]['alpha0']", kw.pop("alpha0", 0.0), rng="[-pi, pi]")  # the rest: initial_state's
        return SetStart(str(item.get("name", f"start[{i}]")), alpha0, **kw)
    if isinstance(item, numbers.Real) and not isinstance(item, bool):  # numpy's scalars too, not numpy.bool_
        return SetStart(f"alpha0={float(item):g}", float(item))
    raise TypeError(f"starts[{i}] must be a float (alpha0), an exact.State, a mapping or a SetStart, got "
                    f"{type(item).__name__}")


def check_starts(params: PeelParams, starts: Any) -> tuple[list[SetStart], list[tuple[SetStart, str]]]:
    """The starts to run and the default design's starts without a consistent state (with why).

    A given start out of its range or without a consistent state is a ValueError naming ``starts[i]``; an empty
    set is a ValueError.
    """
    if isinstance(starts, str):
        if starts != "default":
            raise ValueError(f"starts must be 'default' or a sequence of starts, got {starts!r}")
        given, design = list(default_starts(params)), True
    else:
        if isinstance(starts, np.ndarray) and starts.ndim == 1:  # α0 values (np.linspace(-0.3, 0.3, 7))
            starts = starts.tolist()
        if not isinstance(starts, Sequence):
            raise TypeError(f"starts must be 'default' or a sequence of starts, got {type(starts).__name__}")
        if len(starts) == 0:
            raise ValueError("starts must hold at least one start (or be 'default')")
        given, design = [_as_start(i, s) for i, s in enumerate(starts)], False
    valid, invalid = [], []
    for i, s in enumerate(given):
        try:
            initial_state(params, **s.kwargs())
        except ValueError as exc:
            if not design:
                raise ValueError(f"starts[{i}] ({s.name}): {exc}") from None
            invalid.append((s, f"invalid start: {' '.join(str(exc).split())[:200]}"))
            continue
        valid.append(s)
    return valid, invalid


def run_start(params: PeelParams, start: SetStart, t_transient: float, t_window: float, rtol: float,
              deadline: float | None) -> dict[str, Any]:
    """One start's windowed run as plain data: ``{"trajectory", "outcome", "reason", "message", "wall"}`` (the
    trajectory None unless the run finished; never raises for a model outcome)."""
    w0 = time.perf_counter()
    out: dict[str, Any] = {"trajectory": None, "outcome": "failure", "reason": "", "message": "", "wall": 0.0}
    left = None if deadline is None else deadline - time.time()
    if left is not None and left <= 0:
        return {**out, "outcome": "max_wall", "message": "not run: the call's max_wall was spent before it began"}
    try:
        out["trajectory"] = simulate(params, t_transient + t_window, rtol=rtol, save="jumps", t_transient=t_transient,
                                     max_wall=left, **start.kwargs())
        out["outcome"] = "ran"
    except ModelBreakdown as exc:
        out.update(outcome="breakdown", reason=str(getattr(exc, "reason", "")), message=_msg(exc))
    except SolverBudgetExceeded as exc:
        out.update(outcome="max_wall" if exc.budget == "max_wall" else "failure", message=_msg(exc))
    except (SolverFailure, ValueError, ArithmeticError) as exc:
        out.update(message=f"{type(exc).__name__}: {_msg(exc)}")
    out["wall"] = time.perf_counter() - w0
    return out


def _lost(exc: BaseException, what: str) -> dict[str, Any]:
    return {"trajectory": None, "outcome": "failure", "reason": "", "wall": 0.0,
            "message": f"{what}: {type(exc).__name__}: {_msg(exc)}"}


def _msg(exc: BaseException) -> str:
    return " ".join(str(exc).split())[:300]


def run_all(params: PeelParams, starts: list[SetStart], t_transient: float, t_window: float, rtol: float,
            deadline: Deadline, workers: int | None, executor: Executor | None,
            say: Callable[[int, int, str], None]) -> list[dict[str, Any]]:
    """:func:`run_start` of every start, in the order of the starts whatever order they finish in."""
    args = [(params, s, t_transient, t_window, rtol, deadline.at) for s in starts]
    total = len(args)

    def note(k: int, done: int, res: dict[str, Any]) -> None:
        say(done, total, f"{starts[k].name}: {res['outcome']}")

    results: list[dict[str, Any]] = []
    if executor is None and (workers == 0 or total == 1):
        for k, a in enumerate(args):
            try:
                results.append(run_start(*a))
            except Exception as exc:  # as the executor's path: an outcome, not an exception
                results.append(_lost(exc, "this start's run raised"))
            note(k, k + 1, results[-1])
        return results
    if executor is not None:
        return _collect(executor, args, note)
    with worker_pool(AUTO, workers, n_tasks=total) as (pool, _kind, _n):
        if pool is None:  # one CPU, or inside a worker: no nested pool
            return run_all(params, starts, t_transient, t_window, rtol, deadline, 0, None, say)
        return _collect(pool, args, note)


def _collect(executor: Executor, args: list[tuple], note: Callable[[int, int, dict[str, Any]], None]
             ) -> list[dict[str, Any]]:
    """The starts' runs on ``executor``, in the order of ``args``; a start the executor lost is an outcome."""
    results: list[dict[str, Any]] = []
    futs = [executor.submit(run_start, *a) for a in args]
    for k, f in enumerate(futs):
        try:
            res = f.result()
        except Exception as exc:  # the executor lost the start: an outcome, not an exception
            res = _lost(exc, "the executor lost this start")
        results.append(res)
        note(k, k + 1, res)
    return results
