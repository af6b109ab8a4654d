"""The row files of a benchmark script: its parser's ``--json`` and ``--csv`` and the rows written to each path
given (:func:`peelapprox.io.write_rows`, which reads the format from the ending)."""

from __future__ import annotations

import argparse
from typing import Any

from peelapprox.io import write_rows

__all__ = ["add_row_files", "write_row_files"]


def add_row_files(ap: argparse.ArgumentParser) -> None:
    """Add ``--json FILE`` and ``--csv FILE`` to ``ap``."""
    ap.add_argument("--json", help="write the rows as JSON (a path ending in .json)")
    ap.add_argument("--csv", help="write the rows as CSV (a path ending in .csv)")


def write_row_files(args: argparse.Namespace, rows: list[dict[str, Any]]) -> None:
    """Write ``rows`` to the ``--json`` and ``--csv`` paths of ``args`` that were given."""
    for path in (args.json, args.csv):
        if path:
            write_rows(path, rows)
