"""What the subcommands share: their help (:class:`HelpFormatter`, :func:`subcommand`: a description, examples,
every default), the model's parameter options (the law's among them, :func:`add_params`, :func:`params_from_args`),
the wall-clock budget ``--max-wall`` (:func:`add_max_wall_option`, :func:`wall_left`), printing a summary with
units (:data:`UNITS`), writing a table that records the law."""

from __future__ import annotations

import argparse
import json
import re
import sys
import textwrap
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, NoReturn

from .. import GEOMETRIES, GRAVITY, LOAD_MASS_RANGE, LOAD_RANGE, LOADINGS, TAPE_MASS_RANGE, PeelForce, PeelParams
from .._checks import interval
from .._ranges import default_load_masses
from ..errors import WallBudget
from ..io import fmt_number, write_csv, write_rows
from ._checks import clip, positive_float
from ._force import add_force_options, force_from_args, law_fields

__all__ = ["FORMATS", "HYBRID_ONLY", "MAX_WALL", "NEGATIVE_NUMBER", "ArgumentParser", "FromMethods", "HelpFormatter",
           "HelpFromMethods", "REDUCED_ONLY", "UNITS", "add_format", "add_max_wall_option", "add_params",
           "add_variant_options", "add_grid_params", "methods", "params_from_args", "print_mapping", "scipy_solvers",
           "variant_summary", "say", "subcommand", "wall_left", "wall_spent", "write_table"]

#: ``--format`` of the subcommands that print one summary: ``table`` (``key: value [unit]`` lines), ``csv`` (a
#: header and one row), ``json``.
FORMATS = ("table", "csv", "json")


#: A negative number as an option's value: ``-1``, ``-1.5``, ``-.5``, ``-1e-5``, ``-1.5E+3``, ``-inf``, ``-nan``.
#: argparse's own rule (``^-\d+$|^-\d*\.\d+$`` before Python 3.13) misses the exponent form, so ``--I -1e-5``
#: was read as an unknown option ``-1e-5`` and ``--I`` as missing its value ("expected one argument").
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


def methods() -> Mapping[str, Any]:
    """exact's table of solver methods (name -> class), imported when first needed."""
    from exact import METHODS

    return METHODS


class FromMethods(Sequence[str]):
    """A list read from the table of solver methods when argparse first needs it (to check a value or to print
    the help): building the parser loads no ``exact``."""

    def __init__(self, read: Callable[[Mapping[str, Any]], Iterable[str]]):
        self._read: Callable[[Mapping[str, Any]], Iterable[str]] = read
        self._items: tuple[str, ...] | None = None

    def _all(self) -> tuple[str, ...]:
        if self._items is None:
            self._items = tuple(self._read(methods()))
        return self._items

    def __getitem__(self, i):  # type: ignore[override]
        return self._all()[i]

    def __len__(self) -> int:
        return len(self._all())

    def __repr__(self) -> str:
        return repr(self._all())


class HelpFromMethods(str):
    """An option's help written from the table of solver methods when printed (argparse formats a help as
    ``help % params``); ``short`` stands for it until then."""

    def __new__(cls, short: str, write: Callable[[Mapping[str, Any]], str]) -> HelpFromMethods:
        obj = super().__new__(cls, short)
        obj._write = write  # type: ignore[attr-defined]
        return obj

    def __mod__(self, params: Any) -> str:
        return self._write(methods()) % params  # type: ignore[attr-defined]


