"""Tabulated peel-force laws: a measured curve f(v), PCHIP in ln v, checked point by point.

A table is ``(V, v, f)``: the pull speed it was measured at (None: used at every V), peel velocities
[m/s] and forces [N].  :func:`check_table` validates one; :class:`TableLaw` evaluates a set of them.

Interpolation: scipy's :class:`~scipy.interpolate.PchipInterpolator` of f in ``u = ln v`` (monotone cubic
Hermite, Fritsch–Carlson slopes).  It is shape-preserving: between two data it is monotone when they are,
so it adds no extremum the data do not have; f and f' are continuous (f'' jumps at the data).  At a local
extremum of the data PCHIP puts f' = 0 *at that datum*, so the folds of a tabulated law are data points:
their positions are as accurate as the spacing of the table (first order in the spacing, in ln v), their
forces to second order (f is flat there); away from the extrema f converges at third order for smooth
data.  tests/test_law.py measures both.

Several tables at several pull speeds ``V_1 < V_2 < ...`` are interpolated linearly in V between the two
tables around V, on the v range common to all of them; a V outside ``[V_1, V_n]`` is refused, as is a v
outside the table's range: a tabulated law is never extrapolated.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MIN_POINTS", "TableLaw", "check_table", "check_tables"]

#: Fewest points of a table: one maximum then one minimum, each with a neighbour on either side.
MIN_POINTS = 5


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def check_table(v, f, label: str = "") -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(v, f)`` as tuples of floats, or ValueError naming the first offending point.

    Checks, in order: both 1-D of the same length with at least :data:`MIN_POINTS` points; every value
    finite; ``v > 0`` and strictly increasing; ``f > 0``; no two consecutive f equal (a flat step makes the
    fold ambiguous); exactly one interior local maximum followed by one interior local minimum of the data
    (the N shape of a stick-slip law).  ``label`` (e.g. ``" of table 2 (V=1)"``) is added to the messages.
    """
    return _check_arrays(_floats("v" + label, v), _floats("f" + label, f), label)


def _floats(name: str, x) -> np.ndarray:
    """x as a float array (NaN kept: :func:`_check_arrays` names it), or ArgumentTypeError."""
    from .._checks import ArgumentTypeError

    bad = x is None or isinstance(x, (str, bytes, bool, np.bool_))
    try:
        a = np.asarray(x) if not bad else None
    except (TypeError, ValueError):  # ragged nesting
        a = None
    if a is None or a.dtype.kind not in "iuf":
        raise ArgumentTypeError(f"{name} must be an array of real numbers, got {type(x).__name__}")
    return a.astype(float)


def _check_arrays(va: np.ndarray, fa: np.ndarray, label: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    for name, a in (("v", va), ("f", fa)):
        if a.ndim != 1:
            raise ValueError(f"{name}{label} must be a 1-D array, got shape {a.shape}")
    if va.size != fa.size:
        raise ValueError(f"v and f{label} must have the same length, got {va.size} and {fa.size}")
    if va.size < MIN_POINTS:
        raise ValueError(f"a peel-force table{label} needs at least {MIN_POINTS} points (one maximum then one "
                         f"minimum, each between two others), got {va.size}")
    for name, a in (("v", va), ("f", fa)):
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"{name}{label} must be finite: {name}[{i}] = {float(a[i])!r}")
    bad = np.flatnonzero(va <= 0)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"v{label} must be > 0 (peel velocities in m/s): v[{i}] = {float(va[i])!r}")
    bad = np.flatnonzero(np.diff(va) <= 0)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"v{label} must be strictly increasing: v[{i}] = {float(va[i])!r} >= "
                         f"v[{i + 1}] = {float(va[i + 1])!r}")
    bad = np.flatnonzero(fa <= 0)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"f{label} must be > 0 (a peel force in N): f[{i}] = {float(fa[i])!r} at v = {float(va[i])!r}")
    d = np.diff(fa)
    bad = np.flatnonzero(d == 0)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"f{label} must have no flat step (the fold would be ambiguous): f[{i}] = f[{i + 1}] "
                         f"= {float(fa[i])!r} at v = {float(va[i])!r}, {float(va[i + 1])!r}")
    turns = np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:])) + 1  # interior local extrema of the data
    kinds = ["max" if d[i - 1] > 0 else "min" for i in turns]
    if kinds != ["max", "min"]:
        found = ", ".join(f"local {k} at index {i} (v = {_fmt(va[i])}, f = {_fmt(fa[i])})"
                          for k, i in zip(kinds, turns)) or "none (the data are monotone: no folds, no stick-slip)"
        raise ValueError(f"f{label} must have exactly one local maximum followed by one local minimum (the "
                         f"N shape of a stick-slip law); found {found}")
    return tuple(float(x) for x in va), tuple(float(x) for x in fa)


