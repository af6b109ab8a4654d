"""The option objects of :func:`exact.simulate` besides the method (what to save, the budgets), and the table
:data:`METHODS` of its methods, which the budget reads a method's step budget from.

In the style of diffrax (``diffeqsolve(solver=Dopri5(), saveat=SaveAt(ts=...), ...)``), each group of
``simulate``'s keywords has a frozen, keyword-only, self-validating dataclass: the method
(:mod:`exact._method_contract`), :class:`SaveAt` (every step, the states at given times, or the jumps only, after
``t_transient``) and :class:`Budget` (stored points, accepted steps, stored jumps, wall time).  ``simulate``
builds them from its keywords (``method_option``, :func:`output_options`) or takes them as given, and hands
them to the method, which reads their fields and validates nothing again.  Each object checks its fields with
the named validators of :mod:`peelapprox.validate`, so a bad field raises the same error as the ``simulate``
keyword of that name; what depends on the horizon ``t_end`` is checked or resolved by ``simulate``
(:meth:`SaveAt.within`, :meth:`Budget.resolved`).
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from peelapprox import TIME_MAX
from peelapprox.validate import ArgumentTypeError, choice, flag, in_range, integer, interval, optional, positive, reals

__all__ = ["SaveAt", "Budget", "METHODS", "default_max_steps", "method_class", "output_options"]

SAVES = ("steps", "jumps")

#: The solver methods of :func:`exact.simulate` by name (subclasses of :class:`exact._method_contract.Method`), in
#: the order a model's default is picked: filled by :mod:`exact._methods` with the built-in ones.
METHODS: dict[str, Any] = {}


def method_class(method: Any) -> Any:
    """The class of a method given by name (its :data:`METHODS` entry), as an object, or as the class itself."""
    if isinstance(method, str):
        return METHODS[method]
    return method if isinstance(method, type) else type(method)


def default_max_steps(method: Any, t_end: float) -> int:
    """The step budget ``simulate`` uses when ``max_steps=None``: ``clip(rate * t_end, floor, cap)`` of the
    method's ``step_budget`` (a method's name, object or class)."""
    rate, lo, hi = method_class(method).step_budget
    return int(min(hi, max(lo, rate * t_end)))


def _sorted_times(name: str, ts: Any, lo: float, hi: float, range_text: str) -> np.ndarray:
    """``ts`` as a flat float array, non-empty, sorted, every time in ``[lo, hi]`` (the message shows
    ``range_text = [lo, hi]``)."""
    te = reals(name, ts, lo, hi).ravel()
    if te.size == 0 or np.any(np.diff(te) < 0):
        shown = interval(lo, hi) if range_text.endswith("TIME_MAX]") else f"[{lo:g}, {hi:g}]"  # t_eval: as ever
        raise ValueError(f"{name} must be a non-empty, sorted sequence of times in {range_text} = {shown}")
    return te


@dataclass(frozen=True, kw_only=True, eq=False)
class SaveAt:
    """What a run stores (``simulate``'s ``save``, ``t_eval``, ``t_transient``).  Give exactly one of:

    Parameters
    ----------
    steps : bool
        Every accepted step, plus the states just before and after each jump (``save="steps"``).
    ts : array_like of float
        The states exactly at these times (``t_eval``): sorted, non-empty, in ``[t_transient, TIME_MAX]``
        (and within ``[t_transient, t_end]``, checked by ``simulate``); stored as a read-only float array.
    jumps_only : bool
        No points, only the jumps (``save="jumps"``): memory proportional to the number of jumps.
    t_transient : float
        Integrate from 0 but store no point or jump before this time [s], in [0, TIME_MAX] = [0, 1e6]
        (and at most ``t_end``).

    The jumps after ``t_transient`` are stored in every case.  Equal by value (``ts`` elementwise) and
    hashable.

    Raises
    ------
    ValueError, TypeError
        A field outside its range or of the wrong kind (named), or not exactly one of the three choices.
    """

    steps: bool = False
    ts: np.ndarray | None = None
    jumps_only: bool = False
    t_transient: float = 0.0

    def __post_init__(self) -> None:
        steps, jumps_only = flag("steps", self.steps), flag("jumps_only", self.jumps_only)
        t_transient = in_range("t_transient", self.t_transient, 0.0, TIME_MAX)
        ts = None
        if self.ts is not None:
            ts = _sorted_times("ts", self.ts, t_transient, TIME_MAX, "[t_transient, TIME_MAX]")
            ts.flags.writeable = False
        if steps + jumps_only + (ts is not None) != 1:
            raise ValueError(f"SaveAt needs exactly one of steps=True, ts=[...] or jumps_only=True, got "
                             f"steps={steps}, ts={'None' if ts is None else f'<{ts.size} times>'}, "
                             f"jumps_only={jumps_only}")
        for name, value in (("steps", steps), ("ts", ts), ("jumps_only", jumps_only), ("t_transient", t_transient)):
            object.__setattr__(self, name, value)

    def _key(self) -> tuple:
        ts = None if self.ts is None else (self.ts.shape, self.ts.tobytes())
        return (self.steps, ts, self.jumps_only, self.t_transient)

    def __eq__(self, other: object) -> bool:
        return self._key() == other._key() if isinstance(other, SaveAt) else NotImplemented

    def __hash__(self) -> int:
        return hash(self._key())

    def within(self, t_end: float) -> SaveAt:
        """``self`` if ``t_transient`` and every time of ``ts`` lie within ``[0, t_end]``; else ValueError
        naming the field and the range the horizon allows."""
        in_range("t_transient", self.t_transient, 0.0, t_end)
        if self.ts is not None:
            _sorted_times("ts", self.ts, self.t_transient, t_end, "[t_transient, t_end]")
        return self


@dataclass(frozen=True, kw_only=True)
class Budget:
    """The limits of one run; needing more than one raises ``SolverBudgetExceeded`` naming it.

    Parameters
    ----------
    max_steps : int, optional
        Accepted steps, all of them (from t = 0), in [1, MAX_COUNT = 1e15]; None: scaled with the horizon
        by :func:`default_max_steps` (resolved by :meth:`resolved`).
    max_jumps : int
        Stored jumps (those at ``t >= t_transient``: a memory budget), in [1, 1e15].
    max_points : int
        Stored points, in [1, 1e15].
    max_wall : float, optional
        Wall-clock seconds of the integration, in (0, inf) (checked between the hybrid method's kernel calls, at
        most 250,000 steps (~0.4 s) apart, and at every step of a scipy method); None: bounded by ``max_steps``
        only.

    Raises
    ------
    ValueError, TypeError
        A field outside its range or of the wrong kind (a float count included), named.
    """

    max_steps: int | None = None
    max_jumps: int = 20_000_000
    max_points: int = 5_000_000
    max_wall: float | None = None

    def __post_init__(self) -> None:
        # the order of simulate's checks: points, jumps, steps, wall
        object.__setattr__(self, "max_points", integer("max_points", self.max_points))
        object.__setattr__(self, "max_jumps", integer("max_jumps", self.max_jumps))
        object.__setattr__(self, "max_steps", optional(integer, "max_steps", self.max_steps))
        object.__setattr__(self, "max_wall", optional(positive, "max_wall", self.max_wall))

    def resolved(self, method: Any, t_end: float) -> Budget:
        """This budget with ``max_steps=None`` replaced by ``default_max_steps(method, t_end)`` (a method's name
        or object)."""
        if self.max_steps is not None:
            return self
        return replace(self, max_steps=default_max_steps(method, t_end))


def _given(value: Any, default: Any) -> bool:
    """A keyword differs from its default (a keyword at its default value counts as not given)."""
    if default is None:
        return value is not None
    plain = isinstance(value, (numbers.Real, str)) and not isinstance(value, (bool, np.bool_))
    return not (plain and value == default)


#: ``simulate``'s defaults of the keywords an option object stands for, where they are not the object's field
#: defaults (the others are: tests/test_options.py compares the signature with the fields).
_KEYWORD_DEFAULTS = {"solver": None, "eps": None, "save": "steps", "t_eval": None}


def _refuse(kind: str, obj: Any, pairs: Sequence[tuple[str, Any]], holds: str) -> None:
    """ValueError naming both if a keyword that the object ``obj`` stands for is given (not at its default)."""
    defaults = {f.name: f.default for f in fields(obj)} | _KEYWORD_DEFAULTS
    for name, value in pairs:
        if _given(value, defaults.get(name)):
            raise ValueError(f"{name} and {kind} both given ({name}={value!r:.60}, {kind}={obj!r:.80}): "
                             f"{holds}; give one of them")


def output_options(method: Any, t_end: float, saveat: Any, budget: Any, *, save: Any, t_eval: Any,
                   t_transient: Any, max_points: Any, max_steps: Any, max_jumps: Any,
                   max_wall: Any) -> tuple[SaveAt, Budget]:
    """The :class:`SaveAt` and the resolved :class:`Budget` of a ``simulate`` call with horizon ``t_end``.

    ``saveat`` / ``budget`` (objects or None) replace the keywords they hold, which must then be left at
    their defaults; the keyword path checks in ``simulate``'s documented order and messages (``t_eval``
    named as such, within ``[t_transient, t_end]``, at most ``max_points`` times).
    """
    if saveat is not None:
        if not isinstance(saveat, SaveAt):
            raise ArgumentTypeError(f"saveat must be a SaveAt or None, got {type(saveat).__name__}")
        _refuse("saveat", saveat, [("save", save), ("t_eval", t_eval), ("t_transient", t_transient)],
                "saveat=SaveAt(...) holds save, t_eval and t_transient")
        saveat.within(t_end)
    else:
        t_transient = in_range("t_transient", t_transient, 0.0, t_end)
        save = choice("save", save, SAVES)
    if budget is not None:
        if not isinstance(budget, Budget):
            raise ArgumentTypeError(f"budget must be a Budget or None, got {type(budget).__name__}")
        _refuse("budget", budget, [("max_points", max_points), ("max_steps", max_steps), ("max_jumps", max_jumps),
                                   ("max_wall", max_wall)],
                "budget=Budget(...) holds max_points, max_steps, max_jumps and max_wall")
    else:
        budget = Budget(max_points=max_points, max_jumps=max_jumps, max_steps=max_steps, max_wall=max_wall)
    if saveat is None:
        if t_eval is not None:
            te = _sorted_times("t_eval", t_eval, t_transient, t_end, "[t_transient, t_end]")
            saveat = SaveAt(ts=te, t_transient=t_transient)
        else:
            saveat = SaveAt(steps=save == "steps", jumps_only=save == "jumps", t_transient=t_transient)
        name = "t_eval"
    else:
        name = "saveat.ts"
    if saveat.ts is not None and saveat.ts.size > budget.max_points:
        raise ValueError(f"{name} has {saveat.ts.size} points, more than max_points={budget.max_points}")
    return saveat, budget.resolved(method, t_end)

