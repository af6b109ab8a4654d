"""Exceptions for physical breakdowns of the model and exhausted budgets."""

from __future__ import annotations

from typing import Any, Optional

__all__ = ["ModelBreakdown", "SolverBudgetExceeded", "SolverFailure", "KernelCacheWarning"]


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
        Short machine-readable cause (``"v_floor"``, ``"no_landing"``, ...).
    partial : object or None
        The trajectory computed up to the breakdown, when available.
    """

    def __init__(self, message: str, *, t: float, state: dict, reason: str, partial: Optional[Any] = None):
        super().__init__(message)
        self.t = t
        self.state = state
        self.reason = reason
        self.partial = partial


class SolverBudgetExceeded(RuntimeError):
    """A step, jump or stored-point budget was used up before ``t_end``.

    Attributes: ``budget`` (name of the keyword), ``limit``, ``t`` and
    ``state`` where the run stopped, ``partial`` trajectory.
    """

    def __init__(self, message: str, *, budget: str, limit: int, t: float, state: dict, partial: Optional[Any] = None):
        super().__init__(message)
        self.budget = budget
        self.limit = limit
        self.t = t
        self.state = state
        self.partial = partial


class SolverFailure(RuntimeError):
    """The integrator could not continue (step-size underflow, repeated rejection).

    Attributes: ``t``, ``state``, ``partial``.
    """

    def __init__(self, message: str, *, t: float, state: dict, partial: Optional[Any] = None):
        super().__init__(message)
        self.t = t
        self.state = state
        self.partial = partial


class KernelCacheWarning(RuntimeWarning):
    """No writable numba cache location: kernels are compiled without on-disk caching (see ``peelapprox._jit``)."""
