"""Input and output helpers shared by the three packages: one writer for every table (rows as CSV or JSON,
chosen by the extension), one JSON normaliser (:func:`jsonable`), one number formatter for tables and
messages (:func:`fmt_number`), and the pieces every result object's data out and notebook display share: the
lazy import of an optional dependency (:func:`optional_import`: pandas and xarray for ``to_dataframe`` and
``to_xarray``, tqdm for progress bars), the parameters as flat metadata (:func:`param_attrs`), the small HTML
table of ``_repr_html_`` (:func:`html_table`) and the rate-limited progress line of the long loops
(:class:`ProgressLine`: a line per ~5 % in a terminal or a log, one updating line in Jupyter)."""

from __future__ import annotations

import csv
import html
import importlib
import json
import math
import numbers
from collections.abc import Iterable, Mapping, Sequence
from types import ModuleType
from typing import IO, Any

import numpy as np

from ._progress import ProgressLine

__all__ = ["TABLE_EXTENSIONS", "ProgressLine", "fmt_number", "html_table", "jsonable", "optional_import",
           "param_attrs", "write_csv", "write_rows"]

#: The file name endings :func:`write_rows` accepts.
TABLE_EXTENSIONS = (".csv", ".json")


def jsonable(x: Any, *, keep_nonfinite: bool = False, scalar: bool = False) -> Any:
    """``x`` as plain JSON data: what it reads back as from JSON.

    numpy scalars and 0-d arrays become Python scalars, integers ``int`` and other reals ``float`` (``bool``
    stays ``bool``); tuples, lists and numpy arrays become lists and mappings dicts (non-str keys as their
    JSON text, as :func:`json.dumps` writes them), recursively.

    Parameters
    ----------
    x : Any
        The value.
    keep_nonfinite : bool
        Keep NaN and ±inf (Python's JSON writes them as ``NaN``/``Infinity``); by default they become None
        (strict JSON has no NaN: the tables of :func:`write_rows`).
    scalar : bool
        Accept only a JSON scalar (None, bool, str, int, float or a numpy scalar); a container is a TypeError.

    Raises
    ------
    TypeError
        For a value JSON cannot hold (or a container, with ``scalar=True``).
    """
    if x is None or isinstance(x, bool):
        return x
    if isinstance(x, str):
        return str(x)
    if isinstance(x, np.generic) or (isinstance(x, np.ndarray) and x.ndim == 0):
        x = x.item()
        if x is None or isinstance(x, (bool, str)):
            return x
    if isinstance(x, numbers.Integral):
        return int(x)
    if isinstance(x, numbers.Real):
        v = float(x)
        return v if keep_nonfinite or math.isfinite(v) else None
    if not scalar:
        if isinstance(x, Mapping):
            return {_json_key(k): jsonable(v, keep_nonfinite=keep_nonfinite) for k, v in x.items()}
        if isinstance(x, (list, tuple, np.ndarray)):
            return [jsonable(v, keep_nonfinite=keep_nonfinite) for v in x]
        raise TypeError(f"value {x!r} of type {type(x).__name__} is not JSON-serialisable")
    raise TypeError(f"value {x!r} of type {type(x).__name__} is not a JSON scalar (float, int, str, bool, None)")


def _json_key(k: Any) -> str:
    """A mapping key as JSON writes it (str keys as they are; numbers, bools and None as their JSON text)."""
    if isinstance(k, str):
        return k
    k = jsonable(k, keep_nonfinite=True, scalar=True)
    return json.dumps(k)


def fmt_number(x: Any, digits: int = 3, *, missing: str = "–", nan: str | None = None,
               plain: tuple[float, float] | None = None, int_digits: int | None = None,
               short_exponent: bool = False) -> str:
    """A number for a table or a message, with ``digits`` significant digits.

    Parameters
    ----------
    x : Any
        The value: None prints as ``missing``, NaN as ``nan``, ±inf as ``inf``/``-inf``, an integer exactly,
        a float in format ``g`` with ``digits`` significant digits; anything else (bool, str, ...) as ``str(x)``.
    digits : int
        Significant digits of a float.
    missing : str
        The text of None (a dash; ``""`` for an empty table cell).
    nan : str or None
        The text of NaN (default: ``missing``; ``"nan"`` where a report prints it).
    plain : (float, float) or None
        Print a nonzero float with ``lo <= |x| < hi`` in format ``g``, others in scientific notation (format
        ``e``, also ``digits`` significant digits); None: format ``g`` throughout.
    int_digits : int or None
        Print an integer with more digits than this like a float; None: every integer exactly.
    short_exponent : bool
        Write exponents as people do: ``1e-05`` -> ``1e-5``, ``1e+300`` -> ``1e300``.
    """
    if x is None:
        return missing
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, numbers.Real):
        return str(x)
    if isinstance(x, numbers.Integral) and (int_digits is None or abs(x) < 10**int_digits):
        return str(x)
    v = float(x)
    if math.isnan(v):
        return missing if nan is None else nan
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    if plain is not None and v != 0 and not plain[0] <= abs(v) < plain[1]:
        s = f"{v:.{digits - 1}e}"
    else:
        s = f"{v:.{digits}g}"
    if short_exponent and "e" in s:
        m, e = s.split("e")
        s = f"{m}e{int(e)}"
    return s


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


def optional_import(module: str, purpose: str, extra: str = "data", *, pip: str | None = None,
                    error: type[ImportError] = ImportError) -> ModuleType:
    """Import the optional dependency ``module`` when a method needs it (never at ``import peelapprox``).

    Parameters
    ----------
    module : str
        The module, e.g. ``"pandas"``.
    purpose : str
        What needs it, for the message, e.g. ``"Trajectory.to_dataframe"``.
    extra : str
        The extra of ``pyproject.toml`` that installs it (``data``: pandas and xarray).
    pip : str, optional
        Its name on PyPI when that is not ``module``.
    error : type
        The ImportError subclass raised (the peers': :class:`peelapprox.kernels.PeerUnavailableError`).

    Raises
    ------
    ImportError
        ``"<purpose> needs <module>: pip install 'peelapprox[<extra>]' (or pip install <pip>)"`` when it does not
        import.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise error(f"{purpose} needs {module}: pip install 'peelapprox[{extra}]' (or pip install {pip or module})"
                    ) from exc


def param_attrs(params: Any) -> dict[str, Any]:
    """The fields of a :class:`peelapprox.PeelParams` as flat metadata (``df.attrs``, xarray attrs: plain
    scalars a netCDF file can hold): ``V, I, k, R, l, geometry``, the law as ``force`` (its ``repr``) and
    ``force_key`` (its SHA-256, :attr:`peelapprox.PeelForce.key`)."""
    out: dict[str, Any] = {n: jsonable(getattr(params, n), scalar=True) for n in ("V", "I", "k", "R", "l", "geometry")}
    out["force"] = repr(params.force)
    out["force_key"] = params.force.key
    return out


def html_table(title: str, items: Mapping[str, Any] | Iterable[tuple[str, Any]]) -> str:
    """A small two-column HTML table (``_repr_html_`` of the result objects): a bold ``title`` and one row per
    ``(name, value)``, floats by :func:`fmt_number` (4 significant digits), everything escaped."""
    pairs = items.items() if isinstance(items, Mapping) else items
    body = "".join(f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
                   f"<td style='text-align:left'>{html.escape(fmt_number(v, 4))}</td></tr>" for k, v in pairs)
    return f"<table><caption style='text-align:left'><b>{html.escape(title)}</b></caption>{body}</table>"
