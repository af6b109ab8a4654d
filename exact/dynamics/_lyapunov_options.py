"""The methods of :func:`exact.lyapunov` and their options: which method takes which option, each option's
check, and :func:`check_lyapunov_options`, which makes those checks without running anything."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from peelapprox.validate import ArgumentTypeError, choice, duration, function, in_range, integer, optional, positive
from peelapprox.validate import eps as _eps

__all__ = ["D0_RANGE", "LYAPUNOV_METHODS", "check_lyapunov_options"]

#: Valid initial perturbation ``d0`` of the two-trajectory method (scaled units): below 1e-12 the perturbation
#: of F, ``d0 f_max``, nears the rounding of F itself (``2e-16 F``) and the two orbits can start at distance 0;
#: above 1 it is not a perturbation.
D0_RANGE = (1e-12, 1.0)

#: The methods of :func:`lyapunov` and the options each takes besides the common ``t_transient``, ``alpha0``,
#: ``rtol`` and ``max_wall`` (their defaults: the table of :func:`lyapunov`).
LYAPUNOV_METHODS: dict[str, tuple[str, ...]] = {
    "two-trajectory": ("tau", "n", "T", "n_discard", "d0", "solver"),
    "tangent": ("T", "max_steps"),
    "return-map": ("n_returns", "h"),
    "variational": ("eps", "T", "tau", "progress"),
}

#: The scipy solvers of a model variant's method (:func:`exact.simulate`'s ``solver``; the two-trajectory
#: method's option ``solver``, for ``params.variant`` only).
SOLVERS = ("Radau", "BDF", "LSODA", "DOP853", "RK45")

#: The check of each option of :data:`LYAPUNOV_METHODS`, ``check(name, value) -> value``: the one the methods apply
#: (the variational method's, in ``exact.dynamics._variational``, are the same validators).
_OPTION_CHECKS: dict[str, Callable[[str, Any], Any]] = {
    "tau": duration,
    "n": lambda name, x: integer(name, x, lo=2),
    "T": duration,
    "n_discard": lambda name, x: integer(name, x, lo=0),
    "d0": lambda name, x: in_range(name, x, *D0_RANGE),
    "max_steps": lambda name, x: optional(integer, name, x),
    "n_returns": lambda name, x: integer(name, x, lo=2),
    "h": lambda name, x: positive(name, x, hi=1.0),
    "eps": _eps,
    "progress": lambda name, x: optional(function, name, x),
    "solver": lambda name, x: optional(choice, name, x, SOLVERS),
}


def _check(name: str, x: Any) -> Any:
    """Option ``name`` of :data:`LYAPUNOV_METHODS` checked by its :data:`_OPTION_CHECKS` entry."""
    return _OPTION_CHECKS[name](name, x)


def check_lyapunov_options(method: str = "two-trajectory", **options: Any) -> str:
    """Check a method of :func:`lyapunov` and its options without running it (the checks :func:`lyapunov` makes).

    For callers that want a bad option reported before their own long runs (``peelapprox dynamics`` checks
    its ``--eps`` before the window run).

    Parameters
    ----------
    method : {"two-trajectory", "tangent", "return-map", "variational"}
    **options
        Options of ``method`` (:data:`LYAPUNOV_METHODS`), each checked by the validator the method applies.

    Returns
    -------
    str
        ``method``.

    Raises
    ------
    ValueError
        An unknown method (the message lists :data:`LYAPUNOV_METHODS`), an option out of its range (named, with the
        range), or both ``T`` and ``n`` for the two-trajectory method.
    peelapprox.validate.ArgumentTypeError
        (a ``TypeError`` and ``ValueError``) An option of another method, or of none (named, with the method),
        or of the wrong kind.
    """
    method = choice("method", method, tuple(LYAPUNOV_METHODS))
    own = LYAPUNOV_METHODS[method]
    for name in options:
        if name not in own:
            others = [m for m, opts in LYAPUNOV_METHODS.items() if name in opts]
            what = (f"an option of method {' and '.join(map(repr, others))}" if others else
                    "an option of no method")
            raise ArgumentTypeError(f"lyapunov: {name!r} is {what}, not of method={method!r} (whose options are "
                                    f"{', '.join(own)})")
    for name, value in options.items():
        _check(name, value)
    if method == "two-trajectory" and options.get("T") is not None and options.get("n") is not None:
        raise ValueError(f"lyapunov: give T (measured seconds, n = round(T/tau)) or n (renormalisation intervals), "
                         f"not both; got T={options['T']!r} and n={options['n']!r}")
    return method
