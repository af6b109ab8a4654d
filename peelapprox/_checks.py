"""The model-independent argument checks behind :mod:`peelapprox.validate` (its docstring states the
rules); :mod:`peelapprox._params` builds on these, and :mod:`peelapprox.validate` adds the checks that
know the model (parameters, state ranges, durations), so neither imports the other in a circle.
The public list of names is ``peelapprox.validate.__all__``; this private module keeps none of its own."""

from __future__ import annotations

import functools
import math
import numbers
import os
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import numpy as np

from .io import fmt_number

T = TypeVar("T")

#: Upper bound of every integer count (steps, points, jumps, periods): 1e15 is beyond any run that can
#: finish (a year of wall time at 30 ns per step) and far inside numba's int64 (9.2e18).
MAX_COUNT = 10**15


class ArgumentTypeError(TypeError, ValueError):
    """An argument of the wrong kind (a string or bool for a number, a float for a count, ...).

    A ``TypeError``; also a ``ValueError`` so that handlers of the library's earlier "bad arguments raise
    ValueError" rule still catch it (module docstring).
    """


def _bound(x: float) -> str:
    """A bound as people write it (:func:`peelapprox.io.fmt_number`): ``0``, ``1e-14``, ``0.01``, ``1e+300`` ->
    ``1e300``, ``inf``."""
    return fmt_number(x, 6, nan="nan", int_digits=6, short_exponent=True)


def interval(lo: float = -math.inf, hi: float = math.inf, *, lo_open: bool = False, hi_open: bool = False) -> str:
    """The text of a range, ``"[lo, hi]"`` with ``(``/``)`` for open or infinite ends (``"(0, inf)"``).

    Remembered per bounds (their types and signs too: ``-0.0`` is written ``-0``): every validator builds its
    message's range before it checks, and a sweep's inner loops validate the same few ranges thousands of times a
    point (12 µs each to format, under the GIL)."""
    return _interval(lo, hi, lo_open, hi_open, math.copysign(1.0, lo), math.copysign(1.0, hi))


@functools.lru_cache(maxsize=512, typed=True)
def _interval(lo: float, hi: float, lo_open: bool, hi_open: bool, lo_sign: float, hi_sign: float) -> str:
    """:func:`interval`, cached (the signs are part of the key: ``0.0 == -0.0``)."""
    left = "(" if lo_open or math.isinf(lo) else "["
    right = ")" if hi_open or math.isinf(hi) else "]"
    return f"{left}{_bound(lo)}, {_bound(hi)}{right}"


#: Characters of a value :func:`shown` keeps in a message: a user's text (a path, an expression, an option's value)
#: can be any size (a 700 KB expression was echoed whole), and a message is read on one line.
SHOWN_LIMIT = 200


def shown(value: Any, limit: int = SHOWN_LIMIT) -> str:
    """``repr(value)`` for a message, cut after ``limit`` characters, its full length said.

    The cut text ends in ``"... (N characters)"``.

    N is the length of the value itself for ``str``/``bytes`` (what the user typed) and of its ``repr``
    otherwise, so the reader knows how much was left out.  ``repr`` is the value as Python writes it
    (quotes and escapes included: a trailing space or a control character is visible).

    Parameters
    ----------
    value : object
        What the user passed.
    limit : int
        Characters of the ``repr`` kept (at least 1).

    Returns
    -------
    str
        ``repr(value)`` if it has at most ``limit`` characters, else its first ``limit`` characters followed
        by ``"... (N characters)"``.

    Examples
    --------
    >>> shown("abc")
    "'abc'"
    >>> shown("x" * 700_000, limit=5)
    "'xxxx... (700000 characters)"
    """
    r = repr(value)
    limit = max(1, int(limit))
    if len(r) <= limit:
        return r
    n = len(value) if isinstance(value, (str, bytes)) else len(r)
    return f"{r[:limit]}... ({n} characters)"


def _got(x: Any) -> str:
    """:func:`shown` (60 characters), with the type for values whose repr hides it (``'abc' (str)``)."""
    r = shown(x, 60)
    if isinstance(x, (str, bytes, bool, np.bool_)) or x is None:
        return r if x is None else f"{r} ({type(x).__name__})"
    return r


