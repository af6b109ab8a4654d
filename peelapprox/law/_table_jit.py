"""The compiled tabulated peel-force law: a measured curve f(v) as data for the compiled solvers.

:func:`table_law` is a law of the ABI of :mod:`peelapprox.law._abi` (signature ``LAW_SIG``, compiled once,
cached on disk): its coefficients ``coef`` are the packed tables of a ``PeelForce.tabulated`` law at the run's
pull speed V, built by :func:`table_coefficients`.  A new table, of any length, is new data and recompiles
nothing.  It plays the part of Eq. (fvV) for a measured curve.

It evaluates exactly the piecewise cubic that :class:`~peelapprox.law._table.TableLaw` evaluates with scipy (the
PCHIP of f in ``u = ln v``, in scipy's order of operations: :func:`_pchip_sums`), so with one table the numbers
are scipy's bitwise (tests/test_law_table_jit.py).  It is **not extrapolated**: ``PeelForce`` refuses a v
outside the tables' common range and the drivers stop a run that leaves it, but a Runge-Kutta stage evaluated
there still gets finite numbers (:func:`table_law`).  The interval of a u is found by bisection between the
bounds of a guide (:func:`_interval`), so a call's cost hardly grows with the length of an even table
(measured in comparisons/benchmark/table_cost.py).

:func:`quintic_law` is its sibling for a smoothed law (``PeelForce.smoothed``): one piecewise quintic in u, C⁴,
packed by :func:`pack_quintic` as one block of the same layout with six coefficients per interval, the interval
found by the same guide.  A smoothed law's f‴ is continuous, so the solver's 8th-order steps are not rejected
at its knots as they are at a cubic's (docs/your-own-tape.md, "Cost").
"""

from __future__ import annotations

import numpy as np

from .._compiled._jit import kernel
from ._abi import LAW_FP, LAW_LNV, LAW_SIG
from ._table import TableLaw, check_tables

__all__ = ["T_COUNT", "T_ULO", "T_UHI", "T_HEAD", "pack_blocks", "pack_quintic", "quintic_law", "table_law",
           "table_coefficients"]

#: Indices of the header of ``coef``: the number of tables used, ln lo, ln hi; the first block starts at T_HEAD.
#: ``coef = [m, ln lo, ln hi, block_1, ..., block_m]``: ``m`` in {1, 2} tables of nonzero weight at V, ``[lo,
#: hi]`` the common v range of **all** the law's tables (``TableLaw.v_range()``, whatever V), then per table
#: ``[w, n, r, x_0 .. x_{n-1}, g_0 .. g_{n-1}, c[0,0], c[1,0], c[2,0], c[3,0], ..., c[3,n-2]]``: its weight, its
#: number of knots (a float holding an integer), ``r = (n - 1) / (x_{n-1} - x_0)`` (guide cells per unit of u),
#: its knots in u (``PchipInterpolator.x``), the guide of :func:`_interval`, and the four coefficients of each of
#: its ``n - 1`` intervals (``.c[:, i]``, highest power first): ``6 n - 1`` numbers.  The kernel reads only what
#: :func:`table_coefficients` wrote; a vector from elsewhere is not checked (numba does not check bounds).
T_COUNT, T_ULO, T_UHI, T_HEAD = 0, 1, 2, 3


@kernel(inline="always")
def _interval(coef, xo, go, n, ginv, u):
    """``i`` with ``x[i] <= u < x[i+1]`` (``n - 2`` at ``u = x[n-1]``) of the knots ``x = coef[xo:xo+n]``, for
    ``x[0] <= u <= x[n-1]``: scipy's ``find_interval``, by bisection between the guide's bounds.

    The guide ``coef[go:go+n]`` holds, for each of the ``n - 1`` equal cells of ``[x[0], x[n-1]]`` (``ginv`` is
    cells per unit of u), the interval holding the cell's left edge (and ``n - 2`` for the right end): the
    interval of u lies between the guide entries of its cell and of the next, one or two intervals apart
    for evenly spread knots (a bisection over the whole table costs ``log2 n`` steps, mispredicted when
    successive calls are far apart).  Should rounding put u in a neighbouring cell, the bounds are widened to the
    table's end on that side (the answer stays exact, only slower)."""
    j = int((u - coef[xo]) * ginv)
    if j > n - 2:
        j = n - 2
    elif j < 0:
        j = 0
    lo = int(coef[go + j])
    hi = int(coef[go + j + 1])
    if u < coef[xo + lo]:
        lo = 0
    if hi < n - 2 and u >= coef[xo + hi + 1]:
        hi = n - 2
    while lo < hi:  # x[lo] <= u, and u < x[hi + 1] unless hi = n - 2
        mid = (lo + hi + 1) >> 1
        if u < coef[xo + mid]:
            hi = mid - 1
        else:
            lo = mid
    return lo


