"""One writer for every table the package saves: rows (dicts) as CSV or JSON, chosen by the extension."""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from typing import IO, Any

import numpy as np

__all__ = ["TABLE_EXTENSIONS", "jsonable", "write_csv", "write_rows"]

#: The file name endings :func:`write_rows` accepts.
TABLE_EXTENSIONS = (".csv", ".json")


def jsonable(v: Any) -> Any:
    """A JSON-safe scalar: numpy scalars to Python, non-finite floats to None (strict JSON has no NaN)."""
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def write_rows(path, rows: Iterable[Mapping[str, Any]], *, fields: Sequence[str] | None = None) -> str:
    """Write ``rows`` to ``path`` (``.csv`` or ``.json``); returns the path.

    CSV: columns ``fields`` (default: every key, in first-seen order), None or absent as an empty cell,
    floats in full precision (``repr``).  JSON: a list of objects, NaN/inf as null (strict JSON).

    Raises
    ------
    ValueError
        If the extension is neither ``.csv`` nor ``.json``.
    """
    rows = [dict(r) for r in rows]
    p = str(path)
    if p.endswith(".json"):
        with open(p, "w") as fh:
            json.dump([{k: jsonable(v) for k, v in r.items()} for r in rows], fh, indent=1, allow_nan=False)
    elif p.endswith(".csv"):
        with open(p, "w", newline="") as fh:
            write_csv(fh, rows, fields=fields)
    else:
        raise ValueError(f"path must end in {' or '.join(TABLE_EXTENSIONS)}, got {p!r}")
    return p


def write_csv(fh: IO[str], rows: Iterable[Mapping[str, Any]], *, fields: Sequence[str] | None = None) -> None:
    """Write ``rows`` as CSV to the open text stream ``fh`` (e.g. ``sys.stdout``), as :func:`write_rows` does
    to a ``.csv`` file: columns ``fields`` (default: every key, first-seen order), None or absent as an empty
    cell, floats in full precision."""
    rows = [dict(r) for r in rows]
    cols = list(fields) if fields is not None else list(dict.fromkeys(k for r in rows for k in r))
    w = csv.writer(fh)
    w.writerow(cols)
    for r in rows:
        w.writerow(["" if r.get(c) is None else (repr(float(r[c])) if isinstance(r[c], (float, np.floating))
                                                 else r[c]) for c in cols])