class TableLaw:
    """The evaluator of a tabulated law: PCHIP interpolants in ``ln v``, linear in V between tables."""

    def __init__(self, tables: tuple[tuple[float | None, tuple[float, ...], tuple[float, ...]], ...]):
        from scipy.interpolate import PchipInterpolator

        self.V: list[float | None] = [t[0] for t in tables]
        self.pchips = [PchipInterpolator(np.log(np.asarray(t[1])), np.asarray(t[2])) for t in tables]
        self.lo = max(t[1][0] for t in tables)
        self.hi = min(t[1][-1] for t in tables)

    def v_range(self) -> tuple[float, float]:
        return self.lo, self.hi

    def _weights(self, V: float) -> list[tuple[int, float]]:
        if len(self.V) == 1:
            V0 = self.V[0]
            if V0 is not None and V != V0:
                raise ValueError(f"V={V!r} m/s: this tabulated law was measured at V={V0!r} m/s only (pass V=None "
                                 "to use one table at every pull speed, or tables at several V)")
            return [(0, 1.0)]
        Vs = [float(x) for x in self.V if x is not None]  # several tables: every V is a number
        if not (Vs[0] <= V <= Vs[-1]):
            raise ValueError(f"V={V!r} m/s is outside the tables' pull speeds [{Vs[0]!r}, {Vs[-1]!r}] m/s: a "
                             "tabulated law is not extrapolated in V")
        j = int(np.searchsorted(Vs, V, side="right")) - 1
        if j >= len(Vs) - 1:
            return [(len(Vs) - 1, 1.0)]
        t = (V - Vs[j]) / (Vs[j + 1] - Vs[j])
        return [(j, 1.0 - t), (j + 1, t)] if t > 0 else [(j, 1.0)]

    def __call__(self, v: np.ndarray, V: float, order: int) -> np.ndarray:
        if v.size and (v.min() < self.lo or v.max() > self.hi):
            bad = v.ravel()[np.flatnonzero(((v < self.lo) | (v > self.hi)).ravel())[0]]
            raise ValueError(f"v={float(bad)!r} m/s is outside the table's range [{self.lo!r}, {self.hi!r}] m/s: "
                             "a tabulated law is not extrapolated")
        u = np.log(v)
        out = np.zeros(v.shape)
        for j, w in self._weights(V):
            p = self.pchips[j]
            if order == 0:
                g = p(u)
            elif order == 1:
                g = p(u, 1) / v
            else:
                g = (p(u, 2) - p(u, 1)) / (v * v)
            out = out + w * g
        return out


Table = tuple[float | None, tuple[float, ...], tuple[float, ...]]


def check_tables(tables, V_range: tuple[float, float]) -> tuple[Table, ...]:
    """``(V, v, f)`` triples as canonical tuples, each table checked by :func:`check_table`: one table (V a
    pull speed in ``V_range`` or None: used at every V), or several at strictly increasing V in ``V_range``
    whose v ranges overlap."""
    from .._checks import in_range

    try:
        items = list(tables)
    except TypeError:
        raise TypeError(f"tables must be a sequence of (V, v, f) triples, got {type(tables).__name__}") from None
    if not items:
        raise ValueError("tables must hold at least one (V, v, f) triple, got none")
    out = []
    for n, item in enumerate(items):
        if not isinstance(item, (tuple, list)) or len(item) != 3:
            raise ValueError(f"tables[{n}] must be a (V, v, f) triple, got {type(item).__name__}")
        if len(items) == 1:
            V = None if item[0] is None else in_range("V", item[0], *V_range)
            out.append((V, *check_table(item[1], item[2])))
            break
        V = in_range(f"V of tables[{n}]", item[0], *V_range)
        out.append((V, *check_table(item[1], item[2], f" of tables[{n}] (V={V!r})")))
    for n in range(1, len(out)):
        if not out[n][0] > out[n - 1][0]:  # type: ignore[operator]  # several tables: every V is a number
            raise ValueError(f"the tables' pull speeds must be strictly increasing: tables[{n - 1}] has V="
                             f"{out[n - 1][0]!r}, tables[{n}] has V={out[n][0]!r}")
    lo, hi = max(t[1][0] for t in out), min(t[1][-1] for t in out)
    if not lo < hi:
        raise ValueError(f"the tables' v ranges do not overlap (common range [{lo!r}, {hi!r}] m/s)")
    return tuple(out)
