"""Reading columns of numbers from a CSV file safely: the one low-level reader of the package's data files.

:func:`read_columns` reads named columns of a CSV file into float arrays, converting each from the unit its header
cell states (``v [mm/s]``, ``f (kN)``) to the unit the caller wants; it is what :meth:`peelapprox.PeelForce.from_csv`
(and the CLI's ``--force-table``, ``--force-fit``) read tables with, and what a reader of measured force traces
reuses.  Its safety:

* only a regular file is read, opened without blocking (``O_NONBLOCK``: a FIFO would otherwise wait for a writer
  forever) and checked by ``fstat`` on the open descriptor (the file checked is the file read): a FIFO, a device,
  a socket or a directory is refused with its kind named;
* at most ``max_bytes`` (default :data:`MAX_BYTES`, 16 MiB), by the file's size and again by what is read;
* UTF-8 text (a byte-order mark before the header, as spreadsheets write it, is skipped), else the line of the
  first bad byte is named;
* ``#`` starts a comment (a whole line or its end), blank lines are skipped; the first remaining line is the header;
* every error is a ``ValueError`` beginning with ``where`` (the caller's name for the file) and naming the line
  and, for a cell, the column.

Units (:data:`UNITS`): velocities ``m/s``, ``mm/s``, ``cm/s``, ``um/s`` (``µm/s``), ``m/min``, ``mm/min``; forces
``N``, ``mN``, ``cN``, ``kN``; times ``s``, ``ms``, ``us`` (``µs``), ``min``.  A unit outside the table, or of another
dimension than the one wanted (``v [N]``), is refused, naming it and the units accepted.
"""

from __future__ import annotations

import csv
import errno
import os
import re
import stat
from array import array
from collections.abc import Collection, Iterator, Mapping

import numpy as np

from ._checks import shown

__all__ = ["MAX_BYTES", "UNITS", "convert", "header_cell", "read_columns", "read_regular"]

#: Largest file read [bytes], 16 MiB: a measured curve has hundreds to a few thousand rows of ~30 bytes (a force
#: trace of 20 s at 10 kHz ~ 5 MB), so 16 MiB (~500,000 rows, parsed in seconds) is beyond any real table, while a
#: path to a huge file (a log, a disk image) is refused at once instead of filling the memory.
MAX_BYTES = 16 * 1024 * 1024

#: Each unit: ``(dimension, factor to the SI unit)``.
UNITS: dict[str, tuple[str, float]] = {
    "m/s": ("velocity", 1.0), "mm/s": ("velocity", 1e-3), "cm/s": ("velocity", 1e-2), "um/s": ("velocity", 1e-6),
    "µm/s": ("velocity", 1e-6), "m/min": ("velocity", 1.0 / 60.0), "mm/min": ("velocity", 1e-3 / 60.0),
    "N": ("force", 1.0), "mN": ("force", 1e-3), "cN": ("force", 1e-2), "kN": ("force", 1e3),
    "s": ("time", 1.0), "ms": ("time", 1e-3), "us": ("time", 1e-6), "µs": ("time", 1e-6), "min": ("time", 60.0),
}

