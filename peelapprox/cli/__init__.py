"""Command line: ``peelapprox simulate | folds | estimate | segment ...`` (also ``python -m peelapprox``).

The CLI is the only place that ties the three packages (peelapprox, exact,
comparisons) together; each subcommand lives in its own module here, and its
handler imports what it needs (the solvers, the harness) lazily, through their
public names, when it runs.

Output paths are checked before any computation and reported exactly as
written (:mod:`peelapprox.cli._checks`).  A user error is one line on stderr,
``peelapprox <command>: error: <message>``, never a traceback; exit status 2
for a usage error (a bad argument or output path), 3 when the model or solver
stops (ModelBreakdown, SolverBudgetExceeded, SolverFailure, TransientNotPassed),
1 when writing fails (OSError) or, for ``sweep``, when a point failed.
"""

from __future__ import annotations

import argparse
import textwrap
from collections.abc import Sequence

from .._version import __version__
from . import basins, benchmark, compare, dynamics, estimate, figures, orbit, simulate, sweep
from ._checks import exit_status, one_line
from ._common import HelpFormatter

__all__ = ["build_parser", "main"]

# The handlers, looked up here when the parser is built (so that they can be replaced, e.g. in a test).
_simulate = simulate.run
_folds = estimate.run_folds
_estimate = estimate.run_estimate
_segment = estimate.run_segment
_compare = compare.run
_benchmark = benchmark.run
_sweep = sweep.run
_figures = figures.run
_dynamics = dynamics.run
_orbit = orbit.run_orbit
_bifurcation = orbit.run_bifurcation
_basins = basins.run


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``peelapprox``: one subparser per subcommand, its handler in ``func``."""
    ap = argparse.ArgumentParser(
        prog="peelapprox", formatter_class=HelpFormatter,
        description=textwrap.fill(
            "Stick-slip peeling of an adhesive tape from a roller (De, Maybhate and Ananthakrishna, Phys. Rev. E 70, "
            "046223 (2004)): the exact model, the paper's reduced equations and their comparison.  'peelapprox COMMAND "
            "--help' describes a command, its options (units, defaults) and examples.", 100),
        epilog="examples:\n"
               "  peelapprox compare                                  # the paper's scenes, approximate vs exact\n"
               "  peelapprox simulate --V 1 --I 1e-2 --t-end 20 --plot run.png\n"
               "  peelapprox dynamics --V 2 --I 1e-4 --lyapunov       # period, force drops, Lyapunov exponent\n"
               "  python -m peelapprox --version\n\n"
               "exit status: 0 done, 2 a bad argument or output path, 3 the model or solver stopped (breakdown, "
               "budget),\n1 writing failed (or, for sweep, a point failed).")
    ap.add_argument("--version", action="version", version=f"peelapprox {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")
    simulate.add_parser(sub).set_defaults(func=_simulate)
    estimate.add_folds_parser(sub).set_defaults(func=_folds)
    estimate.add_estimate_parser(sub).set_defaults(func=_estimate)
    estimate.add_segment_parser(sub).set_defaults(func=_segment)
    compare.add_parser(sub).set_defaults(func=_compare)
    benchmark.add_parser(sub).set_defaults(func=_benchmark)
    sweep.add_parser(sub).set_defaults(func=_sweep)
    figures.add_parser(sub).set_defaults(func=_figures)
    dynamics.add_parser(sub).set_defaults(func=_dynamics)
    orbit.add_orbit_parser(sub).set_defaults(func=_orbit)
    orbit.add_bifurcation_parser(sub).set_defaults(func=_bifurcation)
    basins.add_parser(sub).set_defaults(func=_basins)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``); returns the exit status.

    User errors end in ``SystemExit`` with one line on stderr (module docstring
    for the statuses); any other exception is a bug and propagates with its
    traceback.
    """
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        return args.func(args)
    except Exception as exc:
        status = exit_status(exc)
        if status is None:  # not a user error or a documented stop: a bug, with its traceback
            raise
        ap.exit(status, f"peelapprox {args.command}: error: {one_line(exc)}\n")
