"""Smoothed peel-force laws: a C⁴ quintic spline in ln v smoothing noisy points (kind ``"smoothed"``).

:func:`smooth` makes the law's data from measured points ``(v_i, f_i)``: scipy's
:func:`~scipy.interpolate.make_smoothing_spline` of f in ``u = ln v`` (a natural cubic smoothing spline, knots at
the data, its penalty ``lam`` chosen from generalised cross-validation's, shape-constrained, unless given:
:func:`smooth`), then checks the N shape of the result: the roots of its derivative inside the data range must be
exactly one maximum followed by one minimum (a ``ValueError`` says what it found otherwise). The law is that
spline's **quintic projection**: the least-squares quintic B-spline on the same knots
(:func:`scipy.interpolate.make_lsq_spline` on 16 samples per knot interval), C⁴, so that f‴ does not jump at the
knots and the solver's 8th-order steps are not rejected there (a cubic's f‴ jumps at every knot: 3x the rejected
steps at V = 1, I = 1e-2 with fvV smoothed from 600 points, the same count as fvV's with the quintic). It follows
the cubic to 4e-4 of f's range (measured on 40 noisy points of the cubic family and on fvV at 600 points; f'' to 4 %
inside, 11-40 % in the end intervals, where the natural cubic's f'' = 0 is an end condition, not data). The N shape
is checked on the law itself (the projection): where it is lost (a flat maximum's projection can grow a wiggle 1e-3
of its height, 2 of 30 noise draws of the cubic family with 1 % noise), ``lam="gcv"``'s search goes on to the next
penalty; with a given ``lam``, or where no penalty projects N-shaped, the cubic itself is kept (C², the table
kernel). The folds are roots of the spline's derivative, between data points (not at a datum, as a table's PCHIP
puts them).

The data of a smoothed law (``PeelForce.tables`` of a ``"smoothed"`` law, plain tuples of floats, so the law is
immutable, hashable and JSON-able as the others) are one triple ``(V, knots, coefficients)``: the pull speed the
points were measured at (None: used at every V), the B-spline knots as peel velocities [m/s] (the spline is in
``u = ln v``, its knots at ``ln knots``; degree k = 5 (or 3: a law stored by 0.3.0's first releases, or whose
projection lost the N shape), the end knots repeated k + 1 times, the interior ones simple and increasing: the
spline is C^(k-1) everywhere; as velocities, like a table's v, so that code reading a law's ``tables`` sees
velocities whatever its kind) and its B-spline coefficients (``len(knots) - k - 1`` of them: the degree is read
from the two lengths).  :func:`check_spline` validates them (for a law read back by ``PeelForce.from_dict``).

Evaluation: by numpy, :class:`SplineLaw` (scipy's ``BSpline`` and its derivatives in u; ``f' = p'/v``,
``f'' = (p'' - p')/v²``); compiled, the spline converted to its piecewise-polynomial form (``PPoly.from_spline``:
the same polynomial on each knot interval, to rounding) and packed (:func:`spline_coefficients`) for
:func:`peelapprox.law._table_jit.quintic_law` (a cubic: as a one-table block of the table kernel
``table_law``).  Outside the data range a spline law is refused (never extrapolated), as a table is.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._checks import in_range, shown

__all__ = ["LAW_DEGREE", "MAX_POINTS", "MIN_POINTS", "RESIDUAL_FACTOR", "SplineLaw", "check_spline", "degree", "smooth",
           "smoothing_length", "spline_coefficients", "spline_shape"]

#: Fewest points to smooth: one maximum and one minimum, each with a neighbour on either side.
MIN_POINTS = 5
_DEGREE = 3
#: The degree of a smoothed law: the smoothing spline's quintic projection (module docstring).
LAW_DEGREE = 5
#: Samples per knot interval of the quintic projection's least squares.
_PROJECTION_SAMPLES = 16
#: The grid of penalties ``lam="gcv"`` searches upward when GCV's spline is not N-shaped (:func:`smooth`).
_LAM_RATIO, _LAM_STEPS = 1.25, 250
#: The searched spline must follow the data as noise does: its median absolute (weighted) residual at most this many
#: times the noise's standard deviation estimated from the data's second differences (``noise_level`` of
#: ``peelapprox/_slips.py``, the slip detector's), else it is refused.  For normal noise the median absolute residual
#: is 0.67 sigma; measured on 40 points of the cubic at 0.3-3 % noise, 100 seeds each: at most 1.03 times the
#: estimate (``tests/test_law_smooth_default.py``; with the median of the absolute second differences, the estimate
#: this module used before it shared the detector's: the detector's is 0.70-1.43 times that one on those 300 draws,
#: and none of the 300 laws changed).
RESIDUAL_FACTOR = 3.0
#: More points than this are averaged in bins of ln v before smoothing (:func:`smooth`): the work is bounded.
MAX_POINTS = 1000


def degree(tables: Any) -> int:
    """The degree of the spline law with these tables: ``len(knots) - len(coefficients) - 1``."""
    _, t, c = tables[0]
    return len(t) - len(c) - 1


def _bspline(t: Any, c: Any) -> Any:
    """The B-spline in ``u = ln v`` of the knots ``t`` given as velocities [m/s] and the coefficients ``c`` (its
    degree from their lengths)."""
    from scipy.interpolate import BSpline

    return BSpline(np.log(np.asarray(t, dtype=float)), np.asarray(c, dtype=float), len(t) - len(c) - 1,
                   extrapolate=False)


def _quintic(u: np.ndarray, t: tuple, c: tuple) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    """The quintic projection (module docstring) of the cubic ``(t, c)`` smoothing the data at ``u``, as
    ``(knots, coefficients)``; None if it is not N-shaped (the cubic is kept)."""
    from scipy.interpolate import make_lsq_spline

    cubic = _bspline(t, c)
    k = LAW_DEGREE
    knots = np.concatenate([np.full(k + 1, u[0]), u[1:-1], np.full(k + 1, u[-1])])
    m = _PROJECTION_SAMPLES
    ud = np.append((u[:-1, None] + np.arange(m) / m * np.diff(u)[:, None]).ravel(), u[-1])
    with np.errstate(all="ignore"):
        q = make_lsq_spline(ud, cubic(ud), knots, k=k)
    t5 = tuple(math.exp(float(x)) for x in knots)
    c5 = tuple(float(x) for x in q.c)
    if not all(math.isfinite(x) for x in c5) or [k for k, _ in spline_shape(t5, c5)] != ["max", "min"]:
        return None
    return t5, c5


def spline_shape(t: Any, c: Any) -> list[tuple[str, float]]:
    """The interior extrema of the spline ``(t, c)`` (knots as velocities), in order: ``[("max" | "min", u), ...]``,
    u = ln v (roots of its derivative where the derivative changes sign, from its piecewise-polynomial form)."""
    from scipy.interpolate import PPoly

    pp = PPoly.from_spline(_bspline(t, c))
    d1 = pp.derivative()
    u_lo, u_hi = math.log(t[0]), math.log(t[-1])
    out: list[tuple[str, float]] = []
    for u in np.sort(d1.roots(extrapolate=False)):
        u = float(u)
        if not (u_lo < u < u_hi) or (out and u == out[-1][1]):
            continue
        h = 1e-7 * max(1.0, u_hi - u_lo)
        a, b = float(d1(max(u - h, u_lo))), float(d1(min(u + h, u_hi)))
        if a > 0 > b:
            out.append(("max", u))
        elif a < 0 < b:
            out.append(("min", u))
    return out


def _shape_error(t: Any, c: Any, label: str) -> str | None:
    """None if the spline has exactly one maximum then one minimum, else what it has (for a message)."""
    ext = spline_shape(t, c)
    if [k for k, _ in ext] == ["max", "min"]:
        return None
    spl = _bspline(t, c)
    found = ", ".join(f"a local {k} at v = {math.exp(u):.6g} m/s (f = {float(spl(u)):.6g} N)" for k, u in ext)
    return (f"{label} must have exactly one local maximum followed by one local minimum inside the data range (the "
            f"N shape of a stick-slip law); found {found or 'none (it is monotone: no folds, no stick-slip)'}")


def smooth(v: Any, f: Any, lam: Any = "gcv", V: Any = None) -> tuple:
    """The tables of a ``"smoothed"`` law smoothing the points ``(v, f)`` (module docstring).

    ``lam``: ``"gcv"`` or a penalty >= 0 (0: the interpolating natural spline; larger: smoother).  The penalty is
    scipy's: the spline minimises ``sum w_i (f_i - s(u_i))^2 + lam * integral s''(u)^2 du`` in ``u = ln v``, so it
    smooths over a length ``ell = (lam * L / n)^(1/4)`` in ln v (:func:`smoothing_length`; L the data's range in
    ln v, n the points): features of f narrower than ell in ln v are flattened, and the folds are biased once ell
    approaches half their distance in ln v.

    ``"gcv"`` (the default) is a shape-constrained choice: the penalty of generalised cross-validation (scipy's
    ``lam=None``) if its law is N-shaped, else the smallest penalty on a grid of ratio 1.25 upward from
    ``1e-4 h^3`` (h the mean spacing of the data in ln v) whose law has exactly one maximum then one minimum --
    the least smoothing that removes the noise's wiggles (GCV follows the noise near the flat folds: on 40 points
    of the cubic with 1 % noise its spline has 6 to 10 extrema) -- provided it still follows the data as noise
    would: the median absolute weighted residual at most :data:`RESIDUAL_FACTOR` times the noise estimated from
    the data's second differences (1.4826 MAD / √6, the slip detector's ``noise_level`` in ``peelapprox/_slips.py``;
    a median, so that the bias of a steep end, where any penalty cuts the curvature, does not refuse a law that
    follows the folds).  A spline N-shaped only at a penalty that misses the data (two dips merged into one) is
    refused.

    More than :data:`MAX_POINTS` points are first averaged in runs of ``ceil(n / MAX_POINTS)`` consecutive points
    (each run's mean ln v and mean f, weighted by its length; the two end points kept as they are, so the law's
    range is the data's), which bounds the work: GCV's cost grows faster than the points (20,000 points of the
    cubic smooth in about 2 s, where they took 60 s unbinned).

    ValueError naming the argument (and index) for bad points (f must be > 0, a peel force, as a table's), a bad
    ``lam``, or a smoothed curve that is not N-shaped (what it has, named: with ``"gcv"``, GCV's spline, when no
    penalty on the grid gives the N shape).
    """
    from .._ranges import PARAM_RANGES
    from .._slips import noise_level
    from ._fit import check_points

    va, fa = check_points(v, f, need=MIN_POINTS, what="a smoothed law needs (one maximum then one minimum, "
                                                       "each between two others)")
    if isinstance(lam, str):
        if lam != "gcv":
            raise ValueError(f"lam must be 'gcv' (chosen by generalised cross-validation) or a number >= 0, got "
                             f"{shown(lam)}")
        penalty = None
    else:
        penalty = in_range("lam", lam, 0.0)
    V0 = None if V is None else in_range("V", V, *PARAM_RANGES["V"])
    u = np.log(va)
    if np.any(np.diff(u) <= 0):
        i = int(np.flatnonzero(np.diff(u) <= 0)[0])
        raise ValueError(f"v must be strictly increasing in ln v: v[{i}] = {va[i]!r} and v[{i + 1}] = {va[i + 1]!r} "
                         "have the same logarithm")
    noise = noise_level(fa)
    u, fa, w = _binned(u, fa)
    t, c = _smoothing_spline(u, fa, w, penalty)
    msg = _shape_error(t, c, "the smoothed f (PeelForce.smoothed)")
    q = None if msg else _quintic(u, t, c)
    if q is None and penalty is None:
        found = _search(u, fa, w, noise)
        if found is not None:
            return ((V0, *found),)
    if q is not None:
        return ((V0, *q),)
    if msg:
        used = repr(penalty) if penalty is not None else (
            f"GCV's; no larger penalty gave the N shape while following the data (median absolute residual at "
            f"most {RESIDUAL_FACTOR:g}x the noise estimated from second differences)")
        raise ValueError(f"{msg}; lam: {used} (a larger lam smooths more: over ell = (lam L/n)^(1/4) in ln v, here "
                         f"L = {u[-1] - u[0]:.3g}, n = {u.size})")
    return ((V0, t, c),)  # N-shaped as a cubic, at no penalty as a quintic: the cubic (module docstring)


def smoothing_length(lam: float, v: Any) -> float:
    """The length in ln v over which the penalty ``lam`` smooths points at the velocities ``v`` (:func:`smooth`):
    ``(lam * L / n)^(1/4)``, L the range of ln v and n the points (the equivalent kernel's bandwidth of a
    smoothing spline with n/L points per unit of u)."""
    u = np.log(np.asarray(v, dtype=float))
    return float((lam * (u[-1] - u[0]) / u.size) ** 0.25)


def _smoothing_spline(u: np.ndarray, f: np.ndarray, w: np.ndarray | None,
                      lam: float | None) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The cubic smoothing spline of ``(u, f)`` (weights w) at the penalty lam (None: GCV's), as velocity knots
    and coefficients; ValueError if it cannot be made or is not finite."""
    from scipy.interpolate import make_smoothing_spline

    with np.errstate(all="ignore"):
        try:
            spl = make_smoothing_spline(u, f, w=w, lam=lam)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise ValueError(f"v, f: the smoothing spline cannot be made of these points ({exc})") from None
    t, c = tuple(math.exp(float(x)) for x in spl.t), tuple(float(x) for x in spl.c)
    if not all(math.isfinite(x) for x in c):
        raise ValueError("v, f: the smoothing spline of these points is not finite (f too large, or v too close "
                         "together in ln v)")
    return t, c


def _search(u: np.ndarray, f: np.ndarray, w: np.ndarray | None,
            noise: float) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    """The smallest penalty on the grid whose law (the quintic projection) is N-shaped and follows the data
    (:func:`smooth`), as ``(knots, coefficients)``; None if there is none."""
    lam = 1e-4 * ((u[-1] - u[0]) / (u.size - 1)) ** 3  # the penalty is of order h^3 where smoothing starts
    sw = np.ones_like(f) if w is None else np.sqrt(w)
    for _ in range(_LAM_STEPS):
        tt, cc = _smoothing_spline(u, f, w, lam)
        kinds = [k for k, _ in spline_shape(tt, cc)]
        qq = _quintic(u, tt, cc) if kinds == ["max", "min"] else None
        if qq is not None:
            resid = float(np.median(np.abs(_bspline(*qq)(u) - f) * sw))
            # the N shape only at a penalty that misses the data: not a smoothing of noise
            return qq if resid <= RESIDUAL_FACTOR * noise else None
        if not kinds:  # monotone: smoothing more cannot bring the folds back
            return None
        lam *= _LAM_RATIO
    return None


def _binned(u: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``(u, f, weights)``: the points as they are (weights None) up to :data:`MAX_POINTS`, else averaged in runs of
    ``k = ceil(n / MAX_POINTS)`` consecutive points (mean u, mean f, weight the run's length; the last run may be
    shorter), the two end points kept as they are so that the law's range is the data's."""
    n = u.size
    if n <= MAX_POINTS:
        return u, f, None
    k = -(-(n - 2) // (MAX_POINTS - 2))
    starts = np.arange(1, n - 1, k)
    counts = np.diff(np.append(starts, n - 1)).astype(float)
    ub = np.add.reduceat(u[1:-1], starts - 1) / counts
    fb = np.add.reduceat(f[1:-1], starts - 1) / counts
    return (np.concatenate([[u[0]], ub, [u[-1]]]), np.concatenate([[f[0]], fb, [f[-1]]]),
            np.concatenate([[1.0], counts, [1.0]]))


def check_spline(tables: Any, V_range: tuple[float, float]) -> tuple:
    """The canonical ``((V, knots, coefficients),)`` of a spline law (module docstring), or ValueError/TypeError."""
    try:
        items = list(tables)
    except TypeError:
        raise TypeError(f"tables of a spline law must be one (V, knots, coefficients) triple in a sequence, got "
                        f"{type(tables).__name__}") from None
    if len(items) != 1 or not isinstance(items[0], (tuple, list)) or len(items[0]) != 3:
        raise ValueError("tables of a spline law must hold exactly one (V, knots, coefficients) triple")
    V, t, c = items[0]
    V = None if V is None else in_range("V", V, *V_range)
    ta = _floats("knots", t)
    ca = _floats("coefficients", c)
    k = ta.size - ca.size - 1
    if k not in (_DEGREE, LAW_DEGREE) or ta.size < 2 * (k + 1) + 1:
        raise ValueError(f"a spline law is quintic (len(knots) - {LAW_DEGREE + 1} coefficients, at least "
                         f"{2 * LAW_DEGREE + 3} knots) or cubic (len(knots) - {_DEGREE + 1}, at least "
                         f"{2 * _DEGREE + 3}), got {ta.size} knots and {ca.size} coefficients")
    ends = (ta[:k + 1], ta[-k - 1:])
    if np.any(ends[0] != ta[0]) or np.any(ends[1] != ta[-1]):
        raise ValueError(f"the knots of a spline law of degree {k} must repeat each end {k + 1} times (clamped)")
    if ta[0] <= 0:
        raise ValueError(f"the knots of a spline law are peel velocities, > 0 [m/s]: knots[0] = {float(ta[0])!r}")
    inner = np.log(ta[k:-k])
    bad = np.flatnonzero(np.diff(inner) <= 0)
    if bad.size:
        i = int(bad[0]) + k
        raise ValueError(f"the knots of a spline law must be strictly increasing inside (simple knots: f'' "
                         f"continuous): knots[{i}] = {float(ta[i])!r} >= knots[{i + 1}] = {float(ta[i + 1])!r}")
    tt, cc = tuple(float(x) for x in ta), tuple(float(x) for x in ca)
    msg = _shape_error(tt, cc, "a spline law")
    if msg:
        raise ValueError(msg)
    return ((V, tt, cc),)


def _floats(name: str, x: Any) -> np.ndarray:
    from .._checks import reals

    a = reals(f"{name} of a spline law", x)
    if a.ndim != 1:
        raise ValueError(f"{name} of a spline law must be 1-D, got shape {a.shape}")
    return a


class SplineLaw:
    """The numpy evaluator of a spline law: scipy's ``BSpline`` in ``u = ln v``, refused outside its range."""

    def __init__(self, tables: tuple):
        V, t, c = tables[0]
        self.V = V
        spl = _bspline(t, c)
        self.derivs = (spl, spl.derivative(1), spl.derivative(2))
        self.lo, self.hi = float(t[0]), float(t[-1])
        self.u_lo, self.u_hi = math.log(t[0]), math.log(t[-1])

    def v_range(self) -> tuple[float, float]:
        return self.lo, self.hi

    def check_V(self, V: float) -> None:
        if self.V is not None and V != self.V:
            raise ValueError(f"V={V!r} m/s: this smoothed law was measured at V={self.V!r} m/s only (smooth with "
                             "V=None to use it at every pull speed)")

    def __call__(self, v: np.ndarray, V: float, order: int) -> np.ndarray:
        self.check_V(V)
        if v.size and (v.min() < self.lo or v.max() > self.hi):
            bad = v.ravel()[np.flatnonzero(((v < self.lo) | (v > self.hi)).ravel())[0]]
            raise ValueError(f"v={float(bad)!r} m/s is outside the smoothed law's range [{self.lo!r}, {self.hi!r}] "
                             "m/s (its data): a smoothed law is not extrapolated")
        u = np.clip(np.log(v), self.u_lo, self.u_hi)  # exp then log may leave the range by an ulp
        if order == 0:
            return np.asarray(self.derivs[0](u), dtype=float)
        d1 = np.asarray(self.derivs[1](u), dtype=float)
        if order == 1:
            return d1 / v
        return (np.asarray(self.derivs[2](u), dtype=float) - d1) / (v * v)


def spline_coefficients(tables: tuple, V: float) -> np.ndarray:
    """``coef`` of the compiled kernel for a spline law at V: its piecewise-polynomial form packed for
    :func:`peelapprox.law._table_jit.quintic_law` (a cubic: as one table of ``table_law``,
    :func:`peelapprox.law._table_jit.pack_blocks`)."""
    from scipy.interpolate import PPoly

    from ._table_jit import pack_blocks, pack_quintic

    V0, t, c = tables[0]
    SplineLaw(tables).check_V(V)
    pp = PPoly.from_spline(_bspline(t, c))
    x = np.asarray(pp.x, dtype=float)
    idx = np.flatnonzero(np.diff(x) > 0)  # the intervals of the repeated end knots are empty
    xs = np.append(x[idx], x[idx[-1] + 1])
    cs = np.asarray(pp.c, dtype=float)[:, idx]
    if degree(tables) == LAW_DEGREE:
        return pack_quintic(xs, cs)
    return pack_blocks([(1.0, xs, cs)], float(xs[0]), float(xs[-1]))
