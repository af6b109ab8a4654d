"""The peel-force law on the command line: ``--force``, ``--force-table``, ``--force-family`` (a tape's own law).

Every subcommand that builds a :class:`peelapprox.PeelParams` takes one law (:func:`add_force_options`,
called by :func:`peelapprox.cli._common.add_params`), at most one of

* ``--force EXPR`` with ``--const NAME=VALUE`` (repeatable): :meth:`PeelForce.expression`;
* ``--force-table FILE.csv``: a measured curve, :meth:`PeelForce.tabulated` (:func:`read_force_table`);
* ``--force-family NAME`` with ``--coef NAME=VALUE`` (repeatable): :meth:`PeelForce.family`;
* ``--force-table FILE.csv --smooth [--lam LAM]``: the file's noisy points smoothed, :meth:`PeelForce.smoothed`;
* ``--force-fit FILE.csv --family NAME``: a family fitted to the file's points, :meth:`PeelForce.fit`;

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
import dataclasses
import textwrap
from typing import Any

import numpy as np

from .. import PeelForce, SolverBudgetExceeded
from .._csvread import MAX_BYTES
from .._deadline import Expired, caller_budget
from ..law._tablefile import TABLE_COLUMNS
from ..validate import shown

__all__ = ["MAX_TABLE_BYTES", "TABLE_COLUMNS", "add_force_options", "families_help", "fitted_table",
           "force_from_args", "law_fields", "name_value", "read_force_table", "smoothed_table"]


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
    kind.add_argument("--force-fit", metavar="FILE.csv",
                      help="a family (--family) fitted to a measured curve (PeelForce.fit): the CSV of "
                           "--force-table, one curve; units in the header (v [mm/s], f [kN]) are converted; an "
                           "optional column sigma (f's standard deviation [N]) weights the fit; standard errors and "
                           "chi2 are printed")
    g.add_argument("--family", metavar="NAME",
                   help=f"the family --force-fit fits: {', '.join(_family_names())}")
    g.add_argument("--smooth", action="store_true",
                   help="with --force-table: smooth the (noisy) points by a C4 spline in ln v (PeelForce.smoothed) "
                        "instead of interpolating them")
    g.add_argument("--lam", type=_lam, default="gcv", metavar="LAM",
                   help="with --smooth: the smoothing penalty, a number >= 0 (it smooths over about "
                        "(LAM * L / n)^(1/4) in ln v, L the data's range in ln v, n the points), or 'gcv' (default: "
                        "cross-validation's, else the least penalty that gives the N shape while following the data)")
    g.add_argument("--const", type=name_value, action="append", metavar="NAME=VALUE",
                   help="a constant of --force (repeatable)")
    g.add_argument("--coef", type=name_value, action="append", metavar="NAME=VALUE",
                   help="a coefficient of --force-family (repeatable; the others at their defaults)")


def _lam(text: str) -> float | str:
    """Argparse type of ``--lam``: ``gcv`` or a real number (its range is checked by :meth:`PeelForce.smoothed`)."""
    if text.strip().lower() == "gcv":
        return "gcv"
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be 'gcv' or a number >= 0, got {shown(text)}") from None


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
    SolverBudgetExceeded
        Building ``--force`` (sympy's derivatives) took longer than ``--max-wall`` (the build's own limit is
        ``LAW_BUILD_SECONDS``, 60 s, a ValueError; ``--max-wall`` applies where nearer).
    """
    expr, table, family = getattr(args, "force", None), getattr(args, "force_table", None), \
        getattr(args, "force_family", None)
    consts, coefs = getattr(args, "const", None), getattr(args, "coef", None)
    fit, fit_family, smooth = getattr(args, "force_fit", None), getattr(args, "family", None), \
        getattr(args, "smooth", False)
    lam = getattr(args, "lam", "gcv")
    if smooth and table is None:
        raise ValueError("--smooth smooths the points of --force-table FILE; there is no --force-table")
    if lam != "gcv" and not smooth:
        raise ValueError("--lam is the penalty of --smooth; there is no --smooth")
    if (fit is None) != (fit_family is None):
        raise ValueError("--force-fit FILE and --family NAME go together (the family fitted to the file's points)")
    if fit is not None:
        return fitted_table(fit, str(fit_family))
    if consts and expr is None:
        raise ValueError("--const sets a constant of --force EXPR; there is no --force")
    if coefs and family is None:
        raise ValueError("--coef sets a coefficient of --force-family NAME; there is no --force-family")
    option = "--force" if expr is not None else "--force-family"
    max_wall = getattr(args, "max_wall", None)
    try:
        with caller_budget(max_wall):  # the law's build: at most LAW_BUILD_SECONDS, or --max-wall if nearer
            if expr is not None:
                return PeelForce.expression(expr, **_pairs("--const", consts))
            if family is not None:
                return PeelForce.family(family, **_pairs("--coef", coefs))
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{option}: {exc}") from None
    except Expired:  # the caller's budget only (the law's own limit is a ValueError above)
        raise SolverBudgetExceeded(f"{option}: more than {max_wall:g} s of wall time (--max-wall) building the "
                                   "peel-force law before the run started; pass a larger --max-wall, or write the "
                                   "law in a simpler form (expanded, fewer factors)", budget="max_wall",
                                   limit=float(max_wall or 0.0), t=0.0, state={"t": 0.0}) from None
    if table is not None:
        return smoothed_table(table, lam) if smooth else read_force_table(table)
    return PeelForce.paper()