def real(name: str, x: Any, *, rng: str = "(-inf, inf)") -> float:
    """``float(x)`` if x is a real number of any value (NaN and ±inf included), else ArgumentTypeError.

    Accepts Python and numpy real scalars, 0-d real arrays and other ``float()``-convertible numbers
    (``Fraction``); rejects None, ``bool``/``numpy.bool_``, ``str``/``bytes``, complex numbers, and
    arrays or sequences with any dimension.  ``rng`` is the range printed in the message.
    """
    bad = (x is None or isinstance(x, (bool, np.bool_, str, bytes, complex, np.complexfloating))
           or np.ndim(x) != 0)
    if not bad:
        if isinstance(x, np.ndarray) and x.dtype.kind not in "iuf":
            bad = True
        else:
            try:
                return float(x)
            except (TypeError, ValueError, OverflowError):
                # OverflowError: an int beyond the float range; it is a number, but not a usable one
                if isinstance(x, numbers.Integral):
                    raise ValueError(f"{name} must be finite and in {rng}, got {_got(x)}") from None
                bad = True
    raise ArgumentTypeError(f"{name} must be a real number in {rng}, got {_got(x)}")


def in_range(name: str, x: Any, lo: float = -math.inf, hi: float = math.inf, *, lo_open: bool = False,
             hi_open: bool = False) -> float:
    """``float(x)`` if x is a finite real number in the range from ``lo`` to ``hi``.

    Parameters
    ----------
    name : str
        The argument's name, as the caller spells it.
    x : object
        The value given.
    lo, hi : float
        Bounds; infinite bounds are always open (the value must be finite).
    lo_open, hi_open : bool
        Exclude the bound itself.

    Returns
    -------
    float

    Raises
    ------
    ArgumentTypeError
        If x is not a real number (see :func:`real`).
    ValueError
        If x is NaN, infinite or outside the range: ``"<name> must be finite and in [lo, hi], got x"``.
    """
    rng = interval(lo, hi, lo_open=lo_open, hi_open=hi_open)
    y = real(name, x, rng=rng)
    ok = math.isfinite(y) and (y > lo if lo_open else y >= lo) and (y < hi if hi_open else y <= hi)
    if not ok:
        raise ValueError(f"{name} must be finite and in {rng}, got {_got(x)}")
    return y


def finite(name: str, x: Any) -> float:
    """``float(x)`` if x is a finite real number, else an error naming ``name`` (:func:`in_range`)."""
    return in_range(name, x)


def positive(name: str, x: Any, hi: float = math.inf) -> float:
    """``float(x)`` if x is a finite real number in ``(0, hi]`` (``(0, inf)`` by default)."""
    return in_range(name, x, 0.0, hi, lo_open=True)


def nonnegative(name: str, x: Any, hi: float = math.inf) -> float:
    """``float(x)`` if x is a finite real number in ``[0, hi]`` (``[0, inf)`` by default)."""
    return in_range(name, x, 0.0, hi)


def optional(check: Callable[..., T], name: str, x: Any, *args: Any, **kwargs: Any) -> T | None:
    """None stays None; anything else goes through ``check(name, x, *args, **kwargs)``."""
    return None if x is None else check(name, x, *args, **kwargs)


def optional_finite(name: str, x: Any) -> float | None:
    """None stays None; anything else goes through :func:`finite`."""
    return optional(finite, name, x)


def integer(name: str, x: Any, lo: int = 1, hi: int = MAX_COUNT) -> int:
    """``int(x)`` if x is an integer (``int`` or a numpy integer, not bool, not float) in ``[lo, hi]``.

    Raises
    ------
    ArgumentTypeError
        For floats (``100.0`` included: pass ``100``), bools, strings, None.
    ValueError
        Outside ``[lo, hi]`` (``hi`` defaults to :data:`MAX_COUNT`).
    """
    rng = interval(lo, hi)
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (numbers.Integral, np.integer)):
        hint = f"; write {int(x)} for a whole number" if isinstance(x, float) and x.is_integer() else ""
        raise ArgumentTypeError(f"{name} must be an integer in {rng}, got {_got(x)}{hint}")
    y = int(x)
    if not lo <= y <= hi:
        raise ValueError(f"{name} must be an integer in {rng}, got {_got(x)}")
    return y


def _same_kind(x: Any, c: Any) -> bool:
    """x could equal the choice c: strings with strings, integers (not bools) with integers, bools with bools."""
    if isinstance(c, (bool, np.bool_)) or isinstance(x, (bool, np.bool_)):
        return isinstance(x, (bool, np.bool_)) and isinstance(c, (bool, np.bool_))
    if isinstance(c, str):
        return isinstance(x, str)
    if isinstance(c, numbers.Integral):
        return isinstance(x, (numbers.Integral, np.integer))
    return isinstance(x, type(c))


