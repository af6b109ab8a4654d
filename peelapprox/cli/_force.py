"""The peel-force law on the command line: ``--force``, ``--force-table``, ``--force-family`` (a tape's own law).

Every subcommand that builds a :class:`peelapprox.PeelParams` takes one law (:func:`add_force_options`,
called by :func:`peelapprox.cli._common.add_params`), at most one of

* ``--force EXPR`` with ``--const NAME=VALUE`` (repeatable): :meth:`PeelForce.expression`;
* ``--force-table FILE.csv``: a measured curve, :meth:`PeelForce.tabulated` (:func:`read_force_table`);
* ``--force-family NAME`` with ``--coef NAME=VALUE`` (repeatable): :meth:`PeelForce.family`;

and none means the paper's fvV (:meth:`PeelForce.paper`).  :func:`force_from_args` builds the law; a
consumer that cannot run it (a table where a closed form is needed, a table too short for the run) raises its
own ``ValueError`` naming ``params.force``, which the CLI prints as one line with exit status 2, as any bad
argument.

What a subcommand prints and writes records the law it ran (:func:`law_fields`): ``law`` (its ``repr``) and
``law_key`` (:attr:`PeelForce.key`) in every CSV row, and in JSON also ``law_spec``,
``dataclasses.asdict(law)``, from which :meth:`PeelForce.from_dict` rebuilds it.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import errno
import math
import os
import re
import stat
import textwrap
from typing import Any

from .. import PeelForce
from ..validate import shown

__all__ = ["MAX_TABLE_BYTES", "TABLE_COLUMNS", "add_force_options", "families_help", "force_from_args", "law_fields",
           "name_value", "read_force_table"]

#: The headers ``--force-table`` accepts: one table, or several grouped by the pull speed V [m/s].
TABLE_COLUMNS = (("v", "f"), ("V", "v", "f"))


def _family_names() -> tuple[str, ...]:
    """The families' names.  peelapprox has no public list of them (``PeelForce.family`` only names them in the
    error for an unknown one), so they are read from the private registry, inside the package."""
    from ..law._families import FAMILIES

    return tuple(FAMILIES)


def families_help() -> str:
    """One line per family: ``NAME: coef=default, ...`` (defaults from ``PeelForce.family(NAME)``)."""
    lines = []
    for name in _family_names():
        law = PeelForce.family(name)
        coefs = ", ".join(f"{c}={x:g}" for c, x in law.coefficients)
        lines.append(f"{name}: {coefs}")
    return "; ".join(lines)


def name_value(text: str) -> tuple[str, int | float]:
    """Argparse type of ``--const`` and ``--coef``: ``NAME=VALUE``, VALUE a real number.

    VALUE written as an integer (``150``) is an ``int``, otherwise a ``float`` (``150.0``, ``1.5e2``): an
    expression law keeps the difference, as sympy does (``PeelForce.expression("a*v", a=150)`` is the law
    ``"150*v"``, and ``a=150.0`` the law ``"150.0*v"``; equal values, unequal laws), so that ``--const a=150``
    gives the law a Python user gets with ``a=150``.
    """
    name, sep, value = text.partition("=")
    name = name.strip()
    if not sep or not name.isidentifier():
        raise argparse.ArgumentTypeError(f"value must be NAME=VALUE (e.g. a=150), got {shown(text)}")
    try:
        return name, int(value)
    except ValueError:
        pass
    try:
        x = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"value of {name} must be a real number, got {shown(value.strip())}") from None
    return name, x


def add_force_options(sp: argparse.ArgumentParser) -> None:
    """The law options (module docstring), in their own group of ``--help``, the three kinds exclusive."""
    g = sp.add_argument_group(
        "peel-force law",
        textwrap.fill("f(v, V) [N]; default the paper's fvV. At most one of --force, --force-table, --force-family. "
                      f"Families and their coefficients (defaults): {families_help()}.", 100))
    kind = g.add_mutually_exclusive_group()
    kind.add_argument("--force", metavar="EXPR",
                      help="a law in v [m/s] and optionally V [m/s], e.g. 'a + b*v - c*v**2 + d*v**3' "
                           "(PeelForce.expression); constants by --const")
    kind.add_argument("--force-table", metavar="FILE.csv",
                      help="a measured curve (PeelForce.tabulated): CSV with the header v,f (one table) or "
                           "V,v,f (one table per pull speed V); lines starting with # are comments")
    kind.add_argument("--force-family", metavar="NAME",
                      help=f"a family (PeelForce.family): {', '.join(_family_names())}; coefficients by --coef")
    g.add_argument("--const", type=name_value, action="append", metavar="NAME=VALUE",
                   help="a constant of --force (repeatable)")
    g.add_argument("--coef", type=name_value, action="append", metavar="NAME=VALUE",
                   help="a coefficient of --force-family (repeatable; the others at their defaults)")


def _pairs(option: str, pairs: list[tuple[str, int | float]] | None) -> dict[str, int | float]:
    out: dict[str, int | float] = {}
    for name, x in pairs or ():
        if name in out:
            raise ValueError(f"{option} {name} is given twice")
        out[name] = x
    return out


def force_from_args(args: argparse.Namespace) -> PeelForce:
    """The law the options of :func:`add_force_options` describe (the paper's without any).

    Raises
    ------
    ValueError
        ``--const`` without ``--force``, ``--coef`` without ``--force-family``, a name given twice, or what
        :class:`PeelForce` or :func:`read_force_table` refuses (unknown family or coefficient, bad
        expression, bad table), prefixed with the option.
    """
    expr, table, family = getattr(args, "force", None), getattr(args, "force_table", None), \
        getattr(args, "force_family", None)
    consts, coefs = getattr(args, "const", None), getattr(args, "coef", None)
    if consts and expr is None:
        raise ValueError("--const sets a constant of --force EXPR; there is no --force")
    if coefs and family is None:
        raise ValueError("--coef sets a coefficient of --force-family NAME; there is no --force-family")
    try:
        if expr is not None:
            return PeelForce.expression(expr, **_pairs("--const", consts))
        if family is not None:
            return PeelForce.family(family, **_pairs("--coef", coefs))
    except (ValueError, TypeError) as exc:
        option = "--force" if expr is not None else "--force-family"
        raise ValueError(f"{option}: {exc}") from None
    if table is not None:
        return read_force_table(table)
    return PeelForce.paper()


# --------------------------------------------------------------------------------------------- the table file

#: Largest ``--force-table`` file read [bytes], 16 MiB: a measured peel-force curve has hundreds to a few thousand
#: rows of ~30 bytes, so 16 MiB (about 500,000 rows, parsed and checked in a few seconds) is far beyond any real
#: table, while a path to a huge file (a log, a disk image) is refused at once instead of filling the memory.
MAX_TABLE_BYTES = 16 * 1024 * 1024

_FILE_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
               (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _read_regular(path: str, where: str) -> bytes:
    """The bytes of the regular file ``path``, at most :data:`MAX_TABLE_BYTES`, or a ValueError beginning with
    ``where``.

    The file is opened without blocking (``O_NONBLOCK``: opening a FIFO for reading would otherwise wait for a
    writer forever) and its kind is read from the open descriptor (``fstat``), so the file checked is the file
    read.  A FIFO, a device, a socket or a directory is refused, and so is a file of more than
    :data:`MAX_TABLE_BYTES` (by its size, and again by what is read: a file growing meanwhile is caught too).
    """
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
    limit = f"{MAX_TABLE_BYTES // (1024 * 1024)} MiB"
    if st.st_size > MAX_TABLE_BYTES:
        os.close(fd)
        raise ValueError(f"{where}: {st.st_size} bytes, more than the {limit} a table may have (a measured curve "
                         "is a few thousand rows; is this the right file?)")
    with os.fdopen(fd, "rb") as fh:
        try:
            data = fh.read(MAX_TABLE_BYTES + 1)
        except OSError as exc:
            raise ValueError(f"{where}: cannot read it ({exc.strerror or exc})") from None
    if len(data) > MAX_TABLE_BYTES:
        raise ValueError(f"{where}: more than the {limit} a table may have (a measured curve is a few thousand "
                         "rows; is this the right file?)")
    return data


def _data_lines(text: str) -> list[tuple[int, str]]:
    """``(line number, text)`` of the lines that are not blank or comments (``#`` to the end of a line)."""
    out = []
    for n, line in enumerate(re.split(r"\r\n|\r|\n", text), start=1):  # universal newlines, as open() reads
        line = line.split("#", 1)[0].strip()
        if line:
            out.append((n, line))
    return out


def _csv_rows(lines: list[tuple[int, str]], where: str) -> list[list[str]]:
    """The cells of each data line (:mod:`csv`), a csv error (e.g. a field over csv's size limit, an unclosed
    quote) as a ValueError naming the file line."""
    rows = []
    for lineno, text in lines:
        try:
            cells = next(csv.reader([text]), [])
        except csv.Error as exc:
            raise ValueError(f"{where} line {lineno}: not a CSV row ({exc})") from None
        rows.append(cells)
    return rows


def read_force_table(path: str) -> PeelForce:
    """The law :meth:`PeelForce.tabulated` makes of the CSV file ``path`` (``--force-table``).

    The first data line is the header, ``v,f`` (one table, used at every V) or ``V,v,f`` in any order
    (one table per distinct V, the rows of a V in file order, the tables in order of first appearance).
    ``#`` starts a comment (whole line or its end); blank lines are skipped.  The file is UTF-8 text (a
    byte-order mark before the header, as spreadsheets write it, is skipped), a regular file of at most
    :data:`MAX_TABLE_BYTES`.

    Raises
    ------
    ValueError
        Naming the file (and for a cell its line and column): missing or unreadable; not a regular file (a
        FIFO, a device, a directory: refused without waiting on it); larger than :data:`MAX_TABLE_BYTES`; not
        UTF-8 text; no header, a header other than those of :data:`TABLE_COLUMNS`; a line that is not a CSV
        row (csv's error, e.g. a field longer than its limit); a row with too few or too many cells, a cell
        that is not a number; or :meth:`PeelForce.tabulated`'s error (which names the offending point
        ``v[i]``/``f[i]``), with the file line of that point added.
    """
    where = f"--force-table {shown(path)}"
    data = _read_regular(path, where)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise ValueError(f"{where} line {line}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    lines = _data_lines(text)
    if not lines:
        raise ValueError(f"{where}: no header (expected {' or '.join(','.join(c) for c in TABLE_COLUMNS)})")
    rows = _csv_rows(lines, where)
    header = [h.strip() for h in rows[0]]
    if sorted(header) not in [sorted(c) for c in TABLE_COLUMNS] or len(set(header)) != len(header):
        raise ValueError(f"{where} line {lines[0][0]}: header {shown(','.join(header))}: expected the columns "
                         f"{' or '.join(','.join(c) for c in TABLE_COLUMNS)} (V is the pull speed, v the peel "
                         "velocity [m/s], f the force [N])")
    col = {name: i for i, name in enumerate(header)}
    groups: dict[float | None, list[tuple[int, float, float]]] = {}
    for (lineno, _), cells in zip(lines[1:], rows[1:]):
        if len(cells) != len(header):
            raise ValueError(f"{where} line {lineno}: {len(cells)} column(s), expected {len(header)} "
                             f"({','.join(header)})")
        vals = {}
        for name, i in col.items():
            cell = cells[i].strip()
            try:
                vals[name] = float(cell)
            except ValueError:
                raise ValueError(f"{where} line {lineno} column {i + 1} ({name}): not a number: "
                                 f"{shown(cell)}") from None
        V = vals.get("V")
        if V is not None and not math.isfinite(V):
            raise ValueError(f"{where} line {lineno} column {col['V'] + 1} (V): must be finite, got {V!r}")
        groups.setdefault(V, []).append((lineno, vals["v"], vals["f"]))
    if not groups:
        raise ValueError(f"{where}: no data rows after the header")
    tables = [(V, [r[1] for r in pts], [r[2] for r in pts]) for V, pts in groups.items()]
    try:
        if "V" in col:
            return PeelForce.tabulated(tables=tables)
        return PeelForce.tabulated(tables[0][1], tables[0][2])
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{where}: {_with_line(str(exc), list(groups.values()))}") from None


def _with_line(msg: str, groups: list[list[tuple[int, float, float]]]) -> str:
    """``msg`` with the file line of the point it names (``v[i]``/``f[i]`` of ``tables[n]``, or of the only
    table) appended, when it names one."""
    m = re.search(r"\b[vf]\[(\d+)\]", msg)
    if not m:
        return msg
    t = re.search(r"tables\[(\d+)\]", msg)
    n = int(t.group(1)) if t else (0 if len(groups) == 1 else None)
    i = int(m.group(1))
    if n is None or n >= len(groups) or i >= len(groups[n]):
        return msg
    return f"{msg} (line {groups[n][i][0]})"


# --------------------------------------------------------------------------------------------- the record

def law_fields(law: PeelForce, *, spec: bool = False) -> dict[str, Any]:
    """What a result records of its law: ``law`` (``repr``), ``law_key`` (:attr:`PeelForce.key`) and, with
    ``spec=True`` (JSON), ``law_spec``: ``dataclasses.asdict(law)``, which :meth:`PeelForce.from_dict`
    rebuilds."""
    out: dict[str, Any] = {"law": repr(law), "law_key": law.key}
    if spec:
        out["law_spec"] = dataclasses.asdict(law)
    return out