_FILE_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
               (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
_BRACKETS = frozenset("[](){}")
_NEWLINE = re.compile(r"\r\n|\r|\n")


def header_cell(cell: str, any_name: bool = False) -> tuple[str, str | None]:
    """A header cell's ``(name, unit)``: ``name``, ``name [unit]`` or ``name (unit)`` (unit None when the cell
    states none); a cell of another shape (a bracket in the name, text after the unit, an unclosed bracket) is
    all name, and so matches no column.  ``any_name``: the name may hold brackets itself (a caller's column spec,
    ``"f [a] [N]"``), the unit being the last bracketed group.

    Linear in the cell's length: a scan for the bracket opening the unit and one over the unit, no regular
    expression (a backtracking pattern with a lazy name beside optional blanks took seconds on a 2 kB header and
    minutes on ``'v,f,a' + ' ' * 500 + '[' + ' ' * 500 + 'x'``).
    """
    text = cell.strip()
    if any_name:
        k = max(text.rfind(ch, 0, len(text) - 1) for ch in "[]()") if len(text) > 1 else -1
        k = k if k >= 0 else len(text)
    else:
        k = next((i for i, ch in enumerate(text) if ch in _BRACKETS), len(text))
    if k == len(text) or text[k] not in "[(" or text[-1] not in "])" or len(text) - k < 2:
        return text, None
    unit = text[k + 1:-1]
    if any(ch in "[]()" for ch in unit):
        return text, None
    return text[:k].rstrip(), unit.strip()


def convert(name: str, unit: str, to: str, where: str) -> float:
    """The factor taking values of column ``name`` from ``unit`` to ``to`` (:data:`UNITS`), or a ValueError naming
    the unknown or mismatched unit and those accepted."""
    if unit == to:
        return 1.0
    if unit not in UNITS:
        dim = UNITS.get(to, ("", 1.0))[0]
        ok = ", ".join(u for u, (d, _) in UNITS.items() if d == dim) or to
        raise ValueError(f"{where}: column {name}: unknown unit {shown(unit)}; the units of a {dim or 'value'} "
                         f"are {ok}")
    if to not in UNITS or UNITS[unit][0] != UNITS[to][0]:
        raise ValueError(f"{where}: column {name}: the unit {shown(unit)} is a {UNITS[unit][0]}, but {name} must be "
                         f"given in {to}" + (f" (a {UNITS[to][0]})" if to in UNITS else ""))
    return UNITS[unit][1] / UNITS[to][1]


def read_regular(path: str, where: str, max_bytes: int = MAX_BYTES) -> bytes:
    """The bytes of the regular file ``path``, at most ``max_bytes``, or a ValueError beginning with ``where``
    (module docstring)."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if exc.errno == errno.EISDIR:
            raise ValueError(f"{where}: is a directory; a table must be a regular file (a CSV on disk)") from None
        raise ValueError(f"{where}: cannot read it ({exc.strerror or exc})") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        kind = next((what for test, what in _FILE_KINDS if test(st.st_mode)), "not a regular file")
        raise ValueError(f"{where}: is {kind}; a table must be a regular file (a CSV on disk)")
    limit = f"{max_bytes // (1024 * 1024)} MiB" if max_bytes >= 1024 * 1024 else f"{max_bytes} bytes"
    if st.st_size > max_bytes:
        os.close(fd)
        raise ValueError(f"{where}: {st.st_size} bytes, more than the {limit} a table may have (a measured curve "
                         "is a few thousand rows; is this the right file?)")
    with os.fdopen(fd, "rb") as fh:
        try:  # the size fstat gave (a buffer of max_bytes would cost that much whatever the file), then the rest
            parts = [fh.read(st.st_size + 1)]  # of a file that grew, or of one whose size reads 0 (/proc), in MiBs
            total = len(parts[0])
            while total > st.st_size and total <= max_bytes and parts[-1]:
                parts.append(fh.read(min(1 << 20, max_bytes + 1 - total)))
                total += len(parts[-1])
        except OSError as exc:
            raise ValueError(f"{where}: cannot read it ({exc.strerror or exc})") from None
    data = parts[0] if len(parts) == 1 else b"".join(parts)
    if len(data) > max_bytes:
        raise ValueError(f"{where}: more than the {limit} a table may have (a measured curve is a few thousand "
                         "rows; is this the right file?)")
    return data


def _data_lines(text: str) -> Iterator[tuple[int, str]]:
    """``(line number, text)`` of the lines that are not blank or comments (``#`` to the end of a line), one at a
    time (a list of them cost ~60 bytes per byte of the file)."""
    start, n = 0, 1
    for m in _NEWLINE.finditer(text):  # universal newlines, as open() reads
        line = text[start:m.start()].split("#", 1)[0].strip()
        if line:
            yield n, line
        start, n = m.end(), n + 1
    line = text[start:].split("#", 1)[0].strip()
    if line:
        yield n, line


def _csv_row(lineno: int, text: str, where: str, delimiter: str) -> list[str]:
    """The cells of one data line (:mod:`csv`), a csv error (a NUL byte, an unclosed quote, a field over csv's
    size limit) as a ValueError naming the file line."""
    try:
        return next(csv.reader([text], delimiter=delimiter), [])
    except csv.Error as exc:
        raise ValueError(f"{where} line {lineno}: not a CSV row ({exc})") from None


def read_columns(path: str, columns: Mapping[str, str], *, where: str, delimiter: str | None = None,
                 max_bytes: int = MAX_BYTES, optional: Collection[str] = (), stated: Mapping[str, str] | None = None,
                 exact: bool = False, expected: str | None = None,
                 max_rows: int | None = None) -> dict[str, np.ndarray]:
    """The named columns of the CSV file ``path`` as float arrays, in the units asked for.

    Parameters
    ----------
    path : str
        The file (module docstring: a regular UTF-8 file of at most ``max_bytes``, ``#`` comments).
    columns : mapping of str to str
        Each column's name in the header and the unit its values are returned in (``{"v": "m/s", "f": "N"}``;
        ``""``: no unit, no conversion).  A header cell is ``name``, ``name [unit]`` or ``name (unit)``.
    where : str
        How messages name the file (e.g. ``"--force-table 'x.csv'"``).
    delimiter : str, optional
        The cell separator (one character; default ``,``).
    max_bytes : int
        The largest file read.
    optional : collection of str
        Columns that may be missing (absent from the result then).
    stated : mapping of str to str, optional
        The unit of a column whose header cell gives none (default: already in the unit asked for).
    exact : bool
        Refuse columns other than those of ``columns`` (else they are ignored).
    expected : str, optional
        What a wrong header is told to be (default: the names of ``columns``).
    max_rows : int, optional
        The most data rows read (a ValueError naming the limit at the first row beyond).  Memory is the file's
        bytes, its text (1-4 bytes a character) and 8 bytes a value read.

    Returns
    -------
    dict of str to numpy.ndarray
        Each column present, converted; and ``"line"``: the file line of each row (ints), for messages.

    Raises
    ------
    ValueError
        Beginning with ``where`` and naming the line (and column): not a regular file, too large, not UTF-8, no
        header, a missing, repeated or (with ``exact``) unexpected column, an unknown unit or one of another
        dimension, a line that is not a CSV row, a row of the wrong length, a cell that is not a number, no rows.
    """
    if delimiter is not None and (not isinstance(delimiter, str) or len(delimiter) != 1 or delimiter in "#\"\r\n"):
        raise ValueError(f"delimiter must be one character other than '#', a quote or a newline, got "
                         f"{shown(delimiter)}")
    lines = _data_lines(_decoded(read_regular(path, where, max_bytes), where))
    want = expected or ",".join(columns)
    first = next(lines, None)
    if first is None:
        raise ValueError(f"{where}: no header (expected {want})")
    delim = delimiter or ","
    raw = [h.strip() for h in _csv_row(*first, where, delim)]
    col, factor = _header_columns(raw, first[0], columns, where=where, optional=optional, stated=stated, exact=exact,
                                  want=want)
    # 8 bytes a value (array), not a Python float and a list slot (~32): memory module docstring
    out = {n: array("d") for n in col}
    line_of = array("q")
    for lineno, text_line in lines:
        if max_rows is not None and len(line_of) >= max_rows:
            raise ValueError(f"{where} line {lineno}: more than the {max_rows} data rows a file may have here")
        cells = _csv_row(lineno, text_line, where, delim)
        if len(cells) != len(raw):
            raise ValueError(f"{where} line {lineno}: {len(cells)} column(s), expected {len(raw)} "
                             f"({','.join(raw)})")
        for n, i in col.items():
            cell = cells[i].strip()
            try:
                out[n].append(float(cell) * factor[n])
            except ValueError:
                raise ValueError(f"{where} line {lineno} column {i + 1} ({n}): not a number: {shown(cell)}") from None
        line_of.append(lineno)
    if not line_of:
        raise ValueError(f"{where}: no data rows after the header")
    result = {n: np.frombuffer(x, dtype=float) for n, x in out.items()}
    result["line"] = np.frombuffer(line_of, dtype=np.int64)
    return result


def _decoded(data: bytes, where: str) -> str:
    """The file's bytes as text (UTF-8, a byte-order mark dropped); a ValueError naming the line of a bad byte."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise ValueError(f"{where} line {line}: not UTF-8 text ({exc.reason} at byte {exc.start}); is this a "
                         "CSV file?") from None


def _header_columns(raw: list[str], lineno: int, columns: Mapping[str, str], *, where: str,
                    optional: Collection[str], stated: Mapping[str, str] | None, exact: bool,
                    want: str) -> tuple[dict[str, int], dict[str, float]]:
    """The index of each wanted column present in the header ``raw`` (line ``lineno``) and the factor converting
    its values to the unit asked for; a ValueError for a missing, repeated or (``exact``) unexpected column."""
    names, units = [], []
    for cell in raw:
        name, unit = header_cell(cell)
        names.append(name)
        units.append(unit)
    shown_header = shown(",".join(raw))
    required = [n for n in columns if n not in optional]
    if (len(set(names)) != len(names) or any(n not in names for n in required)
            or (exact and any(n not in columns for n in names))):
        raise ValueError(f"{where} line {lineno}: header {shown_header}: expected the columns {want}")
    col = {n: names.index(n) for n in columns if n in names}
    factor = {}
    for n, i in col.items():
        unit = str(units[i] if units[i] is not None else (stated or {}).get(n, columns[n]))
        factor[n] = convert(n, unit, columns[n], where) if columns[n] or unit else 1.0
    return col, factor
