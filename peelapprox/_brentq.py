"""Brent's root finder, bitwise :func:`scipy.optimize.brentq`, without importing scipy.

The folds and branch inverses of the peel-force law (fvV's in ``law/_paper.py``, any law's in ``law/_folds.py`` and
``law/_compiled.py``) are found by Brent's method on the first call of every solver; importing :mod:`scipy.optimize`
for it cost a new process ~0.6 s of CPU (docs/performance.md, "After `peelapprox warmup`"). :func:`brentq` is a
line-by-line port of scipy's ``scipy/optimize/Zeros/brentq.c`` as of scipy 1.17.1 (Charles Harris's algorithm, with
the sign tests by ``signbit`` of scipy PR #17664, which no product can underflow; BSD licence) and of the checks of
its Python wrapper (``scipy/optimize/_zeros_py.py``: the argument checks, the NaN check of each function value, the
errors): the same double arithmetic in the same order, so every root it returns is bitwise scipy's (checked against
:func:`scipy.optimize.brentq` on seeded random functions and brackets and on the real fold calls,
``tests/test_brentq.py``). Python floats are IEEE doubles and each operation below rounds once, as the C code's do
(x86-64's SSE arithmetic, no fused multiply-add in scipy's build, which the tests would catch).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from typing import Any

__all__ = ["brentq", "XTOL", "RTOL", "MAXITER"]

#: scipy's defaults: ``xtol = 2e-12``, ``rtol = 4 ulp(1)`` (also the smallest rtol allowed), ``maxiter = 100``.
XTOL = 2e-12
RTOL = 4 * 2.220446049250313e-16
MAXITER = 100


def brentq(f: Callable[..., Any], a: float, b: float, args: tuple = (), xtol: float = XTOL, rtol: float = RTOL,
           maxiter: int = MAXITER) -> float:
    """A root of ``f(x, *args)`` in ``[a, b]`` by Brent's method: bitwise :func:`scipy.optimize.brentq`.

    Same arguments, semantics and errors as scipy's with ``full_output=False, disp=True``: converged when
    ``|b - a| / 2 < (xtol + rtol |x|) / 2`` for the bracket ``[a, b]`` and the best estimate x, or
    ``f(x) == 0`` exactly.

    Parameters
    ----------
    f : callable
        ``f(x, *args)``, a real number (anything :class:`float` accepts) for a float ``x``.
    a, b : float
        The bracket; ``f(a)`` and ``f(b)`` must not have the same sign.
    args : tuple
        Extra arguments of ``f`` (a non-tuple is taken as one argument, as scipy does).
    xtol : float
        Absolute tolerance, > 0 (2e-12).
    rtol : float
        Relative tolerance, ≥ 4 ulp(1) = 8.88e-16 (the default).
    maxiter : int
        Iterations at most (100).

    Returns
    -------
    float
        The root estimate (a Python float).

    Raises
    ------
    ValueError
        ``xtol <= 0``, ``rtol < 4 ulp``, ``f(a)`` and ``f(b)`` of the same sign, or a NaN value of ``f``
        (scipy's messages).
    RuntimeError
        Not converged within ``maxiter`` iterations (scipy's message).
    """
    if not isinstance(args, tuple):
        args = (args,)
    maxiter = operator.index(maxiter)
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < RTOL:
        raise ValueError(f"rtol too small ({rtol:g} < {RTOL:g})")
    if maxiter < 0:
        raise ValueError("maxiter must be >= 0")
    return _brentq(f, float(a), float(b), float(xtol), float(rtol), maxiter, args)


def _value(f: Callable[..., Any], x: float, args: tuple) -> float:
    """``f(x, *args)`` as a float; a NaN is scipy's ValueError."""
    fx = f(x, *args)
    if fx != fx:
        raise ValueError(f"The function value at x={x} is NaN; solver cannot continue.")
    return float(fx)


def _div(a: float, b: float) -> float:
    """``a / b`` as C divides doubles: by a zero, ±inf (the signs of a and b) or NaN (``0/0``, NaN/0), where
    Python raises ZeroDivisionError.  (A product or sum that overflows is inf in Python too.)"""
    try:
        return a / b
    except ZeroDivisionError:
        if a == 0 or a != a:
            return math.nan
        return math.copysign(math.inf, a) * math.copysign(1.0, b)


def _brentq(f: Callable[..., Any], xa: float, xb: float, xtol: float, rtol: float, maxiter: int,
            args: tuple) -> float:
    """scipy's ``brentq.c``, statement for statement (its comments: the state at the top of the loop)."""
    fabs, copysign = math.fabs, math.copysign
    xpre, xcur = xa, xb
    xblk = fblk = spre = scur = 0.0
    fpre = _value(f, xpre, args)
    fcur = _value(f, xcur, args)
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    if copysign(1.0, fpre) == copysign(1.0, fcur):  # C's signbit(fpre) == signbit(fcur): no product to underflow
        raise ValueError("f(a) and f(b) must have different signs")
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and copysign(1.0, fpre) != copysign(1.0, fcur):
            xblk = xpre
            fblk = fpre
            spre = scur = xcur - xpre
        if fabs(fblk) < fabs(fcur):
            xpre = xcur
            xcur = xblk
            xblk = xpre
            fpre = fcur
            fcur = fblk
            fblk = fpre
        delta = (xtol + rtol * fabs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or fabs(sbis) < delta:
            return xcur
        if fabs(spre) > delta and fabs(fcur) < fabs(fpre):
            if xpre == xblk:  # interpolate
                stry = _div(-fcur * (xcur - xpre), fcur - fpre)
            else:  # extrapolate
                dpre = _div(fpre - fcur, xpre - xcur)
                dblk = _div(fblk - fcur, xblk - xcur)
                stry = _div(-fcur * (fblk * dblk - fpre * dpre), dblk * dpre * (fblk - fpre))
            lim = 3 * fabs(sbis) - delta
            if 2 * fabs(stry) < (fabs(spre) if fabs(spre) < lim else lim):  # good short step
                spre = scur
                scur = stry
            else:  # bisect
                spre = sbis
                scur = sbis
        else:  # bisect
            spre = sbis
            scur = sbis
        xpre = xcur
        fpre = fcur
        if fabs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
        fcur = _value(f, xcur, args)
    raise RuntimeError(f"Failed to converge after {maxiter} iterations.")
