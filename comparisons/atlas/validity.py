"""Regenerate the measured validity :func:`peelapprox.estimate` reports (``peelapprox/_reduced/_validity.py``) from an
atlas.

    python -m comparisons.atlas.validity --from DIR_OR_CSV [--source TEXT] [--target FILE] [--check]

``DIR_OR_CSV`` is an atlas directory (its ``atlas_regimes.csv``, written by ``peelapprox atlas --out DIR``) or
that file.  Its ``approx:default`` rows (per regime label of :func:`peelapprox.estimate`: the exact stick-slip
points, the fractions predicted within 10 % for the slip interval, the force drop and both) become the table
``VALIDITY`` of the target (default: ``peelapprox/_reduced/_validity.py`` of this checkout), rewritten between its
``VALIDITY: dict[str, Validity] = {`` line and the closing brace, floats as ``repr`` (the CSV's text parsed to
the same floats, which ``tests/test_approx_attractor.py::test_validity_table_is_the_measurement`` checks against
the committed source file); ``--source`` replaces the one-line ``SOURCE`` string (where the numbers come
from, quoted to readers of :attr:`peelapprox.RegimeEstimate.validity`).  ``--check`` writes nothing and exits 1
when the target differs from what the table would be.  The generated table is the only edit: no hand copy.
"""

from __future__ import annotations

import argparse
import csv
import re
import sys
from pathlib import Path

__all__ = ["TARGET", "read_validity", "render", "regenerate", "main"]

#: The file the table is written into.
TARGET = Path(__file__).resolve().parents[2] / "peelapprox" / "_reduced" / "_validity.py"
_HEAD = "VALIDITY: dict[str, Validity] = {\n"
_SOURCE = re.compile(r'^SOURCE = \(.*?\)\n', re.S | re.M)


def read_validity(path: str | Path) -> dict[str, tuple[int, float, float, float, int, float]]:
    """``{regime: (points, slip_interval, force_drop, both, unflagged_points, unflagged_match)}`` from the
    ``approx:default`` rows of an atlas's ``atlas_regimes.csv`` (``path`` the file or its directory, or a file of
    the same rows such as ``comparisons.benchmark.approx_grid``'s), and its ``approx:default:unflagged`` rows where
    it has them (the points no rule but the regime's flags, and the share of them matching the exact set; ``(0,
    0.0)``: not measured); ValueError naming ``path`` when the file has no ``approx:default`` rows or a regime lacks
    one of the three observables."""
    p = Path(path)
    if p.is_dir():
        p = p / "atlas_regimes.csv"
    rows: dict[str, dict[str, dict[str, str]]] = {}
    unflagged: dict[str, tuple[int, float]] = {}
    with open(p, newline="") as fh:
        for r in csv.DictReader(fh):
            if r.get("approximation") == "approx:default":
                rows.setdefault(r["regime"], {})[r["observable"]] = r
            elif r.get("approximation") == "approx:default:unflagged":
                unflagged[r["regime"]] = (int(r["stick_slip"]), float(r["fraction"] or 0.0))
    if not rows:
        raise ValueError(f"path: {p} has no approx:default rows (an atlas_regimes.csv of peelapprox atlas)")
    out = {}
    for label, r in sorted(rows.items()):
        missing = {"slip_interval", "force_drop", "slip_interval+force_drop"} - set(r)
        if missing:
            raise ValueError(f"path: {p}: regime {label!r} lacks the rows {sorted(missing)}")
        frac = [float(r[k]["fraction"] or 0.0) for k in ("slip_interval", "force_drop", "slip_interval+force_drop")]
        out[label] = (int(r["slip_interval"]["stick_slip"]), frac[0], frac[1], frac[2], *unflagged.get(label, (0, 0.0)))
    return out


def render(table: dict[str, tuple[int, float, float, float, int, float]]) -> str:
    """The ``VALIDITY = {...}`` block of the table (one line per regime, floats as ``repr``)."""
    lines = [f"    {label!r}: Validity({n}, {si!r}, {fd!r}, {both!r},\n"
             f"{' ' * (len(repr(label)) + 15)}{nu}, {um!r}),"
             for label, (n, si, fd, both, nu, um) in table.items()]
    return _HEAD + "\n".join(lines) + "\n}\n"


def regenerate(source_file: str | Path, target: str | Path = TARGET, source: str | None = None) -> str:
    """The target's text with its table (and, if given, its ``SOURCE``) replaced from ``source_file``."""
    text = Path(target).read_text()
    start = text.index(_HEAD)
    end = text.index("\n}\n", start) + 3
    text = text[:start] + render(read_validity(source_file)) + text[end:]
    if source is not None:
        if not _SOURCE.search(text):
            raise ValueError(f"target: {target} has no SOURCE = (...) assignment to replace")
        text = _SOURCE.sub(lambda _: f"SOURCE = ({source!r})\n", text, count=1)
    return text


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.atlas.validity", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--from", dest="source_file", required=True, help="an atlas directory or its atlas_regimes.csv")
    ap.add_argument("--target", default=str(TARGET), help="the module to rewrite (default peelapprox/_reduced/_validity.py)")  # noqa: E501
    ap.add_argument("--source", help="the new SOURCE sentence (where the numbers come from)")
    ap.add_argument("--check", action="store_true", help="write nothing; exit 1 if the target is not up to date")
    args = ap.parse_args(argv)
    try:
        new = regenerate(args.source_file, args.target, args.source)
    except (OSError, ValueError) as exc:
        print(f"python -m comparisons.atlas.validity: {exc}", file=sys.stderr)
        return 2
    old = Path(args.target).read_text()
    if args.check:
        print("up to date" if new == old else f"{args.target} differs from {args.source_file}")
        return 0 if new == old else 1
    if new != old:
        Path(args.target).write_text(new)
    print(f"{args.target}: {len(read_validity(args.source_file))} regimes from {args.source_file}"
          + ("" if new != old else " (unchanged)"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
