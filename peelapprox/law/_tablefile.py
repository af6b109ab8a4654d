"""A peel-force curve from a CSV file: :meth:`peelapprox.PeelForce.from_csv` and the points the CLI fits or smooths.

The file is read by :func:`peelapprox._csvread.read_columns` (a regular UTF-8 file of at most 16 MiB, ``#``
comments, errors naming the file, line and column).  Its header names the columns ``v`` (peel velocity) and ``f``
(force), and optionally ``V`` (the pull speed: one table per distinct V, rows of a V in file order, tables in order
of first appearance; at most :data:`MAX_TABLES` tables), each optionally with its unit (``v [mm/s]``, ``f [kN]``,
``V (m/min)``: converted to m/s and N; an unknown unit is refused, named).  ``columns`` names other header cells
instead (``{"v": "speed [mm/s]", "f": "force"}``; a unit given there is the unit of a header cell that states none).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._checks import shown
from .._csvread import header_cell, read_columns

__all__ = ["MAX_TABLES", "TABLE_COLUMNS", "read_points", "with_line"]

#: The headers accepted without ``columns``: one table, or several grouped by the pull speed V [m/s].
TABLE_COLUMNS = (("v", "f"), ("V", "v", "f"))
_UNIT = {"V": "m/s", "v": "m/s", "f": "N"}
#: Most distinct pull speeds V (tables) in one file: a law is interpolated between neighbouring tables, and a
#: measured family holds tens; beyond, the file is refused (ValueError naming it and the count) before any
#: table is built.
MAX_TABLES = 1000


def read_points(path: Any, *, columns: Any = None, delimiter: str | None = None,
                where: str | None = None, sigma: bool = False) -> list[tuple[Any, ...]]:
    """``[(V or None, v [m/s], f [N], file lines), ...]``: the file's tables (module docstring).

    With ``sigma=True`` an optional column ``sigma`` (the standard deviation of each f [N], a unit allowed as
    for f) is read too, and each table is ``(V or None, v, f, lines, sigma or None)``.

    Raises
    ------
    ValueError
        read_columns' errors (naming file, line, column), a bad ``columns``, a V that is not finite (its line).
    TypeError
        ``path`` not a path.
    """
    import os

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file path (str or os.PathLike), got {type(path).__name__}")
    path = os.fspath(path)
    where = where or f"file {shown(path)}"
    if columns is None:
        names = {"V": "V", "v": "v", "f": "f"}
        stated: dict[str, str] = {}
        expected = (f"{' or '.join(','.join(c) for c in TABLE_COLUMNS)} (V is the pull speed, v the peel velocity "
                    "[m/s], f the force [N])" + (", optionally sigma (f's standard deviation [N])" if sigma else ""))
        exact = True
    else:
        if isinstance(columns, Mapping):
            spec = dict(columns)
        elif isinstance(columns, (tuple, list)) and len(columns) in (2, 3):
            spec = dict(zip(("v", "f") if len(columns) == 2 else ("V", "v", "f"), columns))
        else:
            raise TypeError("columns must be a mapping {'v': header, 'f': header[, 'V': header]} or a sequence of "
                            f"the headers of v, f (or V, v, f), got {shown(columns)}")
        bad = sorted(set(spec) - set(_UNIT))
        if bad or not {"v", "f"} <= set(spec) or not all(isinstance(x, str) for x in spec.values()):
            raise ValueError(f"columns must name the file's columns for v and f (and optionally V) as strings, got "
                             f"{shown(columns)}")
        names, stated = {}, {}
        for key, text in spec.items():
            name, unit = header_cell(text, any_name=True)
            names[key] = name
            if unit:
                stated[name] = unit
        expected, exact = ",".join(names[k] for k in ("V", "v", "f") if k in names), False
    wanted = {names[k]: _UNIT[k] for k in ("V", "v", "f") if k in names}
    optional = [names["V"]] if "V" in names else []
    if sigma:
        wanted["sigma"] = "N"
        optional.append("sigma")
    cols = read_columns(path, wanted, where=where, delimiter=delimiter, optional=tuple(optional), stated=stated,
                        exact=exact, expected=expected)
    v, f, lines = cols[names["v"]], cols[names["f"]], cols["line"]
    sd = cols.get("sigma") if sigma else None
    extra: tuple = (sd,) if sigma else ()
    if "V" not in names or names["V"] not in cols:
        return [(None, v, f, lines, *extra)]
    Vs = cols[names["V"]]
    nonfinite = np.flatnonzero(~np.isfinite(Vs))
    if nonfinite.size:
        i = int(nonfinite[0])
        raise ValueError(f"{where} line {lines[i]} (V): must be finite, got {float(Vs[i])!r}")
    out: list[tuple[Any, ...]] = []
    for V, sel in _split(Vs, where):
        out.append((V, v[sel], f[sel], lines[sel], *((None if sd is None else sd[sel]),)[:len(extra)]))
    return out


def _split(Vs: np.ndarray, where: str) -> list[tuple[float, np.ndarray]]:
    """``[(V, the indices of its rows in file order), ...]`` in order of first appearance of each V, or ValueError
    beyond :data:`MAX_TABLES` distinct V.

    One sort, O(rows log rows) whatever the number of tables: a pass over the rows per distinct V was O(rows x
    tables), 500 s on a file of 300,000 rows each at its own V.
    """
    _, first, group = np.unique(Vs, return_index=True, return_inverse=True)  # first: each V's first row
    if first.size > MAX_TABLES:
        raise ValueError(f"{where} (V): at most MAX_TABLES = {MAX_TABLES} distinct pull speeds V (one table each), "
                         f"got {first.size}")
    group = group.ravel()
    rows = np.argsort(group, kind="stable")  # the rows of each V together, in file order
    counts = np.bincount(group, minlength=first.size)
    ends = np.cumsum(counts)
    return [(float(Vs[first[k]]), rows[ends[k] - counts[k]:ends[k]]) for k in np.argsort(first, kind="stable")]


def with_line(msg: str, tables: list) -> str:
    """``msg`` with the file line of the point it names (``v[i]``/``f[i]`` of ``tables[n]``, or of the only table)
    appended, when it names one."""
    m = re.search(r"\b[vf]\[(\d+)\]", msg)
    if not m:
        return msg
    t = re.search(r"tables\[(\d+)\]", msg)
    n = int(t.group(1)) if t else (0 if len(tables) == 1 else None)
    i = int(m.group(1))
    if n is None or n >= len(tables) or i >= len(tables[n][3]):
        return msg
    return f"{msg} (line {int(tables[n][3][i])})"


def from_csv(cls: Any, path: Any, columns: Any, delimiter: str | None, where: str | None = None) -> Any:
    """:meth:`peelapprox.PeelForce.from_csv`: a tabulated law of the file's tables."""
    tables = read_points(path, columns=columns, delimiter=delimiter, where=where)
    label = where or f"file {shown(str(path))}"
    try:
        if len(tables) == 1 and tables[0][0] is None:
            return cls.tabulated(tables[0][1], tables[0][2])
        return cls.tabulated(tables=[(V, v, f) for V, v, f, *_ in tables])
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{label}: {with_line(str(exc), tables)}") from None