@kernel(inline="always")
def _pchip_sums(coef, u):
    """``(Σ w p, Σ w p', Σ w p'')`` of the packed tables at ``u`` in ``[ln lo, ln hi]``.

    Each table's PCHIP of f in u (scipy's :class:`~scipy.interpolate.PchipInterpolator`) on its interval
    ``x[i] <= u < x[i+1]`` (the last closed at the right, as scipy's ``find_interval``), at ``s = u - x[i]``, in
    the order of operations of scipy's ``PPoly`` (``_ppoly.evaluate_poly1``: ascending powers, not Horner)::

        p   = ((c3 + c2 s) + c1 (s s)) + c0 ((s s) s)
        p'  = (c2 + (c1 s) 2) + (c0 (s s)) 3
        p'' = c1 2 + (c0 s) 6

    with ``c0..c3 = c[0..3, i]``; two tables (the two around V) are summed with ``TableLaw._weights``' weights,
    as TableLaw sums them, so one table gives scipy's numbers bitwise and two differ by rounding."""
    F = 0.0
    D = 0.0
    D2 = 0.0
    o = T_HEAD
    for _ in range(int(coef[T_COUNT])):
        w = coef[o]
        n = int(coef[o + 1])
        xo = o + 3
        go = xo + n
        i = _interval(coef, xo, go, n, coef[o + 2], u)
        s = u - coef[xo + i]
        co = go + n + 4 * i
        c0 = coef[co]
        c1 = coef[co + 1]
        c2 = coef[co + 2]
        c3 = coef[co + 3]
        ss = s * s
        p = ((c3 + c2 * s) + c1 * ss) + c0 * (ss * s)
        p1 = (c2 + (c1 * s) * 2.0) + (c0 * ss) * 3.0
        p2 = c1 * 2.0 + (c0 * s) * 6.0
        F += w * p
        D += w * p1
        D2 += w * p2
        o = go + n + 4 * (n - 1)
    return F, D, D2


@kernel(inline="always")
def _quintic_sums(coef, u):
    """``(p, p', p'')`` of the packed piecewise quintic (:func:`pack_quintic`) at ``u`` in ``[ln lo, ln hi]``: on
    its interval ``x[i] <= u < x[i+1]``, at ``s = u - x[i]``, by Horner's rule with ``c0..c5 = c[0..5, i]``
    (highest power first)."""
    n = int(coef[T_HEAD + 1])
    xo = T_HEAD + 3
    go = xo + n
    i = _interval(coef, xo, go, n, coef[T_HEAD + 2], u)
    s = u - coef[xo + i]
    co = go + n + 6 * i
    c0 = coef[co]
    c1 = coef[co + 1]
    c2 = coef[co + 2]
    c3 = coef[co + 3]
    c4 = coef[co + 4]
    c5 = coef[co + 5]
    p = ((((c0 * s + c1) * s + c2) * s + c3) * s + c4) * s + c5
    p1 = ((((c0 * 5.0) * s + c1 * 4.0) * s + c2 * 3.0) * s + c3 * 2.0) * s + c4
    p2 = (((c0 * 20.0) * s + c1 * 12.0) * s + c2 * 6.0) * s + c3 * 2.0
    return p, p1, p2


@kernel(inline="always")
def _sums(coef, u, quintic):
    """``(p, p', p'')`` at u of the packed table(s) (:func:`_pchip_sums`) or piecewise quintic
    (:func:`_quintic_sums`)."""
    if quintic:
        return _quintic_sums(coef, u)
    return _pchip_sums(coef, u)


@kernel(inline="always")
def _law_at(x, coef, form, quintic):
    """The body of :func:`table_law` (``quintic`` False) and :func:`quintic_law` (True): the forms, the
    C¹-linear continuation outside ``[ln lo, ln hi]`` and ``v <= 0`` (their docstrings)."""
    if form == LAW_LNV:
        u = x
        v = np.exp(x)
    else:
        if not x > 0.0:  # v <= 0 or NaN: no law there (never a division by zero)
            return np.nan, np.nan, np.nan
        v = x
        u = np.log(x)
    ulo = coef[T_ULO]
    uhi = coef[T_UHI]
    if not (ulo <= u <= uhi):  # the C¹ continuation (docstring); NaN: NaN, never an index from it
        u0 = ulo if u < ulo else uhi
        F, D, _ = _sums(coef, u0, quintic)
        F = F + D * (u - u0)
        D2 = 0.0
    else:
        F, D, D2 = _sums(coef, u, quintic)
    if form == LAW_LNV:
        return v, F, D
    if form == LAW_FP:
        return F, D / v, np.nan
    return F, D / v, (D2 - D) / (v * v)


@kernel(signature=LAW_SIG, lazy=True)  # compiled by the first run of a tabulated law: the default path needs none
def table_law(x, coef, form):
    """The tabulated law at ``x`` in the form ``form`` (:mod:`peelapprox.law._abi`), ``coef`` from
    :func:`table_coefficients`: ``LAW_LNV: (v, f, p'(u))`` (p' is ``v f'(v)``), ``LAW_FP: (f, f', NaN)``,
    ``LAW_FPP: (f, f', f'')`` with ``f' = p'/v`` and ``f'' = (p'' - p')/v²`` (``u = ln v`` by numba's log, which
    may differ from numpy's by an ulp).

    Outside ``[ln lo, ln hi]`` the law is continued C¹-linearly in u from the nearer end ``u0``, ``f(u) = f(u0) +
    p'(u0) (u - u0)``, ``p'' = 0``: only so that a Runge-Kutta stage evaluated there before the driver stops the
    run gets finite numbers; no result may rest on them.  A NaN argument (or v <= 0) gives non-finite numbers,
    never a read outside ``coef``."""
    return _law_at(x, coef, form, False)


