"""What the subcommands share: the model's parameter options (the law's among them), printing a summary,
writing a table that records the law."""

from __future__ import annotations

import argparse
import json
import sys

from .. import PeelForce
from ..io import fmt_number, write_rows
from ._force import add_force_options, law_fields

__all__ = ["add_params", "print_mapping", "say", "write_table"]


def add_params(sp: argparse.ArgumentParser) -> None:
    """The options ``--V --I --k --R`` of :class:`peelapprox.PeelParams`, and its law ``force``
    (:func:`peelapprox.cli._force.add_force_options`; build it with ``force_from_args``)."""
    sp.add_argument("--V", type=float, required=True, help="pull speed [m/s]")
    sp.add_argument("--I", type=float, required=True, help="roller inertia [kg m^2]")
    sp.add_argument("--k", type=float, default=1000.0, help="tape stiffness [N/m] (1000)")
    sp.add_argument("--R", type=float, default=0.1, help="roller radius [m] (0.1)")
    add_force_options(sp)


def print_mapping(row: dict, fmt: str) -> None:
    """``row`` as JSON or as right-aligned ``key: value`` lines (floats to 6 significant digits)."""
    if fmt == "json":
        print(json.dumps(row, indent=2))
    else:
        width = max(len(k) for k in row)
        for key, val in row.items():
            if isinstance(val, float):
                val = fmt_number(val, 6, nan="nan")
            print(f"{key:>{width}}: {val}")


def write_table(path: str, rows: list[dict], law: PeelForce | None = None) -> None:
    """Write rows as CSV or JSON, chosen by the file extension (:func:`peelapprox.io.write_rows`), and say so.

    ``path`` was checked by :func:`~peelapprox.cli._checks.check_output_path` (kind ``"table"``) before the run.
    With ``law``, every row records it (:func:`~peelapprox.cli._force.law_fields`: ``law`` and ``law_key``,
    and in a ``.json`` also ``law_spec``), after its own columns.
    """
    if law is not None:
        extra = law_fields(law, spec=str(path).endswith(".json"))
        rows = [{**r, **extra} for r in rows]
    write_rows(path, rows)
    print(f"wrote {path}", file=sys.stderr)


def say(msg: str) -> None:
    """A progress line on stderr."""
    print(msg, file=sys.stderr, flush=True)
