"""Command line: ``peelapprox simulate | folds | estimate | segment ...`` (also ``python -m peelapprox``).

The CLI is the only place that ties the three packages (peelapprox, exact,
comparisons) together; each subcommand lives in its own module here, and its
handler imports what it needs (the solvers, the harness) lazily, through their
public names, when it runs.

Output paths are checked before any computation and reported exactly as
written (:mod:`peelapprox.cli._checks`).  Nothing ends in a traceback: an
error is one line on stderr, ``peelapprox <command>: error: <message>``, the
user's input in it cut to a few hundred characters, with the exit status

* 0: done;
* 1: writing failed (OSError) or, for ``sweep``, a point failed;
* 2: a usage error: a bad argument or output path (ValueError, argparse's errors);
* 3: the model or solver stopped (ModelBreakdown, SolverBudgetExceeded, SolverFailure, TransientNotPassed);
* 4: an internal error, any other exception: a bug of peelapprox, reported as
  ``peelapprox <command>: internal error: <Type>: <message> (a bug: please report it; set
  PEELAPPROX_TRACEBACK=1 to see the traceback)``; with ``PEELAPPROX_TRACEBACK=1`` it is re-raised, traceback
  and all;
* 130: interrupted (Ctrl-C).

A warning (e.g. scipy's about a stiff step) is one line too, ``peelapprox <command>: warning: <Category>:
<message>``.  An option's value may be a negative number in any notation (``--alpha0 -1e-3``); another value
that starts with ``-`` is written ``--option=VALUE``.
"""

from __future__ import annotations

import argparse
import os
import sys
import textwrap
import warnings
from collections.abc import Callable, Sequence
from typing import Any

from .._deadline import WallSpent, time_limit
from .._version import __version__
from . import atlas, basins, benchmark, cache, compare, data, dynamics, estimate, figures, front, orbit, simulate, sweep
from ._checks import EXIT_INTERNAL, EXIT_INTERRUPTED, TRACEBACK_ENV, clip, exit_status, one_line
from ._common import ArgumentParser, HelpFormatter, add_max_wall_option

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
_atlas = atlas.run
_warmup = cache.run_warmup
_doctor = cache.run_doctor
_front = front.run
_series = data.run_series
_infer = data.run_infer


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``peelapprox``: one subparser per subcommand, its handler in ``func``."""
    ap = ArgumentParser(
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
               "budget),\n1 writing failed (or, for sweep, a point failed), 4 an internal error (a bug: one line, "
               f"the traceback\nwith {TRACEBACK_ENV}=1), 130 interrupted.  A negative value is written as it is "
               "(--alpha0 -1e-3);\nanother value that starts with '-' as --option=VALUE.")
    ap.add_argument("--version", action="version", version=f"peelapprox {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")
    simulate.add_parser(sub).set_defaults(func=_simulate)
    _hard_wall(estimate.add_folds_parser(sub)).set_defaults(func=_folds)
    _hard_wall(estimate.add_estimate_parser(sub)).set_defaults(func=_estimate)
    _hard_wall(estimate.add_segment_parser(sub)).set_defaults(func=_segment)
    _hard_wall(compare.add_parser(sub)).set_defaults(func=_compare)
    _hard_wall(benchmark.add_parser(sub)).set_defaults(func=_benchmark)
    sweep.add_parser(sub).set_defaults(func=_sweep)
    _hard_wall(figures.add_parser(sub)).set_defaults(func=_figures)
    dynamics.add_parser(sub).set_defaults(func=_dynamics)
    orbit.add_orbit_parser(sub).set_defaults(func=_orbit)
    orbit.add_bifurcation_parser(sub).set_defaults(func=_bifurcation)
    basins.add_parser(sub).set_defaults(func=_basins)
    atlas.add_parser(sub).set_defaults(func=_atlas)
    cache.add_warmup_parser(sub).set_defaults(func=_warmup)
    cache.add_doctor_parser(sub).set_defaults(func=_doctor)
    front.add_parser(sub).set_defaults(func=_front)
    data.add_series_parser(sub).set_defaults(func=_series)
    data.add_infer_parser(sub).set_defaults(func=_infer)
    return ap


def _hard_wall(sp: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """``--max-wall S`` (default 600 s) on a subcommand whose library calls have no wall budget of their own: the
    whole command is stopped when it is spent (exit status 3; :func:`main` arms the timer).  The subcommands that
    run budgeted library calls (simulate, dynamics, orbit, bifurcation, basins, sweep, atlas) pass theirs on instead and
    write what they computed."""
    add_max_wall_option(sp, spent="when it is spent the command stops (exit status 3)")
    sp.set_defaults(hard_wall=True)
    return sp


def _warning_line(command: str) -> Callable[..., None]:
    """A ``warnings.showwarning`` that prints a warning as one line, ``peelapprox <command>: warning: <Category>:
    <message>`` (cut as an error is), instead of Python's two lines with a source line of the library that
    issued it (scipy's ``solver._y, solver.t = integrator.run(``), which read like part of a traceback."""

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int, file: Any = None,
             line: str | None = None) -> None:
        text = clip(" ".join(str(message).split()))
        print(f"peelapprox {command}: warning: {category.__name__}: {text}", file=sys.stderr if file is None else file)

    return show


def _internal_error(command: str, exc: BaseException) -> str:
    """The one line of an internal error (module docstring)."""
    return (f"peelapprox {command}: internal error: {type(exc).__name__}: {one_line(exc)} (a bug: please report "
            f"it; set {TRACEBACK_ENV}=1 to see the traceback)\n")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``); returns the exit status.

    Every error ends in ``SystemExit`` with one line on stderr and the status of the module docstring: a user
    error (2), a stop of the model or solver (3), a failed write (1), an interruption (130), and any other
    exception, a bug, as an internal error (4), re-raised with its traceback only when the environment variable
    ``PEELAPPROX_TRACEBACK`` is ``1``.
    """
    ap = build_parser()
    command = "(no command)"
    try:
        args = ap.parse_args(argv)
        command = args.command
        with warnings.catch_warnings():  # restores Python's printer when the command returns
            warnings.showwarning = _warning_line(command)
            if not getattr(args, "hard_wall", False):
                return args.func(args)
            try:
                with time_limit(args.max_wall, WallSpent):
                    return args.func(args)
            except WallSpent:
                ap.exit(3, f"peelapprox {command}: error: more than {args.max_wall:g} s of wall time (--max-wall); "
                           "pass a larger --max-wall\n")
    except KeyboardInterrupt:
        ap.exit(EXIT_INTERRUPTED, f"peelapprox {command}: interrupted\n")
    except Exception as exc:
        status = exit_status(exc)
        if status is not None:
            # the library's advice names its keyword; on the command line it is the option
            text = (one_line(exc).replace("pass a larger max_wall, or None", "pass a larger --max-wall")
                    .replace("wall time (max_wall)", "wall time (--max-wall)"))
            ap.exit(status, f"peelapprox {command}: error: {text}\n")
        if os.environ.get(TRACEBACK_ENV, "").strip() == "1":
            raise
        ap.exit(EXIT_INTERNAL, _internal_error(command, exc))