def choice(name: str, x: Any, choices: Sequence[T]) -> T:
    """The element of ``choices`` equal to x (same type), else an error listing the choices.

    ArgumentTypeError if x is of none of the choices' types (``None`` for a string choice), ValueError
    otherwise; both read ``"<name> must be one of (...), got x"``.
    """
    for c in choices:
        if _same_kind(x, c) and x == c:
            return c
    msg = f"{name} must be one of {tuple(choices)!r}, got {_got(x)}"
    if not any(_same_kind(x, c) for c in choices):
        raise ArgumentTypeError(msg)
    raise ValueError(msg)


def flag(name: str, x: Any) -> bool:
    """x if it is a bool (or ``numpy.bool_``), else ArgumentTypeError: 0, 1, "yes" are not flags."""
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    raise ArgumentTypeError(f"{name} must be True or False, got {_got(x)}")


def function(name: str, x: Any) -> Callable:
    """x if it is callable, else ArgumentTypeError."""
    if not callable(x):
        raise ArgumentTypeError(f"{name} must be callable, got {_got(x)}")
    return x


def reals(name: str, x: Any, lo: float = -math.inf, hi: float = math.inf, *, lo_open: bool = False,
          hi_open: bool = False, nonempty: bool = True) -> np.ndarray:
    """x as a float array (any shape, scalars as 0-d) with every element finite and in the range.

    ArgumentTypeError for None, strings, bools or boolean/object/complex arrays; ValueError for an empty
    array (with ``nonempty``), a non-finite element or one out of range (the first offender is shown).
    """
    rng = interval(lo, hi, lo_open=lo_open, hi_open=hi_open)
    kind = "an array of real numbers"
    if x is None or isinstance(x, (str, bytes, bool, np.bool_)):
        raise ArgumentTypeError(f"{name} must be {kind} in {rng}, got {_got(x)}")
    try:
        a = np.asarray(x)
    except (TypeError, ValueError):  # ragged nesting
        raise ArgumentTypeError(f"{name} must be {kind} in {rng}, got {_got(x)}") from None
    if a.dtype.kind not in "iuf":
        raise ArgumentTypeError(f"{name} must be {kind} in {rng}, got {_got(x)} (dtype {a.dtype})")
    a = a.astype(float)
    if nonempty and a.size == 0:
        raise ValueError(f"{name} must be a non-empty array of finite values in {rng}, got an empty array")
    ok = np.isfinite(a) & ((a > lo) if lo_open else (a >= lo)) & ((a < hi) if hi_open else (a <= hi))
    if not np.all(ok):
        bad = a.ravel()[np.flatnonzero(~ok.ravel())[0]]
        raise ValueError(f"{name} must be finite and in {rng} (every element), got {_got(float(bad))}")
    return a


def times(name: str, x: Any, *, lo: float = 0.0, hi: float = math.inf, increasing: bool = True,
          ndim: int | None = 1) -> np.ndarray:
    """x as a non-empty float array of finite times in ``[lo, hi]``, strictly increasing if ``increasing``.

    ``ndim=1`` requires a 1-D array (``None``: any shape, used where times are broadcast elementwise).
    Errors as :func:`reals`; ``ValueError`` names the first non-increasing position.
    """
    a = reals(name, x, lo, hi)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"{name} must be a {ndim}-D array of times in {interval(lo, hi)}, got shape {a.shape}")
    if increasing and a.ndim == 1 and a.size > 1:
        bad = np.flatnonzero(np.diff(a) <= 0)
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"{name} must be strictly increasing, got {name}[{i}] = {float(a[i])!r} >= "
                             f"{name}[{i + 1}] = {float(a[i + 1])!r}")
    return a


def path(name: str, x: Any) -> str:
    """x as a ``str`` file-system path if it is a ``str`` or an ``os.PathLike`` giving one, else ArgumentTypeError.

    Bytes paths are refused (the package joins paths with ``str`` file names), and so (ValueError) is a
    NUL character, which no file name can hold; whether the path exists or can be written is for the caller
    to check.
    """
    if isinstance(x, (str, os.PathLike)):
        p = os.fspath(x)
        if isinstance(p, str):
            if "\0" in p:
                raise ValueError(f"{name} must be a path without NUL characters, got {_got(p)}")
            return p
    raise ArgumentTypeError(f"{name} must be a path (str or os.PathLike), got {_got(x)}")