# --------------------------------------------------------------------------------------------- the table file

#: Largest ``--force-table`` file read [bytes]: :data:`peelapprox._csvread.MAX_BYTES` (16 MiB).
MAX_TABLE_BYTES = MAX_BYTES


def read_force_table(path: str) -> PeelForce:
    """The law :meth:`PeelForce.from_csv` makes of the CSV file ``path`` (``--force-table``), its errors naming
    ``--force-table PATH`` and the file line (and column)."""
    from ..law._tablefile import from_csv

    try:
        return from_csv(PeelForce, path, None, None, where=f"--force-table {shown(path)}")
    except ValueError as exc:
        if "exactly one local maximum followed by one local minimum" not in str(exc):
            raise
        raise ValueError(f"{exc}; for noisy points add --smooth, or fit a family (--force-fit FILE --family NAME)"
                         ) from None


def _one_table(option: str, path: str, sigma: bool = False) -> tuple[np.ndarray, np.ndarray, list]:
    """``(v, f, tables)`` of the file of ``option``: one table (no V column, or one V); with ``sigma``, a sigma
    column is read too (``tables[0][4]``, None without one)."""
    from ..law._tablefile import read_points

    tables = read_points(path, where=f"{option} {shown(path)}", sigma=sigma)
    if len(tables) != 1:
        raise ValueError(f"{option} {shown(path)}: {len(tables)} tables (one per V); {option} takes one curve")
    return tables[0][1], tables[0][2], tables


def smoothed_table(path: str, lam: float | str = "gcv") -> PeelForce:
    """``--force-table FILE --smooth [--lam LAM]``: :meth:`PeelForce.smoothed` of the file's points (one curve)."""
    from ..law._tablefile import with_line

    v, f, tables = _one_table("--force-table", path)
    try:
        return PeelForce.smoothed(v, f, lam=lam, V=tables[0][0])
    except (ValueError, TypeError) as exc:
        opt = "" if lam == "gcv" else f" --lam {lam:g}"
        raise ValueError(f"--force-table {shown(path)} --smooth{opt}: {with_line(str(exc), tables)}") from None


def fitted_table(path: str, family: str) -> PeelForce:
    """``--force-fit FILE --family NAME``: :meth:`PeelForce.fit` of the family to the file's points (one curve;
    a V column gives the V of a V-dependent family; a ``sigma`` column, f's standard deviation [N], weights the
    fit: chi^2 is then meaningful and the standard errors absolute)."""
    from ..law._tablefile import with_line

    v, f, tables = _one_table("--force-fit", path, sigma=True)
    try:
        return PeelForce.fit(v, f, family, sigma=tables[0][4], V=tables[0][0])
    except (ValueError, TypeError) as exc:
        raise ValueError(f"--force-fit {shown(path)} --family {family}: {with_line(str(exc), tables)}") from None


# --------------------------------------------------------------------------------------------- the record

def law_fields(law: PeelForce, *, spec: bool = False) -> dict[str, Any]:
    """What a result records of its law: ``law`` (``repr``), ``law_key`` (:attr:`PeelForce.key`), for a fitted
    law (``--force-fit``) its statistics (``fit_weighted``: a sigma column was given; ``fit_stderr_<name>`` of each
    fitted coefficient and of the folds; ``fit_chi2``, ``fit_dof``, ``fit_chi2_dof``; ``fit_folds_note`` where the
    folds are not estimated) and, with
    ``spec=True`` (JSON), ``law_spec``: ``dataclasses.asdict(law)``, which :meth:`PeelForce.from_dict`
    rebuilds."""
    out: dict[str, Any] = {"law": repr(law), "law_key": law.key}
    fr = law.fit_result
    if fr is not None:  # a fitted law (--force-fit): its statistics
        out["fit_weighted"] = fr.absolute_sigma
        out.update({f"fit_stderr_{n}": fr.stderr[n] for n in fr.names})
        out.update(fit_chi2=fr.chi2, fit_dof=fr.dof, fit_chi2_dof=fr.chi2_dof)
        if fr.folds is not None:
            out.update({f"fit_stderr_{k}": x for k, x in fr.folds.stderr.items()})
        else:
            out["fit_folds_note"] = fr.folds_note
    if spec:
        out["law_spec"] = dataclasses.asdict(law)
    return out