def scipy_solvers(table: Mapping[str, Any]) -> Iterable[str]:
    """Every scipy solver of the methods in ``table``, in its order (the valid ``--solver`` values)."""
    return dict.fromkeys(s for m in table.values() for s in m.solvers)


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser with the command line's two rules for its own errors (its subparsers are of this class
    too, ``add_subparsers`` makes them so):

    * an option's value may be a negative number in any float notation (:data:`NEGATIVE_NUMBER`), e.g.
      ``--alpha0 -1e-3``, as it may be a positive one;
    * its one-line error (exit status 2, after the usage) echoes what the user passed cut to a few hundred
      characters (:func:`~peelapprox.cli._checks.clip`), and "expected one argument" says how to pass a value
      that starts with ``-`` (``--opt=VALUE``).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message: str) -> NoReturn:
        m = re.match(r"argument (\S+): expected one argument$", message)
        if m:
            opt = m.group(1).split("/")[-1]
            message += f" (a value that starts with '-' is written {opt}=VALUE)"
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {clip(message)}\n")


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """The subcommands' help: the description and the examples as written (their lines kept), and every option's
    default appended to its help, ``(default: X)``, unless the help states it (it says ``default``)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        d = action.default
        if (not action.option_strings or d is None or d is False or d is argparse.SUPPRESS or "default" in text
                or isinstance(d, list)):
            return text
        shown = fmt_number(d, 6, short_exponent=True) if isinstance(d, float) else str(d)
        return f"{text} (default: {shown.replace('%', '%%')})"


def subcommand(sub: Any, name: str, *, help: str, description: str, examples: Sequence[str],
               **kwargs: Any) -> argparse.ArgumentParser:
    """A subparser with a one-line ``help`` (in ``peelapprox --help``), a ``description`` (its paragraphs, split at
    blank lines, wrapped to 100 columns) and ``examples`` (its epilog, one command a line as written, ``#``
    comments kept), formatted by :class:`HelpFormatter`."""
    text = "\n\n".join(textwrap.fill(p, 100) for p in description.split("\n\n"))
    epilog = "examples:\n" + "\n".join(f"  {e}" for e in examples)
    return sub.add_parser(name, help=help, description=text, epilog=epilog, formatter_class=HelpFormatter, **kwargs)


#: The default ``--max-wall`` of every subcommand [s]: ten minutes, the longest a command run by hand should block
#: unasked (the library's calls default to ``exact.DEFAULT_MAX_WALL``, an hour).
MAX_WALL = 600.0


def add_max_wall_option(parser: argparse.ArgumentParser | argparse._ArgumentGroup, default: float = MAX_WALL,
                        what: str = "the whole command", spent: str = "") -> None:
    """``--max-wall S``: the wall-clock budget [s] of ``what``, a positive number of seconds (``default`` 600);
    ``spent`` says what happens when it is spent (appended to the help)."""
    parser.add_argument("--max-wall", type=positive_float, default=default, metavar="S",
                        help=f"wall-clock budget of {what} [s]" + (f"; {spent}" if spent else ""))


def wall_spent(wall: WallBudget) -> bool:
    """Whether the command's budget ``wall`` (of ``--max-wall``) is spent."""
    return wall.limit is not None and time.perf_counter() - wall.t0 >= wall.limit


def wall_left(wall: WallBudget) -> float | None:
    """The seconds left of ``wall`` to pass on as a library call's ``max_wall`` (None: unbounded), at least 1 ms:
    a call made as it runs out still starts, and stops at its own first check."""
    if wall.limit is None:
        return None
    return max(1e-3, wall.limit - (time.perf_counter() - wall.t0))


def add_variant_options(v: Any, *, loading_default: str | None = "velocity") -> None:
    """The model variant's options ``--tape-mass --loading --load-mass --load`` (docs/tape-mass.md) in the
    argument group ``v``; ``loading_default=None`` for a command that records only the options given (``sweep``)."""
    v.add_argument("--tape-mass", type=float, default=None, metavar="KG",
                   help=f"mass m of the peeled ribbon [kg], in [{TAPE_MASS_RANGE[0]:g}, {TAPE_MASS_RANGE[1]:g}]: "
                        "the tape-mass model, a smooth ODE (method smooth) (default: none, the paper's massless "
                        "tape; 0 is the same)")
    v.add_argument("--loading", choices=LOADINGS, default=loading_default,
                   help="velocity: the end pulled at the constant speed V (the paper); load: a constant force "
                        "--load on a body of mass --load-mass, its speed V_p a state starting at V (default: "
                        "velocity)")
    v.add_argument("--load-mass", type=float, default=None, metavar="KG",
                   help=f"mass M at the pulled end [kg], in [{LOAD_MASS_RANGE[0]:g}, {LOAD_MASS_RANGE[1]:g}]; "
                        "required with --loading load (default: none)")
    v.add_argument("--load", type=float, default=None, metavar="N",
                   help=f"the load F_L [N], in [{LOAD_RANGE[0]:g}, {LOAD_RANGE[1]:g}], with --loading load "
                        "(default: --load-mass times g = 9.80665 m/s^2, a hanging mass)")


