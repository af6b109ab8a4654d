"""The compiled tabulated law (peelapprox.law._table_jit) against scipy's PCHIP (TableLaw).

The oracle is scipy: :class:`~peelapprox._law_table.TableLaw` (``PchipInterpolator`` in ln v, linear in V)
and the interpolants themselves, evaluated by scipy's own code.  The tables are samples of the paper's law
(Eq. fvV) at two pull speeds, of different lengths, so their PCHIPs have the N shape of a measured curve.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from numba import njit, types
from numba.core import event

from peelapprox import PeelForce, peel_force
from peelapprox.law._abi import LAW_FP, LAW_FPP, LAW_LNV, LAW_TYPE, paper_coefficients, paper_law
from peelapprox.law._table import TableLaw
from peelapprox.law._table_jit import (
    T_COUNT,
    T_HEAD,
    T_UHI,
    T_ULO,
    _guide,
    _interval,
    table_coefficients,
    table_law,
)

EPS = np.finfo(float).eps


def _table(V: float, n: int, lo: float, hi: float, seed: int | None = None):
    """n samples of fvV at V for v from lo to hi: evenly spaced in ln v, or (seed) at random ln v between."""
    if seed is None:
        v = np.logspace(math.log10(lo), math.log10(hi), n)
    else:
        u = np.random.default_rng(seed).uniform(math.log(lo), math.log(hi), n - 2)
        v = np.exp(np.concatenate([[math.log(lo)], np.sort(u), [math.log(hi)]]))
    return (V, v, peel_force(v, V))


#: Three tables of the paper's law at V = 1, 2, 3 m/s (40, 57 and 23 points, different v ranges; the last at
#: uneven knots).
TABLES = PeelForce.tabulated(tables=[_table(1.0, 40, 1e-3, 30.0), _table(2.0, 57, 2e-3, 40.0),
                                     _table(3.0, 23, 5e-4, 25.0, seed=11)]).tables
ONE = PeelForce.tabulated(*_table(1.0, 40, 1e-3, 30.0)[1:], V=None).tables


def _forms(coef, v):
    """(f, f', f'') of table_law at each v: f from the LNV form at u = ln v (numpy's log), f' and f'' from FPP."""
    out = np.empty((v.size, 3))
    for k, x in enumerate(v):
        out[k] = table_law(x, coef, LAW_FPP)
        vv, f, fu = table_law(float(np.log(x)), coef, LAW_LNV)
        fp, nan = table_law(x, coef, LAW_FP)[1:]
        assert f == out[k, 0] or abs(f - out[k, 0]) <= 4 * EPS * (abs(f) + abs(fu * np.log(x)))
        assert fp == out[k, 1] and math.isnan(nan)  # FP and FPP: the same u, the same operations
    return out


def _bound(law: TableLaw, V: float, v: np.ndarray) -> np.ndarray:
    """The rounding bound of f, f', f'' at v, one column each: ``8 eps (Σ w |g| + |ln v| Σ w |dg/du|)``.

    Where the kernel and TableLaw may differ: ``u = ln v`` (numba's log and numpy's, each within an ulp: a
    shift of u by ≤ 2 eps |u|, which moves g by |dg/du| times that), and the order of the two-table sum and the
    division by v (a few roundings of the terms w g).  8 eps covers these few roundings."""
    u = np.log(v)
    out = np.zeros((v.size, 3))
    for j, w in law._weights(V):
        p = law.pchips[j]
        d = [p(u, k) for k in range(4)]
        g = [np.abs(d[0]), np.abs(d[1] / v), np.abs((d[2] - d[1]) / v**2)]
        dg = [np.abs(d[1]), np.abs((d[2] - d[1]) / v), np.abs((d[3] - 3 * d[2] + 2 * d[1]) / v**2)]
        for k in range(3):
            out[:, k] += w * (g[k] + np.abs(u) * dg[k])
    return 8 * EPS * out


def _inside(law: TableLaw, n: int = 400, seed: int = 7) -> np.ndarray:
    lo, hi = law.v_range()
    return np.exp(np.random.default_rng(seed).uniform(math.log(lo), math.log(hi), n))


