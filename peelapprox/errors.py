"""Exceptions for physical breakdowns of the model and exhausted budgets."""

from __future__ import annotations

import time
from typing import Any

__all__ = ["ModelBreakdown", "SolverBudgetExceeded", "SolverFailure", "KernelCacheWarning", "WallBudget",
           "budget_exceeded"]


class ModelBreakdown(RuntimeError):
    """The model itself stops making sense along the orbit.

    Examples: the pull side of CONSTR, ``F(1 - cos θ)``, falls towards
    ``f(0+, V)`` on AB so that the peel velocity would have to reach zero; a
    CD→AB jump with no AB root to land on (``f_min <= f(0+, V)``); the peel
    geometry degenerating (``1 - cos θ <= 0``).

    Attributes
    ----------
    t : float
        Time of the breakdown [s].
    state : dict
        ``alpha, omega, F, v, branch`` at ``t``.
    reason : str
        Short machine-readable cause (``"no_root"``, ``"no_landing"``, ``"geometry"``, ``"v_ceiling"``, or
        ``"v_floor"`` for a floor the caller passed).
    partial : object or None
        The trajectory computed up to the breakdown, when available.
    """

    def __init__(self, message: str, *, t: float, state: dict, reason: str, partial: Any | None = None):
        super().__init__(message)
        self.t = t
        self.state = state
        self.reason = reason
        self.partial = partial


class SolverBudgetExceeded(RuntimeError):
    """A step, jump, stored-point or wall-time budget was used up before ``t_end``.

    Attributes: ``budget`` (name of the keyword), ``limit``, ``t`` and
    ``state`` where the run stopped, ``partial`` trajectory.
    """

    def __init__(self, message: str, *, budget: str, limit: float, t: float, state: dict, partial: Any | None = None):
        super().__init__(message)
        self.budget = budget
        self.limit = limit
        self.t = t
        self.state = state
        self.partial = partial


def budget_exceeded(name: str, limit: float, t_end: float, state: dict, partial: Any | None) -> SolverBudgetExceeded:
    """The exception for a used-up budget, with the message both drivers give."""
    hints = {"max_points": "; pass t_eval, save='jumps' or a larger max_points",
             "max_steps": "; pass a larger max_steps (the default scales with t_end)",
             "max_wall": "; pass a larger max_wall, or None"}
    what = f"{limit:g} s of wall time" if name == "max_wall" else f"{name}={limit} {name[4:]}"
    return SolverBudgetExceeded(
        f"more than {what} before t_end={t_end} (stopped at t={state['t']:.6g}){hints.get(name, '')}",
        budget=name, limit=limit, t=state["t"], state=state, partial=partial,
    )


class WallBudget:
    """The wall-clock budget ``max_wall`` [s] of one public call made of many solver runs (None: unbounded).

    ``left(t, state, t_end)`` is the time left for the next run, to pass on as its ``max_wall``; it raises
    :class:`SolverBudgetExceeded` (``budget="max_wall"``, with the caller's ``t`` and ``state``) once the
    budget is spent.  ``reraise(exc)`` turns an inner run's ``max_wall`` exception into one naming this
    budget.
    """

    def __init__(self, max_wall: float | None):
        self.limit = max_wall
        self.t0 = time.perf_counter()

    def left(self, t: float, state: Any, t_end: float) -> float | None:
        """Seconds left (None: unbounded); ``state`` is the dict, or a callable building it only if needed."""
        if self.limit is None:
            return None
        rest = self.limit - (time.perf_counter() - self.t0)
        if rest <= 0.0:
            raise budget_exceeded("max_wall", self.limit, t_end, state() if callable(state) else state, None)
        return rest

    def reraise(self, exc: SolverBudgetExceeded) -> SolverBudgetExceeded:
        if exc.budget != "max_wall" or self.limit is None:
            return exc
        return SolverBudgetExceeded(f"more than {self.limit:g} s of wall time (max_wall) at t={exc.t:.6g}; pass a "
                                    "larger max_wall, or None", budget="max_wall", limit=self.limit, t=exc.t,
                                    state=exc.state, partial=exc.partial)


class SolverFailure(RuntimeError):
    """The integrator could not continue (step-size underflow, repeated rejection).

    Attributes: ``t``, ``state``, ``partial``.
    """

    def __init__(self, message: str, *, t: float, state: dict, partial: Any | None = None):
        super().__init__(message)
        self.t = t
        self.state = state
        self.partial = partial


class KernelCacheWarning(RuntimeWarning):
    """A kernel or law cache that another user could have written was refused (and replaced by a private one), or
    there is no private cache location and kernels are compiled without on-disk caching (docs/usage.md, "Where
    the caches are, and what is refused")."""