def _guide(x: np.ndarray) -> np.ndarray:
    """The guide of :func:`_interval` for the knots x: the interval holding each cell's left edge, as floats."""
    n = x.size
    edges = x[0] + np.arange(n - 1) * ((x[-1] - x[0]) / (n - 1))
    g = np.clip(np.searchsorted(x, edges, side="right") - 1, 0, n - 2)
    return np.append(g, n - 2).astype(float)


def table_coefficients(tables, V: float) -> np.ndarray:
    """``coef`` of :func:`table_law` for a tabulated law at the pull speed V (layout: :data:`T_HEAD`).

    Parameters
    ----------
    tables : sequence of (V or None, v, f)
        The law's tables, as ``PeelForce.tables`` (checked again by
        :func:`peelapprox.law._table.check_tables`: sorted, positive, finite, one maximum then one minimum).
    V : float
        The run's pull speed [m/s] (constant during a run): selects the table, or the two around V and their
        weights (linear in V), as :class:`~peelapprox.law._table.TableLaw` does.

    Returns
    -------
    numpy.ndarray
        float64, contiguous: the header and the blocks of the tables of nonzero weight.

    Raises
    ------
    ValueError
        V outside the tables' pull speeds, or a table measured at one V used at another (the messages of
        TableLaw); a bad table (the messages of ``check_tables``); V not finite.
    TypeError
        V not a real number, tables not a sequence of triples.
    """
    from .._checks import finite

    V = finite("V", V)
    tables = check_tables(tables, (0.0, np.inf))
    law = TableLaw(tables)
    u_lo = max(float(p.x[0]) for p in law.pchips)
    u_hi = min(float(p.x[-1]) for p in law.pchips)
    used = [(j, w) for j, w in law._weights(V) if w != 0.0]
    return pack_blocks([(w, law.pchips[j].x, law.pchips[j].c) for j, w in used], u_lo, u_hi)


def pack_blocks(blocks, u_lo: float, u_hi: float) -> np.ndarray:
    """``coef`` of :func:`table_law` from ``(w, x, c)`` blocks -- a weight, the breakpoints in u and the ``(4,
    n - 1)`` power coefficients of a piecewise cubic (scipy's ``PPoly.x``, ``PPoly.c``) -- and the common range
    ``[u_lo, u_hi]`` (layout: module docstring).  A tabulated law's blocks are its PCHIPs'; a smoothed law's, its
    spline's piecewise-polynomial form (:mod:`peelapprox.law._spline`)."""
    parts = []
    for w, x, c in blocks:
        x = np.asarray(x, dtype=float)
        c = np.asarray(c, dtype=float)
        if c.shape != (4, x.size - 1):  # pragma: no cover - PCHIPs and splines are cubic PPolys
            raise RuntimeError(f"unexpected piecewise-cubic coefficient shape {c.shape} for {x.size} knots")
        parts += [np.array([w, float(x.size), (x.size - 1) / (x[-1] - x[0])]), x, _guide(x), c.T.reshape(-1)]
    return np.ascontiguousarray(np.concatenate([np.array([float(len(blocks)), u_lo, u_hi]), *parts]), dtype=float)


@kernel(signature=LAW_SIG, lazy=True)  # compiled by the first run of a smoothed law
def quintic_law(x, coef, form):
    """The smoothed law at ``x`` in the form ``form``, ``coef`` from :func:`pack_quintic`: as :func:`table_law`
    (the same forms, the same C¹-linear continuation outside ``[ln lo, ln hi]``), of a piecewise quintic."""
    return _law_at(x, coef, form, True)


def pack_quintic(x, c) -> np.ndarray:
    """``coef`` of :func:`quintic_law` from the breakpoints ``x`` in u and the ``(6, n - 1)`` power coefficients
    of a piecewise quintic (scipy's ``PPoly.x``, ``PPoly.c``): the header of :data:`T_HEAD` with one block of
    weight 1 whose intervals carry six coefficients each."""
    x = np.asarray(x, dtype=float)
    c = np.asarray(c, dtype=float)
    if c.shape != (6, x.size - 1):  # pragma: no cover - the smoothed law's PPoly is quintic
        raise RuntimeError(f"unexpected piecewise-quintic coefficient shape {c.shape} for {x.size} knots")
    head = [1.0, float(x[0]), float(x[-1]), 1.0, float(x.size), (x.size - 1) / (x[-1] - x[0])]
    return np.ascontiguousarray(np.concatenate([np.array(head), x, _guide(x), c.T.reshape(-1)]), dtype=float)