@pytest.mark.parametrize("tables, V, m", [(ONE, 1.7, 1), (TABLES, 1.37, 2), (TABLES, 2.81, 2), (TABLES, 2.0, 1),
                                          (TABLES, 1.0, 1), (TABLES, 3.0, 1)],
                         ids=["one table", "between 1 and 2", "between 2 and 3", "at V=2", "at V=1", "at V=3"])
def test_matches_tablelaw_in_all_three_forms(tables, V, m):
    """Hypothesis: table_law evaluates TableLaw's PCHIPs (scipy) and V-weights: f, f', f'' agree at 400 random
    v inside the common range within the rounding bound of :func:`_bound` (ln v by two logs, the order of the
    weighted sum); one table at V = a table's speed packs one table (m = 1), V between two packs both."""
    law = TableLaw(tables)
    coef = table_coefficients(tables, V)
    assert coef[T_COUNT] == m
    v = _inside(law)
    got = _forms(coef, v)
    ref = np.column_stack([law(v, V, k) for k in range(3)])
    assert np.all(np.isfinite(got))
    err = np.abs(got - ref)
    assert np.all(err <= _bound(law, V, v)), np.max(err / _bound(law, V, v), axis=0)


def test_one_table_in_u_is_scipy_bitwise():
    """Hypothesis: at the same u, one table's f and p'(u) (LAW_LNV) are scipy's ``PPoly`` numbers exactly: the
    same coefficients, the same interval (x[i] <= u < x[i+1], the last closed) and the same operations in the
    same order (tolerance 0; at the knots too).  v = exp(u) is numba's exp: within an ulp of numpy's."""
    p = TableLaw(ONE).pchips[0]
    coef = table_coefficients(ONE, 1.0)
    us = np.concatenate([np.random.default_rng(3).uniform(p.x[0], p.x[-1], 500), p.x])
    for u in us:
        v, f, fu = table_law(u, coef, LAW_LNV)
        assert f == p(u) and fu == p(u, 1)
        assert abs(v - np.exp(u)) <= EPS * np.exp(u)


def test_layout_of_the_coefficients():
    """Hypothesis: the coefficient vector is as documented: header (m, ln lo, ln hi), then per table used
    (w, n, r, the knots, the guide, the four coefficients of each interval) -- checked against TableLaw's PCHIPs
    exactly (copies of numbers: tolerance 0), with the weights of TableLaw._weights; the guide's entry j is the
    interval of the left edge of cell j (numpy's searchsorted, the oracle)."""
    law = TableLaw(TABLES)
    coef = table_coefficients(TABLES, 1.37)
    lo, hi = law.v_range()
    assert coef[T_ULO] == max(p.x[0] for p in law.pchips) and coef[T_UHI] == min(p.x[-1] for p in law.pchips)
    assert np.exp(coef[T_ULO]) == pytest.approx(lo, rel=4 * EPS)
    assert np.exp(coef[T_UHI]) == pytest.approx(hi, rel=4 * EPS)
    o = T_HEAD
    for j, w in law._weights(1.37):
        p = law.pchips[j]
        x, n = p.x, p.x.size
        assert coef[o] == w and coef[o + 1] == n and coef[o + 2] == (n - 1) / (x[-1] - x[0])
        assert np.array_equal(coef[o + 3:o + 3 + n], x)
        edges = x[0] + np.arange(n - 1) * ((x[-1] - x[0]) / (n - 1))
        assert np.array_equal(coef[o + 3 + n:o + 3 + 2 * n - 1], np.searchsorted(x, edges, side="right") - 1)
        assert coef[o + 3 + 2 * n - 1] == n - 2
        assert np.array_equal(coef[o + 3 + 2 * n:o + 6 * n - 1].reshape(n - 1, 4), p.c.T)
        o += 6 * n - 1
    assert o == coef.size and coef.flags.c_contiguous and coef.dtype == np.float64