def add_params(sp: argparse.ArgumentParser, *, geometry: bool = True, variants: str | None = None) -> None:
    """The options ``--V --I --k --R`` of :class:`peelapprox.PeelParams` and, with ``geometry`` (for the exact
    model; the reduced equations are the paper's linear closure), ``--l --geometry``, its law ``force``
    (:func:`peelapprox.cli._force.add_force_options`) and the model variant (a tape mass, a load):
    ``--tape-mass --loading --load-mass --load``; :func:`params_from_args` builds them.

    ``variants``: None if the subcommand runs the variants; else why it does not (e.g. "runs the paper's reduced
    equations, derived for the massless tape under velocity control"): the variant options are still there,
    and :func:`params_from_args` refuses them with that reason (exit status 2), rather than ignoring them.
    """
    g = sp.add_argument_group("model parameters (PeelParams)")
    g.add_argument("--V", type=float, required=True, help="pull speed [m/s]")
    g.add_argument("--I", type=float, required=True, help="roller inertia [kg m^2]")
    g.add_argument("--k", type=float, default=1000.0, help="tape stiffness [N/m]")
    g.add_argument("--R", type=float, default=0.1, help="roller radius [m]")
    if geometry:
        g.add_argument("--l", type=float, default=1.0, help="roller-motor distance [m] (read by --geometry exact)")
        g.add_argument("--geometry", choices=GEOMETRIES, default="paper",
                       help="the closure cos(theta): paper (the paper's sin(alpha) form) or exact (the full geometry "
                            "with l)")
    title = "model variant (docs/tape-mass.md, docs/constant-load.md)"
    if variants is not None:
        title += f"; refused here: this command {variants}"
    add_variant_options(sp.add_argument_group(title))
    sp.set_defaults(variants_refused=variants)
    add_force_options(sp)


def add_grid_params(sp: argparse.ArgumentParser) -> None:
    """The :class:`peelapprox.PeelParams` fields of every point of a (V, I) grid, whose axes V and I are:
    ``--k --R --l --geometry``, each None unless given (a resumed grid's options must match what was given), its
    default in its help (``peelapprox sweep``, ``peelapprox atlas``)."""
    p = sp.add_argument_group("model parameters (PeelParams; V and I are the grid)")
    p.add_argument("--k", type=float, default=None, help="tape stiffness [N/m] (default: 1000)")
    p.add_argument("--R", type=float, default=None, help="roller radius [m] (default: 0.1)")
    p.add_argument("--l", type=float, default=None, help="roller-motor distance [m] (read by --geometry exact; "
                                                        "default: 1)")
    p.add_argument("--geometry", choices=GEOMETRIES, default=None,
                   help="the closure cos(theta): paper or exact (default: paper)")


#: Why a subcommand refuses the model variants (``add_params(variants=...)``).
REDUCED_ONLY = ("runs the paper's reduced equations, derived for the massless tape under velocity control "
                "(tape_mass none, --loading velocity)")
HYBRID_ONLY = ("finds periodic orbits of the hybrid solver, the paper's massless model under velocity control "
               "(tape_mass none, --loading velocity)")

#: The variant options of :func:`add_params` as the CLI spells them, and their defaults.
_VARIANT_OPTIONS = {"tape_mass": ("--tape-mass", None), "loading": ("--loading", "velocity"),
                    "load_mass": ("--load-mass", None), "load": ("--load", None)}