@pytest.mark.parametrize("spacing", ["even", "random", "bunched", "above edges", "below edges"])
def test_the_interval_is_scipys(spacing):
    """Hypothesis: the guided bisection finds scipy's interval, ``x[i] <= u < x[i+1]`` (the last closed), for
    knots even in ln v, at random, bunched (half of 300 knots within 1 % of the range, so that cells hold
    up to ~150 knots and others none), or one double above (below) the cell edges of an even grid, where the
    rounding of the cell number puts u in the neighbouring cell and the guards must widen the bounds: at every
    knot, the doubles either side, every cell edge and the doubles either side, and 2000 random u.  Oracle:
    numpy's searchsorted; tolerance: none (an index)."""
    n = 300
    rng = np.random.default_rng(5)
    if spacing == "even":
        x = np.linspace(-7.0, 3.0, n)
    elif spacing == "random":
        x = np.sort(rng.uniform(-7.0, 3.0, n))
    elif spacing == "bunched":
        x = np.sort(np.concatenate([rng.uniform(-7.0, 3.0, n // 2), rng.uniform(-1.05, -0.95, n - n // 2)]))
    else:
        x = -7.0 + np.arange(n) * (10.0 / (n - 1))
        x[1:-1] = np.nextafter(x[1:-1], np.inf if spacing == "above edges" else -np.inf)
    block = np.concatenate([x, _guide(x)])
    r = (n - 1) / (x[-1] - x[0])
    edges = x[0] + np.arange(n - 1) * ((x[-1] - x[0]) / (n - 1))
    us = np.concatenate([x, np.nextafter(x, -np.inf), np.nextafter(x, np.inf), edges, np.nextafter(edges, -np.inf),
                         np.nextafter(edges, np.inf), rng.uniform(x[0], x[-1], 2000)])
    us = us[(us >= x[0]) & (us <= x[-1])]
    want = np.clip(np.searchsorted(x, us, side="right") - 1, 0, n - 2)
    got = np.array([_interval(block, 0, n, n, r, u) for u in us])
    assert np.array_equal(got, want)


def test_continuity_at_the_knots():
    """Hypothesis: f and f' are continuous at every interior knot x_k (PCHIP is C¹): between u = x_k (the right
    piece at s = 0) and the next double below (the left piece at s = h), f changes by at most |p'| ulp(x_k)
    plus rounding and f' by rounding only: 64 eps of the scale of the terms (|f|, and |p'| + |p''| h for f'),
    the rounding of scipy's coefficients (built from differences of the data) and of the power sum."""
    for tables, V in ((ONE, 1.0), (TABLES, 1.37)):
        law = TableLaw(tables)
        coef = table_coefficients(tables, V)
        for j, _ in law._weights(V):
            x = law.pchips[j].x
            for k in range(1, x.size - 1):
                if not coef[T_ULO] < x[k] < coef[T_UHI]:
                    continue
                a, b = np.nextafter(x[k], -np.inf), x[k]
                _, fa, da = table_law(a, coef, LAW_LNV)
                _, fb, db = table_law(b, coef, LAW_LNV)
                h = x[k] - x[k - 1]
                d2 = abs(table_law(np.exp(b), coef, LAW_FPP)[2]) * np.exp(2 * b) + abs(db)
                assert abs(fa - fb) <= abs(db) * (b - a) + 64 * EPS * abs(fb)
                assert abs(da - db) <= 64 * EPS * (abs(db) + d2 * h + abs(fb) / h)


def test_c1_continuation_outside_the_table():
    """Hypothesis: outside [ln lo, ln hi] the law is f(u0) + p'(u0) (u - u0) from the nearer end u0, p' = p'(u0),
    p'' = 0 -- exactly (tolerance 0: the kernel forms these numbers from the same sums at u0); it is continuous
    with f' continuous at both ends (the next double outside differs by |p'| ulp plus 4 eps |f|), and finite
    far out (ln v 5 beyond the ends)."""
    for tables, V in ((ONE, 1.0), (TABLES, 2.81)):
        coef = table_coefficients(tables, V)
        for u0, side in ((coef[T_ULO], -1.0), (coef[T_UHI], 1.0)):
            _, f0, d0 = table_law(u0, coef, LAW_LNV)
            for du in (np.nextafter(u0, side * np.inf) - u0, 1e-9 * side, 0.3 * side, 5.0 * side):
                u = u0 + du
                v, f, d = table_law(u, coef, LAW_LNV)
                assert f == f0 + d0 * (u - u0) and d == d0 and v == np.exp(u)
                assert np.isfinite(f) and np.isfinite(d)
                w = float(np.exp(u))
                F, fp, fpp = table_law(w, coef, LAW_FPP)
                uw = float(np.log(w))
                assert F == f0 + d0 * (uw - u0) and fp == d0 / w and fpp == (0.0 - d0) / (w * w)
            _, f1, d1 = table_law(np.nextafter(u0, side * np.inf), coef, LAW_LNV)
            assert abs(f1 - f0) <= abs(d0) * abs(np.nextafter(u0, side * np.inf) - u0) + 4 * EPS * abs(f0)
            assert d1 == d0
            # the law just inside has the same slope to rounding (C¹ at the end)
            _, _, di = table_law(np.nextafter(u0, -side * np.inf), coef, LAW_LNV)
            assert abs(di - d0) <= 64 * EPS * (abs(d0) + abs(f0))


def test_nan_in_nan_out():
    """Hypothesis: a NaN argument gives NaN (never an index computed from it: no read outside coef), in every
    form; the solvers never pass one (the drivers check their states)."""
    coef = table_coefficients(TABLES, 1.37)
    for form in (LAW_LNV, LAW_FP, LAW_FPP):
        assert math.isnan(table_law(math.nan, coef, form)[1 if form == LAW_LNV else 0])


def _drive_py(law, coef, u0, du, n):
    """A loop compiled once for the law's function type, as the solvers' drivers are."""
    s = 0.0
    for i in range(n):
        v, f, fu = law(u0 + du * i, coef, LAW_LNV)
        s += f + fu
    return s


@functools.cache
def _driver():
    """:func:`_drive_py` compiled for its explicit signature when the test first asks, not at import (every
    pytest-xdist worker imports this module to collect it: ~0.45 s of CPU each)."""
    return njit(types.float64(LAW_TYPE, types.float64[::1], types.float64, types.float64, types.int64))(_drive_py)


def test_a_new_table_costs_no_compilation():
    """Hypothesis: table_law is compiled once for LAW_SIG, so tables of other lengths (20, 1000 points), two
    tables or the paper's law through the same compiled driver compile nothing: the dispatchers keep one
    signature each, and numba's compile-event recorder sees no compilation.  The driver's sum equals the law's
    own calls summed in Python (same numbers: tolerance 0)."""
    _drive = _driver()
    _drive(table_law, table_coefficients(ONE, 1.0), -5.0, 1e-3, 10)  # compile the driver once, outside
    _drive(paper_law, paper_coefficients(1.0), -5.0, 1e-3, 1)  # and the paper's law (compiled on first use)
    coefs = [table_coefficients(PeelForce.tabulated(*_table(1.0, n, 1e-3, 30.0)[1:]).tables, 1.0)
             for n in (20, 1000)] + [table_coefficients(TABLES, 1.5)]
    with event.install_recorder("numba:compile") as rec:
        for c in coefs:
            s = _drive(table_law, c, -5.0, 1e-3, 1000)
            ref = 0.0
            for i in range(1000):
                _, f, fu = table_law(-5.0 + 1e-3 * i, c, LAW_LNV)
                ref += f + fu
            assert s == ref
        _drive(paper_law, paper_coefficients(1.0), -5.0, 1e-3, 10)
    assert sum(1 for _, e in rec.buffer if e.is_start) == 0
    assert len(table_law.signatures) == 1 and len(_drive.signatures) == 1


def test_bad_input_is_refused_as_tablelaw_refuses_it():
    """Hypothesis: a V outside the tables' speeds, or another V than a single table's own, raises TableLaw's
    ValueError (the same message); V not finite or not a number, and a bad table, are refused by name."""
    for tables, V in ((TABLES, 0.5), (TABLES, 3.5), (PeelForce.tabulated(*_table(1.0, 40, 1e-3, 30.0)[1:],
                                                                         V=1.0).tables, 2.0)):
        with pytest.raises(ValueError) as want:
            TableLaw(tables)._weights(V)
        with pytest.raises(ValueError) as got:
            table_coefficients(tables, V)
        assert str(got.value) == str(want.value)
    with pytest.raises(ValueError, match="V must be finite"):
        table_coefficients(ONE, math.nan)
    with pytest.raises(TypeError, match="V"):
        table_coefficients(ONE, "fast")  # type: ignore[arg-type]
    v, f = np.array(ONE[0][1]), np.array(ONE[0][2])
    f[4] = np.nan
    with pytest.raises(ValueError, match=r"f\[4\]"):
        table_coefficients([(None, v, f)], 1.0)