def params_from_args(args: argparse.Namespace) -> PeelParams:
    """The :class:`PeelParams` of the options of :func:`add_params` (``l`` and ``geometry`` at their defaults where
    the subcommand has no such option).

    A ValueError (exit status 2) if the subcommand refuses the variant options (``add_params(variants=...)``) and
    one is given, naming the options and why; PeelParams' own ValueError names a field out of range, as its option
    (``--I``, ``--tape-mass``, ...); with ``--loading load`` and no ``--load``, a default load ``--load-mass`` times g
    outside LOAD_RANGE is a ValueError saying that the default was used."""
    extra: dict[str, Any] = {k: getattr(args, k) for k in ("l", "geometry") if getattr(args, k, None) is not None}
    given: dict[str, Any] = {k: getattr(args, k, d) for k, (_, d) in _VARIANT_OPTIONS.items()
             if getattr(args, k, d) != d and not (k == "tape_mass" and getattr(args, k) == 0.0)}  # 0: massless
    why = getattr(args, "variants_refused", None)
    if given and why is not None:
        shown = " ".join(f"{_VARIANT_OPTIONS[k][0]} {v:g}" if isinstance(v, float) else f"{_VARIANT_OPTIONS[k][0]} {v}"
                         for k, v in given.items())
        raise ValueError(f"{shown}: the model variants (tape mass, constant load) are not available here: this "
                         f"command {why}; drop {', '.join(_VARIANT_OPTIONS[k][0] for k in given)} (peelapprox "
                         f"simulate runs the variants)")
    _check_default_load(args)
    try:
        return PeelParams(V=args.V, I=args.I, k=args.k, R=args.R, force=force_from_args(args), **extra, **given)
    except ValueError as exc:  # a field named as its option (--I, --tape-mass, ...)
        msg = str(exc)
        options = {**{k: f"--{k}" for k in ("V", "I", "k", "R", "l", "geometry")},
                   **{k: opt for k, (opt, _) in _VARIANT_OPTIONS.items()}}
        for k, opt in options.items():
            if msg.startswith(k + " ") or msg.startswith(k + "="):
                raise ValueError(opt + msg[len(k):]) from None
        raise


def _check_default_load(args: argparse.Namespace) -> None:
    """With ``--loading load``, ``--load-mass M`` in its range and no ``--load``: a ValueError unless the default
    load M g lies in LOAD_RANGE, saying that the default was used (the user gave no --load) and which --load-mass
    gives a valid one (:func:`peelapprox._ranges.default_load_masses`)."""
    M = getattr(args, "load_mass", None)
    if getattr(args, "loading", None) != "load" or getattr(args, "load", None) is not None or M is None:
        return
    if not LOAD_MASS_RANGE[0] <= M <= LOAD_MASS_RANGE[1]:
        return  # PeelParams names --load-mass and its range
    load = M * GRAVITY
    if not LOAD_RANGE[0] <= load <= LOAD_RANGE[1]:
        raise ValueError(f"--load was not given, so its default --load-mass times g = {M:g} kg * {GRAVITY:g} m/s^2 = "
                         f"{load:.6g} N was used; the load must be in {interval(*LOAD_RANGE)} N: give --load, or a "
                         f"--load-mass in {interval(*default_load_masses())} kg")


def variant_summary(params: PeelParams) -> dict[str, Any]:
    """The variant fields of ``params`` that are set (``tape_mass`` [kg], ``loading``, ``load_mass`` [kg],
    ``load`` [N]) for a summary; ``{}`` for the paper's model (its summaries as before the variants)."""
    if params.variant is None:
        return {}
    return {k: getattr(params, k) for k in _VARIANT_OPTIONS if getattr(params, k) is not None}


def add_format(sp: argparse.ArgumentParser | argparse._ArgumentGroup, what: str = "the summary") -> None:
    """``--format`` with the choices :data:`FORMATS` (table)."""
    sp.add_argument("--format", choices=FORMATS, default="table",
                    help=f"how {what} is printed: table (key: value [unit] lines), csv (a header and a row) or json")


_STATE_UNITS = {"t": "s", "alpha": "rad", "omega": "rad/s", "F": "N", "v": "m/s", "Vp": "m/s"}
_S = "s"
_N = "N"
_MS = "m/s"
#: The unit of a printed key (``table`` output; JSON and CSV carry none: the names are documented in docs/usage.md).
UNITS: dict[str, str] = {
    "V": _MS, "I": "kg m^2", "k": "N/m", "R": "m", "l": "m", "tape_mass": "kg", "load_mass": "kg", "load": _N,
    **{k: _S for k in ("period", "t_end", "t_transient", "window", "settle_time", "wall_time", "wall_time_s",
                       "compile_time_s", "lyapunov_time", "lyapunov_wall_time", "dt", "period_at_f_min",
                       "period_at_f_max", "period_at_mean", "cd_damping_time", "t_ab_crude", "t_ab_quasi_static",
                       "t_cd_quasi_static")},
    **{k: "rad" for k in ("alpha0", "alpha_in", "alpha_exit", "amplitude")},
    **{k: "rad/s" for k in ("alphadot_in", "alphadot_exit", "omega0")},
    **{k: _MS for k in ("Vp_range", "v_max", "v_min", "v_inflection", "v_land_cd", "v_land_ab", "v_breakdown",
                        "v_in", "v_f", "fixed_point_v")},
    **{k: _N for k in ("f_max", "f_min", "f_zero", "fixed_point_F", "F_in", "F_exit", "dF", "F_mean", "F_max_bound",
                       "F_min_bound", "dF_ab_quasi_static", "dF_cd_quasi_static", "mean_force_drop",
                       "force_drop_std", "F_min_at_jumps", "F_max_at_jumps", "F_at_jumps", "F_at_jumps_range", "F0")},
    **{k: "N s/m" for k in ("fprime_at_V", "fixed_point_fprime")},
    **{k: "bits/s" for k in ("lyapunov_bits_per_s", "lyapunov_stderr")},
}


def _number(val: Any) -> bool:
    return isinstance(val, (int, float)) and not isinstance(val, bool)


def _text(key: str, val: Any) -> str:
    """``val`` for a ``key: value`` line, floats to 6 significant digits, with the unit of ``key`` (:data:`UNITS`)
    after a number or a list of numbers; a state (a dict of ``t, alpha, omega, F, v``) with each unit."""
    unit = UNITS.get(key)
    if key == "period" and not _number(val):  # dynamics' period is a label ("period-3", "aperiodic")
        unit = None
    if isinstance(val, dict):
        return ", ".join(f"{k} = {fmt_number(v, 6, nan='nan')}" + (f" {_STATE_UNITS[k]}" if k in _STATE_UNITS and
                                                                  _number(v) else "") for k, v in val.items())
    if isinstance(val, (list, tuple)) and val and all(_number(x) for x in val):
        return "[" + ", ".join(fmt_number(float(x), 6, nan="nan") for x in val) + "]" + (f" {unit}" if unit else "")
    if isinstance(val, float):
        return fmt_number(val, 6, nan="nan") + (f" {unit}" if unit else "")
    if _number(val) and unit:
        return f"{val} {unit}"
    return str(val)


def print_mapping(row: dict, fmt: str) -> None:
    """``row`` as JSON, as CSV (a header and one row) or as right-aligned ``key: value [unit]`` lines (floats to 6
    significant digits, units from :data:`UNITS`)."""
    if fmt == "json":
        print(json.dumps(row, indent=2))
    elif fmt == "csv":
        write_csv(sys.stdout, [{k: json.dumps(v) if isinstance(v, (dict, list)) else v for k, v in row.items()}],
                  fields=list(row))
    else:
        width = max(len(k) for k in row)
        for key, val in row.items():
            print(f"{key:>{width}}: {_text(key, val)}")


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
